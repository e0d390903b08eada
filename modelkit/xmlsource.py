"""Safe XML reading with exact source positions, shared by the URDF, SDF and MJCF readers.

lxml parses; this module adds what the readers need on top of it:

* refusal of entity declarations (``<!ENTITY>``: billion laughs, external files) and of network
  access, before lxml sees the document;
* a line **and column** for every element and attribute. lxml records only the line where a start
  tag *ends*; we scan the text once for start tags, which appear in the same order as the elements
  in document order, and pair them up;
* number and vector parsing with the strictness of urdfdom (no ``1_000``, no ``inf`` words, no
  trailing text).
"""

from __future__ import annotations

import dataclasses
import re
from array import array
from bisect import bisect_right
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation
from modelkit.textio import DEFAULT_MAX_BYTES, decode_text, read_bytes, read_head

_SKIPPED = re.compile(
    r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<!DOCTYPE(?:[^\[>]|\[.*?\])*>", re.DOTALL | re.IGNORECASE
)
_START_TAG = re.compile(r"<([^\s/>!?][^\s/>]*)")
# One attribute of a start tag: its name as written and its quoted value (skipped whole, so that
# text inside a value is never taken for another attribute).
_ATTRIBUTE = re.compile(r"""([^\s=/>"']+)\s*=\s*(?:"[^"]*"|'[^']*')""")
_ENTITY_DECL = re.compile(r"<!ENTITY", re.IGNORECASE)
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
# Blank-separated numbers, whole: ``\s`` is exactly the whitespace ``str.split()`` splits on.
_NUMBERS = re.compile(rf"\s*(?:{_NUMBER.pattern}(?:\s+{_NUMBER.pattern})*)?\s*")


def mask_markup(text: str) -> str:
    """``text`` with comments, CDATA sections, processing instructions and the DOCTYPE blanked out
    (replaced by as many spaces), so that a ``<`` in them is not taken for a tag; offsets are kept."""
    return _SKIPPED.sub(lambda m: " " * len(m.group(0)), text)


def bare_copy(element: Element) -> Element:
    """A detached copy of ``element`` without layout whitespace (blank texts and every tail), for a
    writer that keeps a source's element as data and indents it anew."""
    copy = etree.fromstring(etree.tostring(element, with_tail=False))
    for part in copy.iter():
        if part.text is not None and not part.text.strip():
            part.text = None
        part.tail = None
    return copy


def location_at(text: str, display: str, offset: int) -> SourceLocation:
    """The 1-based line and column of ``offset`` in ``text``."""
    line = text.count("\n", 0, offset) + 1
    col = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return SourceLocation(display, line, col)


def parse_number(text: str | None) -> float | None:
    """A decimal number as urdfdom reads one (surrounding blanks allowed); None if it is not one."""
    if text is None:
        return None
    stripped = text.strip()
    if not _NUMBER.fullmatch(stripped):
        return None
    return float(stripped)


def parse_numbers(text: str | None) -> list[float] | None:
    """Blank-separated numbers; None when any item is not a number."""
    if text is None or _NUMBERS.fullmatch(text) is None:  # one match for the whole list
        return None
    return [float(item) for item in text.split()]


@dataclass
class XmlDocument:
    """A parsed XML file and the positions of its elements."""

    root: Element
    display: str
    text: str
    path: Path | None = None
    # Where elements really come from when this document was generated (xacro output): element →
    # location in the source file. Consulted before the document's own positions.
    origins: dict[Element, SourceLocation] = field(default_factory=dict)
    _starts: dict[Element, int] = field(default_factory=dict, repr=False)
    _line_offsets: array[int] = field(default_factory=lambda: array("q", [0]), repr=False)
    # Offsets of each element's attributes, found on the first look-up of one (an element with 100,000
    # attributes, each diagnosed, is scanned once, not once per attribute).
    _attribute_offsets: dict[Element, dict[str, int]] = field(default_factory=dict, repr=False)

    def _position(self, offset: int) -> tuple[int, int]:
        line = bisect_right(self._line_offsets, offset)
        return line, offset - self._line_offsets[line - 1] + 1

    def loc(self, element: Element, attribute: str | None = None) -> SourceLocation:
        """Where ``element`` starts, or where its ``attribute`` is written (1-based line and col).

        An attribute the element does not have is placed at the element. The line and column are found
        when first read (:class:`LazyLocation`): a reader records a location for every element and
        attribute it reads, and only the few a diagnostic shows are ever looked at."""
        if self.origins:
            origin = self.origins.get(element)
            if origin is not None:
                return origin
        return LazyLocation.at(self, element, attribute)

    def find_loc(self, element: Element, attribute: str | None = None) -> SourceLocation:
        """:meth:`loc`, found now (what a :class:`LazyLocation` computes when first read)."""
        origin = self.origins.get(element)
        if origin is not None:
            return origin
        start = self._starts.get(element)
        if start is None:
            line = element.sourceline if isinstance(element.sourceline, int) else 0
            return SourceLocation(self.display, line, 1 if line else 0)
        if attribute and element.get(attribute) is not None:
            offset = self._attributes_of(element, start).get(attribute)
            if offset is not None:
                return SourceLocation(self.display, *self._position(offset))
        return SourceLocation(self.display, *self._position(start))

    def _attributes_of(self, element: Element, start: int) -> dict[str, int]:
        """Where each attribute of the start tag at ``start`` is written (the first spelling)."""
        offsets = self._attribute_offsets.get(element)
        if offsets is None:
            offsets = {}
            name = _START_TAG.match(self.text, start)
            end = tag_end(self.text, start)
            for match in _ATTRIBUTE.finditer(self.text, name.end() if name else start, end):
                offsets.setdefault(match.group(1), match.start())
            self._attribute_offsets[element] = offsets
        return offsets

    def text_loc(self, element: Element) -> SourceLocation:
        """Where the text content of ``element`` starts (just after its start tag), found when first read."""
        origin = self.origins.get(element)
        if origin is not None:
            return origin
        return LazyLocation.at(self, element, None, text=True)

    def find_text_loc(self, element: Element) -> SourceLocation:
        """:meth:`text_loc`, found now."""
        origin = self.origins.get(element)
        if origin is not None:
            return origin
        start = self._starts.get(element)
        if start is None:
            return self.find_loc(element)
        end = tag_end(self.text, start)
        offset = min(end + 1, len(self.text))
        while offset < len(self.text) and self.text[offset] in " \t\r\n":
            offset += 1
        return SourceLocation(self.display, *self._position(offset))


class LazyLocation(SourceLocation):
    """A :class:`SourceLocation` in an :class:`XmlDocument` whose line and column are computed when first
    read. It equals, hashes, orders, prints and pickles as the plain location it stands for (a pickle or a
    shallow copy is that plain location; a deep copy shares it, as any location), so no consumer can tell
    the two apart.

    The document stays alive as long as the location does; it must not change after the location is
    taken (readers only read)."""

    # ``file`` is the document's display name (set at once); the pending look-up and, once made, the
    # found place live in the instance dict; ``line`` and ``col`` are properties over them.

    def __init__(self, file: str, line: int = 0, col: int = 0) -> None:  # as SourceLocation (replace())
        self.__dict__.update(file=file, _found=SourceLocation(file, line, col))

    @classmethod
    def at(
        cls, doc: XmlDocument, element: Element, attribute: str | None, text: bool = False
    ) -> LazyLocation:
        """Where ``element`` (its ``attribute``, or with ``text`` its text content) is in ``doc``."""
        self = cls.__new__(cls)
        self.__dict__.update(file=doc.display, _found=None, _pending=(doc, element, attribute, text))
        return self

    def _resolve(self) -> SourceLocation:
        found: SourceLocation | None = self.__dict__["_found"]
        if found is None:
            doc, element, attribute, text = self.__dict__.pop("_pending")
            found = doc.find_text_loc(element) if text else doc.find_loc(element, attribute)
            self.__dict__["_found"] = found
        return found

    @property
    def line(self) -> int:
        return self._resolve().line

    @property
    def col(self) -> int:
        return self._resolve().col

    def _key(self) -> tuple[str, int, int]:
        found = self._resolve()
        return (found.file, found.line, found.col)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, SourceLocation):
            return self._key() == (other.file, other.line, other.col)
        return NotImplemented

    def __hash__(self) -> int:
        return hash(self._key())  # what the dataclass hashes for a plain location

    def __lt__(self, other: object) -> bool:
        if isinstance(other, SourceLocation):
            return self._key() < (other.file, other.line, other.col)
        return NotImplemented

    def __le__(self, other: object) -> bool:
        if isinstance(other, SourceLocation):
            return self._key() <= (other.file, other.line, other.col)
        return NotImplemented

    def __gt__(self, other: object) -> bool:
        if isinstance(other, SourceLocation):
            return self._key() > (other.file, other.line, other.col)
        return NotImplemented

    def __ge__(self, other: object) -> bool:
        if isinstance(other, SourceLocation):
            return self._key() >= (other.file, other.line, other.col)
        return NotImplemented

    def __repr__(self) -> str:
        return repr(self._resolve())

    def __str__(self) -> str:
        return str(self._resolve())

    def __reduce__(self) -> tuple[type[SourceLocation], tuple[str, int, int]]:
        return (SourceLocation, self._key())


