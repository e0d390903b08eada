"""The written MJCF reads like MuJoCo Menagerie's models, and compiles to the same model as before.

Style (issue 17 item 6): ``<compiler meshdir>``, a ``<default>`` class per robot with ``visual`` and
``collision`` subclasses that the geoms name with ``class=``, mesh assets named after their source
file's stem. None of it may change what MuJoCo builds: ``tests/mjcf/style_before.json`` holds,
for ten robots (the corpus and example-robot-data), what MuJoCo compiled from the writer's output
before the style change (commit 2f1c8fd: every geom spelled out, no meshdir, no classes) — body
masses and inertias, every geom's body, type, size, pose, contype, conaffinity, group, priority,
friction, solref and solimp, every mesh's vertex count and bounds. The same is compiled from today's
output and compared to 1e-12.

One deliberate change since: the MJCF humanoid's contact parameters and timestep. The writer before
lost the source's own (condim 1, friction 0.7, solref ".015 1", solimp ".9 .99 .003", timestep 0.005)
and gave every geom priority 1; the reference now holds the source's, which the output compiles to
exactly (each of its 19 collision geoms and the option checked against MuJoCo's compile of the
source itself).

A second one: visual COLLADA and glTF meshes are split by their materials' colours, one geom per colour
(docs/convert.md, "A mesh file's own colours"). The reference was regenerated after checking that,
with the visual mesh geoms left out on both sides, today's output compiled exactly to the reference
before it on all ten robots; the visual mesh geoms went from 20 to 21 (Go1), 7 to 9 (KR16), 11 to 28
(Panda) and 7 to 20 (UR5), unchanged elsewhere.

Regenerate the reference only from a writer known to be right:
``python -m tests.test_mjcf_style > tests/mjcf/style_before.json``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from modelkit.convert.api import convert
from modelkit.convert.options import WriteOptions

from .conftest import CORPUS, example_robot_data

mujoco = pytest.importorskip("mujoco")

REFERENCE = Path(__file__).parent / "mjcf" / "style_before.json"
ERD = example_robot_data()

# name -> (where, path inside it)
ROBOTS: dict[str, tuple[str, str]] = {
    "panda": ("erd", "panda_description/urdf/panda.urdf"),
    "ur5": ("erd", "ur_description/urdf/ur5_robot.urdf"),
    "go1": ("erd", "go1_description/urdf/go1.urdf"),
    "solo": ("erd", "solo_description/robots/solo12.urdf"),
    "pantilt": ("corpus", "choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_pantilt.body"),
    "tracks": ("corpus", "choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_tracks.body"),
    "pa10": ("corpus", "choreonoid/share/model/PA10/PA10.body"),
    "gr001": ("corpus", "choreonoid/share/model/GR001/GR001.body"),
    "kr16": ("corpus", "kuka_experimental/kuka_kr16_support/urdf/kr16_2.urdf"),
    "humanoid": ("corpus", "mujoco_model/humanoid/humanoid.xml"),
}


def source_of(name: str) -> Path | None:
    where, rel = ROBOTS[name]
    base = ERD if where == "erd" else (CORPUS if CORPUS.is_dir() else None)
    return None if base is None else base / rel


def written(name: str, folder: Path) -> Path:
    source = source_of(name)
    if source is None or not source.is_file():
        pytest.skip(f"{name}: {ROBOTS[name][1]} not available")
    out = folder / name / f"{name}.xml"
    # frames as bodies: the style changed no number; writing frames as sites (MK873) changed the body
    # set on purpose, and tests/test_mjcf_frame_sites.py checks where the sites are
    result = convert([source], out, force=True, options=WriteOptions(frame_sites=False))
    assert result.outputs == [str(out)], [d.message for d in result.diagnostics]
    return out


def _r(values: Any) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


def fingerprint(path: Path) -> dict[str, Any]:
    """What MuJoCo builds from ``path``, keyed by names (mesh assets by their vertex data, since
    their names are what the style changes)."""
    m = mujoco.MjModel.from_xml_path(str(path))

    def body(i: int) -> str:
        return str(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i))

    meshes = []
    for i in range(m.nmesh):
        start, count = int(m.mesh_vertadr[i]), int(m.mesh_vertnum[i])
        verts = m.mesh_vert[start:start + count]
        meshes.append([count, _r(verts.min(axis=0)), _r(verts.max(axis=0))])
    geoms = []
    for g in range(m.ngeom):
        mesh = int(m.geom_dataid[g])
        geoms.append({
            "body": body(int(m.geom_bodyid[g])),
            "type": int(m.geom_type[g]),
            "size": _r(m.geom_size[g]),
            "pos": _r(m.geom_pos[g]),
            "quat": _r(m.geom_quat[g]),
            "contype": int(m.geom_contype[g]),
            "conaffinity": int(m.geom_conaffinity[g]),
            "group": int(m.geom_group[g]),
            "priority": int(m.geom_priority[g]),
            "condim": int(m.geom_condim[g]),
            "friction": _r(m.geom_friction[g]),
            "solref": _r(m.geom_solref[g]),
            "solimp": _r(m.geom_solimp[g]),
            "rgba": _r(m.geom_rgba[g]),
            "mesh": meshes[mesh] if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and mesh >= 0 else None,
        })
    return {
        "nbody": int(m.nbody), "njnt": int(m.njnt), "ngeom": int(m.ngeom), "nmesh": int(m.nmesh),
        "nq": int(m.nq), "nu": int(m.nu),
        "bodies": {body(i): {"mass": float(m.body_mass[i]), "inertia": _r(m.body_inertia[i]),
                             "ipos": _r(m.body_ipos[i]), "pos": _r(m.body_pos[i]), "quat": _r(m.body_quat[i])}
                   for i in range(m.nbody)},
        "geoms": geoms,
        "option": {"timestep": float(m.opt.timestep), "integrator": int(m.opt.integrator),
                   "cone": int(m.opt.cone), "impratio": float(m.opt.impratio)},
    }


def same(a: Any, b: Any, where: str = "") -> list[str]:
    """Differences between two fingerprints (numbers to 1e-12)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{where}: keys {sorted(set(a) ^ set(b))}"]
        return [d for k in a for d in same(a[k], b[k], f"{where}/{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} items against {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b, strict=True)) for d in same(x, y, f"{where}[{i}]")]
    if isinstance(a, float) or isinstance(b, float):
        return [] if abs(float(a) - float(b)) <= 1e-12 * max(1.0, abs(float(a))) else [f"{where}: {a} != {b}"]
    return [] if a == b else [f"{where}: {a!r} != {b!r}"]


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_compiles_to_the_same_model_as_before(name: str, tmp_path: Path) -> None:
    reference = json.loads(REFERENCE.read_text())[name]
    got = json.loads(json.dumps(fingerprint(written(name, tmp_path))))
    # The integrator follows the actuators, not the style: a source's own position or velocity servos
    # (UR5's transmissions) get implicitfast since the actuators were written (MK825).
    for fingerprinted in (reference, got):
        fingerprinted["option"].pop("integrator")
        # Principal moments as a set: MuJoCo orders them by how the inertia was written (a
        # `fullinertia` is eigen-decomposed and sorted, a `diaginertia` kept as given), and a tensor
        # whose 1e-18 products of inertia are now written as 0 (clean_inertia) is a `diaginertia`.
        for each in fingerprinted["bodies"].values():
            each["inertia"] = sorted(each["inertia"])
        # q and −q are one rotation: the text a writer picks (since fmt_rpy, the shorter of a rotation's two
        # Euler triples) may give MuJoCo's compiler the other sign (Go1's camera_right), not another turn.
        for each in [*fingerprinted["bodies"].values(), *fingerprinted["geoms"]]:
            each["quat"] = _one_sign(each["quat"])
    assert same(reference, got) == []


def _one_sign(q: list[float]) -> list[float]:
    """The quaternion with its first component of magnitude above 1e-12 positive."""
    first = next((v for v in q if abs(v) > 1e-12), 1.0)
    return [-v for v in q] if first < 0.0 else list(q)


if __name__ == "__main__":  # the reference, from the writer of this checkout
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        prints = {n: fingerprint(written(n, Path(tmp))) for n in sorted(ROBOTS)}
    json.dump(prints, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")
