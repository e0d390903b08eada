"""Every free robot converted with the default options, reset to its ``home`` key on a plain floor.

The user's step after ``modelkit convert ROBOT -o robot.xml`` for a robot that moves itself: the
written MJCF loaded through ``MjSpec`` with one default-contact ``<geom type="plane">`` added, reset
to ``home`` (MuJoCo's reset when there is no key), then 2 s of MuJoCo. The robots are the URDF files
of example-robot-data and pybullet_data (its random objects left out), the ``.urdf``, ``.body``
and ``.sdf`` files of ``../shared/corpus`` and the ``model.urdf`` files under each ``--extra`` folder
(icub-models' ``share`` folder, also put on ``ROS_PACKAGE_PATH``); those whose written file has a
free root are measured.

Per robot: whether the file has a key, how deep its collision shapes start inside the floor (the
deepest contact; 0 when none), how far the floor throws the base up within the first second, MuJoCo's
warnings and the first non-finite state; the load ratio of the bodies it stands on after 0.3 s (the
robot's mass times the body's ``body_invweight0``, the largest; MK883), whether ``convert`` said
MK883, how deep it sinks, whether it falls (the base more than 10 cm lower) within 2 s, how far the
base tilts (it tipped over beyond 0.15 rad) and whether ``convert`` said MK887 (it cannot stand). A file
that does not convert or compile is counted, not fatal.

    python bench/bench_home_floor.py [--json out.json] [--source DIR] [--extra DIR ...]

``--source`` runs another checkout's modelkit (a worktree of an older commit) for a before/after.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import sysconfig
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "corpus"
THROWN = 0.01  # m: a base rising more than this in the second was thrown by the floor
INSIDE = 1e-3  # m: a start deeper than this is inside the floor
FELL = 0.1  # m: a base this much lower than it started has fallen
TIPPED = 0.15  # rad: a base turned this much about a horizontal axis within 2 s has tipped over
SETTLED = 0.3  # s: the bodies touching the floor then are the ones the robot stands on
EXTRA: list[Path] = []  # --extra folders


def _example_robot_data() -> Path:
    return Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"


def robot_files() -> list[Path]:
    import pybullet_data

    data = Path(pybullet_data.getDataPath())
    found = sorted(_example_robot_data().rglob("*.urdf"))
    found += sorted(p for p in data.rglob("*.urdf") if "random_urdfs" not in p.parts)
    found += sorted(p for p in CORPUS.rglob("*") if p.suffix in (".urdf", ".body", ".sdf"))
    for folder in EXTRA:
        found += sorted(folder.rglob("model.urdf"))
    return found


def measure(path: Path) -> dict[str, Any] | None:
    """The robot at ``path`` converted and reset on a floor; None when it does not convert, does not
    compile or has no free root."""
    import mujoco
    import numpy as np

    from modelkit.api import load
    from modelkit.convert.api import write

    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(str(p) for p in [_example_robot_data(), *EXTRA])
    try:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "robot.xml"
            said = {note.code for note in write(load(path), out, force=True)}
            spec = mujoco.MjSpec.from_file(str(out))
            spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
            m = spec.compile()
    except Exception:  # a file that does not convert or compile is counted by the caller
        return None
    if m.njnt == 0 or int(m.jnt_type[0]) != int(mujoco.mjtJoint.mjJNT_FREE):
        return None
    d = mujoco.MjData(m)
    key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(m, d, key)
    mujoco.mj_forward(m, d)
    floor = m.geom("floor").id
    deepest = min([float(c.dist) for c in d.contact[:d.ncon] if floor in tuple(c.geom)] or [0.0])
    start = highest = lowest = float(d.qpos[2])
    up = np.zeros(9)
    mujoco.mju_quat2Mat(up, d.qpos[3:7])
    start_up, tilt = up.reshape(3, 3)[:, 2].copy(), 0.0
    unstable = None
    ratio, sunk = 0.0, 0.0
    mass = float(m.body_subtreemass[int(m.jnt_bodyid[0])])
    warnings = 0
    for step in range(round(2.0 / m.opt.timestep)):
        if step == round(1.0 / m.opt.timestep):
            warnings = int(sum(int(w.number) for w in d.warning))
        mujoco.mj_step(m, d)
        if not np.all(np.isfinite(d.qpos)):
            unstable = step * m.opt.timestep
            break
        if step < round(1.0 / m.opt.timestep):
            highest = max(highest, float(d.qpos[2]))
        lowest = min(lowest, float(d.qpos[2]))
        mujoco.mju_quat2Mat(up, d.qpos[3:7])
        tilt = max(tilt, float(np.arccos(np.clip(up.reshape(3, 3)[:, 2] @ start_up, -1.0, 1.0))))
        touching = [c for c in d.contact[:d.ncon] if floor in tuple(c.geom)]
        sunk = max([sunk, *(-float(c.dist) for c in touching)])
        if step == round(SETTLED / m.opt.timestep):
            bodies = {int(m.geom_bodyid[g]) for c in touching for g in c.geom if g != floor}
            ratio = max([0.0, *(mass * float(m.body_invweight0[b][0]) for b in bodies)])
    return {"key": key >= 0, "start_height": start, "inside": max(0.0, -deepest), "thrown": highest - start,
            "warnings": warnings, "unstable_at": unstable, "load_ratio": ratio, "mk883": "MK883" in said,
            "sunk": sunk, "fell": start - lowest > FELL, "tilt": tilt, "mk887": "MK887" in said}


def _short(name: str) -> str:
    """The file's name with its folder (icub-models' files are all ``model.urdf``)."""
    path = Path(name)
    return f"{path.parent.name}/{path.name}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--json", type=Path)
    parser.add_argument("--source", type=Path, default=ROOT, help="the checkout whose modelkit runs")
    parser.add_argument("--extra", type=Path, nargs="*", default=[],
                        help="more robot folders: their model.urdf files (icub-models' share folder)")
    args = parser.parse_args(argv)
    EXTRA.extend(p.resolve() for p in args.extra)
    sys.path.insert(0, str(args.source.resolve()))
    os.environ["PYTHONPATH"] = str(args.source.resolve())  # the worker processes import it too
    import modelkit

    print(f"modelkit from {Path(modelkit.__file__).parent}")
    files = robot_files()
    with ProcessPoolExecutor(2) as pool:
        measured = dict(zip((str(f) for f in files), pool.map(measure, files, chunksize=4), strict=True))
    free = {name: row for name, row in measured.items() if row is not None}
    inside = [name for name, row in free.items() if row["inside"] > INSIDE]
    thrown = [name for name, row in free.items() if row["thrown"] > THROWN]
    warned = [name for name, row in free.items() if row["warnings"] or row["unstable_at"] is not None]
    print(f"{len(files)} files, {len(free)} free robots converted, {sum(r['key'] for r in free.values())} "
          "with a home key")
    print(f"start more than {INSIDE * 1e3:g} mm inside the floor: {len(inside)}")
    print(f"thrown more than {THROWN * 1e2:g} cm up in 1 s: {len(thrown)}"
          + (f" (most {max(free[n]['thrown'] for n in thrown):.2f} m)" if thrown else ""))
    print(f"MuJoCo warnings or a non-finite state in 1 s: {len(warned)} {[Path(n).name for n in warned]}")
    said = sorted(name for name, row in free.items() if row["mk883"])
    fell = sorted(name for name, row in free.items() if row["fell"])
    standing = [row["load_ratio"] for row in free.values() if not row["fell"] and row["unstable_at"] is None]
    print(f"fell (base {FELL * 1e2:g} cm lower) within 2 s: {len(fell)} "
          + str([f"{_short(n)} (load ratio {free[n]['load_ratio']:.0f})" for n in fell]))
    print(f"largest load ratio of a robot that stands: {max(standing, default=0.0):.0f}; "
          f"MK883 said for {len(said)}: {[_short(n) for n in said]}")
    tipped = sorted(name for name, row in free.items() if row["tilt"] > TIPPED or row["fell"])
    cannot = sorted(name for name, row in free.items() if row["mk887"])
    print(f"tipped ({TIPPED:g} rad) or fell within 2 s: {len(tipped)} {[_short(n) for n in tipped]}")
    print(f"MK887 said for {len(cannot)}: {[_short(n) for n in cannot]}; of them tipped or fell: "
          f"{len(set(cannot) & set(tipped))}")
    if args.json:
        args.json.write_text(json.dumps(free, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
