"""What another format keeps for itself, and a target cannot hold, is said once: never dropped silently.

Before, a URDF joint's ``<safety_controller>``, ``<calibration>`` and ``<gazebo>`` block vanished in
every other target, and an MJCF output said nothing of the source's ``<gazebo>`` blocks or an SDF
model's plugins. Each case converts a small file and reads the notes a user sees.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import pytest

from modelkit.convert.api import convert
from modelkit.convert.notes import ConversionNote

INERTIA = '<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
URDF = f"""<robot name="r">
  <link name="a"><inertial><mass value="1"/>{INERTIA}</inertial>
    <collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="b"><inertial><mass value="1"/>{INERTIA}</inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" k_position="10" k_velocity="1"/>
    <calibration rising="0.1"/></joint>
  <gazebo reference="a"><mu1>0.2</mu1><mu2>0.2</mu2><kp>1e6</kp></gazebo>
  <gazebo reference="j"><provideFeedback>true</provideFeedback></gazebo>
  <gazebo><plugin name="p" filename="libmy_plugin.so"/></gazebo>
</robot>"""


def _notes(tmp_path: Path, target: str) -> list[ConversionNote]:
    source = tmp_path / "r.urdf"
    source.write_text(URDF)
    return convert([source], tmp_path / "out" / f"r.{target}").notes


def _about(notes: list[ConversionNote], *words: str) -> list[ConversionNote]:
    return [n for n in notes if all(w in n.message for w in words)]


@pytest.mark.parametrize("target", ["xml", "sdf", "body"])
def test_urdf_joint_data_is_said_once_in_every_other_target(tmp_path: Path, target: str) -> None:
    notes = _notes(tmp_path, target)
    safety = _about(notes, "joint j", "<safety_controller>")
    assert len(safety) == 1 and "soft_lower_limit -0.9" in safety[0].message and safety[0].code == "MK820"
    assert len(_about(notes, "joint j", "<calibration>", "rising 0.1")) == 1
    if target == "sdf":  # written as libsdformat converts it (tests/test_sdf_gazebo_tags.py)
        assert not _about(notes, "joint j", "<gazebo>") and not _about(notes, 'joint "j"', "<gazebo>")
        assert "<provide_feedback>true</provide_feedback>" in (tmp_path / "out" / "r.sdf").read_text()
    else:
        assert len(_about(notes, "joint j", "<gazebo> block", "<provideFeedback>")) == 1


def test_mjcf_says_what_of_the_gazebo_blocks_it_leaves_out_and_not_what_it_carries(tmp_path: Path) -> None:
    notes = _notes(tmp_path, "xml")
    link = _about(notes, "link a", "<gazebo> block")
    assert len(link) == 1 and "<kp>" in link[0].message and "mu1" not in link[0].message  # mu1: geom friction
    robot = _about(notes, "the robot's <gazebo> blocks")
    assert len(robot) == 1 and robot[0].code == "MK808"
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "r.xml"))
    assert [float(model.geom_friction[g][0]) for g in range(model.ngeom) if model.geom_contype[g]] == [0.2]


def test_sdf_writes_a_link_blocks_tags_and_notes_nothing_twice(tmp_path: Path) -> None:
    """Link a's block holds mu1, mu2 (its friction) and kp, which the SDF writer writes as libsdformat
    does (tests/test_sdf_gazebo_tags.py): nothing is left out, and convert adds no note of its own."""
    notes = _notes(tmp_path, "sdf")
    assert len(_about(notes, "<gazebo>", 'link "a"')) + len(_about(notes, "link a", "<gazebo>")) == 0
    written = (tmp_path / "out" / "r.sdf").read_text()
    assert "<kp>1e6</kp>" in written


def test_urdf_to_urdf_says_nothing_of_its_own_blocks(tmp_path: Path) -> None:
    notes = _notes(tmp_path, "urdf")
    # nothing left out; the one note on a <gazebo> block says its friction is also PyBullet's <contact>
    assert _about(notes, "<safety_controller>") == []
    assert [n.code for n in _about(notes, "<gazebo>")] == ["MK852"]
    assert _about(notes, "link a", "mu1 0.2", "also written as PyBullet's <contact>")
    written = (tmp_path / "out" / "r.urdf").read_text()
    assert "<safety_controller" in written and "<calibration" in written and "provideFeedback" in written


def test_sdf_model_plugin_is_named_by_its_library_in_mjcf(tmp_path: Path) -> None:
    source = tmp_path / "p.sdf"
    source.write_text(
        '<sdf version="1.9"><model name="m"><link name="a"><inertial><mass>1</mass></inertial></link>'
        '<plugin filename="gz-sim-wheel-slip-system" name="gz::sim::systems::WheelSlip"/></model></sdf>'
    )
    notes = convert([source], tmp_path / "out" / "p.xml").notes
    said = _about(notes, "SDF model plugins", "gz-sim-wheel-slip-system")
    assert len(said) == 1 and said[0].code == "MK808"


MJCF = """<mujoco model="o">
  <option timestep="0.001" integrator="RK4"><flag warmstart="disable"/></option>
  <worldbody>
    <body name="b" pos="0 0 1"><freejoint/>
      <geom type="box" size="0.1 0.1 0.1" mass="1" solref="0.01 1" solimp="0.8 0.9 0.01" margin="0.002"/>
    </body>
  </worldbody>
