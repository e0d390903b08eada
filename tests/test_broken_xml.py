"""Corpora of deliberately broken URDF, xacro and SDF files, each with one precise diagnostic.

Each folder ``tests/broken_<format>/`` holds case files with exactly one fault on top of a clean base in
``support/`` and an ``EXPECTED.yaml`` with the same keys as ``tests/broken_body/EXPECTED.yaml``: the
diagnostic the fault must produce (code, severity, line, column, message fragment) and the exit code of
``modelkit validate``. Every case runs through the CLI in-process with ``--format json``; none may
raise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import yaml
from click.testing import CliRunner, Result

from modelkit.cli import main

from .broken_support import SEVERITIES, Expected, crash_text, json_diagnostics, problems, show

HERE = Path(__file__).resolve().parent
FOLDERS = {"urdf": HERE / "broken_urdf", "xacro": HERE / "broken_xacro", "sdf": HERE / "broken_sdf"}
SUFFIXES = {"urdf": (".urdf",), "xacro": (".xacro",), "sdf": (".sdf", ".world")}
KNOWN_KEYS = {"code", "severity", "line", "column", "message", "exit", "hint", "args", "absent", "file"}


@dataclass(frozen=True)
class Case:
    folder: str
    name: str
    code: str
    severity: str
    line: int
    column: int
    message: str
    exit: int
    hint: str | None = None
    args: tuple[str, ...] = ()
    absent: bool = False
    file: str | None = None  # the file the diagnostic points at, when not the case file (an include)
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def path(self) -> Path:
        return FOLDERS[self.folder] / self.name

    @property
    def ident(self) -> str:
        return f"{self.folder}/{self.name}"


def _load_cases() -> list[Case]:
    cases: list[Case] = []
    for folder, where in FOLDERS.items():
        expected = where / "EXPECTED.yaml"
        if not expected.is_file():
            continue
        raw = yaml.safe_load(expected.read_text(encoding="utf-8")) or {}
        assert isinstance(raw, dict), f"{expected}: must map case file names to expectations"
        for name, entry in raw.items():
            assert isinstance(entry, dict), f"{folder}/{name}: the expectation must be a mapping"
            cases.append(Case(
                folder=folder,
                name=str(name),
                code=str(entry["code"]),
                severity=str(entry["severity"]),
                line=int(entry["line"]),
                column=int(entry["column"]),
                message=str(entry["message"]),
                exit=int(entry["exit"]),
                hint=None if entry.get("hint") is None else str(entry["hint"]),
                args=tuple(str(a) for a in entry.get("args", ())),
                absent=bool(entry.get("absent", False)),
                file=None if entry.get("file") is None else str(entry["file"]),
                extra={k: v for k, v in entry.items() if k not in KNOWN_KEYS},
            ))
    return cases


CASES = _load_cases()


def _invoke(path: Path, *args: str) -> Result:
    return CliRunner().invoke(main, ["validate", "--format", "json", *args, str(path)], catch_exceptions=True)


# ---- the corpora are consistent ----------------------------------------------------------------


def test_corpus_size() -> None:
    """The issue asks for at least 30 cases over URDF, xacro and SDF."""
    assert len(CASES) >= 30, len(CASES)


def test_expected_entries_are_well_formed() -> None:
    from modelkit.codes import CODES

    for case in CASES:
        assert case.name.endswith(SUFFIXES[case.folder]), case.ident
        assert case.code in CODES, f"{case.ident}: {case.code} is not in modelkit/codes.py"
        assert case.severity in SEVERITIES, f"{case.ident}: severity {case.severity!r}"
        assert case.exit in (0, 1, 2), f"{case.ident}: exit {case.exit}"
        assert case.message, f"{case.ident}: empty message fragment"
        assert not case.extra, f"{case.ident}: unknown expectation keys {sorted(case.extra)}"
        if case.exit != 2:
            want = 1 if case.severity == "error" else 0
            assert case.exit == want, f"{case.ident}: a {case.severity} case exits {want}, not {case.exit}"


@pytest.mark.parametrize("folder", sorted(FOLDERS))
def test_every_case_file_is_listed_and_vice_versa(folder: str) -> None:
    where = FOLDERS[folder]
    if not where.is_dir():
        pytest.skip(f"no {where.name} corpus yet")
    on_disk = {p.name for p in where.iterdir() if p.name.endswith(SUFFIXES[folder])}
    cases = [c for c in CASES if c.folder == folder]
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

    want_file = str(case.path if case.file is None else FOLDERS[case.folder] / case.file)
    expected = Expected(want_file, case.code, case.severity, case.line, case.column, case.message, case.exit,
                        case.hint)
    found = problems(expected, result.exit_code, diagnostics)
    wanted = f"{case.severity} {case.code} at {case.line}:{case.column}"
    assert not found, (f"{case.ident}: expected {wanted}\n  - " + "\n  - ".join(found)
                          + "\nall diagnostics:\n" + show(diagnostics))
