"""A ``<link>``: inertial, visuals, collisions, sensors and lights, placed in the SDF link frame.

Everything a link holds is expressed here in the link's own SDF frame; :mod:`assemble` later moves
it to the model's link frame (the joint frame) when the two differ.

Inertials follow the SDF defaults: a link without ``<inertial>`` has 1 kg and a unit inertia
(``Inertial.defaulted``); ``<inertia>`` entries default to ixx = iyy = izz = 1 and zero products.
``<inertial auto="true">`` (SDFormat 1.11) is computed here from collision primitives, as
libsdformat does (density from ``<collision><density>``, else ``<inertial><density>``, else
1000 kg/m³; a given ``<mass>`` rescales the result); meshes and other shapes are not computed
(MK343) and the written values stay.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import Severity
from modelkit.formats.sdf.collect import Item
from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.geometry import element_data, read_geometry, read_material
from modelkit.formats.sdf.kept import keep_shape
from modelkit.formats.sdf.poses import FrameGraph
from modelkit.formats.sdf.sensors import light_device, plugin_data, sensor_device
from modelkit.formats.sdf.values import Values, child, children
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    Inertial,
    Link,
    Sphere,
    SurfaceFriction,
)
from modelkit.spatial import Mat3, Pose, Vec3

DEFAULT_DENSITY = 1000.0
LINK_FLAGS = ("gravity", "kinematic", "self_collide", "enable_wind", "must_be_base_link")
NOT_MODELLED = ("projector", "audio_sink", "audio_source", "battery", "particle_emitter")


@dataclass
class LinkData:
    item: Item
    link: Link
    pose: Pose  # the SDF link frame in the top-level model frame
    collision_densities: list[float | None] = field(default_factory=list)


def read_link(ctx: Context, graph: FrameGraph, item: Item) -> LinkData:
    src = item.src
    values = src.values
    el = item.element
    link = Link(name=item.name, source=values.loc(el))
    link.sources["name"] = values.loc(el, "name")
    pose = graph.pose(item.name)
    to_link = pose.inverse()
    data = LinkData(item, link, pose)
    what = f'link "{item.local}"'

    def place(pose_el: Element | None, owner_src: Any, default: str, label: str) -> Pose:
        return to_link @ graph.element_pose(owner_src, pose_el, item.scope, default, label)

    names: dict[str, dict[str, int]] = {}
    for kind in ("visual", "collision"):
        for geom_el in children(el, kind):
            name = geom_el.get("name")
            label = f'{kind} "{name}" of {what}'
            if name is None:
                ctx.sink.emit("MK120", f"a <{kind}> of {what} has no name attribute", values.loc(geom_el))
            else:
                _unique(ctx, src, names.setdefault(kind, {}), geom_el, kind, name, what)
            geometry_el = child(geom_el, "geometry")
            if geometry_el is None:
                ctx.sink.emit(
                    "MK122",
                    f"{label} has no <geometry>; libsdformat gives it an empty one (nothing is "
                    f"{'shown' if kind == 'visual' else 'collided with'})",
                    values.loc(geom_el),
                    severity=Severity.WARNING,
                )
            shape = read_geometry(ctx, src, geometry_el, label, visual_only=(kind == "visual"))
            keep_shape(link.extras, kind, name, geom_el)  # <laser_retro>, <max_contacts>, <cast_shadows>
            placed = place(child(geom_el, "pose"), src, item.name, label)
            if shape.unmodelled is not None:
                entry = {"element": kind, "name": name, "pose": placed, **shape.unmodelled}
                link.extras.setdefault("sdf_geometry", []).append(entry)
            if shape.geometry is None:
                if kind == "visual":  # libsdformat still loads (and judges) its material
                    read_material(ctx, src, child(geom_el, "material"), child(geom_el, "transparency"), label)
                continue
            geom = Geom(shape.geometry, placed, name, source=values.loc(geom_el))
            if kind == "visual":
                material = read_material(
                    ctx, src, child(geom_el, "material"), child(geom_el, "transparency"), label
                )
                geom.material = material.material
                if material.extras and name is not None:
                    link.extras.setdefault("sdf_materials", {})[name] = material.extras
                link.visuals.append(geom)
            else:
                surface = child(geom_el, "surface")
                geom.friction = surface_friction(values, surface)
                rest = None if surface is None else surface_rest(surface)
                if rest is not None:
                    link.extras.setdefault("sdf_surface", []).append({"collision": name, "xml": rest})
                link.collisions.append(geom)
                data.collision_densities.append(values.number(child(geom_el, "density")))
            for plugin in children(geom_el, "plugin"):
                link.extras.setdefault("sdf_plugins", []).append(plugin_data(ctx, src, plugin, label))
    for tag, make_device in (("sensor", sensor_device), ("light", light_device)):
        for device_el in children(el, tag):
            device = make_device(ctx, src, device_el, what)
            if device is None:
                continue
            _unique(ctx, src, names.setdefault(tag, {}), device_el, tag, device.name, what)
            device.pose = place(child(device_el, "pose"), src, item.name, f'{tag} "{device.name}"')
            link.devices.append(device)
    link.inertial = _inertial(ctx, graph, item, to_link, data)
    flags: dict[str, Any] = {}
    for key in LINK_FLAGS:
        flag = child(el, key)
        if flag is not None:
            flags[key] = values.boolean(flag)
    decay = child(el, "velocity_decay")
    if decay is not None:
        flags["velocity_decay"] = element_data(decay)
    if "self_collide" in flags:
        link.self_collide = flags.pop("self_collide")
    if flags:
        link.extras["sdf_link"] = flags
    for key in NOT_MODELLED:
        for other in children(el, key):
            ctx.sink.emit(
                "MK155",
                f"<{key}> of {what} is not part of the robot model; it is kept only as data",
                values.loc(other),
            )
            link.extras.setdefault("sdf_other", []).append({"element": key, "data": element_data(other)})
    return data


def _unique(
    ctx: Context, src: Any, seen: dict[str, int], el: Element, kind: str, name: str, owner: str
) -> None:
    values = src.values
    if name in seen:
        ctx.sink.emit(
            "MK237",
            f'{owner} has two {kind}s named "{name}" (the first at line {seen[name]}); SDFormat requires '
            "unique names",
            values.loc(el, "name"),
        )
    else:
        seen[name] = values.loc(el).line


def _empty_mass_value(values: Values, element: Element | None, default: str) -> None:
    """An empty ``<mass>`` is read by libsdformat as its default, silently: said here (MK025), located,
    since a mass nobody wrote changes every dynamic check. (An empty ``<ixx>`` is MK121: libsdformat
    refuses it.)"""
    if element is not None and not (element.text or "").strip():
        values.sink.emit(
            "MK025",
            f"<{element.tag}> is empty: libsdformat takes its default, {default}",
            values.text_loc(element),
            hint=f"write the value, or leave out <{element.tag}> to mean the default",
        )


def _inertial(ctx: Context, graph: FrameGraph, item: Item, to_link: Pose, data: LinkData) -> Inertial:
    src = item.src
    values = src.values
    el = child(item.element, "inertial")
    if el is None:
        return Inertial(1.0, rot3.ZERO3, rot3.IDENTITY, defaulted=True, source=values.loc(item.element))
    inertial = Inertial(1.0, source=values.loc(el))
    mass_el = child(el, "mass")
    _empty_mass_value(values, mass_el, "1 kg")
    mass = values.number(mass_el, 1.0)
    inertial.mass = 1.0 if mass is None else mass
    if mass_el is not None:
        inertial.sources["mass"] = values.text_loc(mass_el)
    pose_el = child(el, "pose")
    frame = to_link @ graph.element_pose(
        src, pose_el, item.scope, item.name, f'the inertial of link "{item.local}"'
    )
    if pose_el is not None:
        inertial.sources["com"] = values.loc(pose_el)
    inertia_el = child(el, "inertia")
    tensor = rot3.IDENTITY
    if inertia_el is not None:
        inertial.sources["inertia"] = values.loc(inertia_el)
        get = {k: values.child_number(inertia_el, k, d) for k, d in _INERTIA_DEFAULTS.items()}
        v = {k: (d if get[k] is None else float(get[k] or 0.0)) for k, d in _INERTIA_DEFAULTS.items()}
        tensor = rot3.inertia_from_moments(**v)
    inertial.com = frame.translation_tuple
    inertial.inertia = rot3.rotate_inertia(tensor, frame.rotation_tuple)
    if values.attribute_bool(el, "auto"):
        _auto(ctx, item, el, inertial, data)
    return inertial


_INERTIA_DEFAULTS = {"ixx": 1.0, "ixy": 0.0, "ixz": 0.0, "iyy": 1.0, "iyz": 0.0, "izz": 1.0}


def _auto(ctx: Context, item: Item, el: Element, inertial: Inertial, data: LinkData) -> None:
    import numpy as np  # automatic inertia is rare: numpy only for the files that ask for it

    from modelkit.spatial import combine_mass_properties, rotate_inertia

    values = item.src.values
    link = data.link
    density = values.child_number(el, "density", DEFAULT_DENSITY) or DEFAULT_DENSITY
    parts: list[tuple[float, Vec3, Mat3]] = []
    skipped: list[str] = []
    for geom, own in zip(link.collisions, data.collision_densities, strict=True):
        solid = _solid(geom.geometry, own if own is not None else density)
        if solid is None:
            skipped.append(f'"{geom.name}" ({type(geom.geometry).__name__.lower()})')
            continue
        mass, com, tensor = solid
        r = geom.pose.rotation
        parts.append((mass, r @ com + geom.pose.translation, rotate_inertia(tensor, r)))
    where = values.loc(el, "auto")
    if skipped or not parts:
        why = ", ".join(skipped) if skipped else "it has no collision"
        ctx.sink.emit(
            "MK343",
            f'link "{item.local}" asks for automatic inertia, which modelkit computes only from box, '
            f"sphere, cylinder, capsule, ellipsoid and cone collisions; not from {why}: the written "
            "values are used",
            where,
        )
        return
    total, com, tensor = combine_mass_properties(parts)
    if "mass" in inertial.sources and total > 0.0:
        scale = inertial.mass / total
        total, tensor = inertial.mass, tensor * scale
    inertial.mass, inertial.com, inertial.inertia = total, com, tensor
    inertial.sources.setdefault("inertia", where)
    ctx.sink.emit(
        "MK342",
        f'link "{item.local}": automatic inertia computed from {len(parts)} collision shape(s): mass '
        f"{total:.6g} kg, centre of mass {np.round(com, 9).tolist()}",
        where,
    )


def _solid(geometry: object, density: float) -> tuple[float, Vec3, Mat3] | None:
    """Mass, centre of mass and inertia about it (own axes) of a uniform primitive."""
    import numpy as np

    zero = np.zeros(3)
    if isinstance(geometry, Box):
        a, b, c = (float(x) for x in geometry.size)
        m = density * a * b * c
        return m, zero, np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12.0
    if isinstance(geometry, Sphere):
        r = geometry.radius
        m = density * 4.0 / 3.0 * math.pi * r**3
        return m, zero, np.eye(3) * 0.4 * m * r * r
    if isinstance(geometry, Cylinder):
        r, h = geometry.radius, geometry.length
        m = density * math.pi * r * r * h
        side = m * (3 * r * r + h * h) / 12.0
        return m, zero, np.diag([side, side, 0.5 * m * r * r])
    if isinstance(geometry, Capsule):
        r, h = geometry.radius, geometry.length
        mc = density * math.pi * r * r * h
        mh = density * 4.0 / 3.0 * math.pi * r**3
        side = mc * (3 * r * r + h * h) / 12.0 + mh * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0)
        return mc + mh, zero, np.diag([side, side, 0.5 * mc * r * r + 0.4 * mh * r * r])
    if isinstance(geometry, Ellipsoid):
        a, b, c = (float(x) for x in geometry.radii)
        m = density * 4.0 / 3.0 * math.pi * a * b * c
        return m, zero, np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 5.0
    if isinstance(geometry, Cone):
        r, h = geometry.radius, geometry.length
        m = density * math.pi * r * r * h / 3.0
        side = m * (3.0 * r * r / 20.0 + 3.0 * h * h / 80.0)
        return m, np.array([0.0, 0.0, -h / 4.0]), np.diag([side, side, 0.3 * m * r * r])
    return None


def surface_friction(values: Values, surface: Element | None) -> SurfaceFriction | None:
    """A collision's own friction: ``<surface><friction>``'s ODE ``<mu>``/``<mu2>`` (Gazebo's engines
    read these), else Bullet's ``<friction>``/``<friction2>``; Bullet's ``<rolling_friction>``. None
    when the collision gives no coefficient. ``<torsional>`` (Gazebo's ODE patch model, which has no
    counterpart in the other formats) is not read."""
    friction = None if surface is None else child(surface, "friction")
    if friction is None:
        return None
    ode, bullet = child(friction, "ode"), child(friction, "bullet")
    first = values.child_number(ode, "mu") if ode is not None else None
    second = values.child_number(ode, "mu2") if ode is not None else None
    if first is None and bullet is not None:
        first = values.child_number(bullet, "friction")
        second = values.child_number(bullet, "friction2")
    rolling = None if bullet is None else values.child_number(bullet, "rolling_friction")
    if first is None and second is None and rolling is None:
        return None
    sliding = 1.0 if first is None else first  # SDF's default mu
    other = 1.0 if second is None else second
    return SurfaceFriction(sliding, None, rolling, None if other == sliding else other)


CARRIED_FRICTION = {"ode": ("mu", "mu2"), "bullet": ("friction", "friction2", "rolling_friction")}
"""The ``<surface><friction>`` children ``Geom.friction`` holds (the rest is kept as XML)."""


def surface_rest(surface: Element) -> str | None:
    """A collision's ``<surface>`` without what ``Geom.friction`` holds, as XML for the SDF writer to
    write back (bounce, contact stiffness, torsional friction, slip...); None when nothing is left."""
    from lxml import etree

    from modelkit.xmlsource import bare_copy

    copy = bare_copy(surface)  # the writer indents it anew
    friction = child(copy, "friction")
    if friction is not None:
        for engine, tags in CARRIED_FRICTION.items():
            holder = child(friction, engine)
            if holder is None:
                continue
            for tag in tags:
                for element in children(holder, tag):
                    holder.remove(element)
            if not len(holder):
                friction.remove(holder)
        if not len(friction):
            copy.remove(friction)
    if not any(isinstance(c.tag, str) for c in copy):
        return None
    return etree.tostring(copy, encoding="unicode", with_tail=False)
