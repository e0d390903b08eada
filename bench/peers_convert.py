"""Converters side by side on the corpus URDFs: modelkit against the peers users reach for.

    python bench/peers_convert.py [--json FILE] [--corpus DIR]

URDF → MJCF: MuJoCo's own URDF import (`MjModel.from_xml_path` on the URDF, saved with
`mj_saveLastXML`) against `modelkit convert`. URDF → SDF: libsdformat's own URDF conversion
(`sdf::Root::Load` on the URDF, through a small program compiled against libsdformat12) against
`modelkit convert`. For each model and tool: does the result load warning-free in the target
engine (MuJoCo: compile and step 1 s with no warnings; SDF: libsdformat loads with no error),
and what was lost compared with the URDF: links dropped or fused, a floating base welded, the
total mass changed, inertia recomputed. Reports, never fails.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_CORPUS = REPO.parent / "shared" / "corpus"

SDF_PROBE = r"""
#include <iostream>
#include <sdf/sdf.hh>
// Loads a URDF or SDF the way libsdformat does and prints what it made of it.
int main(int argc, char **argv) {
  sdf::Root root;
  sdf::Errors errors = root.Load(argv[1]);
  std::cout << "errors " << errors.size() << "\n";
  for (const auto &e : errors) std::cout << "error " << e.Message() << "\n";
  const sdf::Model *model = root.Model();
  if (!model) { std::cout << "nomodel\n"; return 0; }
  std::cout << "static " << model->Static() << "\n";
  for (uint64_t i = 0; i < model->LinkCount(); ++i) {
    const sdf::Link *l = model->LinkByIndex(i);
    std::cout << "link " << l->Name() << " " << l->Inertial().MassMatrix().Mass() << "\n";
  }
  for (uint64_t i = 0; i < model->FrameCount(); ++i)
    std::cout << "frame " << model->FrameByIndex(i)->Name() << "\n";
  for (uint64_t i = 0; i < model->JointCount(); ++i) {
    const sdf::Joint *j = model->JointByIndex(i);
    std::cout << "joint " << j->Name() << " " << static_cast<int>(j->Type()) << " "
              << j->ParentLinkName() << "\n";
  }
  return 0;
}
"""


def sdf_probe() -> Path | None:
    compiler, pkg = shutil.which("g++"), shutil.which("pkg-config")
    if not compiler or not pkg:
        return None
    flags = subprocess.run([pkg, "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    if flags.returncode:
        return None
    folder = Path(tempfile.gettempdir()) / "modelkit-oracles"
    folder.mkdir(parents=True, exist_ok=True)
    binary = folder / "sdf_probe"
    if not binary.exists():
        src = folder / "sdf_probe.cc"
        src.write_text(SDF_PROBE)
        subprocess.run([compiler, "-O0", "-o", str(binary), str(src), *flags.stdout.split()], check=True)
    return binary


def run_probe(binary: Path, path: Path) -> dict[str, Any]:
    out = subprocess.run([str(binary), path.name], cwd=path.parent, capture_output=True, text=True,
                         timeout=120)
    links: dict[str, float] = {}
    joints: list[tuple[str, int, str]] = []
    frames: list[str] = []
    errors = 0
    messages: list[str] = []
    for line in out.stdout.splitlines():
        word, _, rest = line.partition(" ")
        if word == "errors":
            errors = int(rest)
        elif word == "error":
            messages.append(rest[:160])
        elif word == "link":
            name, _, mass = rest.rpartition(" ")
            links[name] = float(mass)
        elif word == "frame":
            frames.append(rest)
        elif word == "joint":
            parts = rest.split(" ")
            joints.append((parts[0], int(parts[1]), parts[2]))
    return {"errors": errors, "messages": messages, "links": links, "joints": joints, "frames": frames,
            "world_joint": any(p == "world" for _, _, p in joints)}


def urdf_facts(path: Path) -> dict[str, Any]:
    from modelkit.api import validate

    robot = validate(path).robot
    assert robot is not None
    masses = {lk.name: (lk.inertial.mass if lk.inertial else 0.0) for lk in robot.links}
    return {"links": masses, "total_mass": sum(masses.values()), "robot": robot}


def mujoco_step_warnings(model: Any) -> int:
    import mujoco

    data = mujoco.MjData(model)
    steps = round(1.0 / model.opt.timestep)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return int(sum(w.number for w in data.warning))


def mujoco_facts(path: Path) -> dict[str, Any]:
    import mujoco

    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as exc:  # the peer refusing a file is a result, not a crash
        return {"loads": False, "error": str(exc).splitlines()[0][:160]}
    free = int(np.sum(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE))
    return {"loads": True, "bodies": int(model.nbody - 1), "free_joints": free,
            "total_mass": float(model.body_mass.sum()), "warnings": mujoco_step_warnings(model),
            "model": model}


def compare_mjcf(src: dict[str, Any], facts: dict[str, Any]) -> list[str]:
    if not facts.get("loads"):
        return [f"refused: {facts.get('error')}"]
    lost = []
    if facts["bodies"] < len(src["links"]):
        lost.append(f"{len(src['links']) - facts['bodies']} link(s) fused or dropped")
    if facts["free_joints"] == 0:
        lost.append("floating base welded to the world")
    if abs(facts["total_mass"] - src["total_mass"]) > 1e-9 * max(1.0, src["total_mass"]):
        lost.append(f"total mass {src['total_mass']:.9g} → {facts['total_mass']:.9g} kg")
    if facts["warnings"]:
        lost.append(f"{facts['warnings']} simulation warning(s) in 1 s")
    return lost


def compare_sdf(src: dict[str, Any], facts: dict[str, Any]) -> list[str]:
    if facts["errors"]:
        return [f"errors: {'; '.join(facts['messages'][:2])}"]
    lost = []
    dropped = sorted(set(src["links"]) - set(facts["links"]) - set(facts.get("frames", [])))
    if dropped:
        lost.append(f"{len(dropped)} link(s) dropped or lumped: {', '.join(dropped[:4])}")
    as_frames = sorted(set(src["links"]) & set(facts.get("frames", [])))
    if as_frames:
        lost.append(f"massless link(s) kept as <frame>: {', '.join(as_frames[:4])} (no loss)")
    total = sum(facts["links"].values())
    if abs(total - src["total_mass"]) > 1e-9 * max(1.0, src["total_mass"]):
        lost.append(f"total mass {src['total_mass']:.9g} → {total:.9g} kg")
    return lost


def urdf_files(corpus: Path) -> list[Path]:
    return sorted(p for p in corpus.rglob("*.urdf") if p.is_file())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    import mujoco

    from modelkit.convert import convert

    probe = sdf_probe()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, urdf in enumerate(urdf_files(args.corpus)):
            try:
                src = urdf_facts(urdf)
            except AssertionError:
                continue
            row: dict[str, Any] = {"file": str(urdf.relative_to(args.corpus)), "links": len(src["links"])}
            peer = mujoco_facts(urdf)
            if peer.get("loads"):
                saved = Path(tmp) / f"peer{i}.xml"
                mujoco.mj_saveLastXML(str(saved), peer["model"])
            row["mujoco_import"] = compare_mjcf(src, peer)
            row["mujoco_import_ok"] = bool(peer.get("loads")) and not peer.get("warnings")
            ours_xml = Path(tmp) / f"mjcf{i}" / "robot.xml"
            result = convert([urdf], ours_xml)
            failed = {"loads": False, "error": "convert failed"}
            ours = mujoco_facts(ours_xml) if not result.status else failed
            row["modelkit_mjcf"] = compare_mjcf(src, ours)
            row["modelkit_mjcf_ok"] = bool(ours.get("loads")) and not ours.get("warnings")
            if probe is not None:
                peer_sdf = run_probe(probe, urdf)
                row["libsdformat"] = compare_sdf(src, peer_sdf)
                row["libsdformat_ok"] = not peer_sdf["errors"]
                ours_sdf = Path(tmp) / f"sdf{i}" / "robot.sdf"
                result = convert([urdf], ours_sdf)
                refused = {"errors": 1, "messages": ["convert failed"]}
                facts = run_probe(probe, ours_sdf) if not result.status else refused
                row["modelkit_sdf"] = compare_sdf(src, facts) if not result.status else ["convert failed"]
                row["modelkit_sdf_ok"] = not facts["errors"]
            rows.append(row)
    def count(key: str) -> int:
        return sum(1 for r in rows if r.get(key))
    def clean(key: str) -> int:
        return sum(1 for r in rows if all(item.endswith("(no loss)") for item in r.get(key, ["missing"])))
    print(f"{len(rows)} corpus URDFs")
    print(f"URDF→MJCF  MuJoCo import: loads warning-free {count('mujoco_import_ok')}, nothing lost "
          f"{clean('mujoco_import')}; modelkit: {count('modelkit_mjcf_ok')}, "
          f"nothing lost {clean('modelkit_mjcf')}")
    if probe is not None:
        print(f"URDF→SDF   libsdformat: loads {count('libsdformat_ok')}, "
              f"nothing lost {clean('libsdformat')}; "
              f"modelkit: {count('modelkit_sdf_ok')}, nothing lost {clean('modelkit_sdf')}")
    for r in rows:
        print(f"- {r['file']} ({r['links']} links)")
        for key in ("mujoco_import", "modelkit_mjcf", "libsdformat", "modelkit_sdf"):
            if key in r:
                print(f"    {key:14s} {'; '.join(r[key]) or 'nothing lost'}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("MUJOCO_GL", "egl")
    sys.exit(main())
