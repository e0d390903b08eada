"""Issue 17 §5: every writer prints clean numbers (no arithmetic dust, readable rotations) and a
read-back is still the same robot to 1e-9, on real robots nobody here wrote (pybullet_data)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from lxml import etree

from modelkit.api import load, validate
from modelkit.convert.api import write
from modelkit.convert.compare import compare_poses, compare_robots
from modelkit.convert.notes import renames
from modelkit.convert.numbers import clean_angle, clean_length, clean_rotation, fmt, fmt_text, length_scale
from modelkit.convert.options import WriteOptions
from modelkit.formats.mjcf.write_xml import euler_text, quat_wxyz, set_pose, z_turn, zaxis_text
from modelkit.formats.urdf.massless import TINY_INERTIA
from modelkit.spatial import Pose, matrix_from_rpy

pybullet_data = pytest.importorskip("pybullet_data")
DATA = Path(pybullet_data.getDataPath())
ROBOTS = ["franka_panda/panda.urdf", "kuka_iiwa/model.urdf", "laikago/laikago_toes_zup.urdf", "a1/a1.urdf",
          "quadruped/minitaur.urdf"]
TARGETS = ["xml", "urdf", "sdf"]
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
DUST = re.compile(r"e-1[0-9]$|\.\d*(?:0{7,}[1-9]|9{7,})\d*$")  # near zero, or a 0000000x/9999999 tail


def test_dust_goes_and_written_decimals_stay() -> None:
    assert fmt(0.0615250000000001) == "0.061525"
    assert fmt(0.30000000000000004) == "0.3"
    assert fmt(0.9999999999999999) == "1"
    assert fmt(1 / 3) == "0.333333333333333"  # a value, not a decimal with a dusty tail
    assert fmt(0.499999999989993) == "0.499999999989993"  # 1e-11 from 0.5: a real rotation
    assert fmt(3.14159265359) == "3.14159265359"
    assert fmt(6.123233995736766e-17) == "6.12323399573677e-17"  # fmt alone cannot call it dust
    assert clean_rotation(1.03411553555107e-13) == 0.0
    assert clean_rotation(-0.707106781186547) == -math.sqrt(0.5)
    assert clean_rotation(0.7071067811) == 0.7071067811
    assert clean_angle(-3.14159265358959) == -math.pi
    assert clean_angle(2.06823107110214e-13) == 0.0
    assert clean_angle(1.5708) == 1.5708
    assert clean_length(-2.0e-13) == 0.0
    assert clean_length(2.28232e-12) == 0.0 and clean_length(-5.54343e-11) == 0.0  # iCub's, and ten times it
    assert clean_length(-8.66e-10) == -8.66e-10  # ANYmal's COM: over 1e-10 of a metre robot, a value
    with length_scale(1e-3):  # a millimetre robot: 2e-13 m is no longer dust below 1e-10 of it
        assert clean_length(-2.0e-13) == -2.0e-13
        assert clean_length(-5.0e-14) == 0.0
    assert clean_angle(1.53106e-11) == 0.0 and clean_angle(-9e-11) == 0.0  # iCub's
    assert clean_angle(2e-10) == 2e-10
    assert clean_angle(math.pi / 2 + 5e-11) == math.pi / 2 + 5e-11  # only zero takes the 1e-10
    assert clean_rotation(5e-11) == 0.0 and clean_rotation(2e-10) == 2e-10


def test_source_text_numbers_in_the_writers_form() -> None:
    """Attribute text a source wrote (an MJCF <option>, a <pair>): number lists re-printed, words kept."""
    assert fmt_text(".005") == "0.005" and fmt_text(" 0  0 -9.810 ") == "0 0 -9.81"
    assert fmt_text("1E-4 5e-3 100") == "0.0001 0.005 100"
    for kept in ("implicitfast", "0.5 soft", "inf", "1 nan", "1_000", ""):
        assert fmt_text(kept) == kept


def test_quaternions_and_euler_angles_are_exact_values() -> None:
    half_turn = matrix_from_rpy(3.14159265359, 0.0, 0.0)  # a source's 12-digit π
    assert " ".join(fmt(v) for v in quat_wxyz(half_turn)) == "0 1 0 0"
    quarter = matrix_from_rpy(math.pi / 2, 0.0, 0.0) @ matrix_from_rpy(0.0, 0.0, 1e-13)
    assert " ".join(fmt(v) for v in quat_wxyz(quarter)) == "0.707106781186548 0.707106781186548 0 0"
    rotation = matrix_from_rpy(1.57079, 0.0, 1.57079)
    assert euler_text(rotation) == "1.57079 0 1.57079"


def test_mjcf_rotations_take_the_shortest_exact_text() -> None:
    def written(rotation: np.ndarray) -> dict[str, str]:
        el = etree.Element("geom")
        set_pose(el, Pose(rotation, np.zeros(3)))
        return dict(el.attrib)

    assert zaxis_text(matrix_from_rpy(math.pi / 2, 0.0, 0.0)) == "0 -1 0"
    assert zaxis_text(matrix_from_rpy(0.0, 0.0, math.pi / 2)) is None  # a turn about Z: no zaxis
    assert written(matrix_from_rpy(math.pi / 2, 0.0, 0.0)) == {"zaxis": "0 -1 0"}
    assert written(matrix_from_rpy(math.pi, 0.0, 0.0)) == {"zaxis": "0 0 -1"}
    assert written(matrix_from_rpy(1.57079, 0.0, 1.57079)) == {"euler": "1.57079 0 1.57079"}
    assert written(matrix_from_rpy(0.0, 0.0, math.pi)) == {"quat": "0 0 0 1"}
    # pybullet_data's Spirit40 writes its leg cylinders at rpy="0 1.5707963268 0", 5e-12 past π/2: the
    # matrix's own triple is (−π, 1.57079632678979, −π) and its zaxis "1 0 -5.10341196725696e-12" was
    # written; the source's triple is the other one of the two, and the shortest
    assert written(matrix_from_rpy(0.0, 1.5707963268, 0.0)) == {"euler": "0 1.5707963268 0"}
    # differentiable-robot-model's Allegro hand writes π as 3.1415926518 (1.8e-9 short): its quaternion
    # "8.95e-10 1 0 0" is shorter, and a number a reader sees as noise; the source's text is exact too
    assert written(matrix_from_rpy(3.1415926518, 0.0, 0.0)) == {"euler": "3.1415926518 0 0"}
    for rotation in (matrix_from_rpy(0.3, -1.2, 2.9), matrix_from_rpy(math.pi, 0.0, 0.0)):
        assert np.allclose(z_turn([0.0, 0.0, -1.0]) @ np.eye(3), matrix_from_rpy(math.pi, 0.0, 0.0))
        assert written(rotation)  # never the identity for a turn


@pytest.mark.parametrize("source", ROBOTS)
def test_real_robots_are_written_clean_and_read_back_equal(source: str, tmp_path: Path) -> None:
    robot = validate(DATA / source).robots[0]
    masses = {link.name: link.inertial.mass for link in robot.links
              if link.inertial is not None and link.inertial.mass > 0.0}
    for target in TARGETS:
        path = tmp_path / target / f"robot.{target}"
        path.parent.mkdir()
        notes = write(robot, path)
        text = path.read_text()
        dusty = sorted({n for n in NUMBER.findall(text) if DUST.search(n)})
        # the URDF and SDF writers' tiny inertial of a massless link (TINY_INERTIA) is a chosen value
        dusty = [n for n in dusty if not (target in ("sdf", "urdf") and n == fmt(TINY_INERTIA))]
        assert dusty == [], f"{source} → {target}: {dusty}"
        if target == "xml":
            mujoco.MjModel.from_xml_path(str(path))
        back = validate(path).robots[0]
        names = renames(notes, "link")
        assert compare_poses(robot, back, names, tol=1e-9) == []
        # massless links are given a writer's minimum mass (MK816 notes): compare the real ones
        back_masses = {link.name: link.inertial.mass for link in back.links if link.inertial is not None}
        for name, mass in masses.items():
            assert back_masses.get(names.get(name, name)) == pytest.approx(mass, rel=1e-9), (target, name)


def test_axis_dust_is_written_as_zero(tmp_path: Path) -> None:
    """iCub's URDF (example-robot-data) writes hip axes as ``0 -1 6.12323e-17`` (a cosine of π/2): every
    target writes ``0 -1 0``, and a real small component relative to the axis stays."""
    from modelkit.convert.numbers import fmt_direction

    assert fmt_direction([0.0, -1.0, 6.123233995736766e-17]) == "0 -1 0"
    assert fmt_direction([0.0, -2.0, 1e-9]) == "0 -2 1e-9"  # 5e-10 of the length: not dust
    assert fmt_direction([0.0, -2.0, 1e-10]) == "0 -2 0"  # 5e-11 of the length: dust
    source = tmp_path / "axis.urdf"
    source.write_text("""<robot name="axis">
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 -1 6.12323e-17"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""")
    robot = validate(source).robot
    assert robot is not None
    where = ((".xml", "worldbody//joint"), (".urdf", "joint/axis"), (".sdf", "model/joint/axis/xyz"))
    for suffix, path in where:
        out = tmp_path / f"out{suffix}"
        write(robot, out)
        text = out.read_text()
        assert "e-17" not in text, suffix
        node = etree.parse(str(out)).getroot().find(path)
        assert node is not None
        value = node.get("axis") if suffix == ".xml" else node.get("xyz") if suffix == ".urdf" else node.text
        assert value == "0 -1 0", suffix


