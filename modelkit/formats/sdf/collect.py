"""Flattening a ``<model>``: its links, joints and frames, those of nested and included models.

A nested model's elements get scoped names (``outer_child::link``) as libsdformat gives them; the
nested model itself becomes a frame named after it in the enclosing scope. Included models are
read from their own files (with their own SDF version) and nested the same way, or merged into the
enclosing model when ``<include merge="true">``. Include cycles are reported, never followed.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from lxml.etree import _Element as Element

from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.values import child, children

MODEL_FRAME = "__model__"


@dataclass(eq=False)
class Scope:
    """One model's namespace within the flattened top-level model."""

    name: str  # the model's name (after any include override), for messages
    prefix: str  # "" for the top-level model, "a::b::" inside nested models
    frame: str  # the flattened name of this model's frame ("__model__" at the top)
    src: SdfDocument  # the document that holds this model's elements
    element: Element
    static: bool = False
    parent: Scope | None = None
    first_link: str | None = None  # flattened name of the first direct <link>
    nested: list[Scope] = field(default_factory=list)

    def scoped(self, name: str) -> str:
        """The flattened name of a frame named ``name`` inside this scope."""
        if name == MODEL_FRAME:
            return self.frame
        return self.prefix + name

    @property
    def path(self) -> str:
        return self.prefix[:-2] if self.prefix else self.name


@dataclass(eq=False)
class Item:
    """A link, joint, frame or nested model, with where it is written."""

    kind: str  # "link" | "joint" | "frame" | "model"
    name: str  # flattened
    local: str  # as written
    element: Element
    scope: Scope  # the scope that declares it
    src: SdfDocument
    pose_element: Element | None = None
    pose_src: SdfDocument | None = None
    inner: Scope | None = None  # the nested model's own scope (kind "model")
    placement: str | None = None  # placement frame, a name inside ``inner``
    placement_src: tuple[SdfDocument, Element, str | None] | None = None  # where it is written


@dataclass
class ModelTree:
    """A top-level model, flattened."""

    name: str
    scope: Scope
    items: list[Item] = field(default_factory=list)
    plugins: list[tuple[Scope, SdfDocument, Element]] = field(default_factory=list)
    other: list[tuple[Scope, SdfDocument, Element]] = field(default_factory=list)  # not modelled

    def of_kind(self, kind: str) -> list[Item]:
        return [i for i in self.items if i.kind == kind]