_TAG_TOKEN = re.compile(r"\"[^\"]*\"|'[^']*'|>")


def tag_end(text: str, start: int) -> int:
    """Offset of the ``>`` that closes the start tag beginning at ``start`` (quotes respected)."""
    for match in _TAG_TOKEN.finditer(text, start):
        if match.group(0) == ">":
            return match.start()
    return len(text)


def _index_positions(doc: XmlDocument) -> None:
    text = doc.text
    doc._line_offsets = array("q", [0])  # a compact array: a large file has a million lines
    doc._line_offsets.extend(m.end() for m in re.finditer(r"\n", text))
    starts = [m.start() for m in _START_TAG.finditer(mask_markup(text))]
    elements = [e for e in doc.root.iter() if isinstance(e.tag, str)]
    if len(elements) < len(starts) and elements and (
        doc._position(starts[len(elements) - 1])[0] == elements[-1].sourceline
    ):  # the extra ones follow the root (a tail read past, MK020/MK027): no element of the tree
        del starts[len(elements):]
    if len(starts) != len(elements):  # cannot pair them safely: fall back to lxml's lines
        return
    doc._starts = dict(zip(elements, starts, strict=True))


# Our own nesting limit, below libxml2's (256 without XML_PARSE_HUGE), so that it is always ours that
# answers (MK023), whatever the lxml build; TinyXML2 (urdfdom, libsdformat, MuJoCo) stops at 500.
MAX_XML_DEPTH = 250
# Attributes on one element (real models: a few dozen; each unknown one is a diagnostic of its own).
MAX_XML_ATTRIBUTES = 1000


