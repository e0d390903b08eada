"""One robot converted to MJCF, URDF and SDF in one folder: the three share ``meshes/`` (issue 18: nothing
lost). example-robot-data's UR5 has ``base.dae`` (visual) beside ``base.stl`` (collision): both were
written ``base.stl`` and ``base_2.stl`` in the order each writer met them, the MJCF writer collision
first and the URDF writer visual first, so the second conversion was refused and, with ``--force``,
replaced the first one's meshes with other shapes. A converted mesh now keeps its source's suffix in
its name (``base_dae.stl``; split by its colours, ``base_dae_0.stl`` and ``base_dae_1.stl``)."""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import pytest
from click.testing import CliRunner

from modelkit.cli import main

from .conftest import example_robot


def test_mjcf_urdf_and_sdf_of_one_robot_share_a_folder(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    source = example_robot("ur_description/urdf/ur5_robot.urdf")
    robots = source.parents[2]
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(robots) + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", ""))
    for suffix in ("urdf", "xml", "sdf"):
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(tmp_path / f"ur5.{suffix}")])
        assert result.exit_code == 0, result.output
    meshes = {p.name for p in (tmp_path / "meshes").iterdir()}
    # the visual base.dae, split by its two colours (docs/convert.md, "A mesh file's own colours")
    assert {"base.stl", "base_dae_0.stl", "base_dae_1.stl"} <= meshes and "base_2.stl" not in meshes
    urdf = (tmp_path / "ur5.urdf").read_text()
    assert 'filename="meshes/base_dae_0.stl"' in urdf and 'filename="meshes/base.stl"' in urdf
    mujoco.MjModel.from_xml_path(str(tmp_path / "ur5.xml"))
