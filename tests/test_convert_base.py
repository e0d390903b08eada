"""``--base fixed|floating|auto``: arms stay welded, robots that move themselves float, in every target."""

from __future__ import annotations

import subprocess
from pathlib import Path

import mujoco
import pybullet_data
import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.api import validate
from modelkit.cli import main
from modelkit.convert.api import convert
from modelkit.convert.base import decide
from modelkit.convert.options import WriteOptions
from modelkit.model import JointType
from tests.conftest import example_robot, require_tool
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

DATA = Path(pybullet_data.getDataPath())
KUKA = DATA / "kuka_iiwa" / "model.urdf"
PANDA = DATA / "franka_panda" / "panda.urdf"
A1 = DATA / "a1" / "a1.urdf"
LAIKAGO = DATA / "laikago" / "laikago_toes_zup.urdf"
RACECAR = DATA / "racecar" / "racecar.urdf"
R2D2 = DATA / "r2d2.urdf"
VISION60 = DATA / "quadruped" / "vision60.urdf"  # legs sideways at q = 0: its body is the lowest point
CUBE = DATA / "cube.urdf"


def _convert(source: Path, out: Path, base: str = "auto") -> list[tuple[str, str]]:
    result = convert([source], out, options=WriteOptions(base=base), force=True)
    assert result.status == 0, [str(d) for d in result.diagnostics]
    return [(n.code, n.message) for n in result.notes]


