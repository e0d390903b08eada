"""Body pairs that touch at rest in a written MJCF model, found by compiling it with MuJoCo.

A URDF arm is drawn with its links' collision meshes overlapping where they meet (Panda's hand and
link 5 at q = 0, its two fingers), and MuJoCo collides the convex hulls of meshes, which overlap more.
MuJoCo already ignores contacts between a parent and its child body and between bodies welded
together; any other pair that touches at rest pushes the robot apart at the first step. The MJCF
writer gives each such pair a ``<contact><exclude>`` (MK832).

The model is compiled from memory (the writer's XML and the mesh files staged for the output, MuJoCo's
virtual file system), the reference configuration is applied (the ``home`` keyframe, the robot's
initial joint positions, when there is one; else ``qpos0``, i.e. q = 0) and ``mj_forward`` runs
collision detection: every contact there is
between two of the robot's own bodies, since the file holds no floor. MuJoCo's Python bindings come with
the core install (``mujoco-core``); when they cannot be imported or the compiler refuses the file,
:func:`touching_pairs` says why and the writer notes that nothing was checked (MK833).

The same pass gives three more facts of the file at rest: a welded standing arm's links below its base
(MK865), a free robot's lowest collision shape, where the ``home`` key rests it on the floor (MK882),
and how soft MuJoCo makes the floor's contact on the bodies it stands on (MK883).

MuJoCo softens a contact in proportion to the inverse mass the contact moves (its constraint
regularisation is ``(1 − d) / d`` times the diagonal of the inverse inertia in contact space, which
the compiler estimates per body as ``body_invweight0``). So under a robot's weight a body sinks in
proportion to the robot's mass times that body's ``body_invweight0``: a dimensionless *load ratio*,
1 for a rigid block resting on the floor. Measured with MuJoCo's default contact on the 133 free
robots of example-robot-data, pybullet_data, the shared corpus and icub-models 3.2.0 reset to
``home`` on a plain floor for 2 s (``bench/bench_home_floor.py``, docs/convert.md): every robot that
stands has a ratio of at most 177 (HyQ, 10.9 mm of sink; quadrupeds 31 to 137, humanoids 7.5 to 33);
icub-models' iCubLisboa01, whose source gives each foot 10 g, has 926: its feet sink 33 mm and it
falls at 1.1 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Touching:
    """Two bodies in contact at rest (names as written, in tree order), and how deep."""

    body1: str
    body2: str
    depth: float  # m: the deepest penetration between their geoms (0 when they only touch)
    where: str  # "home" or "q = 0"


@dataclass(frozen=True)
class BelowBase:
    """A moving body of a welded robot whose collision shapes reach below the robot's base at rest."""

    body: str
    depth: float  # m below the lowest point of the base's collision shapes


@dataclass(frozen=True)
class SoftSupport:
    """A body a free robot stands on at rest whose floor contact MuJoCo makes soft: the robot's mass
    times the body's ``body_invweight0`` (translation) is above :data:`SOFT_LOAD_RATIO`."""

    body: str
    mass: float  # kg: the body's own
    robot_mass: float  # kg
    ratio: float  # the load ratio


@dataclass(frozen=True)
class Lowest:
    """Where a free robot's collision shapes reach lowest at rest (the state :func:`touching_pairs`
    applied): the world height and the body whose shape reaches it; and the bodies at that level
    (within :data:`SUPPORT_LEVEL`) whose contact with a default floor is too soft to carry the robot."""

    height: float
    body: str
    soft: list[SoftSupport] = field(default_factory=list)


@dataclass(frozen=True)
class Checked:
    pairs: list[Touching]
    failure: str | None = None  # why nothing was checked
    unusable: str | None = None  # the failure is one a user of the file meets too: what MuJoCo does
    below: list[BelowBase] = field(default_factory=list)  # a welded robot's bodies under its base
    lowest: Lowest | None = None  # a robot whose root body is free: its lowest collision shape at rest


