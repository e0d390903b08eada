"""``modelkit verify`` on MJCF sources, against real MuJoCo, Pinocchio, PyBullet and Drake.

The MJCF reader turns a MuJoCo body with n joints into a chain of n links (the first n − 1 massless,
``<body>__<joint>``) and moves a link's frame to its last joint's anchor; the MuJoCo adapter reports
MuJoCo's compiled bodies in that convention. These tests hold the adapter to it on the dm_control
suite and MuJoCo's humanoid: layers 1–3a pass for MuJoCo and Pinocchio, and the engines reading the
URDF/SDF either pass or fail exactly where a documented defect outside the adapter says (xfail).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from modelkit.model import Robot
from modelkit.verify.api import verify
from modelkit.verify.engine_mujoco import MujocoModel
from modelkit.verify.facts import StaticFacts
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
    from modelkit.verify.reference import source_static

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
    from modelkit.verify.layers import configurations
    from modelkit.verify.reference import SourceModel

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


# Engines reading the written URDF/SDF: what fails there, and why (defects outside the MuJoCo
# adapter, measured; the test fails if another check fails, and xpasses strictly once fixed).
DRAKE_WORLD = ("the source's root is the synthesised 'world' link (top-level bodies hang from the world "
               "by their joints): engine_drake looks for a body named 'world' in the model instance, "
               "but Drake parses it as its own world body")
UNLIMITED_SLIDE = ("an unlimited slide is written to URDF as a prismatic joint with limits ±1e16 (URDF "
                   "has no unlimited prismatic joint); layer 1 compares ±inf with ±1e16")
INITIAL_POSITION = ("the SDF writer puts <initial_position> under <axis> (the hinge's ref); Drake's "
                    "libsdformat refuses the element")
URDF_SDF_ENGINES = ("pybullet", "drake", "drake-urdf")
KNOWN: dict[str, dict[tuple[str, str], str]] = {}
for _name in ("acrobot", "cartpole", "manipulator", "pendulum", "point_mass", "reacher", "stacker"):
    KNOWN[_name] = {("drake", "load"): DRAKE_WORLD, ("drake-urdf", "load"): DRAKE_WORLD}
for _name in ("ball_in_cup", "cheetah", "hopper", "swimmer", "walker"):
    KNOWN[_name] = {("drake", "load"): DRAKE_WORLD, ("drake-urdf", "load"): DRAKE_WORLD,
                    ("pybullet", "limits"): UNLIMITED_SLIDE}
KNOWN["finger"] = {("drake", "load"): INITIAL_POSITION, ("drake-urdf", "load"): DRAKE_WORLD}


@pytest.mark.parametrize("source", MODELS, ids=_id)
def test_urdf_and_sdf_engines_pass_or_fail_only_where_known(source: Path) -> None:
    engines = [e for e in URDF_SDF_ENGINES
               if importlib.util.find_spec("pydrake" if e.startswith("drake") else e) is not None]
    if not engines:
        pytest.skip("neither PyBullet nor Drake is installed")
    report = verify(source, None, ("pinocchio", *engines), configurations=10, samples=5, replay=False)
    assert report.errors == []
    failed = {(c.engine, c.quantity) for c in report.failed}
    known = {f: why for f, why in KNOWN.get(source.stem, {}).items() if f[0] in engines}
    unexplained = [f"layer {c.layer} {c.engine} {c.quantity} {c.where}: {c.detail}" for c in report.failed
                   if (c.engine, c.quantity) not in known]
    assert unexplained == []
    if failed:
        pytest.xfail("; ".join(sorted({f"{e} {q}: {known[(e, q)]}" for e, q in failed})))
