"""YAML read the way Choreonoid reads it, keeping the source position of every node.

* libyaml (``CSafeLoader``) does the scanning, as in Choreonoid, so tabs in flow sequences work.
* Every scalar stays a string; typing happens where a value is used (see :mod:`modelkit.scalars`).
* Anchors and aliases are kept as shared nodes (never copied), so an alias bomb costs nothing to
  load; :func:`parse_yaml` then measures the expanded size and refuses documents that would
  explode, and refuses recursive aliases.
* ``<<`` merge keys follow Choreonoid: explicit keys win, and in a merge list the earlier mapping wins.
* Duplicate keys, which PyYAML and Choreonoid silently collapse, are reported.
* Long flow lists of plain decimal numbers (inline meshes: a 50 MB file holds millions of them) are
  not composed a node per number: :func:`parse_yaml` finds them in the text, blanks their contents
  (same length, line breaks kept, so every other mark stays put), and keeps each as a
  :class:`YNumbers`: the floats in an ``array('d')``, the item nodes made only when asked for.
"""

from __future__ import annotations

import re
from array import array
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml

from modelkit.diagnostics import Diagnostic, DiagnosticSink, SourceLocation, diag
from modelkit.textio import (  # re-exported: the file checks are shared with the XML readers
    DEFAULT_EXPANSION_LIMIT,
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_LIST_ITEMS,
    decode_text,
    read_bytes,
)


@dataclass(eq=False)
class YNode:
    loc: SourceLocation
    anchor: str | None = field(default=None, kw_only=True)


@dataclass(eq=False)
class YScalar(YNode):
    value: str
    plain: bool = True  # False when the scalar was quoted or a block scalar


@dataclass(eq=False)
class YSeq(YNode):
    items: list[YNode] = field(default_factory=list)


@dataclass(eq=False)
class YMap(YNode):
    """A mapping after merge resolution: key -> (key node, value node), in document order."""

    entries: dict[str, tuple[YScalar, YNode]] = field(default_factory=dict)
    merged_keys: set[str] = field(default_factory=set)  # keys that came from a `<<` merge

    def get(self, *spellings: str) -> YNode | None:
        for key in spellings:
            entry = self.entries.get(key)
            if entry is not None:
                return entry[1]
        return None

    def find(self, *spellings: str) -> tuple[str, YNode] | None:
        """The first spelling present, with its value."""
        for key in spellings:
            entry = self.entries.get(key)
            if entry is not None:
                return key, entry[1]
        return None

    def key_loc(self, key: str) -> SourceLocation:
        entry = self.entries.get(key)
        return entry[0].loc if entry else self.loc

    def __contains__(self, key: object) -> bool:
        return key in self.entries

    def keys(self) -> Iterator[str]:
        return iter(self.entries)

    def items(self) -> Iterator[tuple[str, YNode]]:
        for key, (_, value) in self.entries.items():
            yield key, value


class YNumbers(YSeq):
    """A flow list of plain decimal numbers, kept compactly (see :func:`parse_yaml`).

    ``values`` holds the floats (what ``float`` and C's ``strtod`` read from each item); ``items`` makes
    the item nodes, with their locations, on first use, exactly as a composed list would have them.
    """

    def __init__(
        self, loc: SourceLocation, text: str, start: int, end: int, values: array, anchor: str | None = None
    ) -> None:
        self.loc = loc
        self.anchor = anchor
        self.text = text  # the document text; start/end: the '[' and just after the ']'
        self.start = start
        self.end = end
        self.values = values
        self._items: list[YNode] | None = None

    @property
    def items(self) -> list[YNode]:
        if self._items is None:
            self._items = self._make_items()
        return self._items

    @items.setter
    def items(self, value: list[YNode]) -> None:
        self._items = value

    def texts(self) -> list[str]:
        """The items' texts."""
        return _NUMBER_RE.findall(self.text, self.start + 1, self.end - 1)

    def _make_items(self) -> list[YNode]:
        line = self.loc.line  # 1-based
        line_start = self.start - (self.loc.col - 1)  # text index where the current line begins
        out: list[YNode] = []
        for match in _TOKEN_OR_BREAK_RE.finditer(self.text, self.start + 1, self.end - 1):
            token = match.group(1)
            if token is None:  # a line break (libyaml's: CRLF, CR or LF)
                line += 1
                line_start = match.end()
            else:
                where = SourceLocation(self.loc.file, line, match.start() - line_start + 1)
                out.append(YScalar(where, token))
        return out


