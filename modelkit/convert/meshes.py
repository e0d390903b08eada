"""Meshes for a writer: copy a source mesh file, convert it, or write triangles as a file.

Every mesh a written model references lives in the output folder's ``meshes/`` with a
deterministic, safe name, and is referenced by a path relative to the model file, so the folder
can be moved as a whole. What had to change on the way is a conversion note.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from modelkit.convert.notes import NoteSink
from modelkit.convert.numbers import fmt
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan, safe_file_name
from modelkit.diagnostics import SourceLocation
from modelkit.model import Capsule, Cone, Ellipsoid, Mesh, TriangleMeshData
from modelkit.spatial import Vec3

MESH_FOLDER = "meshes"
PRIMITIVE_SECTIONS = 32  # segments around the axis of a cone, capsule or ellipsoid written as a mesh


@dataclass(frozen=True)
class MeshRef:
    """What a writer puts in its mesh element: a reference and the scale to apply to it."""

    uri: str  # relative to the model file (or a kept package:// URI)
    scale: Vec3
    file_format: str  # "stl" | "obj" | "dae"


STL_HEADER = b"modelkit binary STL".ljust(80, b" ")


def triangles_to_bytes(mesh: TriangleMeshData, file_format: str) -> bytes:
    """Triangles as a binary STL or an OBJ file; deterministic bytes.

    Written with numpy rather than trimesh: both formats are a few lines of layout, and importing
    trimesh (and scipy under it) takes 0.5-0.8 s, more than a whole conversion. Facet normals are
    computed from the winding (STL readers recompute them; zero for a degenerate triangle).
    """
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if file_format == "obj":
        lines = ["# modelkit OBJ"]
        lines += [f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in vertices]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
        return ("\n".join(lines) + "\n").encode("ascii")
    corners = vertices[faces] if len(faces) else np.zeros((0, 3, 3))
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    table = np.zeros(len(faces), dtype=record)
    table["normal"] = normals
    table["corners"] = corners
    return STL_HEADER + np.uint32(len(faces)).astype("<u4").tobytes() + table.tobytes()


def primitive_triangles(geometry: Cone | Capsule | Ellipsoid) -> TriangleMeshData:
    """A closed, outward-wound triangle mesh of a primitive in the model's convention (axis Z,
    cone apex at +length/2)."""
    import trimesh

    if isinstance(geometry, Cone):
        tm = trimesh.creation.cone(radius=geometry.radius, height=geometry.length,
                                   sections=PRIMITIVE_SECTIONS)
        tm.apply_translation([0.0, 0.0, -geometry.length / 2.0])  # trimesh: base at z=0, apex at +h
    elif isinstance(geometry, Capsule):
        tm = trimesh.creation.capsule(height=geometry.length, radius=geometry.radius,
                                      count=[PRIMITIVE_SECTIONS, PRIMITIVE_SECTIONS])
    else:
        tm = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
        tm.apply_scale(np.asarray(geometry.radii, dtype=float))
    return TriangleMeshData(np.asarray(tm.vertices, dtype=float), np.asarray(tm.faces, dtype=np.int64))


class MeshExporter:
    """Turns the model's mesh geometry into files in the output plan, once each."""

    def __init__(self, plan: OutputPlan, model_relpath: str, options: WriteOptions, notes: NoteSink) -> None:
        self.plan = plan
        self.options = options
        self.notes = notes
        depth = model_relpath.count("/")
        self.prefix = "../" * depth  # from the model file's folder back to the output folder

    def _stage(self, data: bytes, name: str) -> str:
        relpath = self.plan.add(f"{MESH_FOLDER}/{name}", data, "mesh")
        return self.prefix + relpath

    def triangles(self, mesh: TriangleMeshData, name: str, scale: Vec3 | None = None) -> MeshRef:
        ext = self.options.mesh_format
        uri = self._stage(triangles_to_bytes(mesh, ext), f"{safe_file_name(name, 'mesh')}.{ext}")
        return MeshRef(uri, np.ones(3) if scale is None else np.asarray(scale, dtype=float), ext)

    def primitive(self, geometry: Cone | Capsule | Ellipsoid, name: str, target: str,
                  source: SourceLocation | None) -> MeshRef:
        kind = type(geometry).__name__.lower()
        self.notes.note("MK802", f"the target has no {kind}; written as a triangle mesh "
                        f"({PRIMITIVE_SECTIONS} segments around the axis)", source, target)
        return self.triangles(primitive_triangles(geometry), name)

    def mesh(self, geometry: Mesh, name: str, target: str, source: SourceLocation | None,
             readable: tuple[str, ...]) -> MeshRef | None:
        """A reference for ``geometry`` that the target reads (``readable``: "stl", "obj", "dae").

        Returns None (with an MK805 note) when the mesh is missing or unreadable.
        """
        scale = np.asarray(geometry.scale, dtype=float)
        if geometry.data is not None and (geometry.path is None or geometry.generator):
            kind = geometry.generator or "in-memory mesh"
            self.notes.note("MK803", f"{kind} written as a mesh file", source, target)
            return self.triangles(geometry.data, name, scale)
        uri = geometry.uri or ""
        if (self.options.keep_package_uris and uri.startswith(("package://", "model://"))
                and not geometry.fragment):
            ext = Path(uri).suffix.lower().lstrip(".")
            if ext in readable:
                return MeshRef(uri, scale, ext)
        if geometry.path is None:
            self.notes.note("MK805", f"mesh {uri or '(no uri)'} was not found; the shape is left out",
                            source, target)
            return None
        from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata, load_mesh

        meta = geometry.source_params.get("metadata")
        metadata = (MeshMetadata(meta.get("length_unit"), meta.get("upper_axis"))
                    if isinstance(meta, dict) and meta else None)
        path = Path(geometry.path)
        ext = path.suffix.lower().lstrip(".")
        as_is = ext in readable and not geometry.fragment and metadata is None
        if as_is and (ext != "dae" or self.options.keep_collada):
            try:
                data = path.read_bytes()
                self.plan.protect(path)
            except OSError as exc:
                self.notes.note("MK805", f"mesh {uri} cannot be read ({exc.strerror}); the shape is left out",
                                source, target)
                return None
            return MeshRef(self._stage(data, safe_file_name(path.name, "mesh")), scale, ext)
        try:
            loaded = load_mesh(path, geometry.fragment, metadata)
        except MeshLoadError as exc:
            self.notes.note("MK805", f"mesh {uri} cannot be loaded ({exc.message}); the shape is left out",
                            source, target)
            return None
        part = f"#{geometry.fragment}" if geometry.fragment else ""
        unit = f", unit scale {loaded.unit_scale:g} applied" if loaded.unit_scale != 1.0 else ""
        self.notes.note("MK804", f"mesh {path.name}{part} ({loaded.source_format}) converted to "
                        f"{self.options.mesh_format.upper()}{unit}", source, target)
        stem = path.stem + (f"_{geometry.fragment}" if geometry.fragment else "")
        return self.triangles(loaded.mesh, stem, scale)