</mujoco>"""


def test_mjcf_options_and_contact_parameters_survive_mjcf_and_are_said_elsewhere(tmp_path: Path) -> None:
    source = tmp_path / "o.xml"
    source.write_text(MJCF)
    out = tmp_path / "m" / "o.xml"
    notes = convert([source], out).notes
    assert not [n for n in notes if n.code in ("MK851", "MK853")]
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.opt.timestep == 0.001 and model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
    assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_WARMSTART
    g = next(g for g in range(model.ngeom) if model.geom_contype[g])
    assert list(model.geom_solref[g]) == [0.01, 1.0] and model.geom_margin[g] == 0.002
    assert list(model.geom_solimp[g][:3]) == pytest.approx([0.8, 0.9, 0.01])
    for target in ("o.urdf", "o.sdf", "o.body"):
        notes = convert([source], tmp_path / target.replace(".", "_") / target).notes
        options = [n for n in notes if n.code == "MK853"]
        assert len(options) == 1 and "<option>" in options[0].message, target
        contact = [n for n in notes if n.code == "MK851" and "contact (and fluid) parameters" in n.message]
        assert len(contact) == 1 and "solref 0.01 1" in contact[0].message, target


PAIRS = """<mujoco model="cp"><worldbody>
  <body name="a"><freejoint/><geom name="ga" type="sphere" size="0.1" mass="1"/>
    <body name="b" pos="0 0 0.3"><joint name="j" type="hinge"/>
      <geom name="gb" type="sphere" size="0.1" mass="1"/></body></body></worldbody>
  <contact><pair geom1="ga" geom2="gb" friction="0.5 0.5 0.005 0.0001 0.0001"/><exclude body1="a" body2="b"/>
  </contact>
