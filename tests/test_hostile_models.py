"""Hostile models found by the hostile corpus (issue 18, item 2): each is refused at once with a
located, coded error, exits as the README's table says, and quotes nothing it should not."""

from __future__ import annotations

from pathlib import Path

import pytest

from .test_hostile_input import assert_refused, run, validate_json

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
