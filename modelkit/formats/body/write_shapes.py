"""A link's visual and collision geoms as `.body` `elements` (body-format.md §3.5, §4, §5).

Choreonoid's cylinders, capsules and cones lie along local **Y**; the model's along **Z**. The reader
turns a Y shape placed at R into the model's R·Rx(−90°) (``elements.Y_TO_Z``); this module writes
the inverse, R_model·Rx(+90°), as the Shape's ``rotation`` — the one place the writer deals with axes.

Visual/collision split (§3.5): a geom that is both (the same object in both lists, or an equal
shape at the same pose) is a plain ``Shape``; visual-only geoms go under one ``Visual`` node and
collision-only geoms under one ``Collision`` node.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.output import safe_file_name
from modelkit.formats.body.elements import Y_TO_Z
from modelkit.formats.body.write_yaml import Flow, deg, num, nums, put_pose
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, Link, Mesh, Sphere, VisualMaterial

Z_TO_Y = Y_TO_Z.T  # Rx(+90°): the inverse of the reader's boundary rotation
PRIMITIVE_KINDS = ("Cylinder", "Capsule", "Cone")
READABLE = ("stl", "obj", "dae")  # what Choreonoid loads (Assimp for COLLADA); VRML is converted


def _same_shape(a: Geom, b: Geom) -> bool:
    """Equal geometry at an equal pose (a shape a source wrote twice, as visual and collision)."""
    if a is b:
        return True
    if type(a.geometry) is not type(b.geometry):
        return False
    if not (np.array_equal(a.pose.rotation, b.pose.rotation)
            and np.array_equal(a.pose.translation, b.pose.translation)):
        return False
    ga, gb = a.geometry, b.geometry
    if isinstance(ga, Mesh) and isinstance(gb, Mesh):
        return (ga.data is None and gb.data is None and ga.path == gb.path and ga.uri == gb.uri
                and ga.fragment == gb.fragment and np.array_equal(ga.scale, gb.scale)
                and ga.generator == gb.generator and ga.source_params == gb.source_params)
    fields = [k for k in vars(ga) if k != "source"]
    return all(np.array_equal(np.asarray(getattr(ga, k)), np.asarray(getattr(gb, k))) for k in fields)


def link_elements(link: Link, ctx: WriteContext, from_body: bool = False) -> list[dict[str, Any]]:
    """The `elements` of a link's shapes: shared ones plain, the rest under Visual / Collision."""
    unmatched = list(link.collisions)
    shared: set[int] = set()
    for geom in link.visuals:
        match = next((c for c in unmatched if c is geom), None)
        if match is None:
            match = next((c for c in unmatched if _same_shape(geom, c)), None)
        if match is not None:
            unmatched.remove(match)
            shared.add(id(geom))
    out: list[dict[str, Any]] = []
    visual_only: list[dict[str, Any]] = []
    for i, geom in enumerate(link.visuals):
        is_shared = id(geom) in shared
        role = "shape" if is_shared else "visual"
        target = f"link[{link.name}]/{role}[{i}]"
        if not is_shared:
            coloured = coloured_shapes(geom, ctx, target)
            if coloured is not None:
                visual_only.extend(coloured)
                continue
        node = shape_node(geom, ctx, target, f"{link.name}_{role}_{i}", from_body)
        if node is None:
            continue
        (out if is_shared else visual_only).append(node)
    if visual_only:
        out.append({"type": "Visual", "elements": visual_only})
    collision_only = []
    for i, geom in enumerate(unmatched):
        node = shape_node(geom, ctx, f"link[{link.name}]/collision[{i}]", f"{link.name}_collision_{i}",
                          from_body)
        if node is not None:
            collision_only.append(node)
    if collision_only:
        out.append({"type": "Collision", "elements": collision_only})
    return out