def _drop(path: Path, seconds: float = 1.0) -> float:
    """How far the first top-level body falls in ``seconds`` of zero-control simulation."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body = next(i for i in range(1, model.nbody) if model.body_parentid[i] == 0)
    start = float(data.xpos[body][2])
    while data.time < seconds:
        mujoco.mj_step(model, data)
    return start - float(data.xpos[body][2])


@pytest.mark.parametrize("source", [KUKA, PANDA], ids=["kuka_iiwa", "panda"])
def test_arm_is_welded_by_default_and_does_not_fall(source: Path, tmp_path: Path) -> None:
    out = tmp_path / "arm.xml"
    notes = _convert(source, out)
    assert b"freejoint" not in out.read_bytes()
    decided = [m for c, m in notes if c == "MK830"]
    assert len(decided) == 1 and "welded" in decided[0] and "rests on the ground" in decided[0]
    assert abs(_drop(out)) < 1e-9
    floating = tmp_path / "floating.xml"
    _convert(source, floating, "floating")
    assert b"<freejoint" in floating.read_bytes()
    assert _drop(floating) > 4.0  # the same arm set free falls (no floor in the output): the test can fail


@pytest.mark.parametrize(
    ("source", "why"),
    [(A1, "legs"), (LAIKAGO, "legs"), (RACECAR, "wheels"), (R2D2, "wheels"), (VISION60, "4 limbs"),
     (CUBE, "no moving joint")],
    ids=["a1", "laikago", "racecar", "r2d2", "vision60", "cube"],
)
def test_robots_that_move_themselves_float(source: Path, why: str, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    notes = _convert(source, out)
    root = etree.parse(str(out)).getroot()
    top = root.find("worldbody/body")
    assert top is not None and top.find("freejoint") is not None
    decided = [m for c, m in notes if c == "MK830"]
    assert len(decided) == 1 and "floating" in decided[0] and why in decided[0]
    fixed = tmp_path / "fixed.xml"
    notes = _convert(source, fixed, "fixed")
    assert b"freejoint" not in fixed.read_bytes()
    assert any(c == "MK830" and "as asked" in m for c, m in notes)


@pytest.mark.parametrize("side", ["left", "right"])
def test_a_hand_on_its_palm_is_welded(side: str, tmp_path: Path) -> None:
    """Allegro's hand (example-robot-data) has four limbs of four joints, which the legs rule would float;
    three of them (the fingers) point up from the palm at q = 0, so they are not legs."""
    source = example_robot(f"allegro_hand_description/urdf/allegro_{side}_hand.urdf")
    out = tmp_path / "hand.xml"
    notes = _convert(source, out)
    assert b"freejoint" not in out.read_bytes()
    decided = [m for c, m in notes if c == "MK830"]
    assert len(decided) == 1 and "welded" in decided[0] and "3 limb(s) point up" in decided[0]
    assert abs(_drop(out)) < 1e-9


def test_decide_reports_feet_and_wheels() -> None:
    a1 = validate(A1).robot
    assert a1 is not None
    decision = decide(a1)
    assert decision.kind is JointType.FLOATING
    assert all(f'"{leg}_toe"' in decision.reason for leg in ("FL", "FR", "RL", "RR"))
    car = validate(RACECAR).robot
    assert car is not None
    assert "left_rear_wheel_joint" in decide(car).reason


def test_source_answer_wins_unless_overridden(tmp_path: Path) -> None:
    floating = tmp_path / "a1.xml"
    _convert(A1, floating)
    back = tmp_path / "again" / "again.xml"
    notes = _convert(floating, back)  # MJCF with a free joint: the source says floating
    assert b"<freejoint" in back.read_bytes() and not [c for c, _ in notes if c in ("MK830", "MK831")]
    welded = tmp_path / "welded" / "welded.xml"
    notes = _convert(floating, welded, "fixed")
    assert b"freejoint" not in welded.read_bytes()
    overridden = [m for c, m in notes if c == "MK831"]
    assert len(overridden) == 1 and "floats" in overridden[0] and "welded as asked" in overridden[0]


def test_urdf_output_carries_the_base(tmp_path: Path) -> None:
    arm = tmp_path / "arm" / "arm.urdf"
    _convert(KUKA, arm)
    root = etree.parse(str(arm)).getroot()
    weld = [j for j in root.findall("joint") if j.find("parent").get("link") == "world"]  # type: ignore[union-attr]
    assert root.find("link").get("name") == "world"  # type: ignore[union-attr]
    assert len(weld) == 1 and weld[0].get("type") == "fixed"
    back = validate(arm).robot
    assert back is not None and back.root == "world" and back.root_joint is JointType.FIXED
    legged = tmp_path / "legged" / "a1.urdf"
    _convert(A1, legged)
    assert b'"world"' not in legged.read_bytes()
    free = tmp_path / "free" / "arm.urdf"
    _convert(KUKA, free, "floating")
    assert b'"world"' not in free.read_bytes()
    tool = require_tool("check_urdf")
    for path in (arm, legged, free):
        run = subprocess.run([tool, str(path)], capture_output=True, timeout=120)
        assert run.returncode == 0, run.stderr


def test_sdf_output_carries_the_base(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    arm = tmp_path / "arm" / "arm.sdf"
    _convert(KUKA, arm)
    model = etree.parse(str(arm)).getroot().find("model")
    assert model is not None
    welds = [j for j in model.findall("joint") if j.findtext("parent") == "world"]
    assert len(welds) == 1 and welds[0].get("type") == "fixed"
    legged = tmp_path / "legged" / "a1.sdf"
    _convert(A1, legged)
    legged_model = etree.parse(str(legged)).getroot().find("model")
    assert legged_model is not None
    assert not [j for j in legged_model.findall("joint") if j.findtext("parent") == "world"]
    for path in (arm, legged):
        assert not oracle_has_errors(sdf_oracle, path)
    back = validate(arm).robot
    assert back is not None and back.root_joint is JointType.FIXED


def test_body_output_carries_the_base(tmp_path: Path) -> None:
    arm = tmp_path / "arm" / "arm.body"
    _convert(KUKA, arm)
    back = validate(arm).robot
    assert back is not None and back.root_joint is JointType.FIXED
    legged = tmp_path / "legged" / "a1.body"
    _convert(A1, legged)
    back = validate(legged).robot
    assert back is not None and back.root_joint is JointType.FLOATING


def test_cli_base_option(tmp_path: Path) -> None:
    out = tmp_path / "a1.xml"
    run = CliRunner().invoke(main, ["convert", str(A1), "-o", str(out), "--base", "fixed"])
    assert run.exit_code == 0, run.output
    assert b"freejoint" not in out.read_bytes()
    assert "MK830" in run.output
    bad = CliRunner().invoke(main, ["convert", str(A1), "-o", str(out), "--base", "welded", "--force"])
    assert bad.exit_code == 2 and "welded" in bad.output


WELDED_URDF = """\
<robot name="r">
  <link name="world"/>
  <joint name="fix_base" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 0.5"/></joint>
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_urdf_world_weld_is_the_source_answer_and_keeps_its_name(tmp_path: Path) -> None:
    source = tmp_path / "r.urdf"
    source.write_text(WELDED_URDF)
    sdf = tmp_path / "sdf" / "r.sdf"
    notes = _convert(source, sdf)
    assert not [c for c, _ in notes if c in ("MK830", "MK831")]
    model = etree.parse(str(sdf)).getroot().find("model")
    assert model is not None
    (weld,) = [j for j in model.findall("joint") if j.findtext("parent") == "world"]
    assert weld.get("name") == "fix_base" and weld.get("type") == "fixed"
    urdf = tmp_path / "urdf" / "r.urdf"
    _convert(source, urdf)
    back = validate(urdf).robot
    assert back is not None and back.root == "world"
    assert [(j.name, j.child) for j in back.joints if j.parent == "world"] == [("fix_base", "base")]
    mjcf = tmp_path / "mjcf" / "r.xml"
    _convert(source, mjcf)
    body = etree.parse(str(mjcf)).getroot().find("worldbody/body")
    assert body is not None and body.get("name") == "base" and body.find("freejoint") is None
    assert body.get("pos") == "0 0 0.5"
    free = tmp_path / "free" / "r.xml"
    notes = _convert(source, free, "floating")
    assert b"<freejoint" in free.read_bytes()
    assert [c for c, _ in notes if c == "MK831"] == ["MK831"]


