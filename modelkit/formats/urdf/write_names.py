"""URDF writer, names: every link and joint gets a name no other link or joint has.

URDF itself allows a joint named like a link (``check_urdf`` accepts it), but libsdformat's
URDF → SDF conversion fails on it (peers.md §2.1), so the joint is renamed ``<name>_joint``.
Empty and duplicate names are renamed too. Each rename is an MK800 note that records it as data
(:func:`modelkit.convert.notes.renames` reads it back for round-trip comparisons).
"""

from __future__ import annotations

from collections.abc import Iterable

from modelkit.convert.context import WriteContext
from modelkit.model import Robot


class NameTable:
    """Written names of the robot's links and joints (by position), unique across both."""

    def __init__(self, robot: Robot, ctx: WriteContext, reserved: Iterable[str] = ()) -> None:
        self.ctx = ctx
        self.taken: set[str] = set(reserved)
        self.links: list[str] = []
        self.joints: list[str] = []
        self.link_map: dict[str, str] = {}  # source link name → written name (its first link)
        self.joint_map: dict[str, str] = {}
        wanted = [link.name for link in robot.links]
        for link in robot.links:
            if link.name and link.name not in self.taken:
                name = link.name
            else:
                why = "it is empty" if not link.name else f'"{link.name}" is taken'
                name = self.fresh(link.name or "link")
                self._note("link", link.name, name, why, link.loc("name"))
            self.taken.add(name)
            self.links.append(name)
            self.link_map.setdefault(link.name, name)
        link_names = set(wanted)
        for joint in robot.joints:
            if not joint.name:
                name = self.fresh(f"{self.link_map.get(joint.child, joint.child) or 'joint'}_joint")
                self._note("joint", joint.name, name, "it is empty", joint.loc("name"))
            elif joint.name in link_names:
                name = self.fresh(f"{joint.name}_joint")
                self._note(
                    "joint",
                    joint.name,
                    name,
                    "a link has the same name (libsdformat's URDF to SDF conversion refuses that)",
                    joint.loc("name"),
                )
            elif joint.name in self.taken:
                name = self.fresh(joint.name)
                self._note("joint", joint.name, name, f'"{joint.name}" is taken', joint.loc("name"))
            else:
                name = joint.name
            self.taken.add(name)
            self.joints.append(name)
            self.joint_map.setdefault(joint.name, name)

    def fresh(self, base: str) -> str:
        """``base``, or ``base_2``, ``base_3``... : the first that no link or joint has; reserved."""
        name, n = base, 1
        while name in self.taken:
            n += 1
            name = f"{base}_{n}"
        self.taken.add(name)
        return name

    def link(self, name: str) -> str:
        return self.link_map.get(name, name)

    def joint(self, name: str) -> str:
        return self.joint_map.get(name, name)

    def _note(self, kind: str, old: str, new: str, why: str, source: object) -> None:
        from modelkit.diagnostics import SourceLocation

        self.ctx.rename(kind, old, new, why, source if isinstance(source, SourceLocation) else None)
