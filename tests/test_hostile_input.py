"""Hostile input: never hang, never explode, never leak (issue 9, section 2).

Every case is a real file written in ``tmp_path`` (real FIFOs, real symlinks, real sparse files),
run through ``modelkit validate`` and ``modelkit tree`` in-process with a watchdog. Each failure must
be a coded diagnostic with a location, exit 1 or 2, and no traceback.
"""

from __future__ import annotations

import json
import os
import re
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType

import pytest
from click.testing import CliRunner, Result
from hypothesis import given
from hypothesis import strategies as st

from modelkit.cli import main

WATCHDOG_SECONDS = 20


@contextmanager
def watchdog(seconds: float) -> Iterator[None]:
    """Raise TimeoutError in the main thread after ``seconds`` (a hang fails the test)."""

    def expire(signum: int, frame: FrameType | None) -> None:
        raise TimeoutError(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def run(*args: str, seconds: float = WATCHDOG_SECONDS) -> Result:
    with watchdog(seconds):
        result = CliRunner().invoke(main, list(args))
    assert not isinstance(result.exception, TimeoutError), f"modelkit {' '.join(args)} hung"
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert "Traceback" not in result.output
    return result


def validate_json(
    path: Path, *extra: str, seconds: float = WATCHDOG_SECONDS
) -> tuple[int, list[dict[str, object]]]:
    result = run("validate", "--format", "json", str(path), *extra, seconds=seconds)
    report = json.loads(result.stdout)
    return result.exit_code, report["diagnostics"] if isinstance(report, dict) else report


def assert_refused(
    path: Path, codes: set[str], *extra: str, tree: bool = True, seconds: float = WATCHDOG_SECONDS
) -> list[dict[str, object]]:
    """validate (and tree, unless it does not open the file at fault) fail with one of ``codes``,
    located, exit 1 or 2, within ``seconds`` each."""
    status, found = validate_json(path, *extra, seconds=seconds)
    assert status in (1, 2), found
    errors = [d for d in found if d["severity"] == "error"]
    assert errors and all(d["code"] and d["file"] for d in errors), found
    assert {d["code"] for d in errors} & codes, found
    printed = run("tree", str(path), *extra, seconds=seconds)
    if tree:
        assert printed.exit_code in (1, 2), printed.output
        assert any(code in printed.output for code in codes), printed.output
    else:  # tree does not open meshes or textures: it may print the tree, but never hang
        assert printed.exit_code in (0, 1, 2)
    return found


def _listing(report: object) -> list[dict[str, object]]:
    return report["diagnostics"] if isinstance(report, dict) else report  # type: ignore[return-value]


# ---- 1. only regular files are read ----------------------------------------------------------------

SPECIAL_KINDS = ("fifo", "dev_zero", "dev_urandom", "sparse_2gb", "directory", "symlink_loop")


def make_special(path: Path, kind: str) -> None:
    """Make ``path`` a file no reader may read whole (or at all)."""
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev_zero":
        path.symlink_to("/dev/zero")
    elif kind == "dev_urandom":
        path.symlink_to("/dev/urandom")
    elif kind == "sparse_2gb":
        with path.open("wb") as handle:
            handle.truncate(2 * 1024**3)
    elif kind == "directory":
        path.mkdir()
    elif kind == "symlink_loop":
        path.symlink_to(path.name)
    else:  # pragma: no cover
        raise ValueError(kind)


UNREADABLE = {"MK001", "MK002"}
MESH_UNREADABLE = {"MK001", "MK002", "MK500", "MK501"}


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
@pytest.mark.parametrize("suffix", [".urdf", ".body", ".sdf", ".xacro", ".xml", ".mjcf"])
def test_special_file_as_the_model(tmp_path: Path, kind: str, suffix: str) -> None:
    model = tmp_path / f"model{suffix}"
    make_special(model, kind)
    found = assert_refused(model, UNREADABLE)
    assert all(d["file"] == str(model) for d in found)


def _urdf_mesh(tmp_path: Path, name: str) -> Path:
    model = tmp_path / "m.urdf"
    model.write_text(
        f'<robot name="r"><link name="a"><collision><geometry><mesh filename="{name}"/></geometry>'
        "</collision></link></robot>"
    )
    return model


def _body_mesh(tmp_path: Path, name: str) -> Path:
    model = tmp_path / "m.body"
    model.write_text(
        "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: base\n"
        f"    elements:\n      - type: Resource\n        uri: {name}\n"
    )
    return model


def _sdf_mesh(tmp_path: Path, name: str) -> Path:
    model = tmp_path / "m.sdf"
    model.write_text(
        '<sdf version="1.9"><model name="r"><link name="a"><collision name="c"><geometry><mesh>'
        f"<uri>{name}</uri></mesh></geometry></collision></link></model></sdf>"
    )
    return model


def _mjcf_mesh(tmp_path: Path, name: str) -> Path:
    model = tmp_path / "m.xml"
    model.write_text(
        f'<mujoco model="r"><asset><mesh name="m" file="{name}"/></asset><worldbody><body name="a">'
        '<geom type="mesh" mesh="m"/></body></worldbody></mujoco>'
    )
    return model


MESH_MODELS: dict[str, Callable[[Path, str], Path]] = {
    "urdf": _urdf_mesh,
    "body": _body_mesh,
    "sdf": _sdf_mesh,
    "mjcf": _mjcf_mesh,
}


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
@pytest.mark.parametrize("fmt", sorted(MESH_MODELS))
def test_special_file_as_a_mesh(tmp_path: Path, kind: str, fmt: str) -> None:
    make_special(tmp_path / "part.stl", kind)
    model = MESH_MODELS[fmt](tmp_path, "part.stl")
    if fmt in ("urdf", "sdf"):
        # check_urdf and libsdformat never open meshes: a collision mesh no loader can read is a coded,
        # located warning (an error when it cannot be opened at all: too large, a loop), and an error
        # for --target mjcf, which loads it (tree does not open meshes, so it is run without a target)
        status, found = validate_json(model)
        assert status in (0, 1, 2), found  # 2: a file over --max-bytes is not read at all (MK002)
        assert any(d["line"] for d in found if d["code"] in MESH_UNREADABLE), found
        status, found = validate_json(model, "--target", "mjcf")
        errors = [d for d in found if d["severity"] == "error"]
        assert status in (1, 2) and {d["code"] for d in errors} & MESH_UNREADABLE, found
        printed = run("tree", str(model))
        assert printed.exit_code in (0, 1, 2)
    else:
        found = assert_refused(model, MESH_UNREADABLE, tree=fmt == "mjcf")
    assert any(d["line"] for d in found if d["code"] in MESH_UNREADABLE), found


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
@pytest.mark.parametrize("fmt", ["urdf", "mjcf"])
def test_special_file_as_a_texture(tmp_path: Path, kind: str, fmt: str) -> None:
    make_special(tmp_path / "skin.png", kind)
    model = tmp_path / f"m.{fmt if fmt == 'urdf' else 'xml'}"
    if fmt == "urdf":
        model.write_text(
            '<robot name="r"><link name="a"><visual><geometry><box size="1 1 1"/></geometry>'
            '<material name="m"><texture filename="skin.png"/></material></visual></link></robot>'
        )
    else:
        model.write_text(
            '<mujoco model="r"><asset><texture name="t" type="2d" file="skin.png"/></asset>'
            '<worldbody><body name="a"><geom size="1"/></body></worldbody></mujoco>'
        )
    found = assert_refused(model, {"MK001", "MK002", "MK507"}, tree=fmt == "mjcf")
    assert any(d["line"] for d in found if d["severity"] == "error"), found


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
def test_special_file_as_an_xacro_include(tmp_path: Path, kind: str) -> None:
    make_special(tmp_path / "part.xacro", kind)
    model = tmp_path / "m.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="part.xacro"/>\n  <link name="a"/>\n</robot>\n'
    )
    assert_refused(model, UNREADABLE | {"MK705", "MK711"})  # /dev/zero is outside the model's tree


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
def test_special_file_as_an_xacro_yaml(tmp_path: Path, kind: str) -> None:
    make_special(tmp_path / "values.yaml", kind)
    model = tmp_path / "m.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:property name="v" value="${xacro.load_yaml(\'values.yaml\')}"/>\n'
        '  <link name="${v.name}"/>\n</robot>\n'
    )
    assert_refused(model, UNREADABLE | {"MK705", "MK700", "MK711"})


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
def test_special_file_as_an_sdf_include(tmp_path: Path, kind: str) -> None:
    make_special(tmp_path / "part.sdf", kind)
    model = tmp_path / "w.sdf"
    model.write_text(
        '<sdf version="1.9"><world name="w"><include><uri>part.sdf</uri></include></world></sdf>'
    )
    assert_refused(model, UNREADABLE | {"MK500", "MK530"})


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
def test_special_file_as_a_sub_body(tmp_path: Path, kind: str) -> None:
    make_special(tmp_path / "sub.body", kind)
    model = tmp_path / "m.body"
    model.write_text(
        "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: base\n"
        "  - type: SubBody\n    uri: sub.body\n    parent: base\n"
    )
    assert_refused(model, UNREADABLE | {"MK216"})


@pytest.mark.parametrize("kind", SPECIAL_KINDS)
def test_special_file_as_an_mjcf_include(tmp_path: Path, kind: str) -> None:
    make_special(tmp_path / "part.xml", kind)
    model = tmp_path / "m.xml"
    model.write_text(
        '<mujoco model="r"><include file="part.xml"/><worldbody><body name="a"><geom size="1"/>'
        "</body></worldbody></mujoco>"
    )
    assert_refused(model, UNREADABLE | {"MK170"})


def test_read_regular_bounds_a_file_that_grows(tmp_path: Path) -> None:
    from modelkit.textio import UnreadableFile, read_regular

    target = tmp_path / "a.urdf"
    target.write_bytes(b"x" * 100)
    assert read_regular(target, 100) == b"x" * 100
    with pytest.raises(UnreadableFile) as info:
        read_regular(target, 99)
    assert info.value.code == "MK002"


# ---- 2. cycles -----------------------------------------------------------------------------------


def test_sdf_joint_cycle_is_reported_not_looped(tmp_path: Path) -> None:
    model = tmp_path / "cycle.sdf"
    links = "".join(f'<link name="{n}"/>' for n in "abc")
    joints = "".join(
        f'<joint name="j{p}{c}" type="revolute"><parent>{p}</parent><child>{c}</child>'
        "<axis><xyz>0 0 1</xyz></axis></joint>"
        for p, c in ("ab", "bc", "ca")
    )
    model.write_text(f'<sdf version="1.9"><model name="m">{links}{joints}</model></sdf>')
    # a closed chain, which libsdformat loads (its own four_bar.sdf is one): a located warning, at once
    status, found = validate_json(model, seconds=10)
    assert status == 0 and [d["code"] for d in found if d["severity"] != "info"].count("MK241") == 1, found
    assert run("tree", str(model), seconds=10).exit_code == 0


def test_urdf_joint_cycle_is_reported(tmp_path: Path) -> None:
    model = tmp_path / "cycle.urdf"
    links = "".join(f'<link name="{n}"/>' for n in "ab")
    joints = "".join(
        f'<joint name="j{p}{c}" type="fixed"><parent link="{p}"/><child link="{c}"/></joint>'
        for p, c in ("ab", "ba")
    )
    model.write_text(f'<robot name="r">{links}{joints}</robot>')
    assert_refused(model, {"MK200", "MK203"})


def test_body_parent_cycle_is_reported(tmp_path: Path) -> None:
    model = tmp_path / "cycle.body"
    model.write_text(
        "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: root\n"
        "  - name: a\n    parent: b\n    jointType: fixed\n  - name: b\n    parent: a\n    jointType: fixed\n"
    )
    assert_refused(model, {"MK200", "MK203", "MK218"})


# ---- 3. size and complexity limits ------------------------------------------------------------------


def _chain_urdf(path: Path, n: int) -> None:
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/><child link="l{i}"/></joint>'
        for i in range(1, n)
    )
    path.write_text(f'<robot name="r">{links}{joints}</robot>')


