"""``--srdf`` and ``--home``: MoveIt's named joint states give the home pose (modelkit.formats.srdf).

The user's next step is the check: example-robot-data's Kinova arm converted with its SRDF's only
state, ``arm_up``, stands clear of a floor at its base in MuJoCo and holds that pose under its servos;
converted without it, its zero pose put into range folds two links 45 mm through that floor."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from modelkit.formats.common import ReadOptions
from tests.conftest import example_robot

mujoco = pytest.importorskip("mujoco")

ARM = """<robot name="arm">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0 0 0.2"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial></link>
  <link name="finger_a"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <link name="finger_b"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="0.5" upper="5.5" effort="50" velocity="2"/></joint>
  <joint name="finger_a_joint" type="prismatic"><parent link="upper"/><child link="finger_a"/>
    <origin xyz="0 0 0.4"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="1"/></joint>
  <joint name="finger_b_joint" type="prismatic"><parent link="upper"/><child link="finger_b"/>
    <origin xyz="0 0 0.4"/><axis xyz="-1 0 0"/><limit lower="0" upper="0.04" effort="20" velocity="1"/>
    <mimic joint="finger_a_joint"/></joint>
</robot>
"""

SRDF = """<?xml version="1.0"?>
<robot name="arm">
  <group name="arm"><joint name="shoulder"/></group>
  <group name="hand"><joint name="finger_a_joint"/></group>
  <group_state name="tucked" group="arm"><joint name="shoulder" value="5"/></group_state>
  <group_state name="ready" group="arm"><joint name="shoulder" value="-5"/></group_state>
  <group_state name="ready" group="hand"><joint name="finger_a_joint" value="0.03"/></group_state>
  <group_state name="odd" group="arm">
    <joint name="shoulder" value="6"/><joint name="elbow" value="1"/><joint name="finger_a_joint" value="x"/>
  </group_state>
