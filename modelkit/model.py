"""The robot model every reader produces and every writer consumes.

Conventions, settled here and nowhere else:

* SI units (m, kg, s), angles in radians, right-handed frames.
* A link's frame is its joint frame: a joint's ``origin`` is the child link frame expressed in the
  parent link frame at q = 0, and the joint axis is expressed in the child link frame.
* Cylinders, capsules and cones lie along their local **Z** axis (readers of Y-axis formats rotate
  at the boundary). Cone apex at +length/2.
* Inertia is about the centre of mass, in link axes, a full 3×3 tensor.
* Every element keeps its :class:`SourceLocation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Any

from modelkit.diagnostics import SourceLocation
from modelkit.rot3 import ArrayField
from modelkit.spatial import Mat3, Pose, Vec3

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

# Array fields (ArrayField) read as numpy arrays but may hold plain tuples, which the numpy-free readers
# store: read them with modelkit.rot3.peek (or Pose.rotation_tuple ...) where numpy must not be imported.

WORLD_LINK = "world"
"""The name of the link that stands for the world itself (every format's convention)."""

AXIS_UNIT_TOLERANCE = 1e-3
BALL_KEYS = ("#x", "#y", "#z")
"""A ball joint's position in a configuration (``Robot.world_poses``): the angles about the joint
frame's X, Y and Z axes, applied in that order (R = Rx·Ry·Rz, the URDF writer's chain of three joints),
under the keys ``NAME#x``, ``NAME#y`` and ``NAME#z``."""
"""A written joint axis whose length is off 1 by more than this is not a rounded unit vector
("0.7071 0 0.7071" has length 0.99999): URDF and SDF readers warn (MK306). The ``.body`` reader warns
from 1e-6 on, since Choreonoid uses the axis unnormalised."""


class JointType(StrEnum):
    FIXED = "fixed"
    REVOLUTE = "revolute"  # limited or unlimited (URDF "continuous" = revolute without limits)
    PRISMATIC = "prismatic"
    FLOATING = "floating"  # 6 DOF (Choreonoid "free"; a non-root one splits off a floating subtree)
    PLANAR = "planar"
    BALL = "ball"
    PSEUDO_CONTINUOUS_TRACK = "pseudo_continuous_track"  # fixed kinematically, moving contact surface

    @property
    def moves(self) -> bool:
        return self not in (JointType.FIXED, JointType.PSEUDO_CONTINUOUS_TRACK)


# ---- geometry -------------------------------------------------------------------------------


@dataclass(eq=False)
class Box:
    size: ArrayField[Vec3] = ArrayField()  # noqa: RUF009 full edge lengths


@dataclass(eq=False)
class Sphere:
    radius: float


@dataclass(eq=False)
class Cylinder:
    radius: float
    length: float


@dataclass(eq=False)
class Capsule:
    radius: float
    length: float  # length of the cylindrical part (hemispheres add 2·radius)


@dataclass(eq=False)
class Cone:
    radius: float
    length: float


@dataclass(eq=False)
class Ellipsoid:
    radii: ArrayField[Vec3] = ArrayField()  # noqa: RUF009


@dataclass(eq=False)
class TriangleMeshData:
    """Triangles held in memory (generated geometry, or a mesh already loaded)."""

    vertices: NDArray[np.float64]  # (n, 3)
    faces: NDArray[np.int64]  # (m, 3)


@dataclass(eq=False)
class Mesh:
    """A mesh: a file reference, triangles in memory, or both.

    ``uri`` is as written in the source; ``path`` is where the resolver found it (None when it could
    not be resolved). ``fragment`` selects a named part (VRML DEF / COLLADA node). ``generator``
    names the generated-geometry kind ("Extrusion", "IndexedFaceSet", ...) when the triangles were
    computed from source data rather than read from a file.
    """

    uri: str | None = None
    path: str | None = None
    fragment: str | None = None
    scale: ArrayField[Vec3] = ArrayField((1.0, 1.0, 1.0))  # noqa: RUF009
    data: TriangleMeshData | None = None
    generator: str | None = None
    source_params: dict[str, Any] = field(default_factory=dict)


Geometry = Box | Sphere | Cylinder | Capsule | Cone | Ellipsoid | Mesh


@dataclass(eq=False)
class VisualMaterial:
    name: str | None = None
    diffuse: ArrayField[Vec3 | None] = ArrayField(None)  # noqa: RUF009 RGB 0..1
    transparency: float = 0.0
    ambient: float | None = None
    specular: ArrayField[Vec3 | None] = ArrayField(None)  # noqa: RUF009
    emissive: ArrayField[Vec3 | None] = ArrayField(None)  # noqa: RUF009
    specular_exponent: float | None = None
    texture: str | None = None

    @property
    def rgba(self) -> tuple[float, float, float, float] | None:
        if self.diffuse is None:
            return None
        r, g, b = (float(v) for v in self.__dict__["_diffuse"])
        return (r, g, b, 1.0 - self.transparency)


@dataclass(frozen=True)
class SurfaceFriction:
    """A collision shape's own friction against whatever it touches, as the source set it.

    ``sliding`` is the Coulomb coefficient (dimensionless). ``torsional`` (about the contact normal)
    and ``rolling`` are in metres (torque = coefficient × normal force), as MuJoCo and PyBullet define
    them; 0 where the source's engine does not apply them (an MJCF geom of condim 3 has no torsional
    friction, whatever its ``friction`` attribute says), None where the source does not say. Readers
    set it only when the source gives a shape its own friction; a `.body` link's friction is a pair
    of contact materials instead (``Link.contact_material``). ``sliding2`` is the coefficient along
    the second friction direction when the source gives one that differs (SDF ``<mu2>``, a Gazebo
    ``<mu2>``); None: isotropic.
    """

    sliding: float
    torsional: float | None = None
    rolling: float | None = None
    sliding2: float | None = None  # the second direction's where it differs (SDF ``mu2``): anisotropic


@dataclass(eq=False)
class Geom:
    """One visual or collision shape, placed in its link frame."""

    geometry: Geometry
    pose: Pose = field(default_factory=Pose)
    name: str | None = None
    material: VisualMaterial | None = None
    source: SourceLocation | None = None
    friction: SurfaceFriction | None = None  # collision shapes: the source's own friction, if any


@dataclass(eq=False)
class Inertial:
    mass: float
    com: ArrayField[Vec3] = ArrayField((0.0, 0.0, 0.0))  # noqa: RUF009
    inertia: ArrayField[Mat3] = ArrayField(((0.0, 0.0, 0.0),) * 3)  # noqa: RUF009 about the COM, link axes
    defaulted: bool = False  # True when the source gave no mass information (Choreonoid defaults)
    source: SourceLocation | None = None
    sources: dict[str, SourceLocation] = field(default_factory=dict)


class DeviceKind(StrEnum):
    """The one device vocabulary every reader maps to and every writer maps from.

    Frame convention (settled at each format's boundary): a device's ``pose`` is its sensor frame
    in the link frame, robotics style: **+X is the viewing / scanning / forward direction, +Y left,
    +Z up** (SDF's sensor frame). A camera image's top edge is towards +Z. Lights shine along their
    ``direction`` parameter, a vector in the device frame (default (0, 0, -1), as SDF, MJCF and
    Choreonoid default).

    Canonical parameters (SI units, radians; absent = not given by the source):

    * cameras (``camera``, ``depth_camera``, ``rgbd_camera``): ``width``, ``height`` (pixels),
      ``horizontal_fov``, ``near``, ``far``, ``update_rate`` (Hz), ``noise_stddev``;
    * ``lidar``: ``horizontal_samples``, ``horizontal_min_angle``, ``horizontal_max_angle``,
      ``vertical_samples`` (1 for a planar scanner), ``vertical_min_angle``,
      ``vertical_max_angle``, ``range_min``, ``range_max``, ``range_resolution``, ``update_rate``,
      ``noise_stddev``, ``detection_rate``;
    * ``imu``, ``accelerometer``, ``gyro``: ``update_rate``, ``max_acceleration`` and
      ``max_angular_velocity`` (vec3), ``noise_stddev``;
    * ``force_torque``: ``update_rate``, ``max_force``, ``max_torque`` (vec3);
    * ``contact``: ``update_rate``;
    * lights (``spot_light``, ``point_light``, ``directional_light``): ``color`` (RGB 0..1),
      ``intensity``, ``attenuation_constant``, ``attenuation_linear``,
      ``attenuation_quadratic``, ``range``, ``direction``, ``spot_inner_angle``,
      ``spot_outer_angle`` (half-angles), ``spot_falloff``, ``on``;
    * every kind: anything else the source said under its own snake_case name, kept for a writer
      of the same format.
    """

    CAMERA = "camera"
    DEPTH_CAMERA = "depth_camera"
    RGBD_CAMERA = "rgbd_camera"
    LIDAR = "lidar"
    IMU = "imu"
    ACCELEROMETER = "accelerometer"
    GYRO = "gyro"
    FORCE_TORQUE = "force_torque"
    CONTACT = "contact"
    SPOT_LIGHT = "spot_light"
    POINT_LIGHT = "point_light"
    DIRECTIONAL_LIGHT = "directional_light"
    OTHER = "other"  # no canonical meaning (plugins, GPS, altimeter ...): ``source_kind`` says what


CAMERA_KINDS = frozenset({DeviceKind.CAMERA, DeviceKind.DEPTH_CAMERA, DeviceKind.RGBD_CAMERA})
LIGHT_KINDS = frozenset({DeviceKind.SPOT_LIGHT, DeviceKind.POINT_LIGHT, DeviceKind.DIRECTIONAL_LIGHT})


@dataclass(eq=False)
class Device:
    """A sensor, light or other device attached to a link.

    ``kind`` is the source format's device type (``Camera``, ``RangeSensor``, ``SpotLight``...);
    ``params`` holds its parameters in SI units and radians under snake_case names.
    ``canonical`` is the kind in the shared vocabulary (:class:`DeviceKind`) with its parameters in
    ``canonical_params``; readers fill both so that any writer can map the device.
    """

    kind: str
    name: str
    pose: Pose = field(default_factory=Pose)
    params: dict[str, Any] = field(default_factory=dict)
    source: SourceLocation | None = None
    canonical: DeviceKind = DeviceKind.OTHER
    canonical_params: dict[str, Any] = field(default_factory=dict)


@dataclass(eq=False)
class Link:
    name: str
    inertial: Inertial | None = None
    visuals: list[Geom] = field(default_factory=list)
    collisions: list[Geom] = field(default_factory=list)
    devices: list[Device] = field(default_factory=list)
    contact_material: str | None = None
    self_collide: bool | None = None
    """The source's own word on whether this link collides with the robot's other links (SDF
    ``<self_collide>``, a URDF ``<gazebo>`` block's ``selfCollide``); None: it says nothing."""
    synthesised: bool = False
    """Made up by a reader or a pass, not written in the source (an MJCF multi-joint body's
    intermediate frames, the world link a reader adds to hang joints from, a track's rollers)."""
    track: str | None = None  # a roller (synthesised) standing for this source track link
    extras: dict[str, Any] = field(default_factory=dict)  # one format's own data, kept as is
    source: SourceLocation | None = None
    sources: dict[str, SourceLocation] = field(default_factory=dict)  # per attribute: "name", "mass"...

    def loc(self, attribute: str) -> SourceLocation | None:
        return self.sources.get(attribute, self.source)


NO_LIMIT = 1e16  # rad or m: SDFormat's default joint bound before 1.10, meaning "no limit"


@dataclass(eq=False)
class JointLimits:
    lower: float = -math.inf
    upper: float = math.inf
    velocity: float = math.inf  # symmetric bound |dq| ≤ velocity, when symmetric
    velocity_lower: float = -math.inf
    velocity_upper: float = math.inf
    effort: float = math.inf

    @property
    def position_limited(self) -> bool:
        return math.isfinite(self.lower) or math.isfinite(self.upper)

    @property
    def endless(self) -> bool:
        """No position bound, or bounds at SDFormat's "no limit" (±1e16 or beyond), which a URDF made from
        an SDF keeps as numbers (example-robot-data's iris: rotors limited to ±1e16)."""
        return self.lower <= -NO_LIMIT and self.upper >= NO_LIMIT


@dataclass(eq=False)
class Mimic:
    """This joint follows another: q = multiplier · q_leader + offset (URDF/SDF mimic, MJCF equality)."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0
    source: SourceLocation | None = None


@dataclass(eq=False)
class Joint:
    name: str
    type: JointType
    parent: str
    child: str
    origin: Pose = field(default_factory=Pose)  # child frame in parent frame at q = 0
    axis: ArrayField[Vec3] = ArrayField((0.0, 0.0, 1.0))  # noqa: RUF009 in the child frame
    limits: JointLimits = field(default_factory=JointLimits)
    armature: float = 0.0
    damping: float = 0.0  # viscous, N·m·s/rad or N·s/m
    friction: float = 0.0  # Coulomb (dry) friction, N·m or N
    spring_stiffness: float = 0.0  # N·m/rad or N/m, pulling q towards spring_reference
    spring_reference: float = 0.0  # q at which the spring is at rest (a ball joint: 0, its zero orientation)
    mimic: Mimic | None = None
    initial_position: float = 0.0
    joint_id: int | None = None
    actuation_mode: str | None = None
    synthesised: bool = False  # made up, not written in the source (see Link.synthesised)
    track: str | None = None  # a roller's joint (synthesised): the source track link it stands for
    implicit_name: bool = False
    """The source gives the joint no name of its own: it is named after its child link (``.body``,
    where a link is its joint), so a writer that can names it after the link as written."""
    extras: dict[str, Any] = field(default_factory=dict)  # one format's own data, kept as is
    source: SourceLocation | None = None
    sources: dict[str, SourceLocation] = field(default_factory=dict)  # per attribute: "parent", "axis"...

    def loc(self, attribute: str) -> SourceLocation | None:
        return self.sources.get(attribute, self.source)


class ActuatorKind(StrEnum):
    """What an actuator's control means: a force or torque, a target velocity, a target position."""

    EFFORT = "effort"
    VELOCITY = "velocity"
    POSITION = "position"


@dataclass(eq=False)
class Actuator:
    """One actuator driving one joint, in the source's own terms (canonical across formats).

    ``gear`` scales the control into joint force (MJCF ``gear``); ``kp`` (N·m/rad or N/m) and ``kv``
    (N·m·s/rad or N·s/m) are the servo gains of a position or velocity actuator, None when the
    source gave none (a writer then makes them up and says so). ``force_range`` bounds the force at
    the joint, ``ctrl_range`` the control; None = unbounded or not given. ``reduction`` is the
    transmission's mechanical reduction (URDF ``mechanicalReduction``, Choreonoid ``gearRatio``),
    ``rotor_inertia`` the motor rotor's inertia before the reduction (kg·m²; the joint's armature
    already holds reduction² · rotor inertia where the reader knew both). ``source_kind`` names what the
    source wrote (``PositionJointInterface``, ``ros2_control position``, ``jointDisplacement``,
    ``position``, ``general``...). ``ros_interface``: the source names a ROS control hardware interface
    (a URDF ``<transmission>`` or ``<ros2_control>`` command interface), which says how a ROS controller
    commands the joint, not what the joint does at zero control (a ROS effort interface is usually under
    a position or trajectory controller's PID).
    """

    joint: str
    kind: ActuatorKind = ActuatorKind.EFFORT
    name: str | None = None
    gear: float = 1.0
    kp: float | None = None
    kv: float | None = None
    force_range: tuple[float, float] | None = None
    ctrl_range: tuple[float, float] | None = None
    reduction: float = 1.0
    rotor_inertia: float = 0.0
    source_kind: str = ""
    source: SourceLocation | None = None
    ros_interface: bool = False


@dataclass(eq=False)
class CollisionExclusion:
    """Two links whose collisions with each other the source disables (MoveIt's SRDF
    ``<disable_collisions link1 link2 reason>``: adjacent, colliding at the default pose, always or never
    in collision over the sampled workspace). ``reason`` is the source's word for why."""

    link1: str
    link2: str
    reason: str = ""
    source: SourceLocation | None = None


@dataclass(eq=False)
class LoopConstraint:
    """A closed-loop joint between two links of the tree (Choreonoid ``extra_joints``)."""

    name: str
    type: str  # "fixed" | "hinge" | "ball" | "piston"
    link1: str
    link2: str
    pose_in_link1: Pose = field(default_factory=Pose)
    pose_in_link2: Pose = field(default_factory=Pose)
    axis: ArrayField[Vec3] = ArrayField((1.0, 0.0, 0.0))  # noqa: RUF009 in the joint frame
    source: SourceLocation | None = None


@dataclass(eq=False)
class Robot:
    """A robot: links joined into a tree by joints, plus how the root meets the world.

    ``links`` and ``joints`` are lists (not dicts) so that a reader can keep duplicate names for the
    validation rules to report. ``root`` names the root link; ``root_joint`` says whether it floats
    (``FLOATING``) or is welded to the world (``FIXED``) at ``root_pose``, or is None when the format
    leaves it open (URDF).

    ``actuators`` are the source's own actuators (none: the source says nothing about actuation).

    ``masses_unknown`` is True when the reader could not tell the masses (an MJCF file MuJoCo could
    not compile: the masses it would infer from geoms); mass rules then say nothing.
    ``root_joint_name`` and ``root_joint_source`` are the name and place of the source's element that
    set ``root_joint`` (a ``.body`` root's joint type; a URDF's fixed joint from ``world``, absorbed
    into ``root_pose``), for the targets that write the weld as a named joint and for notes.
    ``free_link_poses`` holds the world pose of each link no joint connects to the tree where the
    source gives one (SDF floats such a link as a separate body, or fixes it in a static model).
    ``materials_file`` is the contact-material table the links' ``contact_material`` names refer to
    when the user gave one (Choreonoid's ``materials.yaml``, the reading option ``--materials``); None:
    Choreonoid's own table.
    """

    name: str
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    root: str | None = None
    root_joint: JointType | None = None
    root_pose: Pose = field(default_factory=Pose)
    loops: list[LoopConstraint] = field(default_factory=list)
    actuators: list[Actuator] = field(default_factory=list)
    source_format: str = ""
    source: SourceLocation | None = None
    masses_unknown: bool = False
    root_joint_name: str | None = None
    root_joint_source: SourceLocation | None = None
    free_link_poses: dict[str, Pose] = field(default_factory=dict)
    self_collide: bool | None = None  # the model-wide flag (SDF <model><self_collide>), see Link's
    collision_exclusions: list[CollisionExclusion] = field(default_factory=list)  # link pairs (SRDF)
    materials_file: Path | None = None
    extras: dict[str, Any] = field(default_factory=dict)  # one format's own data, kept as is

    def total_mass(self) -> float:
        """The sum of the links' masses (a negative mass, which validate refuses, counts as 0)."""
        return sum(max(float(link.inertial.mass), 0.0) for link in self.links if link.inertial is not None)

    def link(self, name: str) -> Link | None:
        for link in self.links:
            if link.name == name:
                return link
        return None

    @property
    def free_links_float(self) -> bool:
        """Whether the links of ``free_link_poses`` float as separate bodies (SDF: a model that is not
        static) rather than stay fixed in the world (a static model: its root welded without a world
        joint of its own)."""
        static = (self.root_joint is JointType.FIXED and "sdf_world_joint" not in self.extras
                  and self.root != WORLD_LINK)
        return not static

    def children_of(self) -> dict[str, list[Joint]]:
        """Parent link name → the joints that hang from it, in document order (a new dict each call)."""
        out: dict[str, list[Joint]] = {}
        for joint in self.joints:
            out.setdefault(joint.parent, []).append(joint)
        return out

    def tree_order(self) -> tuple[list[Link], dict[str, Joint]]:
        """Links depth-first from the root, every parent before its children (siblings in joint order;
        iterative, a link reached twice is taken once), and each reached link's parent joint. Empty when
        the root is unknown."""
        links: dict[str, Link] = {}
        for link in self.links:
            links.setdefault(link.name, link)
        children = self.children_of()
        parent_joint: dict[str, Joint] = {}
        order: list[Link] = []
        if self.root is None or self.root not in links:
            return order, parent_joint
        stack = [self.root]
        seen = {self.root}
        while stack:
            name = stack.pop()
            order.append(links[name])
            kids = [j for j in children.get(name, []) if j.child in links and j.child not in seen]
            for joint in kids:
                seen.add(joint.child)
                parent_joint[joint.child] = joint
            stack.extend(j.child for j in reversed(kids))
        return order, parent_joint

    def world_poses(self, positions: dict[str, float] | None = None) -> dict[str, Pose]:
        """Forward kinematics: each link's pose in the world (root at ``root_pose``).

        ``positions`` maps joint names to q (default 0), and a ball joint's three angles to
        ``NAME#x``... (:data:`BALL_KEYS`). Links unreachable from the root are absent.
        """
        import numpy as np

        from modelkit.spatial import axis_angle

        positions = positions or {}
        if self.root is None:
            return {}
        poses: dict[str, Pose] = {self.root: self.root_pose}
        children_of = self.children_of()
        stack = [self.root]
        while stack:
            parent = stack.pop()
            for joint in children_of.get(parent, []):
                if joint.child in poses:
                    continue
                q = positions.get(joint.name, 0.0)
                motion: Pose | None = None  # the joint at rest: the child sits at the joint's origin
                axis = np.asarray(joint.axis, dtype=float)
                if joint.type is JointType.REVOLUTE and q != 0.0 and np.linalg.norm(axis) > 0:
                    motion = Pose(axis_angle(axis, q), np.zeros(3))
                elif joint.type is JointType.PRISMATIC and q != 0.0:
                    motion = Pose(np.eye(3), axis * q)
                elif joint.type is JointType.BALL:
                    rotation = np.eye(3)
                    for key, unit in zip(BALL_KEYS, np.eye(3), strict=True):
                        angle = positions.get(joint.name + key, 0.0)
                        if angle != 0.0:
                            rotation = rotation @ axis_angle(unit, angle)
                    motion = Pose(rotation, np.zeros(3))
                placed = poses[parent] @ joint.origin
                poses[joint.child] = placed if motion is None else placed @ motion
                stack.append(joint.child)
        return poses
