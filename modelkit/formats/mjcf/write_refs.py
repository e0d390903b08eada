"""MJCF to MJCF: the names under which the source's objects were written, for what refers to them.

The source's own sensors (:mod:`.write_own`), tendons and general actuators (:mod:`.write_transmissions`)
name sites, joints, bodies, geoms, tendons, actuators and cameras of the source. Written back, they
must name the written objects, whose names may differ (MK800), and only objects written as the
source has them: a joint written as one element, a body frame where the source's was, a site that is
not a device's own small sphere when its shape matters.
"""

from __future__ import annotations

from dataclasses import dataclass

from modelkit.formats.mjcf.write_bodies import BodyTree
from modelkit.formats.mjcf.write_devices import DeviceWriter
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.model import Robot
from modelkit.spatial import Pose


@dataclass
class WrittenObjects:
    """Looks up the written name of a source object."""

    robot: Robot
    names: NameTable
    tree: BodyTree
    devices: DeviceWriter

    def object(self, objtype: str, name: str, shaped: bool = False) -> str | None:
        """The written name of a source object of MuJoCo type ``objtype``, or ``None`` when it is not
        written as the source has it. ``shaped``: the site's own shape matters (a touch sensor's volume),
        so a device's site in its place will not do."""
        if objtype == "site":
            if name in self.devices.site_for:
                return None if shaped else self.devices.site_for[name]
            return self.names.written("site", name)
        if objtype == "joint":
            written = self.tree.joint_names.get(name, [])
            return written[0] if len(written) == 1 else None
        if objtype == "body":
            return self.body(name)
        if objtype == "xbody":  # the body's own frame: only where the body is written at it
            return self.body(name) if self.at_source_frame(name) else None
        if objtype == "geom":  # its collision and visual copies share its pose: the first will do
            return self.names.written("geom", name, first=True)
        if objtype in ("actuator", "camera", "tendon"):
            return self.names.written(objtype, name)
        return None

    def scalar_joint(self, name: str) -> str | None:
        """The written name of a source joint written as one hinge or slide, or ``None``."""
        written = self.object("joint", name)
        return written if written is not None and written in self.tree.scalar_joints else None

    def at_source_frame(self, name: str) -> bool:
        """Whether the body of link ``name`` is written at the MuJoCo body's frame: the link frame sits
        in the written body where the reader found it in the source body (``mjcf_body_offset``; a chain
        body is written back at its source frame, :mod:`.write_chains`)."""
        link = self.robot.link(name)
        if link is None:
            return False
        offset = [float(x) for x in link.extras.get("mjcf_body_offset") or (0.0, 0.0, 0.0)]
        return (Pose(translation=offset).inverse() @ self.tree.frame(name)).is_identity()

    def source_frame(self, name: str) -> Pose | None:
        """The MuJoCo source body's frame of link ``name`` in its written body (None: not written)."""
        link = self.robot.link(name)
        if link is None or name not in self.tree.bodies:
            return None
        offset = [float(x) for x in link.extras.get("mjcf_body_offset") or (0.0, 0.0, 0.0)]
        return self.tree.frame(name) @ Pose(translation=offset).inverse()

    def body(self, link: str) -> str | None:
        return self.tree.body_name.get(link) if link in self.tree.bodies else None
