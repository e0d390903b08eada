"""``--merge-fixed``: fuse links on fixed joints into their parents.

Every link hanging on a ``fixed`` joint is fused into its parent, repeatedly, until no fixed joint
remains, except:

* the root's weld to the world is never merged: it is ``Robot.root_joint``, not a joint of the
  list; and where a reader made the world a link (URDF ``world``, SDF world joints), fixed joints
  from the ``world`` link are kept, since fusing a body into the world would remove it;
* ``pseudo_continuous_track`` joints are not fixed joints: their links keep their moving contact
  surface (``.body`` target) and are never merged. After :mod:`modelkit.convert.tracks` has run
  (other targets), a track link is an ordinary fixed visual link and is merged like any other;
  its rollers then hang from the parent and keep ``track`` naming the source track.

What fusing a child C on fixed joint J (origin X, C's frame in the parent P's frame) does:

* mass properties: C's COM and inertia are re-expressed in P's frame (``R c + t``, ``R I Rᵀ``)
  and combined with P's by :func:`modelkit.spatial.combine_mass_properties` (the parallel-axis
  theorem about the combined COM, the same helper the readers use to lump masses). A link without
  an inertial adds nothing; the result is ``defaulted`` when any part was;
* visuals, collisions and devices of C are re-posed by X and appended to P's;
* joints hanging from C hang from P, their origins composed with X (axes are in the child frame
  and unchanged); mimic relations are left untouched (a fixed joint is never a mimic leader);
* loops naming C name P, their pose in C composed with X. A loop that thereby joins a link to
  itself constrains nothing any more and is removed (said in the note);
* P keeps its own contact material; when C had another one, C's shapes take P's (said in the note).

One MK815 note per merged link.
"""

from __future__ import annotations

from modelkit.convert.notes import NoteSink
from modelkit.model import WORLD_LINK, Inertial, Joint, JointType, Robot
from modelkit.spatial import Pose, combine_mass_properties, rotate_inertia


def _mergeable(robot: Robot, joint: Joint) -> bool:
    return (joint.type is JointType.FIXED and joint.parent != WORLD_LINK and joint.child != robot.root
            and joint.parent != joint.child and robot.link(joint.parent) is not None
            and robot.link(joint.child) is not None)


def merged_inertial(parent: Inertial | None, child: Inertial | None, origin: Pose) -> Inertial | None:
    """The parent's inertial with the child's (given in the child frame at ``origin``) added."""
    if child is None:
        return parent
    rotation, offset = origin.rotation, origin.translation
    moved = (child.mass, rotation @ child.com + offset, rotate_inertia(child.inertia, rotation))
    if parent is None:
        return Inertial(moved[0], moved[1], moved[2], child.defaulted, child.source, dict(child.sources))
    mass, com, inertia = combine_mass_properties([(parent.mass, parent.com, parent.inertia), moved])
    defaulted = parent.defaulted or child.defaulted
    return Inertial(mass, com, inertia, defaulted, parent.source, dict(parent.sources))


def merge_fixed_joints(robot: Robot, notes: NoteSink) -> None:
    """Fuse every link hanging on a fixed joint into its parent (module docstring), with notes."""
    while True:
        joint = next((j for j in robot.joints if _mergeable(robot, j)), None)
        if joint is None:
            return
        _merge(robot, joint, notes)


def _merge(robot: Robot, joint: Joint, notes: NoteSink) -> None:
    parent = robot.link(joint.parent)
    child = robot.link(joint.child)
    assert parent is not None and child is not None
    origin = joint.origin
    details: list[str] = []
    parent.inertial = merged_inertial(parent.inertial, child.inertial, origin)
    for geom in [*child.visuals, *child.collisions]:
        geom.pose = origin @ geom.pose
    for device in child.devices:
        device.pose = origin @ device.pose
    if child.contact_material and child.collisions and child.contact_material != parent.contact_material:
        if parent.contact_material is None and not parent.collisions:
            parent.contact_material = child.contact_material
        else:
            details.append(f"its shapes take contact material {parent.contact_material or '(none)'} "
                           f"instead of {child.contact_material}")
    parent.visuals.extend(child.visuals)
    parent.collisions.extend(child.collisions)
    parent.devices.extend(child.devices)
    for other in robot.joints:
        if other is not joint and other.parent == child.name:
            other.parent = parent.name
            other.origin = origin @ other.origin
    for loop in list(robot.loops):
        if loop.link1 == child.name:
            loop.link1, loop.pose_in_link1 = parent.name, origin @ loop.pose_in_link1
        if loop.link2 == child.name:
            loop.link2, loop.pose_in_link2 = parent.name, origin @ loop.pose_in_link2
        if loop.link1 == loop.link2 == parent.name:
            robot.loops.remove(loop)
            details.append(f"loop {loop.name} now joins {parent.name} to itself and is removed")
    robot.joints.remove(joint)
    robot.links.remove(child)
    mass = child.inertial.mass if child.inertial is not None else 0.0
    message = (f"link {child.name} (fixed joint {joint.name}) fused into {parent.name}: "
               f"{len(child.visuals)} visual(s), {len(child.collisions)} collision(s), "
               f"{len(child.devices)} device(s) and {mass:.6g} kg moved")
    if details:
        message += "; " + "; ".join(details)
    notes.note("MK815", message, child.source or joint.source, f"link[{parent.name}]")

