"""Layer 3b's calibrated tolerance (``replay.replay_layer``): 1e-8 rad times the model's own
amplification of a 1e-12 rad start difference, measured at run time in MuJoCo. A chaotic model
(a passive double pendulum) passes when the conversion is sound, though the engines part by far more
than 1e-8; a 1 % inertia error in the URDF PyBullet reads still fails, caught early while the
comparison is well conditioned; a non-finite state is the engine's failure, with its time."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import jsonschema
import pytest

import modelkit
from modelkit.convert import write
from modelkit.convert.notes import renames
from modelkit.convert.options import WriteOptions
from modelkit.model import JointType
from modelkit.verify.engines import mujoco as engine_mujoco
from modelkit.verify.engines import pybullet as engine_pybullet
from modelkit.verify.engines.protocol import TorqueLaw
from modelkit.verify.layers.replay import PERTURBATION, TOLERANCE, replay_layer
from modelkit.verify.report import VerifyReport, report_json
from modelkit.verify.report.html import render_html

PENDULUM = Path(__file__).parent / "replay" / "double_pendulum.urdf"
SECONDS, DT = 10.0, 1e-3
Written = tuple[Any, Path, Path, dict[str, Any], dict[str, Any]]
PASSIVE = TorqueLaw(("shoulder", "elbow"), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.3, 0.47), (0.0, 0.9))


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Written:
    robot = modelkit.load(PENDULUM)
    robot.root_joint = JointType.FIXED
    out = tmp_path_factory.mktemp("pendulum")
    # as verify writes the engines' files: the root is PyBullet's base (no `world` link)
    urdf_notes = write(robot, out / "p.urdf", options=WriteOptions(urdf_world_link=False))
    mjcf_notes = write(robot, out / "p.xml")
    maps = [{"link": renames(n, "link"), "joint": renames(n, "joint")} for n in (urdf_notes, mjcf_notes)]
    return robot, out / "p.urdf", out / "p.xml", maps[0], maps[1]


def _replay(written: Written, urdf: Path,
            law: TorqueLaw = PASSIVE) -> tuple[list[Any], list[Any], dict[str, Any]]:
    robot, _, mjcf, urdf_map, mjcf_map = written
    root = str(robot.root)
    mj = engine_mujoco.simulator(mjcf, mjcf_map, root=root, dt=DT)
    pb = engine_pybullet.simulator(urdf, urdf_map, root=root, dt=DT)
    try:
        return replay_layer(robot, [mj, pb], law, SECONDS, DT)
    finally:
        mj.close()
        pb.close()


def test_a_chaotic_sound_conversion_passes_on_its_measured_envelope(written: Any) -> None:
    checks, skips, calibration = _replay(written, written[1])
    assert not skips
    (check,) = checks
    record = calibration["pybullet"]
    assert check.quantity == "replay" and check.passed, check
    # the model amplifies a start difference by orders of magnitude (measured ×8e8 by 10 s) ...
    assert record["amplification_end"] > 1e4, record
    assert record["envelope_end"] == pytest.approx(record["amplification_end"] * PERTURBATION)
    # ... so the engines part by more than the fixed 1e-8 a well-conditioned model is held to
    assert record["largest_error"] > TOLERANCE, record
    assert record["margin"] > 1.0 and check.tolerance > TOLERANCE
    assert "margin" in check.detail and "amplification" in check.detail
    # report.json (schema) and report.html carry the envelope and the margin
    report = VerifyReport("p.urdf", checks=checks, replay=calibration)
    schema = json.loads((Path(__file__).parents[1] / "schemas" / "verify-report.schema.json").read_text())
    data = json.loads(report_json(report))
    jsonschema.validate(data, schema)
    assert data["replay"]["pybullet"]["envelope_end"] == record["envelope_end"]
    page = render_html(report)
    assert "the replay's tolerance" in page and f"{record['envelope_end']:.2e}" in page


def test_the_envelope_does_not_swallow_a_one_percent_inertia_error(written: Any, tmp_path: Path) -> None:
    text = written[1].read_text()
    start = text.index('<link name="lower">')
    head, tail = text[:start], text[start:]
    bad = tmp_path / "p_iyy.urdf"
    bad.write_text(head + tail.replace('iyy="0.0093"', 'iyy="0.009393"', 1))
    assert bad.read_text() != text
    checks, _, calibration = _replay(written, bad)
    (check,) = checks
    assert not check.passed, check
    record = calibration["pybullet"]
    assert record["worst_ratio_time"] < record["strict_until"] + 1.0, record  # caught early
    assert check.error > 10 * check.tolerance


def test_a_non_finite_state_is_the_engine_s_failure_with_its_time(written: Any, tmp_path: Path) -> None:
    """PyBullet reading a NaN moment of inertia integrates NaN from the first step: an engine-error
    check for PyBullet naming the time, not a replay difference."""
    text = written[1].read_text()
    start = text.index('<link name="lower">')
    bad = tmp_path / "p_nan.urdf"
    bad.write_text(text[:start] + text[start:].replace('iyy="0.0093"', 'iyy="nan"', 1))
    checks, _, calibration = _replay(written, bad)
    (error,) = [c for c in checks if c.quantity == "engine-error"]
    assert (error.layer, error.engine, error.passed) == (3, "pybullet", False) and math.isinf(error.error)
    assert "non-finite" in error.detail and "at t = 0.001 s" in error.detail, error
    assert not [c for c in checks if c.quantity == "replay"]  # nothing before the first step to compare
    assert calibration == {}
