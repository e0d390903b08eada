"""Names for the MJCF writer: unique per MuJoCo namespace, deterministic, renames noted (MK800).

MuJoCo requires names to be unique within each object type (bodies, joints, geoms, sites,
cameras, lights, meshes, sensors, actuators, equalities) and reserves the body name ``world``.
A clash gets the first free ``<name>_<n>`` (n = 2, 3, ...), and the MK800 note reads
``<kind> "<old>" renamed to "<new>" (<why>)`` so that tools can recover the mapping.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from modelkit.convert.context import WriteContext
from modelkit.diagnostics import SourceLocation

RESERVED = {"body": {"world"}}
RENAME_NOTE = re.compile(r'^(\w+) "(.*)" renamed to "(.*)" \(')


@dataclass
class NameTable:
    """One set of taken names per MuJoCo object type."""

    ctx: WriteContext
    taken: dict[str, set[str]] = field(default_factory=dict)

    def claim(
        self,
        kind: str,
        wanted: str,
        source: SourceLocation | None = None,
        target: str | None = None,
        note: bool = True,
    ) -> str:
        """A unique name of ``kind`` as close to ``wanted`` as possible (noted when changed)."""
        taken = self.taken.setdefault(kind, set(RESERVED.get(kind, set())))
        base = wanted or kind
        name, n = base, 1
        while name in taken:
            n += 1
            name = f"{base}_{n}"
        taken.add(name)
        if name != wanted and note:
            why = "MuJoCo reserves it" if wanted in RESERVED.get(kind, set()) else "the name is taken"
            if not wanted:
                why = "MuJoCo needs a name here"
            self.ctx.note("MK800", f'{kind} "{wanted}" renamed to "{name}" ({why})', source, target or name)
        return name


def renames_from_notes(messages: list[str], kind: str = "body") -> dict[str, str]:
    """Old → new names of ``kind`` from MK800 note messages (for round-trip comparisons)."""
    out: dict[str, str] = {}
    for message in messages:
        match = RENAME_NOTE.match(message)
        if match and match.group(1) == kind:
            out[match.group(2)] = match.group(3)
    return out
