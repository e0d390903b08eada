"""The PyBullet adapter (in its child process) and layer 3b's replay, against the real engines.

The tutorial pan-tilt robot is converted with its root welded; PyBullet's facts are compared with
the source model, its dynamics with MuJoCo's own ``mj_fullM``/``qfrc_bias`` on the written MJCF,
and the replay with MuJoCo's (``engine_mujoco.simulator``).
"""

from __future__ import annotations

import math
import os
import re
import signal
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pybullet")
mujoco = pytest.importorskip("mujoco")

import modelkit  # noqa: E402
from modelkit.convert import write  # noqa: E402
from modelkit.convert.compare import random_configuration  # noqa: E402
from modelkit.convert.notes import renames  # noqa: E402
from modelkit.convert.options import WriteOptions  # noqa: E402
from modelkit.model import JointType, Robot  # noqa: E402
from modelkit.verify.engines import pybullet as engine_pybullet  # noqa: E402
from modelkit.verify.engines.pybullet import PyBulletError, PyBulletModel  # noqa: E402
from modelkit.verify.layers.replay import TOLERANCE, default_law, layer3b  # noqa: E402

from .conftest import TUTORIAL  # noqa: E402

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"

ROTATED = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><origin xyz="0.1 0.2 0.3" rpy="0.3 0.2 0.1"/><mass value="2"/>
    <inertia ixx="0.1" ixy="0.01" ixz="0.02" iyy="0.2" iyz="0.03" izz="0.25"/></inertial></link>
  <link name="a"><inertial><origin xyz="0.05 -0.1 0.2" rpy="0.5 -0.4 1.1"/><mass value="1.5"/>
    <inertia ixx="0.05" ixy="0.004" ixz="-0.003" iyy="0.06" iyz="0.002" izz="0.07"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0.1 0.05" rpy="-0.2 0.7 0.3"/><mass value="0.7"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>
  <joint name="j1" type="revolute"><origin xyz="0.1 0 0.4" rpy="0.1 0.2 0.3"/>
    <parent link="base"/><child link="a"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-1" upper="1.5" effort="10" velocity="5"/></joint>
  <joint name="j2" type="prismatic"><origin xyz="0 0.3 0.1" rpy="0.4 0 -0.2"/>
    <parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <limit lower="-0.2" upper="0.3" effort="10" velocity="5"/></joint>
