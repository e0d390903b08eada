"""Measurement harness for the converted tracked robot (shared by tests/test_tracks_turning.py and
bench/bench_tracks.py): ``modelkit convert`` writes MJCF and URDF with default options, and the
WRITTEN files are driven on a plain floor in real MuJoCo and PyBullet by the seed's track controller.

* MuJoCo: the written MJCF plus a ``<geom type="plane">`` with default contact in the worldbody and
  ``priority="1"`` on the robot's colliding geoms (so their friction and condim win against the
  floor's; added only where the writer did not already), timestep 1 ms, ``implicitfast``, elliptic
  cone; the file's own ``<option impratio>`` is kept.
* PyBullet: pybullet_data's ``plane.urdf`` as shipped, ``loadURDF`` with
  ``URDF_USE_INERTIA_FROM_FILE | URDF_USE_IMPLICIT_CYLINDER``, gravity −9.81, dt 1 ms, every default
  motor off, damping 0; each roller link's lateral friction is the written ``<contact>`` value when
  the URDF has one, else the model's floor friction (what ``convert`` records for the rollers);
  ``enableConeFriction`` as the MK809 note asks for tracks (0), unless told otherwise.

Actuation (both engines the same law, the one Choreonoid's track realises): every roller of a track
is held at the belt speed ``(v ∓ w·offset_y) / r`` by a velocity servo ``τ = kv·(target − q̇)`` bounded
by ``SERVO_BOUND_FACTOR`` × what friction can pass through the roller (so the belt slips on the floor
rather than stalling, as Choreonoid's imposed surface speed does). MuJoCo integrates the servo
implicitly (``kv`` is the roller joint's damping in ``implicitfast``, ``kv·target`` its applied force);
PyBullet's velocity motor is a constraint with that force bound.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from modelkit.convert.tracks import PYBULLET_CONE_FRICTION, PYBULLET_SOLVER_ITERATIONS

REPO = Path(__file__).resolve().parents[1]
TRACKS = REPO / "samples/choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_tracks.body"

DT = 1e-3
SETTLE = 0.5  # s of zero belt speed before the command starts
SAMPLE_EVERY = 10  # steps: 100 Hz
SERVO_GAIN = 50.0  # N m s/rad per roller: the implicit servo's stiffness (error ≤ τ/kv)
SERVO_BOUND_FACTOR = 3.0  # × μ·N·r per roller: enough for the belt to slip instead of stalling


@dataclass(frozen=True)
class Profile:
    """A constant command (v m/s, w rad/s) held for ``duration`` s."""

    name: str
    v: float
    w: float
    duration: float = 10.0


PROFILES = (Profile("straight", 0.3, 0.0), Profile("spin", 0.0, 0.5), Profile("arc", 0.3, 0.3))


@dataclass
class Path2D:
    """The root frame's planar pose relative to command start, sampled at 100 Hz."""

    engine: str
    profile: str
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray  # unwrapped

    def final(self) -> tuple[float, float, float]:
        return float(self.x[-1]), float(self.y[-1]), float(self.yaw[-1])


@dataclass(frozen=True)
class Tracks:
    """What the harness needs from the conversion: roller joints per side, radius, offset, friction."""

    left: tuple[str, ...]
    right: tuple[str, ...]
    radius: float
    offset_y: float
    mu: float
    mass: float


