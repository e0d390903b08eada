"""The files ``convert`` writes drive on a plain floor (issue 16): the tutorial's pan-tilt and
primitive robots converted by the CLI with default options, the MJCF in MuJoCo on a default plane and
the URDF in PyBullet on pybullet_data's plane.urdf, driven by the seed's law for 10 s
(:mod:`plain_floor_support`). Bounds: the yaw within 10 % of the ideal unicycle's, the end position
within 10 % of the ideal distance travelled (5 cm for the spin, which travels none).

One bound is not met, in both engines, and is marked ``xfail(strict=True)`` with the measured figure
(it fails if it starts passing, so the mark cannot go stale): the arc's end position, 29–32 cm from
the ideal unicycle's end (bound 20 cm) while its yaw is within 9 %. The robot is not slipping: the
COM is 8 cm behind the axle and the seed law has no integral term, so the wheel speeds lag their
targets differently on the two sides and the robot runs a different arc; the rigid no-slip reference
of verify's layer 4 (the same law on a robot that cannot slip) follows the same arc, and both
engines stay within 1.5 mm of it there (docs/verify.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.cli import main
from tests.plain_floor_support import Pose2, drive_mujoco, drive_pybullet, ideal

MODELS = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
RADIUS, HALF_AXLE = 0.076, 0.145  # the tutorial robots' wheels (the .body files)
PROFILES = {"straight": (0.3, 0.0), "spin": (0.0, 0.5), "arc": (0.3, 0.3)}
ARC_GAP = ("end 29-32 cm from the ideal unicycle's (bound 20 cm): COM 8 cm behind the axle and no integral "
           "term in the seed law; the no-slip reference runs the same arc")
KNOWN_GAPS = {("mujoco", "arc"): ARC_GAP, ("pybullet", "arc"): ARC_GAP}


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Path]:
    out: dict[tuple[str, str], Path] = {}
    for robot in ("pantilt", "primitive"):
        folder = tmp_path_factory.mktemp(robot)
        for suffix in ("xml", "urdf"):
            target = folder / f"robot.{suffix}"
            result = CliRunner().invoke(main, ["convert", str(MODELS / f"mobile_robot_{robot}.body"),
                                               "-o", str(target)])
            assert result.exit_code == 0, result.output
            out[(robot, suffix)] = target
    return out


def _check(got: Pose2, profile: str) -> None:
    v, w = PROFILES[profile]
    want = ideal(v, w)
    assert abs(got.yaw - want.yaw) <= max(0.1 * abs(want.yaw), 0.05), (got, want)
    travelled = math.hypot(want.x, want.y)
    bound = 0.05 if travelled == 0.0 else 0.1 * travelled
    assert math.hypot(got.x - want.x, got.y - want.y) <= bound, (got, want)


def _params() -> list[object]:
    out: list[object] = []
    for robot in ("pantilt", "primitive"):
        for engine in ("mujoco", "pybullet"):
            for profile in PROFILES:
                gap = KNOWN_GAPS.get((engine, profile))
                marks = [pytest.mark.xfail(strict=True, reason=gap)] if gap else []
                name = f"{robot}-{engine}-{profile}"
                out.append(pytest.param(robot, engine, profile, marks=marks, id=name))
    return out


@pytest.mark.parametrize(("robot", "engine", "profile"), _params())
def test_written_files_drive_on_a_plain_floor(written: dict[tuple[str, str], Path], robot: str, engine: str,
                                              profile: str) -> None:
    v, w = PROFILES[profile]
    if engine == "mujoco":
        got = drive_mujoco(written[(robot, "xml")], v, w, RADIUS, HALF_AXLE)
    else:
        got = drive_pybullet(written[(robot, "urdf")], v, w, RADIUS, HALF_AXLE)
    _check(got, profile)


def test_written_files_carry_their_contact(written: dict[tuple[str, str], Path]) -> None:
    """What makes them drive travels in the files: sphere wheels, priority, the caster's zero friction,
    the MJCF's <option>, PyBullet's <contact>."""
    mjcf = written[("pantilt", "xml")].read_text()
    assert '<option timestep="0.001" integrator="implicitfast" cone="elliptic" impratio="10"/>' in mjcf
    contact = 'group="3" priority="1" solref="0.004 1" solimp="0.99 0.999 0.001 0.5 2"'
    assert f'<default class="collision">\n        <geom {contact}/>' in mjcf  # the geoms' class
    wheel = 'type="sphere" size="0.076" class="collision" friction="3 0.005 0.0001" condim="3"'
    assert mjcf.count(wheel) == 2
    assert 'class="collision" friction="0 0.005 0.0001" condim="1"' in mjcf
    urdf = written[("pantilt", "urdf")].read_text()
    assert urdf.count('<lateral_friction value="3"/>') == 2 and '<lateral_friction value="0"/>' in urdf
    assert urdf.count('<sphere radius="0.076"/>') == 2


def test_wheel_collision_cylinder_keeps_the_cylinder(tmp_path: Path) -> None:
    target = tmp_path / "r.xml"
    source = str(MODELS / "mobile_robot_pantilt.body")
    args = ["convert", source, "-o", str(target), "--wheel-collision", "cylinder"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert 'type="cylinder" size="0.076 0.015"' in target.read_text()
    assert "MK826" not in result.output


TYRE_END = "            diffuseColor: [ 0.2, 0.2, 0.2 ]\n  -\n    name: RightWheel"


@pytest.mark.parametrize("suffix", ["xml", "urdf"])
def test_a_tyre_given_twice_rolls_as_one(tmp_path: Path, suffix: str) -> None:
    """The primitive robot with its left tyre given twice (the same cylinder, a copy-paste a semantic-fuzz
    mutant made): ``convert`` made a sphere of the first and kept the second cylinder, whose rim contacts
    scrubbed, so in MuJoCo the spin turned about the left wheel (its effective radius 40.9 mm of 76) and
    verify's layer 4 failed 13 checks. Every collision that rolls now gets the sphere, and the spin is
    the unicycle's."""
    text = (MODELS / "mobile_robot_primitive.body").read_text()
    assert text.count(TYRE_END) == 1
    source = tmp_path / "twice.body"
    source.write_text(text.replace(TYRE_END, TYRE_END.replace("\n  -", "\n      - *TireShape\n  -", 1)))
    target = tmp_path / f"robot.{suffix}"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
    assert result.exit_code == 0, result.output
    said = [line for line in result.output.splitlines() if "MK826 wheel LeftWheel" in line]
    assert len(said) == 2 and all("of the 2 that roll on the floor" in line for line in said), result.output
    tree = etree.parse(str(target))
    if suffix == "xml":
        shapes = [g.get("type") for g in tree.iterfind(".//body[@name='LeftWheel']/geom[@class='collision']")]
    else:
        shapes = [g.tag for g in tree.iterfind("link[@name='LeftWheel']/collision/geometry/*")]
    assert shapes == ["sphere", "sphere"], shapes
    v, w = PROFILES["spin"]
    drive = drive_mujoco if suffix == "xml" else drive_pybullet
    _check(drive(target, v, w, RADIUS, HALF_AXLE), "spin")
