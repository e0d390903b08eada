"""Strange numbers never become a traceback or a run without end (issue 18 §2): an inertia of 1e308 is
a located error, not "zero", and convert refuses it cleanly; every scenario number has a bound."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from modelkit.verify.drive.scenario import MAX_STEPS, load

HUGE = """<robot name="r">
<link name="a"><inertial><mass value="1"/>
<inertia ixx="{v}" ixy="0" ixz="0" iyy="{v}" iyz="0" izz="{v}"/></inertial></link>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
</inertial></link>
<joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
</robot>
"""


@pytest.mark.parametrize("value", ["1e308", "1e120"])
def test_a_huge_inertia_is_a_located_error_not_zero(tmp_path: Path, value: str) -> None:
    model = tmp_path / "huge.urdf"
    model.write_text(HUGE.format(v=value))
    found = [d for d in validate(model).diagnostics if d.code == "MK302"]
    assert len(found) == 1, found
    assert found[0].severity.value == "error"
    assert "too large to compute with" in found[0].message and "zero" not in found[0].message
    assert found[0].location is not None and found[0].location.line == 3


def test_an_inertia_below_the_bound_is_judged_as_before(tmp_path: Path) -> None:
    model = tmp_path / "big.urdf"
    model.write_text(HUGE.format(v="1e90"))
    assert not [d for d in validate(model).diagnostics if d.code == "MK302"]


@pytest.mark.parametrize("suffix", [".xml", ".sdf", ".urdf", ".body"])
def test_convert_refuses_a_huge_inertia_without_a_traceback(tmp_path: Path, suffix: str) -> None:
    model = tmp_path / "huge.urdf"
    model.write_text(HUGE.format(v="1e308"))
    out = tmp_path / f"out{suffix}"
    result = CliRunner().invoke(main, ["convert", str(model), "-o", str(out)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 1 and "MK302" in result.output and "Traceback" not in result.output
    assert not out.exists()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("simulation:\n  dt: 1e-9\n", "simulation.dt: 1e-09 must be at least 1e-05"),
        ("simulation:\n  sample_rate: 1e-9\n", "simulation.sample_rate: 1e-09 must be at least 0.1"),
        ("controller:\n  kd: 1e300\n", "controller.kd: 1e+300 must be at most 10000"),
        ("robot:\n  wheel_radius: 1e300\n", "robot.wheel_radius: 1e+300 must be at most 100"),
        ("tolerances:\n  engines_yaw: 1e300\n", "tolerances.engines_yaw: 1e+300 must be at most 1000"),
        ("profiles:\n  - {name: x, duration: 5, commands: [[0, 1e300]]}\n", "must be at most 1000"),
        ("profiles:\n  - {name: x, duration: 5, commands: [{t: 0, w: -1e300}]}\n", "must be at least -1000"),
    ],
)
def test_every_scenario_number_is_bounded(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(text)
    scenario, found = load(path)
    assert scenario is None
    assert [d.code for d in found] == ["MK902"], found
    assert message in found[0].message and found[0].location is not None and found[0].location.line >= 2


def test_the_steps_of_all_profiles_together_are_bounded(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(
        "simulation:\n  dt: 0.00001\n"
        "profiles: [straight, spin, arc, steps, {name: long, duration: 100, commands: [[0, 1]]}]\n"
    )
    scenario, found = load(path)
    assert scenario is None and [d.code for d in found] == ["MK902"]
    assert f"more than {MAX_STEPS:,}" in found[0].message and found[0].location.line == 2
    path.write_text("simulation:\n  dt: 0.00001\n")  # the built-in profiles at 100 kHz: 4.2e6 steps
    scenario, found = load(path)
    assert scenario is not None and not found


SELF_JOINT = """format: ChoreonoidBody
format_version: 2.0
name: r
links:
  - name: base
    joint_type: free
    mass: 1
    inertia: [0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1]
  - name: arm
    parent: base
    joint_type: revolute
    joint_axis: [0, 0, 1]
    joint_id: 0
    mass: 1
    inertia: [0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1]
extra_joints:
  - link1_name: arm
    link2_name: {other}
    joint_type: ball
"""


def test_a_body_extra_joint_from_a_link_to_itself_is_a_located_error(tmp_path: Path) -> None:
    model = tmp_path / "self.body"
    model.write_text(SELF_JOINT.format(other="arm"))
    found = [d for d in validate(model).diagnostics if d.code == "MK215"]
    assert len(found) == 1 and found[0].severity.value == "error", found
    assert 'joins link "arm" to itself' in found[0].message
    assert found[0].location is not None and (found[0].location.line, found[0].location.col) == (18, 17)
    model.write_text(SELF_JOINT.format(other="base"))
    assert not [d for d in validate(model).diagnostics if d.code == "MK215"]


def test_an_inverted_range_has_its_own_note_in_the_mjcf(tmp_path: Path) -> None:
    from modelkit.convert.api import write

    model = tmp_path / "inv.urdf"
    model.write_text(HUGE.format(v="0.1").replace(
        'type="continuous"', 'type="revolute"').replace(
        "</joint>", '<limit lower="1" upper="-1" effort="1" velocity="1"/></joint>'))
    robot = validate(model).robot
    assert robot is not None
    notes = write(robot, tmp_path / "inv.xml", "mjcf")
    inverted = [n for n in notes if n.code == "MK824"]
    assert len(inverted) == 1 and "lower limit 1 is above upper limit -1" in inverted[0].message
    assert not [n for n in notes if "one side" in n.message]
    assert ' range=' not in (tmp_path / "inv.xml").read_text()


SAMPLES = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"


def test_a_300_character_robot_name_gives_layer_4_files_it_can_write(tmp_path: Path) -> None:
    from modelkit.verify.drive.scenario import default_scenario
    from modelkit.verify.drive.variant import write_variant
    from modelkit.verify.drive.vehicle import find_drive

    model = tmp_path / "long.body"
    text = (SAMPLES / "mobile_robot.body").read_text()
    model.write_text(text.replace("name: MobileRobot", "name: " + "R" * 300, 1))
    robot = validate(model).robot
    assert robot is not None and robot.name == "R" * 300
    scenario = default_scenario()
    files, _ = write_variant(robot, find_drive(robot, scenario), scenario, tmp_path / "out", "sphere")
    assert all(path.is_file() and len(path.name) <= 120 for path in files.values()), files


def test_an_output_name_of_245_characters_is_written(tmp_path: Path) -> None:
    model = tmp_path / "huge.urdf"
    model.write_text(HUGE.format(v="0.1"))
    out = tmp_path / ("r" * 240 + ".urdf")
    result = CliRunner().invoke(main, ["convert", str(model), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert out.is_file() and [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize("target", ["mjcf", "sdf", "urdf", "body"])
def test_the_library_writer_refuses_a_huge_inertia_with_a_clear_error(tmp_path: Path, target: str) -> None:
    from modelkit.convert.api import write

    model = tmp_path / "huge.urdf"
    model.write_text(HUGE.format(v="1e308"))
    robot = validate(model).robot
    assert robot is not None
    with pytest.raises(ValueError, match='link "a": mass or inertia 1e\\+308 cannot be written \\(MK302'):
        write(robot, tmp_path / f"out.{target}", target)
