"""Roll-pitch-yaw angles near ±π keep their source's text: iCub (example-robot-data) turns its shank
meshes by ``rpy="-1.5708 3.1416 -1.5708"``, a pitch 7.3e-6 past π. Wrapped to (−π, π] it was written
as ``-3.14158530717959``; a whole turn more about one axis is the same matrix, so the source's own
``3.1416`` is written, and every target still reads the source's matrix."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from modelkit.api import validate
from modelkit.convert.api import write
from modelkit.convert.numbers import SNAP, fmt_rpy
from modelkit.spatial import matrix_from_rpy

ICUB_SHANK = (-1.5708, 3.1416, -1.5708)


def _back(text: str) -> np.ndarray:
    return matrix_from_rpy(*(float(v) for v in text.split()))


@pytest.mark.parametrize(("rpy", "text"), [
    (ICUB_SHANK, "-1.5708 3.1416 -1.5708"),
    ((3.1416, 0.0, 0.0), "3.1416 0 0"),
    ((-3.1416, 0.0, 0.0), "-3.1416 0 0"),
    ((0.0, 1.5708, -3.1416), "0 1.5708 -3.1416"),
    ((3.2, 0.1, -3.2), "3.2 0.1 -3.2"),
    ((0.1, 0.2, 0.3), "0.1 0.2 0.3"),  # away from ±π: as before
    ((0.0, 1.5707963268, 0.0), "0 1.5707963268 0"),  # Spirit40: the other triple, as before
])
def test_angles_past_pi_come_back_as_written(rpy: tuple[float, float, float], text: str) -> None:
    assert fmt_rpy(matrix_from_rpy(*rpy)) == text
    assert float(np.max(np.abs(_back(text) - matrix_from_rpy(*rpy)))) <= SNAP


@pytest.mark.parametrize(("rpy", "text"), [
    ((0.0, 0.0, -2.02458193231342), "0 0 -2.02458193231342"),  # not 4.25860337486616: a sign shorter only
    ((-1.5707963267949, 0.0, -0.523598775598299), "-1.5707963267949 0 -0.523598775598299"),  # "0." only
    ((0.0, 0.0, -math.pi), "0 0 -3.14159265358979"),
    # dm_control's quadruped: the other triple's pitch −5.8889409321148 is a 14-digit decimal by chance
    ((0.982793723247329, 2.74734827852501, -2.55359005004223),
     "0.982793723247329 2.74734827852501 -2.55359005004223"),
])
def test_a_turn_is_taken_only_for_fewer_digits(rpy: tuple[float, float, float], text: str) -> None:
    """The texts of before stay where a turned angle saves no significant digit (pybullet_data's and
    dm_control's robots have such angles)."""
    assert fmt_rpy(matrix_from_rpy(*rpy)) == text


def test_ties_keep_angles_in_the_usual_range() -> None:
    """π itself: ``3.14159265358979`` and ``-3.14159265358979`` are as long; the one in (−π, π] is
    written, as before the turned angles were considered."""
    assert fmt_rpy(matrix_from_rpy(math.pi, 0.0, 0.0)) == "3.14159265358979 0 0"
    assert fmt_rpy(np.eye(3)) == "0 0 0"


def test_every_text_gives_the_matrix_back() -> None:
    angles = (-3.1416, -3.14159, -2.0, -1.5708, 0.0, 0.7, 1.5707963268, 3.1416, 3.2, -3.2)
    for rpy in itertools.product(angles, repeat=3):
        rotation = matrix_from_rpy(*rpy)
        text = fmt_rpy(rotation)
        assert float(np.max(np.abs(_back(text) - rotation))) <= SNAP, (rpy, text)
        assert all(abs(float(v)) < 2.0 * math.pi for v in text.split()), (rpy, text)


def _source(tmp_path: Path) -> Path:
    source = tmp_path / "shank.urdf"
    source.write_text(f"""<robot name="shank">
  <link name="thigh"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="shank"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/>
    <origin xyz="0 0 -0.2" rpy="{' '.join(str(a) for a in ICUB_SHANK)}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
""")
    return source


def test_every_target_keeps_the_text_and_the_matrix(tmp_path: Path) -> None:
    robot = validate(_source(tmp_path)).robot
    assert robot is not None
    expected = matrix_from_rpy(*ICUB_SHANK)
    for suffix, text in ((".urdf", 'rpy="-1.5708 3.1416 -1.5708"'), (".sdf", "-0.2 -1.5708 3.1416 -1.5708"),
                         (".xml", 'euler="-1.5708 3.1416 -1.5708"')):
        out = tmp_path / suffix[1:] / f"shank{suffix}"
        out.parent.mkdir()
        write(robot, out)
        assert text in out.read_text(), (suffix, out.read_text())
        if suffix == ".xml":  # what MuJoCo compiles: the shank's world rotation at q = 0
            model = mujoco.MjModel.from_xml_path(str(out))
            data = mujoco.MjData(model)
            mujoco.mj_kinematics(model, data)
            thigh = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "thigh")
            shank = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "shank")
            relative = data.xmat[thigh].reshape(3, 3).T @ data.xmat[shank].reshape(3, 3)
            assert np.allclose(relative, expected, rtol=0.0, atol=1e-9), relative
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, expected.ravel())
            relative_quat = np.zeros(4)
            mujoco.mju_mulQuat(relative_quat, _conjugate(data.xquat[thigh]), data.xquat[shank])
            assert min(np.max(np.abs(relative_quat - quat)), np.max(np.abs(relative_quat + quat))) <= 1e-9
        else:  # what the target's reader reads: the knee's origin
            back = validate(out).robot
            assert back is not None
            knee = next(j for j in back.joints if j.name == "knee")
            assert np.allclose(knee.origin.rotation, expected, rtol=0.0, atol=1e-9), (suffix, knee.origin)


def _conjugate(q: np.ndarray) -> np.ndarray:
    return np.array([q[0], -q[1], -q[2], -q[3]])