STANDING_ARM_JOINTS = 3  # a welded robot is judged for MK865 when its moving part starts as such a chain
BELOW_TOLERANCE = 1e-3  # m: what a collision shape may reach below the base before it is said (MK865)
SUPPORT_LEVEL = 1e-3  # m: a body whose collision shapes reach this close to the lowest point stands there
SOFT_LOAD_RATIO = 400.0
"""MK883: the load ratio above which a support body's contact is said to be too soft: more than twice the
largest of the robots measured standing (177), less than half of the one that falls (926)."""
DEFAULT_SOLREF = (0.02, 1.0)
DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)


def touching_pairs(xml: bytes, assets: dict[str, bytes]) -> Checked:
    """The body pairs of the MJCF ``xml`` whose collision geoms touch at the ``home`` key, or at q = 0
    when it has none.

    ``assets`` maps each file name as MuJoCo resolves it (``meshes/link0.stl``) to its bytes."""
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - mujoco-core is a core dependency
        return Checked([], f"MuJoCo's Python bindings cannot be imported ({exc})")
    from modelkit.formats.mjcf.quiet import collected_warnings

    with collected_warnings(mujoco):  # never MUJOCO_LOG.TXT in the working directory, nor stderr
        return _touching(mujoco, xml, assets)


def _touching(mujoco: Any, xml: bytes, assets: dict[str, bytes]) -> Checked:
    try:
        model = mujoco.MjModel.from_xml_string(xml.decode("utf-8"), assets)
    except Exception as exc:  # MuJoCo raises ValueError with its compiler's message
        said = " ".join(str(exc).split())
        return Checked([], f"MuJoCo did not compile the written file ({said})",
                       f"MuJoCo refuses the written file ({said}): the file is written, but it does not load")
    data = mujoco.MjData(model)
    found: dict[tuple[int, int], tuple[float, set[str]]] = {}
    home = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    # a home key that is q = 0 (servo controls only) is named so: the user's "at rest" is q = 0 there
    zero = home < 0 or bool((model.key_qpos[home] == model.qpos0).all())
    states: list[tuple[str, Any]] = [("q = 0" if zero else "home", home if home >= 0 else None)]
    for label, key in states:
        if key is None:
            mujoco.mj_resetData(model, data)
        else:
            mujoco.mj_resetDataKeyframe(model, data, key)
        try:
            mujoco.mj_forward(model, data)
        except mujoco.FatalError as exc:  # its arena overflows: too many geoms overlap at once
            said = " ".join(str(exc).splitlines()[0].split())
            return Checked([], f"MuJoCo stopped while finding the contacts at {label} ({said})",
                           f"MuJoCo loads the written file but stops at its first step at {label} ({said}): "
                           f"{model.nbody - 1} bodies whose collision shapes overlap too many at once "
                           "for its memory")
        for i in range(data.ncon):
            contact = data.contact[i]
            b1, b2 = (int(model.geom_bodyid[contact.geom[0]]), int(model.geom_bodyid[contact.geom[1]]))
            if b1 == b2:
                continue
            pair = (min(b1, b2), max(b1, b2))
            depth, labels = found.get(pair, (0.0, set()))
            found[pair] = (max(depth, max(0.0, -float(contact.dist))), labels | {label})

    def name(body: int) -> str:
        return str(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or "world")

    pairs = [
        Touching(name(b1), name(b2), depth, " and ".join(s for s, _ in states if s in labels))
        for (b1, b2), (depth, labels) in sorted(found.items())
    ]
    lows = _lowest_by_body(mujoco, model, data)
    below = [BelowBase(name(body), depth) for body, depth in _below_base(mujoco, model, data, lows)]
    lowest = _free_root_lowest(mujoco, model, lows)
    rest = None
    if lowest is not None:
        soft = [SoftSupport(name(body), float(model.body_mass[body]), mass, ratio)
                for body, mass, ratio in _soft_supports(model, lows, lowest[0])]
        rest = Lowest(lowest[0], name(lowest[1]), soft)
    return Checked(pairs, below=below, lowest=rest)


