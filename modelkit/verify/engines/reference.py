"""The references no writer touched: the source model's own facts and forward kinematics (engine
"source"), and yourdfpy's FK on the written URDF (engine "yourdfpy", poses only).

Both compute no dynamics: their ``mass_matrix``/``bias`` raise :class:`NotImplementedError` and the
layers say so (Pinocchio, built from the same in-memory model, is the dynamics reference).
"""

from __future__ import annotations

import importlib.util
import math
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.model import (
    WORLD_LINK,
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    JointType,
    Mesh,
    Robot,
    Sphere,
)
from modelkit.spatial import Pose
from modelkit.verify.engines.child import Worker, serve
from modelkit.verify.engines.protocol import (
    Array,
    EngineError,
    JointFacts,
    LinkFacts,
    ShapeFacts,
    StaticFacts,
)

Renames = dict[str, dict[str, str]]
DOF_TYPES = (JointType.REVOLUTE, JointType.PRISMATIC)


def unit(v: Any) -> Array:
    a = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(a))
    return a / n if n > 0 else np.zeros(3)


def joint_type_name(t: JointType) -> str:
    """The layers' joint type vocabulary; a track that is still a track moves nothing: fixed."""
    return "fixed" if t is JointType.PSEUDO_CONTINUOUS_TRACK else t.value


def source_static(robot: Robot) -> StaticFacts:
    """The source model's links and joints as the layers compare them."""
    facts = StaticFacts()
    for link in robot.links:
        inertial = link.inertial
        if inertial is None:
            facts.links[link.name] = LinkFacts(0.0, np.zeros(3), np.zeros((3, 3)))
        else:
            facts.links[link.name] = LinkFacts(float(inertial.mass), np.asarray(inertial.com, dtype=float),
                                               np.asarray(inertial.inertia, dtype=float))
    for joint in robot.joints:
        moving = joint.type in DOF_TYPES
        facts.joints[joint.name] = JointFacts(
            joint_type_name(joint.type), joint.parent, joint.child,
            unit(joint.axis) if moving else np.zeros(3),
            joint.limits.lower if moving else -math.inf, joint.limits.upper if moving else math.inf)
    facts.shapes = {link.name: [s for s in map(shape_facts, link.collisions) if s is not None]
                    for link in robot.links}
    facts.named_frames = frozenset(named_frames(robot))
    return facts


def named_frames(robot: Robot) -> list[str]:
    """The names of the source's frames that are not links: MJCF sites, which the reader keeps with the
    link they hang on (``extras``). An SDF source's ``<frame>``s are links of verify's reference
    (``verify.api._reference``, MK874), compared as links."""
    out: list[str] = []
    for link in robot.links:
        out.extend(str(site.get("name")) for site in (link.extras.get("mjcf_sites") or [])
                   if isinstance(site, dict) and site.get("name"))
    return out


def shape_facts(geom: Geom) -> ShapeFacts | None:
    """A source collision shape as the layers compare it. A mesh whose file is not there (and that
    has no triangles) is of type "missing-mesh": the writers drop it (MK805) and the shape checks
    leave it out, with a Skip that says so."""
    g = geom.geometry
    pose = Pose(np.asarray(geom.pose.rotation, dtype=float).copy(),
                np.asarray(geom.pose.translation, dtype=float).copy())
    if isinstance(g, Box):
        return ShapeFacts("box", np.asarray(g.size, dtype=float), pose)
    if isinstance(g, Sphere):
        return ShapeFacts("sphere", np.array([g.radius], dtype=float), pose)
    if isinstance(g, Cylinder | Capsule | Cone):
        kind = {Cylinder: "cylinder", Capsule: "capsule", Cone: "cone"}[type(g)]
        return ShapeFacts(kind, np.array([g.radius, g.length], dtype=float), pose)
    if isinstance(g, Ellipsoid):
        return ShapeFacts("ellipsoid", np.asarray(g.radii, dtype=float), pose)
    if isinstance(g, Mesh):
        missing = g.data is None and (g.path is None or not os.path.isfile(g.path))
        return ShapeFacts("missing-mesh" if missing else "mesh", np.asarray(g.scale, dtype=float), pose)
    return None  # pragma: no cover - the model has no other geometry


