"""Fault injection on real written files, measured with the real engines (no mocks).

The tutorial pan-tilt robot (root welded) is written as MJCF, URDF and SDF; each fault is injected
into a fresh copy, and the perturbed file is read back by MuJoCo (MJCF) or Drake (SDF, URDF): it
must differ from the unperturbed file in exactly the injected quantity, by exactly the injected
amount. Then the verification layers must fail on that quantity, naming the link or joint.
"""

from __future__ import annotations

import copy
import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import modelkit
from modelkit.convert import write
from modelkit.convert.notes import renames
from modelkit.model import JointType, Robot
from modelkit.spatial import matrix_from_quat_wxyz
from modelkit.verify.engines.mujoco import load as load_mujoco
from modelkit.verify.engines.protocol import StaticFacts
from modelkit.verify.layers.inject import InjectError, apply, inject, parse
from tests.conftest import TUTORIAL

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
FORMATS = {"mjcf": "x.xml", "urdf": "x.urdf", "sdf": "x.sdf"}
Renames = dict[str, dict[str, str]]


@dataclass
class Written:
    robot: Robot
    folder: Path
    renames: dict[str, Renames]


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Written:
    robot = copy.deepcopy(modelkit.load(PANTILT))
    robot.root_joint = JointType.FIXED
    folder = tmp_path_factory.mktemp("pantilt")
    maps: dict[str, Renames] = {}
    for fmt_name, name in FORMATS.items():
        notes = write(robot, folder / name)
        maps[fmt_name] = {"link": renames(notes, "link"), "joint": renames(notes, "joint")}
    return Written(robot, folder, maps)


def _copy(w: Written, tmp_path: Path) -> Path:
    out = tmp_path / "perturbed"
    shutil.copytree(w.folder, out)
    return out


def _engine(fmt_name: str, path: Path) -> Any:
    """MuJoCo reads the MJCF, Drake the SDF and the URDF (the root is "Chassis" in every file)."""
    if fmt_name == "mjcf":
        return load_mujoco(path, {}, root="Chassis")
    pytest.importorskip("pydrake", reason="Drake is an optional extra: pip install modelkit[drake]")
    from modelkit.verify.engines.drake import load as load_drake

    return load_drake(path, {}, root="Chassis")


def _same(a: Any, b: Any) -> bool:
    """Equal up to the engine's own round-off (Drake keeps inertia about the body origin: a COM off
    the origin costs ~1e-17 kg·m² on the way back), far below any injected fault."""
    if isinstance(a, str) or isinstance(b, str):
        return bool(a == b)
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if np.array_equal(x, y):
        return True
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        return False
    return float(np.max(np.abs(x - y))) <= 1e-12 * max(float(np.max(np.abs(x))), 1e-3)


def _differences(a: StaticFacts, b: StaticFacts) -> dict[tuple[str, str], tuple[Any, Any]]:
    """Every (link or joint, quantity) whose value differs between two readings (beyond round-off)."""
    out: dict[tuple[str, str], tuple[Any, Any]] = {}
    assert set(a.links) == set(b.links) and set(a.joints) == set(b.joints)
    for name, la in a.links.items():
        lb = b.links[name]
        for quantity in ("mass", "com", "inertia"):
            va, vb = getattr(la, quantity), getattr(lb, quantity)
            if not _same(va, vb):
                out[(name, quantity)] = (va, vb)
    for name, ja in a.joints.items():
        jb = b.joints[name]
        for quantity in ("type", "parent", "child", "axis", "lower", "upper"):
            va, vb = getattr(ja, quantity), getattr(jb, quantity)
            if not _same(va, vb):
                out[(name, quantity)] = (va, vb)
    return out


