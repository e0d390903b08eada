"""Wheels whose collision is a mesh file (issue 16): the tutorial's ``mobile_robot.body`` with its
wheels' collision cylinders replaced by the tutorial's own wheel mesh, ``vmega_wheel.dae`` (a
polygonal tyre, radius 0.076 m, 0.0575 m wide), as a user with CAD wheels writes it.

``convert`` finds such a wheel from the mesh's vertices and writes the same sphere a cylinder wheel
gets (MK826); ``verify``'s layer 4 finds and drives it; the files drive on a plain floor in both
engines. A mesh that is not round about the axle (Hello Robot's Stretch: a square prism) is no wheel,
and a robot that stands on its two wheels alone (the tutorial's ``mobile_robot_mesh.body``, whose
chassis mesh is not shipped) is not driven, with the reason.
"""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from modelkit.geometry.extents import round_about
from modelkit.model import Geom, Mesh
from modelkit.spatial import Pose
from modelkit.verify.drive import Scenario
from modelkit.verify.drive.vehicle import find_drive, supported
from tests.conftest import TUTORIAL
from tests.plain_floor_support import drive_mujoco, drive_pybullet, ideal

CYLINDER = """          - &TireShape
            type: Shape
            geometry:
              type: Cylinder
              height: 0.03
              radius: 0.076
              division_number: 60"""
MESH = """          - &TireShape
            type: Resource
            uri: "../meshes/vmega_wheel.dae\""""
MESH_RADIUS = 0.075968  # half the mesh's mean reach across the axle (MK826 says it)
HALF_AXLE = 0.145


@pytest.fixture(scope="module")
def mesh_wheeled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("tutorial") / "tutorial"
    shutil.copytree(TUTORIAL.parent, folder)
    text = (folder / "model" / "mobile_robot.body").read_text()
    assert CYLINDER in text
    body = folder / "model" / "mesh_wheels.body"
    body.write_text(text.replace(CYLINDER, MESH))
    return body


def _convert(source: Path, target: Path, *options: str) -> str:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target), *options])
    assert result.exit_code == 0, result.output
    return result.output


def test_a_round_mesh_wheel_is_written_as_the_sphere_a_cylinder_gets(mesh_wheeled: Path,
                                                                   tmp_path: Path) -> None:
    output = _convert(mesh_wheeled, tmp_path / "r.xml")
    notes = [line for line in output.splitlines() if "MK826" in line]
    assert len(notes) == 2, output
    assert all("collision mesh vmega_wheel.dae (round about the joint axis: radius 0.075968 m, width "
               "0.0575 m) is written as a sphere of radius 0.075968 m" in note for note in notes)
    mjcf = (tmp_path / "r.xml").read_text()
    assert mjcf.count('type="sphere" size="0.075968" pos="0 -0.005751 0"') == 2
    _convert(mesh_wheeled, tmp_path / "r.urdf")
    assert (tmp_path / "r.urdf").read_text().count('<sphere radius="0.075968"/>') == 2
    # the source's shape on request, and Choreonoid's and Gazebo's formats keep it by default
    output = _convert(mesh_wheeled, tmp_path / "c.xml", "--wheel-collision", "cylinder")
    assert "MK826" not in output and 'type="sphere"' not in (tmp_path / "c.xml").read_text()
    assert "MK826" not in _convert(mesh_wheeled, tmp_path / "r.sdf")


def test_an_ellipsoid_wheel_lies_along_the_mesh_axle(mesh_wheeled: Path, tmp_path: Path) -> None:
    _convert(mesh_wheeled, tmp_path / "e.xml", "--wheel-collision", "ellipsoid")
    import mujoco

    m = mujoco.MjModel.from_xml_path(str(tmp_path / "e.xml"))
    found = 0
    for g in range(m.ngeom):
        if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_ELLIPSOID:
            continue
        found += 1
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, m.geom_quat[g])
        axle = rotation.reshape(3, 3)[:, 2]  # the ellipsoid's z in its body (the wheel, axle along y)
        assert abs(abs(axle[1]) - 1.0) < 1e-9
        assert m.geom_size[g] == pytest.approx([MESH_RADIUS, MESH_RADIUS, 0.5 * 0.0575], abs=1e-6)
    assert found == 2


@pytest.mark.parametrize(("engine", "v", "w"), [("mujoco", 0.3, 0.0), ("mujoco", 0.0, 0.5),
                                                ("pybullet", 0.3, 0.0), ("pybullet", 0.0, 0.5)])