def _lowest_by_body(mujoco: Any, model: Any, data: Any) -> dict[int, float]:
    """Body → the lowest world height of its collision shapes in the state ``data`` holds (bodies
    without a collision shape that has a lowest point are left out)."""
    lowest: dict[int, float] = {}
    for g in range(model.ngeom):
        if not (model.geom_contype[g] or model.geom_conaffinity[g]):
            continue
        low = _lowest_point(mujoco, model, data, g)
        if low is not None:
            body = int(model.geom_bodyid[g])
            lowest[body] = min(lowest.get(body, math.inf), low)
    return lowest


def _free_root_lowest(mujoco: Any, model: Any, lows: dict[int, float]) -> tuple[float, int] | None:
    """When the first joint is a free joint on a body of the world (the robot's root, as the MJCF
    writer puts it), the lowest point of the collision shapes of that body's tree (``lows``:
    :func:`_lowest_by_body`), and the body whose shape reaches it; None when that tree has none."""
    if model.njnt == 0 or int(model.jnt_type[0]) != int(mujoco.mjtJoint.mjJNT_FREE):
        return None
    root = int(model.jnt_bodyid[0])
    if int(model.body_parentid[root]) != 0:
        return None
    tree = [(low, body) for body, low in lows.items() if int(model.body_rootid[body]) == root]
    return min(tree) if tree else None


def _soft_supports(model: Any, lows: dict[int, float], floor: float) -> list[tuple[int, float, float]]:
    """(body, robot mass, load ratio) of each body of the free root's tree whose collision shapes reach
    within :data:`SUPPORT_LEVEL` of ``floor`` and whose load ratio is above :data:`SOFT_LOAD_RATIO`, in
    body order. Only bodies whose collision geoms all keep MuJoCo's default ``solref`` and ``solimp``
    are judged: the ratios were measured with them (a wheeled robot's stiff contact, an MJCF source's
    own values, change how far a body sinks)."""
    root = int(model.jnt_bodyid[0])
    mass = float(model.body_subtreemass[root])
    out: list[tuple[int, float, float]] = []
    for body, low in sorted(lows.items()):
        if int(model.body_rootid[body]) != root or low - floor > SUPPORT_LEVEL:
            continue
        geoms = [g for g in range(int(model.body_geomadr[body]), int(model.body_geomadr[body])
                                  + int(model.body_geomnum[body]))
                 if model.geom_contype[g] or model.geom_conaffinity[g]]
        if not all(np.allclose(model.geom_solref[g], DEFAULT_SOLREF)
                   and np.allclose(model.geom_solimp[g], DEFAULT_SOLIMP) for g in geoms):
            continue
        ratio = mass * float(model.body_invweight0[body][0])
        if ratio > SOFT_LOAD_RATIO:
            out.append((body, mass, ratio))
    return out


def _below_base(mujoco: Any, model: Any, data: Any, lowest: dict[int, float]) -> list[tuple[int, float]]:
    """A welded robot's moving bodies whose collision shapes reach more than :data:`BELOW_TOLERANCE`
    below its base, in the state ``data`` holds (the last one :func:`_touching` applied; ``lowest``:
    :func:`_lowest_by_body` there).

    The base is every body welded to the world; the plane it stands on is the lowest point of its
    collision shapes (a base without any, such as a virtual frame, says nothing). A table or floor
    under the robot is there: a shape below it starts inside it, and MuJoCo pushes the arm out at the
    first step. A robot whose moving links' centre of mass is not above that plane hangs from its base
    (mounted from above or from the side: TriFinger's finger, a humanoid's arm, a drone's) and is not
    judged. Only a standing arm is: one chain of at least :data:`STANDING_ARM_JOINTS` moving joints
    from the base before it branches, longer than any branch after it (UR5, Panda, Kinova with the
    fingers of their grippers). A hand
    (example-robot-data's Allegro), a gripper (PR2's, Choreonoid's Robotiq 2F-85), an upper body whose
    arms branch at a waist (Alex) or a one-motor test rig (pybullet_data's Minitaur motor) is held by
    a wrist, a torso or a frame, not a table, and its fingers or arms reach past that mount's plane
    as they are built to. Nor is a robot with a free joint, which stands nowhere yet."""
    if any(int(t) == int(mujoco.mjtJoint.mjJNT_FREE) for t in model.jnt_type):
        return []
    welded = [int(b) for b in range(1, model.nbody) if int(model.body_weldid[b]) == 0]
    if not welded or len(welded) == model.nbody - 1:
        return []
    base = [lowest[b] for b in welded if b in lowest]
    if not base:
        return []  # a base without collision shapes (a virtual frame): where it stands is not known
    plane = min(base)
    moving = [b for b in range(1, model.nbody) if int(model.body_weldid[b]) != 0]
    if _arm_joints(model, moving) < STANDING_ARM_JOINTS:
        return []  # fingers, a gripper's jaws, an upper body's arms, a test rig's motor
    mass = float(sum(model.body_mass[b] for b in moving))
    if mass > 0.0 and sum(float(model.body_mass[b] * data.xipos[b][2]) for b in moving) / mass <= plane:
        return []  # the robot hangs from its base (a finger under its frame, an arm on a shoulder, a drone's)
    return [(body, plane - low) for body, low in sorted(lowest.items())
            if int(model.body_weldid[body]) != 0 and plane - low > BELOW_TOLERANCE]


