"""``<geometry>`` and ``<material>``: SDF shapes and colours as the robot model holds them.

Box, sphere, cylinder, capsule, ellipsoid, cone and mesh map one to one (SDF cylinders, capsules
and cones already lie along Z). Plane, heightmap, image and polyline have no counterpart in the
model: they are reported (MK430) and kept as data for writers that can use them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from lxml.etree import _Element as Element

from modelkit.diagnostics import DiagnosticSink, Severity
from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.values import child, is_custom, local_name
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geometry, Mesh, Sphere, VisualMaterial

SHAPES = ("box", "sphere", "cylinder", "capsule", "ellipsoid", "cone", "mesh")
UNMODELLED = ("plane", "heightmap", "image", "polyline")


@dataclass
class ShapeResult:
    """What a ``<geometry>`` gave: a model shape, or data about a shape the model cannot hold."""

    geometry: Geometry | None = None
    unmodelled: dict[str, Any] | None = None


def element_data(element: Element) -> Any:
    """An element's content as plain data: numbers where the text is numbers, dicts for children
    (repeated children become lists, attributes are ``@name`` keys)."""
    kids = [c for c in element if isinstance(c.tag, str)]
    if not kids and not element.attrib:
        return _scalar((element.text or "").strip())
    out: dict[str, Any] = {"@" + str(k): str(v) for k, v in element.attrib.items()}
    groups: dict[str, list[Any]] = {}
    for c in kids:
        key = local_name(c)
        groups.setdefault(key, []).append(element_data(c))
    for key, items in groups.items():
        out[key] = items[0] if len(items) == 1 else items
    text = (element.text or "").strip()
    if text:
        out["#text"] = _scalar(text)
    return out


def _scalar(text: str) -> Any:
    parts = text.split()
    try:
        numbers = [float(p) for p in parts]
    except ValueError:
        return text
    if not numbers:
        return text
    return numbers[0] if len(numbers) == 1 else numbers


def read_geometry(
    ctx: Context, src: SdfDocument, geometry: Element | None, owner: str, visual_only: bool
) -> ShapeResult:
    """The shape in a ``<geometry>`` element; ``owner`` names the visual/collision for messages."""
    sink = ctx.sink
    values = src.values
    if geometry is None:
        return ShapeResult()  # a missing <geometry> is reported by the caller
    shapes = [c for c in geometry if isinstance(c.tag, str) and not is_custom(c)]
    known = [c for c in shapes if c.tag in (*SHAPES, *UNMODELLED, "empty")]
    if not known:
        sink.emit(
            "MK122",
            f"the <geometry> of {owner} holds no shape; libsdformat loads it as an empty geometry",
            values.loc(geometry),
            severity=Severity.WARNING,
        )
        return ShapeResult()
    if len(known) > 1:
        sink.emit(
            "MK124",
            f"the <geometry> of {owner} holds {len(known)} shapes; only the first (<{known[0].tag}>) is used",
            values.loc(known[1]),
        )
    shape = known[0]
    kind = str(shape.tag)
    if kind == "empty":
        return ShapeResult()
    if kind in UNMODELLED:
        sink.emit(
            "MK430",
            f"{owner} has a <{kind}> geometry, which the robot model cannot hold; it is kept only as data",
            values.loc(shape),
        )
        return ShapeResult(unmodelled={"kind": kind, "params": element_data(shape)})
    return ShapeResult(geometry=_shape(ctx, src, shape, owner, visual_only))


def _not_positive(
    sink: DiagnosticSink,
    src: SdfDocument,
    el: Element,
    what: str,
    values: tuple[float, ...],
    visual_only: bool,
) -> None:
    """MK417 for a visual; MK416 for a collision: a warning when zero, an error when negative (see codes)."""
    shown = f"{values[0]:g}" if len(values) == 1 else str([float(v) for v in values])
    where = src.values.text_loc(el)
    if visual_only:
        sink.emit(
            "MK417",
            f"{what} is {shown}, not positive, so it draws nothing (libsdformat loads it)",
            where,
        )
    elif min(values) < 0.0:
        sink.emit(
            "MK416",
            f"{what} is negative ({shown}); libsdformat loads it, but it cannot be simulated "
            "meaningfully (PyBullet inverts the shape's bounds and the body falls through the floor); "
            "MuJoCo refuses it",
            where,
            severity=Severity.ERROR,
        )
    else:
        sink.emit(
            "MK416",
            f"{what} is {shown}; libsdformat loads it, MuJoCo refuses it",
            where,
            hint="to mean no collision, leave the <collision> out",
        )


def _positive(
    sink: DiagnosticSink, src: SdfDocument, el: Element | None, value: float, what: str, visual_only: bool
) -> float:
    if value <= 0.0 and el is not None:
        _not_positive(sink, src, el, what, (value,), visual_only)
    return value


def _shape(ctx: Context, src: SdfDocument, shape: Element, owner: str, visual_only: bool) -> Geometry | None:
    values = src.values
    sink = ctx.sink
    kind = shape.tag

    def number(name: str, default: float) -> float:
        el = child(shape, name)
        value = values.number(el, default)
        value = default if value is None else value
        return _positive(sink, src, el, value, f"<{kind}> {name} of {owner}", visual_only)

    def positive_vector(name: str) -> tuple[float, ...]:
        """A three-number child (ones when absent or unreadable); non-positive entries reported."""
        el = child(shape, name)
        vector = values.vector(el, 3) if el is not None else None
        vector = (1.0, 1.0, 1.0) if vector is None else vector
        if el is not None and any(v <= 0.0 for v in vector):
            _not_positive(sink, src, el, f"<{kind}> {name} of {owner}", tuple(vector), visual_only)
        return vector

    if kind == "box":
        return Box(positive_vector("size"))
    if kind == "sphere":
        return Sphere(number("radius", 1.0))
    if kind == "cylinder":
        return Cylinder(number("radius", 1.0), number("length", 1.0))
    if kind == "capsule":
        return Capsule(number("radius", 0.5), number("length", 1.0))
    if kind == "cone":
        return Cone(number("radius", 0.5), number("length", 1.0))
    if kind == "ellipsoid":
        return Ellipsoid(positive_vector("radii"))
    return _mesh(ctx, src, shape, owner, visual_only)


def _mesh(ctx: Context, src: SdfDocument, shape: Element, owner: str, visual_only: bool) -> Mesh | None:
    values = src.values
    uri_el = child(shape, "uri")
    uri = values.text(uri_el)
    if not uri or uri_el is None:
        ctx.sink.emit("MK122", f"the <mesh> of {owner} has no <uri>", values.loc(shape))
        return None
    scale_el = child(shape, "scale")
    scale = values.vector(scale_el, 3) if scale_el is not None else None
    if scale is None:
        scale = (1.0, 1.0, 1.0)
    submesh_el = child(shape, "submesh")
    submesh = values.text(child(submesh_el, "name")) if submesh_el is not None else None
    mesh = ctx.mesh(
        uri,
        src,
        values.text_loc(uri_el),
        (float(scale[0]), float(scale[1]), float(scale[2])),
        visual_only,
        submesh or None,
    )
    if submesh_el is not None and values.boolean(child(submesh_el, "center")):
        mesh.source_params["center_submesh"] = True
    optimization = shape.get("optimization")
    if optimization:
        mesh.source_params["optimization"] = optimization
    return mesh


@dataclass
class MaterialResult:
    material: VisualMaterial | None
    extras: dict[str, Any] = field(default_factory=dict)  # what VisualMaterial cannot hold


def read_material(
    ctx: Context, src: SdfDocument, material: Element | None, transparency: Element | None, owner: str
) -> MaterialResult:
    """A visual's ``<material>`` (and ``<transparency>``) as a :class:`VisualMaterial`."""
    values = src.values
    visual_transparency = values.number(transparency) if transparency is not None else None
    if material is None:
        if visual_transparency:
            return MaterialResult(VisualMaterial(transparency=visual_transparency))
        return MaterialResult(None)
    result = VisualMaterial()
    extras: dict[str, Any] = {}
    diffuse = values.color(child(material, "diffuse"))
    ambient = values.color(child(material, "ambient"))
    specular = values.color(child(material, "specular"))
    emissive = values.color(child(material, "emissive"))
    if diffuse is not None:
        result.diffuse = tuple(diffuse[:3])
        result.transparency = 1.0 - diffuse[3]
    if visual_transparency is not None:
        result.transparency = visual_transparency
    if specular is not None:
        result.specular = tuple(specular[:3])
    if emissive is not None:
        result.emissive = tuple(emissive[:3])
    if ambient is not None:  # the model holds it as an intensity of the diffuse colour
        result.ambient = _ambient_intensity(ambient, diffuse)
    script = child(material, "script")
    if script is not None:
        name = values.text(child(script, "name"))
        uris = [values.text(u) for u in script if isinstance(u.tag, str) and u.tag == "uri"]
        result.name = name or None
        extras["script"] = {"name": name, "uri": [u for u in uris if u]}
        for what, given in (("uri", any(uris)), ("name", bool(name))):
            if not given:  # libsdformat's Material::Load refuses the file (errors 9 and 8)
                ctx.sink.emit(
                    "MK122",
                    f"the material <script> of {owner} has no <{what}> (or it is empty); libsdformat "
                    "refuses the file",
                    values.loc(script),
                    hint="give <uri> (e.g. file://media/materials/scripts/gazebo.material) and <name>, or "
                    "replace the script by <diffuse>/<ambient> colours",
                )
        if diffuse is None:
            ctx.sink.emit(
                "MK533",
                f'the colour of {owner} comes from the OGRE material script "{name}"; only its name is kept',
                values.loc(script),
                hint="add a <diffuse> colour for tools that do not read Gazebo material scripts",
            )
    _check_shader(ctx, src, child(material, "shader"), owner)
    for key in ("pbr", "shader", "lighting", "double_sided", "render_order"):
        el = child(material, key)
        if el is not None:
            extras[key] = element_data(el)
    pbr = child(material, "pbr")
    if pbr is not None:
        for workflow in pbr:
            albedo = child(workflow, "albedo_map") if isinstance(workflow.tag, str) else None
            texture = values.text(albedo)
            if albedo is not None and texture:
                result.texture = texture
                ctx.texture(texture, src, values.text_loc(albedo))
                break
    return MaterialResult(result, extras)


