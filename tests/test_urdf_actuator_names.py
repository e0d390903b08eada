"""Two URDF transmissions naming one actuator for different joints (pybullet_data's xArm 6 gives joint3
and joint4 the same "motor3"): check_urdf and PyBullet load the file, Drake refuses it. validate says so
(MK242, at the second actuator's name) and the URDF convert writes gives the second its own name (MK800),
so Drake loads the written file."""

from __future__ import annotations

import subprocess
from pathlib import Path

from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main

LINK = """  <link name="{n}"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
"""
JOINT = """  <joint name="{j}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <transmission name="{j}_trans"><type>transmission_interface/SimpleTransmission</type>
    <joint name="{j}"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="{m}"><mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>
"""
SOURCE = ('<?xml version="1.0"?>\n<robot name="arm">\n' + "".join(LINK.format(n=n) for n in "abc")
          + JOINT.format(j="joint3", p="a", c="b", m="motor3")
          + JOINT.format(j="joint4", p="b", c="c", m="motor3") + "</robot>\n")


def _drake_loads(path: Path) -> str | None:
    """None when Drake's parser takes the file, else its message."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(time_step=0.0)  # kept alive while the parser uses it
    try:
        Parser(plant).AddModels(file_name=str(path))
    except Exception as exc:  # Drake raises RuntimeError with its own words
        return str(exc)
    return None


def test_the_shared_actuator_name_is_said_and_written_apart(tmp_path: Path) -> None:
    source = tmp_path / "arm.urdf"
    source.write_text(SOURCE)
    (diagnostic,) = [d for d in validate(source).diagnostics if d.code == "MK242"]
    line = SOURCE[:SOURCE.rindex("motor3")].count("\n") + 1  # the second actuator's name
    assert diagnostic.location is not None and diagnostic.location.line == line
    assert 'joint "joint4"' in diagnostic.message and 'joint "joint3"' in diagnostic.message
    assert subprocess.run(["check_urdf", str(source)], capture_output=True).returncode == 0
    refused = _drake_loads(source)
    assert refused is not None and "motor3" in refused  # what MK242 says Drake does
    out = tmp_path / "out" / "arm.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert 'actuator "motor3" is written as "motor3_joint4"' in result.output
    text = out.read_text()
    assert text.count('<actuator name="motor3">') == 1 and '<actuator name="motor3_joint4">' in text
    assert _drake_loads(out) is None
    assert subprocess.run(["check_urdf", str(out)], capture_output=True).returncode == 0


def test_a_transmission_of_a_joint_the_robot_lacks_is_left_out(tmp_path: Path) -> None:
    """example-robot-data's TALOS left arm keeps the transmission of ``arm_left_1_joint``, a joint cut off
    with the rest of the robot: check_urdf loads it, Drake refuses it ("Transmission specifies joint ...
    which does not exist"). validate says so (MK139); convert leaves that one transmission out (MK808),
    so Drake loads the written file, and keeps the others."""
    ghost = JOINT.format(j="gone", p="a", c="b", m="motor9").split("  <transmission", 1)[1]
    source = tmp_path / "cut.urdf"
    source.write_text(SOURCE.replace("</robot>", "  <transmission" + ghost + "</robot>")
                      .replace('name="motor3"', 'name="motor4"', 1))
    assert "MK139" in {d.code for d in validate(source).diagnostics}
    assert _drake_loads(source) is not None  # the source itself is refused
    out = tmp_path / "out" / "cut.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "MK808" in result.output and '"gone_trans" left out' in result.output
    assert _drake_loads(out) is None
    assert out.read_text().count("<transmission") == 2


def test_a_transmission_of_a_joint_of_several_coordinates_is_left_out(tmp_path: Path) -> None:
    """A semantic-fuzz mutant of ros-industrial's UR5 turned ``shoulder_pan_joint`` planar (another, the
    wrist floating) and kept its transmission: check_urdf loads the written URDF, Drake refused it ("this
    joint has 3 degrees of freedom, and MultibodyPlant currently only supports actuators for single
    degree-of-freedom joints"; for the floating wrist: "Transmission specifies joint ... which does not
    exist"). convert leaves such a transmission out (MK808) and keeps the others."""
    for kind in ("planar", "floating"):
        source = tmp_path / f"{kind}.urdf"
        text = SOURCE.replace('name="motor3"', 'name="motor4"', 1)
        text = text.replace('<joint name="joint3" type="revolute">', f'<joint name="joint3" type="{kind}">')
        source.write_text(text)
        assert _drake_loads(source) is not None
        out = tmp_path / "out" / f"{kind}.urdf"
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
        assert result.exit_code == 0, result.output
        said = f"\"joint3_trans\" left out: it drives joint(s) 'joint3' ({kind})"
        assert said in result.output, result.output
        assert _drake_loads(out) is None
        assert out.read_text().count("<transmission") == 1