def parse_xml_bytes(
    data: bytes,
    display: str,
    sink: DiagnosticSink,
    path: Path | None = None,
    keep_blank_text: bool = True,
    positions: bool = True,
    urdfdom: bool = False,
) -> XmlDocument | None:
    """Parse XML held in memory; problems become diagnostics and the result is None.

    ``keep_blank_text=False`` drops whitespace-only text between elements (not the text of an element
    without children): a third less memory for a large pretty-printed file, for readers that never
    write the document back. ``positions=False`` leaves out the index of start-tag positions, for a
    document whose every element is given an entry in ``origins`` (an xacro expansion): its locations
    are those, and a location not found there is the element's line as lxml has it. ``urdfdom``: the
    document is a URDF, whose own loader also reads past text after the root element (MK027)."""
    text = decode_text(data, display, sink)
    if text is None:
        return None
    entity = _ENTITY_DECL.search(text)
    if entity:
        sink.emit(
            "MK021",
            "the document declares XML entities; modelkit refuses them (they can expand without bound "
            "or read other files)",
            location_at(text, display, entity.start()),
            hint="replace the entities with their text, or generate the file with xacro",
        )
        return None
    if not text.strip():
        sink.emit("MK020", "the document is empty", SourceLocation(display))
        return None
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=False,
        remove_blank_text=not keep_blank_text and "<!DOCTYPE" not in text,  # a DTD would decide otherwise
    )
    try:
        root = (
            etree.fromstring(data, parser)
            if not data.startswith((b"\xff\xfe", b"\xfe\xff"))
            else (etree.fromstring(text.encode("utf-8"), parser))
        )
    except etree.XMLSyntaxError as exc:
        line, col = exc.position if exc.position else (exc.lineno or 0, 0)
        message = str(exc.msg or exc).split(", line ")[0]
        where = SourceLocation(display, line or 0, max(col, 1))
        if message.startswith("Excessive depth"):  # libxml2's own limit (256) behind ours
            _too_deep(sink, where)
            return None
        if "XML_PARSE_HUGE" in message or message.startswith("Comment too big"):
            sink.emit(
                "MK026",
                "one text, attribute value, name or comment is longer than 10,000,000 bytes (the XML "
                "parser's limit); the document is refused unread",
                where,
                hint="no robot model holds one value this long: is the file generated wrongly?",
            )
            return None
        root = _as_tinyxml2_reads(data, parser, message, where, text, display, sink, urdfdom)
        if root is None:
            return None
    except ValueError as exc:  # e.g. an encoding declaration lxml cannot honour
        sink.emit("MK020", f"malformed XML: {exc}", SourceLocation(display))
        return None
    deep = root.xpath("/".join(["*"] * MAX_XML_DEPTH))  # the elements one level below the limit
    if isinstance(deep, list) and deep and isinstance(deep[0], etree._Element):
        first = deep[0].sourceline
        at = SourceLocation(display, first, 1) if isinstance(first, int) else SourceLocation(display)
        _too_deep(sink, at)
        return None
    crowded = next((e for e in root.iter() if len(e.attrib) > MAX_XML_ATTRIBUTES), None)
    if crowded is not None:
        line = crowded.sourceline if isinstance(crowded.sourceline, int) else 0
        sink.emit(
            "MK024",
            f"the element <{crowded.tag}> has {len(crowded.attrib):,} attributes, over the limit of "
            f"{MAX_XML_ATTRIBUTES:,}; the document is refused unread",
            SourceLocation(display, line, 1 if line else 0),
            hint="no robot model element has more than a few dozen attributes",
        )
        return None
    doc = XmlDocument(root=root, display=display, text=text, path=path)
    if positions:
        _index_positions(doc)
    return doc


