"""URDF ``<link>`` elements: inertial, visuals, collisions, geometry and materials.

A part that cannot be read (an inertial with a mass that is not a number, a box without size) is
reported and left out; the rest of the link is still read. urdfdom behaves alike except that it
stops reading the link at the first bad part (and check_urdf still exits 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import Severity, did_you_mean
from modelkit.formats.meshref import MeshChecker
from modelkit.formats.urdf.values import Context, number, origin, vector
from modelkit.model import Box, Capsule, Cylinder, Geom, Geometry, Inertial, Link, Sphere, VisualMaterial

INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


@dataclass
class Materials:
    """The robot's named materials: top-level ones first, then those defined inside visuals.

    As in urdfdom, a name already known wins over an inline definition, and a material defined
    inside a visual becomes known to the links that follow it in the document.
    """

    files: MeshChecker  # resolves and checks texture files
    table: dict[str, VisualMaterial] = field(default_factory=dict)

    def parse(self, ctx: Context, element: Element, name: str | None) -> VisualMaterial | None:
        """The material defined by ``element`` (None when it has neither color nor texture)."""
        material = VisualMaterial(name=name)
        found = False
        color = ctx.first(element, "color")
        if color is not None:
            rgba = vector(ctx, color, "rgba", f'material "{name}" color', count=4)
            if color.get("rgba") is None:
                ctx.emit("MK120", "<color> has no `rgba` attribute", ctx.loc(color))
            elif rgba is not None:
                found = True
                if any(v < 0.0 or v > 1.0 for v in rgba):
                    ctx.emit(
                        "MK513",
                        f'material "{name}": rgba "{color.get("rgba")}" has values outside 0..1 '
                        "(urdfdom rejects the colour; modelkit clamps it)",
                        ctx.loc(color, "rgba"),
                        hint="colours are fractions: 255 is written 1",
                    )
                material.diffuse = tuple(min(max(v, 0.0), 1.0) for v in rgba[:3])
                material.transparency = 1.0 - min(max(rgba[3], 0.0), 1.0)
        texture = ctx.first(element, "texture")
        if texture is not None:
            filename = texture.get("filename")
            if filename is None:  # urdfdom and PyBullet skip such a <texture> and load the file
                ctx.emit(
                    "MK120",
                    "<texture> has no `filename` attribute; urdfdom and PyBullet ignore it",
                    ctx.loc(texture),
                    hint='give the image, e.g. <texture filename="package://pkg/textures/wood.png"/>',
                    severity=Severity.WARNING,
                )
            else:
                found = True
                material.texture = filename
                self.files.texture(filename, ctx.loc(texture, "filename"))
        return material if found else None

    def define(self, ctx: Context, element: Element) -> None:
        """A top-level ``<material name>`` (its name must be unique; it needs a colour or texture)."""
        name = element.get("name")
        if name is None:
            ctx.emit("MK120", "<material> at robot level has no `name` attribute", ctx.loc(element))
            return
        if name in self.table:
            ctx.emit(
                "MK140",
                f'material "{name}" is defined twice (urdfdom refuses the file: "material is not unique")',
                ctx.loc(element, "name"),
            )
            return
        material = self.parse(ctx, element, name)
        if material is None:
            if not ctx.children(element):  # a bad <color> or <texture> is reported already
                ctx.emit(
                    "MK141",
                    f'material "{name}" has neither <color rgba> nor <texture filename>',
                    ctx.loc(element),
                )
            material = VisualMaterial(name=name)
        self.table[name] = material

    def use(self, ctx: Context, element: Element, link: str) -> VisualMaterial | None:
        """The material of a visual: a reference by name, an inline definition, or both."""
        name = element.get("name")
        if name is None:
            ctx.emit(
                "MK136",
                f'a <material> in a visual of link "{link}" has no `name`; urdfdom then drops the '
                "visual and PyBullet refuses the file",
                ctx.loc(element),
                hint='give it a name, e.g. <material name="red">',
            )
            return self.parse(ctx, element, None)
        known = self.table.get(name)
        if known is not None:
            return known
        inline = self.parse(ctx, element, name)
        if inline is not None:
            self.table[name] = inline
            return inline
        ctx.emit(
            "MK135",
            f'link "{link}" uses material "{name}", which is not defined (before this point); the visual '
            "gets no colour",
            ctx.loc(element, "name"),
            hint=did_you_mean(name, set(self.table)),
        )
        return VisualMaterial(name=name)


def read_link(ctx: Context, element: Element, meshes: MeshChecker, materials: Materials) -> Link:
    """A :class:`Link` with its inertial, visuals and collisions; faults are reported, never raised."""
    name = element.get("name")
    link = Link(name=name or "", source=ctx.loc(element))
    if name is None:
        ctx.emit("MK120", "<link> has no `name` attribute", ctx.loc(element))
        link.sources["name"] = ctx.loc(element)
    else:
        link.sources["name"] = ctx.loc(element, "name")
    inertial = ctx.first(element, "inertial")
    if inertial is not None:
        link.inertial = read_inertial(ctx, inertial, link.name)
    for visual in ctx.children(element, "visual"):
        geom = _read_geom(ctx, visual, link.name, meshes, visual_only=True)
        if geom is not None:
            material = ctx.first(visual, "material")
            if material is not None:
                geom.material = materials.use(ctx, material, link.name)
            link.visuals.append(geom)
    for collision in ctx.children(element, "collision"):
        geom = _read_geom(ctx, collision, link.name, meshes, visual_only=False)
        if geom is not None:
            link.collisions.append(geom)
    return link


def read_inertial(ctx: Context, element: Element, link: str) -> Inertial | None:
    """Mass, centre of mass and inertia; the ``<origin>`` rotation turns the tensor into link axes.

    None (with the faults reported) when any part is missing or malformed, as urdfdom drops it.
    """
    origin_el = ctx.first(element, "origin")
    pose = origin(ctx, origin_el, f'inertial of link "{link}"')
    mass_el = ctx.first(element, "mass")
    inertia_el = ctx.first(element, "inertia")
    for name, child in (("mass", mass_el), ("inertia", inertia_el)):
        if child is None:
            ctx.emit("MK122", f'<inertial> of link "{link}" has no <{name}>', ctx.loc(element))
    mass = None if mass_el is None else number(ctx, mass_el, "value", f'mass of link "{link}"', required=True)
    tensor = None if inertia_el is None else _inertia(ctx, inertia_el, link)
    if pose is None or mass is None or tensor is None or mass_el is None or inertia_el is None:
        return None
    inertial = Inertial(
        mass=mass,
        com=pose.translation_tuple,
        inertia=rot3.rotate_inertia(tensor, pose.rotation_tuple),
        source=ctx.loc(element),
    )
    inertial.sources["mass"] = ctx.loc(mass_el, "value")
    inertial.sources["inertia"] = ctx.loc(inertia_el)
    if origin_el is not None:
        inertial.sources["com"] = ctx.loc(origin_el)
    return inertial


def _inertia(ctx: Context, element: Element, link: str) -> rot3.M3 | None:
    missing = [k for k in INERTIA_KEYS if element.get(k) is None]
    if missing:
        ctx.emit(
            "MK120",
            f'<inertia> of link "{link}" lacks {", ".join(missing)} (all six of ixx, ixy, ixz, iyy, iyz, '
            "izz are required)",
            ctx.loc(element),
        )
        return None
    values = [number(ctx, element, k, f'inertia of link "{link}"') for k in INERTIA_KEYS]
    if any(v is None for v in values):
        return None
    return rot3.inertia_from_moments(*(float(v or 0.0) for v in values))


# A visual or collision without a shape (MK122): who loads the file and who refuses it.
NO_SHAPE_CONSUMERS = (
    "urdfdom (check_urdf, libsdformat) logs an error, drops it and loads the file; PyBullet refuses the file"
)


def _read_geom(
    ctx: Context, element: Element, link: str, meshes: MeshChecker, visual_only: bool
) -> Geom | None:
    kind = "visual" if visual_only else "collision"
    what = f'{kind} of link "{link}"'
    pose = origin(ctx, ctx.first(element, "origin"), what)
    geometry_el = ctx.first(element, "geometry")
    if geometry_el is None:
        ctx.emit(
            "MK122",
            f'<{kind}> of link "{link}" has no <geometry>; it is left out ({NO_SHAPE_CONSUMERS})',
            ctx.loc(element),
            severity=Severity.WARNING,
        )
        return None
    geometry = read_geometry(ctx, geometry_el, what, meshes, visual_only)
    if geometry is None or pose is None:
        return None
    return Geom(geometry=geometry, pose=pose, name=element.get("name"), source=ctx.loc(element))


def read_geometry(
    ctx: Context, element: Element, what: str, meshes: MeshChecker, visual_only: bool
) -> Geometry | None:
    """The first shape in ``<geometry>``: box, cylinder, sphere, capsule (URDF 1.1) or mesh."""
    shapes = ctx.children(element)
    if not shapes:
        ctx.emit(
            "MK122",
            f"<geometry> of the {what} holds no shape; it is left out ({NO_SHAPE_CONSUMERS})",
            ctx.loc(element),
            severity=Severity.WARNING,
        )
        return None
    shape = shapes[0]
    tag = ctx.tag(shape)
    loc = ctx.loc(shape)
    if tag == "box":
        if shape.get("size") is None:
            ctx.emit("MK120", f"<box> of the {what} has no `size` attribute", loc)
            return None
        size = vector(ctx, shape, "size", f"box of the {what}")
        if size is None:
            return None
        if any(s <= 0.0 for s in size):
            _not_positive(ctx, shape, "size", f"box of the {what}")
        return Box(size=tuple(size))
    if tag in ("cylinder", "capsule"):
        if tag == "capsule":
            ctx.uses_feature("<capsule>", "1.1", loc)
        missing = [k for k in ("radius", "length") if shape.get(k) is None]
        if missing:
            ctx.emit("MK120", f"<{tag}> of the {what} needs both `radius` and `length`", loc)
            return None
        radius = number(ctx, shape, "radius", f"{tag} of the {what}")
        length = number(ctx, shape, "length", f"{tag} of the {what}")
        if radius is None or length is None:
            return None
        if radius <= 0.0:
            _not_positive(ctx, shape, "radius", f"{tag} of the {what}")
        if length < 0.0 or (length == 0.0 and tag == "cylinder"):
            _not_positive(ctx, shape, "length", f"{tag} of the {what}")
        return Cylinder(radius, length) if tag == "cylinder" else Capsule(radius, length)
    if tag == "sphere":
        radius = number(ctx, shape, "radius", f"sphere of the {what}", required=True)
        if radius is None:
            return None
        if radius <= 0.0:
            _not_positive(ctx, shape, "radius", f"sphere of the {what}")
        return Sphere(radius)
    if tag == "mesh":
        return _mesh(ctx, shape, what, meshes, visual_only)
    ctx.emit(
        "MK412",
        f"unknown geometry type <{tag}> in the {what} (URDF has box, cylinder, sphere, capsule, mesh)",
        loc,
    )
    return None


def _not_positive(
    ctx: Context, element: Element, attribute: str, what: str, rule: str = "be positive"
) -> None:
    ctx.emit(
        "MK400",
        f'{what}: `{attribute}="{element.get(attribute)}"` must {rule}',
        ctx.loc(element, attribute),
    )


def _mesh(ctx: Context, shape: Element, what: str, meshes: MeshChecker, visual_only: bool) -> Geometry | None:
    filename = shape.get("filename")
    if filename is None:
        ctx.emit("MK120", f"<mesh> of the {what} has no `filename` attribute", ctx.loc(shape))
        return None
    scale = (1.0, 1.0, 1.0)
    text = shape.get("scale")
    if text is not None:
        items = text.split()
        if len(items) == 1 and number(ctx, shape, "scale", f"mesh of the {what}") is not None:
            value = float(items[0])
            ctx.emit(
                "MK420",
                f'mesh of the {what}: `scale="{text}"` has one number; URDF needs three (urdfdom drops '
                "the shape); modelkit reads it as a uniform scale",
                ctx.loc(shape, "scale"),
                hint=f'write scale="{value:g} {value:g} {value:g}"',
            )
            scale = (value, value, value)
        elif len(items) != 1:
            values = vector(ctx, shape, "scale", f"mesh of the {what}")
            if values is None:
                return None
            scale = (values[0], values[1], values[2])
        else:
            return None
        if any(s == 0.0 for s in scale):
            _not_positive(ctx, shape, "scale", f"mesh of the {what}", "not be zero")
    return meshes.mesh(filename, ctx.loc(shape, "filename"), scale=scale, visual_only=visual_only)
