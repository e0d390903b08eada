"""`modelkit verify` speed: the whole command with its report, layer 4's harness overhead, many models
at once, each engine's load, the replay's overhead.

    python bench/bench_verify.py [--repeat N] [--many-repeat M] [--no-many] [--json FILE] [--source MODEL]
                                 [--as-is] [--only-command]

(a) `modelkit verify MODEL -o DIR` in a fresh process (N runs after a warm-up, taking turns): all four
    layers and the report (report.json, report.html with its plots and pictures), with every engine
    (the default) and with the default install's engines (MuJoCo, PyBullet, Pinocchio), and both
    without the replay (`--no-replay`: layers 1-3a + 4). Median/min/max wall time, the median CPU
    time (user + system of the command and every child it waited for), and the median of each phase
    as the command prints it ("wall time: convert …, load …, layer 1 …, layer 4 …"). With Python's
    bytecode cache on in a temporary PYTHONPYCACHEPREFIX (as after a pip install), unless --as-is.
    The issue's target: the full verify of the tutorial pan-tilt robot under 5 s on a 2-core machine
    (part 1's: layers 1-3 under 3 s). The machine's load average is printed with the figures.
(b) Layer 4's harness overhead (`modelkit.verify.bench.bench`) per profile of the default scenario:
    simulated seconds per wall second of each engine's driver inside verify (controllers, samples)
    against a bare stepping loop of the same engine on the same floating-base variant (target ≥ 0.8),
    and a minimal hand-written closed loop (read, control, step) with the same controllers.
(c) The speed-up of `-j 2` over `-j 1` on the four tutorial robots (`bench_verify_many.py`, M runs
    each after a warm-up, the same summary.json required).
(d) Each engine's share of "load": a fresh process per engine that imports the adapter and loads
    the written file (N runs): import and load seconds, medians. "load" includes what an adapter
    imports lazily (yourdfpy and trimesh) and PyBullet's child process (started, pybullet imported).
(e) The replay's overhead (`modelkit.verify.layers.replay.overhead`): simulated seconds per wall second
    of each engine's replay against a bare stepping loop of the same engine on the same model
    (target ≥ 0.8), and for PyBullet the minimal closed loop (read the states, send torques, step)
    that any replay needs.
Reports, never fails: exit 0 whatever the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from modelkit.convert.options import WriteOptions

# The engines' files as verify writes them for layers 1-3: the root is the base (no URDF world link,
# the engines weld it), the sensors on their links (their link sets are compared with the source's),
# motors on joints the source does not actuate (the passive robot), frames as bodies (link sets compared).
ENGINE_FILES = WriteOptions(urdf_world_link=False, urdf_sensor_links=False, actuators="motor",
                            frame_sites=False)

REPO = Path(__file__).resolve().parents[1]
PANTILT = REPO / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model" / "mobile_robot_pantilt.body"
MODELKIT = Path(sys.executable).with_name("modelkit")
DEFAULT_INSTALL = "mujoco,pybullet,pinocchio"
FILES = {"mjcf": "x.xml", "urdf": "x.urdf", "sdf": "x.sdf"}  # the written file each input kind reads

LOAD_ONE = """
import json, sys, time
from pathlib import Path
engine, folder, root = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
t0 = time.perf_counter()
import modelkit.verify.api as api
t1 = time.perf_counter()
load = api._resolve(api.ENGINES[engine])
t2 = time.perf_counter()
if api.INPUTS[engine] == "robot":
    import modelkit
    model_in = api.welded_copy(modelkit.load(folder / "source.body"))[0]
else:
    model_in = folder / {files}[api.INPUTS[engine]]
