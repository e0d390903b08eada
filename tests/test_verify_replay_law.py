"""The replay's PD law (``replay.default_law``): gains from the effective inertia 1/(M⁻¹)ᵢᵢ and the
stability criterion of semi-implicit Euler on the linearised closed loop (``replay.step_growth``)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.verify.layers.replay import (
    MAX_BANDWIDTH,
    _axis_inertia_and_gravity,
    default_law,
    stable_scale,
    step_growth,
)
from tests.conftest import CORPUS

DT = 1e-3
HOPPER = CORPUS / "dm_control_suite" / "dm_control" / "suite" / "hopper.xml"


def test_one_joint_growth_is_the_textbook_limit() -> None:
    """One joint of inertia 1: semi-implicit Euler is stable for kd·dt < 2 (undamped: ω·dt < 2)."""
    m = np.array([[1.0]])
    assert step_growth(m, np.array([1e4]), np.array([140.0]), DT) < 1.0  # ω = 100 rad/s, ζ = 0.7
    assert step_growth(m, np.array([1e4]), np.array([2.5e3]), DT) > 1.0  # kd·dt = 2.5
    assert step_growth(m, np.array([4.1e6]), np.array([0.0]), DT) > 1.0  # ω·dt = 2.02
    assert step_growth(m, np.array([3.9e6]), np.array([0.0]), DT) == pytest.approx(1.0)  # undamped: on it


def test_coupled_gains_from_the_diagonal_are_rejected_from_the_effective_inertia_accepted() -> None:
    """Two strongly coupled joints (hopper's planar root and torso): M's diagonal is 1, the effective
    inertia 1/(M⁻¹)ᵢᵢ is 0.0199. Gains sized on the diagonal look safe joint by joint (kd·dt/Mᵢᵢ =
    0.14) but the loop diverges; sized on the effective inertia it contracts."""
    m = np.array([[1.0, 0.99], [0.99, 1.0]])
    diagonal = np.diag(m)
    effective = 1.0 / np.diag(np.linalg.inv(m))
    assert effective == pytest.approx([0.0199, 0.0199])
    omega, zeta = MAX_BANDWIDTH, 0.7

    def gains(inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        kp = inertia * omega**2
        return kp, 2.0 * zeta * np.sqrt(kp * inertia)

    rejected = gains(diagonal)
    assert step_growth(m, *rejected, DT) > 1.5
    accepted = gains(effective)
    assert step_growth(m, *accepted, DT) < 1.0
    # the law's remedy for the rejected set: halve the bandwidth until the step contracts
    inverse = np.linalg.inv(m)
    scale = stable_scale(inverse, *rejected, DT)
    assert scale < 1.0
    assert step_growth(m, rejected[0] * scale**2, rejected[1] * scale, DT) < 1.0
    assert step_growth(m, rejected[0] * (2 * scale) ** 2, rejected[1] * 2 * scale, DT) >= 1.0 - 1e-6
    assert stable_scale(inverse, *accepted, DT) == 1.0


@pytest.mark.skipif(not HOPPER.exists(), reason="corpus not present")
def test_hopper_law_uses_the_effective_inertia_and_is_stable() -> None:
    """hopper (planar root joints in the tree, armature zeroed as the replay does): the subtree
    inertia overstates what the torso joints drive ~100×; the law's loop contracts at 1 ms."""
    pytest.importorskip("pinocchio")
    from modelkit.verify.engines.pinocchio import PinocchioModel

    robot = modelkit.load(HOPPER)
    law = default_law(robot, DT)
    model = PinocchioModel(robot)
    model.model.armature = np.zeros(model.model.nv)
    full = model.mass_matrix({})
    index = [model.dof_names().index(n) for n in law.joints]
    inverse = np.linalg.inv(full)[np.ix_(index, index)]
    m = np.linalg.inv(inverse)
    growth = step_growth(m, np.array(law.kp), np.array(law.kd), DT)
    assert growth < 1.0
    world = robot.world_poses({})
    children: dict[str, list[str]] = {}
    for j in robot.joints:
        children.setdefault(j.parent, []).append(j.child)
    subtree, _ = _axis_inertia_and_gravity(robot, "waist", world, children)
    waist = law.joints.index("waist")
    effective = 1.0 / inverse[waist, waist]
    assert subtree > 50 * effective
    assert law.kd[waist] == pytest.approx(2 * 0.7 * math.sqrt(law.kp[waist] * effective))
    assert math.sqrt(law.kp[waist] / effective) <= MAX_BANDWIDTH * (1 + 1e-12)
    # the old rule (gains from the subtree inertia) is what the criterion rejects: measured 1.9-2.2
    old_kp, old_kd = np.zeros(len(law.joints)), np.zeros(len(law.joints))
    joints = {j.name: j for j in robot.joints}
    for i, joint in enumerate(joints[n] for n in law.joints):
        inertia, load = _axis_inertia_and_gravity(robot, joint.name, world, children)
        reference = 1.0 if joint.type.value == "revolute" else 0.1
        stiffness = max(inertia * (2 * math.pi * 2) ** 2, 10 * load / reference)
        old_kp[i] = min(stiffness, inertia * MAX_BANDWIDTH**2)
        old_kd[i] = 2 * 0.7 * math.sqrt(old_kp[i] * inertia)
    assert step_growth(m, old_kp, old_kd, DT) > 1.5


@pytest.mark.skipif(not HOPPER.exists(), reason="corpus not present")
def test_without_pinocchio_the_law_falls_back_to_the_subtree_inertia(monkeypatch: pytest.MonkeyPatch) -> None:
    """Pinocchio absent (its adapter cannot be imported): the gains come from the subtree inertia."""
    robot = modelkit.load(HOPPER)
    monkeypatch.setitem(sys.modules, "modelkit.verify.engines.pinocchio", None)
    law = default_law(robot, DT)
    children: dict[str, list[str]] = {}
    for j in robot.joints:
        children.setdefault(j.parent, []).append(j.child)
    waist = law.joints.index("waist")
    subtree, _ = _axis_inertia_and_gravity(robot, "waist", robot.world_poses({}), children)
    assert law.kd[waist] == pytest.approx(2 * 0.7 * math.sqrt(law.kp[waist] * subtree))


def test_a_mimic_joint_is_held_not_left_free() -> None:
    """The replay runs the open tree (limits and mimic couplings off), so a joint the law left out
    would be free to be flung away (Panda's finger_joint2 reached 100 m/s, PyBullet's clamp, at
    4.7 s). The mimic follower is in the law, held at q = 0 with its own gains."""
    robot = modelkit.load(Path(__file__).parent / "replay" / "bead_mimic.urdf")
    law = default_law(robot, DT)
    follower = law.joints.index("finger_b_joint")
    leader = law.joints.index("finger_a_joint")
    assert law.amplitude[follower] == 0.0
    assert law.kp[follower] > 0.0 and law.kd[follower] > 0.0
    assert law.kp[follower] == pytest.approx(law.kp[leader])


def _stiffened(factor: float):  # type: ignore[no-untyped-def]
    """``default_law`` at ``factor`` times its bandwidth (kp × factor², kd × factor)."""
    import dataclasses

    def law(source, dt=DT):  # type: ignore[no-untyped-def]
        base = default_law(source, dt)
        return dataclasses.replace(base, kp=tuple(k * factor**2 for k in base.kp),
                                   kd=tuple(k * factor for k in base.kd))
    return law


def test_a_law_the_reference_cannot_integrate_is_softened(monkeypatch: pytest.MonkeyPatch) -> None:
    """robosuite's GR1 humanoid (layers 1–3a equal to 1e-15) blew up in MuJoCo at 4.48 s under the
    replay law, and verify failed a sound conversion; at half the bandwidth the engines agreed to
    2.6e-13 rad. Reproduced on the hopper with the law at 32× its bandwidth (ω·dt 3.2, beyond semi-
    implicit Euler's limit of 2): verify halves the bandwidth until MuJoCo integrates it (3 times,
    ω·dt 0.4), says so, and the replay passes; with no halving allowed the same run fails."""
    from modelkit.verify import api
    from modelkit.verify.layers import replay

    monkeypatch.setattr(replay, "default_law", _stiffened(32.0))
    report = api.verify(HOPPER)
    graded = ("replay", "stability", "engine-error")
    layer3 = [c for c in report.checks if c.layer == 3 and c.quantity in graded]
    assert layer3 and all(c.passed for c in layer3), [c.detail for c in layer3 if not c.passed]
    (said,) = [s.reason for s in report.skips if "softened" in s.reason]
    assert said.startswith("layer 3b's law softened 3×") and "0.125× the bandwidth" in said
    monkeypatch.setattr(api, "LAW_SOFTENINGS", 0)
    report = api.verify(HOPPER)
    assert [c for c in report.checks if c.layer == 3 and not c.passed and c.engine == "mujoco"]
