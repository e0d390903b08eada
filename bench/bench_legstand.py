"""Legged robots converted with the default options, standing on a plain floor under their own servos.

For each legged robot found here (pybullet_data's and example-robot-data's), as a user would:
``modelkit convert ROBOT -o out/ROBOT.xml`` (defaults: a floating base, position servos with the
documented gain rule, a ``home`` keyframe), then the written MJCF loaded through ``MjSpec`` with one
default-contact ``<geom type="plane">`` added, reset to ``home`` (``ctrl`` = the home positions; the
key stands the base on the floor, MK882), and 2 s of MuJoCo with that ``ctrl``.

Printed per robot: the actuators written (count and kinds), the mass, the lowest collision shape's
height above the floor at the key (negative: inside it), how far the base dropped
(start minus end height) and tilted, the largest joint error from home over the run, the largest
share of the run any one actuator spent at its force limit, and the joint that spent it.

    python bench/bench_legstand.py [--json out.json] [--seconds 2] [--robots spirit40,go1]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _pybullet_data() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


def _example_robot_data() -> Path:
    import sysconfig

    for key in ("purelib", "platlib"):
        robots = Path(sysconfig.get_paths()[key]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            return robots
    raise SystemExit("example-robot-data is not installed")


def robots() -> dict[str, Path]:
    pb, erd = _pybullet_data(), _example_robot_data()
    return {
        "spirit40 (pybullet_data)": pb / "quadruped/spirit40.urdf",
        "laikago_toes (pybullet_data)": pb / "laikago/laikago_toes.urdf",
        "laikago_toes_zup (pybullet_data)": pb / "laikago/laikago_toes_zup.urdf",
        "aliengo (pybullet_data)": pb / "aliengo/aliengo.urdf",
        "a1 (pybullet_data)": pb / "a1/a1.urdf",
        "minitaur (pybullet_data)": pb / "quadruped/minitaur.urdf",
        "vision60 (pybullet_data)": pb / "quadruped/vision60.urdf",
        "go1 (erd)": erd / "go1_description/urdf/go1.urdf",
        "go2 (erd)": erd / "go2_description/urdf/go2.urdf",
        "a1 (erd)": erd / "a1_description/urdf/a1.urdf",
        "anymal_b (erd)": erd / "anymal_b_simple_description/robots/anymal.urdf",
        "anymal_c (erd)": erd / "anymal_c_simple_description/urdf/anymal.urdf",
        "solo12 (erd)": erd / "solo_description/robots/solo12.urdf",
        "hyq (erd)": erd / "hyq_description/robots/hyq_no_sensors.urdf",
        "laikago (erd)": erd / "laikago_description/urdf/laikago.urdf",
        "b1 (erd)": erd / "b1_description/urdf/b1.urdf",
    }


@dataclass
class Stand:
    robot: str
    actuators: str
    mass: float
    start_gap: float  # m, the lowest collision geom above the floor at the home key (negative: inside)
    drop: float  # m, base height at the start minus at the end
    tilt: float  # rad, the base's rotation from upright at the end
    joint_error: float  # rad, the largest |q - q_home| over the run
    saturated: float  # the largest share of steps any one actuator's force sat at its limit
    saturated_joint: str
    note: str = ""


def convert(source: Path, folder: Path) -> Path:
    from modelkit.api import load
    from modelkit.convert.api import write

    out = folder / f"{source.stem}.xml"
    write(load(source), out, force=True)
    return out


def floor_gap(m: mujoco.MjModel, d: mujoco.MjData, floor: int) -> float:
    """How far the lowest collision geom is above the floor (negative: inside it) in the state ``d``
    holds: the floor's margin is raised while the contacts are found, so that a robot above the floor
    sees it too. Nothing is moved: the written ``home`` key places the base (MK882)."""
    margin = float(m.geom_margin[floor])
    m.geom_margin[floor] = 10.0
    try:
        mujoco.mj_forward(m, d)
        gaps = [c.dist for c in d.contact[:d.ncon] if floor in (c.geom1, c.geom2)]
        if not gaps:
            raise ValueError("no collision geom within 10 m of the floor")
        return float(min(gaps))
    finally:
        m.geom_margin[floor] = margin
        mujoco.mj_forward(m, d)


def stand(xml: Path, seconds: float) -> tuple[mujoco.MjModel, dict[str, float]]:
    spec = mujoco.MjSpec.from_file(str(xml))
    floor = spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
    mujoco.mj_resetDataKeyframe(m, d, key)
    if m.jnt_type[0] != mujoco.mjtJoint.mjJNT_FREE:
        raise ValueError("the base is not free")
    gap = floor_gap(m, d, floor.id)
    home = d.qpos.copy()
    start = float(d.qpos[2])
    moving = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
    hinge = [j for j in range(m.njnt) if int(m.jnt_type[j]) in moving]
    adr = np.array([m.jnt_qposadr[j] for j in hinge], dtype=int)
    limited = m.actuator_forcelimited.astype(bool)
    lo, hi = m.actuator_forcerange[:, 0], m.actuator_forcerange[:, 1]
    at_limit = np.zeros(m.nu)
    worst = 0.0
    steps = round(seconds / m.opt.timestep)
    for _ in range(steps):
        mujoco.mj_step(m, d)
        f = d.actuator_force
        at_limit += limited & ((f <= lo + 1e-9 * np.abs(lo)) | (f >= hi - 1e-9 * np.abs(hi)))
        if adr.size:
            worst = max(worst, float(np.abs(d.qpos[adr] - home[adr]).max()))
    w = min(1.0, abs(float(d.qpos[3])))
    share = at_limit / steps if m.nu else np.zeros(1)
    a = int(np.argmax(share)) if m.nu and share.max() > 0.0 else -1  # the joint named only when it sat
    jname = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.actuator_trnid[a, 0])) if a >= 0 else ""
    return m, {"start_gap": gap, "drop": start - float(d.qpos[2]), "tilt": 2.0 * math.acos(w),
               "joint_error": worst, "saturated": float(share.max()), "saturated_joint": jname or ""}


def kinds(xml: Path) -> str:
    import xml.etree.ElementTree as ET

    section = ET.parse(xml).getroot().find("actuator")
    counts: dict[str, int] = {}
    for el in [] if section is None else section:
        counts[el.tag] = counts.get(el.tag, 0) + 1
    return " ".join(f"{n} {t}" for t, n in sorted(counts.items())) or "none"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--json", type=Path)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--robots", default="", help="comma-separated substrings of the robot names")
    args = parser.parse_args(argv)
    import os

    os.environ.setdefault("ROS_PACKAGE_PATH", str(_example_robot_data()))
    wanted = [w for w in args.robots.split(",") if w]
    rows: list[Stand] = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, source in robots().items():
            if wanted and not any(w in name for w in wanted):
                continue
            folder = Path(tmp) / name.split()[0] / name.split()[1].strip("()")
            folder.mkdir(parents=True, exist_ok=True)
            try:
                xml = convert(source, folder)
                m, r = stand(xml, args.seconds)
            except Exception as exc:  # a robot that does not convert or load is reported, not fatal
                rows.append(Stand(name, "", 0.0, math.nan, math.nan, math.nan, math.nan, math.nan, "",
                                  f"{type(exc).__name__}: {str(exc).splitlines()[0][:90]}"))
                continue
            mass = float(m.body_subtreemass[1]) if m.nbody > 1 else 0.0
            rows.append(Stand(name, kinds(xml), mass, **r))
    print(f"{'robot':34} {'actuators':22} {'mass':>7} {'gap mm':>7} {'drop mm':>9} {'tilt':>7} {'q err':>7} "
          f"{'at limit':>8}  joint")
    for s in rows:
        if s.note:
            print(f"{s.robot:34} {s.note}")
            continue
        print(f"{s.robot:34} {s.actuators:22} {s.mass:7.2f} {s.start_gap * 1e3:7.3f} {s.drop * 1e3:9.1f} "
              f"{s.tilt:7.3f} {s.joint_error:7.3f} {s.saturated:8.0%}  {s.saturated_joint}")
    if args.json:
        args.json.write_text(json.dumps([asdict(s) for s in rows], indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
