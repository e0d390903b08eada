"""Gazebo's differential-drive plugin for a wheeled robot the source gives no controller
(modelkit/convert/drive_plugin.py, MK858/MK859).

What is checked, on the files the CLI writes: the plugin names the written wheel joints, left and
right; its wheel separation and radius are verify's (layer 4's drive model, which the plain-floor
tests drive in MuJoCo and PyBullet); libsdformat accepts the SDF, and its URDF import (what Gazebo
spawns a URDF with) carries the plugin into the model; the Gazebo family follows ``--gazebo``; no
plugin where the source has its own, where a wheel turns the other way, or with ``--no-drive-plugin``.
Gazebo itself is not installable here (no Debian package), so no test runs the plugin.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.api import load
from modelkit.cli import main
from modelkit.verify.drive.scenario import default_scenario
from modelkit.verify.drive.vehicle import find_drive
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

MODELS = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
SIM = ("gz-sim-diff-drive-system", "gz::sim::systems::DiffDrive")
CLASSIC = ("libgazebo_ros_diff_drive.so", "diff_drive")


def _convert(source: Path, target: Path, *options: str) -> str:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target), *options])
    assert result.exit_code == 0, result.output
    return result.output


def _drive_plugins(root: etree._Element) -> list[etree._Element]:
    return [p for p in root.iter("plugin") if "diff" in (p.get("filename") or "")]


def _children(plugin: etree._Element) -> list[tuple[str, str]]:
    return [(str(c.tag), (c.text or "").strip()) for c in plugin]


def _revolute_joints(root: etree._Element) -> set[str]:
    return {str(j.get("name")) for j in root.iter("joint") if j.get("type") in ("revolute", "continuous")}


@pytest.mark.parametrize("robot", ["pantilt", "primitive", "sensors"])
def test_gazebo_sim_gets_the_diff_drive_system(tmp_path: Path, robot: str,
                                               sdf_oracle: Path) -> None:  # noqa: F811
    source = MODELS / f"mobile_robot_{robot}.body"
    drive = find_drive(load(source), default_scenario())
    for suffix in ("sdf", "urdf"):
        path = tmp_path / f"robot.{suffix}"
        said = _convert(source, path, "--urdf-distinct-names")
        root = etree.parse(str(path)).getroot()
        (plugin,) = _drive_plugins(root)
        assert (plugin.get("filename"), plugin.get("name")) == SIM
        fields = dict(_children(plugin))
        assert float(fields["wheel_separation"]) == pytest.approx(2 * drive.half_axle, abs=1e-12)
        assert float(fields["wheel_radius"]) == pytest.approx(drive.radius, abs=1e-12)
        left, right = fields["left_joint"], fields["right_joint"]
        assert {left, right} <= _revolute_joints(root), suffix
        assert left.startswith(drive.left) and right.startswith(drive.right)  # LeftWheel or LeftWheel_joint
        assert "MK858 wheels driven by Gazebo Sim's DiffDrive system" in said
        assert "/model/MobileRobot/cmd_vel" in said
        assert not oracle_has_errors(sdf_oracle, path), suffix


def test_gazebos_urdf_import_carries_the_plugin_into_the_model(tmp_path: Path,
                                                              sdf_oracle: Path) -> None:  # noqa: F811
    """libsdformat's URDF to SDF conversion (what ``gz sim`` and ``spawn_entity`` do with a URDF) puts
    the robot-level ``<gazebo>`` plugin into the model, naming joints the converted model has."""
    path = tmp_path / "robot.urdf"
    _convert(MODELS / "mobile_robot_pantilt.body", path, "--urdf-distinct-names")
    run = subprocess.run([str(sdf_oracle), "--print", path.name], cwd=path.parent, capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    model = etree.fromstring(run.stdout.encode()).find("model")
    assert model is not None
    (plugin,) = [p for p in model.findall("plugin") if "diff" in (p.get("filename") or "")]
    fields = dict(_children(plugin))
    assert {fields["left_joint"], fields["right_joint"]} <= _revolute_joints(model)
    assert fields["wheel_separation"] == "0.29" and fields["wheel_radius"] == "0.076"


def test_gazebo_classic_gets_gazebo_ros_diff_drive(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    path = tmp_path / "robot.sdf"
    said = _convert(MODELS / "mobile_robot_pantilt.body", path, "--gazebo", "classic")
    (plugin,) = _drive_plugins(etree.parse(str(path)).getroot())
    assert (plugin.get("filename"), plugin.get("name")) == CLASSIC
    assert _children(plugin) == [
        ("left_joint", "LeftWheel_joint"), ("right_joint", "RightWheel_joint"), ("wheel_separation", "0.29"),
        ("wheel_diameter", "0.152"), ("publish_odom", "true"), ("publish_odom_tf", "true"),
        ("publish_wheel_tf", "false"), ("odometry_frame", "odom"), ("robot_base_frame", "Chassis")]
    assert "commands on cmd_vel (geometry_msgs/Twist)" in said
    assert not oracle_has_errors(sdf_oracle, path)


def test_no_drive_plugin_option(tmp_path: Path) -> None:
    path = tmp_path / "robot.sdf"
    said = _convert(MODELS / "mobile_robot_pantilt.body", path, "--no-drive-plugin")
    assert not _drive_plugins(etree.parse(str(path)).getroot()) and "MK858" not in said


def test_the_sources_own_drive_plugin_is_the_only_one(tmp_path: Path) -> None:
    """An SDF with a DiffDrive of its own (our output, read back) keeps that one and gets no second."""
    first = tmp_path / "a" / "robot.sdf"
    _convert(MODELS / "mobile_robot_pantilt.body", first)
    for suffix in ("sdf", "urdf"):
        again = tmp_path / "b" / f"robot.{suffix}"
        said = _convert(first, again)
        assert len(_drive_plugins(etree.parse(str(again)).getroot())) == 1, suffix
        assert "MK858" not in said
        assert "MK859 no Gazebo drive plugin written: the source names its own" in said


def test_a_source_plugin_the_target_drops_is_replaced(tmp_path: Path) -> None:
    """A URDF's own <gazebo> diff drive stays the only one in URDF, and in SDF too (the SDF writer copies a
    robot-level block's plugins of the Gazebo it writes for into the model, as libsdformat does); an SDF's
    Gazebo Sim DiffDrive written for Gazebo classic is left out (MK848), so the URDF gets gazebo_ros's."""
    urdf = tmp_path / "a" / "robot.urdf"
    _convert(MODELS / "mobile_robot_pantilt.body", urdf, "--urdf-distinct-names")
    kept = tmp_path / "b" / "robot.urdf"
    said = _convert(urdf, kept)
    assert len(_drive_plugins(etree.parse(str(kept)).getroot())) == 1 and "MK858" not in said
    sdf = tmp_path / "c" / "robot.sdf"
    said = _convert(urdf, sdf)
    (plugin,) = _drive_plugins(etree.parse(str(sdf)).getroot())
    assert plugin.get("filename") == SIM[0] and "MK858" not in said
    assert "MK859 no Gazebo drive plugin written: the source names its own" in said
    classic_sdf = tmp_path / "f" / "robot.sdf"
    said = _convert(urdf, classic_sdf, "--gazebo", "classic")  # the source's is Gazebo Sim's: replaced
    (plugin,) = _drive_plugins(etree.parse(str(classic_sdf)).getroot())
    assert plugin.get("filename") == CLASSIC[0] and "MK848" in said and "MK858" in said
    first = tmp_path / "d" / "robot.sdf"
    _convert(MODELS / "mobile_robot_pantilt.body", first)
    classic = tmp_path / "e" / "robot.urdf"
    said = _convert(first, classic, "--gazebo", "classic")
    (plugin,) = _drive_plugins(etree.parse(str(classic)).getroot())
    assert plugin.get("filename") == CLASSIC[0] and "MK848" in said and "MK858" in said


