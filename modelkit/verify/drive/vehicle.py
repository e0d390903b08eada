"""What the controllers and references need to know about a mobile robot, found in its model.

:func:`find_drive` returns a :class:`~modelkit.verify.drive.Drive` or raises ``ValueError`` with one
sentence saying why the model is not a two-sided wheeled or tracked robot (layer 4 then becomes a
Skip). Everything is measured in the root link's frame at q = 0:

* **wheels**: the two unlimited revolute joints whose child link has a round collision (a cylinder
  whose axis lies along the joint axis, a sphere, or a mesh whose extent around the axis is round,
  read from its file when the model holds only the path: Hello Robot's Stretch), axes parallel to
  the root's Y, hanging from the root's rigid body (not from a steering joint or a leg), one on each
  side (mirrored in Y); caster wheels (round, about Y at q = 0, but hanging from a swivel joint, as
  TIAGo's four) are left out when more than two are found; :func:`supported` then says when nothing
  but the wheels reaches the floor (the robot would tip over), :func:`drivable` when the scenario's
  wheel law cannot turn them, and :func:`caster_drag` when casters slide with friction (the no-slip
  reference has none).
  Left is the one at +Y. The radius comes from the collision (cylinder or sphere radius, half the
  mesh's extent across the axis); the half axle width b is half the distance between the two
  collision centres along Y. ``signs``: +1 when the joint axis points along +Y (a positive rotation
  then rolls the wheel forward, towards +X), −1 when it points along −Y. The scenario may name the
  joints and give the radius and b instead.
* **tracks** (Choreonoid's ``PSEUDO_CONTINUOUS_TRACK`` joints): the two track joints, one on each
  side; ``rollers`` and ``roller_radius`` come from the track approximation every writer makes
  (``prepared.extras["tracks"]``, see :mod:`modelkit.convert.tracks`); ``track_offset_y`` is the
  left track joint's origin y in the root frame (the seed's ``trackUnits[0]->offsetTranslation().y()``).
* **pan / tilt**: named in the scenario, else found by name (a revolute joint whose name contains
  "pan" or "tilt"), else by axis (pan: a vertical revolute joint hanging from the root; tilt: a
  horizontal revolute joint hanging from the pan's child link).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from modelkit.checks.masses import subtree
from modelkit.convert.base import root_body, touching_ground, vertical_spans
from modelkit.geometry.extents import ROUNDNESS, mesh_vertices, round_about
from modelkit.model import Geom, Joint, JointType, Link, Mesh, Robot
from modelkit.spatial import Pose
from modelkit.verify.drive import Drive, Scenario

PARALLEL = 1e-6  # |1 − |cos|| below this: two directions are parallel
MIRROR = 1e-3  # m: the two sides must agree this well in x and z (and in |y|)


def find_drive(robot: Robot, scenario: Scenario, prepared: Robot | None = None) -> Drive:
    """The drive of ``robot`` (source names); ``prepared``: the robot after ``convert``'s prepare (its
    track approximation), computed here when a tracked robot comes without it."""
    if robot.root is None:
        raise ValueError("the model has no root link")
    poses = robot.world_poses()
    root_inv = poses[robot.root].inverse()
    frames = {name: root_inv @ pose for name, pose in poses.items()}
    tracks = [j for j in robot.joints if j.type is JointType.PSEUDO_CONTINUOUS_TRACK]
    named = {scenario.left, scenario.right} - {None}
    if tracks and (not named or named <= {j.name for j in tracks}):
        drive = _tracks(robot, scenario, tracks, frames, prepared)
    else:
        drive = _wheels(robot, scenario, frames)
    pan, tilt = _pan_tilt(robot, scenario, frames, {drive.left, drive.right})
    return dataclasses.replace(drive, pan=pan, tilt=tilt)


# ----------------------------------------------------------------------------------------------------
# wheels


def _axis_in_root(joint: Joint, frames: dict[str, Pose]) -> np.ndarray:
    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return axis
    return np.asarray(frames[joint.child].rotation @ (axis / norm))


def _joints_above(robot: Robot, joint: Joint, body: set[str]) -> list[Joint]:
    """The moving joints between the root's rigid body and ``joint``'s parent link, lowest first."""
    parent_of = {j.child: j for j in robot.joints}
    out: list[Joint] = []
    link = joint.parent
    for _ in range(len(robot.joints)):  # a walk up a tree: at most one step per joint
        above = parent_of.get(link)
        if link in body or above is None:
            break
        if above.type.moves:
            out.append(above)
        link = above.parent
    return out


def _turned_above(robot: Robot, joint: Joint, body: set[str]) -> bool:
    """Whether a joint that turns (not a suspension's slide) lies between the root's body and ``joint``."""
    return any(j.type is not JointType.PRISMATIC for j in _joints_above(robot, joint, body))


def _swivels(robot: Robot, joint: Joint, body: set[str], frames: dict[str, Pose]) -> bool:
    """A caster wheel: it hangs from a joint turning without end about the vertical (TIAGo's four)."""
    return any(j.type is JointType.REVOLUTE and not j.limits.position_limited
               and _parallel(_axis_in_root(j, frames), (0.0, 0.0, 1.0))
               for j in _joints_above(robot, joint, body))


def _parallel(a: np.ndarray, b: np.ndarray | Sequence[float]) -> bool:
    return bool(abs(1.0 - abs(float(np.dot(a, b)))) < PARALLEL)


def wheel_shape(link: Link, axis_local: np.ndarray) -> tuple[float, np.ndarray] | None:
    """(radius, centre in the link frame) of the link's round collision about ``axis_local`` (unit,
    link frame), or None when it has none: the largest cylinder along the axis, or sphere; a mesh
    whose vertices are round about the axis (extent across it equal in both directions to 2 %)."""
    best: tuple[float, np.ndarray] | None = None
    for geom in link.collisions:
        found = _round(geom, axis_local)
        if found is not None and (best is None or found[0] > best[0]):
            best = found
    return best


def _round(geom: Geom, axis: np.ndarray) -> tuple[float, np.ndarray] | None:
    found = round_about(geom, axis, PARALLEL)
    return None if found is None else (found.radius, found.centre)


def supported(robot: Robot, drive: Drive) -> str | None:
    """Why the wheeled robot cannot stand for a drive (None when it can): at q = 0 a shape other than
    the two wheels (and what hangs from them) must reach the floor with them (``base.touching_ground``:
    a caster, a skid), or the robot tips over on its axle and the driven comparison would grade its
    fall. The tutorial's ``mobile_robot_mesh.body`` and ``mobile_robot_sensors.urdf`` name a chassis
    mesh that is not shipped: they stand on their wheels alone."""
    if drive.kind != "wheels":
        return None
    spans = vertical_spans(robot, robot.world_poses())
    children = robot.children_of()
    wheels = {name for link in drive.wheel_links for name in subtree(children, link)}
    if touching_ground(spans) - wheels:
        return None
    unread = sorted({link.name for link in robot.links for geom in link.collisions
                     if isinstance(geom.geometry, Mesh) and mesh_vertices(geom.geometry) is None})
    why = (f" (the collision mesh of {', '.join(unread)} cannot be read)" if unread else "")
    return (f"the robot stands on its two wheels alone: no collision shape but the wheels reaches the floor "
            f"at q = 0{why}, so it tips over on its axle and a driven comparison would grade its fall")


def drivable(robot: Robot, drive: Drive, scenario: Scenario) -> str | None:
    """Why the scenario's wheel law cannot drive these wheels (None when it can): ``u = kd (dq* − dq)``
    against the wheel joints' damping c and Coulomb friction f settles at ``dq = (kd dq* − f) / (kd +
    c)``; below half the target speed at the scenario's fastest wheel target, the driven comparison
    would grade a robot that barely moves. Hello Robot's Stretch: c 21.75 N·m·s, f 10.48 N·m against
    the seed's kd 0.5 (its wheels do not turn)."""
    if drive.kind != "wheels" or scenario.controller not in (None, "drive"):
        return None
    joints = {j.name: j for j in robot.joints}
    fastest = max((max(abs(c.v - c.w * drive.half_axle), abs(c.v + c.w * drive.half_axle)) / drive.radius
                   for profile in scenario.profiles if profile.graded for c in profile.commands), default=0.0)
    if fastest <= 0.0:
        return None
    kd = scenario.kd
    for name in (drive.left, drive.right):
        joint = joints.get(name)
        if joint is None:
            continue
        c, f = max(joint.damping, 0.0), max(joint.friction, 0.0)
        settled = (kd * fastest - f) / (kd + c)
        if settled < 0.5 * fastest:
            return (f"the drive law u = kd (dq* - dq), kd {kd:g}, cannot drive wheel joint {name}: against "
                    f"its damping {c:g} N·m·s and friction {f:g} N·m it settles at "
                    f"{max(settled, 0.0) / fastest:.0%} of the {fastest:.3g} rad/s target (give a scenario "
                    "kd for this robot)")
    return None


def caster_drag(robot: Robot, drive: Drive) -> str | None:
    """Why the no-slip reference cannot stand for a robot on swivel casters (None when it can): the
    reference has no casters, and a caster whose contact slides with friction while it swivels drags
    the robot and loads its wheels differently under the drive law. Measured on example-robot-data's
    TIAGo dual (four casters, the source's friction 0.1): MuJoCo's heading ended 55 mrad of 5 rad from
    the reference on the spin; with the casters' friction set to 0 in the source, 0.45 mrad. Casters
    whose every collision shape has a friction of 0 are driven and graded."""
    if not drive.casters:
        return None
    joints = {j.name: j for j in robot.joints}
    links = {link.name: link for link in robot.links}
    sliding: dict[str, str] = {}
    for name in drive.casters:
        joint = joints.get(name)
        link = links.get(joint.child) if joint is not None else None
        if link is None:
            continue
        found = {("the engine's default" if g.friction is None else f"{g.friction.sliding:g}")
                 for g in link.collisions if g.friction is None or g.friction.sliding != 0.0}
        if found:
            sliding[name] = " and ".join(sorted(found))
    if not sliding:
        return None
    shown = ", ".join(f"{name} ({mu})" for name, mu in sorted(sliding.items()))
    return (f"the robot stands on {len(drive.casters)} swivel caster(s) whose contact slides with friction "
            f"while they swivel ({shown}), and the rigid no-slip reference has no casters: their drag "
            "turns the wheels differently under the drive law, so a driven comparison would grade the "
            "reference's omission (example-robot-data's TIAGo dual: MuJoCo's heading 55 mrad from the "
            "reference after a 5 rad spin; 0.45 mrad with frictionless casters)")


def _spinners(robot: Robot, frames: dict[str, Pose], direction: tuple[float, float, float]) -> list[Joint]:
    """The unlimited revolute joints (not mimics) about ``direction`` (root frame) whose child link
    has a collision round about the axis."""
    links = {link.name: link for link in robot.links}
    out = []
    for j in robot.joints:
        if (j.type is not JointType.REVOLUTE or j.limits.position_limited or j.mimic is not None
                or j.child not in links):
            continue
        axis = _axis_in_root(j, frames)
        if _parallel(axis, direction) and wheel_shape(links[j.child], frames[j.child].rotation.T @ axis):
            out.append(j)
    return out


def _heading(robot: Robot, scenario: Scenario, frames: dict[str, Pose]) -> float:
    """:attr:`Drive.heading`: π/2 when the wheels turn about the root's X (the scenario's, else the
    only round wheels found, at least two, with none about Y), else 0."""
    x_axis = (1.0, 0.0, 0.0)
    if scenario.left is not None:
        joint = next((j for j in robot.joints if j.name == scenario.left), None)
        if joint is None or joint.child not in frames:
            return 0.0
        return math.pi / 2 if _parallel(_axis_in_root(joint, frames), x_axis) else 0.0
    if _spinners(robot, frames, (0.0, 1.0, 0.0)) or len(_spinners(robot, frames, x_axis)) < 2:
        return 0.0
    return math.pi / 2


def _turned(frames: dict[str, Pose], heading: float) -> dict[str, Pose]:
    """``frames`` (root frame) in the drive frame: the root frame turned by ``heading`` about Z."""
    c, s = math.cos(heading), math.sin(heading)
    turn = Pose(np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]), np.zeros(3))
    return {name: turn @ pose for name, pose in frames.items()}


