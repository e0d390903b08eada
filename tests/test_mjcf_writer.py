"""The MJCF writer against real MuJoCo: every corpus model converts, loads without warnings after
1 s of simulation, and reads back (through modelkit's MJCF reader) as the same robot."""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import mujoco
import numpy as np
import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import CONVERTIBLE_ERRORS, prepare
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.context import WriteContext
from modelkit.convert.meshes import MeshExporter
from modelkit.convert.notes import ConversionNote, NoteSink
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan
from modelkit.convert.registry import target_info
from modelkit.formats.mjcf.write_bodies import MIN_INERTIA, MIN_MASS
from modelkit.formats.mjcf.write_names import renames_from_notes
from modelkit.formats.mjcf.writer import write_mjcf
from modelkit.model import (
    Box,
    Cylinder,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    LoopConstraint,
    Mesh,
    Mimic,
    Robot,
    TriangleMeshData,
)
from modelkit.spatial import Pose

from .conftest import CORPUS, REPO, TUTORIAL

SUFFIXES = (".body", ".urdf", ".xacro", ".sdf", ".xml", ".world")
TARGET_OF_NOTE = re.compile(r"body\[([^\]]*)\]")


@dataclass
class Written:
    source: Robot  # the model as the writer saw it (after the convert pipeline's preparation)
    path: Path
    notes: list[ConversionNote]
    data: bytes


def render(robot: Robot, folder: Path, name: str = "model.xml") -> Written:
    """Run the writer the way ``convert`` does and commit the files to ``folder``."""
    notes = NoteSink()
    prepared = prepare(robot, target_info("mjcf"), WriteOptions(), notes)
    plan = OutputPlan(folder, set(), True)
    ctx = WriteContext(WriteOptions(), notes, MeshExporter(plan, name, WriteOptions(), notes), name)
    data = write_mjcf(prepared, ctx)
    plan.add(name, data, "model")
    plan.commit()
    return Written(prepared, folder / name, notes.items, data)


def corpus_inputs() -> list[Path]:
    bases = [REPO / "samples", CORPUS]
    return sorted(
        p
        for b in bases
        if b.is_dir()
        for p in b.rglob("*")
        if p.is_file() and p.name.lower().endswith(SUFFIXES)
    )


def convertible(path: Path) -> list[Robot]:
    checked = validate(path)
    if any(d.code not in CONVERTIBLE_ERRORS for d in checked.errors):
        return []
    return [r for r in checked.robots if r.root is not None]


def step_warnings(model: mujoco.MjModel, seconds: float = 1.0) -> dict[int, int]:
    data = mujoco.MjData(model)
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return {i: int(data.warning[i].number) for i in range(len(data.warning)) if data.warning[i].number}


def noted_bodies(notes: list[ConversionNote], code: str, words: str) -> set[str]:
    return {
        m.group(1)
        for n in notes
        if n.code == code and words in n.message and n.target
        for m in [TARGET_OF_NOTE.search(n.target)]
        if m
    }


def explained(diff: Difference, written: Written, renames: dict[str, str]) -> bool:
    """Differences the notes announce: synthesised mass/inertia (MK816/MK870), links written as
    separate top-level bodies (MK813, which the reader reads as robots of their own), locked joints
    held by an equality (MK820), the link ``world`` being MuJoCo's world body (MK814)."""
    notes = written.notes
    where = renames.get(diff.where, diff.where)
    if diff.quantity in ("mass", "inertia", "com"):
        return where in noted_bodies(notes, "MK816", "MuJoCo refuses") | noted_bodies(notes, "MK870", "")
    top_level = noted_bodies(notes, "MK813", "top-level body")
    if diff.quantity in ("link-set", "pose"):
        if where in top_level or (where == "world" and any(n.code == "MK814" for n in notes)):
            return True
        moved = _below(written.source, {k for k, v in renames.items() if v in top_level} | top_level)
        return diff.where in moved
    if diff.quantity.startswith("limit-"):
        return any(n.code == "MK820" and f"joint {diff.where} is locked" in n.message for n in notes)
    return False