def dof_joints(robot: Robot) -> list[str]:
    """The 1-DOF joints of the tree, depth-first from the root in document order (Pinocchio's order)."""
    children = robot.children_of()
    out: list[str] = []
    # A stack, not recursion: a chain of thousands of links is as deep as a tree gets.
    stack = list(reversed(children.get(robot.root, []))) if robot.root else []
    while stack:
        joint = stack.pop()
        if joint.type in DOF_TYPES:
            out.append(joint.name)
        stack.extend(reversed(children.get(joint.child, [])))
    return out


class SourceModel:
    """The in-memory source model as an :class:`~modelkit.verify.engines.protocol.EngineModel`
    (no dynamics)."""

    engine = "source"

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.settings: dict[str, Any] = {"fk": "Robot.world_poses (modelkit), relative to the root link"}
        self._dofs = dof_joints(robot)

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        return source_static(self.robot)

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        poses = self.robot.world_poses(q)
        if self.robot.root is None or self.robot.root not in poses:
            return poses
        base = poses[self.robot.root].inverse()
        return {name: base @ pose for name, pose in poses.items()}

    def mass_matrix(self, q: dict[str, float]) -> Array:
        raise NotImplementedError("the source model computes no dynamics (Pinocchio is built from it)")

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        raise NotImplementedError("the source model computes no dynamics (Pinocchio is built from it)")

    def close(self) -> None:
        return None


def load(model: Path | Robot, renames: Renames, *, root: str) -> SourceModel:
    if not isinstance(model, Robot):
        raise TypeError("the source reference reads the in-memory model, not a file")
    return SourceModel(model)


class _KinematicsOnly:
    """yourdfpy computes no dynamics: the layers skip layer 3 for it."""

    def mass_matrix(self, q: dict[str, float]) -> Array:
        raise NotImplementedError("yourdfpy computes kinematics only")

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        raise NotImplementedError("yourdfpy computes kinematics only")


class YourdfpyKinematics(_KinematicsOnly):
    """yourdfpy's forward kinematics on the written URDF (an independent URDF parser; poses only), in
    this process: what :class:`YourdfpyModel` runs in its child."""

    engine = "yourdfpy"

    def __init__(self, path: Path, root: str) -> None:
        import yourdfpy

        _quiet_yourdfpy()
        self.urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True,
                                       load_collision_meshes=False, build_collision_scene_graph=False)
        self.root = root
        self.settings: dict[str, Any] = {
            "version": getattr(yourdfpy, "__version__", "unknown"), "load_meshes": False,
            "fk": "URDF.get_transform(child, parent) per joint, composed from the base link"}
        self._dofs = [j.name for j in self.urdf.robot.joints
                      if j.type in ("revolute", "continuous", "prismatic") and j.mimic is None]
        # A URDF that welds its root itself (a ``world`` link, a fixed joint to the root): by the URDF
        # convention that link is the world, not the robot's (as in the PyBullet adapter).
        # (--urdf-world-link hangs a floating root from it by a floating joint: the same world)
        self._world_joint = next((j.name for j in self.urdf.robot.joints if j.parent == WORLD_LINK
                                  and j.child == root and j.type in ("fixed", "floating")
                                  and root != WORLD_LINK), None)

    def _robots(self, link: str) -> bool:
        return self._world_joint is None or link != WORLD_LINK

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        facts = StaticFacts()
        for link in self.urdf.robot.links:
            if not self._robots(link.name):
                continue
            inertial = link.inertial
            if inertial is None:
                facts.links[link.name] = LinkFacts(0.0, np.zeros(3), np.zeros((3, 3)))
                continue
            origin = np.asarray(inertial.origin if inertial.origin is not None else np.eye(4), dtype=float)
            rot = origin[:3, :3]
            facts.links[link.name] = LinkFacts(float(inertial.mass or 0.0), origin[:3, 3].copy(),
                                               rot @ np.asarray(inertial.inertia, dtype=float) @ rot.T)
        for joint in self.urdf.robot.joints:
            if joint.name == self._world_joint:
                continue
            jtype = {"continuous": "revolute"}.get(joint.type, joint.type)
            moving = jtype in ("revolute", "prismatic")
            lower, upper = -math.inf, math.inf
            given = joint.limit is not None and (joint.limit.lower, joint.limit.upper) != (None, None)
            if moving and joint.type != "continuous" and given:  # neither given: no bound (MK125)
                lower = float(joint.limit.lower) if joint.limit.lower is not None else 0.0
                upper = float(joint.limit.upper) if joint.limit.upper is not None else 0.0
            facts.joints[joint.name] = JointFacts(jtype, joint.parent, joint.child,
                                                  unit(joint.axis) if moving else np.zeros(3), lower, upper)
        return facts

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        """Each link's pose in the root's frame, from yourdfpy's own joint transforms.

        ``get_transform(link, root)`` multiplies the whole path with ``numpy.linalg.multi_dot``, whose
        search for the best bracketing is cubic in the path's length: 0.02 s per link of a 100-link
        chain, 74 s for layer 2, hours at 1000 links. Each joint's transform (yourdfpy's
        ``get_transform(child, parent)``, one edge) is asked instead and the products are made here,
        parent before child, from the URDF's base link: linear in the links."""
        urdf = self.urdf
        urdf.update_cfg({name: q.get(name, 0.0) for name in self._dofs})
        children: dict[str, list[str]] = {}
        for joint in urdf.robot.joints:
            children.setdefault(joint.parent, []).append(joint.child)
        base = urdf.base_link
        in_base: dict[str, Array] = {base: np.eye(4)}
        stack = [base]
        while stack:
            parent = stack.pop()
            for child in children.get(parent, []):
                if child not in in_base:
                    edge = np.asarray(urdf.get_transform(child, parent), dtype=float)
                    in_base[child] = in_base[parent] @ edge
                    stack.append(child)
        root_inverse = None
        if self.root in in_base:  # the rigid inverse, exact up to one rounding
            rotation, translation = in_base[self.root][:3, :3], in_base[self.root][:3, 3]
            root_inverse = np.eye(4)
            root_inverse[:3, :3] = rotation.T
            root_inverse[:3, 3] = -rotation.T @ translation
        out: dict[str, Pose] = {}
        for link in urdf.robot.links:
            if not self._robots(link.name):
                continue
            if root_inverse is not None and link.name in in_base:
                t = root_inverse @ in_base[link.name]
            else:  # not below the base link: yourdfpy's own path search
                t = np.asarray(urdf.get_transform(link.name, self.root), dtype=float)
            out[link.name] = Pose(t[:3, :3].copy(), t[:3, 3].copy())
        return out

    def close(self) -> None:
        return None


