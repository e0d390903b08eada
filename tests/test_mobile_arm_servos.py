"""A mobile manipulator's arm holds its pose (issue 17 §2): ``--actuators auto`` gave a motor to every
joint without a range on a free base, taking them for wheels and casters. roboschool's Fetch has three
continuous roll joints in its arm; as motors, its gripper fell 0.22 m in 2 s on a plain floor. An
unranged joint off the ground that is not a wheel and that gravity turns at home now gets a position
servo, as on a welded arm; the wheels, and a pan joint about a vertical axis, stay motors.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
from click.testing import CliRunner

from modelkit.cli import main

INERTIA = '<inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/>'


def _link(name: str, mass: float, com: str, collision: str) -> str:
    return (f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
            f'{INERTIA.format(i=0.01 * mass)}</inertial>{collision}</link>')


def _joint(name: str, kind: str, parent: str, child: str, xyz: str, axis: str, rpy: str = "0 0 0") -> str:
    limit = '<limit lower="-1" upper="1" effort="50" velocity="1"/>' if kind == "revolute" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>')


WHEEL = ('<collision><origin rpy="1.5707963267949 0 0"/><geometry><cylinder radius="0.1" length="0.04"/>'
         '</geometry></collision>')
BOX = '<collision><geometry><box size="{s}"/></geometry></collision>'
MOBILE_ARM = "".join([
    '<robot name="mobile_arm">',
    _link("base", 20.0, "0 0 0.2", BOX.format(s="0.5 0.4 0.2").replace("<geometry>",
                                                                       '<origin xyz="0 0 0.2"/><geometry>')),
    _link("caster", 0.5, "0 0 0", '<collision><geometry><sphere radius="0.1"/></geometry></collision>'),
    _link("left_wheel", 1.0, "0 0 0", WHEEL),
    _link("right_wheel", 1.0, "0 0 0", WHEEL),
    _link("pan", 1.0, "0 0 0.05", BOX.format(s="0.1 0.1 0.1")),
    _link("shoulder", 2.0, "0 0 0.15", BOX.format(s="0.08 0.08 0.3")),
    _link("forearm", 1.0, "0.15 0.02 0", BOX.format(s="0.3 0.06 0.06")),  # its COM 2 cm off its roll axis
    _link("hand", 0.5, "0.05 0.03 0", BOX.format(s="0.1 0.1 0.1")),
    _joint("caster_joint", "fixed", "base", "caster", "-0.2 0 0", "0 0 1"),
    _joint("left_wheel_joint", "continuous", "base", "left_wheel", "0.1 0.22 0", "0 1 0"),
    _joint("right_wheel_joint", "continuous", "base", "right_wheel", "0.1 -0.22 0", "0 1 0"),
    _joint("pan_joint", "continuous", "base", "pan", "0 0 0.35", "0 0 1"),
    _joint("shoulder_lift", "revolute", "pan", "shoulder", "0 0 0.1", "0 1 0"),
    _joint("forearm_roll", "continuous", "shoulder", "forearm", "0 0 0.3", "1 0 0"),
    _joint("wrist_roll", "continuous", "forearm", "hand", "0.3 0 0", "1 0 0"),
    "</robot>",
])


def _converted(tmp_path: Path, suffix: str) -> Path:
    source = tmp_path / "mobile_arm.urdf"
    source.write_text(MOBILE_ARM)
    out = tmp_path / "out" / f"mobile_arm.{suffix}"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out), "--base", "floating"])
    assert result.exit_code == 0, result.output
    return out


def test_the_arm_gets_servos_and_the_wheels_motors(tmp_path: Path) -> None:
    root = ET.parse(_converted(tmp_path, "xml")).getroot()
    kinds = {el.get("joint"): el.tag for el in root.find("actuator") or []}
    assert kinds == {
        "left_wheel_joint": "motor", "right_wheel_joint": "motor",  # wheels: zero control leaves them free
        "pan_joint": "motor",  # about a vertical axis: gravity does not turn it
        "shoulder_lift": "position",  # a range
        "forearm_roll": "position", "wrist_roll": "position",  # unranged, in the arm, turned by gravity
    }


def test_the_written_arm_holds_its_pose_on_a_plain_floor(tmp_path: Path) -> None:
    spec = mujoco.MjSpec.from_file(str(_converted(tmp_path, "xml")))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    roll = [int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)])
            for name in ("forearm_roll", "wrist_roll")]
    start = d.qpos[roll].copy()
    for _ in range(round(2.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    assert float(np.abs(d.qpos[roll] - start).max()) < 1e-3


def test_sdf_gets_the_same_controllers(tmp_path: Path) -> None:
    root = ET.parse(_converted(tmp_path, "sdf")).getroot()
    systems = {plugin.findtext("joint_name"): plugin.get("name", "").rsplit("::", 1)[-1]
               for plugin in root.iter("plugin") if plugin.findtext("joint_name")}
    assert systems.get("forearm_roll") == systems.get("wrist_roll") == "JointPositionController", systems
    assert systems.get("pan_joint") == "ApplyJointForce", systems
