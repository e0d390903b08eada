"""Layer 3a, dynamics without contact: the joint-space mass matrix and bias forces of each engine at
random (q, dq) against the reference (Pinocchio built from the source), in the reference's dof order
(errors relative to the largest entry; bias relative to max(1e-6, largest entry, max |M|·max |dq|²):
the last is the scale of the bias's velocity terms, whose round-off is what two engines differ by
when gravity loads no joint; pybullet_data's r2d2, whose wheels and gripper feel neither gravity nor
Coriolis forces, had a bias of 0 against Drake's 1.1e-15 N·m, 1.1e-9 "relative" to the 1e-6 floor).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from modelkit.convert.compare import random_configuration
from modelkit.model import JointType, Robot
from modelkit.verify.engines.protocol import Check, EngineModel, Skip
from modelkit.verify.layers.common import Loaded, Worst, engine_dof, engine_q
from modelkit.verify.layers.kinematics import ball_angles

State = tuple[dict[str, float], dict[str, float]]


def states(robot: Robot, dofs: list[str], count: int, seed: int) -> list[State]:
    """Random (q, dq): q inside the limits, dq uniform in ±2 rad/s (±0.5 m/s on prismatic joints). A
    ball joint is turned by three angles about its X, Y and Z (``kinematics.ball_angles``, a stream of
    their own) and held at rest: ``dofs`` (the reference's) has no velocity of it."""
    rng = np.random.default_rng(seed + 1)
    balls = [joint.name for joint in robot.joints if joint.type is JointType.BALL]
    ball_rng = np.random.default_rng([seed + 1, 1])
    out = []
    for _ in range(count):
        q = random_configuration(robot, rng)
        dq = {name: float(rng.uniform(-2.0, 2.0)) for name in dofs}
        q.update(ball_angles(balls, ball_rng))
        out.append((q, dq))
    return out


def holds_balls_as_chains(model: object) -> bool:
    """Whether an engine model can give its mass matrix and bias with each ball joint in the
    coordinates of the URDF writer's chain (``mass_matrix_with_balls``; MuJoCo does)."""
    return all(hasattr(model, name) for name in ("dof_names_with_balls", "mass_matrix_with_balls",
                                                 "bias_with_balls"))


def layer3a(reference: EngineModel, eng: Loaded, samples: list[State],
            written: Mapping[str, str] | None = None, with_balls: bool = False) -> list[Check]:
    """Mass matrix and bias forces of the engine against the reference, in the reference's dof order.
    ``written``: a reference joint → the engine's, where the conversion's renames do not say (the last
    joint of a ball's chain keeps the ball's name in the reference, the URDF writer's ``NAME_z``).
    ``with_balls``: both models hold ball joints and give them in the chain's coordinates
    (:func:`holds_balls_as_chains`): a ball's three angles are compared too, the ball at rest."""
    eng.model.mass_matrix({})  # NotImplementedError: an engine without dynamics (the caller skips it)
    written = dict(written or {})

    def in_engine(values: dict[str, float]) -> dict[str, float]:
        out = engine_q({k: v for k, v in values.items() if k not in written}, eng)
        out.update({written[k]: v for k, v in values.items() if k in written})
        return out


    mass_matrix_of, bias_of = reference.mass_matrix, reference.bias
    engine_mass_matrix, engine_bias = eng.model.mass_matrix, eng.model.bias
    ref_dofs, eng_dofs = reference.dof_names(), eng.model.dof_names()
    if with_balls:
        ref: Any = reference
        model: Any = eng.model
        mass_matrix_of, bias_of = ref.mass_matrix_with_balls, ref.bias_with_balls
        engine_mass_matrix, engine_bias = model.mass_matrix_with_balls, model.bias_with_balls
        ref_dofs, eng_dofs = ref.dof_names_with_balls(), model.dof_names_with_balls()
    where = {name: i for i, name in enumerate(eng_dofs)}
    order = [where.get(written[name] if name in written else engine_dof(name, eng), -1) for name in ref_dofs]
    label = eng.label
    if -1 in order or len(eng_dofs) != len(ref_dofs):
        lost = [name for name, i in zip(ref_dofs, order, strict=True) if i < 0]
        detail = f"degrees of freedom differ: source {ref_dofs}, engine {eng_dofs}; not found {lost}"
        first = [*lost, ""][0]
        return [Check(3, label, "mass-matrix", first, math.inf, eng.tolerance("mass-matrix"), detail),
                Check(3, label, "bias", first, math.inf, eng.tolerance("bias"), detail)]
    idx = np.asarray(order, dtype=int)
    mm, bias = Worst(), Worst()
    for k, (q, dq) in enumerate(samples):
        ma = mass_matrix_of(q)
        mb = engine_mass_matrix(in_engine(q))[np.ix_(idx, idx)]
        diff = np.abs(ma - mb)
        scale = max(float(np.max(np.abs(ma))) if ma.size else 0.0, 1e-300)
        if diff.size:
            i, j = (int(x) for x in np.unravel_index(int(np.argmax(diff)), diff.shape))
            err = float(diff[i, j]) / scale
            if mm.beats(err):
                mm.see(err, ref_dofs[i] if i == j else f"{ref_dofs[i]}/{ref_dofs[j]}",
                       f"sample {k}: M[{i},{j}] {ma[i, j]:.12g}, engine {mb[i, j]:.12g} "
                       f"(relative to max |M| = {scale:.6g})")
        ba = bias_of(q, dq)
        bb = engine_bias(in_engine(q), in_engine(dq))[idx]
        bdiff = np.abs(ba - bb)
        if bdiff.size:
            n = int(np.argmax(bdiff))
            speed = max((abs(v) for v in dq.values()), default=0.0)
            velocity_terms = (float(np.max(np.abs(ma))) if ma.size else 0.0) * speed**2
            bscale = max(1e-6, float(np.max(np.abs(ba))), velocity_terms)
            err = float(bdiff[n]) / bscale
            if bias.beats(err):
                bias.see(err, ref_dofs[n], f"sample {k}: bias {ba[n]:.12g}, engine {bb[n]:.12g} "
                                           f"(relative to max(1e-6, max |b|, max |M|·max |dq|²) = "
                                           f"{bscale:.6g})")
    what = f"{len(samples)} random (q, dq), {len(ref_dofs)} dofs"
    checks = [mm.check(3, label, "mass-matrix", eng.tolerance("mass-matrix"), what),
              bias.check(3, label, "bias", eng.tolerance("bias"), what)]
    if with_balls:  # say what was compared, also when the worst entry is a hinge's
        said = (f"{what}, each ball joint's three angles included (the URDF chain's coordinates, the ball "
                "at rest)")
        checks = [dataclasses.replace(c, detail=f"{c.detail}; {said}" if c.detail != what else said)
                  for c in checks]
    path = eng.model.settings.get("dynamics_path")
    if path:  # the engine took another documented route to the same numbers: say which
        checks = [dataclasses.replace(c, detail=f"{c.detail}; {path}") for c in checks]
    return checks


def no_dynamics(eng: Loaded, why: str = "") -> Skip:
    """The skip of an engine that gives no mass matrix or bias (``why``: the engine's own reason)."""
    return Skip(3, eng.label, why or f"{eng.label} computes kinematics only: no mass matrix or bias forces")


def kinematic_only(robot: Robot) -> bool:
    """True when no link the joints move has mass: a kinematic model, no dynamics to verify."""
    moved = {j.child for j in robot.joints}
    return not any(link.inertial is not None and link.inertial.mass > 0 for link in robot.links
                   if link.name in moved)
