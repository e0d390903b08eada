"""URDF ``<link>`` elements: inertial, visuals, collisions, geometry and materials.

A part that cannot be read (an inertial with a mass that is not a number, a box without size) is
reported and left out; the rest of the link is still read. urdfdom behaves alike except that it
stops reading the link at the first bad part (and check_urdf still exits 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import Severity, did_you_mean
from modelkit.formats.fractions import clamped_fractions
from modelkit.formats.meshref import MeshChecker
from modelkit.formats.urdf.values import Context, Tolerated, number, origin, vector
from modelkit.model import (
    Box,
    Capsule,
    Cylinder,
    Geom,
    Geometry,
    Inertial,
    Link,
    Sphere,
    SurfaceFriction,
    VisualMaterial,
)
from modelkit.xmlsource import parse_numbers

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
            rgba = _rgba(ctx, color, name)
            if rgba is _SHORT_RGBA:
                found = True  # urdfdom keeps the material (black); modelkit keeps it without a colour
            elif color.get("rgba") is None:
                ctx.emit("MK120", "<color> has no `rgba` attribute", ctx.loc(color))
            elif rgba is None:
                found = True  # reported (MK129, MK121): the material is kept, without a colour
            else:
                found = True
                clamped, outside = clamped_fractions(rgba)
                if outside:
                    ctx.emit(
                        "MK513",
                        f'material "{name}": rgba "{color.get("rgba")}" has values outside 0..1 '
                        "(urdfdom rejects the colour; modelkit clamps it)",
                        ctx.loc(color, "rgba"),
                        hint="colours are fractions: 255 is written 1",
                    )
                material.diffuse = clamped[:3]
                material.transparency = 1.0 - clamped[3]
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
                f'a <material> in a visual of link "{link}" has no `name`: check_urdf loads the file but '
                "urdfdom drops this visual, PyBullet refuses the file",
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


_SHORT_RGBA: list[float] = []  # the colour of an rgba that does not hold four numbers (MK146)

COLOUR_WORD = Tolerated(
    "MK129",
    "modelkit keeps the material without a colour; urdfdom logs an error, drops the colour and loads the "
    "file; PyBullet reads each of four parts with C's atof (a word is 0) or, with another count, says "
    "\"has no rgba\" and keeps 0 0 0 0; MuJoCo refuses the file",
)


def _rgba(ctx: Context, color: Element, name: str | None) -> list[float] | None:
    """The four numbers of ``rgba``; :data:`_SHORT_RGBA` (reported, MK146) when it holds another count."""
    text = color.get("rgba")
    numbers = parse_numbers(text)
    if numbers is None or len(numbers) == 4:
        return vector(ctx, color, "rgba", f'material "{name}" color', count=4, tolerated=COLOUR_WORD)
    ctx.emit(
        "MK146",
        f'material "{name}": `rgba="{text}"` holds {len(numbers)} numbers, not 4; urdfdom silently makes the '
        "colour black (0 0 0 1) and PyBullet uses its default colour; MuJoCo refuses the file",
        ctx.loc(color, "rgba"),
        hint='give red, green, blue and alpha, e.g. rgba="1 0 0 1"',
    )
    return _SHORT_RGBA


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
    contact = ctx.first(element, "contact")
    friction = None
    if contact is not None:
        friction = contact_friction(ctx, contact, link.name)
        link.extras["urdf_contact"] = contact_parameters(contact)
    for collision in ctx.children(element, "collision"):
        geom = _read_geom(ctx, collision, link.name, meshes, visual_only=False)
        if geom is not None:
            geom.friction = friction
            link.collisions.append(geom)
    return link


FRICTIONS = ("lateral_friction", "spinning_friction", "rolling_friction")


def contact_parameters(contact: Element) -> dict[str, str]:
    """The children of PyBullet's ``<contact>`` other than its frictions, as written (``value``; ""
    for ``<friction_anchor/>``): PyBullet's own contact model, which the URDF writer writes back."""
    out: dict[str, str] = {}
    for child in contact:
        tag = child.tag
        if isinstance(tag, str) and tag not in FRICTIONS and tag not in out:
            out[tag] = child.get("value", "")
    return out


PYBULLET_LATERAL_DEFAULT = 0.5
"""PyBullet's lateral friction of a link whose ``<contact>`` does not give one."""