def _shapes(fmt_name: str, path: Path) -> dict[str, list[tuple[str, float, np.ndarray]]]:
    """Per link: (cylinder|sphere, radius, shape axis in the link frame) of every collision and visual
    shape, as the engine built them (MuJoCo ``geom_*``; Drake's SceneGraph)."""
    out: dict[str, list[tuple[str, float, np.ndarray]]] = {}
    if fmt_name == "mjcf":
        m = mujoco.MjModel.from_xml_path(str(path))
        kinds = {int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder", int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere"}
        for g in range(m.ngeom):
            kind = kinds.get(int(m.geom_type[g]))
            if kind is None:
                continue
            body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g]))
            axis = matrix_from_quat_wxyz(m.geom_quat[g])[:, 2]
            out.setdefault(body, []).append((kind, float(m.geom_size[g][0]), axis))
        return out
    pytest.importorskip("pydrake")
    from pydrake.geometry import Cylinder, Role, Sphere
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    plant, scene = AddMultibodyPlantSceneGraph(DiagramBuilder(), 0.0)
    Parser(plant).AddModels(file_name=path)
    plant.Finalize()
    inspector = scene.model_inspector()
    for index in plant.GetBodyIndices(plant.GetModelInstanceByName("MobileRobot")):
        body = plant.get_body(index)
        frame = plant.GetBodyFrameIdOrThrow(index)
        for role in (Role.kProximity, Role.kIllustration):
            for g in inspector.GetGeometries(frame, role):
                shape = inspector.GetShape(g)
                if isinstance(shape, Cylinder | Sphere):
                    axis = np.array(inspector.GetPoseInFrame(g).rotation().matrix())[:, 2]
                    kind = "cylinder" if isinstance(shape, Cylinder) else "sphere"
                    out.setdefault(body.name(), []).append((kind, float(shape.radius()), axis))
    return out


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / max(float(np.max(np.abs(b))), 1e-300)