def test_the_written_files_drive_on_a_plain_floor(mesh_wheeled: Path, tmp_path: Path, engine: str, v: float,
                                                  w: float) -> None:
    """The bounds of ``test_wheels_plain_floor``: yaw within 10 % of the ideal unicycle's, the end within
    10 % of the distance (5 cm for the spin)."""
    target = tmp_path / ("r.xml" if engine == "mujoco" else "r.urdf")
    _convert(mesh_wheeled, target)
    drive = drive_mujoco if engine == "mujoco" else drive_pybullet
    got = drive(target, v, w, MESH_RADIUS, HALF_AXLE)
    want = ideal(v, w)
    assert abs(got.yaw - want.yaw) <= max(0.1 * abs(want.yaw), 0.05), (got, want)
    travelled = math.hypot(want.x, want.y)
    assert math.hypot(got.x - want.x, got.y - want.y) <= (0.05 if travelled == 0 else 0.1 * travelled), got


def test_verify_drives_the_mesh_wheels_it_wrote(mesh_wheeled: Path, tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["verify", str(mesh_wheeled), "-o", str(tmp_path / "v")])
    assert result.exit_code == 0, result.output
    verdict = result.output.strip().splitlines()[-3]
    assert re.match(r"PASS: \d+ checks passed", verdict), result.output
    assert "layer 4 graded arc, spin, straight on the written MobileRobot.xml, the written MobileRobot.urdf" \
        in verdict


def test_verify_compares_given_files_with_the_sphere_convert_wrote(mesh_wheeled: Path,
                                                                 tmp_path: Path) -> None:
    """Files ``convert`` wrote, given to ``verify``: layer 1 compares their spheres with the sphere
    ``convert`` makes of the source's mesh, and says so."""
    from modelkit.verify.api import verify

    _convert(mesh_wheeled, tmp_path / "r.xml")
    _convert(mesh_wheeled, tmp_path / "r.urdf")
    report = verify(mesh_wheeled, tmp_path / "out", engines=("mujoco", "pybullet"), mjcf=tmp_path / "r.xml",
                    urdf=tmp_path / "r.urdf", replay=False)
    assert [c for c in report.checks if not c.passed] == []
    assert {(c.engine, c.quantity) for c in report.checks if c.layer == 1} >= {
        ("mujoco", "shape-size"), ("pybullet", "shape-size"), ("mujoco", "shape-set")}
    said = [s.reason for s in report.skips if "convert's wheel collision" in s.reason]
    assert len(said) == 2 and all("a sphere in place of the source's round mesh on LeftWheel, RightWheel" in s
                                  for s in said), said


def test_find_drive_reads_the_wheel_radius_from_the_mesh(mesh_wheeled: Path) -> None:
    drive = find_drive(validate(mesh_wheeled).robots[0], Scenario(profiles=()))
    assert (drive.left, drive.right) == ("LeftWheel", "RightWheel")
    assert drive.radius == pytest.approx(MESH_RADIUS, abs=1e-7)
    assert drive.half_axle == pytest.approx(HALF_AXLE, abs=1e-6)


def test_a_robot_on_its_two_wheels_alone_is_not_driven() -> None:
    """``mobile_robot_mesh.body``'s chassis collision is ``vmega_body.dae``, which the tutorial does not
    ship: nothing but its wheels reaches the floor, and its COM is 8 cm behind the axle."""
    robot = validate(TUTORIAL / "mobile_robot_mesh.body").robots[0]
    drive = find_drive(robot, Scenario(profiles=()))
    why = supported(robot, drive)
    assert why is not None and "stands on its two wheels alone" in why
    assert "the collision mesh of Chassis cannot be read" in why
    assert supported(validate(TUTORIAL / "mobile_robot.body").robots[0], drive) is None


def _prism(tmp_path: Path, sides: int) -> Geom:
    import trimesh

    stl = tmp_path / f"prism{sides}.stl"
    trimesh.creation.cylinder(radius=0.1, height=0.05, sections=sides).export(stl)
    return Geom(Mesh(uri=stl.name, path=str(stl)), Pose())


def test_roundness_of_a_mesh(tmp_path: Path) -> None:
    """A 16-sided prism is round about its axis (reach 0.8 % apart); a square prism, as Hello Robot's
    Stretch's wheel collision is, is not (41 %); the axis matters."""
    z = np.array([0.0, 0.0, 1.0])
    sixteen = round_about(_prism(tmp_path, 16), z)
    assert sixteen is not None and sixteen.radius == pytest.approx(0.1, rel=0.01)
    assert sixteen.width == pytest.approx(0.05) and np.allclose(sixteen.centre, 0.0, atol=1e-9)
    assert round_about(_prism(tmp_path, 4), z) is None
    assert round_about(_prism(tmp_path, 16), np.array([1.0, 0.0, 0.0])) is None
