"""The SDF writer: every sample and corpus model converts, libsdformat accepts the output (SDF 1.9
and 1.6), the SDF reader reads the same robot back (``compare_robots`` at 1e-9, less the losses the
writer declared), output is byte-identical across runs, and the writer's rules one by one."""

from __future__ import annotations

import glob
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert import api as convert_api
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.notes import ConversionNote, NoteSink, renames
from modelkit.convert.options import WriteOptions
from modelkit.convert.registry import target_info
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Device,
    DeviceKind,
    Ellipsoid,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    Mimic,
    Robot,
)
from modelkit.spatial import Pose, matrix_from_rpy
from tests.conftest import CORPUS, REPO, TUTORIAL
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

PATTERNS = (
    "**/*.body",
    "**/*.urdf",
    "**/*.xacro",
    "**/*.sdf",
    "**/*.world",
    "mujoco_model/**/*.xml",
    "dm_control_suite/**/*.xml",
)
VERSIONS = ("1.9", "1.6")


def input_files() -> list[Path]:
    roots = [REPO / "samples", *([CORPUS] if CORPUS.is_dir() else [])]
    found = {
        Path(p) for root in roots for pat in PATTERNS for p in glob.glob(str(root / pat), recursive=True)
    }
    return sorted(found)


@dataclass
class Written:
    source: Path
    robot: Robot
    outputs: dict[str, Path] = field(default_factory=dict)
    notes: dict[str, list[ConversionNote]] = field(default_factory=dict)

    @property
    def label(self) -> str:
        return f"{self.source.relative_to(self.source.parents[1])}:{self.robot.name}"


def write(robot: Robot, out: Path, version: str = "1.9") -> list[ConversionNote]:
    return convert_api.write(robot, out, "sdf", WriteOptions(sdf_version=version))


@pytest.fixture(scope="module")
def converted() -> Iterator[tuple[list[Written], list[str]]]:
    """Every robot of every readable input, written at SDF 1.9 and 1.6; tracebacks collected."""
    cases: list[Written] = []
    failures: list[str] = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, path in enumerate(input_files()):
            result = validate(path)
            if any(d.code not in convert_api.CONVERTIBLE_ERRORS for d in result.errors):
                continue
            for k, robot in enumerate(result.robots):
                if robot.root is None:
                    continue
                case = Written(path, robot)
                for version in VERSIONS:
                    out = Path(tmp) / f"{i}_{k}_{version}" / "robot.sdf"
                    try:
                        case.notes[version] = write(robot, out, version)
                    except Exception as exc:
                        failures.append(f"{case.label} ({version}): {type(exc).__name__}: {exc}")
                        continue
                    case.outputs[version] = out
                cases.append(case)
        yield cases, failures


def test_every_input_converts(converted: tuple[list[Written], list[str]]) -> None:
    cases, failures = converted
    assert not failures, "\n".join(failures)
    assert len(cases) >= (100 if CORPUS.is_dir() else 10)


@pytest.mark.parametrize("version", VERSIONS)
def test_libsdformat_accepts_every_output(
    converted: tuple[list[Written], list[str]],
    version: str,
    sdf_oracle: Path,  # noqa: F811
) -> None:
    cases, _ = converted
    refused = [c.label for c in cases if oracle_has_errors(sdf_oracle, c.outputs[version])]
    assert not refused, f"libsdformat refuses {len(refused)} of {len(cases)}: {refused}"


# ---- round trip --------------------------------------------------------------------------------


TINY_MASS = 1e-6  # docs/convert.md: what the SDF writer gives a massless link that moves or carries shapes


def _massless(link: Link) -> bool:
    return link.inertial is None or link.inertial.mass <= 0.0


def _violates_triangle(link: Link) -> bool:
    """Principal moments with A + B < C, or equal within rounding (libsdformat refuses both)."""
    if link.inertial is None or link.inertial.mass <= 0.0:
        return False
    moments = np.sort(np.linalg.eigvalsh(np.asarray(link.inertial.inertia, dtype=float)))
    return bool(moments[0] + moments[1] <= moments[2] * (1 + 1e-9))


