"""`modelkit validate` of real robots with large meshes: without the mesh-check cache, on its first
run (cold, the cache filled), and on the next runs (warm, the outcomes read back).

    python bench/bench_mesh_cache.py [--repeat N] [--json FILE] [--source DIR] [FILE ...]

Default files: example-robot-data's slowest to validate (tens of MB of COLLADA text, many meshes).
Each figure is the median wall time of N fresh processes (after one warm-up of the interpreter's
bytecode), taking turns; "cold" empties the cache before each run. The printed output of the three
modes must be the same bytes (checked, reported). Reports, never fails: exit 0 whatever the figures.
``--source DIR`` runs the modelkit package found in DIR (a worktree of another commit) instead of the
installed one, so two commits can be measured the same way, taking turns.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

MODELKIT = Path(sys.executable).with_name("modelkit")


def robots() -> Path:
    """example-robot-data's robots folder, as its PyPI wheel installs it (under cmeel.prefix)."""
    import sysconfig

    for key in ("purelib", "platlib", "data"):
        folder = Path(sysconfig.get_paths()[key]) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if folder.is_dir():
            return folder
    raise SystemExit("example-robot-data is not installed (pip install example-robot-data)")


DEFAULT = ("b1_description/urdf/b1-z1.urdf", "b1_description/urdf/b1.urdf", "go1_description/urdf/go1.urdf",
           "romeo_description/urdf/romeo.urdf", "alex_description/urdf/alex_psyonic_hands.urdf")


def command(source: Path | None) -> list[str]:
    """The modelkit command: the installed one, or the package in ``source`` ahead of it on sys.path."""
    if source is None:
        return [str(MODELKIT)]
    code = (f"import sys; sys.path.insert(0, {str(source.resolve())!r}); import modelkit.cli as cli; "
            f"assert cli.__file__.startswith({str(source.resolve())!r}), cli.__file__; "
            "sys.argv[0] = 'modelkit'; cli.main()")
    return [sys.executable, "-c", code]


def run(path: Path, cache: str, env: dict[str, str], modelkit: list[str]) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run([*modelkit, "validate", str(path)], capture_output=True, text=True, check=False,
                          env={**env, "MODELKIT_CACHE_DIR": cache})
    wall = time.perf_counter() - start
    return wall, hashlib.sha256((done.stdout + str(done.returncode)).encode()).hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--source", type=Path, help="a folder holding another commit's modelkit package")
    args = parser.parse_args()
    modelkit = command(args.source)
    root = robots()
    files = args.files or [root / f for f in DEFAULT]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.setdefault("ROS_PACKAGE_PATH", str(root))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        env["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "pyc")
        cache = str(Path(tmp) / "cache")
        for path in files:
            run(path, "off", env, modelkit)  # bytecode compiled once
            times: dict[str, list[float]] = {"off": [], "cold": [], "warm": []}
            outputs: set[str] = set()
            for _ in range(args.repeat):
                wall, out = run(path, "off", env, modelkit)
                times["off"].append(wall)
                outputs.add(out)
                shutil.rmtree(cache, ignore_errors=True)
                wall, out = run(path, cache, env, modelkit)
                times["cold"].append(wall)
                outputs.add(out)
                wall, out = run(path, cache, env, modelkit)
                times["warm"].append(wall)
                outputs.add(out)
            row = {"file": path.name, **{f"{k}_median_s": statistics.median(v) for k, v in times.items()},
                   "same_output": len(outputs) == 1}
            rows.append(row)
            print(f"{path.name:32s} off {row['off_median_s']:.2f} s  cold {row['cold_median_s']:.2f} s  "
                  f"warm {row['warm_median_s']:.2f} s  same output: {row['same_output']}")
    print(f"load average {os.getloadavg()[0]:.2f}")
    if args.json:
        args.json.write_text(json.dumps({"date": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "repeat": args.repeat,
                                         "load_average": os.getloadavg(), "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