_NUMBER = r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_NUMBER_RE = re.compile(_NUMBER)
_TOKEN_OR_BREAK_RE = re.compile(r"\r\n|\r|\n|(" + _NUMBER + ")")
# A flow list of at least two plain decimal numbers, separated by commas, blanks and line breaks (no tab,
# no comment, no trailing comma): what Choreonoid's scene writer emits for meshes.
_NUMBER_LIST_RE = re.compile(r"\[[ \r\n]*" + _NUMBER + r"(?:[ \r\n]*,[ \r\n]*" + _NUMBER + r")+[ \r\n]*\]")
_BLANK = str.maketrans("0123456789.eE+-,", " " * 16)
FAST_LIST_MIN_ITEMS = 64
"""Shorter number lists are composed as usual (a node per number): the fast path pays off on long ones."""


def _blank_number_lists(text: str, min_items: int) -> tuple[str, dict[int, tuple[int, array]]]:
    """``text`` with the contents of every long number list blanked, and the lists found: the index of
    each '[' -> (the index after its ']', the numbers). A list may sit where no list is (in a quoted
    string, a comment, a block scalar): the caller checks that each one became a composed flow list."""
    regions: dict[int, tuple[int, array]] = {}
    if "[" not in text:
        return text, regions
    pieces: list[str] = []
    done = 0
    for match in _NUMBER_LIST_RE.finditer(text):
        start, end = match.span()
        if text.count(",", start, end) + 1 < min_items:
            continue
        values = array("d", map(float, _NUMBER_RE.findall(text, start + 1, end - 1)))
        regions[start] = (end, values)
        pieces.append(text[done:start + 1])
        pieces.append(text[start + 1:end - 1].translate(_BLANK))
        done = end - 1
    if not regions:
        return text, regions
    pieces.append(text[done:])
    return "".join(pieces), regions


class _FastPathMissed(Exception):
    """A blanked number list did not compose as a flow list: parse the text as it is."""


@dataclass
class _FastCheck:
    """What the event scan saw of the blanked lists: the '[' indices that opened a flow sequence, and how
    far the parser read. Blanking keeps every position, so the parser behaves the same up to the first
    blanked place that was not a flow list; a verdict reached before any such place stands."""

    confirmed: set[int] = field(default_factory=set)
    stop: int = 0

    def trusted(self, blanked: dict[int, tuple[int, array]]) -> bool:
        return all(start in self.confirmed for start in blanked if start <= self.stop)


@dataclass
class YamlDocument:
    root: YNode | None
    path: str
    anchors: dict[str, YNode]


def _loc(path: str, mark: yaml.Mark | None) -> SourceLocation:
    if mark is None:
        return SourceLocation(path)
    return SourceLocation(path, mark.line + 1, mark.column + 1)


