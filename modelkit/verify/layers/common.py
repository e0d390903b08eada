"""What layers 1–3 share: an engine with its model loaded (:class:`Loaded`, names mapped through
the conversion's renames), the worst error of one quantity (:class:`Worst`) and how errors and
vectors are measured and printed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from modelkit.model import BALL_KEYS
from modelkit.verify.engines.protocol import Array, Check, EngineModel

TOLERANCE = 1e-9
Renames = dict[str, dict[str, str]]


@dataclass
class Loaded:
    """One engine with one model loaded, and the renames of the file it read (source → written)."""

    label: str  # "mujoco", "pybullet", "drake-sdf", ...
    model: EngineModel
    renames: Renames = field(default_factory=dict)

    def link(self, source_name: str) -> str:
        return self.renames.get("link", {}).get(source_name, source_name)

    def joint(self, source_name: str) -> str:
        return self.renames.get("joint", {}).get(source_name, source_name)

    def tolerance(self, quantity: str) -> float:
        tolerances = self.model.settings.get("tolerances", {})
        return float(tolerances.get(quantity, TOLERANCE))


class Worst:
    """The worst error seen for one quantity, and where."""

    def __init__(self) -> None:
        self.error = 0.0
        self.where = ""
        self.detail = ""

    def beats(self, error: float) -> bool:
        return error > self.error or (math.isnan(error) and not math.isnan(self.error))

    def see(self, error: float, where: str, detail: str) -> None:
        self.error, self.where, self.detail = error, where, detail

    def check(self, layer: int, engine: str, quantity: str, tolerance: float, empty: str = "") -> Check:
        error = math.inf if math.isnan(self.error) else self.error
        return Check(layer, engine, quantity, self.where, error, tolerance, self.detail or empty)


def vec(v: Array) -> str:
    """A vector as the reports print it (9 significant digits)."""
    return "[" + ", ".join(f"{x:.9g}" for x in np.asarray(v).ravel()) + "]"


def rotation_angle(a: Array, b: Array) -> float:
    """The angle of the rotation between two rotation matrices (radians, accurate near zero)."""
    r = np.asarray(a).T @ np.asarray(b)
    s = 0.5 * float(np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]))
    c = 0.5 * (float(np.trace(r)) - 1.0)
    return math.atan2(s, c)


def zero_inertia(tensor: Array) -> bool:
    """Whether validate calls ``tensor`` zero: every principal moment within ``ZERO_MOMENT`` of 0
    (MK302; iCub's ``head`` gives ±2.4e-35, which the engines hold as 0)."""
    from modelkit.checks.physics import ZERO_MOMENT

    tensor = np.asarray(tensor, dtype=float)
    return bool(np.all(np.abs(np.linalg.eigvalsh(0.5 * (tensor + tensor.T))) <= ZERO_MOMENT))


def engine_q(q: dict[str, float], eng: Loaded) -> dict[str, float]:
    """A configuration keyed by the engine's (written) joint names (:func:`engine_dof`)."""
    return {engine_dof(name, eng): value for name, value in q.items()}


def engine_dof(name: str, eng: Loaded) -> str:
    """A source degree of freedom's name in the engine: its joint's written name; a ball joint's
    angles (``NAME#x``..., ``BALL_KEYS``) follow the ball's written name."""
    base, mark, axis = name.rpartition("#")
    return f"{eng.joint(base)}#{axis}" if base and mark + axis in BALL_KEYS else eng.joint(name)
