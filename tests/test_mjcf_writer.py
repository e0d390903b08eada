"""The MJCF writer against real MuJoCo: every corpus model converts, loads without warnings after
1 s of simulation, and reads back (through modelkit's MJCF reader) as the same robot."""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import mujoco
import numpy as np
import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import CONVERTIBLE_ERRORS, prepare, write
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.context import WriteContext
from modelkit.convert.meshes import MeshExporter
from modelkit.convert.notes import ConversionNote, NoteSink, renames
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan
from modelkit.convert.registry import target_info
from modelkit.formats.mjcf.site_frames import sites_as_links
from modelkit.formats.mjcf.write_bodies import MIN_INERTIA, MIN_MASS
from modelkit.formats.mjcf.writer import write_mjcf
from modelkit.model import (
    Box,
    Capsule,
    Cylinder,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    LoopConstraint,
    Mesh,
    Mimic,
    Robot,
    Sphere,
    TriangleMeshData,
)
from modelkit.spatial import Pose

from .conftest import CORPUS, REPO, TUTORIAL, links_below

SUFFIXES = (".body", ".urdf", ".xacro", ".sdf", ".xml", ".world")
TARGET_OF_NOTE = re.compile(r"body\[([^\]]*)\]")


@dataclass
class Written:
    source: Robot  # the model as the writer saw it (after the convert pipeline's preparation)
    path: Path
    notes: list[ConversionNote]
    data: bytes


def render(
    robot: Robot, folder: Path, name: str = "model.xml", options: WriteOptions | None = None
) -> Written:
    """Run the writer the way ``convert`` does and commit the files to ``folder``."""
    notes = NoteSink()
    options = options or WriteOptions()
    prepared = prepare(robot, target_info("mjcf"), options, notes)
    plan = OutputPlan(folder, set(), True)
    ctx = WriteContext(options, notes, MeshExporter(plan, name, options, notes), name)
    data = write_mjcf(prepared, ctx)
    plan.add(name, data, "model")
    plan.commit()
    return Written(prepared, folder / name, notes.items, data)


def corpus_inputs() -> list[Path]:
    bases = [REPO / "samples", CORPUS]
    return sorted(
        p
        for b in bases
        if b.is_dir()
        for p in b.rglob("*")
        if p.is_file() and p.name.lower().endswith(SUFFIXES)
    )


def convertible(path: Path) -> list[Robot]:
    checked = validate(path)
    if any(d.code not in CONVERTIBLE_ERRORS for d in checked.errors):
        return []
    return [r for r in checked.robots if r.root is not None]


def step_warnings(model: mujoco.MjModel, seconds: float = 1.0) -> dict[int, int]:
    data = mujoco.MjData(model)
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return {i: int(data.warning[i].number) for i in range(len(data.warning)) if data.warning[i].number}


def noted_bodies(notes: list[ConversionNote], code: str, words: str) -> set[str]:
    return {
        m.group(1)
        for n in notes
        if n.code == code and words in n.message and n.target
        for m in [TARGET_OF_NOTE.search(n.target)]
        if m
    }


def explained(diff: Difference, written: Written, renames: dict[str, str]) -> bool:
    """Differences the notes announce: synthesised mass/inertia (MK816/MK870), links written as
    separate top-level bodies (MK813, which the reader reads as robots of their own), locked joints
    held by an equality (MK820), the link ``world`` being MuJoCo's world body (MK814, which makes the
    bodies hanging from it top-level bodies too), a frame link hanging from a frame link, both written
    as sites of one body (MK873)."""
    notes = written.notes
    where = renames.get(diff.where, diff.where)
    if diff.quantity in ("mass", "inertia", "com"):
        return where in noted_bodies(notes, "MK816", "MuJoCo refuses") | noted_bodies(notes, "MK870", "")
    top_level = noted_bodies(notes, "MK813", "top-level body")
    if diff.quantity in ("link-set", "pose"):
        world_body = any(n.code == "MK814" for n in notes)
        if where in top_level or (where == "world" and world_body):
            return True
        if top_level and diff.where == written.source.root:  # the source's root is one top-level body
            return True  # of several, each read back as a robot: the one compared may be another
        if world_body:  # the bodies hanging from the world are top-level: each is read as a robot
            hanging = {j.child for j in written.source.joints if j.parent == "world"}
            if diff.where in links_below(written.source, hanging):
                return True
        moved = links_below(written.source, {k for k, v in renames.items() if v in top_level} | top_level)
        return diff.where in moved
    if diff.quantity.startswith("limit-"):
        return any(n.code == "MK820" and f"joint {diff.where} is locked" in n.message for n in notes)
    if diff.quantity == "joint-parent":  # a frame on a frame: both sites of one body (MK873)
        joint = next((j for j in written.source.joints if j.name == diff.where), None)
        sites = " ".join(n.message for n in notes if n.code == "MK873")
        return joint is not None and all(f" {x} (in " in sites or f" {x} as site " in sites
                                         for x in (joint.parent, joint.child))
    return False


