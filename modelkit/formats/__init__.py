"""The format registry: which reader handles which file.

Readers are imported lazily so that `validate` and `tree` load only what the input needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.body.reader import BodyOptions, ReadResult


@dataclass(frozen=True)
class FormatInfo:
    name: str
    suffixes: tuple[str, ...]
    description: str


FORMATS: tuple[FormatInfo, ...] = (
    FormatInfo("body", (".body",), "Choreonoid body file (YAML), format 1.0 and 2.0"),
)


def detect_format(path: Path, explicit: str | None = None) -> str | None:
    if explicit:
        return explicit
    name = path.name.lower()
    for info in FORMATS:
        if any(name.endswith(s) for s in info.suffixes):
            return info.name
    return None


def read_model(
    path: Path, options: BodyOptions | None = None, fmt: str | None = None, display: str | None = None
) -> ReadResult:
    """Read any supported model file; an unknown format is a diagnostic, not an exception."""
    shown = display or str(path)
    kind = detect_format(path, fmt)
    if kind == "body":
        from modelkit.formats.body.reader import read_body

        return read_body(path, options, shown)
    sink = DiagnosticSink()
    known = ", ".join(s for info in FORMATS for s in info.suffixes)
    sink.emit(
        "MK001",
        f"cannot tell the format of this file (supported: {known}); use --input-format",
        SourceLocation(shown),
    )
    return ReadResult(None, sink.items)
