"""Our MJCF next to MuJoCo's own URDF import and MuJoCo Menagerie's hand-written model of the same robot.

For each robot: the source URDF (example-robot-data, a test dependency) converted by ``modelkit
convert`` (defaults, and ``--merge-fixed``), the same URDF imported by MuJoCo itself, and
Menagerie's model (give the folder of a Menagerie checkout with ``--menagerie DIR``). Printed per
model: bodies, joints, degrees of freedom, actuators (and their kind), total mass, whether the base
floats, the largest distance of the four calves from Menagerie's at its ``home`` pose (each model
posed by joint name, positions relative to the mean of the four hips), and MuJoCo's speed: steps per
second over 5 s on a plane from the home pose, controls at the home pose for position actuators
(zero otherwise), with the mean contact count.

Mesh files that a checkout or a conversion does not hold (Menagerie's visual STL files are not on PyPI)
are taken out the same way from every model before it is compiled: geoms of type mesh that do not
collide, and their assets. Collision shapes of these robots are primitives in all three.

    python bench/bench_menagerie.py --menagerie PATH/TO/mujoco_menagerie [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

ROBOTS = {  # name: (Menagerie file, example-robot-data URDF, calf bodies, hip bodies)
    "go1": ("unitree_go1/go1.xml", "go1_description/urdf/go1.urdf"),
}
LEGS = ("FR", "FL", "RR", "RL")
SECONDS = 5.0


def robots_folder() -> Path:
    import sysconfig

    for key in ("purelib", "platlib"):
        robots = Path(sysconfig.get_paths()[key]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            return robots
    sys.exit("example-robot-data is not installed (pip install example-robot-data)")


def without_visual_meshes(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """The spec without mesh geoms that do not collide, and without mesh assets no geom uses."""
    for geom in list(spec.geoms):
        if geom.type == mujoco.mjtGeom.mjGEOM_MESH and geom.contype == 0 and geom.conaffinity == 0:
            spec.delete(geom)
    used = {g.meshname for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH}
    for mesh in list(spec.meshes):
        if mesh.name not in used:
            spec.delete(mesh)
    return spec


def menagerie_model(path: Path) -> mujoco.MjSpec:
    spec = mujoco.MjSpec.from_file(str(path))
    for mesh in list(spec.meshes):  # Menagerie names meshes after their files when the name is absent
        if not mesh.name:
            mesh.name = Path(mesh.file).stem
    return without_visual_meshes(spec)


def mujoco_import(urdf: Path, folder: Path) -> mujoco.MjSpec:
    """MuJoCo's own URDF import, of the file without its <visual> elements (DAE meshes it cannot read)."""
    text = re.sub(r"<visual>.*?</visual>", "", urdf.read_text(), flags=re.S)
    copy = folder / urdf.name
    copy.write_text(text)
    return mujoco.MjSpec.from_file(str(copy))


def ours(urdf: Path, folder: Path, merge_fixed: bool) -> mujoco.MjSpec:
    """``modelkit convert`` with its defaults (the source's actuators: Go1's transmissions are effort
    interfaces, so motors; ``--actuators`` applies only to a source without any)."""
    from modelkit.convert.api import convert
    from modelkit.convert.options import WriteOptions

    out = folder / f"modelkit{'_merged' if merge_fixed else ''}" / f"{urdf.stem}.xml"
    result = convert([urdf], out, options=WriteOptions(merge_fixed=merge_fixed), force=True)
    if result.status != 0:
        sys.exit(f"convert failed: {[d.message for d in result.diagnostics][:3]}")
    return mujoco.MjSpec.from_file(str(out))


def with_floor(spec: mujoco.MjSpec) -> tuple[mujoco.MjModel, mujoco.MjModel]:
    """The model on a plane, and the model alone (no contact: its own cost per step)."""
    alone = spec.compile()
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], name="bench_floor")
    return spec.compile(), alone


def _home(reference: mujoco.MjModel) -> dict[str, float]:
    key = mujoco.mj_name2id(reference, mujoco.mjtObj.mjOBJ_KEY, "home")
    qpos = reference.key_qpos[key]
    out = {}
    for j in range(reference.njnt):
        if reference.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            name = mujoco.mj_id2name(reference, mujoco.mjtObj.mjOBJ_JOINT, j)
            out[name] = float(qpos[reference.jnt_qposadr[j]])
    return out