CONTACT_WORD = Tolerated(
    "MK128",
    "modelkit leaves it out; PyBullet reads the text as {atof} (C's atof); urdfdom and MuJoCo ignore "
    "<contact> and load the file",
)


def contact_friction(ctx: Context, contact: Element, link: str) -> SurfaceFriction | None:
    """PyBullet's ``<contact>`` of a link: its lateral, spinning and rolling friction hold for all the
    link's collisions (None when it gives none of the three). The other children (stiffness,
    restitution...) are PyBullet's own contact model and are not read."""
    values: dict[str, float] = {}
    for tag in FRICTIONS:
        child = ctx.first(contact, tag)
        if child is None:
            continue
        value = number(ctx, child, "value", f'{tag} of link "{link}"', required=True, tolerated=CONTACT_WORD)
        if value is not None and value < 0.0:
            ctx.emit("MK121", f'{tag} of link "{link}": `value="{child.get("value")}"` is negative',
                     ctx.loc(child, "value"))
            value = None
        if value is not None:
            values[tag] = value
    if not values:
        return None
    return SurfaceFriction(
        values.get("lateral_friction", PYBULLET_LATERAL_DEFAULT),
        values.get("spinning_friction", 0.0),
        values.get("rolling_friction", 0.0),
    )


def read_inertial(ctx: Context, element: Element, link: str) -> Inertial | None:
    """Mass, centre of mass and inertia; the ``<origin>`` rotation turns the tensor into link axes.

    None (with the faults reported) when any part is missing or malformed, as urdfdom drops it.
    """
    origin_el = ctx.first(element, "origin")
    pose = origin(ctx, origin_el, f'inertial of link "{link}"', tolerated=INERTIAL_WORD)
    mass_el = ctx.first(element, "mass")
    inertia_el = ctx.first(element, "inertia")
    for name, child in (("mass", mass_el), ("inertia", inertia_el)):
        if child is None:
            _unreadable_inertial(ctx, element, link, f"has no <{name}>")
    if mass_el is not None and mass_el.get("value") is None:
        _unreadable_inertial(ctx, mass_el, link, "has a <mass> without `value`")
        mass = None
    else:
        mass = None if mass_el is None else number(ctx, mass_el, "value", f'mass of link "{link}"',
                                                    tolerated=INERTIAL_WORD)
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


# What urdfdom does with a link whose <inertial> it cannot read (MK144, MK145, MK127).
URDFDOM_INERTIAL = (
    "urdfdom (check_urdf, libsdformat's URDF conversion) logs an error, keeps the mass it read with an "
    "all-zero inertia, drops every visual and collision of the link, and loads the robot"
)
INERTIAL_WORD = Tolerated(
    "MK127",
    f"modelkit leaves the inertial out; {URDFDOM_INERTIAL}; PyBullet reads the text as {{atof}} (C's atof) "
    "and loads the file; MuJoCo refuses it",
)


def _unreadable_inertial(ctx: Context, element: Element, link: str, what: str) -> None:
    ctx.emit(
        "MK145",
        f'<inertial> of link "{link}" {what}; modelkit leaves the inertial out; {URDFDOM_INERTIAL}; PyBullet '
        "and MuJoCo refuse the file",
        ctx.loc(element),
        hint='give <mass value="..."/> and <inertia ixx=".." ixy=".." ixz=".." iyy=".." iyz=".." izz=".."/>',
    )


def _inertia(ctx: Context, element: Element, link: str) -> rot3.M3 | None:
    missing = [k for k in INERTIA_KEYS if element.get(k) is None]
    if any(k in missing for k in ("ixx", "iyy", "izz")):
        _unreadable_inertial(ctx, element, link, f"has an <inertia> without {', '.join(missing)}")
        return None
    if missing:
        ctx.emit(
            "MK144",
            f'<inertia> of link "{link}" lacks {", ".join(missing)}; modelkit reads them as 0, as PyBullet '
            f"does; {URDFDOM_INERTIAL}; MuJoCo refuses the file",
            ctx.loc(element),
            hint=" ".join(f'{k}="0"' for k in missing) + " (all six of ixx, ixy, ixz, iyy, iyz, izz)",
        )
    values = [number(ctx, element, k, f'inertia of link "{link}"', default=0.0, tolerated=INERTIAL_WORD)
              for k in INERTIA_KEYS]
    if any(v is None for v in values):
        return None
    return rot3.inertia_from_moments(*(float(v or 0.0) for v in values))


