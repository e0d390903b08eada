"""How the robot's root meets the world in the output: welded (fixed) or free (floating).

Settled once here, before any writer runs, so every target carries the same answer (MJCF: a body
without joint or ``<freejoint/>``; SDF: a joint to ``world`` or a free model; URDF: a ``world`` link
with a fixed joint, or no ``world`` link; .body: ``jointType: fixed|free``).

* The source's own answer wins (Choreonoid's root ``jointType``, an SDF world joint or free model, an
  MJCF root body with or without a free joint, a URDF ``world`` link) unless the user asks otherwise
  with ``--base fixed|floating``; then an MK831 note says the source's answer was overridden.
* Where the source is silent (a URDF without ``world``: ``Robot.root_joint is None``), ``--base`` decides;
  ``auto`` floats a robot that moves itself and welds the others (MK830 says which and why):

  - wheels: at least two revolute joints without a range (a wheel turns without end: iCub's ankle,
    round about its pitch axis, is no wheel) with a horizontal axis whose child's shapes touch the lowest
    level with a round section about that axis (a cylinder or sphere on the axis, or any shape whose
    extents across the axis are equal within 10 % and centred on it): floating, also when a shape of
    the root's own body touches too (a caster ball or skid fixed to the base, as on most
    differential-drive robots: the tutorial's robot written to URDF came back welded);
  - rotors: at least two revolute joints without a range about a vertical axis, each turning a leaf
    link clear of the ground whose shapes are round about the axis and flat along it (at most half
    their radius thick: propeller discs): floating, a multirotor flies (bullet-safety-gym's quadcopter
    was welded by the next rule, its body box resting on the ground);
  - otherwise a robot whose root's own rigid body (the root and what is fixed to it) touches the
    lowest level rests on its base: welded (arms, fixtures);
  - legs: at least two branches whose shapes touch the lowest level through two or more moving
    joints each, parting from each other with at least two moving joints on each side (two legs from
    the root; or from a waist, each then with at least as many joints as the waist and starting below
    the root's frame): floating; unless every such branch ends in a link named as a finger
    (``finger``, ``thumb``): a hand or a platform resting on its fingertips (TriFinger, whose
    fingers hang from its frame to the table's level at q = 0) is welded;
  - legs that do not reach the ground at q = 0 (folded or sideways, as some quadrupeds are modelled):
    four or more limbs of two or more moving joints in a row hanging from the root's rigid body (four
    legs, or two legs and two arms; an arm has one, a dual-arm torso two or three) that start around
    the body's centre of mass: floating. A limb that points up at q = 0 (its links rise above its
    first joint by more than half its reach, as a hand's fingers do) is not a leg: a hand on its palm
    is welded, not floated; so is a hand whose fingers lie level with the palm (they start at one end
    of it);
  - a robot without moving joints (an object: a cube, a mug) floats, as URDF's convention has it;
  - a robot without mass is welded (it cannot float in a simulator); one without any shape floats
    (nothing to judge by: URDF's own convention, so a URDF round trip keeps a floating root).

"The lowest level" is the lowest point of the collision shapes (visual shapes when the robot has no
collision shape) at q = 0, and "touches" means within 2 % of the robot's height (at least 1 mm).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from modelkit.convert.moving_paths import MovingPaths
from modelkit.convert.notes import NoteSink
from modelkit.geometry.extents import across, extent
from modelkit.model import WORLD_LINK, Cylinder, Geom, Joint, JointType, Robot, Sphere
from modelkit.spatial import Pose

BASE_CHOICES = ("auto", "fixed", "floating")
# The name of a link that ends a finger: limbs resting on such links are a hand's, not legs (TriFinger)
_FINGER = re.compile("finger|thumb", re.IGNORECASE)
LIMBS = 4  # limbs of ≥ 2 moving joints from the root's body that make a robot legged (4 legs, or 2 + 2 arms)
_UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class BaseDecision:
    """What ``auto`` found for a source that leaves the root open."""

    kind: JointType  # FIXED or FLOATING
    reason: str



def touching_ground(lows: dict[str, tuple[float, float]]) -> set[str]:
    """The links (of :func:`vertical_spans`) whose shapes reach the lowest level: within 2 % of the
    robot's height, at least 1 mm."""
    if not lows:
        return set()
    ground = min(low for low, _ in lows.values())
    tolerance = max(1e-3, 0.02 * (max(high for _, high in lows.values()) - ground))
    return {name for name, (low, _) in lows.items() if low - ground <= tolerance}