def test_our_urdf_of_a_robot_on_a_caster_floats_again(tmp_path: Path) -> None:
    """The tutorial's pan-tilt robot (a .body whose root is free) written to URDF has no `world` link
    (URDF's convention for a floating root) and a caster sphere fixed to its chassis that touches the
    ground. Read back, --base auto welded it ("the root's own body rests on the ground") and did not
    see its sphere wheels, so URDF → MJCF gave a robot nailed to the world without the wheels'
    simulator options. Now the two sphere wheels are wheels, and wheels float the robot."""
    body = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / \
        "model" / "mobile_robot_pantilt.body"
    urdf = tmp_path / "a" / "robot.urdf"
    assert CliRunner().invoke(main, ["convert", str(body), "-o", str(urdf)]).exit_code == 0
    checked = validate(urdf)
    assert checked.robot is not None
    decision = decide(checked.robot)
    assert decision.kind is JointType.FLOATING
    assert '"LeftWheel", "RightWheel"' in decision.reason and "beside a caster" in decision.reason
    mjcf = tmp_path / "b" / "robot.xml"
    result = CliRunner().invoke(main, ["convert", str(urdf), "-o", str(mjcf)])
    assert result.exit_code == 0, result.output
    assert "MK825" in result.output  # the wheels' <option> and stiff contact
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE


def _tree_urdf(root: str, joints: list[tuple[str, str, str]]) -> str:
    """A URDF of boxes: each (parent, child, joint origin xyz) a revolute joint about y; every link a
    1 kg box 5 cm wide around its frame, a foot (``*_foot``) a flat sole 20 × 10 × 3 cm, a ``palm``
    10 × 8 × 6 cm."""
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    def box(name: str) -> str:
        size = "0.2 0.1 0.03" if name.endswith("_foot") else "0.05 0.05 0.05"
        size = "0.1 0.08 0.06" if name == "palm" else size
        return f'<collision><geometry><box size="{size}"/></geometry></collision>'

    names = [root] + [child for _, child, _ in joints]
    links = [f'<link name="{name}">{inertial}{box(name)}</link>' for name in names]
    moving = [f'<joint name="{child}_joint" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
              f'<origin xyz="{xyz}"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="100" '
              'velocity="1"/></joint>' for parent, child, xyz in joints]
    return f'<robot name="r">{"".join(links)}{"".join(moving)}</robot>'


def _limb(parent: str, names: list[str], first: str, step: str) -> list[tuple[str, str, str]]:
    """A chain of joints from ``parent``: the first at ``first``, each next one ``step`` below."""
    chain, above = [], parent
    for i, name in enumerate(names):
        chain.append((above, name, first if i == 0 else step))
        above = name
    return chain


