"""An MJCF joint equality whose actuator is on ``joint1`` (issue 17 §2, §8): MuJoCo reads
``q1 = c0 + c1 q2`` as a constraint between two free joints, so a source may actuate either;
safety-gymnasium's racecar puts its steering servo on ``joint1``. The model's mimic has a direction and
a follower carries no actuator, so the reader reads the constraint the other way there, and the servo
is written on every target (it was left out with MK842: the written racecar could not steer).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.api import load
from modelkit.cli import main

STEERED = """<mujoco model="steered">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">
      <geom type="box" size="0.2 0.1 0.05" mass="2"/>
      <body name="left" pos="0.2 0.2 0">
        <joint name="left_steer" axis="0 0 1" range="-0.7 0.7" damping="0.5" armature="0.01"/>
        <geom type="cylinder" size="0.03 0.02" mass="0.1"/>
      </body>
      <body name="right" pos="0.2 -0.2 0">
        <joint name="right_steer" axis="0 0 1" range="-0.7 0.7" damping="0.5" armature="0.01"/>
        <geom type="cylinder" size="0.03 0.02" mass="0.1"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint joint1="left_steer" joint2="right_steer" polycoef="{coef} 0 0 0"/>
  </equality>
  <actuator>
    <position name="steer" joint="{actuated}" kp="5" ctrlrange="-0.7 0.7"/>
  </actuator>
</mujoco>
"""


def _source(tmp_path: Path, actuated: str, coef: str = "0 1") -> Path:
    path = tmp_path / "steered.xml"
    path.write_text(STEERED.format(coef=coef, actuated=actuated))
    return path


def _mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    return {j.name: (j.mimic.joint, j.mimic.multiplier, j.mimic.offset)
            for j in load(path).joints if j.mimic is not None}


def test_the_actuated_joint1_leads(tmp_path: Path) -> None:
    assert _mimics(_source(tmp_path, "left_steer")) == {"right_steer": ("left_steer", 1.0, 0.0)}
    # the same file actuating joint2 keeps MuJoCo's reading: joint1 follows joint2
    assert _mimics(_source(tmp_path, "right_steer")) == {"left_steer": ("right_steer", 1.0, 0.0)}
    # a linear coupling with an offset, read the other way: q2 = (q1 − 0.1) / 2
    assert _mimics(_source(tmp_path, "left_steer", "0.1 2")) == {"right_steer": ("left_steer", 0.5, -0.05)}


def _settled(xml: Path, target: float, actuator: str = "steer",
             joints: tuple[str, ...] = ("left_steer", "right_steer")) -> np.ndarray:
    """The joints' positions after 3 s with ``actuator``'s control at ``target``."""
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)] = target
    for _ in range(int(3.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    return np.array([d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]]
                     for name in joints])


@pytest.mark.parametrize("coef", ["0 1", "0.1 2"])
def test_the_written_mjcf_steers_as_the_source(tmp_path: Path, coef: str) -> None:
    source = _source(tmp_path, "left_steer", coef)
    out = tmp_path / "out" / "steered.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "MK842" not in result.output and "MK808" not in result.output
    tree = etree.parse(str(out))
    (eq,) = tree.findall("equality/joint")
    assert (eq.get("joint1"), eq.get("joint2")) == ("left_steer", "right_steer")  # as the source wrote it
    assert eq.get("polycoef") == f"{coef} 0 0 0"
    assert [a.get("joint") for a in tree.find("actuator")] == ["left_steer"]
    # the user's next step: command the servo; both wheels turn as in the source
    got, want = _settled(out, 0.3), _settled(source, 0.3)
    assert abs(want[0] - 0.3) < 0.01 and abs(got[0] - 0.3) < 0.01, (got, want)
    assert np.max(np.abs(got - want)) < 1e-3, (got, want)


def test_urdf_puts_the_transmission_on_the_leader(tmp_path: Path) -> None:
    out = tmp_path / "out" / "steered.urdf"
    result = CliRunner().invoke(main, ["convert", str(_source(tmp_path, "left_steer")), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "MK842" not in result.output
    tree = etree.parse(str(out))
    (mimic,) = tree.findall("joint/mimic")
    assert mimic.getparent().get("name") == "right_steer" and mimic.get("joint") == "left_steer"
    actuated = {j.get("name") for j in tree.iter("joint") if j.getparent().tag == "transmission"}
    actuated |= {j.get("name") for j in tree.findall("ros2_control/joint")}
    assert "left_steer" in actuated and "right_steer" not in actuated, etree.tostring(tree).decode()[-1500:]


# Reachy 2's gripper (sai-mujoco): the servo is on the finger joint, which the equalities make follow
# the proximal joint, which in turn follows the distal joint and a copy of itself; the distal joint
# follows its own copy. Five joints, four linear equalities, no loop, one actuated joint.
GRIPPER = """<mujoco model="gripper">
  <compiler angle="radian"/>
  <worldbody>
    <body name="palm">
      <geom type="box" size="0.05 0.05 0.02" mass="0.5"/>
      {bodies}
    </body>
  </worldbody>
  <equality>
    <joint joint1="finger" joint2="proximal" polycoef="0.554 -0.4689 0 0 0" {solver}/>
    <joint joint1="proximal" joint2="distal" polycoef="0 -1 0 0 0" {solver}/>
    <joint joint1="proximal" joint2="proximal_copy" polycoef="0 1 0 0 0" {solver}/>
    <joint joint1="distal" joint2="distal_copy" polycoef="0 1 0 0 0" {solver}/>
  </equality>
  <actuator>
    <position name="grip" joint="finger" kp="2" ctrlrange="0.3 0.8"/>
  </actuator>
