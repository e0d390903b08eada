"""A tensor validate calls zero (every principal moment within ``ZERO_MOMENT`` = 1e-15 of 0, MK302) is
zero for verify too. example-robot-data's iCub writes such tensors: its ``head`` ±2.4e-35 off the
diagonal, its ``r_hip_2`` -5.4e-20 on it. verify failed iCub: Pinocchio refused ``r_hip_2`` ("The 3d
inertia should be positive"), and Drake's URDF reader, holding ``head`` as zero, was compared with the
solid sphere it gives a tensor it refuses (relative error 1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from modelkit.verify.api import verify
from modelkit.verify.layers.approximations import triangle_moments

HEAD = 'ixx="0" ixy="0" ixz="2.40741e-35" iyy="0" iyz="0" izz="0"'
HIP = 'ixx="-5.42101e-20" ixy="0" ixz="0" iyy="-5.42101e-20" iyz="0" izz="0"'


def _link(name: str, tensor: str, mass: float = 1.0) -> str:
    return (f'<link name="{name}"><inertial><origin xyz="0 0 -0.1"/><mass value="{mass}"/>'
            f'<inertia {tensor}/></inertial></link>')


def _revolute(name: str, parent: str, child: str, axis: str) -> str:
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0 0 -0.2"/><axis xyz="{axis}"/>'
            '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>')


def test_zero_tensors_are_zero_in_every_engine(tmp_path: Path) -> None:
    path = tmp_path / "zero.urdf"
    path.write_text(
        '<robot name="zero">'
        + _link("base", 'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"', 5.0)
        + _link("head", HEAD) + _link("hip", HIP)
        + _link("shin", 'ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"')
        + _revolute("neck", "base", "head", "0 1 0") + _revolute("hip_joint", "base", "hip", "1 0 0")
        + _revolute("knee", "hip", "shin", "0 1 0")
        + "</robot>")
    report = verify(path, tmp_path / "out", engines=("pinocchio", "drake-urdf", "pybullet", "mujoco"),
                    replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    graded = {(c.layer, c.engine, c.quantity) for c in report.checks}
    # layer 3 compares each engine with Pinocchio's dynamics, built from the source
    assert {(1, "pinocchio", "inertia"), (1, "drake-urdf", "inertia"), (3, "drake-urdf", "mass-matrix"),
            (3, "pybullet", "mass-matrix")} <= graded


def test_a_zero_tensor_violates_no_triangle_but_a_real_violation_does() -> None:
    assert triangle_moments(np.array([[0, 0, 2.40741e-35], [0, 0, 0], [2.40741e-35, 0, 0]])) is None
    assert triangle_moments(np.diag([1e-3, 1e-3, 3e-3])) is not None