# What urdfdom does with a shape it cannot read (MK143, MK412, MK421).
URDFDOM_DROPS_SHAPE = (
    "urdfdom (check_urdf, libsdformat) logs an error, drops it and every later visual and collision of the "
    "link, and loads the file"
)
# A shape without its size or file (MK143): who loads the file and who refuses it.
UNREADABLE_SHAPE_CONSUMERS = f"{URDFDOM_DROPS_SHAPE}; PyBullet and MuJoCo refuse the file"


def _unreadable_shape(ctx: Context, shape: Element, what: str, lacks: str) -> None:
    ctx.emit(
        "MK143",
        f"<{ctx.tag(shape)}> of the {what} has no {lacks}; modelkit leaves the {what} out "
        f"({UNREADABLE_SHAPE_CONSUMERS})",
        ctx.loc(shape),
    )


# A visual or collision without a shape (MK122): who loads the file and who refuses it.
NO_SHAPE_CONSUMERS = (
    "urdfdom (check_urdf, libsdformat) logs an error, drops it and loads the file; PyBullet refuses the file"
)


# A word where a shape's number should be (MK116, MK127): urdfdom logs it and loads the file.
VISUAL_WORD = Tolerated(
    "MK116",
    f"modelkit leaves the visual out; {URDFDOM_DROPS_SHAPE}; PyBullet reads the text as {{atof}} (C's atof); "
    "MuJoCo's URDF import discards visuals",
)
COLLISION_WORD = Tolerated(
    "MK127",
    f"modelkit leaves the collision out; {URDFDOM_DROPS_SHAPE}; PyBullet reads the text as {{atof}} (C's "
    "atof) and loads the file; MuJoCo refuses it",
)


def _shape_word(visual_only: bool) -> Tolerated:
    return VISUAL_WORD if visual_only else COLLISION_WORD


def _read_geom(
    ctx: Context, element: Element, link: str, meshes: MeshChecker, visual_only: bool
) -> Geom | None:
    kind = "visual" if visual_only else "collision"
    what = f'{kind} of link "{link}"'
    pose = origin(ctx, ctx.first(element, "origin"), what, tolerated=_shape_word(visual_only))
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
            _unreadable_shape(ctx, shape, what, "`size`")
            return None
        size = vector(ctx, shape, "size", f"box of the {what}", tolerated=_shape_word(visual_only))
        if size is None:
            return None
        if any(s <= 0.0 for s in size):
            _size_not_positive(ctx, shape, "size", f"box of the {what}", min(size), visual_only)
        return Box(size=tuple(size))
    if tag in ("cylinder", "capsule"):
        if tag == "capsule":
            ctx.uses_feature("<capsule>", "1.1", loc)
        missing = [k for k in ("radius", "length") if shape.get(k) is None]
        if missing:
            _unreadable_shape(ctx, shape, what, " and ".join(f"`{k}`" for k in missing))
            return None
        radius = number(ctx, shape, "radius", f"{tag} of the {what}", tolerated=_shape_word(visual_only))
        length = number(ctx, shape, "length", f"{tag} of the {what}", tolerated=_shape_word(visual_only))
        if radius is None or length is None:
            return None
        if radius <= 0.0:
            _size_not_positive(ctx, shape, "radius", f"{tag} of the {what}", radius, visual_only)
        if length < 0.0 or (length == 0.0 and tag == "cylinder"):
            _size_not_positive(ctx, shape, "length", f"{tag} of the {what}", length, visual_only)
        return Cylinder(radius, length) if tag == "cylinder" else Capsule(radius, length)
    if tag == "sphere":
        if shape.get("radius") is None:
            _unreadable_shape(ctx, shape, what, "`radius`")
            return None
        radius = number(ctx, shape, "radius", f"sphere of the {what}", tolerated=_shape_word(visual_only))
        if radius is None:
            return None
        if radius <= 0.0:
            _size_not_positive(ctx, shape, "radius", f"sphere of the {what}", radius, visual_only)
        return Sphere(radius)
    if tag == "mesh":
        return _mesh(ctx, shape, what, meshes, visual_only)
    pybullet_shape = tag in PYBULLET_SHAPES
    others = "PyBullet reads it, MuJoCo refuses the file" if pybullet_shape else "PyBullet, MuJoCo refuse it"
    ctx.emit(
        "MK421" if pybullet_shape else "MK412",
        f"{'PyBullet' if pybullet_shape else 'unknown'} geometry type <{tag}> in the {what}; URDF has box, "
        f"cylinder, sphere, capsule and mesh, so modelkit leaves the {what} out ({URDFDOM_DROPS_SHAPE}; "
        f"{others})",
        loc,
        severity=Severity.WARNING,
    )
    return None


