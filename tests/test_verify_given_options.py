"""``verify --urdf/--mjcf FILE`` on files ``convert`` wrote with options other than its defaults.

Before, three of them failed a sound conversion: ``--urdf-distinct-names`` (the wheel joints are
``LeftWheel_joint``: layers 2 and 3 found no such joint), ``--merge-fixed`` (fused links were "missing"
and their shapes on the parent an extra shape), ``--urdf-world-link`` (yourdfpy counted the ``world``
link a floating root hangs from). Now joints are matched by the link they move, a file written with
``--merge-fixed`` is compared with the source merged the same way (a skip says so), and a ``world``
link holding a floating root is the world. A fault in such a file still fails.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.convert.api import convert
from modelkit.convert.options import WriteOptions
from modelkit.verify.api import verify
from tests.conftest import TUTORIAL, example_robot

FAST = {"configurations": 5, "samples": 3, "replay": False, "driven": False}


def _failed(report: object) -> list[object]:
    return [c for c in report.checks if not c.passed]  # type: ignore[attr-defined]


@pytest.mark.parametrize("option", ["urdf_distinct_names", "urdf_world_link"])
def test_urdf_options_pass(tmp_path: Path, option: str) -> None:
    source = TUTORIAL / "mobile_robot_sensors.body"
    urdf = tmp_path / "r.urdf"
    convert([source], urdf, options=WriteOptions(**{option: True}))
    report = verify(source, tmp_path / "v", engines=("pybullet", "yourdfpy", "pinocchio"), urdf=urdf, **FAST)
    assert not report.errors and not _failed(report), _failed(report)


def test_merge_fixed_passes_and_a_fault_in_the_merged_file_fails(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    source = example_robot("ur_description/urdf/ur5_robot.urdf")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{source.parents[2]}:{source.parents[3]}")
    urdf, mjcf = tmp_path / "m.urdf", tmp_path / "m.xml"
    for path in (urdf, mjcf):
        convert([source], path, options=WriteOptions(merge_fixed=True))
    assert "<link name=\"tool0\"" not in urdf.read_text()
    report = verify(source, tmp_path / "ok", engines=("mujoco", "pybullet", "pinocchio"), urdf=urdf,
                    mjcf=mjcf, **FAST)
    assert not report.errors and not _failed(report), _failed(report)
    assert any("convert --merge-fixed" in s.reason for s in report.skips)
    text = urdf.read_text()
    start = text.index('<link name="wrist_3_link">')
    mass = text.index("<mass value=", start)
    end = text.index('"/>', mass)
    urdf.write_text(text[:mass] + '<mass value="0.5' + text[end:])  # wrist 3 (merged with its frames): wrong
    report = verify(source, tmp_path / "bad", engines=("pybullet", "pinocchio"), urdf=urdf, **FAST)
    assert {(c.quantity, c.where) for c in _failed(report) if c.layer == 1} >= {("mass", "wrist_3_link")}