def expected_losses(source: Robot, version: str) -> dict[str, set[str]]:
    """What the SDF format cannot hold of ``source``, judged from the source alone (docs/convert.md's
    SDF section), never from the writer's own notes: the code under test must not decide which of its
    differences are excused.

    * ``frame``: SDF ≥ 1.7 writes a massless link without shapes or devices, on a fixed joint and
      with only such links below it, as a ``<frame>``;
    * ``tiny``: any other massless link gets 1e-6 kg (checked to be exactly that);
    * ``free``: a floating or planar joint does not exist inside an SDF model: the child subtree floats;
    * ``inertia``: a tensor whose principal moments break A + B ≥ C is written as the nearest valid one;
    * ``world``: a source link named ``world`` is SDF's world, not a link.
    """
    links = {lk.name: lk for lk in source.links}
    joint_of = {j.child: j for j in source.joints}
    children: dict[str, list[str]] = {}
    for joint in source.joints:
        children.setdefault(joint.parent, []).append(joint.child)

    def frameable(name: str) -> bool:
        link, joint = links.get(name), joint_of.get(name)
        if link is None or joint is None or name == source.root or joint.parent == "world":
            return False
        if not _massless(link) or link.visuals or link.collisions or link.devices:
            return False
        if joint.type not in (JointType.FIXED, JointType.PSEUDO_CONTINUOUS_TRACK):
            return False
        return all(frameable(child) for child in children.get(name, []))

    frames = {lk.name for lk in source.links if version != "1.6" and frameable(lk.name)}
    free: set[str] = set()
    stack = [j.child for j in source.joints if j.type in (JointType.FLOATING, JointType.PLANAR)]
    while stack:
        name = stack.pop()
        if name not in free:
            free.add(name)
            stack.extend(children.get(name, []))
    return {
        "frame": frames,
        "tiny": {lk.name for lk in source.links
                 if _massless(lk) and lk.name not in frames and lk.name != "world"},
        "free": free,
        "world": {"world"} if "world" in links else set(),
        "inertia": {lk.name for lk in source.links if _violates_triangle(lk)},
    }


def undeclared(source: Robot, back: Robot, diffs: list[Difference], version: str) -> list[Difference]:
    expected = expected_losses(source, version)
    moved_by = {j.name: j.child for j in source.joints}
    world_children = {j.child for j in source.joints if j.parent == "world"} if expected["world"] else set()
    out = []
    for diff in diffs:
        where = moved_by.get(diff.where, diff.where) if diff.quantity.startswith("joint") else diff.where
        if diff.quantity in ("link-set", "joint-set") and (
            where in expected["frame"] or where in expected["world"] or where in expected["free"]
            or where in world_children
        ):
            continue
        if diff.quantity == "mass" and where in expected["tiny"]:
            written = next((lk for lk in back.links if lk.name == where), None)
            if written is not None and written.inertial is not None and written.inertial.mass == TINY_MASS:
                continue
        if diff.quantity == "inertia" and where in expected["inertia"]:
            continue
        if diff.quantity == "pose" and where in expected["free"]:
            continue
        out.append(diff)
    return out


@pytest.mark.parametrize("version", VERSIONS)
def test_round_trip_reads_the_same_robot(converted: tuple[list[Written], list[str]], version: str) -> None:
    cases, _ = converted
    bad: list[str] = []
    for case in cases:
        notes = case.notes[version]
        back = validate(case.outputs[version])
        assert back.robots, f"{case.label}: nothing read back"
        link_renames = renames(notes)
        # the robot the writer was given: the pipeline replaces tracks by rollers first (MK809)
        source = convert_api.prepare(case.robot, target_info("sdf"), WriteOptions(), NoteSink())
        read_back = back.robots[0]
        diffs = undeclared(source, read_back, compare_robots(source, read_back, link_renames), version)
        if diffs:
            bad.append(f"{case.label}: " + "; ".join(str(x) for x in diffs[:3]))
    assert not bad, f"{len(bad)} of {len(cases)} differ:\n" + "\n".join(bad)


def test_two_runs_are_byte_identical(converted: tuple[list[Written], list[str]], tmp_path: Path) -> None:
    cases, _ = converted
    for case in cases[::5]:
        again = tmp_path / case.label.replace("/", "_").replace(":", "_") / "robot.sdf"
        write(case.robot, again)
        assert again.read_bytes() == case.outputs["1.9"].read_bytes(), case.label