def _too_deep(sink: DiagnosticSink, where: SourceLocation) -> None:
    sink.emit(
        "MK023",
        f"XML elements nest deeper than {MAX_XML_DEPTH} levels; the document is refused unread",
        where,
        hint="no robot model needs this depth: an MJCF chain of bodies is the deepest real case",
    )


_COMMENT = re.compile(rb"<!--(.*?)-->", re.DOTALL)
_DECLARATION = re.compile(rb"\A(\xef\xbb\xbf)?(\s*)(<\?xml\b.*?\?>)", re.DOTALL)
_DECLARED_ENCODING = re.compile(rb"""encoding\s*=\s*["']([^"']*)["']""")


def _blank_comment_hyphens(data: bytes) -> bytes | None:
    """TinyXML2 takes ``--`` inside comments: each such pair (and a ``-`` before ``-->``) becomes a space."""

    def blank(match: re.Match[bytes]) -> bytes:
        inner = match.group(1).replace(b"--", b"- ")
        if inner.endswith(b"-"):
            inner = inner[:-1] + b" "
        return b"<!--" + inner + b"-->"

    return _COMMENT.sub(blank, data)


def _blank_declaration(data: bytes) -> bytes | None:
    """TinyXML2 does not judge the XML declaration (any ``version``, whitespace before it): it becomes
    spaces. Not when it names an encoding other than UTF-8, which the blanked document would lose."""
    found = _DECLARATION.match(data)
    if found is None:
        return None
    encoding = _DECLARED_ENCODING.search(found.group(3))
    if encoding and encoding.group(1).lower().replace(b"-", b"") not in (b"utf8", b"usascii", b"ascii"):
        return None
    start, end = found.span(3)
    return data[:start] + bytes(b if b in b"\r\n" else 32 for b in data[start:end]) + data[end:]


