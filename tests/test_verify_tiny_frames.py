"""Every massless URDF link is written with the tiny inertial (MK816: 1e-6 kg, so that PyBullet does not
give it 1 kg). The URDF engines read that mass; verify compares them with the source holding it, as the
writer's approximation, named in a skip. Without it example-robot-data's A1 (12 kg; its ``base`` root and
four ``*_thigh_shoulder`` frames massless) failed layer 3 in Drake's URDF reader at 4e-7 (bound 1e-9)."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

from .conftest import example_robot


def test_a1s_frames_carry_the_tiny_inertial_and_pass(tmp_path: Path) -> None:
    report = verify(example_robot("a1_description/urdf/a1.urdf"), tmp_path,
                    engines=("pybullet", "pinocchio", "drake-urdf"), replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    assert {(c.layer, c.engine, c.quantity) for c in report.checks} >= {
        (3, "drake-urdf", "mass-matrix"), (3, "pybullet", "mass-matrix")}
    words = "the URDF writer gives 5 link(s) massless in the source"
    said = [s.reason for s in report.skips if words in s.reason]
    assert len(said) == 2 and all("FL_thigh_shoulder" in s and "base" in s for s in said), said
    urdf = next(tmp_path.glob("*.urdf")).read_text()
    assert urdf.count('<mass value="1e-6"/>') == 5