def test_link_limit_and_its_option(tmp_path: Path) -> None:
    model = tmp_path / "chain.urdf"
    _chain_urdf(model, 60)
    assert_refused(model, {"MK005"}, "--max-links", "50")
    status, found = validate_json(model, "--max-links", "60")
    assert not any(d["code"] == "MK005" for d in found) and status in (0, 1)


def test_body_links_limit_is_checked_before_composing(tmp_path: Path) -> None:
    model = tmp_path / "many.body"
    items = "".join(f"  - name: l{i}\n    parent: l{i - 1}\n    jointType: fixed\n" for i in range(1, 200))
    model.write_text("format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: l0\n" + items)
    found = assert_refused(model, {"MK005"}, "--max-links", "100")
    assert next(d for d in found if d["code"] == "MK005")["line"] == 5


def test_list_limit_and_its_option(tmp_path: Path) -> None:
    model = tmp_path / "list.body"
    numbers = ", ".join("0.5" for _ in range(1000))
    model.write_text(
        "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: base\n    elements:\n"
        f"      - type: Shape\n        geometry: {{type: Box, size: [{numbers}]}}\n"
    )
    found = assert_refused(model, {"MK006"}, "--max-list-items", "999")
    assert next(d for d in found if d["code"] == "MK006")["line"] == 8
    _, found = validate_json(model, "--max-list-items", "1000")
    assert not any(d["code"] == "MK006" for d in found)


