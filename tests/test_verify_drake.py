"""The Drake adapter against the source model and MuJoCo, on real files (no mocks).

The tutorial pan-tilt robot (root welded) and PA10 are written as SDF, URDF and MJCF with
``modelkit.convert.write``; Drake reads the SDF (engine "drake") and the URDF ("drake-urdf").
Static facts must equal the source model's, link poses ``Robot.world_poses``, and the mass matrix
and bias forces MuJoCo's ``mj_fullM`` / ``qfrc_bias`` on the written MJCF, all at 1e-9.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pydrake", reason="Drake is an optional extra: pip install modelkit[drake]")

import mujoco

import modelkit
from modelkit.convert import write
from modelkit.convert.compare import random_configuration
from modelkit.convert.notes import renames
from modelkit.model import JointType, Robot
from modelkit.verify.engines import drake as engine_drake
from modelkit.verify.engines.mujoco import load as load_mujoco
from tests.conftest import CORPUS, TUTORIAL

TOL = 1e-9
PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
PA10 = CORPUS / "choreonoid" / "share" / "model" / "PA10" / "PA10.body"


@dataclass
class Written:
    robot: Robot
    files: dict[str, Path]  # "sdf", "urdf", "mjcf"
    renames: dict[str, dict[str, dict[str, str]]]  # format -> {"link": ..., "joint": ...}


def _write(source: Path, out: Path) -> Written:
    if not source.is_file():
        pytest.skip(f"{source} not available")
    robot = copy.deepcopy(modelkit.load(source))
    robot.root_joint = JointType.FIXED  # layers 1-3 weld the base
    files: dict[str, Path] = {}
    maps: dict[str, dict[str, dict[str, str]]] = {}
    for fmt_name, name in (("sdf", "x.sdf"), ("urdf", "x.urdf"), ("mjcf", "x.xml")):
        notes = write(robot, out / name)
        files[fmt_name] = out / name
        maps[fmt_name] = {"link": renames(notes, "link"), "joint": renames(notes, "joint")}
    return Written(robot, files, maps)


@pytest.fixture(scope="module", params=["pantilt", "pa10"])
def written(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Written:
    source = PANTILT if request.param == "pantilt" else PA10
    return _write(source, tmp_path_factory.mktemp(request.param))


def _load(w: Written, fmt_name: str) -> engine_drake.DrakeModel:
    root = w.renames[fmt_name]["link"].get(str(w.robot.root), str(w.robot.root))
    return engine_drake.load(w.files[fmt_name], w.renames[fmt_name], root=root)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    scale = max(float(np.max(np.abs(b))), 1e-300)
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / scale


@pytest.mark.parametrize("fmt_name", ["sdf", "urdf"])
def test_static_facts_equal_the_source(written: Written, fmt_name: str) -> None:
    model = _load(written, fmt_name)
    assert model.engine == ("drake" if fmt_name == "sdf" else "drake-urdf")
    facts = model.static()
    links, joints = written.renames[fmt_name]["link"], written.renames[fmt_name]["joint"]
    assert set(facts.links) == {links.get(link.name, link.name) for link in written.robot.links}
    worst = 0.0
    for link in written.robot.links:
        assert link.inertial is not None
        got = facts.links[links.get(link.name, link.name)]
        worst = max(worst, abs(got.mass - link.inertial.mass) / link.inertial.mass,
                    float(np.max(np.abs(got.com - link.inertial.com))),
                    _rel(got.inertia, link.inertial.inertia))
    assert worst <= TOL
    assert set(facts.joints) == {joints.get(j.name, j.name) for j in written.robot.joints}
    for joint in written.robot.joints:
        got_j = facts.joints[joints.get(joint.name, joint.name)]
        assert got_j.type == joint.type.value
        assert (got_j.parent, got_j.child) == (links.get(joint.parent, joint.parent),
                                               links.get(joint.child, joint.child))
        assert np.max(np.abs(got_j.axis - joint.axis)) <= TOL
        for a, b in ((got_j.lower, joint.limits.lower), (got_j.upper, joint.limits.upper)):
            assert (a == b) if math.isinf(b) else abs(a - b) <= TOL * max(1.0, abs(b))
    assert model.dof_names() == [joints.get(j.name, j.name) for j in written.robot.joints
                                 if j.type in (JointType.REVOLUTE, JointType.PRISMATIC)]


@pytest.mark.parametrize("fmt_name", ["sdf", "urdf"])
def test_link_poses_equal_the_source_fk(written: Written, fmt_name: str) -> None:
    model = _load(written, fmt_name)
    links, joints = written.renames[fmt_name]["link"], written.renames[fmt_name]["joint"]
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(50):
        q = random_configuration(written.robot, rng)
        expected = written.robot.world_poses(q)
        root = expected[str(written.robot.root)].inverse()
        got = model.link_poses({joints.get(k, k): v for k, v in q.items()})
        for name, pose in expected.items():
            rel = root @ pose
            mine = got[links.get(name, name)]
            worst = max(worst, float(np.max(np.abs(mine.translation - rel.translation))),
                        float(np.max(np.abs(mine.rotation - rel.rotation))))
    assert worst <= TOL


@pytest.mark.parametrize("fmt_name", ["sdf", "urdf"])
def test_mass_matrix_and_bias_equal_mujoco(written: Written, fmt_name: str) -> None:
    model = _load(written, fmt_name)
    root = str(written.robot.root)
    mj = load_mujoco(written.files["mjcf"], written.renames["mjcf"],
                     root=written.renames["mjcf"]["link"].get(root, root))
    dj, mjj = written.renames[fmt_name]["joint"], written.renames["mjcf"]["joint"]
    moving = (JointType.REVOLUTE, JointType.PRISMATIC)
    source_dofs = [j.name for j in written.robot.joints if j.type in moving]
    d_idx = [model.dof_names().index(dj.get(n, n)) for n in source_dofs]
    m_idx = [mj.dof_names().index(mjj.get(n, n)) for n in source_dofs]
    # SDF and URDF have no armature field (the writers drop it with MK820): PA10's rotor inertias
    # are on MuJoCo's diagonal only. Compare with MuJoCo's M without them, and check they are there.
    armature = np.diag([float(mj.model.dof_armature[mj.model.joint(mj.dof_names()[i]).dofadr[0]])
                        for i in m_idx])
    source_armature = np.diag([j.armature for j in written.robot.joints
                               if j.type in (JointType.REVOLUTE, JointType.PRISMATIC)])
    assert np.array_equal(armature, source_armature)
    rng = np.random.default_rng(11)
    worst_m = worst_b = 0.0
    gravity_seen = 0.0
    for _ in range(30):
        q = random_configuration(written.robot, rng)
        dq = {n: float(rng.uniform(-2.0, 2.0)) for n in source_dofs}
        qd, qm = {dj.get(k, k): v for k, v in q.items()}, {mjj.get(k, k): v for k, v in q.items()}
        dqd, dqm = {dj.get(k, k): v for k, v in dq.items()}, {mjj.get(k, k): v for k, v in dq.items()}
        md = model.mass_matrix(qd)[np.ix_(d_idx, d_idx)]
        mm = mj.mass_matrix(qm)[np.ix_(m_idx, m_idx)] - armature
        worst_m = max(worst_m, _rel(md, mm))
        bd, bm = model.bias(qd, dqd)[d_idx], mj.bias(qm, dqm)[m_idx]
        worst_b = max(worst_b, _rel(bd, bm))
        gravity_seen = max(gravity_seen, float(np.max(np.abs(model.bias(qd, {})))))
    assert worst_m <= TOL
    assert worst_b <= TOL
    if written.robot.name != "MobileRobot":  # the pan-tilt's COMs lie on their axes: no gravity torque
        assert gravity_seen > 1.0  # the comparison includes gravity torques, not only Coriolis terms


def test_bias_sign_convention_is_mujocos(tmp_path: Path) -> None:
    """``bias`` = C(q, v) v − τ_g: what a motor must supply at q̈ = 0 (M q̈ + b = τ), checked against
    MuJoCo's inverse dynamics ``mj_rne`` at q̈ = 0 on PA10 bent so that gravity loads J2 and J4."""
    w = _write(PA10, tmp_path)
    model = _load(w, "sdf")
    m = mujoco.MjModel.from_xml_path(str(w.files["mjcf"]))
    d = mujoco.MjData(m)
    q = {"J2": 0.5, "J4": -0.3}
    dq = {"J1": 0.7, "J2": -0.4, "J4": 1.1}
    for name, value in q.items():
        d.qpos[m.joint(name).qposadr[0]] = value
    for name, value in dq.items():
        d.qvel[m.joint(name).dofadr[0]] = value
    mujoco.mj_forward(m, d)
    rne = np.zeros(m.nv)
    mujoco.mj_rne(m, d, 0, rne)  # flg_acc = 0: inverse dynamics at zero acceleration
    sdf = w.renames["sdf"]["joint"]
    back = {sdf.get(j.name, j.name): j.name for j in w.robot.joints}
    expected = np.array([rne[m.joint(back[name]).dofadr[0]] for name in model.dof_names()])
    got = model.bias({sdf.get(k, k): v for k, v in q.items()}, {sdf.get(k, k): v for k, v in dq.items()})
    assert abs(expected[model.dof_names().index(sdf.get("J2", "J2"))]) > 1.0  # gravity loads J2
    assert _rel(got, expected) <= TOL
    # and the opposite sign (gravity on the force side, as CalcGravityGeneralizedForces) would fail
    coriolis_plus_gravity = np.array(model.plant.CalcBiasTerm(model.context)) + np.array(
        model.plant.CalcGravityGeneralizedForces(model.context))
    assert _rel(coriolis_plus_gravity, expected) > 0.1