# Every round-trip difference the corpus is allowed, per file (``<path under the corpus or the
# repository>#<robot index>``) and why; each must also be announced by a note (``explained``). Any other
# difference, or one of these gone missing, fails the sweep.
SET_ASIDE: dict[str, tuple[str, frozenset[str]]] = {
    "choreonoid/share/model/misc/ClosedLinkSample.body#0": (
        "WAIST's principal moments violate a + b ≥ c: the two smaller are raised (MK870)",
        frozenset({"inertia WAIST"}),
    ),
    "choreonoid/share/model/misc/ellipsoid1.body#0": (
        "BASE's moments 0.1, 0.004, 0.015 violate a + b ≥ c: the two smaller are raised (MK870)",
        frozenset({"inertia BASE"}),
    ),
    "franka_description/robots/fer/fer.urdf.xacro#0": (
        "fer_link4's full tensor violates a + b ≥ c: the two smaller moments are raised (MK870)",
        frozenset({"inertia fer_link4"}),
    ),
    "gazebo_ros_pkgs/gazebo_plugins/test2/urdf/box.urdf#0": (
        "my_box's moments 1, 100, 1 violate a + b ≥ c: the two smaller are raised (MK870)",
        frozenset({"inertia my_box"}),
    ),
    "gazebo_ros_pkgs/gazebo_plugins/test2/large_models/large_model.urdf.xacro#0": (
        "the root link \"world\" is MuJoCo's world body (MK814): the 30 chains (40 links each) hanging from "
        "it are top-level bodies, read back as 30 robots; the first holds chain 0",
        frozenset(f"link-set link{k}_{chain}" for k in range(1, 41) for chain in range(1, 30)),
    ),
    "kuka_experimental/kuka_kr16_support/urdf/kr16_2.xacro#0": (
        "flange → tool0 is a chain of massless frames on link_6: MJCF sites hang on bodies, not on sites, "
        "so both are sites of link_6 (MK873) and tool0 comes back on link_6, at the same pose",
        frozenset({"joint-parent flange-tool0"}),
    ),
    "gz_sim_worlds/examples/worlds/nested_model.sdf#1": (
        "link_01 is not connected to the root: a top-level body, read back as a robot of its own (MK813)",
        frozenset({"link-set model_01::link_01"}),
    ),
    "gazebo_ros_pkgs/gazebo_plugins/test/test_worlds/gazebo_ros_block_laser.world#3": (
        "object1's link_2 and link_3 have no joint to its root: top-level bodies, read back as robots of "
        "their own (MK813)",
        frozenset({"link-set link_2", "link-set link_3"}),
    ),
    "gz_sim_worlds/test/worlds/models/building_L1/model.sdf#0": (
        "wall_1 is not connected to the root: a top-level body, read back as a robot of its own (MK813)",
        frozenset({"link-set wall_1"}),
    ),
    "gz_sim_worlds/test/worlds/models/nested_models/model.sdf#0": (
        "link_00 and link_01 are not connected: each a top-level body, read back as a robot of its own "
        "(MK813); the one compared is link_01 with the two SDF frames it carries (MK874), so link_00 is "
        "missing",
        frozenset({"link-set model_00::link_00"}),
    ),
    "gz_sim_worlds/examples/worlds/nested_model_joint_positions.sdf#2": (
        "model21_joint is locked (limits 0 0): written unlimited, held by a joint equality (MK820)",
        frozenset({"limit-lower model21_joint", "limit-upper model21_joint"}),
    ),
    "gz_sim_worlds/examples/worlds/nested_model_joint_positions.sdf#3": (
        "model31_joint and model32_joint are locked: written unlimited, held by joint equalities (MK820)",
        frozenset(
            {
                "limit-lower model31_joint",
                "limit-upper model31_joint",
                "limit-lower model32_joint",
                "limit-upper model32_joint",
            }
        ),
    ),
    "gz_sim_worlds/examples/worlds/nested_model_joint_positions.sdf#4": (
        "model42_joint is locked (limits 0 0): written unlimited, held by a joint equality (MK820)",
        frozenset({"limit-lower model42_joint", "limit-upper model42_joint"}),
    ),
    "gz_sim_worlds/test/worlds/joint_position_controller_nested_models.sdf#1": (
        "model21_joint is locked (limits 0 0): written unlimited, held by a joint equality (MK820)",
        frozenset({"limit-lower model21_joint", "limit-upper model21_joint"}),
    ),
    "gz_sim_worlds/test/worlds/tire_drum.sdf#0": (
        "steer is locked (limits 0 0): written unlimited, held by a joint equality (MK820)",
        frozenset({"limit-lower steer", "limit-upper steer"}),
    ),
    **{
        f"kuka_experimental/kuka_lbr_iiwa_support/urdf/lbr_iiwa_14_r820.{suffix}#0": (
            "no link has an inertial: the root is welded (--base auto: no mass to float, MK830), each "
            "moving link gets 1e-6 kg (MK816)",
            frozenset({f"mass link_{i}" for i in range(1, 8)}),
        )
        for suffix in ("urdf", "xacro")
    },
    "urdf_tutorial/urdf/06-flexible.urdf#0": (
        "no link has an inertial: the root is welded (--base auto: no mass to float, MK830), each moving "
        "link gets 1e-6 kg (MK816)",
        frozenset(
            f"mass {name}"
            for name in (
                "gripper_pole",
                "head",
                "left_back_wheel",
                "left_front_wheel",
                "left_gripper",
                "right_back_wheel",
                "right_front_wheel",
                "right_gripper",
            )
        ),
    ),
    # urdf_tutorial 01-05 (no inertial anywhere) used to float with 1e-6 kg made up for base_link; --base
    # auto now welds a robot without mass (MK830), so they round-trip exactly.
}


def corpus_key(path: Path, k: int) -> str:
    base = CORPUS if path.is_relative_to(CORPUS) else REPO
    return f"{path.relative_to(base).as_posix()}#{k}"


def _mark_used_as_in_source(back: Robot, source: Robot) -> None:
    """MJCF to MJCF writes every site back, those the source uses too (write_own); read back without
    what used it (a tendon, a sensor of another robot of the file: not written, MK806), such a site
    would look like a named frame. It is compared as the source has it: used."""
    used = {s.get("name") for s in source.extras.get("mjcf_sites") or [] if s.get("used")}
    for site in back.extras.get("mjcf_sites") or []:
        if site.get("name") in used:
            site["used"] = True


