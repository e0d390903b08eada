"""Source positions of :mod:`modelkit.xmlsource`: elements, attributes, text, and the refusals."""

from __future__ import annotations

from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.xmlsource import (
    XmlDocument,
    location_at,
    mask_markup,
    parse_xml_bytes,
    read_xml,
    tag_end,
)


def _parse(text: str) -> XmlDocument:
    sink = DiagnosticSink()
    doc = parse_xml_bytes(text.encode("utf-8"), "t.xml", sink)
    assert doc is not None, sink.items
    assert not sink.items
    return doc


def _at(doc: XmlDocument, tag: str, attribute: str | None = None, nth: int = 0) -> tuple[int, int]:
    element = list(doc.root.iter(tag))[nth]
    where = doc.loc(element, attribute)
    assert where.file == "t.xml"
    return where.line, where.col


def test_element_and_attribute_positions_on_one_line() -> None:
    doc = _parse('<robot name="r"><link name="a"/><link  name="b"/></robot>')
    assert _at(doc, "robot") == (1, 1)
    assert _at(doc, "robot", "name") == (1, 8)
    assert _at(doc, "link", nth=0) == (1, 17)
    assert _at(doc, "link", "name", nth=0) == (1, 23)
    assert _at(doc, "link", nth=1) == (1, 33)
    assert _at(doc, "link", "name", nth=1) == (1, 40)


def test_multi_line_start_tag() -> None:
    doc = _parse('<robot name="r">\n  <joint\n      name="j"\n\ttype = "fixed"\n  >\n  </joint>\n</robot>\n')
    assert _at(doc, "joint") == (2, 3)
    assert _at(doc, "joint", "name") == (3, 7)
    assert _at(doc, "joint", "type") == (4, 2)


def test_attribute_written_inside_another_value() -> None:
    doc = _parse("<robot>\n  <link note=\"a name=b\" name='real'/>\n  <link note='type=x'/>\n</robot>")
    assert _at(doc, "link", "name", nth=0) == (2, 25)
    assert _at(doc, "link", "note", nth=0) == (2, 9)
    # "type" appears only inside a value: the attribute is absent, so the element is the place
    assert _at(doc, "link", "type", nth=1) == (3, 3)


def test_absent_attribute_is_placed_at_the_element() -> None:
    doc = _parse('<robot>\n    <link name="a"/>\n</robot>')
    assert _at(doc, "link", "mass") == _at(doc, "link") == (2, 5)


def test_prefixed_attribute_is_not_taken_for_the_plain_one() -> None:
    doc = _parse('<robot xmlns:x="urn:x">\n  <link x:name="p" name="a"/>\n</robot>')
    assert _at(doc, "link", "name") == (2, 20)


def test_comments_cdata_and_instructions_do_not_shift_elements() -> None:
    text = (
        '<?xml version="1.0"?>\n'
        "<!-- <link name=\"commented\"/> -->\n"
        "<robot>\n"
        "  <![CDATA[ <joint name=\"x\"> ]]>\n"
        "  <?pi <link?>\n"
        '  <link name="real"/> <!-- <link -->\n'
        "</robot>\n"
    )
    doc = _parse(text)
    assert len(list(doc.root.iter("link"))) == 1
    assert _at(doc, "robot") == (3, 1)
    assert _at(doc, "link") == (6, 3)
    assert _at(doc, "link", "name") == (6, 9)


def test_text_loc_is_after_the_start_tag() -> None:
    doc = _parse('<sdf>\n  <pose a=">">\n    1 2 3 0 0 0</pose>\n</sdf>')
    pose = doc.root.find("pose")
    assert pose is not None
    assert doc.text_loc(pose) == SourceLocation("t.xml", 3, 5)


def test_entity_declarations_are_refused_with_their_position() -> None:
    text = '<?xml version="1.0"?>\n<!DOCTYPE r [\n  <!ENTITY a "aaaa">\n]>\n<r>&a;</r>\n'
    sink = DiagnosticSink()
    assert parse_xml_bytes(text.encode(), "t.xml", sink) is None
    assert [(d.code, d.location) for d in sink.items] == [("MK021", SourceLocation("t.xml", 3, 3))]


def test_malformed_xml_has_line_and_column() -> None:
    sink = DiagnosticSink()
    assert parse_xml_bytes(b"<robot>\n  <link>\n</robot>\n", "t.xml", sink) is None
    assert len(sink.items) == 1
    found = sink.items[0]
    assert found.code == "MK020"
    assert found.message.startswith("malformed XML: ")
    assert found.location is not None
    assert (found.location.line, found.location.col) == (3, 9)


def test_empty_document() -> None:
    sink = DiagnosticSink()
    assert parse_xml_bytes(b"  \n", "t.xml", sink) is None
    assert [(d.code, d.location) for d in sink.items] == [("MK020", SourceLocation("t.xml"))]


def test_read_xml_reports_directories_and_size(tmp_path: Path) -> None:
    sink = DiagnosticSink()
    assert read_xml(tmp_path, sink) is None
    assert [d.code for d in sink.items] == ["MK001"]
    big = tmp_path / "big.xml"
    big.write_text("<r>" + " " * 100 + "</r>")
    sink = DiagnosticSink()
    assert read_xml(big, sink, max_bytes=50) is None
    assert [d.code for d in sink.items] == ["MK002"]
    sink = DiagnosticSink()
    doc = read_xml(big, sink, display="shown.xml")
    assert doc is not None and not sink.items
    assert doc.loc(doc.root) == SourceLocation("shown.xml", 1, 1)


def test_helpers() -> None:
    text = 'ab\n<!-- <x> -->\n<y a=">" b=\'>\'>'
    masked = mask_markup(text)
    assert len(masked) == len(text)
    assert "<x>" not in masked
    start = text.index("<y")
    assert tag_end(text, start) == len(text) - 1
    assert location_at(text, "f", start) == SourceLocation("f", 3, 1)
    assert location_at(text, "f", 0) == SourceLocation("f", 1, 1)
    assert location_at(text, "f", 4) == SourceLocation("f", 2, 2)