def _wheels(robot: Robot, scenario: Scenario, frames: dict[str, Pose]) -> Drive:
    links = {link.name: link for link in robot.links}
    joints = {j.name: j for j in robot.joints}
    named = [scenario.left, scenario.right]
    heading = _heading(robot, scenario, frames)
    if heading:
        frames = _turned(frames, heading)
    if any(n is not None for n in named):
        if None in named:
            raise ValueError("the scenario names only one wheel joint: give both robot.left and robot.right")
        for n in named:
            if n not in joints:
                raise ValueError(f"the scenario's wheel joint {n!r} is not a joint of the model")
        candidates = [joints[str(n)] for n in named]
    else:
        candidates = [
            j
            for j in robot.joints
            if j.type is JointType.REVOLUTE
            and not j.limits.position_limited
            and _parallel(_axis_in_root(j, frames), (0.0, 1.0, 0.0))
            and j.child in links
            and j.mimic is None
        ]
    found: list[tuple[Joint, float, np.ndarray]] = []  # joint, radius, centre in the root frame
    unround: list[str] = []  # candidates whose collision is not round about their axis
    for j in candidates:
        axis_root = _axis_in_root(j, frames)
        frame = frames[j.child]
        local = np.asarray(frame.rotation.T @ axis_root)
        shape = wheel_shape(links[j.child], local) if j.child in links else None
        if shape is None:
            if scenario.wheel_radius is None or named[0] is None:
                unround.append(j.name)
                continue
            shape = (scenario.wheel_radius, np.zeros(3))
        centre = frame.rotation @ shape[1] + frame.translation
        found.append((j, shape[0], centre))
    body = set(root_body(robot))
    casters: list[str] = []
    if named[0] is None and len(found) > 2:  # caster wheels swivel about a vertical joint
        casters = [j.name for j, _, _ in found if _swivels(robot, j, body, frames)]
        found = [f for f in found if f[0].name not in casters]
    if named[0] is None and len(found) != 2:
        what = ", ".join(j.name for j, _, _ in found) or "none"
        if casters:
            what += f"; caster wheels, which hang from a swivel joint, left out: {', '.join(casters)}"
        if unround:
            what += (f"; {', '.join(unround)} turn(s) about Y, but no collision shape of its link is round "
                     f"about the axis: a cylinder, a sphere or a mesh whose reach across the axis varies by "
                     f"less than {ROUNDNESS:.0%}")
        raise ValueError(
            "not a two-wheeled differential-drive robot: layer 4 needs exactly two unlimited revolute joints "
            f"about the root's Y axis whose links have a round collision (found: {what}); "
            "name them in the scenario (robot.left, robot.right) if the model has them"
        )
    if len(found) != 2:
        raise ValueError("the scenario's wheel joints have no round collision shape: give robot.wheel_radius")
    steered = [j.name for j, _, _ in found if _turned_above(robot, j, body)]
    if named[0] is None and steered:
        raise ValueError(
            f"not a differential drive: the wheel joint(s) {', '.join(steered)} hang from a turning joint (a "
            "steering joint or a leg), not from the root's body or a suspension; name the wheels in the "
            "scenario (robot.left, robot.right) to drive them anyway"
        )
    if named[0] is None:
        found.sort(key=lambda f: -float(f[2][1]))  # left (+Y) first
    (left, r_left, c_left), (right, r_right, c_right) = found
    if c_left[1] <= 0.0 or c_right[1] >= 0.0:
        raise ValueError(
            f"the wheels {left.name} and {right.name} are not on opposite sides of the root's "
            "X-Z plane (left at +Y, right at −Y)"
        )
    if named[0] is None and (abs(c_left[0] - c_right[0]) > MIRROR or abs(c_left[2] - c_right[2]) > MIRROR):
        raise ValueError(
            f"the wheels {left.name} and {right.name} are not mirrored in Y (centres "
            f"{np.round(c_left, 4).tolist()} and {np.round(c_right, 4).tolist()})"
        )
    radius = scenario.wheel_radius
    if radius is None:
        if abs(r_left - r_right) > 1e-9 * max(r_left, r_right):
            raise ValueError(
                f"the wheels have different radii ({r_left:g} and {r_right:g} m): give "
                "robot.wheel_radius in the scenario"
            )
        radius = r_left
    half_axle = scenario.half_axle if scenario.half_axle is not None else 0.5 * float(c_left[1] - c_right[1])
    signs = tuple(1.0 if float(_axis_in_root(j, frames)[1]) > 0.0 else -1.0 for j in (left, right))
    return Drive(
        kind="wheels",
        left=left.name,
        right=right.name,
        radius=float(radius),
        half_axle=float(half_axle),
        wheel_links=(left.child, right.child),
        signs=(signs[0], signs[1]),
        casters=tuple(casters),
        heading=heading,
    )


