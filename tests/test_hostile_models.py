"""Hostile models found by the hostile corpus (issue 18, item 2): each is refused at once with a
located, coded error, exits as the README's table says, and quotes nothing it should not."""

from __future__ import annotations

from pathlib import Path

import pytest

from .test_hostile_input import assert_linear_calls, assert_refused, run, validate_json

# ---- MJCF <size> counts MuJoCo would build one by one -------------------------------------------


def _mjcf_size(tmp_path: Path, attributes: str) -> Path:
    model = tmp_path / "size.xml"
    model.write_text(
        f'<mujoco model="m">\n  <size {attributes}/>\n  <worldbody><body name="a"><joint/><geom size="1"/>'
        "</body></worldbody>\n</mujoco>\n"
    )
    return model


@pytest.mark.parametrize(
    "attributes",
    ['nkey="100000000"', 'nkey="99999999999999999999"', 'nuserdata="1000000000"', 'nuser_geom="100000000"'],
)
def test_mjcf_size_counts_are_capped_before_mujoco(tmp_path: Path, attributes: str) -> None:
    found = assert_refused(_mjcf_size(tmp_path, attributes), {"MK007"}, seconds=10)
    error = next(d for d in found if d["code"] == "MK007")
    assert error["line"] == 2 and error["column"], error


@pytest.mark.parametrize(
    "attributes",
    ['memory="100G" njmax="2000000000"', 'nconmax="2000000000" nstack="2000000000"', 'memory="1000000G"'],
)
def test_mjcf_huge_memory_sizes_are_refused_at_once(tmp_path: Path, attributes: str) -> None:
    """MuJoCo itself refuses these without allocating (no mjData is made by validate)."""
    found = assert_refused(_mjcf_size(tmp_path, attributes), {"MK170", "MK171", "MK007"}, seconds=10)
    assert all(d["line"] for d in found if d["severity"] == "error"), found


@pytest.mark.parametrize("keys", ["1", "2", "10000"])
def test_mjcf_keyframes_within_the_cap_are_read(tmp_path: Path, keys: str) -> None:
    """A one-coordinate model with keyframes (its key_qpos rows are one number wide) reads cleanly."""
    status, found = validate_json(_mjcf_size(tmp_path, f'nkey="{keys}"'), seconds=10)
    assert status == 0 and not [d for d in found if d["severity"] == "error"], found


# ---- .body numbers that are infinity or not-a-number --------------------------------------------

BODY_HEAD = "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n"


@pytest.mark.parametrize(
    ("line", "text"),
    [
        ("    translation: [nan, 0, 0]\n", "nan"),
        ("    rotation: [0, 0, 1, inf]\n", "inf"),
        ("    mass: -inf\n", "-inf"),
        ("    centerOfMass: [0, 1e400, 0]\n", "1e400"),
        ("    jointAxis: [0, NaN, 1]\n", "NaN"),
        (
            "    elements:\n      - type: Shape\n        geometry: {type: Box, size: [Infinity, 1, 1]}\n",
            "Infinity",
        ),
    ],
)
def test_body_non_finite_numbers_are_located_errors(tmp_path: Path, line: str, text: str) -> None:
    model = tmp_path / "nan.body"
    arm = "  - name: arm\n    parent: base\n    jointType: revolute\n"
    model.write_text(BODY_HEAD + "  - name: base\n" + arm + line)
    status, found = validate_json(model, seconds=10)
    assert status == 1, found
    errors = [d for d in found if d["code"] == "MK100" and text in str(d["message"])]
    assert errors and errors[0]["line"] == 8 + line.count("\n"), found
    out = tmp_path / "out.urdf"
    converted = run("convert", str(model), "-o", str(out), seconds=20)
    assert converted.exit_code == 1 and "MK100" in converted.output and not out.exists()


def test_body_yaml_nan_spellings_are_refused_too(tmp_path: Path) -> None:
    model = tmp_path / "nan.body"
    model.write_text(BODY_HEAD + "  - name: base\n    mass: .nan\n    translation: [0, .inf, 0]\n")
    status, found = validate_json(model, seconds=10)
    assert status == 1 and [d["line"] for d in found if d["code"] == "MK100"] == [6, 7], found


