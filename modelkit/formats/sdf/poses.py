"""The frame graphs of a flattened model: where every frame is, and what it is attached to.

SDFormat (1.7+) gives each link, joint, ``<frame>`` and nested model an implicit frame.

* The **pose graph** (``//pose/@relative_to``) says in which frame each pose is written. By
  default a link's pose is relative to its model frame, a joint's to its child frame, a
  ``<frame>``'s to the frame it is attached to, a nested model's to the enclosing model frame, and
  a visual, collision, sensor, light or inertial to its link (or joint, for joint sensors).
* The **attached-to graph** says which link a frame moves with: a joint moves with its child, a
  ``<frame>`` with its ``attached_to``, a model frame with the model's canonical link.

Both graphs must be acyclic and name only frames of the same scope (or of nested scopes, with
``::``). Faults are reported with the codes of libsdformat's error codes 2, 3, 15, 22–27 and 29:
MK230–MK240 and MK152. Poses are resolved to the top-level model frame (SDF 1.4–1.6 files use the
same rules, with ``<pose frame="...">`` read as ``relative_to``, as libsdformat's converter does).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation, did_you_mean
from modelkit.formats.sdf.collect import MODEL_FRAME, Item, ModelTree, Scope
from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.values import child
from modelkit.spatial import Pose

_RESERVED = re.compile(r"^__.*__$")


def reserved_name(local: str) -> bool:
    """A name libsdformat 12 refuses for a link, joint, frame or model in every version (MK238)."""
    return local == "world" or _RESERVED.match(local) is not None


@dataclass(eq=False)
class Vertex:
    name: str  # flattened
    kind: str  # "model" | "link" | "joint" | "frame"
    item: Item | None  # None for the top-level model frame
    scope: Scope  # the scope whose names this vertex's attributes use
    default_relative: str | None  # None only for the top-level model frame
    attached_to: str | None = None  # flattened, unresolved; None for links


class FrameGraph:
    """Pose and attached-to resolution for one flattened top-level model."""

    def __init__(self, tree: ModelTree, sink: DiagnosticSink) -> None:
        self.tree = tree
        self.sink = sink
        self.vertices: dict[str, Vertex] = {}
        self.canonical: dict[str, str | None] = {}  # scope frame -> canonical link
        self._pose: dict[str, Pose] = {}
        self._relative: dict[str, str] = {}
        self._pose_cycles: set[frozenset[str]] = set()
        self._attached_cycles: set[frozenset[str]] = set()
        self._link_of: dict[str, str | None] = {}
        self._build()

    # -- construction ------------------------------------------------------------------------

    def _build(self) -> None:
        top = self.tree.scope
        self.vertices[MODEL_FRAME] = Vertex(MODEL_FRAME, "model", None, top, None)
        self._check_names()
        # Links first: when a name is used twice (reported), it names the link, the anchor of frames.
        for item in sorted(self.tree.items, key=lambda i: i.kind != "link"):
            if item.name in self.vertices:
                continue  # a duplicate: reported by _check_names or the name rules
            self.vertices[item.name] = self._vertex(item)
        self._canonical_links(top)
        for vertex in self.vertices.values():
            if vertex.kind == "model":
                inner = vertex.item.inner if vertex.item is not None else top
                if inner is not None:
                    vertex.attached_to = self.canonical.get(inner.frame)

    def _vertex(self, item: Item) -> Vertex:
        scope = item.scope
        if item.kind == "link":
            return Vertex(item.name, "link", item, scope, scope.frame)
        if item.kind == "model":
            return Vertex(item.name, "model", item, scope, scope.frame)
        if item.kind == "joint":
            child_name = item.src.values.text(child(item.element, "child"))
            target = scope.scoped(child_name) if child_name else scope.frame
            return Vertex(item.name, "joint", item, scope, target, target)
        attached = item.element.get("attached_to")
        target = scope.scoped(attached) if attached else scope.frame
        return Vertex(item.name, "frame", item, scope, target, target)

    def _check_names(self) -> None:
        """Sibling names must be unique (SDF 1.7+: links, joints, frames and nested models share one
        namespace) and not reserved. Repeats among links and joints are left to the model rules
        (MK204 duplicate link, MK205 duplicate joint, MK211 link/joint collision)."""
        seen: dict[str, Item] = {}
        for item in self.tree.items:
            values = item.src.values
            where = values.loc(item.element, "name") if item.element.get("name") is not None else None
            if item.element.get("name") is None and item.kind != "model":
                self.sink.emit("MK120", f"<{item.kind}> has no name attribute", values.loc(item.element))
                continue
            modern = item.src.at_least(1, 7)
            if reserved_name(item.local):  # libsdformat 12: every version
                self.sink.emit(
                    "MK238",
                    f'the {item.kind} name "{item.local}" is reserved in SDFormat ("world" and names '
                    "that start and end with __)",
                    where,
                )
            elif item.src.at_least(1, 8) and "::" in item.local:
                self.sink.emit(
                    "MK238",
                    f'the {item.kind} name "{item.local}" contains "::", which SDFormat 1.8+ reserves '
                    "for scoped names",
                    where,
                )
            first = seen.get(item.name)
            if first is None:
                seen[item.name] = item
                continue
            if {first.kind, item.kind} <= {"link", "joint"}:
                continue  # link/link, joint/joint, link/joint: the rules MK204, MK205, MK211 report them
            if first.kind != item.kind and not modern:
                continue  # libsdformat renames pre-1.7 collisions
            line = first.src.values.loc(first.element, "name").line
            self.sink.emit(
                "MK237",
                f'{item.kind} "{item.local}" has the same name as the {first.kind} at line {line} in '
                f'model "{item.scope.path}"; SDFormat requires links, joints, frames and nested models '
                "to have unique names",
                where or item.src.values.loc(item.element),
                hint=f'rename the {item.kind} (e.g. "{item.local}_{item.kind}")',
            )

    def _canonical_links(self, scope: Scope) -> str | None:
        for inner in scope.nested:
            self._canonical_links(inner)
        values = scope.src.values
        element = scope.element
        written = element.get("canonical_link") if element.tag == "model" else None
        chosen: str | None = None
        if written:
            target = scope.scoped(written)
            vertex = self.vertices.get(target)
            if vertex is not None and vertex.kind == "link":
                chosen = target
            else:
                self.sink.emit(
                    "MK236",
                    f'canonical_link "{written}" is not a link of model "{scope.name}"',
                    values.loc(element, "canonical_link"),
                    hint=self.suggest(scope, written, ("link",)),
                )
        if chosen is None:
            chosen = scope.first_link
        if chosen is None:
            for inner in scope.nested:
                chosen = self.canonical.get(inner.frame)
                if chosen is not None:
                    break
        if chosen is None and _own_static(scope):
            # libsdformat requires a link only of models that are not static (Model::Load)
            self.sink.emit(
                "MK152",
                f'static model "{scope.name}" has no link: libsdformat loads it (a static model needs '
                "none); there is nothing to simulate in it",
                values.loc(element),
                severity=Severity.INFO,
            )
        elif chosen is None:
            self.sink.emit(
                "MK152",
                f'model "{scope.name}" has no link; SDFormat requires at least one in a model that is '
                "not static",
                values.loc(element),
                hint="add a <link>, or <static>true</static> if the model is only frames",
            )
        self.canonical[scope.frame] = chosen
        return chosen

    # -- names -------------------------------------------------------------------------------

    def lookup(self, scope: Scope, name: str) -> str | None:
        """The vertex a name written in ``scope`` refers to, or None."""
        flat = scope.scoped(name)
        if flat in self.vertices:
            return flat
        if flat.endswith("::" + MODEL_FRAME):
            nested = flat[: -len("::" + MODEL_FRAME)]
            if nested in self.vertices and self.vertices[nested].kind == "model":
                return nested
        return None

    def suggest(
        self, scope: Scope, name: str, kinds: tuple[str, ...] = ("link", "joint", "frame", "model")
    ) -> str | None:
        """A "did you mean" hint: the closest name of the given kinds in ``scope``."""
        local = [
            v.name[len(scope.prefix) :]
            for v in self.vertices.values()
            if v.kind in kinds and v.item is not None and v.item.scope is scope
        ]
        if "model" in kinds:
            local.append(MODEL_FRAME)
        return did_you_mean(name, local)

    # -- the pose graph ----------------------------------------------------------------------

    def _relative_of(self, vertex: Vertex) -> str | None:
        """The vertex ``vertex``'s pose is written in (the explicit relative_to when valid)."""
        if vertex.name in self._relative:
            return self._relative[vertex.name]
        target = vertex.default_relative
        item = vertex.item
        if item is not None and item.pose_element is not None and item.pose_src is not None:
            written, attr = _relative_attribute(item.pose_src, item.pose_element)
            if written:
                scope = item.scope
                found = self.lookup(scope, written)
                if found is None:
                    self.sink.emit(
                        "MK230",
                        f'{attr} "{written}" of {item.kind} "{item.local}" names no link, joint, frame or '
                        f'nested model of model "{scope.path}"',
                        item.pose_src.values.loc(item.pose_element, attr),
                        hint=self.suggest(scope, written),
                    )
                else:
                    target = found
        if target is not None and target not in self.vertices:
            target = vertex.scope.frame  # an undefined default (joint child): reported elsewhere
        self._relative[vertex.name] = target or MODEL_FRAME
        return target

    def _own_pose(self, vertex: Vertex) -> Pose:
        item = vertex.item
        if item is None or item.pose_src is None:
            return Pose()
        pose = item.pose_src.values.pose(item.pose_element) or Pose()
        if item.kind == "model" and item.placement and item.inner is not None:
            placement = self.lookup(item.inner, item.placement)
            if placement is None:
                src, el, attr = item.placement_src or (item.src, item.element, None)
                self.sink.emit(
                    "MK240",
                    f'placement frame "{item.placement}" is not a frame of model "{item.local}"',
                    src.values.loc(el, attr) if attr else src.values.text_loc(el),
                )
            else:
                inside = self._resolve(placement, stop=item.inner.frame)
                pose = pose @ inside.inverse()
        return pose

    def pose(self, name: str) -> Pose:
        """The pose of a frame in the top-level model frame (identity when it cannot be resolved)."""
        return self._resolve(name, MODEL_FRAME)

    def _resolve(self, name: str, stop: str) -> Pose:
        """The pose of ``name`` in frame ``stop``, following relative_to edges (iteratively: a chain
        of ten thousand links must not exhaust the stack). A cycle is reported and its vertices
        resolve as if the cycle were cut where it was found."""
        memo = stop == MODEL_FRAME
        chain: list[str] = []
        on_chain: set[str] = set()
        current = name
        base = Pose()
        while current != stop and current in self.vertices:
            if memo and current in self._pose:
                base = self._pose[current]
                break
            if current in on_chain:
                self._report_pose_cycle(chain[chain.index(current) :])
                break
            relative = self._relative_of(self.vertices[current])
            if relative is None:
                break  # the top-level model frame
            chain.append(current)
            on_chain.add(current)
            current = relative
        result = base
        for vertex in reversed(chain):
            result = result @ self._own_pose(self.vertices[vertex])
            if memo:
                self._pose[vertex] = result
        return result

    def _report_pose_cycle(self, cycle: list[str]) -> None:
        key = frozenset(cycle)
        if key in self._pose_cycles:
            return
        self._pose_cycles.add(key)
        explicit = []
        for name in cycle:
            item = self.vertices[name].item
            if item is not None and item.pose_element is not None and item.pose_src is not None:
                written, attr = _relative_attribute(item.pose_src, item.pose_element)
                if written:
                    explicit.append((item.pose_src.values.loc(item.pose_element, attr), item, attr))
        if not explicit:
            return  # only implicit edges: the attached_to cycle behind them is reported (MK233)
        loc, item, attr = min(explicit, key=lambda e: (e[0].line, e[0].col))
        loop = " -> ".join([*cycle, cycle[0]])
        self.sink.emit(
            "MK231",
            f"the {attr} attributes form a cycle ({loop}); these poses cannot be resolved",
            loc,
        )

    def element_pose(
        self,
        src: SdfDocument,
        pose_element: Element | None,
        scope: Scope,
        default: str,
        what: str,
    ) -> Pose:
        """The pose of a leaf element (visual, sensor, ...) in the top-level model frame."""
        base = default
        if pose_element is not None:
            written, attr = _relative_attribute(src, pose_element)
            if written:
                found = self.lookup(scope, written)
                if found is None:
                    self.sink.emit(
                        "MK230",
                        f'{attr} "{written}" of {what} names no link, joint, frame or nested model of '
                        f'model "{scope.path}"',
                        src.values.loc(pose_element, attr),
                        hint=self.suggest(scope, written),
                    )
                else:
                    base = found
        own = src.values.pose(pose_element) or Pose()
        return self.pose(base) @ own

    # -- the attached-to graph ---------------------------------------------------------------

    def link_of(self, name: str) -> str | None:
        """The link a frame moves with (None for an undefined name or a cycle, both reported)."""
        if name in self._link_of:
            return self._link_of[name]
        path: list[str] = []
        on_path: set[str] = set()
        current: str | None = name
        result: str | None = None
        while current is not None:
            if current in self._link_of:  # resolved before: a chain of frames is walked once in all
                result = self._link_of[current]
                break
            vertex = self.vertices.get(current)
            if vertex is None:
                break
            if vertex.kind == "link":
                result = current
                break
            if current in on_path:
                self._report_attached_cycle(path[path.index(current) :])
                break
            path.append(current)
            on_path.add(current)
            nxt = vertex.attached_to
            if nxt is not None and nxt not in self.vertices and vertex.kind == "frame":
                item = vertex.item
                if item is not None:
                    self.sink.emit(
                        "MK232",
                        f'attached_to "{item.element.get("attached_to")}" of frame "{item.local}" names '
                        f'no link, joint, frame or nested model of model "{vertex.scope.path}"',
                        item.src.values.loc(item.element, "attached_to"),
                        hint=self.suggest(vertex.scope, str(item.element.get("attached_to"))),
                    )
                nxt = None
            current = nxt
        for visited in path:
            self._link_of.setdefault(visited, result)
        self._link_of[name] = result
        return result

    def _report_attached_cycle(self, cycle: list[str]) -> None:
        key = frozenset(cycle)
        if key in self._attached_cycles:
            return
        self._attached_cycles.add(key)
        frames = [self.vertices[n].item for n in cycle if self.vertices[n].kind == "frame"]
        items = [i for i in frames if i is not None and i.element.get("attached_to")]
        loop = " -> ".join([*cycle, cycle[0]])
        where: SourceLocation | None = None
        if items:
            first = min(items, key=lambda i: i.src.values.loc(i.element, "attached_to"))
            where = first.src.values.loc(first.element, "attached_to")
        else:
            located = [self.vertices[n].item for n in cycle if self.vertices[n].item is not None]
            if located and located[0] is not None:
                where = located[0].src.values.loc(located[0].element)
        self.sink.emit(
            "MK233",
            f"the attached_to attributes form a cycle ({loop}); these frames are attached to no link",
            where,
        )

    def check_attachments(self) -> None:
        """Resolve every frame's attachment once, so that undefined names and cycles are reported."""
        for vertex in list(self.vertices.values()):
            if vertex.kind == "frame":
                self.link_of(vertex.name)

    def resolve_all(self) -> None:
        for name in list(self.vertices):
            self.pose(name)


def _relative_attribute(src: SdfDocument, pose_element: Element) -> tuple[str, str]:
    """(frame name, attribute name) of a pose's relative_to (``frame`` before SDFormat 1.7)."""
    written = (pose_element.get("relative_to") or "").strip()
    if written:
        return written, "relative_to"
    if not src.at_least(1, 7):
        legacy = (pose_element.get("frame") or "").strip()
        if legacy:
            return legacy, "frame"
    return "", "relative_to"


def _own_static(scope: Scope) -> bool:
    """Whether the model itself says ``<static>true</static>`` (or its ``<include>`` does, at the top)."""
    if scope.src.values.boolean(child(scope.element, "static")):
        return True
    return scope.parent is None and scope.static
