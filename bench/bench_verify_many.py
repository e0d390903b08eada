"""`modelkit verify` on many models: the speed-up of -j 2 over -j 1 on the four tutorial robots.

    python bench/bench_verify_many.py [--repeat N] [--json FILE] [--no-replay]

Runs `modelkit verify primitive pantilt sensors tracks -o TMP -j J` in a fresh process for J = 1 and
J = 2, N times each after a warm-up, taking turns; prints the median/min/max wall time of each, the
speed-up (median -j 1 / median -j 2) and the machine's core count, and checks that both give the
same summary.json (the same verdicts and numbers whatever -j). The defaults of verify are used
(every engine, layers 1-3 with the replay, and layer 4 once it is there).
Reports, never fails: exit 0 whatever the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
MODELS = [REPO / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model" / f"mobile_robot_{n}.body"
          for n in ("primitive", "pantilt", "sensors", "tracks")]
MODELKIT = Path(sys.executable).with_name("modelkit")


def run(jobs: int, out: Path, extra: list[str]) -> float:
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    t0 = time.perf_counter()
    command = [str(MODELKIT), "verify", *map(str, MODELS), "-j", str(jobs), "-o", str(out), *extra]
    done = subprocess.run(command, capture_output=True, text=True, cwd=REPO, env=env, check=False)
    seconds = time.perf_counter() - t0
    if done.returncode not in (0, 1):
        print(done.stdout + done.stderr, file=sys.stderr)
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-replay", action="store_true", help="pass --no-replay to verify")
    args = parser.parse_args()
    extra = ["--no-replay"] if args.no_replay else []
    times: dict[int, list[float]] = {1: [], 2: []}
    summaries: dict[int, bytes] = {}
    with tempfile.TemporaryDirectory(prefix="bench-verify-many-") as tmp:
        for jobs in (1, 2):  # warm-up (file cache, compiled bytecode)
            run(jobs, Path(tmp) / f"warm{jobs}", extra)
        for i in range(args.repeat):
            for jobs in (1, 2):
                out = Path(tmp) / f"j{jobs}-{i}"
                times[jobs].append(run(jobs, out, extra))
                summaries[jobs] = (out / "summary.json").read_bytes()
    medians = {j: statistics.median(t) for j, t in times.items()}
    result: dict[str, Any] = {
        "models": [m.name for m in MODELS],
        "cores": len(os.sched_getaffinity(0)),
        "replay": not args.no_replay,
        "repeat": args.repeat,
        "seconds": {f"-j {j}": {"median": medians[j], "min": min(t), "max": max(t)}
                    for j, t in times.items()},
        "speedup_j2_over_j1": medians[1] / medians[2],
        "same_summary": summaries[1] == summaries[2],
    }
    for j, t in times.items():
        print(f"-j {j}: median {medians[j]:.2f} s (min {min(t):.2f}, max {max(t):.2f}) "
              f"for {len(MODELS)} models")
    print(f"speed-up of -j 2 over -j 1: {result['speedup_j2_over_j1']:.2f}x on {result['cores']} cores; "
          f"same summary.json: {result['same_summary']}")
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
