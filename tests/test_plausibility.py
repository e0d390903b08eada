"""The plausibility warnings (MK316, MK418, MK419) and the non-unit joint axis (MK306) in URDF and SDF:
the lecture's smartcar gets each of them where its file is wrong, small hand-written files show each rule
firing and not firing, and the corpus's sound files get none of them."""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import validate
from modelkit.formats.common import ReadOptions
from modelkit.resources import Resolver

from .conftest import CORPUS, SAMPLES, example_robot_data

NEW_CODES = {"MK306", "MK316", "MK411", "MK418", "MK419"}
SMARTCAR = SAMPLES / "smartcar" / "urdf" / "myrobot.urdf.xacro"
UNICYCLE = SAMPLES / "gazebo_unicycle" / "unicycle.sdf"
WHEELS = ("left_front_wheel", "right_front_wheel", "left_back_wheel", "right_back_wheel")

INERTIA = '<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/>'


def _urdf(
    tmp_path: Path,
    visual: str = '<cylinder radius="0.05" length="0.02"/>',
    collision: str = '<cylinder radius="0.05" length="0.02"/>',
    visual_origin: str = "",
    collision_origin: str = "",
    wheel_inertia: float = 1e-4,
    axis: str = "0 0 1",
) -> Path:
    """A box base and one wheel on a continuous joint; the wheel's shapes and numbers as given."""
    text = f"""<?xml version="1.0"?>
<robot name="cart">
  <link name="base">
    <inertial><mass value="1"/>{INERTIA.format(i=0.002)}</inertial>
    <visual><geometry><box size="0.2 0.1 0.05"/></geometry></visual>
    <collision><geometry><box size="0.2 0.1 0.05"/></geometry></collision>
  </link>
  <link name="wheel">
    <inertial><mass value="0.1"/>{INERTIA.format(i=wheel_inertia)}</inertial>
    <visual>{visual_origin}<geometry>{visual}</geometry></visual>
    <collision>{collision_origin}<geometry>{collision}</geometry></collision>
  </link>
  <joint name="wheel_joint" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <origin xyz="0.3 0.2 0" rpy="1.5708 0 0"/>
    <axis xyz="{axis}"/>
  </joint>
</robot>
"""
    path = tmp_path / "cart.urdf"
    path.write_text(text)
    return path


def _found(path: Path, code: str) -> list[tuple[int, str]]:
    return [
        (d.location.line if d.location else 0, d.message)
        for d in validate(path).diagnostics
        if d.code == code
    ]


def test_a_sound_cart_gets_none_of_the_new_warnings(tmp_path: Path) -> None:
    path = _urdf(tmp_path)
    assert {d.code for d in validate(path).diagnostics} & NEW_CODES == set()


# ---- MK411 collision repeated ----------------------------------------------------------------------------


def test_a_collision_given_twice_is_said(tmp_path: Path) -> None:
    """A tyre given twice (a semantic-fuzz mutant of the tutorial's primitive robot): engines make a
    contact for each, and MuJoCo and PyBullet drove 10.9 mrad apart on verify's arc. The same shape
    turned, moved or resized is another shape, and is not said."""
    twice = '<cylinder radius="0.05" length="0.02"/></geometry></collision><collision><geometry>' \
            '<cylinder radius="0.05" length="0.02"/>'
    (line, message), = _found(_urdf(tmp_path, collision=twice), "MK411")
    assert 'link "wheel": collision 1 repeats collision 0 (the same cylinder at the same pose)' in message
    assert line == 11  # both collisions are on the wheel link's collision line
    for other in ('<cylinder radius="0.05" length="0.03"/>', '<sphere radius="0.05"/>'):
        different = twice.rsplit("<cylinder", 1)[0] + other
        assert _found(_urdf(tmp_path, collision=different), "MK411") == []
    moved = twice.replace("<collision><geometry>", '<collision><origin xyz="0 0 0.01"/><geometry>')
    assert _found(_urdf(tmp_path, collision=moved), "MK411") == []