# ----------------------------------------------------------------------------------------------------
# tracks


def _tracks(
    robot: Robot, scenario: Scenario, tracks: list[Joint], frames: dict[str, Pose], prepared: Robot | None
) -> Drive:
    joints = {j.name: j for j in robot.joints}
    if scenario.left is not None and scenario.right is not None:
        pair = [joints[n] for n in (scenario.left, scenario.right) if n in joints]
        if len(pair) != 2:
            raise ValueError("the scenario's track joints are not joints of the model")
    else:
        if len(tracks) != 2:
            raise ValueError(
                f"layer 4 drives a robot with two tracks; this one has {len(tracks)} "
                f"({', '.join(j.name for j in tracks)})"
            )
        pair = sorted(tracks, key=lambda j: -float(frames[j.child].translation[1]))
    left, right = pair
    y_left, y_right = (float(frames[j.child].translation[1]) for j in pair)
    if y_left <= 0.0 or y_right >= 0.0:
        raise ValueError(
            f"the tracks {left.name} and {right.name} are not on opposite sides of the root's X-Z plane"
        )
    if prepared is None:
        prepared = prepare_tracks(robot)
    info = prepared.extras.get("tracks", {})
    if left.name not in info or right.name not in info:
        raise ValueError(
            f"the track approximation (convert's rollers) is missing for {left.name}/{right.name}"
        )
    radii = {float(info[n]["radius"]) for n in (left.name, right.name)}
    if len(radii) != 1:
        raise ValueError(f"the two tracks' rollers differ in radius ({sorted(radii)})")
    roller_radius = radii.pop()
    p_frames = _root_frames(prepared)
    signs = []
    for name in (left.name, right.name):
        roller0 = next(j for j in prepared.joints if j.name == info[name]["rollers"][0])
        signs.append(1.0 if float(_axis_in_root(roller0, p_frames)[1]) > 0.0 else -1.0)
    half_axle = scenario.half_axle if scenario.half_axle is not None else 0.5 * (y_left - y_right)
    return Drive(
        kind="tracks",
        left=left.name,
        right=right.name,
        radius=float(scenario.wheel_radius or roller_radius),
        half_axle=float(half_axle),
        wheel_links=(left.child, right.child),
        signs=(signs[0], signs[1]),
        rollers={n: tuple(info[n]["rollers"]) for n in (left.name, right.name)},
        roller_radius=roller_radius,
        track_offset_y=float(frames[left.child].translation[1]),
    )


