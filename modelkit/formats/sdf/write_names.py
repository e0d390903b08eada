"""Names the SDF writer gives links, joints and frames: unique in the model, none reserved.

SDFormat ≥ 1.7 requires every link, joint and frame of a model to have a distinct name, forbids
``world``, names that start and end with ``__``, and ``::`` (the scope delimiter of nested
models). Links keep their names where they can; a joint or frame that clashes gets ``_joint`` /
``_frame`` appended (then ``_2``, ``_3``...). Every change is an MK800 note naming both names
(:func:`modelkit.convert.notes.renames` reads them back).
"""

from __future__ import annotations

from modelkit.convert.context import WriteContext
from modelkit.diagnostics import SourceLocation

SUFFIX = {"link": "_link", "joint": "_joint", "frame": "_frame"}


class Names:
    """Hands out the written names of one model (links first, then joints, then frames)."""

    def __init__(self, ctx: WriteContext) -> None:
        self.ctx = ctx
        self.used: set[str] = {"world"}
        self.links: dict[str, str] = {}
        self.joints: dict[str, str] = {}
        self.frames: dict[str, str] = {}

    def claim(self, kind: str, name: str, source: SourceLocation | None, why_taken: str = "") -> str:
        table = {"link": self.links, "joint": self.joints, "frame": self.frames}[kind]
        if name in table:
            return table[name]
        wanted = name.replace("::", "__")
        reason = ""
        if wanted != name:
            reason = "SDFormat reserves '::' for nested model scopes"
        if not wanted or (wanted.startswith("__") and wanted.endswith("__")):
            wanted = f"{kind}_{wanted.strip('_')}".rstrip("_")
            reason = "SDFormat reserves names that start and end with '__'"
        new = wanted
        if new in self.used:
            reason = why_taken or (
                "SDFormat reserves the name world"
                if new == "world"
                else f"SDFormat ≥ 1.7 forbids a {kind} sharing its name with another link, joint or frame "
                "of the model"
            )
            new = wanted + SUFFIX[kind]
            count = 2
            while new in self.used:
                new = f"{wanted}{SUFFIX[kind]}_{count}"
                count += 1
        self.used.add(new)
        table[name] = new
        if new != name:
            self.ctx.rename(kind, name, new, reason, source)
        return new
