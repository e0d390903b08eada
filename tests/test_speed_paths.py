"""The fast paths of issue 9 §3 give exactly what the slow ones gave.

* :class:`modelkit.xmlsource.LazyLocation`: a location found when first read equals, hashes, orders,
  prints, copies and pickles as the plain location found at once;
* the xacro deep clone (:class:`modelkit.formats.xacro.origins._Cloner`) makes the same tree as
  minidom's ``cloneNode(deep=True)``;
* ``xacro.substitution_args`` is imported without PyYAML, and PyYAML still works for it when needed;
* ``parse_numbers`` (one regular expression for the whole list) agrees with the item-by-item parse.
"""

from __future__ import annotations

import copy
import dataclasses
import pickle
import random
import subprocess
import sys
import xml.dom.minidom as minidom
from pathlib import Path
from typing import Any

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.xacro.origins import OriginMap, dom_elements
from modelkit.xmlsource import LazyLocation, parse_number, parse_numbers, parse_xml_bytes

TEXT = b"""<?xml version="1.0"?>
<robot name="r">
  <!-- a comment -->
  <link name="a"><inertial><mass value="1"/></inertial></link>
  <joint name="j" type="fixed">
    <parent link="a"/><child   link="b"/>
    <origin xyz="1 2 3"/>
  </joint>
  <link name="b">text <![CDATA[x]]></link>
</robot>
"""


def _doc():  # type: ignore[no-untyped-def]
    doc = parse_xml_bytes(TEXT, "r.urdf", DiagnosticSink())
    assert doc is not None
    return doc


def test_lazy_locations_equal_eager_ones() -> None:
    doc = _doc()
    cases = [(e, a) for e in doc.root.iter() if isinstance(e.tag, str) for a in (None, *e.keys(), "missing")]
    assert len(cases) > 10
    for element, attribute in cases:
        lazy = doc.loc(element, attribute)
        eager = doc.find_loc(element, attribute)
        assert type(lazy) is LazyLocation and type(eager) is SourceLocation
        assert eager.line > 0 and eager.col > 0
        assert (lazy.file, lazy.line, lazy.col) == (eager.file, eager.line, eager.col)
        assert lazy == eager and eager == lazy and hash(lazy) == hash(eager)
        assert str(lazy) == str(eager) and repr(lazy) == repr(eager)
        for other in (pickle.loads(pickle.dumps(lazy)), copy.copy(lazy), copy.deepcopy(lazy)):
            assert type(other) is SourceLocation and other == eager
        assert dataclasses.astuple(lazy) == dataclasses.astuple(eager)
        assert dataclasses.replace(lazy, line=99) == SourceLocation(eager.file, 99, eager.col)
        text_lazy, text_eager = doc.text_loc(element), doc.find_text_loc(element)
        assert text_lazy == text_eager and str(text_lazy) == str(text_eager)
    # a mixed list sorts as the plain locations do, whichever side is lazy
    mixed = [doc.loc(e, a) if i % 2 else doc.find_loc(e, a) for i, (e, a) in enumerate(cases)]
    plain = [doc.find_loc(e, a) for e, a in cases]
    random.Random(3).shuffle(mixed)
    assert [str(x) for x in sorted(mixed)] == [str(x) for x in sorted(plain)]
    assert doc.loc(doc.root) < SourceLocation("r.urdf", 99, 1) < doc.loc(doc.root).__class__("s", 0, 0)
    assert doc.loc(doc.root) != "r.urdf"


def _shape(node: minidom.Node) -> object:
    """Everything of a minidom subtree a writer or xacro can see, as plain data."""
    if node.nodeType == node.ELEMENT_NODE:
        assert isinstance(node, minidom.Element)
        attrs = [(a.nodeName, a.namespaceURI, a.localName, a.prefix, a.value, a.specified,
                  a.ownerElement is node, a.ownerDocument is node.ownerDocument)
                 for a in node.attributes.values()]
        by_ns = sorted((str(k), v.nodeName) for k, v in node._attrsNS.items())  # type: ignore[attr-defined]
        kids = node.childNodes
        links = [(k.parentNode is node, k.previousSibling is (kids[i - 1] if i else None),
                  k.nextSibling is (kids[i + 1] if i + 1 < len(kids) else None)) for i, k in enumerate(kids)]
        return ("E", node.nodeName, node.namespaceURI, node.prefix, node.localName, attrs, by_ns, links,
                [_shape(k) for k in kids])
    return (node.nodeType, getattr(node, "data", None), getattr(node, "target", None))


def test_xacro_clone_equals_minidom_clone() -> None:
    text = (b'<robot xmlns:xacro="http://ros.org/wiki/xacro" xmlns:g="urn:g" name="r">'
            b'<xacro:macro name="m" params="a *b"><link name="${a}" g:x="1" y=\'2\'>t<!--c--><?pi d?>'
            b'<![CDATA[z]]><visual><g:thing/></visual></link>\n  <xacro:insert_block name="b"/></xacro:macro>'
            b"</robot>")
    doc = parse_xml_bytes(text, "m.xacro", DiagnosticSink())
    assert doc is not None
    dom = minidom.parseString(text)
    top = dom.documentElement
    assert top is not None
    origins = OriginMap(1000)
    origins.adopt(top, doc)
    elements = list(dom_elements(top))
    for node in elements:
        ours: Any = node.cloneNode(True)
        theirs: Any = minidom.Element.cloneNode(node, True)
        assert _shape(ours) == _shape(theirs)
        assert ours.toxml() == theirs.toxml()
        assert ours.ownerDocument is dom and ours.parentNode is None
        for old, new in zip(dom_elements(node), dom_elements(ours), strict=True):
            assert type(new) is type(node)  # tracked, so that clones of clones keep their origins
            assert origins.get(new) is origins.get(old) is not None
    cloned = sum(len(list(dom_elements(node))) for node in elements)
    assert origins.clone_budget == 1000 - cloned


def test_substitution_args_without_yaml(tmp_path: Path) -> None:
    probe = (
        "import sys\n"
        "from modelkit.formats.xacro.expand import substitution_args\n"
        "sa = substitution_args()\n"
        "assert 'yaml' not in sys.modules and 'yaml.reader' not in sys.modules\n"
        "assert sa.convert_value('[1, 2]', 'str') == '[1, 2]'\n"
        "try:\n"
        "    sa.yaml.load('a: 1')\n"  # xacro calls it without a Loader: PyYAML 6 refuses, but it is PyYAML
        "except TypeError:\n"
        "    pass\n"
        "import yaml\n"
        "assert sa.yaml.parser.ParserError is yaml.parser.ParserError and sys.modules['yaml'] is yaml\n"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def test_parse_numbers_agrees_with_items() -> None:
    def by_items(text: str) -> list[float] | None:
        out = []
        for item in text.split():
            value = parse_number(item)
            if value is None:
                return None
            out.append(value)
        return out

    rng = random.Random(7)
    alphabet = "0123456789.eE+- \t\n\u00a0\x1cx_\u0663"
    cases = ["", " ", "1 2 3", " 1e5  -2.  .5 ", "1..2", "inf", "1 nan", "1_0", "\x1c1\x1c2", "1e", "+.5e-3"]
    cases += ["".join(rng.choice(alphabet) for _ in range(rng.randint(0, 14))) for _ in range(20000)]
    for text in cases:
        assert parse_numbers(text) == by_items(text), repr(text)
