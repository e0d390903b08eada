"""Massless frame links as MJCF ``<site>``s (MK873), as MuJoCo Menagerie writes them, and back.

A URDF's pure frames (UR5's ``base`` and ``tool0``, Panda's ``panda_hand_tcp``, ANYmal C's camera
chains) are sites in the body they hang on, where MuJoCo puts them (checked against Pinocchio's
forward kinematics of the source URDF); ``--frame-bodies`` gives the old bodies; the sites come back as
links in URDF (check_urdf reads them) and as ``<frame>``s in SDF, and stay sites through MJCF.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.cli import main
from modelkit.convert import WriteOptions, write
from modelkit.convert.frames import frame_links
from modelkit.convert.notes import ConversionNote
from modelkit.formats.reading import read_model
from modelkit.model import (
    Actuator,
    Device,
    DeviceKind,
    Inertial,
    Joint,
    JointType,
    Link,
    LoopConstraint,
    Robot,
)
from modelkit.spatial import Pose

from .conftest import example_robot, require_tool

mujoco = pytest.importorskip("mujoco")

UR5 = "ur_description/urdf/ur5_robot.urdf"
PANDA = "panda_description/urdf/panda.urdf"
GO1 = "go1_description/urdf/go1.urdf"
ANYMAL = "anymal_c_simple_description/urdf/anymal.urdf"
FRAMES = {UR5: ["tool0", "base"], PANDA: ["panda_hand_tcp"]}


def _robot(relative: str) -> Robot:
    robot = read_model(example_robot(relative)).robot
    assert robot is not None
    return robot


def _mjcf(robot: Robot, path: Path, sites: bool = True) -> tuple[object, list[ConversionNote]]:
    notes = write(robot, path, options=WriteOptions(frame_sites=sites))
    return mujoco.MjModel.from_xml_path(str(path)), notes


def test_which_links_are_frames() -> None:
    """Measured on example-robot-data: whole massless chains are frames, links with shapes are not."""
    assert frame_links(_robot(UR5)) == ["tool0", "base"]  # ee_link has a collision box: a body
    assert frame_links(_robot(PANDA)) == ["panda_hand_tcp"]
    go1 = frame_links(_robot(GO1))
    assert len(go1) == 7 and all(n.startswith(("camera_optical_", "camera_laserscan_link_")) for n in go1)
    anymal = _robot(ANYMAL)
    frames = frame_links(anymal)
    children = anymal.children_of()
    leaves = [n for n in frames if not children.get(n)]
    assert len(leaves) == 10 and len(frames) == 18
    assert "depth_camera_front_camera_parent" in frames  # the massless parent of a chain
    assert not any(n.endswith("_camera") for n in frames)  # the camera bodies carry shapes


def _small() -> Robot:
    """a (the root) → f (massless) → g (1 kg); a → h (massless leaf); a → s (massless, an IMU)."""
    heavy = Inertial(1.0, (0, 0, 0), np.eye(3) * 0.01)
    imu = Device("imu", "imu", canonical=DeviceKind.IMU)
    return Robot("r", root="a", root_joint=JointType.FIXED,
                 links=[Link("a", heavy), Link("f"), Link("g", heavy), Link("h"), Link("s", devices=[imu])],
                 joints=[Joint("af", JointType.FIXED, "a", "f"), Joint("fg", JointType.FIXED, "f", "g"),
                         Joint("ah", JointType.FIXED, "a", "h", origin=Pose(np.eye(3), (0, 0, 1))),
                         Joint("as", JointType.FIXED, "a", "s")])


def test_a_massless_link_carrying_a_body_or_named_elsewhere_is_no_frame() -> None:
    assert frame_links(_small()) == ["h"]
    moving = _small()
    moving.joints[2].type = JointType.REVOLUTE
    assert frame_links(moving) == []
    looped = _small()
    looped.loops.append(LoopConstraint("loop", "fixed", "h", "g"))
    assert frame_links(looped) == []
    driven = _small()
    driven.actuators.append(Actuator("ah"))
    assert frame_links(driven) == []
    weighed = _small()
    weighed.links[3].inertial = Inertial(1e-9, (0, 0, 0), np.zeros((3, 3)))
    assert frame_links(weighed) == []
    zero = _small()
    zero.links[3].inertial = Inertial(0.0, (0, 0, 0), np.zeros((3, 3)))
    assert frame_links(zero) == ["h"]


def test_a_site_name_taken_by_a_device_site_is_renamed(tmp_path: Path) -> None:
    """MuJoCo needs unique site names: the root's IMU writes site "imu" first (a body's own devices come
    before the frames below it), so a frame link named "imu" is site "imu_2" (MK800 of the link)."""
    robot = _small()
    robot.links[3].name = robot.joints[2].child = "imu"
    robot.links[0].devices, robot.links[4].devices = robot.links[4].devices, []
    model, notes = _mjcf(robot, tmp_path / "m.xml")
    assert model.site("imu").bodyid[0] == model.site("imu_2").bodyid[0] == model.body("a").id
    assert model.site("imu_2").pos.tolist() == [0.0, 0.0, 1.0]
    assert ("link", "imu", "imu_2") in [n.renamed for n in notes if n.code == "MK800"]
    assert "imu as site imu_2 (in a)" in next(n.message for n in notes if n.code == "MK873")


@pytest.mark.parametrize("relative", [UR5, PANDA])
def test_frames_are_sites_where_pinocchio_puts_the_links(relative: str, tmp_path: Path) -> None:
    pinocchio = pytest.importorskip("pinocchio")
    robot = _robot(relative)
    sites, notes = _mjcf(robot, tmp_path / "sites" / "m.xml")
    bodies, old_notes = _mjcf(robot, tmp_path / "bodies" / "m.xml", sites=False)
    frames = FRAMES[relative]
    assert bodies.nbody - sites.nbody == len(frames)
    assert sites.nsite == len(frames) and bodies.nsite == 0
    mk873 = [n for n in notes if n.code == "MK873"]
    assert len(mk873) == 1 and all(name in mk873[0].message for name in frames)
    assert not any(n.code == "MK873" for n in old_notes)
    assert not any(n.code == "MK816" and any(f" {f} " in n.message for f in frames) for n in notes)

    source = str(example_robot(relative))
    pin = pinocchio.buildModelFromUrdf(source)
    pdata = pin.createData()
    data = mujoco.MjData(sites)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = pinocchio.neutral(pin)
        for j in range(1, pin.njoints):
            name = pin.names[j]
            lower, upper = pin.lowerPositionLimit[pin.idx_qs[j]], pin.upperPositionLimit[pin.idx_qs[j]]
            value = rng.uniform(max(lower, -3.0), min(upper, 3.0))
            q[pin.idx_qs[j]] = value
            data.qpos[sites.jnt_qposadr[sites.joint(name).id]] = value
        pinocchio.framesForwardKinematics(pin, pdata, q)
        mujoco.mj_kinematics(sites, data)
        for name in frames:
            placed = pdata.oMf[pin.getFrameId(name)]
            site = data.site(name)
            assert np.max(np.abs(site.xpos - placed.translation)) < 1e-9, name
            assert np.max(np.abs(site.xmat.reshape(3, 3) - placed.rotation)) < 1e-9, name


def test_anymal_camera_chains_are_sites(tmp_path: Path) -> None:
    robot = _robot(ANYMAL)
    sites, _ = _mjcf(robot, tmp_path / "sites" / "m.xml")
    bodies, _ = _mjcf(robot, tmp_path / "bodies" / "m.xml", sites=False)
    frames = frame_links(robot)
    assert bodies.nbody - sites.nbody == len(frames) == 18
    for name in frames:
        assert sites.site(name).bodyid[0] > 0
    # a chain's leaf sits where the bodies put it, in the body of the camera's real ancestor
    d_sites, d_bodies = mujoco.MjData(sites), mujoco.MjData(bodies)
    mujoco.mj_kinematics(sites, d_sites)
    mujoco.mj_kinematics(bodies, d_bodies)
    for name in frames:
        assert np.max(np.abs(d_sites.site(name).xpos - d_bodies.body(name).xpos)) < 1e-12
        assert np.max(np.abs(d_sites.site(name).xmat - d_bodies.body(name).xmat)) < 1e-12


def test_frame_bodies_on_the_command_line(tmp_path: Path) -> None:
    source = str(example_robot(UR5))
    runner = CliRunner()
    default = runner.invoke(main, ["convert", source, "-o", str(tmp_path / "a" / "ur5.xml")])
    bodies = runner.invoke(main, ["convert", source, "-o", str(tmp_path / "b" / "ur5.xml"), "--frame-bodies"])
    assert default.exit_code == 0 and bodies.exit_code == 0, default.output + bodies.output
    assert "MK873" in default.output and "MK873" not in bodies.output
    text = (tmp_path / "a" / "ur5.xml").read_text()
    assert '<site name="tool0" pos="0 0.0823 0" euler="-1.57079632679 0 0"/>' in text
    assert '<body name="tool0"' in (tmp_path / "b" / "ur5.xml").read_text()


@pytest.mark.parametrize("relative", [UR5, PANDA])
def test_urdf_to_mjcf_to_urdf_gives_the_links_back(relative: str, tmp_path: Path) -> None:
    robot = _robot(relative)
    write(robot, tmp_path / "mid" / "m.xml")
    middle = read_model(tmp_path / "mid" / "m.xml").robot
    assert middle is not None
    assert {s["name"] for s in middle.extras["mjcf_sites"]} == set(FRAMES[relative])
    notes = write(middle, tmp_path / "end" / "back.urdf")
    assert not any(n.code == "MK808" and "sites" in n.message for n in notes)
    back = read_model(tmp_path / "end" / "back.urdf").robot
    assert back is not None
    names = {lk.name for lk in back.links} - {"world"}  # Panda: the weld --base auto settled
    assert names == {lk.name for lk in robot.links} - {"world"}
    poses, source_poses = back.world_poses(), robot.world_poses()
    for name in FRAMES[relative]:
        assert back.link(name).inertial is None  # type: ignore[union-attr]
        parent = next(j.parent for j in robot.joints if j.child == name)
        was, now = source_poses[parent].inverse() @ source_poses[name], poses[parent].inverse() @ poses[name]
        assert np.max(np.abs(np.asarray(was.rotation) - np.asarray(now.rotation))) < 1e-12
        assert np.max(np.abs(np.asarray(was.translation) - np.asarray(now.translation))) < 1e-12
    checked = subprocess.run([require_tool("check_urdf"), str(tmp_path / "end" / "back.urdf")],
                             capture_output=True, text=True, timeout=120)
    assert checked.returncode == 0, checked.stderr
    for name in FRAMES[relative]:
        assert f"child(1):  {name}" in checked.stdout or f"  {name}\n" in checked.stdout, checked.stdout

    # MJCF → MJCF keeps them as sites; MJCF → SDF writes them as frames
    write(middle, tmp_path / "again" / "m.xml")
    again = mujoco.MjModel.from_xml_path(str(tmp_path / "again" / "m.xml"))
    assert {again.site(i).name for i in range(again.nsite)} == set(FRAMES[relative])
    write(middle, tmp_path / "sdf" / "m.sdf")
    sdf = (tmp_path / "sdf" / "m.sdf").read_text()
    for name in FRAMES[relative]:
        assert f'<frame name="{name}" attached_to=' in sdf


def test_verify_finds_the_frames_among_the_sites_of_a_default_mjcf(tmp_path: Path) -> None:
    """``verify robot.urdf --mjcf robot.xml`` on convert's default file: the frame links are sites
    there, found as the source's links (link and joint sets complete) at their poses (layer 2)."""
    pytest.importorskip("pinocchio")
    from modelkit.verify.api import verify

    write(_robot(UR5), tmp_path / "ur5.xml")
    report = verify(example_robot(UR5), mjcf=tmp_path / "ur5.xml", engines=("mujoco", "pinocchio"),
                    replay=False, driven=False, configurations=5, samples=2)
    assert not report.errors
    checks = {(c.engine, c.quantity): c for c in report.checks}
    assert checks[("mujoco", "link-set")].error == 0.0, checks[("mujoco", "link-set")].detail
    assert checks[("mujoco", "joint-set")].error == 0.0
    assert report.failed == [], [c.detail for c in report.failed]