class _Converter:
    """Turns PyYAML's composed node graph into Y-nodes, sharing aliased nodes."""

    def __init__(
        self,
        path: str,
        sink: DiagnosticSink,
        anchor_names: dict[int, str],
        imported: dict[tuple[int, int], YNode] | None = None,
        numbers: tuple[str, dict[int, tuple[int, array]]] | None = None,
    ) -> None:
        self.path = path
        self.sink = sink
        self.memo: dict[int, YNode] = {}
        self.anchor_names = anchor_names
        # The original text and its blanked number lists (by the index of the '['), when there are some.
        self.text, self.numbers = numbers or ("", {})
        self.numbers_found = 0
        # Aliases of another file's anchors, by the 0-based (line, column) of their stand-in scalar.
        self.imported = imported or {}

    def convert(self, node: yaml.Node) -> YNode:
        done = self.memo.get(id(node))
        if done is not None:
            return done
        if self.imported and isinstance(node, yaml.ScalarNode) and node.start_mark is not None:
            found = self.imported.get((node.start_mark.line, node.start_mark.column))
            if found is not None:
                return found
        loc = _loc(self.path, node.start_mark)
        anchor = self.anchor_names.get(id(node))
        result: YNode
        if isinstance(node, yaml.ScalarNode):
            result = YScalar(loc, node.value, plain=node.style in (None, ""), anchor=anchor)
            self.memo[id(node)] = result
        elif self.numbers and isinstance(node, yaml.SequenceNode) and node.start_mark.index in self.numbers:
            end, values = self.numbers[node.start_mark.index]
            if node.value or node.end_mark.index != end or node.flow_style is not True:
                raise _FastPathMissed
            result = YNumbers(loc, self.text, node.start_mark.index, end, values, anchor=anchor)
            self.numbers_found += 1
            self.memo[id(node)] = result
        elif isinstance(node, yaml.SequenceNode):
            seq = YSeq(loc, anchor=anchor)
            self.memo[id(node)] = seq
            seq.items = [self.convert(child) for child in node.value]
            result = seq
        elif isinstance(node, yaml.MappingNode):
            mapping = YMap(loc, anchor=anchor)
            self.memo[id(node)] = mapping
            self._fill_mapping(mapping, node)
            result = mapping
        else:  # pragma: no cover - PyYAML has no other node kinds
            raise TypeError(node)
        return result

    def _fill_mapping(self, mapping: YMap, node: yaml.MappingNode) -> None:
        merges: list[tuple[YScalar, yaml.Node]] = []
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                self.sink.emit(
                    "MK019", "a mapping key must be a scalar", _loc(self.path, key_node.start_mark)
                )
                continue
            key = YScalar(
                _loc(self.path, key_node.start_mark), key_node.value, plain=key_node.style in (None, "")
            )
            if key_node.tag == "tag:yaml.org,2002:merge" or (key.value == "<<" and key.plain):
                merges.append((key, value_node))
                continue
            if key.value == "":
                self.sink.emit("MK018", "empty key", key.loc)
                continue
            previous = mapping.entries.get(key.value)
            if previous is not None:
                self.sink.emit(
                    "MK011",
                    f'duplicate key "{key.value}" at line {key.loc.line} (first at line '
                    f"{previous[0].loc.line}); Choreonoid silently keeps only this last value",
                    key.loc,
                )
            mapping.entries[key.value] = (key, self.convert(value_node))
        for key, value_node in merges:
            self._merge(mapping, key, value_node)

    def _merge(self, mapping: YMap, key: YScalar, value_node: yaml.Node) -> None:
        value = self.convert(value_node)
        sources: list[YNode]
        if isinstance(value, YMap):
            sources = [value]
        elif isinstance(value, YSeq):
            sources = list(value.items)
        else:
            self.sink.emit(
                "MK016", 'a value to merge by the "<<" key must be a mapping or a list of mappings', value.loc
            )
            return
        for source in sources:
            if not isinstance(source, YMap):
                self.sink.emit("MK016", 'an element to merge by the "<<" key must be a mapping', source.loc)
                continue
            for k, entry in source.entries.items():
                if k not in mapping.entries:
                    mapping.entries[k] = entry
                    mapping.merged_keys.add(k)


MAX_NESTING = 128