class Collector:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx

    def top(
        self,
        src: SdfDocument,
        element: Element,
        name: str,
        static: bool,
        stack: tuple[str, ...],
    ) -> ModelTree:
        scope = Scope(name=name, prefix="", frame=MODEL_FRAME, src=src, element=element, static=static)
        tree = ModelTree(name, scope)
        self._model(tree, scope, src, element, stack)
        return tree

    # -- one model element -------------------------------------------------------------------

    def _model(
        self, tree: ModelTree, scope: Scope, src: SdfDocument, element: Element, stack: tuple[str, ...]
    ) -> None:
        for el in element:
            tag = el.tag
            if not isinstance(tag, str):
                continue
            if tag in ("link", "joint", "frame"):
                local = el.get("name") or ""
                item = Item(tag, scope.scoped(local), local, el, scope, src, child(el, "pose"), src)
                tree.items.append(item)
                if tag == "link" and scope.first_link is None:
                    scope.first_link = item.name
            elif tag == "model":
                self._nested(tree, scope, src, el, stack)
            elif tag == "include":
                self._include(tree, scope, src, el, stack)
            elif tag == "plugin":
                tree.plugins.append((scope, src, el))
            elif tag == "gripper":
                tree.other.append((scope, src, el))

    def _nested(
        self, tree: ModelTree, scope: Scope, src: SdfDocument, el: Element, stack: tuple[str, ...]
    ) -> None:
        local = el.get("name") or ""
        static = src.values.boolean(child(el, "static")) or scope.static
        inner = self._scope(scope, local, src, el, static, merge=False)
        item = Item("model", scope.scoped(local), local, el, scope, src, child(el, "pose"), src, inner)
        placement = el.get("placement_frame")
        if placement:
            item.placement = placement
            item.placement_src = (src, el, "placement_frame")
        tree.items.append(item)
        self._model(tree, inner, src, el, stack)

    def _scope(
        self, parent: Scope, local: str, src: SdfDocument, el: Element, static: bool, merge: bool
    ) -> Scope:
        if merge:
            prefix, frame = parent.prefix, parent.prefix + f"_merged__{local}__model__"
        else:
            prefix, frame = parent.prefix + local + "::", parent.prefix + local
        inner = Scope(local, prefix, frame, src, el, static, parent)
        parent.nested.append(inner)
        return inner

    def _include(
        self, tree: ModelTree, scope: Scope, src: SdfDocument, inc: Element, stack: tuple[str, ...]
    ) -> None:
        loaded = self.load_include(src, inc, stack)
        if loaded is None:
            return
        target, model_el, path_key = loaded
        name_el = child(inc, "name")
        local = (src.values.text(name_el) or "") or (model_el.get("name") or "")
        static_el = child(inc, "static")
        if static_el is not None:
            static = src.values.boolean(static_el)
        else:
            static = target.values.boolean(child(model_el, "static"))
        merge = src.values.attribute_bool(inc, "merge")
        inner = self._scope(scope, local, target, model_el, static or scope.static, merge)
        pose_el, pose_src = child(inc, "pose"), src
        if pose_el is None:
            pose_el, pose_src = child(model_el, "pose"), target
        item = Item("model", inner.frame, local, inc, scope, src, pose_el, pose_src, inner)
        placement_el = child(inc, "placement_frame")
        if placement_el is not None and src.values.text(placement_el):
            item.placement = src.values.text(placement_el)
            item.placement_src = (src, placement_el, None)
        elif model_el.get("placement_frame"):
            item.placement = model_el.get("placement_frame")
            item.placement_src = (target, model_el, "placement_frame")
        tree.items.append(item)
        self._model(tree, inner, target, model_el, (*stack, path_key))

    # -- includes ------------------------------------------------------------------------------

    def load_include(
        self, src: SdfDocument, inc: Element, stack: tuple[str, ...]
    ) -> tuple[SdfDocument, Element, str] | None:
        """The document and ``<model>`` an ``<include>`` brings in, or None (reported)."""
        values = src.values
        uri_el = child(inc, "uri")
        uri = values.text(uri_el)
        if uri_el is None or not uri:
            self.ctx.sink.emit(
                "MK122", "<include> has no <uri>", values.loc(inc if uri_el is None else uri_el)
            )
            return None
        placement_el = child(inc, "placement_frame")
        if placement_el is not None and values.text(placement_el) and child(inc, "pose") is None:
            self.ctx.sink.emit(
                "MK157",
                f'<include> of "{uri.strip()}" has a <placement_frame> but no <pose>: libsdformat refuses it '
                '("<pose> is required when specifying the placement_frame element")',
                values.loc(placement_el),
                hint="add the <pose> at which the placement frame goes, e.g. <pose>0 0 0 0 0 0</pose>",
            )
        loc = values.text_loc(uri_el)
        path = self.ctx.include_file(uri, src, loc)
        if path is None:
            return None
        key = os.path.normpath(os.path.abspath(path))
        if key in stack:
            chain = " -> ".join(Path(p).name for p in (*stack[stack.index(key) :], key))
            self.ctx.sink.emit(
                "MK531",
                f'including "{uri}" would include {Path(key).name} again (an include cycle: {chain})',
                loc,
            )
            return None
        target = self.ctx.document(path)
        if target is None:
            self.ctx.sink.emit("MK530", f'included model "{uri}" cannot be read ({path})', loc)
            return None
        models = children(target.doc.root, "model")
        placed = [
            el for el in target.doc.root if isinstance(el.tag, str) and el.tag in ("model", "actor", "light")
        ]
        if len(placed) > 1:
            self.ctx.sink.emit(
                "MK530",
                f"included file {path} holds {len(placed)} models, actors or lights; libsdformat refuses an "
                '<include> that brings more than one ("Found more than one model for <include>")',
                loc,
            )
            return None
        if not models:
            what = "a world" if children(target.doc.root, "world") else "no <model>"
            self.ctx.sink.emit("MK530", f"included file {path} holds {what}, not a model", loc)
            return None
        return target, models[0], key
