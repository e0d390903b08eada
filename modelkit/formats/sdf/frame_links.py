"""SDF ``<frame>``s made frame links for targets without them.

The SDF reader keeps each ``<frame>`` of a model as a named pose on the link it is attached to
(``link.extras["sdf_frames"]``: frame name → pose in the link's frame; a frame attached to another
frame or to a joint is resolved to the link that carries it). The SDF writer writes them back as
``<frame attached_to>``. URDF, MJCF and ``.body`` have no such element, so before their writers run,
:func:`frames_as_links` makes each frame a massless link on a fixed joint from its link, named after
the frame: a URDF link is a TF frame (what ``robot_state_publisher`` and MoveIt look up, a tool
flange, a sensor mount), the MJCF writer writes such a link as a ``<site>`` (MK873) and the
``.body`` writer as a link. One MK874 note lists them; a name a link already has gets ``_2``...
(MK800). This is the same representation an MJCF source's named-frame sites get
(:mod:`modelkit.formats.mjcf.site_frames`), so the SDF writer writes either kind back as a
``<frame>``. ``--frame-bodies`` (``WriteOptions.frame_sites=False``) makes the MJCF writer write such
links as bodies without inertial instead of sites; ``verify`` compares them as links of the source
(its reference runs this same pass), so layers 1 and 2 check where every engine puts each frame.
"""

from __future__ import annotations

from modelkit.convert.names import unique_name
from modelkit.convert.notes import NoteSink
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose

FRAMES = "sdf_frames"


def frames_as_links(robot: Robot, notes: NoteSink) -> None:
    """Each SDF frame of ``robot`` a massless link on a fixed joint (module docstring)."""
    hosts = [link for link in robot.links if link.extras.get(FRAMES)]
    if not hosts:
        return
    link_names = {link.name for link in robot.links}
    joint_names = {joint.name for joint in robot.joints}
    listed: list[str] = []
    for host in hosts:
        frames: dict[str, Pose] = host.extras.pop(FRAMES)
        for wanted, pose in frames.items():
            name = unique_name(str(wanted), link_names)
            if name != wanted:
                notes.rename("frame", str(wanted), name, "a link has the frame's name", host.source,
                             f"link[{name}]")
            joint = unique_name(f"{name}_joint", joint_names)
            robot.links.append(Link(name, source=host.source))
            robot.joints.append(Joint(joint, JointType.FIXED, host.name, name, origin=pose,
                                      source=host.source))
            listed.append(f"{name} (on {host.name})")
    notes.note(
        "MK874",
        f"{len(listed)} SDF frame(s) written as massless links on fixed joints (the target has no "
        f"<frame>; MJCF writes such links as sites): {', '.join(listed)}",
        robot.source,
        "link",
    )
