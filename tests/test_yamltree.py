"""The YAML layer: positions, Choreonoid's merge semantics, and refusing hostile documents."""

from __future__ import annotations

import time

from modelkit.diagnostics import DiagnosticSink
from modelkit.yamltree import YMap, YScalar, YSeq, decode_text, locate, parse_yaml, to_plain


def parse(text: str) -> tuple[object, list[tuple[str, int, int]]]:
    sink = DiagnosticSink()
    doc = parse_yaml(text, "t.yaml", sink)
    found = [(d.code, d.location.line, d.location.col) for d in sink.items if d.location]
    return doc.root, found


def test_scalars_stay_strings_with_positions() -> None:
    root, found = parse("a: 1e-5\nb: [ 0.5,\t0.25 ]\nc: 'x'\n")
    assert found == []
    assert isinstance(root, YMap)
    a = root.get("a")
    assert isinstance(a, YScalar) and a.value == "1e-5" and (a.loc.line, a.loc.col) == (1, 4)
    b = root.get("b")
    assert isinstance(b, YSeq) and [i.value for i in b.items if isinstance(i, YScalar)] == ["0.5", "0.25"]
    assert (b.items[1].loc.line, b.items[1].loc.col) == (2, 11)
    c = root.get("c")
    assert isinstance(c, YScalar) and not c.plain


def test_merge_keys_explicit_wins_and_earlier_merge_wins() -> None:
    root, found = parse("A: &A {x: 1, y: 1}\nB: &B {x: 2, z: 2}\nm: {<<: [*A, *B], y: 3}\n")
    assert found == []
    assert to_plain(root)["m"] == {"y": "3", "x": "1", "z": "2"}  # type: ignore[index]


def test_aliases_are_shared_not_copied() -> None:
    root, _ = parse("a: &x [1, 2]\nb: *x\n")
    assert isinstance(root, YMap)
    assert root.get("a") is root.get("b")


def test_duplicate_key_reported_at_second_occurrence() -> None:
    _, found = parse("a: 1\nb: 2\na: 3\n")
    assert found == [("MK011", 3, 1)]


def test_duplicate_anchor_and_undefined_alias() -> None:
    assert parse("a: &x 1\nb: &x 2\n")[1] == [("MK012", 2, 4)]
    assert parse("a: *nope\n")[1] == [("MK013", 1, 4)]


def test_recursive_alias_refused() -> None:
    root, found = parse("a: &r [1, *r]\n")
    assert root is None and found[0][0] == "MK014"


def test_alias_bomb_refused_quickly() -> None:
    lines = ["l0: &l0 [a, a, a, a, a, a, a, a, a, a]"]
    for i in range(1, 12):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]")
    start = time.perf_counter()
    root, found = parse("\n".join(lines) + "\n")
    elapsed = time.perf_counter() - start
    assert root is None and found[0][0] == "MK015"
    assert elapsed < 5.0  # hang guard only: 10^12 nodes would never finish


def test_deep_nesting_refused_without_recursion_error() -> None:
    root, found = parse("a: " + "[" * 50000 + "]" * 50000 + "\n")
    assert root is None and found[0][0] == "MK010"


def test_deep_nesting_mark_is_ours_not_libyamls() -> None:
    # The refusal points at the bracket that opens level 129 (top mapping = level 1), whatever
    # nesting limit the installed libyaml has of its own (PyYAML 6.0.4's stops at 1000, ahead).
    for depth in (200, 1000, 5000):
        _, found = parse("a: " + "[" * depth + "]" * depth + "\n")
        assert found[0] == ("MK010", 1, 3 + 128), depth
    block = "".join(" " * i + "k:\n" for i in range(140))
    _, found = parse(block)
    assert found[0] == ("MK010", 129, 129)


def test_syntax_error_has_position() -> None:
    _, found = parse("a: [1, 2\nb: 3\n")
    assert found[0] == ("MK010", 1, 4)  # the bracket that is never closed


def test_merge_of_scalar_is_an_error() -> None:
    _, found = parse("a: {<<: 5}\n")
    assert found == [("MK016", 1, 9)]


def test_encoding_checks() -> None:
    sink = DiagnosticSink()
    assert decode_text(b"a: 1\x00\n", "f", sink) is None and sink.items[0].code == "MK003"
    sink = DiagnosticSink()
    assert decode_text(b"a: 1\nb: \xff\n", "f", sink) is None
    assert (sink.items[0].code, sink.items[0].location.line) == ("MK003", 2)  # type: ignore[union-attr]
    assert decode_text("a: 1\n".encode("utf-16"), "f", DiagnosticSink()) == "a: 1\n"


def test_locate_follows_json_paths() -> None:
    root, _ = parse("links:\n  - name: A\n    mass: x\n")
    assert root is not None
    value, key = locate(root, ("links", 0, "mass"))  # type: ignore[arg-type]
    assert isinstance(value, YScalar) and (value.loc.line, value.loc.col) == (3, 11)
    assert key is not None and (key.loc.line, key.loc.col) == (3, 5)