def test_inertia_dust_is_written_as_zero(tmp_path: Path) -> None:
    """iCub's ankle links (example-robot-data) are ``ixx=iyy=izz=0, ixz=1.35525e-20``: float dust of a
    zero tensor, with a negative eigenvalue MuJoCo refuses. Entries below 1e-12 of mass × size² are 0
    in every target, so the MJCF loads (the foot welded below carries the inertia)."""
    from modelkit.convert.numbers import clean_inertia, length_scale

    with length_scale(1.0):
        dusty = np.array([[0.0, 0.0, 1.35525e-20], [0.0, 0.0, 0.0], [1.35525e-20, 0.0, 0.0]])
        assert not clean_inertia(dusty, 0.2675).any()
        real = np.array([[1e-9, 0.0, 2e-12], [0.0, 1e-9, 0.0], [2e-12, 0.0, 1e-9]])
        assert (clean_inertia(real, 0.001) == real).all()  # 2e-12 > 1e-12 × 1e-9 kg·m²: kept
        assert not clean_inertia(np.diag([1e-20, 1e-20, 1e-20]), 1.0).any()  # Drake's cart-pole: all dust
        # dm_control's dog's tail: 3e-15 is 4e-9 of the tensor (kept), under 1e-12 of 0.01 kg × 1 m²
        tail = np.array([[4.47e-7, 3.03e-15, -2.12e-7], [3.03e-15, 7.28e-7, 2.26e-15],
                         [-2.12e-7, 2.26e-15, 5.74e-7]])
        assert (clean_inertia(tail, 0.01) == tail).all()
        dust = tail.copy()
        dust[0, 1] = dust[1, 0] = 5e-19  # 7e-13 of the tensor's largest: dust
        assert clean_inertia(dust, 0.01)[0, 1] == 0.0 and clean_inertia(dust, 0.01)[1, 2] == 2.26e-15
        # a written tensor is no dust whatever the mass beside it (a fuzz mutant: 3.5e38 kg, whose
        # 1e-12 of m·L² zeroed the wheel's 0.0023 kg·m², and MuJoCo refused the MJCF)
        wheel = np.diag([0.0012, 0.0023, 0.0012])
        assert (clean_inertia(wheel, 3.5e38) == wheel).all()
        assert not clean_inertia(np.diag([1e-20, 1e-20, 1e-20]), 3.5e38).any()
    source = tmp_path / "ankle.urdf"
    source.write_text("""<robot name="ankle">
  <link name="shin"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="ankle"><inertial><mass value="0.2675"/>
    <inertia ixx="0" ixy="0" ixz="1.35525e-20" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="foot"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="roll" type="revolute"><parent link="shin"/><child link="ankle"/><axis xyz="1 0 0"/>
    <limit lower="-0.4" upper="0.4" effort="11" velocity="1"/></joint>
  <joint name="sole" type="fixed"><parent link="ankle"/><child link="foot"/><origin xyz="0 0 -0.05"/></joint>
</robot>
""")
    robot = validate(source).robot
    assert robot is not None
    for suffix in (".xml", ".urdf", ".sdf"):
        out = tmp_path / f"out{suffix}"
        write(robot, out)
        assert "e-20" not in out.read_text(), suffix
    mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))  # refused before: a negative eigenvalue