@cache
def corpus_results(tmp: str) -> dict[str, object]:
    """Convert, load, step and read back every corpus model once (shared by the tests).

    ``differences``: per robot with any, the round-trip differences as ``"<quantity> <where>"``;
    ``unannounced``: differences no note explains."""
    stats: dict[str, object] = {"converted": 0, "loaded": 0, "clean": 0, "exact": 0, "failures": []}
    failures: list[str] = stats["failures"]  # type: ignore[assignment]
    differences: dict[str, frozenset[str]] = {}
    unannounced: list[str] = []
    stats["differences"], stats["unannounced"] = differences, unannounced
    for n, path in enumerate(corpus_inputs()):
        for k, robot in enumerate(convertible(path)):
            folder = Path(tmp) / f"{n:03d}_{k}"
            written = render(robot, folder)
            stats["converted"] = int(stats["converted"]) + 1  # type: ignore[call-overload]
            try:
                model = mujoco.MjModel.from_xml_path(str(written.path))
            except ValueError as exc:
                failures.append(f"load {path}#{k}: {exc}")
                continue
            stats["loaded"] = int(stats["loaded"]) + 1  # type: ignore[call-overload]
            warnings = step_warnings(model)
            if warnings:
                failures.append(f"warnings {path}#{k}: {warnings}")
            else:
                stats["clean"] = int(stats["clean"]) + 1  # type: ignore[call-overload]
            back = validate(written.path).robots
            # Sites that name frames as links on both sides (what URDF and SDF get): the frame links
            # written as sites come back, and an MJCF source's own sites are compared where they are
            source = copy.deepcopy(written.source)
            _mark_used_as_in_source(back[0], source)
            sites_as_links(source, NoteSink())
            sites_as_links(back[0], NoteSink())
            link_renames = renames(written.notes, "link")
            diffs = compare_robots(source, back[0], link_renames)
            if not diffs:
                stats["exact"] = int(stats["exact"]) + 1  # type: ignore[call-overload]
                continue
            key = corpus_key(path, k)
            differences[key] = frozenset(f"{d.quantity} {d.where}" for d in diffs)
            unannounced.extend(f"{key}: {d}" for d in diffs if not explained(d, written, link_renames))
    return stats


@pytest.fixture(scope="module")
def sweep(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not available")
    return corpus_results(str(tmp_path_factory.mktemp("mjcf_sweep")))


def test_corpus_converts_loads_steps_and_round_trips(sweep: dict[str, object]) -> None:
    print({k: v for k, v in sweep.items() if k not in ("failures", "differences", "unannounced")})
    assert sweep["failures"] == []
    assert int(sweep["converted"]) >= 150  # type: ignore[call-overload]
    assert sweep["converted"] == sweep["loaded"] == sweep["clean"]
    expected = {key: diffs for key, (_, diffs) in SET_ASIDE.items()}
    assert sweep["differences"] == expected
    assert sweep["unannounced"] == []
    assert sweep["exact"] == int(sweep["converted"]) - len(SET_ASIDE)  # type: ignore[call-overload]


def test_body_mass_is_the_models_exactly(tmp_path: Path) -> None:
    """MuJoCo's compiled masses and inertias, not just modelkit's read-back, match the model."""
    for name in ("mobile_robot_sensors.body", "mobile_robot_pantilt.body"):
        (robot,) = convertible(TUTORIAL / name)
        written = render(robot, tmp_path / name)
        model = mujoco.MjModel.from_xml_path(str(written.path))
        for link in written.source.links:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, link.name)
            assert b > 0
            mass = link.inertial.mass if link.inertial else 0.0
            assert model.body_mass[b] == pytest.approx(mass, rel=1e-9, abs=0.0)
            if link.inertial:
                assert np.allclose(model.body_ipos[b], link.inertial.com, rtol=0, atol=1e-12)
                moments = np.sort(np.linalg.eigvalsh(link.inertial.inertia))
                assert np.allclose(np.sort(model.body_inertia[b]), moments, rtol=1e-9, atol=0)


# -- multi-joint MuJoCo bodies ----------------------------------------------------------------

SUITE = CORPUS / "dm_control_suite/dm_control/suite"
MULTI_JOINT = [
    SUITE / "fish.xml",
    SUITE / "humanoid.xml",
    SUITE / "humanoid_CMU.xml",
    SUITE / "quadruped.xml",
    SUITE / "cheetah.xml",
    SUITE / "swimmer.xml",
    SUITE / "point_mass.xml",
    CORPUS / "mujoco_model/humanoid/humanoid.xml",
]