</robot>
"""


class Converted:
    def __init__(self, robot: Robot, urdf: Path, mjcf: Path, urdf_renames: dict[str, dict[str, str]],
                 mjcf_renames: dict[str, dict[str, str]]) -> None:
        self.robot, self.urdf, self.mjcf = robot, urdf, mjcf
        self.urdf_renames, self.mjcf_renames = urdf_renames, mjcf_renames

    def written(self, kind: str, name: str) -> str:
        return self.urdf_renames[kind].get(name, name)


# As verify writes the engines' files: the root is PyBullet's base, welded by the engine (no `world` link).
ENGINE_FILE = WriteOptions(urdf_world_link=False)


@pytest.fixture(scope="module")
def pantilt(tmp_path_factory: pytest.TempPathFactory) -> Converted:
    robot = modelkit.load(PANTILT)
    robot.root_joint = JointType.FIXED
    out = tmp_path_factory.mktemp("pantilt")
    urdf_notes = write(robot, out / "x.urdf", options=ENGINE_FILE)
    mjcf_notes = write(robot, out / "x.xml")
    maps = [{"link": renames(n, "link"), "joint": renames(n, "joint")} for n in (urdf_notes, mjcf_notes)]
    return Converted(robot, out / "x.urdf", out / "x.xml", maps[0], maps[1])


@pytest.fixture(scope="module")
def pb(pantilt: Converted) -> Any:
    model = engine_pybullet.load(pantilt.urdf, pantilt.urdf_renames, root=str(pantilt.robot.root))
    yield model
    model.close()


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / max(1.0, float(np.max(np.abs(b))))


def _relative_to_root(robot: Robot, q: dict[str, float]) -> dict[str, Any]:
    poses = robot.world_poses(q)
    base = poses[str(robot.root)].inverse()
    return {k: base @ v for k, v in poses.items()}


# ---- static facts ---------------------------------------------------------------------------------


def _static_errors(model: PyBulletModel, robot: Robot, link_map: dict[str, str],
                   joint_map: dict[str, str]) -> dict[str, float]:
    facts = model.static()
    assert set(facts.links) == {link_map.get(link.name, link.name) for link in robot.links}
    assert set(facts.joints) == {joint_map.get(j.name, j.name) for j in robot.joints}
    err = {"mass": 0.0, "com": 0.0, "inertia": 0.0, "axis": 0.0, "limits": 0.0}
    for link in robot.links:
        got = facts.links[link_map.get(link.name, link.name)]
        assert link.inertial is not None
        err["mass"] = max(err["mass"], abs(got.mass - link.inertial.mass) / max(1.0, link.inertial.mass))
        err["com"] = max(err["com"], _rel(got.com, link.inertial.com))
        err["inertia"] = max(err["inertia"], float(np.max(np.abs(got.inertia - link.inertial.inertia)))
                             / float(np.max(np.abs(link.inertial.inertia))))
    for joint in robot.joints:
        got_j = facts.joints[joint_map.get(joint.name, joint.name)]
        assert got_j.type == joint.type.value
        assert got_j.parent == link_map.get(joint.parent, joint.parent)
        assert got_j.child == link_map.get(joint.child, joint.child)
        axis = np.asarray(joint.axis, dtype=float) / float(np.linalg.norm(joint.axis))
        err["axis"] = max(err["axis"], float(np.max(np.abs(got_j.axis - axis))))
        for a, b in ((got_j.lower, joint.limits.lower), (got_j.upper, joint.limits.upper)):
            assert math.isfinite(a) == math.isfinite(b)
            if math.isfinite(b):
                err["limits"] = max(err["limits"], abs(a - b))
    return err


def test_static_facts_equal_the_source(pantilt: Converted, pb: Any) -> None:
    err = _static_errors(pb, pantilt.robot, pantilt.urdf_renames["link"], pantilt.urdf_renames["joint"])
    # Diagonal inertias, unrotated inertial frames: every figure is exact or at round-off.
    assert max(err.values()) <= 1e-12, err
    assert pb.static().links[str(pantilt.robot.root)].mass == 14.0  # the fixed base is not massless
    assert pb.dof_names() == [pantilt.written("joint", j) for j in
                              ("LeftWheel", "RightWheel", "PanJoint", "TiltJoint")]


def test_rotated_inertial_frames_and_products_of_inertia(tmp_path: Path) -> None:
    """PyBullet diagonalises the inertia into a rotated inertial frame and keeps joint axes in it:
    both are rotated back into link axes (verification.md: 1e-6 on PyBullet's float32 paths)."""
    path = tmp_path / "rot.urdf"
    path.write_text(ROTATED)
    robot = modelkit.load(path)
    with engine_pybullet.load(path, {}, root="base") as model:
        err = _static_errors(model, robot, {}, {})
        assert max(err.values()) <= 1e-6, err
        rng = np.random.default_rng(3)
        for _ in range(5):
            q = random_configuration(robot, rng)
            ref = _relative_to_root(robot, q)
            got = model.link_poses(q)
            for name, pose in ref.items():
                assert np.max(np.abs(got[name].translation - pose.translation)) <= 1e-12
                assert np.max(np.abs(got[name].rotation - pose.rotation)) <= 1e-12


# ---- kinematics -----------------------------------------------------------------------------------


@pytest.mark.parametrize(("pose_path", "tolerance"), [("com-frame", 1e-12), ("link-frame", 1e-6)])
def test_link_poses_at_random_configurations(pantilt: Converted, pose_path: str, tolerance: float) -> None:
    robot = pantilt.robot
    rng = np.random.default_rng(0)
    with engine_pybullet.load(pantilt.urdf, pantilt.urdf_renames, root=str(robot.root),
                              pose_path=pose_path) as model:
        assert model.settings["pose_path"] == pose_path
        worst = 0.0
        for i in range(20):
            q = {} if i == 0 else random_configuration(robot, rng)
            q_written = {pantilt.written("joint", k): v for k, v in q.items()}
            got = model.link_poses(q_written)
            for name, pose in _relative_to_root(robot, q).items():
                other = got[pantilt.written("link", name)]
                worst = max(worst, float(np.max(np.abs(other.translation - pose.translation))),
                            float(np.max(np.abs(other.rotation - pose.rotation))))
    assert worst <= tolerance
    if pose_path == "link-frame":
        assert worst > 0.0  # the float32 path really is float32: the double path is the better one


# ---- dynamics against MuJoCo ----------------------------------------------------------------------


def _mujoco_dynamics(mjcf: Path, q: dict[str, float], dq: dict[str, float],
                     order: list[str]) -> tuple[np.ndarray, np.ndarray]:
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    model.opt.gravity[:] = (0.0, 0.0, -9.81)
    data = mujoco.MjData(model)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in order]
    for j in ids:
        data.qpos[model.jnt_qposadr[j]] = q.get(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j), 0.0)
        data.qvel[model.jnt_dofadr[j]] = dq.get(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j), 0.0)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    dofs = [model.jnt_dofadr[j] for j in ids]
    return full[np.ix_(dofs, dofs)], data.qfrc_bias[dofs].copy()