</mujoco>"""


def test_mjcf_contact_pairs_and_excludes_are_written_back_or_said(tmp_path: Path) -> None:
    source = tmp_path / "cp.xml"
    source.write_text(PAIRS)
    out = tmp_path / "m" / "cp.xml"
    notes = convert([source], out).notes
    model = mujoco.MjModel.from_xml_path(str(out))
    assert (model.npair, model.nexclude) == (1, 1) and list(model.pair_friction[0][:2]) == [0.5, 0.5]
    assert not [n for n in notes if n.code == "MK851"]
    for target in ("cp.urdf", "cp.sdf", "cp.body"):
        notes = convert([source], tmp_path / target.replace(".", "_") / target).notes
        said = [n for n in notes if n.code == "MK851" and "contact pairs" in n.message]
        assert len(said) == 1, target


def test_mjcf_options_and_pairs_are_written_in_clean_numbers(tmp_path: Path) -> None:
    """An MJCF source's <option> and <pair> numbers as the writers print every number (``.005`` →
    ``0.005``, ``5e-3`` → ``0.005``), names and words as written; MuJoCo compiles the same values."""
    source = tmp_path / "cn.xml"
    source.write_text(PAIRS.replace('<mujoco model="cp">', '<mujoco model="cp"><option timestep=".005" '
                                    'gravity="0 0 -9.810" integrator="implicitfast"/>')
                      .replace('friction="0.5 0.5 0.005 0.0001 0.0001"',
                               'friction=".5 .50 5e-3 1E-4 0.00010"'))
    out = tmp_path / "m" / "cn.xml"
    convert([source], out)
    text = out.read_text()
    option = ET.fromstring(text).find("option")
    assert option is not None
    got = [option.get(k) for k in ("timestep", "gravity", "integrator")]
    assert got == ["0.005", "0 0 -9.81", "implicitfast"]
    assert 'friction="0.5 0.5 0.005 0.0001 0.0001"' in text and 'geom1="ga" geom2="gb"' in text
    assert ".005" not in text.replace("0.005", "") and "9.810" not in text
    got, want = mujoco.MjModel.from_xml_path(str(out)), mujoco.MjModel.from_xml_path(str(source))
    assert got.opt.timestep == want.opt.timestep and list(got.opt.gravity) == list(want.opt.gravity)
    assert list(got.pair_friction[0]) == list(want.pair_friction[0])


WALKER = """<mujoco model="w"><default><geom contype="1" conaffinity="0" friction=".7 .1 .1"/></default>
  <worldbody><body name="a" pos="0 0 1"><freejoint/><geom type="capsule" size="0.05 0.2" mass="1"/>
    <body name="b" pos="0 0 -0.3"><joint name="j" type="hinge"/>
      <geom type="capsule" size="0.05 0.2" mass="1"/></body></body></worldbody>
</mujoco>"""


def test_mjcf_collision_filter_and_idle_coefficients_survive_mjcf(tmp_path: Path) -> None:
    """dm_control's walker: limbs of contype 1, conaffinity 0 touch the floor, never each other; its
    friction ".7 .1 .1" keeps torsional and rolling 0.1 for contacts MuJoCo mixes with a larger condim.
    Before, the output let the limbs collide (and excluded the touching pair) and wrote ".7" only."""
    source = tmp_path / "w.xml"
    source.write_text(WALKER)
    out = tmp_path / "m" / "w.xml"
    convert([source], out)
    a, b = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    solid = [g for g in range(b.ngeom) if b.geom_contype[g] or b.geom_conaffinity[g]]
    assert len(solid) == a.ngeom == 2 and b.nexclude == 0
    for g, h in zip(range(a.ngeom), solid, strict=True):
        assert (b.geom_contype[h], b.geom_conaffinity[h]) == (1, 0)
        assert list(b.geom_friction[h]) == pytest.approx(list(a.geom_friction[g]))


TOUCH = """<mujoco model="t"><worldbody><camera name="fixed" pos="0 -2 1"/><site name="top" pos="0 0 3"/>
  <body name="a" pos="0 0 1"><freejoint/><geom type="sphere" size="0.1" mass="1"/>
    <site name="toe" pos="0 0 -0.1"/></body></worldbody>
  <tendon><spatial name="cord"><site site="toe"/><site site="top"/></spatial></tendon>
  <sensor><touch name="toe_touch" site="toe"/><subtreelinvel name="vel" body="a"/>
    <tendonpos name="cord_length" tendon="cord"/><user name="custom" dim="1" needstage="pos" datatype="real"/>
  </sensor>
