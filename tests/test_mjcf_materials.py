"""MJCF materials: the MJCF writer writes a ``<material>`` (specular, shininess, emission, a PNG texture)
and the MJCF reader reads one into the model's material. Before, every MJCF output had only ``rgba``
and an MJCF source's specular, shininess, emission and textures were lost in every target without a
note. Oracle: MuJoCo's compiled material and texture arrays."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from PIL import Image

from modelkit.convert.api import convert
from modelkit.formats.mjcf.write_geoms import mujoco_material
from modelkit.model import VisualMaterial
from tests.conftest import TUTORIAL

SOURCE = """<mujoco model="tx"><compiler texturedir="tx"/>
  <asset><texture name="t" type="2d" file="red.png"/>
    <material name="shiny" texture="t" specular="0.3" shininess="0.7" emission="0.2" rgba="1 1 1 1"/>
    <material name="plain" rgba="0 1 0 1"/></asset>
  <worldbody><body name="a"><freejoint/>
    <geom type="box" size="0.1 0.1 0.1" material="shiny"/>
    <geom type="sphere" size="0.05" pos="0 0 0.2" material="plain"/></body></worldbody></mujoco>"""


def _source(tmp_path: Path) -> Path:
    (tmp_path / "src" / "tx").mkdir(parents=True)
    Image.new("RGB", (8, 4), (255, 0, 0)).save(tmp_path / "src" / "tx" / "red.png")
    path = tmp_path / "src" / "tx.xml"
    path.write_text(SOURCE)
    return path


def test_mjcf_to_mjcf_keeps_material_and_texture(tmp_path: Path) -> None:
    source = _source(tmp_path)
    out = tmp_path / "out" / "tx.xml"
    assert not [n for n in convert([source], out).notes if n.code == "MK818"]
    given, written = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    shiny = mujoco.mj_name2id(written, mujoco.mjtObj.mjOBJ_MATERIAL, "shiny")
    assert shiny >= 0 and written.nmat == 1  # "plain" holds nothing but the colour: rgba alone
    for array in ("mat_specular", "mat_shininess", "mat_emission"):
        assert np.isclose(getattr(written, array)[shiny], getattr(given, array)[0]), array
    texture = int(written.mat_texid[shiny][1])
    assert texture >= 0 and (written.tex_width[texture], written.tex_height[texture]) == (8, 4)
    image = (source.parent / "tx" / "red.png").read_bytes()
    assert (out.parent / "textures" / "red.png").read_bytes() == image
    assert np.array_equal(written.tex_data, given.tex_data)


def test_other_targets_get_the_look_they_hold(tmp_path: Path) -> None:
    """URDF keeps the texture (copied) and says what it drops; .body keeps all of it."""
    source = _source(tmp_path)
    urdf = tmp_path / "u" / "tx.urdf"
    notes = convert([source], urdf).notes
    assert '<texture filename="textures/red.png"/>' in urdf.read_text()
    assert any(n.code == "MK818" and "specular, emissive, shininess left out" in n.message for n in notes)
    body = tmp_path / "b" / "tx.body"
    convert([source], body)
    text = body.read_text()
    assert "specular: [ 0.3, 0.3, 0.3 ]" in text and "emissive: [ 0.2, 0.2, 0.2 ]" in text
    assert "specular_exponent: 89.9" in text  # 127 × 0.7 + 1


def test_body_specular_becomes_a_mujoco_material() -> None:
    """The tutorial's LiDAR and RealSense are shiny (specular 1 1 1): a MuJoCo material with specular 1."""
    assert mujoco_material(VisualMaterial(diffuse=(0.8, 0.8, 0.8), specular=(1.0, 1.0, 1.0))) == (
        {"specular": "1"}, [])
    coloured = VisualMaterial(diffuse=(1.0, 0.0, 0.0), specular=(0.2, 0.4, 0.6), emissive=(0.1, 0.2, 0.0),
                              specular_exponent=300.0)
    attributes, approximated = mujoco_material(coloured)
    assert attributes == {"specular": "0.4", "shininess": "1", "emission": "0.3"}
    assert len(approximated) == 3  # a coloured specular, an exponent above MuJoCo's range, an emissive colour


def test_tutorial_sensor_robot_mjcf_loads_with_its_material(tmp_path: Path) -> None:
    out = tmp_path / "sensors.xml"
    convert([TUTORIAL / "mobile_robot_sensors.body"], out)
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nmat == 1 and np.isclose(model.mat_specular[0], 1.0)


def test_a_generated_texture_is_named_not_carried(tmp_path: Path) -> None:
    """A builtin (generated) texture has no image file: MK178 names it; the material's look is kept."""
    from modelkit.api import validate

    source = tmp_path / "gen.xml"
    source.write_text("""<mujoco model="gen"><asset>
      <texture name="c" type="2d" builtin="checker" width="8" height="8"/>
      <material name="checks" texture="c" specular="0.9"/></asset>
      <worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05" material="checks"/></body>
      </worldbody></mujoco>""")
    found = [d for d in validate(source).diagnostics if d.code == "MK178"]
    assert len(found) == 1 and "material checks: its texture c" in found[0].message
    out = tmp_path / "out" / "gen.xml"
    convert([source], out)
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.ntex == 0 and model.nmat == 1 and np.isclose(model.mat_specular[0], 0.9)