def same_bodies(source: mujoco.MjModel, written: mujoco.MjModel) -> None:
    """Every written body is the source's body of that name: mass (as printed), inertia, and at the
    source's qpos0 (its ``ref``: the same q in the written file, which folds it in) the same
    orientation, centre of mass, and joints (names, order, types, anchors, axes). Not the body
    origin: a one-joint body's frame is written at its joint (the model's link frame)."""
    ds, dw = mujoco.MjData(source), mujoco.MjData(written)
    for j in range(written.njnt):  # the written joint's q is the source's qpos: copy qpos0 by name
        s = mujoco.mj_name2id(source, mujoco.mjtObj.mjOBJ_JOINT, written.joint(j).name)
        if s >= 0 and written.joint(j).name:
            width = {0: 7, 1: 4}.get(int(written.jnt_type[j]), 1)
            a, b = written.jnt_qposadr[j], source.jnt_qposadr[s]
            dw.qpos[a : a + width] = ds.qpos[b : b + width]
    mujoco.mj_kinematics(source, ds)
    mujoco.mj_kinematics(written, dw)
    for bw in range(1, written.nbody):
        bs = mujoco.mj_name2id(source, mujoco.mjtObj.mjOBJ_BODY, written.body(bw).name)
        assert bs > 0, written.body(bw).name
        # exact up to printing: fmt keeps 15 significant digits (≤ 5e-15 relative; masses MuJoCo
        # computed from geom densities have 17)
        assert written.body_mass[bw] == pytest.approx(source.body_mass[bs], rel=5e-15, abs=0.0)
        assert np.allclose(
            np.sort(written.body_inertia[bw]), np.sort(source.body_inertia[bs]), rtol=1e-12, atol=0
        )
        assert np.allclose(dw.xmat[bw], ds.xmat[bs], rtol=0, atol=1e-12)
        assert np.allclose(dw.xipos[bw], ds.xipos[bs], rtol=0, atol=1e-12)
        jw = [j for j in range(written.njnt) if written.jnt_bodyid[j] == bw]
        js = [j for j in range(source.njnt) if source.jnt_bodyid[j] == bs]
        free = mujoco.mjtJoint.mjJNT_FREE  # the model keeps no name for a lone root free joint
        assert [written.joint(j).name for j in jw if written.jnt_type[j] != free] == [
            source.joint(j).name for j in js if source.jnt_type[j] != free
        ]
        for a, b in zip(jw, js, strict=True):
            assert written.jnt_type[a] == source.jnt_type[b]
            if written.jnt_type[a] != mujoco.mjtJoint.mjJNT_SLIDE:  # a slide's anchor is moot (and
                # moved by its ref, which the written file folds into the body pose)
                assert np.allclose(dw.xanchor[a], ds.xanchor[b], rtol=0, atol=1e-12)
            assert np.allclose(dw.xaxis[a], ds.xaxis[b], rtol=0, atol=1e-12)


@pytest.mark.parametrize("path", MULTI_JOINT, ids=lambda p: p.name)
def test_multi_joint_bodies_are_written_back_as_one_body(tmp_path: Path, path: Path) -> None:
    """A body with several joints, which the reader reads as a chain of links, is one body again:
    no intermediate body, no made-up mass, the source's bodies and joints exactly."""
    if not path.exists():
        pytest.skip("corpus not available")
    robot = convertible(path)[0]  # the main robot (quadruped.xml has a ball too)
    intermediates = [lk.name for lk in robot.links if lk.extras.get("mjcf_intermediate_of")]
    assert intermediates
    written = render(robot, tmp_path)
    assert not [n for n in written.notes if n.code == "MK816" and "MuJoCo refuses" in n.message]
    tree = etree.fromstring(written.data)
    assert not set(intermediates) & {b.get("name") for b in tree.iter("body")}
    model = mujoco.MjModel.from_xml_path(str(written.path))
    same_bodies(mujoco.MjModel.from_xml_path(str(path)), model)
    assert compare_robots(written.source, validate(written.path).robots[0]) == []


CHAINS = """<mujoco model="chains">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <inertial pos="0 0 0" mass="3" diaginertia="1 1 1"/>
      <body name="b" pos="0.1 0 0" quat="0.9 0.1 0.3 0.2">
        <joint name="h1" type="hinge" axis="1 0 0" pos="0 0 0.1" range="-1 1"/>
        <joint name="s2" type="slide" axis="0 1 1" pos="0.2 0 0.1" ref="0.05"/>
        <joint name="b3" type="ball" pos="0.2 0.1 0.3"/>
        <inertial pos="0.1 0 0" mass="2" fullinertia="1 2 2.5 0.1 0 0"/>
        <geom type="sphere" size="0.1" pos="0.3 0 0"/>
        <site name="tip" pos="0.4 0 0"/>
        <body name="c" pos="0.5 0 0" euler="0 0.5 0">
          <joint name="h4" type="hinge" axis="0 0 1" pos="0 0.1 0" ref="0.3"/>
          <joint name="h5" type="hinge" axis="0 1 0" pos="0 0 0.2"/>
          <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
          <geom type="box" size="0.1 0.1 0.1"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_chain_bodies_with_offsets_refs_and_a_ball(tmp_path: Path) -> None:
    """Rotated bodies, joint anchors away from the body origin, slide and hinge refs, a ball joint
    and a closed loop on a chain's end link: each body is written as one, its joints at the source's
    ``pos``, the end link's contents shifted into the body frame."""
    source = tmp_path / "source.xml"
    source.write_text(CHAINS)
    (robot,) = convertible(source)
    assert {lk.name for lk in robot.links} >= {"b__h1", "b__s2", "c__h4"}
    at_c = Pose(np.eye(3), np.array([0.1, 0.0, 0.0]))
    world = robot.world_poses()
    robot.loops = [
        LoopConstraint("tie", "ball", "c", "base", at_c, world["base"].inverse() @ world["c"] @ at_c)
    ]
    written = render(robot, tmp_path / "out")
    tree = etree.fromstring(written.data)
    assert [b.get("name") for b in tree.iter("body")] == ["base", "b", "c"]
    b = tree.find("worldbody/body/body")
    assert b is not None
    # the source's anchors, but before the slide: its ref is folded into the body pose, so the
    # anchors of the joints before it move by ref · axis (0.05 · (0 1 1)/√2)
    assert [(j.get("name"), j.get("pos")) for j in b.findall("joint")] == [
        ("h1", "0 0.0353553390593274 0.135355339059327"),
        ("s2", "0.2 0 0.1"),
        ("b3", "0.2 0.1 0.3"),
    ]
    model = mujoco.MjModel.from_xml_path(str(written.path))
    same_bodies(mujoco.MjModel.from_xml_path(str(source)), model)
    assert compare_robots(written.source, validate(written.path).robots[0]) == []
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tie_1")
    assert model.site_bodyid[site] == mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "c")
    expected = (world["c"] @ at_c).translation
    assert np.allclose(data.site_xpos[site], expected, rtol=0, atol=1e-12)
    assert step_warnings(model) == {}


