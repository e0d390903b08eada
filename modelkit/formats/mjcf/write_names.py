"""Names for the MJCF writer: unique per MuJoCo namespace, deterministic, renames noted (MK800).

MuJoCo requires names to be unique within each object type (bodies, joints, geoms, sites,
cameras, lights, meshes, sensors, actuators, equalities) and reserves the body name ``world``.
A clash gets the first free ``<name>_<n>`` (n = 2, 3, ...), and an MK800 note records the rename
as data (:func:`modelkit.convert.notes.renames`; a body is the model's "link"). The table remembers
which name each wanted name got (:meth:`NameTable.written`), so that the source's own sensors can name
the objects they refer to under their written names (:mod:`.write_own`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from modelkit.convert.context import WriteContext
from modelkit.convert.names import unique_name
from modelkit.diagnostics import SourceLocation

RESERVED = {"body": {"world"}, "default": {"main", "visual", "collision"}}
MODEL_KIND = {"body": "link"}  # MuJoCo's word → the model's, in rename records


@dataclass
class NameTable:
    """One set of taken names per MuJoCo object type."""

    ctx: WriteContext
    taken: dict[str, set[str]] = field(default_factory=dict)
    # per kind: wanted name → the names written for it, in order
    given: dict[str, dict[str, list[str]]] = field(default_factory=dict)

    def claim(
        self,
        kind: str,
        wanted: str,
        source: SourceLocation | None = None,
        target: str | None = None,
        note: bool = True,
        remember: bool = True,
    ) -> str:
        """A unique name of ``kind`` as close to ``wanted`` as possible (noted when changed);
        ``remember=False`` for an object no source object of that name is (a device's own site)."""
        taken = self.taken.setdefault(kind, set(RESERVED.get(kind, set())))
        name = unique_name(wanted or kind, taken)
        if name != wanted and note:
            why = "MuJoCo reserves it" if wanted in RESERVED.get(kind, set()) else "the name is taken"
            if not wanted:
                why = "MuJoCo needs a name here"
            self.ctx.rename(MODEL_KIND.get(kind, kind), wanted, name, why, source, target or name)
        if remember:
            self.given.setdefault(kind, {}).setdefault(wanted, []).append(name)
        return name

    def written(self, kind: str, wanted: str, first: bool = False) -> str | None:
        """The name written for the one object of ``kind`` that wanted ``wanted``; ``None`` when none
        or several did (a reference to it cannot be told apart), unless ``first``: the first one's
        (a geom written twice, as collision and visual geom at the same pose)."""
        names = self.given.get(kind, {}).get(wanted, [])
        return names[0] if len(names) == 1 or (first and names) else None

