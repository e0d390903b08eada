"""Which writer writes which target format, and the file suffix each target gets.

Writers are imported lazily (mujoco only for MJCF output). A writer is a function
``write(robot, ctx) -> bytes``: the model file's content; meshes go through ``ctx.meshes``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from modelkit.convert.context import WriteContext
    from modelkit.model import Robot

Writer = Callable[["Robot", "WriteContext"], bytes]


@dataclass(frozen=True)
class TargetInfo:
    name: str
    suffix: str  # what `convert -o DIR --to NAME` names the files
    suffixes: tuple[str, ...]  # output suffixes that select this target
    writer: str  # "module:function"
    tracks_native: bool = False  # the target holds pseudo continuous tracks itself


TARGETS: tuple[TargetInfo, ...] = (
    TargetInfo("urdf", ".urdf", (".urdf",), "modelkit.formats.urdf.writer:write_urdf"),
    TargetInfo("sdf", ".sdf", (".sdf",), "modelkit.formats.sdf.writer:write_sdf"),
    TargetInfo("mjcf", ".xml", (".xml", ".mjcf"), "modelkit.formats.mjcf.writer:write_mjcf"),
    TargetInfo("body", ".body", (".body",), "modelkit.formats.body.writer:write_body", tracks_native=True),
)
TARGET_NAMES = tuple(t.name for t in TARGETS)


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