def coloured_shapes(geom: Geom, ctx: WriteContext, target: str) -> list[dict[str, Any]] | None:
    """A visual COLLADA or glTF mesh without a colour of its own, whose file's materials give colours
    and which is converted (the STL holds none): one Shape per colour, each with its colour as its
    material (:meth:`MeshExporter.coloured_parts`); None otherwise."""
    g = geom.geometry
    if geom.material is not None or not isinstance(g, Mesh):
        return None
    parts = ctx.meshes.coloured_parts(g, target, geom.source, READABLE)
    if parts is None:
        return None
    shapes = []
    for k, (ref, colour) in enumerate(parts):
        material = (VisualMaterial(diffuse=colour[:3], transparency=1.0 - colour[3])
                    if colour is not None else None)
        part = Geom(Mesh(uri=ref.uri), geom.pose, geom.name if k == 0 else None, material, geom.source)
        shapes.append(_shape(part, {"type": "Resource", "uri": ref.uri}, geom.pose.rotation,
                             geom.pose.translation, np.asarray(ref.scale), ctx, target))
    return shapes


def not_generated(g: object) -> bool:
    """The primitives Choreonoid's reader refuses (the reader's MK400 rules, body-format.md §3)."""
    if isinstance(g, Box):
        return any(float(x) < 0.0 for x in g.size)
    if isinstance(g, Sphere):
        return float(g.radius) <= 0.0
    if isinstance(g, Ellipsoid):
        return any(float(x) <= 0.0 for x in g.radii)
    if isinstance(g, (Cylinder, Cone)):
        return float(g.radius) <= 0.0 or float(g.length) <= 0.0
    if isinstance(g, Capsule):
        return float(g.radius) <= 0.0 or float(g.length) < 0.0
    return False


def shape_node(geom: Geom, ctx: WriteContext, target: str, mesh_name: str,
               from_body: bool = False) -> dict[str, Any] | None:
    """One Shape (or Resource) element; None when the shape cannot be written (note made)."""
    g = geom.geometry
    if not_generated(g):
        ctx.note("MK880", f"{type(g).__name__.lower()} of {target} has a size Choreonoid cannot generate "
                 "(it refuses the whole file); this shape is left out", geom.source, target)
        return None
    rotation, translation = geom.pose.rotation, geom.pose.translation
    scale: np.ndarray | None = None
    geometry: dict[str, Any]
    if isinstance(g, Box):
        geometry = {"type": "Box", "size": nums(g.size)}
    elif isinstance(g, Sphere):
        geometry = {"type": "Sphere", "radius": num(g.radius)}
    elif isinstance(g, Ellipsoid):
        # Choreonoid has no ellipsoid: a unit sphere scaled per axis (the reader reads it back as an
        # Ellipsoid, as Choreonoid's own ellipsoid1.body does).
        geometry = {"type": "Sphere", "radius": num(1.0)}
        scale = np.asarray(g.radii, dtype=float)
    elif isinstance(g, (Cylinder, Capsule, Cone)):
        geometry = {"type": type(g).__name__, "radius": num(g.radius), "height": num(g.length)}
        rotation = rotation @ Z_TO_Y
    elif isinstance(g, Mesh):
        return _mesh_node(geom, g, ctx, target, mesh_name, from_body)
    else:  # pragma: no cover - every Geometry kind is handled above
        return None
    return _shape(geom, geometry, rotation, translation, scale, ctx, target)


def _shape(geom: Geom, geometry: dict[str, Any], rotation: np.ndarray, translation: np.ndarray,
           scale: np.ndarray | None, ctx: WriteContext, target: str) -> dict[str, Any]:
    node: dict[str, Any] = {"type": "Shape"}
    if geom.name:
        node["name"] = geom.name
    put_pose(node, rotation, translation)
    if scale is not None and not np.all(scale == 1.0):
        node["scale"] = nums(scale)
    node["geometry"] = geometry
    appearance = _appearance(geom.material, ctx, geom, target)
    if appearance:
        node["appearance"] = appearance
    return node