class ListTooLong(Exception):
    """A YAML sequence has more items than the limit; ``mark`` is where it starts."""

    def __init__(self, mark: Any, limit: int, key: str = "") -> None:
        super().__init__(mark)
        self.mark = mark
        self.limit = limit
        self.key = key  # the top-level key whose value the list is ("" for any other list)


_ITEM_EVENTS = (yaml.ScalarEvent, yaml.AliasEvent, yaml.SequenceStartEvent, yaml.MappingStartEvent)


def _scan_events(
    text: str,
    max_list_items: int = DEFAULT_MAX_LIST_ITEMS,
    top_limits: dict[str, int] | None = None,
    blanked: dict[int, tuple[int, array]] | None = None,
    check: _FastCheck | None = None,
) -> tuple[dict[tuple[int, int], str], Any, list[tuple[str, int, int]]]:
    """One pass over the event stream (libyaml's parser is iterative, so this is safe on any input).

    Returns the anchor names by (line, column) of the anchored node (PyYAML's composer drops them)
    and, when the nesting passes :data:`MAX_NESTING`, the mark where it does: the composer and
    everything after it recurse, so such documents are refused before composing.

    Some libyaml builds (the one in PyYAML 6.0.4's wheels) refuse deep flow nesting with a limit of
    their own while scanning ahead, before any event at our limit is produced. The nesting verdict
    must not depend on a library's internal limit, so such a refusal is re-scanned with PyYAML's
    pure-Python parser (iterative too, and without a nesting limit) to find our own mark.
    """
    names, too_deep, aliases, error = _scan_events_with(
        text, yaml.CSafeLoader, max_list_items, top_limits, blanked, check
    )
    if too_deep is None and error is not None and _is_nesting_refusal(error):
        names, too_deep, aliases, _ = _scan_events_with(
            text, yaml.SafeLoader, max_list_items, top_limits, blanked, check
        )
    return names, too_deep, aliases


def _is_nesting_refusal(error: yaml.YAMLError) -> bool:
    problem = str(getattr(error, "problem", "") or "") + " " + str(getattr(error, "context", "") or "")
    return "nesting" in problem or "depth" in problem or "flow level" in problem


def _scan_events_with(
    text: str,
    loader: Any,
    max_list_items: int = DEFAULT_MAX_LIST_ITEMS,
    top_limits: dict[str, int] | None = None,
    blanked: dict[int, tuple[int, array]] | None = None,
    check: _FastCheck | None = None,
) -> tuple[dict[tuple[int, int], str], Any, list[tuple[str, int, int]], yaml.YAMLError | None]:
    names: dict[tuple[int, int], str] = {}
    aliases: list[tuple[str, int, int]] = []  # (anchor, line, column) of every alias, 0-based
    depth = 0
    documents = 0
    # Items counted so far in each open sequence (None for a mapping), innermost last: a long list
    # costs far more to compose and check than its bytes suggest, so it is refused here, early.
    counts: list[list[Any]] = []
    try:
        for event in yaml.parse(text, Loader=loader):
            if check is not None and event.start_mark is not None:
                check.stop = max(check.stop, event.start_mark.index)
            if isinstance(event, yaml.DocumentStartEvent):
                documents += 1
                if documents > 1:
                    break
            if counts and isinstance(event, _ITEM_EVENTS):
                entry = counts[-1]  # [items, start mark, limit, last key (mappings) or None, own key]
                entry[0] += 1
                if entry[3] is None and entry[0] > entry[2]:
                    raise ListTooLong(entry[1], entry[2], entry[4])
                if entry[3] is not None and entry[0] % 2 == 1:  # a mapping's key
                    entry[3] = event.value if isinstance(event, yaml.ScalarEvent) else ""
            if isinstance(event, yaml.SequenceStartEvent):
                key = counts[0][3] if len(counts) == 1 and counts[0][3] is not None else ""
                limit = (top_limits or {}).get(key, max_list_items)
                counts.append([0, event.start_mark, limit, None, key])
                at = event.start_mark.index if event.start_mark is not None else -1
                numbers = blanked.get(at) if blanked else None
                if numbers is not None:  # a blanked number list: its items are counted at once
                    if check is not None and event.flow_style:
                        check.confirmed.add(at)
                    counts[-1][0] = len(numbers[1])
                    if counts[-1][0] > limit:
                        raise ListTooLong(event.start_mark, limit, key)
            elif isinstance(event, yaml.MappingStartEvent):
                counts.append([0, event.start_mark, 0, "", ""])
            elif isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)) and counts:
                counts.pop()
            if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
                depth += 1
                if depth > MAX_NESTING:
                    return names, event.start_mark, aliases, None
            elif isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
                depth -= 1
            anchor = getattr(event, "anchor", None)
            if anchor and isinstance(event, yaml.AliasEvent) and event.start_mark is not None:
                aliases.append((anchor, event.start_mark.line, event.start_mark.column))
            elif anchor and event.start_mark is not None:
                names[(event.start_mark.line, event.start_mark.column)] = anchor
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        if check is not None and mark is not None:
            check.stop = max(check.stop, mark.index)
        return names, None, aliases, exc
    return names, None, aliases, None


