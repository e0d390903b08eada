"""``verify`` on a fixed-base arm given as the three files ``convert`` writes with its defaults (the
user's "verify a conversion I made before"): the URDF welds the root to a ``world`` link, the SDF to
the world, the MJCF holds massless frames as sites, a mimic joint couples the fingers. Every engine
reads the given files and the robot passes; before, PyBullet refused the URDF ("base link is
'world'"), yourdfpy counted ``world`` as an extra link, Drake could not replace the URDF's weld once
its parser had added the mimic coupler, Drake's SDF failed layer 3 on the writer's 1e-6 kg frames,
and MuJoCo's replay could not hold PyBullet's frame masses on a site (nor a COM moved off a body
MuJoCo had compiled as centred)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.cli import main
from modelkit.verify.api import verify

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision>
  </link>
  <link name="link1">
    <inertial><origin xyz="0 0 0.15"/><mass value="1.2"/>
      <inertia ixx="0.012" iyy="0.011" izz="0.002" ixy="0.0001" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.15"/><geometry><box size="0.04 0.04 0.3"/></geometry></collision>
  </link>
  <link name="link2">
    <inertial><mass value="0.6"/><inertia ixx="0.003" iyy="0.003" izz="0.0005" ixy="0" ixz="0" iyz="0"/>
      </inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.03 0.03 0.2"/></geometry></collision>
  </link>
  <link name="tool0"/>
  <link name="ee_link">
    <collision><geometry><box size="0.01 0.01 0.01"/></geometry></collision>
  </link>
  <link name="finger_a">
    <inertial><origin xyz="0 0 0.02"/><mass value="0.05"/>
      <inertia ixx="1e-5" iyy="1e-5" izz="2e-6" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="finger_b">
    <inertial><origin xyz="0 0 0.02"/><mass value="0.05"/>
      <inertia ixx="1e-5" iyy="1e-5" izz="2e-6" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="2"/>
  </joint>
  <joint name="joint2" type="revolute">
    <parent link="link1"/><child link="link2"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="30" velocity="2"/>
  </joint>
  <joint name="tool0_joint" type="fixed">
    <parent link="link2"/><child link="tool0"/><origin xyz="0 0 0.2" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="ee_joint" type="fixed">
    <parent link="link2"/><child link="ee_link"/><origin xyz="0.01 0 0.21"/>
  </joint>
  <joint name="finger_a_joint" type="prismatic">
    <parent link="link2"/><child link="finger_a"/><origin xyz="0 0.01 0.2"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.03" effort="10" velocity="0.2"/>
  </joint>
  <joint name="finger_b_joint" type="prismatic">
    <parent link="link2"/><child link="finger_b"/><origin xyz="0 -0.01 0.2"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.03" effort="10" velocity="0.2"/>
    <mimic joint="finger_a_joint"/>
  </joint>
</robot>
"""


@pytest.fixture(scope="module")
def given(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("arm")
    source = folder / "arm.urdf"
    source.write_text(ARM)
    out = {"source": source}
    for kind, suffix in (("urdf", "urdf"), ("mjcf", "xml"), ("sdf", "sdf")):
        target = folder / "given" / f"arm.{suffix}"
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
        assert result.exit_code == 0, result.output
        out[kind] = target
    assert '<link name="world"' in out["urdf"].read_text() and '<site name="tool0"' in out["mjcf"].read_text()
    return out


def test_the_files_convert_wrote_pass_in_every_engine(given: dict[str, Path], tmp_path: Path) -> None:
    report = verify(given["source"], tmp_path / "out", urdf=given["urdf"], mjcf=given["mjcf"],
                    sdf=given["sdf"], configurations=5, samples=5, driven=False)
    assert report.errors == []
    assert [f"{c.engine} {c.quantity} {c.where}: {c.detail}" for c in report.failed] == []
    engines = {c.engine for c in report.checks}
    assert {"mujoco", "pybullet", "pinocchio", "yourdfpy"} <= engines
    replay = [c for c in report.checks if c.quantity == "replay"]
    assert replay and all(c.passed for c in replay)
    for engine in ("pybullet", "yourdfpy"):  # the URDF's world link is the world, not a link
        links = [c for c in report.checks if c.engine == engine and c.quantity == "link-set"]
        assert links and links[0].passed
    if "drake-urdf" in engines:
        base = report.engines["drake-urdf"]["base"]
        assert "weld" in base and "kept" in base


def test_a_fault_in_the_given_files_still_fails(given: dict[str, Path], tmp_path: Path) -> None:
    report = verify(given["source"], tmp_path / "out", ("mujoco", "pybullet", "pinocchio"),
                    urdf=given["urdf"], mjcf=given["mjcf"], inject=["mass:link2:5%"], configurations=2,
                    samples=2, driven=False)
    failed = {(c.engine, c.quantity, c.where) for c in report.failed}
    assert {("mujoco", "mass", "link2"), ("pybullet", "mass", "link2")} <= failed


def test_a_floating_robot_with_a_repaired_inertia_given_as_convert_wrote_it(tmp_path: Path) -> None:
    """``convert --base floating``: the MJCF has a free joint and a ``home`` keyframe of 7 + n numbers,
    which MuJoCo refused once verify deleted the free joint to weld the base ("keyframe 'home': invalid
    qpos size", example-robot-data's A1, Solo12 and ANYmal C); and a source tensor that violates the
    triangle inequality, which the SDF writer lifts (MK860): Drake's layer 1 compared the lifted tensor
    with the source's and failed (ANYmal C's ``hatch``)."""
    source = tmp_path / "arm.urdf"
    violating = 'ixx="0.012" iyy="0.011" izz="0.03"'  # 0.012 + 0.011 < 0.03
    source.write_text(ARM.replace('ixx="0.012" iyy="0.011" izz="0.002"', violating))
    given = {}
    for kind, suffix in (("mjcf", "xml"), ("sdf", "sdf")):
        given[kind] = tmp_path / "given" / f"arm.{suffix}"
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(given[kind]),
                                           "--base", "floating"])
        assert result.exit_code == 0, result.output
    assert "<freejoint" in given["mjcf"].read_text() and '<key name="home"' in given["mjcf"].read_text()
    engines = ("mujoco", "pinocchio", *(("drake",) if "drake" in _installed() else ()))
    report = verify(source, tmp_path / "out", engines, mjcf=given["mjcf"], sdf=given["sdf"],
                    configurations=3, samples=3, replay=False, driven=False)
    assert report.errors == []
    assert [f"{c.engine} {c.quantity} {c.where}: {c.detail}" for c in report.failed] == []
    assert {c.engine for c in report.checks} == set(engines)
    if "drake" in engines:
        inertia = [c for c in report.checks if c.engine == "drake" and c.quantity == "inertia"]
        assert inertia and inertia[0].passed


def _installed() -> set[str]:
    import importlib.util

    return {"drake"} if importlib.util.find_spec("pydrake") is not None else set()