# ---- MK418 collision far from visual --------------------------------------------------------------------


def test_collision_repeating_the_joint_origin_is_far_from_the_visual(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision_origin='<origin xyz="0.3 0.2 0"/>')
    ((line, message),) = _found(path, "MK418")
    assert line == 11  # the <collision> element
    assert "0.2236 m away" in message  # gaps 0.2 and 0.1 m along x and y between the boxes
    assert "centred at 0.3 0.2 0, the visuals at 0 0 0" in message
    assert 'repeats the origin of joint "wheel_joint" (0.3 0.2 0)' in message


def test_a_collision_touching_its_visual_is_not_far(tmp_path: Path) -> None:
    # shifted by its own radius: still overlapping the visual (gap 0)
    path = _urdf(tmp_path, collision_origin='<origin xyz="0.05 0 0"/>')
    assert _found(path, "MK418") == []


def test_far_is_relative_to_the_size(tmp_path: Path) -> None:
    # a gap of 0.06 m beside boxes of half-diagonal 0.0714 m (0.05, 0.05, 0.01): 0.84 of the size, not far
    near = _urdf(tmp_path, collision_origin='<origin xyz="0.16 0 0"/>')
    assert _found(near, "MK418") == []
    # a gap of 0.1 m: 1.4 of the size
    far = _urdf(tmp_path, collision_origin='<origin xyz="0.2 0 0"/>')
    ((_, message),) = _found(far, "MK418")
    assert "0.1 m away" in message


# ---- MK419 collision shape differs from visual ------------------------------------------------------------


def test_cylinders_along_different_axes(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision_origin='<origin rpy="0 1.5708 0"/>')
    ((line, message),) = _found(path, "MK419")
    assert line == 11
    assert "both are cylinders" in message and "90° from the visual's (0 0 1)" in message
    assert _found(path, "MK418") == []  # same centre: not far


def test_cylinders_turned_about_their_own_axis_agree(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision_origin='<origin rpy="0 0 0.7"/>')
    assert _found(path, "MK419") == []


def test_box_collision_of_very_different_size(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision='<box size="0.3 0.1 0.02"/>')
    ((_, message),) = _found(path, "MK419")
    assert "along the link's x axis the box collision is 0.3 m long and the cylinder visual 0.1 m" in message
    assert "a factor 3" in message


def test_a_box_around_a_cylinder_is_a_usual_collision(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision='<box size="0.1 0.1 0.02"/>')
    assert _found(path, "MK419") == []


def test_a_dot_standing_for_no_collision_is_not_judged(tmp_path: Path) -> None:
    path = _urdf(tmp_path, collision='<sphere radius="0.001"/>')
    assert _found(path, "MK419") == []


# ---- MK316 implausible inertia ---------------------------------------------------------------------------


def test_unit_inertia_on_a_light_wheel(tmp_path: Path) -> None:
    path = _urdf(tmp_path, wheel_inertia=1.0)
    ((line, message),) = _found(path, "MK316")
    assert line == 9  # the wheel's <inertial> line (where the inertia is written)
    assert 'link "wheel": mass 0.1 kg' in message
    assert "radius of gyration of 3.162 m" in message
    assert "44.3 times the 0.07141 m" in message  # corner of the cylinder's box: sqrt(0.05² + 0.05² + 0.01²)


def test_inertia_within_the_factor_is_accepted(tmp_path: Path) -> None:
    # radius of gyration 0.1 m: 1.9 times the shapes' reach, physically too large but within the factor 3
    assert _found(_urdf(tmp_path, wheel_inertia=1e-3), "MK316") == []


