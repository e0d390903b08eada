"""Geoms that collide through ``<contact><pair>`` alone (issue 17: outputs a user can use as is).

MJX models (jaxterity's G1, ``zoo/unitree_g1/g1_walk.xml``) give every geom ``contype="0"
conaffinity="0"`` and collide the feet with the floor, and with each other, by explicit pairs. Such a
geom is a collision shape: MuJoCo collides it through the pair. Until 2026-12-03 the reader took it for a
visual, so the URDF and SDF outputs had no collision at all and the robot fell through any floor. The
floor is the source's world, which a robot file does not hold, so its pairs are left out (MK851); the
MJCF writer then lets the paired geom collide with any default floor, with the pair's contact values.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main

_BLOCK = """<mujoco model="block">
  <default><geom contype="0" conaffinity="0" condim="1"/></default>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.01"/>
    <body name="base" pos="0 0 0.2">
      <freejoint/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
      <geom name="shell" type="sphere" size="0.05" rgba="1 0 0 1"/>
      <geom name="foot" type="box" size="0.1 0.1 0.02" pos="0 0 -0.1"/>
    </body>
  </worldbody>
  <contact>
    <pair name="foot_floor" geom1="foot" geom2="floor" condim="3" friction="0.6 0.6"/>
  </contact>
</mujoco>
"""


@pytest.fixture
def source(tmp_path: Path) -> Path:
    path = tmp_path / "block.xml"
    path.write_text(_BLOCK)
    return path


def _settled_height(model_file: Path, add_floor: bool) -> float:
    """The foot's lowest point after 1 s from 0.2 m up (on a default floor when ``add_floor``)."""
    spec = mujoco.MjSpec.from_file(str(model_file))
    if add_floor:
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    model = spec.compile()
    data = mujoco.MjData(model)
    while data.time < 1.0:
        mujoco.mj_step(model, data)
    foot = model.geom("foot").id
    return float(data.geom_xpos[foot][2] - model.geom_size[foot][2])


def test_a_paired_geom_is_a_collision_shape(source: Path) -> None:
    v = validate(source)
    assert v.errors == [] and v.robot is not None
    (link,) = v.robot.links
    assert [g.name for g in link.collisions] == ["foot"]  # the shell collides with nothing: a visual
    assert "shell" in [g.name for g in link.visuals]


def test_the_urdf_keeps_the_paired_geom_as_collision(source: Path, tmp_path: Path) -> None:
    target = tmp_path / "out" / "block.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
    assert result.exit_code == 0, result.output
    assert target.read_text().count("<collision") == 1


def test_the_mjcf_foot_lands_on_the_users_floor_as_on_the_sources(source: Path, tmp_path: Path) -> None:
    """The source on its own floor and the written MJCF on a default one land alike; the pair with
    the source's floor is said (MK851) with what the geom now carries."""
    target = tmp_path / "out" / "block.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
    assert result.exit_code == 0, result.output
    (note,) = [line for line in result.output.splitlines() if "MK851" in line]
    assert "'floor' is not in the written file" in note and "collides with any floor" in note, note
    assert "condim, friction" in note
    foot = next(line for line in target.read_text().splitlines() if 'name="foot"' in line)
    assert 'contype="1" conaffinity="0"' in foot and 'condim="3"' in foot, foot
    assert 'friction="0.6 0.005 0.0001"' in foot, foot
    assert abs(_settled_height(source, add_floor=False)) < 0.005  # the source stands on its floor
    assert abs(_settled_height(target, add_floor=True)) < 0.005  # ours on the user's
    shell = next(line for line in target.read_text().splitlines() if 'name="shell"' in line)
    assert 'class="visual"' in shell  # what collided with nothing still does not


def test_a_geom_that_already_touches_a_default_floor_is_left_as_it_is(tmp_path: Path) -> None:
    path = tmp_path / "block.xml"
    path.write_text(_BLOCK.replace('<geom name="foot"', '<geom name="foot" contype="1"'))
    target = tmp_path / "out" / "block.xml"
    result = CliRunner().invoke(main, ["convert", str(path), "-o", str(target)])
    assert result.exit_code == 0, result.output
    (note,) = [line for line in result.output.splitlines() if "MK851" in line]
    assert "collides with any floor" not in note
    foot = next(line for line in target.read_text().splitlines() if 'name="foot"' in line)
    assert "friction" not in foot and 'condim="1"' in foot, foot


