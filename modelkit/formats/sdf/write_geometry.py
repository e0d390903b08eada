"""Visuals and collisions of the SDF writer: shapes, meshes, materials and contact friction.

Box, sphere and cylinder are native in every SDF version, capsule and ellipsoid from SDFormat 1.8;
a cone (never native) and, before 1.8, a capsule or ellipsoid are written as meshes (MK802).
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import PairFriction, describe
from modelkit.convert.meshes import MeshRef
from modelkit.convert.names import unique_name
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.formats.sdf.kept import shape_entries, write_back
from modelkit.formats.sdf.write_xml import add_pose, child_or_sub, data_element, num, rgba, sub
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    Link,
    Mesh,
    Sphere,
    SurfaceFriction,
    VisualMaterial,
)
from modelkit.spatial import Pose

MESH_READABLE = ("stl", "obj", "dae")


class GeomWriter:
    def __init__(self, ctx: WriteContext, version: tuple[int, int], source_format: str = "") -> None:
        self.ctx = ctx
        self.version = version
        self.source_format = source_format
        self.surface_noted: set[str] = set()  # links whose own friction has had its MK852 note

    def link_geoms(
        self,
        el: Element,
        link: Link,
        written: str,
        offset: Pose,
        relative_to: str | None,
        friction: PairFriction | None,
    ) -> None:
        """Write the link's visuals and collisions under ``el``; ``offset`` maps link-frame poses to
        the frame the pose is written in (identity when the link frame is the written frame)."""
        kept = {str(e.get("collision")): str(e.get("xml")) for e in link.extras.get("sdf_surface", [])}
        for kind, geoms in (("visual", link.visuals), ("collision", link.collisions)):
            elements = shape_entries(link.extras, kind)  # <laser_retro>, <cast_shadows>... (kept.py)
            looks = link.extras.get("sdf_materials") or {}  # an SDF source's <script>, <pbr>...
            used: set[str] = set()
            for index, geom in enumerate(geoms):
                name = unique_name(geom.name or f"{kind}_{index}", used)
                target = f"link[{written}]/{kind}[{name}]"
                if kind == "visual" and geom.material is None and isinstance(geom.geometry, Mesh):
                    parts = self.ctx.meshes.coloured_parts(geom.geometry, target, geom.source, MESH_READABLE)
                    if parts is not None:
                        self._coloured_visuals(el, geom, name, parts, used, offset, relative_to)
                        continue
                shape = sub(el, kind, name=name)
                add_pose(shape, offset @ geom.pose, relative_to)
                if not self._geometry(shape, geom, f"{written}_{kind}_{name}", target):
                    el.remove(shape)
                    continue
                if geom.name in elements:
                    write_back(shape, elements[geom.name])
                if kind == "collision" and geom.name in kept:
                    shape.append(etree.fromstring(kept[geom.name]))  # the source's surface, friction aside
                if kind == "visual":
                    self._material(shape, geom, target, looks.get(geom.name or ""))
                elif geom.friction is not None:
                    self._surface(shape, geom.friction, link, target)
                elif friction is not None:
                    self._friction(shape, friction, link, target)

    def _coloured_visuals(self, el: Element, geom: Geom, name: str,
                          parts: list[tuple[MeshRef, tuple[float, float, float, float] | None]],
                          used: set[str], offset: Pose, relative_to: str | None) -> None:
        """A visual mesh split by its file's colours (:meth:`MeshExporter.coloured_parts`): one
        ``<visual>`` per part (the first keeps the name), each with its colour as its material."""
        for k, (ref, colour) in enumerate(parts):
            visual = sub(el, "visual", name=name if k == 0 else unique_name(f"{name}_{k}", used))
            add_pose(visual, offset @ geom.pose, relative_to)
            _mesh_element(sub(visual, "geometry"), ref)
            if colour is not None and colour[3] < 1.0:
                num(visual, "transparency", 1.0 - colour[3])
            if colour is not None:
                self._colours(sub(visual, "material"),
                              VisualMaterial(diffuse=colour[:3], transparency=1.0 - colour[3]))

    def _geometry(self, parent: Element, geom: Geom, mesh_name: str, target: str) -> bool:
        g = geom.geometry
        el = sub(parent, "geometry")
        native_18 = self.version >= (1, 8)
        if isinstance(g, Box):
            sub(sub(el, "box"), "size", fmt_vec(g.size))
        elif isinstance(g, Sphere):
            num(sub(el, "sphere"), "radius", g.radius)
        elif isinstance(g, Cylinder):
            shape = sub(el, "cylinder")
            num(shape, "radius", g.radius)
            num(shape, "length", g.length)
        elif isinstance(g, Capsule) and native_18:
            shape = sub(el, "capsule")
            num(shape, "radius", g.radius)
            num(shape, "length", g.length)
        elif isinstance(g, Ellipsoid) and native_18:
            sub(sub(el, "ellipsoid"), "radii", fmt_vec(g.radii))
        elif isinstance(g, Capsule | Ellipsoid | Cone):
            ref = self.ctx.meshes.primitive(g, mesh_name, target, geom.source)
            mesh = sub(el, "mesh")
            sub(mesh, "uri", ref.uri)
        elif isinstance(g, Mesh):
            found = self.ctx.meshes.mesh(g, mesh_name, target, geom.source, readable=MESH_READABLE)
            if found is None:
                return False
            _mesh_element(el, found)
        else:  # pragma: no cover - the model has no other geometry
            return False
        return True

    @staticmethod
    def _colours(el: Element, material: VisualMaterial) -> None:
        if material.diffuse is not None:
            ambient = material.ambient if material.ambient is not None else 1.0
            sub(
                el,
                "ambient",
                rgba([ambient * float(c) for c in material.diffuse], 1.0 - material.transparency),
            )
            sub(el, "diffuse", rgba(material.diffuse, 1.0 - material.transparency))
        if material.specular is not None:
            sub(el, "specular", rgba(material.specular))
        if material.emissive is not None:
            sub(el, "emissive", rgba(material.emissive))

    def _material(self, visual: Element, geom: Geom, target: str, kept: Any = None) -> None:
        """The visual's ``<material>``; ``kept``: an SDF source's own material elements beyond the colours
        (``<script>``, ``<pbr>``, ``<shader>``...), written back."""
        material = geom.material
        if material is None:
            return
        if isinstance(kept, dict) and kept:
            if material.transparency:
                num(visual, "transparency", material.transparency)
            el = sub(visual, "material")
            self._colours(el, material)
            for key, data in kept.items():
                if key == "pbr" and material.texture:
                    continue  # its albedo map is a file next to the source: not copied (noted below)
                if key == "script" and isinstance(data, dict):
                    script = sub(el, "script")
                    for uri in data.get("uri") or []:
                        sub(script, "uri", str(uri))
                    if data.get("name"):
                        sub(script, "name", str(data["name"]))
                else:
                    el.append(data_element(str(key), data))
            self._texture_note(material, geom, target)
            return
        if material.transparency:
            num(visual, "transparency", material.transparency)
        if material.diffuse is None and material.specular is None and material.emissive is None:
            return
        el = sub(visual, "material")
        self._colours(el, material)
        self._texture_note(material, geom, target)

    def _texture_note(self, material: VisualMaterial, geom: Geom, target: str) -> None:
        if material.texture:
            self.ctx.note(
                "MK818",
                f"texture {material.texture} is not carried over; the colours are",
                geom.source,
                target,
            )

    def _surface(self, collision: Element, friction: SurfaceFriction, link: Link, target: str) -> None:
        """A shape's own friction: ODE's ``<mu>``/``<mu2>`` and Bullet's ``<friction>``/``<friction2>``
        and ``<rolling_friction>``. Torsional friction is not written: SDF's ``<torsional>`` is Gazebo
        ODE's contact-patch model, with no coefficient of MuJoCo's or PyBullet's meaning."""
        second = friction.sliding if friction.sliding2 is None else friction.sliding2
        friction_el = child_or_sub(child_or_sub(collision, "surface"), "friction")
        ode = child_or_sub(friction_el, "ode")
        _first(ode, "mu", friction.sliding)
        _first(ode, "mu2", second, after="mu")
        bullet = child_or_sub(friction_el, "bullet")
        _first(bullet, "friction", friction.sliding)
        _first(bullet, "friction2", second, after="friction")
        if friction.rolling is not None:
            num(bullet, "rolling_friction", friction.rolling)
        if friction.torsional:
            self.ctx.note(
                "MK851",
                f"a collision of link {link.name} has a torsional friction of {fmt(friction.torsional)} m, "
                "which SDF cannot hold (its <torsional> is Gazebo ODE's contact-patch model); left out",
                link.loc("collision"),
                target,
            )
        if self.source_format != "sdf" and link.name not in self.surface_noted:
            self.surface_noted.add(link.name)
            self.ctx.note(
                "MK852",
                f"link {link.name}: the source's friction of its collisions ({describe(friction)}) is "
                "written as each collision's <surface><friction> (ODE mu/mu2, Bullet friction); Gazebo/ODE "
                "takes the smaller of two shapes' values, and other engines may multiply them",
                link.loc("collision"),
                target,
            )

    def _friction(self, collision: Element, friction: PairFriction, link: Link, target: str) -> None:
        surface = sub(collision, "surface")
        if friction.restitution > 0.0:
            num(sub(surface, "bounce"), "restitution_coefficient", friction.restitution)
        friction_el = sub(surface, "friction")
        ode = sub(friction_el, "ode")
        num(ode, "mu", friction.static)
        num(ode, "mu2", friction.static)
        bullet = sub(friction_el, "bullet")
        num(bullet, "friction", friction.static)
        num(bullet, "friction2", friction.static)
        num(bullet, "rolling_friction", 0.0)
        how = "from Choreonoid's material table" if friction.from_table else "by Choreonoid's √ rule"
        self.ctx.note(
            "MK817",
            f'link "{link.name}" (material {friction.material}): friction against {friction.against} '
            f"({how}) is written as this collision's <mu>/<mu2> (ode) and <friction>/<friction2> "
            "(bullet, rolling 0) = "
            f"{fmt(friction.static)}"
            + (
                f" (dynamic {fmt(friction.dynamic)} has no field)"
                if friction.dynamic != friction.static
                else ""
            )
            + "; Gazebo combines the two surfaces of a contact (ODE: the smaller mu; other engines may "
            "multiply), so the pair value holds only against a surface with a larger coefficient",
            link.loc("material"),
            target,
        )


def _first(parent: Element, tag: str, value: float, after: str | None = None) -> None:
    """``<tag>value</tag>`` as the first child of ``parent`` (after ``after``), where SDF lists it
    before the kept children (``<fdir1>``, ``<slip1>``...)."""
    element = etree.Element(tag)
    element.text = fmt(value)
    previous = parent.find(after) if after is not None else None
    parent.insert(0 if previous is None else list(parent).index(previous) + 1, element)


def _mesh_element(geometry: Element, ref: MeshRef) -> None:
    """``<mesh>`` in ``geometry``: the file, and its scale when it is not 1."""
    mesh = sub(geometry, "mesh")
    sub(mesh, "uri", ref.uri)
    if any(abs(float(s) - 1.0) > 0.0 for s in ref.scale):
        sub(mesh, "scale", fmt_vec(ref.scale))
