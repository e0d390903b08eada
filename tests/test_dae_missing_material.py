"""A COLLADA geometry bound to a material the file lacks keeps its triangles; a mesh without triangles
is left out with MK805, never written as an empty file.

example-robot-data's ANYmal B foot (``anymal_foot.dae``) binds one of its three materials to an
effect the file does not hold. pycollada then drops the whole ``<instance_geometry>``, and ``convert``
wrote an 84-byte STL that PyBullet refused ("issue extracting mesh") and RViz showed as nothing. Assimp,
which RViz, Gazebo and Choreonoid read COLLADA with, keeps the geometry with its default material.
"""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from modelkit.cli import main
from modelkit.geometry.meshfiles import load_mesh
from tests.conftest import example_robot

HEADER = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_effects><effect id="red-fx"><profile_COMMON><technique sid="t"><phong>
    <diffuse><color>1 0 0 1</color></diffuse></phong></technique></profile_COMMON></effect>
  </library_effects>
  <library_materials><material id="red" name="red"><instance_effect url="#red-fx"/></material>
  </library_materials>
"""
GEOMETRY = """  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3"><param name="X" type="float"/>
        <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <{kind} material="{symbol}" count="{count}"><input semantic="VERTEX" source="#v" offset="0"/>
      <p>{p}</p></{kind}>
  </mesh></geometry></library_geometries>
"""
SCENE = """  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g">
    <bind_material><technique_common>
      <instance_material symbol="{symbol}" target="#{target}"/>
    </technique_common></bind_material></instance_geometry></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""
URDF = """<robot name="r">
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  <visual><geometry><mesh filename="{mesh}"/></geometry></visual>
  <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
</robot>
"""


def dae(tmp_path: Path, target: str, kind: str = "triangles") -> Path:
    p, count = ("0 1 2 0 1 3 0 2 3 1 2 3", 4) if kind == "triangles" else ("0 1 0 2", 2)
    text = (HEADER + GEOMETRY.format(kind=kind, symbol="m", count=count, p=p)
            + SCENE.format(symbol="m", target=target))
    path = tmp_path / f"tet_{target}_{kind}.dae"
    path.write_text(text)
    return path


def test_a_missing_material_keeps_the_triangles(tmp_path: Path) -> None:
    kept = load_mesh(dae(tmp_path, "red"))
    assert len(kept.mesh.faces) == 4
    loaded = load_mesh(dae(tmp_path, "carbon"))
    assert len(loaded.mesh.faces) == 4
    assert any("#carbon not in the file" in note and "kept without a colour" in note for note in loaded.notes)


def test_anymal_feet_are_written_whole(tmp_path: Path) -> None:
    source = example_robot("anymal_b_simple_description/robots/anymal.urdf")
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(tmp_path / "anymal.urdf")])
    assert result.exit_code == 0, result.output
    written = tmp_path / "meshes" / "anymal_foot_dae.stl"
    assert len(load_mesh(written).mesh.faces) == 81 + 4484 + 39  # the source's three <triangles>


def test_a_mesh_without_triangles_is_left_out(tmp_path: Path) -> None:
    mesh = dae(tmp_path, "red", kind="lines")
    source = tmp_path / "r.urdf"
    source.write_text(URDF.format(mesh=mesh.name))
    out = tmp_path / "out" / "r.urdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert f"MK805 mesh {mesh.name} holds no triangles; the shape is left out" in result.output
    assert "<mesh" not in out.read_text() and not (out.parent / "meshes").exists()
