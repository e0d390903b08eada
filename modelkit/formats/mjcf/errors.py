"""MuJoCo's error messages → a diagnostic at the best source location modelkit can find.

MuJoCo raises ``ValueError`` with texts such as::

    XML Error: Schema violation: unrecognized attribute: 'foo'
    Element 'joint', line 4

    Error: mass and inertia of moving bodies must be larger than mjMINVAL
    Element name 'a', id 1, line 3

    Error: Error opening file 'missing.stl'

The line is that of the element's start tag in the file that holds it (0 when MuJoCo lost track,
as in included files). modelkit looks the element up in its own parse to add the column and, for
an attribute error, the attribute's position.
"""

from __future__ import annotations

import re

from modelkit.diagnostics import SourceLocation
from modelkit.formats.mjcf.source import Placed, SourceIndex

_LINE = re.compile(r"\bline (\d+)")
_ELEMENT_NAME = re.compile(r"Element name '([^']*)'")
_ELEMENT_TAG = re.compile(r"Element '([^']*)'")
_ATTRIBUTE = re.compile(r"(?:unrecognized|invalid|repeated) attribute: '([^']*)'")
_FILE = re.compile(r"(?:opening file|file|resource)[^']*'([^']+)'")
_PREFIX = re.compile(r"^(?:XML Error|Error):\s*(?:Error:\s*)?")


def error_text(exc: BaseException) -> str:
    """MuJoCo's message on one line, without its ``Error:`` prefixes."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    if not lines:
        return type(exc).__name__
    head = _PREFIX.sub("", lines[0]).strip() or lines[0]
    tail = "; ".join(lines[1:])
    return f"{head} ({tail})" if tail else head


def error_location(message: str, index: SourceIndex) -> SourceLocation:
    """Where the thing MuJoCo complains about is written, as precisely as can be told."""
    line_match = _LINE.search(message)
    line = int(line_match.group(1)) if line_match else 0
    name_match, tag_match = _ELEMENT_NAME.search(message), _ELEMENT_TAG.search(message)
    name = name_match.group(1) if name_match else None
    tag = tag_match.group(1) if tag_match else None
    attr_match = _ATTRIBUTE.search(message)
    attribute = attr_match.group(1) if attr_match else None
    file_match = _FILE.search(message)
    if file_match and not (name or tag):
        placed = _by_file(index, file_match.group(1))
        if placed is not None:
            return placed.loc("file")
    elements = list(index.iter_all())
    if line > 0:
        on_line = [p for p in elements if p.loc().line == line]
        chosen = _best(on_line, name, tag, attribute, index, loose=True)
        if chosen is not None:
            return chosen.loc(attribute)
        return SourceLocation(index.main.display, line, 1)
    chosen = _best(elements, name, tag, attribute, index, loose=False)
    return chosen.loc(attribute) if chosen is not None else index.top().loc()


def _best(
    candidates: list[Placed],
    name: str | None,
    tag: str | None,
    attribute: str | None,
    index: SourceIndex,
    loose: bool,
) -> Placed | None:
    """The candidate that matches MuJoCo's description best (main document first).

    A name may be the element's own (``Element name 'b'``) or one it refers to (a tendon's
    ``<joint joint="b">``): on the named line both count; elsewhere only the element's own.
    """
    pool = sorted(candidates, key=lambda p: p.doc is not index.main)
    if tag is not None:
        pool = [p for p in pool if p.tag == tag]
    if attribute is not None:
        pool = [p for p in pool if p.el.get(attribute) is not None] or pool
    if name is not None:
        own = [p for p in pool if p.el.get("name") == name]
        refers = [p for p in pool if name in p.el.attrib.values()] if loose else []
        pool = own or refers or (pool if loose else [])
    return pool[0] if pool else None


def _by_file(index: SourceIndex, written: str) -> Placed | None:
    """The asset element (``<mesh>``, ``<texture>``, ``<hfield>``...) whose ``file`` is ``written``."""
    tail = written.replace("\\", "/").split("/")[-1]
    best: Placed | None = None
    for placed in index.iter_all():
        value = placed.el.get("file")
        if value is None:
            continue
        if value == written or written.endswith(value):
            return placed
        if best is None and value.replace("\\", "/").split("/")[-1] == tail:
            best = placed
    return best