def _list_too_long(exc: ListTooLong, path: str) -> Diagnostic:
    if exc.key:
        return diag(
            "MK005",
            f'"{exc.key}" has more than {exc.limit} items, over the limit; refusing the document',
            _loc(path, exc.mark),
            hint="raise the limit with --max-links if the model is genuine",
        )
    return diag(
        "MK006",
        f"a list has more than {exc.limit} items; refusing the document",
        _loc(path, exc.mark),
        hint="raise the limit with --max-list-items if the file is genuine",
    )


def _too_deep(mark: Any, path: str) -> Diagnostic:
    message = f"YAML nesting deeper than {MAX_NESTING} levels; refusing the document"
    return diag("MK010", message, _loc(path, mark))


@dataclass(frozen=True)
class StructureScan:
    """What the event scan found: a refusal (MK006, MK010) or None, and how many aliases there are."""

    problem: Diagnostic | None
    aliases: int


def scan_structure(text: str, path: str, max_list_items: int = DEFAULT_MAX_LIST_ITEMS) -> StructureScan:
    """What the event scan refuses before anything is composed: a list over ``max_list_items``
    (MK006) or nesting deeper than :data:`MAX_NESTING` (MK010). One pass over the events, never
    recursive, so it is safe on any text; without aliases nothing can expand past the text's size."""
    try:
        _, too_deep, aliases = _scan_events(text, max_list_items)
    except ListTooLong as exc:
        return StructureScan(_list_too_long(exc, path), 0)
    return StructureScan(_too_deep(too_deep, path) if too_deep is not None else None, len(aliases))


_Node = TypeVar("_Node")


def measure_composed(root: yaml.Node, limit: int) -> tuple[str, yaml.Node] | None:
    """:func:`measure_expansion` on PyYAML's composed node graph (an alias is the anchored node
    object itself): ``("recursive", node)``, ``("limit", node)`` or None, in time linear in the
    number of distinct nodes."""
    return _measure(root, limit, _composed_children, lambda node: 1)


def _composed_children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [item for pair in node.value for item in pair]
    return []


def measure_expansion(root: YNode, limit: int) -> tuple[str, YNode] | None:
    """Check the size the document would have with every alias copied out.

    Returns ``("recursive", node)`` for a node that contains itself, ``("limit", node)`` for the
    node where the expanded count passes ``limit``, or None when the document is fine. Shared nodes
    are measured once, so the check is linear in the size of the file.
    """
    return _measure(root, limit, _children,
                    lambda node: 1 + (len(node.values) if isinstance(node, YNumbers) else 0))


