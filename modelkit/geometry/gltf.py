"""glTF 2.0 meshes (``.glb``, binary; ``.gltf``, JSON with its buffers) as a scene of triangles.

glTF's own conventions are metres and +Y up. The triangles are taken where the file's nodes place them,
with no up-axis change (as COLLADA's ``up_axis`` is ignored): that is how rviz (Assimp) and trimesh
show them, and how robots that ship glTF visuals author them. Measured on dexmate's Vega gripper: the
base's ``.glb`` visual, placed by its nodes, spans the bounds of the link's ``.obj`` collision mesh to
0.8 mm; rotated from Y-up to Z-up it would not.

The parsing is trimesh's. A ``.gltf`` file names its buffers (and images) by URI: only ``data:`` URIs and
regular files inside the file's own folder are read, so a model cannot make the reader open
``../../../etc/shadow`` (the message names the URI, never content).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import numpy as np
from numpy.typing import NDArray

from modelkit.textio import DEFAULT_MAX_BYTES, UnreadableFile, read_regular

Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]


class GltfRefused(Exception):
    """The file cannot be used as a mesh; the message says why (it quotes no content)."""


def _folder_resolver(folder: Path, max_bytes: int) -> Any:
    """A trimesh resolver that reads regular files inside ``folder`` only."""
    from trimesh.resolvers import Resolver

    class FolderOnly(Resolver):
        def __init__(self) -> None:
            pass

        def get(self, name: str) -> bytes:
            base = folder.resolve()
            target = (base / unquote(name)).resolve()
            if not target.is_relative_to(base):
                raise GltfRefused(f'it refers to "{name}", outside its own folder')
            try:
                return read_regular(target, max_bytes)
            except UnreadableFile as exc:
                raise GltfRefused(f'its file "{name}" cannot be read ({exc.message})') from exc

        def namespaced(self, namespace: str) -> Any:
            raise GltfRefused("nested resolvers are not used")

        def write(self, name: str, data: Any) -> None:
            raise GltfRefused("nothing is written")

        def keys(self) -> list[str]:
            return []

    return FolderOnly()


Rgba = tuple[float, float, float, float]


def _base_colour(geometry: Any) -> Rgba | None:
    """A primitive's material colour (``baseColorFactor``, RGBA 0..1); None without one."""
    material = getattr(getattr(geometry, "visual", None), "material", None)
    factor = getattr(material, "baseColorFactor", None)
    if factor is None:
        return None
    values = np.asarray(factor, dtype=np.float64).reshape(-1)
    if len(values) not in (3, 4) or not np.all(np.isfinite(values)):
        return None
    if np.asarray(factor).dtype == np.uint8:  # trimesh keeps the factor as bytes
        values = values / 255.0
    values = np.clip(values, 0.0, 1.0)
    alpha = float(values[3]) if len(values) == 4 else 1.0
    return (float(values[0]), float(values[1]), float(values[2]), alpha)


def gltf_graph(data: bytes, binary: bool, folder: Path,
               max_bytes: int = DEFAULT_MAX_BYTES) -> tuple[list[tuple[str, str, NDArray[np.float64]]],
                                                           dict[str, list[tuple[Mesh, Rgba | None]]]]:
    """The scene of a glTF file: its edges (parent node, child node, the child's 4×4 transform in its
    parent), from the root ``world``, and the triangles each node holds, in its own frame, each mesh
    with its material's colour. Raises :class:`GltfRefused` for anything that is not a usable glTF
    scene of triangles."""
    import trimesh

    resolver = _folder_resolver(folder, max_bytes)
    try:
        scene: Any = trimesh.load(io.BytesIO(data), file_type="glb" if binary else "gltf", force="scene",
                             process=False, resolver=resolver)
    except GltfRefused:
        raise
    except Exception as exc:  # trimesh's own failures: a wrong magic number, bad JSON, short buffers
        raise GltfRefused(f"not a readable glTF file ({type(exc).__name__}: {exc})") from exc
    edges: list[tuple[str, str, NDArray[np.float64]]] = []
    meshes: dict[str, list[tuple[Mesh, Rgba | None]]] = {}
    for parent, child, attributes in scene.graph.to_edgelist():
        matrix = np.asarray(attributes.get("matrix", np.eye(4)), dtype=np.float64).reshape(4, 4)
        edges.append((str(parent), str(child), matrix))
        name = attributes.get("geometry")
        geometry = scene.geometry.get(name) if name is not None else None
        faces = getattr(geometry, "faces", None)
        if geometry is None or faces is None or len(faces) == 0:
            continue  # points, lines, or a node without a mesh
        vertices = np.asarray(geometry.vertices, dtype=np.float64).reshape(-1, 3)
        mesh = (vertices, np.asarray(faces, dtype=np.int64).reshape(-1, 3))
        meshes.setdefault(str(child), []).append((mesh, _base_colour(geometry)))
    return edges, meshes


def gltf_root(data: bytes, binary: bool, folder: Path, max_bytes: int = DEFAULT_MAX_BYTES) -> Any:
    """The scene of a glTF file as :class:`modelkit.geometry.meshfiles.MeshSceneNode` s: the root
    (``world``), its nodes named as in the file."""
    from modelkit.geometry.meshfiles import MeshSceneNode

    edges, meshes = gltf_graph(data, binary, folder, max_bytes)
    nodes: dict[str, MeshSceneNode] = {}

    def node(name: str) -> MeshSceneNode:
        found = nodes.get(name)
        if found is None:
            held = meshes.get(name, [])
            found = nodes[name] = MeshSceneNode(name=name, meshes=[m for m, _ in held],
                                                colours=[c for _, c in held])
        return found

    root = node("world")
    for parent, child, matrix in edges:
        made = node(child)
        made.matrix = matrix
        node(parent).children.append(made)
    root.name = None  # trimesh's name for the scene, not one of the file's nodes
    return root
