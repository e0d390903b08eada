"""Layer 2, kinematics: link poses relative to the root link, the source's forward kinematics against
each engine's, at q = 0 and random configurations inside the limits (errors: positions in metres,
rotations in radians, the angle of R_aᵀR_b).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from modelkit.convert.compare import random_configuration
from modelkit.model import BALL_KEYS, JointType, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.protocol import Check, EngineModel
from modelkit.verify.layers.common import Loaded, Worst, engine_q, rotation_angle, vec

BALL_ANGLE = 1.0  # rad: each of a ball joint's three angles is drawn in ±this (no gimbal lock in rpy)


def ball_angles(balls: list[str], rng: np.random.Generator) -> dict[str, float]:
    """Each ball joint's three angles about its X, Y and Z (``NAME#x``..., ``BALL_KEYS``), drawn in
    ±:data:`BALL_ANGLE`."""
    return {name + key: float(rng.uniform(-BALL_ANGLE, BALL_ANGLE)) for name in balls for key in BALL_KEYS}


def configurations(robot: Robot, count: int, seed: int) -> list[dict[str, float]]:
    """q = 0, then ``count`` random configurations inside the limits (±π / ±0.5 m where unlimited),
    mimic joints set from their leaders; a ball joint turned by three angles about its X, Y and Z
    (``BALL_KEYS``), drawn from a stream of their own (the other joints' draws are those of a model
    without ball joints)."""
    rng = np.random.default_rng(seed)
    balls = [joint.name for joint in robot.joints if joint.type is JointType.BALL]
    ball_rng = np.random.default_rng([seed, 1])
    # q = 0 with every mimic joint at its offset (q = multiplier · 0 + offset), as a URDF reader that
    # applies <mimic> holds it: dexmate's F5D6 hand's thumb (offset 0.00765 rad) was 7.65e-3 rad off
    # in yourdfpy at "q = 0" when the mimic joints were left at 0 there
    out: list[dict[str, float]] = [_with_mimics(robot, {})]
    for _ in range(count):
        q = random_configuration(robot, rng)
        q.update(ball_angles(balls, ball_rng))
        out.append(_with_mimics(robot, q))
    return out


def _with_mimics(robot: Robot, q: dict[str, float]) -> dict[str, float]:
    """``q`` with each mimic joint following its leader (yourdfpy and URDF readers apply it); a
    leader ``q`` does not name is at 0. Joints in the model's order, so a mimic of a mimic follows."""
    moving = {joint.name for joint in robot.joints if joint.type in (JointType.REVOLUTE, JointType.PRISMATIC)}
    for joint in robot.joints:
        if joint.mimic is not None and joint.name in moving and joint.mimic.joint in moving:
            value = joint.mimic.multiplier * q.get(joint.mimic.joint, 0.0) + joint.mimic.offset
            if value or joint.name in q:
                q[joint.name] = value
    return q


def layer2(reference: EngineModel, eng: Loaded, configs: list[dict[str, float]],
           chain_joints: Mapping[str, str] | None = None, detached: Mapping[str, str] | None = None
           ) -> list[Check]:
    """Link poses relative to the root link, source FK vs the engine, over every configuration.

    A ball joint turns by its three angles (``BALL_KEYS``) in an engine that holds it as a ball joint
    (MuJoCo, Drake's SDF), or as the URDF writer's chain of three joints (``chain_joints``: ``NAME#x``...
    → the written joint); an engine that holds it neither way compares with it at zero (said in the
    check's detail).

    ``detached`` (link → the head of its subtree, :func:`approximations.detached_subtrees`): the links
    of a subtree that hangs by a floating joint, which the engine holds as a free body left where it
    is at q = 0 (MK813): each is compared where the source puts it when its head stays at its pose at
    q = 0 and the joints inside the subtree move."""
    position, rotation = Worst(), Worst()
    chain_joints = dict(chain_joints or {})
    detached = dict(detached or {})
    held = _ball_keys_held(eng, configs, chain_joints)
    at_rest = reference.link_poses({}) if detached else {}
    for i, q in enumerate(configs):
        q = {k: v for k, v in q.items() if k not in held}
        ref = reference.link_poses(q)
        moved = dict(ref)  # the heads as the source moves them, before any is put back at rest
        for link, head in detached.items():
            if link in ref and head in moved:
                ref[link] = at_rest[head] @ moved[head].inverse() @ moved[link]
        qe = engine_q({k: v for k, v in q.items() if k not in chain_joints}, eng)
        qe.update({chain_joints[k]: v for k, v in q.items() if k in chain_joints})
        got: dict[str, Pose] = eng.model.link_poses(qe)
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
    if detached:
        heads = sorted(set(detached.values()))
        n += (f"; the subtree(s) of {', '.join(heads)} (hanging by a floating or planar joint) held where "
              "the engine holds them, a free body at its pose at q = 0 (MK813)")
    if held:
        balls = sorted({k.rpartition("#")[0] for k in held})
        n += ("; ball joint(s) held at zero, which the engine holds neither as a ball nor as a chain: "
              + ", ".join(balls))
    return [position.check(2, eng.label, "pose-position", eng.tolerance("pose"), n),
            rotation.check(2, eng.label, "pose-rotation", eng.tolerance("pose"), n)]


def _ball_keys_held(eng: Loaded, configs: list[dict[str, float]],
                    chain_joints: Mapping[str, str]) -> set[str]:
    """The ball angles (``NAME#x``...) the engine cannot take: kept at zero in both models."""
    keys = {k for q in configs for k in q if k.rpartition("#")[0] and k[k.rindex("#"):] in BALL_KEYS}
    if not keys:
        return set()
    facts = eng.model.static()
    balls = {name for name, joint in facts.joints.items() if joint.type == "ball"}
    dofs = set(eng.model.dof_names())
    held = set()
    for key in keys:
        if key in chain_joints and chain_joints[key] in dofs:
            continue
        if eng.joint(key.rpartition("#")[0]) in balls:
            continue
        held.add(key)
    return held