def root_body(robot: Robot) -> list[str]:
    """The root's rigid body: the root link and every link hanging from it by fixed joints."""
    children = robot.children_of()
    body, stack = [], [robot.root or ""]
    while stack:
        name = stack.pop()
        body.append(name)
        stack.extend(joint.child for joint in children.get(name, []) if not joint.type.moves)
    return body


def vertical_spans(robot: Robot, poses: dict[str, Pose]) -> dict[str, tuple[float, float]]:
    """Link name → the lowest and highest world height of its collision shapes (its visuals when the
    robot has no collision shape at all), at ``poses``; links without shapes or pose are absent."""
    use_collisions = any(link.collisions for link in robot.links)
    spans: dict[str, tuple[float, float]] = {}
    for link in robot.links:
        geoms = link.collisions if use_collisions else link.visuals
        pose = poses.get(link.name)
        if pose is None or not geoms:
            continue
        span = extent(geoms, pose.rotation.T @ _UP)
        if span is not None:
            z = float(pose.translation[2])
            spans[link.name] = (z + span[0], z + span[1])
    return spans


def settle_base(robot: Robot, choice: str, notes: NoteSink) -> None:
    """Set ``robot.root_joint`` (and the joints from a ``world`` root) to the base the output gets."""
    if choice not in BASE_CHOICES:
        raise ValueError(f"base must be one of {', '.join(BASE_CHOICES)}, not {choice!r}")
    if robot.root is None:
        return
    if robot.root == WORLD_LINK:
        absorb_world_weld(robot)
    where = robot.root_joint_source or robot.source
    if robot.root == WORLD_LINK:
        _settle_world_root(robot, choice, notes)
        return
    if robot.root_joint is not None:
        asked = _asked(choice)
        if asked is not None and asked is not robot.root_joint:
            notes.note("MK831", f'the source {_word(robot.root_joint)} the root "{robot.root}"; written '
                       f"{_past(asked)} as asked (--base {choice})", where, f"link[{robot.root}]")
            robot.root_joint = asked
        return
    asked = _asked(choice)
    if asked is not None:
        robot.root_joint = asked
        notes.note("MK830", f'the source leaves the root "{robot.root}" open; it is {_past(asked)} '
                   f"as asked (--base {choice})", where, f"link[{robot.root}]")
        return
    decision = decide(robot)
    robot.root_joint = decision.kind
    how = _past(decision.kind)
    notes.note("MK830", f'the source leaves the root "{robot.root}" open; --base auto: {how}: '
               f"{decision.reason}", where, f"link[{robot.root}]")


def absorb_world_weld(robot: Robot) -> None:
    """An empty ``world`` link with one fixed joint to the robot (a URDF's way of welding it) is the
    root welded at that joint's origin; the joint's name is kept (``root_joint_name``) for the
    targets that write the weld as a joint (URDF, SDF)."""
    world = robot.link(WORLD_LINK)
    hanging = [joint for joint in robot.joints if joint.parent == WORLD_LINK]
    if (
        world is None
        or world.visuals or world.collisions or world.devices
        or (world.inertial is not None and world.inertial.mass > 0.0)
        or len(hanging) != 1
        or hanging[0].type is not JointType.FIXED
        or any(j.child == WORLD_LINK for j in robot.joints)
        or any(WORLD_LINK in (loop.link1, loop.link2) for loop in robot.loops)
    ):
        return
    weld = hanging[0]
    robot.links.remove(world)
    robot.joints.remove(weld)
    robot.root, robot.root_joint = weld.child, JointType.FIXED
    robot.root_pose = robot.root_pose @ weld.origin
    robot.root_joint_name = weld.name
    if weld.source is not None:
        robot.root_joint_source = weld.source