def convert(out_dir: Path, body: Path = TRACKS) -> dict[str, Path]:
    """``modelkit convert`` (the CLI, default options) to MJCF and URDF in ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {"mjcf": out_dir / "robot.xml", "urdf": out_dir / "robot.urdf"}
    for path in files.values():
        subprocess.run([sys.executable, "-m", "modelkit.cli", "convert", str(body), "-o", str(path),
                        "--force", "-q"], check=True, capture_output=True, cwd=REPO)
    return files


def track_info(body: Path = TRACKS) -> Tracks:
    """The rollers ``convert`` writes (``extras["tracks"]``), from the same pass the writers run."""
    import modelkit
    from modelkit.convert.friction import floor_friction
    from modelkit.convert.notes import NoteSink
    from modelkit.convert.tracks import TRACKS_KEY, approximate_tracks

    robot = modelkit.load(body)
    approximate_tracks(robot, NoteSink())
    record = robot.extras[TRACKS_KEY]
    sides = sorted(record.values(), key=lambda rec: -_track_y(robot, rec["track_link"]))
    left, right = sides[0], sides[1]
    table = floor_friction(robot)
    mu = max((table[n].dynamic for n in left["roller_links"] if n in table), default=1.0)
    mass = sum(link.inertial.mass for link in robot.links if link.inertial is not None)
    return Tracks(tuple(left["rollers"]), tuple(right["rollers"]), float(left["radius"]),
                  _track_y(robot, left["track_link"]), float(mu), float(mass))


def _track_y(robot, link: str) -> float:  # type: ignore[no-untyped-def]
    poses = robot.world_poses()
    root = poses[str(robot.root)].inverse()
    return float((root @ poses[link]).translation[1])


def targets(tracks: Tracks, profile: Profile) -> tuple[float, float]:
    """``MobileRobotTrackController``: belt speeds ``v ∓ w·offset_y`` as roller speeds (rad/s)."""
    return ((profile.v - profile.w * tracks.offset_y) / tracks.radius,
            (profile.v + profile.w * tracks.offset_y) / tracks.radius)


def servo_bound(tracks: Tracks, gravity: float = 9.81) -> float:
    """Each roller's torque bound: ``SERVO_BOUND_FACTOR`` × μ·(m g / rollers)·r."""
    count = len(tracks.left) + len(tracks.right)
    return SERVO_BOUND_FACTOR * tracks.mu * tracks.mass * gravity / count * tracks.radius


# ---- MuJoCo -------------------------------------------------------------------------------------


def mjcf_on_floor(text: str) -> str:
    """The written MJCF with a default plane and ``priority="1"`` on colliding robot geoms."""
    def prioritise(match: re.Match[str]) -> str:
        tag = match.group(0)
        if "priority=" in tag or 'contype="0"' in tag or 'class="' in tag:
            return tag
        return tag.replace("<geom ", '<geom priority="1" ', 1)

    text = re.sub(r"<geom [^>]*>", prioritise, text)
    return text.replace("<worldbody>", '<worldbody>\n    <geom name="modelkit_floor" type="plane" '
                        'size="0 0 1"/>', 1)


def run_mujoco(mjcf: Path, tracks: Tracks, profile: Profile, kv: float = SERVO_GAIN,
               impratio: float | None = None, elliptic: bool = True) -> Path2D:
    """``impratio``: override the file's ``<option impratio>`` (None: keep what the file says);
    ``elliptic`` False: MuJoCo's default pyramidal cone."""
    import mujoco

    staged = mjcf.with_name(mjcf.stem + "_on_floor.xml")  # beside it: the meshes resolve
    staged.write_text(mjcf_on_floor(mjcf.read_text()))
    model = mujoco.MjModel.from_xml_path(str(staged))
    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    model.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC if elliptic else mujoco.mjtCone.mjCONE_PYRAMIDAL
    if impratio is not None:
        model.opt.impratio = impratio
    data = mujoco.MjData(model)
    sides = []
    for names in (tracks.left, tracks.right):
        dofs = [int(model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)])
                for n in names]
        sides.append(dofs)
    for dofs in sides:
        model.dof_damping[dofs] = kv
    bound = servo_bound(tracks)
    mujoco.mj_forward(model, data)
    return _drive(profile, tracks, "mujoco", lambda target: _mj_step(model, data, sides, target, kv, bound),
                  lambda: _mj_pose(data))


def _mj_step(model, data, sides, target, kv, bound) -> None:  # type: ignore[no-untyped-def]
    import mujoco

    for dofs, goal in zip(sides, target, strict=True):
        for dof in dofs:
            # implicit servo kv·(goal − q̇): damping kv (implicit) + kv·goal; bounded explicitly
            explicit = kv * (goal - data.qvel[dof])
            excess = explicit - max(-bound, min(bound, explicit))
            data.qfrc_applied[dof] = kv * goal - excess
    mujoco.mj_step(model, data)