def test_more_than_six_dofs_stay_a_chain(tmp_path: Path) -> None:
    """A chain MuJoCo would refuse as one body (more than 6 dofs, or a rotation after a ball) is
    written link by link, as before (the massless moving links with MuJoCo's minimum mass)."""
    source = tmp_path / "source.xml"
    source.write_text(CHAINS)
    (robot,) = convertible(source)
    for joint in robot.joints:
        if joint.name in ("h1", "s2"):  # b: ball, ball, ball (9 dofs)
            joint.type = JointType.BALL
        if joint.name == "h4":  # c: ball, hinge
            joint.type = JointType.BALL
    written = render(robot, tmp_path / "out")
    tree = etree.fromstring(written.data)
    assert [b.get("name") for b in tree.iter("body")] == ["base", "b__h1", "b__s2", "b", "c__h4", "c"]
    model = mujoco.MjModel.from_xml_path(str(written.path))
    for name in ("b__h1", "b__s2", "c__h4"):
        assert model.body_mass[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)] == MIN_MASS
    assert step_warnings(model) == {}
    diffs = compare_robots(written.source, validate(written.path).robots[0])
    assert sorted(str(d) for d in diffs) == [
        f"mass {name}: 0.0 became 1e-06" for name in ("b__h1", "b__s2", "c__h4")
    ]


def test_only_the_readers_chains_are_collapsed(tmp_path: Path) -> None:
    """An intermediate link that carries anything (here a geom) is no longer the reader's: the
    chain is written link by link, the massless moving body with MuJoCo's minimum mass (MK816)."""
    (robot,) = convertible(SUITE / "fish.xml") if (SUITE / "fish.xml").exists() else pytest.skip("no corpus")
    link = robot.link("finright__finright_roll")
    assert link is not None
    link.visuals.append(Geom(Box(np.array([0.01, 0.01, 0.01]))))
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    bodies = {b.get("name") for b in tree.iter("body")}
    assert "finright__finright_roll" in bodies and "finleft__finleft_roll" not in bodies
    model = mujoco.MjModel.from_xml_path(str(written.path))
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "finright__finright_roll")
    assert model.body_mass[b] == MIN_MASS
    assert any(
        n.code == "MK816" and n.target == "body[finright__finright_roll]/inertial" for n in written.notes
    )


def test_two_runs_are_byte_identical(tmp_path: Path) -> None:
    for path in (TUTORIAL / "mobile_robot_sensors.body", CORPUS / "choreonoid/share/model/SR1/SR1.body"):
        if not path.exists():
            continue
        (robot,) = convertible(path)
        first = render(robot, tmp_path / "a")
        second = render(robot, tmp_path / "b")
        assert first.data == second.data
        files_a = sorted(p.relative_to(tmp_path / "a") for p in (tmp_path / "a").rglob("*") if p.is_file())
        files_b = sorted(p.relative_to(tmp_path / "b") for p in (tmp_path / "b").rglob("*") if p.is_file())
        assert files_a == files_b
        for rel in files_a:
            assert (tmp_path / "a" / rel).read_bytes() == (tmp_path / "b" / rel).read_bytes()
        assert b"/work" not in first.data and b"\t" not in first.data


# -- the tutorial robots ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "name",
    [
        "mobile_robot.body",
        "mobile_robot_primitive.body",
        "mobile_robot_sensors.body",
        "mobile_robot_pantilt.body",
        "mobile_robot_tracks.body",
    ],
)
def test_tutorial_robot(tmp_path: Path, name: str) -> None:
    (robot,) = convertible(TUTORIAL / name)
    # --wheel-collision cylinder: the source's wheel cylinders (the default writes spheres, MK826)
    written = render(robot, tmp_path, options=WriteOptions(wheel_collision="cylinder"))
    model = mujoco.MjModel.from_xml_path(str(written.path))
    source = written.source
    moving = [j for j in source.joints if j.type.moves]
    assert model.njnt == len(moving) + 1  # + the root's free joint
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and model.jnt_bodyid[0] == 1
    total = sum(lk.inertial.mass for lk in source.links if lk.inertial)
    assert math.isclose(float(np.sum(model.body_mass)), total, rel_tol=1e-12)
    assert step_warnings(model) == {}
    if source.link("LeftWheel") is None:  # the tracks robot: rollers instead of wheels
        return
    wheel = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "LeftWheel")
    cylinders = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == wheel
        and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER
        and model.geom_contype[g]
    ]
    expected = [
        g.geometry
        for g in source.link("LeftWheel").collisions  # type: ignore[union-attr]
        if isinstance(g.geometry, Cylinder)
    ]
    assert len(cylinders) == len(expected) >= 1
    assert model.geom_size[cylinders[0]][0] == pytest.approx(expected[0].radius, abs=1e-15)
    assert model.geom_size[cylinders[0]][1] * 2 == pytest.approx(expected[0].length, abs=1e-15)
    # the wheel's axis: the cylinder's Z lies along the joint axis (the wheel's Y)
    quat = model.geom_quat[cylinders[0]]
    zaxis = np.zeros(9)
    mujoco.mju_quat2Mat(zaxis, quat)
    assert np.allclose(zaxis.reshape(3, 3)[:, 2] * np.sign(zaxis.reshape(3, 3)[1, 2]), [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize(
    "name", ["mobile_robot.body", "mobile_robot_primitive.body", "mobile_robot_pantilt.body"]
)
def test_tutorial_wheels_default_to_spheres(tmp_path: Path, name: str) -> None:
    """--wheel-collision auto: each wheel's collision is a sphere of the wheel radius at the cylinder's
    centre (MK826), with priority 1, and the file has the wheeled robot's <option> (MK825)."""
    (robot,) = convertible(TUTORIAL / name)
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    assert [n.code for n in written.notes].count("MK826") == 2
    assert "MK825" in [n.code for n in written.notes]
    assert model.opt.timestep == 0.001 and model.opt.impratio == 10.0
    assert model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    for link in ("LeftWheel", "RightWheel"):
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, link)
        spheres = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body and model.geom_contype[g]]
        assert len(spheres) == 1 and model.geom_type[spheres[0]] == mujoco.mjtGeom.mjGEOM_SPHERE
        assert model.geom_size[spheres[0]][0] == pytest.approx(0.076, abs=1e-15)
        assert model.geom_priority[spheres[0]] == 1


