"""Pseudo continuous tracks for targets that have none: a row of driven rollers per track.

What Choreonoid does (``Link::PseudoContinuousTrackJoint``): the track link is welded to its
parent; in every contact involving it the AIST solver adds to the track's contact-point velocity
``dq_target · normalize(a × n_out)``, where ``a`` is the joint axis in world axes and ``n_out`` the
contact normal pointing *out of* the track (the solver writes ``axis × normal`` when the track is
body 0, whose ``normal`` points out of it, and ``normal × axis`` when it is body 1, whose ``normal``
points into it: the same vector). That is exactly the surface velocity of a rigid wheel of radius
``r`` spinning about ``+a`` at ``ω = dq_target / r``: ``ω a × (r n_out) = ω r (a × n_out)``.
So a positive track velocity moves the belt like a positive rotation about the joint axis: with
``a = +Y`` and the floor below (``n_out = -Z``) the contact surface moves towards -X relative to
the body and friction pushes the vehicle towards +X. The tutorial's ``MobileRobotTrackController``
confirms it: it sends ``dq_target = linear.x ∓ ω·y`` to both tracks (axis ``[0, 1, 0]``), so a
positive ``linear.x`` drives the robot forward (+X).

The approximation written here, for every target but ``.body``:

* the track link stays, on a **fixed** joint to its parent, keeping its visuals; its collision
  shapes and its contact material move to the rollers;
* the track's frame of work is taken from its collision geometry (its visuals when it has none):
  ``a`` = the joint axis (unit), ``up`` = the root link's +Z seen from the track, made
  perpendicular to ``a``, and ``forward = a × up`` (the direction a positive track velocity drives
  the vehicle). The geometry's extents along these three directions give the track's length ``L``
  (forward), width ``w`` (along ``a``) and height ``h`` (up);
* ``N`` rollers ``<track>_roller<i>`` (links; the joints are ``<track>_roller<i>_joint``) of radius
  ``r = h / 2`` and width ``w``, centres at ``r`` above the track's lowest point (so each roller's
  bottom lies on the track's bottom plane) and centred across the width, spread along the length
  so that the first and last touch the track's ends. ``N = max(2, 1 + floor((L − 2r) / (2r·(1 +
  ROLLER_CLEARANCE))))``: as many as fit **without touching each other** (MuJoCo collides sibling
  bodies, so overlapping rollers would brake each other). For the tutorial's tracks
  (L = 0.34, h = 0.12) that gives 2 rollers of radius 0.06 at x = ±0.11, whose convex hull *is* the
  track's cross-section; a track shorter than 4r gets 2 overlapping rollers (said in the note);
* each roller joint is revolute, unlimited, about ``a`` (the roller frame has the track frame's
  axes), so a positive rotation drives the vehicle the way a positive track velocity does; roller
  i > 0 mimics roller 0 (multiplier 1), so commanding roller 0 at ``ω = v / r`` reproduces a track
  velocity ``v``. Roller 0 takes the track joint's id and actuation mode (velocity when unset), and
  its velocity limits divided by ``r``;
* mass: ``TRACK_MASS_FRACTION`` of the track's mass moves to the rollers (equal shares, solid
  cylinders); the track keeps the rest with its COM moved so the assembly's mass and COM are
  exactly the track's. When a valid inertia remains, the track's inertia is chosen so that the
  assembly's inertia about its COM is exactly the track's too; otherwise the track keeps its own
  tensor scaled by ``1 − TRACK_MASS_FRACTION`` and the note gives the assembly's inertia change;
* ``robot.extras["tracks"][<track joint name>]`` records what was made, for controllers and the
  verification: ``rollers`` (joint names, roller 0 first), ``roller_links``, ``radius``, ``axis``
  (unit, in the roller frames), ``forward``, ``track_link``, ``width``, ``length``, ``overlap``,
  ``mujoco_impratio``;
* turning: a tracked vehicle turns by skidding (its belts slip lengthwise while its ends slide
  sideways), and both engines resolve such a combined slip with more sideways friction than
  Coulomb's law gives, so with their defaults the robot hardly turns (:data:`TRACK_IMPRATIO`,
  :data:`PYBULLET_CONE_FRICTION`). The MJCF writer writes ``<option impratio>`` (soft friction,
  whose force follows the slip); for PyBullet the note says to turn cone friction off.

Each track gets one MK809 warning saying what was written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from modelkit.convert.names import unique_name
from modelkit.convert.notes import NoteSink
from modelkit.geometry.extents import extent
from modelkit.model import (
    Actuator,
    ActuatorKind,
    Cylinder,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    Mimic,
    Robot,
)
from modelkit.spatial import (
    Mat3,
    Pose,
    Vec3,
    combine_mass_properties,
    inertia_tolerance,
    parallel_axis,
    principal_moments,
    rotate_inertia,
)

TRACK_MASS_FRACTION = 0.5
"""The share of a track's mass given to its rollers (the moving belt's share, roughly)."""

ROLLER_CLEARANCE = 0.02
"""Minimum gap between neighbouring rollers, as a fraction of the roller diameter."""

MAX_ROLLERS = 64
"""At most this many rollers per track. A real track is a few roller diameters long (the tutorial's: 2
rollers); a track whose extent is absurd for its height (an Extrusion point at 1e38 m) would otherwise
ask for billions of rollers. Past the cap the rollers are spread evenly with gaps, and the note says so."""

TRACKS_KEY = "tracks"
"""``Robot.extras`` key of the per-track record."""

TRACK_IMPRATIO = 0.03
"""MuJoCo's ``<option impratio>`` for a robot with tracks: friction 1/0.03 ≈ 33 times softer than the
normal direction. A turning track skids sideways while its belt slips lengthwise; MuJoCo's default
(impratio 1) resolves that combined slip in the metric of the constraint's inertia, not along the slip,
so the lateral friction of the end rollers holds nearly their full μN and the vehicle hardly turns.
Softer friction makes the force follow the slip (Coulomb). Measured on the tutorial's tracked robot,
spin 0.5 rad/s for 10 s, MuJoCo elliptic cones, 1 ms: impratio 1 / 0.3 / 0.1 / 0.03 turn it
0.93 / 1.32 / 2.94 / 3.22 rad; the skid-steer reference (``verify.reference_skid``) says 3.25 rad.
The cost: every friction contact of the model creeps more; parked on a 10° slope with its belts held,
the robot slides 214 mm in 10 s (12 mm at impratio 1; docs/convert.md)."""

PYBULLET_CONE_FRICTION = 0
"""What a PyBullet user must set (``setPhysicsEngineParameter(enableConeFriction=...)``) for the
rollers to skid: Bullet's cone friction holds the direction across the slip like a joint (measured:
1.42 rad of the reference's 3.25 on the spin above; 3.60 rad with 0). A URDF cannot carry it: MK809
says so."""

PYBULLET_SOLVER_ITERATIONS = 400
"""What a PyBullet user must set (``setPhysicsEngineParameter(numSolverIterations=...)``) for the
rollers' velocity motors to hold the belt speed while the tracks skid: Bullet solves motors, the
belt's gear constraints and the sliding contacts together by projected Gauss–Seidel, and at its
default 50 iterations a motor under a skid turn's load stays unconverged (measured on the tutorial's
spin, 1 rad/s for 10 s: a roller 0.31 rad behind its target; at 400 within 0.004 rad). A URDF cannot
carry it: MK809 says so."""

TRACK_ROLLER = "track roller"  # the source_kind of the roller servos added here (not the source's)


@dataclass(frozen=True)
class TrackShape:
    """A track's working directions (unit, in the track frame) and its extents along them."""

    axis: Vec3
    forward: Vec3
    up: Vec3
    length_range: tuple[float, float]
    width_range: tuple[float, float]
    height_range: tuple[float, float]

    @property
    def radius(self) -> float:
        return 0.5 * (self.height_range[1] - self.height_range[0])

    @property
    def length(self) -> float:
        return self.length_range[1] - self.length_range[0]

    @property
    def width(self) -> float:
        return self.width_range[1] - self.width_range[0]