def _below(robot: Robot, tops: set[str]) -> set[str]:
    out = set(tops)
    changed = True
    while changed:
        changed = False
        for joint in robot.joints:
            if joint.parent in out and joint.child not in out:
                out.add(joint.child)
                changed = True
    return out


@cache
def corpus_results(tmp: str) -> dict[str, object]:
    """Convert, load, step and read back every corpus model once (shared by the tests)."""
    stats: dict[str, object] = {"converted": 0, "loaded": 0, "clean": 0, "round_trip": 0, "failures": []}
    failures: list[str] = stats["failures"]  # type: ignore[assignment]
    for n, path in enumerate(corpus_inputs()):
        for k, robot in enumerate(convertible(path)):
            folder = Path(tmp) / f"{n:03d}_{k}"
            written = render(robot, folder)
            stats["converted"] = int(stats["converted"]) + 1  # type: ignore[call-overload]
            try:
                model = mujoco.MjModel.from_xml_path(str(written.path))
            except ValueError as exc:
                failures.append(f"load {path}#{k}: {exc}")
                continue
            stats["loaded"] = int(stats["loaded"]) + 1  # type: ignore[call-overload]
            warnings = step_warnings(model)
            if warnings:
                failures.append(f"warnings {path}#{k}: {warnings}")
            else:
                stats["clean"] = int(stats["clean"]) + 1  # type: ignore[call-overload]
            back = validate(written.path).robots
            renames = renames_from_notes([x.message for x in written.notes if x.code == "MK800"])
            diffs = [
                d
                for d in compare_robots(written.source, back[0], renames)
                if not explained(d, written, renames)
            ]
            if diffs:
                failures.append(f"round trip {path}#{k}: {[str(d) for d in diffs[:3]]}")
            else:
                stats["round_trip"] = int(stats["round_trip"]) + 1  # type: ignore[call-overload]
    return stats


@pytest.fixture(scope="module")
def sweep(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not available")
    return corpus_results(str(tmp_path_factory.mktemp("mjcf_sweep")))


def test_corpus_converts_loads_steps_and_round_trips(sweep: dict[str, object]) -> None:
    print({k: v for k, v in sweep.items() if k != "failures"})
    assert sweep["failures"] == []
    assert int(sweep["converted"]) >= 150  # type: ignore[call-overload]
    assert sweep["converted"] == sweep["loaded"] == sweep["clean"] == sweep["round_trip"]


def test_body_mass_is_the_models_exactly(tmp_path: Path) -> None:
    """MuJoCo's compiled masses and inertias, not just modelkit's read-back, match the model."""
    for name in ("mobile_robot_sensors.body", "mobile_robot_pantilt.body"):
        (robot,) = convertible(TUTORIAL / name)
        written = render(robot, tmp_path / name)
        model = mujoco.MjModel.from_xml_path(str(written.path))
        for link in written.source.links:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, link.name)
            assert b > 0
            mass = link.inertial.mass if link.inertial else 0.0
            assert model.body_mass[b] == pytest.approx(mass, rel=1e-9, abs=0.0)
            if link.inertial:
                assert np.allclose(model.body_ipos[b], link.inertial.com, rtol=0, atol=1e-12)
                moments = np.sort(np.linalg.eigvalsh(link.inertial.inertia))
                assert np.allclose(np.sort(model.body_inertia[b]), moments, rtol=1e-9, atol=0)


def test_two_runs_are_byte_identical(tmp_path: Path) -> None:
    for path in (TUTORIAL / "mobile_robot_sensors.body", CORPUS / "choreonoid/share/model/SR1/SR1.body"):
        if not path.exists():
            continue
        (robot,) = convertible(path)
        first = render(robot, tmp_path / "a")
        second = render(robot, tmp_path / "b")
        assert first.data == second.data
        files_a = sorted(p.relative_to(tmp_path / "a") for p in (tmp_path / "a").rglob("*") if p.is_file())
        files_b = sorted(p.relative_to(tmp_path / "b") for p in (tmp_path / "b").rglob("*") if p.is_file())
        assert files_a == files_b
        for rel in files_a:
            assert (tmp_path / "a" / rel).read_bytes() == (tmp_path / "b" / rel).read_bytes()
        assert b"/work" not in first.data and b"\t" not in first.data


