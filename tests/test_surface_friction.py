"""A collision shape's own friction travels between URDF, SDF and MJCF, into what each consumer reads.

Before, an MJCF geom's ``friction``, an SDF collision's ``<surface><friction>`` and a URDF link's
PyBullet ``<contact>`` were dropped by every writer without a note, and ``validate`` called our own
URDF output's ``<contact>`` an element URDF does not define (MK123). Each case here loads the written
file in its consumer (MuJoCo, PyBullet, libsdformat) and reads the friction back from the engine.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pybullet
import pytest

from modelkit.api import validate
from modelkit.convert.api import convert
from modelkit.formats.reading import read_model
from modelkit.model import SurfaceFriction
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>'
)
BOX = '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'

URDF = f"""<robot name="r"><link name="a">{INERTIAL}{BOX}
  <contact><lateral_friction value="0.3"/><rolling_friction value="0.01"/><spinning_friction value="0.02"/>
  <stiffness value="30000"/><damping value="1000"/></contact>
</link></robot>"""
MJCF = """<mujoco model="r"><worldbody><body name="a" pos="0 0 1"><freejoint/>
  <geom type="box" size="0.1 0.1 0.1" mass="1" friction="0.3 0.02 0.01" condim="6"/>
</body></worldbody></mujoco>"""
SDF = """<sdf version="1.9"><model name="r"><link name="a">
  <inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>
    <surface><friction><ode><mu>0.3</mu><mu2>0.3</mu2></ode>
      <bullet><rolling_friction>0.01</rolling_friction></bullet></friction></surface></collision>
</link></model></sdf>"""
SOURCES = {"urdf": URDF, "xml": MJCF, "sdf": SDF}
# what each source says: SDF has no torsional coefficient of MuJoCo's or PyBullet's meaning
EXPECTED = {
    "urdf": SurfaceFriction(0.3, 0.02, 0.01),
    "xml": SurfaceFriction(0.3, 0.02, 0.01),
    "sdf": SurfaceFriction(0.3, None, 0.01),
}


def _base_dynamics(urdf: Path) -> tuple[float, ...]:
    """PyBullet's ``getDynamicsInfo`` of the file's base link, loaded as PyBullet users load it."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(urdf), physicsClientId=client)
        return tuple(pybullet.getDynamicsInfo(body, -1, physicsClientId=client))
    finally:
        pybullet.disconnect(client)


def _source(tmp_path: Path, kind: str) -> Path:
    path = tmp_path / f"source.{kind}"
    path.write_text(SOURCES[kind])
    return path


@pytest.mark.parametrize("kind", sorted(SOURCES))
def test_each_reader_holds_the_shape_friction(tmp_path: Path, kind: str) -> None:
    robot = read_model(_source(tmp_path, kind)).robot
    assert robot is not None
    link = robot.link("a")
    assert link is not None and len(link.collisions) == 1
    assert link.collisions[0].friction == EXPECTED[kind]


def test_pybullet_contact_is_not_called_unknown_but_its_typos_are(tmp_path: Path) -> None:
    clean = _source(tmp_path, "urdf")
    assert [d.code for d in validate(clean).diagnostics if d.code == "MK123"] == []
    typo = tmp_path / "typo.urdf"
    typo.write_text(URDF.replace("lateral_friction", "lateral_fricton"))
    found = [d for d in validate(typo).diagnostics if d.code == "MK123"]
    assert len(found) == 1 and "lateral_fricton" in found[0].message


def test_mujoco_default_friction_is_not_a_source_choice(tmp_path: Path) -> None:
    """condim 3 leaves torsional and rolling without effect; MuJoCo's default is nobody's choice."""
    path = tmp_path / "d.xml"
    path.write_text(MJCF.replace(' friction="0.3 0.02 0.01" condim="6"', ' friction="1 0.02 0.01"'))
    robot = read_model(path).robot
    assert robot is not None and robot.links[-1].collisions[0].friction is None


