"""Conversion speed: `modelkit convert` per corpus model and target, fresh process and in-process.

    python bench/bench_convert.py [--repeat N] [--json FILE] [--corpus DIR]

(a) The tutorial sensor robot to every target, fresh processes taking turns with
    `modelkit validate` on the same file (N runs each after a warm-up): the targets are
    under 1 s and never more than twice validate's time.
(b) Every model of the conformance set (samples and corpus: .body, URDF, xacro, SDF, MJCF) to
    every target, in-process: read+validate time and write time per model, median per target.
Reports, never fails: exit 0 whatever the figures.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
DEFAULT_CORPUS = REPO.parent / "shared" / "corpus"
SENSORS = REPO / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model" / "mobile_robot_sensors.body"
TARGETS = {"urdf": ".urdf", "sdf": ".sdf", "mjcf": ".xml", "body": ".body"}
MODELKIT = Path(sys.executable).with_name("modelkit")


def conformance_files(corpus: Path) -> list[Path]:
    found: list[Path] = []
    for root in (REPO / "samples", corpus):
        for pattern in ("*.body", "*.urdf", "*.xacro", "*.sdf", "*.world", "*.xml"):
            found.extend(root.rglob(pattern))
    return sorted(p for p in set(found) if p.is_file())


def fresh(cmd: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    return time.perf_counter() - start


def bench_fresh(repeat: int) -> dict[str, Any]:
    jobs: dict[str, list[str]] = {"validate": [str(MODELKIT), "validate", str(SENSORS)]}
    with tempfile.TemporaryDirectory() as tmp:
        for name, suffix in TARGETS.items():
            jobs[f"convert {name}"] = [str(MODELKIT), "convert", str(SENSORS), "-o",
                                       str(Path(tmp) / f"r{suffix}"), "--force", "-q"]
        times: dict[str, list[float]] = {k: [] for k in jobs}
        for cmd in jobs.values():
            fresh(cmd)  # warm-up
        for _ in range(repeat):
            for name, cmd in jobs.items():
                times[name].append(fresh(cmd))
    validate = statistics.median(times["validate"])
    return {
        name: {"median_s": statistics.median(t), "min_s": min(t), "max_s": max(t),
               "ratio_to_validate": statistics.median(t) / validate}
        for name, t in times.items()
    }


def bench_inprocess(corpus: Path) -> dict[str, Any]:
    from modelkit.api import validate
    from modelkit.convert.api import CONVERTIBLE_ERRORS, render_model
    from modelkit.convert.options import WriteOptions
    from modelkit.convert.output import OutputPlan

    rows: list[dict[str, Any]] = []
    for path in conformance_files(corpus):
        start = time.perf_counter()
        checked = validate(path)
        read_s = time.perf_counter() - start
        robots = [r for r in checked.robots if r.root is not None]
        if not robots or any(d.code not in CONVERTIBLE_ERRORS for d in checked.errors):
            continue
        row: dict[str, Any] = {"file": str(path.relative_to(path.parents[2])), "read_s": read_s}
        for name, suffix in TARGETS.items():
            start = time.perf_counter()
            try:
                plan = OutputPlan(Path(tempfile.gettempdir()))
                for robot in robots:
                    render_model(robot, name, plan, f"x{suffix}", WriteOptions())
                row[f"{name}_s"] = time.perf_counter() - start
            except Exception as exc:  # a benchmark reports, never fails
                row[f"{name}_s"] = None
                row[f"{name}_error"] = f"{type(exc).__name__}: {exc}"
        rows.append(row)
    summary = {}
    for name in TARGETS:
        values = [r[f"{name}_s"] for r in rows if r.get(f"{name}_s") is not None]
        summary[name] = {
            "models": len(values),
            "failed": sum(1 for r in rows if r.get(f"{name}_s") is None),
            "median_write_s": statistics.median(values) if values else None,
            "max_write_s": max(values) if values else None,
        }
    return {"rows": rows, "summary": summary,
            "median_read_s": statistics.median(r["read_s"] for r in rows) if rows else None}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=10)
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    fresh_figures = bench_fresh(args.repeat)
    print(f"(a) fresh process, {SENSORS.name}, {args.repeat} runs each (median / min / max s, × validate)")
    for name, f in fresh_figures.items():
        print(f"  {name:16s} {f['median_s']:.3f} / {f['min_s']:.3f} / {f['max_s']:.3f}  "
              f"×{f['ratio_to_validate']:.2f}")
    inproc = bench_inprocess(args.corpus)
    print(f"(b) in-process over {len(inproc['rows'])} models; median read+validate "
          f"{inproc['median_read_s']:.3f} s")
    for name, s in inproc["summary"].items():
        med = s["median_write_s"]
        mx = s["max_write_s"]
        print(f"  {name:5s} models {s['models']:3d} failed {s['failed']:2d}  median write "
              f"{med if med is None else round(med, 4)} s  max {mx if mx is None else round(mx, 3)} s")
    slow = sorted(inproc["rows"], key=lambda r: -max(r.get(f"{n}_s") or 0 for n in TARGETS))[:5]
    for r in slow:
        print("  slowest:", r["file"], {n: round(r.get(f"{n}_s") or 0, 3) for n in TARGETS})
    if args.json:
        args.json.write_text(json.dumps({"fresh": fresh_figures, "inprocess": inproc}, indent=2,
                                        sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
