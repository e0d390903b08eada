"""What every engine adapter reports, and what every layer produces.

Names in :class:`StaticFacts` are the engine's (the written file's) names; the layers map them to
the source model's names through the conversion's renames. Frames: a link's frame is the model's
link frame (= its joint frame); COM and inertia are expressed in it, inertia about the COM.
Joint axes are unit vectors in the child link frame. Revolute and prismatic joints only carry a
``q``; the base is welded at the identity for layers 1–3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from modelkit.spatial import Pose

Array = NDArray[np.float64]


class EngineError(RuntimeError):
    """An engine could not load a model file."""


@dataclass(frozen=True)
class LinkFacts:
    mass: float
    com: Array  # (3,) in the link frame
    inertia: Array  # (3, 3) about the COM, link axes


@dataclass(frozen=True)
class JointFacts:
    type: str  # "revolute" | "prismatic" | "fixed" | "ball" | "floating" | ...
    parent: str
    child: str
    axis: Array  # (3,) unit, child frame (zeros for fixed)
    lower: float = -math.inf
    upper: float = math.inf


@dataclass(frozen=True)
class ShapeFacts:
    """One collision shape of a link, in the model's conventions.

    ``type``: "box", "sphere", "cylinder", "capsule", "ellipsoid", "cone" (the source only: no
    engine has one) or "mesh". ``size``: box (3,) full edge lengths; sphere (1,) radius; cylinder,
    capsule, cone (2,) radius and length along the shape's local Z (a capsule's cylindrical part);
    ellipsoid (3,) radii; mesh (3,) its scale (the vertices are not compared). ``pose``: the
    shape's frame in the link frame (a mesh's frame is the one its file's vertices are given in).
    """

    type: str
    size: Array
    pose: Pose


@dataclass
class StaticFacts:
    links: dict[str, LinkFacts] = field(default_factory=dict)
    joints: dict[str, JointFacts] = field(default_factory=dict)
    # Collision shapes per link (every link a key, [] for none); empty when the engine reports none.
    shapes: dict[str, list[ShapeFacts]] = field(default_factory=dict)
    # The source's named frames that are not links (SDF <frame>s, MJCF sites): an engine that lists a
    # file's frames with its bodies (Drake on SDF) reports them; they are no extra link.
    named_frames: frozenset[str] = frozenset()
    # Named frames that are no link of the engine (MJCF sites), each as a fixed joint from its body's
    # link: a source link found only here was written as a frame (MK873), neither missing nor extra.
    frames: dict[str, JointFacts] = field(default_factory=dict)


class EngineModel(Protocol):
    """One converted model loaded into one engine, base welded to the world at the identity.

    ``dof_names`` lists the 1-DOF joints (revolute, prismatic) in the order of the engine's own
    generalised coordinates; ``q``/``dq`` dictionaries are keyed by the engine's joint names.
    """

    engine: str  # "mujoco", "pybullet", "pinocchio", "drake", "yourdfpy", "source"
    settings: dict[str, Any]  # every setting that matters for reproducing the numbers

    def dof_names(self) -> list[str]: ...

    def static(self) -> StaticFacts: ...

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]: ...

    def mass_matrix(self, q: dict[str, float]) -> Array: ...  # (n, n) in dof_names() order

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array: ...  # gravity + Coriolis

    def close(self) -> None: ...


class Simulator(Protocol):
    """An engine that can integrate the fixed-base model (layer 3b: the torque replay)."""

    engine: str
    settings: dict[str, Any]

    def dof_names(self) -> list[str]: ...

    def replay(self, law: TorqueLaw, seconds: float, dt: float) -> Array: ...  # (steps + 1, n) of q

    def close(self) -> None: ...


@dataclass(frozen=True)
class TorqueLaw:
    """The contact-free replay's control law, the same in every engine: a PD law tracking
    sinusoids, u_i = kp_i (q*_i(t) − q_i) − kd_i dq_i, with q*_i(t) = amp_i sin(2π f_i t + φ_i).
    Joint order is the source model's; engines map it through the renames.

    A ball joint named in ``balls`` takes three entries, ``NAME#x``, ``NAME#y``, ``NAME#z``
    (``BALL_KEYS``), in that order: its position is the rotation vector of its orientation, and its
    law the one of :mod:`modelkit.verify.engines.ball_law` (a torque in the child's frame from the
    rotation error, not ``u_i`` above)."""

    joints: tuple[str, ...]
    kp: tuple[float, ...]
    kd: tuple[float, ...]
    amplitude: tuple[float, ...]
    frequency: tuple[float, ...]
    phase: tuple[float, ...]
    balls: tuple[str, ...] = ()

    def ball_columns(self) -> list[tuple[str, int]]:
        """Each ball joint with the index of its ``NAME#x`` entry (its three entries start there)."""
        return [(name, self.joints.index(name + "#x")) for name in self.balls]

    def torque(self, t: float, q: Array, dq: Array) -> Array:
        """u_i of the scalar law (a ball's three entries follow ``ball_law`` instead)."""
        target = np.asarray(self.amplitude) * np.sin(
            2.0 * math.pi * np.asarray(self.frequency) * t + np.asarray(self.phase)
        )
        return np.asarray(self.kp) * (target - q) - np.asarray(self.kd) * dq


@dataclass(frozen=True)
class Check:
    """One verified quantity: the worst error over everything compared, against its tolerance."""

    layer: int  # 1 static, 2 kinematics, 3 dynamics
    engine: str
    quantity: str  # "link-set", "joint-set", "joint-type", "axis", "limits", "mass", "com", "inertia",
    #                "pose", "mass-matrix", "bias", "replay"
    where: str  # the source link or joint with the worst error ("" for the whole model)
    error: float
    tolerance: float
    detail: str = ""

    @property
    def passed(self) -> bool:
        return self.error <= self.tolerance


@dataclass(frozen=True)
class Skip:
    """A layer or an engine that was not run, and exactly why (never a silent pass)."""

    layer: int
    engine: str
    reason: str


@dataclass(frozen=True)
class Observation:
    """A number the report shows but does not grade (layer 4: slip against the engine's own wheel
    odometry, distance from the ideal unicycle, a report-only profile or the native-wheel run)."""

    layer: int
    engine: str  # "mujoco", "pybullet", "mujoco~pybullet" for a comparison between two runs
    quantity: str  # "slip", "unicycle-position", "unicycle-yaw", "native-position", ...
    where: str  # the profile (and variant) it was measured on
    value: float
    unit: str  # "m", "rad"
    detail: str = ""
