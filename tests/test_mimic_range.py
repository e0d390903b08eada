"""MK326: a mimic that carries its follower past the follower's range somewhere in the leader's range.

Real faults it finds: example-robot-data's PR2 (each gripper's ``r_parallel_root_joint`` mimics its
finger at ×−1, so over the finger's [0, 0.548] rad it would go to [−0.548, 0] while its own range is
[0, 0.548]: a simulator holding the coupling locks the gripper shut), Fourier's Inspire hands (the
thumb) and Dexmate's f5d6 hands.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import validate
from tests.conftest import example_robot

URDF = """<robot name="thumb">
  <link name="palm"/><link name="a"/><link name="b"/>
  <joint name="pitch" type="revolute"><parent link="palm"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="{leader_low}" upper="0.6" effort="1" velocity="1"/></joint>
  <joint name="distal" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="1.2" effort="1" velocity="1"/>
    <mimic joint="pitch" multiplier="{multiplier}" offset="0"/></joint>
</robot>
"""


def _said(tmp_path: Path, leader_low: float, multiplier: float) -> list[str]:
    path = tmp_path / "thumb.urdf"
    path.write_text(URDF.format(leader_low=leader_low, multiplier=multiplier))
    return [f"{d.location}: {d.message} ({d.hint})" for d in validate(path).diagnostics if d.code == "MK326"]


def test_a_mimic_past_its_followers_range_is_said_with_the_range_the_coupling_allows(tmp_path: Path) -> None:
    (said,) = _said(tmp_path, -0.1, 2.4)  # the Inspire hand's thumb distal joint
    assert ':7:' in said  # the <mimic> element's line
    assert ('joint "distal" mimics "pitch" (2.4 × q + 0): over the leader\'s range [-0.1, 0.6] it would '
            "reach [-0.24, 1.44], past its own range [0, 1.2] by 0.24") in said
    assert "the coupling allows the leader [0, 0.5]" in said
    assert _said(tmp_path, 0.0, 2.0) == []  # [0, 1.2] exactly: within
    (none,) = _said(tmp_path, 0.0, -2.0)  # the image [-1.2, 0] meets the range at 0 only
    assert "only the leader at 0 keeps the follower in its range: check the mimic's multiplier" in none


def test_the_pr2_grippers_locked_by_their_mimics() -> None:
    said = [d.message for d in validate(example_robot("pr2_description/urdf/pr2.urdf")).diagnostics
            if d.code == "MK326"]
    assert sorted(m.split('"')[1] for m in said) == ["l_gripper_r_parallel_root_joint",
                                                    "r_gripper_r_parallel_root_joint"]
    assert all("past its own range [0, 0.548] by 0.548" in m for m in said)
    hints = [d.hint for d in validate(example_robot("pr2_description/urdf/pr2.urdf")).diagnostics
             if d.code == "MK326"]
    assert all(h is not None and h.startswith("only the leader at 0 keeps the follower") for h in hints)


@pytest.mark.parametrize("relative", ["panda_description/urdf/panda.urdf"])
def test_a_consistent_gripper_is_not_said(relative: str) -> None:
    assert not [d for d in validate(example_robot(relative)).diagnostics if d.code == "MK326"]