EEF = """<mujoco model="hand">
  <worldbody>
    <body name="hand" quat="0.7071068 0.7071068 0 0">
      <freejoint/>
      <geom type="box" size="0.04 0.04 0.02" mass="0.5"/>
      <body name="eef" pos="0 0 0.05" quat="0.707 0 -0.707 0">
        <site name="grip_site" size="0.01" rgba="1 1 0 1" group="2"/>
        <site name="ee_x" pos="0.1 0 0" quat="0.707105 0 0.707108 0" type="cylinder" size="0.005 0.1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_the_sites_of_an_mjcf_frame_body_go_with_it(tmp_path: Path) -> None:
    """robosuite's grippers hang their controller's sites (``grip_site``, ``ee_x``...) on ``eef``, a
    massless body without a joint: a frame link, written as a site in ``hand``. Its sites were lost
    with it (MK808 named them); they are now written in ``hand`` too, where MuJoCo puts them."""
    source = tmp_path / "hand.xml"
    source.write_text(EEF)
    robot = read_model(source).robot
    assert robot is not None and frame_links(robot) == ["eef"]
    b, notes = _mjcf(robot, tmp_path / "m" / "hand.xml")
    assert not [n for n in notes if n.code == "MK808"], [n.message for n in notes]
    a = mujoco.MjModel.from_xml_string(EEF)
    da, db = mujoco.MjData(a), mujoco.MjData(b)
    mujoco.mj_forward(a, da)
    mujoco.mj_forward(b, db)
    for name in ("grip_site", "ee_x"):
        i, j = (mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name) for m in (a, b))
        assert mujoco.mj_id2name(b, mujoco.mjtObj.mjOBJ_BODY, int(b.site_bodyid[j])) == "hand"
        np.testing.assert_allclose(db.site_xpos[j], da.site_xpos[i], rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(db.site_xmat[j], da.site_xmat[i], rtol=0.0, atol=1e-12)
        assert (b.site_type[j], b.site_group[j]) == (a.site_type[i], a.site_group[i])