</mujoco>
"""
GRIPPER_JOINTS = ("finger", "proximal", "distal", "proximal_copy", "distal_copy")
GRIPPER_SOLVER = 'solref="0.005 1" solimp="0.95 0.99 0.001"'


def _gripper(tmp_path: Path) -> Path:
    bodies = "\n      ".join(
        f'<body name="{name}_link" pos="0 {0.02 * i:g} 0.03"><joint name="{name}" axis="1 0 0" '
        f'range="-3 3" damping="0.05" armature="0.001"/><geom type="capsule" size="0.005 0.02" contype="0" '
        f'conaffinity="0" '
        f'mass="0.01"/></body>'
        for i, name in enumerate(GRIPPER_JOINTS))
    path = tmp_path / "gripper.xml"
    path.write_text(GRIPPER.format(bodies=bodies, solver=GRIPPER_SOLVER))
    return path


def test_a_group_of_coupled_joints_is_read_from_its_actuated_joint(tmp_path: Path) -> None:
    mimics = _mimics(_gripper(tmp_path))
    # proximal = (finger − 0.554) / −0.4689; distal = −proximal; the copies as their joints
    m, o = 1.0 / -0.4689, 0.554 / 0.4689
    want = {"proximal": (m, o), "distal": (-m, -o), "proximal_copy": (m, o), "distal_copy": (-m, -o)}
    assert set(mimics) == set(want)
    for name, (mult, off) in want.items():
        leader, got_m, got_o = mimics[name]
        assert leader == "finger" and got_m == pytest.approx(mult, rel=1e-12) and got_o == pytest.approx(off)


def test_the_written_gripper_closes_as_the_source_on_every_target(tmp_path: Path) -> None:
    source = _gripper(tmp_path)
    out = tmp_path / "out" / "gripper.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "MK842" not in result.output and "MK808" not in result.output  # the servo kept, nothing lost
    written = etree.parse(str(out))
    assert [a.get("joint") for a in written.find("actuator")] == ["finger"]
    # every coupling, the composed ones too, as soft as the source's equalities
    assert {(e.get("solref"), e.get("solimp")) for e in written.findall("equality/joint")} == {
        ("0.005 1", "0.95 0.99 0.001 0.5 2")}
    got, want = _settled(out, 0.6, "grip", GRIPPER_JOINTS), _settled(source, 0.6, "grip", GRIPPER_JOINTS)
    assert abs(want[0] - 0.6) < 0.01 and np.max(np.abs(got - want)) < 1e-3, (got, want)
    urdf = tmp_path / "out" / "gripper.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(urdf)])
    assert result.exit_code == 0 and "MK842" not in result.output, result.output
    tree = etree.parse(str(urdf))
    assert {m.getparent().get("name"): m.get("joint") for m in tree.iter("mimic")} == {
        name: "finger" for name in GRIPPER_JOINTS[1:]}
    actuated = {j.get("name") for j in tree.iter("joint") if j.getparent().tag == "transmission"}
    assert actuated == {"finger"}