def test_tutorial_sensors_appear(tmp_path: Path) -> None:
    """LiDAR → site + rangefinder along the device's forward axis; camera → <camera> looking forward;
    spot light → <light> (needs the .body reader to fill ``device.canonical``)."""
    (robot,) = convertible(TUTORIAL / "mobile_robot_sensors_ex.body")
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    devices = {d.name: (lk, d) for lk in written.source.links for d in lk.devices}
    assert "LiDAR" in devices and "RealSense" in devices
    tilt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, devices["LiDAR"][0].name)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "LiDAR")
    assert site >= 0 and model.site_bodyid[site] == tilt
    sensor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "LiDAR")
    assert model.sensor_type[sensor] == mujoco.mjtSensor.mjSENS_RANGEFINDER
    lidar = devices["LiDAR"][1]
    ray = data.site_xmat[site].reshape(3, 3)[:, 2]  # the rangefinder's ray: the site's +Z
    body = data.xmat[tilt].reshape(3, 3)
    assert np.allclose(ray, body @ lidar.pose.rotation[:, 0], atol=1e-12)
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "RealSense")
    assert cam >= 0
    camera = devices["RealSense"][1]
    look = -data.cam_xmat[cam].reshape(3, 3)[:, 2]
    assert np.allclose(look, body @ camera.pose.rotation[:, 0], atol=1e-12)
    up = data.cam_xmat[cam].reshape(3, 3)[:, 1]
    assert np.allclose(up, body @ camera.pose.rotation[:, 2], atol=1e-12)
    p = camera.canonical_params
    vfov = 2 * math.atan(math.tan(p["horizontal_fov"] / 2) * p["height"] / p["width"])
    assert model.cam_fovy[cam] == pytest.approx(math.degrees(vfov), rel=1e-12)
    assert list(model.cam_resolution[cam]) == [p["width"], p["height"]]
    lights = [d for _, d in devices.values() if d.canonical.value.endswith("light")]
    assert lights, "the sensors_ex robot has a spot light"
    assert model.nlight == len(lights)
    assert any(n.code == "MK807" and "rangefinder" in n.message for n in written.notes)


# -- unit cases -------------------------------------------------------------------------------


def _link(name: str, mass: float = 1.0) -> Link:
    return Link(name, Inertial(mass, np.zeros(3), np.eye(3) * 0.01 * mass) if mass else None)


def _chain(*joints: Joint, masses: dict[str, float] | None = None) -> Robot:
    masses = masses or {}
    names = ["base"] + [j.child for j in joints]
    robot = Robot(
        "unit",
        [_link(n, masses.get(n, 1.0)) for n in names],
        list(joints),
        root="base",
        root_joint=JointType.FIXED,
    )
    return robot


def _hinge(name: str, parent: str, child: str, origin: Pose | None = None) -> Joint:
    return Joint(
        name,
        JointType.REVOLUTE,
        parent,
        child,
        origin or Pose(np.eye(3), np.array([0.0, 0.0, 0.5])),
        np.array([1.0, 0.0, 0.0]),
        JointLimits(-1.0, 1.0, effort=3.0),
    )


def test_mimic_becomes_joint_equality(tmp_path: Path) -> None:
    follower = _hinge("f", "base", "b")
    follower.mimic = Mimic("a", multiplier=-2.0, offset=0.25)
    robot = _chain(_hinge("a", "base", "a_link"), follower)
    written = render(robot, tmp_path, options=WriteOptions(actuators="motor"))  # the leader's motor alone
    tree = etree.fromstring(written.data)
    (eq,) = tree.findall("equality/joint")
    assert (eq.get("joint1"), eq.get("joint2"), eq.get("polycoef")) == ("f", "a", "0.25 -2 0 0 0")
    assert [m.get("joint") for m in tree.findall("actuator/motor")] == ["a"]
    assert tree.find("actuator/motor").get("ctrlrange") == "-3 3"  # type: ignore[union-attr]
    model = mujoco.MjModel.from_xml_path(str(written.path))
    data = mujoco.MjData(model)
    data.qpos[0] = 0.3
    for _ in range(2000):
        mujoco.mj_step(model, data)
    assert data.qpos[1] == pytest.approx(0.25 - 2.0 * data.qpos[0], abs=2e-3)
    back = validate(written.path).robots[0]
    mimic = next(j for j in back.joints if j.name == "f").mimic
    assert mimic is not None and (mimic.joint, mimic.multiplier, mimic.offset) == ("a", -2.0, 0.25)


