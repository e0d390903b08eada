"""How many triangles MuJoCo itself reads from a mesh file.

MuJoCo's OBJ reader reads only the first ``o``/``g`` group of a file (measured with MuJoCo 4.0:
two tetrahedra under two ``o`` or ``g`` lines give 4 faces of 8, under two ``usemtl`` lines 8).
example-robot-data's ``alex_description/meshes/cycloidal_arm/nub.obj`` (1,404 triangles in four
objects) comes out as its first 29 faces, a flat disc, and the model is refused ("mesh volume is too
small"); 21 of the 84 OBJ files of example-robot-data and the corpus lose faces this way. The writer
asks the reader rather than copy its rule: the file is compiled alone, through MuJoCo's C library
(:mod:`.native`, no Python bindings), and its face count is compared with the file's own. Each file
is compiled under a fresh path: MuJoCo caches mesh files by path within a process.
"""

from __future__ import annotations

import hashlib
import tempfile
from pathlib import Path

from modelkit.formats.mjcf.native import compiled

_PROBE = ('<mujoco model="probe"><asset><mesh name="probe" file="{file}" inertia="shell"/></asset>'
          "<worldbody/></mujoco>")


_answers: dict[tuple[bytes, str], int | None] = {}  # by content: a mesh is often both visual and collision


def faces_mujoco_reads(data: bytes, ext: str) -> int | None:
    """The number of faces MuJoCo reads from ``data`` (a ``.ext`` mesh file), or ``None`` when MuJoCo's
    library is not available or does not compile the file alone (its verdict then comes with the
    model, as before)."""
    key = (hashlib.sha256(data).digest(), ext)
    if key not in _answers:
        _answers[key] = _probe(data, ext)
    return _answers[key]


def _probe(data: bytes, ext: str) -> int | None:
    with tempfile.TemporaryDirectory(prefix="modelkit-mesh-") as folder:
        mesh = Path(folder) / f"probe.{ext}"
        mesh.write_bytes(data)
        model_file = Path(folder) / "probe.xml"
        model_file.write_text(_PROBE.format(file=mesh.name), encoding="utf-8")
        with compiled(model_file) as result:
            if result is None:
                return None
            counts = result.model.mesh_facenum
            return int(counts[0]) if counts else None
