"""The .body reader against hand-computed values (poses, mass properties, shapes, devices)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from modelkit.api import validate
from modelkit.formats.body.reader import BodyOptions, read_body
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, JointType, Mesh, Robot, Sphere

from .conftest import TUTORIAL, corpus_bodies

DEG = math.pi / 180.0


def load(path: Path, **kw: object) -> Robot:
    result = read_body(path, BodyOptions(**kw))  # type: ignore[arg-type]
    assert result.robot is not None, result.diagnostics
    return result.robot


def write(tmp_path: Path, text: str, name: str = "t.body") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_tutorial_sensor_robot_structure_and_mass() -> None:
    robot = load(TUTORIAL / "mobile_robot_sensors.body")
    assert robot.name == "MobileRobot" and robot.root == "Chassis"
    assert robot.root_joint is JointType.FLOATING
    chassis = robot.link("Chassis")
    assert chassis is not None and chassis.inertial is not None
    assert chassis.inertial.mass == 14.0
    np.testing.assert_allclose(chassis.inertial.com, [-0.08, 0.0, 0.08])
    np.testing.assert_allclose(chassis.inertial.inertia, np.diag([0.1, 0.17, 0.22]))
    assert chassis.contact_material == "Slider"
    joints = {j.name: j for j in robot.joints}
    assert set(joints) == {"LeftWheel", "RightWheel", "PanJoint", "TiltJoint"}
    left = joints["LeftWheel"]
    assert left.type is JointType.REVOLUTE and left.parent == "Chassis" and left.child == "LeftWheel"
    assert left.joint_id == 0 and not left.limits.position_limited
    np.testing.assert_allclose(left.origin.translation, [0.0, 0.145, 0.076])
    np.testing.assert_allclose(left.axis, [0.0, 1.0, 0.0])
    assert joints["TiltJoint"].parent == "PanLink" and joints["TiltJoint"].joint_id == 3
    tilt = robot.link("TiltLink")
    assert tilt is not None and tilt.inertial is not None
    np.testing.assert_allclose(tilt.inertial.com, [0.0, 0.0, 0.0])  # not given: zero
    assert tilt.inertial.mass == 1.0 and not tilt.inertial.defaulted


def test_tutorial_link_world_poses() -> None:
    robot = load(TUTORIAL / "mobile_robot_sensors.body")
    poses = robot.world_poses()
    np.testing.assert_allclose(poses["TiltLink"].translation, [-0.02, 0.0, 0.165 + 0.12])
    # Pan by 90°: TiltLink's origin stays on the pan axis; its x axis turns to world +y.
    turned = robot.world_poses({"PanJoint": math.pi / 2})
    np.testing.assert_allclose(turned["TiltLink"].translation, [-0.02, 0.0, 0.285], atol=1e-12)
    np.testing.assert_allclose(turned["TiltLink"].rotation @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_cylinders_turn_from_y_to_z() -> None:
    robot = load(TUTORIAL / "mobile_robot_sensors.body")
    wheel = robot.link("LeftWheel")
    assert wheel is not None
    (tire,) = wheel.collisions
    assert isinstance(tire.geometry, Cylinder)
    assert (tire.geometry.radius, tire.geometry.length) == (0.076, 0.03)
    # Choreonoid's cylinder axis is link +Y; the model's cylinder axis is its local Z.
    np.testing.assert_allclose(tire.pose.rotation @ [0, 0, 1], [0, 1, 0], atol=1e-12)
    pan = robot.link("PanLink")
    assert pan is not None
    disc = pan.visuals[0]
    # rotation [1,0,0,90] on a Y cylinder = a Z cylinder: identity in the model.
    assert isinstance(disc.geometry, Cylinder)
    np.testing.assert_allclose(disc.pose.rotation, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(disc.pose.translation, [0, 0, 0.01])
    assert disc.material is not None and disc.material.rgba == (0.5, 0.5, 0.5, 1.0)


def test_visual_collision_split_and_shared_alias() -> None:
    robot = load(TUTORIAL / "mobile_robot_sensors.body", check_resources=False)
    chassis = robot.link("Chassis")
    assert chassis is not None
    assert [type(g.geometry) for g in chassis.visuals] == [Mesh]
    assert [type(g.geometry) for g in chassis.collisions] == [Box, Cylinder]
    box = chassis.collisions[0]
    np.testing.assert_allclose(box.pose.translation, [-0.1, 0.0, 0.0975])
    pan = robot.link("PanLink")
    assert pan is not None
    # Shapes outside Visual/Collision are both; the aliased PanFrame appears twice.
    assert len(pan.visuals) == 3 and pan.visuals == pan.collisions
    np.testing.assert_allclose(pan.visuals[1].pose.translation, [0, 0.07, 0.065])
    np.testing.assert_allclose(pan.visuals[2].pose.translation, [0, -0.07, 0.065])
    wheel = robot.link("LeftWheel")
    assert wheel is not None
    mesh = wheel.visuals[0]
    assert isinstance(mesh.geometry, Mesh) and mesh.geometry.path is not None
    assert mesh.geometry.path.endswith("meshes/vmega_wheel.dae")
    np.testing.assert_allclose(mesh.pose.rotation @ [1, 0, 0], [-1, 0, 0], atol=1e-12)


def test_devices_camera_range_sensor_light() -> None:
    robot = load(TUTORIAL / "mobile_robot_sensors_ex.body", check_resources=False)
    tilt = robot.link("TiltLink")
    assert tilt is not None
    devices = {d.name: d for d in tilt.devices}
    lidar = devices["LiDAR"]
    assert lidar.kind == "RangeSensor"
    assert lidar.params["optical_frame"] == "robotics"
    # yaw_range 360, yaw_step 0.4: 360/0.4 + 1 = 901 rays (both ends); pitch 30/2 + 1 = 16.
    np.testing.assert_allclose(lidar.params["max_yaw_angle"], 180 * DEG)
    assert lidar.params["yaw_samples"] == 901
    assert lidar.params["pitch_samples"] == 16
    np.testing.assert_allclose(lidar.params["min_pitch_angle"], -15 * DEG)
    assert lidar.params["scan_rate"] == 20.0
    planar = load(TUTORIAL / "mobile_robot_sensors.body", check_resources=False).link("TiltLink")
    assert planar is not None
    lidar2 = next(d for d in planar.devices if d.name == "LiDAR")
    np.testing.assert_allclose(lidar2.params["max_yaw_angle"], 135 * DEG)
    assert lidar2.params["yaw_samples"] == 271  # 270° / 1° + 1
    assert lidar2.params["pitch_samples"] == 1
    camera = devices["RealSense"]
    assert camera.kind == "Camera" and camera.params["camera_kind"] == "RangeCamera"
    assert (camera.params["width"], camera.params["height"]) == (320, 240)
    np.testing.assert_allclose(camera.params["field_of_view"], 62 * DEG)
    # rotation [[0,1,0,90],[0,0,1,-90]] with the cv optical frame: the camera looks along link +X.
    # The device pose is the canonical robotics sensor frame (+X viewing, +Z image up; model.DeviceKind).
    np.testing.assert_allclose(camera.pose.rotation @ [1, 0, 0], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(camera.pose.rotation @ [0, 0, 1], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(camera.pose.translation, [0.06, 0.0, -0.02])
    light = devices["Light"]
    assert light.kind == "SpotLight"
    np.testing.assert_allclose(light.params["beam_width"], 36 * DEG)
    np.testing.assert_allclose(light.params["direction"], (1.0, 0.0, 0.0))


def test_terrain_primitives_format_1() -> None:
    robot = load(TUTORIAL / "terrain.body")
    assert robot.root_joint is JointType.FIXED
    np.testing.assert_allclose(robot.root_pose.translation, [0, 0, -0.1])
    kinds = {link.name: type(link.visuals[0].geometry) for link in robot.links}
    assert kinds == {
        "Ground": Box,
        "object1": Cylinder,
        "object2": Cylinder,
        "object3": Sphere,
        "object4": Cone,
        "object5": Capsule,
    }
    cone = robot.link("object4")
    assert cone is not None
    # rotation [1,0,0,90] turns Choreonoid's +Y apex to +Z: the model cone (apex +Z) is unrotated.
    np.testing.assert_allclose(cone.visuals[0].pose.rotation, np.eye(3), atol=1e-12)
    capsule = robot.link("object5")
    assert capsule is not None and isinstance(capsule.visuals[0].geometry, Capsule)
    assert capsule.visuals[0].geometry.length == 0.8


def test_rigid_bodies_combine_with_parallel_axis(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
    joint_type: free
    elements:
      - type: RigidBody
        translation: [0.1, 0, 0]
        mass: 1.0
        inertia: [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01]
      - type: Transform
        translation: [-0.1, 0, 0]
        elements:
          type: RigidBody
          mass: 3.0
          inertia: [0.01, 0, 0, 0.01, 0, 0.01]
""",
    )
    link = load(body).links[0]
    assert link.inertial is not None
    assert link.inertial.mass == 4.0
    np.testing.assert_allclose(link.inertial.com, [-0.05, 0, 0])
    # d1 = 0.15 m, d2 = 0.05 m along x: 0.02 + 1·0.0225 + 3·0.0025 about y and z.
    np.testing.assert_allclose(link.inertial.inertia, np.diag([0.02, 0.05, 0.05]), atol=1e-15)


