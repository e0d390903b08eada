"""ASCII STL is read without importing trimesh (its import is 0.5–0.8 s; example-robot-data's
simple_humanoid, one 8 KB ASCII cube, took 0.96 s to validate, now 0.17 s): the same vertices as
trimesh's ``load_stl_ascii`` and the same verdicts on malformed text."""

from __future__ import annotations

import io
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from trimesh.exchange import stl as trimesh_stl

from modelkit.geometry.meshfiles import MeshLoadError, ascii_stl_solids, load_mesh

FACET = ("facet normal 0 0 1\n outer loop\n  vertex {x} 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
         "endfacet\n")
CASES = {
    "plain": "solid a\n" + FACET.format(x=0) + "endsolid a\n",
    "upper case": ("solid a\n" + FACET.format(x=0) + "endsolid a\n").upper(),
    "CRLF": ("solid a\n" + FACET.format(x=0) + "endsolid a\n").replace("\n", "\r\n"),
    "tabs": ("solid a\n" + FACET.format(x=0) + "endsolid a\n").replace(" ", "\t"),
    "exponent": "solid a\n" + FACET.format(x="1.5e-3") + "endsolid a\n",
    "two solids": ("solid a\n" + FACET.format(x=0) + "endsolid a\nsolid b\n" + FACET.format(x=2)
                   + FACET.format(x=3) + "endsolid b\n"),
    "no endsolid": "solid a\n" + FACET.format(x=0),
    "a word for a number": "solid a\n" + FACET.format(x="abc") + "endsolid a\n",
    "four numbers": "solid a\n" + FACET.format(x="0 9") + "endsolid a\n",
    "two numbers": "solid a\n" + FACET.format(x=0).replace("vertex 1 0 0", "vertex 1 0") + "endsolid a\n",
    "no facet": "solid a\nendsolid a\n",
    "nan": "solid a\n" + FACET.format(x="nan") + "endsolid a\n",
}


def _trimesh(text: str) -> list[np.ndarray] | None:
    """trimesh's vertices per solid, or None where it (or numpy under it) refuses the text."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            loaded = trimesh_stl.load_stl_ascii(io.StringIO(text))
    except (ValueError, Warning):
        return None
    solids = list(loaded["geometry"].values()) if "geometry" in loaded else [loaded]
    return [np.asarray(solid["vertices"]) for solid in solids]


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_same_vertices_and_refusals_as_trimesh(case: str) -> None:
    text = CASES[case]
    expected = _trimesh(text)
    if expected is None:
        with pytest.raises(ValueError):
            ascii_stl_solids(text)
        return
    got = ascii_stl_solids(text)
    assert len(got) == len(expected)
    for mine, theirs in zip(got, expected, strict=True):
        assert np.array_equal(mine, theirs, equal_nan=True)


def test_a_malformed_ascii_stl_is_mk501(tmp_path: Path) -> None:
    path = tmp_path / "bad.stl"
    path.write_text(CASES["four numbers"])
    with pytest.raises(MeshLoadError) as refused:
        load_mesh(path)
    assert refused.value.code == "MK501"


def test_reading_an_ascii_stl_imports_no_trimesh(tmp_path: Path) -> None:
    path = tmp_path / "cube.stl"
    path.write_text(CASES["two solids"])
    code = ("import sys; from pathlib import Path; from modelkit.geometry.meshfiles import load_mesh; "
            f"m = load_mesh(Path({str(path)!r})); print(len(m.mesh.faces), 'trimesh' in sys.modules)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.split() == ["3", "False"]