WHEELS = """<robot name="cart">
  <link name="base"><inertial><mass value="5"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.3 0.05"/></geometry></collision></link>
  <link name="caster"><inertial><mass value="0.1"/>
    <inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="caster_mount" type="fixed"><parent link="base"/><child link="caster"/>
    <origin xyz="-0.15 0 0"/></joint>
""" + "".join(f"""
  <link name="{side}_wheel"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="0.05" length="0.03"/>
    </geometry></collision></link>
  <joint name="{side}_wheel_joint" type="continuous"><parent link="base"/><child link="{side}_wheel"/>
    <origin xyz="0.1 {y} 0"/><axis xyz="0 {axis} 0"/></joint>""" for side, y, axis in (
    ("left", 0.17, "1"), ("right", -0.17, "{right}"))) + "\n</robot>\n"


def test_a_wheel_that_turns_the_other_way_gets_no_plugin(tmp_path: Path) -> None:
    """A URDF cart whose right wheel axis points to −Y: a positive speed would turn it backwards under
    a plugin that commands one sign, so MK859 says why; with both axes to +Y it gets the plugin."""
    for right, expected in (("1", 1), ("-1", 0)):
        source = tmp_path / f"cart{right}.urdf"
        source.write_text(WHEELS.replace("{right}", right))
        path = tmp_path / f"out{right}" / "cart.sdf"
        said = _convert(source, path, "--base", "floating")  # auto welds it: the caster is on the base
        assert len(_drive_plugins(etree.parse(str(path)).getroot())) == expected, said
        if expected == 0:
            assert "MK859 no Gazebo drive plugin written: wheel joint right_wheel_joint's axis points" in said
        else:
            assert "separation 0.34 m, radius 0.05 m" in said
