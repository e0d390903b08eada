"""MuJoCo's bodies as plain data, whichever way they were read (compiled model or bare spec).

The compiled reader (:mod:`.compiled`) and the fallback (:mod:`.uncompiled`) both fill these
records; :mod:`.build` turns them into robots. Values are MuJoCo's: poses relative to the parent
body, joint anchors and axes in the body frame, sizes as MuJoCo stores them (half-lengths), angles
in radians.

The records hold plain tuples (vectors ``(x, y, z)``, matrices tuples of rows, :mod:`modelkit.rot3`)
whatever the arrays they were read from (numpy rows from the ``mujoco`` bindings or plain tuples), so
turning them into robots imports no numpy.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import Any

from modelkit import rot3
from modelkit.rot3 import M3, V3
from modelkit.spatial import Pose


def pose_of(pos: Any, quat: Any) -> Pose:
    """A MuJoCo position and quaternion (w, x, y, z; a zero one is no rotation, as in MuJoCo)."""
    return Pose(rot3.from_quat_wxyz(quat), rot3.vec3(pos))


def translation(vector: Any) -> Pose:
    return Pose(rot3.IDENTITY, rot3.vec3(vector))


def single(value: Any) -> float:
    """A number MuJoCo stores in single precision (colours, lights, material terms) as the shortest
    decimal that is the same float32: the ``0.8`` a source wrote, not ``0.800000011920929``."""
    x = float(value)
    if not math.isfinite(x) or x == 0.0:
        return x
    stored = struct.pack("<f", x)
    for digits in range(1, 10):
        short = float(f"{x:.{digits}g}")
        if struct.pack("<f", short) == stored:
            return short
    return x  # never reached: nine significant digits identify every float32


def singles(values: Any) -> tuple[float, ...]:
    return tuple(single(v) for v in values)


@dataclass
class MjJoint:
    """One MuJoCo joint; ``kind`` is ``free``, ``ball``, ``slide`` or ``hinge``."""

    index: int
    name: str | None
    kind: str
    pos: V3
    axis: V3  # unit once compiled; as written from a bare spec (the builder normalises)
    limited: bool = False
    range: tuple[float, float] = (0.0, 0.0)
    ref: float = 0.0
    damping: float = 0.0
    frictionloss: float = 0.0
    armature: float = 0.0
    stiffness: float = 0.0
    springref: float = 0.0
    actfrc: tuple[float, float] | None = None
    qpos_address: int | None = None  # where the joint's values start in qpos (compiled models)
    physics: dict[str, str] = field(default_factory=dict)  # margin, solreflimit... where not MuJoCo's default


# MJCF joint attribute -> (the compiled array's row kind "jnt" or "dof", its field, MuJoCo's default): the
# limit's and the dry friction's solver parameters, the limit margin, gravity compensation by actuators
JOINT_PHYSICS_DEFAULTS: dict[str, tuple[str, str, tuple[float, ...]]] = {
    "margin": ("jnt", "margin", (0.0,)),
    "solreflimit": ("jnt", "solref", (0.02, 1.0)),
    "solimplimit": ("jnt", "solimp", (0.9, 0.95, 0.001, 0.5, 2.0)),
    "solreffriction": ("dof", "solref", (0.02, 1.0)),
    "solimpfriction": ("dof", "solimp", (0.9, 0.95, 0.001, 0.5, 2.0)),
    "actuatorgravcomp": ("jnt", "actgravcomp", (0.0,)),
}
BODY_PHYSICS_DEFAULTS: dict[str, tuple[str, str, tuple[float, ...]]] = {
    "gravcomp": ("body", "gravcomp", (0.0,)),
}


GEOM_CONTACT_DEFAULTS: dict[str, tuple[float, ...]] = {
    "solref": (0.02, 1.0),
    "solimp": (0.9, 0.95, 0.001, 0.5, 2.0),
    "margin": (0.0,),
    "gap": (0.0,),
    "solmix": (1.0,),
    "condim": (3.0,),
    "priority": (0.0,),
    "contype": (1.0,),
    "conaffinity": (1.0,),
}
"""A geom's contact parameters besides its friction coefficients, with MuJoCo's defaults. ``condim``
and ``priority`` decide, with MuJoCo's mixing rule, which geom's friction a contact uses: an MJCF
source's own are written back as they were (MJCF output keeps MuJoCo's rules, see
``formats.mjcf.write_geoms``). ``contype`` and ``conaffinity`` are the geom's collision filter (dm_control's
walker: 1 and 0, its limbs touch the floor but not each other)."""
INTEGER_CONTACT = frozenset({"condim", "priority", "contype", "conaffinity"})
MUJOCO_FRICTION = (1.0, 0.005, 0.0001)


@dataclass
class MjGeom:
    """One geom, placed in its body frame. For a mesh the pose is that of the file's coordinates
    (MuJoCo's re-centring of the mesh on its centre of mass is undone)."""

    index: int
    name: str | None
    kind: str  # "box", "sphere", "capsule", "cylinder", "ellipsoid", "mesh", "plane", "hfield", "sdf"
    size: V3
    pose: Pose
    contype: int = 1
    conaffinity: int = 1
    group: int = 0
    rgba: tuple[float, float, float, float] | None = None
    material: str | None = None
    look: dict[str, Any] = field(default_factory=dict)  # its material: specular... (not the defaults)
    mesh_name: str | None = None
    mesh_file: str | None = None
    mesh_path: str | None = None
    mesh_scale: V3 = (1.0, 1.0, 1.0)
    friction: V3 = (1.0, 0.005, 0.0001)  # sliding, torsional, rolling (MuJoCo's defaults)
    condim: int = 3
    contact: dict[str, str] = field(default_factory=dict)  # solref, solimp... where not MuJoCo's default
    paired: bool = False  # named by an explicit <contact><pair>
    collision_group: bool = False  # in group 3 of a file that collides nothing itself (its scene does)

    @property
    def visual_only(self) -> bool:
        """MuJoCo collides a geom when its contype or conaffinity is non-zero, or when a ``<pair>`` names
        it (MJX models such as jaxterity's G1 keep ``contype="0" conaffinity="0"`` on every geom and
        collide the feet with the floor and each other by pairs alone). In a file that collides
        nothing itself, the geoms of collision group 3 are its collision shapes: the scene that
        includes it pairs them (``CompiledModel.collisions_elsewhere``)."""
        return self.contype == 0 and self.conaffinity == 0 and not self.paired and not self.collision_group


@dataclass
class MjInertial:
    """Mass, centre of mass and the full inertia tensor about it, in body axes."""

    mass: float
    ipos: V3
    inertia: M3


@dataclass
class MjSite:
    index: int
    name: str | None
    kind: str
    pose: Pose
    size: V3
    shown: dict[str, Any] = field(default_factory=dict)  # group, rgba: when not MuJoCo's default


@dataclass
class MjBody:
    """One MuJoCo body (not the world): its pose in its parent body and what it holds."""

    index: int
    name: str | None
    parent: int  # 0 is the world
    pose: Pose  # in the parent body's frame
    joints: list[MjJoint] = field(default_factory=list)
    geoms: list[MjGeom] = field(default_factory=list)
    sites: list[MjSite] = field(default_factory=list)
    inertial: MjInertial | None = None
    mocap: bool = False
    physics: dict[str, str] = field(default_factory=dict)  # gravcomp where not MuJoCo's default


def plain(values: tuple[float, ...] | list[float]) -> str:
    """Numbers as the shortest decimals that give them back (``0.015 1``), ``0`` for ±0."""
    texts = []
    for x in values:
        text = "0" if x == 0.0 else repr(float(x))
        texts.append(text[:-2] if text.endswith(".0") else text)
    return " ".join(texts)


def non_default(m: Any, table: dict[str, tuple[str, str, tuple[float, ...]]],
                index: dict[str, int]) -> dict[str, str]:
    """The attributes of ``table`` (MJCF attribute → the compiled array's row kind and field, MuJoCo's
    default) whose compiled value differs from the default, as MJCF attribute text; ``index`` gives the
    row per kind (``jnt``, ``dof``, ``body``). An array the loaded library lacks is skipped."""
    out: dict[str, str] = {}
    for attribute, (row, name, default) in table.items():
        try:
            raw = getattr(m, f"{row}_{name}")[index[row]]
        except AttributeError:
            continue
        values = tuple(float(x) for x in (raw if hasattr(raw, "__len__") else (raw,)))
        if any(abs(a - b) > 1e-12 * max(1.0, abs(b)) for a, b in zip(values, default, strict=True)):
            flag = attribute == "actuatorgravcomp"
            out[attribute] = ("true" if values[0] else "false") if flag else plain(values)
    return out