def test_body_infinite_joint_limits_mean_unlimited_but_nan_does_not(tmp_path: Path) -> None:
    arm = "  - name: arm\n    parent: base\n    jointType: revolute\n    jointAxis: Z\n"
    model = tmp_path / "limits.body"
    limits = "    jointRange: [-inf, inf]\n    maxJointVelocity: inf\n"
    model.write_text(BODY_HEAD + "  - name: base\n" + arm + limits)
    _, found = validate_json(model, seconds=10)
    assert not [d for d in found if d["code"] == "MK100"], found
    model.write_text(BODY_HEAD + "  - name: base\n" + arm + "    jointRange: [nan, 1]\n")
    status, found = validate_json(model, seconds=10)
    assert status == 1 and [d["line"] for d in found if d["code"] == "MK100"] == [10], found


def test_body_a_link_may_be_called_nan(tmp_path: Path) -> None:
    model = tmp_path / "named.body"
    model.write_text(BODY_HEAD + "  - name: nan\n    mass: 1\n  - name: inf\n    parent: nan\n")
    _, found = validate_json(model, seconds=10)
    assert not [d for d in found if d["code"] == "MK100"], found


# ---- tree prints what it can, but exits 1 with the error codes ----------------------------------


@pytest.mark.parametrize(
    ("name", "text", "code"),
    [
        (
            "two_parents.urdf",
            '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
            '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'
            '<joint name="k" type="fixed"><parent link="b"/><child link="c"/></joint>'
            '<joint name="l" type="fixed"><parent link="c"/><child link="b"/></joint></robot>',
            "MK220",
        ),
        ("mk100.body", BODY_HEAD + "  - name: r\n    mass: heavy\n  - name: a\n    parent: r\n", "MK100"),
        ("nan.body", BODY_HEAD + "  - name: r\n    translation: [nan, 0, 0]\n", "MK100"),
        ("cycle.body", BODY_HEAD + "  - name: r\n  - name: a\n    parent: b\n  - name: b\n    parent: a\n",
         "MK203"),
    ],
)
def test_tree_exits_1_with_the_codes_when_the_file_has_errors(
    tmp_path: Path, name: str, text: str, code: str
) -> None:
    model = tmp_path / name
    model.write_text(text)
    printed = run("tree", str(model), seconds=10)
    assert printed.exit_code == 1 and code in printed.stderr, printed.output
    status, _ = validate_json(model, seconds=10)
    assert status == 1


# ---- a resource that is not what it claims: the problem and the path, never its content ----------

RESOURCE = "  - name: base\n    elements:\n      - type: Resource\n        "
SECRET = "root:x:0:0:SECRET-CONTENT:/root:/bin/bash\nsecond { line [ SECRET-TWO\n"


@pytest.mark.parametrize("how", ["symlink_out", "copy_without_header"])
@pytest.mark.parametrize("uri", ["x.wrl", "x.stl", "x.obj", "x.dae"])
def test_body_resource_content_is_never_quoted(tmp_path: Path, how: str, uri: str) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "passwd").write_text(SECRET)
    folder = tmp_path / "model"
    folder.mkdir()
    if how == "symlink_out":
        (folder / uri).symlink_to(outside / "passwd")
    else:
        (folder / uri).write_text(SECRET)
    model = folder / "m.body"
    model.write_text(BODY_HEAD + RESOURCE + f"uri: {uri}\n")
    found = assert_refused(model, {"MK501"}, tree=False, seconds=10)
    error = next(d for d in found if d["code"] == "MK501")
    assert error["line"] == 8, error
    if how == "symlink_out":
        message = str(error["message"])
        assert "symbolic link out of its folder" in message and "passwd" in message
    outputs = [run("validate", str(model)).output, run("tree", str(model)).output]
    converted = tmp_path / "out.urdf"
    outputs.append(run("convert", str(model), "-o", str(converted), seconds=20).output)
    for output in outputs:
        assert "SECRET" not in output and "root:x" not in output, output


def test_a_vrml_resource_linked_from_outside_still_loads(tmp_path: Path) -> None:
    outside = tmp_path / "shared"
    outside.mkdir()
    (outside / "box.wrl").write_text(
        "#VRML V2.0 utf8\nShape { geometry Box { size 1 1 1 } }\n"
    )
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "box.wrl").symlink_to(outside / "box.wrl")
    model = folder / "m.body"
    model.write_text(BODY_HEAD + RESOURCE + "uri: box.wrl\n")
    status, found = validate_json(model, seconds=10)
    assert status == 0 and not [d for d in found if d["severity"] == "error"], found


# ---- xacro: an include diamond and a power tower -------------------------------------------------

XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def test_xacro_include_diamond_is_bounded(tmp_path: Path) -> None:
    """Each of 30 files includes the next one twice: 2^30 inclusions of files read once each."""
    levels = 30
    for i in range(levels - 1):
        include = f'<xacro:include filename="l{i + 1}.xacro"/>'
        (tmp_path / f"l{i}.xacro").write_text(f"<robot {XACRO_NS}>\n  {include}\n  {include}\n</robot>\n")
    (tmp_path / f"l{levels - 1}.xacro").write_text(f'<robot {XACRO_NS}><link name="x"/></robot>\n')
    model = tmp_path / "top.xacro"
    model.write_text(f'<robot name="r" {XACRO_NS}>\n  <xacro:include filename="l0.xacro"/>\n</robot>\n')
    found = assert_refused(model, {"MK008"}, seconds=10)
    error = next(d for d in found if d["code"] == "MK008")
    # located at the include that passed the bound: one of the two include lines of a level's file
    assert str(error["file"]).endswith(".xacro") and error["line"] in (2, 3), error


def test_xacro_includes_of_a_real_robot_size_pass(tmp_path: Path) -> None:
    """Twenty parts each included by a macro file used twice: 40 inclusions, far below the bound."""
    for i in range(20):
        (tmp_path / f"p{i}.xacro").write_text(f'<robot {XACRO_NS}><link name="p{i}_${{side}}"/></robot>\n')
    parts = "".join(f'<xacro:include filename="p{i}.xacro"/>' for i in range(20))
    (tmp_path / "arm.xacro").write_text(
        f'<robot {XACRO_NS}><xacro:macro name="arm" params="side">{parts}</xacro:macro></robot>\n'
    )
    model = tmp_path / "top.xacro"
    model.write_text(
        f'<robot name="r" {XACRO_NS}><xacro:include filename="arm.xacro"/><link name="base"/>'
        '<xacro:arm side="l"/><xacro:arm side="r"/></robot>\n'
    )
    _, found = validate_json(model, seconds=20)
    assert not [d for d in found if d["code"] == "MK008"], found


def test_xacro_power_tower_is_bounded(tmp_path: Path) -> None:
    model = tmp_path / "tower.xacro"
    model.write_text(f'<robot name="r" {XACRO_NS}>\n  <link name="${{9**9**9**9}}"/>\n</robot>\n')
    found = assert_refused(model, {"MK709"}, seconds=10)
    assert next(d for d in found if d["code"] == "MK709")["line"] == 2


# ---- SDF: a deep chain of frames, an element with 100,000 attributes, an empty mass --------------


def _frame_chain(path: Path, n: int) -> None:
    pose = "<pose>0 0 0.001 0 0 0</pose>"
    frames = "".join(
        f'<frame name="f{i}" attached_to="{"a" if i == 0 else f"f{i - 1}"}">{pose}</frame>' for i in range(n)
    )
    path.write_text(f'<sdf version="1.9"><model name="m"><link name="a"/>{frames}</model></sdf>')


def test_sdf_frame_chain_is_resolved_in_linear_time(tmp_path: Path) -> None:
    """Each frame's link was found by walking the whole chain again: 5,000 frames never finished."""
    from modelkit.api import validate

    assert_linear_calls(_frame_chain, tmp_path, ".sdf", 2500)
    model = tmp_path / "frames10000.sdf"
    _frame_chain(model, 10000)
    with_codes = validate(model)
    assert not with_codes.errors, with_codes.errors[:3]
    model = tmp_path / "frames5000.sdf"
    _frame_chain(model, 5000)
    assert run("tree", str(model), seconds=10).exit_code == 0


@pytest.mark.parametrize("suffix", [".sdf", ".urdf", ".xml", ".xacro"])
def test_an_element_with_100000_attributes_is_refused_unread(tmp_path: Path, suffix: str) -> None:
    attributes = " ".join(f'a{i}="1"' for i in range(100_000))
    root = {".sdf": '<sdf version="1.9"><model name="m">', ".urdf": '<robot name="r">',
            ".xml": '<mujoco model="m"><worldbody>',
            ".xacro": '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'}[suffix]
    end = {".sdf": "</model></sdf>", ".xml": "</worldbody></mujoco>"}.get(suffix, "</robot>")
    tag = {".xml": "body"}.get(suffix, "link")
    model = tmp_path / f"m{suffix}"
    model.write_text(f'{root}\n<{tag} name="a" {attributes}/>\n{end}\n')
    found = assert_refused(model, {"MK024"}, seconds=10)
    assert next(d for d in found if d["code"] == "MK024")["line"] == 2


