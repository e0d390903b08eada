"""Placing top-level models in the world: the world's own frame graph.

Inside a ``<world>``, a model's pose may be ``relative_to`` the world, a world ``<frame>``, another
model, or a frame inside another model (``other::link``); a ``placement_frame`` says which frame of
the model the pose puts there. A model outside any world is placed by its pose alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink
from modelkit.formats.sdf.collect import MODEL_FRAME
from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.poses import FrameGraph
from modelkit.formats.sdf.values import child
from modelkit.model import WORLD_LINK
from modelkit.spatial import Pose


@dataclass(eq=False)
class Placed:
    """A world-level frame: a model (with its graph) or a ``<frame>``."""

    name: str
    src: SdfDocument
    pose_src: SdfDocument
    pose_element: Element | None
    default: str = WORLD_LINK
    graph: FrameGraph | None = None
    placement: str | None = None
    placement_loc: tuple[SdfDocument, Element, str | None] | None = None
    kind: str = "model"
    element: Element | None = None  # the <frame> element of a world frame


@dataclass
class WorldFrames:
    sink: DiagnosticSink
    entries: dict[str, Placed] = field(default_factory=dict)
    _pose: dict[str, Pose] = field(default_factory=dict)
    _reported: set[frozenset[str]] = field(default_factory=set)

    def add(self, entry: Placed) -> None:
        self.entries.setdefault(entry.name, entry)

    def pose(self, name: str, path: list[str] | None = None) -> Pose:
        """The world pose of a world-level frame or model (identity when unresolvable)."""
        path = [] if path is None else path
        if name == WORLD_LINK:
            return Pose()
        if name in self._pose:
            return self._pose[name]
        entry = self.entries.get(name)
        if entry is None:
            return self._inside(name, path)
        if name in path:
            self._cycle(path[path.index(name) :])
            return Pose()
        path.append(name)
        base = self.pose(self._relative(entry), path)
        path.pop()
        own = entry.pose_src.values.pose(entry.pose_element) or Pose()
        if entry.placement and entry.graph is not None:
            target = entry.graph.lookup(entry.graph.tree.scope, entry.placement)
            if target is None:
                src, el, attr = entry.placement_loc or (entry.src, entry.pose_element, None)
                if el is not None:
                    self.sink.emit(
                        "MK240",
                        f'placement frame "{entry.placement}" is not a frame of model "{name}"',
                        src.values.loc(el, attr) if attr else src.values.text_loc(el),
                    )
            else:
                own = own @ entry.graph.pose(target).inverse()
        result = base @ own
        self._pose[name] = result
        return result

    def _inside(self, name: str, path: list[str]) -> Pose:
        model, sep, rest = name.partition("::")
        entry = self.entries.get(model)
        if not sep or entry is None or entry.graph is None:
            return Pose()
        target = entry.graph.lookup(entry.graph.tree.scope, rest)
        inner = entry.graph.pose(target) if target is not None else Pose()
        return self.pose(model, path) @ inner

    def exists(self, name: str) -> bool:
        """Whether ``name`` is the world, a world-level model or frame, or a frame inside a model."""
        return self._exists(name)

    def _exists(self, name: str) -> bool:
        if name == WORLD_LINK or name in self.entries:
            return True
        model, sep, rest = name.partition("::")
        entry = self.entries.get(model)
        return (
            bool(sep)
            and entry is not None
            and entry.graph is not None
            and (entry.graph.lookup(entry.graph.tree.scope, rest) is not None or rest == MODEL_FRAME)
        )

    def _relative(self, entry: Placed) -> str:
        el = entry.pose_element
        if el is None:
            return entry.default
        written = (el.get("relative_to") or "").strip()
        if not written and not entry.pose_src.at_least(1, 7):
            written = (el.get("frame") or "").strip()
        if not written:
            return entry.default
        if self._exists(written):
            return written
        self.sink.emit(
            "MK230",
            f'relative_to "{written}" of {entry.kind} "{entry.name}" names no model or frame of the world',
            entry.pose_src.values.loc(el, "relative_to"),
        )
        return entry.default

    def _cycle(self, cycle: list[str]) -> None:
        key = frozenset(cycle)
        if key in self._reported:
            return
        self._reported.add(key)
        first = self.entries[cycle[0]]
        el = first.pose_element
        loop = " -> ".join([*cycle, cycle[0]])
        self.sink.emit(
            "MK231",
            f"the relative_to attributes form a cycle ({loop}); these poses cannot be resolved",
            first.pose_src.values.loc(el, "relative_to") if el is not None else None,
        )


def world_frame_entries(src: SdfDocument, world: Element) -> list[Placed]:
    """The ``<frame>`` elements of a world, as world-level frames."""
    out: list[Placed] = []
    for el in world:
        if isinstance(el.tag, str) and el.tag == "frame":
            attached = (el.get("attached_to") or "").strip()
            out.append(
                Placed(
                    el.get("name") or "",
                    src,
                    src,
                    child(el, "pose"),
                    default=attached or WORLD_LINK,
                    kind="frame",
                    element=el,
                )
            )
    return out
