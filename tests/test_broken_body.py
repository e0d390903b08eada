"""A corpus of deliberately broken Choreonoid `.body` files, each with one precise diagnostic.

Every ``tests/broken_body/*.body`` file holds exactly one fault on top of the clean pendulum in
``tests/broken_body/support/clean_pendulum.body``; ``tests/broken_body/EXPECTED.yaml`` says which
diagnostic the fault must produce (code, severity, line, column, message fragment) and which exit code
``modelkit validate`` must return. Each case runs through the CLI in-process with ``--format json``.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from modelkit.cli import main

from .broken_support import Case, crash_text, entry_problems, json_diagnostics, load_cases, problems, show

HERE = Path(__file__).resolve().parent
CORPUS = HERE / "broken_body"
CLEAN_BASE = CORPUS / "support" / "clean_pendulum.body"

# A hang guard, not a timing assertion: an in-process run that takes longer than this is a hang.
IN_PROCESS_LIMIT_S = 60
# The alias-bomb and deep-nesting cases must be refused quickly; a subprocess is killed after this.
SUBPROCESS_LIMIT_S = 30



CASES = load_cases(CORPUS)


@contextmanager
def _hang_guard(seconds: int) -> Iterator[None]:
    """Turn a hang into a test failure (SIGALRM, so only in the main thread; elsewhere no guard)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def expired(signum: int, frame: object) -> None:
        raise TimeoutError(f"still running after {seconds} s: the tool hangs on this input")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _invoke(path: Path, *args: str) -> Result:
    runner = CliRunner()
    with _hang_guard(IN_PROCESS_LIMIT_S):
        return runner.invoke(main, ["validate", "--format", "json", *args, str(path)], catch_exceptions=True)


# ---- the corpus is consistent ------------------------------------------------------------------


def test_expected_entries_are_well_formed() -> None:
    assert len(CASES) >= 40
    for case in CASES:
        assert case.name.endswith(".body"), case.name
        assert entry_problems(case) == []


def test_every_case_file_is_listed_and_vice_versa() -> None:
    on_disk = {p.name for p in CORPUS.glob("*.body")}
    listed = {c.name for c in CASES if not c.absent}
    absent = {c.name for c in CASES if c.absent}
    assert sorted(on_disk - listed - absent) == [], "case files missing from EXPECTED.yaml"
    assert sorted(listed - on_disk) == [], "EXPECTED.yaml entries without a case file"
    assert sorted(absent & on_disk) == [], "entries marked `absent: true` must not exist"


def test_clean_base_has_no_findings() -> None:
    from modelkit.api import validate

    result = _invoke(CLEAN_BASE, "--strict")
    assert crash_text(result) is None, crash_text(result)
    diagnostics = json_diagnostics(result)
    assert diagnostics == [], "the clean base must validate without findings:\n" + show(diagnostics)
    assert result.exit_code == 0
    library = validate(CLEAN_BASE)
    assert library.robot is not None
    assert [d for d in library.diagnostics if d.severity.value != "info"] == []
    assert [link.name for link in library.robot.links] == ["base", "arm"]


# ---- one precise diagnostic per case -----------------------------------------------------------


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_broken_body(case: Case) -> None:
    result = _invoke(case.path, *case.args)
    crash = crash_text(result)
    assert crash is None, f"{case.name}: the CLI raised instead of reporting:\n{crash}"
    try:
        diagnostics = json_diagnostics(result)
    except (ValueError, KeyError) as exc:
        pytest.fail(f"{case.name}: --format json printed no diagnostics document ({exc}):\n{result.output}")

    found = problems(case, result.exit_code, diagnostics)
    wanted = f"{case.severity} {case.code} at {case.line}:{case.column}"
    assert not found, (f"{case.name}: expected {wanted}\n  - " + "\n  - ".join(found)
                          + "\nall diagnostics:\n" + show(diagnostics))


# ---- hostile YAML is refused quickly ---------------------------------------------------------------


HOSTILE = [c for c in CASES if c.hang_guard]


@pytest.mark.parametrize("case", HOSTILE, ids=[c.name for c in HOSTILE])
def test_hostile_yaml_is_refused_quickly(case: Case) -> None:
    command = [sys.executable, "-m", "modelkit.cli", "validate", "--format", "json", *case.args,
               str(case.path)]
    started = time.monotonic()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=SUBPROCESS_LIMIT_S,
                              check=False)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{case.name}: still running after {SUBPROCESS_LIMIT_S} s (the document must be refused, "
                    "not expanded)")
    elapsed = time.monotonic() - started
    assert "Traceback" not in done.stderr, done.stderr
    assert done.returncode == case.exit, f"exit {done.returncode} after {elapsed:.1f} s\n{done.stderr}"
    codes = [d["code"] for d in json.loads(done.stdout)["diagnostics"]]
    assert case.code in codes, codes
