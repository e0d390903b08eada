"""What the broken-input corpora share: running `modelkit validate --format json` in-process and
comparing its findings with a case's one expected diagnostic."""

from __future__ import annotations

import json
import traceback
from dataclasses import dataclass
from typing import Any

from click.testing import Result

SEVERITIES = frozenset({"error", "warning", "info"})


@dataclass(frozen=True)
class Expected:
    """The one diagnostic a broken case must produce, and the exit code of `modelkit validate`."""

    file: str
    code: str
    severity: str
    line: int
    column: int
    message: str
    exit: int
    hint: str | None = None


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


def problems(expected: Expected, exit_code: int, diagnostics: list[dict[str, Any]]) -> list[str]:
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
        if found.get("file") != expected.file:
            out.append(f"file {found.get('file')!r}, expected {expected.file!r}")
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
