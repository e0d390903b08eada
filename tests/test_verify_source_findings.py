"""A source inertia that a URDF reader refuses is the source's finding, not a conversion FAIL:
example-robot-data's Go1 ``base`` has all six terms 1e-6 (principal moments 0, 0, 3e-6: singular,
validate's MK302 for the link alone); PyBullet replaces it by zero. verify compares PyBullet with that
zero tensor and says so with the code."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import modelkit
from modelkit.verify.api import verify
from modelkit.verify.layers import approximations

GO1_LIKE = """<?xml version="1.0"?>
<robot name="go1_like">
  <link name="base">
    <inertial><mass value="5"/>
      <inertia ixx="1e-6" ixy="1e-6" ixz="1e-6" iyy="1e-6" iyz="1e-6" izz="1e-6"/></inertial>
  </link>
  <link name="trunk">
    <inertial><mass value="5"/><inertia ixx="0.02" iyy="0.05" izz="0.06" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="floating_base" type="fixed"><parent link="base"/><child link="trunk"/></joint>
  <link name="thigh">
    <inertial><origin xyz="0 0 -0.1"/><mass value="1"/>
      <inertia ixx="0.005" iyy="0.005" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="thigh"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="10"/></joint>
</robot>
"""


def test_the_refused_tensor_is_classified_with_validate_s_code(tmp_path: Path) -> None:
    path = tmp_path / "go1_like.urdf"
    path.write_text(GO1_LIKE)
    robot = modelkit.load(path)
    refused = approximations.refused_inertias("pybullet", "urdf", robot)
    assert set(refused) == {"base"}
    assert refused["base"].code == "MK302"  # a zero principal moment: singular
    assert np.allclose(refused["base"].tensor, 0.0)
    assert approximations.refused_inertias("mujoco", "mjcf", robot) == {}  # the MJCF writer lifts it
    assert approximations.refusal_code((0.19125, 0.19125, 0.45)) == "MK303"  # ClosedLinkSample-like


def test_pybullet_refusing_the_source_inertia_is_no_conversion_fail(tmp_path: Path) -> None:
    path = tmp_path / "go1_like.urdf"
    path.write_text(GO1_LIKE)
    report = verify(path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3, samples=3,
                    driven=False)
    assert not report.errors
    assert [c for c in report.checks if not c.passed] == [], [c for c in report.checks if not c.passed]
    inertia = [c for c in report.checks if c.engine == "pybullet" and c.quantity == "inertia"]
    assert len(inertia) == 1 and inertia[0].error == 0.0
    (entry,) = [s for s in report.skips if s.engine == "pybullet" and "source finding MK302" in s.reason]
    assert "base" in entry.reason and "holds zero" in entry.reason
    assert "not a conversion fault" in entry.reason
    # the base is welded: its tensor takes part in no dynamics, so the replay runs and passes
    assert [c for c in report.checks if c.quantity == "replay" and c.passed]