def test_mjcf_condim_1_mixes_by_mujocos_rule_in_mjcf_output(tmp_path: Path) -> None:
    """A geom of condim 1 is frictionless only against other condim-1 geoms: MuJoCo mixes two geoms of
    equal priority by the larger condim and friction, so on a default floor (condim 3, friction 1) it
    slides with friction 1 (dm_control's humanoid: condim 1, friction 0.7). Its own sliding friction
    is kept, and MJCF output keeps its condim and priority, so the same floor gives the same contact."""
    path = tmp_path / "c.xml"
    path.write_text(MJCF.replace(' friction="0.3 0.02 0.01" condim="6"', ' friction="0.7" condim="1"'))
    robot = read_model(path).robot
    assert robot is not None and robot.links[-1].collisions[0].friction == SurfaceFriction(0.7, 0.0, 0.0)
    out = tmp_path / "o" / "c.xml"
    convert([path], out)
    spec = mujoco.MjSpec.from_file(str(out))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qpos[2] = 0.099  # resting on the floor
    mujoco.mj_forward(model, data)
    assert data.ncon > 0
    contact = data.contact[0]
    assert contact.dim == 3 and contact.friction[0] == pytest.approx(1.0)  # as the source on that floor


@pytest.mark.parametrize("kind", sorted(SOURCES))
def test_mujoco_reads_the_written_friction(tmp_path: Path, kind: str) -> None:
    out = tmp_path / "out" / "r.xml"
    convert([_source(tmp_path, kind)], out)
    model = mujoco.MjModel.from_xml_path(str(out))
    geoms = [g for g in range(model.ngeom) if model.geom_contype[g] or model.geom_conaffinity[g]]
    assert len(geoms) == 1
    g = geoms[0]
    expected = EXPECTED[kind]
    assert model.geom_friction[g][0] == pytest.approx(expected.sliding, abs=1e-12)
    assert model.geom_condim[g] == (6 if expected.rolling else 4 if expected.torsional else 3)
    assert model.geom_friction[g][2] == pytest.approx(expected.rolling or 0.0, abs=1e-12)
    if expected.torsional:
        assert model.geom_friction[g][1] == pytest.approx(expected.torsional, abs=1e-12)
    # another format's friction wins against a default floor's; an MJCF source keeps MuJoCo's own rule
    assert model.geom_priority[g] == (0 if kind == "xml" else 1)


@pytest.mark.parametrize("kind", sorted(SOURCES))
def test_pybullet_reads_the_written_friction(tmp_path: Path, kind: str) -> None:
    out = tmp_path / "out" / "r.urdf"
    convert([_source(tmp_path, kind)], out)
    info = _base_dynamics(out)
    expected = EXPECTED[kind]
    assert info[1] == pytest.approx(expected.sliding)  # lateral
    assert info[6] == pytest.approx(expected.rolling or 0.0)  # rolling
    assert info[7] == pytest.approx(expected.torsional or 0.0)  # spinning
    assert [d.code for d in validate(out).diagnostics if d.code == "MK123"] == []


@pytest.mark.parametrize("kind", sorted(SOURCES))
def test_sdf_holds_the_written_friction(tmp_path: Path, kind: str, sdf_oracle: Path) -> None:  # noqa: F811
    out = tmp_path / "out" / "r.sdf"
    result = convert([_source(tmp_path, kind)], out)
    assert not oracle_has_errors(sdf_oracle, out)
    robot = read_model(out).robot
    assert robot is not None
    link = robot.link("a")
    assert link is not None
    written = link.collisions[0].friction
    expected = EXPECTED[kind]
    assert written == SurfaceFriction(expected.sliding, None, expected.rolling)
    lost = [n for n in result.notes if n.code == "MK851" and "torsional" in n.message]
    if expected.torsional:  # SDF's <torsional> is another model: said, not silently dropped
        assert len(lost) == 1 and "torsional friction of 0.02" in lost[0].message
    else:
        assert lost == []


@pytest.mark.parametrize("kind", sorted(SOURCES))
def test_body_says_it_cannot_hold_shape_friction(tmp_path: Path, kind: str) -> None:
    result = convert([_source(tmp_path, kind)], tmp_path / "out" / "r.body")
    lost = [n for n in result.notes if n.code == "MK851" and "own friction" in n.message]
    assert len(lost) == 1 and "sliding 0.3" in lost[0].message


def test_round_trip_urdf_mjcf_urdf_keeps_the_contact(tmp_path: Path) -> None:
    middle = tmp_path / "m" / "r.xml"
    convert([_source(tmp_path, "urdf")], middle)
    back = tmp_path / "b" / "r.urdf"
    convert([middle], back)
    robot = read_model(back).robot
    assert robot is not None
    link = robot.link("a")
    assert link is not None and link.collisions[0].friction == EXPECTED["urdf"]


