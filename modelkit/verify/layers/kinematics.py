"""Layer 2, kinematics: link poses relative to the root link, the source's forward kinematics against
each engine's, at q = 0 and random configurations inside the limits (errors: positions in metres,
rotations in radians, the angle of R_aᵀR_b).
"""

from __future__ import annotations

import numpy as np

from modelkit.convert.compare import random_configuration
from modelkit.model import Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.protocol import Check, EngineModel
from modelkit.verify.layers.common import Loaded, Worst, engine_q, rotation_angle, vec


def configurations(robot: Robot, count: int, seed: int) -> list[dict[str, float]]:
    """q = 0, then ``count`` random configurations inside the limits (±π / ±0.5 m where unlimited),
    mimic joints set from their leaders."""
    rng = np.random.default_rng(seed)
    out: list[dict[str, float]] = [{}]
    for _ in range(count):
        q = random_configuration(robot, rng)
        for joint in robot.joints:  # a mimic joint follows its leader (yourdfpy and URDF readers apply it)
            if joint.mimic is not None and joint.name in q and joint.mimic.joint in q:
                q[joint.name] = joint.mimic.multiplier * q[joint.mimic.joint] + joint.mimic.offset
        out.append(q)
    return out


def layer2(reference: EngineModel, eng: Loaded, configs: list[dict[str, float]]) -> list[Check]:
    """Link poses relative to the root link, source FK vs the engine, over every configuration."""
    position, rotation = Worst(), Worst()
    for i, q in enumerate(configs):
        ref = reference.link_poses(q)
        got: dict[str, Pose] = eng.model.link_poses(engine_q(q, eng))
        for name, pa in ref.items():
            pb = got.get(eng.link(name))
            if pb is None:
                continue
            dp = float(np.linalg.norm(pa.translation - pb.translation))
            if position.beats(dp):
                position.see(dp, name, f"configuration {i}: origin {vec(pa.translation)} m, "
                                       f"engine {vec(pb.translation)} m")
            da = rotation_angle(pa.rotation, pb.rotation)
            if rotation.beats(da):
                rotation.see(da, name, f"configuration {i}: orientation differs by {da:.3g} rad")
    n = f"{len(configs)} configurations, every link"
    return [position.check(2, eng.label, "pose-position", eng.tolerance("pose"), n),
            rotation.check(2, eng.label, "pose-rotation", eng.tolerance("pose"), n)]
