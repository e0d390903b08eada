"""Our MJCF next to MuJoCo's own URDF import and MuJoCo Menagerie's hand-written model of the same robot.

Robots: Universal Robots UR5 (example-robot-data has the UR5; Menagerie the UR5e, a different arm:
its kinematics differ by centimetres, so the UR rows compare structure and speed, not FK), Franka
Panda and Unitree Go1. For each: the source URDF (example-robot-data, a test dependency) converted by
``modelkit convert`` (defaults; ``--merge-fixed``; ``--actuators position``), the same URDF imported
by MuJoCo itself, and Menagerie's model, read from ``--menagerie DIR`` (a Menagerie checkout, or a
folder holding only the XML files at the same relative paths, e.g. ``DIR/franka_emika_panda/panda.xml``).

Printed per model: bodies, joints, degrees of freedom, actuators (count and kind), total mass, the
integrator, what the joints and actuators carry (damping, armature, friction loss, force ranges, a
``home`` keyframe), FK: the largest distance between comparable frames (arm links and hand, the Go1's
hips, calves and feet) at Menagerie's ``home`` pose, each model posed by joint name and every
position taken in the model's root frame (against Menagerie, and against MuJoCo's import where it
loads), and MuJoCo's speed: steps per second, contact-free (contacts disabled), the same time step in
every model, median and best of ``--rounds`` runs that take turns, and the ratios to Menagerie's (the
best run is the least disturbed by other load on a shared machine). Where no model lost a collision
mesh (the Go1), also with collision detection on, without a floor: the robot's own geoms.

Mesh geoms are taken out of every model before it is compiled, the same way for all rows (Menagerie's
mesh files are not on PyPI, so a folder of its XML files alone has none): visual meshes have no effect
on the dynamics; collision meshes do, which is why the speed is measured contact-free. Explicit
``<inertial>`` elements keep every mass and inertia exact. The output says how many mesh geoms each
model lost.

    python bench/bench_menagerie.py --menagerie PATH [--json out.json] [--rounds 31] [--robots go1]
"""

from __future__ import annotations

import argparse
import copy
import json
import re
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

TIMESTEP = 0.002  # s, Menagerie's (MuJoCo's default) in every model
SECONDS = 4.0  # simulated per timed run (2,000 steps, 10-60 ms here: short, so some runs escape other load)


@dataclass(frozen=True)
class Robot:
    menagerie: str  # path of Menagerie's model under --menagerie
    urdf: str  # path under example-robot-data's robots folder
    root: tuple[str, str]  # (Menagerie body, URDF link) whose frame the positions are taken in
    frames: tuple[tuple[str, str], ...]  # comparable (Menagerie body or site, URDF link)
    joints: dict[str, str] = field(default_factory=dict)  # Menagerie joint -> URDF joint, where they differ
    note: str = ""


_LEGS = ("FR", "FL", "RR", "RL")
ROBOTS = {
    "ur5": Robot(
        "universal_robots_ur5e/ur5e.xml", "ur_description/urdf/ur5_robot.urdf", ("base", "base_link"),
        tuple((n, n) for n in ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
                               "wrist_2_link", "wrist_3_link")),
        note="Menagerie has the UR5e, example-robot-data the UR5: different link lengths, FK not comparable"),
    "panda": Robot(
        "franka_emika_panda/panda.xml", "panda_description/urdf/panda.urdf", ("link0", "panda_link0"),
        (*((f"link{i}", f"panda_link{i}") for i in range(1, 8)), ("hand", "panda_hand"),
         ("left_finger", "panda_leftfinger"), ("right_finger", "panda_rightfinger")),
        joints={**{f"joint{i}": f"panda_joint{i}" for i in range(1, 8)},
                "finger_joint1": "panda_finger_joint1", "finger_joint2": "panda_finger_joint2"}),
    "go1": Robot(
        "unitree_go1/go1.xml", "go1_description/urdf/go1.urdf", ("trunk", "base"),
        tuple((f"{leg}_{part}", f"{leg}_{part}") for leg in _LEGS for part in ("hip", "calf"))
        + tuple((leg, f"{leg}_foot") for leg in _LEGS)),  # Menagerie's feet are sites
}
ROWS = ("menagerie", "modelkit", "modelkit --merge-fixed", "modelkit --actuators position", "mujoco import")


