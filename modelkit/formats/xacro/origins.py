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
from xml.dom import Node

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
                clone: Any = minidom.Element.cloneNode(self, deep)
                count = 0
                for old, new in zip(dom_elements(self), dom_elements(clone), strict=True):
                    object.__setattr__(new, "__class__", TrackedElement)
                    origin = origins.get(old)
                    if origin is not None:
                        origins[new] = origin
                    count += 1
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

    def get(self, node: minidom.Node | None) -> Origin | None:
        """The origin of ``node``, else of its nearest ancestor that has one."""
        while node is not None:
            origin = self._origins.get(node)  # type: ignore[call-overload]
            if origin is not None:
                return origin
            node = node.parentNode
        return None