def _root_frames(robot: Robot) -> dict[str, Pose]:
    poses = robot.world_poses()
    inv = poses[str(robot.root)].inverse()
    return {name: inv @ pose for name, pose in poses.items()}


def prepare_tracks(robot: Robot) -> Robot:
    """The robot with its tracks approximated by rollers, as every writer writes it."""
    from modelkit.convert.api import prepare
    from modelkit.convert.notes import NoteSink
    from modelkit.convert.options import WriteOptions
    from modelkit.convert.registry import target_info

    return prepare(robot, target_info("mjcf"), WriteOptions(), NoteSink())


# ----------------------------------------------------------------------------------------------------
# pan / tilt


def _pan_tilt(
    robot: Robot, scenario: Scenario, frames: dict[str, Pose], drive_joints: set[str]
) -> tuple[str | None, str | None]:
    joints = {j.name: j for j in robot.joints}
    for n in (scenario.pan, scenario.tilt):
        if n is not None and n not in joints:
            raise ValueError(f"the scenario's pan/tilt joint {n!r} is not a joint of the model")
    revolute = [
        j
        for j in robot.joints
        if j.type is JointType.REVOLUTE and j.name not in drive_joints and j.mimic is None
    ]
    pan = scenario.pan or _one([j for j in revolute if "pan" in j.name.lower()])
    tilt = scenario.tilt or _one([j for j in revolute if "tilt" in j.name.lower()])
    if pan is None:
        pan = _one(
            [
                j
                for j in revolute
                if j.parent == robot.root and _parallel(_axis_in_root(j, frames), (0.0, 0.0, 1.0))
            ]
        )
    if tilt is None and pan is not None:
        child = joints[pan].child
        tilt = _one(
            [
                j
                for j in revolute
                if j.parent == child and abs(float(_axis_in_root(j, frames)[2])) < math.sqrt(PARALLEL)
            ]
        )
    return pan, tilt


def _one(joints: list[Joint]) -> str | None:
    return joints[0].name if len(joints) == 1 else None
