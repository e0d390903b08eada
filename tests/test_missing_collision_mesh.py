"""A missing collision mesh, judged as the file's own loader judges it (issue 18 §3, the guide's
conformance rule: a file its own format's loader accepts gets no error from validate).

check_urdf and libsdformat never open meshes, so they accept a URDF, xacro or SDF file whose collision
mesh is missing. validate then warns, and the message says that MuJoCo and PyBullet refuse the file.
``--target mjcf`` and ``--target pybullet`` make it an error, and so does ``--strict``. PyBullet also
refuses a missing visual mesh; MuJoCo's URDF import discards visuals. ``convert`` exits 1, because the
written robot has no collision there. Choreonoid's and MuJoCo's loaders open their meshes, so a `.body`
or MJCF file keeps the error. Each loader is run live here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mujoco
import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from tests.test_conformance import check_urdf_accepts, reference
from tests.test_sdf_reader import sdf_oracle  # noqa: F401  (a fixture)

INERTIAL = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
_PYBULLET_LOADS = "import sys, pybullet as p; p.connect(p.DIRECT); p.loadURDF(sys.argv[1])"


def _urdf(tmp_path: Path, part: str) -> Path:
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r"><link name="a">{INERTIAL}{part}</link></robot>')
    return path


COLLISION = '<collision><geometry><mesh filename="gone.stl"/></geometry></collision>'
VISUAL = '<visual><geometry><mesh filename="gone.stl"/></geometry></visual>'


def _pybullet_loads(path: Path) -> bool:
    run = subprocess.run([sys.executable, "-c", _PYBULLET_LOADS, str(path)], capture_output=True, timeout=60)
    return run.returncode == 0


def _mujoco_loads(path: Path) -> bool:
    try:
        mujoco.MjModel.from_xml_path(str(path))
    except ValueError:
        return False
    return True


def _severities(path: Path, target: str | None = None) -> list[tuple[str, str]]:
    found = validate(path, target=target).diagnostics
    return [(d.code, d.severity.value) for d in found if d.code == "MK500"]


def test_a_urdf_collision_mesh_missing(tmp_path: Path) -> None:
    path = _urdf(tmp_path, COLLISION)
    assert check_urdf_accepts(path)[0]
    assert not _pybullet_loads(path) and not _mujoco_loads(path)
    assert _severities(path) == [("MK500", "warning")]
    (d,) = [d for d in validate(path).diagnostics if d.code == "MK500"]
    assert "check_urdf never opens meshes" in d.message and "MuJoCo and PyBullet refuse it" in d.message
    assert _severities(path, "mjcf") == [("MK500", "error")]
    assert _severities(path, "pybullet") == [("MK500", "error")]
    assert _severities(path, "sdf") == [("MK500", "warning")]
    runner = CliRunner()
    assert runner.invoke(main, ["validate", str(path)]).exit_code == 0
    assert runner.invoke(main, ["validate", "--strict", str(path)]).exit_code == 1
    assert runner.invoke(main, ["validate", "--target", "mjcf", str(path)]).exit_code == 1
    converted = runner.invoke(main, ["convert", str(path), "-o", str(tmp_path / "out" / "r.xml")])
    assert converted.exit_code == 1 and "error MK805" in converted.output, converted.output
    assert _mujoco_loads(tmp_path / "out" / "r.xml")  # what is written loads, without that collision


def test_a_urdf_visual_mesh_missing(tmp_path: Path) -> None:
    path = _urdf(tmp_path, VISUAL)
    assert check_urdf_accepts(path)[0]
    assert not _pybullet_loads(path) and _mujoco_loads(path)  # MuJoCo's import discards visuals
    assert _severities(path) == [("MK500", "warning")]
    assert _severities(path, "mjcf") == [("MK500", "warning")]
    assert _severities(path, "pybullet") == [("MK500", "error")]
    converted = CliRunner().invoke(main, ["convert", str(path), "-o", str(tmp_path / "out" / "r.xml")])
    assert converted.exit_code == 0, converted.output


def test_an_sdf_collision_mesh_missing(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    path = tmp_path / "r.sdf"
    path.write_text(
        '<sdf version="1.9"><model name="r"><link name="a"><inertial><mass>1</mass></inertial>'
        '<collision name="c"><geometry><mesh><uri>gone.stl</uri></mesh></geometry></collision>'
        "</link></model></sdf>"
    )
    accepted, said = reference("sdf", path, sdf_oracle, tmp_path)
    assert accepted, said
    assert _severities(path) == [("MK500", "warning")]
    (d,) = [d for d in validate(path).diagnostics if d.code == "MK500"]
    assert "libsdformat never opens meshes" in d.message
    assert _severities(path, "mjcf") == [("MK500", "error")]
    converted = CliRunner().invoke(main, ["convert", str(path), "-o", str(tmp_path / "out" / "r.urdf")])
    assert converted.exit_code == 1, converted.output


@pytest.mark.parametrize("fmt", ["mjcf", "body"])
def test_formats_whose_loader_opens_meshes_keep_the_error(tmp_path: Path, fmt: str) -> None:
    if fmt == "mjcf":
        path = tmp_path / "r.xml"
        path.write_text('<mujoco><asset><mesh name="m" file="gone.stl"/></asset><worldbody><body name="a">'
                        '<freejoint/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
        assert not _mujoco_loads(path)
    else:
        path = tmp_path / "r.body"
        path.write_text(
            "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nroot_link: a\nlinks:\n"
            "  - name: a\n    joint_type: free\n    mass: 1\n    inertia: [ 1, 0, 0, 0, 1, 0, 0, 0, 1 ]\n"
            "    elements:\n      - type: Collision\n        elements:\n"
            "          - type: Resource\n            uri: gone.stl\n"
        )
    assert ("MK500", "error") in _severities(path)
