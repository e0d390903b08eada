"""URDF writer, names: every link a name no other link has, every joint one no other joint has.

URDF allows a joint named like a link (``check_urdf``, ``robot_state_publisher`` and rviz take it),
and ROS tools find joints by name (``joint_states``), so a source joint named like its link keeps its
name (MK846 says so: libsdformat's URDF → SDF conversion refuses such a file, peers.md §2.1). With
``WriteOptions.urdf_distinct_names`` such a joint is renamed ``<name>_joint`` instead. Empty and
duplicate names are renamed. Each rename is an MK800 note that records it as data
(:func:`modelkit.convert.notes.renames` reads it back for round-trip comparisons). Names the writer
adds (sensor frames, ball-joint links, the world joint) avoid every name, link or joint.
"""

from __future__ import annotations

from collections.abc import Iterable

from modelkit.convert.context import WriteContext
from modelkit.model import Robot


class NameTable:
    """Written names of the robot's links and joints (by position), unique across both."""

    def __init__(self, robot: Robot, ctx: WriteContext, reserved: Iterable[str] = ()) -> None:
        self.ctx = ctx
        self.taken: set[str] = set(reserved)  # every written name, links and joints
        self.link_names: set[str] = set(reserved)
        self.joint_names: set[str] = set()
        self.links: list[str] = []
        self.joints: list[str] = []
        self.link_map: dict[str, str] = {}  # source link name → written name (its first link)
        self.joint_map: dict[str, str] = {}
        distinct = ctx.options.urdf_distinct_names
        wanted = [link.name for link in robot.links]
        for link in robot.links:
            if link.name and link.name not in self.link_names:
                name = link.name
            else:
                why = "it is empty" if not link.name else f'"{link.name}" is taken'
                name = self.fresh(link.name or "link")
                self._note("link", link.name, name, why, link.loc("name"))
            self.taken.add(name)
            self.link_names.add(name)
            self.links.append(name)
            self.link_map.setdefault(link.name, name)
        link_names = set(wanted)
        shared: list[str] = []
        for joint in robot.joints:
            if not joint.name:
                name = self.fresh(f"{self.link_map.get(joint.child, joint.child) or 'joint'}_joint")
                self._note("joint", joint.name, name, "it is empty", joint.loc("name"))
            elif distinct and joint.name in link_names:
                name = self.fresh(f"{joint.name}_joint")
                self._note(
                    "joint",
                    joint.name,
                    name,
                    "a link has the same name (libsdformat's URDF to SDF conversion refuses that)",
                    joint.loc("name"),
                )
            elif joint.name in self.joint_names:
                name = self.fresh(joint.name)
                self._note("joint", joint.name, name, f'"{joint.name}" is taken', joint.loc("name"))
            else:
                name = joint.name
                if name in link_names:
                    shared.append(name)
            self.taken.add(name)
            self.joint_names.add(name)
            self.joints.append(name)
            self.joint_map.setdefault(joint.name, name)
        if shared:
            ctx.note(
                "MK846",
                f"{len(shared)} joint(s) keep the name of a link, as in the source and as URDF and ROS "
                "allow (joint_states, robot_state_publisher): "
                + ", ".join(f'"{n}"' for n in shared[:8])
                + (f" and {len(shared) - 8} more" if len(shared) > 8 else "")
                + "; libsdformat's URDF to SDF conversion (gz sdf, spawning this URDF in Gazebo) refuses "
                "such a file: option urdf_distinct_names (--urdf-distinct-names) renames them "
                "<name>_joint, or convert to SDF",
                robot.source,
                "joint",
            )

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