def robots_folder() -> Path:
    import sysconfig

    for key in ("purelib", "platlib"):
        robots = Path(sysconfig.get_paths()[key]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            return robots
    sys.exit("example-robot-data is not installed (pip install example-robot-data)")


def without_meshes(spec: mujoco.MjSpec) -> tuple[mujoco.MjSpec, dict[str, int]]:
    """The spec without mesh geoms and mesh assets, and how many visual and collision geoms went."""
    removed = {"visual": 0, "collision": 0}
    for geom in list(spec.geoms):
        if geom.type == mujoco.mjtGeom.mjGEOM_MESH:
            removed["visual" if geom.contype == 0 and geom.conaffinity == 0 else "collision"] += 1
            spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    return spec, removed


def mujoco_import(urdf: Path, folder: Path) -> mujoco.MjSpec:
    """MuJoCo's own URDF import of the file without its <visual> elements (DAE meshes it cannot read).
    Its collision meshes are deleted from the spec before it is compiled, so their files are never read."""
    stripped = folder / urdf.name
    stripped.write_text(re.sub(r"<visual>.*?</visual>", "", urdf.read_text(), flags=re.S))
    return mujoco.MjSpec.from_file(str(stripped))


def ours(urdf: Path, folder: Path, label: str) -> mujoco.MjSpec:
    """``modelkit convert`` with its defaults, or the one option the label names."""
    from modelkit.convert.api import convert
    from modelkit.convert.options import WriteOptions

    options = (WriteOptions(merge_fixed=True) if label.endswith("--merge-fixed")
               else WriteOptions(actuators="position") if label.endswith("--actuators position")
               else WriteOptions())
    out = folder / label.replace(" ", "_").replace("-", "") / f"{urdf.stem}.xml"
    result = convert([urdf], out, options=options, force=True)
    if result.status != 0:
        sys.exit(f"convert failed: {[d.message for d in result.diagnostics][:3]}")
    return mujoco.MjSpec.from_file(str(out))


def _name(model: mujoco.MjModel, kind: mujoco.mjtObj, index: int) -> str:
    return mujoco.mj_id2name(model, kind, index) or ""


def home_pose(model: mujoco.MjModel) -> tuple[dict[str, float], float]:
    """Menagerie's ``home`` keyframe: hinge and slide positions by joint name, and the free joint's height."""
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    qpos = model.key_qpos[key]
    home, height = {}, 0.0
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            height = float(qpos[model.jnt_qposadr[j] + 2])
        else:
            home[_name(model, mujoco.mjtObj.mjOBJ_JOINT, j)] = float(qpos[model.jnt_qposadr[j]])
    return home, height


def pose(model: mujoco.MjModel, data: mujoco.MjData, home: dict[str, float], height: float) -> None:
    """Reset, then the home pose by joint name; position servos (gain and bias) hold it. A model whose
    own ``home`` keyframe is this pose (Menagerie's) takes the keyframe's controls, which also drive
    tendon actuators (Panda's fingers)."""
    mujoco.mj_resetData(model, data)
    for j in range(model.njnt):
        adr = model.jnt_qposadr[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            data.qpos[adr:adr + 7] = [0, 0, height, 1, 0, 0, 0]
        else:
            data.qpos[adr] = home.get(_name(model, mujoco.mjtObj.mjOBJ_JOINT, j), 0.0)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0 and model.nu and np.allclose(model.key_qpos[key], data.qpos):
        data.ctrl[:] = model.key_ctrl[key]
        return
    for a in range(model.nu):
        if model.actuator_biastype[a] != 0 and model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT:
            data.ctrl[a] = home.get(_name(model, mujoco.mjtObj.mjOBJ_JOINT, model.actuator_trnid[a][0]), 0.0)


def frame_positions(model: mujoco.MjModel, data: mujoco.MjData, root: str, names: list[str]
                    ) -> dict[str, np.ndarray]:
    """Each named body's (else site's) position in the root body's frame (the world's when MuJoCo's
    import fused the root into it). Names the model does not have are left out."""
    mujoco.mj_kinematics(model, data)
    r = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, root)
    origin, rotation = (data.xpos[r], data.xmat[r].reshape(3, 3)) if r >= 0 else (np.zeros(3), np.eye(3))
    out = {}
    for name in names:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        s = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
        if b >= 0:
            out[name] = rotation.T @ (data.xpos[b] - origin)
        elif s >= 0:
            out[name] = rotation.T @ (data.site_xpos[s] - origin)
    return out


def fk_gap(a: dict[str, np.ndarray], b: dict[str, np.ndarray], pairs: list[tuple[str, str]]) -> str:
    """Largest distance in mm over the frame pairs both have, and how many of the pairs that was."""
    gaps = [float(np.linalg.norm(a[x] - b[y])) for x, y in pairs if x in a and y in b]
    return f"{max(gaps) * 1e3:.3f} mm ({len(gaps)}/{len(pairs)} frames)" if gaps else "no common frame"


def actuator_kinds(model: mujoco.MjModel) -> str:
    kinds: dict[str, int] = {}
    for a in range(model.nu):
        bias = model.actuator_biasprm[a]
        kind = ("motor" if model.actuator_biastype[a] == 0 and model.actuator_gaintype[a] == 0
                else "position" if bias[1] != 0 else "velocity" if bias[2] != 0 else "other")
        if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
            kind += " (tendon)"
        kinds[kind] = kinds.get(kind, 0) + 1
    return ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) or "none"


