"""Shared test fixtures: where the corpus and samples are, and oracle availability."""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import settings

from modelkit.model import Robot

# No timing assertions in unit tests: Hypothesis's default 200 ms deadline per example is one, and it
# failed a property test (the XML number parser) while other suites loaded the 2-core machine. The
# properties themselves are unchanged.
settings.register_profile("modelkit", deadline=None)
settings.load_profile("modelkit")

# Mesh-check outcomes are not kept on disk between tests (a test that damages a mesh or counts loads must
# see every load); tests/test_mesh_cache.py turns the cache on in a folder of its own.
os.environ["MODELKIT_CACHE_DIR"] = "off"

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO.parent / "shared" / "corpus"
SAMPLES = REPO / "samples"
TUTORIAL = SAMPLES / "choreonoid_ros2_mobile_robot_tutorial" / "model"

# A clean two-link pendulum (a copy of Choreonoid's misc/pendulum.body) for tests that must run
# without the shared corpus.
PENDULUM_BODY = """\
format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: Pendulum
root_link: BASE
links:
  -
    name: BASE
    joint_type: fixed
    center_of_mass: [ 0, 0, 0.1 ]
    mass: 10.0
    inertia: [ 0.06667, 0, 0, 0, 0.06667, 0, 0, 0, 0.06667 ]
    elements:
      - { type: Shape, translation: [ 0, 0, 0.1 ], geometry: { type: Box, size: [ 0.2, 0.2, 0.2 ] } }
  -
    name: ARM
    parent: BASE
    translation: [ 0.125, 0, 0.1 ]
    joint_type: revolute
    joint_id: 0
    joint_axis: [ 1, 0, 0 ]
    center_of_mass: [ 0, 0, 0.5 ]
    mass: 1.0
    inertia: [ 0.0835417, 0, 0, 0, 0.0835417, 0, 0, 0, 0.000416667 ]
    elements:
      - { type: Shape, translation: [ 0, 0, 0.5 ], geometry: { type: Box, size: [ 0.05, 0.05, 1.0 ] } }
"""


def example_robot_data() -> Path | None:
    """The `robots` folder of the example-robot-data wheel (PyPI; a test dependency), or None."""
    import sysconfig

    for key in ("purelib", "platlib"):
        robots = Path(sysconfig.get_paths()[key]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            return robots
    return None


def example_robot(relative: str) -> Path:
    """A file of example-robot-data's ``robots`` folder; the test is skipped when the wheel is missing
    (a test dependency, so CI fails on that skip)."""
    import pytest

    robots = example_robot_data()
    path = robots / relative if robots is not None else None
    if path is None or not path.is_file():
        pytest.skip(f"example-robot-data is not installed (a test dependency): {relative}")
    return path


# Skips that are answers, not missing tools: a corpus file that is not text for a test that reads
# text. In CI (MODELKIT_REQUIRE_ORACLES) every other skip fails the run (see pytest_sessionfinish).
SKIPS_ALLOWED_IN_CI = (r"^not UTF-8 text$",)


def corpus_bodies() -> list[Path]:
    return sorted(CORPUS.rglob("*.body")) if CORPUS.is_dir() else []


def require_tool(name: str) -> str:
    """The path of a peer tool used as an oracle; skip without it, unless CI demands oracles."""
    path = shutil.which(name)
    if path is None:
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail(f"{name} is required in CI (MODELKIT_REQUIRE_ORACLES is set) but not installed")
        pytest.skip(f"{name} not installed (apt-get install liburdfdom-tools)")
    return path


@pytest.fixture
def corpus() -> Path:
    if not CORPUS.is_dir():
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail(f"corpus not found at {CORPUS}")
        pytest.skip("shared corpus not available")
    return CORPUS


@pytest.fixture(scope="session", autouse=True)
def _mujoco_warnings_without_log_file() -> Iterator[list[str]]:
    """Tests that compile models with MuJoCo directly (oracles, writer outputs) must not leave
    MuJoCo's ``MUJOCO_LOG.TXT`` in the working directory: its warnings are collected instead."""
    try:
        import mujoco
    except ImportError:
        yield []
        return
    collected: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: collected.append(str(message)))
    try:
        yield collected
    finally:
        mujoco.set_mju_user_warning(previous)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """In CI a skipped test is a test that did not run: a missing oracle, engine, corpus or data
    package. Fail the run for every skip whose reason is not in ``SKIPS_ALLOWED_IN_CI``."""
    if not os.environ.get("MODELKIT_REQUIRE_ORACLES"):
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is None:
        return
    unexplained = []
    for report in reporter.stats.get("skipped", []):
        longrepr = report.longrepr
        reason = str(longrepr[2]) if isinstance(longrepr, tuple) else str(longrepr)
        reason = reason.removeprefix("Skipped: ")
        if not any(re.search(allowed, reason) for allowed in SKIPS_ALLOWED_IN_CI):
            unexplained.append(f"{report.nodeid}: {reason}")
    if unexplained:
        count = len(unexplained)
        reporter.write_line(f"CI (MODELKIT_REQUIRE_ORACLES) does not accept {count} skip(s):", red=True)
        for line in unexplained:
            reporter.write_line("  " + line, red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def links_below(robot: Robot, tops: set[str]) -> set[str]:
    """``tops`` and every link below them in ``robot``."""
    out = set(tops)
    changed = True
    while changed:
        changed = False
        for joint in robot.joints:
            if joint.parent in out and joint.child not in out:
                out.add(joint.child)
                changed = True
    return out


def assert_pybullet_refuses(urdf: Path) -> None:
    """PyBullet's ``loadURDF`` refuses the file (in a connection of its own)."""
    import pybullet

    client = pybullet.connect(pybullet.DIRECT)
    try:
        with pytest.raises(pybullet.error):
            pybullet.loadURDF(str(urdf), physicsClientId=client)
    finally:
        pybullet.disconnect(client)