def _unit(v: Vec3) -> Vec3:
    return np.asarray(v, dtype=float) / float(np.linalg.norm(v))


def track_shape(robot: Robot, joint: Joint, geoms: list[Geom]) -> TrackShape | None:
    """The track's directions and extents (None when the axis is zero or no shape is readable)."""
    axis = np.asarray(joint.axis, dtype=float)
    if not np.linalg.norm(axis) > 0.0:
        return None
    axis = _unit(axis)
    poses = robot.world_poses()
    up = np.array([0.0, 0.0, 1.0])
    if robot.root in poses and joint.child in poses:
        relative = poses[robot.root].inverse() @ poses[joint.child]
        up = relative.rotation.T @ up  # the root's +Z in the track frame
    for candidate in (up, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])):
        forward = np.cross(axis, candidate)
        if np.linalg.norm(forward) > 1e-9:
            break
    forward = _unit(forward)
    up = np.cross(forward, axis)  # right-handed (forward, axis, up), up ⟂ axis
    ranges = [extent(geoms, d) for d in (forward, axis, up)]
    length, width, height = ranges
    if length is None or width is None or height is None or height[1] - height[0] <= 0.0:
        return None
    return TrackShape(axis, forward, up, length, width, height)


# ---- mass properties ---------------------------------------------------------------------------


