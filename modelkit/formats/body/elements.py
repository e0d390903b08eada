"""Walking a link's `elements` tree: shapes, rigid bodies, devices, resources.

An affine transform stack (Trans·Rot·Scale per node, §3.3 of body-format.md; plain tuples, see
:mod:`modelkit.rot3`: reading imports no numpy) and a visual/collision mode are carried down the
tree. Choreonoid's Y-axis primitives are turned into
the model's Z-axis primitives here (the only place where that rotation is applied).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation
from modelkit.formats.body import devices as dev
from modelkit.formats.body import values as v
from modelkit.formats.body.values import IDENTITY_AFFINE, Affine
from modelkit.formats.fractions import clamped_fractions
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Device,
    Ellipsoid,
    Geom,
    Geometry,
    Mesh,
    Sphere,
    TriangleMeshData,
    VisualMaterial,
)
from modelkit.resources import Resolver, found_report
from modelkit.rot3 import peek
from modelkit.spatial import Pose
from modelkit.yamltree import YamlDocument, YMap, YNode, YScalar, YSeq, parse_yaml, read_text

# Choreonoid's cylinders, capsules and cones lie along local Y; the model's along Z.
Y_TO_Z_TUPLE: rot3.M3 = rot3.axis_angle((1.0, 0.0, 0.0), -math.pi / 2.0)


def __getattr__(name: str) -> Any:
    """``Y_TO_Z`` as a numpy array, for the writers (imported on first use, not by the reader)."""
    if name == "Y_TO_Z":
        import numpy as np

        return np.array(Y_TO_Z_TUPLE)
    raise AttributeError(name)


SCENE_ONLY_NODES = frozenset(
    {"Node", "LineSet", "DirectionalLight", "PerspectiveCamera", "OrthographicCamera", "Fog", "Text"}
)
MESH_EXTENSIONS = frozenset({".stl", ".obj", ".dae", ".wrl"})
YAML_EXTENSIONS = frozenset({".yaml", ".yml"})


@dataclass
class WalkContext:
    """What the walk needs to know about the file being read."""

    path: Path
    display: str
    angle_scale: float
    sink: DiagnosticSink
    resolver: Resolver
    check_resources: bool = True
    faithful_extrusion: bool = True
    main_anchors: dict[str, YNode] = field(default_factory=dict)
    mesh_cache: dict[tuple[str, str | None], str | None] = field(default_factory=dict)
    yaml_cache: dict[str, YamlDocument | None] = field(default_factory=dict)
    depth: int = 0

    @property
    def base_dir(self) -> Path:
        return self.path.parent


@dataclass
class Collected:
    """Everything a link's elements contribute."""

    visuals: list[Geom] = field(default_factory=list)
    collisions: list[Geom] = field(default_factory=list)
    rigid_bodies: list[tuple[float, rot3.V3, rot3.M3, SourceLocation]] = field(default_factory=list)
    devices: list[Device] = field(default_factory=list)


MAX_ELEMENT_DEPTH = 100


def iter_elements(node: YNode | None) -> list[tuple[str, YMap]]:
    """The (type, node) pairs of an `elements` value in its three forms (§3.1)."""
    if node is None:
        return []
    if isinstance(node, YSeq):
        out = []
        for item in node.items:
            if isinstance(item, YMap):
                t = v.scalar_text(item.get("type"))
                if t is not None:
                    out.append((t, item))
        return out
    if isinstance(node, YMap):
        if "type" in node:
            t = v.scalar_text(node.get("type"))
            return [(t, node)] if t is not None else []
        pairs = []
        for key in sorted(node.entries):
            value = node.get(key)
            if isinstance(value, YMap):
                nested = v.scalar_text(value.get("type"))
                if nested is None or nested == key:
                    pairs.append((key, value))
        return pairs
    return []


def walk(
    elements: YNode | None, transform: Affine, mode: str, out: Collected, ctx: WalkContext, depth: int = 0
) -> None:
    if depth > MAX_ELEMENT_DEPTH:
        if elements is not None:
            ctx.sink.emit(
                "MK608",
                f"elements are nested more than {MAX_ELEMENT_DEPTH} levels deep; the rest is not read",
                elements.loc,
            )
        return
    for node_type, node in iter_elements(elements):
        _walk_node(node_type, node, transform, mode, out, ctx, depth)


