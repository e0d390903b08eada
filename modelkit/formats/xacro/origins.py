"""Where each element of an xacro expansion comes from.

xacro works on ``xml.dom.minidom`` trees and knows no line numbers. Each source file (the top file
and every included one) is first parsed by :mod:`modelkit.xmlsource`, which knows exact positions,
then by minidom; the two parses see the same elements in the same document order, so each minidom
element is paired with its lxml twin and recorded in an :class:`OriginMap`.

Macros and blocks are expanded by ``cloneNode``. Rather than annotating the source with temporary
attributes (which xacro would evaluate, and which a macro call or an ``xacro:property`` would
reject as unknown parameters), the paired elements get a subclass of minidom's ``Element`` whose
``cloneNode`` copies the origins onto the clone. An element produced by a macro therefore points at
the line of the macro body that wrote it, and an inserted block at the call that passed it.
"""

from __future__ import annotations

import xml.dom.minidom as minidom
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any
from xml.dom import Node, UserDataHandler

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.diagnostics import SourceLocation
from modelkit.xmlsource import XmlDocument


class ExpansionTooLarge(Exception):
    """Macro expansion cloned more elements than the budget allows (a macro bomb)."""


@dataclass(frozen=True)
class Origin:
    """An element of a source file: the parsed file and the element in it."""

    doc: XmlDocument
    element: Element

    def loc(self, attribute: str | None = None) -> SourceLocation:
        return self.doc.loc(self.element, attribute)


def dom_elements(node: minidom.Node) -> Iterator[minidom.Element]:
    """``node`` (when it is an element) and its descendant elements, in document order."""
    stack = [node]
    while stack:
        current = stack.pop()
        if current.nodeType == Node.ELEMENT_NODE:
            yield current  # type: ignore[misc]
        stack.extend(reversed(current.childNodes))


def source_elements(root: Element) -> list[Element]:
    """The elements of a parsed source file in document order (comments and PIs left out)."""
    return [e for e in root.iter() if isinstance(e.tag, str)]


def attributes(element: Element) -> list[tuple[str, str]]:
    """The element's attributes as (name, value) strings, in document order."""
    return [(str(k), str(v)) for k, v in element.attrib.items()]


def tag_name(element: Element) -> str:
    """The element's name as written (``xacro:macro``, ``link``): what minidom calls its tagName."""
    local = etree.QName(element).localname
    return f"{element.prefix}:{local}" if element.prefix else local


def _text(data: str) -> Any:
    """``minidom.Text`` holding ``data`` (what ``Document.createTextNode`` makes, without the owner), made
    without the chain of ``__init__`` calls and property setters."""
    text: Any = _Text.__new__(_Text)
    text._data = data
    text.ownerDocument = text.parentNode = text.previousSibling = text.nextSibling = None
    return text


def _attr(qualified: str, namespace: str | None, local: str, prefix: str | None, value: str) -> Any:
    """``minidom.Attr(qualified, namespace, local, prefix)`` with ``value`` set, as minidom makes it (the
    value also in its one child text node), without the property setters."""
    attr: Any = _Attr.__new__(_Attr)
    attr.ownerElement = None
    attr._name = qualified
    attr.namespaceURI = namespace
    attr._prefix = prefix
    attr._localName = local
    children: Any = _NodeList()
    children.append(_text(value))
    attr.childNodes = children
    attr._value = value
    return attr


_Text: Any = minidom.Text
_Attr: Any = minidom.Attr
_NodeList: Any = minidom.NodeList  # type: ignore[attr-defined]
_new = object.__new__
_TEXT_NODE = Node.TEXT_NODE