def _asked(choice: str) -> JointType | None:
    return {"fixed": JointType.FIXED, "floating": JointType.FLOATING}.get(choice)


def _word(kind: JointType) -> str:
    return "welds" if kind is JointType.FIXED else "floats"


def _past(kind: JointType) -> str:
    return "welded" if kind is JointType.FIXED else "floating"


def _settle_world_root(robot: Robot, choice: str, notes: NoteSink) -> None:
    """A ``world`` root link: the joints that hang from it carry the base (fixed or floating)."""
    asked = _asked(choice)
    if asked is None:
        return
    for joint in robot.joints:
        if joint.parent != WORLD_LINK or joint.type not in (JointType.FIXED, JointType.FLOATING):
            continue
        if joint.type is not asked:
            notes.note("MK831", f'the source {_word(joint.type)} "{joint.child}" to the world by the joint '
                       f'"{joint.name}"; written {_past(asked)} as asked (--base {choice})',
                       joint.source, f"joint[{joint.name}]")
            joint.type = asked


# ---- auto ------------------------------------------------------------------------------------


def decide(robot: Robot) -> BaseDecision:
    """Float a robot that moves itself (wheels, legs), weld the others (see the module docstring)."""
    if robot.total_mass() <= 0.0:
        return BaseDecision(JointType.FIXED, "the robot has no mass to float")
    if not any(joint.type.moves for joint in robot.joints):
        return BaseDecision(JointType.FLOATING, "it has no moving joint (an object), so URDF's own "
                            "convention (a root that does not hang from `world` floats)")
    poses = robot.world_poses()
    every_limb = _limbs(robot)
    raised_limbs = _raised(robot, poses, every_limb)
    limbs = [name for name in every_limb if name not in raised_limbs]
    raised = len(every_limb) - len(limbs)
    use_collisions = any(link.collisions for link in robot.links)
    lows = vertical_spans(robot, poses)
    if not lows:
        return BaseDecision(JointType.FLOATING, "it has no shape to judge by, so URDF's own convention "
                            "(a root that does not hang from `world` floats)")
    touching = touching_ground(lows)
    paths = MovingPaths(robot)
    on_base = any(paths.length(name) == 0 for name in touching)  # the root's rigid body touches
    # Wheels first: a differential-drive robot's caster is often a shape of the root's own body that
    # touches the ground (a fixed ball or skid), and the robot still drives.
    wheels = _wheels(robot, poses, touching, use_collisions)
    if len(wheels) >= 2:
        shown = ", ".join(f'"{j.name}"' for j in wheels[:4]) + (" ..." if len(wheels) > 4 else "")
        caster = " beside a caster of the root's own body" if on_base else ""
        return BaseDecision(JointType.FLOATING, f"it drives on wheels (joint(s) {shown}: a round shape "
                            f"on a horizontal axis touching the ground{caster})")
    rotors = _rotors(robot, poses, touching, use_collisions)
    if len(rotors) >= 2:
        shown = ", ".join(f'"{j.name}"' for j in rotors[:8]) + (" ..." if len(rotors) > 8 else "")
        return BaseDecision(JointType.FLOATING, f"it flies on {len(rotors)} rotors (joint(s) {shown}: a flat "
                            "round shape turning without end about a vertical axis, clear of the ground)")
    if on_base:
        return _by_limbs(robot, poses, limbs, "the root's own body rests on the ground (an arm or a fixture"
                         + (f"; {raised} limb(s) point up, as a hand's fingers do" if raised else "") + ")")
    feet = _feet(paths, sorted(touching), _below_root(robot, poses))
    if len(feet) >= 2 and all(_FINGER.search(name) for name in feet):
        shown = ", ".join(f'"{name}"' for name in feet[:6])
        return BaseDecision(JointType.FIXED, f"its {len(feet)} limbs that touch the ground end in links "
                            f"named as fingers ({shown}): a hand or a manipulation platform resting on its "
                            "fingertips, not a legged robot")
    if len(feet) >= 2:
        shown = ", ".join(f'"{name}"' for name in feet[:6])
        return BaseDecision(JointType.FLOATING, f"it stands on {len(feet)} legs (feet {shown} touch the "
                            "ground, the root's body does not)")
    return _by_limbs(robot, poses, limbs, "no wheels or legs touch the ground (an arm or a fixture)")