def _walk_node(
    node_type: str, node: YMap, transform: Affine, mode: str, out: Collected, ctx: WalkContext, depth: int
) -> None:
    sink = ctx.sink
    if node_type == "Skip" or node_type in SCENE_ONLY_NODES:
        return
    if node_type == "Group":
        walk(node.get("elements"), transform, mode, out, ctx, depth + 1)
    elif node_type == "Transform":
        walk(
            node.get("elements"),
            v.compose(transform, v.node_transform(node, ctx.angle_scale, sink)),
            mode,
            out,
            ctx,
            depth + 1,
        )
    elif node_type in ("Visual", "Collision"):
        new_mode = node_type.lower()
        if mode not in ("both", new_mode):
            other = "Collision" if new_mode == "visual" else "Visual"
            sink.emit("MK604", f"a {node_type} node inside a {other} node: Choreonoid refuses this", node.loc)
            return
        inner = v.compose(transform, v.node_transform(node, ctx.angle_scale, sink))
        shape = node.get("shape")
        if isinstance(shape, YMap):
            add_shape(shape, inner, new_mode, out, ctx)
        resource = node.get("resource")
        if isinstance(resource, YMap):
            add_resource(resource, inner, new_mode, out, ctx, depth)
        walk(node.get("elements"), inner, new_mode, out, ctx, depth + 1)
    elif node_type == "RigidBody":
        inner = v.compose(transform, v.node_transform(node, ctx.angle_scale, sink))
        _add_rigid_body(node, inner, out)
        walk(node.get("elements"), inner, mode, out, ctx, depth + 1)
    elif node_type == "Resource":
        add_resource(node, transform, mode, out, ctx, depth)
    elif node_type == "Shape":
        add_shape(node, transform, mode, out, ctx)
    elif node_type in dev.CORE_DEVICES or node_type in dev.PLUGIN_DEVICES:
        inner = v.compose(transform, v.node_transform(node, ctx.angle_scale, sink))
        _add_device(node_type, node, inner, out, ctx)
        walk(node.get("elements"), inner, mode, out, ctx, depth + 1)
    # Unknown node types are reported by the schema check (MK602/MK603) and skipped here.


def _add_rigid_body(node: YMap, affine: Affine, out: Collected) -> None:
    mass = v.get_number(node, "mass", default=0.0) or 0.0
    com = v.vector3(node.get("center_of_mass", "centerOfMass"))
    local_inertia = inertia_matrix(node.get("inertia"))
    linear, offset = affine
    c = rot3.add(rot3.matvec(linear, rot3.ZERO3 if com is None else com), offset)
    inertia = rot3.rotate_inertia(rot3.ZERO33 if local_inertia is None else local_inertia, linear)
    out.rigid_bodies.append((mass, c, inertia, node.loc))


def inertia_matrix(node: YNode | None) -> rot3.M3 | None:
    """9 numbers row-major, or 6 numbers xx, xy, xz, yy, yz, zz."""
    values = v.numbers(node)
    if values is None:
        return None
    if len(values) == 9:
        return rot3.mat3((values[0:3], values[3:6], values[6:9]))
    if len(values) == 6:
        return rot3.inertia_from_moments(*values)
    return None


# ---- devices ---------------------------------------------------------------------------------


