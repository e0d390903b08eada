"""Every format modelkit knows: the declarations of ``modelkit/formats/<name>/declare.py``, collected.

Data only, importable without any reader or writer (nor numpy): the CLI's ``--input-format`` and
``--to`` choices come from here at startup. :mod:`modelkit.formats.reading` picks the reader,
:mod:`modelkit.convert.registry` the writer. A new format adds its package with a ``declare.py`` and
one entry below (``tests/test_format_registry.py`` fails until it does).
"""

from __future__ import annotations

from typing import Any

from modelkit.formats.body import declare as body
from modelkit.formats.declaration import FormatDeclaration
from modelkit.formats.mjcf import declare as mjcf
from modelkit.formats.sdf import declare as sdf
from modelkit.formats.urdf import declare as urdf
from modelkit.formats.xacro import declare as xacro

DECLARED: tuple[FormatDeclaration, ...] = (body.FORMAT, urdf.FORMAT, xacro.FORMAT, sdf.FORMAT, mjcf.FORMAT)
"""Every format, in the order of ``--input-format``'s choices. Detection tries them in this order
(their suffixes and root tags are disjoint, so the order decides nothing there)."""

WRITTEN: tuple[FormatDeclaration, ...] = (urdf.FORMAT, sdf.FORMAT, mjcf.FORMAT, body.FORMAT)
"""The formats that declare an output, in the order of ``convert --to``'s choices."""

FORMAT_NAMES: tuple[str, ...] = tuple(d.name for d in DECLARED)
TARGET_NAMES: tuple[str, ...] = tuple(d.name for d in WRITTEN)


EXTRAS_QUIET: frozenset[str] = frozenset().union(*(d.extras.quiet for d in DECLARED))
"""Robot ``extras`` keys a target that drops them has nothing to say about (each format's own, declared)."""
EXTRAS_QUIET_LINK: frozenset[str] = frozenset().union(*(d.extras.quiet_link for d in DECLARED))
"""The same for link ``extras`` keys."""
EXTRAS_DROPPED: dict[str, tuple[str, str]] = {
    key: (code, what) for d in DECLARED for key, code, what in d.extras.dropped
}
"""Robot ``extras`` key → (code, words) of the note a target that drops it gives (each format's own)."""
EXTRAS_PARTLY_CARRIED: frozenset[str] = frozenset().union(*(d.extras.partly_carried for d in DECLARED))
"""Dropped robot keys whose content the model's fields carry in part (counted by walking writers)."""
EXTRAS_OWNER: dict[str, str] = {key: d.name for d in DECLARED for key, _, _ in d.extras.dropped}
"""Robot ``extras`` key declared dropped → the format that owns it."""
EXTRAS_DROPPED_LINK: dict[str, tuple[str, str, str]] = {
    key: (d.name, code, what) for d in DECLARED for key, code, what in d.extras.dropped_link
}
"""Link ``extras`` key → (owning format, code, words) of the note every other target gives."""
EXTRAS_DROPPED_JOINT: dict[str, tuple[str, str, str]] = {
    key: (d.name, code, what) for d in DECLARED for key, code, what in d.extras.dropped_joint
}
"""The same for joint ``extras`` keys."""
EXTRAS_DEFAULTS: dict[str, dict[str, object]] = {
    key: dict(entries) for d in DECLARED for key, entries in d.extras.defaults
}
"""Dropped key → its entries that say only the owning format's default (left out of a note)."""
EXTRAS_CARRIED_TO: dict[str, tuple[frozenset[str], str]] = {
    key: (frozenset(targets), left) for d in DECLARED for key, targets, left in d.extras.carried_to
}
"""Dropped key → the targets whose writers carry it all the same, and the function that tells what of a
value they still drop ("": nothing)."""


def carried_by(target: str) -> frozenset[str]:
    """The other formats' dropped keys that ``target``'s writer carries whole (no note for them)."""
    return frozenset(key for key, (targets, left) in EXTRAS_CARRIED_TO.items()
                     if target in targets and not left)


def partly_carried_by(target: str) -> dict[str, str]:
    """The other formats' dropped keys that ``target``'s writer carries in part → the "module:function"
    that gives, from a value and its owner, the part it still drops."""
    return {key: left for key, (targets, left) in EXTRAS_CARRIED_TO.items() if target in targets and left}


def declared(name: str) -> FormatDeclaration:
    """The declaration of format ``name`` (KeyError: no such format)."""
    for d in DECLARED:
        if d.name == name:
            return d
    raise KeyError(name)


def declared_function(path: str) -> Any:
    """The function a declaration names as ``"module:function"`` (imported on first use)."""
    import importlib

    module, name = path.split(":")
    return getattr(importlib.import_module(module), name)