def test_sdf_element_with_a_few_unknown_attributes_is_still_read(tmp_path: Path) -> None:
    attributes = " ".join(f'a{i}="1"' for i in range(999))  # with its name: 1,000, the most allowed
    model = tmp_path / "m.sdf"
    model.write_text(f'<sdf version="1.9"><model name="m"><link name="a" {attributes}/></model></sdf>')
    status, found = validate_json(model, seconds=10)
    assert status == 0 and sum(d["code"] == "MK123" for d in found) == 999


@pytest.mark.parametrize("element", ["<mass></mass>", "<mass/>", "<mass>  </mass>"])
def test_sdf_empty_mass_is_a_located_warning(tmp_path: Path, element: str) -> None:
    model = tmp_path / "m.sdf"
    model.write_text(
        '<sdf version="1.9">\n<model name="m">\n<link name="a">\n<inertial>\n'
        f"{element}<inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia>\n</inertial>\n</link>\n</model>\n</sdf>\n"
    )
    status, found = validate_json(model, seconds=10)
    empty = [d for d in found if d["code"] == "MK025"]
    assert [(d["line"], d["severity"]) for d in empty] == [(5, "warning")], found
    assert "1 kg" in str(empty[0]["message"]) and status == 0
    assert run("validate", "--strict", str(model)).exit_code == 1


# ---- a 50 MB XML file: under --max-bytes, so read; one huge value is the parser's limit -----------


@pytest.mark.parametrize(
    "where",
    ["text", "attribute", "comment", "whitespace"],
)
def test_a_50_mb_urdf_with_one_huge_value_gets_its_own_code(tmp_path: Path, where: str) -> None:
    big = "x" * (50 * 1024 * 1024) if where != "whitespace" else " " * (50 * 1024 * 1024)
    body = {
        "text": f'<link name="a">{big}</link>',
        "attribute": f'<link name="{big}"/>',
        "comment": f'<!-- {big} --><link name="a"/>',
        "whitespace": f'<link name="a"/>{big}',
    }[where]
    model = tmp_path / "big.urdf"
    model.write_text(f'<robot name="r">\n{body}\n</robot>\n')
    found = assert_refused(model, {"MK026"}, seconds=10)
    error = next(d for d in found if d["code"] == "MK026")
    assert error["line"] == 2 and int(error["column"]) > 10_000_000, error  # type: ignore[call-overload]


def test_a_urdf_over_max_bytes_is_mk002_and_exit_2(tmp_path: Path) -> None:
    model = tmp_path / "huge.urdf"
    model.write_text('<robot name="r"><link name="a"/>' + " " * (65 * 1024 * 1024) + "</robot>")
    status, found = validate_json(model, seconds=10)
    assert status == 2 and [d["code"] for d in found] == ["MK002"], found
    assert run("tree", str(model), seconds=10).exit_code == 2


def _subbody_file(folder: Path, name: str, children: list[tuple[str, str]]) -> None:
    text = (f"format: ChoreonoidBody\nformat_version: 2.0\nname: {name}\nroot_link: {name}_root\nlinks:\n"
            f"  - name: {name}_root\n    joint_type: fixed\n    mass: 1.0\n"
            "    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]\n"
            "    elements:\n      - { type: Shape, geometry: { type: Box, size: [ 0.1, 0.1, 0.1 ] } }\n")
    for uri, prefix in children:
        text += f"  - {{ type: SubBody, uri: {uri}, parent: {name}_root, prefix: {prefix} }}\n"
    (folder / f"{name}.body").write_text(text)


def test_a_subbody_diamond_stops_at_the_load_bound(tmp_path: Path) -> None:
    """Each of 20 nested bodies includes the next twice: 2^20 loads ran for minutes; now MK009 at the
    SubBody where 2,000 loads are passed. A 300-deep chain (300 loads) is not bounded."""
    from modelkit.api import validate

    for i in range(20):
        _subbody_file(tmp_path, f"d{i}", [(f"d{i + 1}.body", f"a{i}_"), (f"d{i + 1}.body", f"b{i}_")]
                      if i < 19 else [])
    result = validate(tmp_path / "d0.body")
    codes = {d.code for d in result.errors}
    assert codes == {"MK009"}, codes
    assert any(d.location and d.location.line == 13 for d in result.errors if d.code == "MK009")
    for i in range(300):
        _subbody_file(tmp_path, f"c{i}", [(f"c{i + 1}.body", f"p{i}_")] if i < 299 else [])
    chain = validate(tmp_path / "c0.body")  # (under pytest's deeper stack its last level may get MK104)
    assert "MK009" not in {d.code for d in chain.diagnostics} and chain.robot is not None