_TAIL_INSTRUCTION = re.compile(rb"<\?.*?\?>", re.DOTALL)
_TAIL_END_TAG = re.compile(rb"</[^\s<>/]+\s*>")
_TAIL_TAG = re.compile(rb"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<(/?)[^\s<>/!?]+(?:\s[^<>]*?)?(/?)>",
                       re.DOTALL)
_TAIL_BLANK = b" \t\r\n"


def _blank_tail(data: bytes, line: int, col: int, reads: Callable[[bytes], bool]) -> bytes | None:
    """``data`` with what follows the root element blanked, when the parser behind ``reads`` reads that
    tail (``_tinyxml2_reads``, ``_tinyxml1_reads``). libxml2 stops at its first node (``line``,
    ``col``: its position, in characters). The tail becomes spaces, so every offset stays. None (the
    error stands) when it cannot be placed or the parser refuses it."""
    start = _tail_start(data, line, col)
    if start is None or not reads(data[start:]):
        return None
    return data[:start] + bytes(b if b in b"\r\n" else 32 for b in data[start:])


def _tail_start(data: bytes, line: int, col: int) -> int | None:
    """The byte offset of libxml2's (line, column), in characters; None where it cannot be placed."""
    if line < 1 or col < 1 or data.startswith(b"\xef\xbb\xbf"):
        return None
    lines = data.split(b"\n")
    if line > len(lines):
        return None
    try:
        before = lines[line - 1].decode("utf-8")[: col - 1].encode("utf-8")
    except UnicodeDecodeError:
        return None
    return sum(len(lines[k]) + 1 for k in range(line - 1)) + len(before)


def _open_comment_start(data: bytes) -> int:
    """Where the comment that is never closed starts (the first ``<!--`` without a ``-->`` after it,
    comments being read in turn), or -1."""
    at = data.find(b"<!--")
    while at >= 0:
        end = data.find(b"-->", at + 4)
        if end < 0:
            return at
        at = data.find(b"<!--", end + 3)
    return -1


def _blank_open_comment(data: bytes) -> bytes | None:
    """``data`` with a comment that is never closed blanked to the end, when it follows a whole root
    element (what is before it parses alone); None otherwise (inside the root it is an error for
    urdfdom too: the root's end tag is missing)."""
    start = _open_comment_start(data)
    if start < 0:
        return None
    try:
        parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
        etree.fromstring(data[:start], parser)
    except (etree.XMLSyntaxError, ValueError):
        return None
    return data[:start] + bytes(b if b in b"\r\n" else 32 for b in data[start:])


def _tinyxml2_reads(tail: bytes) -> bool:
    """TinyXML2 reads ``tail`` (after the root element): blanks, comments, processing instructions and
    whole elements, up to the end or to a stray end tag, where it stops (MuJoCo and PyBullet then load
    ``</robot>`` followed by anything)."""
    return _scan_tail(tail, end_tag_stops=True, text_stops=False)


