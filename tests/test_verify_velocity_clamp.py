"""Layer 3b lifts PyBullet's joint velocity clamp (100 rad/s by default; MuJoCo has none).

Unitree's G1 in example-robot-data: its light wrists are whipped by the arms under the replay's
well-conditioned law (MuJoCo: 157 rad/s on the right wrist roll at 3.3 s). With the clamp on, PyBullet
held them at 100 rad/s and the engines parted by 3.7 rad on a sound model, a FAIL; without it they
agree to ~5e-10 rad over 10 s. The clamp is set once per body (through the base): given per link,
the same call changed the links' dynamics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from modelkit.verify.api import verify

from .conftest import example_robot


@pytest.fixture(scope="module")
def g1() -> Path:
    return example_robot("g1_description/urdf/g1_29dof_rev_1_0.urdf")


def test_a_wrist_past_100_rad_per_s_replays_alike_in_both_engines(g1: Path, tmp_path: Path) -> None:
    report = verify(g1, out_dir=tmp_path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3,
                    samples=3, driven=False)
    (replay,) = [c for c in report.checks if c.quantity == "replay"]
    assert replay.passed, replay.detail
    assert replay.error < 1e-8, replay.detail  # round-off apart, as a well-conditioned model should be
    assert [c for c in report.checks if not c.passed] == []


def test_the_g1_replay_really_passes_the_clamp(g1: Path, tmp_path: Path) -> None:
    """The case above is the clamp's: MuJoCo's own replay of the same law passes 100 rad/s."""
    import modelkit
    from modelkit.convert.api import write
    from modelkit.convert.options import WriteOptions
    from modelkit.verify.api import welded_copy
    from modelkit.verify.engines.mujoco import simulator
    from modelkit.verify.layers.replay import default_law

    welded, _ = welded_copy(modelkit.load(g1))
    path = tmp_path / "g1.xml"
    write(welded, path, "mjcf", WriteOptions(), force=True)
    sim = simulator(path, {"link": {}, "joint": {}}, root=str(welded.root), dt=1e-3)
    try:
        q = np.asarray(sim.replay(default_law(welded), 4.0, 1e-3))
    finally:
        sim.close()
    speed = np.abs(np.diff(q, axis=0)).max() / 1e-3
    assert speed > 100.0, speed