def test_free_root_is_welded_and_world_joint_not_reported(tmp_path: Path) -> None:
    """A floating root (no world joint in the file) is welded at the identity too; the nq drops."""
    robot = copy.deepcopy(modelkit.load(PANTILT))
    assert robot.root_joint is JointType.FLOATING
    notes = write(robot, tmp_path / "float.sdf")
    model = engine_drake.load(tmp_path / "float.sdf", {"joint": renames(notes, "joint")}, root="Chassis")
    assert model.settings["nq"] == 4 and "free root" in model.settings["base"]
    assert all(j.parent != "world" for j in model.static().joints.values())
    poses = model.link_poses({})
    assert poses["Chassis"].is_identity(0.0)


def test_unknown_root_and_bad_file_raise_clear_errors(tmp_path: Path) -> None:
    w = _write(PANTILT, tmp_path)
    with pytest.raises(engine_drake.DrakeLoadError, match=r"no link named 'Nope'.*Chassis"):
        engine_drake.load(w.files["sdf"], {}, root="Nope")
    bad = tmp_path / "bad.sdf"
    bad.write_text('<sdf version="1.9"><model name="m"><link name="a"/><joint name="j" type="revolute">'
                   "<parent>a</parent><child>missing</child><axis><xyz>0 0 1</xyz></axis></joint>"
                   "</model></sdf>")
    with pytest.raises(engine_drake.DrakeLoadError, match=r"bad\.sdf: Drake could not parse.*missing"):
        engine_drake.load(bad, {}, root="a")


def test_parser_warnings_are_kept(tmp_path: Path) -> None:
    """Drake only warns about an invalid inertia (a negative mass); the warning is kept for the report,
    and not printed: verify on Hello Robot's Stretch put 19 "WARNING:drake:" lines on the terminal."""
    odd = tmp_path / "odd.sdf"
    odd.write_text('<sdf version="1.9"><model name="m"><link name="a"><inertial><mass>-1</mass>'
                   "</inertial></link></model></sdf>")
    model = engine_drake.load(odd, {}, root="a")
    assert any("invalid inertia" in w for w in model.warnings)
    assert model.settings["parser_warnings"] == model.warnings
    # in a process of its own, as the CLI runs it (pytest captures Python's logging itself)
    import subprocess
    import sys

    code = ("from pathlib import Path; from modelkit.verify.engines import drake; "
            f"print(len(drake.load(Path({str(odd)!r}), {{}}, root='a').warnings))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() != "0" and "invalid inertia" not in run.stderr, run.stderr