def _mj_pose(data) -> tuple[float, float, float]:  # type: ignore[no-untyped-def]
    w, x, y, z = data.qpos[3:7]
    return float(data.qpos[0]), float(data.qpos[1]), math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


# ---- PyBullet -----------------------------------------------------------------------------------


def run_pybullet(urdf: Path, tracks: Tracks, profile: Profile,
                 cone_friction: bool = bool(PYBULLET_CONE_FRICTION),
                 iterations: int | None = PYBULLET_SOLVER_ITERATIONS) -> Path2D:
    """``cone_friction``: Bullet's ``enableConeFriction``; by default what MK809 asks of a PyBullet
    user for a tracked robot (off), True: PyBullet's own default. ``iterations``: Bullet's
    ``numSolverIterations``, by default what MK809 asks (None: PyBullet's default, 50)."""
    import pybullet as p
    import pybullet_data

    client = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=client)
        p.setTimeStep(DT, physicsClientId=client)
        if not cone_friction:
            p.setPhysicsEngineParameter(enableConeFriction=0, physicsClientId=client)
        if iterations:  # what MK809 asks of a PyBullet user for a tracked robot
            p.setPhysicsEngineParameter(numSolverIterations=iterations, physicsClientId=client)
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=client)
        flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER
        body = p.loadURDF(str(urdf), [0, 0, 0], flags=flags, physicsClientId=client)
        index = {}
        for j in range(p.getNumJoints(body, physicsClientId=client)):
            info = p.getJointInfo(body, j, physicsClientId=client)
            index[info[1].decode()] = j
            p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, force=0, physicsClientId=client)
        for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
            p.changeDynamics(body, link, linearDamping=0, angularDamping=0, jointDamping=0,
                             physicsClientId=client)
        written = "<contact>" in urdf.read_text()
        sides = [[index[n] for n in names] for names in (tracks.left, tracks.right)]
        if not written:  # the writer gives no <contact> yet: the rollers' floor friction
            for joint in sides[0] + sides[1]:
                p.changeDynamics(body, joint, lateralFriction=tracks.mu, physicsClientId=client)
        inertial = p.getDynamicsInfo(body, -1, physicsClientId=client)[3]
        bound = servo_bound(tracks)

        def step(target: tuple[float, float]) -> None:
            for joints, goal in zip(sides, target, strict=True):
                p.setJointMotorControlArray(body, joints, p.VELOCITY_CONTROL,
                                            targetVelocities=[goal] * len(joints),
                                            forces=[bound] * len(joints), physicsClientId=client)
            p.stepSimulation(physicsClientId=client)

        def pose() -> tuple[float, float, float]:
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
            rot = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
            origin = np.asarray(pos) - rot @ np.asarray(inertial)
            yaw = p.getEulerFromQuaternion(orn)[2]
            return float(origin[0]), float(origin[1]), float(yaw)

        return _drive(profile, tracks, "pybullet", step, pose)
    finally:
        p.disconnect(client)


# ---- shared loop --------------------------------------------------------------------------------


def _drive(profile: Profile, tracks: Tracks, engine: str, step, pose) -> Path2D:  # type: ignore[no-untyped-def]
    for _ in range(round(SETTLE / DT)):
        step((0.0, 0.0))
    x0, y0, th0 = pose()
    goal = targets(tracks, profile)
    rows = []
    steps = round(profile.duration / DT)
    unwrap = 0.0
    last = 0.0
    for k in range(steps + 1):
        if k % SAMPLE_EVERY == 0:
            x, y, th = pose()
            d = th - th0
            rel = math.atan2(math.sin(d), math.cos(d))
            unwrap += math.atan2(math.sin(rel - last), math.cos(rel - last))
            last = rel
            c, s = math.cos(th0), math.sin(th0)
            rows.append((k * DT, c * (x - x0) + s * (y - y0), -s * (x - x0) + c * (y - y0), unwrap))
        if k < steps:
            step(goal)
    a = np.array(rows)
    return Path2D(engine, profile.name, a[:, 0], a[:, 1], a[:, 2], a[:, 3])