def test_rigid_body_rotation_rotates_inertia(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
    joint_type: free
    elements:
      - type: RigidBody
        rotation: [0, 0, 1, 90]
        center_of_mass: [0.2, 0, 0]
        mass: 2.0
        inertia: [0.1, 0, 0, 0, 0.2, 0, 0, 0, 0.3]
""",
    )
    inertial = load(body).links[0].inertial
    assert inertial is not None
    np.testing.assert_allclose(inertial.com, [0, 0.2, 0], atol=1e-12)
    np.testing.assert_allclose(inertial.inertia, np.diag([0.2, 0.1, 0.3]), atol=1e-12)


def test_missing_mass_gives_choreonoid_defaults_and_a_warning(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
    joint_type: free
""",
    )
    v = validate(body)
    assert v.robot is not None
    inertial = v.robot.links[0].inertial
    assert inertial is not None and inertial.defaulted
    assert inertial.mass == 1.0
    np.testing.assert_allclose(inertial.inertia, np.eye(3))
    assert [d.code for d in v.diagnostics] == ["MK304"]


def test_radian_mode_and_ranges(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
formatVersion: 1.0
angleUnit: radian
links:
  - name: base
  - name: arm
    parent: base
    jointType: revolute
    jointAxis: -X
    jointRange: [-1.5, unlimited]
    maxJointVelocity: 2
    rotation: [0, 0, 1, 1.5707963267948966]
    mass: 1
    inertia: [0.01, 0.01, 0.01, 0, 0, 0]
  - name: slider
    parent: arm
    jointType: slide
    jointRange: 0.2
    mass: 1
    inertia: [0.01, 0, 0, 0.01, 0, 0.01]
""",
    )
    robot = load(body)
    arm, slider = robot.joints
    np.testing.assert_allclose(arm.axis, [-1, 0, 0])
    assert arm.limits.lower == -1.5 and arm.limits.upper == math.inf
    assert arm.limits.velocity == 2.0
    np.testing.assert_allclose(arm.origin.rotation @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    assert slider.type is JointType.PRISMATIC
    assert (slider.limits.lower, slider.limits.upper) == (-0.2, 0.2)


def test_degree_ranges_convert_only_for_revolute(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
  - name: a
    parent: base
    joint_type: revolute
    joint_range: [-90, 45]
    max_joint_velocity: 180
    joint_displacement: 30
    mass: 1
    inertia: [0.01, 0, 0, 0.01, 0, 0.01]
  - name: b
    parent: a
    joint_type: prismatic
    joint_range: [-0.5, 0.5]
    mass: 1
    inertia: [0.01, 0, 0, 0.01, 0, 0.01]
""",
    )
    a, b = load(body).joints
    np.testing.assert_allclose([a.limits.lower, a.limits.upper], [-math.pi / 2, math.pi / 4])
    np.testing.assert_allclose(a.limits.velocity, math.pi)
    np.testing.assert_allclose(a.initial_position, math.pi / 6)
    assert (b.limits.lower, b.limits.upper) == (-0.5, 0.5)