def _add_device(kind: str, node: YMap, affine: Affine, out: Collected, ctx: WalkContext) -> None:
    name = v.get_text(node, "name") or ""
    if "scale" in node:
        ctx.sink.emit(
            "MK606",
            f'{kind} "{name}" has `scale`, which corrupts the device rotation in Choreonoid',
            node.key_loc("scale"),
        )
    params = dev.read_params(kind, node, ctx.angle_scale, ctx.sink)
    if kind in ("Camera", "CameraDevice"):
        fmt = params.get("format")
        if fmt not in dev.CAMERA_FORMATS:
            where = node.get("format")
            ctx.sink.emit(
                "MK600",
                f'camera "{name}" has no valid `format` '
                f"({'missing' if fmt is None else repr(fmt)}): Choreonoid creates no device",
                where.loc if where is not None else node.loc,
                hint="use COLOR, DEPTH, COLOR_DEPTH, POINT_CLOUD or COLOR_POINT_CLOUD",
            )
            return
        params["camera_kind"] = dev.CAMERA_FORMATS[fmt]
    if kind == "RangeSensor":
        for axis in ("yaw", "pitch"):
            lo, hi = v.number(node.get(f"min_{axis}_angle")), v.number(node.get(f"max_{axis}_angle"))
            if lo is not None and hi is not None and lo > hi:
                ctx.sink.emit(
                    "MK607",
                    f'range sensor "{name}": min_{axis}_angle {lo} exceeds max_{axis}_angle {hi}; '
                    "Choreonoid ignores both",
                    node.key_loc(f"min_{axis}_angle"),
                )
    if kind in dev.PLUGIN_DEVICES:
        params["plugin"] = True
    device_id = v.integer(node.get("id"))
    if device_id is not None:
        params["id"] = device_id
    pose, _ = split_affine(affine)
    if pose is None:
        pose = Pose(rot3.IDENTITY, affine[1])
    # The canonical device model: the pose becomes the robotics sensor frame (§8.7); the source's
    # optical_frame words stay in params for the .body writer.
    pose = Pose(dev.canonical_rotation(kind, params, pose.rotation_tuple), pose.translation_tuple)
    canonical, canonical_params = dev.canonical_device(kind, params)
    out.devices.append(Device(kind, name, pose, params, node.loc, canonical, canonical_params))


# ---- shapes ----------------------------------------------------------------------------------


def _close(a: float, b: float, rtol: float = 1e-5, atol: float = 1e-8) -> bool:
    """numpy's ``isclose``: |a − b| ≤ atol + rtol·|b|."""
    return abs(a - b) <= atol + rtol * abs(b)


def split_affine(affine: Affine) -> tuple[Pose | None, rot3.V3]:
    """Split an affine map into a rigid pose and a per-axis scale applied first.

    Returns (None, scale) when the linear part is not a rotation times a diagonal scale (shear).
    """
    linear, offset = affine
    columns = rot3.transpose(linear)
    scale = (rot3.norm(columns[0]), rot3.norm(columns[1]), rot3.norm(columns[2]))
    if any(s <= 1e-12 for s in scale):
        return None, scale
    c0, c1, c2 = ((c[0] / s, c[1] / s, c[2] / s) for c, s in zip(columns, scale, strict=True))
    gram = rot3.matmul((c0, c1, c2), rot3.transpose((c0, c1, c2)))  # RᵀR (its rows are R's columns)
    if not all(_close(gram[i][j], 1.0 if i == j else 0.0, atol=1e-9) for i in range(3) for j in range(3)):
        return None, scale
    if rot3.dot(c0, (c1[1] * c2[2] - c1[2] * c2[1], c1[2] * c2[0] - c1[0] * c2[2],
                     c1[0] * c2[1] - c1[1] * c2[0])) < 0:  # a mirror: a proper rotation, a negative x scale
        c0 = (-c0[0], -c0[1], -c0[2])
        scale = (-scale[0], scale[1], scale[2])
    return Pose(rot3.transpose((c0, c1, c2)), offset), scale


def _fraction(material: YMap, keys: tuple[str, ...], read: Any, ctx: WalkContext) -> Any:
    """A colour (three numbers) or an intensity or transparency (one) of a ``material``, each number
    clamped to 0..1 with MK513 when it is outside: Choreonoid loads it, but the model holds fractions,
    and libsdformat refuses such a colour (urdfdom drops it)."""
    node = material.get(*keys)
    value = read(node)
    if value is None or node is None:
        return value
    numbers = [float(x) for x in value] if isinstance(value, tuple | list) else [float(value)]
    clamped, outside = clamped_fractions(numbers)
    if not outside:
        return value
    shown = " ".join(f"{x:g}" for x in numbers)
    key = next((k for k in keys if k in material), keys[-1])
    ctx.sink.emit(
        "MK513",
        f"material `{key}` {shown} has values outside 0..1 (Choreonoid loads it; libsdformat refuses such a "
        "colour and urdfdom drops it; modelkit clamps it)",
        node.loc,
        hint="colours, intensities and transparency are fractions: 255 is written 1",
    )
    return clamped if len(clamped) > 1 else clamped[0]