def test_a_placeholder_inertia_on_a_welded_sensor_frame_is_judged_with_its_body(tmp_path: Path) -> None:
    text = f"""<?xml version="1.0"?>
<robot name="r">
  <link name="trunk">
    <inertial><mass value="10"/>{INERTIA.format(i=0.05)}</inertial>
    <collision><geometry><box size="0.4 0.2 0.1"/></geometry></collision>
  </link>
  <link name="imu"><inertial><mass value="0.001"/>{INERTIA.format(i=1e-4)}</inertial>
    <visual><geometry><box size="0.001 0.001 0.001"/></geometry></visual></link>
  <joint name="imu_joint" type="fixed"><parent link="trunk"/><child link="imu"/></joint>
</robot>
"""
    path = tmp_path / "r.urdf"
    path.write_text(text)
    assert _found(path, "MK316") == []
    heavy = tmp_path / "heavy.urdf"
    heavy.write_text(text.replace(INERTIA.format(i=1e-4), INERTIA.format(i=5.0)))
    ((line, message),) = _found(heavy, "MK316")
    assert line == 7  # the imu's inertial, the largest inertia written in the body
    assert 'the rigid body of link "trunk" (links "trunk", "imu" joined by fixed joints' in message


def test_marker_shapes_that_cannot_hold_the_mass_are_not_judged(tmp_path: Path) -> None:
    # 50 g in a 1 mm sphere (denser than osmium): the sphere marks the link, it is not its extent
    marker = '<sphere radius="0.001"/>'
    path = _urdf(tmp_path, visual=marker, collision=marker, wheel_inertia=1e-3)
    assert _found(path, "MK316") == []
    # the same inertia on a sphere of radius 1 cm: 0.1 kg in its 2 cm box is 12.5 t/m³, below osmium's 22.6
    sphere = '<sphere radius="0.01"/>'
    path = _urdf(tmp_path, visual=sphere, collision=sphere, wheel_inertia=1e-3)
    ((_, message),) = _found(path, "MK316")
    assert "radius of gyration of 0.1 m, 5.77 times the 0.01732 m" in message


def test_links_with_mesh_files_validate_did_not_load_are_not_judged(tmp_path: Path) -> None:
    path = _urdf(tmp_path, visual='<mesh filename="wheel.stl"/>', wheel_inertia=1.0)  # no such file
    assert _found(path, "MK316") == []


def _box_stl(path: Path, half: tuple[float, float, float]) -> None:
    """An ASCII STL of a box centred on the origin (12 triangles)."""
    signs = [(sx, sy, sz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    corners = [(sx * half[0], sy * half[1], sz * half[2]) for sx, sy, sz in signs]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    lines = ["solid box"]
    for face in faces:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {' '.join(str(c) for c in corners[i])}" for i in face]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid box", ""]))


def test_a_mesh_validate_loaded_counts_with_its_extent(tmp_path: Path) -> None:
    _box_stl(tmp_path / "wheel.stl", (0.05, 0.05, 0.01))
    mesh = '<mesh filename="wheel.stl" scale="2 2 2"/>'
    ((_, message),) = _found(_urdf(tmp_path, visual=mesh, collision=mesh, wheel_inertia=1.0), "MK316")
    assert "22.1 times the 0.1428 m" in message  # the scaled box: half extents 0.1, 0.1, 0.02
    assert _found(_urdf(tmp_path, visual=mesh, collision=mesh, wheel_inertia=1e-3), "MK316") == []
    # a box collision far beside the mesh visual
    far = _urdf(tmp_path, visual=mesh, collision_origin='<origin xyz="0.5 0 0"/>')
    ((_, message),) = _found(far, "MK418")
    assert "the visuals at 0 0 0; sizes (half-diagonals) 0.07141 and 0.1428 m" in message


def test_plain_obj_and_glb_meshes_count_with_their_extent(tmp_path: Path) -> None:
    """The fast checks of OBJ and ``.glb`` files (no trimesh) give the rules the meshes' corners too."""
    import trimesh

    box = trimesh.creation.box(extents=(0.1, 0.1, 0.02))
    (tmp_path / "wheel.obj").write_text(trimesh.exchange.obj.export_obj(box, include_normals=False))
    (tmp_path / "wheel.glb").write_bytes(trimesh.Scene(box).export(file_type="glb"))
    for name in ("wheel.obj", "wheel.glb"):
        mesh = f'<mesh filename="{name}" scale="2 2 2"/>'
        ((_, message),) = _found(_urdf(tmp_path, visual=mesh, collision=mesh, wheel_inertia=1.0), "MK316")
        assert "22.1 times the 0.1428 m" in message, name