def _tinyxml1_reads(tail: bytes) -> bool:
    """urdfdom's TinyXML (1) reads ``tail``: blanks, comments, processing instructions, stray end tags
    and whole elements, up to the end or to text outside any element, where it stops (check_urdf loads
    ``</robot>`` then ``garbage <b>``, and refuses ``</robot>`` then ``</x> <b>``), or to a comment that
    is never closed, which it reads to the end of the file without an error."""
    return _scan_tail(tail, end_tag_stops=False, text_stops=True, open_comment_ends=True)


def _scan_tail(tail: bytes, end_tag_stops: bool, text_stops: bool, open_comment_ends: bool = False) -> bool:
    at = 0
    while True:
        while at < len(tail) and tail[at] in _TAIL_BLANK:
            at += 1
        if at == len(tail):
            return True
        if tail[at:at + 1] != b"<":
            return text_stops
        end_tag = _TAIL_END_TAG.match(tail, at)
        if end_tag:
            if end_tag_stops:
                return True
            at = end_tag.end()
            continue
        for simple in (_COMMENT, _TAIL_INSTRUCTION):  # _COMMENT: the comments' own pattern
            found = simple.match(tail, at)
            if found:
                at = found.end()
                break
        else:
            if open_comment_ends and tail.startswith(b"<!--", at):
                return True  # never closed (a closed one matched _COMMENT)
            end = _element_end(tail, at)
            if end is None:
                return False
            at = end


def _element_end(tail: bytes, at: int) -> int | None:
    """Where the element starting at ``at`` ends, when it is whole and well formed (lxml parses it)."""
    depth = 0
    for found in _TAIL_TAG.finditer(tail, at):
        if found.start() != at and depth == 0:
            return None
        text = found.group(0)
        if text.startswith((b"<!", b"<?")):
            continue
        if found.group(1):
            depth -= 1
        elif not found.group(2):
            depth += 1
        if depth == 0:
            try:
                etree.fromstring(tail[at : found.end()], etree.XMLParser(resolve_entities=False,
                                                                          no_network=True, load_dtd=False))
            except (etree.XMLSyntaxError, ValueError):
                return None
            return found.end()
        if depth < 0:
            return None
    return None


# A start tag (quoted values may hold ">"), or markup whose text must stay as it is.
_TAG_OR_OPAQUE = re.compile(rb"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>"
                            rb"""|<[A-Za-z_:][^\s<>/"']*(?:[^<>"']|"[^"]*"|'[^']*')*>""", re.DOTALL)
_GLUED_ATTRIBUTE = re.compile(rb"""(=\s*(?:"[^"]*"|'[^']*'))(?=[A-Za-z_:])""")


def _space_between_attributes(data: bytes) -> bytes | None:
    """TinyXML2 reads an attribute that follows the previous one's closing quote with no space between
    (robotblockset's ``type="box"size="..."``); XML requires the space. One is put there in every start
    tag (comments, CDATA and processing instructions untouched); no line changes, and locations are
    found in the file's own text. None when there is nothing to mend."""
    changed = False

    def mend(found: re.Match[bytes]) -> bytes:
        nonlocal changed
        tag = found.group(0)
        if tag.startswith((b"<!", b"<?")):
            return tag
        mended = _GLUED_ATTRIBUTE.sub(rb"\1 ", tag)
        changed = changed or mended != tag
        return mended

    repaired = _TAG_OR_OPAQUE.sub(mend, data)
    return repaired if changed else None


_TINYXML2 = "libsdformat, urdfdom, MuJoCo and PyBullet (TinyXML2)"


def _declared_version(text: str) -> str:
    version = re.search(r"version\s*=\s*[\"']([^\"']*)", text)
    return version.group(1) if version else ""


@dataclass(frozen=True)
class _Leniency:
    """Something libxml2 refuses that TinyXML2 reads past: how to read past it, and what to say."""

    repair: Callable[[bytes, tuple[int, int]], bytes | None]  # (data, libxml2's line and column)
    say: Callable[[str], str]  # the document's text → the warning
    hint: str
    # where to place the warning (a byte offset in the data before the repair); None: where libxml2 stopped
    locate: Callable[[bytes], int] | None
    code: str = "MK020"


