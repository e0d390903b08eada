"""MuJoCo's bodies as plain data, whichever way they were read (compiled model or bare spec).

The compiled reader (:mod:`.compiled`) and the fallback (:mod:`.uncompiled`) both fill these
records; :mod:`.build` turns them into robots. Values are MuJoCo's: poses relative to the parent
body, joint anchors and axes in the body frame, sizes as MuJoCo stores them (half-lengths), angles
in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.spatial import Mat3, Pose, Vec3


def quat_matrix(quat: Any) -> Mat3:
    """The rotation matrix of a MuJoCo quaternion (w, x, y, z); normalised first."""
    q = np.asarray(quat, dtype=float)
    n = float(np.linalg.norm(q))
    if n == 0.0 or not math.isfinite(n):
        return np.eye(3)
    w, x, y, z = q / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def pose_of(pos: Any, quat: Any) -> Pose:
    return Pose(quat_matrix(quat), np.asarray(pos, dtype=float).copy())


def translation(vector: Any) -> Pose:
    return Pose(np.eye(3), np.asarray(vector, dtype=float).copy())


def inverse(pose: Pose) -> Pose:
    r = pose.rotation.T
    return Pose(r, -r @ pose.translation)


@dataclass
class MjJoint:
    """One MuJoCo joint; ``kind`` is ``free``, ``ball``, ``slide`` or ``hinge``."""

    index: int
    name: str | None
    kind: str
    pos: Vec3
    axis: Vec3
    limited: bool = False
    range: tuple[float, float] = (0.0, 0.0)
    ref: float = 0.0
    damping: float = 0.0
    frictionloss: float = 0.0
    armature: float = 0.0
    stiffness: float = 0.0
    springref: float = 0.0
    actfrc: tuple[float, float] | None = None


@dataclass
class MjGeom:
    """One geom, placed in its body frame. For a mesh the pose is that of the file's coordinates
    (MuJoCo's re-centring of the mesh on its centre of mass is undone)."""

    index: int
    name: str | None
    kind: str  # "box", "sphere", "capsule", "cylinder", "ellipsoid", "mesh", "plane", "hfield", "sdf"
    size: Vec3
    pose: Pose
    contype: int = 1
    conaffinity: int = 1
    group: int = 0
    rgba: tuple[float, float, float, float] | None = None
    material: str | None = None
    mesh_name: str | None = None
    mesh_file: str | None = None
    mesh_path: str | None = None
    mesh_scale: Vec3 = field(default_factory=lambda: np.ones(3))

    @property
    def visual_only(self) -> bool:
        """MuJoCo collides a geom only when its contype or conaffinity is non-zero."""
        return self.contype == 0 and self.conaffinity == 0


@dataclass
class MjInertial:
    """Mass, centre of mass, principal moments and the principal axes' orientation (body frame)."""

    mass: float
    ipos: Vec3
    iquat: Any
    diag: Vec3
    explicit: bool = True

    def tensor(self) -> Mat3:
        """The full inertia tensor about the centre of mass, in body axes."""
        r = quat_matrix(self.iquat)
        return r @ np.diag(np.asarray(self.diag, dtype=float)) @ r.T


@dataclass
class MjSite:
    index: int
    name: str | None
    kind: str
    pose: Pose
    size: Vec3


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