def _measure(root: _Node, limit: int, children: Callable[[_Node], list[_Node]],
             own: Callable[[_Node], int]) -> tuple[str, _Node] | None:
    """The expanded size of a node graph whose shared nodes stand for copies: each node counts
    ``own(node)`` plus its children's sizes. Iterative post-order walk (a malicious file must not hit
    Python's recursion limit either), each distinct node measured once."""
    sizes: dict[int, int] = {}
    on_stack: set[int] = set()
    stack: list[tuple[_Node, bool]] = [(root, False)]
    while stack:
        node, children_done = stack.pop()
        key = id(node)
        if children_done:
            on_stack.discard(key)
            total = own(node)
            for child in children(node):
                total += sizes.get(id(child), 1)
                if total > limit:
                    return ("limit", node)
            sizes[key] = total
            continue
        if key in sizes:
            continue
        if key in on_stack:
            return ("recursive", node)
        on_stack.add(key)
        stack.append((node, True))
        for child in children(node):
            if id(child) in on_stack:
                return ("recursive", child)
            if id(child) not in sizes:
                stack.append((child, False))
    return None


def _children(node: YNode) -> list[YNode]:
    if isinstance(node, YNumbers):
        return []  # numbers only
    if isinstance(node, YSeq):
        return node.items
    if isinstance(node, YMap):
        return [value for _, value in node.entries.values()]
    return []


def read_text(
    path: Path, sink: DiagnosticSink, max_bytes: int = DEFAULT_MAX_BYTES, display: str | None = None
) -> str | None:
    """Read a text file with the checks every input gets: exists, size, text encoding."""
    name = display or str(path)
    data = read_bytes(path, sink, max_bytes, name)
    return None if data is None else decode_text(data, name, sink)


def parse_yaml(
    text: str,
    path: str,
    sink: DiagnosticSink,
    expansion_limit: int = DEFAULT_EXPANSION_LIMIT,
    max_list_items: int = DEFAULT_MAX_LIST_ITEMS,
    top_limits: dict[str, int] | None = None,
    imported_anchors: dict[str, YNode] | None = None,
    fast_lists: int | None = FAST_LIST_MIN_ITEMS,
) -> YamlDocument:
    """Compose the first YAML document of ``text`` into Y-nodes, reporting problems into ``sink``.

    ``top_limits`` bounds the list under a top-level key more tightly (the ``links`` of a body:
    MK005) than any other list (``max_list_items``: MK006); both are checked before composing.
    ``imported_anchors`` are another document's anchors that aliases here may use when no anchor of
    that name precedes them in this text (Choreonoid's YAML resources see the main .body's anchors).

    Long number lists are kept compactly (:class:`YNumbers`; ``fast_lists`` items or more, None: never).
    The result, diagnostics included, is the same as without; where a blanked list turns out not to be
    a flow list (it sat in a string or a comment), the text is parsed again as it is."""
    if fast_lists:
        blanked, regions = _blank_number_lists(text, fast_lists)
        if regions:
            trial = DiagnosticSink()
            try:
                doc = _parse_yaml(blanked, path, trial, expansion_limit, max_list_items, top_limits,
                                  imported_anchors, (text, regions))
            except _FastPathMissed:
                pass
            else:
                sink.extend(trial.items)
                return doc
    return _parse_yaml(text, path, sink, expansion_limit, max_list_items, top_limits, imported_anchors, None)