# PyBullet's own URDF shapes (MK421).
PYBULLET_SHAPES = ("plane", "cdf")


def _scale_as_pybullet_reads_it(
    ctx: Context, shape: Element, what: str, text: str, numbers: list[float]
) -> tuple[float, float, float]:
    """MK420: a mesh ``scale`` of another count than three, read as PyBullet reads it (the first three
    numbers; one or two: the first as a uniform scale)."""
    if len(numbers) > 3:
        count, how, used = f"{len(numbers)} numbers", "the first three", (numbers[0], numbers[1], numbers[2])
    else:
        count = ("one number", "two numbers")[len(numbers) - 1]
        how, used = "the first as a uniform scale", (numbers[0], numbers[0], numbers[0])
    ctx.emit(
        "MK420",
        f'mesh of the {what}: `scale="{text}"` has {count}; URDF needs three. modelkit reads {how}, as '
        "PyBullet does; urdfdom logs an error, drops the shape and every later visual and collision of the "
        "link, and loads the robot; MuJoCo refuses the file",
        ctx.loc(shape, "scale"),
        hint=f'write scale="{" ".join(f"{v:g}" for v in used)}"',
    )
    return used


def _not_positive(
    ctx: Context, element: Element, attribute: str, what: str, rule: str = "be positive"
) -> None:
    ctx.emit(
        "MK400",
        f'{what}: `{attribute}="{element.get(attribute)}"` must {rule}',
        ctx.loc(element, attribute),
    )


def _size_not_positive(
    ctx: Context, element: Element, attribute: str, what: str, value: float, visual_only: bool
) -> None:
    """MK417 for a visual; MK416 for a collision: a warning when zero, an error when negative (see codes)."""
    if visual_only:
        ctx.emit(
            "MK417",
            f'{what}: `{attribute}="{element.get(attribute)}"` is not positive, so it draws nothing '
            "(check_urdf, PyBullet and MuJoCo's URDF import, which drops visuals, load it)",
            ctx.loc(element, attribute),
        )
        return
    if value < 0.0:
        ctx.emit(
            "MK416",
            f'{what}: `{attribute}="{element.get(attribute)}"` is negative; check_urdf and PyBullet load it, '
            "but it cannot be simulated meaningfully (PyBullet inverts the shape's bounds and the body falls "
            "through the floor) and MuJoCo refuses it",
            ctx.loc(element, attribute),
            severity=Severity.ERROR,
        )
        return
    ctx.emit(
        "MK416",
        f'{what}: `{attribute}="{element.get(attribute)}"` is zero; check_urdf and PyBullet load it '
        "(PyBullet collides with a point), MuJoCo refuses it",
        ctx.loc(element, attribute),
        hint="to mean no collision, leave the <collision> out",
    )


def _mesh(ctx: Context, shape: Element, what: str, meshes: MeshChecker, visual_only: bool) -> Geometry | None:
    filename = shape.get("filename")
    if filename is None:
        _unreadable_shape(ctx, shape, what, "`filename`")
        return None
    scale = (1.0, 1.0, 1.0)
    text = shape.get("scale")
    if text is not None:
        numbers = parse_numbers(text)
        if numbers and len(numbers) != 3 and all(math.isfinite(v) for v in numbers):
            scale = _scale_as_pybullet_reads_it(ctx, shape, what, text, numbers)
        else:
            values = vector(ctx, shape, "scale", f"mesh of the {what}", tolerated=_shape_word(visual_only))
            if values is None:
                return None
            scale = (values[0], values[1], values[2])
        if any(s == 0.0 for s in scale):
            _not_positive(ctx, shape, "scale", f"mesh of the {what}", "not be zero")
    return meshes.mesh(filename, ctx.loc(shape, "filename"), scale=scale, visual_only=visual_only)