def test_rotation_list_composes_left_to_right(tmp_path: Path) -> None:
    body = write(
        tmp_path,
        """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
    rotation: [[0, 1, 0, 90], [0, 0, 1, -90]]
    translation: [[1, 0, 0], [0, 2, 0]]
""",
    )
    robot = load(body)
    r = robot.root_pose.rotation
    # Ry(90)·Rz(-90): x ↦ Ry(90)(0,-1,0) = (0,-1,0); z ↦ Ry(90)(0,0,1) = (1,0,0)
    np.testing.assert_allclose(r @ [1, 0, 0], [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(r @ [0, 0, 1], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(robot.root_pose.translation, [1, 2, 0])


def test_non_uniform_scaled_sphere_is_an_ellipsoid() -> None:
    from .conftest import CORPUS

    path = CORPUS / "choreonoid/share/model/misc/ellipsoid1.body"
    if not path.exists():
        pytest.skip("corpus not available")
    robot = load(path)
    geom = robot.links[0].visuals[0].geometry
    assert isinstance(geom, Ellipsoid)


def test_extrusion_track_becomes_a_mesh() -> None:
    robot = load(TUTORIAL / "mobile_robot_tracks.body", check_resources=False)
    track = robot.link("LeftTracks")
    assert track is not None
    joint = next(j for j in robot.joints if j.child == "LeftTracks")
    assert joint.type is JointType.PSEUDO_CONTINUOUS_TRACK
    geom = track.visuals[0].geometry
    assert isinstance(geom, Mesh) and geom.generator == "Extrusion" and geom.data is not None
    assert len(geom.data.faces) > 0


@pytest.mark.parametrize("path", corpus_bodies(), ids=lambda p: p.name)
def test_every_corpus_body_loads(path: Path) -> None:
    result = read_body(path)
    assert result.robot is not None
    assert result.robot.root is not None


def test_list_numbers_use_strtod_prefix_like_choreonoid(tmp_path: Path) -> None:
    """GR001.body has `specularColor: [ 0.2, 0.2, 0.t ]`, which Choreonoid reads as (0.2, 0.2, 0)."""
    body = write(tmp_path, """
format: ChoreonoidBody
format_version: 2.0
links:
  - name: base
    elements:
      - type: Shape
        geometry: {type: Box, size: [1, 1, 1]}
        appearance: {material: {diffuse: [0.5, 0.5, 0.5], specularColor: [0.2, 0.2, 0.t]}}
""")
    material = load(body).links[0].visuals[0].material
    assert material is not None and material.specular is not None
    np.testing.assert_allclose(material.specular, [0.2, 0.2, 0.0])


# ---- issue 9 §1: what Choreonoid accepts is not an error ------------------------------------------

_HEADER = "format: ChoreonoidBody\nformat_version: 2.0\nname: T\n"
_MASS = "    mass: 1.0\n    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]\n"


def test_yaml_resources_use_the_main_files_anchors(tmp_path: Path) -> None:
    """Choreonoid's YAML resource reader imports the main .body's anchors; local anchors win."""
    (tmp_path / "parts.yaml").write_text(  # the whole document is an `elements` value (body-format §3.6)
        "- { type: Shape, geometry: *BOX, appearance: *APP }\n"
        "- { type: Shape, geometry: &SPH { type: Sphere, radius: 0.3 } }\n"
        "- { type: Shape, geometry: *SPH }\n"
    )
    main = write(
        tmp_path,
        _HEADER + "APP: &APP { material: { diffuse: [ 1, 0, 0 ] } }\n"
        "BOX: &BOX { type: Box, size: [ 0.1, 0.2, 0.3 ] }\n"
        "SPH: &SPH { type: Sphere, radius: 9.0 }\n"
        "links:\n  -\n    name: BASE\n    joint_type: fixed\n" + _MASS
        + "    elements:\n      - { type: Resource, uri: parts.yaml }\n",
    )
    v = validate(main)
    # MK119 (info): the top-level keys APP, BOX and SPH only hold anchors; MK411 (warning): the two
    # spheres of the resource are the same shape at the same pose, as this test wants them
    assert [d.code for d in v.diagnostics if d.code != "MK119"] == ["MK411"] and v.robot is not None
    (link,) = v.robot.links
    shapes = [c.geometry for c in link.collisions]
    assert isinstance(shapes[0], Box) and list(shapes[0].size) == [0.1, 0.2, 0.3]
    assert [s.radius for s in shapes[1:] if isinstance(s, Sphere)] == [0.3, 0.3]  # the local &SPH
    # an anchor defined nowhere is still MK013, located in the resource file
    (tmp_path / "parts.yaml").write_text("- { type: Shape, geometry: *NOPE }\n")
    (d,) = validate(main).errors
    assert d.code == "MK013" and d.location is not None
    assert d.location.file.endswith("parts.yaml") and (d.location.line, d.location.col) == (1, 28)


def test_duplicate_key_is_a_warning_naming_both_lines_and_tree_and_convert_proceed(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from modelkit.cli import main

    path = write(
        tmp_path,
        _HEADER + "links:\n  -\n    name: BASE\n    joint_type: free\n    mass: 1.0\n    mass: 2.0\n"
        "    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]\n",
    )
    v = validate(path)
    (d,) = v.diagnostics
    assert (d.code, d.severity.value) == ("MK011", "warning")
    assert d.location is not None and (d.location.line, d.location.col) == (9, 5)
    assert "line 9" in d.message and "first at line 8" in d.message
    assert v.robot is not None and v.robot.links[0].inertial is not None
    assert v.robot.links[0].inertial.mass == 2.0  # Choreonoid keeps the last value
    runner = CliRunner()
    assert runner.invoke(main, ["tree", str(path)]).exit_code == 0
    assert runner.invoke(main, ["validate", str(path)]).exit_code == 0
    assert runner.invoke(main, ["validate", "--strict", str(path)]).exit_code == 1
    out = tmp_path / "out.urdf"
    converted = runner.invoke(main, ["convert", str(path), "-o", str(out)])
    assert converted.exit_code == 0, converted.output
    assert out.is_file()


def test_unlimited_ranges_in_every_spelling(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        _HEADER + "links:\n  -\n    name: BASE\n    joint_type: fixed\n" + _MASS
        + "  -\n    name: A\n    parent: BASE\n    joint_type: revolute\n    joint_axis: Y\n"
        "    joint_range: unlimited\n    joint_velocity_range: [ -unlimited, unlimited ]\n" + _MASS
        + "  -\n    name: B\n    parent: A\n    joint_type: revolute\n"
        "    joint_range: [ -unlimited, 90 ]\n    max_joint_velocity: unlimited\n" + _MASS
        + "  -\n    name: C\n    parent: B\n    joint_type: prismatic\n"
        "    joint_range: [ -0.5, unlimited ]\n    max_joint_effort: unlimited\n" + _MASS,
    )
    v = validate(path)
    assert v.errors == [], v.errors
    assert v.robot is not None
    joints = {j.name: j.limits for j in v.robot.joints}
    assert (joints["A"].lower, joints["A"].upper) == (-math.inf, math.inf)
    assert (joints["A"].velocity_lower, joints["A"].velocity_upper) == (-math.inf, math.inf)
    assert joints["B"].lower == -math.inf and joints["B"].upper == pytest.approx(math.pi / 2)
    assert joints["B"].velocity == math.inf
    assert (joints["C"].lower, joints["C"].upper) == (-0.5, math.inf)
    # a word that is not "unlimited" is still refused, as Choreonoid does ("Unknown symbol")
    bad = write(tmp_path, path.read_text().replace("[ -unlimited, 90 ]", "[ -infinite, 90 ]"), "bad.body")
    assert [d.code for d in validate(bad).errors] == ["MK100"]


def test_nested_rotation_and_translation_lists_with_aliases(tmp_path: Path) -> None:
    """`rotation: [[...], [...]]` is R1·R2 (about the already rotated axes); translations add up."""
    path = write(
        tmp_path,
        _HEADER + "R1: &R1 [ 0, 1, 0, 90 ]\nT1: &T1 [ 0.1, 0, 0 ]\n"
        "links:\n  -\n    name: BASE\n    joint_type: fixed\n" + _MASS
        + "  -\n    name: A\n    parent: BASE\n    joint_type: fixed\n"
        "    rotation: [ *R1, [ 0, 0, 1, -90 ] ]\n    translation: [ *T1, [ 0, 0.2, 0 ] ]\n" + _MASS,
    )
    v = validate(path)
    assert v.errors == [] and v.robot is not None
    (joint,) = v.robot.joints
    ry = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=float)
    rz = np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1]], dtype=float)
    np.testing.assert_allclose(joint.origin.rotation, ry @ rz, atol=1e-12)
    np.testing.assert_allclose(joint.origin.translation, [0.1, 0.2, 0.0])