def _by_limbs(robot: Robot, poses: dict[str, Pose], limbs: list[str], otherwise: str) -> BaseDecision:
    """Legs that do not reach the ground at q = 0 (folded, or sideways): four or more limbs that start
    around the body's centre of mass (:func:`_around_body`); a hand's fingers start at one end of it."""
    if len(limbs) < LIMBS:
        return BaseDecision(JointType.FIXED, otherwise)
    shown = ", ".join(f'"{name}"' for name in limbs[:6])
    if not _around_body(robot, poses, limbs):
        return BaseDecision(JointType.FIXED, f"its {len(limbs)} limbs of two or more moving joints (first "
                            f"joints {shown}) start at one end of its body, as a hand's fingers do, not "
                            "around its centre of mass as legs do (an arm's end or a fixture)")
    return BaseDecision(JointType.FLOATING, f"it has {len(limbs)} limbs of two or more moving joints "
                        f"each from its body (first joints {shown}): a legged robot")


LIMBS_AROUND = 0.25  # of their spread: how far the limbs' first joints' centroid may be from the body's COM


def _around_body(robot: Robot, poses: dict[str, Pose], limbs: list[str]) -> bool:
    """Whether the limbs' first joints lie around the root body's centre of mass (the root and what is
    fixed to it; the root's frame when that body has no mass): their centroid within
    :data:`LIMBS_AROUND` of their spread from it. A quadruped's hips: 0.00 (vision60, Spirit 40 with
    legs sideways or folded); the fingers of fourier-robot-descriptions' and Inspire's hands: 0.49 to
    2.5 (hands modelled pointing sideways, whose fingers do not point up at q = 0)."""
    by_name = {joint.name: joint for joint in robot.joints}
    firsts = np.array([poses[by_name[name].child].translation for name in limbs
                       if by_name[name].child in poses])
    if len(firsts) == 0 or robot.root not in poses:
        return True
    links = {link.name: link for link in robot.links}
    mass, moment = 0.0, np.zeros(3)
    for name in root_body(robot):
        link = links.get(name)
        if link is not None and link.inertial is not None and name in poses and link.inertial.mass > 0.0:
            pose = poses[name]
            com = np.asarray(pose.rotation) @ np.asarray(link.inertial.com) + np.asarray(pose.translation)
            mass += float(link.inertial.mass)
            moment += float(link.inertial.mass) * com
    centre = moment / mass if mass > 0.0 else np.asarray(poses[robot.root].translation, dtype=float)
    centroid = firsts.mean(axis=0)
    spread = float(np.max(np.linalg.norm(firsts - centroid, axis=1)))
    return spread <= 0.0 or float(np.linalg.norm(centroid - centre)) <= LIMBS_AROUND * spread


def _limbs(robot: Robot) -> list[str]:
    """The first moving joints below the root's rigid body whose subtree holds ≥ 2 moving joints in a row."""
    children = robot.children_of()
    starts = [joint for name in root_body(robot) for joint in children.get(name, []) if joint.type.moves]
    return sorted(joint.name for joint in starts if _depth(children, joint.child) >= 1)


def _raised(robot: Robot, poses: dict[str, Pose], first_joints: list[str]) -> set[str]:
    """The limbs (by first joint) that rise at q = 0: the highest of the limb's link frames is above the
    first joint's frame by more than half the farthest one's distance from it (a hand's raised finger)."""
    children = robot.children_of()
    by_name = {joint.name: joint for joint in robot.joints}
    return {name for name in first_joints if name in by_name and _points_up(children, poses, by_name[name])}


