"""``verify SOURCE --mjcf F --urdf G``: check a conversion someone already made, usually ``convert``'s
default output. Before, such files failed layer 1 (``convert`` writes sphere wheel collisions, MK826,
where the source has cylinders) and layer 4 drove files it wrote itself, not F and G."""

from __future__ import annotations

from pathlib import Path

import modelkit
from modelkit.convert import write
from modelkit.verify.api import verify

from .conftest import TUTORIAL


def test_convert_default_files_given_pass_and_layer4_drives_them(tmp_path: Path) -> None:
    source = TUTORIAL / "mobile_robot.body"
    given = tmp_path / "given"
    for name in ("r.urdf", "r.xml", "r.sdf"):
        write(modelkit.load(source), given / name)
    assert '<sphere radius="0.076"/>' in (given / "r.urdf").read_text()  # convert's default wheels
    # SDF forbids a joint named like a link: the wheels' joints are renamed (MK800), and verify finds
    # that from convert's own renames (before, Drake failed layer 2 by 3.12 rad: RightWheel not turned)
    assert "<joint name=\"RightWheel_joint\"" in (given / "r.sdf").read_text()
    out = tmp_path / "out"
    report = verify(source, out, engines=("mujoco", "pybullet", "drake"), urdf=given / "r.urdf",
                    mjcf=given / "r.xml", sdf=given / "r.sdf", replay=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    wheels = [s.reason for s in report.skips if "convert's wheel collision" in s.reason]
    assert (2, "drake", "pose-rotation") in {(c.layer, c.engine, c.quantity) for c in report.checks}
    assert len(wheels) == 2 and all("a sphere in place of the source's cylinder on LeftWheel, RightWheel" in w
                                    for w in wheels), wheels
    layer4 = report.engines["layer4"]
    assert layer4["files"] == {"mjcf": str(given / "r.xml"), "urdf": str(given / "r.urdf")}
    assert {("mujoco", "straight"), ("pybullet", "spin")} <= {(c.engine, c.where) for c in report.checks
                                                              if c.layer == 4 and c.quantity == "noslip-yaw"}
    # the given files are driven: layer 4 writes no model of its own (the report-only native run,
    # which would write MobileRobot_cylinder.*, is off by default)
    assert not [p.name for p in (out / "layer4").rglob("*") if p.is_file()]


def test_a_given_file_with_a_wrong_wheel_fails_layer4_on_that_file(tmp_path: Path) -> None:
    """The given URDF's left wheel is 5 % too large: layer 1 names it, and layer 4, driving that very
    file in PyBullet, leaves the no-slip reference."""
    source = TUTORIAL / "mobile_robot.body"
    given = tmp_path / "given"
    write(modelkit.load(source), given / "r.urdf")
    path = given / "r.urdf"
    path.write_text(path.read_text().replace('<sphere radius="0.076"/>', '<sphere radius="0.0798"/>', 1))
    report = verify(source, tmp_path / "out", engines=("pybullet",), urdf=path, replay=False)
    failed = {(c.layer, c.quantity, c.where) for c in report.checks if not c.passed}
    assert (1, "shape-size", "LeftWheel") in failed
    assert (4, "noslip-yaw", "straight") in failed


def test_a_given_file_with_a_welded_base_is_not_driven(tmp_path: Path) -> None:
    """``convert --base fixed`` writes the mobile robot welded: layer 4, which drives it on a floor,
    says it did not run that engine (it failed to load the file before it drove the given files)."""
    from modelkit.convert.options import WriteOptions

    source = TUTORIAL / "mobile_robot.body"
    given = tmp_path / "given" / "r.xml"
    write(modelkit.load(source), given, options=WriteOptions(base="fixed"))
    assert "freejoint" not in given.read_text()
    report = verify(source, tmp_path / "out", engines=("mujoco",), mjcf=given, replay=False)
    assert [c for c in report.checks if not c.passed] == []
    said = [s.reason for s in report.skips if s.layer == 4 and s.engine == "mujoco"]
    assert any("welds the robot's base" in s for s in said), said


def test_given_urdf_sensor_links_are_graded_where_the_sensors_are(tmp_path: Path) -> None:
    """convert's default URDF writes each camera, LiDAR and IMU as a link on a fixed joint (MK847, with
    the writer's 1e-6 kg). verify compares the URDF engines with the source holding those frames at
    the sensors' poses: the given files pass, and a frame moved by 1 cm fails layer 2 there. Before,
    the frames were extra links (layer 1) and their 1e-6 kg failed layer 3 and the replay (the
    tutorial's tracked robot: 8 of 99 checks)."""
    source = TUTORIAL / "mobile_robot_sensors.body"
    given = tmp_path / "given"
    for name in ("r.urdf", "r.xml"):
        write(modelkit.load(source), given / name)
    urdf = (given / "r.urdf").read_text()
    assert '<link name="LiDAR">' in urdf and '<link name="RealSense_optical">' in urdf
    engines = ("mujoco", "pybullet", "pinocchio", "yourdfpy")
    report = verify(source, tmp_path / "out", engines, urdf=given / "r.urdf", mjcf=given / "r.xml",
                    configurations=3, samples=3, driven=False)
    assert not report.errors, report.errors
    assert [f"{c.engine} {c.quantity} {c.where}: {c.detail}" for c in report.failed] == []
    assert [c for c in report.checks if c.quantity == "replay" and c.passed]
    said = [s.reason for s in report.skips if s.engine == "pybullet" and "sensor frame" in s.reason]
    assert said and "RealSense_optical on RealSense" in said[0]
    moved = given / "moved.urdf"  # beside the meshes
    start = urdf.index('<joint name="LiDAR_joint"')
    head, tail = urdf[:start], urdf[start:]
    moved.write_text(head + tail.replace('<origin xyz="0 0 0.025"', '<origin xyz="0.01 0 0.025"', 1))
    faulty = verify(source, tmp_path / "out2", ("pybullet", "yourdfpy"), urdf=moved, configurations=3,
                    samples=1, replay=False, driven=False)
    assert {("pybullet", "pose-position", "LiDAR"), ("yourdfpy", "pose-position", "LiDAR")} <= {
        (c.engine, c.quantity, c.where) for c in faulty.failed}