def _pose(model: mujoco.MjModel, data: mujoco.MjData, home: dict[str, float], height: float) -> None:
    mujoco.mj_resetData(model, data)
    for j in range(model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            adr = model.jnt_qposadr[j]
            data.qpos[adr:adr + 7] = [0, 0, height, 1, 0, 0, 0]
        elif name in home:
            data.qpos[model.jnt_qposadr[j]] = home[name]
    for a in range(model.nu):
        if model.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED and model.actuator_biastype[a] != 0:
            joint = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, model.actuator_trnid[a][0])
            data.ctrl[a] = home.get(joint, 0.0)  # a position servo holds the home pose


def _calves(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    mujoco.mj_kinematics(model, data)
    hips = [data.xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{leg}_hip")] for leg in LEGS]
    calves = [data.xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{leg}_calf")] for leg in LEGS]
    return np.asarray(calves) - np.mean(hips, axis=0)


def _speed(model: mujoco.MjModel, home: dict[str, float], height: float
           ) -> tuple[float, float, mujoco.MjData]:
    data = mujoco.MjData(model)
    _pose(model, data, home, height)
    steps = round(SECONDS / model.opt.timestep)
    contacts = 0
    start = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
        contacts += data.ncon
    return steps / (time.perf_counter() - start), contacts / steps, data


def measure(models: tuple[mujoco.MjModel, mujoco.MjModel], home: dict[str, float], height: float,
            reference: np.ndarray | None) -> dict[str, Any]:
    model, alone = models
    data = mujoco.MjData(model)
    _pose(model, data, home, height)
    calves = _calves(model, data)
    kinds = sorted({("position" if model.actuator_biastype[a] != 0 else "motor") for a in range(model.nu)})
    row: dict[str, Any] = {
        "bodies": int(model.nbody - 1), "joints": int(model.njnt), "dofs": int(model.nv),
        "actuators": int(model.nu),
        "actuator_kinds": kinds, "mass_kg": round(float(model.body_mass.sum()), 4),
        "floating": bool(np.any(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)),
        "calf_fk_mm": None if reference is None else round(float(np.abs(calves - reference).max()) * 1e3, 3),
    }
    speed, contacts, data = _speed(model, home, height)
    free_speed, _, _ = _speed(alone, home, height)
    row.update(steps_per_s_floor=round(speed), mean_contacts=round(contacts, 1),
               end_height_m=round(float(data.qpos[2]), 3) if row["floating"] else None,
               steps_per_s_no_contact=round(free_speed), timestep=float(model.opt.timestep))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--menagerie", type=Path, required=True, help="a MuJoCo Menagerie checkout")
    parser.add_argument("--json", type=Path, help="write the rows here too")
    args = parser.parse_args()
    robots = robots_folder()
    table: dict[str, dict[str, Any]] = {}
    for name, (menagerie_file, urdf_rel) in ROBOTS.items():
        urdf = robots / urdf_rel
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            menagerie = with_floor(menagerie_model(args.menagerie / menagerie_file))
            home = _home(menagerie[0])
            height = float(menagerie[0].key_qpos[0][2])
            ref_data = mujoco.MjData(menagerie[0])
            _pose(menagerie[0], ref_data, home, height)
            reference = _calves(menagerie[0], ref_data)
            rows = {"menagerie": measure(menagerie, home, height, reference)}
            for label in ("modelkit", "modelkit --merge-fixed", "mujoco import"):
                try:
                    spec = (mujoco_import(urdf, folder) if label == "mujoco import"
                            else ours(urdf, folder, merge_fixed=label.endswith("--merge-fixed")))
                    model = with_floor(without_visual_meshes(spec))
                except ValueError as exc:  # MuJoCo refuses the model: that is the row
                    rows[label] = {"refused": str(exc).splitlines()[0]}
                    continue
                rows[label] = measure(model, home, height, reference)
            table[name] = rows
    for name, rows in table.items():
        print(f"== {name}")
        keys = list(rows["menagerie"])
        print("| model | " + " | ".join(keys) + " |")
        print("|---" * (len(keys) + 1) + "|")
        for label, row in rows.items():
            if "refused" in row:
                print(f"| {label} | MuJoCo refuses it: {row['refused']} |")
                continue
            print(f"| {label} | " + " | ".join(str(row[k]) for k in keys) + " |")
    if args.json:
        args.json.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
