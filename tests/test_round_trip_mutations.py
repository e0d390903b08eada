"""The round trips can fail: a deliberately wrong writer is caught by them.

``test_round_trips.py`` passes when X → Y → X gives the source back. That proves little unless a
writer that gets something wrong makes it fail. Here each writer, in turn, is replaced by one that
writes a slightly wrong robot (a mass 1 % off, an axis reversed, a joint 1 mm away, a tensor 5 %
off, a centre of mass 1 mm away, a joint limit 0.1 off) and the same trip, with the same comparison
and the same list of documented losses, must report the fault by its quantity.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import modelkit.convert.api as convert_api
from modelkit.convert.compare import compare_robots
from modelkit.convert.notes import renames
from modelkit.convert.registry import load_writer
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose

from .conftest import CORPUS, TUTORIAL
from .test_round_trips import EXPECTED_LOSSES, FAMILY_TARGET, _read, _settled, _trip

SOURCES = {
    "body": TUTORIAL / "mobile_robot_pantilt.body",
    "urdf": CORPUS / "kuka_experimental" / "kuka_kr16_support" / "urdf" / "kr16_2.urdf",
    "mjcf": CORPUS / "dm_control_suite" / "dm_control" / "suite" / "acrobot.xml",
    "sdf": CORPUS / "sdformat_urdf" / "sdformat_test_files" / "models" / "joint_revolute_axis"
    / "joint_revolute_axis.sdf",
}


def _hinge(robot: Robot) -> Joint:
    """The first revolute joint that moves a link with mass: the one every mutation touches."""
    links = {lk.name: lk for lk in robot.links}
    for joint in robot.joints:
        link = links[joint.child]
        if joint.type is JointType.REVOLUTE and link.inertial is not None and link.inertial.mass > 0:
            return joint
    raise AssertionError(f"{robot.name}: no revolute joint moves a mass")


def _link(robot: Robot) -> Link:
    child = _hinge(robot).child
    return next(lk for lk in robot.links if lk.name == child)


def _mass(robot: Robot) -> None:
    inertial = _link(robot).inertial
    assert inertial is not None
    inertial.mass *= 1.01


def _axis(robot: Robot) -> None:
    joint = _hinge(robot)
    joint.axis = -np.asarray(joint.axis, dtype=float)


def _origin(robot: Robot) -> None:
    joint = _hinge(robot)
    moved = np.asarray(joint.origin.translation) + np.array([0.0, 0.0, 1e-3])
    joint.origin = Pose(joint.origin.rotation, moved)


def _inertia(robot: Robot) -> None:
    inertial = _link(robot).inertial
    assert inertial is not None
    inertial.inertia = np.asarray(inertial.inertia, dtype=float) * 1.05


def _com(robot: Robot) -> None:
    inertial = _link(robot).inertial
    assert inertial is not None
    inertial.com = np.asarray(inertial.com, dtype=float) + np.array([1e-3, 0.0, 0.0])


def _limit(robot: Robot) -> None:
    joint = next(j for j in robot.joints if j.type is JointType.REVOLUTE and np.isfinite(j.limits.upper))
    joint.limits.upper += 0.1


# mutation → the quantities that may report it (a reversed axis or a moved joint also shows as poses)
MUTATIONS: dict[str, tuple[Callable[[Robot], None], tuple[str, ...]]] = {
    "mass": (_mass, ("mass",)),
    "axis": (_axis, ("axis",)),
    "origin": (_origin, ("pose",)),
    "inertia": (_inertia, ("inertia",)),
    "com": (_com, ("com",)),
    "limit": (_limit, ("limit-upper",)),
}
CASES = [(family, through, mutation) for family in SOURCES for through in ("urdf", "sdf", "mjcf", "body")
         if through != FAMILY_TARGET[family] for mutation in MUTATIONS
         if mutation != "limit" or family == "urdf"]  # the other sources' hinges are unlimited


@pytest.mark.parametrize(("family", "through", "mutation"), CASES, ids=["-".join(c) for c in CASES])
def test_a_wrong_writer_fails_the_round_trip(family: str, through: str, mutation: str, tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    path = SOURCES[family]
    if not path.is_file():
        pytest.fail(f"{path} is missing: the mutation check needs it")
    mutate, quantities = MUTATIONS[mutation]
    source = _read(path)

    def wrong_writer(target: str):  # type: ignore[no-untyped-def]
        real = load_writer(target)
        if target != through:
            return real

        def write(prepared: Robot, ctx: object) -> object:
            robot = copy.deepcopy(prepared)
            mutate(robot)
            return real(robot, ctx)  # type: ignore[arg-type]

        return write

    monkeypatch.setattr(convert_api, "load_writer", wrong_writer)
    final, notes = _trip(source, through, FAMILY_TARGET[family], tmp_path)
    differences = compare_robots(_settled(source, notes), final, renames(notes, "link"))
    expected = EXPECTED_LOSSES.get((path.name, through))
    if expected is not None:
        differences = [d for d in differences if not expected[1](d)]
    assert any(d.quantity in quantities for d in differences), (
        f"a writer to {through} that got the {mutation} wrong passed the round trip: "
        + "; ".join(str(d) for d in differences[:5]))


@pytest.mark.parametrize("family", list(SOURCES))
def test_the_mutated_sources_trip_exactly_with_the_real_writers(family: str, tmp_path: Path) -> None:
    """The control: without a mutation the same trips are exact (up to documented losses), so the
    differences above come from the wrong writer."""
    source = _read(SOURCES[family])
    for through in ("urdf", "sdf", "mjcf", "body"):
        if through == FAMILY_TARGET[family]:
            continue
        final, notes = _trip(source, through, FAMILY_TARGET[family], tmp_path / through)
        differences = compare_robots(_settled(source, notes), final, renames(notes, "link"))
        expected = EXPECTED_LOSSES.get((SOURCES[family].name, through))
        if expected is not None:
            differences = [d for d in differences if not expected[1](d)]
        assert differences == [], (through, [str(d) for d in differences[:5]])
