"""Conversion notes: what a writer approximated, renamed, dropped or synthesised.

A note is data with a stable code from :mod:`modelkit.codes` (MK8xx), like a diagnostic, plus the
target element it concerns. Writers add notes to a :class:`NoteSink`; the CLI prints them and
``--report FILE.json`` saves them.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from modelkit.codes import CODES
from modelkit.diagnostics import Severity, SourceLocation


@dataclass(frozen=True)
class ConversionNote:
    code: str
    severity: Severity
    message: str
    source: SourceLocation | None = None  # where the converted thing came from
    target: str | None = None  # the element written for it (``link[wheel]/collision[0]``, a file)
    renamed: tuple[str, str, str] | None = None  # MK800: (kind, source name, written name)

    def to_json(self) -> dict[str, object]:
        loc = self.source
        return {
            "code": self.code,
            "name": CODES[self.code].name,
            "severity": self.severity.value,
            "message": self.message,
            "file": loc.file if loc else None,
            "line": loc.line if loc and loc.line else None,
            "column": loc.col if loc and loc.col else None,
            "target": self.target,
            **({"renamed": dict(zip(("kind", "from", "to"), self.renamed, strict=True))}
               if self.renamed else {}),
        }

    def render(self) -> str:
        where = f"{self.source}: " if self.source else ""
        target = f" [{self.target}]" if self.target else ""
        return f"{where}{self.severity.value} {self.code} {self.message}{target}"


@dataclass
class NoteSink:
    """Collects a writer's notes, once each, in the order they were made."""

    items: list[ConversionNote] = field(default_factory=list)
    _seen: set[tuple[object, ...]] = field(default_factory=set)

    def note(
        self,
        code: str,
        message: str,
        source: SourceLocation | None = None,
        target: str | None = None,
        severity: Severity | None = None,
    ) -> None:
        entry = CODES[code]
        item = ConversionNote(code, severity or Severity(entry.severity), message, source, target)
        key = (item.code, item.message, item.source, item.target)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(item)

    def rename(self, kind: str, old: str, new: str, why: str, source: SourceLocation | None = None,
               target: str | None = None) -> None:
        """Record that ``kind`` ("link", "joint", "mesh" ...) ``old`` is written as ``new`` (MK800)."""
        item = ConversionNote("MK800", Severity(CODES["MK800"].severity),
                              f'{kind} "{old}" is written as "{new}": {why}', source,
                              target or f"{kind}[{new}]", (kind, old, new))
        key = (item.code, item.message, item.source, item.target)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(item)

    def extend(self, notes: Iterable[ConversionNote]) -> None:
        for n in notes:
            key = (n.code, n.message, n.source, n.target)
            if key not in self._seen:
                self._seen.add(key)
                self.items.append(n)


def renames(notes: Iterable[ConversionNote], kind: str = "link") -> dict[str, str]:
    """Source name → written name for one kind of element, from the MK800 notes of a conversion."""
    out: dict[str, str] = {}
    for n in notes:
        if n.renamed is not None and n.renamed[0] == kind:
            out.setdefault(n.renamed[1], n.renamed[2])
    return out


def note_matches(notes: Iterable[ConversionNote], code: str, pattern: re.Pattern[str]) -> list[re.Match[str]]:
    """The matches of ``pattern`` at the start of the messages of the notes with ``code``: what a writer
    said in words another module reads back (verify reads the MK813 chains a writer made)."""
    return [found for note in notes if note.code == code for found in [pattern.match(note.message)] if found]
