"""The portability rules over hand-built models: multiple parents, mimic targets, libsdformat's
massless-link dropping and COLLADA meshes for MuJoCo."""

from __future__ import annotations

from modelkit.checks import run_rules
from modelkit.diagnostics import SourceLocation
from modelkit.model import Geom, Inertial, Joint, JointType, Link, Mesh, Mimic, Robot


def _link(name: str, mass: float | None = 1.0, line: int = 1) -> Link:
    inertial = None if mass is None else Inertial(mass=mass, inertia=[[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]])
    return Link(name, inertial=inertial, source=SourceLocation("r.urdf", line, 3))


def _joint(name: str, parent: str, child: str, kind: JointType = JointType.REVOLUTE, line: int = 1) -> Joint:
    return Joint(name, kind, parent, child, source=SourceLocation("r.urdf", line, 3))


def _codes(robot: Robot, code: str) -> list[str]:
    return [d.message for d in run_rules(robot) if d.code == code]


def test_second_parent_is_reported_once_at_the_second_joint() -> None:
    robot = Robot(
        "r",
        [_link("a"), _link("b"), _link("c")],
        [_joint("j1", "a", "b", line=10), _joint("j2", "a", "c", line=11), _joint("j3", "b", "c", line=12)],
        root="a",
        source_format="urdf",
    )
    found = [d for d in run_rules(robot) if d.code == "MK220"]
    assert len(found) == 1
    assert found[0].location == SourceLocation("r.urdf", 12, 3)
    assert '"c"' in found[0].message and "j2" in found[0].message and "line 11" in found[0].message


def test_mimic_targets() -> None:
    joints = [
        _joint("j1", "a", "b"),
        _joint("j2", "b", "c"),
        _joint("j3", "c", "d", JointType.FIXED),
        _joint("j4", "d", "e"),
        _joint("j5", "e", "f"),
        _joint("j6", "f", "g"),
    ]
    joints[1].mimic = Mimic("j1", 2.0)  # fine
    joints[3].mimic = Mimic("j_missing")
    joints[4].mimic = Mimic("j3")  # a fixed joint
    joints[5].mimic = Mimic("j6")  # itself
    robot = Robot("r", [_link(n) for n in "abcdefg"], joints, root="a", source_format="urdf")
    assert _codes(robot, "MK320") == ['joint "j4" mimics "j_missing", which is not a joint of this robot']
    invalid = _codes(robot, "MK321")
    assert len(invalid) == 2
    assert any("fixed joint" in m for m in invalid) and any("mimics itself" in m for m in invalid)


def test_mimic_loop() -> None:
    joints = [_joint("j1", "a", "b"), _joint("j2", "b", "c")]
    joints[0].mimic = Mimic("j2")
    joints[1].mimic = Mimic("j1")
    robot = Robot("r", [_link(n) for n in "abc"], joints, root="a", source_format="urdf")
    assert len(_codes(robot, "MK321")) == 2



def test_mimic_loop_names_only_the_joints_on_it() -> None:
    """A joint whose mimics lead into a loop is not on it; a 10,000-joint loop is found whole (in one pass
    over the leaders: a walk per joint took 23 s on 5,000); a joint whose name an earlier one holds is
    judged by its own mimic."""
    count = 10_000
    names = [chr(ord("a") + i % 26) + str(i) for i in range(count + 1)]
    joints = [_joint(f"j{i}", names[i], names[i + 1]) for i in range(count)]
    for i in range(1, count):
        joints[i].mimic = Mimic(f"j{i + 1 if i + 1 < count else 1}")  # j1 .. j9999 loop; j0 leads nowhere
    joints[0].mimic = Mimic("j5")  # into the loop, not on it
    robot = Robot("r", [_link(n) for n in names], joints, root=names[0], source_format="urdf")
    looped = _codes(robot, "MK321")
    assert len(looped) == count - 1 and not any('"j0"' in m for m in looped)
    twin = _joint("j0", "x", "y")  # a second "j0", mimicking j1, which never leads back to a "j0"
    twin.mimic = Mimic("j1")
    robot.joints.append(twin)
    robot.links += [_link("x"), _link("y")]
    assert len(_codes(robot, "MK321")) == count - 1

def test_massless_links_dropped_like_libsdformat() -> None:
    links = [_link("base"), _link("frame", None), _link("arm", None), _link("hand"), _link("tool", 0.0)]
    joints = [
        _joint("j_frame", "base", "frame", JointType.FIXED),  # lumped into base: fine
        _joint("j_arm", "base", "arm"),  # massless moving link: dropped with "hand"
        _joint("j_hand", "arm", "hand"),
        _joint("j_tool", "base", "tool", JointType.PRISMATIC),  # zero mass: dropped
    ]
    robot = Robot("r", links, joints, root="base", source_format="urdf")
    messages = _codes(robot, "MK322")
    assert len(messages) == 2
    assert any('"arm"' in m and "1 link(s) below" in m for m in messages)
    assert any('"tool"' in m for m in messages)
    robot.source_format = "body"  # only URDF goes through libsdformat's URDF parser
    assert _codes(robot, "MK322") == []


def test_massless_root_is_saved_by_a_massive_fixed_child() -> None:
    links = [_link("base", None), _link("body"), _link("wheel")]
    joints = [_joint("fix", "base", "body", JointType.FIXED), _joint("w", "body", "wheel")]
    robot = Robot("r", links, joints, root="base", source_format="urdf")
    assert _codes(robot, "MK322") == []
    robot.links[1].inertial = None
    assert len(_codes(robot, "MK322")) == 1  # the whole robot would be dropped
    assert "whole robot" in _codes(robot, "MK322")[0]


def test_collada_meshes_flagged_once_per_uri_for_urdf() -> None:
    link = _link("a")
    link.visuals = [Geom(Mesh(uri="package://p/m.dae")), Geom(Mesh(uri="package://p/m.dae"))]
    link.collisions = [Geom(Mesh(uri="package://p/m.stl"))]
    robot = Robot("r", [link], [], root="a", source_format="urdf")
    assert len(_codes(robot, "MK512")) == 1
    robot.source_format = "body"
    assert _codes(robot, "MK512") == []
