"""Layer 3b gives MuJoCo the inertias PyBullet's URDF importer diagonalised (products of inertia).

PyBullet keeps a tensor with products of inertia as principal moments and axes, computed by
``btMatrix3x3::diagonalize`` with a threshold of 1e-6, so it integrates a robot a little different
from the file. On example-robot-data's Romeo the two engines parted by 1.3e-10 rad after one step and
1.1e-7 rad at 0.29 s, over the calibrated tolerance (6.9e-8): a FAIL of a sound conversion. With
PyBullet's numbers in both engines they agree to round-off (about 1e-15 rad a step, 1e-10 at 10 s);
layer 3a still compares each engine's tensor with the source's."""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.verify.api import verify

from .conftest import example_robot


@pytest.fixture(scope="module")
def romeo() -> Path:
    return example_robot("romeo_description/urdf/romeo.urdf")


def test_pybullet_s_diagonalised_inertias_replay_alike_in_both_engines(romeo: Path, tmp_path: Path) -> None:
    report = verify(romeo, out_dir=tmp_path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3,
                    samples=3, driven=False)
    (replay,) = [c for c in report.checks if c.quantity == "replay"]
    assert replay.passed, replay.detail
    assert report.replay["pybullet"]["largest_error"] < 1e-9, report.replay
    (said,) = [s for s in report.skips if "diagonalised inertia" in s.reason]
    assert "link(s) with products of inertia" in said.reason
    assert [c for c in report.checks if not c.passed] == []