def test_anisotropic_sdf_friction_is_said_where_it_cannot_be_held(tmp_path: Path) -> None:
    path = tmp_path / "a.sdf"
    path.write_text(SDF.replace("<mu2>0.3</mu2>", "<mu2>0.6</mu2>"))
    for target in ("r.xml", "r.urdf"):
        result = convert([path], tmp_path / target.replace(".", "_") / target)
        lost = [n for n in result.notes if n.code == "MK851"]
        assert len(lost) == 1 and "0.6" in lost[0].message, target
    result = convert([path], tmp_path / "sdf" / "r.sdf")
    robot = read_model(tmp_path / "sdf" / "r.sdf").robot
    assert robot is not None
    assert robot.links[0].collisions[0].friction == SurfaceFriction(0.3, None, 0.01, 0.6)


@pytest.mark.parametrize("target", ["r.xml", "r.sdf", "r.body"])
def test_pybullet_contact_model_is_kept_in_urdf_and_said_elsewhere(tmp_path: Path, target: str) -> None:
    source = _source(tmp_path, "urdf")
    back = tmp_path / "u" / "r.urdf"
    convert([source], back)
    info = _base_dynamics(back)
    assert (info[8], info[9]) == (pytest.approx(1000.0), pytest.approx(30000.0))  # damping, stiffness
    result = convert([source], tmp_path / "o" / target)
    said = [n for n in result.notes if n.code == "MK851" and "PyBullet <contact> parameters" in n.message]
    assert len(said) == 1 and "damping 1000" in said[0].message and "stiffness 30000" in said[0].message


def test_gazebo_mu_of_a_urdf_link_reaches_mujoco_and_sdf(tmp_path: Path) -> None:
    path = tmp_path / "g.urdf"
    path.write_text(
        f'<robot name="r"><link name="a">{INERTIAL}{BOX}</link>'
        '<gazebo reference="a"><mu1>0.7</mu1><mu2>0.7</mu2></gazebo></robot>'
    )
    out = tmp_path / "m" / "r.xml"
    convert([path], out)
    model = mujoco.MjModel.from_xml_path(str(out))
    assert [float(model.geom_friction[g][0]) for g in range(model.ngeom) if model.geom_contype[g]] == [0.7]
    result = convert([path], tmp_path / "s" / "r.sdf")
    assert not [n for n in result.notes if n.code == "MK808"]  # the block is carried as <surface>
    robot = read_model(tmp_path / "s" / "r.sdf").robot
    assert robot is not None and robot.links[0].collisions[0].friction == SurfaceFriction(0.7)
    # URDF to URDF: the block as written, and the same friction as PyBullet's <contact>, which
    # PyBullet reads (it ignores <gazebo>: the source in PyBullet has its default 0.5), said in MK852
    assert _base_dynamics(path)[1] == pytest.approx(0.5)
    same = tmp_path / "u" / "r.urdf"
    result = convert([path], same)
    assert same.read_text().count("<mu1>") == 1
    assert _base_dynamics(same)[1] == pytest.approx(0.7)
    said = [n for n in result.notes if n.code == "MK852" and "PyBullet reads no <gazebo> block" in n.message]
    assert len(said) == 1 and "mu1 0.7" in said[0].message


SURFACE = """<sdf version="1.9"><model name="r"><link name="a">
  <inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>
    <surface><bounce><restitution_coefficient>0.5</restitution_coefficient></bounce>
      <friction><ode><mu>0.4</mu><mu2>0.4</mu2><fdir1>1 0 0</fdir1></ode>
        <torsional><coefficient>0.02</coefficient></torsional></friction>
      <contact><ode><kp>1e6</kp></ode></contact></surface></collision>
</link></model></sdf>"""


def test_sdf_surface_beyond_friction_is_kept_in_sdf_and_said_elsewhere(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    source = tmp_path / "s.sdf"
    source.write_text(SURFACE)
    out = tmp_path / "o" / "r.sdf"
    result = convert([source], out)
    assert not [n for n in result.notes if n.code in ("MK851", "MK808")]
    assert not oracle_has_errors(sdf_oracle, out)
    text = out.read_text()
    kept_parts = (
        "<restitution_coefficient>0.5<", "<fdir1>1 0 0<", "<coefficient>0.02<", "<kp>1e6<", "<mu>0.4<"
    )
    for kept in kept_parts:
        assert kept in text, kept
    for target in ("r.xml", "r.urdf", "r.body"):
        notes = convert([source], tmp_path / target.replace(".", "_") / target).notes
        said = [n for n in notes if n.code == "MK851" and "SDF surface parameters" in n.message]
        assert len(said) == 1 and "<bounce>" in said[0].message and "<contact>" in said[0].message, target
