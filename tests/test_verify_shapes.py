"""Layer 1's collision-shape checks (``modelkit.verify.layers.shapes``), against the real engines.

MuJoCo reads the written MJCF, PyBullet (in its child process) the written URDF. Each engine's
shapes are read back in the link frame and compared with the source model's collision shapes:
unperturbed conversions pass at round-off; the injected geometry faults (``cylinder-y``,
``wheel-radius``) fail ``shape-pose`` / ``shape-size`` naming the link. The frame conventions the
adapters undo (MuJoCo moves a mesh geom's frame to the mesh's centroid; PyBullet gives shapes in
the link's inertial frame, and a cylinder's dimensions as (length, radius)) are pinned on a
hand-written model whose every shape is off-axis and turned.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import modelkit
from modelkit.convert import write
from modelkit.convert.options import WriteOptions
from modelkit.model import JointType
from modelkit.spatial import Pose, matrix_from_rpy
from modelkit.verify.engines.mujoco import load as load_mujoco
from modelkit.verify.engines.protocol import ShapeFacts, StaticFacts
from modelkit.verify.engines.reference import source_static
from modelkit.verify.layers import common, shapes, static
from tests.conftest import CORPUS, TUTORIAL

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
CHOREONOID = CORPUS / "choreonoid" / "share" / "model"
Renames = dict[str, dict[str, str]]


def _load(engine: str, path: Path, maps: Renames, root: str) -> Any:
    if engine == "mujoco":
        return load_mujoco(path, maps, root=root)
    pytest.importorskip("pybullet")
    from modelkit.verify.engines.pybullet import load as load_pybullet

    return load_pybullet(path, maps, root=root)


def _layer1(source_file: Path, engine: str, folder: Path, spec: str | None = None) -> list[Any]:
    """``modelkit verify`` of the source with one engine (layer 1 only matters here), optionally with
    an injected fault: the real path, tracks approximated and names mapped as the command does."""
    from modelkit.verify.api import verify

    report = verify(source_file, folder, engines=(engine,), inject=(spec,) if spec else (),
                    configurations=1, samples=1, replay=False, driven=False)
    assert report.errors == []
    return [c for c in report.checks if c.layer == 1]


# ---- the injected geometry faults fail layer 1, naming the link ------------------------------------

@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
@pytest.mark.parametrize(("spec", "quantity"), [("cylinder-y:LeftWheel", "shape-pose"),
                                                ("wheel-radius:LeftWheel:5%", "shape-size")])
def test_geometry_faults_fail_layer1(engine: str, spec: str, quantity: str, tmp_path: Path) -> None:
    checks = _layer1(PANTILT, engine, tmp_path, spec)
    failed = [c for c in checks if not c.passed]
    assert [(c.layer, c.quantity, c.where) for c in failed] == [(1, quantity, "LeftWheel")], failed
    check = failed[0]
    assert check.engine == engine and check.tolerance == 1e-9
    if quantity == "shape-pose":  # the wheel's axle (link y) became the link's z: a quarter turn
        assert check.error == pytest.approx(math.pi / 2, abs=1e-9)
        assert "cylinder" in check.detail and "axis turned by 1.5708 rad" in check.detail
    else:
        assert check.error == pytest.approx(0.05, rel=1e-9)
        assert "cylinder size [0.076, 0.03] read back as [0.0798, 0.03]" in check.detail


# ---- unperturbed conversions pass ------------------------------------------------------------------

ROBOTS = [*(TUTORIAL / name for name in ("mobile_robot.body", "mobile_robot_pantilt.body",
                                          "mobile_robot_primitive.body", "mobile_robot_sensors.body",
                                          "mobile_robot_sensors_ex.body", "mobile_robot_tracks.body",
                                          "mobile_robot_mesh.body")),
          CHOREONOID / "PA10" / "PA10.body", CHOREONOID / "GR001" / "GR001.body"]


@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
@pytest.mark.parametrize("source", ROBOTS, ids=lambda p: p.stem)
def test_unperturbed_conversions_pass_the_shape_checks(engine: str, source: Path, tmp_path: Path) -> None:
    if not source.exists():
        pytest.skip(f"{source} not available")
    checks = {c.quantity: c for c in _layer1(source, engine, tmp_path) if c.quantity.startswith("shape")}
    assert set(checks) == {"shape-set", "shape-size", "shape-pose"}
    assert all(c.passed for c in checks.values()), checks
    assert checks["shape-pose"].error <= 1e-13 and checks["shape-size"].error <= 1e-13
    count = int(checks["shape-set"].detail.split()[0])
    in_source = sum(len(link.collisions) for link in modelkit.validate(source).robots[0].links)
    if source.name == "mobile_robot_mesh.body":  # its chassis mesh file is missing in samples/ (MK805)
        assert count == in_source - 1
    elif source.name == "mobile_robot_tracks.body":  # each track's approximation is compared (MK809)
        assert count > in_source
    else:
        assert count == in_source > 0


def test_a_missing_mesh_is_a_skip_not_a_silent_pass(tmp_path: Path) -> None:
    from modelkit.api import validate

    robot = validate(TUTORIAL / "mobile_robot_mesh.body").robots[0]
    robot.root_joint = JointType.FIXED
    notes = write(robot, tmp_path / "x.xml")
    assert "MK805" in {n.code for n in notes}
    source = source_static(robot)
    assert [s.type for s in source.shapes["Chassis"]] == [shapes.MISSING]
    eng = common.Loaded("mujoco", load_mujoco(tmp_path / "x.xml", {}, root="Chassis"))
    (skip,) = shapes.skips(source, eng)
    assert skip.layer == 1 and "file is missing" in skip.reason and "Chassis" in skip.reason


# ---- the engines' frame conventions, on off-axis, turned shapes ------------------------------------

URDF = """<?xml version="1.0"?>
<robot name="t">
  <link name="base">
    <inertial><origin xyz="0.1 0.2 0.3" rpy="0.3 0.2 0.1"/><mass value="2"/>
      <inertia ixx="0.1" ixy="0.01" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial>
    <collision><origin xyz="0.5 0 0" rpy="0.1 0.2 0.3"/>
      <geometry><box size="0.1 0.2 0.3"/></geometry></collision>
    <collision><origin xyz="0 0.5 0" rpy="0.4 0 0"/>
      <geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.2 0.1"/><mass value="1"/>
      <inertia ixx="0.05" ixy="0" ixz="0.002" iyy="0.06" iyz="0" izz="0.07"/></inertial>
    <collision><origin xyz="0 0.1 0" rpy="0.4 0 0"/><geometry><sphere radius="0.07"/></geometry></collision>
    <collision><origin xyz="0.3 0.1 0.05" rpy="0.4 -0.3 0.2"/>
      <geometry><mesh filename="part.stl" scale="2 1 1"/></geometry></collision>
    <collision><origin xyz="-0.1 0 0.2" rpy="0 1.2 0"/>
      <geometry><cylinder radius="0.02" length="0.15"/></geometry></collision>
  </link>
  <link name="empty"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="1 0 0" rpy="0 0 0.5"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="k" type="fixed"><parent link="arm"/><child link="empty"/></joint>
