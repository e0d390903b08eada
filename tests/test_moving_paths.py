"""The paths of moving joints from the root (convert's base decision and legged checks), against a
walk up from every link, on random trees; and on chains too long for a path per link."""

from __future__ import annotations

import random

import numpy as np

from modelkit.convert.base import decide
from modelkit.convert.moving_paths import MovingPaths
from modelkit.model import Box, Geom, Inertial, Joint, JointType, Link, Robot
from modelkit.spatial import Pose

KINDS = (JointType.FIXED, JointType.REVOLUTE, JointType.PRISMATIC, JointType.BALL)


def _walked(robot: Robot, link: str) -> list[str]:
    """The moving joints above ``link``, root first, by walking up its parents."""
    parent_joint = {joint.child: joint for joint in robot.joints}
    found: list[str] = []
    while link in parent_joint:
        joint = parent_joint[link]
        if joint.type.moves:
            found.append(joint.name)
        link = joint.parent
    return found[::-1]


def _shared(one: list[str], two: list[str]) -> int:
    count = 0
    while count < min(len(one), len(two)) and one[count] == two[count]:
        count += 1
    return count


def test_paths_agree_with_a_walk_up_on_random_trees() -> None:
    rng = random.Random(7)
    for _ in range(500):
        count = rng.randint(1, 60)
        links = [Link(f"l{i}") for i in range(count)]
        joints = [Joint(f"j{i}", rng.choice(KINDS), f"l{rng.randrange(i)}", f"l{i}") for i in range(1, count)]
        robot = Robot("r", links, joints, root="l0")
        paths = MovingPaths(robot)
        walked = {link.name: _walked(robot, link.name) for link in links}
        for name, path in walked.items():
            assert paths.length(name) == len(path) and paths.joints(name) == path
        for _ in range(20):
            one, two = rng.choice(links).name, rng.choice(links).name
            assert paths.shared(one, two) == _shared(walked[one], walked[two])


def test_a_long_chain_lying_on_the_floor_is_decided() -> None:
    """10,000 hinges in a row along x, every link on the floor: a path per touching link was quadratic
    (33 s at 5,000 links); the paths share one tree now."""
    count = 10_000
    box = Geom(Box((0.1, 0.05, 0.05)))  # not round about the hinges: no wheels
    links = [Link(f"l{i}", Inertial(0.5, inertia=np.eye(3) * 1e-3), collisions=[box]) for i in range(count)]
    step = Pose(translation=np.array([0.1, 0.0, 0.0]))
    joints = [Joint(f"j{i}", JointType.REVOLUTE, f"l{i - 1}", f"l{i}", step, axis=(0.0, 1.0, 0.0))
              for i in range(1, count)]
    robot = Robot("r", links, joints, root="l0")
    paths = MovingPaths(robot)
    assert paths.length(f"l{count - 1}") == count - 1 and paths.shared("l5000", "l9000") == 5000
    assert paths.at(f"l{count - 1}", 4999) == "j5000"
    decision = decide(robot)  # the root's own body rests on the floor: welded, as an arm on a table
    assert decision.kind is JointType.FIXED and "rests on the ground" in decision.reason