def test_mass_matrix_and_bias_match_mujoco(pantilt: Converted, pb: Any) -> None:
    robot = pantilt.robot
    source_order = [j.name for j in robot.joints if j.type is JointType.REVOLUTE]
    assert [pantilt.written("joint", j) for j in source_order] == pb.dof_names()
    rng = np.random.default_rng(1)
    worst_m = worst_b = 0.0
    for _ in range(20):
        q = random_configuration(robot, rng)
        dq = {k: float(rng.uniform(-3.0, 3.0)) for k in q}
        m_ref, b_ref = _mujoco_dynamics(pantilt.mjcf, q, dq, source_order)
        m = pb.mass_matrix({pantilt.written("joint", k): v for k, v in q.items()})
        b = pb.bias({pantilt.written("joint", k): v for k, v in q.items()},
                    {pantilt.written("joint", k): v for k, v in dq.items()})
        worst_m = max(worst_m, float(np.max(np.abs(m - m_ref))) / float(np.max(np.abs(m_ref))))
        worst_b = max(worst_b, float(np.max(np.abs(b - b_ref))) / max(1.0, float(np.max(np.abs(b_ref)))))
    assert worst_m <= 1e-9
    assert worst_b <= 1e-9


# ---- layer 3b: the replay -------------------------------------------------------------------------


def _replay(pantilt: Converted, urdf: Path) -> Any:
    from modelkit.verify.engines import mujoco as engine_mujoco

    root = str(pantilt.robot.root)
    mj = engine_mujoco.simulator(pantilt.mjcf, pantilt.mjcf_renames, root=root, dt=1e-3)
    pbs = engine_pybullet.simulator(urdf, pantilt.urdf_renames, root=root, dt=1e-3)
    try:
        return layer3b(pantilt.robot, [mj, pbs], default_law(pantilt.robot), 10.0, 1e-3)
    finally:
        mj.close()
        pbs.close()


def test_default_law_is_well_conditioned(pantilt: Converted) -> None:
    law = default_law(pantilt.robot)
    assert law.joints == ("LeftWheel", "RightWheel", "PanJoint", "TiltJoint")
    assert all(k > 0 for k in law.kp) and all(d > 0 for d in law.kd)
    assert all(0 < a <= 1.0 for a in law.amplitude)
    assert len(set(law.frequency)) == len(law.frequency)


def test_default_law_respects_limits(tmp_path: Path) -> None:
    path = tmp_path / "rot.urdf"
    path.write_text(ROTATED)
    law = default_law(modelkit.load(path))
    assert law.joints == ("j1", "j2")
    assert law.amplitude == pytest.approx((0.5, 0.1))  # half the way to the nearer limit


def test_replay_agrees_with_mujoco(pantilt: Converted) -> None:
    checks, skips = _replay(pantilt, pantilt.urdf)
    assert not skips
    (check,) = checks
    assert (check.layer, check.engine, check.quantity) == (3, "pybullet", "replay")
    assert check.tolerance == TOLERANCE == 1e-8
    assert check.passed, check
    assert check.error <= 1e-12, check  # measured ~6e-16 rad
    assert "travel" in check.detail