def _declaration_at(data: bytes) -> int:
    """The offset of the XML declaration's version (0 without a declaration)."""
    declaration = _DECLARATION.match(data)
    return declaration.start(3) if declaration else 0


_AFTER_ROOT = "Extra content at the end of the document"  # libxml2's complaint about a tail after the root
_DECLARATION_HINT = 'start the file with <?xml version="1.0"?> or leave the declaration out'
#: libxml2's complaint → how TinyXML2 reads past it.
_TINYXML2_LENIENCY = {
    "hyphen within comment": _Leniency(
        lambda data, _: _blank_comment_hyphens(data),
        lambda text: 'a comment contains "--", which XML forbids: libsdformat, urdfdom and MuJoCo (TinyXML2) '
        "accept it, strict XML tools (xacro, lxml, ROS launch) refuse it",
        'write "- -" or "-" inside comments',
        locate=None,
    ),
    "Unsupported version": _Leniency(
        lambda data, _: _blank_declaration(data),
        lambda text: f'the XML declaration names version "{_declared_version(text)}", not 1.0; {_TINYXML2} '
        "ignore it, strict XML tools (lxml, so urdf_parser_py and yourdfpy) refuse it",
        _DECLARATION_HINT,
        locate=_declaration_at,
    ),
    "XML declaration allowed only at the start": _Leniency(
        lambda data, _: _blank_declaration(data),
        lambda text: f"the XML declaration is not at the start of the file; {_TINYXML2} ignore it, strict "
        "XML tools (lxml, so urdf_parser_py and yourdfpy, and xacro) refuse it",
        _DECLARATION_HINT,
        locate=_declaration_at,
    ),
    "attributes construct error": _Leniency(
        lambda data, _: _space_between_attributes(data),
        lambda text: "an attribute follows the previous attribute's closing quote without a space between "
        f"them, which XML requires: {_TINYXML2} read it, strict XML tools (lxml, so urdf_parser_py and "
        "yourdfpy, and xacro) refuse the file",
        "put a space between the attributes",
        locate=None,
    ),
    _AFTER_ROOT: _Leniency(
        # TinyXML2 reads whole elements, comments and processing instructions after the root, up to a
        # stray end tag of any name (PyFlyt's rocket ends with `</robot>` twice), where it stops
        lambda data, at: _blank_tail(data, *at, _tinyxml2_reads),
        lambda text: "the document goes on after its root element ends (an end tag, element, comment or "
        f"processing instruction): {_TINYXML2} read the root element and ignore the rest, strict XML tools "
        "(lxml, so urdf_parser_py and yourdfpy, and xacro) refuse the file",
        "delete everything after the root element's end tag",
        locate=None,
    ),
}
#: A comment after a URDF's root element that is never closed: urdfdom alone reads past it (MK027).
_OPEN_COMMENT = _Leniency(
    lambda data, _: _blank_open_comment(data),
    lambda text: "a comment after the root element is never closed: urdfdom (TinyXML) reads the root "
    "element and ignores the rest of the file; PyBullet and MuJoCo (TinyXML2: "
    "XML_ERROR_PARSING_COMMENT) and strict XML tools (lxml, so xacro) refuse the file",
    'close the comment with "-->" or delete it',
    locate=_open_comment_start,
    code="MK027",
)
#: A URDF's own loader is urdfdom (TinyXML 1): what follows its root element is read past when both
#: parsers read it (MK020), or when urdfdom alone does (MK027: it stops quietly at text outside any
#: element; PyBullet refuses it and MuJoCo nearly always, so it is an error under their targets).
_URDFDOM_LENIENCY = {
    _AFTER_ROOT: (
        dataclasses.replace(_TINYXML2_LENIENCY[_AFTER_ROOT], repair=lambda data, at: _blank_tail(
            data, *at, lambda tail: _tinyxml2_reads(tail) and _tinyxml1_reads(tail))),
        _Leniency(
            lambda data, at: _blank_tail(data, *at, _tinyxml1_reads),
            lambda text: "text, or a comment never closed, follows the root element's end: urdfdom (TinyXML) "
            "reads the root element and ignores the rest of the file; PyBullet (TinyXML2) refuses the file "
            "(XML_ERROR_PARSING_TEXT or _COMMENT), so do MuJoCo for all but a few such tails and strict XML "
            "tools (lxml, so xacro)",
            "delete everything after the root element's end tag",
            locate=None,
            code="MK027",
        ),
    ),
    "Comment not terminated": (_OPEN_COMMENT,),
    # `<!-- a <!-- b` at the end: libxml2 first meets the "--" of the inner `<!--`; the comment is never
    # closed, and urdfdom ignores it whole
    "hyphen within comment": (_OPEN_COMMENT, _TINYXML2_LENIENCY["hyphen within comment"]),
}