# ---- the perturbed file differs in exactly the injected quantity ------------------------------------


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_inertia_fault_scales_one_tensor(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    before = _engine(fmt_name, written.folder / FORMATS[fmt_name]).static()
    result = inject(path, "inertia:TiltLink:1%", written.renames[fmt_name])
    assert result.written == "TiltLink" and result.changes
    diff = _differences(before, _engine(fmt_name, path).static())
    assert set(diff) == {("TiltLink", "inertia")}
    old, new = diff[("TiltLink", "inertia")]
    assert _relative(new, 1.01 * old) <= 1e-12
    assert _relative(new, old) == pytest.approx(0.01, rel=1e-9)


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_mass_fault_scales_one_mass(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    before = _engine(fmt_name, written.folder / FORMATS[fmt_name]).static()
    inject(path, "mass:PanLink:10%", written.renames[fmt_name])
    diff = _differences(before, _engine(fmt_name, path).static())
    assert set(diff) == {("PanLink", "mass")}
    old, new = diff[("PanLink", "mass")]
    assert new == pytest.approx(1.1 * old, rel=1e-12)


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_com_fault_shifts_one_com_along_x(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    before = _engine(fmt_name, written.folder / FORMATS[fmt_name]).static()
    inject(path, "com:PanLink:0.01", written.renames[fmt_name])
    diff = _differences(before, _engine(fmt_name, path).static())
    assert set(diff) == {("PanLink", "com")}
    old, new = diff[("PanLink", "com")]
    assert np.max(np.abs(np.asarray(new) - np.asarray(old) - [0.01, 0.0, 0.0])) <= 1e-15


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_axis_fault_negates_one_axis_and_changes_fk(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    original = _engine(fmt_name, written.folder / FORMATS[fmt_name])
    perturbed = _engine(fmt_name, path)
    before = original.static()
    inject(path, "axis:PanJoint:flip", written.renames[fmt_name])
    perturbed = _engine(fmt_name, path)
    diff = _differences(before, perturbed.static())
    assert set(diff) == {("PanJoint", "axis")}
    old, new = diff[("PanJoint", "axis")]
    assert np.array_equal(new, -old)
    # FK: equal at q = 0, different at q != 0 (the pan link turns the other way)
    for name, pose in original.link_poses({}).items():
        other = perturbed.link_poses({})[name]
        assert np.max(np.abs(pose.rotation - other.rotation)) <= 1e-15
    q = {"PanJoint": 0.5}
    a, b = original.link_poses(q), perturbed.link_poses(q)
    turned = a["PanLink"].rotation.T @ b["PanLink"].rotation
    assert math.acos(max(-1.0, min(1.0, (np.trace(turned) - 1.0) / 2.0))) == pytest.approx(1.0, abs=1e-12)
    for name in ("Chassis", "LeftWheel", "RightWheel"):
        assert np.max(np.abs(a[name].rotation - b[name].rotation)) <= 1e-15


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_cylinder_y_fault_turns_the_cylinders_only(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    before_facts = _engine(fmt_name, written.folder / FORMATS[fmt_name]).static()
    before = _shapes(fmt_name, written.folder / FORMATS[fmt_name])
    inject(path, "cylinder-y:LeftWheel", written.renames[fmt_name])
    assert _differences(before_facts, _engine(fmt_name, path).static()) == {}
    after = _shapes(fmt_name, path)
    for link in before:
        if link != "LeftWheel":
            assert [(k, r) for k, r, _ in after[link]] == [(k, r) for k, r, _ in before[link]]
            assert all(np.array_equal(x[2], y[2]) for x, y in zip(after[link], before[link], strict=True))
    (kind, radius, axis_before), = before["LeftWheel"]
    (_, radius_after, axis_after), = after["LeftWheel"]
    assert kind == "cylinder" and radius_after == radius
    assert abs(axis_before[1]) == pytest.approx(1.0, abs=1e-12)  # the wheel's axle: link y
    assert abs(axis_after[2]) == pytest.approx(1.0, abs=1e-12)  # left unconverted: link z, upright


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_wheel_radius_fault_scales_the_radius_only(written: Written, fmt_name: str, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    before_facts = _engine(fmt_name, written.folder / FORMATS[fmt_name]).static()
    before = _shapes(fmt_name, written.folder / FORMATS[fmt_name])
    inject(path, "wheel-radius:RightWheel:5%", written.renames[fmt_name])
    assert _differences(before_facts, _engine(fmt_name, path).static()) == {}
    after = _shapes(fmt_name, path)
    for link in before:
        ratio = 1.05 if link == "RightWheel" else 1.0
        expected = [ratio * r for _, r, _ in before[link]]
        assert [r for _, r, _ in after[link]] == pytest.approx(expected, rel=1e-12)
        assert all(np.array_equal(x[2], y[2]) for x, y in zip(after[link], before[link], strict=True))


def test_apply_perturbs_every_file_and_describes_it(written: Written, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    files = {fmt_name: out / name for fmt_name, name in FORMATS.items()}
    line = apply("axis:LeftWheel:flip", files, written.renames)
    assert line.startswith("axis:LeftWheel:flip: ")
    assert "x.sdf: joint[LeftWheel_joint]/axis/xyz: 0 1 0 → 0 -1 0" in line
    assert "x.urdf: joint[LeftWheel]/axis xyz: 0 1 0 → 0 -1 0" in line  # URDF keeps the name (MK846)
    assert "x.xml: joint[LeftWheel] axis: 0 1 0 → 0 -1 0" in line
    # the rest of each file is kept byte for byte: only the injected line differs
    for fmt_name, name in FORMATS.items():
        a = (written.folder / name).read_text().splitlines()
        b = files[fmt_name].read_text().splitlines()
        assert len(a) == len(b), fmt_name
        assert sum(x != y for x, y in zip(a, b, strict=True)) == 1, fmt_name


# ---- the spec grammar and its errors ----------------------------------------------------------------


def test_spec_grammar() -> None:
    assert parse("inertia:TiltLink:1%").amount == pytest.approx(1.01)
    assert parse("mass:PanLink:-5%").amount == pytest.approx(0.95)
    assert parse("wheel-radius:LeftWheel:2.5%").amount == pytest.approx(1.025)
    assert parse("com:Chassis:0.01").amount == 0.01
    assert parse("com:Chassis:-0.02m").amount == -0.02
    flip = parse("axis:PanJoint:flip")
    assert (flip.kind, flip.target, flip.amount) == ("axis", "PanJoint", None)
    assert parse("cylinder-y:LeftWheel").target == "LeftWheel"
    assert parse("mass:ns:link:10%").target == "ns:link"  # names may contain ':'


@pytest.mark.parametrize(("spec", "column", "message"), [
    ("bogus:X", 0, "unknown fault 'bogus'"),
    ("inertia:TiltLink:1", 17, "expected a percentage such as 1% or -5%"),
    ("inertia:TiltLink", 16, "missing the value"),
    ("inertia:TiltLink:-100%", 17, "non-zero and above -100%"),
    ("mass:PanLink:0%", 13, "non-zero"),
    ("com:Chassis:x", 12, "expected a non-zero distance in metres"),
    ("axis:PanJoint:flop", 14, "expected 'flip'"),
    ("cylinder-y:", 11, "missing the link name"),
])
def test_bad_specs_are_located(spec: str, column: int, message: str) -> None:
    with pytest.raises(InjectError) as info:
        parse(spec)
    assert info.value.column == column
    assert message in info.value.message
    lines = str(info.value).splitlines()
    assert lines[1].strip() == spec and lines[2].index("^") - 4 == column


def test_unknown_names_list_the_valid_ones(written: Written, tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    with pytest.raises(InjectError) as info:
        inject(out / "x.sdf", "axis:Pan:flip", written.renames["sdf"])
    # source names, also where the SDF renamed the joint (LeftWheel → LeftWheel_joint)
    valid = "LeftWheel, PanJoint, RightWheel, TiltJoint"
    assert f"x.sdf has no joint 'Pan'; its joints: {valid}" in str(info.value)
    assert info.value.column == len("axis:")
    with pytest.raises(InjectError, match="no link 'Tilt'; its links: Chassis, LeftWheel, PanLink"):
        inject(out / "x.xml", "mass:Tilt:5%", written.renames["mjcf"])
    with pytest.raises(InjectError, match="'world_joint' is a fixed joint: no axis to flip"):
        inject(out / "x.sdf", "axis:world_joint:flip", written.renames["sdf"])
    with pytest.raises(ValueError, match="MJCF, URDF or SDF"):
        inject(out / "meshes" / "vmega_wheel.stl", "mass:Chassis:5%")
    assert (out / "x.sdf").read_bytes() == (written.folder / "x.sdf").read_bytes()  # nothing written


# ---- each fault fails the right layer ---------------------------------------------------------------

LAYER_FAULTS = [
    # spec, the failing checks (layer, quantity, source link/joint) that must appear
    ("inertia:TiltLink:1%", {(1, "inertia", "TiltLink")}),
    ("mass:PanLink:10%", {(1, "mass", "PanLink")}),
    ("com:PanLink:0.01", {(1, "com", "PanLink")}),
    ("axis:PanJoint:flip", {(1, "axis", "PanJoint")}),
    ("axis:TiltJoint:flip", {(1, "axis", "TiltJoint")}),
]


def _layer_checks(w: Written, out: Path, fmt_name: str, label: str) -> list[Any]:
    from modelkit.verify.engines.pinocchio import load as load_pinocchio
    from modelkit.verify.engines.reference import SourceModel, source_static
    from modelkit.verify.layers import common, dynamics, kinematics, static

    model = _engine(fmt_name, out / FORMATS[fmt_name])
    eng = common.Loaded(label, model, w.renames[fmt_name])
    source = SourceModel(w.robot)
    pin = load_pinocchio(w.robot, {}, root="Chassis")
    checks = list(static.layer1(source_static(w.robot), eng))
    checks += kinematics.layer2(source, eng, kinematics.configurations(w.robot, 20, 0))
    checks += dynamics.layer3a(pin, eng, dynamics.states(w.robot, pin.dof_names(), 10, 0))
    return checks


ENGINES = [("mjcf", "mujoco"), ("sdf", "drake"), ("urdf", "drake-urdf")]


@pytest.mark.parametrize(("fmt_name", "label"), ENGINES)
def test_unperturbed_files_pass_every_layer(written: Written, fmt_name: str, label: str) -> None:
    checks = _layer_checks(written, written.folder, fmt_name, label)
    assert [c for c in checks if not c.passed] == []


@pytest.mark.parametrize(("fmt_name", "label"), ENGINES)
@pytest.mark.parametrize(("spec", "expected"), LAYER_FAULTS)
def test_each_fault_fails_the_right_layer(written: Written, tmp_path: Path, fmt_name: str, label: str,
                                          spec: str, expected: set[tuple[int, str, str]]) -> None:
    out = _copy(written, tmp_path)
    inject(out / FORMATS[fmt_name], spec, written.renames[fmt_name])
    failed = [c for c in _layer_checks(written, out, fmt_name, label) if not c.passed]
    found = {(c.layer, c.quantity, c.where) for c in failed}
    assert expected <= found, failed
    layer1 = [c for c in failed if c.layer == 1]
    assert {(c.quantity, c.where) for c in layer1} == {(q, w) for _, q, w in expected}  # nothing else
    for c in layer1:
        assert c.engine == label and c.error > c.tolerance and c.detail
    if spec.startswith("axis:"):  # a flipped axis moves the links at q != 0: layer 2 fails too
        assert {c.quantity for c in failed if c.layer == 2} >= {"pose-rotation"}
    if spec.startswith(("inertia:", "com:")):  # and the dynamics (mass matrix)
        assert ("mass-matrix" in {c.quantity for c in failed if c.layer == 3}), failed
    else:
        # With the base welded, PanLink's mass is dynamically invisible (its COM lies on the pan axis,
        # no joint above it), and a flipped axis only changes signs of the pan/tilt coupling, which
        # is zero here: only layers 1 and 2 can catch these. Layer 3 must not claim otherwise.
        assert not [c for c in failed if c.layer == 3], failed


GEOMETRY_FAULTS = [("cylinder-y:LeftWheel", "shape-pose", "LeftWheel"),
                   ("wheel-radius:RightWheel:5%", "shape-size", "RightWheel")]


@pytest.mark.parametrize(("spec", "quantity", "link"), GEOMETRY_FAULTS)
def test_geometry_faults_fail_layer1_shapes_only(written: Written, tmp_path: Path, spec: str, quantity: str,
                                                 link: str) -> None:
    """Collision geometry is a layer-1 fact (``StaticFacts.shapes``, ``modelkit.verify.layers.shapes``):
    a turned or resized wheel fails exactly one shape check, naming the link; it changes no mass
    property, so layers 2 and 3 stay green. (PyBullet: ``tests/test_verify_shapes.py``.)"""
    out = _copy(written, tmp_path)
    inject(out / "x.xml", spec, written.renames["mjcf"])
    failed = [c for c in _layer_checks(written, out, "mjcf", "mujoco") if not c.passed]
    assert [(c.layer, c.quantity, c.where) for c in failed] == [(1, quantity, link)], failed
    assert failed[0].error > failed[0].tolerance and failed[0].detail


@pytest.mark.parametrize("spec", [spec for spec, _, _ in GEOMETRY_FAULTS])
def test_geometry_faults_are_invisible_to_drake(written: Written, tmp_path: Path, spec: str) -> None:
    """Drake's adapter registers no geometry (no SceneGraph), so it reports no shapes and the
    verify run says so in a Skip; these faults are caught by MuJoCo and PyBullet, not by Drake.
    This test pins that gap down; it will fail, as it should, once Drake reports shapes."""
    out = _copy(written, tmp_path)
    inject(out / "x.sdf", spec, written.renames["sdf"])
    assert [c for c in _layer_checks(written, out, "sdf", "drake") if not c.passed] == []
    assert _engine("sdf", out / "x.sdf").static().shapes == {}


@pytest.mark.parametrize("fmt_name", list(FORMATS))
def test_swap_fault_exchanges_two_joints_and_moves_the_wheels(written: Written, fmt_name: str,
                                                               tmp_path: Path) -> None:
    out = _copy(written, tmp_path)
    path = out / FORMATS[fmt_name]
    done = inject(path, "swap:LeftWheel:RightWheel", written.renames[fmt_name])
    assert done.changes and all("→" in c for c in done.changes)
    if fmt_name == "sdf":
        return  # no engine of this test reads SDF without Drake; the edit itself is checked above
    original = _engine(fmt_name, written.folder / FORMATS[fmt_name])
    perturbed = _engine(fmt_name, path)
    a, b = original.static(), perturbed.static()
    # same joint names, but the joint called LeftWheel now moves the right wheel's link
    assert set(a.joints) == set(b.joints)
    left = written.renames[fmt_name]["joint"].get("LeftWheel", "LeftWheel")
    right = written.renames[fmt_name]["joint"].get("RightWheel", "RightWheel")
    assert b.joints[left].child == a.joints[right].child
    assert b.joints[right].child == a.joints[left].child


def test_swap_fault_grammar() -> None:
    fault = parse("swap:LeftWheel:RightWheel")
    assert (fault.kind, fault.target, fault.other) == ("swap", "LeftWheel", "RightWheel")
    with pytest.raises(InjectError, match="second, different joint"):
        parse("swap:LeftWheel:LeftWheel")


def test_swapped_wheels_fail_layer_4_naming_the_quantity(tmp_path: Path) -> None:
    """A converter that mixes up the left and right wheel: layer 2 sees the wheels' poses swap, and the
    driven robot turns the wrong way (layer 4: the heading against the no-slip reference)."""
    from modelkit.verify.api import verify

    report = verify(PANTILT, tmp_path, ("mujoco", "pybullet"), inject=["swap:LeftWheel:RightWheel"],
                    configurations=5, replay=False)
    failed = {(c.layer, c.engine, c.quantity, c.where) for c in report.failed}
    assert (2, "mujoco", "pose-rotation", "LeftWheel") in failed
    assert {(4, e, "noslip-yaw", "spin") for e in ("mujoco", "pybullet")} <= failed
    assert any("swap:LeftWheel:RightWheel" in line and "layer 4" in line for line in report.injected)


def test_a_given_file_is_never_edited_the_fault_goes_into_a_copy(tmp_path: Path) -> None:
    """``verify SRC --urdf F --mjcf G --inject ...`` edited F and G in place (the user's files): now the
    faults go into copies in ``OUT/injected``, whose relative references (meshes) point at the
    originals' folder, and the engines still read and fail the injected value."""
    from modelkit.verify.api import verify

    source = TUTORIAL / "mobile_robot.body"
    given = tmp_path / "given"
    for name in ("r.urdf", "r.xml"):
        write(modelkit.load(source), given / name)
    before = {p: p.read_bytes() for p in given.rglob("*") if p.is_file()}
    assert any(p.suffix == ".stl" for p in before)  # the copies must find these meshes
    out = tmp_path / "out"
    report = verify(source, out, engines=("mujoco", "pybullet"), urdf=given / "r.urdf", mjcf=given / "r.xml",
                    inject=["mass:Chassis:50%"], replay=False, driven=False)
    assert {p: p.read_bytes() for p in given.rglob("*") if p.is_file()} == before
    assert sorted(p.name for p in (out / "injected").iterdir()) == ["r.urdf", "r.xml"]
    assert "/meshes/" in (out / "injected" / "r.urdf").read_text()
    assert not report.errors, report.errors
    failed = {(c.engine, c.quantity, c.where) for c in report.checks if not c.passed}
    assert {("mujoco", "mass", "Chassis"), ("pybullet", "mass", "Chassis")} <= failed
    assert any("is left as it is" in line for line in report.injected)