</robot>
"""


def _files(tmp_path: Path, srdf: str = SRDF) -> tuple[Path, Path]:
    urdf, semantic = tmp_path / "arm.urdf", tmp_path / "arm.srdf"
    urdf.write_text(ARM)
    semantic.write_text(srdf)
    return urdf, semantic


def _home(robot_file: Path, srdf: Path, state: str | None = None) -> tuple[dict[str, float], set[str]]:
    checked = validate(robot_file, ReadOptions(srdf=srdf, home=state))
    robot = checked.robots[0]
    return {j.name: j.initial_position for j in robot.joints}, {d.code for d in checked.diagnostics}


def test_the_preferred_state_merged_over_its_groups_and_turned_into_range(tmp_path: Path) -> None:
    urdf, srdf = _files(tmp_path)
    home, codes = _home(urdf, srdf)  # no --home: "ready" (of home, ready, default...), both its groups
    assert home["shoulder"] == pytest.approx(-5 + 2 * np.pi, abs=1e-15)  # a whole turn into [0.5, 5.5]
    assert home["finger_a_joint"] == 0.03 and home["finger_b_joint"] == 0.03  # the mimic follows
    assert {"MK147", "MK149"} <= codes


def test_a_named_state_and_what_cannot_be_used(tmp_path: Path) -> None:
    urdf, srdf = _files(tmp_path)
    assert _home(urdf, srdf, "tucked")[0]["shoulder"] == 5.0
    home, _ = _home(urdf, srdf, "odd")
    checked = validate(urdf, ReadOptions(srdf=srdf, home="odd"))
    said = [d for d in checked.diagnostics if d.code == "MK149"]
    assert len(said) == 3 and all(d.severity.value == "warning" for d in said)  # 6 rad, elbow, "x"
    assert any('"elbow" is no joint' in d.message for d in said)
    assert home["shoulder"] == 6.0 and said[0].location is not None and said[0].location.line > 0


def test_cli_home_state_that_is_missing_is_an_error_naming_the_states(tmp_path: Path) -> None:
    urdf, srdf = _files(tmp_path)
    out = tmp_path / "out" / "arm.xml"
    result = CliRunner().invoke(main, ["convert", str(urdf), "--srdf", str(srdf), "--home", "nowhere",
                                       "-o", str(out)])
    assert result.exit_code == 1, result.output
    assert "MK148" in result.output and '"tucked", "ready", "odd"' in result.output
    assert not out.exists()
    usage = CliRunner().invoke(main, ["convert", str(urdf), "--home", "ready", "-o", str(out)])
    assert usage.exit_code == 2 and "--srdf" in usage.output


def test_the_srdf_is_an_input_never_overwritten(tmp_path: Path) -> None:
    urdf, _ = _files(tmp_path)
    srdf = tmp_path / "out" / "arm.xml"  # an SRDF named like the output file
    srdf.parent.mkdir()
    srdf.write_text(SRDF)
    result = CliRunner().invoke(main, ["convert", str(urdf), "--srdf", str(srdf), "-o", str(srdf), "--force"])
    assert result.exit_code != 0
    assert srdf.read_text() == SRDF


def _floor_and_hold(path: Path) -> tuple[float, float]:
    """(deepest penetration of a plane at z = 0 at the home keyframe, largest body move holding it 2 s)."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    mujoco.mj_forward(m, d)
    floor = [d.contact[i] for i in range(d.ncon) if 0 in (m.geom_bodyid[d.contact[i].geom[0]],
                                                          m.geom_bodyid[d.contact[i].geom[1]])]
    deepest = max([-c.dist for c in floor], default=0.0)
    start, moved = d.xpos.copy(), 0.0
    for _ in range(round(2.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        moved = max(moved, float(np.linalg.norm(d.xpos - start, axis=1).max()))
    return deepest, moved


def test_kinova_stands_clear_of_its_floor_at_its_srdf_state(tmp_path: Path) -> None:
    urdf = example_robot("kinova_description/robots/kinova.urdf")
    srdf = example_robot("kinova_description/srdf/kinova.srdf")
    package = f"example-robot-data={urdf.parents[3]}"
    common = ["--package-path", package]  # the default options: its effort interfaces servoed (MK864)
    with_state, without = tmp_path / "a" / "kinova.xml", tmp_path / "b" / "kinova.xml"
    result = CliRunner().invoke(main, ["convert", str(urdf), "--srdf", str(srdf), *common,
                                       "-o", str(with_state)])
    assert result.exit_code == 0, result.output
    assert 'SRDF group_state "arm_up"' in result.output and "MK865" not in result.output
    zero = CliRunner().invoke(main, ["convert", str(urdf), *common, "-o", str(without)])
    assert zero.exit_code == 0
    deepest, moved = _floor_and_hold(with_state)
    assert deepest == 0.0 and moved < 1e-3, (deepest, moved)
    deepest = _floor_and_hold(without)[0]
    assert 0.04 < deepest < 0.05  # the zero pose put into range: 45 mm into the floor
    # ... which convert says (MK865), with the same depth
    (said,) = [line for line in zero.output.splitlines() if "MK865" in line]
    assert "j2s6s200_link_2 45 mm" in said and "j2s6s200_link_3 45 mm" in said


# -- <disable_collisions>: the pairs MoveIt's setup assistant disabled -----------------------------------

EXCLUSIONS = """<?xml version="1.0"?>
<robot name="arm">
  <disable_collisions link1="base" link2="upper" reason="Adjacent"/>
  <disable_collisions link1="base" link2="finger_a" reason="Never"/>
  <disable_collisions link1="finger_a" link2="base" reason="Never"/>
  <disable_collisions link1="finger_a" link2="finger_b" reason="Default"/>
  <disable_collisions link1="upper" link2="ghost" reason="Never"/>
</robot>
"""


def test_disabled_pairs_become_mujoco_exclusions(tmp_path: Path) -> None:
    """Written: base-finger_a (Never, once though listed twice) and the fingers (Default). Not written:
    base-upper, a body and its parent, which MuJoCo already ignores. The pair naming a link the robot
    lacks is a warning (MK126). MuJoCo compiles the two exclusions."""
    urdf, srdf = _files(tmp_path, EXCLUSIONS)
    out = tmp_path / "out" / "arm.xml"
    result = CliRunner().invoke(main, ["convert", str(urdf), "--srdf", str(srdf), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "warning MK126 1 disable_collisions pair(s) name a link the robot lacks" in result.output
    assert ("MK866 2 of the SRDF's 4 disabled collision pair(s) written as <contact><exclude> (Default 1, "
            "Never 1); not written: 1 between a body and its parent (MuJoCo ignores those); 1 repeated"
            in result.output)
    model = mujoco.MjModel.from_xml_path(str(out))
    pairs = set()
    for i in range(model.nexclude):
        signature = int(model.exclude_signature[i])
        first, second = signature >> 16, signature & 0xFFFF
        pairs.add(frozenset((model.body(first).name, model.body(second).name)))
    assert pairs == {frozenset(("base", "finger_a")), frozenset(("finger_a", "finger_b"))}


def test_disabled_pairs_are_said_not_written_in_urdf(tmp_path: Path) -> None:
    urdf, srdf = _files(tmp_path, EXCLUSIONS)
    out = tmp_path / "out" / "arm.urdf"
    result = CliRunner().invoke(main, ["convert", str(urdf), "--srdf", str(srdf), "-o", str(out)])
    assert result.exit_code == 0, result.output
    said = "MK867 the SRDF's 4 disabled collision pair(s) are not written: urdf has no exclusion"
    assert said in result.output
