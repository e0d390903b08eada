"""A mesh named by a path longer than the file system can look up (ENAMETOOLONG, issue 18 §2): a
coded MK500 in every format, never MK899 (modelkit failing on the input) or a traceback. Before
2026-12-03 ``Path.exists`` raised on such a name in every reader (MK899)."""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import validate

NAME = "a" * 5000 + ".stl"  # one component over NAME_MAX (255)
DEEP = "/".join(["b" * 200] * 30) + ".stl"  # every component allowed, the whole over PATH_MAX (4096)

MODELS = {
    "urdf": '<robot name="r"><link name="a"><collision><geometry><mesh filename="{uri}"/></geometry>'
            "</collision></link></robot>",
    "sdf": '<sdf version="1.7"><model name="m"><link name="a"><collision name="c"><geometry><mesh>'
           "<uri>{uri}</uri></mesh></geometry></collision></link></model></sdf>",
    "xml": '<mujoco><asset><mesh name="m" file="{uri}"/></asset><worldbody><body><freejoint/>'
           '<geom type="mesh" mesh="m"/></body></worldbody></mujoco>',
    "body": "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nroot_link: a\nlinks:\n  - name: a\n"
            "    joint_type: free\n    mass: 1\n    inertia: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    elements:\n"
            "      - type: Resource\n        uri: {uri}\n",
}


@pytest.mark.parametrize("uri", [NAME, DEEP], ids=["long-name", "long-path"])
@pytest.mark.parametrize("suffix", list(MODELS))
def test_a_mesh_path_too_long_to_look_up_is_not_found(tmp_path: Path, suffix: str, uri: str) -> None:
    path = tmp_path / f"m.{suffix}"
    path.write_text(MODELS[suffix].format(uri=uri))
    codes = [d.code for d in validate(path).diagnostics]
    assert "MK899" not in codes and "MK500" in codes, codes


INCLUDES = {
    "sdf": ('<sdf version="1.7"><world name="w"><include><uri>{uri}</uri></include></world></sdf>', "MK500"),
    "xml": ('<mujoco><include file="{uri}.xml"/><worldbody/></mujoco>', "MK170"),
    "xacro": ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
              '<xacro:include filename="{uri}.xacro"/><link name="a"/></robot>', "MK705"),
    "urdf": ('<robot name="r"><material name="m"><texture filename="{uri}.png"/></material><link name="a"/>'
             "</robot>", "MK507"),
}


@pytest.mark.parametrize("uri", [NAME, DEEP], ids=["long-name", "long-path"])
@pytest.mark.parametrize("suffix", list(INCLUDES))
def test_an_include_or_texture_too_long_to_look_up_is_not_found(tmp_path: Path, suffix: str,
                                                                 uri: str) -> None:
    """The same for an included file (SDF ``<include>``, MJCF ``<include>``, ``xacro:include``) and a
    texture: each format's own "cannot be found" code."""
    model, code = INCLUDES[suffix]
    path = tmp_path / f"m.{suffix}"
    path.write_text(model.format(uri=uri))
    codes = [d.code for d in validate(path).diagnostics]
    assert "MK899" not in codes and code in codes, codes


def test_a_materials_file_too_long_to_look_up_cannot_be_read(tmp_path: Path) -> None:
    """``--materials`` naming such a path: the same two errors as a materials file that does not exist."""
    from modelkit.formats.common import ReadOptions

    body = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
    options = ReadOptions(materials_path=tmp_path / NAME.replace(".stl", ".yaml"))
    codes = [d.code for d in validate(body / "mobile_robot_pantilt.body", options).errors]
    assert "MK899" not in codes and "MK511" in codes, codes


_BODY = ("format: ChoreonoidBody\nformat_version: 2.0\nname: r\nroot_link: a\nlinks:\n  - name: a\n"
         "    joint_type: free\n    mass: 1\n    inertia: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n")
BODY_FILES = {
    "sub-body": (_BODY + "  - type: SubBody\n    uri: {uri}.body\n    parent: a\n", "MK216"),
    "yaml-resource": (_BODY + "    elements:\n      - type: Resource\n        uri: {uri}.yaml\n", "MK500"),
    "texture": (_BODY + "    elements:\n      - type: Shape\n"
                "        geometry: {{ type: Box, size: [1, 1, 1] }}\n"
                "        appearance: {{ texture: {{ uri: {uri}.png }} }}\n", "MK507"),
}


@pytest.mark.parametrize("uri", [NAME, DEEP], ids=["long-name", "long-path"])
@pytest.mark.parametrize("kind", list(BODY_FILES))
def test_a_body_file_resource_too_long_to_look_up_is_not_found(tmp_path: Path, kind: str,
                                                               uri: str) -> None:
    """A ``.body`` SubBody, YAML resource or texture (``Path.exists`` and ``is_file`` raised on these
    until 2026-12-04: MK899)."""
    model, code = BODY_FILES[kind]
    path = tmp_path / "m.body"
    path.write_text(model.format(uri=uri.removesuffix(".stl")))
    codes = [d.code for d in validate(path).diagnostics]
    assert "MK899" not in codes and code in codes, codes


@pytest.mark.parametrize("uri", [NAME, DEEP], ids=["long-name", "long-path"])
def test_a_load_yaml_file_too_long_to_look_up_is_not_found(tmp_path: Path, uri: str) -> None:
    path = tmp_path / "m.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    f'<xacro:property name="p" value="${{xacro.load_yaml(\'{uri}.yaml\')}}"/>'
                    '<link name="a"><inertial><mass value="${p[\'m\']}"/>'
                    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    codes = [d.code for d in validate(path).diagnostics]
    assert "MK899" not in codes and "MK705" in codes, codes


def test_a_package_name_too_long_to_look_up_on_the_package_path_is_not_found(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    path = tmp_path / "m.urdf"
    path.write_text(MODELS["urdf"].format(uri=f"package://{'p' * 300}/m.stl"))
    codes = [d.code for d in validate(path).diagnostics]
    assert "MK899" not in codes and "MK504" in codes, codes


def test_convert_and_verify_given_names_too_long_say_so(tmp_path: Path) -> None:
    """``convert -o`` a name the file system cannot create: the write fails with MK894 and nothing is
    left; ``verify`` of a model (or ``--urdf``) named so: "no such file", exit 2. Both were MK899."""
    from click.testing import CliRunner

    from modelkit.cli import main

    source = tmp_path / "m.urdf"
    source.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
                      'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(tmp_path / ("o" * 300 + ".xml"))])
    assert result.exit_code == 2 and "MK894" in result.output and "MK899" not in result.output, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.urdf"]
    too_long = [str(tmp_path / ("v" * 300 + ".urdf"))], [str(source), "--urdf", str(tmp_path / ("u" * 300))]
    for args in too_long:
        result = CliRunner().invoke(main, ["verify", *args])
        assert result.exit_code == 2 and "no such file" in result.output, result.output
        assert "MK899" not in result.output