# yourdfpy in a child process: its import (trimesh, scipy.spatial, networkx) is ≈ 0.5 s of CPU, which
# in verify's process sat on the critical path of every run; ``start_yourdfpy`` starts the child
# when verify starts, so that the import runs on the other core while verify reads and converts
# (the tutorial's pan-tilt robot, every engine: 4.80 → 4.45 s, medians of 6 interleaved runs).
YOURDFPY_CHILD = ("import sys; from modelkit.verify.engines.reference import yourdfpy_child; "
                  "sys.exit(yourdfpy_child())")


class YourdfpyError(EngineError):
    """yourdfpy refused the written URDF, or its child process failed."""


class YourdfpyMimicChain(EngineError):
    """The written URDF has what yourdfpy does not move as the file says (:func:`yourdfpy_limit`): a
    mimic of a mimic (ManiSkill's Inspire hand: the thumb's IP joint mimics its MCP joint, which mimics
    CMC pitch, on purpose; urdfdom, MuJoCo, PyBullet and Pinocchio follow the chain, yourdfpy 0.0.5x takes
    a leader that is itself a mimic as 0), or a planar or floating joint. verify skips it, the others
    grade."""

    engine_limit = True  # verify reports a skip, not a failed load


def mimic_chain(path: Path) -> tuple[str, str] | None:
    """(follower, leader) of the first mimic whose leader mimics another joint in the URDF at ``path``,
    or None (also when the file cannot be parsed: yourdfpy then says why)."""
    root = _urdf_root(path)
    return None if root is None else _mimic_chain_in(root)


def _urdf_root(path: Path) -> Any:
    from lxml import etree

    try:
        return etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True,
                                                       huge_tree=False)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return None


def _mimic_chain_in(root: Any) -> tuple[str, str] | None:
    leaders: dict[str, str] = {str(joint.get("name")): str(mimic.get("joint"))
                               for joint in root.iterfind("joint") for mimic in joint.iterfind("mimic")}
    return next(((follower, leader) for follower, leader in leaders.items() if leader in leaders), None)