# ---- the tutorial sensors robot ------------------------------------------------------------------


def test_tutorial_sensors_are_written(tmp_path: Path) -> None:
    robot = validate(TUTORIAL / "mobile_robot_sensors.body").robots[0]
    out = tmp_path / "robot.sdf"
    notes = write(robot, out)
    doc = etree.parse(str(out))
    lidar = doc.find(".//sensor[@name='LiDAR']")
    camera = doc.find(".//sensor[@name='RealSense']")
    assert lidar is not None and camera is not None, [n.render() for n in notes if n.code == "MK806"]
    assert lidar.get("type") == "gpu_lidar"
    assert lidar.findtext("lidar/scan/horizontal/samples") == "271"
    assert float(lidar.findtext("lidar/scan/horizontal/min_angle") or 0) == pytest.approx(-2.356194490192345)
    assert float(lidar.findtext("lidar/range/max") or 0) == 10.0
    assert float(lidar.findtext("update_rate") or 0) == 10.0
    assert camera.get("type") in ("rgbd_camera", "depth_camera")
    assert camera.findtext("camera/image/width") == "320" and camera.findtext("camera/image/height") == "240"
    assert float(camera.findtext("camera/clip/near") or 0) == 0.04
    lights = doc.findall(".//link/light")
    ex = validate(TUTORIAL / "mobile_robot_sensors_ex.body").robots[0]
    if any(d.canonical.value.endswith("_light") for lk in ex.links for d in lk.devices):
        write(ex, tmp_path / "ex.sdf")
        lights = etree.parse(str(tmp_path / "ex.sdf")).findall(".//link/light")
        assert lights and lights[0].get("type") == "spot"
        assert lights[0].find("spot/outer_angle") is not None


# ---- unit rules ------------------------------------------------------------------------------


def inertial(mass: float = 1.0) -> Inertial:
    return Inertial(
        mass, np.array([0.01, 0.02, 0.03]), np.array([[2.0, 0.1, 0.2], [0.1, 2.5, 0.3], [0.2, 0.3, 3.0]])
    )


def arm(root_joint: JointType | None = JointType.FLOATING) -> Robot:
    """base → (revolute "elbow") → elbow, plus a joint named like a link, a massless tip frame and a
    massless link with a shape."""
    pose = Pose(matrix_from_rpy(0.1, 1.5707963267948966, -0.3), np.array([0.1, 0.2, 0.3]))
    return Robot(
        name="arm",
        links=[
            Link("base", inertial(2.0), visuals=[Geom(Box(np.array([0.1, 0.2, 0.3])))]),
            Link(
                "elbow",
                inertial(),
                collisions=[
                    Geom(Capsule(0.05, 0.2)),
                    Geom(Ellipsoid(np.array([0.1, 0.2, 0.3]))),
                    Geom(Cone(0.1, 0.2)),
                ],
            ),
            Link("tip", None),
            Link("tool", None),
            Link("lamp", None, visuals=[Geom(Box(np.ones(3)))]),
        ],
        joints=[
            Joint(
                "elbow",
                JointType.REVOLUTE,
                "base",
                "elbow",
                pose,
                np.array([0.0, 1.0, 0.0]),
                JointLimits(-1.0, 2.0, velocity=3.0, effort=4.0),
                damping=0.5,
                friction=0.25,
            ),
            Joint("tip_joint", JointType.FIXED, "elbow", "tip", Pose(np.eye(3), np.array([0.0, 0.0, 0.5]))),
            Joint("tool_joint", JointType.FIXED, "tip", "tool", Pose(matrix_from_rpy(0, 0, 1), np.zeros(3))),
            Joint(
                "lamp_joint",
                JointType.REVOLUTE,
                "elbow",
                "lamp",
                Pose(),
                np.array([1.0, 0, 0]),
                mimic=Mimic("elbow", 2.0, 0.1),
            ),
        ],
        root="base",
        root_joint=root_joint,
        root_pose=Pose(matrix_from_rpy(0, 0, 0.5), np.array([1.0, 2.0, 3.0])),
    )