def cylinder_inertia(mass: float, radius: float, length: float, axis: Vec3) -> Mat3:
    """A solid cylinder's inertia about its centre, its axis along the unit vector ``axis``."""
    along = 0.5 * mass * radius * radius
    across = mass * (3.0 * radius * radius + length * length) / 12.0
    a = np.asarray(axis, dtype=float)
    return across * np.eye(3) + (along - across) * np.outer(a, a)


def valid_inertia(inertia: Mat3) -> bool:
    """Positive semi-definite and meeting the triangle inequality (gz-math's tolerance)."""
    moments = principal_moments(inertia)
    tol = inertia_tolerance(moments)
    return bool(moments[0] >= -tol and moments[0] + moments[1] >= moments[2] - tol)


def split_mass(track: Inertial, roller_centres: list[Vec3], roller_inertia: Mat3,
               roller_mass: float) -> tuple[Inertial, bool]:
    """The track's remaining inertial after giving each roller ``roller_mass``, and whether the
    assembly's inertia is exactly the track's (else the track's tensor is scaled)."""
    mass = track.mass - roller_mass * len(roller_centres)
    com0 = np.asarray(track.com, dtype=float)
    com = (track.mass * com0 - roller_mass * sum(roller_centres, np.zeros(3))) / mass
    exact = np.asarray(track.inertia, dtype=float) - parallel_axis(mass, com0 - com)
    for centre in roller_centres:
        exact = exact - roller_inertia - parallel_axis(roller_mass, com0 - centre)
    exact = 0.5 * (exact + exact.T)
    if valid_inertia(exact):
        return Inertial(mass, com, exact, track.defaulted, track.source, dict(track.sources)), True
    scaled = (1.0 - TRACK_MASS_FRACTION) * np.asarray(track.inertia, dtype=float)
    return Inertial(mass, com, scaled, track.defaulted, track.source, dict(track.sources)), False


# ---- the pass ----------------------------------------------------------------------------------


def rollers_that_fit(shape: TrackShape) -> int:
    """As many rollers as fit end to end without touching (at least 2); see the module docstring."""
    r = shape.radius
    span = shape.length - 2.0 * r
    if span <= 0.0:
        return 2
    fit = span / (2.0 * r * (1.0 + ROLLER_CLEARANCE)) + 1e-9
    return max(2, 1 + math.floor(fit)) if fit < MAX_ROLLERS else MAX_ROLLERS + 1


def roller_count(shape: TrackShape) -> int:
    """:func:`rollers_that_fit`, at most :data:`MAX_ROLLERS`."""
    return min(rollers_that_fit(shape), MAX_ROLLERS)


def _rotation_z_to(axis: Vec3, forward: Vec3) -> Mat3:
    """A rotation whose third column is ``axis`` (a cylinder's Z turned onto the roller axis)."""
    return np.column_stack([forward, np.cross(axis, forward), axis])


def approximate_tracks(robot: Robot, notes: NoteSink) -> None:
    """Replace every pseudo continuous track by a row of driven rollers (module docstring), with a
    MK809 note per track."""
    for joint in [j for j in robot.joints if j.type is JointType.PSEUDO_CONTINUOUS_TRACK]:
        link = robot.link(joint.child)
        if link is None:
            joint.type = JointType.FIXED
            continue
        _approximate(robot, joint, link, notes)