_SHADERS = (  # libsdformat 12 takes both spellings of the normal-map types
    "pixel",
    "vertex",
    "normal_map_object_space",
    "normal_map_tangent_space",
    "normal_map_objectspace",
    "normal_map_tangentspace",
)


def _check_shader(ctx: Context, src: SdfDocument, shader: Element | None, owner: str) -> None:
    """libsdformat's Material::Load refuses an unknown shader type and a normal-map shader without a
    ``<normal_map>`` (error 8)."""
    if shader is None:
        return
    kind = (shader.get("type") or "pixel").strip()
    if kind not in _SHADERS:
        ctx.sink.emit(
            "MK121",
            f'the material shader type "{kind}" of {owner} is not one of {", ".join(_SHADERS[:4])}; '
            "libsdformat refuses the file",
            src.values.loc(shader, "type"),
        )
    elif kind.startswith("normal_map") and child(shader, "normal_map") is None:
        ctx.sink.emit(
            "MK122",
            f'the material shader of {owner} is "{kind}" but has no <normal_map>; libsdformat refuses '
            "the file",
            src.values.loc(shader),
            hint="give <normal_map> the texture file, or use the shader type pixel",
        )


def _ambient_intensity(
    ambient: tuple[float, float, float, float], diffuse: tuple[float, float, float, float] | None
) -> float | None:
    """VRML's ambientIntensity when the ambient colour is a multiple of the diffuse colour."""
    if diffuse is None:
        return None
    a = ambient[:3]
    d = diffuse[:3]
    if max(d) <= 0.0:
        return None
    k = sum(x * y for x, y in zip(a, d, strict=True)) / sum(y * y for y in d)
    # numpy.allclose(a, k·d, atol=1e-6): |a − k·d| ≤ atol + rtol·|k·d|, rtol = 1e-5
    if all(abs(x - k * y) <= 1e-6 + 1e-5 * abs(k * y) for x, y in zip(a, d, strict=True)) and 0.0 <= k <= 1.0:
        return k
    return None