def _same(a: object, b: object) -> bool:
    return a is b


@contextmanager
def comparisons_as_calls() -> Iterator[None]:
    """Links and joints compare by identity in C (``eq=False``), so a scan of a list of them
    (``links.index(link)``, ``link in links``) is invisible to a call count. For the block, they
    compare by identity through a Python function, the same answer, each comparison a call."""
    from modelkit.model import Joint, Link

    for kind in (Link, Joint):
        kind.__eq__ = _same  # type: ignore[assignment,method-assign]
    try:
        yield
    finally:
        for kind in (Link, Joint):
            del kind.__eq__


def call_count(path: Path) -> int:
    """Function calls (Python and built-in) that ``validate(path)`` makes, counted by cProfile, with
    link and joint comparisons counted as calls (:func:`comparisons_as_calls`).

    The count depends only on the work done, not on the machine or on what else runs, so a test can
    compare two sizes without timing anything. A loop that calls nothing per step over plain values
    (``name in a_list_of_names``) is not counted; the readers and rules call functions per element,
    so a super-linear walk over links or frames shows as a super-linear count."""
    import cProfile
    import pstats

    from modelkit.api import validate

    profile = cProfile.Profile()
    with comparisons_as_calls():
        profile.enable()
        try:
            validate(path)
        finally:
            profile.disable()
    return pstats.Stats(profile).total_calls