def test_centre_of_mass_dust_is_written_as_zero(tmp_path: Path) -> None:
    """pybullet_data's xArm 6 gripper has finger centres of mass at ``2.9948e-14 0.021559 0.015181`` (a CAD
    export's dust, 6e-14 of the arm's size): every target writes the point with 0, a real small offset
    (1e-9 m on a 0.5 m robot) stays, and the source's non-dust values are untouched."""
    from modelkit.convert.numbers import fmt_position

    with length_scale(0.5):
        assert fmt_position([2.9948e-14, 0.021559, 0.015181]) == "0 0.021559 0.015181"
        assert fmt_position([1e-9, 0.0, -0.25]) == "1e-9 0 -0.25"
    source = DATA / "xarm" / "xarm6_with_gripper.urdf"
    robot = validate(source).robot
    assert robot is not None
    for suffix in (".xml", ".urdf", ".sdf"):
        out = tmp_path / f"out{suffix}"
        write(robot, out)
        text = out.read_text()
        assert not re.search(r"[-\d.]+e-1[3-9]", text), (suffix, re.findall(r"\S*e-1[3-9]\S*", text)[:3])
        assert "0.021559 0.015181" in text, suffix


def test_a_pitch_past_a_right_angle_keeps_its_source_text(tmp_path: Path) -> None:
    """pybullet_data's Spirit40 turns its leg cylinders by rpy="0 1.5707963268 0", 5e-12 past π/2. The
    matrix's own roll-pitch-yaw is (−π, 1.57079632678979, −π): URDF and SDF wrote that, MJCF a zaxis
    with 5.1e-12 in it. Of the two triples of every rotation, the shorter is written, here the source's."""
    source = tmp_path / "leg.urdf"
    source.write_text("""<robot name="leg">
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0.103 0 0" rpy="0 1.5707963268 0"/>
      <geometry><cylinder radius="0.013" length="0.206"/></geometry></visual></link>
</robot>
""")
    robot = validate(source).robot
    assert robot is not None
    for suffix, text in ((".urdf", 'rpy="0 1.5707963268 0"'), (".sdf", "0.103 0 0 0 1.5707963268 0"),
                         (".xml", 'euler="0 1.5707963268 0"')):
        out = tmp_path / f"out{suffix}"
        write(robot, out)
        assert text in out.read_text(), (suffix, out.read_text())
    for rpy in ((0.3, 2.9, -1.0), (3.0, -1.6, 0.2), (0.0, -1.5707963268, 0.0)):  # either triple: same matrix
        from modelkit.convert.numbers import fmt_rpy

        again = matrix_from_rpy(*(float(v) for v in fmt_rpy(matrix_from_rpy(*rpy)).split()))
        assert np.allclose(again, matrix_from_rpy(*rpy), atol=1e-12)


