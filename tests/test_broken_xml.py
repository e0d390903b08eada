"""Corpora of deliberately broken URDF, xacro and SDF files, each with one precise diagnostic.

Each folder ``tests/broken_<format>/`` holds case files with exactly one fault on top of a clean base in
``support/`` and an ``EXPECTED.yaml`` with the same keys as ``tests/broken_body/EXPECTED.yaml``: the
diagnostic the fault must produce (code, severity, line, column, message fragment) and the exit code of
``modelkit validate``. Every case runs through the CLI in-process with ``--format json``; none may
raise.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from modelkit.cli import main

from .broken_support import Case, crash_text, entry_problems, json_diagnostics, load_cases, problems, show

HERE = Path(__file__).resolve().parent
FOLDERS = {"urdf": HERE / "broken_urdf", "xacro": HERE / "broken_xacro", "sdf": HERE / "broken_sdf"}
SUFFIXES = {"urdf": (".urdf",), "xacro": (".xacro",), "sdf": (".sdf", ".world")}


CASES = [case for folder in FOLDERS.values() for case in load_cases(folder)]


def _invoke(path: Path, *args: str) -> Result:
    return CliRunner().invoke(main, ["validate", "--format", "json", *args, str(path)], catch_exceptions=True)


# ---- the corpora are consistent ----------------------------------------------------------------


def test_corpus_size() -> None:
    """The issue asks for at least 30 cases over URDF, xacro and SDF."""
    assert len(CASES) >= 30, len(CASES)


def test_expected_entries_are_well_formed() -> None:

    for case in CASES:
        assert case.name.endswith(SUFFIXES[case.tag]), case.ident
        assert entry_problems(case) == []


@pytest.mark.parametrize("folder", sorted(FOLDERS))
def test_every_case_file_is_listed_and_vice_versa(folder: str) -> None:
    where = FOLDERS[folder]
    if not where.is_dir():
        pytest.skip(f"no {where.name} corpus yet")
    on_disk = {p.name for p in where.iterdir() if p.name.endswith(SUFFIXES[folder])}
    cases = [c for c in CASES if c.tag == folder]
    listed = {c.name for c in cases if not c.absent}
    absent = {c.name for c in cases if c.absent}
    assert sorted(on_disk - listed - absent) == [], "case files missing from EXPECTED.yaml"
    assert sorted(listed - on_disk) == [], "EXPECTED.yaml entries without a case file"
    assert sorted(absent & on_disk) == [], "entries marked `absent: true` must not exist"


@pytest.mark.parametrize("folder", sorted(FOLDERS))
def test_clean_bases_have_no_findings(folder: str) -> None:
    support = FOLDERS[folder] / "support"
    found = support.glob("clean*") if support.is_dir() else iter(())
    bases = sorted(p for p in found if p.name.endswith(SUFFIXES[folder]))
    if not bases:
        pytest.skip(f"no clean base for {folder} yet")
    for base in bases:
        result = _invoke(base, "--strict")
        assert crash_text(result) is None, crash_text(result)
        diagnostics = json_diagnostics(result)
        assert diagnostics == [], f"{base.name} must validate without findings:\n" + show(diagnostics)
        assert result.exit_code == 0


# ---- one precise diagnostic per case -----------------------------------------------------------


@pytest.mark.parametrize("case", CASES, ids=[c.ident for c in CASES])
def test_broken_case(case: Case) -> None:
    result = _invoke(case.path, *case.args)
    crash = crash_text(result)
    assert crash is None, f"{case.ident}: the CLI raised instead of reporting:\n{crash}"
    try:
        diagnostics = json_diagnostics(result)
    except (ValueError, KeyError) as exc:
        pytest.fail(f"{case.ident}: --format json printed no diagnostics document ({exc}):\n{result.output}")

    found = problems(case, result.exit_code, diagnostics)
    wanted = f"{case.severity} {case.code} at {case.line}:{case.column}"
    assert not found, (f"{case.ident}: expected {wanted}\n  - " + "\n  - ".join(found)
                          + "\nall diagnostics:\n" + show(diagnostics))
