"""Start-up of `modelkit validate` per format, and `modelkit tree` on 1000 links, as ratios in one run.

    python bench/bench_startup.py [--repeat N] [--links N] [--json FILE]

Issue 9 §3 asks for `validate` on a small file of any format within 5x the bare interpreter
(`python -c pass`) and `tree` on a 1000-link URDF chain within 5x Debian's `check_urdf`. Every command
runs in a fresh process, all of them taking turns (run 1 of each, then run 2 of each ...) after one warm-up
each, with Python's bytecode cache on in a temporary PYTHONPYCACHEPREFIX (as after `pip install`; this
environment sets PYTHONDONTWRITEBYTECODE, which would make every run compile modelkit again). Medians;
each ratio is to a median of the same run. A benchmark reports and never fails (exit 0).
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from bench_tree import chain_urdf
from bench_validate import REPO, Job, cached_bytecode_env, modelkit_command, run_once

CORPUS = REPO.parent / "shared" / "corpus"
SMALL = {  # format → a small real file (repository samples, else the shared corpus)
    "URDF": CORPUS / "urdf_tutorial" / "urdf" / "01-myfirst.urdf",
    "xacro": REPO / "samples" / "smartcar" / "urdf" / "myrobot.urdf.xacro",
    "SDF": REPO / "samples" / "gazebo_unicycle" / "unicycle.sdf",
    ".body": CORPUS / "choreonoid" / "share" / "model" / "misc" / "pendulum.body",
    "MJCF": REPO / "tests" / "mjcf" / "pendulum.xml",
}
GOAL = 5.0


def _medians(jobs: dict[str, Job], repeat: int) -> dict[str, dict[str, float]]:
    for command, env in jobs.values():  # warm-up: bytecode cache and page cache
        run_once(command, env)
    walls: dict[str, list[float]] = {name: [] for name in jobs}
    for _ in range(repeat):
        for name, (command, env) in jobs.items():
            walls[name].append(run_once(command, env)[0])
    return {name: {"median_ms": 1000 * statistics.median(w), "min_ms": 1000 * min(w), "max_ms": 1000 * max(w)}
            for name, w in walls.items()}


def run(repeat: int, links: int, work: Path) -> dict[str, Any]:
    env = cached_bytecode_env(work / "pycache")
    py = sys.executable
    mk = modelkit_command()
    chain = work / f"chain{links}.urdf"
    chain.write_text(chain_urdf(links))
    jobs: dict[str, Job] = {
        "python -c pass": ([py, "-c", "pass"], env),
        "python -c 'import numpy'": ([py, "-c", "import numpy"], env),
        "python -c 'import modelkit.cli'": ([py, "-c", "import modelkit.cli"], env),
    }
    for fmt, path in SMALL.items():
        if path.is_file():
            jobs[f"validate {path.name} ({fmt})"] = ([*mk, "validate", str(path)], env)
    check_urdf = shutil.which("check_urdf")
    if check_urdf and SMALL["URDF"].is_file():
        jobs[f"check_urdf {SMALL['URDF'].name}"] = ([check_urdf, str(SMALL["URDF"])], env)
    if check_urdf:
        jobs[f"check_urdf chain of {links} links"] = ([check_urdf, str(chain)], env)
    jobs[f"tree chain of {links} links"] = ([*mk, "tree", str(chain)], env)
    jobs[f"validate chain of {links} links"] = ([*mk, "validate", str(chain)], env)
    figures = _medians(jobs, repeat)
    base = figures["python -c pass"]["median_ms"]
    for row in figures.values():
        row["x_interpreter"] = row["median_ms"] / base
    reference = figures.get(f"check_urdf chain of {links} links")
    if reference:
        for name in (f"tree chain of {links} links", f"validate chain of {links} links"):
            figures[name]["x_check_urdf"] = figures[name]["median_ms"] / reference["median_ms"]
    return {"date": datetime.now(UTC).isoformat(timespec="seconds"), "python": sys.version.split()[0],
            "repeat": repeat, "links": links, "figures": figures}


def report(results: dict[str, Any]) -> str:
    lines = [f"fresh processes, {results['repeat']} runs each taking turns, medians (ms); goal <= {GOAL:g}x",
             "", f"{'command':<48} {'median':>8} {'min':>7} {'max':>7} {'x python':>9} {'x check_urdf':>13}"]
    for name, row in results["figures"].items():
        vs_check = f"{row['x_check_urdf']:.1f}" if "x_check_urdf" in row else ""
        lines.append(f"{name:<48} {row['median_ms']:8.1f} {row['min_ms']:7.1f} {row['max_ms']:7.1f} "
                     f"{row['x_interpreter']:9.2f} {vs_check:>13}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--links", type=int, default=1000)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="mk-startup-") as tmp:
        results = run(args.repeat, args.links, Path(tmp))
    print(report(results))
    if args.json:
        args.json.write_text(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