def _material(shape: YMap, ctx: WalkContext) -> VisualMaterial | None:
    appearance = shape.get("appearance")
    if not isinstance(appearance, YMap):
        return None
    m = appearance.get("material")
    result = VisualMaterial()
    if isinstance(m, YMap):
        result.diffuse = _fraction(m, ("diffuse", "diffuseColor"), v.vector3, ctx)
        result.ambient = _fraction(m, ("ambient", "ambientIntensity"), v.number, ctx)
        result.specular = _fraction(m, ("specular", "specularColor"), v.vector3, ctx)
        result.emissive = _fraction(m, ("emissive", "emissiveColor"), v.vector3, ctx)
        result.transparency = _fraction(m, ("transparency",), v.number, ctx) or 0.0
        exponent = v.number(m.get("specular_exponent"))
        shininess = v.number(m.get("shininess"))
        if exponent is None and shininess is not None:
            exponent = 127.0 * min(max(shininess, 0.0), 1.0) + 1.0
        result.specular_exponent = exponent
    texture = appearance.get("texture")
    if isinstance(texture, YMap):
        uri_node = texture.get("uri", "url")
        uri = v.scalar_text(uri_node)
        if uri is not None and uri_node is not None:
            res = ctx.resolver.resolve(uri, ctx.base_dir, ctx.path)
            if res.path is None or not os.path.isfile(res.path):  # False for a name too long to look up
                ctx.sink.emit(
                    "MK507",
                    f'texture "{uri}" cannot be found'
                    + (f" ({res.message})" if res.message else f" at {res.path}"),
                    uri_node.loc,
                )
            result.texture = str(res.path) if res.path is not None else uri
    if peek(result, "diffuse") is None and result.texture is None and not isinstance(m, YMap):
        return None
    return result


def add_shape(shape: YMap, transform: Affine, mode: str, out: Collected, ctx: WalkContext) -> None:
    affine = v.compose(transform, v.node_transform(shape, ctx.angle_scale, ctx.sink))
    geometry_node = shape.get("geometry")
    if not isinstance(geometry_node, YMap):
        return  # an empty shape
    kind = v.scalar_text(geometry_node.get("type"))
    if kind is None:
        return
    material = _material(shape, ctx)
    name = v.get_text(shape, "name")
    if kind == "Resource":
        _add_mesh_file(geometry_node, affine, mode, out, ctx, material=material, name=name)
        return
    built = _build_geometry(kind, geometry_node, ctx)
    if built is None:
        return
    geometry, local = built
    placed = _place(geometry, v.compose(affine, local), kind, geometry_node.loc, ctx)
    if placed is None:
        return
    geom = Geom(placed[0], placed[1], name=name, material=material, source=shape.loc)
    _file_geom(geom, mode, out)


def _file_geom(geom: Geom, mode: str, out: Collected) -> None:
    if mode in ("both", "visual"):
        out.visuals.append(geom)
    if mode in ("both", "collision"):
        out.collisions.append(geom)


def _positive(geometry: YMap, key: str, default: float) -> float:
    value = v.get_number(geometry, key, default=default)
    return default if value is None else value