</robot>
"""

Vec = list[float]
EXPECTED: dict[str, list[tuple[str, Vec, Vec, Vec]]] = {  # link: [(type, size, xyz, rpy)]
    "base": [("box", [0.1, 0.2, 0.3], [0.5, 0, 0], [0.1, 0.2, 0.3]),
             ("cylinder", [0.05, 0.4], [0, 0.5, 0], [0.4, 0, 0])],
    "arm": [("sphere", [0.07], [0, 0.1, 0], [0.4, 0, 0]),
            ("mesh", [2, 1, 1], [0.3, 0.1, 0.05], [0.4, -0.3, 0.2]),
            ("cylinder", [0.02, 0.15], [-0.1, 0, 0.2], [0, 1.2, 0])],
    "empty": [],
}


def _expected_facts() -> StaticFacts:
    facts = StaticFacts()
    facts.shapes = {link: [ShapeFacts(kind, np.array(size, dtype=float),
                                      Pose(matrix_from_rpy(*rpy), np.array(xyz, dtype=float)))
                           for kind, size, xyz, rpy in items] for link, items in EXPECTED.items()}
    return facts


def _mjcf_of_urdf(urdf: Path, out: Path) -> Path:
    """The same model as MJCF, through modelkit's own URDF reader and MJCF writer, with every link a body
    as verify's layers 1-3 write it (convert's default makes the shapeless, massless "empty" a site)."""
    robot = modelkit.load(urdf)
    robot.root_joint = JointType.FIXED
    write(robot, out, options=WriteOptions(frame_sites=False))
    return out


@pytest.fixture(scope="module")
def frames(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import trimesh

    folder = tmp_path_factory.mktemp("frames")
    part = trimesh.creation.box([0.1, 0.2, 0.3])
    part.apply_translation([0.5, 0.1, -0.2])  # off its own origin: MuJoCo recentres it
    part.export(folder / "part.stl")
    (folder / "t.urdf").write_text(URDF)
    return folder


@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
def test_engines_report_shapes_in_the_link_frame(frames: Path, engine: str, tmp_path: Path) -> None:
    path = frames / "t.urdf" if engine == "pybullet" else _mjcf_of_urdf(frames / "t.urdf", frames / "t.xml")
    model = _load(engine, path, {}, "base")
    try:
        got = model.static().shapes
    finally:
        model.close()
    assert set(got) == set(EXPECTED)
    checks = shapes.compare(_expected_facts(), StaticFacts(shapes=got), common.Loaded(engine, model))
    by = {c.quantity: c for c in checks}
    assert by["shape-set"].error == 0.0, by["shape-set"].detail
    assert by["shape-size"].error <= 1e-15, by["shape-size"].detail  # sizes are exact
    assert by["shape-pose"].error <= 1e-14, by["shape-pose"].detail  # round-off of the frame algebra


# ---- the comparison itself -------------------------------------------------------------------------

def _one(kind: str, size: list[float], rotation: np.ndarray | None = None,
         xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> StaticFacts:
    pose = Pose(np.eye(3) if rotation is None else rotation, np.array(xyz, dtype=float))
    return StaticFacts(shapes={"L": [ShapeFacts(kind, np.array(size, dtype=float), pose)]})


@pytest.fixture(scope="module")
def real(frames: Path) -> Any:
    """A real engine model to stand behind ``Loaded`` (``compare`` reads its tolerances only; the
    facts compared are the ones each test builds)."""
    return load_mujoco(_mjcf_of_urdf(frames / "t.urdf", frames / "real.xml"), {}, root="base")


def _compare(real: Any, a: StaticFacts, b: StaticFacts, label: str = "mujoco") -> dict[str, Any]:
    return {c.quantity: c for c in shapes.compare(a, b, common.Loaded(label, real))}


def _pose_error(real: Any, kind: str, size: list[float], rotation: np.ndarray) -> float:
    return float(_compare(real, _one(kind, size), _one(kind, size, rotation))["shape-pose"].error)


def test_symmetries_are_not_errors(real: Any) -> None:
    flip = matrix_from_rpy(math.pi, 0.0, 0.0)  # a half turn about x: a cylinder's axis reversed
    turn = matrix_from_rpy(0.0, 0.0, 0.7)  # about a cylinder's own axis
    assert _pose_error(real, "cylinder", [0.1, 0.3], flip) < 1e-15
    assert _pose_error(real, "capsule", [0.1, 0.3], turn) < 1e-15
    assert _pose_error(real, "box", [1, 2, 3], flip) < 1e-15
    assert _pose_error(real, "sphere", [0.1], matrix_from_rpy(0.3, 0.2, 1.0)) == 0.0
    # ... but a box turned a quarter, a mesh turned half, a cylinder tilted are
    quarter, tilt = matrix_from_rpy(0.0, 0.0, math.pi / 2), matrix_from_rpy(1e-6, 0.0, 0.0)
    assert _pose_error(real, "box", [1, 2, 3], quarter) == pytest.approx(math.pi / 2)
    assert _pose_error(real, "mesh", [1, 1, 1], flip) == pytest.approx(math.pi)
    assert _pose_error(real, "cylinder", [0.1, 0.3], tilt) == pytest.approx(1e-6, rel=1e-6)


def test_types_counts_sizes_positions(real: Any) -> None:
    c = _compare(real, _one("box", [1, 2, 3]), _one("cylinder", [1, 2]))
    assert (c["shape-set"].error, c["shape-set"].where) == (2.0, "L")
    assert c["shape-set"].detail == "collision shapes: source 1 box, engine 1 cylinder"
    c = _compare(real, _one("box", [1, 2, 3]), StaticFacts(shapes={"L": []}))
    assert c["shape-set"].error == 1.0 and "engine none" in c["shape-set"].detail
    c = _compare(real, _one("box", [1, 2, 3]), _one("box", [1, 2, 3.003]))
    assert c["shape-size"].error == pytest.approx(0.001) and c["shape-size"].where == "L"
    c = _compare(real, _one("sphere", [0.1]), _one("sphere", [0.1], xyz=(0.0, 2e-9, 0.0)))
    assert c["shape-pose"].error == pytest.approx(2e-9) and not c["shape-pose"].passed


def test_primitives_the_format_lacks_are_expected_as_meshes(real: Any) -> None:
    capsule = _one("capsule", [0.1, 0.3])
    as_mesh = _one("mesh", [1.0, 1.0, 1.0])
    assert _compare(real, capsule, as_mesh, "pybullet")["shape-set"].error == 0.0  # URDF has no capsule
    assert _compare(real, capsule, as_mesh, "mujoco")["shape-set"].error == 2.0  # MJCF has one
    assert _compare(real, _one("cone", [0.1, 0.3]), as_mesh, "mujoco")["shape-set"].error == 0.0


def test_engines_without_shapes_are_skipped_with_a_reason() -> None:
    from modelkit.verify.engines.pinocchio import load as load_pinocchio

    robot = modelkit.load(PANTILT)
    eng = common.Loaded("pinocchio", load_pinocchio(robot, {}, root="Chassis"))
    source = source_static(robot)
    assert eng.model.static().shapes == {}
    assert [c for c in static.layer1(source, eng) if c.quantity.startswith("shape")] == []
    (skip,) = shapes.skips(source, eng)
    assert skip.layer == 1 and skip.engine == "pinocchio" and "reports no collision shapes" in skip.reason