def test_a_biped_rooted_at_its_torso_stands_on_legs_below_a_waist(tmp_path: Path) -> None:
    """OpenLoong (fourier-robot-descriptions' ``qinglong.urdf``) hangs its legs from three waist joints
    below its torso, the root: the legs part below the root's frame with more joints each than the
    waist has, so the robot floats. Before, the feet rule wanted the legs to part at the root itself,
    and the humanoid was welded in the air by its torso."""
    waist = _limb("torso", ["waist_pitch", "waist_roll", "pelvis"], "0 0 -0.05", "0 0 -0.05")
    legs = [joint for side, y in (("l", "0.1"), ("r", "-0.1"))
            for joint in _limb("pelvis", [f"{side}_hip", f"{side}_knee", f"{side}_ankle", f"{side}_foot"],
                               f"0 {y} -0.05", "0 0 -0.3")]
    arms = [joint for side, y in (("la", "0.2"), ("ra", "-0.2"))
            for joint in _limb("torso", [f"{side}_shoulder", f"{side}_elbow", f"{side}_wrist"],
                               f"0 {y} 0.1", "0 0 -0.25")]
    path = tmp_path / "biped.urdf"
    path.write_text(_tree_urdf("torso", waist + legs + arms))
    robot = validate(path).robot
    assert robot is not None
    decision = decide(robot)
    assert decision.kind is JointType.FLOATING, decision.reason
    assert 'feet "l_foot", "r_foot"' in decision.reason
    # the same legs parting above the torso's frame (a waist that rises first) are not taken for legs
    raised = [("torso", "waist_pitch", "0 0 0.3"), *waist[1:]]
    path.write_text(_tree_urdf("torso", raised + legs + arms))
    robot = validate(path).robot
    assert robot is not None and decide(robot).kind is JointType.FIXED

@pytest.mark.parametrize(("segment", "kind"), [("finger", JointType.FIXED), ("leg", JointType.FLOATING)])
def test_limbs_resting_on_fingertips_are_a_hand_not_legs(tmp_path: Path, segment: str,
                                                          kind: JointType) -> None:
    """TriFinger (differentiable-robot-model's ``trifinger_edu.urdf``): three fingers hang from its frame
    to the table's level at q = 0, and the URDF leaves the root open; the same tree with its links named
    as legs is a tripod, and floats."""
    limbs = [joint for k, (x, y) in enumerate(((0.1, 0.0), (-0.05, 0.09), (-0.05, -0.09)))
             for joint in _limb("frame", [f"{segment}_{part}_{k}" for part in ("upper", "middle", "tip")],
                                f"{x} {y} -0.05", "0 0 -0.16")]
    path = tmp_path / "platform.urdf"
    path.write_text(_tree_urdf("frame", limbs))
    robot = validate(path).robot
    assert robot is not None
    decision = decide(robot)
    assert decision.kind is kind, decision.reason
    assert ("named as fingers" in decision.reason) is (segment == "finger"), decision.reason


def test_an_upper_body_whose_arms_hang_below_its_pelvis_stays_welded() -> None:
    """Alex (example-robot-data): its arms part after three spine joints, at shoulders 0.43 m above the
    pelvis (the root), and reach lower than the pelvis: hands, not feet."""
    source = example_robot("alex_description/urdf/alex_nub_hands.urdf")
    robot = validate(source).robot
    assert robot is not None
    decision = decide(robot)
    assert decision.kind is JointType.FIXED, decision.reason


def test_a_hand_whose_fingers_point_sideways_is_welded_not_legged(tmp_path: Path) -> None:
    """fourier-robot-descriptions' and Inspire's hands are modelled with the fingers level with the palm
    at q = 0: five limbs of two or more joints that do not point up, which the limbs rule took for
    legs (floated, "a legged robot"). Legs start around the body's centre of mass, a hand's fingers
    at one end of the palm: welded. A quadruped with its legs sideways (vision60) still floats."""
    fingers = [joint for i, y in enumerate(("-0.03", "-0.015", "0", "0.015", "0.03"))
               for joint in _limb("palm", [f"f{i}_a", f"f{i}_b", f"f{i}_c"], f"0.06 {y} 0", "0.04 0 0")]
    path = tmp_path / "hand.urdf"
    path.write_text(_tree_urdf("palm", fingers))
    robot = validate(path).robot
    assert robot is not None
    decision = decide(robot)
    assert decision.kind is JointType.FIXED, decision.reason
    assert "5 limbs" in decision.reason and "one end of its body" in decision.reason
    quadruped = validate(VISION60).robot
    assert quadruped is not None and decide(quadruped).kind is JointType.FLOATING


DISCS = """<robot name="discs">
  <link name="body"><inertial><mass value="2"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.3 0.2 0.05"/></geometry></collision></link>
  SIDES
</robot>"""
SIDE = """<link name="disc_{s}"><inertial><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.1" length="0.03"/></geometry>
    </collision></link>
  <joint name="disc_{s}" type="{kind}"><parent link="body"/><child link="disc_{s}"/>
    <origin xyz="0 {y} 0.1"/><axis xyz="0 1 0"/>{limit}</joint>"""