def _edit_inertial(urdf: Path, link: str, attribute: str, factor: float, suffix: str) -> Path:
    """A copy of ``urdf`` (beside it: same meshes/) with one inertial number scaled, as a buggy
    converter would write it."""
    text = urdf.read_text()
    found = re.search(rf'<link name="{link}">.*?{attribute}="([^"]+)"', text, re.S)
    assert found is not None
    start, end = found.span(1)
    out = urdf.with_name(f"{urdf.stem}_{suffix}.urdf")
    out.write_text(text[:start] + repr(float(found.group(1)) * factor) + text[end:])
    return out


def test_replay_catches_a_one_percent_inertia_error(pantilt: Converted) -> None:
    checks, _ = _replay(pantilt, _edit_inertial(pantilt.urdf, "TiltLink", "iyy", 1.01, "iyy1pct"))
    (check,) = checks
    assert not check.passed, check
    assert check.error > 1e3 * TOLERANCE
    assert check.where == "TiltJoint"


def test_pantilt_masses_are_invisible_to_the_replay(pantilt: Converted) -> None:
    """Every moving link of the pan-tilt robot has its COM on its own joint axis and on the axes of
    the joints that carry it, and the chassis is welded: no mass enters the fixed-base dynamics, so
    a 1 % mass error is layer 1's to catch, not the replay's (the replay still agrees to round-off)."""
    checks, _ = _replay(pantilt, _edit_inertial(pantilt.urdf, "TiltLink", "mass value", 1.01, "mass1pct"))
    (check,) = checks
    assert check.passed and check.error <= 1e-12, check


def test_replay_catches_a_one_percent_mass_error(tmp_path: Path) -> None:
    """On a robot whose COMs sit off the joint axes, 1 % of one link's mass fails the replay."""
    src = tmp_path / "src.urdf"
    src.write_text(ROTATED)
    robot = modelkit.load(src)
    robot.root_joint = JointType.FIXED
    out = tmp_path / "out"
    out.mkdir()
    urdf_notes, mjcf_notes = write(robot, out / "r.urdf", options=ENGINE_FILE), write(robot, out / "r.xml")
    maps = [{"link": renames(n, "link"), "joint": renames(n, "joint")} for n in (urdf_notes, mjcf_notes)]
    converted = Converted(robot, out / "r.urdf", out / "r.xml", maps[0], maps[1])
    (good,), _ = _replay(converted, converted.urdf)
    assert good.passed and good.error <= 1e-12, good
    (bad,), _ = _replay(converted, _edit_inertial(converted.urdf, "b", "mass value", 1.01, "mass1pct"))
    assert not bad.passed, bad
    assert bad.error > 1e3 * TOLERANCE


# ---- a URDF PyBullet refuses or crashes on: a clear error, never a hang -----------------------------


def test_refused_urdf_is_a_clear_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'><inertial><mass value='1'/></inertial></link>"
                   "<joint name='j' type='revolute'><parent link='a'/><child link='missing'/>"
                   "</joint></robot>")
    with pytest.raises(PyBulletError, match="PyBullet load failed"):
        engine_pybullet.load(bad, {}, root="a", timeout=30.0)
    with pytest.raises(PyBulletError, match="load failed"):
        engine_pybullet.load(tmp_path / "absent.urdf", {}, root="a", timeout=30.0)


def test_crashed_child_is_a_clear_error(pantilt: Converted) -> None:
    model = engine_pybullet.load(pantilt.urdf, pantilt.urdf_renames, root=str(pantilt.robot.root))
    try:
        os.kill(model._worker.proc.pid, signal.SIGSEGV)
        with pytest.raises(PyBulletError, match=r"died during mass_matrix .*signal 11"):
            model.mass_matrix({})
    finally:
        model.close()


def test_hung_child_times_out_and_is_killed(pantilt: Converted) -> None:
    model = engine_pybullet.simulator(pantilt.urdf, pantilt.urdf_renames, root=str(pantilt.robot.root),
                                      dt=1e-3)
    try:
        with pytest.raises(PyBulletError, match="did not answer replay within the timeout"):
            model._worker.request("replay", timeout=0.2, steps=10_000_000, dt=1e-3,
                                  **model.law_vectors(default_law(pantilt.robot)))
        assert model._worker.proc.poll() is not None
    finally:
        model.close()
