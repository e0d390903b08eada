"""PyBullet's inverse-dynamics library (``calculateMassMatrix``, ``calculateInverseDynamics``) refuses
a tensor it composed itself when its rounding leaves it asymmetric by more than 5 machine epsilons
(an absolute 1.1e-15 kg·m²): heavy links whose principal axes are turned reach that, as the KUKA KR210
of rtb-data does (1.4e-14 on link_2). The file is sound; verify failed it with "engine-error". Layer 3a
now reads PyBullet's mass matrix and bias from its forward dynamics for such a model, says so, and
still fails an injected fault."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet
import pytest

from modelkit.verify.api import verify

# KR210's link_2 tensor (kg·m²), its mass and COM: products of inertia turn the principal axes
HEAVY = 'ixx="180.42" ixy="-0.83462" ixz="0.32549" iyy="177.68" iyz="-20.82" izz="20.495"'


def _arm(path: Path) -> Path:
    path.write_text(
        '<robot name="heavy">'
        '<link name="base"><inertial><mass value="50"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<link name="upper"><inertial><origin xyz="0.25 0.1 0.6"/><mass value="600"/>'
        f'<inertia {HEAVY}/></inertial></link>'
        '<link name="fore"><inertial><origin xyz="0.5 0 0.1" rpy="0.3 0.2 0.1"/><mass value="300"/>'
        f'<inertia {HEAVY}/></inertial></link>'
        '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
        '<origin xyz="0 0 0.7"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1e4" velocity="2"/>'
        '</joint>'
        '<joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>'
        '<origin xyz="0 0 1.1"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1e4" velocity="2"/>'
        '</joint></robot>')
    return path


def _refused_by_inverse_dynamics(urdf: Path) -> bool:
    client = pybullet.connect(pybullet.DIRECT)
    try:
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
        body = pybullet.loadURDF(str(urdf), useFixedBase=True, flags=flags, physicsClientId=client)
        try:
            pybullet.calculateMassMatrix(body, [0.3, -0.4], physicsClientId=client)
        except (pybullet.error, SystemError):
            return True
        return False
    finally:
        pybullet.disconnect(physicsClientId=client)


@pytest.fixture(scope="module")
def arm(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _arm(tmp_path_factory.mktemp("heavy") / "heavy.urdf")


def test_pybullet_is_graded_through_its_forward_dynamics(arm: Path, tmp_path: Path) -> None:
    report = verify(arm, tmp_path / "out", engines=("pinocchio", "pybullet", "mujoco"), replay=False,
                    driven=False)
    assert _refused_by_inverse_dynamics(tmp_path / "out" / "heavy.urdf")  # the case is real
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    graded = {c.quantity: c for c in report.checks if c.layer == 3 and c.engine == "pybullet"}
    assert set(graded) == {"mass-matrix", "bias"}
    for check in graded.values():
        assert check.error < 1e-8 and "forward dynamics" in check.detail and "upper" in check.detail
    assert "forward dynamics" in report.engines["pybullet"]["dynamics_path"]


def test_the_forward_route_still_fails_a_fault(arm: Path, tmp_path: Path) -> None:
    report = verify(arm, tmp_path / "out", engines=("pinocchio", "pybullet"), replay=False, driven=False,
                    inject=("mass:fore:10%",))
    failed = {(c.layer, c.engine, c.quantity) for c in report.checks if not c.passed}
    assert {(3, "pybullet", "mass-matrix"), (3, "pybullet", "bias")} <= failed
    worst = next(c for c in report.checks
                 if (c.layer, c.engine, c.quantity) == (3, "pybullet", "mass-matrix"))
    assert worst.error > 1e-3 and np.isfinite(worst.error)