def assert_linear_calls(
    make: Callable[[Path, int], None], folder: Path, suffix: str, small: int
) -> list[int]:
    """Calls for a model of ``small`` elements and of four times as many, after a tiny warm-up (so
    that imports and caches filled on first use count in neither): about 4×, never 16×."""
    counts = []
    for n in (10, small, 4 * small):
        model = folder / f"model{n}{suffix}"
        make(model, n)
        counts.append(call_count(model))
    assert counts[2] < 6 * counts[1], counts  # linear: 4.0× measured; quadratic: 16×
    return counts[1:]


def test_links_are_checked_in_linear_time(tmp_path: Path) -> None:
    """The unique-names rule once compared links with list.index: quadratic in links."""
    assert_linear_calls(_chain_urdf, tmp_path, ".urdf", 1000)


XACRO_BOMBS = {
    "power": "${10**10**10}",
    "list": "${[0]*10**9}",
    "string": "${'a'*10**10}",
    "range": "${python.sum(python.range(10**12))}",
    "comprehension": "${len([x for x in python.range(10**6) for y in python.range(10**6)])}",
    "shift": "${1 &lt;&lt; 10**9}",
    "format": "${'%0999999999d' % 1}",
    "factorial": "${math.factorial(10**7)}",
    "padding": "${'a'.ljust(10**10)}",
}


@pytest.mark.parametrize("name", sorted(XACRO_BOMBS))
def test_xacro_expression_bombs_are_bounded(tmp_path: Path, name: str) -> None:
    model = tmp_path / "bomb.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        f'  <xacro:property name="big" value="{XACRO_BOMBS[name]}"/>\n'
        '  <link name="a"><visual><geometry><box size="${big} 1 1"/></geometry></visual></link>\n'
        "</robot>\n"
    )
    found = assert_refused(model, {"MK709"}, seconds=10)
    assert next(d for d in found if d["code"] == "MK709")["line"] == 2


def test_xacro_ordinary_arithmetic_still_works(tmp_path: Path) -> None:
    model = tmp_path / "ok.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:property name="n" value="${2**10 * 3 + len([i for i in python.range(5)])}"/>\n'
        "  <xacro:property name=\"s\" value=\"${'%d-%s' % (n, 'x' * 3)}\"/>\n"
        '  <link name="l_${n}_${s}"/>\n</robot>\n'
    )
    from modelkit.api import validate

    result = validate(model)
    assert result.robot is not None and result.robot.links[0].name == "l_3077_3077-xxx", result.diagnostics