@pytest.mark.parametrize(("kind", "floats"), [("continuous", True), ("revolute", False)])
def test_a_wheel_turns_without_end(tmp_path: Path, kind: str, floats: bool) -> None:
    """Two discs on horizontal axes touching the ground float the robot as wheels only when their joints
    have no range: a round link on a limited hinge (icub-models' and example-robot-data's iCub: the ankle
    below the pitch joint) is no wheel, as the writers' wheel rules already had it."""
    limit = '<limit lower="-0.7" upper="0.4" effort="10" velocity="1"/>' if kind == "revolute" else ""
    sides = "\n  ".join(SIDE.format(s=s, y=y, kind=kind, limit=limit) for s, y in (("l", 0.15), ("r", -0.15)))
    path = tmp_path / "discs.urdf"
    path.write_text(DISCS.replace("SIDES", sides))
    robot = validate(path).robot
    assert robot is not None
    decision = decide(robot)
    assert (decision.kind is JointType.FLOATING) is floats
    assert ("drives on wheels" in decision.reason) is floats


def test_icub_stands_on_legs_not_wheels() -> None:
    robot = validate(example_robot("icub_description/robots/icub_reduced.urdf")).robot
    assert robot is not None
    decision = decide(robot)
    assert decision.kind is JointType.FLOATING and "legs" in decision.reason, decision.reason


COPTER = """<robot name="copter">
  <link name="body"><inertial><mass value="1.4"/><inertia ixx="0.05" iyy="0.05" izz="0.24" ixy="0" ixz="0"
    iyz="0"/></inertial><collision><geometry><box size="0.3 0.3 0.17"/></geometry></collision></link>
  ROTORS
</robot>"""
ROTOR = """<link name="rotor_{i}"><inertial><mass value="0.005"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="2e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder length="{thickness}" radius="0.14"/></geometry></collision></link>
  <joint name="rotor_{i}_joint" type="{kind}"><parent link="body"/><child link="rotor_{i}"/>
    <origin xyz="{x} {y} 0.1"/><axis xyz="0 0 1"/>{limit}</joint>"""


@pytest.mark.parametrize(("kind", "thickness", "floats"),
                         [("continuous", 0.005, True), ("revolute", 0.005, False),
                          ("continuous", 0.2, False)],
                         ids=["rotors", "limited", "thick"])
def test_a_multirotor_flies(tmp_path: Path, kind: str, thickness: float, floats: bool) -> None:
    """bullet-safety-gym's quadcopter (a box body resting on the ground, four propeller discs 5 mm thick on
    continuous joints about vertical axes) was welded, as an arm on its base is. Discs turning without end
    about vertical axes, clear of the ground, make it fly; a limited joint or a thick drum (a turntable)
    does not."""
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>' if kind == "revolute" else ""
    corners = [(0.2, 0.2), (-0.2, 0.2), (-0.2, -0.2), (0.2, -0.2)]
    rotors = "\n  ".join(ROTOR.format(i=i, x=x, y=y, kind=kind, limit=limit, thickness=thickness)
                         for i, (x, y) in enumerate(corners))
    path = tmp_path / "copter.urdf"
    path.write_text(COPTER.replace("ROTORS", rotors))
    robot = validate(path).robot
    assert robot is not None
    decision = decide(robot)
    assert (decision.kind is JointType.FLOATING) is floats, decision.reason
    assert ("flies on 4 rotors" in decision.reason) is floats, decision.reason
    if floats:
        _convert(path, tmp_path / "copter.xml")
        assert _drop(tmp_path / "copter.xml") > 1.0  # free: it falls without thrust, as a copter does


def test_rotors_limited_at_sdformats_no_limit_turn_without_end() -> None:
    """example-robot-data's iris (a URDF made from an SDF) keeps SDFormat's "no limit" as numbers: its four
    rotors are revolute joints limited to ±1e16 rad. They turn without end as a continuous joint does,
    so the quadrotor flies; it was welded as an arm is."""
    robot = validate(example_robot("iris_description/robots/iris.urdf")).robot
    assert robot is not None
    assert all(j.limits.lower == -1e16 for j in robot.joints if "rotor" in j.name)
    decision = decide(robot)
    assert decision.kind is JointType.FLOATING and "flies on 4 rotors" in decision.reason, decision.reason
