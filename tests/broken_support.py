"""What the broken-input corpora share: running `modelkit validate --format json` in-process and
comparing its findings with a case's one expected diagnostic."""

from __future__ import annotations

import json
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from click.testing import Result

SEVERITIES = frozenset({"error", "warning", "info"})


KNOWN_KEYS = frozenset(
    {"code", "severity", "line", "column", "message", "exit", "hint", "args", "absent", "hang_guard", "file"}
)


@dataclass(frozen=True)
class Case:
    """One broken file of a corpus folder and the one diagnostic it must produce.

    The keys of an ``EXPECTED.yaml`` entry are described in ``tests/broken_body/EXPECTED.yaml``;
    ``file`` names the file the diagnostic points at when it is not the case file (an include).
    """

    folder: Path
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
    hang_guard: bool = False
    file: str | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def path(self) -> Path:
        return self.folder / self.name

    @property
    def tag(self) -> str:
        """The format the folder holds: ``broken_urdf`` -> ``urdf``."""
        return self.folder.name.removeprefix("broken_")

    @property
    def ident(self) -> str:
        return f"{self.tag}/{self.name}"

    @property
    def diagnostic_file(self) -> str:
        return str(self.path if self.file is None else self.folder / self.file)


def load_cases(folder: Path) -> list[Case]:
    """The cases listed in ``folder/EXPECTED.yaml`` (none when the file does not exist)."""
    expected = folder / "EXPECTED.yaml"
    if not expected.is_file():
        return []
    raw = yaml.safe_load(expected.read_text(encoding="utf-8")) or {}
    assert isinstance(raw, dict), f"{expected}: must map case file names to expectations"
    cases = []
    for name, entry in raw.items():
        assert isinstance(entry, dict), f"{folder.name}/{name}: the expectation must be a mapping"
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
            hang_guard=bool(entry.get("hang_guard", False)),
            file=None if entry.get("file") is None else str(entry["file"]),
            extra={k: v for k, v in entry.items() if k not in KNOWN_KEYS},
        ))
    return cases


def entry_problems(case: Case) -> list[str]:
    """What is wrong with an expectation itself (not with the tool's output)."""
    from modelkit.codes import CODES

    out = []
    if case.code not in CODES:
        out.append(f"{case.ident}: {case.code} is not in modelkit/codes.py")
    if case.severity not in SEVERITIES:
        out.append(f"{case.ident}: severity {case.severity!r}")
    if case.exit not in (0, 1, 2):
        out.append(f"{case.ident}: exit {case.exit}")
    if not case.message:
        out.append(f"{case.ident}: empty message fragment")
    if case.extra:
        out.append(f"{case.ident}: unknown expectation keys {sorted(case.extra)}")
    if case.exit != 2 and case.exit != (1 if case.severity == "error" else 0):
        out.append(f"{case.ident}: a {case.severity} case exits {1 if case.severity == 'error' else 0}")
    return out


def crash_text(result: Result) -> str | None:
    """The traceback when the CLI raised anything other than SystemExit."""
    if result.exception is None or isinstance(result.exception, SystemExit):
        return None
    info = result.exc_info
    if info is None:
        return repr(result.exception)
    return "".join(traceback.format_exception(*info))


def json_diagnostics(result: Result) -> list[dict[str, Any]]:
    diagnostics = json.loads(result.stdout)["diagnostics"]
    assert isinstance(diagnostics, list)
    return diagnostics


def show(diagnostics: list[dict[str, Any]]) -> str:
    if not diagnostics:
        return "  (no diagnostics)"
    return "\n".join(
        f"  {d.get('file')}:{d.get('line')}:{d.get('column')} {d.get('severity')} {d.get('code')} "
        f"{d.get('message')}" + (f" (hint: {d['hint']})" if d.get("hint") else "")
        for d in diagnostics
    )


def problems(expected: Case, exit_code: int, diagnostics: list[dict[str, Any]]) -> list[str]:
    """Every way the run differs from the expectation (an empty list when it matches)."""
    out: list[str] = []
    if exit_code != expected.exit:
        out.append(f"exit code {exit_code}, expected {expected.exit}")
    same_code = [d for d in diagnostics if d.get("code") == expected.code]
    if len(same_code) != 1:
        out.append(f"{len(same_code)} diagnostic(s) with code {expected.code}, expected exactly 1")
    if same_code:
        where_wanted = (expected.line, expected.column)
        found = min(same_code, key=lambda d: (d.get("line"), d.get("column")) != where_wanted)
        if found.get("file") != expected.diagnostic_file:
            out.append(f"file {found.get('file')!r}, expected {expected.diagnostic_file!r}")
        if (found.get("line"), found.get("column")) != (expected.line, expected.column):
            where = f"{found.get('line')}:{found.get('column')}"
            out.append(f"position {where}, expected {expected.line}:{expected.column}")
        if found.get("severity") != expected.severity:
            out.append(f"severity {found.get('severity')}, expected {expected.severity}")
        message = str(found.get("message", ""))
        if expected.message.lower() not in message.lower():
            out.append(f"message {message!r} lacks {expected.message!r}")
        if expected.code in message:
            out.append(f"message {message!r} repeats its own code (the renderers already print it)")
        if expected.hint is not None and expected.hint.lower() not in str(found.get("hint") or "").lower():
            out.append(f"hint {found.get('hint')!r} lacks {expected.hint!r}")
    others = [d for d in diagnostics if d.get("severity") == "error" and d.get("code") != expected.code]
    if others:
        out.append("other error-level diagnostics: " + ", ".join(
            f"{d.get('code')} at {d.get('line')}:{d.get('column')}" for d in others))
    return out
