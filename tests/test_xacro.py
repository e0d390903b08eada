"""xacro: expansion without ROS, legacy (pre-Jade) xacro, diagnostics placed in the sources.

The smartcar sample (samples/smartcar, transcribed from the lecture in the seed) is legacy xacro: its
tree is pinned by hand from the lecture and checked against check_urdf on our expansion. The corpus
file 08-macroed.urdf.xacro is checked against check_urdf and against xacro's own ``process_file``.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from modelkit.api import validate
from modelkit.cli import main
from modelkit.diagnostics import Severity
from modelkit.formats.common import ReadOptions
from modelkit.formats.xacro import expand_xacro, read_xacro
from modelkit.resources import Resolver

from .conftest import CORPUS, REPO, SAMPLES, require_tool

SMARTCAR = SAMPLES / "smartcar" / "urdf" / "myrobot.urdf.xacro"
BROKEN = REPO / "tests" / "broken_xacro"
CLEAN = BROKEN / "support" / "clean.urdf.xacro"
MACROED = CORPUS / "urdf_tutorial" / "urdf" / "08-macroed.urdf.xacro"

# The lecture's car: base_link carries four wheels on continuous joints and the head on the fixed
# joint "tobox"; check_urdf orders children by joint name, so the head comes last.
SMARTCAR_TREE = """\
robot name is: smartcar
---------- Successfully Parsed XML ---------------
root Link: base_link has 5 child(ren)
    child(1):  left_back_wheel
    child(2):  left_front_wheel
    child(3):  right_back_wheel
    child(4):  right_front_wheel
    child(5):  head
"""

# Every pre-Jade construct of the sample, as (file, line, code).
SMARTCAR_LEGACY = [
    ("myrobot.urdf.xacro", 18, "MK701"),  # <include filename="$(find smartcar)/urdf/robot_body...">
    ("myrobot.urdf.xacro", 21, "MK701"),  # <smartcar_body/>
    ("myrobot.urdf.xacro", 23, "MK701"),  # <smartcar_sim/>
    ("robot_body.urdf.xacro", 3, "MK701"),  # <property name="M_PI" .../>
    ("robot_body.urdf.xacro", 6, "MK701"),  # <include filename="$(find smartcar)/urdf/gazebo...">
    ("robot_body.urdf.xacro", 8, "MK701"),  # <property name="base_x" .../>
    ("robot_body.urdf.xacro", 9, "MK701"),  # <property name="base_y" .../>
]


def cli(*args: str) -> Result:
    result = CliRunner().invoke(main, list(args), catch_exceptions=True)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result


def findings(*args: str) -> tuple[int, list[dict[str, Any]]]:
    result = cli("validate", "--format", "json", "--show-info", *args)
    diagnostics: list[dict[str, Any]] = json.loads(result.stdout)["diagnostics"]
    return result.exit_code, diagnostics


def legacy_list(diagnostics: list[dict[str, Any]]) -> list[tuple[str, int, str]]:
    return [(Path(d["file"]).name, d["line"], d["code"]) for d in diagnostics if d["code"] == "MK701"]


def check_urdf(urdf: Path) -> subprocess.CompletedProcess[str]:
    tool = require_tool("check_urdf")
    return subprocess.run([tool, str(urdf)], capture_output=True, text=True, check=False, timeout=60)


def without_banner(text: str) -> str:
    """xacro's output without the comment banner that names the input file."""
    return re.sub(r"<!-- [=|].*?-->\n", "", text)


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


# ---- the smartcar sample (legacy xacro) ---------------------------------------------------------


def test_smartcar_tree_in_auto_mode_is_the_lecture_car() -> None:
    result = cli("tree", str(SMARTCAR))
    assert result.exit_code == 0, result.output
    assert result.stdout == SMARTCAR_TREE


def test_smartcar_tree_equals_check_urdf_on_our_expansion(tmp_path: Path) -> None:
    text, _ = expand_xacro(SMARTCAR)
    assert text is not None
    urdf = write(tmp_path / "smartcar.urdf", text)
    done = check_urdf(urdf)
    assert done.returncode == 0, done.stderr
    assert done.stdout == SMARTCAR_TREE
    assert cli("tree", str(SMARTCAR)).stdout == done.stdout


