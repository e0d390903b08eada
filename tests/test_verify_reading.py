"""``modelkit verify`` takes the reading options of ``validate`` and ``convert``: ``--package-path``,
xacro ``KEY:=VALUE`` arguments (and the others, through the same ``reading_options``)."""

from __future__ import annotations

import json
import struct
from pathlib import Path

from click.testing import CliRunner

from modelkit.cli import main

XACRO = """<?xml version="1.0"?>
<robot name="armlet" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="mass" default="1.0"/>
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.1 0 0"/><mass value="$(arg mass)"/>
      <inertia ixx="0.001" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="package://shapes_pkg/meshes/tetra.stl"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


def _tetrahedron(path: Path) -> None:
    """A binary STL (MuJoCo refuses ASCII STL) of a small tetrahedron."""
    v = [(0.0, 0.0, 0.0), (0.05, 0.0, 0.0), (0.0, 0.05, 0.0), (0.0, 0.0, 0.05)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for f in faces:
        data += struct.pack("<3f", 0.0, 0.0, 0.0)
        for i in f:
            data += struct.pack("<3f", *v[i])
        data += b"\0\0"
    path.write_bytes(data)


def _verify(tmp_path: Path, *words: str) -> tuple[int, dict[str, object], str]:
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["verify", *words, "--engines", "mujoco", "--no-replay",
                                       "--no-driven", "-o", str(out)])
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else {}
    return result.exit_code, report, result.output


def test_package_path_and_xacro_arguments_reach_the_reader(tmp_path: Path) -> None:
    package = tmp_path / "elsewhere" / "somewhere"  # not named shapes_pkg: found only through the option
    (package / "meshes").mkdir(parents=True)
    _tetrahedron(package / "meshes" / "tetra.stl")
    model = tmp_path / "armlet.urdf.xacro"
    model.write_text(XACRO)

    code, report, output = _verify(tmp_path, str(model), "mass:=2.5",
                                   "--package-path", f"shapes_pkg={package}")
    assert code == 0, output
    assert report["parameters"]["reading"] == {"package_paths": {"shapes_pkg": str(package)},
                                               "xacro_args": {"mass": "2.5"}}
    mjcf = (tmp_path / "out" / str(report["files"]["mjcf"])).read_text()  # type: ignore[index]
    assert 'mass="2.5"' in mjcf  # the xacro argument, not the default 1.0
    assert not [s for s in report["skips"] if "missing" in s["reason"]], report["skips"]
    shapes = [c for c in report["checks"] if c["quantity"] == "shape-set"]
    assert shapes and shapes[0]["passed"]

    code, report, output = _verify(tmp_path, str(model))  # without them: the default mass, no mesh
    mjcf = (tmp_path / "out" / str(report["files"]["mjcf"])).read_text()  # type: ignore[index]
    assert 'mass="2.5"' not in mjcf and 'mass="1"' in mjcf
    assert [s for s in report["skips"] if "missing" in s["reason"]], report["skips"]


def test_only_xacro_arguments_is_a_usage_error(tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["verify", "mass:=2"])
    assert result.exit_code == 2
    assert "no model given" in result.output
