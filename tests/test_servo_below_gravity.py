"""MK868: a position servo whose force limit is below the gravity load it holds at home is said, with
the load and the limit; MuJoCo, running the written file, is the oracle of both the load (its inverse
dynamics at home) and the sag.

The test arm is a base and one horizontal link on a hinge about y: 2 kg at 0.25 m, a gravity load of
2 × 9.81 × 0.25 = 4.905 N·m at q = 0. Its effort limit decides whether the servo the default
``--actuators auto`` writes can hold it. example-robot-data's PR2, whose shoulders need 52 N·m against
their 30 N·m limit (the real arm's counterbalance spring is not in its URDF), is the real case.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from tests.conftest import example_robot, example_robot_data

mujoco = pytest.importorskip("mujoco")
np = pytest.importorskip("numpy")

ARM = """<robot name="arm">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <dynamics friction="FRICTION"/>
    <limit lower="-2" upper="2" effort="EFFORT" velocity="1"/></joint>
</robot>
"""


def _convert(tmp_path: Path, effort: float, friction: float = 0.0) -> tuple[list, Path]:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace("EFFORT", str(effort)).replace("FRICTION", str(friction)))
    out = tmp_path / "out" / "arm.xml"
    return write(load(path), out, force=True), out


def _tip_drift(path: Path, seconds: float = 2.0) -> float:
    """How far the arm's bodies move from home in ``seconds`` under the written servos (m)."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    start = data.xipos.copy()  # the centres of mass: a body frame on its hinge stays put
    worst = 0.0
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
        worst = max(worst, float(np.linalg.norm(data.xipos - start, axis=1).max()))
    return worst


def test_a_servo_weaker_than_gravity_is_said_and_the_arm_sags(tmp_path: Path) -> None:
    notes, out = _convert(tmp_path, effort=3.0)
    (said,) = [n for n in notes if n.code == "MK868"]
    assert said.severity == "warning"
    assert "1 joint(s)" in said.message and "shoulder 4.91 > 3;" in said.message
    assert _tip_drift(out) > 0.05  # saturated at 3 N·m of 4.9, the link falls


def test_a_servo_strong_enough_is_not_said_and_holds(tmp_path: Path) -> None:
    notes, out = _convert(tmp_path, effort=10.0)
    assert not [n for n in notes if n.code == "MK868"]
    assert _tip_drift(out) < 1e-3


def test_friction_that_makes_up_the_difference_is_counted(tmp_path: Path) -> None:
    # 4.905 N·m of load less 2 N·m of Coulomb friction is within a 3 N·m limit
    notes, _ = _convert(tmp_path, effort=3.0, friction=2.0)
    assert not [n for n in notes if n.code == "MK868"]


def test_the_pr2_shoulders_are_said_with_mujocos_own_load(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    source = example_robot("pr2_description/urdf/pr2.urdf")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(example_robot_data()))
    out = tmp_path / "pr2" / "pr2.xml"
    notes = write(load(source), out, force=True)
    (said,) = [n for n in notes if n.code == "MK868"]
    assert "2 joint(s)" in said.message
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)  # at rest: qfrc_bias is gravity's load on each joint
    for side in ("l", "r"):
        joint = model.joint(f"{side}_shoulder_lift_joint")
        need = abs(float(data.qfrc_bias[joint.dofadr[0]]))
        limit = float(model.actuator(f"{side}_shoulder_lift_joint").forcerange[1])
        assert need > limit == 30.0
        assert f"{side}_shoulder_lift_joint {need:.3g} > 30" in said.message
    # the other joints hold: no third name, and MuJoCo's load is within every other servo's range
    for a in range(model.nu):
        joint = int(model.actuator_trnid[a, 0])
        if model.joint(joint).name.endswith("shoulder_lift_joint") or not model.actuator_forcelimited[a]:
            continue
        assert abs(float(data.qfrc_bias[model.jnt_dofadr[joint]])) <= model.actuator_forcerange[a][1]


def test_an_arm_folded_on_a_quadrupeds_back_carries_no_leg_share(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """example-robot-data's B1 with a Z1 arm: the arm at q = 0 lies folded on the body, a fifth limb not
    pointing up. Only the four limbs whose feet reach the ground are legs, so the arm's joint3 holds its
    own 8 N·m, not a fifth of the robot's weight (49.9 N·m, said as beyond its 30 N·m limit before)."""
    from modelkit.convert.base import decide
    from modelkit.convert.legs import carried_loads, leg_joints
    from modelkit.convert.servo_gains import joint_loads

    source = example_robot("b1_description/urdf/b1-z1.urdf")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(example_robot_data()))
    robot = load(source)
    robot.root_joint = decide(robot).kind  # floating: it stands on its four feet
    legs = leg_joints(robot)
    assert len(legs) == 12 and all(name[:3] in ("FL_", "FR_", "RL_", "RR_") for name in legs)
    assert set(carried_loads(robot, {})) == legs
    assert joint_loads(robot)["joint3"].gravity == pytest.approx(8.03, abs=0.01)
    notes = write(robot, tmp_path / "b1" / "b1.xml", force=True)
    assert not [n for n in notes if n.code == "MK868"]
