"""COLLADA meshes decode only their positions (modelkit/geometry/dae_sources.py): the mesh a model gets is
the same to the bit, a primitive indexing past a source is still refused, and a hostile declared size
is not allocated. The speed is measured in bench (docs/performance.md), not asserted here."""

from __future__ import annotations

import io
import re
from pathlib import Path

import collada
import numpy as np
import pytest
from collada import source as dae_source
from collada.common import DaeError

from modelkit.geometry.dae_sources import positions_only
from modelkit.geometry.meshfiles import MeshLoadError, load_mesh

WHEEL = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "meshes" \
    / "vmega_wheel.dae"


def _sources(data: bytes, patched: bool) -> dict[str, np.ndarray]:
    def load() -> collada.Collada:
        return collada.Collada(io.BytesIO(data))

    if patched:
        with positions_only():
            dae = load()
    else:
        dae = load()
    return {src.id: np.asarray(src.data) for geom in dae.geometries for src in geom.sourceById.values()
            if isinstance(src, dae_source.FloatSource)}


def test_positions_are_decoded_and_the_rest_is_zeros_of_its_size() -> None:
    """The tutorial's wheel (Blender: positions, normals, texture coordinates): the positions are the
    same to the bit; the normals (19,173 numbers) and texture coordinates (50,880) are zeros of the
    shape pycollada gives them; and pycollada's own loader is back after the block."""
    data = WHEEL.read_bytes()
    plain, fast = _sources(data, False), _sources(data, True)
    assert plain.keys() == fast.keys() and len(plain) == 3
    positions = "Megarover_003-mesh-positions"
    assert np.array_equal(plain[positions], fast[positions]) and plain[positions].shape == (4559, 3)
    for name in set(plain) - {positions}:
        assert fast[name].shape == plain[name].shape and not fast[name].any() and plain[name].any(), name
    assert dae_source.FloatSource.load.__qualname__ == "FloatSource.load"


def test_the_mesh_a_model_gets_is_unchanged() -> None:
    """load_mesh (what validate and convert use) against pycollada's own decoding of every number."""
    loaded = load_mesh(WHEEL)
    dae = collada.Collada(str(WHEEL))
    triangles = [prim for geom in dae.geometries for prim in geom.primitives]
    corners = np.concatenate([np.asarray(p.vertex, dtype=np.float64)[np.asarray(p.vertex_index).reshape(-1)]
                              for p in triangles])
    ours = np.asarray(loaded.mesh.vertices)[np.asarray(loaded.mesh.faces).reshape(-1)]
    assert {tuple(c) for c in np.round(corners, 12)} == {tuple(c) for c in np.round(ours, 12)}
    assert len(np.asarray(loaded.mesh.faces)) == sum(len(np.asarray(p.vertex_index)) for p in triangles)


def _shrunk_normals(data: bytes, keep: int) -> bytes:
    """The wheel with its normals array cut to ``keep`` numbers (count and text): its primitive then
    indexes past the normals."""
    text = data.decode()
    match = re.search(r'(<float_array id="Megarover_003-mesh-normals-array" count=")(\d+)(">)([^<]*)', text)
    assert match
    numbers = " ".join(match.group(4).split()[:keep])
    shrunk = f"{match.group(1)}{keep}{match.group(3)}{numbers}"
    return (text[:match.start()] + shrunk + text[match.end():]).encode()


def test_a_primitive_indexing_past_a_stubbed_source_is_still_refused(tmp_path: Path) -> None:
    broken = _shrunk_normals(WHEEL.read_bytes(), 30)
    with pytest.raises(DaeError) as plain:
        collada.Collada(io.BytesIO(broken))
    with pytest.raises(DaeError) as fast, positions_only():
        collada.Collada(io.BytesIO(broken))
    assert type(fast.value) is type(plain.value)
    path = tmp_path / "broken.dae"
    path.write_bytes(broken)
    with pytest.raises(MeshLoadError):
        load_mesh(path)


def test_the_stub_has_as_many_numbers_as_the_text_whatever_the_count_says() -> None:
    """``count="300000000000"`` on the texture coordinates: pycollada ignores the attribute and decodes
    the text's 50,880 numbers; the stub has as many (zeros of 2.4 TB were never allocated)."""
    text = WHEEL.read_bytes().decode()
    declared = r'(<float_array id="Megarover_003-mesh-map-0-array" count=")\d+'
    hostile = re.sub(declared, r"\g<1>300000000000", text).encode()
    plain, fast = _sources(hostile, False), _sources(hostile, True)
    name = "Megarover_003-mesh-map-0"
    assert plain[name].shape == fast[name].shape == (25440, 2) and not fast[name].any()


def test_a_normal_that_is_not_a_number_is_read_as_assimp_reads_it(tmp_path: Path) -> None:
    """One normal written ``abc``: Assimp (Choreonoid, RViz, Gazebo) reads the text leniently, and so
    does load_mesh now (before, numpy stopped decoding there and the primitive indexed past the end:
    MK501). A position that is not a number is still refused."""
    text = WHEEL.read_bytes().decode()
    start = text.index('<float_array id="Megarover_003-mesh-normals-array"')
    at = text.index(">", start) + 1
    normals = tmp_path / "normals.dae"
    normals.write_text(text[:at] + "abc" + text[at + text[at:].index(" "):])
    assert len(np.asarray(load_mesh(normals).mesh.faces)) == len(np.asarray(load_mesh(WHEEL).mesh.faces))
    start = text.index('<float_array id="Megarover_003-mesh-positions-array"')
    at = text.index(">", start) + 1
    positions = tmp_path / "positions.dae"
    positions.write_text(text[:at] + "abc" + text[at + text[at:].index(" "):])
    with pytest.raises(MeshLoadError):
        load_mesh(positions)
