"""URDF that ROS tools take (issue 17 item 7): the source's joint names, sensors as TF frames.

Oracles: ``check_urdf`` (urdfdom, what robot_state_publisher parses with), yourdfpy forward kinematics
(the transforms robot_state_publisher would publish), libsdformat 12 (what Gazebo spawns a URDF with).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import render_model
from modelkit.convert.notes import ConversionNote
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan
from modelkit.model import Robot
from tests.conftest import TUTORIAL, require_tool
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
SENSORS = TUTORIAL / "mobile_robot_sensors.body"


def _read(path: Path) -> Robot:
    checked = validate(path)
    assert checked.robot is not None, [str(d) for d in checked.diagnostics]
    return checked.robot


def _write(
    robot: Robot, folder: Path, options: WriteOptions | None = None
) -> tuple[Path, list[ConversionNote]]:
    plan = OutputPlan(folder)
    notes = render_model(robot, "urdf", plan, "robot.urdf", options or WriteOptions())
    assert not plan.problems()
    plan.commit()
    return folder / "robot.urdf", notes


def _check_urdf(path: Path) -> str:
    run = subprocess.run([require_tool("check_urdf"), str(path)], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    return run.stdout


def _joints(path: Path) -> dict[str, tuple[str, str]]:
    root = etree.parse(str(path)).getroot()
    out: dict[str, tuple[str, str]] = {}
    for joint in root.iter("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        assert parent is not None and child is not None
        out[joint.get("name", "")] = (parent.get("link", ""), child.get("link", ""))
    return out


def test_pantilt_wheel_joints_keep_their_source_names(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """The wheel joints are LeftWheel / RightWheel as in the .body (joint_states drives them in rviz);
    check_urdf takes the file; libsdformat refuses the shared name, which MK846 says and
    urdf_distinct_names avoids."""
    robot = _read(PANTILT)
    path, notes = _write(robot, tmp_path / "kept")
    joints = _joints(path)
    assert joints["LeftWheel"] == ("Chassis", "LeftWheel")
    assert joints["RightWheel"] == ("Chassis", "RightWheel")
    assert {"PanJoint", "TiltJoint"} <= set(joints) and not any(n.endswith("_joint") for n in joints)
    assert "MK800" not in {n.code for n in notes}
    kept = [n for n in notes if n.code == "MK846"]
    assert len(kept) == 1 and '"LeftWheel", "RightWheel"' in kept[0].message
    tree = _check_urdf(path)
    assert "root Link: Chassis has 3 child(ren)" in tree and "child(1):  LeftWheel" in tree
    assert oracle_has_errors(sdf_oracle, path)  # libsdformat: "Non-unique name", a frame-graph cycle

    distinct, notes = _write(robot, tmp_path / "distinct", WriteOptions(urdf_distinct_names=True))
    assert {"LeftWheel_joint", "RightWheel_joint"} <= set(_joints(distinct))
    assert "MK846" not in {n.code for n in notes} and sum(n.code == "MK800" for n in notes) == 2
    _check_urdf(distinct)
    assert not oracle_has_errors(sdf_oracle, distinct)