def codes(notes: list[ConversionNote]) -> list[str]:
    return [n.code for n in notes]


def test_link_joint_name_clash_is_renamed(tmp_path: Path) -> None:
    notes = write(arm(), tmp_path / "a.sdf")
    doc = etree.parse(str(tmp_path / "a.sdf"))
    assert doc.find(".//joint[@name='elbow_joint']/child").text == "elbow"  # type: ignore[union-attr]
    assert any(n.code == "MK800" and 'joint "elbow" is written as "elbow_joint"' in n.message for n in notes)
    assert renames(notes) == {}  # no link was renamed
    assert renames(notes, "joint") == {"elbow": "elbow_joint"}


def test_massless_links_become_frames_or_tiny_links(tmp_path: Path) -> None:
    notes = write(arm(), tmp_path / "a.sdf")
    doc = etree.parse(str(tmp_path / "a.sdf"))
    assert doc.find(".//frame[@name='tip']").get("attached_to") == "elbow"  # type: ignore[union-attr]
    assert doc.find(".//frame[@name='tool']").get("attached_to") == "tip"  # type: ignore[union-attr]
    assert doc.find(".//link[@name='tip']") is None and doc.find(".//joint[@name='tip_joint']") is None
    assert doc.findtext(".//link[@name='lamp']/inertial/mass") == "1e-6"  # carries a shape: a tiny link
    assert codes(notes).count("MK816") == 3
    back = validate(tmp_path / "a.sdf").robots[0]
    frames = back.link("elbow").extras["sdf_frames"]  # type: ignore[union-attr]
    assert np.allclose(frames["tip"].translation, [0, 0, 0.5]) and set(frames) == {"tip", "tool"}
    # SDF 1.6 has no attachable frames: every massless link is a tiny link
    notes16 = write(arm(), tmp_path / "b.sdf", "1.6")
    doc16 = etree.parse(str(tmp_path / "b.sdf"))
    assert doc16.find(".//frame") is None and doc16.findtext(".//link[@name='tool']/inertial/mass") == "1e-6"
    assert codes(notes16).count("MK816") == 3


def test_version_fallbacks(tmp_path: Path) -> None:
    notes19 = write(arm(), tmp_path / "a.sdf", "1.9")
    doc = etree.parse(str(tmp_path / "a.sdf"))
    assert doc.find(".//capsule") is not None and doc.find(".//ellipsoid") is not None
    assert doc.find(".//link[@name='elbow']/pose").get("relative_to") == "base"  # type: ignore[union-attr]
    assert codes(notes19).count("MK802") == 1  # the cone
    assert "MK812" in codes(notes19)  # mimic needs 1.11
    notes16 = write(arm(), tmp_path / "b.sdf", "1.6")
    doc16 = etree.parse(str(tmp_path / "b.sdf"))
    assert doc16.find(".//capsule") is None and codes(notes16).count("MK802") == 3
    assert not doc16.xpath("//*[@relative_to]")
    # 1.6 poses are composed into the model frame: the same robot reads back
    for path in (tmp_path / "a.sdf", tmp_path / "b.sdf"):
        back = validate(path).robots[0]
        poses = back.world_poses()
        assert np.allclose(poses["elbow"].translation, (arm().root_pose @ arm().joints[0].origin).translation)
    notes111 = write(arm(), tmp_path / "c.sdf", "1.11")
    mimic = etree.parse(str(tmp_path / "c.sdf")).find(".//mimic")
    assert mimic is not None and mimic.get("joint") == "elbow_joint" and "MK812" not in codes(notes111)


def test_fixed_root_is_a_world_joint(tmp_path: Path) -> None:
    robot = arm(JointType.FIXED)
    write(robot, tmp_path / "a.sdf")
    doc = etree.parse(str(tmp_path / "a.sdf"))
    joint = doc.find(".//joint[@name='world_joint']")
    assert joint is not None and joint.findtext("parent") == "world" and joint.findtext("child") == "base"
    assert doc.find(".//static") is None
    back = validate(tmp_path / "a.sdf").robots[0]
    assert back.root == "base" and back.root_joint is JointType.FIXED
    assert np.allclose(back.root_pose.rotation, robot.root_pose.rotation, atol=1e-12)
    assert np.allclose(back.root_pose.translation, robot.root_pose.translation, atol=1e-12)
    notes = write(arm(None), tmp_path / "b.sdf")
    assert "MK830" in codes(notes)  # --base auto settles the open root: no wheels or legs, welded
    assert validate(tmp_path / "b.sdf").robots[0].root_joint is JointType.FIXED


