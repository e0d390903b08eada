"""Which writer writes which target format, and the file suffix each target gets: derived from the
formats' declarations (:mod:`modelkit.formats.registry`, each format's ``declare.py``).

Writers are imported lazily (mujoco only for MJCF output). A writer is a function
``write(robot, ctx) -> bytes``: the model file's content; meshes go through ``ctx.meshes``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from modelkit.formats.declaration import FormatDeclaration
from modelkit.formats.registry import TARGET_NAMES, WRITTEN

if TYPE_CHECKING:
    from modelkit.convert.context import WriteContext
    from modelkit.model import Robot

Writer = Callable[["Robot", "WriteContext"], bytes]
__all__ = ["TARGETS", "TARGET_NAMES", "TargetInfo", "Writer", "load_writer", "target_for_path", "target_info"]


@dataclass(frozen=True)
class TargetInfo:
    """A format modelkit writes: its name and its declared output."""

    name: str
    suffix: str  # what `convert -o DIR --to NAME` names the files
    suffixes: tuple[str, ...]  # output suffixes that select this target
    writer: str  # "module:function"
    tracks_native: bool = False  # the target holds pseudo continuous tracks itself
    auto_wheel: str = "cylinder"  # the wheel collision `--wheel-collision auto` writes
    sites_native: bool = False  # the target holds MJCF sites itself (else they become frame links)
    frames_native: bool = False  # the target holds SDF <frame>s itself (else they become frame links)
    pair_exclusions_native: bool = False  # the target excludes one link pair's contacts (else MK867)
    spawn: str = ""  # how a user stands a free robot on the ground, "{z}" its height (MK884); "": itself
    places_root: bool = False  # the file places the root at the model's root pose


def _target(declaration: FormatDeclaration) -> TargetInfo:
    out = declaration.output
    if out is None:
        raise ValueError(f"format {declaration.name} declares no output")
    return TargetInfo(declaration.name, out.suffix, out.suffixes, out.writer, out.tracks_native,
                      out.auto_wheel, out.sites_native, out.frames_native,
                      out.pair_exclusions_native, out.spawn, out.places_root)


TARGETS: tuple[TargetInfo, ...] = tuple(_target(d) for d in WRITTEN)


def target_info(name: str) -> TargetInfo:
    for t in TARGETS:
        if t.name == name:
            return t
    raise KeyError(name)


def target_for_path(path: Path) -> TargetInfo | None:
    """The target an output file name selects by its suffix (None: a folder, or unknown)."""
    name = path.name.lower()
    for t in TARGETS:
        if any(name.endswith(s) for s in t.suffixes):
            return t
    return None


def load_writer(name: str) -> Writer:
    module_name, _, function = target_info(name).writer.partition(":")
    writer: Writer = getattr(importlib.import_module(module_name), function)
    return writer