</mujoco>"""


def test_mjcf_to_mjcf_says_which_of_its_own_elements_it_does_not_write(tmp_path: Path) -> None:
    """Touch sensors, the sites they use and a world camera are not in the model's devices; MJCF to
    MJCF dropped them without a word (dm_control's hopper lost 3 sensors, 2 sites and 2 cameras).
    They are now written back (formats/mjcf/write_own), the tendon and its sensor too
    (formats/mjcf/write_transmissions); a user sensor, which needs the program's callback, is named."""
    source = tmp_path / "t.xml"
    source.write_text(TOUCH)
    notes = convert([source], tmp_path / "m" / "t.xml").notes
    (sensors,) = [n for n in notes if n.code == "MK806" and "sensors" in n.message]
    assert "1 of 4 MJCF sensors not written (custom)" in sensors.message
    assert not [n for n in notes if "MJCF tendons" in n.message]
    others = [n for n in notes if "sites" in n.message or "cameras" in n.message]
    assert not any("not written" in n.message for n in others)


SDF_FLAGS = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="m">
    <link name="base"><gravity>false</gravity><kinematic>true</kinematic><enable_wind>false</enable_wind>
      <velocity_decay><linear>0.1</linear></velocity_decay>
      <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
      <visual name="v"><geometry><box><size>0.1 0.1 0.1</size></box></geometry>
        <material><ambient>1 0 0 1</ambient><diffuse>1 0 0 1</diffuse></material></visual>
    </link>
    <link name="plain"><gravity>true</gravity>
      <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
    </link>
    <joint name="j" type="fixed"><parent>base</parent><child>plain</child></joint>
  </model>
</sdf>
"""


@pytest.mark.parametrize("target", ["xml", "urdf", "body"])
def test_sdf_link_flags_and_material_parameters_are_said(tmp_path: Path, target: str) -> None:
    """An SDF link's <gravity>, <kinematic>, <velocity_decay> (MJCF and .body said nothing before; URDF
    printed the reader's dict, and now carries them in a <gazebo> block: test_sdf_gazebo_blocks) and a
    visual's ambient colour; flags at SDFormat's defaults say nothing."""
    source = tmp_path / "m.sdf"
    source.write_text(SDF_FLAGS)
    out = tmp_path / "out" / f"m.{target}"
    notes = convert([source], out).notes
    flags = _about(notes, "SDF link flags")
    if target == "urdf":
        assert not flags, [n.message for n in notes]
        blocks = {b.get("reference"): b for b in ET.parse(out).getroot().findall("gazebo")}
        assert set(blocks) == {"base"}  # "plain" says only SDFormat's defaults
        assert [(c.tag, c.findtext("linear") if len(c) else c.text) for c in blocks["base"]] == [
            ("gravity", "false"), ("kinematic", "true"), ("velocity_decay", "0.1")]
    else:
        assert len(flags) == 1 and flags[0].code == "MK808", [n.message for n in notes]
        assert "gravity false, kinematic true, velocity_decay (linear 0.1)" in flags[0].message
        assert "enable_wind" not in flags[0].message and "link plain" not in flags[0].message
    # the ambient colour: the model's material holds its intensity (.body writes it, URDF says it drops
    # it); the SDF reader's exact colour is for SDF round trips, no note of its own
    assert len([n for n in notes if "ambient" in n.message]) == (1 if target == "urdf" else 0)
    assert not any("{" in n.message or "'" in n.message for n in notes), [n.message for n in notes]


MOCAP = """<mujoco model="mc"><worldbody>
 <body name="target" mocap="true" pos="0 0 1">
  <geom type="box" size="0.1 0.1 0.1" contype="0" conaffinity="0"/></body>
 <body name="arm" pos="0 0 0.5"><joint name="b" type="ball" range="0 45"/>
  <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.02"/></body>
</worldbody></mujoco>"""


def test_mjcf_mocap_and_ball_cone_are_kept_in_mjcf_and_said_elsewhere(tmp_path: Path) -> None:
    source = tmp_path / "mc.xml"
    source.write_text(MOCAP)
    out = tmp_path / "out" / "back.xml"
    convert([source], out)
    target = mujoco.MjModel.from_xml_path(str(out.with_name("back_target.xml")))
    assert target.body_mocapid[1] == 0  # the mocap body is one again (it was a plain welded body)
    arm = mujoco.MjModel.from_xml_path(str(out.with_name("back_mc.xml")))
    assert arm.jnt_limited[0] and abs(arm.jnt_range[0][1] - 0.785398163397) < 1e-9
    for suffix in ("urdf", "sdf", "body"):
        notes = convert([source], tmp_path / suffix / f"mc.{suffix}").notes
        assert len(_about(notes, "link target", "MJCF mocap flag")) == 1, suffix
        cone = _about(notes, "joint b", "cone limit")
        assert len(cone) == 1 and "(0 0.785398)" in cone[0].message and cone[0].code == "MK820", suffix


PHYSICS = """<mujoco model="ph"><compiler angle="radian"/><worldbody>
 <body name="a" pos="0 0 1" gravcomp="1">
  <joint name="j" type="hinge" axis="0 1 0" range="-1 1" margin="0.01" solreflimit="0.02 1"
    solimplimit="0.8 0.9 0.01" solreffriction="0.03 1" frictionloss="0.1" actuatorgravcomp="true"/>
  <inertial pos="0 0 -0.1" mass="1" diaginertia="0.01 0.01 0.001"/>
  <geom type="sphere" size="0.05"/></body>
</worldbody><actuator><motor joint="j" gear="2"/></actuator></mujoco>"""


def test_mjcf_gravity_compensation_and_joint_solver_parameters_kept_and_said(tmp_path: Path) -> None:
    """Before, MJCF → MJCF dropped gravcomp (the body then falls), the limit's and dry friction's
    solver parameters and actuatorgravcomp, and every other target said nothing of them."""
    source = tmp_path / "ph.xml"
    source.write_text(PHYSICS)
    out = tmp_path / "out" / "ph.xml"
    notes = convert([source], out).notes
    assert not _about(notes, "gravity compensation") and not _about(notes, "solver parameters")
    given, written = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    for array in ("body_gravcomp", "jnt_margin", "jnt_solref", "jnt_solimp", "dof_solref", "dof_solimp",
                  "jnt_actgravcomp", "dof_frictionloss"):
        assert (getattr(given, array) == getattr(written, array)).all(), array
    for suffix in ("urdf", "sdf", "body"):
        notes = convert([source], tmp_path / suffix / f"ph.{suffix}").notes
        grav = _about(notes, "link a: MJCF gravity compensation (gravcomp 1)")
        assert len(grav) == 1 and grav[0].code == "MK808", suffix
        solver = _about(notes, "joint j: MJCF joint solver parameters")
        assert len(solver) == 1 and solver[0].code == "MK820", suffix
        # solreflimit is MuJoCo's default: nothing lost, not named
        for word in ("margin 0.01", "solimplimit 0.8 0.9 0.01 0.5 2", "solreffriction 0.03 1",
                     "actuatorgravcomp true"):
            assert word in solver[0].message, (suffix, solver[0].message)
        assert "solreflimit" not in solver[0].message


def test_robot_records_are_named_not_dumped(tmp_path: Path) -> None:
    """A robot's MJCF tendons, equalities and keyframes are named (or counted) in the notes, not printed
    as the reader's records (before: ``wraps [{'type': 'joint', ...}]``, ``obj1id 1, obj2id 2``)."""
    source = tmp_path / "t.xml"
    source.write_text("""<mujoco model="t"><worldbody><body name="b"><joint name="j1" axis="0 1 0"/>
      <geom type="sphere" size="0.1"/><body name="c"><joint name="j2" axis="0 1 0"/>
      <geom type="sphere" size="0.1"/></body></body></worldbody>
      <tendon><fixed name="t1"><joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>
      <equality><joint joint1="j1" joint2="j2" polycoef="0 2 0 0 0"/></equality>
      <keyframe><key name="home"/><key name="other"/></keyframe></mujoco>""")
    notes = convert([source], tmp_path / "out" / "t.sdf").notes
    assert len(_about(notes, "MJCF tendons (1: t1)")) == 1
    assert len(_about(notes, "MJCF keyframes (stored joint positions) (2: home, other)")) == 1
    assert not any("{" in n.message or "obj1id" in n.message for n in notes), [n.message for n in notes]


def test_mjcf_fluid_model_kept_and_said(tmp_path: Path) -> None:
    """A geom's ellipsoid fluid model (fluidshape, fluidcoef: forces when the option sets a density or
    viscosity) was lost in every target without a note; MJCF → MJCF now writes it back."""
    source = tmp_path / "fl.xml"
    source.write_text("""<mujoco model="fl"><option density="1.2" viscosity="2e-5"/><worldbody>
      <body name="a" pos="0 0 1"><freejoint/><geom type="sphere" size="0.05" fluidshape="ellipsoid"
        fluidcoef="0.4 0.25 1.5 1 1"/></body></worldbody></mujoco>""")
    out = tmp_path / "out" / "fl.xml"
    convert([source], out)
    given, written = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    assert (given.geom_fluid[0] == written.geom_fluid[0]).all()  # the collision geom (the visual copy: none)
    assert not written.geom_fluid[1:].any()
    notes = convert([source], tmp_path / "urdf" / "fl.urdf").notes
    said = _about(notes, "link a: MJCF contact (and fluid) parameters")
    assert len(said) == 1 and "fluidcoef 0.4 0.25 1.5 1 1, fluidshape ellipsoid" in said[0].message


def test_mjcf_size_visual_and_statistic_written_back(tmp_path: Path) -> None:
    """<size memory>, <visual> and <statistic> (MuJoCo's memory, viewer and camera extent) were lost MJCF
    → MJCF without a note; they are written back, and another target says nothing of them (nothing of
    the robot is lost there)."""
    source = tmp_path / "g.xml"
    source.write_text("""<mujoco model="g"><size memory="10M"/>
      <visual><headlight ambient="0.5 0.5 0.5"/><global offwidth="800"/></visual>
      <statistic extent="2" center="0 0 1"/>
      <worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05"/></body></worldbody></mujoco>""")
    out = tmp_path / "out" / "g.xml"
    convert([source], out)
    given, written = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    assert written.narena == given.narena == 10 * 2**20
    assert written.vis.global_.offwidth == 800 and list(written.vis.headlight.ambient) == [0.5, 0.5, 0.5]
    assert written.stat.extent == 2.0
    notes = convert([source], tmp_path / "urdf" / "g.urdf").notes
    assert not [n for n in notes if "size" in n.message or "visual>" in n.message or "statistic" in n.message]


KEPT = """<mujoco model="kept">
  <worldbody>
    <camera name="overview" pos="0 -3 1"/>
    <light name="sun" pos="0 0 4" directional="true"/>
    <body name="arm" pos="0 0 1">
      <joint name="swing" axis="0 1 0" range="-2 2"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
      <site name="imu" pos="0 0 -0.25"/>
      <site name="tip" pos="0 0 -0.5"/>
      <camera name="eye" pos="0 0 -0.5"/>
      <body name="hand" pos="0 0 -0.5">
        <joint name="wrist" axis="0 1 0" range="-1 1"/>
        <geom type="sphere" size="0.05" mass="0.2"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="drive" joint="swing" gear="2"/>
    <intvelocity name="turn" joint="wrist" kp="5" actrange="-1 1"/>
  </actuator>
  <sensor>
    <accelerometer name="imu_acc" site="imu"/>
    <jointvel name="swing_vel" joint="swing"/>
    <touch name="tip_touch" site="tip"/>
  </sensor>
</mujoco>"""


@pytest.mark.parametrize("target", ["sdf", "body", "urdf"])
def test_mjcf_to_other_formats_names_what_the_model_does_not_carry(tmp_path: Path, target: str) -> None:
    """SDF and ``.body`` left out, without a word, the MJCF actuators the model does not hold (here an
    intvelocity servo), the sensors no device stands for, the world's camera and light and the sites
    devices do not use; URDF said so. Every target now names that part, and only it: the motor (a
    canonical actuator), the accelerometer (an IMU device) and the body's camera (a device) are written."""
    source = tmp_path / "kept.xml"
    source.write_text(KEPT)
    notes = convert([source], tmp_path / "out" / f"kept.{target}").notes
    said = {n.message.split(":")[0].split(" (")[0].lstrip("0123456789 ") + "|" + n.message for n in notes
            if n.code in ("MK806", "MK808")}
    by_kind = {key.split("|")[0]: key.split("|")[1] for key in said}
    assert set(by_kind) == {"MJCF actuators", "MJCF sensors", "MJCF cameras", "MJCF lights",
                            "MJCF sites"}, sorted(by_kind)
    for kind, names in (("MJCF actuators", ["turn"]), ("MJCF sensors", ["swing_vel", "tip_touch"]),
                        ("MJCF cameras", ["overview"]), ("MJCF lights", ["sun"]), ("MJCF sites", ["tip"])):
        message = by_kind[kind]
        if target == "urdf":  # the URDF writer counts
            assert message.startswith(f"{len(names)} {kind}"), message
        else:
            assert f"({len(names)}: {', '.join(names)})" in message, message