def test_verify_counts_geoms_that_collide_by_pairs_alone(tmp_path: Path) -> None:
    """Two pads that touch each other only by a ``<pair>`` (contype 0, no floor): the source model and
    the written MJCF both have them as collision shapes, and layer 1 compares them (before, MuJoCo's
    adapter left them out and the shape sets differed)."""
    from modelkit.verify.api import verify

    path = tmp_path / "pads.xml"
    path.write_text(_BLOCK.replace(
        '<geom name="foot" type="box" size="0.1 0.1 0.02" pos="0 0 -0.1"/>',
        '<geom name="foot" type="box" size="0.1 0.1 0.02" pos="0 0 -0.1"/>\n'
        '      <body name="pad" pos="0.3 0 0"><joint type="hinge" axis="0 1 0"/>\n'
        '        <inertial pos="0 0 0" mass="0.1" diaginertia="0.001 0.001 0.001"/>\n'
        '        <geom name="pad" type="box" size="0.05 0.05 0.02"/></body>').replace(
        '<pair name="foot_floor" geom1="foot" geom2="floor" condim="3" friction="0.6 0.6"/>',
        '<pair name="foot_pad" geom1="foot" geom2="pad"/>'))
    report = verify(path, None, ("mujoco", "pinocchio"), configurations=5, samples=3, replay=False,
                    driven=False)
    assert report.errors == []
    assert list(report.failed) == []
    shapes = [c for c in report.checks if c.engine == "mujoco" and c.quantity == "shape-set"]
    assert shapes and all(c.passed for c in shapes)


# MuJoCo Menagerie's Apptronik Apollo: no geom collides and no pair is in the robot file; its scene
# pairs the soles with its floor. Menagerie keeps collision shapes in geom group 3 (visuals in 2).
_SCENE_PAIRED = """<mujoco model="walker">
  <default>
    <geom contype="0" conaffinity="0"/>
    <default class="visual"><geom group="2"/></default>
    <default class="collision"><geom group="3" rgba="0 1 0 0.4"/></default>
  </default>
  <worldbody>
    <body name="pelvis" pos="0 0 0.3">
      <freejoint/>
      <inertial pos="0 0 0" mass="2" diaginertia="0.02 0.02 0.02"/>
      <geom class="visual" type="sphere" size="0.08"/>
      <geom class="collision" type="capsule" size="0.06 0.05"/>
      <body name="shin" pos="0 0 -0.15">
        <joint name="knee" axis="0 1 0" range="-1 1"/>
        <inertial pos="0 0 -0.05" mass="0.5" diaginertia="0.002 0.002 0.001"/>
        <geom class="visual" type="cylinder" size="0.03 0.05" pos="0 0 -0.05"/>
        <geom name="sole" class="collision" type="box" size="0.08 0.04 0.01" pos="0 0 -0.11"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_file_that_collides_nothing_itself_keeps_its_group_3_geoms_as_collisions(tmp_path: Path) -> None:
    """Every output has the two collision shapes; the MJCF keeps them colliding nothing, as the source
    (its scene pairs them); the URDF stands on PyBullet's plane instead of falling through it."""
    import pybullet as p
    import pybullet_data

    source = tmp_path / "walker.xml"
    source.write_text(_SCENE_PAIRED)
    robot = validate(source).robot
    assert robot is not None
    assert {link.name: len(link.collisions) for link in robot.links} == {"pelvis": 1, "shin": 1}
    assert all(len(link.visuals) >= 1 for link in robot.links)
    urdf = tmp_path / "out" / "walker.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(urdf)])
    assert result.exit_code == 0, result.output
    client = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=client)
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=client)
        body = p.loadURDF(str(urdf), [0, 0, 0.3], physicsClientId=client)
        for _ in range(480):
            p.stepSimulation(physicsClientId=client)
        assert p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2] > 0.1
    finally:
        p.disconnect(client)
    xml = tmp_path / "out" / "walker.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(xml)])
    assert result.exit_code == 0, result.output
    m = mujoco.MjModel.from_xml_path(str(xml))
    assert not any(m.geom_contype) and not any(m.geom_conaffinity) and m.npair == 0  # as the source
    assert sum(int(g) == 3 for g in m.geom_group) == 2


def test_group_3_geoms_that_collide_nothing_stay_visuals_where_the_file_collides(tmp_path: Path) -> None:
    text = _SCENE_PAIRED.replace('<geom name="sole" class="collision"', '<geom name="sole" contype="1"')
    source = tmp_path / "walker.xml"
    source.write_text(text)
    robot = validate(source).robot
    assert robot is not None
    assert {link.name: len(link.collisions) for link in robot.links} == {"pelvis": 0, "shin": 1}