def test_smartcar_with_legacy_flag_gives_the_same_tree() -> None:
    result = cli("tree", "--legacy", str(SMARTCAR))
    assert (result.exit_code, result.stdout) == (0, SMARTCAR_TREE)


def test_smartcar_current_xacro_behaviour_loses_the_car(tmp_path: Path) -> None:
    result = cli("tree", "--no-legacy", str(SMARTCAR))
    assert result.exit_code != 0
    assert result.stdout != SMARTCAR_TREE
    # What current xacro produces: the legacy elements pass through, and the robot has no links.
    text, _ = expand_xacro(SMARTCAR, ReadOptions(legacy_xacro=False))
    assert text is not None
    assert "<smartcar_body/>" in text and "<include " in text and "<link" not in text
    done = check_urdf(write(tmp_path / "plain.urdf", text))
    assert done.returncode != 0
    assert "No link elements found" in done.stderr


def test_smartcar_validate_no_legacy_reports_each_construct_as_an_error() -> None:
    code, diagnostics = findings("--no-legacy", str(SMARTCAR))
    assert code == 1
    assert legacy_list(diagnostics) == SMARTCAR_LEGACY
    legacy = [d for d in diagnostics if d["code"] == "MK701"]
    assert {d["severity"] for d in legacy} == {"error"}
    first = legacy[0]
    assert (first["line"], first["column"]) == (18, 1)
    assert "legacy xacro: <include> without the xacro: prefix" in first["message"]
    assert '<xacro:include filename="$(find smartcar)/urdf/robot_body.urdf.xacro"/>' in first["hint"]


def test_smartcar_validate_auto_warns_per_construct_without_errors() -> None:
    code, diagnostics = findings(str(SMARTCAR))
    assert code == 0
    assert legacy_list(diagnostics) == SMARTCAR_LEGACY
    assert {d["severity"] for d in diagnostics if d["code"] == "MK701"} == {"warning"}
    assert [d for d in diagnostics if d["severity"] == "error"] == []
    hints = [d["hint"] for d in diagnostics if d["code"] == "MK701"]
    assert 'use <xacro:property name="M_PI" value="3.14159"/>' in hints
    assert "use <xacro:smartcar_body/>" in hints


def test_smartcar_with_legacy_flag_reports_constructs_as_info_only() -> None:
    code, diagnostics = findings("--legacy", str(SMARTCAR))
    assert code == 0
    assert legacy_list(diagnostics) == SMARTCAR_LEGACY
    assert {d["severity"] for d in diagnostics if d["code"] == "MK701"} == {"info"}


def _modernise(text: str) -> str:
    text = re.sub(r"<(/?)(property|include|macro|arg|if|unless|insert_block)\b", r"<\1xacro:\2", text)
    return re.sub(r"<(smartcar_body|smartcar_sim)/>", r"<xacro:\1/>", text)


