"""A flat collision mesh (all its vertices in one plane: Hello Robot Stretch RE1's ArUco marker plates)
has no convex hull, which MuJoCo collides with. The MJCF writer writes it as a thin box spanning the
plane (MK881, a warning); before, it was left out with an error (MK805) and ``convert`` exited 1.
``verify`` compares MuJoCo's box with the box recomputed from the source mesh."""

from __future__ import annotations

import struct
from pathlib import Path

import mujoco
import numpy as np

from modelkit.convert.api import convert
from modelkit.convert.meshes import plate_of
from modelkit.verify.api import verify


def _square_stl(side: float, turn: float) -> bytes:
    """A square plate of ``side`` m in the mesh's XY plane (exactly: z = 0), turned by ``turn`` rad in
    it; the URDF turns the plane itself."""
    corners = np.array([[0, 0, 0], [side, 0, 0], [0, side, 0], [side, side, 0]]) @ _rz(turn).T
    faces = [(0, 1, 2), (1, 3, 2)]
    records = b"".join(struct.pack("<12fH", 0.0, 0.0, 1.0, *corners[a], *corners[b], *corners[d], 0)
                       for a, b, d in faces)
    return b"plate".ljust(80, b" ") + struct.pack("<I", len(faces)) + records


URDF = """<robot name="marker">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0"
    iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="aruco"><inertial><mass value="0.01"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0.1 0.05" rpy="0.7 0 0.5"/><geometry><mesh filename="plate.stl"/></geometry>
    </visual>
    <collision><origin xyz="0 0.1 0.05" rpy="0.7 0 0.5"/><geometry><mesh filename="plate.stl"/></geometry>
    </collision></link>
  <joint name="mount" type="fixed"><parent link="base"/><child link="aruco"/><origin xyz="0.1 0 0"/></joint>
</robot>"""


def _source(tmp_path: Path) -> Path:
    (tmp_path / "plate.stl").write_bytes(_square_stl(0.06, 0.3))
    source = tmp_path / "marker.urdf"
    source.write_text(URDF)
    return source


def test_a_flat_collision_mesh_is_a_thin_box_in_its_plane(tmp_path: Path) -> None:
    out = tmp_path / "out" / "marker.xml"
    result = convert([_source(tmp_path)], out)
    said = [n for n in result.notes if n.code == "MK881"]
    assert len(said) == 1 and "plate.stl is flat" in said[0].message
    assert "0.06 × 0.06 × 0.001 m" in said[0].message
    assert not [n for n in result.notes if n.code == "MK805"]
    model = mujoco.MjModel.from_xml_path(str(out))
    boxes = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
             and np.allclose(model.geom_size[g], [0.03, 0.03, 0.0005], atol=1e-8)]
    assert len(boxes) == 1
    # the box holds the square: its four corners lie on the box's face plane, inside it
    mujoco.mj_forward(model, data := mujoco.MjData(model))
    g = boxes[0]
    local = np.array([[0, 0, 0], [0.06, 0, 0], [0, 0.06, 0], [0.06, 0.06, 0]]) @ _rz(0.3).T
    rpy = _rz(0.5) @ _rx(0.7)  # URDF rpy: Rz(yaw)·Ry(pitch)·Rx(roll)
    body = int(model.geom_bodyid[g])
    in_link = np.array([0, 0.1, 0.05]) + local @ rpy.T
    world = in_link @ data.xmat[body].reshape(3, 3).T + data.xpos[body]
    in_box = (world - data.geom_xpos[g]) @ data.geom_xmat[g].reshape(3, 3)
    # to the STL's single precision, to which the box is written: 4 float32 ulps of the plate's 0.06 m
    assert np.all(np.abs(in_box) <= model.geom_size[g] + 4 * np.finfo(np.float32).eps * 0.06), in_box


def _rx(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_verify_compares_the_box_with_the_source_plate(tmp_path: Path) -> None:
    source = _source(tmp_path)
    report = verify(source, tmp_path / "out", ("mujoco", "pybullet"), configurations=1, samples=1,
                    replay=False, driven=False)
    assert report.failed == [], [c.detail for c in report.failed]
    said = [s.reason for s in report.skips if s.engine == "mujoco" and "MK881" in s.reason]
    assert said and "aruco" in said[0]
    # a box written wrong in a given MJCF (its plate 10 % larger) fails shape-size on that link
    given = tmp_path / "given" / "marker.xml"
    convert([source], given)
    text = given.read_text()
    assert 'type="box" size="0.03 0.03 0.0005"' in text  # no float32 dust (0.0300000014376254 before)
    wrong = text.replace('size="0.03 0.03 0.0005"', 'size="0.033 0.033 0.0005"')
    assert wrong != text
    given.write_text(wrong)
    faulty = verify(source, tmp_path / "out2", ("mujoco",), mjcf=given, configurations=1, samples=1,
                    replay=False, driven=False)
    failed = {(c.layer, c.quantity): c for c in faulty.failed}
    assert (1, "shape-size") in failed and failed[(1, "shape-size")].where == "aruco", sorted(failed)


def test_a_square_gives_its_own_square_whatever_its_principal_axes() -> None:
    """A square's two in-plane principal axes are any pair: the box is the smallest rectangle, not one
    along them (a diagonal pair gave a box turned by 45°, 41 % wider)."""
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)[[0, 1, 2, 1, 3, 2]]
    plate = plate_of(corners.reshape(-1, 3, 3))
    assert np.allclose(sorted(plate.size), [0.001, 1.0, 1.0])
    assert np.allclose(plate.centre, [0.5, 0.5, 0.0])