def test_full_inertia_and_joint_details_round_trip(tmp_path: Path) -> None:
    robot = arm()
    write(robot, tmp_path / "a.sdf")
    back = validate(tmp_path / "a.sdf").robots[0]
    written, read = robot.links[1].inertial, back.link("elbow")
    assert written is not None and read is not None and read.inertial is not None
    assert np.allclose(read.inertial.inertia, written.inertia, rtol=0, atol=1e-15)
    joint = next(j for j in back.joints if j.child == "elbow")
    assert (joint.limits.lower, joint.limits.upper, joint.limits.velocity, joint.limits.effort) == (
        -1,
        2,
        3,
        4,
    )
    assert (joint.damping, joint.friction) == (0.5, 0.25)


def test_canonical_devices_and_unknown_device(tmp_path: Path) -> None:
    robot = arm()
    robot.links[0].devices = [
        Device(
            "Camera",
            "cam",
            Pose(np.eye(3), np.array([0.1, 0, 0])),
            canonical=DeviceKind.CAMERA,
            canonical_params={
                "width": 640,
                "height": 480,
                "horizontal_fov": 1.0,
                "near": 0.05,
                "far": 50.0,
                "update_rate": 30.0,
            },
        ),
        Device(
            "SpotLight",
            "lamp",
            canonical=DeviceKind.SPOT_LIGHT,
            canonical_params={
                "color": [1.0, 0.5, 0.25],
                "spot_outer_angle": 0.5,
                "spot_inner_angle": 0.2,
                "direction": [1.0, 0.0, 0.0],
                "range": 8.0,
            },
        ),
        Device("Marker", "marker"),
    ]
    out = tmp_path / "a.sdf"
    notes = write(robot, out)
    doc = etree.parse(str(out))
    assert doc.findtext(".//sensor[@name='cam']/camera/image/width") == "640"
    # canonical angles are half-angles from the beam axis; SDF's are whole cone angles
    assert doc.findtext(".//light[@name='lamp']/spot/outer_angle") == "1"
    assert doc.findtext(".//light[@name='lamp']/spot/inner_angle") == "0.4"
    assert doc.findtext(".//light[@name='lamp']/diffuse") == "1 0.5 0.25 1"
    assert "MK806" in codes(notes)
    back = validate(out)
    assert not back.errors
    assert back.robot is not None
    (lamp,) = [d for lk in back.robot.links for d in lk.devices if d.name == "lamp"]
    assert lamp.canonical_params["spot_outer_angle"] == 0.5
    assert lamp.canonical_params["spot_inner_angle"] == 0.2


@pytest.mark.parametrize("version", ["1.6", "1.9", "1.11"])
def test_initial_position_is_dropped_with_a_note(tmp_path: Path, version: str) -> None:
    """SDFormat's <axis><initial_position> has no known implementation (deprecated in 1.8 and 1.9,
    removed from 1.10; Drake's libsdformat refuses it): never written, an MK820 note says so."""
    robot = arm()
    robot.joints[0].initial_position = 0.25
    notes = write(robot, tmp_path / "a.sdf", version)
    tree = etree.parse(str(tmp_path / "a.sdf"))
    assert tree.find(".//joint//initial_position") is None
    # the position controller --actuators auto gives the welded arm's elbow starts there (gz-sim's parameter)
    (plugin,) = [p for p in tree.iterfind(".//plugin") if p.findtext("joint_name") == "elbow_joint"]
    assert plugin.get("name") == "gz::sim::systems::JointPositionController"
    assert plugin.findtext("initial_position") == "0.25"
    (note,) = [n for n in notes if n.code == "MK820" and "initial position" in n.message]
    assert 'joint "elbow"' in note.message and "0.25" in note.message
    assert note.target == "joint[elbow_joint]/axis"
