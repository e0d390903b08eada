"""Diagnostics: what validation and reading report, and how it is rendered.

A :class:`Diagnostic` is plain data (code, severity, message, location, hint). The meaning of each
code lives in :mod:`modelkit.codes`; renderers here only format records.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import StrEnum

from modelkit.codes import CODES


class Severity(StrEnum):
    ERROR = "error"
    WARNING = "warning"
    INFO = "info"

    @property
    def rank(self) -> int:
        return {"error": 2, "warning": 1, "info": 0}[self.value]


@dataclass(frozen=True, order=True)
class SourceLocation:
    """A place in a source file; line and column are 1-based (0 when unknown)."""

    file: str
    line: int = 0
    col: int = 0

    def __str__(self) -> str:
        if self.line <= 0:
            return self.file
        return f"{self.file}:{self.line}:{self.col}"

    def __deepcopy__(self, memo: dict[int, object]) -> SourceLocation:
        """A location is a value that never changes: a deep copy of a model shares it (``convert`` copies
        the model it writes; a 10,000-link chain holds 150,000 locations)."""
        return self


@dataclass(frozen=True)
class Diagnostic:
    code: str
    severity: Severity
    message: str
    location: SourceLocation | None = None
    hint: str | None = None

    def sort_key(self) -> tuple[str, int, int, str, str]:
        loc = self.location
        return (
            loc.file if loc else "",
            loc.line if loc else 0,
            loc.col if loc else 0,
            self.code,
            self.message,
        )

    def to_json(self) -> dict[str, object]:
        loc = self.location
        return {
            "file": loc.file if loc else None,
            "line": loc.line if loc else None,
            "column": loc.col if loc else None,
            "severity": self.severity.value,
            "code": self.code,
            "name": CODES[self.code].name,
            "message": self.message,
            "hint": self.hint,
        }


def diag(
    code: str,
    message: str,
    location: SourceLocation | None = None,
    hint: str | None = None,
    severity: Severity | None = None,
) -> Diagnostic:
    """Build a diagnostic whose severity defaults to the one the code catalogue gives."""
    entry = CODES[code]
    return Diagnostic(code, severity or Severity(entry.severity), message, location, hint)


@dataclass
class DiagnosticSink:
    """Collects diagnostics while a file is read; de-duplicates identical records."""

    items: list[Diagnostic] = field(default_factory=list)
    _seen: set[tuple[object, ...]] = field(default_factory=set)

    def add(self, d: Diagnostic) -> None:
        key = (d.code, d.location, d.message)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(d)

    def emit(
        self,
        code: str,
        message: str,
        location: SourceLocation | None = None,
        hint: str | None = None,
        severity: Severity | None = None,
    ) -> None:
        self.add(diag(code, message, location, hint, severity))

    def extend(self, ds: Iterable[Diagnostic]) -> None:
        for d in ds:
            self.add(d)


def closest(word: str, candidates: Iterable[str]) -> str | None:
    """The candidate most like ``word`` (difflib's ratio, at least 0.6), or None."""
    import difflib

    match = difflib.get_close_matches(word, list(candidates), n=1)
    return match[0] if match else None


def did_you_mean(word: str, candidates: Iterable[str]) -> str | None:
    """The hint ``did you mean "X"?`` when ``word`` is close to one of ``candidates``; else None."""
    match = closest(word, candidates)
    return None if match is None else f'did you mean "{match}"?'



def sorted_diagnostics(ds: Iterable[Diagnostic]) -> list[Diagnostic]:
    return sorted(ds, key=Diagnostic.sort_key)


def render_text(d: Diagnostic) -> str:
    where = str(d.location) if d.location else "<unknown>"
    text = f"{where}: {d.severity.value} {d.code} {d.message}"
    if d.hint:
        text += f" (hint: {d.hint})"
    return text


def _gh_escape(text: str, prop: bool = False) -> str:
    text = text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    if prop:
        text = text.replace(":", "%3A").replace(",", "%2C")
    return text


def render_github(d: Diagnostic) -> str:
    """One GitHub Actions workflow command (an annotation on the pull request)."""
    level = {"error": "error", "warning": "warning", "info": "notice"}[d.severity.value]
    props = []
    if d.location:
        props.append(f"file={_gh_escape(d.location.file, True)}")
        if d.location.line > 0:
            props.append(f"line={d.location.line}")
            props.append(f"col={d.location.col}")
    props.append(f"title={d.code}")
    message = d.message + (f" (hint: {d.hint})" if d.hint else "")
    return f"::{level} {','.join(props)}::{_gh_escape(message)}"


def render_json(ds: Iterable[Diagnostic], files: Iterable[str]) -> str:
    items = [d.to_json() for d in ds]
    summary = {
        "errors": sum(1 for i in items if i["severity"] == "error"),
        "warnings": sum(1 for i in items if i["severity"] == "warning"),
        "infos": sum(1 for i in items if i["severity"] == "info"),
    }
    return json.dumps(
        {"files": list(files), "diagnostics": items, "summary": summary}, indent=2, sort_keys=False
    )