def _build_geometry(kind: str, g: YMap, ctx: WalkContext) -> tuple[Geometry, Affine] | None:
    """The geometry in Choreonoid's shape frame (cylinders along Y) and a local affine (identity)."""
    sink = ctx.sink
    local = IDENTITY_AFFINE
    if kind == "Box":
        read = v.vector3(g.get("size"))
        size = (1.0, 1.0, 1.0) if read is None else read
        if any(x < 0 for x in size):
            size_node = g.get("size")
            where = (
                size_node.items[next(i for i, x in enumerate(size) if x < 0)].loc
                if isinstance(size_node, YSeq)
                else g.loc
            )
            sink.emit("MK400", f"a box cannot be generated with size {list(size)} (negative edge)", where)
            return None
        return Box(size), local
    if kind == "Sphere":
        r = _positive(g, "radius", 1.0)
        if r <= 0:
            sink.emit("MK400", f"a sphere cannot be generated with radius {r}", (g.get("radius") or g).loc)
            return None
        return Sphere(r), local
    if kind in ("Cylinder", "Capsule", "Cone"):
        r = _positive(g, "radius", 1.0)
        h = _positive(g, "height", 1.0)
        bad_height = h < 0 if kind == "Capsule" else h <= 0
        if r <= 0 or bad_height:
            culprit: YNode = (g.get("radius") if r <= 0 else g.get("height")) or g
            sink.emit(
                "MK400", f"a {kind.lower()} cannot be generated with radius {r} and height {h}", culprit.loc
            )
            return None
        if kind == "Cylinder":
            return Cylinder(r, h), local
        return (Capsule(r, h) if kind == "Capsule" else Cone(r, h)), local
    if kind in ("Extrusion", "ElevationGrid", "IndexedFaceSet", "TriangleMesh"):
        mesh = _generated_mesh(kind, g, ctx)
        if mesh is None:
            return None
        return mesh, local
    return None  # unknown geometry: reported by the schema check (MK412)


def _generated_mesh(kind: str, g: YMap, ctx: WalkContext) -> Mesh | None:
    from modelkit.geometry import generated as gen

    sink = ctx.sink
    crease = v.number(g.get("crease_angle", "creaseAngle"))
    if crease is not None and ctx.angle_scale != 1.0 and 0.0 < crease < 1.0:
        sink.emit(
            "MK312",
            f"crease_angle {crease} is in degrees here; {crease} rad would be "
            f"{math.degrees(crease):.1f} degrees",
            g.key_loc("crease_angle" if "crease_angle" in g else "creaseAngle"),
        )
    params: dict[str, Any] = {}
    try:
        if kind == "Extrusion":
            cs = v.numbers(g.get("cross_section", "crossSection")) or []
            spine = v.numbers(g.get("spine")) or []
            orientation = v.numbers(g.get("orientation")) or []
            orientation = [x * ctx.angle_scale if i % 4 == 3 else x for i, x in enumerate(orientation)]
            scale = v.numbers(g.get("scale")) or []
            begin_cap = v.get_bool(g, "beginCap", default=True)
            end_cap = v.get_bool(g, "end_cap", "endCap", default=True)
            data, report = gen.extrusion(
                cs,
                spine,
                orientation=orientation,
                scale=scale,
                begin_cap=begin_cap,
                end_cap=end_cap,
                faithful=ctx.faithful_extrusion,
            )
            _extrusion_findings(report, g, ctx)
            params = {
                "cross_section": cs,
                "spine": spine,
                "orientation": orientation,
                "scale": scale,
                "begin_cap": begin_cap,
                "end_cap": end_cap,
                "faithful": ctx.faithful_extrusion,
            }
        elif kind == "ElevationGrid":
            xd = v.integer(g.get("x_dimension", "xDimension")) or 0
            zd = v.integer(g.get("z_dimension", "zDimension")) or 0
            xs = v.get_number(g, "x_spacing", "xSpacing", default=1.0) or 1.0
            zs = v.get_number(g, "z_spacing", "zSpacing", default=1.0) or 1.0
            heights = v.numbers(g.get("height")) or []
            data = gen.elevation_grid(xd, zd, xs, zs, heights, ccw=v.get_bool(g, "ccw", default=True))
        elif kind == "IndexedFaceSet":
            vertices = v.numbers(g.get("vertices", "coordinate")) or []
            faces = [int(x) for x in (v.numbers(g.get("faces", "coordIndex")) or [])]
            data, dropped = gen.indexed_face_set(vertices, faces)
            if dropped:
                sink.emit(
                    "MK409",
                    f"the last polygon ({dropped} indices) lacks its -1 terminator and is dropped",
                    _fault_location(g, "faces", None),
                )
        else:
            vertices = v.numbers(g.get("vertices", "coordinate")) or []
            triangles = [int(x) for x in (v.numbers(g.get("faces", "coordIndex", "triangles")) or [])]
            data = gen.triangle_mesh(vertices, triangles)
    except gen.GeometryError as exc:
        sink.emit(exc.code, f"{kind}: {exc.message}", _fault_location(g, exc.key, exc.index))
        return None
    return Mesh(data=data, generator=kind, source_params=params)


