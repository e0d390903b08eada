"""yourdfpy runs in a child process that verify starts ahead (its import, ≈ 0.5 s, then runs on the
other core): the child gives the same facts and poses as yourdfpy in this process, to the bit; a
refused file is an engine error with yourdfpy's message; no child outlives the run."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.convert.api import write
from modelkit.verify.api import ENGINE_FILES, verify, welded_copy

pytest.importorskip("yourdfpy")
from modelkit.verify.engines import reference

PANTILT = (Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
           / "mobile_robot_pantilt.body")


def _children() -> set[int]:
    out: set[int] = set()
    for task in os.listdir("/proc/self/task"):
        with open(f"/proc/self/task/{task}/children") as f:
            out |= {int(pid) for pid in f.read().split()}
    return {pid for pid in out if os.path.exists(f"/proc/{pid}") and "Z" not in _state(pid)}


def _state(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"


def test_the_child_gives_what_yourdfpy_gives_here(tmp_path: Path) -> None:
    robot = welded_copy(modelkit.load(PANTILT))[0]
    path = tmp_path / "robot.urdf"
    write(robot, path, "urdf", options=ENGINE_FILES, force=True)
    root = str(robot.root)
    here = reference.YourdfpyKinematics(path, root)
    there = reference.YourdfpyModel(path, root, reference.yourdfpy_worker())
    try:
        assert there.dof_names() == here.dof_names() and len(here.dof_names()) == 4
        a, b = here.static(), there.static()
        assert set(a.links) == set(b.links) and set(a.joints) == set(b.joints)
        for name in a.links:
            assert a.links[name].mass == b.links[name].mass
            assert np.array_equal(a.links[name].inertia, b.links[name].inertia)
        rng = np.random.default_rng(5)
        for _ in range(3):
            q = {name: float(rng.uniform(-1.0, 1.0)) for name in here.dof_names()}
            mine, theirs = here.link_poses(q), there.link_poses(q)
            assert set(mine) == set(theirs)
            for link, pose in mine.items():
                assert np.array_equal(pose.rotation, theirs[link].rotation)
                assert np.array_equal(pose.translation, theirs[link].translation)
        assert there.settings["process"] == "child process"
    finally:
        there.close()


def test_a_file_yourdfpy_refuses_is_an_engine_error_from_the_child(tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>'
                   '<child link="missing"/></joint></robot>\n')
    worker = reference.yourdfpy_worker()
    with pytest.raises(reference.YourdfpyError, match="yourdfpy load failed"):
        reference.YourdfpyModel(bad, "a", worker)
    assert worker.proc.poll() is not None  # closed with the model that failed to load


def test_verify_runs_yourdfpy_in_its_child_and_leaves_no_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delitem(sys.modules, "yourdfpy", raising=False)  # as in a fresh `modelkit verify`
    before = _children()
    report = verify(PANTILT, None, ("mujoco", "pinocchio", "yourdfpy"), configurations=3, samples=2,
                    replay=False, driven=False)
    assert "yourdfpy" not in sys.modules  # imported in the child only
    assert report.engines["yourdfpy"]["process"] == "child process"
    checks = [c for c in report.checks if c.engine == "yourdfpy"]
    assert {c.layer for c in checks} == {1, 2} and all(c.passed for c in checks)
    assert _children() <= before