def _as_tinyxml2_reads(
    data: bytes,
    parser: etree.XMLParser,
    message: str,
    where: SourceLocation,
    text: str,
    display: str,
    sink: DiagnosticSink,
    urdfdom: bool = False,
) -> etree._Element | None:
    """Parse ``data`` again past what libxml2 refuses and TinyXML2 (the reference loaders' parser)
    accepts, each with a warning; every offset stays where it was; ``urdfdom``: also past what urdfdom's
    TinyXML accepts (a URDF's own loader). The error (MK020) when that fails."""
    applied: set[str] = set()
    while not data.startswith((b"\xff\xfe", b"\xfe\xff")):
        known = (*_TINYXML2_LENIENCY, *(_URDFDOM_LENIENCY if urdfdom else ()))
        problem = next((p for p in known if p in message and p not in applied), None)
        if problem is None:
            break
        applied.add(problem)
        repaired = None
        candidates = _URDFDOM_LENIENCY.get(problem) if urdfdom else None
        for leniency in candidates or (_TINYXML2_LENIENCY[problem],):
            repaired = leniency.repair(data, (where.line or 0, where.col or 0))
            if repaired is not None:
                break
        if repaired is None:
            break
        if leniency.locate is not None:
            at = leniency.locate(data)
            where = location_at(text, display, len(data[:at].decode("utf-8", "replace")))
        sink.emit(leniency.code, leniency.say(text), where, hint=leniency.hint, severity=Severity.WARNING)
        data = repaired
        try:
            return etree.fromstring(data, parser)
        except etree.XMLSyntaxError as exc:
            line, col = exc.position if exc.position else (exc.lineno or 0, 0)
            message = str(exc.msg or exc).split(", line ")[0]
            where = SourceLocation(display, line or 0, max(col, 1))
        except ValueError as exc:
            message = str(exc)
            break
    sink.emit("MK020", f"malformed XML: {message}", where)
    return None


def read_xml(
    path: Path,
    sink: DiagnosticSink,
    max_bytes: int = DEFAULT_MAX_BYTES,
    display: str | None = None,
    keep_blank_text: bool = True,
    urdfdom: bool = False,
) -> XmlDocument | None:
    """Read and parse an XML file with the checks every input gets: exists, size, encoding, syntax
    (``urdfdom``: see :func:`parse_xml_bytes`)."""
    name = display or str(path)
    data = read_bytes(path, sink, max_bytes, name)
    return None if data is None else parse_xml_bytes(data, name, sink, path, keep_blank_text, urdfdom=urdfdom)


def sniff_root_tag(path: Path, limit: int = 65536) -> str | None:
    """The name of the first element of an XML file (``robot``, ``sdf``, ``mujoco``), or None."""
    data = read_head(path, limit)
    if data is None:
        return None
    head = data.decode("utf-8", errors="replace")
    match = _START_TAG.search(mask_markup(head))
    if match is None:
        return None
    return match.group(1).split(":")[-1]
