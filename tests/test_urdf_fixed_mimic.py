"""URDF: a ``<mimic>`` on a fixed joint (MK325) and joint limits at SDF's "no limit" (verify layer 1).

example-robot-data's ``talos_reduced.urdf`` keeps the full model's gripper mimics on joints it made
fixed; Drake refused the URDF ``convert`` wrote ("which has 0 DOF cannot mimic"), and verify failed the
conversion. The oracle is Drake's parser: it refuses the source and loads what ``convert`` writes.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from modelkit.api import load, validate
from modelkit.convert.api import write
from modelkit.verify.layers.static import _limit_error
from tests.test_sdf_actuators import _drake_loads

SOURCE = """<robot name="g">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="pad"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="finger_joint" type="revolute"><parent link="base"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit effort="1" lower="-1" upper="0" velocity="1"/></joint>
  <joint name="pad_joint" type="fixed"><parent link="finger"/><child link="pad"/><origin xyz="0 0 0.05"/>
    <mimic joint="finger_joint" multiplier="1" offset="0"/></joint>
</robot>
"""


def test_a_mimic_on_a_fixed_joint_is_said_and_dropped(tmp_path: Path) -> None:
    source = tmp_path / "g.urdf"
    source.write_text(SOURCE)
    with pytest.raises(Exception, match="0 DOF cannot mimic"):
        _drake_loads(source)
    (said,) = [d for d in validate(source).diagnostics if d.code == "MK325"]
    assert said.severity == "warning" and "'pad_joint' is fixed" in said.message
    robot = load(source)
    assert all(j.mimic is None for j in robot.joints)
    out = tmp_path / "out" / "g.urdf"
    write(robot, out, force=True)
    assert "<mimic" not in out.read_text()
    assert _drake_loads(out) >= 2  # it loads: finger_joint, pad_joint (and the base's joint to the world)


def test_sdf_no_limit_equals_infinity() -> None:
    """Layer 1 compares a limit of ±1e16 (SDF's default, "none") with ±inf as equal; finite limits as
    numbers, as before."""
    assert _limit_error(1e16, math.inf) == 0.0 and _limit_error(-1e16, -math.inf) == 0.0
    assert _limit_error(1e16, -math.inf) == math.inf
    assert _limit_error(1e15, math.inf) == math.inf
    assert _limit_error(1.0, 1.0 + 1e-12) < 1e-9
    assert _limit_error(1e16, 1e15) == pytest.approx(0.9)  # finite stand-ins are held exactly
    assert _limit_error(1e16, 1e17) == pytest.approx(0.9)