def _arm_joints(model: Any, moving: list[int]) -> int:
    """The moving joints of the chain the robot's moving bodies start with, up to its first branch;
    0 when several chains start from the base, or when a branch holds as many joints in a row as that
    chain (the arms above a humanoid's waist; a gripper's fingers at an arm's end hold fewer)."""
    children: dict[int, list[int]] = {}
    for body in moving:
        children.setdefault(int(model.body_parentid[body]), []).append(body)
    starts = [b for b in moving if int(model.body_weldid[int(model.body_parentid[b])]) == 0]
    if len(starts) != 1:
        return 0
    count, body = 0, starts[0]
    while True:
        count += int(model.body_jntnum[body])
        below = children.get(body, [])
        if len(below) != 1:
            break
        body = below[0]
    if any(_longest_chain(model, children, branch) >= count for branch in children.get(body, [])):
        return 0
    return count


def _longest_chain(model: Any, children: dict[int, list[int]], top: int) -> int:
    """The most moving joints on one path down from body ``top`` (itself included)."""
    longest: dict[int, int] = {}
    order, stack = [], [top]
    while stack:  # bodies in depth-first order; then each body after its children
        body = stack.pop()
        order.append(body)
        stack.extend(children.get(body, []))
    for body in reversed(order):
        below = [longest[c] for c in children.get(body, [])]
        longest[body] = int(model.body_jntnum[body]) + max(below, default=0)
    return longest[top]


def _lowest_point(mujoco: Any, model: Any, data: Any, g: int) -> float | None:
    """The lowest world height of geom ``g``'s surface (None for a plane, an hfield or an SDF)."""
    kind = int(model.geom_type[g])
    types = mujoco.mjtGeom
    size = model.geom_size[g]
    z = float(data.geom_xpos[g][2])
    rz = np.asarray(data.geom_xmat[g]).reshape(3, 3)[2]  # the geom's axes' world heights
    if kind == int(types.mjGEOM_SPHERE):
        return z - float(size[0])
    if kind == int(types.mjGEOM_CAPSULE):
        return z - abs(float(rz[2])) * float(size[1]) - float(size[0])
    if kind == int(types.mjGEOM_CYLINDER):
        axial = abs(float(rz[2]))
        return z - axial * float(size[1]) - math.sqrt(max(0.0, 1.0 - axial * axial)) * float(size[0])
    if kind == int(types.mjGEOM_BOX):
        return z - float(np.abs(rz) @ np.asarray(size))
    if kind == int(types.mjGEOM_ELLIPSOID):
        return z - float(np.linalg.norm(rz * np.asarray(size)))
    if kind == int(types.mjGEOM_MESH):
        mesh = int(model.geom_dataid[g])
        start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        if count == 0:
            return None
        return z + float((np.asarray(model.mesh_vert[start:start + count]) @ rz).min())
    return None
