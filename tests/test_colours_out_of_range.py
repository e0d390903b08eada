"""Colours outside 0..1 in `.body` and MJCF sources (MK513): their loaders take them, libsdformat refuses
them in SDF and urdfdom drops them from URDF, so the readers clamp them and say so. Found by semantic
fuzzing: a `.body` `diffuseColor` of -0.5 became an SDF `<ambient>` that libsdformat refused."""

from __future__ import annotations

import subprocess
from pathlib import Path

import mujoco
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main

from .conftest import require_tool
from .test_conformance import _libsdformat_accepts
from .test_sdf_reader import sdf_oracle  # noqa: F401  (the compiled libsdformat checker, a fixture)

BODY = """format: ChoreonoidBody
format_version: 2.0
name: c
root_link: base
links:
  - name: base
    jointType: free
    mass: 1.0
    inertia: [0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1]
    elements:
      - type: Shape
        geometry: {type: Box, size: [0.2, 0.2, 0.2]}
        appearance:
          material: {diffuseColor: [-0.5, 2.0, 0.5], specularColor: [3, 0, 0], emissiveColor: [0, -1, 0],
                     transparency: -0.5}
"""

MJCF = ('<mujoco model="m"><asset><material name="bright" emission="3"/></asset><worldbody>'
        '<body name="a"><freejoint/><geom name="g" size="0.1" rgba="-0.5 2 0.5 1.5"/>'
        '<body name="b" pos="1 0 0"><joint name="j" type="hinge"/>'
        '<geom name="h" size="0.1" material="bright"/></body></body></worldbody></mujoco>')


def _convert(source: Path, output: Path) -> None:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(output), "-q"])
    assert result.exit_code == 0, result.output


def test_a_body_colour_outside_0_1_is_clamped_and_said(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    source = tmp_path / "c.body"
    source.write_text(BODY)
    said = [d for d in validate(source).diagnostics if d.code == "MK513"]
    assert [d.severity.value for d in said] == ["warning"] * 4, said
    assert {d.message.split("`")[1] for d in said} == {"diffuseColor", "specularColor", "emissiveColor",
                                                        "transparency"}
    _convert(source, tmp_path / "sdf" / "c.sdf")
    assert _libsdformat_accepts(sdf_oracle, tmp_path / "sdf" / "c.sdf")
    written = (tmp_path / "sdf" / "c.sdf").read_text()
    assert "<diffuse>0 1 0.5 1</diffuse>" in written and "<specular>1 0 0 1</specular>" in written
    _convert(source, tmp_path / "urdf" / "c.urdf")
    check = subprocess.run([require_tool("check_urdf"), str(tmp_path / "urdf" / "c.urdf")],
                           capture_output=True, text=True)
    assert check.returncode == 0 and "rgba" not in check.stdout + check.stderr, check.stdout + check.stderr


def test_an_mjcf_rgba_or_emission_outside_0_1_is_clamped_and_said(tmp_path: Path,
                                                                  sdf_oracle: Path) -> None:  # noqa: F811
    source = tmp_path / "m.xml"
    source.write_text(MJCF)
    mujoco.MjModel.from_xml_path(str(source))  # MuJoCo loads it
    said = [d for d in validate(source).diagnostics if d.code == "MK513"]
    assert len(said) == 2 and all(d.severity.value == "warning" for d in said), said
    assert any("rgba -0.5 2 0.5 1.5" in d.message for d in said)
    assert any("emission 3" in d.message for d in said)
    _convert(source, tmp_path / "sdf" / "m.sdf")
    assert _libsdformat_accepts(sdf_oracle, tmp_path / "sdf" / "m.sdf")


def test_colours_within_0_1_are_not_said(tmp_path: Path) -> None:
    source = tmp_path / "c.body"
    source.write_text(BODY.replace("[-0.5, 2.0, 0.5]", "[0.5, 1.0, 0.0]").replace("[3, 0, 0]", "[1, 0, 0]")
                      .replace("[0, -1, 0]", "[0, 0, 0]").replace("transparency: -0.5", "transparency: 0.25"))
    assert not [d for d in validate(source).diagnostics if d.code == "MK513"]


def test_a_colour_component_too_small_for_a_float_is_written_0_in_sdf(tmp_path: Path,
                                                                       sdf_oracle: Path) -> None:  # noqa: F811
    """libsdformat reads colours as 32-bit floats and refused `<ambient>1e-300 0 0 1</ambient>` ("Out of
    range"); a semantic fuzz mutant of Choreonoid's SpringModel.body wrote it."""
    source = tmp_path / "c.body"
    source.write_text(BODY.replace("[-0.5, 2.0, 0.5]", "[1.0e-300, 0.5, 1.0e-39]"))
    _convert(source, tmp_path / "sdf" / "c.sdf")
    assert _libsdformat_accepts(sdf_oracle, tmp_path / "sdf" / "c.sdf")
    assert "<diffuse>0 0.5 0 1</diffuse>" in (tmp_path / "sdf" / "c.sdf").read_text()