def _parse_yaml(
    text: str,
    path: str,
    sink: DiagnosticSink,
    expansion_limit: int,
    max_list_items: int,
    top_limits: dict[str, int] | None,
    imported_anchors: dict[str, YNode] | None,
    numbers: tuple[str, dict[int, tuple[int, array]]] | None,
) -> YamlDocument:
    check = _FastCheck() if numbers else None
    blanked = numbers[1] if numbers else None
    original = numbers[0] if numbers else text
    try:
        try:
            anchors_by_pos, too_deep, alias_marks = _scan_events(
                text, max_list_items, top_limits, blanked, check
            )
        finally:
            if check is not None and blanked and not check.trusted(blanked):
                raise _FastPathMissed
    except ListTooLong as exc:
        sink.add(_list_too_long(exc, path))
        return YamlDocument(None, path, {})
    if too_deep is not None:
        sink.add(_too_deep(too_deep, path))
        return YamlDocument(None, path, {})
    stand_ins: dict[tuple[int, int], YNode] = {}
    if imported_anchors:
        text, stand_ins = _stand_in_imported_aliases(text, anchors_by_pos, alias_marks, imported_anchors)
    try:
        loader = yaml.CSafeLoader(text)
        try:
            node = _first_document(loader)
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        _report_yaml_error(exc, path, sink, original)
        return YamlDocument(None, path, {})
    except yaml.YAMLError as exc:  # pragma: no cover - libyaml errors are marked
        sink.emit("MK010", f"YAML error: {exc}", SourceLocation(path))
        return YamlDocument(None, path, {})
    if node is None:
        sink.emit("MK004", "the file contains no YAML document", SourceLocation(path, 1, 1))
        return YamlDocument(None, path, {})
    anchor_names = _anchor_ids(node, anchors_by_pos)
    converter = _Converter(path, sink, anchor_names, stand_ins, numbers)
    root = converter.convert(node)
    anchors = {name: converter.memo[nid] for nid, name in anchor_names.items() if nid in converter.memo}
    # Without an alias nothing expands: the node count is bounded by the file size, and a large genuine
    # file (a 50 MB .body with inline meshes has 8 million scalars) is no alias bomb.
    problem = measure_expansion(root, expansion_limit) if alias_marks else None
    if problem is not None:
        kind, where = problem
        if kind == "recursive":
            # Point at the alias that closes the loop: the first alias of this anchor after it.
            loc = where.loc
            for name, line, col in alias_marks:
                if name == where.anchor and (line + 1, col + 1) > (where.loc.line, where.loc.col):
                    loc = SourceLocation(path, line + 1, col + 1)
                    break
            sink.emit(
                "MK014",
                f'alias "*{where.anchor}" refers to a node that contains it (a recursive structure)'
                if where.anchor
                else "an alias refers to a node that contains it (a recursive structure)",
                loc,
            )
        else:
            sink.emit(
                "MK015",
                f"expanding the aliases would produce more than {expansion_limit} nodes "
                "(an alias bomb); refusing the document",
                where.loc,
            )
        return YamlDocument(None, path, anchors)
    return YamlDocument(root, path, anchors)


_YAML_LINE_BREAK = re.compile("\r\n|[\r\n\x85\u2028\u2029]")


def _stand_in_imported_aliases(
    text: str,
    local: dict[tuple[int, int], str],
    aliases: list[tuple[str, int, int]],
    imported: dict[str, YNode],
) -> tuple[str, dict[tuple[int, int], YNode]]:
    """``text`` with each alias of an imported anchor turned into a plain scalar of the same length
    (``*NAME`` -> ``~NAME``, so every mark stays put), and the imported node for each such scalar.

    An alias uses the imported anchor only when no local anchor of its name comes before it, as in
    Choreonoid (local anchors take precedence)."""
    starts = [0] + [m.end() for m in _YAML_LINE_BREAK.finditer(text)]  # libyaml's line breaks
    chars = list(text)
    stand_ins: dict[tuple[int, int], YNode] = {}
    for name, line, col in aliases:
        if name not in imported or any(n == name and pos < (line, col) for pos, n in local.items()):
            continue
        offset = starts[line] + col if line < len(starts) else -1
        if 0 <= offset < len(chars) and chars[offset] == "*":
            chars[offset] = "~"
            stand_ins[(line, col)] = imported[name]
    return "".join(chars), stand_ins


def _first_document(loader: yaml.CSafeLoader) -> yaml.Node | None:
    # Choreonoid uses only the first document; later documents are not even parsed.
    if loader.check_node():
        return loader.get_node()
    return None


