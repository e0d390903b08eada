"""The Choreonoid `.body` writer: every model converts, validates and reads back as the same robot.

Our `.body` reader is the reference here (it follows Choreonoid's documented behaviour,
body-format.md). One pass over `samples/` and the shared corpus converts every readable model once;
the tests below check that pass from several sides.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.api import load, validate
from modelkit.cli import main
from modelkit.convert.api import CONVERTIBLE_ERRORS, output_stem, write
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.notes import ConversionNote, NoteSink
from modelkit.diagnostics import Diagnostic
from modelkit.formats.body.writer import body_renames
from modelkit.formats.mjcf.site_frames import sites_as_links
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    Mesh,
    Robot,
)
from modelkit.spatial import Pose, axis_angle, rot_x
from tests.conftest import CORPUS, SAMPLES

SUFFIXES = (".body", ".urdf", ".xacro", ".sdf", ".world", ".xml")
# Losses the writer reports: a joint type Choreonoid lacks inside a body (MK813).
APPROXIMATED_JOINTS = (JointType.PLANAR, JointType.BALL)


def model_files() -> list[Path]:
    files: list[Path] = []
    for root in (SAMPLES, CORPUS):
        if root.is_dir():
            files += sorted(p for p in root.rglob("*") if p.suffix in SUFFIXES and p.is_file())
    return files


@dataclass
class Converted:
    source: Path
    robot: Robot
    output: Path
    notes: list[ConversionNote]
    source_diagnostics: list[Diagnostic]
    readback: Robot | None = None
    errors: list[Diagnostic] = field(default_factory=list)
    traceback: str | None = None


@pytest.fixture(scope="module")
def converted(tmp_path_factory: pytest.TempPathFactory) -> list[Converted]:
    """Every robot of every readable model file, written as `.body` and read back."""
    import traceback

    out = tmp_path_factory.mktemp("body_out")
    results: list[Converted] = []
    for n, path in enumerate(model_files()):
        checked = validate(path)
        if any(d.code not in CONVERTIBLE_ERRORS for d in checked.errors):
            continue  # the reader reports errors (missing meshes are convertible)
        for i, robot in enumerate(r for r in checked.robots if r.root is not None):
            target = out / f"{n:03d}_{i}_{output_stem(path)}" / "model.body"
            item = Converted(path, robot, target, [], checked.diagnostics)
            try:
                item.notes = write(robot, target, "body")
            except Exception:  # the test reports it
                item.traceback = traceback.format_exc()
                results.append(item)
                continue
            back = validate(target)
            item.readback, item.errors = back.robot, back.errors
            results.append(item)
    if not results:
        pytest.skip("no model files found")
    return results


def _inherited(item: Converted, d: Diagnostic) -> bool:
    """A finding the source already has (its code is among the source's findings, any severity),
    or a massless moving link the source's reader invented (MJCF multi-joint bodies): the writer
    writes the model it is given, and these are the model's own problems."""
    if d.code in {s.code for s in item.source_diagnostics}:
        return True
    synthesised = {lk.name for lk in item.robot.links if lk.synthesised}
    return d.code == "MK313" and any(f'"{name}"' in d.message for name in synthesised)


def test_every_model_converts_and_validates(converted: list[Converted]) -> None:
    crashed = [f"{c.source}:\n{c.traceback}" for c in converted if c.traceback]
    assert not crashed, "\n".join(crashed)
    unread = [str(c.source) for c in converted if c.readback is None]
    assert not unread
    new_errors = [
        f"{c.source} ({c.robot.name}): {d.code} {d.message}"
        for c in converted
        for d in c.errors
        if not _inherited(c, d)
    ]
    assert not new_errors, "\n".join(new_errors)
    clean = sum(1 for c in converted if not c.errors)
    print(f"\n.body writer: {len(converted)} robots converted, {clean} validate without any error")
    assert len(converted) > 150  # the corpus is there and was read


def _site_links(robot: Robot) -> set[str]:
    """The links an MJCF source's sites that name frames become (MK873), judged from the source model."""
    made = copy.deepcopy(robot)
    sites_as_links(made, NoteSink())
    return {lk.name for lk in made.links} - {lk.name for lk in robot.links}


def _expected_loss(robot: Robot, d: Difference) -> bool:
    if d.quantity == "link-set" and d.detail == "link only in the converted model":
        return d.where in _site_links(robot)  # a gain: the source's frame sites as links (MK873)
    if d.quantity == "mass" and d.detail == "0.0 became 1e-06":
        # a moving link with nothing of mass at or below it in the source: Choreonoid cannot simulate its
        # joint, so the writer gives it 1e-6 kg (MK816); judged from the source model
        from modelkit.checks.masses import lumped_masses

        joint = next((j for j in robot.joints if j.child == d.where), None)
        return joint is not None and joint.type.moves and lumped_masses(robot, every_joint=True).get(
            d.where, 1.0) <= 0.0
    if d.quantity != "joint-type":
        return False
    joint = next((j for j in robot.joints if j.name == d.where), None)
    return joint is not None and joint.type in APPROXIMATED_JOINTS


def test_round_trip_keeps_the_robot(converted: list[Converted]) -> None:
    failures = []
    exact = 0
    for c in converted:
        assert c.readback is not None
        diffs = compare_robots(c.robot, c.readback, body_renames(c.robot), tol=1e-9,
                               check_velocity_effort=True)
        unexpected = [d for d in diffs if not _expected_loss(c.robot, d)]
        if unexpected:
            failures.append(f"{c.source} ({c.robot.name}): " + "; ".join(str(d) for d in unexpected[:3]))
        if not diffs:
            exact += 1
    print(f"\n.body writer: {exact}/{len(converted)} round trips identical at 1e-9")
    assert not failures, "\n".join(failures)


def _close(a: object, b: object, tol: float = 1e-9) -> bool:
    try:
        x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    except (TypeError, ValueError):
        return a == b
    return x.shape == y.shape and bool(np.allclose(x, y, atol=tol, rtol=tol))


def _same_pose(a: Pose, b: Pose) -> bool:
    return _close(a.rotation, b.rotation) and _close(a.translation, b.translation)


def _same_geometry(a: Geom, b: Geom) -> bool:
    """Same kind and dimensions; generated triangles (Extrusion ...) vertex for vertex."""
    ga, gb = a.geometry, b.geometry
    if type(ga) is not type(gb):
        return False
    if isinstance(ga, Mesh) and isinstance(gb, Mesh):
        if ga.data is not None or gb.data is not None:
            return (ga.data is not None and gb.data is not None and _close(ga.data.vertices, gb.data.vertices)
                    and np.array_equal(ga.data.faces, gb.data.faces))
        return _close(ga.scale, gb.scale)
    return all(_close(getattr(ga, k), getattr(gb, k)) for k in vars(ga))


def _file_colours(g: Geom) -> list[tuple[float, ...]] | None:
    """The colours a visual's COLLADA or glTF file gives its faces (independently of the writer: the
    mesh loader's palette, the faces' order), or None when it gives none (or the visual has its own)."""
    from modelkit.geometry.meshfiles import MeshLoadError, load_mesh

    mesh = g.geometry
    if g.material is not None or not isinstance(mesh, Mesh) or mesh.path is None:
        return None
    if Path(mesh.path).suffix.lower() not in (".dae", ".glb", ".gltf"):
        return None
    try:
        loaded = load_mesh(Path(mesh.path), mesh.fragment)
    except MeshLoadError:
        return None
    if loaded.face_colours is None:
        return None
    used = sorted(set(loaded.face_colours.tolist()))
    return [tuple(round(float(x), 6) for x in (loaded.palette[k] or ())) for k in used]


def _same_geoms(src: list[Geom], back: list[Geom], visuals: bool = False) -> bool:
    """Each source shape is one shape read back; a visual whose file gives colours (written as a
    shape per colour, docs/convert.md) is as many shapes at its pose, in exactly those colours."""
    left = list(back)
    for g in src:
        colours = _file_colours(g) if visuals else None
        if colours is not None:
            for colour in colours:
                part = next((b for b in left if isinstance(b.geometry, Mesh) and _same_pose(b.pose, g.pose)
                             and _colour_of(b) == colour), None)
                if part is None:
                    return False
                left.remove(part)
            continue
        hit = next((b for b in left if _same_geometry(g, b) and _same_pose(b.pose, g.pose)
                    and _same_material(g, b)), None)
        if hit is None:
            return False
        left.remove(hit)
    return not left


def _colour_of(g: Geom) -> tuple[float, ...]:
    """A part's RGBA as the reader gives it back (rounded as the writer's decimals), () without one."""
    m = g.material
    if m is None or m.diffuse is None:
        return ()
    return tuple(round(float(x), 6) for x in (*m.diffuse, 1.0 - m.transparency))


def _same_material(a: Geom, b: Geom) -> bool:
    ma, mb = a.material, b.material
    if ma is None or mb is None:
        return ma is mb
    keys = ("diffuse", "specular", "emissive", "ambient", "specular_exponent", "transparency")
    return all(
        _close(getattr(ma, k), getattr(mb, k)) if getattr(ma, k) is not None else getattr(mb, k) is None
        for k in keys
    )


def test_body_round_trip_keeps_devices_materials_and_tracks(converted: list[Converted]) -> None:
    bodies = [c for c in converted if c.source.suffix == ".body"]
    assert len(bodies) >= 20
    tracks = devices = 0
    for c in bodies:
        assert c.readback is not None
        # geometry is compared unless the source itself lacks a mesh file (the reader's finding, not the
        # writer's note: the code under test does not excuse its own differences)
        missing_mesh = any(d.code == "MK500" for d in c.source_diagnostics)
        for link in c.robot.links:
            other = c.readback.link(link.name)
            assert other is not None
            assert other.contact_material == link.contact_material, (c.source, link.name)
            assert [(d.kind, d.name, d.canonical) for d in link.devices] == [
                (d.kind, d.name, d.canonical) for d in other.devices
            ], (c.source, link.name)
            for d, e in zip(link.devices, other.devices, strict=True):
                devices += 1
                assert _same_pose(d.pose, e.pose), (c.source, d.name)
                assert d.canonical_params.keys() == e.canonical_params.keys()
                for key, value in d.canonical_params.items():
                    assert _close(value, e.canonical_params[key]), (c.source, d.name, key)
            if not missing_mesh:
                same_visuals = _same_geoms(link.visuals, other.visuals, visuals=True)
                assert same_visuals, (c.source, link.name, "visuals")
                assert _same_geoms(link.collisions, other.collisions), (c.source, link.name, "collisions")
        for joint in c.robot.joints:
            if joint.type is JointType.PSEUDO_CONTINUOUS_TRACK:
                tracks += 1
                back = next(j for j in c.readback.joints if j.child == joint.child)
                assert back.type is JointType.PSEUDO_CONTINUOUS_TRACK
                assert _close(back.axis, joint.axis)
    assert tracks >= 2 and devices >= 10
    extrusions = [g for c in bodies for lk in c.robot.links for g in lk.visuals
                  if isinstance(g.geometry, Mesh) and g.geometry.generator == "Extrusion"]
    assert extrusions  # the track belts: checked vertex for vertex above


def _files(folder: Path) -> dict[Path, bytes]:
    return {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_two_runs_are_byte_identical(converted: list[Converted], tmp_path: Path) -> None:
    picked = {c.source.suffix: c for c in converted if c.traceback is None}
    with_devices = [c for c in converted
                    if c.source.suffix == ".body" and any(lk.devices for lk in c.robot.links)]
    picked.update({str(c.source): c for c in with_devices})
    assert len(picked) >= 5
    for i, c in enumerate(picked.values()):
        again = tmp_path / f"again_{i}" / "model.body"
        write(c.robot, again, "body")
        assert _files(c.output.parent) == _files(again.parent), c.source


def test_written_body_is_a_fixed_point(converted: list[Converted], tmp_path: Path) -> None:
    """Writing what was read back from a written `.body` gives the same text again."""
    checked = 0
    for i, c in enumerate(c for c in converted if c.source.suffix == ".body"):
        assert c.readback is not None
        again = tmp_path / f"again_{i}" / "model.body"
        write(c.readback, again, "body")
        assert again.read_text() == c.output.read_text(), c.source
        checked += 1
    assert checked >= 20


# ---- unit tests ---------------------------------------------------------------------------------


def _robot(*geoms: Geom, root_joint: JointType | None = JointType.FLOATING) -> Robot:
    base = Link("base", Inertial(2.0, np.array([0.0, 0.0, 0.1]), np.diag([0.1, 0.2, 0.3])), list(geoms), [])
    return Robot("unit", [base], [], root="base", root_joint=root_joint, source_format="test")


def _write_and_read(robot: Robot, path: Path) -> tuple[str, Robot, list[ConversionNote]]:
    notes = write(robot, path, "body")
    back = validate(path)
    assert not back.errors, [str(d) for d in back.errors]
    assert back.robot is not None
    return path.read_text(), back.robot, notes


@pytest.mark.parametrize("shape", [Cylinder(0.1, 0.4), Capsule(0.05, 0.2), Cone(0.1, 0.3)])
def test_z_axis_primitives_become_y_axis_shapes_and_come_back(shape: Cylinder, tmp_path: Path) -> None:
    at_identity = Geom(shape, Pose())
    tilted = Geom(shape, Pose(axis_angle([1.0, 2.0, 3.0], 0.7), np.array([0.1, -0.2, 0.3])))
    text, back, _ = _write_and_read(_robot(at_identity, tilted), tmp_path / "m.body")
    # The model's Z primitive at identity is Choreonoid's Y primitive turned +90° about X.
    assert "rotation: [ 1, 0, 0, 90 ]" in text
    kind = type(shape).__name__
    assert f"type: {kind}" in text
    link = back.link("base")
    assert link is not None and len(link.visuals) == 2
    for src, got in zip((at_identity, tilted), link.visuals, strict=True):
        assert type(got.geometry) is type(shape)
        assert isinstance(got.geometry, (Cylinder, Capsule, Cone))
        assert math.isclose(got.geometry.radius, shape.radius)
        assert math.isclose(got.geometry.length, shape.length)
        assert np.allclose(got.pose.rotation, src.pose.rotation, atol=1e-12)
        assert np.allclose(got.pose.translation, src.pose.translation, atol=1e-12)
    # A cone's apex stays on +Z: the rotation is Rx(+90°), the inverse of the reader's Rx(−90°).
    apex_in_file = rot_x(math.pi / 2) @ np.array([0.0, 1.0, 0.0])
    assert np.allclose(apex_in_file, [0.0, 0.0, 1.0])


def test_ellipsoid_is_a_scaled_sphere(tmp_path: Path) -> None:
    text, back, _ = _write_and_read(_robot(Geom(Ellipsoid(np.array([0.1, 0.2, 0.3])))), tmp_path / "m.body")
    assert "scale: [ 0.1, 0.2, 0.3 ]" in text and "type: Sphere" in text
    link = back.link("base")
    assert link is not None
    got = link.visuals[0].geometry
    assert isinstance(got, Ellipsoid) and np.allclose(got.radii, [0.1, 0.2, 0.3])


def _arm(limits: JointLimits) -> Robot:
    robot = _robot(Geom(Box(np.array([0.1, 0.1, 0.1]))))
    arm = Link("arm", Inertial(1.0, np.zeros(3), np.eye(3) * 0.01))
    robot.links.append(arm)
    origin = Pose(rot_x(0.3), np.array([0.0, 0.0, 0.5]))
    axis = np.array([0.0, 1.0, 0.0])
    robot.joints.append(Joint("elbow", JointType.REVOLUTE, "base", "arm", origin, axis, limits))
    return robot


def test_unlimited_revolute(tmp_path: Path) -> None:
    text, back, _ = _write_and_read(_arm(JointLimits()), tmp_path / "m.body")
    assert "joint_range: [ unlimited, unlimited ]" in text
    assert "max_joint_velocity" not in text and "max_joint_effort" not in text
    joint = back.joints[0]
    assert joint.type is JointType.REVOLUTE and joint.name == "elbow"
    assert joint.limits.lower == -math.inf and joint.limits.upper == math.inf


def test_limited_revolute_in_degrees(tmp_path: Path) -> None:
    limits = JointLimits(lower=-math.pi / 2, upper=math.inf, velocity=math.pi, effort=20.0)
    text, back, _ = _write_and_read(_arm(limits), tmp_path / "m.body")
    assert "joint_range: [ -90, unlimited ]" in text and "max_joint_velocity: 180" in text
    got = back.joints[0].limits
    assert math.isclose(got.lower, -math.pi / 2, rel_tol=1e-15) and got.upper == math.inf
    assert math.isclose(got.velocity, math.pi, rel_tol=1e-15) and got.effort == 20.0


def test_fixed_root_and_open_root(tmp_path: Path) -> None:
    pose = Pose(axis_angle([0.0, 0.0, 1.0], math.pi / 3), np.array([1.0, 2.0, 0.5]))
    robot = _robot(root_joint=JointType.FIXED)
    robot.root_pose = pose
    text, back, notes = _write_and_read(robot, tmp_path / "fixed" / "m.body")
    assert "joint_type: fixed" in text and "rotation: [ 0, 0, 1, 60 ]" in text
    assert back.root_joint is JointType.FIXED
    assert np.allclose(back.root_pose.rotation, pose.rotation) and np.allclose(back.root_pose.translation,
                                                                                pose.translation)
    assert not [n for n in notes if n.code == "MK814"]
    # A root the source leaves open is settled by --base auto (MK830): this one has no shape to judge
    # by, so it floats (URDF's convention); a root body without mass is welded instead.
    _, back, notes = _write_and_read(_robot(root_joint=None), tmp_path / "open" / "m.body")
    assert back.root_joint is JointType.FLOATING and [n.code for n in notes] == ["MK830"]
    massless = _robot(root_joint=None)
    massless.links[0].inertial = None
    text, back, notes = _write_and_read(massless, tmp_path / "massless" / "m.body")
    assert back.root_joint is JointType.FIXED and "mass: 0" in text
    assert back.links[0].inertial is not None and back.links[0].inertial.mass == 0.0


def test_mesh_reference_is_relative_and_copied(tmp_path: Path) -> None:
    import trimesh

    source = tmp_path / "src" / "parts" / "part.stl"
    source.parent.mkdir(parents=True)
    source.write_bytes(trimesh.exchange.stl.export_stl(trimesh.creation.box((0.1, 0.2, 0.3))))
    mesh = Mesh(uri="parts/part.stl", path=str(source), scale=np.array([2.0, 2.0, 2.0]))
    out = tmp_path / "out" / "robot.body"
    text, back, _ = _write_and_read(_robot(Geom(mesh, Pose(rot_x(0.5), np.array([0, 0, 1.0])))), out)
    assert "uri: meshes/part.stl" in text and "scale: [ 2, 2, 2 ]" in text
    assert str(tmp_path) not in text  # no absolute path
    copied = out.parent / "meshes" / "part.stl"
    assert copied.read_bytes() == source.read_bytes()
    link = back.link("base")
    assert link is not None
    got = link.visuals[0].geometry
    assert isinstance(got, Mesh) and Path(got.path or "").resolve() == copied.resolve()
    assert np.allclose(got.scale, 2.0)


def test_texture_is_copied_beside_the_model(tmp_path: Path) -> None:
    from modelkit.model import VisualMaterial

    image = tmp_path / "src" / "wood.png"
    image.parent.mkdir()
    image.write_bytes(b"\x89PNG\r\n\x1a\n not really an image")
    material = VisualMaterial(diffuse=np.array([0.5, 0.4, 0.3]), transparency=0.25, texture=str(image))
    out = tmp_path / "out" / "m.body"
    write(_robot(Geom(Box(np.array([1.0, 1.0, 1.0])), material=material)), out, "body")
    text = out.read_text()
    assert "uri: meshes/wood.png" in text and "transparency: 0.25" in text
    assert (out.parent / "meshes" / "wood.png").read_bytes() == image.read_bytes()
    back = validate(out).robot
    assert back is not None
    got = back.links[0].visuals[0].material
    assert got is not None and got.texture is not None and Path(got.texture).name == "wood.png"
    assert got.transparency == 0.25 and got.diffuse is not None and np.allclose(got.diffuse, [0.5, 0.4, 0.3])


def test_mimic_and_ball_joints_are_noted(tmp_path: Path) -> None:
    from modelkit.model import Mimic

    robot = _arm(JointLimits(-1.0, 1.0))
    robot.joints[0].mimic = Mimic("other", 2.0)
    robot.links.append(Link("ball_child", Inertial(1.0, np.zeros(3), np.eye(3) * 0.01)))
    robot.joints.append(Joint("ball", JointType.BALL, "arm", "ball_child"))
    notes = write(robot, tmp_path / "m.body", "body")
    assert {"MK812", "MK813"} <= {n.code for n in notes}
    back = validate(tmp_path / "m.body").robot
    assert back is not None and back.joints[1].type is JointType.FIXED


def test_shapes_choreonoid_cannot_generate_are_left_out(tmp_path: Path) -> None:
    """A URDF zero-radius sphere (check_urdf and PyBullet load it) would make the whole .body refused
    by Choreonoid (MK400): the writer leaves that shape out with an MK880 note and keeps the rest."""
    source = tmp_path / "s.urdf"
    source.write_text(
        '<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" '
        'ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><sphere radius="0"/></geometry></collision>'
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
    )
    robot = validate(source).robot
    assert robot is not None
    notes = write(robot, tmp_path / "s.body", "body")
    assert [n.code for n in notes if n.code == "MK880"] == ["MK880"]
    back = validate(tmp_path / "s.body")
    assert back.errors == [] and back.robot is not None
    (link,) = back.robot.links
    assert [type(g.geometry).__name__ for g in link.collisions] == ["Box"]


FINGER = """<robot name="hand">
  <link name="palm"><inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0"
    iyz="0"/></inertial></link>
  <link name="finger1"/>
  <link name="finger2"/>
  <joint name="j1" type="revolute"><parent link="palm"/><child link="finger1"/><origin xyz="0 0 0.05"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="finger1"/><child link="finger2"/><origin xyz="0 0 0.03"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="1.5" effort="1" velocity="1"/></joint>
</robot>
"""


def test_massless_moving_chain_gets_a_tiny_mass(tmp_path: Path) -> None:
    """A URDF finger chain without inertials (urdfdom loads it; example-robot-data's Romeo has 24 such
    links): Choreonoid cannot simulate a joint that moves nothing with mass, and validate says so
    (MK313, an error for .body). The writer gives each such moving link 1e-6 kg and 1e-9 kg·m² (MK816),
    so the written file validates; the palm, which has mass, is untouched."""
    source = tmp_path / "hand.urdf"
    source.write_text(FINGER)
    assert [d.code for d in validate(source).diagnostics if d.code == "MK313"] == ["MK313", "MK313"]
    robot = validate(source).robot
    assert robot is not None
    notes = write(robot, tmp_path / "out" / "hand.body", force=True)
    tiny = [n for n in notes if n.code == "MK816"]
    assert sorted(n.message.split()[1] for n in tiny) == ["finger1", "finger2"]
    back = validate(tmp_path / "out" / "hand.body")
    assert back.errors == [] and back.robot is not None
    masses = {lk.name: lk.inertial.mass if lk.inertial else None for lk in back.robot.links}
    assert masses == {"palm": 0.5, "finger1": 1e-6, "finger2": 1e-6}


DUSTY_URDF = """<robot name="dusty">
  <link name="base">
    <inertial><mass value="2"/><origin xyz="0.1 3.08087e-14 0"/>
      <inertia ixx="0.0955703125" ixy="0" ixz="0" iyy="0.0955703125" iyz="-1.1552820390394e-17"
               izz="0.001234375"/>
    </inertial>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <visual><origin xyz="0 -5.54343e-12 4.45647e-12" rpy="1.57080000000002 1.53105e-11 0"/>
      <geometry><box size="0.1 0.1 0.1"/></geometry></visual>
  </link>
  <joint name="shoulder" type="continuous">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 2.28232e-12 0.2" rpy="0 0 1.84768450970784e-13"/><axis xyz="6.12323399573677e-17 0 1"/>
  </joint>
</robot>
"""


def test_clean_numbers(tmp_path: Path) -> None:
    """Issue 17 §5 for .body as for the other targets: CAD dust below 1e-10 of the model's size in a
    position, an axis or a rotation and below 1e-12 of a tensor's largest entry is written as 0 (or the
    key left out), and the file reads back as the source to 1e-9."""
    source = tmp_path / "dusty.urdf"
    source.write_text(DUSTY_URDF)
    out = tmp_path / "out" / "dusty.body"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert "e-1" not in text and "e-2" not in text, text
    assert "inertia: [ 0.0955703125, 0, 0, 0, 0.0955703125, 0, 0, 0, 0.001234375 ]" in text
    assert "joint_axis: [ 0, 0, 1 ]" in text
    assert "translation: [ 0, 0, 0.2 ]" in text
    want, got = load(source), load(out)
    for name, pose in want.world_poses().items():
        other = got.world_poses()[name]
        assert np.allclose(pose.translation, other.translation, atol=1e-9)
        assert np.allclose(pose.rotation, other.rotation, atol=1e-9)
