"""``modelkit verify`` on MJCF sources, against real MuJoCo, Pinocchio, PyBullet and Drake.

The MJCF reader turns a MuJoCo body with n joints into a chain of n links (the first n − 1 massless,
``<body>__<joint>``) and moves a link's frame to its last joint's anchor; the MuJoCo adapter reports
MuJoCo's compiled bodies in that convention. These tests hold the adapter to it on the dm_control
suite and MuJoCo's humanoid: layers 1–3a pass for MuJoCo and Pinocchio, the engines reading the
URDF/SDF pass, and the replay passes or fails exactly where a documented cause says (strict xfail).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from modelkit.model import Robot
from modelkit.verify.api import verify
from modelkit.verify.engines.mujoco import MujocoModel
from modelkit.verify.engines.protocol import Check, StaticFacts
from tests.conftest import CORPUS

SUITE = CORPUS / "dm_control_suite" / "dm_control" / "suite"
HUMANOID = CORPUS / "mujoco_model" / "humanoid" / "humanoid.xml"
# lqr.xml is generated at run time in dm_control (no robot with a root link in the stored file).
MODELS = [HUMANOID, *sorted(p for p in SUITE.glob("*.xml") if p.name != "lqr.xml")]

pytestmark = pytest.mark.skipif(not SUITE.exists() or not HUMANOID.exists(), reason="corpus not present")


def _id(path: Path) -> str:
    return f"{path.parent.name}/{path.name}"


@pytest.mark.parametrize("source", MODELS, ids=_id)
def test_mujoco_and_pinocchio_pass_layers_1_to_3a(source: Path) -> None:
    report = verify(source, None, ("mujoco", "pinocchio"), configurations=10, samples=5, replay=False)
    assert report.errors == []
    failed = [f"layer {c.layer} {c.engine} {c.quantity} {c.where}: {c.error:.3g}: {c.detail}"
              for c in report.failed]
    assert failed == []
    for layer in (1, 2, 3):
        quantities = {c.quantity for c in report.checks if c.engine == "mujoco" and c.layer == layer}
        assert quantities, f"no layer {layer} check for MuJoCo"
    assert {"link-set", "joint-set", "com", "inertia", "shape-pose"} <= {
        c.quantity for c in report.checks if c.engine == "mujoco"}


def _static(source: Path, tmp_path: Path) -> tuple[Robot, MujocoModel, StaticFacts]:
    from modelkit.api import validate
    from modelkit.convert.api import write
    from modelkit.verify.api import welded_copy
    from modelkit.verify.engines.reference import source_static

    robot = welded_copy(validate(source).robots[0])[0]
    path = tmp_path / "x.xml"
    write(robot, path, "mjcf", force=True)
    return robot, MujocoModel(path, str(robot.root)), source_static(robot)


def test_a_multi_joint_body_is_the_readers_chain(tmp_path: Path) -> None:
    """humanoid's thigh_right has hip_x, hip_z, hip_y: two massless intermediates, each joint moving
    the next link; waist_lower's joints sit at pos 0 0 .065: its link frame is there, its COM and
    capsule re-expressed in it (MuJoCo's body frame is 0.065 m away)."""
    _, mj, src = _static(HUMANOID, tmp_path)
    facts = mj.static()
    chain = ["thigh_right__hip_x_right", "thigh_right__hip_z_right", "thigh_right"]
    for name in chain[:2]:
        assert facts.links[name].mass == 0.0
    assert [facts.joints[j].child for j in ("hip_x_right", "hip_z_right", "hip_y_right")] == chain
    assert [facts.joints[j].parent for j in ("hip_x_right", "hip_z_right", "hip_y_right")] == [
        "pelvis", *chain[:2]]
    m = mj.model
    b = m.body("waist_lower").id
    anchor = np.array(m.jnt_pos[m.joint("abdomen_y").id])
    assert np.allclose(anchor, [0.0, 0.0, 0.065])
    assert np.allclose(facts.links["waist_lower"].com, m.body_ipos[b] - anchor, atol=1e-15)
    assert np.allclose(facts.links["waist_lower"].com, src.links["waist_lower"].com, atol=1e-12)
    (capsule,) = facts.shapes["waist_lower"]
    assert np.allclose(capsule.pose.translation, [0.0, 0.0, -0.065], atol=1e-12)
    assert facts.joints["abdomen_z"].child == "waist_lower__abdomen_z"
    assert set(facts.links) == set(src.links)


def test_link_poses_follow_the_reader_at_random_configurations(tmp_path: Path) -> None:
    """Intermediate links move with their own joint only: their poses come out of MuJoCo's body
    frames by undoing the later joints, and match the source model's forward kinematics."""
    from modelkit.verify.engines.reference import SourceModel
    from modelkit.verify.layers.kinematics import configurations

    robot, mj, _ = _static(SUITE / "swimmer.xml", tmp_path)
    ref = SourceModel(robot)
    for q in configurations(robot, 5, seed=3)[1:]:
        a, b = ref.link_poses(q), mj.link_poses(q)
        assert set(a) == set(b)
        for name, pose in a.items():
            assert np.allclose(pose.translation, b[name].translation, atol=1e-12), name
            assert np.allclose(pose.rotation, b[name].rotation, atol=1e-12), name


def test_the_replay_splits_a_chain_without_changing_its_kinematics(tmp_path: Path) -> None:
    """The replay gives PyBullet's 1 kg to intermediate links: the MuJoCo simulator makes them bodies
    of their own (nested, one joint each), whose frames are the link frames the adapter reports."""
    robot, mj, _ = _static(HUMANOID, tmp_path)
    wanted = {"thigh_right__hip_x_right", "thigh_right__hip_z_right"}
    split = MujocoModel(tmp_path / "x.xml", str(robot.root), split=wanted)
    assert split.model.nbody == mj.model.nbody + 2
    assert split.model.nv == mj.model.nv
    q = {name: 0.3 + 0.1 * i for i, name in enumerate(mj.dof_names())}
    a, b = mj.link_poses(q), split.link_poses(q)
    for name in ("thigh_right__hip_x_right", "thigh_right__hip_z_right", "thigh_right", "foot_right"):
        assert np.allclose(a[name].translation, b[name].translation, atol=1e-12), name
        assert np.allclose(a[name].rotation, b[name].rotation, atol=1e-12), name
    # MuJoCo's frame of the new body, moved to its joint's anchor, is the intermediate link frame
    d, sm = split.data, split.model
    body, root = sm.body("thigh_right__hip_x_right").id, sm.body(str(robot.root)).id
    anchor = sm.jnt_pos[sm.joint("hip_x_right").id]
    world = d.xmat[body].reshape(3, 3) @ anchor + d.xpos[body]
    relative = d.xmat[root].reshape(3, 3).T @ (world - d.xpos[root])
    assert np.allclose(relative, a["thigh_right__hip_x_right"].translation, atol=1e-12)


# Engines reading the written URDF/SDF, and the replay: what still fails there, and why (measured).
# Each is a strict xfail: the test fails if another check fails, and flags itself once the cause is fixed.
URDF_SDF_ENGINES = ("pybullet", "drake", "drake-urdf", "yourdfpy")
KNOWN: dict[str, dict[tuple[str, str], str]] = {}  # model stem -> (engine, quantity) -> why, layers 1-3a
# hopper's replay was unstable here until replay.default_law took its gains from the effective
# inertia 1/(M^-1)_ii and checked the linearised step's growth factor (docs/verify.md).
REPLAY_KNOWN: dict[str, dict[tuple[str, str], str]] = {}


class KnownFailure(Exception):
    """Only the known causes failed (the strict xfail's expected exception: anything else is a failure)."""


def _known(table: dict[str, dict[tuple[str, str], str]], source: Path) -> object:
    why = table.get(source.stem, {})
    if not why:
        return source
    reason = "; ".join(sorted(set(why.values())))
    return pytest.param(source, marks=pytest.mark.xfail(strict=True, raises=KnownFailure, reason=reason))


def _only_known(failed: list[Check], known: dict[tuple[str, str], str]) -> None:
    unexplained = [f"layer {c.layer} {c.engine} {c.quantity} {c.where}: {c.detail}" for c in failed
                   if (c.engine, c.quantity) not in known]
    assert unexplained == []
    if failed:
        raise KnownFailure("; ".join(sorted({f"{c.engine} {c.quantity}: {known[(c.engine, c.quantity)]}"
                                             for c in failed})))


def _installed(engines: tuple[str, ...]) -> list[str]:
    return [e for e in engines
            if importlib.util.find_spec("pydrake" if e.startswith("drake") else e) is not None]


@pytest.mark.parametrize("source", [_known(KNOWN, m) for m in MODELS], ids=_id)
def test_urdf_and_sdf_engines_pass(source: Path) -> None:
    engines = _installed(URDF_SDF_ENGINES)
    if not engines:
        pytest.skip("neither PyBullet, Drake nor yourdfpy is installed")
    report = verify(source, None, ("pinocchio", *engines), configurations=10, samples=5, replay=False)
    assert report.errors == []
    _only_known(report.failed, KNOWN.get(source.stem, {}))


@pytest.mark.parametrize("source", [_known(REPLAY_KNOWN, m) for m in MODELS], ids=_id)
def test_replay_passes(source: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Layer 3b on every MJCF source, the joints' passive terms left out in both engines; MuJoCo's
    warnings are collected, never written to MUJOCO_LOG.TXT in the working directory."""
    if not _installed(("pybullet",)):
        pytest.skip("PyBullet is not installed")
    monkeypatch.chdir(tmp_path)
    report = verify(source, None, ("mujoco", "pybullet", "pinocchio"), configurations=1, samples=1)
    assert list(tmp_path.iterdir()) == []
    if source.stem in NOT_INTEGRABLE:
        said = [s.reason for s in report.skips if s.reason.startswith("layer 3b (replay) not graded")]
        assert len(said) == 1 and "mass matrix and bias equal to the source's" in said[0]
        assert not [c for c in report.checks if c.quantity in ("replay", "stability", "engine-error")]
    else:
        assert [c for c in report.checks if c.quantity == "replay"], "no replay check"
    _only_known(report.failed, REPLAY_KNOWN.get(source.stem, {}))


# Swinging free without its armature, damping and limits (what the replay integrates), the CMU
# humanoid blows up in MuJoCo on the source itself (1.25 s at 1 ms, 1.91 s at 0.125 ms): the replay
# is skipped with the engine's message. It passed before only because PyBullet's 1 kg for a massless
# URDF link (its bodies' intermediate joint links) made it a heavier robot.
NOT_INTEGRABLE = {"humanoid_CMU"}


def test_a_replay_that_blows_up_on_a_sound_file_is_skipped_and_on_a_faulty_one_fails(tmp_path: Path) -> None:
    """The skip needs MuJoCo's layer 3a to pass: a mass fault in the written files (injected) keeps
    the blow-up a failure."""
    if not _installed(("pybullet",)):
        pytest.skip("PyBullet is not installed")
    report = verify(SUITE / "humanoid_CMU.xml", None, ("mujoco", "pybullet", "pinocchio"), configurations=1,
                    samples=1, inject=["mass:lhumerus:10%"])
    assert not [s for s in report.skips if s.reason.startswith("layer 3b (replay) not graded")]
    assert {c.quantity for c in report.failed if c.layer == 3 and c.engine == "mujoco"} >= {"mass-matrix"}


def test_drake_uses_its_world_body_for_a_world_root(tmp_path: Path) -> None:
    """pendulum's root is the synthesised 'world' link (its pole hangs from the world by a hinge):
    Drake parses it as its own world body, in the SDF and in the URDF; the hinge is the model's joint,
    nothing is welded, and 'world' is no link of the model instance."""
    pytest.importorskip("pydrake")
    from modelkit.api import validate
    from modelkit.convert.api import write
    from modelkit.verify.api import welded_copy
    from modelkit.verify.engines import drake as engine_drake
    from modelkit.verify.engines.reference import SourceModel

    robot = welded_copy(validate(SUITE / "pendulum.xml").robots[0])[0]
    assert robot.root == "world"
    for fmt, name in (("sdf", "p.sdf"), ("urdf", "p.urdf")):
        write(robot, tmp_path / name, fmt, force=True)
        model = engine_drake.load(tmp_path / name, {"link": {}, "joint": {}}, root="world")
        facts = model.static()
        assert set(facts.links) == {"pole"}
        assert facts.joints["hinge"].parent == "world" and facts.joints["hinge"].type == "revolute"
        assert model.dof_names() == ["hinge"]
        assert "world body" in model.settings["base"]
        q = {"hinge": 0.7}
        ref, got = SourceModel(robot).link_poses(q), model.link_poses(q)
        assert np.allclose(ref["pole"].translation, got["pole"].translation, atol=1e-12)
        assert np.allclose(ref["pole"].rotation, got["pole"].rotation, atol=1e-12)


def test_unlimited_slides_are_compared_with_the_urdf_stand_in(tmp_path: Path) -> None:
    """swimmer's rootx/rooty slides are unlimited: the URDF holds ±1e16 (MK819), every URDF reader must
    hold exactly that (listed as an approximation), Drake reads the SDF's ±1e16 as unlimited; a URDF
    bound of 1e15 instead fails layer 1 at that joint."""
    from lxml import etree

    engines = ("pinocchio", *_installed(("yourdfpy", "pybullet", "drake", "drake-urdf")))
    report = verify(SUITE / "swimmer.xml", tmp_path, engines, configurations=2, samples=2, replay=False)
    assert report.failed == []
    for engine in set(engines) & {"yourdfpy", "pybullet", "drake-urdf"}:
        (entry,) = [s for s in report.skips if s.engine == engine and "MK819" in s.reason]
        assert "rootx [-1e+16, 1e+16]" in entry.reason and "rooty" in entry.reason
    assert not [s for s in report.skips if s.engine in ("drake", "mujoco") and "MK819" in s.reason]
    urdf = tmp_path / "swimmer.urdf"
    tree = etree.parse(str(urdf))
    limit = tree.find("./joint[@name='rootx']/limit")
    assert limit is not None and limit.get("lower") == "-1e16" and limit.get("upper") == "1e16"
    limit.set("upper", "1e15")
    broken = tmp_path / "broken.urdf"
    tree.write(str(broken))
    report = verify(SUITE / "swimmer.xml", None, ("pinocchio", "yourdfpy"), urdf=broken, configurations=2,
                    samples=2, replay=False)
    (failed,) = report.failed
    assert (failed.engine, failed.quantity, failed.where) == ("yourdfpy", "limits", "rootx")
    assert failed.error == pytest.approx(0.9)


def test_replay_leaves_the_passive_terms_out_and_says_so(tmp_path: Path) -> None:
    """MuJoCo's damping, friction loss, stiffness (and armature when asked) are zeroed on the replay's
    compiled model, and ``left_out`` names the joints that had them; the report says so."""
    from modelkit.verify.engines.mujoco import MujocoSimulator

    robot, _, _ = _static(HUMANOID, tmp_path)
    none: dict[str, dict[str, str]] = {"link": {}, "joint": {}}
    sim = MujocoSimulator(tmp_path / "x.xml", none, str(robot.root), 1e-3, armature=False)
    m = sim.inner.model
    assert not m.dof_damping.any() and not m.dof_frictionloss.any() and not m.dof_armature.any()
    assert not m.jnt_stiffness.any()
    assert sim.left_out["damping"]["abdomen_z"] == 5.0 and "armature" in sim.left_out
    kept = MujocoSimulator(tmp_path / "x.xml", {"link": {}, "joint": {}}, str(robot.root), 1e-3)
    assert kept.inner.model.dof_armature.any() and "armature" not in kept.left_out
    if _installed(("pybullet",)):
        report = verify(HUMANOID, None, ("mujoco", "pybullet", "pinocchio"), configurations=1, samples=1)
        (entry,) = [s for s in report.skips if "passive terms" in s.reason]
        assert "joint damping of 21 joint(s)" in entry.reason and "abdomen_x 5" in entry.reason


def test_the_replays_1_kg_sits_at_the_link_origin(tmp_path: Path) -> None:
    """PyBullet's 1 kg for an intermediate link is at the link origin, its joint's anchor: MuJoCo's
    replay body for waist_lower__abdomen_z carries it at jnt_pos (0 0 .065), not at the body frame
    (the cause of humanoid's 0.19 rad replay difference)."""
    from modelkit.verify.engines.mujoco import MujocoSimulator

    robot, _, _ = _static(HUMANOID, tmp_path)
    sim = MujocoSimulator(tmp_path / "x.xml", {"link": {}, "joint": {}}, str(robot.root), 1e-3,
                          armature=False, inertials={"waist_lower__abdomen_z": (1.0, 1.0)})
    m = sim.inner.model
    b = m.body("waist_lower__abdomen_z").id
    assert m.body_mass[b] == 1.0
    assert np.allclose(m.body_ipos[b], m.jnt_pos[m.joint("abdomen_z").id]) and m.body_ipos[b][2] == 0.065


def test_mujoco_warnings_are_collected_and_instability_fails(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """A replay that blows up (absurd gains) makes MuJoCo warn; the warning is collected on the
    simulator, no MUJOCO_LOG.TXT appears in the working directory, and it is a failed check."""
    from modelkit.verify.api import engine_warnings
    from modelkit.verify.engines.mujoco import MujocoSimulator
    from modelkit.verify.engines.protocol import TorqueLaw
    from modelkit.verify.report import VerifyReport

    robot, _, _ = _static(SUITE / "pendulum.xml", tmp_path)
    monkeypatch.chdir(tmp_path)
    sim = MujocoSimulator(tmp_path / "x.xml", {"link": {}, "joint": {}}, str(robot.root), 1e-3)
    law = TorqueLaw(("hinge",), (1e12,), (1e9,), (1.0,), (1.0,), (0.0,))
    sim.replay(law, 0.1, 1e-3)
    assert any("unstable" in w for w in sim.runtime_warnings)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    report = VerifyReport("x")
    (check,) = engine_warnings(report, "mujoco", sim.runtime_warnings, "replay_warnings", "the replay")
    assert (check.quantity, check.passed) == ("stability", False) and "QACC" in check.detail
    assert report.engines["mujoco"]["replay_warnings"]


# A two-link arm whose bodies MuJoCo holds up against gravity (trossen-arm-sim's WXAI follower: every
# body gravcomp="1", every joint actuatorgravcomp). No URDF holds it, so PyBullet's arm falls: the
# replay leaves MuJoCo's gravity compensation out too (it failed by 0.13 rad at 0.22 s before).
GRAVCOMP_ARM = """<mujoco model="held">
  <compiler angle="radian" autolimits="true"/>
  <worldbody>
    <body name="base" gravcomp="1">
      <geom type="cylinder" size="0.03 0.03" mass="1"/>
      <body name="upper" pos="0 0 0.05" gravcomp="1">
        <joint name="shoulder" axis="0 1 0" range="-2 2" actuatorgravcomp="true"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02" mass="0.5"/>
        <body name="fore" pos="0.2 0 0" gravcomp="1">
          <joint name="elbow" axis="0 1 0" range="-2 2" actuatorgravcomp="true"/>
          <geom type="capsule" fromto="0 0 0 0.15 0 0.02" size="0.015" mass="0.3"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="shoulder" joint="shoulder" ctrlrange="-5 5"/>
    <motor name="elbow" joint="elbow" ctrlrange="-5 5"/>
  </actuator>
</mujoco>
"""


def test_the_replay_leaves_mujocos_gravity_compensation_out_and_says_so(tmp_path: Path) -> None:
    engines = _installed(("mujoco", "pybullet", "pinocchio"))
    if engines != ["mujoco", "pybullet", "pinocchio"]:
        pytest.skip("needs MuJoCo, PyBullet and Pinocchio")
    source = tmp_path / "held.xml"
    source.write_text(GRAVCOMP_ARM)
    report = verify(source, None, tuple(engines), configurations=2, samples=2, driven=False)
    assert report.failed == [], [(c.engine, c.quantity, c.where, c.error) for c in report.failed]
    assert [c for c in report.checks if c.quantity == "replay" and c.engine == "pybullet"]
    (entry,) = [s for s in report.skips if "passive terms" in s.reason]
    assert "body gravity compensation of 3 bodies (base 1, fore 1, upper 1)" in entry.reason
