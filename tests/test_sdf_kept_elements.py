"""SDF elements the robot model does not hold (:mod:`modelkit.formats.sdf.kept`): written back to SDF,
said by every other target. Before, a model's ``<allow_auto_disable>``, a joint's ``<physics>`` and its
stop's ``<stiffness>``, a collision's ``<max_contacts>`` and a visual's ``<cast_shadows>`` vanished in
every target, SDF included, without a note. Oracle: libsdformat 12 reads each written SDF."""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from modelkit.convert.api import convert
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

INERTIAL = ("<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia>"
            "</inertial>")


def model(flags: str, collision: str, visual: str, limit: str, physics: str) -> str:
    return f"""<?xml version="1.0"?>
<sdf version="1.9">
  <model name="m">
    {flags}
    <link name="base">{INERTIAL}
      <collision name="c"><geometry><box><size>0.2 0.2 0.1</size></box></geometry>{collision}</collision>
      <visual name="v"><geometry><box><size>0.2 0.2 0.1</size></box></geometry>{visual}</visual>
    </link>
    <link name="arm"><pose>0 0 0.3 0 0 0</pose>{INERTIAL}</link>
    <joint name="j" type="revolute"><parent>base</parent><child>arm</child>
      <axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1</upper>{limit}</limit></axis>{physics}</joint>
  </model>
</sdf>
"""


GIVEN = model("<allow_auto_disable>false</allow_auto_disable><enable_wind>true</enable_wind>",
              "<laser_retro>100</laser_retro><max_contacts>5</max_contacts>",
              "<laser_retro>100</laser_retro><cast_shadows>false</cast_shadows>",
              "<stiffness>1e6</stiffness><dissipation>5</dissipation>",
              "<physics><ode><cfm>0.01</cfm><provide_feedback>true</provide_feedback></ode></physics>")
DEFAULTS = model("<allow_auto_disable>1</allow_auto_disable><enable_wind>false</enable_wind>",
                 "<laser_retro>0</laser_retro><max_contacts>10</max_contacts>",
                 "<laser_retro>0.0</laser_retro><cast_shadows>true</cast_shadows>",
                 "<stiffness>100000000</stiffness><dissipation>1.0</dissipation>", "")


def _source(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "src" / "m.sdf"
    path.parent.mkdir(exist_ok=True)
    path.write_text(text)
    return path


def _values(path: Path) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for el in etree.parse(str(path)).iter():
        if isinstance(el.tag, str) and el.tag in ("allow_auto_disable", "enable_wind", "laser_retro",
                                                  "max_contacts", "cast_shadows", "stiffness", "dissipation",
                                                  "cfm", "provide_feedback"):
            out.setdefault(el.tag, []).append((el.text or "").strip())
    return out


def test_sdf_to_sdf_writes_them_back_and_libsdformat_reads_it(tmp_path: Path,
                                                              sdf_oracle: Path) -> None:  # noqa: F811
    out = tmp_path / "out" / "m.sdf"
    result = convert([_source(tmp_path, GIVEN)], out)
    assert not [n for n in result.notes if n.code in ("MK808", "MK820")], [n.message for n in result.notes]
    assert _values(out) == {
        "allow_auto_disable": ["false"], "enable_wind": ["true"], "cast_shadows": ["false"],
        "laser_retro": ["100", "100"], "max_contacts": ["5"], "stiffness": ["1e6"], "dissipation": ["5"],
        "cfm": ["0.01"], "provide_feedback": ["true"]}
    assert not oracle_has_errors(sdf_oracle, out)


@pytest.mark.parametrize("suffix", ["xml", "urdf", "body"])
def test_other_targets_say_what_they_leave_out(tmp_path: Path, suffix: str) -> None:
    notes = convert([_source(tmp_path, GIVEN)], tmp_path / "out" / f"m.{suffix}").notes
    text = "\n".join(n.message for n in notes)
    # a URDF carries the joint's <physics>, the model flags and the elements of the link's one visual and
    # one collision in <gazebo> blocks (test_sdf_gazebo_blocks); the joint stop's sit in the axis
    carried = suffix == "urdf"
    assert ("SDF joint solver parameters (<physics>)" in text) is not carried
    assert "SDF joint stop parameters (<stiffness>, <dissipation>)" in text
    assert ("link base: SDF visual and collision elements" in text) is not carried
    assert ("<laser_retro>, <max_contacts>" in text and "<cast_shadows>" in text) is not carried
    assert ("SDF model flags" in text) is not carried


def test_values_at_sdformats_defaults_are_not_kept_or_said(tmp_path: Path) -> None:
    source = _source(tmp_path, DEFAULTS)
    for suffix in ("sdf", "xml"):
        out = tmp_path / "out" / f"m.{suffix}"
        notes = convert([source], out).notes
        assert not [n for n in notes if "SDF model flags" in n.message or "SDF joint stop" in n.message
                    or "visual and collision elements" in n.message], [n.message for n in notes]
    assert _values(tmp_path / "out" / "m.sdf") == {}  # written as SDFormat's defaults: left out


MATERIAL = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="m">
    <link name="base">
      <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
      <visual name="v"><geometry><box><size>0.1 0.1 0.1</size></box></geometry>
        <material><diffuse>1 0 0 1</diffuse>
          <script><uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Red</name></script>
          <pbr><metal><metalness>0.5</metalness><roughness>0.2</roughness></metal></pbr>
          <double_sided>true</double_sided></material></visual>
    </link>
  </model>
</sdf>
"""


def test_material_script_pbr_written_back_and_said_elsewhere(tmp_path: Path,
                                                            sdf_oracle: Path) -> None:  # noqa: F811
    """A visual's Gazebo material script, PBR block and double_sided flag were lost in every target,
    SDF included, without a note (the reader kept them, nobody wrote or named them)."""
    source = _source(tmp_path, MATERIAL)
    out = tmp_path / "out" / "m.sdf"
    convert([source], out)
    material = next(etree.parse(str(out)).iter("material"))
    assert material.findtext("script/name") == "Gazebo/Red"
    assert material.findtext("script/uri") == "file://media/materials/scripts/gazebo.material"
    assert material.findtext("pbr/metal/metalness") == "0.5" and material.findtext("double_sided") == "true"
    assert not oracle_has_errors(sdf_oracle, out)
    for suffix in ("xml", "urdf", "body"):
        notes = convert([source], tmp_path / suffix / f"m.{suffix}").notes
        said = [n for n in notes if "SDF material elements beyond the colours" in n.message]
        assert len(said) == 1 and said[0].code == "MK818" and "Gazebo/Red" in said[0].message, suffix


def test_link_flags_and_data_elements_written_back(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """An SDF link's <gravity>, <kinematic>, <velocity_decay> and a <battery> (validate's MK155: kept
    only as data) were lost SDF → SDF without a note; they are written back."""
    source = _source(tmp_path, GIVEN.replace(
        '<link name="arm">', '<link name="arm"><gravity>false</gravity><kinematic>true</kinematic>'
        '<velocity_decay><linear>0.1</linear></velocity_decay>'
        '<battery name="b"><voltage>12</voltage></battery>'))
    out = tmp_path / "out" / "m.sdf"
    convert([source], out)
    arm = next(el for el in etree.parse(str(out)).iter("link") if el.get("name") == "arm")
    assert arm.findtext("gravity") == "false" and arm.findtext("kinematic") == "true"
    assert arm.findtext("velocity_decay/linear") == "0.1" and arm.findtext("battery/voltage") == "12"
    assert not oracle_has_errors(sdf_oracle, out)