def test_a_collision_origin_holding_an_rpy_is_far_from_its_obj_visual() -> None:
    """example-robot-data's Alex with nub hands: each nub's collision origin is ``xyz="0 1.57 0"`` (the
    visual's ``rpy`` typed into ``xyz``); its OBJ mesh lies 1.47 m beside the visual."""
    robots = example_robot_data()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    path = robots / "alex_description" / "urdf" / "alex_nub_hands.urdf"
    options = ReadOptions(resolver=Resolver(environ={"AMENT_PREFIX_PATH": str(robots.parents[2])}))
    found = [d for d in validate(path, options).diagnostics if d.code == "MK418"]
    links = sorted(d.message.split(":")[0] for d in found)
    assert links == ['link "leftNub"', 'link "rightNub"']
    assert all("1.47 m away" in d.message and "centred at 0.035 1.57 0" in d.message for d in found)


# ---- MK306 axis not a unit vector ------------------------------------------------------------------------


def test_urdf_axis_not_unit_is_reported_at_its_line(tmp_path: Path) -> None:
    path = _urdf(tmp_path, axis="0 0 2")
    ((line, message),) = _found(path, "MK306")
    assert line == 16
    assert 'the axis "0 0 2" has length 2, not 1' in message and "PyBullet" in message
    robot = validate(path).robot
    assert robot is not None
    assert [list(j.axis) for j in robot.joints] == [[0.0, 0.0, 1.0]]  # the model holds it normalised


def test_urdf_axis_rounded_to_four_digits_is_a_unit_vector(tmp_path: Path) -> None:
    assert _found(_urdf(tmp_path, axis="0.7071 0 0.7071"), "MK306") == []


def test_sdf_axis_not_unit(tmp_path: Path) -> None:
    def sdf(xyz: str) -> Path:
        path = tmp_path / "m.sdf"
        path.write_text(f"""<?xml version="1.0"?>
<sdf version="1.9">
  <model name="m">
    <link name="a"/>
    <link name="b"><pose>0 0 1 0 0 0</pose></link>
    <joint name="j" type="revolute">
      <parent>a</parent><child>b</child>
      <axis><xyz>{xyz}</xyz></axis>
    </joint>
  </model>
</sdf>
""")
        return path

    ((line, message),) = _found(sdf("0 3 4"), "MK306")
    assert line == 8 and 'the axis "0 3 4" has length 5, not 1' in message
    assert _found(sdf("0 0.6 0.8"), "MK306") == []


# ---- the lecture's samples ------------------------------------------------------------------------------


def test_smartcar_gets_each_warning_with_its_numbers() -> None:
    diagnostics = [d for d in validate(SMARTCAR).diagnostics if d.code in NEW_CODES]
    by_code: dict[str, list[str]] = {}
    for d in diagnostics:
        assert d.location is not None and d.location.file.endswith("robot_body.urdf.xacro")
        by_code.setdefault(d.code, []).append(d.message)
    far = by_code["MK418"]
    assert len(far) == 5  # the four wheels and the head
    assert any("repeats the origin of joint \"left_front_wheel_joint\" (0.08 0.08 0.025)" in m for m in far)
    differs = by_code["MK419"]
    assert sum("both are cylinders" in m and "90°" in m for m in differs) == 4  # the wheels
    assert any('"head"' in m and "cylinder collision is 0.05 m long and the box visual 0.02 m" in m
               for m in differs)
    inertia = by_code["MK316"]
    assert sum("mass 0.1 kg with a largest principal moment of 1 kg·m²" in m and "3.162 m" in m
               for m in inertia) == 4  # the wheels: radius of gyration 3.2 m
    assert any('the rigid body of link "base_link" (links "base_link", "head"' in m for m in inertia)
    assert "MK306" not in by_code