def _approximate(robot: Robot, joint: Joint, link: Link, notes: NoteSink) -> None:
    source = joint.source or link.source
    target = f"link[{link.name}]"
    joint.type = JointType.FIXED
    geoms = link.collisions or link.visuals
    shape = track_shape(robot, joint, geoms) if geoms else None
    if shape is None:
        notes.note("MK809", f"pseudo continuous track {joint.name} has no readable shape or a zero axis: "
                   "written as a fixed joint without rollers (its surface does not move)", source, target)
        return
    r, n = shape.radius, roller_count(shape)
    first = shape.length_range[0] + r
    spacing = (shape.length - 2.0 * r) / (n - 1)
    height = shape.height_range[0] + r
    middle = 0.5 * (shape.width_range[0] + shape.width_range[1])
    centres = [(first + i * spacing) * shape.forward + height * shape.up + middle * shape.axis
               for i in range(n)]
    overlap = spacing < 2.0 * r

    roller_mass = TRACK_MASS_FRACTION * link.inertial.mass / n if link.inertial is not None else 0.0
    roller_mass = max(roller_mass, 0.0)
    inertia_local = cylinder_inertia(roller_mass, r, shape.width, shape.axis)
    exact = True
    if link.inertial is not None and roller_mass > 0.0:
        link.inertial, exact = split_mass(link.inertial, centres, inertia_local, roller_mass)

    material = link.contact_material
    collision_sources = [g.source for g in link.collisions]
    link.collisions = []
    link.contact_material = None
    taken = {item.name for item in robot.links} | {item.name for item in robot.joints}
    link_names: list[str] = []
    joint_names: list[str] = []
    index = robot.links.index(link) + 1
    joint_index = robot.joints.index(joint) + 1
    geom_source = collision_sources[0] if collision_sources else link.source
    for i, centre in enumerate(centres):
        name = unique_name(f"{link.name}_roller{i}", taken)
        joint_name = unique_name(f"{name}_joint", taken)
        inertial = (Inertial(roller_mass, np.zeros(3), inertia_local.copy(), source=link.inertial.source)
                    if link.inertial is not None else None)
        along_axis = Pose(_rotation_z_to(shape.axis, shape.forward), np.zeros(3))
        cylinder = Geom(Cylinder(r, shape.width), along_axis, name=f"{name}_collision", source=geom_source)
        roller = Link(name, inertial, collisions=[cylinder], contact_material=material,
                      synthesised=True, track=link.name, source=link.source)
        limits = JointLimits()
        for attribute in ("velocity", "velocity_lower", "velocity_upper"):
            value = getattr(joint.limits, attribute)
            if math.isfinite(value) and r > 0.0:
                setattr(limits, attribute, value / r)
        roller_joint = Joint(joint_name, JointType.REVOLUTE, link.name, name, Pose(np.eye(3), centre),
                             shape.axis.copy(), limits, source=joint.source,
                             synthesised=True, track=link.name)
        if i == 0:
            roller_joint.joint_id = joint.joint_id
            roller_joint.actuation_mode = joint.actuation_mode or "velocity"
            if robot.actuators:  # a source with actuators: the driven roller keeps its motor
                robot.actuators.append(Actuator(joint_name, ActuatorKind.EFFORT, source_kind=TRACK_ROLLER,
                                                source=joint.source))
        else:
            roller_joint.mimic = Mimic(joint_names[0], 1.0, 0.0, joint.source)
        robot.links.insert(index + i, roller)
        robot.joints.insert(joint_index + i, roller_joint)
        link_names.append(name)
        joint_names.append(joint_name)
    joint.joint_id = None
    joint.actuation_mode = None

    robot.extras.setdefault(TRACKS_KEY, {})[joint.name] = {
        "rollers": joint_names,
        "roller_links": link_names,
        "radius": r,
        "axis": [float(v) for v in shape.axis],
        "forward": [float(v) for v in shape.forward],
        "track_link": link.name,
        "width": shape.width,
        "length": shape.length,
        "overlap": overlap,
        "mujoco_impratio": TRACK_IMPRATIO,
    }
    message = _message(joint, link, shape, joint_names, spacing, roller_mass, exact, overlap, material)
    if rollers_that_fit(shape) > MAX_ROLLERS:
        message += (f"; the track is longer than {MAX_ROLLERS} rollers of its height cover (length "
                    f"{shape.length:.6g} m for a height of {2 * r:.6g} m), so its {MAX_ROLLERS} rollers "
                    f"are spread with gaps of {spacing - 2 * r:.6g} m between them")
    notes.note("MK809", message, source, target)