def _points_up(children: dict[str, list[Joint]], poses: dict[str, Pose], joint: Joint) -> bool:
    """Whether the limb below ``joint`` rises at q = 0 (:func:`_raised`)."""
    start = poses.get(joint.child)
    if start is None:
        return False
    origin = np.asarray(start.translation, dtype=float)
    rise = reach = 0.0
    stack, seen = [joint.child], set()
    while stack:
        name = stack.pop()
        if name in seen or name not in poses:
            continue
        seen.add(name)
        stack.extend(j.child for j in children.get(name, []))
        offset = np.asarray(poses[name].translation, dtype=float) - origin
        rise = max(rise, float(offset @ _UP))
        reach = max(reach, float(np.linalg.norm(offset)))
    return reach > 0.0 and rise > 0.5 * reach


def _depth(children: dict[str, list[Joint]], link: str) -> int:
    """The most moving joints on a path down from ``link``."""
    best: dict[str, int] = {}
    order: list[str] = []
    stack = [link]
    while stack:
        name = stack.pop()
        if name in best:
            continue
        best[name] = 0
        order.append(name)
        stack.extend(j.child for j in children.get(name, []))
    for name in reversed(order):
        best[name] = max((best.get(j.child, 0) + (1 if j.type.moves else 0) for j in children.get(name, [])),
                         default=0)
    return best[link]


def _wheels(robot: Robot, poses: dict[str, Pose], touching: set[str], use_collisions: bool) -> list[Joint]:
    out: list[Joint] = []
    links = {link.name: link for link in robot.links}
    for joint in robot.joints:
        if (joint.type is not JointType.REVOLUTE or not joint.limits.endless
                or joint.child not in touching or joint.child not in poses):
            continue  # a wheel turns without end, as the writers' wheels (convert.wheels, legs.is_wheel) do
        link = links[joint.child]
        axis = np.asarray(joint.axis, dtype=float)
        norm = float(np.linalg.norm(axis))
        if norm == 0.0:
            continue
        axis = axis / norm  # in the child frame
        world_axis = poses[joint.child].rotation @ axis
        if abs(float(world_axis[2])) > 0.2:
            continue
        geoms = link.collisions if use_collisions else link.visuals
        if any(_round_about(geom, axis) for geom in geoms):
            out.append(joint)
    return out


ROTOR_FLATNESS = 0.5  # a rotor's shapes are at most this much of their radius thick along the axis


def _rotors(robot: Robot, poses: dict[str, Pose], touching: set[str], use_collisions: bool) -> list[Joint]:
    """A multirotor's rotors: revolute joints without a range about a vertical axis whose child is a leaf
    (no joint below it moves) clear of the ground, with a shape round about the axis and flat along it
    (a propeller's disc: bullet-safety-gym's quadcopter, 0.005 m thick, 0.14 m in radius). A turntable
    or a wrist turning without end has a thick or non-round link, or links below it that move."""
    out: list[Joint] = []
    links = {link.name: link for link in robot.links}
    children = robot.children_of()
    for joint in robot.joints:
        if (joint.type is not JointType.REVOLUTE or not joint.limits.endless or joint.mimic is not None
                or joint.child in touching or joint.child not in poses
                or any(j.type.moves for j in children.get(joint.child, []))):
            continue
        axis = np.asarray(joint.axis, dtype=float)
        norm = float(np.linalg.norm(axis))
        if norm == 0.0:
            continue
        axis = axis / norm  # in the child frame
        if abs(float((poses[joint.child].rotation @ axis)[2])) < 1.0 - 1e-6:
            continue
        geoms = links[joint.child].collisions if use_collisions else links[joint.child].visuals
        if geoms and all(_round_about(geom, axis) and _flat_along(geom, axis) for geom in geoms):
            out.append(joint)
    return out