@pytest.mark.parametrize("kind", ["replicate", "hfield", "flexcomp"])
def test_mjcf_sizes_are_checked_before_mujoco(tmp_path: Path, kind: str) -> None:
    model = tmp_path / "big.xml"
    body = {
        "replicate": '<replicate count="1000"><replicate count="1000"><body><geom size="1"/></body>'
        "</replicate></replicate>",
        "hfield": '<body name="a"><geom size="1"/></body>',
        "flexcomp": '<flexcomp name="f" type="grid" count="1000 1000 1000" spacing="1 1 1" dim="3"/>',
    }[kind]
    asset = '<asset><hfield name="h" nrow="100000" ncol="100000" size="1 1 1 1"/></asset>'
    model.write_text(
        f'<mujoco model="m">{asset if kind == "hfield" else ""}<worldbody>{body}</worldbody></mujoco>'
    )
    assert_refused(model, {"MK005"}, seconds=10)


# ---- 4. no disclosure -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "line",
    [
        '<xacro:include filename="/etc/passwd"/>',
        '<xacro:include filename="../outside/secret.xacro"/>',
        '<xacro:property name="v" lazy_eval="false" value="${xacro.load_yaml(\'/etc/passwd\')}"/>',
        '<xacro:property name="v" lazy_eval="false" value="${xacro.load_yaml(\'../outside/secret.yaml\')}"/>',
        '<xacro:property name="v" lazy_eval="false" value="${xacro.load_yaml(\'link.yaml\')}"/>',
    ],
)
def test_xacro_reads_nothing_outside_the_model_tree(tmp_path: Path, line: str) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    secret = "root:x:0:0:SECRET-CONTENT"
    (outside / "secret.xacro").write_text(
        f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro">{secret}</robot>'
    )
    (outside / "secret.yaml").write_text(f"name: {secret}\n")
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "link.yaml").symlink_to(outside / "secret.yaml")  # a symlink out is outside too
    model = folder / "m.xacro"
    head = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    model.write_text(f'{head}\n  {line}\n  <link name="a"/>\n</robot>\n')
    found = assert_refused(model, {"MK711"})
    assert next(d for d in found if d["code"] == "MK711")["line"] == 2
    for command in (("validate",), ("tree",)):
        output = run(*command, str(model)).output
        assert "SECRET" not in output and "root:x" not in output


def test_xacro_package_paths_given_are_readable(tmp_path: Path) -> None:
    package = tmp_path / "parts"
    package.mkdir()
    (package / "arm.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="arm"/></robot>'
    )
    folder = tmp_path / "model"
    folder.mkdir()
    model = folder / "m.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="$(find parts)/arm.xacro"/>\n</robot>\n'
    )
    status, found = validate_json(model, "--package-path", f"parts={package}")
    assert not any(d["code"] == "MK711" for d in found), found
    assert status in (0, 1)


# ---- 5. no writes -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "body",
    [
        '<geom size="nan"/>',
        '<geom type="mesh" mesh="missing"/>',
        '<inertial pos="0 0 0" mass="-1" diaginertia="1 1 1"/>',
    ],
)
def test_mujoco_writes_no_log_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, body: str) -> None:
    monkeypatch.chdir(tmp_path)
    model = tmp_path / "m.xml"
    model.write_text(f'<mujoco model="m"><worldbody><body name="a">{body}</body></worldbody></mujoco>')
    before = sorted(os.listdir(tmp_path))
    status, _ = validate_json(model)
    run("tree", str(model))
    assert sorted(os.listdir(tmp_path)) == before
    assert status in (0, 1, 2)


# ---- 6. the fuzz corpus ----------------------------------------------------------------------------

RUNNER = Path(__file__).parent / "hostile" / "runner.py"
ADDRESS_SPACE = 3 * 1024**3  # virtual: numpy, lxml and MuJoCo map far more than they touch
PEAK_RSS_KIB = 1024 * 1024


