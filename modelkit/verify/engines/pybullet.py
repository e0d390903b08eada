"""PyBullet adapter: a written URDF loaded into PyBullet **in a child process**.

PyBullet keeps global state and can crash on bad input, so it runs in
:mod:`modelkit.verify.engines.pybullet_worker`, started by path with this interpreter; every request has a
timeout, and a crash, a refusal or a timeout becomes an :class:`~modelkit.verify.engines.protocol.EngineError`
carrying PyBullet's message (never a hang).

Settings (verification.md §2.8, §6): ``URDF_USE_INERTIA_FROM_FILE | URDF_USE_IMPLICIT_CYLINDER``,
``useFixedBase=True``, gravity (0, 0, −9.81), linear/angular/joint damping of every link zeroed,
default velocity motors off (force 0), torques re-sent before every ``stepSimulation``.

Frames. PyBullet keeps each link's *inertial* (COM) frame: ``getDynamicsInfo`` gives the principal
moments and the inertial frame (position, orientation) in the URDF link frame — PyBullet
diagonalises a URDF inertia with products of inertia into that orientation — so the tensor about
the COM in link axes is R·diag·Rᵀ. ``getBasePositionAndOrientation`` and ``getLinkState()[0:2]``
are COM frames (double precision); ``getLinkState()[4:6]`` is the URDF link frame but float32.
Link poses therefore come, by default, from the COM frame with the inertial frame undone
(``pose_path="com-frame"``, double precision), or from ``[4:6]`` (``pose_path="link-frame"``,
float32, tolerance 1e-6). Poses are reported relative to the root link's frame, so where PyBullet
places the welded base (it places the base's COM frame) does not matter.

Joint axes: ``getJointInfo`` gives the axis in the child's inertial frame; it is rotated back into
the child link frame with the child's inertial orientation.
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.convert.tracks import PYBULLET_SOLVER_ITERATIONS
from modelkit.formats.urdf.writer import PYBULLET_MAX_JOINTS
from modelkit.model import WORLD_LINK
from modelkit.spatial import Pose
from modelkit.verify.engines import ball_law, child
from modelkit.verify.engines.child import Worker
from modelkit.verify.engines.protocol import (
    Array,
    EngineError,
    JointFacts,
    LinkFacts,
    ShapeFacts,
    StaticFacts,
    TorqueLaw,
)

Renames = dict[str, dict[str, str]]

WORKER = Path(__file__).with_name("pybullet_worker.py")
# -P: the worker's folder must not go first on sys.path, or this module (engines/pybullet.py) would
# shadow the real ``pybullet`` package (and engines/mujoco.py ``mujoco``) in the child.
GRAVITY = -9.81
DEFAULT_TIMEOUT = child.DEFAULT_TIMEOUT  # one request (load, a batch of poses; a 10 s replay takes ~0.1 s)
SETTINGS: dict[str, Any] = {
    "flags": "URDF_USE_INERTIA_FROM_FILE|URDF_USE_IMPLICIT_CYLINDER",
    "useFixedBase": True,
    "gravity": [0.0, 0.0, GRAVITY],
    "linearDamping": 0.0,
    "angularDamping": 0.0,
    "jointDamping": 0.0,
    "default_motors": "off (VELOCITY_CONTROL force 0)",
    "control": "TORQUE_CONTROL re-sent before every stepSimulation",
    "replay_joint_limits": "made inert for the replay (changeDynamics bounds ±1e30, jointLimitForce 0)",
    "integrator": "PyBullet btMultiBody semi-implicit Euler",
    "process": "child process (modelkit/verify/engines/pybullet_worker.py)",
    "base_mass_properties": "getDynamicsInfo(-1) of a second, floating-base load (a fixed base reads 0)",
}



def invalid_inertia_note(link: str, moments: tuple[float, float, float]) -> str:
    """Why PyBullet holds a zero tensor for a link whose source inertia violates the triangle
    inequality: its URDF importer prints "Bad inertia tensor properties" and replaces the tensor by
    zero. A real consumer refusing the source's data (MK303), so the check stays failed."""
    a, b, c = moments
    return (f"PyBullet replaced the invalid tensor by zero (\"Bad inertia tensor properties\"): the source "
            f"inertia of {link} violates the triangle inequality (principal moments {a:g} + {b:g} < {c:g}, "
            "MK303), so this is PyBullet refusing the source's data, not a conversion fault")

class PyBulletError(EngineError):
    """PyBullet refused a file, failed a request, crashed or timed out."""


REFUSED_TENSOR = re.compile(r"invalid inertia tensor (?:for )?body (\d+) (I\(\d,\d\)!=I\(\d,\d\))\. "
                            r"I\(\d,\d\)-I\(\d,\d\)= ?([-+0-9.eE]+)")
"""What PyBullet's inverse-dynamics library (btInverseDynamics, behind ``calculateMassMatrix`` and
``calculateInverseDynamics``) prints when a link's tensor, as it composed it about the link frame
from the importer's principal moments and rotation, is not symmetric to 5 machine epsilons
(``kIsZero``, an absolute bound of 1.1e-15 kg·m²): the rounding of a heavy link's rotated tensor
passes it (ros-industrial's KUKA KR210, rtb-data: 1.4e-14 on a ~100 kg·m² tensor). The file is sound;
stepping never checks it."""

