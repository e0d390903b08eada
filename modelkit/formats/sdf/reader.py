"""The SDFormat reader (SDF 1.4–1.11): models and worlds into robot models, with diagnostics.

A file holds one ``<model>``, or worlds whose ``<model>`` and ``<include>`` elements each become a
robot (the first is ``ReadResult.robot``, the others ``ReadResult.more``, in document order).
Reading goes: document and version (:mod:`document`), element check against the SDFormat
catalogue (:mod:`spec`), flattening of nested and included models (:mod:`collect`), frame graphs
(:mod:`poses`, :mod:`world`), links and joints (:mod:`links`, :mod:`joints`), then the tree with
link frames moved to joint frames (:mod:`assemble`). See ``docs/sdf.md``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink, sorted_diagnostics
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.sdf.actuators import read_actuators
from modelkit.formats.sdf.assemble import Assembler, Placement
from modelkit.formats.sdf.collect import Collector, ModelTree, Scope
from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.document import SdfDocument, version_text
from modelkit.formats.sdf.joints import read_joint
from modelkit.formats.sdf.kept import MODEL_KEY, MODEL_TAGS, keep
from modelkit.formats.sdf.links import read_link
from modelkit.formats.sdf.poses import FrameGraph
from modelkit.formats.sdf.sensors import light_device, plugin_data
from modelkit.formats.sdf.values import child
from modelkit.formats.sdf.world import Placed, WorldFrames, world_frame_entries
from modelkit.limits import too_many_links
from modelkit.model import WORLD_LINK, Device, Robot
from modelkit.spatial import Pose

NOT_MODELLED_IN_WORLD = ("actor", "population", "joint")
# Named elements of a world whose names libsdformat requires unique among their own kind.
WORLD_NAMED = ("light", "actor", "frame", "joint", "road", "population")


def read_sdf(path: Path, options: ReadOptions, display: str) -> ReadResult:
    """Read an SDF file; every problem is a diagnostic, the robots are what could be read."""
    sink = DiagnosticSink()
    ctx = Context(options, sink)
    src = ctx.document(path, display)
    robots = _Reader(ctx, src).read() if src is not None else []
    ctx.add_value_faults()
    return ReadResult(robots[0] if robots else None, sorted_diagnostics(sink.items), robots[1:])


@dataclass
class _Model:
    """A top-level model on its way to becoming a robot."""

    tree: ModelTree
    graph: FrameGraph
    entry: Placed
    static: bool
    stack: tuple[str, ...]
    world: dict[str, Any] | None = None
    extras: dict[str, Any] = field(default_factory=dict)


class _Reader:
    def __init__(self, ctx: Context, src: SdfDocument) -> None:
        self.ctx = ctx
        self.src = src
        self.sink = ctx.sink
        self.collector = Collector(ctx)
        self.stack = (os.path.normpath(os.path.abspath(src.path)),)

    def read(self) -> list[Robot]:
        src, values = self.src, self.src.values
        root = src.doc.root
        robots: list[Robot] = []
        links = sum(1 for _ in root.iter("{*}link"))
        joints = sum(1 for _ in root.iter("{*}joint"))
        if too_many_links(self.sink, values.loc(root), links, joints, self.ctx.options.max_links):
            return robots
        singles = [el for el in root if isinstance(el.tag, str) and el.tag in ("model", "light", "actor")]
        for extra in singles[1:]:
            self.sink.emit(
                "MK153",
                f"<sdf> may hold only one model, light or actor outside a world; this <{extra.tag}> is "
                "not read",
                values.loc(extra),
            )
        worlds = [el for el in root if isinstance(el.tag, str) and el.tag == "world"]
        if singles:
            first = singles[0]
            if first.tag == "model":
                model = self._top_model(src, first, None, None)
                frames = WorldFrames(self.sink)
                frames.add(model.entry)
                robots.append(self._robot(model, frames))
            elif first.tag == "actor":
                self._not_modelled(src, first, "an actor (animated mesh) is not a robot model")
        seen_worlds: dict[str, int] = {}
        for world in worlds:
            name = world.get("name")
            if name is None:  # libsdformat: "Required attribute[name] in element[world] is not specified"
                self.sink.emit(
                    "MK120", "<world> has no name attribute; libsdformat refuses the file", values.loc(world)
                )
            elif name in seen_worlds:
                self.sink.emit(
                    "MK237",
                    f'two worlds are named "{name}" (the first at line {seen_worlds[name]}); libsdformat '
                    "refuses the file (each world must have a unique name)",
                    values.loc(world, "name"),
                )
            else:
                seen_worlds[name] = values.loc(world).line or 0
            robots.extend(self._world(world))
        if not robots:
            what = "a world without models" if worlds else "no model"
            self.sink.emit(
                "MK154",
                f"this file holds {what}; there is no robot to check",
                values.loc(worlds[0] if worlds else root),
            )
        return robots

    # -- models --------------------------------------------------------------------------------

    def _top_model(
        self,
        src: SdfDocument,
        element: Element,
        include: Element | None,
        include_src: SdfDocument | None,
        stack: tuple[str, ...] | None = None,
    ) -> _Model:
        values = src.values
        name = element.get("name")
        if name is None:
            self.sink.emit("MK120", "<model> has no name attribute", values.loc(element))
        static = values.boolean(child(element, "static"))
        pose_src, pose_el = src, child(element, "pose")
        placement = element.get("placement_frame") or None
        placement_loc: tuple[SdfDocument, Element, str | None] | None = (
            (src, element, "placement_frame") if placement else None
        )
        if include is not None and include_src is not None:
            inc_values = include_src.values
            override = inc_values.text(child(include, "name"))
            name = override or name
            static_el = child(include, "static")
            if static_el is not None:
                static = inc_values.boolean(static_el)
            if child(include, "pose") is not None:
                pose_src, pose_el = include_src, child(include, "pose")
            placement_el = child(include, "placement_frame")
            if placement_el is not None and inc_values.text(placement_el):
                placement = inc_values.text(placement_el)
                placement_loc = (include_src, placement_el, None)
        stack = stack or self.stack
        tree = self.collector.top(src, element, name or "", static, stack)
        graph = FrameGraph(tree, self.sink)
        graph.check_attachments()
        graph.resolve_all()
        entry = Placed(
            name or "", src, pose_src, pose_el, graph=graph, placement=placement, placement_loc=placement_loc
        )
        return _Model(tree, graph, entry, static, stack)

    def _robot(self, model: _Model, frames: WorldFrames) -> Robot:
        ctx, tree, graph = self.ctx, model.tree, model.graph
        # a link named "world" is refused (MK238) and left out, so that it causes no follow-on errors
        # (a duplicate of the world a joint's parent "world" names, a second root)
        links = [read_link(ctx, graph, item) for item in tree.of_kind("link") if item.local != "world"]
        joints = [read_joint(ctx, graph, item) for item in tree.of_kind("joint")]
        placement = Placement(frames.pose(model.entry.name) if model.entry.name else Pose(), model.static)
        robot = Assembler(tree, graph, links, joints, placement, self.sink).robot()
        plugins = [plugin_data(ctx, src, el, f'model "{scope.path}"') for scope, src, el in tree.plugins]
        if plugins:
            robot.extras["sdf_plugins"] = plugins
            pairs = zip(tree.plugins, plugins, strict=True)
            read_actuators(robot, [(src, el, data) for (_, src, el), data in pairs])
        keep(robot.extras, MODEL_KEY, tree.scope.element, MODEL_TAGS, "model")
        self_collide = child(tree.scope.element, "self_collide")
        if self_collide is not None:
            robot.self_collide = tree.scope.src.values.boolean(self_collide)
        for scope, src, el in tree.other:
            self._not_modelled(src, el, f'<{el.tag}> of model "{scope.path}" is not part of the robot model')
        for scope in _scopes(tree):
            if scope.static and not model.static and scope is not tree.scope:
                self.sink.emit(
                    "MK155",
                    f'nested model "{scope.path}" is static inside a model that moves: valid SDF '
                    "(libsdformat accepts it) whose links stay fixed in the world; the robot model keeps "
                    "them apart from the moving tree, and convert writes them as separate bodies (MK813)",
                    scope.src.values.loc(scope.element),
                )
        if model.world is not None:
            robot.extras["sdf_world"] = model.world
        robot.extras["sdf_version"] = version_text(tree.scope.src.version)
        return robot

    def _not_modelled(self, src: SdfDocument, el: Element, message: str) -> None:
        self.sink.emit("MK155", message + "; it is skipped", src.values.loc(el))

    # -- worlds --------------------------------------------------------------------------------

    def _world(self, world: Element) -> list[Robot]:
        src, values = self.src, self.src.values
        frames = WorldFrames(self.sink)
        for entry in world_frame_entries(src, world):
            frames.add(entry)
        models: list[_Model] = []
        names: dict[str, int] = {}
        lights: list[Device] = []
        plugins: list[dict[str, Any]] = []
        world_name = world.get("name") or ""
        for el in world:
            tag = el.tag
            if not isinstance(tag, str):
                continue
            model: _Model | None = None
            if tag == "model":
                model = self._top_model(src, el, None, None)
            elif tag == "include":
                loaded = self.collector.load_include(src, el, self.stack)
                if loaded is not None:
                    target, model_el, key = loaded
                    model = self._top_model(target, model_el, el, src, (*self.stack, key))
            elif tag == "light":
                device = light_device(self.ctx, src, el, f'world "{world_name}"')
                if device is not None:
                    pose_el = child(el, "pose")
                    relative = (pose_el.get("relative_to") or "").strip() if pose_el is not None else ""
                    device.pose = frames.pose(relative or "world") @ (values.pose(pose_el) or Pose())
                    lights.append(device)
            elif tag == "plugin":
                plugins.append(plugin_data(self.ctx, src, el, f'world "{world_name}"'))
            elif tag in NOT_MODELLED_IN_WORLD:
                self._not_modelled(src, el, f'<{tag}> in world "{world_name}" is not part of any robot model')
            if model is None:
                continue
            name = model.entry.name
            if name in names:
                self.sink.emit(
                    "MK237",
                    f'world "{world_name}" has two models named "{name}" (the first at line {names[name]})',
                    values.loc(el, "name"),
                )
            else:
                names[name] = values.loc(el).line
                frames.add(model.entry)
            models.append(model)
        self._world_names(world)
        self._world_shared_names(world, names)
        for entry in world_frame_entries(src, world):
            attached = entry.default
            if attached != WORLD_LINK and not frames.exists(attached):
                self.sink.emit(
                    "MK232",
                    f'frame "{entry.name}" is attached_to "{attached}", which names no model or frame of '
                    f'world "{world_name}" (libsdformat error 22)',
                    values.loc(entry.element, "attached_to") if entry.element is not None else None,
                )
        if models:
            models[0].world = {"name": world_name, "lights": lights, "plugins": plugins}
        return [self._robot(model, frames) for model in models]

    def _world_names(self, world: Element) -> None:
        """Same-type siblings of a world share no name (models are checked as they are placed)."""
        values = self.src.values
        seen: dict[tuple[str, str], int] = {}
        for el in world:
            if not isinstance(el.tag, str) or el.tag not in WORLD_NAMED or el.get("name") is None:
                continue
            key = (str(el.tag), el.get("name") or "")
            if key in seen:
                self.sink.emit(
                    "MK237",
                    f'world "{world.get("name") or ""}" has two <{el.tag}> elements named "{key[1]}" (the '
                    f"first at line {seen[key]}); libsdformat refuses the file",
                    values.loc(el, "name"),
                )
            else:
                seen[key] = values.loc(el).line or 0


    def _world_shared_names(self, world: Element, models: dict[str, int]) -> None:
        """MK158: a light or actor named like a model or like another light or actor of the world.

        libsdformat loads such a world and only warns ("Non-unique name[a] detected 2 times in XML children
        of world"); names must be unique among a world's children for Gazebo's entities and for `gz sdf`.
        """
        values = self.src.values
        first: dict[str, tuple[str, int]] = {name: ("model", line) for name, line in models.items()}
        for el in world:
            tag, name = el.tag, el.get("name")
            if not isinstance(tag, str) or tag not in SHARED_NAME_TAGS or not name:
                continue
            earlier = first.get(name)
            if earlier is None:
                first[name] = (tag, values.loc(el).line or 0)
            elif earlier[0] != tag:  # the same type twice is MK237's
                self.sink.emit(
                    "MK158",
                    f'<{tag}> "{name}" of world "{world.get("name") or ""}" has the name of the '
                    f"<{earlier[0]}> at line {earlier[1]}; libsdformat loads the world but warns that the "
                    "names of a world's children are not unique",
                    values.loc(el, "name"),
                    hint="give every model, light and actor of the world its own name",
                )


# World children that libsdformat only warns about when one shares a name with a model or with another of
# them (MK158); frames and joints share the frame graph's namespace and are judged there.
SHARED_NAME_TAGS = ("light", "actor")


def _scopes(tree: ModelTree) -> list[Scope]:
    out: list[Scope] = []
    stack = [tree.scope]
    while stack:
        scope = stack.pop()
        out.append(scope)
        stack.extend(scope.nested)
    return out
