"""verify on long chains (issue 18 §2): no traceback, no cubic memory, no quadratic reference.

Real engines, no mocks: yourdfpy's per-joint composition against its own path search, Pinocchio's
Data size bound, PyBullet's joint-state limit and the replay law's refusal are each measured here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from modelkit.api import load
from modelkit.verify.api import verify
from tests import chain_support

pytest.importorskip("yourdfpy")
pytest.importorskip("pinocchio")


def test_yourdfpy_poses_are_its_own_path_products(tmp_path: Path) -> None:
    """The per-joint composition gives what ``get_transform(link, root)`` gives (to rounding), also
    for a root below the URDF's base link, and does not grow with the square of the chain."""
    from modelkit.verify.engines.reference import YourdfpyKinematics

    path = chain_support.write(tmp_path, "urdf", 60, branches=3)
    for root in ("link0", "link5"):
        model = YourdfpyKinematics(path, root)
        rng = np.random.default_rng(3)
        q = {name: float(rng.uniform(-1.0, 1.0)) for name in model.dof_names()}
        ours = model.link_poses(q)
        model.urdf.update_cfg(q)
        assert set(ours) == {link.name for link in model.urdf.robot.links}
        for link, pose in ours.items():
            theirs = np.asarray(model.urdf.get_transform(link, root), dtype=float)
            assert np.abs(pose.translation - theirs[:3, 3]).max() < 1e-12, link
            assert np.abs(pose.rotation - theirs[:3, :3]).max() < 1e-12, link


def test_pinocchio_refuses_a_data_of_cubic_size_before_allocating_it(tmp_path: Path) -> None:
    from modelkit.verify.engines.pinocchio import PinocchioModel, TooManyDofs, max_dofs

    assert max_dofs() == 161
    PinocchioModel(load(chain_support.write(tmp_path, "urdf", max_dofs() + 1)))  # 161 joints: built
    with pytest.raises(TooManyDofs, match="162 degrees of freedom"):
        PinocchioModel(load(chain_support.write(tmp_path, "urdf", max_dofs() + 2)))


def test_the_replay_law_of_a_long_chain_is_refused_not_a_traceback(tmp_path: Path) -> None:
    """A 30-link chain's slowest modes contract by less than 1e-6 per step whatever the gains."""
    from modelkit.verify.layers.replay import UnstableLaw, default_law

    with pytest.raises(UnstableLaw, match="slowest modes of a long chain"):
        default_law(load(chain_support.write(tmp_path, "urdf", 30)))
    with pytest.raises(UnstableLaw, match="cannot be checked: 199 degrees of freedom"):
        default_law(load(chain_support.write(tmp_path, "urdf", 200)))


def test_verify_of_a_200_link_chain_skips_what_the_engines_cannot_hold(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    pytest.importorskip("pybullet")
    source = chain_support.write(tmp_path, "urdf", 200)
    report = verify(source, tmp_path / "out", engines=("mujoco", "pybullet", "pinocchio", "yourdfpy"),
                    driven=False)
    assert not report.errors and not report.failed and report.exit_code == 0, report.failed[:3]
    reasons = {(s.engine, s.layer): s.reason for s in report.skips}
    assert "199 joints" in reasons[("pybullet", 0)]
    assert "199 degrees of freedom" in reasons[("pinocchio", 0)]
    assert {c.engine for c in report.checks if c.layer == 2} >= {"mujoco", "yourdfpy"}


def test_pybullets_joint_limit_is_its_own(tmp_path: Path) -> None:
    """The skip above is PyBullet's limit, not ours: 127 moving joints answer, 128 do not."""
    pytest.importorskip("pybullet")
    from modelkit.verify.engines.pybullet import (
        MAX_MOVING_JOINTS,
        PyBulletError,
        PyBulletModel,
        TooManyJoints,
        load,
    )

    fits = chain_support.write(tmp_path, "urdf", MAX_MOVING_JOINTS + 1)
    model = load(fits, {}, root="link0")
    try:
        assert len(model.link_poses({})) == MAX_MOVING_JOINTS + 1
    finally:
        model.close()
    beyond = chain_support.write(tmp_path, "urdf", MAX_MOVING_JOINTS + 2)
    with pytest.raises(TooManyJoints, match=f"{MAX_MOVING_JOINTS + 1} joints"):
        load(beyond, {}, root="link0")
    unchecked = PyBulletModel(beyond, {}, "link0")  # past the check: PyBullet itself fails
    try:
        with pytest.raises(PyBulletError, match="getJointState failed"):
            unchecked.link_poses({})
    finally:
        unchecked.close()


def test_mujocos_refusal_of_a_deep_mjcf_is_explained(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    from modelkit.formats.mjcf.writer import MUJOCO_MAX_BODY_DEPTH

    source = chain_support.write(tmp_path, "urdf", MUJOCO_MAX_BODY_DEPTH + 1)
    report = verify(source, tmp_path / "out", engines=("mujoco",), driven=False, replay=False)
    [load_check] = [c for c in report.checks if c.quantity == "load"]
    assert not load_check.passed and report.exit_code == 1
    assert "XML_ELEMENT_DEPTH_EXCEEDED" in load_check.detail and "MK872" in load_check.detail


def _star(path: Path, moving: int, fixed: int) -> Path:
    """A base with ``moving`` revolute and ``fixed`` fixed children (a tree, as example-robot-data's
    tiago_dual: 101 moving and 28 fixed joints)."""
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    parts = [f'<robot name="star"><link name="base">{inertial}</link>']
    for i in range(moving + fixed):
        kind = "revolute" if i < moving else "fixed"
        parts.append(f'<link name="l{i}">{inertial}</link><joint name="j{i}" type="{kind}">'
                     f'<parent link="base"/><child link="l{i}"/><origin xyz="{0.01 * i} 0 0"/>'
                     '<axis xyz="0 1 0"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    path.write_text("\n".join([*parts, "</robot>"]))
    return path


def test_pybullets_limit_counts_fixed_joints_too(tmp_path: Path) -> None:
    """100 moving and 28 fixed joints: PyBullet answers no getJointState (tiago_dual failed layers 2
    and 3 so), so verify's check counts every joint and skips PyBullet, as for a long chain."""
    pytest.importorskip("pybullet")
    from modelkit.verify.engines.pybullet import PyBulletError, PyBulletModel, TooManyJoints, load

    tree = _star(tmp_path / "star.urdf", 100, 28)
    with pytest.raises(TooManyJoints, match="128 joints"):
        load(tree, {}, root="base")
    unchecked = PyBulletModel(tree, {}, "base")
    try:
        with pytest.raises(PyBulletError, match="getJointState failed"):
            unchecked.link_poses({})
    finally:
        unchecked.close()
