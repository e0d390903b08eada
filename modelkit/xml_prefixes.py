"""Reading XML whose namespace prefixes are used without being declared, as TinyXML2 reads it.

Robot files use namespaced custom elements and attributes without declaring the prefix: SDF's
``<gz:...>`` and ``<ignition:...>``, a URDF's Drake extensions (``drake:acceleration`` on ``<limit>``,
``<drake:collision_filter_group>``: the URDFs of airo-models). TinyXML2, the parser of urdfdom
(check_urdf, robot_state_publisher), libsdformat, MuJoCo and Drake, ignores namespaces and reads them;
lxml refuses the document. When that is the only problem, :func:`read_declaring_prefixes` declares the
undeclared prefixes on the root element (at the end of its start tag, so line numbers and the columns
of every other line are unchanged) and parses the document again. The elements are then a foreign
namespace's (``urn:modelkit:undeclared:PREFIX``), which every reader leaves alone as it leaves a
declared one's.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.textio import UnreadableFile, read_regular
from modelkit.xmlsource import XmlDocument, location_at, mask_markup, parse_xml_bytes, read_xml, tag_end

UNDECLARED_NAMESPACE = "urn:modelkit:undeclared:"
_PREFIXED = re.compile(r"(?:<|\s)([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*")
_DECLARED = re.compile(r"xmlns:([A-Za-z_][\w.-]*)\s*=")
_ENCODING = re.compile(r"<\?xml[^>]*encoding\s*=\s*[\"']([^\"']+)", re.IGNORECASE)


@dataclass
class Declared:
    """What :func:`read_declaring_prefixes` read: the document (None when unusable), the prefixes it had
    to declare (sorted; empty when the file declares its own), and where the first one is used."""

    doc: XmlDocument | None
    prefixes: list[str] = field(default_factory=list)
    first_use: SourceLocation | None = None


def read_declaring_prefixes(path: Path, display: str, sink: DiagnosticSink, max_bytes: int,
                            keep_blank_text: bool = True, urdfdom: bool = False) -> Declared:
    """Read and parse ``path``; when lxml refuses it only for undeclared namespace prefixes, parse it
    again with them declared. The caller says whether that deserves a note (URDF: yes). ``urdfdom``:
    read as urdfdom reads a URDF (``xmlsource.parse_xml_bytes``)."""
    first = DiagnosticSink()
    doc = read_xml(path, first, max_bytes, display, keep_blank_text, urdfdom=urdfdom)
    if doc is not None or not any(d.code == "MK020" and "Namespace prefix" in d.message for d in first.items):
        sink.extend(first.items)
        return Declared(doc)
    try:
        text = read_regular(path, max_bytes).decode("utf-8")
    except (UnreadableFile, UnicodeDecodeError):
        sink.extend(first.items)
        return Declared(None)
    declared = declare_prefixes(text)
    if declared is None:
        sink.extend(first.items)
        return Declared(None)
    repaired, prefixes, offset = declared
    second = DiagnosticSink()
    doc = parse_xml_bytes(repaired.encode("utf-8"), display, second, path, keep_blank_text, urdfdom=urdfdom)
    sink.extend(second.items)
    return Declared(doc, prefixes, location_at(text, display, offset) if doc is not None else None)


def declare_prefixes(text: str) -> tuple[str, list[str], int] | None:
    """``text`` with every undeclared namespace prefix declared on the root element, the prefixes, and
    the offset of the first use of one (None when there is nothing to declare or no root to hold it)."""
    encoding = _ENCODING.search(text)
    if encoding and encoding.group(1).lower().replace("_", "-") not in ("utf-8", "utf8"):
        return None
    masked = mask_markup(text)
    start = masked.find("<")
    while start >= 0 and masked[start + 1 : start + 2] in ("!", "?", ""):
        start = masked.find("<", start + 1)
    if start < 0:
        return None
    end = tag_end(masked, start)
    if end >= len(masked):
        return None
    own = set(_DECLARED.findall(masked)) | {"xml", "xmlns", "http", "https"}
    uses = [m for m in _PREFIXED.finditer(masked) if m.group(1) not in own]
    if not uses:
        return None
    prefixes = sorted({m.group(1) for m in uses})
    insert = "".join(f' xmlns:{p}="{UNDECLARED_NAMESPACE}{p}"' for p in prefixes)
    at = end - 1 if masked[end - 1] == "/" else end
    return text[:at] + insert + text[at:], prefixes, uses[0].start(1)