# -- the tutorial robots ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "name",
    [
        "mobile_robot.body",
        "mobile_robot_primitive.body",
        "mobile_robot_sensors.body",
        "mobile_robot_pantilt.body",
        "mobile_robot_tracks.body",
    ],
)
def test_tutorial_robot(tmp_path: Path, name: str) -> None:
    (robot,) = convertible(TUTORIAL / name)
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    source = written.source
    moving = [j for j in source.joints if j.type.moves]
    assert model.njnt == len(moving) + 1  # + the root's free joint
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and model.jnt_bodyid[0] == 1
    total = sum(lk.inertial.mass for lk in source.links if lk.inertial)
    assert math.isclose(float(np.sum(model.body_mass)), total, rel_tol=1e-12)
    assert step_warnings(model) == {}
    if source.link("LeftWheel") is None:  # the tracks robot: rollers instead of wheels
        return
    wheel = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "LeftWheel")
    cylinders = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == wheel
        and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER
        and model.geom_contype[g]
    ]
    expected = [
        g.geometry
        for g in source.link("LeftWheel").collisions  # type: ignore[union-attr]
        if isinstance(g.geometry, Cylinder)
    ]
    assert len(cylinders) == len(expected) >= 1
    assert model.geom_size[cylinders[0]][0] == pytest.approx(expected[0].radius, abs=1e-15)
    assert model.geom_size[cylinders[0]][1] * 2 == pytest.approx(expected[0].length, abs=1e-15)
    # the wheel's axis: the cylinder's Z lies along the joint axis (the wheel's Y)
    quat = model.geom_quat[cylinders[0]]
    zaxis = np.zeros(9)
    mujoco.mju_quat2Mat(zaxis, quat)
    assert np.allclose(zaxis.reshape(3, 3)[:, 2] * np.sign(zaxis.reshape(3, 3)[1, 2]), [0, 1, 0], atol=1e-12)


def test_tutorial_sensors_appear(tmp_path: Path) -> None:
    """LiDAR → site + rangefinder along the device's forward axis; camera → <camera> looking forward;
    spot light → <light> (needs the .body reader to fill ``device.canonical``)."""
    (robot,) = convertible(TUTORIAL / "mobile_robot_sensors_ex.body")
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    devices = {d.name: (lk, d) for lk in written.source.links for d in lk.devices}
    assert "LiDAR" in devices and "RealSense" in devices
    tilt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, devices["LiDAR"][0].name)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "LiDAR")
    assert site >= 0 and model.site_bodyid[site] == tilt
    sensor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "LiDAR")
    assert model.sensor_type[sensor] == mujoco.mjtSensor.mjSENS_RANGEFINDER
    lidar = devices["LiDAR"][1]
    ray = data.site_xmat[site].reshape(3, 3)[:, 2]  # the rangefinder's ray: the site's +Z
    body = data.xmat[tilt].reshape(3, 3)
    assert np.allclose(ray, body @ lidar.pose.rotation[:, 0], atol=1e-12)
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "RealSense")
    assert cam >= 0
    camera = devices["RealSense"][1]
    look = -data.cam_xmat[cam].reshape(3, 3)[:, 2]
    assert np.allclose(look, body @ camera.pose.rotation[:, 0], atol=1e-12)
    up = data.cam_xmat[cam].reshape(3, 3)[:, 1]
    assert np.allclose(up, body @ camera.pose.rotation[:, 2], atol=1e-12)
    p = camera.canonical_params
    vfov = 2 * math.atan(math.tan(p["horizontal_fov"] / 2) * p["height"] / p["width"])
    assert model.cam_fovy[cam] == pytest.approx(math.degrees(vfov), rel=1e-12)
    assert list(model.cam_resolution[cam]) == [p["width"], p["height"]]
    lights = [d for _, d in devices.values() if d.canonical.value.endswith("light")]
    assert lights, "the sensors_ex robot has a spot light"
    assert model.nlight == len(lights)
    assert any(n.code == "MK807" and "rangefinder" in n.message for n in written.notes)


# -- unit cases -------------------------------------------------------------------------------


