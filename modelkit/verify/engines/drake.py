"""Drake adapter: our written SDF (engine "drake") or URDF ("drake-urdf") in a continuous
``MultibodyPlant``, so that the SDF output is read by a real SDF consumer (Drake parses SDFormat
with libsdformat).

Loading: ``MultibodyPlant(time_step=0)`` (continuous: no discrete solver, no contact), no
``SceneGraph`` (the shapes are parsed and checked by the parser, not registered: layers 1–3 need
no geometry), gravity (0, 0, −9.81). The root is welded to the world at the identity: a joint the
file itself declares between the world and the root (SDF ``<joint>`` to ``world``, URDF ``world``
link) is removed with ``RemoveJoint`` and replaced by ``WeldFrames(world, root, identity)``, which
is also what a free root gets, unless it is a weld without rotation, which is kept
(:func:`_unrotated_weld`); then the plant is finalized. The base weld is not reported as a
joint (the source's root joint is not a tree joint either). A root named ``world`` (the MJCF
reader's synthesised link that top-level bodies hang from by their joints, or a URDF ``world``
link) is Drake's world body itself: nothing is welded, the file's joints to it are the model's
joints, and it is not reported as a link (as an SDF world frame is no link of the model).

Facts, in the file's names (Drake scopes names by model instance; one model is loaded, so the
unscoped ``body.name()`` / ``joint.name()`` are the written names):

* mass, COM and inertia: ``RigidBody.default_spatial_inertia()`` (about the body origin, body
  axes), shifted to the COM (``Shift(p_BoBcm)``), rotational inertia as a full 3×3;
* joint type (``type_name``: ``weld`` → ``fixed``, ``ball_rpy`` → ``ball``, …), axis in the child
  link frame (``revolute_axis()`` / ``translation_axis()`` is expressed in the joint's frames F and
  M, which coincide at q = 0; rotated by M's fixed pose in the child body), position limits.
  SDFormat writes an unlimited joint as ±1e16 (its documented "no limit" default before 1.10) and
  Drake keeps the number: in an SDF file a bound of magnitude ≥ 1e16 is reported as ±inf, as URDF
  ``continuous`` is. A URDF's bounds are reported as parsed: its ±1e16 is the URDF writer's stand-in
  for an unlimited prismatic joint (MK819), which layer 1 compares as a documented approximation;
* an SDF ``<frame attached_to>`` (how the SDF writer keeps a massless leaf link) is a frame in
  Drake, not a body: it is reported as a massless link with its pose, and a fixed joint
  ``fixed:NAME`` to what it is attached to (the fixed joint the link hung from);
* poses: ``EvalBodyPoseInWorld`` (frames: ``CalcPoseInWorld``), relative to the root;
* mass matrix: ``CalcMassMatrix`` (no reflected inertia unless the file declares one);
* bias: ``CalcBiasTerm`` − ``CalcGravityGeneralizedForces``. Drake's equations of motion are
  M v̇ + C(q, v) v = τ_g(q) + τ: ``CalcBiasTerm`` is C v only (no gravity) and τ_g is on the force
  side. MuJoCo's ``qfrc_bias`` solves M q̈ + qfrc_bias = τ, so qfrc_bias = C v − τ_g (checked to
  1e-12 against ``mj_rne`` in the tests), which is what ``bias`` returns.

Drake only warns about some defects (an invalid inertia, for one: the link is then loaded with
what Drake made of it); every warning it logs while parsing is kept in ``warnings`` and
``settings["parser_warnings"]``, for the report.

Generalised coordinates: with the base welded every remaining joint has ``num_positions`` equal to
``num_velocities``; ``dof_names`` lists the 1-DOF joints by ``position_start()`` (equal to
``velocity_start()`` here, checked at load).
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    BallRpyJoint,
    Frame,
    Joint,
    JointIndex,
    ModelInstanceIndex,
    PrismaticJoint,
    RevoluteJoint,
    RigidBody,
    RotationalInertia,
)

from modelkit.model import BALL_KEYS, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines import ball_law
from modelkit.verify.engines.child import serve
from modelkit.verify.engines.drake_child import (
    LOOP_MESSAGE,
    REVERSED_RANGE_REFUSAL,
    DrakeLoadError,
    DrakeLoopError,
)
from modelkit.verify.engines.protocol import Array, JointFacts, LinkFacts, StaticFacts

Renames = dict[str, dict[str, str]]
GRAVITY = (0.0, 0.0, -9.81)
SDF_UNLIMITED = 1e16  # SDFormat's default joint limit, meaning "no limit"
WORLD = "world"  # Drake's world body's name (a URDF link or SDF frame of that name is the world)
_TYPES = {
    "revolute": "revolute",
    "prismatic": "prismatic",
    "weld": "fixed",
    "ball_rpy": "ball",
    "quaternion_floating": "floating",
    "rpy_floating": "floating",
    "planar": "planar",
    "universal": "universal",
    "screw": "screw",
}


def _unrotated_weld(joint: Any) -> bool:
    """Whether ``joint`` welds its child without rotating it (a URDF ``world`` link's fixed joint, what
    ``convert --base fixed`` writes at the root's pose). Such a weld is kept rather than replaced by
    the identity: poses are taken relative to the root and gravity points the same way in its frame,
    so the layers see the same robot, and Drake cannot remove a joint once its URDF parser added a
    constraint (a mimic joint's coupler: example-robot-data's Panda given as convert's URDF)."""
    if joint.type_name() != "weld":
        return False
    parent = joint.frame_on_parent().GetFixedPoseInBodyFrame().rotation().matrix()
    child = joint.frame_on_child().GetFixedPoseInBodyFrame().rotation().matrix()
    rotation = parent @ joint.X_FM().rotation().matrix() @ child.T
    return bool(np.abs(rotation - np.eye(3)).max() <= 1e-12)


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("drake")
    except Exception:  # pragma: no cover - a source build has no distribution metadata
        return "unknown"


def _pose(transform: RigidTransform) -> Pose:
    rotation = np.array(transform.rotation().matrix(), dtype=float)
    return Pose(rotation, np.array(transform.translation(), dtype=float))


def _vec(values: Any) -> Any:
    """A float64 array typed for pydrake's stubs (which expect ``ndarray[float64, ...]``)."""
    return np.asarray(values, dtype=np.float64)


def _limit(value: float) -> float:
    return math.copysign(math.inf, value) if abs(value) >= SDF_UNLIMITED else float(value)


def _sdf_frames(path: Path) -> dict[str, str]:
    """The model-level ``<frame>`` elements of an SDF file (massless links kept as frames, MK816):
    name → ``attached_to`` (the link or frame it hangs from; "" when the attribute is absent)."""
    tree = etree.parse(str(path))
    return {str(f.get("name")): str(f.get("attached_to") or "") for f in tree.iterfind("./model/frame")
            if f.get("name")}


class _Collect(logging.Handler):
    """Collects what Drake logs (through Python's ``drake`` logger) while it parses a file."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


def _parse(plant: MultibodyPlant, path: Path) -> tuple[list[ModelInstanceIndex], list[str]]:
    logger = logging.getLogger("drake")
    collect = _Collect()
    logger.addHandler(collect)
    # kept for the report, not printed: pydrake's own handler would put each on the terminal
    propagate, logger.propagate = logger.propagate, False
    own = [h for h in logger.handlers if h is not collect]
    for handler in own:
        logger.removeHandler(handler)
    try:
        instances = Parser(plant).AddModels(file_name=path)
    except Exception as exc:  # Drake raises RuntimeError with the parser's message
        raise DrakeLoadError(f"{path.name}: Drake could not parse the file: {exc}") from exc
    finally:
        logger.removeHandler(collect)
        for handler in own:
            logger.addHandler(handler)
        logger.propagate = propagate
    return list(instances), collect.messages



WATER_DENSITY = 1000.0  # kg/m³: the density of Drake's substitute sphere for an invalid URDF inertia


def substitute_moment(mass: float) -> float:
    """The moment of inertia (kg·m², each axis) Drake's URDF parser substitutes for an inertia that
    fails ``CouldBePhysicallyValid()`` (it warns, since Drake 1.16, PR #19238 "plausible-guess
    inertia"): a solid sphere of the link's mass and water's density, 2/5 m r², r = (3m / 4πρ)^(1/3).
    Measured: ClosedLinkSample's WAIST (27 kg) reads back 0.374059359 on every axis."""
    radius = (3.0 * mass / (4.0 * math.pi * WATER_DENSITY)) ** (1.0 / 3.0)
    return 0.4 * mass * radius * radius


def accepts_inertia(tensor: np.ndarray) -> bool:
    """Whether Drake's URDF parser keeps ``tensor`` (3 × 3, about the COM): Drake's own
    ``RotationalInertia.CouldBePhysicallyValid()``, whose triangle inequality allows 16 ε of the
    moments' size. Hello Robot's Stretch ``link_puller`` (principal moments 1.08e-15, 1.09317111e-7,
    1.09317112e-7: short by 5.3e-23) fails validate's exact test (MK303) and is kept by Drake."""
    t = np.asarray(tensor, dtype=float)
    inertia = RotationalInertia(t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])
    return bool(inertia.CouldBePhysicallyValid())


def invalid_inertia_note(link: str, moments: tuple[float, float, float], mass: float) -> str:
    """Why drake-urdf holds another tensor for a link whose source inertia violates the triangle
    inequality (the URDF keeps the source's tensor; the URDF writer does not repair it)."""
    a, b, c = moments
    return (f"Drake's URDF parser replaced the invalid tensor (it warns that it fails "
            f"CouldBePhysicallyValid()) by its plausible-guess inertia, a solid sphere of {mass:g} kg at "
            "water density, "
            f"{substitute_moment(mass):.9g} kg·m² per axis: the source inertia of {link} violates the "
            f"triangle inequality (principal moments {a:g} + {b:g} < {c:g}, MK303), so this is Drake "
            "refusing the source's data, not a conversion fault")

class DrakeModel:
    """One written file in a continuous Drake ``MultibodyPlant``, root welded at the identity."""

    def __init__(self, path: Path, root: str, engine: str) -> None:
        self.engine = engine
        self.path = path
        self._sdf = path.suffix.lower() == ".sdf"
        self.root = root
        plant = MultibodyPlant(time_step=0.0)
        instances, self.warnings = _parse(plant, path)
        if len(instances) != 1:
            raise DrakeLoadError(f"{path.name}: expected one model, Drake found {len(instances)}")
        self._instance: ModelInstanceIndex = instances[0]
        world = plant.world_body()
        # A root named "world" (URDF's convention, and the MJCF reader's synthesised link whose
        # top-level bodies hang from it by their joints) is Drake's own world body: Drake parses a
        # URDF link "world" and an SDF joint's parent "world" as the world, so there is no body of
        # that name in the model instance and nothing to weld; the file's joints to it are the model's.
        self._world_root = root == WORLD and not plant.HasBodyNamed(root, self._instance)
        removed: list[str] = []
        kept: str | None = None
        if self._world_root:
            root_body = world
        else:
            if not plant.HasBodyNamed(root, self._instance):
                names = sorted(plant.get_body(i).name() for i in plant.GetBodyIndices(self._instance))
                raise DrakeLoadError(f"{path.name}: no link named {root!r} (links: {', '.join(names)})")
            root_body = plant.GetBodyByName(root, self._instance)
            for index in list(plant.GetJointIndices()):
                joint = plant.get_joint(index)
                ends = {joint.parent_body().index(), joint.child_body().index()}
                if ends != {world.index(), root_body.index()}:
                    continue
                if _unrotated_weld(joint):
                    kept = joint.name()
                    continue
                removed.append(f"{joint.name()} ({joint.type_name()})")
                plant.RemoveJoint(joint)
            if kept is None:
                plant.WeldFrames(world.body_frame(), root_body.body_frame(), RigidTransform())
        plant.mutable_gravity_field().set_gravity_vector(_vec(GRAVITY))
        try:
            plant.Finalize()
        except RuntimeError as exc:
            if LOOP_MESSAGE in str(exc):
                raise DrakeLoopError(f"{path.name}: {exc}") from exc
            raise
        self.plant = plant
        self.context = plant.CreateDefaultContext()
        placed = self._place_urdf_free_bodies() if not self._sdf else []
        self._root_body: RigidBody = root_body
        self._bodies: dict[str, RigidBody] = {
            plant.get_body(i).name(): plant.get_body(i) for i in plant.GetBodyIndices(self._instance)
        }
        self._frames: dict[str, Frame] = {}
        self._frame_parent: dict[str, str] = {}
        if path.suffix.lower() == ".sdf":
            for name, attached_to in _sdf_frames(path).items():
                if name not in self._bodies and plant.HasFrameNamed(name, self._instance):
                    self._frames[name] = plant.GetFrameByName(name, self._instance)
                    self._frame_parent[name] = attached_to
        self._joints: list[Joint] = [
            plant.get_joint(i) for i in plant.GetJointIndices(self._instance) if not self._is_base_weld(i)
        ]
        dofs = [j for j in self._joints if isinstance(j, RevoluteJoint | PrismaticJoint)]
        dofs.sort(key=lambda j: j.velocity_start())  # a free body's quaternion shifts later positions
        self._dofs = dofs
        self._balls = [j for j in self._joints if isinstance(j, BallRpyJoint)]
        self.settings: dict[str, Any] = {
            "version": _version(),
            "file": path.name,
            "plant": "MultibodyPlant(time_step=0) (continuous), no SceneGraph",
            "base": ("the root is Drake's world body (the file's joints to 'world' are the model's)"
                     if self._world_root else
                     f"the file's weld {kept} to the world kept (no rotation: the same robot in the root's "
                     "frame)" if kept is not None else (
                         f"file's world joint removed ({', '.join(removed)}), " if removed else "free root, "
                     ) + f"WeldFrames(world, {root}, identity)"),
            "gravity": list(GRAVITY),
            "inertia": "default_spatial_inertia shifted to the COM",
            "limits": (f"|bound| >= {SDF_UNLIMITED:g} reported as inf (SDFormat's 'no limit')" if self._sdf
                       else "as parsed (a URDF's ±1e16 is the URDF writer's stand-in for no limit, MK819)"),
            "poses": "EvalBodyPoseInWorld, relative to the root",
            "mass_matrix": "CalcMassMatrix",
            "bias": "CalcBiasTerm - CalcGravityGeneralizedForces (MuJoCo qfrc_bias convention)",
            **({"free_bodies": "Drake's URDF parser leaves the child of a floating joint a free body at "
                               "the world origin (its warning); set where the file's joint origin puts "
                               "it at q = 0: " + ", ".join(placed)} if placed else {}),
            "nq": int(plant.num_positions()),
            "nv": int(plant.num_velocities()),
            "parser_warnings": list(self.warnings),
        }

    def _place_urdf_free_bodies(self) -> list[str]:
        """Drake's URDF parser leaves the child of a ``floating`` joint as a free body at the world
        origin ("not supported by MultibodyPlant. Leaving ... as a free body"), the joint's origin
        unread. Each such body is set, as a user sets a free body's initial pose, where the file puts
        it: its parent's pose at the default positions composed with the joint's origin."""
        plant = self.plant
        placed: list[str] = []
        if not plant.GetFloatingBaseBodies():  # the root is welded: only a floating joint leaves one
            return placed
        for joint in etree.parse(str(self.path)).iterfind("./joint[@type='floating']"):
            parent, child = joint.find("parent"), joint.find("child")
            if parent is None or child is None:
                continue
            names = (str(parent.get("link")), str(child.get("link")))
            if not all(plant.HasBodyNamed(name, self._instance) for name in names):
                continue
            body = plant.GetBodyByName(names[1], self._instance)
            if not body.is_floating_base_body():
                continue
            origin = joint.find("origin")
            xyz, rpy = (origin.get(key, "0 0 0") if origin is not None else "0 0 0" for key in ("xyz", "rpy"))
            offset = RigidTransform(RollPitchYaw(_vec([float(v) for v in rpy.split()])),
                                    _vec([float(v) for v in xyz.split()]))
            parent = plant.EvalBodyPoseInWorld(self.context, plant.GetBodyByName(names[0], self._instance))
            plant.SetDefaultFloatingBaseBodyPose(body, parent @ offset)
            placed.append(names[1])
        if placed:
            self.context = plant.CreateDefaultContext()
        return placed

    def _is_base_weld(self, index: JointIndex) -> bool:
        if self._world_root:
            return False
        joint = self.plant.get_joint(index)
        return (
            joint.parent_body().index() == self.plant.world_body().index()
            and joint.child_body().index() == self._root_body.index()
        )

    def dof_names(self) -> list[str]:
        return [j.name() for j in self._dofs]

    def static(self) -> StaticFacts:
        facts = StaticFacts()
        for name, body in self._bodies.items():
            inertia = body.default_spatial_inertia()
            com = np.array(inertia.get_com(), dtype=float)
            about_com = inertia.Shift(_vec(com)).CalcRotationalInertia().CopyToFullMatrix3()
            facts.links[name] = LinkFacts(float(inertia.get_mass()), com, np.array(about_com, dtype=float))
        for name in self._frames:
            facts.links[name] = LinkFacts(0.0, np.zeros(3), np.zeros((3, 3)))
            # The frame stands for a massless link on a fixed joint (MK816): reported as a link, so
            # its joint is reported too, fixed, to what the frame is attached to.
            facts.joints[f"fixed:{name}"] = JointFacts("fixed", self._frame_parent[name], name, np.zeros(3))
        for joint in self._joints:
            facts.joints[joint.name()] = self._joint_facts(joint)
        return facts

    def _joint_facts(self, joint: Joint) -> JointFacts:
        jtype = _TYPES.get(joint.type_name(), joint.type_name())
        parent, child = joint.parent_body().name(), joint.child_body().name()
        axis = np.zeros(3)
        lower, upper = -math.inf, math.inf
        if isinstance(joint, RevoluteJoint | PrismaticJoint):
            local = joint.revolute_axis() if isinstance(joint, RevoluteJoint) else joint.translation_axis()
            r_child_m = joint.frame_on_child().GetFixedPoseInBodyFrame().rotation().matrix()
            axis = np.array(r_child_m, dtype=float) @ np.array(local, dtype=float)
            lower = float(joint.position_lower_limits()[0])
            upper = float(joint.position_upper_limits()[0])
            if self._sdf:  # SDFormat's "no limit" (a URDF's ±1e16 is the URDF writer's MK819 stand-in)
                lower, upper = _limit(lower), _limit(upper)
        return JointFacts(jtype, parent, child, axis, lower, upper)

    def _set(self, q: dict[str, float], dq: dict[str, float] | None = None) -> None:
        plant, context = self.plant, self.context
        positions = np.array(plant.GetDefaultPositions(), dtype=float)
        velocities = np.zeros(plant.num_velocities())
        for joint in self._dofs:
            positions[joint.position_start()] = q.get(joint.name(), 0.0)
            if dq is not None:
                velocities[joint.velocity_start()] = dq.get(joint.name(), 0.0)
        for ball in self._balls:  # R = Rx·Ry·Rz from the three angles (BALL_KEYS) as Drake's rpy
            start = ball.position_start()
            positions[start:start + 3] = RollPitchYaw(RotationMatrix(_ball_turn(ball, q))).vector()
        plant.SetPositions(context, _vec(positions))
        plant.SetVelocities(context, _vec(velocities))

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        self._set(q)
        plant, context = self.plant, self.context
        base = _pose(plant.EvalBodyPoseInWorld(context, self._root_body)).inverse()
        poses = {n: base @ _pose(plant.EvalBodyPoseInWorld(context, b)) for n, b in self._bodies.items()}
        for name, frame in self._frames.items():
            poses[name] = base @ _pose(frame.CalcPoseInWorld(context))
        return poses

    def _indices(self) -> np.ndarray:
        return np.array([j.velocity_start() for j in self._dofs], dtype=int)

    def mass_matrix(self, q: dict[str, float]) -> Array:
        self._set(q)
        full = np.array(self.plant.CalcMassMatrix(self.context), dtype=float)
        idx = self._indices()
        return full[np.ix_(idx, idx)]

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        self._set(q, dq)
        coriolis = np.array(self.plant.CalcBiasTerm(self.context), dtype=float)
        gravity = np.array(self.plant.CalcGravityGeneralizedForces(self.context), dtype=float)
        return (coriolis - gravity)[self._indices()]

    def dof_names_with_balls(self) -> list[str]:
        """The hinge and slide degrees of freedom, then each ball joint's three (``NAME#x``...)."""
        return [*self.dof_names(), *(ball.name() + key for ball in self._balls for key in BALL_KEYS)]

    def _chain_map(self, q: dict[str, float]) -> Array:
        """T (nv × the names of :meth:`dof_names_with_balls`): v = T·rates. A ``BallRpyJoint``'s
        velocities are the child frame's angular velocity in the parent frame, expressed in the parent:
        ω_F = R·J·(ȧ, ḃ, ċ), R = Rx(a)·Ry(b)·Rz(c) the ball's orientation and J the chain's Jacobian in the
        child's frame (``ball_law.chain_jacobian``)."""
        names = self.dof_names_with_balls()
        out = np.zeros((self.plant.num_velocities(), len(names)))
        for column, joint in enumerate(self._dofs):
            out[joint.velocity_start(), column] = 1.0
        column = len(self._dofs)
        for ball in self._balls:
            _, b, c = (q.get(ball.name() + key, 0.0) for key in BALL_KEYS)
            jacobian = np.array(ball_law.chain_jacobian(b, c), dtype=float).reshape(3, 3)
            start = ball.velocity_start()
            out[start:start + 3, column:column + 3] = _ball_turn(ball, q) @ jacobian
            column += 3
        return out

    def mass_matrix_with_balls(self, q: dict[str, float]) -> Array:
        """Tᵀ·M·T (:meth:`_chain_map`): the mass matrix in the chain's coordinates, a ball's three
        angles included, comparable with the Pinocchio reference's pieces."""
        self._set(q)
        full = np.array(self.plant.CalcMassMatrix(self.context), dtype=float)
        t = self._chain_map(q)
        return np.asarray(t.T @ full @ t)

    def bias_with_balls(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        """Tᵀ·bias, a ball at rest (its chain rates 0, so T's derivative adds nothing)."""
        self._set(q, dq)
        coriolis = np.array(self.plant.CalcBiasTerm(self.context), dtype=float)
        gravity = np.array(self.plant.CalcGravityGeneralizedForces(self.context), dtype=float)
        return np.asarray(self._chain_map(q).T @ (coriolis - gravity))

    def close(self) -> None:
        return None


def _ball_turn(ball: BallRpyJoint, q: dict[str, float]) -> Array:
    """The ball's orientation R = Rx(a)·Ry(b)·Rz(c) from its three angles (``BALL_KEYS``)."""
    angles = (q.get(ball.name() + key, 0.0) for key in BALL_KEYS)
    return np.array(ball_law.chain_matrix(*angles), dtype=float).reshape(3, 3)


def load(model: Path | Robot, renames: Renames, *, root: str) -> DrakeModel:
    """The written SDF (or, by its suffix, URDF) in Drake; engine "drake" for SDF, "drake-urdf"."""
    if isinstance(model, Robot):
        raise TypeError("the Drake adapter reads a written SDF or URDF file")
    path = Path(model)
    return DrakeModel(path, root, "drake-urdf" if path.suffix.lower() == ".urdf" else "drake")


def load_urdf(model: Path | Robot, renames: Renames, *, root: str) -> DrakeModel:
    """The written URDF in Drake (engine "drake-urdf"): the second Drake instance."""
    if isinstance(model, Robot):
        raise TypeError("the Drake adapter reads a written SDF or URDF file")
    return DrakeModel(Path(model), root, "drake-urdf")


class _ChildServer:
    """The child's side of :mod:`.drake_child`: this module (pydrake) imported at once, the head start;
    then one file loaded and asked."""

    def __init__(self) -> None:
        self.model: DrakeModel | None = None

    def load(self, path: str, root: str, engine: str) -> dict[str, Any]:
        """The model's facts that do not depend on a configuration, or ``{"refused": (type, message)}``
        when Drake refuses the file with an exception (re-raised as that type in the parent)."""
        try:
            self.model = DrakeModel(Path(path), root, engine)
        except DrakeLoadError as exc:
            kind = "DrakeReversedRange" if REVERSED_RANGE_REFUSAL in str(exc) else type(exc).__name__
            return {"refused": (kind, str(exc))}
        except RuntimeError as exc:  # Drake's parser and Finalize() raise RuntimeError
            return {"refused": ("DrakeLoadError", f"{type(exc).__name__}: {exc}")}
        model = self.model
        return {"settings": model.settings, "warnings": list(model.warnings), "dofs": model.dof_names(),
                "dofs_with_balls": model.dof_names_with_balls(), "static": model.static()}

    def call(self, method: str, args: tuple[Any, ...]) -> Any:
        assert self.model is not None, "load first"
        return getattr(self.model, method)(*args)


def serve_child() -> int:
    """The child's entry point (:data:`.drake_child.DRAKE_CHILD`; :func:`.child.serve`)."""
    return serve(_ChildServer)
