"""Where MuJoCo's objects are written: the MJCF text, with ``<include>`` files spliced in.

MuJoCo keeps no source positions after parsing (only compile errors name a line). modelkit parses
the same files with :mod:`modelkit.xmlsource` and pairs MuJoCo's bodies, joints and geoms with
their XML elements: by name when the object has one, else by order among its siblings, which
MuJoCo keeps as written. When the pairing is not safe (``<replicate>``, ``<attach>``, counts that
disagree) an object points at its nearest located ancestor instead.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.textio import real_path
from modelkit.xmlsource import XmlDocument, read_xml

# Containers MuJoCo flattens into their body: their children belong to the enclosing body.
TRANSPARENT = frozenset({"frame"})
BODY_CHILDREN = {"body": ("body",), "joint": ("joint", "freejoint"), "geom": ("geom",), "site": ("site",)}


@dataclass(frozen=True, eq=False)
class Placed:
    """An element and the document that holds it."""

    doc: XmlDocument
    el: Element

    def loc(self, attribute: str | None = None) -> SourceLocation:
        return self.doc.loc(self.el, attribute)

    @property
    def tag(self) -> str:
        return str(self.el.tag)


@dataclass
class SourceIndex:
    """The main document and its included documents, walked as one expanded tree."""

    main: XmlDocument
    base_dir: Path
    sink: DiagnosticSink
    max_bytes: int
    _included: dict[Path, XmlDocument | None] = field(default_factory=dict)
    _owner: dict[Path, Element | None] = field(default_factory=dict)  # file → its first <include>

    # -- expansion --------------------------------------------------------------------------

    def children(self, parent: Placed, keep_includes: bool = False) -> Iterator[Placed]:
        """The element children of ``parent``, with each ``<include>`` replaced by the included
        file's top-level children (MuJoCo's semantics).

        MuJoCo refuses a file included twice (or including itself); modelkit expands each file at
        its first ``<include>`` only, so a malicious include graph cannot blow up the walk.
        ``keep_includes`` also yields each ``<include>`` element, before what it brings in.
        """
        for child in parent.el:
            if not isinstance(child.tag, str):
                continue
            placed = Placed(parent.doc, child)
            if child.tag == "include":
                if keep_includes:
                    yield placed
                doc = self._include(placed)
                if doc is not None:
                    yield from self.children(Placed(doc, doc.root), keep_includes)
                continue
            yield placed

    def _include(self, placed: Placed) -> XmlDocument | None:
        name = placed.el.get("file")
        if not name:
            return None
        if not self._owner and self.main.path is not None:
            self._owner[real_path(self.main.path)] = None  # the main file cannot be included
        candidates = [self.base_dir / name]
        if placed.doc.path is not None:
            candidates.append(placed.doc.path.parent / name)
        path = next((p for p in candidates if os.path.exists(p)), candidates[0])
        key = real_path(path)
        owner = self._owner.setdefault(key, placed.el)
        if owner is not placed.el:
            return None
        if key not in self._included:
            display = str(Path(self.main.display).parent / name)
            self._included[key] = (
                read_xml(path, self.sink, self.max_bytes, display) if os.path.exists(path) else None
            )
        return self._included[key]

    def top(self) -> Placed:
        return Placed(self.main, self.main.root)

    def sections(self, tag: str) -> list[Placed]:
        """Every top-level section ``<tag>`` (``worldbody``, ``actuator``...), in expanded order."""
        return [p for p in self.children(self.top()) if p.tag == tag]

    def section_items(self, tag: str) -> list[Placed]:
        """The children of every ``<tag>`` section, in expanded order."""
        return [c for s in self.sections(tag) for c in self.children(s)]

    def members(self, containers: list[Placed], kind: str) -> list[Placed]:
        """The bodies, joints, geoms or sites directly in ``containers`` (through ``<frame>``)."""
        tags = BODY_CHILDREN[kind]
        out: list[Placed] = []
        stack = [iter(list(self.children(c))) for c in reversed(containers)]
        while stack:
            item = next(stack[-1], None)
            if item is None:
                stack.pop()
            elif item.tag in TRANSPARENT:
                stack.append(iter(list(self.children(item))))
            elif item.tag in tags:
                out.append(item)
        return out

    def all_named(self, tags: tuple[str, ...], roots: list[Placed] | None = None) -> dict[str, Placed]:
        """Every element with one of ``tags`` and a name under ``roots`` (default: the whole
        expanded tree), in document order; the first of a name wins."""
        found: dict[str, Placed] = {}
        stack = list(reversed(roots)) if roots is not None else [self.top()]
        while stack:
            placed = stack.pop()
            if placed.tag in tags:
                name = placed.el.get("name")
                if name and name not in found:
                    found[name] = placed
            stack.extend(reversed(list(self.children(placed))))
        return found

    def iter_all(self) -> Iterator[Placed]:
        """Every element of the expanded tree in document order, ``<include>`` elements too."""
        stack = [self.top()]
        while stack:
            placed = stack.pop()
            yield placed
            stack.extend(reversed(list(self.children(placed, keep_includes=True))))


def pair(names: list[str | None], elements: list[Placed], named: dict[str, Placed]) -> list[Placed | None]:
    """Pair MuJoCo objects (by their names, in MuJoCo's order) with XML elements.

    A named object takes the element of that name. Unnamed objects take the element at their index
    when the element count matches the object count (MuJoCo keeps the written order); otherwise
    they stay unpaired.
    """
    same_count = len(names) == len(elements)
    out: list[Placed | None] = []
    for i, name in enumerate(names):
        if name and name in named:
            out.append(named[name])
        elif same_count and not (name and elements[i].el.get("name") not in (None, name)):
            out.append(elements[i])
        else:
            out.append(None)
    return out


@dataclass
class Locator:
    """Source locations of MuJoCo's bodies, joints, geoms and sites (by MuJoCo index).

    Objects of included files point into the included file. Objects that could not be paired
    with an element point at their nearest located ancestor (the ``<worldbody>`` at worst).
    """

    index: SourceIndex
    bodies: dict[int, Placed] = field(default_factory=dict)
    body_fallback: dict[int, Placed] = field(default_factory=dict)
    joints: dict[int, Placed] = field(default_factory=dict)
    geoms: dict[int, Placed] = field(default_factory=dict)
    sites: dict[int, Placed] = field(default_factory=dict)
    inertials: dict[int, Placed] = field(default_factory=dict)
    joint_body: dict[int, int] = field(default_factory=dict)
    geom_body: dict[int, int] = field(default_factory=dict)
    site_body: dict[int, int] = field(default_factory=dict)

    def body(self, index: int, attribute: str | None = None) -> SourceLocation:
        placed = self.bodies.get(index)
        if placed is not None:
            return placed.loc(attribute)
        fallback = self.body_fallback.get(index)
        return fallback.loc() if fallback is not None else self.index.top().loc()

    def joint(self, index: int, attribute: str | None = None) -> SourceLocation:
        placed = self.joints.get(index)
        if placed is not None:
            return placed.loc(attribute)
        return self.body(self.joint_body.get(index, -1))

    def geom(self, index: int) -> SourceLocation:
        placed = self.geoms.get(index)
        return placed.loc() if placed is not None else self.body(self.geom_body.get(index, -1))

    def site(self, index: int) -> SourceLocation:
        placed = self.sites.get(index)
        return placed.loc() if placed is not None else self.body(self.site_body.get(index, -1))

    def inertial(self, body: int, attribute: str | None = None) -> SourceLocation:
        placed = self.inertials.get(body)
        return placed.loc(attribute) if placed is not None else self.body(body)


@dataclass
class TreeShape:
    """What the locator needs to know of one MuJoCo body: its name, parent and members' names."""

    index: int
    name: str | None
    parent: int
    joints: list[tuple[int, str | None]]
    geoms: list[tuple[int, str | None]]
    sites: list[tuple[int, str | None]]


def locate(index: SourceIndex, shapes: list[TreeShape], world_geoms: list[tuple[int, str | None]]) -> Locator:
    """Pair each body (in MuJoCo's depth-first order) and its members with XML elements."""
    loc = Locator(index)
    containers: dict[int, list[Placed]] = {0: index.sections("worldbody")}
    named = {kind: index.all_named(tags, containers[0]) for kind, tags in BODY_CHILDREN.items()}
    world = containers[0][0] if containers[0] else index.top()
    kids: dict[int, list[TreeShape]] = {}
    for shape in shapes:
        kids.setdefault(shape.parent, []).append(shape)
    _pair_members(loc.geoms, world_geoms, index.members(containers[0], "geom"), named["geom"])
    for parent in [0, *(s.index for s in shapes)]:
        children = kids.get(parent, [])
        if not children:
            continue
        elements = index.members(containers[parent], "body") if parent in containers else []
        paired = pair([c.name for c in children], elements, named["body"])
        ancestor = loc.bodies.get(parent) or loc.body_fallback.get(parent) or world
        for child, placed in zip(children, paired, strict=True):
            if placed is None:
                loc.body_fallback[child.index] = ancestor
                continue
            loc.bodies[child.index] = placed
            containers[child.index] = [placed]
    for shape in shapes:
        for j, _ in shape.joints:
            loc.joint_body[j] = shape.index
        for g, _ in shape.geoms:
            loc.geom_body[g] = shape.index
        for s, _ in shape.sites:
            loc.site_body[s] = shape.index
        body = loc.bodies.get(shape.index)
        if body is None:
            continue
        _pair_members(loc.joints, shape.joints, index.members([body], "joint"), named["joint"])
        _pair_members(loc.geoms, shape.geoms, index.members([body], "geom"), named["geom"])
        _pair_members(loc.sites, shape.sites, index.members([body], "site"), named["site"])
        inertial = next((c for c in index.children(body) if c.tag == "inertial"), None)
        if inertial is not None:
            loc.inertials[shape.index] = inertial
    return loc


def _pair_members(
    out: dict[int, Placed],
    objects: list[tuple[int, str | None]],
    elements: list[Placed],
    named: dict[str, Placed],
) -> None:
    for (i, _), placed in zip(objects, pair([n for _, n in objects], elements, named), strict=True):
        if placed is not None:
            out[i] = placed