def _link(name: str, mass: float = 1.0) -> Link:
    return Link(name, Inertial(mass, np.zeros(3), np.eye(3) * 0.01 * mass) if mass else None)


def _chain(*joints: Joint, masses: dict[str, float] | None = None) -> Robot:
    masses = masses or {}
    names = ["base"] + [j.child for j in joints]
    robot = Robot(
        "unit",
        [_link(n, masses.get(n, 1.0)) for n in names],
        list(joints),
        root="base",
        root_joint=JointType.FIXED,
    )
    return robot


def _hinge(name: str, parent: str, child: str, origin: Pose | None = None) -> Joint:
    return Joint(
        name,
        JointType.REVOLUTE,
        parent,
        child,
        origin or Pose(np.eye(3), np.array([0.0, 0.0, 0.5])),
        np.array([1.0, 0.0, 0.0]),
        JointLimits(-1.0, 1.0, effort=3.0),
    )


def test_mimic_becomes_joint_equality(tmp_path: Path) -> None:
    follower = _hinge("f", "base", "b")
    follower.mimic = Mimic("a", multiplier=-2.0, offset=0.25)
    robot = _chain(_hinge("a", "base", "a_link"), follower)
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    (eq,) = tree.findall("equality/joint")
    assert (eq.get("joint1"), eq.get("joint2"), eq.get("polycoef")) == ("f", "a", "0.25 -2 0 0 0")
    assert [m.get("joint") for m in tree.findall("actuator/motor")] == ["a"]
    assert tree.find("actuator/motor").get("ctrlrange") == "-3 3"  # type: ignore[union-attr]
    model = mujoco.MjModel.from_xml_path(str(written.path))
    data = mujoco.MjData(model)
    data.qpos[0] = 0.3
    for _ in range(2000):
        mujoco.mj_step(model, data)
    assert data.qpos[1] == pytest.approx(0.25 - 2.0 * data.qpos[0], abs=2e-3)
    back = validate(written.path).robots[0]
    mimic = next(j for j in back.joints if j.name == "f").mimic
    assert mimic is not None and (mimic.joint, mimic.multiplier, mimic.offset) == ("a", -2.0, 0.25)


def test_loops_become_connect_and_weld(tmp_path: Path) -> None:
    robot = _chain(_hinge("j1", "base", "l1"), _hinge("j2", "base", "l2"))
    at1, at2 = Pose(np.eye(3), np.array([0.0, 0.1, 0.0])), Pose(np.eye(3), np.array([0.0, -0.1, 0.0]))
    robot.loops = [
        LoopConstraint("ball", "ball", "l1", "l2", at1, at2),
        LoopConstraint("weld", "fixed", "l1", "l2", at1, at2),
        LoopConstraint("hinge", "hinge", "l1", "l2", at1, at2, np.array([1.0, 0.0, 0.0])),
        LoopConstraint("piston", "piston", "l1", "l2", at1, at2),
    ]
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    assert [(e.tag, e.get("name")) for e in tree.find("equality")] == [  # type: ignore[union-attr]
        ("connect", "ball"),
        ("weld", "weld"),
        ("connect", "hinge_a"),
        ("connect", "hinge_b"),
    ]
    hinge_sites = {
        s.get("name"): s.get("pos") for s in tree.iter("site") if s.get("name", "").startswith("hinge")
    }
    assert hinge_sites == {
        "hinge_a1": "0.05 0.1 0",
        "hinge_b1": "-0.05 0.1 0",
        "hinge_a2": "0.05 -0.1 0",
        "hinge_b2": "-0.05 -0.1 0",
    }
    codes = [n.code for n in written.notes]
    assert "MK811" in codes and "MK810" in codes
    model = mujoco.MjModel.from_xml_path(str(written.path))
    assert model.neq == 4 and step_warnings(model) == {}


def test_closed_link_sample(tmp_path: Path) -> None:
    path = CORPUS / "choreonoid/share/model/misc/ClosedLinkSample.body"
    if not path.exists():
        pytest.skip("corpus not available")
    (robot,) = convertible(path)
    assert robot.loops
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    types = sorted(int(t) for t in model.eq_type)
    assert types and all(t in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD) for t in types)
    assert step_warnings(model) == {}