t3 = time.perf_counter()
model = load(model_in, {{"link": {{}}, "joint": {{}}}}, root=root)
t4 = time.perf_counter()
model.close()
print(json.dumps({{"import": t2 - t1, "load": t4 - t3}}))
"""


def cached_bytecode_env(prefix: Path) -> dict[str, str]:
    """The environment with Python's bytecode cache on, kept under ``prefix`` (PYTHONPYCACHEPREFIX,
    nothing written into the source tree): what a user's ``pip install`` gives. This development
    environment sets PYTHONDONTWRITEBYTECODE and modelkit is an editable install without
    ``__pycache__``, so as is every process of a verify run (the command, PyBullet's children, the
    plotting and picture processes) compiles modelkit's sources again."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = str(prefix)
    return env


def fresh(cmd: list[str], env: dict[str, str] | None = None) -> tuple[float, str, float]:
    """Wall seconds, stdout, and CPU seconds (user + system) of the command and every child process
    it waited for (PyBullet's, the plotting and picture processes)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, done.stdout, cpu


def phases(stdout: str) -> dict[str, float]:
    """The command's own split: 'wall time: convert 0.30 s, load 0.71 s, layer 1 0.01 s, ...'."""
    line = next((ln for ln in stdout.splitlines() if ln.startswith("wall time:")), "")
    return {name.strip(): float(value) for name, value in re.findall(r"([a-z][a-z0-9 ]*?) ([0-9.]+) s(?:,|$)",
                                                                      line[10:].strip())}


def summary(values: list[float]) -> dict[str, float]:
    return {"median_s": statistics.median(values), "min_s": min(values), "max_s": max(values)}


def bench_command(source: Path, repeat: int, env: dict[str, str] | None = None) -> dict[str, Any]:
    jobs = {
        "every engine": [],
        "every engine, --no-replay": ["--no-replay"],
        f"{DEFAULT_INSTALL}": ["--engines", DEFAULT_INSTALL],
        f"{DEFAULT_INSTALL}, --no-replay": ["--engines", DEFAULT_INSTALL, "--no-replay"],
    }
    walls: dict[str, list[float]] = {k: [] for k in jobs}
    cpus: dict[str, list[float]] = {k: [] for k in jobs}
    split: dict[str, list[dict[str, float]]] = {k: [] for k in jobs}
    codes: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        cmds = {name: [str(MODELKIT), "verify", str(source), "-o", str(Path(tmp) / f"r{i}"), *extra]
                for i, (name, extra) in enumerate(jobs.items())}
        for cmd in cmds.values():
            fresh(cmd, env)  # warm-up (and the bytecode cache)
        for _ in range(repeat):
            for name, cmd in cmds.items():
                wall, out, cpu = fresh(cmd, env)
                walls[name].append(wall)
                cpus[name].append(cpu)
                split[name].append(phases(out))
                codes[name] = next((ln for ln in out.splitlines() if ln.startswith(("PASS", "FAIL"))), "?")
    result: dict[str, Any] = {}
    for name in jobs:
        keys = sorted({k for s in split[name] for k in s}, key=lambda k: list(split[name][0]).index(k)
                      if split[name] and k in split[name][0] else 99)
        result[name] = {**summary(walls[name]), "verdict": codes[name],
                        "cpu_median_s": statistics.median(cpus[name]),
                        "phases_median_s": {k: statistics.median(s.get(k, 0.0) for s in split[name])
                                            for k in keys}}
    return result


def bench_loads(source: Path, repeat: int) -> dict[str, Any]:
    from modelkit import load
    from modelkit.convert import write
    from modelkit.verify.api import DEFAULT_ENGINES, welded_copy

    robot, _ = welded_copy(load(source))
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "source.body").write_bytes(source.read_bytes())
        for name in ("x.xml", "x.urdf", "x.sdf"):
            write(robot, folder / name, options=ENGINE_FILES, force=True)
        script = LOAD_ONE.format(files=json.dumps(FILES))
        for engine in DEFAULT_ENGINES:
            samples: list[dict[str, float]] = []
            for _ in range(repeat):
                done = subprocess.run([sys.executable, "-c", script, engine, str(folder), str(robot.root)],
                                      capture_output=True, text=True, check=False, cwd=source.parent)
                if done.returncode != 0:
                    out[engine] = {"error": done.stderr.strip().splitlines()[-1:]}
                    break
                samples.append(json.loads(done.stdout.strip().splitlines()[-1]))
            if samples:
                out[engine] = {k: statistics.median(s[k] for s in samples) for k in ("import", "load")}
    return out