GEOMETRY_KEY_SPELLINGS = {
    "cross_section": ("cross_section", "crossSection"),
    "x_dimension": ("x_dimension", "xDimension"),
    "faces": ("faces", "coordIndex", "triangles"),
}


def _fault_location(g: YMap, key: str | None, index: int | None) -> SourceLocation:
    """The value (or the list element) of a geometry that a GeometryError blames."""
    if key is None:
        return g.loc
    found = g.find(*GEOMETRY_KEY_SPELLINGS.get(key, (key,)))
    if found is None:
        return g.loc
    _, value = found
    if index is not None and isinstance(value, YSeq) and 0 <= index < len(value.items):
        return value.items[index].loc
    return value.loc


def _extrusion_findings(report: Any, g: YMap, ctx: WalkContext) -> None:
    sink = ctx.sink
    spine_loc = g.key_loc("spine")
    if report.oblique_straight:
        sink.emit(
            "MK403",
            "the straight spine is neither along ±Y nor horizontal: Choreonoid shears and shrinks "
            "the cross-section (modelkit reproduces it; --vrml-extrusion gives the VRML97 shape)",
            spine_loc,
        )
    if report.mirrored:
        sink.emit(
            "MK404",
            "the straight spine points along -Y: Choreonoid mirrors the cross-section (a point reflection)",
            spine_loc,
        )
    if report.open_cross_section_with_caps:
        sink.emit(
            "MK406",
            "the cross-section is not closed but caps are on: the surface is not closed",
            g.key_loc("crossSection" if "crossSection" in g else "cross_section"),
        )
    if report.non_unit_orientation_axis:
        sink.emit(
            "MK415",
            "an orientation axis is not unit length; Choreonoid uses it unnormalised",
            g.key_loc("orientation"),
        )
    for key, count in sorted(report.dropped_numbers.items()):
        if count:
            spelled = {"cross_section": ("cross_section", "crossSection")}.get(key, (key,))
            where = next((s for s in spelled if s in g), spelled[0])
            sink.emit(
                "MK118",
                f"{count} trailing number(s) of `{where}` do not make a whole tuple and are dropped",
                g.key_loc(where),
            )