FORWARD_STEP = 1.0
"""s: the one ``stepSimulation`` that reads PyBullet's forward accelerations when its inverse dynamics
refuses (``Engine.accelerations`` in the worker): a long step keeps (dq' − dq) / step well above the
rounding of dq (the velocity clamp and limits are off for it)."""


def quat_xyzw_matrix(q: tuple[float, ...] | list[float]) -> Array:
    """Rotation matrix of a PyBullet quaternion (x, y, z, w), normalised."""
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _pose(pos: tuple[float, ...], orn: tuple[float, ...]) -> Pose:
    return Pose(quat_xyzw_matrix(orn), np.array(pos, dtype=float))


def _worker() -> Worker:
    return Worker([sys.executable, "-P", str(WORKER)], "PyBullet", PyBulletError)


def _largest_diagonalisation_change(urdf: Path) -> float:
    """The largest relative change PyBullet's importer makes to a link tensor of ``urdf``
    (:func:`~modelkit.verify.engines.bullet_inertia.diagonalised`; relative to the largest element, in
    the link frame: layer 1's inertia measure)."""
    from lxml import etree

    from modelkit import rot3
    from modelkit.verify.engines.bullet_inertia import diagonalised

    worst = 0.0
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    for inertial in etree.parse(str(urdf), parser).iterfind("./link/inertial"):
        el = inertial.find("inertia")
        if el is None:
            continue
        try:
            ixx, ixy, ixz, iyy, iyz, izz = (float(el.get(k, "0"))
                                            for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
            origin = inertial.find("origin")
            rpy = [float(v) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()]
        except ValueError:
            continue
        tensor = np.array(rot3.inertia_from_moments(ixx, ixy, ixz, iyy, iyz, izz))
        rotation = np.array(rot3.from_rpy(*rpy)) if len(rpy) == 3 else np.eye(3)
        file_tensor = rotation @ tensor @ rotation.T
        scale = float(np.max(np.abs(file_tensor)))
        if scale > 0.0 and np.all(np.isfinite(tensor)):
            change = rotation @ (diagonalised(tensor) - tensor) @ rotation.T
            worst = max(worst, float(np.max(np.abs(change))) / scale)
    return worst


class PyBulletModel:
    """A written URDF in PyBullet, base welded: the :class:`~modelkit.verify.engines.protocol.EngineModel`
    and the :class:`~modelkit.verify.engines.protocol.Simulator` of layer 3b. Names are the URDF's."""

    engine = "pybullet"

    def __init__(self, urdf: Path, renames: Renames | None = None, root: str | None = None, dt: float = 1e-3,
                 pose_path: str = "com-frame", timeout: float = DEFAULT_TIMEOUT) -> None:
        if pose_path not in ("com-frame", "link-frame"):
            raise ValueError(f"pose_path must be 'com-frame' or 'link-frame', not {pose_path!r}")
        self.renames: Renames = renames or {}
        self.path = Path(urdf).resolve()
        self.pose_path = pose_path
        self.timeout = timeout
        self.dt = dt
        self.last_replay_wall = math.nan
        self._worker = _worker()
        try:
            info = self._worker.request("load", timeout=timeout, path=str(Path(urdf).resolve()),
                                        gravity=GRAVITY, dt=dt)
            dyn = self._worker.request("dynamics", timeout=timeout, path=str(Path(urdf).resolve()))
        except BaseException:
            self._worker.close()
            raise
        self._types = {v: k for k, v in info["types"].items()}
        self._joints: list[dict[str, Any]] = info["joints"]
        self.base: str = info["base"]
        self.root = root if root is not None else self.base
        # A URDF that welds its root itself (``convert --base fixed``: a ``world`` link and a fixed
        # joint to the root): by the URDF convention ``world`` is the world, so neither that link nor
        # that joint is the robot's, and poses are taken in the root's frame (PyBullet's base is
        # ``world`` then).
        self.world_joint = self._world_joint(self.root)
        if self.root != self.base and self.world_joint is None:
            self._worker.close()
            raise PyBulletError(f"PyBullet's base link is {self.base!r}, not the root {root!r}")
        self._links = [self.base] + [j["child"] for j in self._joints]  # index + 1 = PyBullet link index
        self._dofs = [self._joints[i]["name"] for i in info["movable"]]
        self._inertial = {self._links[d["link"] + 1]: _pose(d["inertial_pos"], d["inertial_orn"])
                          for d in dyn}
        self._dynamics = {self._links[d["link"] + 1]: d for d in dyn}
        # Where the welded base's COM frame sits (undone to get the base link frame for poses).
        self._base_inertial = _pose(dyn[0]["fixed_inertial_pos"], dyn[0]["fixed_inertial_orn"])
        self.settings: dict[str, Any] = dict(SETTINGS, timeStep=dt, pose_path=pose_path,
                                             pose_source=("getLinkState[0:2] with the inertial frame undone "
                                                          "(double)" if pose_path == "com-frame" else
                                                          "getLinkState[4:6] (float32)"))
        # PyBullet's reduced-precision paths (verification.md §2.8, §6: 1e-6 where PyBullet is not
        # double precision), raised for exactly the quantities that go through them:
        # * a URDF inertia with products of inertia is diagonalised by the importer
        #   (BulletURDFImporter: btMatrix3x3::diagonalize with threshold 1e-6, 30 iterations) and kept
        #   as principal moments + a rotation: the tensor read back, and the mass matrix and bias
        #   built from it, carry that approximation (GR001: 5.5e-8 inertia, 1.2e-9 mass matrix);
        #   a link whose inertial frame stays the identity did not take that path;
        # * getLinkState[4:6] is float32 (2.4e-8 m / 4.2e-7 rad measured), used for poses only with
        #   pose_path="link-frame".
        #   The diagonalisation stops at 1e-6 × the trace, so the change, relative to the largest
        #   element (layer 1's measure), can exceed 1e-6: the inertia tolerance is the largest change
        #   Bullet's own algorithm makes to a tensor of the file (bullet_inertia, emulated exactly;
        #   TIAGo's wheel: 1.21e-6), plus 1e-9 of rounding, and never below 1e-6.
        tolerances: dict[str, float] = {}
        if any(not np.allclose(d["inertial_orn"], (0.0, 0.0, 0.0, 1.0), rtol=0.0, atol=1e-15) for d in dyn):
            tolerances.update({"inertia": max(1e-6, _largest_diagonalisation_change(Path(urdf)) + 1e-9),
                               "mass-matrix": 1e-6, "bias": 1e-6})
        if pose_path == "link-frame":
            tolerances["pose"] = 1e-6
        if tolerances:
            self.settings["tolerances"] = tolerances

    def _world_joint(self, root: str) -> str | None:
        """The fixed joint from the base link ``world`` to ``root``, when the file welds it so."""
        if self.base != WORLD_LINK or root == WORLD_LINK:
            return None
        return next((str(j["name"]) for j in self._joints
                     if j["parent"] == -1 and j["child"] == root and self._types.get(j["type"]) == "fixed"),
                    None)

    def _robots(self, name: str) -> bool:
        """Whether the link ``name`` is the robot's (not the file's ``world``)."""
        return self.world_joint is None or name != WORLD_LINK

    def diagonalised_inertials(self) -> dict[str, tuple[float, Array, Array, Array]]:
        """The links whose URDF inertia PyBullet's importer diagonalised (products of inertia: its
        inertial frame is rotated), as PyBullet holds them: mass, COM in the link frame, principal
        moments, and the rotation of the principal axes (quaternion xyzw). The diagonalisation stops
        at a threshold of 1e-6 (see the tolerances above), so this is PyBullet's own approximation of
        the file's tensor."""
        out = {}
        identity = (0.0, 0.0, 0.0, 1.0)
        for name, d in self._dynamics.items():
            # a tensor the importer refused is held as zero about unturned axes: kept here too, so that
            # the replay gives MuJoCo the same zero (Robotiq 2F-85's knuckles, refused by rounding)
            refused = float(d["mass"]) > 0.0 and not np.any(np.asarray(d["inertia_diagonal"], dtype=float))
            if name == self.base or (np.allclose(d["inertial_orn"], identity, rtol=0.0, atol=1e-15)
                                     and not refused):
                continue
            out[name] = (float(d["mass"]), np.asarray(d["inertial_pos"], dtype=float),
                         np.asarray(d["inertia_diagonal"], dtype=float),
                         np.asarray(d["inertial_orn"], dtype=float))
        return out

    # ---- EngineModel --------------------------------------------------------------------------

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        facts = StaticFacts()
        for name, d in self._dynamics.items():
            if not self._robots(name):
                continue
            rot = self._inertial[name].rotation
            inertia = rot @ np.diag(np.asarray(d["inertia_diagonal"], dtype=float)) @ rot.T
            facts.links[name] = LinkFacts(float(d["mass"]), np.asarray(d["inertial_pos"], dtype=float),
                                          0.5 * (inertia + inertia.T))
        for j in self._joints:
            if j["name"] == self.world_joint:
                continue
            kind = self._types.get(j["type"], f"type-{j['type']}")
            moves = kind in ("revolute", "prismatic")
            axis = np.zeros(3)
            if moves:
                axis = self._inertial[j["child"]].rotation @ np.asarray(j["axis"], dtype=float)
                axis = axis / float(np.linalg.norm(axis))
            lower, upper = float(j["lower"]), float(j["upper"])
            if not moves or lower > upper:  # PyBullet stores a continuous joint as lower 0 > upper -1
                lower, upper = -math.inf, math.inf
            facts.joints[j["name"]] = JointFacts(
                kind, self._links[j["parent"] + 1], j["child"], axis, lower, upper)
        facts.shapes = self.shapes()
        return facts

    def shapes(self) -> dict[str, list[ShapeFacts]]:
        """Collision shapes per link from ``getCollisionShapeData``, moved from the link's inertial
        frame (where PyBullet gives them) into the URDF link frame; sizes in the model's convention
        (PyBullet's cylinder and capsule dimensions are (length, radius))."""
        raw = self._worker.request("shapes", timeout=self.timeout)
        out: dict[str, list[ShapeFacts]] = {}
        for index, (name, shapes) in enumerate(zip(self._links, raw, strict=True)):
            inertial = self._base_inertial if index == 0 else self._inertial[name]
            found = out.setdefault(name, [])
            for kind, dims, _file, pos, orn in shapes:
                d = np.asarray(dims, dtype=float)
                size = {"sphere": d[:1], "cylinder": d[[1, 0]], "capsule": d[[1, 0]]}.get(kind, d)
                found.append(ShapeFacts(kind, size, inertial @ _pose(pos, orn)))
        return out

    def _q_vector(self, q: dict[str, float]) -> list[float]:
        return [float(q.get(name, 0.0)) for name in self._dofs]

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        raw = self._worker.request("poses", timeout=self.timeout, q=self._q_vector(q))
        base = _pose(*raw["base"]) @ self._base_inertial.inverse()
        world: dict[str, Pose] = {self.base: base}
        for name, (com_pos, com_orn, link_pos, link_orn) in zip(self._links[1:], raw["links"], strict=True):
            if self.pose_path == "com-frame":
                world[name] = _pose(com_pos, com_orn) @ self._inertial[name].inverse()
            else:
                world[name] = _pose(link_pos, link_orn)
        to_root = world[self.root].inverse()
        return {name: to_root @ pose for name, pose in world.items() if self._robots(name)}

    def mass_matrix(self, q: dict[str, float]) -> Array:
        if not self._through_stepping():
            try:
                m = self._worker.request("mass_matrix", timeout=self.timeout, q=self._q_vector(q))
                return np.asarray(m, dtype=float).reshape(len(self._dofs), len(self._dofs))
            except PyBulletError as exc:
                self._step_instead(exc)
        return self._stepped_mass_matrix(self._q_vector(q))

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        """Gravity + Coriolis/centrifugal: inverse dynamics at zero acceleration."""
        n = len(self._dofs)
        if not self._through_stepping():
            try:
                tau = self._worker.request("inverse_dynamics", timeout=self.timeout, q=self._q_vector(q),
                                           dq=self._q_vector(dq), ddq=[0.0] * n)
                return np.asarray(tau, dtype=float)
            except PyBulletError as exc:
                self._step_instead(exc)
        # qdd0 = M⁻¹ (0 − b): b = −M qdd0, with M from the same forward dynamics.
        position, velocity = self._q_vector(q), self._q_vector(dq)
        free = self._worker.request("accelerations", timeout=self.timeout, q=position, dq=velocity,
                                    torques=[[0.0] * n], gravity=True, step=FORWARD_STEP)
        return -self._stepped_mass_matrix(position) @ np.asarray(free[0], dtype=float)

    def _through_stepping(self) -> bool:
        return "dynamics_path" in self.settings

    def _step_instead(self, exc: PyBulletError) -> None:
        """After PyBullet's inverse dynamics refused a tensor it composed itself (``REFUSED_TENSOR``),
        the mass matrix and bias come from its forward dynamics, said in ``settings``; any other
        failure is the engine's finding and propagates."""
        if PLANAR_REFUSED in str(exc):
            raise NotImplementedError(
                "PyBullet's inverse dynamics (calculateMassMatrix, calculateInverseDynamics) has no planar "
                f"joint ({PLANAR_REFUSED!r}), and its forward dynamics would let the planar base move: no "
                "mass matrix or bias from it") from exc
        found = REFUSED_TENSOR.search(str(exc))
        if found is None:
            raise exc
        body, which, off = found.groups()
        # btInverseDynamics numbers the base 0 and link i of PyBullet i + 1, as ``_links`` does
        link = self._links[int(body)] if int(body) < len(self._links) else f"body {body}"
        self.settings["dynamics_path"] = (
            f"mass matrix and bias from PyBullet's forward dynamics (one {FORWARD_STEP:g} s stepSimulation "
            f"per column, gravity and velocity off, M = (its accelerations)⁻¹; b = −M·qdd at zero torque): "
            "its inverse-dynamics library (calculateMassMatrix, calculateInverseDynamics) refused the tensor "
            f"it composed for {link} ({which}, off by {float(off):.3g} kg·m², its fixed bound 1.1e-15: "
            "the rounding of a heavy link's rotated tensor, not the file)")

    def _stepped_mass_matrix(self, q: list[float]) -> Array:
        n = len(self._dofs)
        unit = np.eye(n).tolist()
        columns = self._worker.request("accelerations", timeout=self.timeout, q=q, dq=[0.0] * n,
                                       torques=unit, gravity=False, step=FORWARD_STEP)
        inverse = np.asarray(columns, dtype=float).T
        m = np.linalg.inv(inverse)
        return 0.5 * (m + m.T)

    # ---- Simulator ----------------------------------------------------------------------------

    def law_vectors(self, law: TorqueLaw) -> dict[str, list[float]]:
        """The law's gains in this engine's dof order (a joint the law does not name gets none)."""
        written = self.renames.get("joint", {})
        by_name = {written.get(j, j): i for i, j in enumerate(law.joints)}
        missing = [j for j in law.joints if written.get(j, j) not in self._dofs]
        if missing:
            raise PyBulletError(f"the torque law names joints PyBullet does not move: {', '.join(missing)}")
        out: dict[str, list[float]] = {}
        for key in ("kp", "kd", "amplitude", "frequency", "phase"):
            values = getattr(law, key)
            out[key] = [float(values[by_name[d]]) if d in by_name else 0.0 for d in self._dofs]
        return out

    def replay(self, law: TorqueLaw, seconds: float, dt: float) -> Array:
        """q after every step from q = dq = 0: (steps + 1, len(law.joints)), one column per
        ``law.joints`` entry (source names, mapped through the renames), in that order. Joints the
        law does not name get no torque. ``last_replay_wall`` keeps the stepping loop's wall time."""
        steps = round(seconds / dt)
        written = self.renames.get("joint", {})
        columns = [self._dofs.index(written.get(j, j)) for j in law.joints]
        # a ball joint (renamed per entry NAME#x... to the URDF writer's chain joints, MK813): its three
        # joints' positions here, which must follow one another (the chain is written that way)
        balls = [columns[c:c + 3] for _, c in law.ball_columns()]
        extra = {"balls": balls} if balls else {}
        slower = 5.0 if balls else 1.0  # the ball's law is computed in Python every step
        result = self._worker.request("replay", timeout=max(self.timeout, 20.0 * seconds * slower),
                                      steps=steps, dt=dt, **self.law_vectors(law), **extra)
        self.last_replay_wall = float(result["wall"])
        q = np.frombuffer(result["q"], dtype=np.float64).reshape(steps + 1, len(self._dofs))
        out = q[:, columns].copy()
        for _, c in law.ball_columns():  # the chain's three angles → the rotation vector
            out[:, c:c + 3] = [ball_law.rotation_log(ball_law.chain_matrix(*row)) for row in out[:, c:c + 3]]
        return out

    def bench(self, seconds: float, dt: float) -> dict[str, float]:
        """Wall seconds of a bare ``stepSimulation`` loop and of a minimal closed loop (read states,
        send torques, step) over ``seconds`` of simulated time, in the child."""
        out = self._worker.request("bench", timeout=max(self.timeout, 20.0 * seconds),
                                   steps=round(seconds / dt), dt=dt)
        return {k: float(v) for k, v in out.items()}

    def alive(self) -> bool:
        """Whether the child process still runs (it ends at :meth:`close`, or when PyBullet crashed)."""
        return self._worker.alive()

    def close(self) -> None:
        self._worker.close()

    def __enter__(self) -> PyBulletModel:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# PyBullet answers getJointState for a multibody of at most 127 joints, fixed ones included (the URDF
# writer's MK862 says so for a file it writes).
MAX_MOVING_JOINTS = PYBULLET_MAX_JOINTS


class TooManyJoints(PyBulletError):
    """The URDF has more joints than PyBullet reports states for."""

    engine_limit = True  # verify reports a skip, not a failed load


PLANAR_REFUSED = "planar joints not implemented"  # btMultiBodyTreeCreator, PyBullet's inverse dynamics


class PlanarJoint(PyBulletError):
    """The URDF has a planar joint, whose child PyBullet's URDF importer places by the child's centre of
    mass instead of its link frame."""

    engine_limit = True  # verify reports a skip, not a failed load


class FloatingJoint(PyBulletError):
    """The URDF has a floating joint, which PyBullet's URDF importer welds."""

    engine_limit = True  # verify reports a skip, not a failed load


def _check_size(model: Path) -> None:
    """What PyBullet cannot hold as the file says, raised before it loads (each an engine limit): more
    joints than it reports states for, a floating joint (PyBullet welds it), or a planar joint whose
    child's centre of mass is off its link frame. At zero coordinates PyBullet puts that centre of mass
    where the child's link frame belongs, so the child and everything below it are off by the offset
    (Hello Robot's Stretch 4: 9.6 cm; a fixed joint in its place is right, and so is a planar child
    whose COM is at its frame)."""
    from lxml import etree

    try:
        root = etree.parse(str(model)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return  # PyBullet's own load says what is wrong with the file
    joints = list(root.iterchildren("joint"))
    if len(joints) > MAX_MOVING_JOINTS:
        raise TooManyJoints(f"{len(joints)} joints: PyBullet reports the joint states of a body of at most "
                            f"{MAX_MOVING_JOINTS} joints, fixed ones included (getJointState fails for "
                            "every joint beyond that)")
    floating = next((j for j in joints if j.get("type") == "floating"), None)
    if floating is not None:
        raise FloatingJoint(f"joint {floating.get('name')} is floating: PyBullet's URDF importer welds it "
                            "(\"joint unsupported, creating a fixed joint instead\"), so its child does not "
                            "move as the file says (validate's MK213)")
    planar = next((j for j in joints if j.get("type") == "planar" and _com_off(root, j)), None)
    if planar is not None:
        raise PlanarJoint(f"joint {planar.get('name')} is planar and its child's centre of mass is off its "
                          "link frame: PyBullet's URDF importer places a planar joint's child by its centre "
                          "of mass instead of its link frame, so the child and every link below it are off "
                          "by that offset (validate's MK327)")


def _com_off(root: Any, joint: Any) -> bool:
    """Whether the URDF ``joint``'s child link has its inertial origin off its link frame."""
    child = joint.find("child")
    name = child.get("link") if child is not None else None
    link = next((e for e in root.iterchildren("link") if e.get("name") == name), None)
    origin = link.find("inertial/origin") if link is not None else None
    try:
        xyz = [float(v) for v in (origin.get("xyz") or "0 0 0").split()] if origin is not None else []
    except ValueError:
        return False
    return any(abs(v) > 1e-9 for v in xyz)


def load(model: Path, renames: Renames, *, root: str, pose_path: str = "com-frame",
         timeout: float = DEFAULT_TIMEOUT) -> PyBulletModel:
    """The engine plug-in entry point (see ``modelkit.verify.api``)."""
    if not isinstance(model, (str, Path)):
        raise PyBulletError("PyBullet reads a URDF file, not an in-memory model")
    _check_size(Path(model))
    return PyBulletModel(Path(model), renames, root, pose_path=pose_path, timeout=timeout)


def render(urdfs: dict[str, Path], configurations: list[dict[str, float]], camera: dict[str, Any],
           timeout: float = DEFAULT_TIMEOUT) -> dict[tuple[str, int], tuple[Any, Any]]:
    """TinyRenderer pictures for the report (``modelkit.verify.report.pictures``), in a child worker of its
    own: (view, configuration index) → (RGB (H, W, 3) uint8, robot mask (H, W) bool). Joint names
    are the URDF's."""
    worker = _worker()
    try:
        paths = {k: str(Path(v).resolve()) for k, v in urdfs.items()}
        raw = worker.request("render", timeout=timeout, paths=paths, configurations=configurations,
                             camera=camera)
    finally:
        worker.close()
    h, w = int(camera["height"]), int(camera["width"])
    out: dict[tuple[str, int], tuple[Any, Any]] = {}
    for item in raw:
        rgba = np.frombuffer(item["rgba"], dtype=np.uint8).reshape(h, w, 4)
        seg = np.frombuffer(item["seg"], dtype=np.int32).reshape(h, w)
        out[(item["view"], int(item["config"]))] = (rgba[:, :, :3].copy(), seg >= 0)
    return out


def simulator(model: Path, renames: Renames, *, root: str, dt: float,
              timeout: float = DEFAULT_TIMEOUT, loaded: object = None) -> PyBulletModel:
    """Layer 3b's entry point: the same adapter, time step ``dt``. ``loaded``: the model layers 1-3
    loaded; when it holds the same file at the same time step its child process is reused (a process
    start and PyBullet's import, ≈ 0.2 s, is most of the replay's wall time on a small robot): layers
    1-3 only set joint states and never step, and the replay starts from a reset of every joint's
    position and velocity and of the time step."""
    _check_size(Path(model))
    if (isinstance(loaded, PyBulletModel) and loaded.path == Path(model).resolve() and loaded.dt == dt
            and loaded.renames == renames and loaded.alive()):
        return loaded
    return PyBulletModel(Path(model), renames, root, dt=dt, timeout=timeout)


# ---- layer 4: the floating-base robot driven on a floor ----------------------------------------

SOLVER_ITERATIONS = 50
TRACK_SOLVER_ITERATIONS = PYBULLET_SOLVER_ITERATIONS
"""numSolverIterations for a tracked robot: what the URDF's MK809 note asks a PyBullet user to set
(``convert.tracks.PYBULLET_SOLVER_ITERATIONS``: at 50 a skidding roller's motor stays unconverged
and loses speed; measured on the tutorial's spin 0.31 rad behind, at 200 still 0.023 rad on the arc
against the 0.02 rad wheel-angle tolerance, at 400 and 700 within 0.004 rad)."""
FLOOR_FRICTION = 1.0
DEFAULT_LINK_FRICTION = 1.0  # a link the URDF gives no friction: MuJoCo's default geom friction
FLOOR = "plane.urdf"
"""Layer 4's floor: pybullet_data's plane.urdf as shipped (what a user loads)."""
ANALYTIC_FLOOR = "analytic"
"""A GEOM_PLANE body of lateral friction 1 (plane.urdf's), for the tests that compare two control
paths to round-off: plane.urdf's collision is a 200 m box, and Bullet's box–sphere contact amplifies
a one-ulp torque difference to 1e-5 m over 10 s (measured), where the analytic plane keeps it at
1e-13; the floor is not what those tests are about."""


def urdf_friction(path: Path) -> dict[str, float]:
    """Link → friction as the URDF writer wrote it (``<gazebo reference="link"><mu1>``: the link's
    contact material against the floor material); PyBullet itself ignores those elements."""
    from lxml import etree

    out: dict[str, float] = {}
    for gazebo in etree.parse(str(path)).getroot().iter("gazebo"):
        reference, mu = gazebo.get("reference"), gazebo.find("mu1")
        if reference and mu is not None and mu.text:
            out[reference] = float(mu.text)
    return out


class PyBulletDriver:
    """The written floating-base URDF on a floor in the PyBullet child, verification.md §6's
    settings and every §2.8 pitfall handled, the seed's controllers built **in the child** from plain
    data (``make_controllers(drive.as_dict(), scenario_dict)``) and run every step there:
    :class:`modelkit.verify.drive.Driver`, plus :meth:`start`/:meth:`result` to run profiles while
    the parent does something else (MuJoCo)."""

    engine = "pybullet"

    def __init__(self, model: Path, renames: Renames, drive: Any, scenario: Any, factory: str | None = None,
                 sys_path: list[str] | None = None, timeout: float = DEFAULT_TIMEOUT,
                 fast: bool = True, floor: str = FLOOR) -> None:
        from modelkit.verify.drive import variant as v

        self.fast = fast
        self.path = Path(model)
        self.renames = renames
        self.drive = drive
        self.timeout = timeout
        self.dt = float(scenario.dt)
        self.factory = factory or v.CONTROLLERS
        self.friction = urdf_friction(self.path)
        # The engine setting a user sets for this robot (the URDF's MK825 note; a URDF cannot carry it).
        from modelkit.convert.tracks import PYBULLET_CONE_FRICTION

        self.engine_parameters = ({"enableConeFriction": PYBULLET_CONE_FRICTION} if drive.kind == "tracks"
                                  else {})
        self.solver_iterations = TRACK_SOLVER_ITERATIONS if drive.kind == "tracks" else SOLVER_ITERATIONS
        joint_names = dict(renames.get("joint", {}))
        for rollers in drive.rollers.values():
            for j in rollers:
                joint_names.setdefault(j, j)
        self._worker = _worker()
        self._pending: tuple[int, list[Any], Any, Any] | None = None
        try:
            info = self._worker.request(
                "drive_setup", timeout=timeout, path=str(self.path.resolve()), gravity=GRAVITY, dt=self.dt,
                solver_iterations=self.solver_iterations, friction=self.friction,
                default_friction=DEFAULT_LINK_FRICTION, floor_friction=FLOOR_FRICTION,
                contact_joints=[joint_names.get(j, j) for j in self._contact_joints(drive)],
                contact_friction=scenario.friction,
                drive=drive.as_dict(), scenario=v.scenario_data(scenario), factory=self.factory,
                joint_names=joint_names, roller_radius=drive.roller_radius or drive.radius, sys_path=sys_path,
                engine_parameters=self.engine_parameters, floor=floor)
        except BaseException:
            self._worker.close()
            raise
        self.controllers = info["controllers"]
        controlled = [j for _, _, joints in self.controllers for j in joints]
        self.recorded = sorted(set(controlled) | set(v.wheel_joints(drive)))
        velocity = any(mode == "velocity" for _, mode, _ in self.controllers)
        self.settings: dict[str, Any] = {
            "version": "pybullet (child process)", "file": self.path.name, "useFixedBase": False,
            "flags": "URDF_USE_INERTIA_FROM_FILE|URDF_USE_IMPLICIT_CYLINDER", "gravity": [0.0, 0.0, GRAVITY],
            "timestep": self.dt, "numSolverIterations": self.solver_iterations,
            "enableConeFriction": (f"{self.engine_parameters['enableConeFriction']} (the setting the "
                                   "URDF's MK825 note names for tracks)"
                                   if self.engine_parameters else "default (1)"),
            "damping": ("linearDamping, angularDamping (PyBullet's own default 0.04, no URDF field) and "
                        "jointDamping 0 on every link: the only changeDynamics on the robot"
                        + ("; while a profile's commands run, the torque-law joints' jointDamping is the "
                           "controller's gain (the law's −gain·q̇, see control), nothing else"
                           if fast else "")),
            "default_motors": ("off (VELOCITY_CONTROL force 0) on the driven and the unbounded joints; "
                               "kept (velocity 0, force the URDF effort: what a user's world has) on the "
                               "bounded joints nothing drives: " + ", ".join(info["held"])
                               if info.get("held") else "off (VELOCITY_CONTROL force 0)"),
            "torque": "TORQUE_CONTROL re-sent before every stepSimulation",
            "control": self._control_setting(fast),
            "velocity_servo": ("VELOCITY_CONTROL (a velocity constraint), max force "
                               f"{info['servo_limit']:.4g} "
                               "N·m (SERVO_FRICTION_SHARE·m·g·μ·r / rollers, as MuJoCo's bound), "
                               "on every roller of a track "
                               "with "
                               "roller 0's target; the rollers of a track coupled by a JOINT_GEAR constraint "
                               "(ratio −1: equal speeds), the URDF's <mimic> that PyBullet ignores")
            if velocity else "none",
            "floor": ("pybullet_data's plane.urdf as shipped (lateral_friction 1)" if floor == FLOOR
                      else "an analytic GEOM_PLANE of lateral friction 1 (a test of the control path)"),
            "friction": dict(sorted(info["friction"].items())),
            "friction_rule": "Bullet multiplies the two bodies' values: plane.urdf's 1 × the link's",
            "friction_source": "the URDF as written: each link's <contact> (the contact materials against "
                               "the floor), PyBullet's default for a link without",
            "rolling_spinning": "the URDF's <contact> values",
            "base_pose": "getBasePositionAndOrientation (COM frame) moved to the root link frame with "
                         "getDynamicsInfo(-1)[3:5] (the local inertial frame)",
            "start_height": info["start_height"],
            "settle": "zero torque; velocity servos held at 0",
            "per_run": "resetSimulation and a fresh load (every run starts from the same state)",
            "controllers": [f"{name} ({mode}: {', '.join(joints)})"
                            for name, mode, joints in self.controllers],
            "process": ("child process (modelkit/verify/engines/pybullet_worker.py); "
                        "controllers built in the child"),
        }
        self.last_wall: list[float] = []

    @staticmethod
    def _contact_joints(drive: Any) -> list[str]:
        """The joints whose child links roll on the floor: the wheels, or every track roller."""
        if drive.kind == "wheels":
            return [drive.left, drive.right]
        return [j for rollers in drive.rollers.values() for j in rollers]

    def start(self, profiles: list[Any], scenario: Any, drive: Any) -> None:
        """Send the profiles to the child and return at once; :meth:`result` collects them."""
        from modelkit.verify.drive import variant as v

        if self._pending is not None:
            raise RuntimeError("a batch is still running; collect it with result() first")
        every = max(1, round(1.0 / (scenario.sample_rate * self.dt)))
        budget = self.timeout + sum(20.0 * (p.duration + p.settle) for p in profiles)
        printed = self._worker.send("drive_batch", runs=[
            {"profile": v.profile_data(p), "sample_every": every, "recorded": self.recorded,
             "fast": self.fast} for p in profiles])
        self._pending = (printed, list(profiles), every, budget)

    def result(self) -> list[Any]:
        """The trajectories of the batch :meth:`start` sent, in its order."""
        if self._pending is None:
            raise RuntimeError("nothing started")
        printed, profiles, every, budget = self._pending
        self._pending = None
        raw = self._worker.receive("drive_batch", printed, budget)
        self.last_wall = [float(r["wall"]) for r in raw]
        self.last_law = [str(r.get("law", "per-step")) for r in raw]
        return [self._trajectory(p, r, every) for p, r in zip(profiles, raw, strict=True)]

    def run(self, profile: Any, scenario: Any, drive: Any) -> Any:
        self.start([profile], scenario, drive)
        return self.result()[0]

    def _trajectory(self, profile: Any, raw: dict[str, Any], every: int) -> Any:
        from modelkit.verify.drive import variant as v

        base = np.frombuffer(raw["base"], dtype=np.float64).reshape(-1, 7)
        q = np.frombuffer(raw["q"], dtype=np.float64).reshape(len(base), len(self.recorded))
        inertial = _pose(*raw["base_inertial"]).inverse()
        rotations: Array = np.empty((len(base), 3, 3))
        positions: Array = np.empty((len(base), 3))
        for i, row in enumerate(base):
            link = _pose(tuple(row[:3]), tuple(row[3:])) @ inertial  # COM frame → the URDF link frame
            rotations[i], positions[i] = link.rotation, link.translation
        times: Array = np.arange(len(base), dtype=np.float64) * (every * self.dt)
        out = v.planar("pybullet", profile, "", times, positions, rotations,
                       {name: q[:, i].copy() for i, name in enumerate(self.recorded)},
                       v.wheel_joints(self.drive), self.drive.heading)
        out.settings = dict(self.settings)
        out.support = {str(k): float(f) for k, f in raw.get("support", {}).items()}
        if raw.get("law") == "per-step" and self.fast:
            out.settings["control"] = self._control_setting(False)  # a controller without an affine law
        return out

    @staticmethod
    def _control_setting(fast: bool) -> str:
        if not fast:
            return ("per step: the controllers' output every step from getJointStates, torques through "
                    "TORQUE_CONTROL, velocity targets through VELOCITY_CONTROL, both re-sent before every "
                    "stepSimulation")
        return ("affine laws u = offset − gain·q̇ applied by Bullet (when every controller has affine_law): "
                "−gain·q̇ as the law joints' jointDamping (changeDynamics; PyBullet applies −d·q̇ explicitly "
                "before every step from the step's starting velocity), set to the gain while a profile's "
                "commands run, 0 while settling and on every other joint; offset through TORQUE_CONTROL "
                "re-sent before every stepSimulation (none sent while it is 0); velocity targets through "
                "VELOCITY_CONTROL at command changes (the motor persists); states read at samples only. "
                "The same physics as calling the controllers every step to round-off")

    def bench(self, seconds: float, command: Any = None) -> dict[str, float]:
        """Wall seconds of a bare ``stepSimulation`` loop on this world (floating robot on the floor)
        and of a minimal closed loop, at ``command`` (a :class:`~modelkit.verify.drive.Command`; None:
        v 0.3, w 0.5): the worker's ``drive_bench``."""
        import dataclasses

        data = dataclasses.asdict(command) if command is not None else None
        out = self._worker.request("drive_bench", timeout=self.timeout + 20.0 * seconds,
                                   steps=round(seconds / self.dt), at=data)
        return {k: float(x) for k, x in out.items()}

    def close(self) -> None:
        self._worker.close()


def driver(model: Path, renames: Renames, *, drive: Any, scenario: Any, factory: str | None = None,
           sys_path: list[str] | None = None, timeout: float = DEFAULT_TIMEOUT, fast: bool = True,
           floor: str = FLOOR) -> PyBulletDriver:
    """Layer 4's entry point (:class:`modelkit.verify.drive.Driver`, plus ``start``/``result``).
    ``fast`` False: the controllers' ``output`` every step even when they have affine laws (the
    reference the fast path is tested against, ``tests/test_verify_drivers_pybullet_fast.py``).
    ``floor``: :data:`FLOOR` (layer 4's) or :data:`ANALYTIC_FLOOR` (see there; tests only). Raises
    :class:`TooManyJoints` for a URDF whose joint states PyBullet cannot report."""
    _check_size(Path(model))
    return PyBulletDriver(Path(model), renames, drive, scenario, factory, sys_path, timeout, fast, floor)