def test_fuzz_corpus(tmp_path: Path) -> None:
    """1,000+ seeded hostile cases in all five formats, in two child processes under RLIMIT_AS."""
    import subprocess
    import sys

    from .hostile.cases import make_cases

    cases = make_cases(tmp_path / "cases")
    assert len(cases) >= 1000
    batches = [cases[0::2], cases[1::2]]
    # The children import this checkout's modelkit, not whichever one the environment installed
    # (an editable install may point at another worktree).
    source = str(Path(__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [source, os.environ.get("PYTHONPATH")]))}
    children = [
        subprocess.Popen(
            [sys.executable, str(RUNNER), str(ADDRESS_SPACE), *map(str, batch)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=tmp_path,
            env=env,
        )
        for batch in batches
    ]
    records: list[dict[str, object]] = []
    peaks: list[int] = []
    for child in children:
        out, err = child.communicate(timeout=240)
        assert child.returncode == 0, err[-2000:]
        for line in out.splitlines():
            record = json.loads(line)
            if "peak_kib" in record:
                peaks.append(record["peak_kib"])
            else:
                records.append(record)
    assert len(records) == len(cases), "a batch stopped early"
    problems = []
    for record in records:
        if record["stray"]:
            problems.append((record["case"], "wrote", record["stray"]))
        if float(record["seconds"]) > 20:  # type: ignore[arg-type]
            problems.append((record["case"], "slow", record["seconds"]))
        for command in ("validate", "tree"):
            outcome = record[command]
            assert isinstance(outcome, dict)
            text = outcome["stdout"] + outcome["stderr"]
            if outcome["exception"] or "Traceback" in text:
                problems.append((record["case"], command, outcome["exception"]))
            elif outcome["exit"] not in (0, 1, 2):
                problems.append((record["case"], command, f"exit {outcome['exit']}"))
            elif outcome["exit"] and not re.search(r"\bMK\d{3}\b", text):
                problems.append((record["case"], command, "failed without a code: " + text[:200]))
    assert not problems, problems[:20]
    assert max(peaks) < PEAK_RSS_KIB, peaks


# ---- property-based: the number and rotation parsers ------------------------------------------------


NUMBER_TEXT = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers().map(str),
    st.text(alphabet="0123456789+-.eE_ xinfa", max_size=30),
    st.from_regex(r"-?\d{1,400}(\.\d*)?([eE][+-]?\d{1,5})?", fullmatch=True),
)


@given(NUMBER_TEXT)
def test_xml_number_parser_never_raises(text: str) -> None:
    from modelkit.xmlsource import parse_number, parse_numbers

    value = parse_number(text)
    assert value is None or isinstance(value, float)
    if value is not None:
        assert value == float(text.strip()) or (value != value)
    # A list is read item by item: doubling the text doubles the list (``text`` may itself hold several
    # numbers, e.g. "0 0"), and one item that is not a number refuses the whole list.
    items = text.split()
    single = parse_numbers(text)
    listed = parse_numbers(f"{text} {text}")
    if single is None:
        assert listed is None and any(parse_number(item) is None for item in items)
    else:
        assert listed is not None and len(single) == len(items) and len(listed) == 2 * len(items)
        assert [repr(v) for v in listed] == [repr(v) for v in single + single]
    if value is not None:
        assert listed is not None and [repr(v) for v in listed] == [repr(value)] * 2


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=0, max_size=6))
def test_body_rotation_parser_never_raises(numbers: list[float]) -> None:
    import numpy as np

    from modelkit.diagnostics import DiagnosticSink
    from modelkit.formats.body.values import rotation
    from modelkit.yamltree import parse_yaml

    sink = DiagnosticSink()
    # Infinity as a file would spell it for Choreonoid's strtod reading (1e400 overflows); YAML's
    # `.inf` is not a number to Choreonoid at all (the schema reports it, not this parser).
    words = (repr(n).replace("inf", "1e400") for n in numbers)
    doc = parse_yaml("r: [" + ", ".join(words) + "]\n", "t.body", sink)
    assert doc.root is not None
    rows = rotation(doc.root.get("r"), 1.0, sink)  # type: ignore[union-attr]
    matrix = None if rows is None else np.array(rows)  # the reader's rotations are tuples (rot3)
    if matrix is not None:
        assert np.all(np.isfinite(matrix))
        np.testing.assert_allclose(matrix @ matrix.T, np.eye(3), atol=1e-9)
    elif len(numbers) == 4:  # four numbers refused: it was said why
        assert sink.items


ANGLE = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6)


@given(ANGLE, ANGLE, ANGLE)
def test_rpy_rotation_is_orthonormal(roll: float, pitch: float, yaw: float) -> None:
    import numpy as np

    from modelkit.spatial import matrix_from_rpy

    matrix = matrix_from_rpy(roll, pitch, yaw)
    np.testing.assert_allclose(matrix @ matrix.T, np.eye(3), atol=1e-9)
    assert abs(np.linalg.det(matrix) - 1.0) < 1e-9