def _place(
    geometry: Geometry, affine: Affine, kind: str, loc: SourceLocation, ctx: WalkContext
) -> tuple[Geometry, Pose] | None:
    """Apply the accumulated transform: scale goes into the geometry, the rest into a pose."""
    pose, scale = split_affine(affine)
    uniform = all(_close(x, scale[0], rtol=1e-12) for x in scale)
    magnitude = (abs(scale[0]), abs(scale[1]), abs(scale[2]))
    if pose is None:
        # Shear: only triangles can carry it. Bake the linear map into the vertices.
        mesh = _as_triangles(geometry)
        if mesh is None:
            ctx.sink.emit("MK414", f"a sheared {kind} cannot be represented; it is left out", loc)
            return None
        import numpy as np  # the triangles are numpy arrays already

        baked = TriangleMeshData(mesh.vertices @ np.array(affine[0]).T, mesh.faces.copy())
        ctx.sink.emit(
            "MK414", f"the transforms above this {kind} shear it; its triangles carry the shear", loc
        )
        return Mesh(data=baked, generator=kind), Pose(rot3.IDENTITY, affine[1])
    if isinstance(geometry, Box):
        size = peek(geometry, "size")
        return Box((size[0] * magnitude[0], size[1] * magnitude[1], size[2] * magnitude[2])), pose
    if isinstance(geometry, Sphere):
        if uniform:
            return Sphere(geometry.radius * abs(scale[0])), pose
        ctx.sink.emit("MK414", "a sphere scaled non-uniformly becomes an ellipsoid", loc)
        return Ellipsoid(rot3.scale(geometry.radius, magnitude)), pose
    if isinstance(geometry, (Cylinder, Capsule, Cone)):
        radial_ok = math.isclose(abs(scale[0]), abs(scale[2]), rel_tol=1e-12)
        if radial_ok and (uniform or not isinstance(geometry, Capsule)):
            rz = Pose(rot3.matmul(pose.rotation_tuple, Y_TO_Z_TUPLE), pose.translation_tuple)
            cls = type(geometry)
            return cls(geometry.radius * abs(scale[0]), geometry.length * abs(scale[1])), rz
        ctx.sink.emit(
            "MK414", f"a {kind.lower()} scaled non-uniformly is kept as a scaled primitive mesh", loc
        )
        return Mesh(
            generator=kind, scale=scale, source_params={"radius": geometry.radius, "height": geometry.length}
        ), pose
    if isinstance(geometry, Mesh):
        geometry.scale = scale if not all(_close(x, 1.0) for x in scale) else (1.0, 1.0, 1.0)
        return geometry, pose
    return geometry, pose  # pragma: no cover - all geometry kinds handled above


def _as_triangles(geometry: Geometry) -> TriangleMeshData | None:
    if isinstance(geometry, Mesh) and geometry.data is not None:
        return geometry.data
    return None


# ---- resources -------------------------------------------------------------------------------


def add_resource(
    node: YMap, transform: Affine, mode: str, out: Collected, ctx: WalkContext, depth: int
) -> None:
    uri_node = node.get("uri")
    uri = v.scalar_text(uri_node)
    if uri is None or uri_node is None:
        return  # missing uri: reported by the schema check (MK101)
    suffix = Path(uri).suffix.lower()
    affine = v.compose(transform, v.node_transform(node, ctx.angle_scale, ctx.sink))
    if suffix in YAML_EXTENSIONS:
        _add_yaml_resource(node, uri, uri_node, affine, mode, out, ctx, depth)
        return
    _add_mesh_file(
        node, affine, mode, out, ctx, material=None, name=v.get_text(node, "name")
    )


def _add_mesh_file(
    node: YMap,
    affine: Affine,
    mode: str,
    out: Collected,
    ctx: WalkContext,
    *,
    material: VisualMaterial | None,
    name: str | None,
) -> None:
    uri_node = node.get("uri")
    uri = v.scalar_text(uri_node)
    if uri is None or uri_node is None:
        return
    fragment = v.get_text(node, "node", "fragment")
    visual_only = mode == "visual"
    resolution = ctx.resolver.resolve(uri, ctx.base_dir, ctx.path)
    path = resolution.path
    severity = Severity.WARNING if visual_only else None
    usage = " (visual only)" if visual_only else ""
    if resolution.code is not None:
        ctx.sink.emit(
            resolution.code,
            (resolution.message or uri) + usage,
            uri_node.loc,
            hint=resolution.hint,
            severity=severity,
        )
    elif path is not None:
        suffix = path.suffix.lower()
        report = found_report(resolution, uri)
        if report is not None:
            code, message, hint, warning = report
            severity_of_note = Severity.WARNING if warning else None
            ctx.sink.emit(code, message, uri_node.loc, hint=hint, severity=severity_of_note)
        if not os.path.exists(path):
            ctx.sink.emit(
                "MK500", f'resource "{uri}" not found at {path}{usage}', uri_node.loc, severity=severity
            )
        elif suffix not in MESH_EXTENSIONS:
            ctx.sink.emit(
                "MK506",
                f'resource "{uri}": {suffix or "no extension"} files are not supported '
                f"(supported: .stl .obj .dae .wrl .yaml)",
                uri_node.loc,
                severity=severity,
            )
        elif ctx.check_resources:
            _check_mesh_loads(path, fragment, node, uri, ctx, severity, usage)
    metadata = _mesh_metadata(node)
    mesh = Mesh(
        uri=uri,
        path=str(path) if path is not None else None,
        fragment=fragment,
        source_params={"metadata": metadata} if metadata else {},
    )
    placed = _place(mesh, affine, "mesh", node.loc, ctx)
    if placed is None:
        return
    _file_geom(Geom(placed[0], placed[1], name=name, material=material, source=uri_node.loc), mode, out)


