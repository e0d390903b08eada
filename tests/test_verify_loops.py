"""ClosedLinkSample (a closed hinge loop, WAIST's inertia violating the triangle inequality, MK303):
the verdict is pinned: Drake's SDF is skipped for the loop, MuJoCo holds the MJCF writer's lifted
tensor (MK870), PyBullet and drake-urdf hold their own replacements of WAIST's refused tensor,
reported as a source finding (MK303), not as a failure."""

from __future__ import annotations

import numpy as np
import pytest

from modelkit.verify.api import verify
from modelkit.verify.layers import approximations
from tests.conftest import CORPUS

pytest.importorskip("mujoco")
pytest.importorskip("pybullet")
pytest.importorskip("pinocchio")
pytest.importorskip("pydrake")

SAMPLE = CORPUS / "choreonoid" / "share" / "model" / "misc" / "ClosedLinkSample.body"


@pytest.fixture(scope="module")
def report():  # type: ignore[no-untyped-def]
    if not SAMPLE.exists():
        pytest.skip("corpus not available")
    return verify(SAMPLE, configurations=5, samples=3)


def test_loop_skips_drake_sdf(report) -> None:  # type: ignore[no-untyped-def]
    assert not report.errors
    drake = [s for s in report.skips if s.engine == "drake"]
    assert len(drake) == 1 and drake[0].layer == 0
    assert "extra_joint_0 (hinge, J1–J3)" in drake[0].reason
    assert "MK811" in drake[0].reason and "tree of joints only" in drake[0].reason
    assert "form one or more loops" in drake[0].reason
    assert not [c for c in report.checks if c.engine == "drake"]


def test_the_refused_inertia_is_a_source_finding_not_a_failure(report) -> None:  # type: ignore[no-untyped-def]
    """WAIST's source inertia violates the triangle inequality (validate's MK303). The URDF keeps it;
    PyBullet replaces it by zero and Drake's URDF parser by its water-density sphere. Each is
    compared with its own replacement (layer 1 checks it holds exactly that) and the report says it
    is the source's finding with its code: nothing fails."""
    assert [c for c in report.checks if not c.passed] == []
    for engine, held in (("pybullet", 'holds zero'), ("drake-urdf", "0.374059359 kg·m² per axis")):
        inertia = [c for c in report.checks if c.engine == engine and c.quantity == "inertia"]
        assert len(inertia) == 1 and inertia[0].passed and inertia[0].error <= 1e-12, inertia  # 0, 4.5e-16
        entry = [s for s in report.skips if s.engine == engine and "source finding MK303" in s.reason]
        assert len(entry) == 1, [s.reason for s in report.skips if s.engine == engine]
        assert "WAIST" in entry[0].reason and held in entry[0].reason
        assert "not a conversion fault" in entry[0].reason


def test_mujoco_holds_the_lifted_tensor(report) -> None:  # type: ignore[no-untyped-def]
    inertia = [c for c in report.checks if c.engine == "mujoco" and c.quantity == "inertia"]
    assert len(inertia) == 1 and inertia[0].passed
    entry = [s for s in report.skips if s.engine == "mujoco" and s.reason.startswith("approximation:")]
    assert len(entry) == 1
    assert "lifts the inertia of WAIST" in entry[0].reason and "0.19125, 0.19125, 0.3825" in entry[0].reason
    assert "(MK870)" in entry[0].reason


def test_sdf_lift_is_the_writers_tensor() -> None:
    from modelkit import load
    from modelkit.convert.notes import ConversionNote

    if not SAMPLE.exists():
        pytest.skip("corpus not available")
    loaded = load(SAMPLE)
    robot = loaded[0] if isinstance(loaded, list) else loaded
    note = ConversionNote.__new__(ConversionNote)
    object.__setattr__(note, "code", "MK860")
    object.__setattr__(note, "message", "")
    object.__setattr__(note, "target", "link[WAIST]/inertial")
    got = approximations.lifted_inertias("sdf", [note], {}, robot)
    assert np.allclose(np.asarray(got["WAIST"].tensor).reshape(3, 3), np.diag([0.19125, 0.3825, 0.19125]),
                       rtol=0, atol=1e-15)
    assert got["WAIST"].code == "MK860" and got["WAIST"].by == "the SDF writer"