def bench_replay(source: Path, repeat: int) -> dict[str, Any]:
    from modelkit import load
    from modelkit.convert import write
    from modelkit.convert.notes import renames
    from modelkit.verify.api import REPLAY_DT, REPLAY_SECONDS, welded_copy
    from modelkit.verify.engines.mujoco import simulator as mujoco_simulator
    from modelkit.verify.engines.pybullet import simulator as pybullet_simulator
    from modelkit.verify.layers.replay import default_law, overhead

    robot, _ = welded_copy(load(source))
    with tempfile.TemporaryDirectory() as tmp:
        maps = {}
        for name in ("x.xml", "x.urdf"):
            notes = write(robot, Path(tmp) / name, options=ENGINE_FILES, force=True)
            maps[name] = {"link": renames(notes, "link"), "joint": renames(notes, "joint")}
        root = str(robot.root)
        sims: list[Any] = [mujoco_simulator(Path(tmp) / "x.xml", maps["x.xml"], root=root, dt=REPLAY_DT),
                pybullet_simulator(Path(tmp) / "x.urdf", maps["x.urdf"], root=root, dt=REPLAY_DT)]
        try:
            return overhead(sims, default_law(robot), REPLAY_SECONDS, REPLAY_DT, repeats=repeat)
        finally:
            for sim in sims:
                sim.close()


def bench_layer4(source: Path, repeat: int) -> dict[str, Any]:
    """(b): ``modelkit.verify.bench.bench`` on every profile of the default scenario, ``repeat`` times;
    medians."""
    from modelkit import load
    from modelkit.verify.bench import bench
    from modelkit.verify.drive import scenario as scenarios
    from modelkit.verify.drive import vehicle
    from modelkit.verify.layers.layer4 import floating

    robot = floating(load(source))
    drive = vehicle.find_drive(robot, scenarios.default_scenario())
    scenario = scenarios.default_scenario(drive.kind, bool(drive.pan or drive.tilt))
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for profile in scenario.profiles:
            runs = [bench(robot, drive, scenario, Path(tmp), profile=profile) for _ in range(repeat)]
            out[profile.name] = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
    return out


def bench_many(repeat: int) -> dict[str, Any]:
    """(c): ``bench_verify_many.py`` in a child process (its own JSON)."""
    with tempfile.TemporaryDirectory() as tmp:
        target = Path(tmp) / "many.json"
        done = subprocess.run([sys.executable, str(Path(__file__).with_name("bench_verify_many.py")),
                               "--repeat", str(repeat), "--json", str(target)],
                              capture_output=True, text=True, check=False)
        if not target.exists():
            return {"error": (done.stderr or done.stdout).strip().splitlines()[-1:]}
        result: dict[str, Any] = json.loads(target.read_text())
        return result