def _flat_along(geom: Geom, axis: np.ndarray) -> bool:
    """Whether the shape is at most :data:`ROTOR_FLATNESS` of its reach across ``axis`` thick along it."""
    along = extent([geom], axis)
    across_span = extent([geom], across(axis)[0])
    if along is None or across_span is None:
        return False
    radius = (across_span[1] - across_span[0]) / 2
    return bool(radius > 0.0 and along[1] - along[0] <= ROTOR_FLATNESS * radius)


def _round_about(geom: Geom, axis: np.ndarray) -> bool:
    """Whether the shape's section across ``axis`` (child frame, through the origin) is a disc about it."""
    offset = np.asarray(geom.pose.translation, dtype=float)
    off_axis = offset - axis * float(axis @ offset)
    if isinstance(geom.geometry, Sphere):
        return bool(np.linalg.norm(off_axis) <= 0.1 * geom.geometry.radius)
    if isinstance(geom.geometry, Cylinder):
        along = geom.pose.rotation @ _UP
        near = np.linalg.norm(off_axis) <= 0.1 * geom.geometry.radius
        return bool(abs(float(along @ axis)) > 0.95 and near)
    side = np.cross(axis, _UP if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0]))
    side = side / np.linalg.norm(side)
    other = np.cross(axis, side)
    spans = [extent([geom], d) for d in (side, other)]
    if spans[0] is None or spans[1] is None:
        return False
    widths = [hi - lo for lo, hi in spans]  # type: ignore[misc]
    centres = [(hi + lo) / 2 for lo, hi in spans]  # type: ignore[misc]
    radius = max(widths) / 2
    return bool(radius > 0.0 and min(widths) >= 0.9 * max(widths)
                and max(abs(c) for c in centres) <= 0.1 * radius)


def _below_root(robot: Robot, poses: dict[str, Pose]) -> set[str]:
    """The moving and fixed joints whose frames are lower than the root's at q = 0 (:func:`_feet`)."""
    root_z = float(poses[robot.root].translation[2]) if robot.root in poses else 0.0
    return {j.name for j in robot.joints
            if j.child in poses and float(poses[j.child].translation[2]) < root_z}


def _feet(paths: MovingPaths, touching: list[str], below_root: set[str]) -> list[str]:
    """One touching link per leg among those that reach the ground through ≥ 2 moving joints (in the order
    of the legs' first joints, then of link names). Two such links are on different legs where their
    paths from the root part with at least two moving joints on each side; where the paths share
    joints (legs from a waist), each side must have at least as many as they share and start below
    the root's frame (``below_root``: the moving joints whose frames are lower). OpenLoong's
    torso-rooted humanoid parts so (3 waist joints, then 6 in each leg, hips 0.17 m below the torso's
    frame); a foot's heel and toe do not (one joint apart), nor an arm's two fingers (7 arm joints
    shared), nor Alex's arms hanging beside its pelvis (their shoulders 0.43 m above it).

    Paths with different first joints share nothing and each has ≥ 2 joints: they are always apart, so a
    link is compared only with the feet found under its own first joint."""
    candidates = [name for name in touching if paths.length(name) >= 2]
    first = {name: paths.at(name, 0) for name in candidates}
    feet: list[str] = []
    under: dict[str, list[str]] = {}  # first joint → the feet found below it
    for name in sorted(candidates, key=lambda each: (first[each], each)):
        siblings = under.setdefault(first[name], [])
        if all(_apart(paths, name, other, below_root) for other in siblings):
            siblings.append(name)
            feet.append(name)
    return feet


def _apart(paths: MovingPaths, one: str, two: str, below_root: set[str]) -> bool:
    """Whether two touching links' paths of moving joints are on different legs (:func:`_feet`)."""
    shared = paths.shared(one, two)
    rest = min(paths.length(one), paths.length(two)) - shared
    if shared == 0:
        return rest >= 2
    return (rest >= max(2, shared) and paths.at(one, shared) in below_root
            and paths.at(two, shared) in below_root)