SUB_NANO = """<robot name="cad">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.00159938741862" iyy="0.00159938741932" izz="5.4423177329e-5"
             ixy="-9.32e-13" ixz="1.039e-11" iyz="1.7563e-11"/></inertial></link>
  <link name="finger"><inertial><origin xyz="0.01 0 0"/><mass value="0.00645"/>
    <inertia ixx="8.2671e-7" iyy="1.98028e-6" izz="2.64638e-6"
             ixy="-1.08876e-6" ixz="-3.7e-10" iyz="8.1e-10"/>
  </inertial></link>
  <link name="tip"><inertial><mass value="0.01"/>
    <inertia ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="knuckle" type="revolute"><parent link="base"/><child link="finger"/>
    <origin xyz="0 2.28232e-12 0.9" rpy="1.5708 1.53106e-11 5.10376e-12"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="pad" type="revolute"><parent link="finger"/><child link="tip"/>
    <origin xyz="0.05 -5.54343e-12 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_sub_nanometre_source_values_are_written_as_zero_or_in_principal_form(tmp_path: Path) -> None:
    """A CAD export's values far under a nanometre (iCub's ``2.28232e-12`` offsets, ``1.53106e-11`` and
    ``5.10376e-12`` angles, from example-robot-data) are written as 0, and a finger's tensor with a
    product under 1e-9 kg·m² (``ixz="-3.7e-10"``, 1.4e-4 of its moments) as its principal axes and
    moments, with no ``e-1x`` number. ANYmal B's base-like tensor keeps ``fullinertia``: its products
    of 1e-11 beside moments 4e-10 apart leave no principal axes but round-off. The tensors and the poses
    read back equal to 1e-9, and MuJoCo compiles the finger's principal moments and axes from the
    source's tensor to 1e-15."""
    source = tmp_path / "cad.urdf"
    source.write_text(SUB_NANO)
    robot = validate(source).robot
    assert robot is not None
    out = tmp_path / "cad.xml"
    notes = write(robot, out)
    text = out.read_text()
    base = ('<inertial pos="0 0 0" mass="2" fullinertia="0.00159938741862 0.00159938741932 5.4423177329e-5 '
            '-9.32e-13 1.039e-11 1.7563e-11"/>')
    assert base in text  # the source's numbers, ixy 5.8e-10 of the tensor included
    dusty = re.findall(r'\w+="[^"]*e-1[0-9][^"]*"', text.replace(base, ""))
    assert dusty == []
    assert '<body name="finger" pos="0 0 0.9" quat="0.707105482511236 0.707108079859474 0 0">' in text
    assert '<body name="tip" pos="0.05 0 0">' in text
    finger = etree.parse(str(out)).getroot().find(".//body[@name='finger']/inertial")
    assert finger is not None and finger.get("fullinertia") is None and finger.get("quat") is not None
    back = validate(out).robot
    assert back is not None
    assert compare_robots(robot, back, renames(notes, "link")) == []
    model = mujoco.MjModel.from_xml_path(str(out))
    finger_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "finger")
    source_tensor = next(link for link in robot.links if link.name == "finger").inertial.inertia
    moments = np.sort(model.body_inertia[finger_id])
    assert np.allclose(moments, np.linalg.eigvalsh(source_tensor), rtol=1e-9, atol=0)
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body_iquat[finger_id])
    axes = rotation.reshape(3, 3)
    rebuilt = axes @ np.diag(model.body_inertia[finger_id]) @ axes.T
    assert np.allclose(rebuilt, source_tensor, rtol=0, atol=1e-15)