def test_legacy_rewriting_equals_xacro_on_hand_modernised_sources(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Auto mode gives what real xacro gives once the prefixes are written by hand."""
    package = tmp_path / "smartcar"
    shutil.copytree(SMARTCAR.parents[1], package)
    for name in ("myrobot.urdf.xacro", "robot_body.urdf.xacro", "gazebo.urdf.xacro"):
        path = package / "urdf" / name
        path.write_text(_modernise(path.read_text(encoding="utf-8")), encoding="utf-8")
    modern = package / "urdf" / "myrobot.urdf.xacro"

    ours, _ = expand_xacro(SMARTCAR)
    plain, diagnostics = expand_xacro(modern, ReadOptions(legacy_xacro=False))
    assert diagnostics == []
    assert ours is not None and plain is not None
    assert without_banner(ours) == without_banner(plain)

    import xacro
    import xacro.substitution_args

    # xacro's own expansion of the modernised files, with a find that needs no ROS.
    monkeypatch.setattr(xacro.substitution_args, "_eval_find", lambda pkg: str(package))
    reference = xacro.process_file(str(modern)).toprettyxml(indent="  ")
    assert plain == reference


# ---- the corpus: urdf_tutorial's 08-macroed ------------------------------------------------------


def test_corpus_macroed_tree_equals_check_urdf(corpus: Path, tmp_path: Path) -> None:
    text, diagnostics = expand_xacro(MACROED)
    assert text is not None, diagnostics
    done = check_urdf(write(tmp_path / "macroed.urdf", text))
    assert done.returncode == 0, done.stderr
    result = cli("tree", str(MACROED))
    assert result.exit_code == 0, result.output
    assert result.stdout == done.stdout
    assert done.stdout.startswith("robot name is: macroed\n")


def test_corpus_macroed_expansion_equals_xacro_process_file(
    corpus: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    text, _ = expand_xacro(MACROED)
    import xacro
    import xacro.substitution_args

    package = MACROED.parents[1]
    monkeypatch.setattr(xacro.substitution_args, "_eval_find", lambda pkg: str(package))
    assert text == xacro.process_file(str(MACROED)).toprettyxml(indent="  ")


# ---- arguments, packages, environment ------------------------------------------------------------


def test_xacro_argument_changes_the_tree() -> None:
    full = cli("tree", str(CLEAN))
    assert full.exit_code == 0 and "child(1):  caster" in full.stdout
    bare = cli("tree", str(CLEAN), "with_caster:=false")
    assert bare.exit_code == 0, bare.output
    assert bare.stdout.splitlines()[2:] == [
        "root Link: base_link has 2 child(ren)",
        "    child(1):  left_wheel",
        "    child(2):  right_wheel",
    ]


def test_find_uses_the_package_path_option(tmp_path: Path) -> None:
    parts = write(
        tmp_path / "elsewhere" / "parts" / "arm.xacro",
        (
            '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:macro name="arm"><link name="arm"/></xacro:macro>\n'
            "</robot>\n"
        ),
    )
    top = write(
        tmp_path / "robot" / "top.xacro",
        (
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:include filename="$(find parts)/arm.xacro"/>\n'
            "  <xacro:arm/>\n"
            "</robot>\n"
        ),
    )
    options = ReadOptions(resolver=Resolver(environ={}))
    text, diagnostics = expand_xacro(top, options)
    assert text is None
    assert [(d.code, d.location and d.location.line) for d in diagnostics] == [("MK702", 2)]
    assert "--package-path parts=DIR" in (diagnostics[0].hint or "")

    options = ReadOptions(resolver=Resolver(package_paths={"parts": parts.parent}, environ={}))
    text, diagnostics = expand_xacro(top, options)
    assert diagnostics == [] and text is not None and '<link name="arm"/>' in text


def test_env_and_optenv_use_the_resolver_environment(tmp_path: Path) -> None:
    top = write(
        tmp_path / "env.xacro",
        (
            '<robot name="$(env ROBOT_NAME)" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <link name="$(optenv LINK_NAME base)"/>\n'
            "</robot>\n"
        ),
    )
    text, diagnostics = expand_xacro(top, ReadOptions(resolver=Resolver(environ={"ROBOT_NAME": "envbot"})))
    assert diagnostics == [] and text is not None
    assert '<robot name="envbot">' in text and '<link name="base"/>' in text
    text, diagnostics = expand_xacro(top, ReadOptions(resolver=Resolver(environ={})))
    assert text is None
    assert [d.code for d in diagnostics] == ["MK700"]
    assert "ROBOT_NAME" in diagnostics[0].message


# ---- where diagnostics point -----------------------------------------------------------------------


def test_urdf_findings_in_macro_output_point_at_the_macro_body(tmp_path: Path) -> None:
    write(
        tmp_path / "body.xacro",
        (
            '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:macro name="arm" params="name parent">\n'
            '    <link name="${name}"/>\n'
            '    <joint name="${name}_joint" type="fixed">\n'
            '      <parent link="${parent}"/>\n'
            '      <child link="${name}"/>\n'
            "    </joint>\n"
            "  </xacro:macro>\n"
            "</robot>\n"
        ),
    )
    top = write(
        tmp_path / "top.xacro",
        (
            '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:include filename="body.xacro"/>\n'
            '  <link name="base"/>\n'
            '  <xacro:arm name="a1" parent="base"/>\n'
            '  <xacro:arm name="a2" parent="nowhere"/>\n'
            "</robot>\n"
        ),
    )
    result = validate(top)
    assert result.robot is not None and len(result.robot.links) == 3
    errors = [d for d in result.diagnostics if d.severity is Severity.ERROR]
    assert errors, result.diagnostics
    about = [d for d in errors if "nowhere" in d.message]
    assert about and about[0].location is not None
    assert (Path(about[0].location.file).name, about[0].location.line) == ("body.xacro", 5)
    # no element of the expansion points at the generated text: every location is a source line
    assert all(d.location and d.location.file.endswith(".xacro") for d in result.diagnostics)


def test_included_files_are_shown_relative_like_the_top_file(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(REPO)
    code, diagnostics = findings("tests/broken_xacro/undefined_in_include.xacro")
    assert code == 1
    assert [(d["file"], d["line"], d["code"]) for d in diagnostics] == [
        ("tests/broken_xacro/support/undefined_in_macro.xacro", 9, "MK707")
    ]


def test_missing_top_file_is_a_diagnostic_not_a_crash(tmp_path: Path) -> None:
    result = cli("validate", str(tmp_path / "nothing.urdf.xacro"))
    assert result.exit_code == 2
    assert "MK001" in result.stdout


# ---- state, output, limits -------------------------------------------------------------------------


def test_expansion_prints_nothing_and_turns_warnings_into_diagnostics(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    noisy = write(
        tmp_path / "noisy.xacro",
        (
            '<robot name="n" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:property name="len" value="2"/>\n'
            "  <link name=\"a\">${xacro.message('hello')}</link>\n"
            "</robot>\n"
        ),
    )
    text, diagnostics = expand_xacro(noisy)
    broken, errors = expand_xacro(BROKEN / "macro_recursion.xacro")
    out, err = capfd.readouterr()
    assert (out, err) == ("", "")
    assert text is not None and broken is None
    found = [(d.code, d.severity.value, d.location and d.location.line, d.message) for d in diagnostics]
    assert found == [
        ("MK703", "warning", 2, "xacro: redefining global symbol: len"),
        ("MK703", "info", 3, "xacro: hello"),
    ]
    assert [d.code for d in errors] == ["MK706"]


def test_expansion_is_deterministic_and_leaves_xacro_as_it_was() -> None:
    import xacro
    import xacro.substitution_args

    before = (xacro.parse, xacro.eval_all, xacro.warning, xacro.substitution_args._eval_find)
    first, _ = expand_xacro(CLEAN)
    for case in ("undefined_property.xacro", "macro_recursion.xacro", "include_malformed.xacro"):
        text, diagnostics = expand_xacro(BROKEN / case)
        assert text is None and diagnostics
    second, _ = expand_xacro(CLEAN)
    assert first is not None and first == second
    assert (xacro.parse, xacro.eval_all, xacro.warning, xacro.substitution_args._eval_find) == before


def test_macro_bomb_stops_at_the_expansion_limit(tmp_path: Path) -> None:
    lines = ['<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">']
    for i in range(30):
        lines.append(f'  <xacro:macro name="m{i}"><g><xacro:m{i + 1}/><xacro:m{i + 1}/></g></xacro:macro>')
    lines += ['  <xacro:macro name="m30"><link name="x"/></xacro:macro>', "  <xacro:m0/>", "</robot>"]
    bomb = write(tmp_path / "bomb.xacro", "\n".join(lines) + "\n")
    text, diagnostics = expand_xacro(bomb, ReadOptions(expansion_limit=2000))
    assert text is None
    assert [d.code for d in diagnostics] == ["MK709"]


def test_property_bomb_stops_at_the_size_limit(tmp_path: Path) -> None:
    lines = ['<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">']
    lines.append("""  <xacro:property name="p0" value="'xxxxxxxxxxxxxxxx'"/>""")
    lines += [f'  <xacro:property name="p{i + 1}" value="${{p{i}+p{i}}}"/>' for i in range(40)]
    lines += ['  <link name="${p40}"/>', "</robot>"]
    bomb = write(tmp_path / "bomb.xacro", "\n".join(lines) + "\n")
    text, diagnostics = expand_xacro(bomb, ReadOptions(max_bytes=20_000))
    assert text is None
    assert [d.code for d in diagnostics] == ["MK709"]


# ---- legacy detection --------------------------------------------------------------------------------


def test_no_false_legacy_alarms_for_gazebo_includes_and_format_elements(tmp_path: Path) -> None:
    model = write(
        tmp_path / "modern.xacro",
        (
            '<robot name="m" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:macro name="cylinder" params="r"><cylinder radius="${r}" length="1"/></xacro:macro>\n'
            '  <link name="a"><visual><geometry><xacro:cylinder r="0.1"/></geometry></visual></link>\n'
            '  <gazebo><include><uri>model://sun</uri></include><property name="x">1</property></gazebo>\n'
            "</robot>\n"
        ),
    )
    text, diagnostics = expand_xacro(model)
    assert text is not None
    assert [d for d in diagnostics if d.code == "MK701"] == []
    assert '<cylinder length="1" radius="0.1"/>' in text


def test_every_legacy_directive_is_detected_and_expanded(tmp_path: Path) -> None:
    write(
        tmp_path / "parts.xacro",
        (
            '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <macro name="wheel" params="name *origin">\n'
            '    <link name="${name}"/>\n'
            '    <joint name="${name}_joint" type="fixed"><parent link="base"/><child link="${name}"/>\n'
            '      <insert_block name="origin"/>\n'
            "    </joint>\n"
            "  </macro>\n"
            "</robot>\n"
        ),
    )
    top = write(
        tmp_path / "old.xacro",
        (
            '<robot name="old" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <arg name="spare" default="false"/>\n'
            '  <property name="offset" value="0.2"/>\n'
            '  <include filename="parts.xacro"/>\n'
            '  <link name="base"/>\n'
            '  <wheel name="left"><origin xyz="0 ${offset} 0"/></wheel>\n'
            '  <if value="$(arg spare)"><wheel name="spare"><origin xyz="0 0 0"/></wheel></if>\n'
            '  <unless value="$(arg spare)">'
            '<wheel name="right"><origin xyz="0 -${offset} 0"/></wheel></unless>\n'
            "</robot>\n"
        ),
    )
    text, diagnostics = expand_xacro(top)
    assert text is not None, diagnostics
    found = sorted(
        (Path(d.location.file).name, d.location.line, d.message.split(" without")[0])
        for d in diagnostics
        if d.location
    )
    assert found == [
        ("old.xacro", 2, "legacy xacro: <arg>"),
        ("old.xacro", 3, "legacy xacro: <property>"),
        ("old.xacro", 4, "legacy xacro: <include>"),
        ("old.xacro", 6, 'legacy xacro: <wheel> calls macro "wheel"'),
        ("old.xacro", 7, "legacy xacro: <if>"),
        ("old.xacro", 7, 'legacy xacro: <wheel> calls macro "wheel"'),
        ("old.xacro", 8, "legacy xacro: <unless>"),
        ("old.xacro", 8, 'legacy xacro: <wheel> calls macro "wheel"'),
        ("parts.xacro", 2, "legacy xacro: <macro>"),
        ("parts.xacro", 5, "legacy xacro: <insert_block>"),
    ]
    assert {d.severity for d in diagnostics} == {Severity.WARNING}
    assert '<link name="left"/>' in text and '<link name="right"/>' in text
    assert '<link name="spare"/>' not in text and '<origin xyz="0 -0.2 0"/>' in text


def test_read_xacro_builds_the_smartcar_with_sources_in_the_xacro_files() -> None:
    result = read_xacro(SMARTCAR, ReadOptions(), str(SMARTCAR))
    robot = result.robot
    assert robot is not None and robot.root == "base_link"
    assert sorted(link.name for link in robot.links) == [
        "base_link",
        "head",
        "left_back_wheel",
        "left_front_wheel",
        "right_back_wheel",
        "right_front_wheel",
    ]
    sources = {(Path(j.source.file).name, j.source.line) for j in robot.joints if j.source}
    assert sources == {("robot_body.urdf.xacro", n) for n in (60, 92, 124, 156, 188)}


def test_a_file_that_includes_itself_is_reported_at_the_include(tmp_path: Path) -> None:
    loop = write(
        tmp_path / "loop.xacro",
        '<robot name="s" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <link name="a"/>\n'
        '  <xacro:include filename="loop.xacro"/>\n'
        "</robot>\n",
    )
    text, diagnostics = expand_xacro(loop)
    assert text is None
    assert [(d.code, d.location and d.location.line) for d in diagnostics] == [("MK706", 3)]
    assert "includes itself" in diagnostics[0].message


def test_tree_of_a_failing_xacro_prints_the_finding_not_a_traceback() -> None:
    result = cli("tree", str(BROKEN / "find_unknown_package.xacro"))
    assert result.exit_code == 1
    assert result.stdout == ""
    assert "find_unknown_package.xacro:8:18: error MK702" in result.stderr
    assert "Traceback" not in result.output