class _Cloner:
    """A deep copy of a minidom subtree, equal to ``Node.cloneNode(deep=True)`` (same node types, names,
    namespaces, prefixes, attribute order and values, text), in one pass that also makes every copied
    element a tracked one and copies its origin. minidom's own clone sets each attribute through
    ``setAttributeNS`` (look-ups, checks and cache clearing meant for an element in use) and needs a
    second walk to copy the origins: together two fifths of a large expansion."""

    def __init__(
        self, document: Any, element_class: type[minidom.Element], origins: dict[Any, Origin]
    ) -> None:
        self.document = document
        self.element_class = element_class
        self.origins = origins
        self.count = 0

    def clone(self, node: Any) -> Any:
        kind = node.nodeType
        doc = self.document
        if kind == Node.ELEMENT_NODE:
            name = node.nodeName
            prefix_of = name.split(":", 1)[0] if ":" in name else None
            new: Any = self.element_class(name, node.namespaceURI, prefix_of)
            new.ownerDocument = doc
            if node._attrs:
                by_name: dict[str, minidom.Attr] = {}
                by_namespace: dict[tuple[str | None, str], minidom.Attr] = {}
                for attr in node._attrs.values():
                    qualified = attr.nodeName
                    prefix, local = qualified.split(":", 1) if ":" in qualified else (None, qualified)
                    copy = _attr(qualified, attr.namespaceURI, local, prefix, attr._value)
                    copy.ownerDocument = doc
                    copy.specified = attr.specified
                    copy.ownerElement = new
                    by_name[qualified] = copy
                    by_namespace[(attr.namespaceURI, local)] = copy
                new._attrs = by_name
                new._attrsNS = by_namespace
            origin = self.origins.get(node)
            if origin is not None:
                self.origins[new] = origin
            self.count += 1
            children = new.childNodes
            previous = None
            for child in node.childNodes:
                if child.nodeType == _TEXT_NODE:  # most children: made here, as clone() would
                    copied: Any = _new(_Text)
                    copied._data = child._data
                    copied.ownerDocument = doc
                    copied.nextSibling = None
                    if hasattr(child, "_user_data"):
                        child._call_user_data_handler(UserDataHandler.NODE_CLONED, child, copied)
                else:
                    copied = self.clone(child)
                copied.parentNode = new
                copied.previousSibling = previous
                if previous is not None:
                    previous.nextSibling = copied
                children.append(copied)
                previous = copied
        elif kind == Node.TEXT_NODE:
            new = _text(node._data)
            new.ownerDocument = doc
        elif kind == Node.COMMENT_NODE:
            new = doc.createComment(node.data)
        elif kind == Node.CDATA_SECTION_NODE:
            new = doc.createCDATASection(node.data)
        elif kind == Node.PROCESSING_INSTRUCTION_NODE:
            new = doc.createProcessingInstruction(node.target, node.data)
        else:  # nothing else occurs inside an element; minidom's own clone if it ever does
            return node.cloneNode(True)
        if hasattr(node, "_user_data"):  # as minidom: the node's user-data handlers hear of the clone
            node._call_user_data_handler(UserDataHandler.NODE_CLONED, node, new)
        return new


class OriginMap:
    """minidom element → :class:`Origin`, kept through xacro's clones."""

    def __init__(self, clone_budget: int) -> None:
        self._origins: dict[minidom.Element, Origin] = {}
        self.clone_budget = clone_budget
        self._element_class = self._tracking_class()

    def _tracking_class(self) -> type[minidom.Element]:
        origins = self._origins
        owner = self

        class TrackedElement(minidom.Element):
            __slots__ = ()

            def cloneNode(self, deep: bool) -> Any:
                if not deep:
                    clone: Any = minidom.Element.cloneNode(self, deep)
                    object.__setattr__(clone, "__class__", TrackedElement)
                    count = 1
                    origin = origins.get(self)
                    if origin is not None:
                        origins[clone] = origin
                else:
                    cloner = _Cloner(self.ownerDocument, TrackedElement, origins)
                    clone = cloner.clone(self)
                    count = cloner.count
                owner.clone_budget -= count
                if owner.clone_budget < 0:
                    raise ExpansionTooLarge()
                return clone

        return TrackedElement

    def adopt(self, dom_root: minidom.Element, doc: XmlDocument) -> list[tuple[minidom.Element, Element]]:
        """Pair a freshly parsed minidom tree with the same file parsed by xmlsource; return the pairs."""
        dom = list(dom_elements(dom_root))
        src = source_elements(doc.root)
        if len(dom) != len(src):  # both parsers saw the same text; never expected
            src = [doc.root] * len(dom)
        for node, element in zip(dom, src, strict=True):
            object.__setattr__(node, "__class__", self._element_class)
            self._origins[node] = Origin(doc, element)
        return list(zip(dom, src, strict=True))

    def release(self, others: list[minidom.Element]) -> None:
        """Take apart every tracked element and ``others`` (the expansion's own), so that reference counting
        frees the DOMs of the run; the map is empty afterwards.

        A minidom tree is a web of cycles (parent and child, siblings, attribute and owner, document and
        root), and the map keeps every element ever parsed or cloned reachable through the tracking class.
        Left to the cyclic collector, a large expansion's 400,000 objects cost one full collection (a sixth
        of the validation of a 1,200-link file); taking the links apart costs a fraction of that.
        Nothing may use the elements afterwards.
        """
        origins = self._origins
        documents: set[int] = set()
        kept: list[Any] = []
        tracked: Any = origins
        untracked: list[Any] = [e for e in others if e not in origins]
        for elements in (tracked, untracked):
            for element in elements:
                element._attrs = element._attrsNS = None  # the attributes' owner links then make no cycle
                children = element.childNodes
                if children:
                    for child in children:
                        child.parentNode = child.previousSibling = child.nextSibling = None
                    del children[:]
                element.parentNode = element.previousSibling = element.nextSibling = None
                document = element.ownerDocument
                if document is not None and id(document) not in documents:
                    documents.add(id(document))
                    kept.append(document)
        for document in kept:
            for child in document.childNodes:
                child.parentNode = child.previousSibling = child.nextSibling = None
            del document.childNodes[:]
            document._id_cache = {}
            document._id_search_stack = None
        origins.clear()

    def get(self, node: minidom.Node | None) -> Origin | None:
        """The origin of ``node``, else of its nearest ancestor that has one."""
        while node is not None:
            origin = self._origins.get(node)  # type: ignore[call-overload]
            if origin is not None:
                return origin
            node = node.parentNode
        return None