_SUFFIXED_NUMBERS = """\
format: ChoreonoidBody
format_version: 2.0
name: Suffixed
links:
  - name: base
    joint_type: free
    mass: 2.0f
    center_of_mass: [0, 0, 0.001f]
    inertia: [0.02, 0, 0, 0, 0.02, 0, 0, 0, 0.02]
  - name: arm
    parent: base
    joint_type: revolute
    joint_axis: [0, 1, 0]
    joint_range: [-90, 90]
    joint_displacement: 30f
    mass: 1.0
    inertia: [0.02, 0, 0, 0, 0.02, 0, 0, 0, 0.02]
"""


def test_a_number_with_a_c_suffix_is_read_as_choreonoid_reads_it(tmp_path: Path) -> None:
    """MK181 (issue 18 item 3): Choreonoid's strtod-based "to" accessors (mass, list elements) read the
    leading number of "2.0f"; its "read" accessors (joint_displacement) ignore "30f" and keep the default.
    Each is a warning at the value, and the model holds what Choreonoid would."""
    path = write(tmp_path, _SUFFIXED_NUMBERS)
    result = read_body(path, BodyOptions())
    assert result.robot is not None
    base = result.robot.link("base")
    assert base.inertial is not None and base.inertial.mass == 2.0 and base.inertial.com[2] == 0.001
    found = [(d.code, d.severity.value, d.location.line if d.location else 0) for d in result.diagnostics]
    assert [f for f in found if f[0] == "MK181"] == [("MK181", "warning", n) for n in (7, 8, 15)]
    v = validate(path)
    assert v.errors == []
    (ignored,) = [d for d in v.warnings if d.code == "MK181" and "30f" in d.message]
    assert "keeps the default" in ignored.message and ignored.location is not None
    assert ignored.location.line == 15 and "2.0" not in ignored.message
    (read,) = [d for d in v.warnings if d.code == "MK181" and '"2.0f"' in d.message]
    assert 'Choreonoid reads 2 and ignores "f"' in read.message


