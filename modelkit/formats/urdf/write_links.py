"""URDF writer, links: ``<inertial>``, ``<visual>``/``<collision>`` geometry and robot-level materials.

URDF 1.0 has box, sphere, cylinder and mesh; capsules, cones and ellipsoids are written as mesh
files (MK802). Colours become robot-level ``<material name>`` entries, shared by identical
materials; URDF holds only ``<color rgba>`` and ``<texture filename>``, so specular, emissive,
ambient and shininess are dropped with one MK818 note per robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import PairFriction, describe, link_surface
from modelkit.convert.meshes import MeshRef
from modelkit.convert.numbers import clean_inertia, fmt, fmt_inertia, fmt_position, fmt_rpy, fmt_vec
from modelkit.diagnostics import SourceLocation
from modelkit.formats.urdf.links import PYBULLET_LATERAL_DEFAULT
from modelkit.formats.urdf.massless import TINY_INERTIA, TINY_MASS
from modelkit.model import (
    WORLD_LINK,
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    Link,
    Mesh,
    Robot,
    Sphere,
    SurfaceFriction,
    VisualMaterial,
)
from modelkit.spatial import Pose

# PyBullet lateral friction of a support link (modelkit.convert.contact_compliance) whose source gives
# none: MuJoCo's default sliding friction, which the MJCF of the same robot gets, instead of PyBullet's
# own default 0.5 (the two written files then mean the same robot)
SUPPORT_FRICTION = 1.0



def origin_element(parent: Element, pose: Pose, always: bool = False) -> None:
    """``<origin xyz rpy>`` for ``pose`` (left out when it is the identity, unless ``always``)."""
    xyz = fmt_position(pose.translation)
    rpy = fmt_rpy(pose.rotation)
    if always or xyz != "0 0 0" or rpy != "0 0 0":
        etree.SubElement(parent, "origin", xyz=xyz, rpy=rpy)


TINY_WORDS = "written with a tiny explicit inertial"  # the MK816 note's words (verify reads them back)


def moving_massless_inertial(parent: Element, link: Link, ctx: WriteContext, target: str) -> None:
    """A tiny explicit ``<inertial>`` for a massless link on a moving joint (MK816). Without one,
    PyBullet gives the link 1 kg and a unit inertia, and libsdformat's URDF to SDF conversion (what
    Gazebo loads) drops it with everything below it. An MJCF body with several joints is read as a
    chain of such links (dm_control's rodent has 16, its humanoid 9: PyBullet made it 9 kg heavier),
    and a ball joint is written as one (two links per ball)."""
    ctx.note(
        "MK816",
        f'link "{link.name}" has no mass but moves; PyBullet would give it 1 kg and libsdformat would drop '
        f"it with its subtree, so it is {TINY_WORDS} (mass {fmt(TINY_MASS)} kg, "
        f"inertia {fmt(TINY_INERTIA)} kg·m²)",
        link.loc("mass"),
        f"{target}/inertial",
    )
    tiny_inertial(parent)


def tiny_inertial(parent: Element) -> None:
    """The explicit ``<inertial>`` of a massless link (:data:`TINY_MASS`)."""
    el = etree.SubElement(parent, "inertial")
    etree.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
    etree.SubElement(el, "mass", value=fmt(TINY_MASS))
    moment = fmt(TINY_INERTIA)
    etree.SubElement(el, "inertia", ixx=moment, ixy="0", ixz="0", iyy=moment, iyz="0", izz=moment)


def inertial_element(parent: Element, link: Link, ctx: WriteContext, target: str) -> None:
    """The link's ``<inertial>``: COM as origin (rpy 0), the full tensor about the COM in link axes."""
    inertial = link.inertial
    if inertial is None or inertial.mass <= 0.0:
        return  # a massless link is a frame; URDF allows a link without <inertial>
    if inertial.defaulted:
        ctx.note(
            "MK801",
            f'link "{link.name}" has no mass information; the default the source format '
            f"implies (mass {fmt(inertial.mass)} kg and its inertia) is written explicitly",
            link.loc("mass"),
            f"{target}/inertial",
        )
    el = etree.SubElement(parent, "inertial")
    etree.SubElement(el, "origin", xyz=fmt_position(inertial.com), rpy="0 0 0")
    etree.SubElement(el, "mass", value=fmt(inertial.mass))
    i = clean_inertia(inertial.inertia, inertial.mass)
    etree.SubElement(
        el,
        "inertia",
        ixx=fmt_inertia(i[0, 0], i),
        ixy=fmt_inertia(i[0, 1], i),
        ixz=fmt_inertia(i[0, 2], i),
        iyy=fmt_inertia(i[1, 1], i),
        iyz=fmt_inertia(i[1, 2], i),
        izz=fmt_inertia(i[2, 2], i),
    )


@dataclass
class MaterialTable:
    """Robot-level materials: one entry per distinct (name, rgba, texture), with unique names."""

    entries: list[tuple[str, tuple[float, float, float, float] | None, str | None]] = field(
        default_factory=list
    )
    _by_key: dict[tuple[object, ...], str] = field(default_factory=dict)
    _names: set[str] = field(default_factory=set)
    appearance_dropped: list[str] = field(default_factory=list)

    def add(self, material: VisualMaterial, fallback: str, texture: str | None) -> str | None:
        rgba = material.rgba
        if rgba is None and texture is None:
            return None
        key = (material.name, rgba, texture)
        known = self._by_key.get(key)
        if known is not None:
            return known
        base = material.name or fallback
        name, n = base, 1
        while name in self._names:
            n += 1
            name = f"{base}_{n}"
        self._names.add(name)
        self._by_key[key] = name
        self.entries.append((name, rgba, texture))
        return name

    def write(self, robot_el: Element) -> None:
        for name, rgba, texture in self.entries:
            el = etree.SubElement(robot_el, "material", name=name)
            if rgba is not None:
                etree.SubElement(el, "color", rgba=fmt_vec(rgba))
            if texture is not None:
                etree.SubElement(el, "texture", filename=texture)


def _texture(
    material: VisualMaterial, robot: Robot, ctx: WriteContext, target: str, source: SourceLocation | None
) -> str | None:
    """The texture copied into the output (a relative reference), or None with an MK818 note."""
    uri = material.texture
    if not uri:
        return None
    base = Path(robot.source.file).parent if robot.source and robot.source.file else None
    return ctx.meshes.texture(uri, base, target, source)


def _mesh_element(parent: Element, ref: MeshRef) -> None:
    el = etree.SubElement(parent, "mesh", filename=ref.uri)
    scale = np.asarray(ref.scale, dtype=float)
    if not np.all(scale == 1.0):
        el.set("scale", fmt_vec(scale))


MESH_READABLE = ("stl", "obj", "dae")  # what the URDF writer copies (COLLADA with --keep-collada)


def _coloured_visual(geom: Geom, ref: MeshRef, colour: tuple[float, float, float, float] | None,
                     materials: MaterialTable, fallback: str, with_name: bool) -> Element:
    """One part of a visual mesh split by its file's colours (:meth:`MeshExporter.coloured_parts`), with
    its colour as the visual's ``<material>``."""
    item = etree.Element("visual")
    if with_name and geom.name:
        item.set("name", geom.name)
    origin_element(item, geom.pose)
    _mesh_element(etree.SubElement(item, "geometry"), ref)
    if colour is not None:
        material = VisualMaterial(diffuse=colour[:3], transparency=1.0 - colour[3])
        mat_name = materials.add(material, fallback, None)
        if mat_name is not None:
            etree.SubElement(item, "material", name=mat_name)
    return item


def geometry_element(parent: Element, geom: Geom, ctx: WriteContext, target: str, mesh_name: str) -> bool:
    """``<geometry>`` for the geom; False (nothing written) when its mesh is missing."""
    shape = geom.geometry
    if isinstance(shape, Mesh):
        ref = ctx.meshes.mesh(shape, mesh_name, target, geom.source, readable=MESH_READABLE)
        if ref is None:
            return False
        _mesh_element(etree.SubElement(parent, "geometry"), ref)
        return True
    if isinstance(shape, Capsule | Cone | Ellipsoid):
        ref = ctx.meshes.primitive(shape, mesh_name, target, geom.source)
        _mesh_element(etree.SubElement(parent, "geometry"), ref)
        return True
    el = etree.SubElement(parent, "geometry")
    if isinstance(shape, Box):
        etree.SubElement(el, "box", size=fmt_vec(shape.size))
    elif isinstance(shape, Sphere):
        etree.SubElement(el, "sphere", radius=fmt(shape.radius))
    elif isinstance(shape, Cylinder):
        etree.SubElement(el, "cylinder", radius=fmt(shape.radius), length=fmt(shape.length))
    return True


def _dropped_appearance(material: VisualMaterial) -> list[str]:
    out = []
    if material.specular is not None and np.any(np.asarray(material.specular) != 0.0):
        out.append("specular")
    if material.emissive is not None and np.any(np.asarray(material.emissive) != 0.0):
        out.append("emissive")
    if material.ambient is not None:
        out.append("ambient")
    if material.specular_exponent is not None:
        out.append("shininess")
    return out


def link_element(
    robot_el: Element, link: Link, name: str, robot: Robot, ctx: WriteContext, materials: MaterialTable,
    friction: PairFriction | None = None,
    moving: bool = False,
    compliance: tuple[float, float] | None = None,
    unnamed: frozenset[str] | set[str] = frozenset(),
) -> Element:
    """The ``<link>`` element with its inertial, visuals, collisions and (with ``friction``, the link's
    contact material against the floor) PyBullet's ``<contact>``, with ``compliance`` (stiffness N/m,
    damping N·s/m: :mod:`modelkit.convert.contact_compliance`) in it. A massless link gets the tiny
    inertial (:func:`tiny_inertial`; with a note of its own where it moves), except a ``world`` link,
    which PyBullet and the other URDF loaders take as the fixed world. The shapes of a kind in
    ``unnamed`` are written without their names (:func:`..write_gazebo.unnamed_shapes`)."""
    el = etree.SubElement(robot_el, "link", name=name)
    target = f"link[{name}]"
    massless = link.inertial is None or link.inertial.mass <= 0.0
    if moving and massless:
        moving_massless_inertial(el, link, ctx, target)
    elif massless and link.name != WORLD_LINK:
        tiny_inertial(el)
    else:
        inertial_element(el, link, ctx, target)
    for kind, geoms in (("visual", link.visuals), ("collision", link.collisions)):
        for i, geom in enumerate(geoms):
            where = f"{target}/{kind}[{i}]"
            if kind == "visual" and geom.material is None and isinstance(geom.geometry, Mesh):
                parts = ctx.meshes.coloured_parts(geom.geometry, where, geom.source, MESH_READABLE)
                if parts is not None:
                    for k, (ref, colour) in enumerate(parts):
                        el.append(_coloured_visual(geom, ref, colour, materials, f"{name}_visual{i}_{k}",
                                                   with_name=k == 0 and "visual" not in unnamed))
                    continue
            item = etree.Element(kind)
            if geom.name and kind not in unnamed:
                item.set("name", geom.name)
            origin_element(item, geom.pose)
            if not geometry_element(item, geom, ctx, where, f"{name}_{kind}{i}"):
                continue
            if kind == "visual" and geom.material is not None:
                texture = _texture(geom.material, robot, ctx, where, geom.source)
                mat_name = materials.add(geom.material, f"{name}_visual{i}", texture)
                if mat_name is not None:
                    etree.SubElement(item, "material", name=mat_name)
                for what in _dropped_appearance(geom.material):
                    if what not in materials.appearance_dropped:
                        materials.appearance_dropped.append(what)
            el.append(item)
    surface, others = link_surface(link)
    kept = link.extras.get(CONTACT_EXTRAS)
    if surface is not None:
        contact = contact_element(el, surface.sliding, surface.rolling or 0.0, surface.torsional or 0.0)
        _surface_losses(link, surface, others, ctx, target)
        if robot.source_format == "urdf" and kept is None:
            # the friction came from the source's <gazebo> mu1, which PyBullet does not read
            ctx.note(
                "MK852",
                f"link {link.name}: the source's Gazebo friction (mu1 {fmt(surface.sliding)}) is also "
                "written "
                "as PyBullet's <contact> lateral_friction, which PyBullet multiplies by the floor's; "
                "PyBullet reads no <gazebo> block and would give the link its default "
                f"{fmt(PYBULLET_LATERAL_DEFAULT)}",
                link.loc("collision"),
                target,
            )
    elif friction is not None and link.collisions:
        contact = contact_element(el, friction.dynamic, 0.0, 0.0)
    elif kept:
        contact = etree.SubElement(el, "contact")
    elif compliance is not None:  # a support without a friction of its own: MuJoCo's default, as the MJCF
        contact = contact_element(el, SUPPORT_FRICTION, 0.0, 0.0)
    else:
        return el
    for tag, value in sorted((kept or {}).items()):
        etree.SubElement(contact, tag, **({"value": value} if value else {}))
    if compliance is not None and not {"stiffness", "damping"} & set(kept or {}):  # the source's own wins
        # in the order a kept <contact> is written (sorted), so that URDF → URDF gives the same bytes
        etree.SubElement(contact, "damping", value=fmt(compliance[1]))
        etree.SubElement(contact, "stiffness", value=fmt(compliance[0]))
    return el


CONTACT_EXTRAS = "urdf_contact"  # PyBullet's <contact> children other than friction (URDF reader)


def contact_element(link_el: Element, lateral: float, rolling: float, spinning: float) -> Element:
    """PyBullet's ``<contact>``. For a `.body` material pair: lateral friction = the pair's dynamic
    friction (Bullet multiplies the two bodies' values, and pybullet_data's plane.urdf has 1, so the
    product is the pair's); rolling and spinning friction 0, as MuJoCo with condim 3 and Choreonoid
    have none. For a shape's own friction: its sliding, rolling and torsional coefficients."""
    contact = etree.SubElement(link_el, "contact")
    etree.SubElement(contact, "lateral_friction", value=fmt(lateral))
    etree.SubElement(contact, "rolling_friction", value=fmt(rolling))
    etree.SubElement(contact, "spinning_friction", value=fmt(spinning))
    return contact


def _surface_losses(
    link: Link, kept: SurfaceFriction, others: list[SurfaceFriction], ctx: WriteContext, target: str
) -> None:
    """MK851 for what one ``<contact>`` per link cannot hold."""
    if others:
        ctx.note(
            "MK851",
            f"the collisions of link {link.name} have different frictions; a URDF link holds one "
            f"(PyBullet's <contact>), and the first is written ({describe(kept)}); left out: "
            + "; ".join(describe(f) for f in others),
            link.loc("collision"),
            target,
        )
    if kept.sliding2 is not None:
        ctx.note(
            "MK851",
            f"a collision of link {link.name} has a sliding friction of {fmt(kept.sliding)} in its first "
            f"direction and {fmt(kept.sliding2)} in its second; PyBullet's <contact> holds one "
            f"coefficient, {fmt(kept.sliding)} (the Gazebo block keeps both)",
            link.loc("collision"),
            target,
        )