def test_smartcar_wheel_collision_location() -> None:
    (d,) = [d for d in validate(SMARTCAR).diagnostics
            if d.code == "MK418" and '"left_front_wheel"' in d.message]
    assert d.location is not None
    lines = (SAMPLES / "smartcar" / "urdf" / "robot_body.urdf.xacro").read_text().splitlines()
    assert lines[d.location.line - 1].strip() == "<collision>"


def test_unicycle_has_none_of_these_faults() -> None:
    # The unicycle sample's collisions are its visuals, and its largest radius of gyration (camera_link:
    # 0.1 kg, 9.1e-5 kg·m², 0.030 m) is 2.7 times its 1 cm cylinder's reach, within the factor 3.
    assert {d.code for d in validate(UNICYCLE).diagnostics} & NEW_CODES == set()


# ---- the corpus ------------------------------------------------------------------------------------------

# Each hit on the corpus, read and judged a real fault of the file (none is on a sound file):
# - SR1.body: 16 links with the identity inertia (1 kg·m²) as a placeholder, e.g. a 0.4 kg wrist of 8 cm;
# - gazebo_ros_pkgs test files: an 8 cm link of 0.1 kg with 1 kg·m², a 1 m box of 1 kg with 100 kg·m²;
#   the Pioneer 3-DX's caster swivel (0.1 kg, 0.01 kg·m² in 5.6 cm of mesh) and centre wheel (0.11 kg,
#   0.031 kg·m²), 5.6 and 9.1 times;
#   trimesh_collision.world's "collision_box" lies 1 m beside its visual (its 10 kg boxes of 5 cm with
#   1 kg·m² are not judged: no material holds 10 kg in 5 cm, so the shapes cannot be the body);
# - gz-sim ackermann_steering.sdf: 0.5 kg steering links of 6.6 cm with 0.025 kg·m² (3.4 times);
#   world_joint.sdf: a 1 kg box with 1 kg·m² (3.5 times);
# - sdformat_urdf joint_revolute_axis.sdf: the axis "0.1 1.23 4.567" (a converter test of normalisation).
CORPUS_HITS = {
    ("choreonoid/share/model/SR1/SR1.body", "MK316"),
    ("gazebo_ros_pkgs/gazebo_plugins/test/test_worlds/gazebo_ros_block_laser_clipping.world", "MK316"),
    ("gazebo_ros_pkgs/gazebo_plugins/test/test_worlds/gazebo_ros_trimesh_collision.world", "MK418"),
    ("gazebo_ros_pkgs/gazebo_plugins/test2/urdf/box.urdf", "MK316"),
    ("gazebo_ros_pkgs/gazebo_plugins/test/multi_robot_scenario/xacro/p3dx/pioneer3dx.xacro", "MK316"),
    ("gz_sim_worlds/examples/worlds/ackermann_steering.sdf", "MK316"),
    ("gz_sim_worlds/examples/worlds/world_joint.sdf", "MK316"),
    ("sdformat_urdf/sdformat_test_files/models/joint_revolute_axis/joint_revolute_axis.sdf", "MK306"),
}
MODEL_SUFFIXES = {".body", ".urdf", ".xacro", ".sdf", ".world", ".xml"}


def test_sound_corpus_files_get_none_of_the_new_codes() -> None:
    if not CORPUS.is_dir():
        pytest.skip("the shared corpus is not next to the checkout")
    found = set()
    for path in sorted(p for p in CORPUS.rglob("*") if p.suffix in MODEL_SUFFIXES and p.is_file()):
        for d in validate(path).diagnostics:
            if d.code in NEW_CODES:
                found.add((str(path.relative_to(CORPUS)), d.code))
    assert found == CORPUS_HITS
