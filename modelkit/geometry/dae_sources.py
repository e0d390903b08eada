"""COLLADA loading that decodes only the numbers the mesh checks read (the vertex positions), and that
keeps a geometry whose material binding is broken.

pycollada decodes every ``<float_array>`` of a ``<mesh>`` when it loads a document: positions, and
normals, texture coordinates and colours, which nothing in modelkit reads (the checks and the STL
export use positions and the triangles' vertex indices). In real robots those are most of the text:
example-robot-data's Go1 ``trunk.dae`` holds 0.52 M position numbers and 1.05 M normal numbers.
Inside :func:`positions_only`, a ``<mesh>`` source that no ``<vertices>`` names as its ``POSITION`` is
given zeros, as many as its text has numbers (counted, not decoded: 0.04 s against 0.2 s for Go1's
normals), instead of the decoded numbers. Its length is what pycollada would have decoded, so its
index checks refuse the same primitives (a truncated normal array, indexed past its end). Only a
number that is not a number is no longer refused there: Assimp, which Choreonoid, RViz and Gazebo
read COLLADA with, reads such a text without complaint too (``fast_atoreal_move``).

pycollada drops a whole ``<instance_geometry>`` when one ``<instance_material>`` names a material the
document lacks (``DaeBrokenRefError``, which the loader is told to ignore): example-robot-data's
ANYmal B foot, whose carbon-fibre material lost its effect, then has no triangles at all, and the
converter wrote an empty STL. Assimp keeps the geometry with its default material. Inside
:func:`materials_optional`, such a binding is kept with no material (no colour), and its target is
listed for the loader's notes.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

# pycollada's loaders are class attributes: one document at a time (a re-entrant lock: the patches nest)
_PATCH = threading.RLock()


@contextmanager
def _patched(owner: Any, name: str, replacement: Callable[..., Any]) -> Iterator[None]:
    """``owner.name`` is the static method ``replacement`` inside the block, one document at a time."""
    with _PATCH:
        original = getattr(owner, name)
        setattr(owner, name, staticmethod(replacement))
        try:
            yield
        finally:
            setattr(owner, name, staticmethod(original))


def _positions(mesh: Any, collada: Any) -> set[str]:
    """The source ids a ``<mesh>``'s ``<vertices>`` take their ``POSITION`` from."""
    out: set[str] = set()
    for vertices in mesh.iterfind(collada.tag("vertices")):
        for entry in vertices.iterfind(collada.tag("input")):
            if entry.get("semantic") == "POSITION":
                out.add((entry.get("source") or "").lstrip("#"))
    return out


def _numbers_in(text: str) -> int:
    """How many whitespace-separated tokens ``text`` holds (what ``numpy.fromstring(sep=" ")`` would
    decode, were they all numbers), without decoding them."""
    raw = np.frombuffer(text.encode(), dtype=np.uint8)
    if raw.size == 0:
        return 0
    space = raw <= 32  # ASCII whitespace and control characters separate tokens
    return int(np.count_nonzero(~space[1:] & space[:-1])) + (0 if space[0] else 1)


@contextmanager
def positions_only() -> Iterator[None]:
    """pycollada's float sources, inside the block: a ``<mesh>`` source other than a ``POSITION`` is
    zeros, as many as its text has numbers (see the module's docstring)."""
    from collada import source as dae

    original = dae.FloatSource.load

    def load(collada: Any, localscope: Any, node: Any, arraynode: Any = None) -> Any:
        parent = node.getparent()
        if arraynode is None:
            arraynode = node.find(collada.tag("float_array"))
        if (arraynode is None or parent is None or parent.tag != collada.tag("mesh")
                or node.get("id") in _positions(parent, collada)):
            return original(collada, localscope, node, arraynode)
        params = node.findall(f"{collada.tag('technique_common')}/{collada.tag('accessor')}/"
                              f"{collada.tag('param')}")
        numbers = _numbers_in(arraynode.text or "")
        if not params or numbers % len(params):  # pycollada's own error for a ragged array
            return original(collada, localscope, node, arraynode)
        empty = arraynode.makeelement(arraynode.tag, {})  # the components as pycollada reads them
        stub = original(collada, localscope, node, empty)
        stub.data = np.zeros((numbers // len(params), len(stub.components)), dtype=np.float32)
        return stub

    with _patched(dae.FloatSource, "load", load):
        yield


@contextmanager
def materials_optional(missing: list[str]) -> Iterator[None]:
    """Inside the block, an ``<instance_material>`` whose target the document lacks is bound to no
    material instead of dropping its ``<instance_geometry>``; each such target is appended to
    ``missing``."""
    from collada import scene

    original = scene.MaterialNode.load

    def load(collada: Any, node: Any) -> Any:
        target = node.get("target") or ""
        if target.startswith("#") and collada.materials.get(target[1:]) is None:
            missing.append(target)
            inputs = [(n.get("semantic"), n.get("input_semantic"), n.get("input_set"))
                      for n in node.findall(collada.tag("bind_vertex_input"))]
            return scene.MaterialNode(node.get("symbol"), None, inputs, xmlnode=node)
        return original(collada, node)

    with _patched(scene.MaterialNode, "load", load):
        yield