def _mesh_node(geom: Geom, g: Mesh, ctx: WriteContext, target: str, mesh_name: str,
               from_body: bool) -> dict[str, Any] | None:
    params = g.source_params
    scale = np.asarray(g.scale, dtype=float)
    # An Extrusion read with Choreonoid's own arithmetic is written back as the same node; one read
    # the VRML97 way (--vrml-extrusion) would come out differently in Choreonoid: a mesh file then.
    native = params.get("faithful", True) is True
    if g.generator == "Extrusion" and native and "spine" in params and "cross_section" in params:
        return _shape(geom, _extrusion(params), geom.pose.rotation, geom.pose.translation, scale, ctx, target)
    if g.generator in PRIMITIVE_KINDS and g.data is None and g.path is None and "radius" in params:
        # A Choreonoid primitive scaled non-uniformly: the reader keeps it in the Y-axis shape frame.
        geometry = {"type": g.generator, "radius": num(params["radius"]), "height": num(params["height"])}
        return _shape(geom, geometry, geom.pose.rotation, geom.pose.translation, scale, ctx, target)
    ref = ctx.meshes.mesh(g, geom.name or mesh_name, target, geom.source, READABLE)
    if ref is None:
        return None
    copied = (g.data is None and g.path is not None and not g.fragment and not params.get("metadata")
              and Path(g.path).suffix.lower().lstrip(".") == ref.file_format)
    # Resource *geometry* must hold exactly one mesh (§4.9): a file we wrote does, an STL does, and so
    # does one a .body source already used as geometry (only those carry a material from a .body).
    single_mesh = not copied or ref.file_format == "stl" or (from_body and geom.material is not None)
    if single_mesh:
        geometry = {"type": "Resource", "uri": ref.uri}
        return _shape(geom, geometry, geom.pose.rotation, geom.pose.translation, np.asarray(ref.scale),
                      ctx, target)
    if geom.material is not None:
        ctx.note("MK818", f"{Path(ref.uri).name} may hold several meshes, so it is a Resource node, which "
                 "takes the file's own materials, not the shape's", geom.source, target)
    node: dict[str, Any] = {"type": "Resource"}
    if geom.name:
        node["name"] = geom.name
    node["uri"] = ref.uri
    put_pose(node, geom.pose.rotation, geom.pose.translation)
    if not np.all(np.asarray(ref.scale) == 1.0):
        node["scale"] = nums(ref.scale)
    return node


def _extrusion(params: dict[str, Any]) -> dict[str, Any]:
    """The Extrusion node the reader read (§4.6), angles back in degrees; ``beginCap`` is camelCase
    because Choreonoid does not read ``begin_cap``."""
    out: dict[str, Any] = {"type": "Extrusion"}
    out["cross_section"] = nums(params["cross_section"])
    out["spine"] = nums(params["spine"])
    orientation = list(params.get("orientation") or [])
    if orientation:
        out["orientation"] = Flow(deg(x) if i % 4 == 3 else num(x) for i, x in enumerate(orientation))
    scale = list(params.get("scale") or [])
    if scale:
        out["scale"] = nums(scale)
    if params.get("begin_cap") is False:
        out["beginCap"] = False
    if params.get("end_cap") is False:
        out["end_cap"] = False
    return out


def _appearance(material: VisualMaterial | None, ctx: WriteContext, geom: Geom,
                target: str) -> dict[str, Any]:
    if material is None:
        return {}
    out: dict[str, Any] = {}
    m: dict[str, Any] = {}
    if material.diffuse is not None:
        m["diffuse"] = nums(material.diffuse)
    if material.ambient is not None:
        m["ambient"] = num(material.ambient)
    if material.specular is not None:
        m["specular"] = nums(material.specular)
    if material.emissive is not None:
        m["emissive"] = nums(material.emissive)
    if material.specular_exponent is not None:
        m["specular_exponent"] = num(material.specular_exponent)
    if material.transparency:
        m["transparency"] = num(material.transparency)
    # The reader makes a material (possibly empty) only when the source had one: keep it.
    out["material"] = m
    if material.texture:
        uri = _texture(material.texture, ctx, geom, target)
        if uri is not None:
            out["texture"] = {"uri": uri}
    return out


def _texture(texture: str, ctx: WriteContext, geom: Geom, target: str) -> str | None:
    path = Path(texture)
    try:
        data = path.read_bytes() if path.is_absolute() or path.exists() else None
    except OSError:
        data = None
    if data is None:
        ctx.note("MK818", f"texture {texture} cannot be read; it is left out", geom.source, target)
        return None
    ctx.meshes.plan.protect(path)
    relpath = ctx.meshes.plan.add(f"meshes/{safe_file_name(path.name, 'texture')}", data, "texture")
    return ctx.meshes.prefix + relpath