def carries(model: mujoco.MjModel) -> str:
    """What the joints and actuators carry beyond kinematics and inertia."""
    has = [("damping", bool(np.any(model.dof_damping > 0))),
           ("armature", bool(np.any(model.dof_armature > 0))),
           ("frictionloss", bool(np.any(model.dof_frictionloss > 0))),
           ("forcerange", bool(np.any(model.actuator_forcelimited))),
           ("home key", mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home") >= 0),
           (f"{model.nexclude} excludes", model.nexclude > 0), (f"{model.neq} equality", model.neq > 0)]
    return ", ".join(name for name, present in has if present) or "-"


_INTEGRATORS = {0: "Euler", 1: "RK4", 2: "implicit", 3: "implicitfast"}


def describe(model: mujoco.MjModel, removed: dict[str, int]) -> dict[str, Any]:
    floating = bool(np.any(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE))
    return {
        "bodies": int(model.nbody - 1), "joints": int(model.njnt), "dofs": int(model.nv),
        "actuators": f"{model.nu}: {actuator_kinds(model)}",
        "mass_kg": round(float(model.body_mass.sum()), 3), "base": "free" if floating else "welded",
        "integrator": _INTEGRATORS.get(int(model.opt.integrator), "?"), "carries": carries(model),
        "mesh_geoms_removed": f"{removed['visual']} visual, {removed['collision']} collision",
    }


def contact_free(model: mujoco.MjModel) -> mujoco.MjModel:
    model.opt.timestep = TIMESTEP
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    return model


def timed_run(model: mujoco.MjModel, home: dict[str, float], height: float) -> float:
    """Steps per CPU second (this process's: less disturbed by other load than wall time) over SECONDS of
    simulated time from the home pose."""
    data = mujoco.MjData(model)
    pose(model, data, home, height)
    steps = round(SECONDS / model.opt.timestep)
    start = time.process_time()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return steps / (time.process_time() - start)


def build(robot: Robot, menagerie_dir: Path, robots: Path, folder: Path
          ) -> tuple[dict[str, dict[str, Any]], dict[str, mujoco.MjModel], dict[str, int]]:
    """Every row's description (or why MuJoCo refused it), its model compiled without meshes, and how
    many collision meshes it lost."""
    urdf = robots / robot.urdf
    rows: dict[str, dict[str, Any]] = {}
    models: dict[str, mujoco.MjModel] = {}
    lost: dict[str, int] = {}
    for label in ROWS:
        try:
            spec = (mujoco.MjSpec.from_file(str(menagerie_dir / robot.menagerie)) if label == "menagerie"
                    else mujoco_import(urdf, folder) if label == "mujoco import"
                    else ours(urdf, folder, label))
            spec, removed = without_meshes(spec)
            model = spec.compile()
        except ValueError as exc:  # MuJoCo refuses the model: that is the row
            rows[label] = {"refused": str(exc).strip().splitlines()[0]}
            continue
        rows[label] = describe(model, removed)
        models[label] = model
        lost[label] = removed["collision"]
    return rows, models, lost


def compare_fk(robot: Robot, models: dict[str, mujoco.MjModel], home_m: dict[str, float],
               home_u: dict[str, float], height: float, rows: dict[str, dict[str, Any]]) -> None:
    positions: dict[str, dict[str, np.ndarray]] = {}
    for label, model in models.items():
        data = mujoco.MjData(model)
        menagerie = label == "menagerie"
        pose(model, data, home_m if menagerie else home_u, height)
        positions[label] = frame_positions(model, data, robot.root[0 if menagerie else 1],
                                           [pair[0 if menagerie else 1] for pair in robot.frames])
    same = [(u, u) for _, u in robot.frames]
    for label in models:
        if label != "menagerie":
            rows[label]["fk_vs_menagerie"] = fk_gap(positions["menagerie"], positions[label],
                                                    list(robot.frames))
        if "mujoco import" in positions and label not in ("menagerie", "mujoco import"):
            rows[label]["fk_vs_mujoco_import"] = fk_gap(positions["mujoco import"], positions[label], same)


def solver_iterations(model: mujoco.MjModel, home: dict[str, float], height: float) -> float:
    """Mean constraint-solver iterations per step over the same run as ``timed_run`` (not timed): a
    model whose joints move under friction loss or limits needs more than one held still."""
    data = mujoco.MjData(model)
    pose(model, data, home, height)
    steps = round(SECONDS / model.opt.timestep)
    total = 0
    for _ in range(steps):
        mujoco.mj_step(model, data)
        total += int(data.solver_niter[0])
    return total / steps


def compare_speed(models: dict[str, mujoco.MjModel], collisions: bool, home_m: dict[str, float],
                  home_u: dict[str, float], height: float, rounds: int, rows: dict[str, dict[str, Any]]
                  ) -> None:
    """Steps per second of every model (median and best run), contact-free, and again with Menagerie's
    integrator where the model's differs; with ``collisions`` (every model kept all its collision shapes) also
    with collision detection on, without a floor (the robot's own geoms only). The runs take turns."""
    integrator = int(models["menagerie"].opt.integrator)
    timed: dict[tuple[str, str], mujoco.MjModel] = {}
    for label, model in models.items():
        if collisions:
            timed[label, "self_collision_no_floor"] = with_collisions = copy.deepcopy(model)
            with_collisions.opt.timestep = TIMESTEP
        timed[label, "contact_free"] = model = contact_free(model)
        if int(model.opt.integrator) != integrator:  # how much of a gap is the integrator's
            timed[label, "contact_free_with_menagerie_integrator"] = variant = copy.deepcopy(model)
            variant.opt.integrator = integrator
    runs: dict[tuple[str, str], list[float]] = {key: [] for key in timed}
    for key, model in timed.items():  # warm-up
        timed_run(model, home_m if key[0] == "menagerie" else home_u, height)
    for _ in range(rounds):  # the models take turns, so that other load on the machine hits them alike
        for key, model in timed.items():
            runs[key].append(timed_run(model, home_m if key[0] == "menagerie" else home_u, height))
    for label, model in models.items():  # contact-free by now (contact_free changed them in place)
        iterations = solver_iterations(model, home_m if label == "menagerie" else home_u, height)
        rows[label]["contact_free_solver_iterations_per_step"] = round(iterations, 2)
    for (label, setup), values in runs.items():
        reference = runs["menagerie", setup.replace("_with_menagerie_integrator", "")]
        for stat, summary in (("median", statistics.median), ("best", max)):
            rows[label][f"{setup}_{stat}_steps_per_s"] = round(summary(values))
            rows[label][f"{setup}_{stat}_ratio"] = round(summary(values) / summary(reference), 2)


def compare(name: str, robot: Robot, menagerie_dir: Path, robots: Path, rounds: int
            ) -> dict[str, dict[str, Any]]:
    with tempfile.TemporaryDirectory() as tmp:
        rows, models, lost = build(robot, menagerie_dir, robots, Path(tmp))
    home_m, height = home_pose(models["menagerie"])
    home_u = {robot.joints.get(j, j): q for j, q in home_m.items()}
    compare_fk(robot, models, home_m, home_u, height, rows)
    compare_speed(models, not any(lost.values()), home_m, home_u, height, rounds, rows)
    if robot.note:
        rows["menagerie"]["note"] = robot.note
    print(f"== {name}: {robot.menagerie} / {robot.urdf}", flush=True)
    return rows


def print_table(rows: dict[str, dict[str, Any]]) -> None:
    keys: list[str] = []
    for row in rows.values():
        keys += [k for k in row if k not in keys and k not in ("refused", "note")]
    print("| model | " + " | ".join(keys) + " |")
    print("|---" * (len(keys) + 1) + "|")
    for label, row in rows.items():
        if "refused" in row:
            print(f"| {label} | MuJoCo refuses it: {row['refused']} |")
        else:
            print(f"| {label} | " + " | ".join(str(row.get(k, "")) for k in keys) + " |")
    notes = [row["note"] for row in rows.values() if "note" in row]
    for note in notes:
        print(f"note: {note}")


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--menagerie", type=Path, required=True,
                        help="a MuJoCo Menagerie checkout, or a folder with its XML files at the same paths")
    parser.add_argument("--robots", default=",".join(ROBOTS), help=f"comma-separated, of {', '.join(ROBOTS)}")
    parser.add_argument("--rounds", type=int, default=31, help="timed runs per model (median and best)")
    parser.add_argument("--json", type=Path, help="write the rows here too")
    args = parser.parse_args()
    robots = robots_folder()
    table = {name: compare(name, ROBOTS[name], args.menagerie, robots, args.rounds)
             for name in args.robots.split(",")}
    print(f"\nMuJoCo {mujoco.__version__}; every mesh geom removed from every model (Menagerie's mesh "
          f"files need not be present); steps per CPU second contact-free (contacts disabled), time step "
          f"{TIMESTEP} s, {SECONDS} s simulated per run, median and best of {args.rounds} runs taking turns")
    for name, rows in table.items():
        print(f"\n== {name}")
        print_table(rows)
    if args.json:
        meta = {"mujoco": mujoco.__version__, "timestep_s": TIMESTEP, "simulated_s_per_run": SECONDS,
                "rounds": args.rounds, "speed": "steps per CPU second, median and best of the runs",
                "meshes": "every mesh geom removed from every model before compiling"}
        args.json.write_text(json.dumps({"meta": meta, "robots": table}, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