def yourdfpy_limit(path: Path) -> str | None:
    """Why yourdfpy's poses of the URDF at ``path`` are not the file's, or None: a mimic of a mimic
    (:class:`YourdfpyMimicChain`), or a planar or floating joint, which yourdfpy 0.0.5x counts as 2 or 6
    coordinates and then places its child at the joint's origin whatever they are (its forward
    kinematics: "this includes: floating, planar, fixed"), shifting every later joint's coordinate;
    roboplan's reachback rides on a planar ``base_joint``."""
    root = _urdf_root(path)
    if root is None:
        return None
    chain = _mimic_chain_in(root)
    if chain is not None:
        follower, leader = chain
        return (f"joint {follower} mimics {leader}, itself a mimic: yourdfpy takes {leader} as 0 there, so "
                "its poses are not the file's (urdfdom, MuJoCo, PyBullet and Pinocchio follow the chain)")
    unmoved = next((joint for joint in root.iterfind("joint") if joint.get("type") in ("planar", "floating")),
                   None)
    if unmoved is not None:
        return (f"joint {unmoved.get('name')} is {unmoved.get('type')}: yourdfpy moves nothing with such a "
                "joint's coordinates and counts them among the others', so its poses are not the file's")
    return None


def _quiet_yourdfpy() -> None:
    """yourdfpy logs a warning per configuration it is asked (hundreds per verify run) on stderr; what
    matters of it is in the report."""
    import logging

    logging.getLogger("yourdfpy").setLevel(logging.ERROR)


class _YourdfpyServer:
    """The child's side: yourdfpy imported at once, then one model loaded and its poses asked."""

    def __init__(self) -> None:
        import yourdfpy  # noqa: F401  (the point of starting early)

        self.model: YourdfpyKinematics | None = None

    def load(self, path: str, root: str) -> dict[str, Any]:
        self.model = YourdfpyKinematics(Path(path), root)
        model = self.model
        return {"settings": model.settings, "dofs": model.dof_names(), "static": model.static()}

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        assert self.model is not None, "load first"
        return self.model.link_poses(q)


def yourdfpy_child() -> int:
    """The child's entry point (:func:`modelkit.verify.engines.child.serve`)."""
    return serve(_YourdfpyServer)


def yourdfpy_worker() -> Worker:
    """The child, started: it imports yourdfpy at once, then waits for :class:`YourdfpyModel`."""
    return Worker([sys.executable, "-P", "-c", YOURDFPY_CHILD], "yourdfpy", YourdfpyError)


def start_yourdfpy() -> Worker | None:
    """verify's head start (``registry.PRESTART``): the child, started; None when yourdfpy is not
    installed, or is already imported in this process (a ``verify -j`` worker forked from a parent
    that imported it), where :func:`load_yourdfpy` then reads the file in this process at no cost."""
    if "yourdfpy" in sys.modules or importlib.util.find_spec("yourdfpy") is None:
        return None
    return yourdfpy_worker()


class YourdfpyModel(_KinematicsOnly):
    """yourdfpy's forward kinematics on the written URDF (an independent URDF parser; poses only),
    computed by :class:`YourdfpyKinematics` in the child process ``worker`` (:func:`yourdfpy_worker`),
    which this model owns from now on."""

    engine = "yourdfpy"

    def __init__(self, path: Path, root: str, worker: Worker) -> None:
        self._worker = worker
        try:
            reply = worker.request("load", path=str(Path(path).resolve()), root=root)
        except BaseException:
            worker.close()
            raise
        self.root = root
        self.settings: dict[str, Any] = dict(reply["settings"], process="child process")
        self._dofs: list[str] = list(reply["dofs"])
        self._static: StaticFacts = reply["static"]

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        return self._static

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        poses: dict[str, Pose] = self._worker.request("link_poses", q=dict(q))
        return poses

    def close(self) -> None:
        self._worker.close()


def load_yourdfpy(model: Path | Robot, renames: Renames, *, root: str,
                  worker: Worker | None = None) -> YourdfpyModel | YourdfpyKinematics:
    """The engine plug-in entry point: in the child ``worker`` (:func:`start_yourdfpy`) when verify
    started one, else in this process."""
    if isinstance(model, Robot):
        raise TypeError("yourdfpy reads the written URDF")
    limit = yourdfpy_limit(Path(model))
    if limit is not None:
        if worker is not None:
            worker.close()
        raise YourdfpyMimicChain(limit)
    if worker is not None and worker.alive():
        return YourdfpyModel(Path(model), root, worker)
    return YourdfpyKinematics(Path(model), root)