def load_average() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "?"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--source", type=Path, default=PANTILT)
    parser.add_argument("--many-repeat", type=int, default=3, help="runs of each -j for (c)")
    parser.add_argument("--no-many", action="store_true", help="leave (c) out")
    parser.add_argument("--as-is", action="store_true",
                        help="(a) in the environment as it is (no bytecode cache when it sets "
                             "PYTHONDONTWRITEBYTECODE), not with a bytecode cache as after a pip install")
    parser.add_argument("--only-command", action="store_true", help="(a) only")
    args = parser.parse_args()
    source = args.source.resolve()
    figures: dict[str, Any] = {"source": source.name, "repeat": args.repeat,
                               "cores": len(os.sched_getaffinity(0)), "load_average_before": load_average(),
                               "bytecode": "as is" if args.as_is else "cached (PYTHONPYCACHEPREFIX)"}
    with tempfile.TemporaryDirectory(prefix="modelkit-bench-pycache-") as prefix:
        figures["command"] = bench_command(source, args.repeat,
                                           None if args.as_is else cached_bytecode_env(Path(prefix)))
    figures["load_average_after_command"] = load_average()
    print(f"(a) modelkit verify {source.name} -o DIR (all four layers and the report), fresh process, "
          f"{args.repeat} runs after a warm-up, bytecode {figures['bytecode']}; {figures['cores']} cores, "
          f"load average {figures['load_average_before']} before, {figures['load_average_after_command']} "
          "after; target: under 5 s")
    for name, row in figures["command"].items():
        split = ", ".join(f"{k} {v:.2f}" for k, v in row["phases_median_s"].items())
        print(f"  {name:38s} median {row['median_s']:.2f} s  (min {row['min_s']:.2f}, max {row['max_s']:.2f})"
              f"  CPU {row['cpu_median_s']:.2f} s  {row['verdict'][:40]}\n      phases (median s): {split}")
    if args.only_command:
        if args.json is not None:
            args.json.write_text(json.dumps(figures, indent=2, sort_keys=True) + "\n")
        return 0
    figures["layer4"] = bench_layer4(source, args.repeat)
    print("(b) layer 4 harness overhead: simulated s per wall s inside verify's drivers vs a bare stepping "
          "loop of the same engine on the same model (target ratio >= 0.8; medians)")
    for profile, row in figures["layer4"].items():
        print(f"  {profile:9s} " + "   ".join(
            f"{e} {row[f'{e}_realtime']:.0f}x vs bare {row[f'{e}_bare_realtime']:.0f}x: "
            f"ratio {row[f'{e}_ratio']:.2f} (minimal closed loop {row[f'{e}_closed_ratio']:.2f}x slower "
            "than the harness)" for e in ("mujoco", "pybullet")))
    if not args.no_many:
        figures["many"] = bench_many(args.many_repeat)
        many = figures["many"]
        print(f"(c) modelkit verify on the four tutorial robots, -j 1 vs -j 2 ({args.many_repeat} runs each)")
        if "error" in many:
            print(f"  error {many['error']}")
        else:
            s1, s2 = many["seconds"]["-j 1"], many["seconds"]["-j 2"]
            print(f"  -j 1 median {s1['median']:.2f} s, -j 2 median {s2['median']:.2f} s: speed-up "
                  f"{many['speedup_j2_over_j1']:.2f}x on {many['cores']} cores; same summary.json: "
                  f"{many['same_summary']}")
    figures["loads"] = bench_loads(source, args.repeat)
    print("(d) each engine in a fresh process: import and load of the written file (median s)")
    for engine, row in figures["loads"].items():
        print(f"  {engine:10s} " + ("error " + str(row["error"]) if "error" in row
                                    else f"import {row['import']:.3f}  load {row['load']:.3f}"))
    figures["replay"] = bench_replay(source, args.repeat)
    print("(e) replay overhead: simulated s per wall s (best of runs), replay vs a bare stepping loop")
    for engine, row in figures["replay"].items():
        line = (f"  {engine:9s} replay {row['replay_call_rate']:.0f}x (loop {row['replay_loop_rate']:.0f}x), "
                f"bare {row['bare_rate']:.0f}x: ratio {row['ratio_call']:.2f} (loop {row['ratio_loop']:.2f})")
        if "minimal_closed_loop_rate" in row:
            line += (f"; minimal closed loop {row['minimal_closed_loop_rate']:.0f}x = "
                     f"{row['minimal_closed_loop_rate'] / row['bare_rate']:.2f} of bare "
                     "(the best any closed-loop replay can do)")
        print(line)
    figures["load_average_after"] = load_average()
    if args.json is not None:
        args.json.write_text(json.dumps(figures, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