def _mesh_metadata(node: YMap) -> dict[str, str]:
    meta = node.get("metadata")
    out: dict[str, str] = {}
    if isinstance(meta, YMap):
        unit = v.get_text(meta, "length_unit")
        axis = v.get_text(meta, "upper_axis")
        if unit:
            out["length_unit"] = unit
        if axis:
            out["upper_axis"] = axis
    elif isinstance(meta, YScalar):
        words = meta.value
        if "millimeter" in words:
            out["length_unit"] = "millimeter"
        elif "inch" in words:
            out["length_unit"] = "inch"
        if "y_upper" in words:
            out["upper_axis"] = "Y"
    return out


def _check_mesh_loads(
    path: Path,
    fragment: str | None,
    node: YMap,
    uri: str,
    ctx: WalkContext,
    severity: Severity | None,
    usage: str,
) -> None:
    key = (str(path), fragment)
    if key not in ctx.mesh_cache:
        from modelkit.geometry import meshfiles

        metadata = _mesh_metadata(node)
        ctx.mesh_cache[key] = meshfiles.mesh_problem(
            path, fragment, meshfiles.MeshMetadata(metadata.get("length_unit"), metadata.get("upper_axis"))
        )
    problem = ctx.mesh_cache[key]
    if problem:
        code, message = problem.split("\t", 1)
        where = node.get("node", "fragment") if code == "MK502" else node.get("uri")
        ctx.sink.emit(code, f'resource "{uri}": {message}{usage}', (where or node).loc, severity=severity)


def _add_yaml_resource(
    node: YMap,
    uri: str,
    uri_node: YNode,
    affine: Affine,
    mode: str,
    out: Collected,
    ctx: WalkContext,
    depth: int,
) -> None:
    resolution = ctx.resolver.resolve(uri, ctx.base_dir, ctx.path)
    if resolution.code is not None or resolution.path is None:
        ctx.sink.emit(
            resolution.code or "MK500",
            resolution.message or f'resource "{uri}" cannot be resolved',
            uri_node.loc,
            hint=resolution.hint,
        )
        return
    path = resolution.path
    key = str(path)
    if key not in ctx.yaml_cache:
        if not os.path.exists(path):  # False for a name too long to look up, as for a missing file
            ctx.sink.emit("MK500", f'YAML resource "{uri}" not found at {path}', uri_node.loc)
            ctx.yaml_cache[key] = None
        else:
            text = read_text(path, ctx.sink)
            # Choreonoid's YAML resource reader imports the main file's anchors (local ones win).
            ctx.yaml_cache[key] = (
                parse_yaml(text, str(path), ctx.sink, imported_anchors=ctx.main_anchors)
                if text is not None
                else None
            )
    doc = ctx.yaml_cache[key]
    if doc is None or doc.root is None:
        return
    fragment = v.get_text(node, "node", "fragment")
    content: YNode | None = doc.root
    if fragment is not None:
        content = doc.anchors.get(fragment) or ctx.main_anchors.get(fragment)
        if content is None:
            where = node.get("node", "fragment") or node
            ctx.sink.emit(
                "MK502",
                f'fragment "{fragment}" is not found in "{uri}" (it must be an anchor name)',
                where.loc,
            )
            return
    sub = WalkContext(
        path,
        str(path),
        ctx.angle_scale,
        ctx.sink,
        ctx.resolver,
        ctx.check_resources,
        ctx.faithful_extrusion,
        ctx.main_anchors,
        ctx.mesh_cache,
        ctx.yaml_cache,
        ctx.depth + 1,
    )
    walk(content, affine, mode, out, sub, depth + 1)
