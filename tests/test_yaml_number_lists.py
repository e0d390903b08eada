"""The compact path for long number lists (``modelkit.yamltree.YNumbers``) gives exactly what composing a
node per number gives: the same tree (values, locations, anchors) and the same diagnostics, on the tricky
places a blanked list can sit (strings, comments, block scalars, aliases, CRLF, errors after it, limits)
and on every `.body` file of the tests and the corpus (with the threshold lowered to two items)."""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.diagnostics import DiagnosticSink
from modelkit.formats.body.values import numbers
from modelkit.yamltree import YMap, YNode, YNumbers, YScalar, YSeq, parse_yaml, to_plain

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "corpus"


def _shape(node: YNode | None, seen: dict[int, int]) -> object:
    if node is None:
        return None
    if id(node) in seen:  # shared (aliased) node
        return ("shared", seen[id(node)])
    seen[id(node)] = len(seen)
    head = (type(node).__name__.replace("YNumbers", "YSeq"), str(node.loc), node.anchor)
    if isinstance(node, YScalar):
        return (*head, node.value, node.plain)
    if isinstance(node, YSeq):
        return (*head, [_shape(item, seen) for item in node.items])
    assert isinstance(node, YMap)
    return (*head, sorted(node.merged_keys),
            [(k, str(key.loc), _shape(value, seen)) for k, (key, value) in node.entries.items()])


Seen = tuple[object, list[str]]


def _both(text: str, **limits: int) -> tuple[Seen, Seen, YNode | None]:
    out = []
    roots = []
    for fast in (2, None):
        sink = DiagnosticSink()
        doc = parse_yaml(text, "t.body", sink, fast_lists=fast, **limits)  # type: ignore[arg-type]
        roots.append(doc.root)
        out.append((_shape(doc.root, {}), sorted(f"{d.code} {d.location} {d.message}" for d in sink.items)))
    return out[0], out[1], roots[0]


LONG = ", ".join(f"{i * 0.25 - 3:g}" for i in range(40))
CASES = {
    "block": f"a: [{LONG}]\nb: 1\n",
    "multiline-crlf": "a: [1, 2,\r\n   3.5, -4e2,\r\n .5]\r\nb: x\r\n",
    "lone-cr": "a: [1, 2,\r   3, 4]\rb: [5, 6]\r",
    "quoted": f'a: "[{LONG}]"\nb: [1, 2]\n',
    "single-quoted-multiline": "a: '[1, 2,\n  3, 4]'\n",
    "comment": f"# [{LONG}]\na: [1, 2, 3]\n",
    "block-scalar": f"a: |\n  [{LONG}]\nb: [3, 4]\n",
    "plain-scalar": "a: x[1, 2, 3]\nb: [1, 2]\n",
    "anchor-alias": f"a: &v [{LONG}]\nb: *v\nc: [*v, *v]\n",
    "nested": "a: [[1, 2], [3, 4, 5], [6.5, 7]]\n",
    "not-numbers": "a: [1, 2, x, 4]\nb: [1, 2, 0x10]\nc: [1 2, 3]\nd: [1, 2, ]\n",
    "error-after": f"a: [{LONG}]\nb: [1, 2\n",
    "error-inside-quoted": f'a: "[{LONG}]\nb: [1, 2]\n',
    "duplicate-key": f"a: [{LONG}]\na: [1, 2]\n",
    "undefined-alias": f"a: [{LONG}]\nb: *nothing\n",
    "tabs": "a: [1,\t2, 3]\n",
    "second-document": "a: [1, 2]\n---\nb: [3, 4, x\n",
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_compact_lists_change_nothing(name: str) -> None:
    fast, slow, _ = _both(CASES[name])
    assert fast == slow


def test_the_list_limits_count_compact_lists() -> None:
    text = "links: [1, 2, 3, 4]\nother: [1, 2, 3, 4, 5, 6]\n"
    for limits in ({"max_list_items": 5}, {"max_list_items": 5, "top_limits": {"links": 3}},
                   {"max_list_items": 6}, {"expansion_limit": 5}):
        fast, slow, _ = _both(text, **limits)
        assert fast == slow, limits
    fast, slow, _ = _both(f"a: &v [{LONG}]\nb: [*v, *v, *v]\n", expansion_limit=100)
    assert fast == slow and any("MK015" in d for d in fast[1])


def test_the_compact_list_is_used_and_reads_the_same_numbers() -> None:
    sink = DiagnosticSink()
    doc = parse_yaml(f"a: [{LONG}]\n", "t.body", sink, fast_lists=2)
    assert isinstance(doc.root, YMap)
    node = doc.root.get("a")
    assert isinstance(node, YNumbers)
    assert numbers(node) == [float(x) for x in LONG.split(", ")]
    assert to_plain(doc.root) == {"a": LONG.split(", ")}


def _body_files() -> list[Path]:
    files = sorted((ROOT / "tests").rglob("*.body")) + sorted((ROOT / "samples").rglob("*.body"))
    if CORPUS.is_dir():
        files += sorted(CORPUS.rglob("*.body"))
    return files


@pytest.mark.parametrize("path", _body_files(), ids=lambda p: p.name)
def test_real_files_read_the_same(path: Path) -> None:
    try:
        text = path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, OSError):
        pytest.skip("not UTF-8 text")
    fast, slow, _ = _both(text)
    assert fast == slow