def _message(joint: Joint, link: Link, shape: TrackShape, rollers: list[str], spacing: float,
             roller_mass: float, exact: bool, overlap: bool, material: str | None) -> str:
    r = shape.radius
    parts = [
        f"pseudo continuous track {joint.name} (length {shape.length:.6g} m, height {2 * r:.6g} m, "
        f"width {shape.width:.6g} m) written as {len(rollers)} rollers of radius {r:.6g} m, "
        f"{spacing:.6g} m apart, under the fixed track link {link.name} (its visuals kept, its "
        f"collision shapes replaced by the rollers): joints {', '.join(rollers)} about the track axis "
        f"{[round(float(v), 9) for v in shape.axis]}, {rollers[0]} driven and the others mimicking it; "
        f"a track velocity v is the roller speed v / {r:.6g} rad/s",
    ]
    if roller_mass > 0.0:
        inertia = ("the assembly's inertia is the track's" if exact else
                   "the track's inertia is scaled by "
                   f"{1.0 - TRACK_MASS_FRACTION:g}, so the assembly's inertia differs from the track's")
        parts.append(f"{TRACK_MASS_FRACTION:g} of the track's mass moved to the rollers "
                     f"({roller_mass:.6g} kg each), total mass and centre of mass unchanged, {inertia}")
    else:
        parts.append("the track has no mass, so the rollers have none")
    if material:
        parts.append(f"contact material {material} moved to the rollers")
    parts.append(f"the tracks skid to turn: the MJCF gets <option impratio=\"{TRACK_IMPRATIO:g}\"> "
                 "(softer friction, so that the rollers' friction follows their slip as Coulomb's does); "
                 f"PyBullet needs setPhysicsEngineParameter(enableConeFriction={PYBULLET_CONE_FRICTION}) "
                 f"for the same and numSolverIterations={PYBULLET_SOLVER_ITERATIONS} for the roller "
                 "motors to hold the belt speed while skidding, which a URDF cannot carry")
    if overlap:
        parts.append("the track is shorter than two roller diameters: the rollers overlap, so a target "
                     "that collides sibling bodies needs them excluded from each other")
    return "; ".join(parts)


def roller_names(robot: Robot, key: str) -> set[str]:
    """The names the track approximation recorded under ``key`` for every track: ``"rollers"`` (joints)
    or ``"roller_links"`` (links); empty without tracks."""
    tracks = robot.extras.get(TRACKS_KEY)
    if not isinstance(tracks, dict):
        return set()
    return {str(name) for record in tracks.values() if isinstance(record, dict)
            for name in record.get(key, [])}


def track_impratio(robot: Robot) -> float | None:
    """The MJCF ``<option impratio>`` the robot's tracks ask for (the smallest), None without tracks."""
    records = robot.extras.get(TRACKS_KEY)
    if not isinstance(records, dict):
        return None
    values = [float(r["mujoco_impratio"]) for r in records.values()
              if isinstance(r, dict) and "mujoco_impratio" in r]
    return min(values) if values else None


def assembly_mass_properties(robot: Robot, track_link: str) -> tuple[float, Vec3, Mat3]:
    """Mass, COM and inertia about the COM (track frame) of a track link and its rollers: for
    checking that the approximation kept the track's mass properties."""
    parts: list[tuple[float, Vec3, Mat3]] = []
    link = robot.link(track_link)
    if link is not None and link.inertial is not None:
        parts.append((link.inertial.mass, link.inertial.com, link.inertial.inertia))
    for joint in robot.joints:
        child = robot.link(joint.child)
        if joint.parent != track_link or child is None or child.inertial is None:
            continue
        if child.track != track_link:
            continue
        rot, offset = joint.origin.rotation, joint.origin.translation
        parts.append((child.inertial.mass, rot @ child.inertial.com + offset,
                      rotate_inertia(child.inertial.inertia, rot)))
    return combine_mass_properties(parts)