def test_loops_become_connect_and_weld(tmp_path: Path) -> None:
    robot = _chain(_hinge("j1", "base", "l1"), _hinge("j2", "base", "l2"))
    at1, at2 = Pose(np.eye(3), np.array([0.0, 0.1, 0.0])), Pose(np.eye(3), np.array([0.0, -0.1, 0.0]))
    robot.loops = [
        LoopConstraint("ball", "ball", "l1", "l2", at1, at2),
        LoopConstraint("weld", "fixed", "l1", "l2", at1, at2),
        LoopConstraint("hinge", "hinge", "l1", "l2", at1, at2, np.array([1.0, 0.0, 0.0])),
        LoopConstraint("piston", "piston", "l1", "l2", at1, at2),
    ]
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    assert [(e.tag, e.get("name")) for e in tree.find("equality")] == [  # type: ignore[union-attr]
        ("connect", "ball"),
        ("weld", "weld"),
        ("connect", "hinge_a"),
        ("connect", "hinge_b"),
    ]
    hinge_sites = {
        s.get("name"): s.get("pos") for s in tree.iter("site") if s.get("name", "").startswith("hinge")
    }
    assert hinge_sites == {
        "hinge_a1": "0.05 0.1 0",
        "hinge_b1": "-0.05 0.1 0",
        "hinge_a2": "0.05 -0.1 0",
        "hinge_b2": "-0.05 -0.1 0",
    }
    codes = [n.code for n in written.notes]
    assert "MK811" in codes and "MK810" in codes
    model = mujoco.MjModel.from_xml_path(str(written.path))
    assert model.neq == 4 and step_warnings(model) == {}


def test_closed_link_sample(tmp_path: Path) -> None:
    path = CORPUS / "choreonoid/share/model/misc/ClosedLinkSample.body"
    if not path.exists():
        pytest.skip("corpus not available")
    (robot,) = convertible(path)
    assert robot.loops
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    types = sorted(int(t) for t in model.eq_type)
    assert types and all(t in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD) for t in types)
    assert step_warnings(model) == {}


def test_massless_links(tmp_path: Path) -> None:
    """A massless body on a fixed joint stays massless; a moving one gets MIN_MASS with an MK816 note;
    a massless moving body carrying a welded massive child needs nothing."""
    fixed = Joint("weld", JointType.FIXED, "base", "frame", Pose(np.eye(3), np.array([0.1, 0.0, 0.0])))
    robot = _chain(
        fixed,
        _hinge("spin", "base", "idle"),
        _hinge("carry", "base", "carrier"),
        Joint("w2", JointType.FIXED, "carrier", "payload"),
        masses={"frame": 0.0, "idle": 0.0, "carrier": 0.0},
    )
    written = render(robot, tmp_path, options=WriteOptions(frame_sites=False))  # default: "frame" a site
    model = mujoco.MjModel.from_xml_path(str(written.path))
    mass = {model.body(b).name: float(model.body_mass[b]) for b in range(1, model.nbody)}
    assert mass == {"base": 1.0, "frame": 0.0, "idle": MIN_MASS, "carrier": 0.0, "payload": 1.0}
    idle = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "idle")
    assert np.allclose(model.body_inertia[idle], MIN_INERTIA, rtol=1e-12)
    notes = {n.target: n for n in written.notes if n.code == "MK816"}
    assert (
        "MuJoCo refuses" in notes["body[idle]/inertial"].message
        and "1e-6 kg" in notes["body[idle]/inertial"].message
    )
    assert "body[frame]" in notes and step_warnings(model) == {}


def test_names_are_unique_and_renames_noted(tmp_path: Path) -> None:
    """Two meshes from files with the same stem get distinct assets; a link called ``world`` that is
    not the root is renamed (MuJoCo reserves the name)."""
    tri = TriangleMeshData(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
        np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
    )
    robot = _chain(_hinge("j", "base", "world"))
    robot.link("base").visuals = [  # type: ignore[union-attr]
        Geom(Mesh(data=tri, generator="TriangleMesh")),
        Geom(Mesh(data=tri, generator="TriangleMesh", scale=np.array([2.0, 2.0, 2.0]))),
        Geom(Box(np.array([1.0, 2.0, 3.0])), name="g"),
        Geom(Box(np.array([1.0, 1.0, 1.0])), name="g"),
    ]
    written = render(robot, tmp_path)
    tree = etree.fromstring(written.data)
    assets = [(m.get("name"), m.get("scale")) for m in tree.iter("mesh")]
    assert len({a for a, _ in assets}) == len(assets) == 2
    assert [b.get("name") for b in tree.iter("body")] == ["base", "world_2"]
    assert [g.get("name") for g in tree.iter("geom") if g.get("name")] == ["g", "g_2"]
    assert renames(written.notes, "link") == {"world": "world_2"}
    assert renames(written.notes, "geom") == {"g": "g_2"}
    model = mujoco.MjModel.from_xml_path(str(written.path))
    assert model.nmesh == 2 and step_warnings(model) == {}
    back = validate(written.path).robots[0]
    assert compare_robots(written.source, back, renames(written.notes, "link")) == []


def test_root_conventions(tmp_path: Path) -> None:
    robot = _chain(_hinge("j", "base", "arm"))
    robot.root_pose = Pose(np.eye(3), np.array([0.0, 0.0, 1.0]))
    # A root the source leaves open is settled by --base auto before the writer (MK830): no shape to
    # judge by, so it floats (URDF's convention).
    for kind, free in ((JointType.FIXED, False), (JointType.FLOATING, True), (None, True)):
        variant = copy.deepcopy(robot)
        variant.root_joint = kind
        written = render(variant, tmp_path / str(kind))
        tree = etree.fromstring(written.data)
        base = tree.find("worldbody/body")
        assert base is not None and base.get("pos") == "0 0 1"
        assert (base.find("freejoint") is not None) is free
        assert any(n.code == "MK830" for n in written.notes) is (kind is None)


def test_triangle_inequality_is_repaired_with_a_note(tmp_path: Path) -> None:
    robot = _chain(_hinge("j", "base", "arm"))
    robot.link("arm").inertial = Inertial(1.0, np.zeros(3), np.diag([1.0, 1.0, 100.0]))  # type: ignore[union-attr]
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    arm = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "arm")
    assert np.allclose(np.sort(model.body_inertia[arm]), [50.0, 50.0, 100.0])
    assert any(n.code == "MK870" and "a + b ≥ c" in n.message for n in written.notes)