def test_principal_axes_are_the_nearest_to_the_link_frame() -> None:
    """A tensor nearly diagonal gets axes near the identity (not eigh's ascending permutation), and the
    axes are a rotation whatever the input's order."""
    from modelkit.formats.mjcf.write_bodies import principal_axes_near_link

    tensor = np.array([[0.03, 0.0, 1e-4], [0.0, 0.01, 0.0], [1e-4, 0.0, 0.02]])
    moments, axes = principal_axes_near_link(tensor)
    assert np.allclose(axes @ np.diag(moments) @ axes.T, tensor, rtol=0, atol=1e-17)
    assert np.linalg.det(axes) == pytest.approx(1.0) and np.min(np.diag(axes)) > 0.99
    assert moments[1] == pytest.approx(0.01) and moments[0] > 0.03 > moments[2] > 0.0199


@pytest.mark.parametrize("relative", ["alex_description/urdf/alex_psyonic_hands.urdf",
                                      "icub_description/robots/icub_reduced.urdf",
                                      "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf"])
def test_example_robot_data_mjcf_has_no_sub_nanometre_number(relative: str, tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """Three example-robot-data robots whose sources write values under 1e-9 (iCub: offsets and angles;
    the Psyonic hands and Alexander: products of inertia beside small moments): the MJCF has no
    ``e-1x`` number (issue 17's check), loads in MuJoCo, and reads back as the same robot to 1e-9."""
    from tests.conftest import example_robot, example_robot_data

    source = example_robot(relative)
    assert re.search(r"e-1[0-9]", source.read_text(), re.IGNORECASE)  # the source has them
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(example_robot_data()))
    robot = validate(source).robot
    assert robot is not None
    out = tmp_path / "robot.xml"
    notes = write(robot, out)
    text = out.read_text()
    assert not re.search(r"e-1[0-9]", text), re.findall(r'\w+="[^"]*e-1[0-9][^"]*"', text)[:3]
    mujoco.MjModel.from_xml_path(str(out))
    back = validate(out).robot
    assert back is not None
    names = renames(notes, "link")
    assert compare_poses(robot, back, names, tol=1e-9) == []
    repaired = " ".join(n.message for n in notes if n.code in ("MK816", "MK819", "MK870"))  # said, not dust
    for link in robot.links:
        if link.inertial is None or link.inertial.mass <= 0.0 or re.search(rf"link {link.name}\b", repaired):
            continue
        other = next((b for b in back.links if b.name == names.get(link.name, link.name)), None)
        if other is not None and other.inertial is not None and other.inertial.mass == link.inertial.mass:
            assert np.allclose(other.inertial.inertia, link.inertial.inertia, rtol=0, atol=1e-9), link.name