def _anchor_ids(root: yaml.Node, by_pos: dict[tuple[int, int], str]) -> dict[int, str]:
    if not by_pos:
        return {}
    found: dict[int, str] = {}
    seen: set[int] = set()
    stack = [root]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        name = by_pos.get((node.start_mark.line, node.start_mark.column))
        if name is not None:
            found[id(node)] = name
        if isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
        elif isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                stack.append(k)
                stack.append(v)
    return found


def _token_at(text: str, mark: yaml.Mark | None, sigil: str) -> str:
    """The anchor or alias name written at ``mark`` (libyaml's messages omit it)."""
    if mark is None:
        return "?"
    lines = text.splitlines()
    if mark.line >= len(lines):
        return "?"
    rest = lines[mark.line][mark.column :]
    start = rest.find(sigil)
    if start < 0:
        return "?"
    name = []
    for ch in rest[start + 1 :]:
        if ch.isspace() or ch in ",[]{}":
            break
        name.append(ch)
    return "".join(name) or "?"


def _report_yaml_error(exc: yaml.MarkedYAMLError, path: str, sink: DiagnosticSink, text: str) -> None:
    problem = exc.problem or "malformed YAML"
    mark = exc.problem_mark or exc.context_mark
    if "duplicate anchor" in f"{exc.context} {problem}":
        first = exc.context_mark
        name = _token_at(text, exc.problem_mark, "&")
        where = f" (first defined at line {first.line + 1})" if first else ""
        sink.emit(
            "MK012",
            f'anchor "{name}" is defined twice{where}; Choreonoid refuses repeated anchor names',
            _loc(path, exc.problem_mark),
        )
        return
    if "undefined alias" in problem:
        name = _token_at(text, exc.problem_mark, "*")
        sink.emit(
            "MK013",
            f'alias "*{name}" refers to an anchor that is not defined before it',
            _loc(path, exc.problem_mark),
        )
        return
    if exc.context and exc.context.startswith("while parsing a flow") and exc.context_mark is not None:
        mark = exc.context_mark  # the bracket that is never closed, not where the parser noticed
    message = problem
    if exc.context:
        message = f"{exc.context}: {problem}"
    sink.emit("MK010", f"YAML syntax error: {message}", _loc(path, mark))


def to_plain(node: YNode) -> object:
    """The node as plain Python data (dict/list/str) for JSON-Schema validation.

    Shared nodes stay shared objects. Call only on documents that passed :func:`measure_expansion`.
    """
    memo: dict[int, object] = {}

    def conv(n: YNode) -> object:
        done = memo.get(id(n))
        if done is not None:
            return done
        if isinstance(n, YScalar):
            return n.value
        if isinstance(n, YNumbers):
            texts: list[object] = list(n.texts())
            memo[id(n)] = texts
            return texts
        if isinstance(n, YSeq):
            out_list: list[object] = []
            memo[id(n)] = out_list
            out_list.extend(conv(c) for c in n.items)
            return out_list
        assert isinstance(n, YMap)
        out: dict[str, object] = {}
        memo[id(n)] = out
        for k, (_, v) in n.entries.items():
            out[k] = conv(v)
        return out

    return conv(node)


def locate(root: YNode, path: tuple[str | int, ...]) -> tuple[YNode | None, YScalar | None]:
    """Follow a JSON path (keys and indices) through the tree: (value node, key node of the last step)."""
    node: YNode | None = root
    key_node: YScalar | None = None
    for step in path:
        if isinstance(node, YMap) and isinstance(step, str):
            entry = node.entries.get(step)
            if entry is None:
                return node, key_node
            key_node, node = entry
        elif isinstance(node, YSeq) and isinstance(step, int) and 0 <= step < len(node.items):
            node = node.items[step]
            key_node = None
        else:
            return node, key_node
    return node, key_node