_TWO_LINKS = (
    "links:\n"
    "  - name: {root}\n    joint_type: free\n    mass: 1.0\n    inertia: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
    "  - name: arm\n    parent: {parent}\n    joint_type: fixed\n    mass: 1.0\n"
    "    inertia: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
)


@pytest.mark.parametrize(
    ("root", "parent"),
    [("&n", "*n"), ("base", ""), ("base", '""'), ("&n", "*n  # the alias of an anchored empty value")],
)
def test_an_empty_parent_is_no_parent_as_in_choreonoid(tmp_path: Path, root: str, parent: str) -> None:
    # Choreonoid's YAML reader keeps `name: &n` (an anchored empty value) as the scalar "" and the
    # alias as the same node; its body loader treats an empty parent string as none: "The parent
    # of arm is not specified" for a link other than the root. An empty name and an empty parent
    # used to match each other here and the file loaded.
    path = write(tmp_path, _HEADER + _TWO_LINKS.format(root=root, parent=parent))
    errors = [d for d in validate(path).diagnostics if d.severity.value == "error"]
    assert [d.code for d in errors] == ["MK218"]
    assert '"arm"' in errors[0].message and "empty" in errors[0].message
    assert errors[0].location is not None and errors[0].location.line == 9  # the link "arm"


def test_an_anchored_empty_value_is_the_empty_scalar_for_every_alias(tmp_path: Path) -> None:
    # `note: &e` holds "" (Choreonoid's reader makes an empty ScalarNode and registers the anchor);
    # its alias as a contact material is that same "" (a warning, as for `material: ""`).
    text = _HEADER.replace("name:", "HOLD: &e\nname:", 1) + _TWO_LINKS.format(root="base", parent="base")
    path = write(tmp_path, text.replace("    parent: base\n", "    parent: base\n    material: *e\n"))
    found = [d for d in validate(path).diagnostics if d.severity.value != "info"]  # MK119: the holder key
    assert [d.code for d in found] == ["MK508"]
    assert '""' in found[0].message