def test_massless_links(tmp_path: Path) -> None:
    """A massless body on a fixed joint stays massless; a moving one gets MIN_MASS with an MK816 note;
    a massless moving body carrying a welded massive child needs nothing."""
    fixed = Joint("weld", JointType.FIXED, "base", "frame", Pose(np.eye(3), np.array([0.1, 0.0, 0.0])))
    robot = _chain(
        fixed,
        _hinge("spin", "base", "idle"),
        _hinge("carry", "base", "carrier"),
        Joint("w2", JointType.FIXED, "carrier", "payload"),
        masses={"frame": 0.0, "idle": 0.0, "carrier": 0.0},
    )
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    mass = {model.body(b).name: float(model.body_mass[b]) for b in range(1, model.nbody)}
    assert mass == {"base": 1.0, "frame": 0.0, "idle": MIN_MASS, "carrier": 0.0, "payload": 1.0}
    idle = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "idle")
    assert np.allclose(model.body_inertia[idle], MIN_INERTIA, rtol=1e-12)
    notes = {n.target: n for n in written.notes if n.code == "MK816"}
    assert (
        "MuJoCo refuses" in notes["body[idle]/inertial"].message
        and "1e-6 kg" in notes["body[idle]/inertial"].message
    )
    assert "body[frame]" in notes and step_warnings(model) == {}


def test_names_are_unique_and_renames_noted(tmp_path: Path) -> None:
    """Two meshes from files with the same stem get distinct assets; a link called ``world`` that is
    not the root is renamed (MuJoCo reserves the name)."""
    tri = TriangleMeshData(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
        np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
    )
    robot = _chain(_hinge("j", "base", "world"))
    robot.link("base").visuals = [  # type: ignore[union-attr]
        Geom(Mesh(data=tri, generator="TriangleMesh")),
        Geom(Mesh(data=tri, generator="TriangleMesh", scale=np.array([2.0, 2.0, 2.0]))),
        Geom(Box(np.array([1.0, 2.0, 3.0])), name="g"),
        Geom(Box(np.array([1.0, 1.0, 1.0])), name="g"),
    ]
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    assets = [(m.get("name"), m.get("scale")) for m in tree.iter("mesh")]
    assert len({a for a, _ in assets}) == len(assets) == 2
    assert [b.get("name") for b in tree.iter("body")] == ["base", "world_2"]
    assert [g.get("name") for g in tree.iter("geom") if g.get("name")] == ["g", "g_2"]
    renames = renames_from_notes([n.message for n in written.notes if n.code == "MK800"])
    assert renames == {"world": "world_2"}
    assert renames_from_notes([n.message for n in written.notes if n.code == "MK800"], "geom") == {"g": "g_2"}
    model = mujoco.MjModel.from_xml_path(str(written.path))
    assert model.nmesh == 2 and step_warnings(model) == {}
    back = validate(written.path).robots[0]
    assert compare_robots(written.source, back, renames) == []


def test_root_conventions(tmp_path: Path) -> None:
    robot = _chain(_hinge("j", "base", "arm"))
    robot.root_pose = Pose(np.eye(3), np.array([0.0, 0.0, 1.0]))
    for kind, free in ((JointType.FIXED, False), (JointType.FLOATING, True), (None, True)):
        variant = copy.deepcopy(robot)
        variant.root_joint = kind
        written = render(variant, tmp_path / str(kind))
        tree = etree.fromstring(written.data)
        base = tree.find("worldbody/body")
        assert base is not None and base.get("pos") == "0 0 1"
        assert (base.find("freejoint") is not None) is free
        assert any(n.code == "MK814" for n in written.notes) is (kind is None)


def test_triangle_inequality_is_repaired_with_a_note(tmp_path: Path) -> None:
    robot = _chain(_hinge("j", "base", "arm"))
    robot.link("arm").inertial = Inertial(1.0, np.zeros(3), np.diag([1.0, 1.0, 100.0]))  # type: ignore[union-attr]
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    arm = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "arm")
    assert np.allclose(np.sort(model.body_inertia[arm]), [50.0, 50.0, 100.0])
    assert any(n.code == "MK870" and "a + b ≥ c" in n.message for n in written.notes)