SINGLE_PRECISION_MJCF = """<mujoco model="m">
  <asset><material name="paint" rgba="0.3 0.6 0.9 1" specular="0.35" shininess="0.7"/></asset>
  <worldbody>
    <light name="lamp" pos="0 0 2" diffuse="0.9 0.8 0.7" specular="0.2 0.2 0.2" attenuation="1 0.1 0.01"/>
    <light name="plain" pos="0 0 3"/>
    <body name="b" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" rgba="0.8 0.6 0.4 1" mass="1"/>
      <geom type="sphere" size="0.05" material="paint" mass="0.1" contype="0" conaffinity="0"/>
      <site name="s" rgba="0.1 0.2 0.3 1"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("target", TARGETS)
def test_single_precision_values_keep_the_sources_decimals(target: str, tmp_path: Path) -> None:
    """MuJoCo stores colours, lights and material terms in single precision: an MJCF source's ``0.8`` is
    read back as the float32 nearest it, which was written ``0.800000011920929`` (774 attributes in the
    MJCF written from 42 of Genesis's MJCF files). Each is now the shortest decimal that is that float32."""
    source = tmp_path / "m.xml"
    source.write_text(SINGLE_PRECISION_MJCF)
    out = tmp_path / "out" / f"m.{target}"
    write(validate(source).robot, out)  # type: ignore[arg-type]
    text = out.read_text()
    numbers = [n for n in NUMBER.findall(text) if "." in n]
    assert [n for n in numbers if DUST.search(n)] == []
    if target == "xml":
        assert 'rgba="0.8 0.6 0.4 1"' in text and 'diffuse="0.9 0.8 0.7"' in text
        assert 'specular="0.2 0.2 0.2"' in text and 'attenuation="1 0.1 0.01"' in text
        assert text.count("diffuse=") == 1  # the plain light's default colour is not written
        model = mujoco.MjModel.from_xml_path(str(out))
        original = mujoco.MjModel.from_xml_path(str(source))
        assert np.array_equal(model.light_diffuse, original.light_diffuse)
    elif target == "urdf":
        assert '<color rgba="0.3 0.6 0.9 1"/>' in text  # the material's colour



def test_small_values_lose_the_dust_of_larger_ones() -> None:
    """A small value computed from larger ones keeps their arithmetic's tail: iCub's (icub-models)
    ``1.38999999999695e-5`` m, a difference of two positions near 0.1 m, is 3e-17 m from ``1.39e-5``:
    2e-12 of the value (over fmt's 1e-12), but far below 1e-12 of the robot's size. A position is
    written with that size as its scale, a tensor's entry with its largest entry's; a value whose
    digits are real (a third, a 4 µrad rotation) keeps them."""
    from modelkit.convert.numbers import fmt_inertia, fmt_length, fmt_position, fmt_tensor

    assert fmt(1.38999999999695e-5) == "1.38999999999695e-5"  # fmt alone knows no scale
    assert fmt_length(1.38999999999695e-5) == "1.39e-5"
    assert fmt_position([-0.0009363, 1.38999999999695e-5, 8.09999999998312e-6]) == "-0.0009363 1.39e-5 8.1e-6"
    assert fmt_length(1 / 3 * 1e-5) == "3.33333333333333e-6"  # a value, not a decimal with a dusty tail
    with length_scale(1e-3):  # on a millimetre robot 3e-17 m is 3e-14 of its size: still dust
        assert fmt_length(1.38999999999695e-5) == "1.39e-5"
    with length_scale(1e-6):  # on a micrometre one it is 3e-11 of it: kept
        assert fmt_length(1.38999999999695e-5) == "1.38999999999695e-5"
    tensor = np.array([[3.03891e-4, 7.12496000000835e-8, 3.3401e-6],
                       [7.12496000000835e-8, 4.6914e-4, -4.76597e-8],
                       [3.3401e-6, -4.76597e-8, 2.77108e-4]])
    assert fmt_inertia(tensor[0, 1], tensor) == "7.12496e-8"
    assert fmt(tensor[0, 1]) == "7.12496000000835e-8"
    assert fmt_tensor([0.0100000187393413, 0.0100000000323507], np.eye(3) * 0.01) == (
        "0.0100000187393413 0.0100000000323507")  # 3e-9 of the tensor: a real difference of moments


ICUB_LIKE = """<robot name="dusty">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="hip"><inertial><origin xyz="-0.0009315 8.09999999998312e-6 -0.044809"/><mass value="0.413242"/>
    <inertia ixx="0.000303891" ixy="7.12496000000835e-8" ixz="3.3401e-6" iyy="0.00046914" iyz="-4.76597e-8"
             izz="0.000277108"/></inertial></link>
  <joint name="hip" type="revolute"><parent link="base"/><child link="hip"/>
    <origin xyz="-0.0009363 1.38999999999695e-5 -0.0743"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


@pytest.mark.parametrize("target", ["xml", "urdf", "sdf", "body"])
def test_every_writer_drops_the_dust_of_small_values(target: str, tmp_path: Path) -> None:
    """The numbers above, as a URDF holds them after another tool's arithmetic: every target writes the
    short decimals, and reads back equal to 1e-9."""
    source = tmp_path / "dusty.urdf"
    source.write_text(ICUB_LIKE)
    robot = validate(source).robot
    assert robot is not None
    out = tmp_path / target / f"robot.{target}"
    notes = write(robot, out)
    text = out.read_text()
    for dusty in ("1.38999999999695", "8.09999999998312", "7.12496000000835"):
        assert dusty not in text, (target, dusty)
    assert "1.39e-5" in text or "1.39e-05" in text
    back = validate(out).robot
    assert back is not None
    assert compare_poses(robot, back, renames(notes, "link"), tol=1e-9) == []


def test_a_tensor_turned_by_a_short_pi_over_2_loses_its_product_dust(tmp_path: Path) -> None:
    """gym-ignition's cart-pole turns its pole's inertia by ``rpy="1.57079632679 0 0"``: π/2 to 11
    decimals, 4.9e-12 rad short. The turned tensor has a product of 5.1e-11 kg·m² beside moments of
    10.4: 4.9e-12 of its largest, no measurement, and it was written (``fullinertia="...
    5.10059809416233e-11"``).
    Entries below 1e-10 of the tensor's largest are 0, as lengths and rotations below 1e-10 are; the
    written file keeps the moments, and the read-back equals the source to 1e-10 of the tensor."""
    from modelkit.convert.numbers import clean_inertia

    a = 1.57079632679
    turn = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(a), -np.sin(a)], [0.0, np.sin(a), np.cos(a)]])
    pole = turn @ np.diag([10.4166979167, 10.4166979167, 6.25e-05]) @ turn.T
    assert 4e-11 < abs(pole[1, 2]) < 6e-11
    cleaned = clean_inertia(pole, 10.0)
    assert cleaned[1, 2] == cleaned[2, 1] == 0.0
    assert np.max(np.abs(cleaned - pole)) <= 1e-10 * np.max(np.abs(pole))
    source = tmp_path / "cartpole.urdf"
    source.write_text("""<robot name="cartpole">
  <link name="rail"><inertial><mass value="10"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="pole"><inertial><origin rpy="1.57079632679 0 0" xyz="0 0 0.5"/><mass value="10"/>
    <inertia ixx="10.4166979167" ixy="0" ixz="0" iyy="10.4166979167" iyz="0" izz="6.25e-05"/>
  </inertial></link>
  <joint name="hinge" type="continuous"><parent link="rail"/><child link="pole"/><axis xyz="1 0 0"/></joint>
</robot>
""")
    for suffix in (".xml", ".urdf", ".sdf", ".body"):
        out = tmp_path / f"out{suffix}"
        notes = write(load(source), out, options=WriteOptions(), force=True)
        assert not [n for n in notes if n.severity.value == "error"], suffix
        assert not re.search(r"e-1\d", out.read_text()), suffix