def test_shapes_of_size_zero_are_left_out_with_a_note(tmp_path: Path) -> None:
    """MuJoCo refuses a geom whose size is not positive ("size 0 must be positive in geom"): such a shape is
    left out with an MK871 note; a capsule of length 0 is the sphere it is."""
    robot = _chain(_hinge("j", "base", "arm"))
    base, arm = robot.links
    base.collisions = [Geom(Box((0.0, 0.0, 0.0))), Geom(Box((0.1, 0.2, 0.3)))]
    base.visuals = [Geom(Sphere(0.0)), Geom(Cylinder(0.0, 1.0))]
    arm.collisions = [Geom(Capsule(0.05, 0.0))]
    written = render(robot, tmp_path)
    model = mujoco.MjModel.from_xml_path(str(written.path))
    geoms = sorted(
        (int(model.geom_type[i]), tuple(np.round(model.geom_size[i], 9)))
        for i in range(model.ngeom)
    )
    assert geoms == [
        (int(mujoco.mjtGeom.mjGEOM_SPHERE), (0.05, 0.0, 0.0)),
        (int(mujoco.mjtGeom.mjGEOM_BOX), (0.05, 0.1, 0.15)),
    ]
    notes = sorted((n.target, n.message) for n in written.notes if n.code == "MK871")
    assert [target for target, _ in notes] == [
        "body[base]/collision[0]", "body[base]/visual[0]", "body[base]/visual[1]"
    ]
    assert "box 0 0 0" in notes[0][1] and "collides with a point" in notes[0][1]
    assert "draws nothing" in notes[1][1]
    assert step_warnings(model) == {}


PIONEER = CORPUS / "gazebo_ros_pkgs/gazebo_plugins/test/multi_robot_scenario/xacro/p3dx/pioneer3dx.xacro"


def test_pioneer3dx_zero_collision_boxes_convert_to_a_model_mujoco_loads(tmp_path: Path) -> None:
    """The Pioneer 3-DX xacro says "no collision" with <box size="0 0 0"/> (MK416, a warning): convert
    proceeds, leaves those boxes out (MK871) and MuJoCo loads the result."""
    from click.testing import CliRunner

    from modelkit.cli import main

    if not PIONEER.is_file():
        pytest.skip("shared corpus not available")
    out = tmp_path / "out" / "p3dx.xml"
    result = CliRunner().invoke(main, ["convert", str(PIONEER), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.count("MK871") == 5 and result.output.count("MK416") == 5, result.output
    model = mujoco.MjModel.from_xml_path(str(out))
    for body in ("sonar", "swivel", "center_hubcap", "left_hub", "right_hub"):
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        collisions = [g for g in range(model.ngeom) if model.geom_bodyid[g] == b and model.geom_group[g] == 3]
        assert b > 0 and collisions == [], body
    assert step_warnings(model) == {}



@pytest.mark.parametrize(("inertia", "lifted"), [
    ("1e-14 1e-14 1e-14 0 0 0", False),  # diaginertia: MuJoCo takes it down to mjMINVAL (1e-15)
    ("5e-15 5e-15 5e-15 0 0 0", True),   # within the 10× margin of mjMINVAL
    ("2e-13 2e-13 2e-13 5e-14 0 0", False),  # fullinertia, smallest eigenvalue 1.5e-13
    # products of inertia, smallest eigenvalue 6e-14: under 10 × mjEPS as a fullinertia, so written as
    # its principal moments and axes (diaginertia + quat), which MuJoCo checks against mjMINVAL
    ("8e-14 8e-14 8e-14 2e-14 0 0", False),
    ("8e-15 8e-15 8e-15 2e-15 0 0", True),   # smallest principal moment 6e-15: within 10× of mjMINVAL
])
def test_a_small_inertia_mujoco_takes_is_written_as_it_is(tmp_path: Path, inertia: str, lifted: bool) -> None:
    """pybullet_data's thrower.xml has a wrist of 4.46e-13, 7.96e-14, 4.46e-13 kg·m² that MuJoCo itself
    compiles; the writer added 1e-9 on each axis (2000× the moment) because anything under 1e-12 counted
    as singular, and verify failed layers 1, 3a and the replay. Now only what MuJoCo refuses, with a 10×
    margin (diagonal: mjMINVAL 1e-15; full: mjEPS 1e-14), is lifted (MK870); the rest is written as given
    and loads."""
    xx, yy, zz, xy, xz, yz = inertia.split()
    source = tmp_path / "wrist.urdf"
    source.write_text(f"""<robot name="wrist">
  <link name="arm"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="hand"><inertial><mass value="1e-6"/>
    <inertia ixx="{xx}" iyy="{yy}" izz="{zz}" ixy="{xy}" ixz="{xz}" iyz="{yz}"/></inertial></link>
  <joint name="flex" type="revolute"><parent link="arm"/><child link="hand"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""")
    robot = validate(source).robot
    assert robot is not None
    out = tmp_path / "wrist.xml"
    notes = write(robot, out)
    noted = [n for n in notes if n.code == "MK870" and "singular" in n.message]
    assert bool(noted) is lifted
    model = mujoco.MjModel.from_xml_path(str(out))
    smallest = float(np.min(model.body_inertia[model.body("hand").id]))
    if lifted:
        assert smallest > 1e-9
    else:
        tensor = np.array([[float(xx), float(xy), float(xz)], [float(xy), float(yy), float(yz)],
                           [float(xz), float(yz), float(zz)]])
        assert smallest == pytest.approx(float(np.min(np.linalg.eigvalsh(tensor))), rel=1e-6)
