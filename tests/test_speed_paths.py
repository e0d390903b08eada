"""The fast paths of issue 9 §3 give exactly what the slow ones gave.

* :class:`modelkit.xmlsource.LazyLocation`: a location found when first read equals, hashes, orders,
  prints, copies and pickles as the plain location found at once (a deep copy shares it, unresolved);
* the xacro deep clone (:class:`modelkit.formats.xacro.origins._Cloner`) makes the same tree as
  minidom's ``cloneNode(deep=True)``;
* ``xacro.substitution_args`` is imported without PyYAML, and PyYAML still works for it when needed;
* ``parse_numbers`` (one regular expression for the whole list) agrees with the item-by-item parse;
* an xacro expansion is printed (:func:`modelkit.formats.xacro.pretty.pretty_xml`) exactly as xacro prints
  it, and leaves no cyclic garbage (:meth:`OriginMap.release`);
* kept ``<gazebo>``/``<transmission>`` blocks (:class:`modelkit.formats.urdf.extensions.KeptBlock`) read as
  the plain dicts with their canonical XML made at once.
"""

from __future__ import annotations

import copy
import dataclasses
import gc
import json
import pickle
import random
import subprocess
import sys
import xml.dom.minidom as minidom
from pathlib import Path
from typing import Any

import pytest

from modelkit.api import validate
from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.urdf.extensions import KeptBlock, canonical_xml
from modelkit.formats.xacro import expand as xacro_expand
from modelkit.formats.xacro.origins import OriginMap, dom_elements
from modelkit.formats.xacro.pretty import pretty_xml
from modelkit.formats.xacro.reader import expand_xacro
from modelkit.xmlsource import LazyLocation, parse_number, parse_numbers, parse_xml_bytes
from tests.conftest import CORPUS, REPO

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
        for other in (pickle.loads(pickle.dumps(lazy)), copy.copy(lazy)):
            assert type(other) is SourceLocation and other == eager
        # a location never changes: a deep copy (convert copies the model it writes) shares it unresolved
        fresh = doc.loc(element, attribute)
        assert copy.deepcopy(fresh) is fresh and "_pending" in fresh.__dict__
        assert copy.deepcopy(fresh) == eager
        assert copy.deepcopy(eager) is eager
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


def _xacro_files() -> list[Path]:
    roots = (REPO / "samples", REPO / "tests", CORPUS)
    return sorted(p for root in roots if root.is_dir() for p in root.rglob("*.xacro"))


def test_xacro_text_as_xacro_prints_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every xacro file of the samples, tests and corpus expands to the same text and findings whether the
    expansion is printed by :func:`pretty_xml` or by minidom's ``toprettyxml`` with xacro's writer."""
    files = _xacro_files()
    assert len(files) >= 30
    ours = [expand_xacro(path) for path in files]
    monkeypatch.setattr(xacro_expand, "pretty_xml", lambda doc: doc.toprettyxml(indent="  "))
    theirs = [expand_xacro(path) for path in files]
    assert sum(text is not None for text, _ in ours) >= 30
    for path, (text, found), (text_x, found_x) in zip(files, ours, theirs, strict=True):
        assert text == text_x, path
        assert [repr(d) for d in found] == [repr(d) for d in found_x], path
    tricky = minidom.parseString(
        b'<?xml version="1.0"?><!--top--><r a="1&amp;&lt;&quot;" b="x\ty"><!--c--><?pi d?>t&amp;'
        b'<![CDATA[z]]><v/>\n  <w>only &gt;</w><x>  </x><y><!--k--></y><z><![CDATA[q]]></z>tail</r><!--end-->'
    )
    import xacro  # noqa: F401  (its element writer is what pretty_xml follows)

    assert pretty_xml(tricky) == tricky.toprettyxml(indent="  ")


def test_xacro_expansion_leaves_no_cyclic_garbage(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = "".join(f'<xacro:part n="l{i}"><origin xyz="{i} 0 0"/></xacro:part>' for i in range(60))
    model = tmp_path / "m.urdf.xacro"
    model.write_text(
        '<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro"><xacro:macro name="part" params="n *o">'
        '<link name="${n}"><visual><xacro:insert_block name="o"/><geometry><box size="1 1 1"/></geometry>'
        '</visual></link><gazebo reference="${n}"><mu1>1</mu1></gazebo></xacro:macro>'
        f"{calls}</robot>"
    )

    def garbage() -> int:
        collecting = gc.isenabled()
        gc.disable()
        try:
            gc.collect()
            text, _ = expand_xacro(model)
            assert text is not None and text.count("<link ") == 60
            return gc.collect()
        finally:
            if collecting:
                gc.enable()

    assert garbage() < 100  # the tracking class and xacro's own few cycles
    monkeypatch.setattr(OriginMap, "release", lambda self, others: None)
    assert garbage() > 2000  # the DOMs, left to the collector


def test_kept_blocks_read_as_plain_dicts(tmp_path: Path) -> None:
    model = tmp_path / "r.urdf"
    model.write_text(
        '<robot name="r" xmlns:g="urn:g"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit effort="1" velocity="1"/>'
        '</joint><gazebo reference="a"><mu1>0.5</mu1><g:x y="1">t</g:x></gazebo><gazebo><static>true</static>'
        '</gazebo><transmission name="t"><type>T</type><joint name="j"/><actuator name="m"/></transmission>'
        "</robot>"
    )
    from lxml import etree

    root = etree.parse(str(model)).getroot()
    blocks: dict[str | None, Any] = {
        "a": root.find("gazebo"), None: root.findall("gazebo")[1], "t": root.find("transmission")
    }

    def fresh() -> list[tuple[KeptBlock, dict[str, Any]]]:
        robot = validate(model).robot
        link = robot.link("a") if robot is not None else None
        assert robot is not None and link is not None
        kept = [(link.extras["gazebo"][0], "a"), (robot.extras["gazebo"][0], None),
                (robot.extras["transmissions"][0], "t")]
        out = []
        for entry, key in kept:
            assert type(entry) is KeptBlock
            plain = dict(dict.items(entry))
            plain["xml"] = canonical_xml(blocks[key])
            out.append((entry, plain))
        return out

    assert next(e for e, _ in fresh())["mu1"] == 0.5
    readers: list[Any] = [
        dict, lambda b: {**b}, copy.copy, copy.deepcopy, lambda b: pickle.loads(pickle.dumps(b)),
        lambda b: json.loads(json.dumps(b, default=str)), lambda b: dict(b.items()), lambda b: b.copy(),
        lambda b: dict(zip(b.keys(), b.values(), strict=True)), lambda b: {k: b[k] for k in b},
        lambda b: {k: b.get(k) for k in b}, lambda b: b | {}, lambda b: {} | b,
    ]
    for index, read in enumerate(readers):
        for entry, plain in fresh():
            got = read(entry)
            assert type(got) is dict
            assert got == (json.loads(json.dumps(plain, default=str)) if index == 5 else plain)
    for entry, plain in fresh():
        assert entry == plain and plain == entry and (entry != plain) is False and list(entry) == list(plain)
        assert repr(entry) == repr(plain) and "xml" in entry and len(entry) == len(plain)
    for (entry, _plain), (other, _) in zip(fresh(), fresh(), strict=True):
        assert entry == other
