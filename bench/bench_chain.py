"""How `modelkit verify`, `convert` and `validate` grow with a serial chain's length (issue 18 §2).

    python bench/bench_chain.py [--verify 100,200,400,1000] [--convert 1000,10000] [--shapes 5000,10000]
                                [--json FILE]

Every run is a fresh `modelkit` process on a chain generated in a temporary folder
(``tests/chain_support.py``: every link with an inertial and a box visual; revolute and continuous
joints about y, alternately limited). For each run: the wall time, the peak RSS of the largest process
(``wait4``), and the peak of the whole process tree's RSS summed (sampled from ``/proc`` every 50 ms:
verify's PyBullet worker and picture processes count). verify runs with ``-j 1 -o DIR`` (its report and
pictures written), every default engine; its own per-phase times ("wall time: ...") are kept.

Two more shapes of URDF chain, for ``validate`` and ``convert`` to MJCF (``--shapes``): one lying on
the floor (each joint 0.1 m along x: every link touches the ground, so convert's base decision looks at
each), and one whose every joint mimics the one before (validate's mimic-loop rule follows each chain).

The columns per link (ms/link, MB/link) are flat when the growth is linear. A benchmark reports, it
never fails: exit 0 whatever the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests import chain_support  # noqa: E402

MODELKIT = [sys.executable, "-c", "import sys; from modelkit.cli import main; sys.argv[0] = 'modelkit'; "
            "sys.exit(main())"]


def _tree_rss(root: int) -> int:
    """The summed RSS (bytes) of ``root`` and its descendants, from /proc."""
    parents: dict[int, int] = {}
    rss: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            parents[int(entry)] = int(fields[1])
            rss[int(entry)] = int(fields[21]) * os.sysconf("SC_PAGE_SIZE")
        except (OSError, IndexError, ValueError):
            continue
    total = 0
    for pid in rss:
        p = pid
        while p not in (0, 1, root) and p in parents:
            p = parents[p]
        if p == root:
            total += rss[pid]
    return total


def run(args: list[str], cwd: Path) -> dict[str, Any]:
    """One fresh process: wall time, exit code, peak RSS of the largest process and of the tree."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    start = time.perf_counter()
    proc = subprocess.Popen([*MODELKIT, *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    peak = 0
    done = threading.Event()

    def sample() -> None:
        nonlocal peak
        while not done.is_set():
            peak = max(peak, _tree_rss(proc.pid))
            done.wait(0.05)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    output = proc.stdout.read() if proc.stdout else b""
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    done.set()
    sampler.join()
    proc.returncode = os.waitstatus_to_exitcode(status)
    text = output.decode("utf-8", "replace")
    found = re.search(r"wall time: (.*)", text)
    phases = {m.group(1).strip(): float(m.group(2))
              for m in re.finditer(r"([a-z0-9 ]+?) ([0-9.]+) s(?:,|$)", found.group(1))} if found else {}
    summary = [line for line in text.splitlines() if line.startswith(("PASS", "FAIL:", "wrote"))]
    return {"seconds": round(wall, 2), "exit": proc.returncode,
            "max_rss_mb": round(usage.ru_maxrss / 1024, 1), "tree_rss_mb": round(peak / 2**20, 1),
            "phases": phases, "summary": summary[-1:], "traceback": "Traceback" in text}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--verify", default="100,200,400,1000", help="chain lengths for verify ('' for none)")
    parser.add_argument("--convert", default="1000,10000", help="chain lengths for convert ('' for none)")
    parser.add_argument("--inputs", default="urdf,body", help="input formats for convert")
    parser.add_argument("--shapes", default="5000,10000",
                        help="lengths of the lying and mimic chains (validate, convert to MJCF; '' for none)")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args()
    sizes = [int(x) for x in args.verify.split(",") if x]
    converts = [int(x) for x in args.convert.split(",") if x]
    shaped = [int(x) for x in args.shapes.split(",") if x]
    machine = {"python": platform.python_version(), "cpus": os.cpu_count(), "load": os.getloadavg()}
    results: dict[str, Any] = {"machine": machine, "verify": {}, "convert": {}, "shapes": {}}
    with tempfile.TemporaryDirectory(prefix="bench-chain-") as tmp:
        folder = Path(tmp)
        print(f"{'command':<24}{'links':>6}{'s':>9}{'ms/link':>9}{'max MB':>9}{'tree MB':>9}{'MB/link':>9}"
              "  phases")
        for n in sizes:
            path = chain_support.write(folder, "urdf", n)
            r = run(["verify", str(path), "-o", str(folder / f"verify{n}"), "-j", "1"], folder)
            results["verify"][n] = r
            phases = ", ".join(f"{k} {v:g}" for k, v in r["phases"].items())
            print(f"{'verify (urdf)':<24}{n:>6}{r['seconds']:>9.2f}{1000 * r['seconds'] / n:>9.1f}"
                  f"{r['max_rss_mb']:>9.0f}{r['tree_rss_mb']:>9.0f}{r['tree_rss_mb'] / n:>9.2f}  {phases} "
                  f"exit {r['exit']}{' TRACEBACK' if r['traceback'] else ''}", flush=True)
        for fmt in [x for x in args.inputs.split(",") if x]:
            for n in converts:
                path = chain_support.write(folder, fmt, n)
                for target in ("urdf", "sdf", "mjcf", "body"):
                    out = folder / f"out_{fmt}_{n}_{target}"
                    r = run(["convert", "-q", str(path), "-o", str(out), "--to", target], folder)
                    results["convert"][f"{fmt}->{target}:{n}"] = r
                    print(f"{'convert ' + fmt + '->' + target:<24}{n:>6}{r['seconds']:>9.2f}"
                          f"{1000 * r['seconds'] / n:>9.2f}{r['max_rss_mb']:>9.0f}{r['tree_rss_mb']:>9.0f}"
                          f"{r['tree_rss_mb'] / n:>9.3f}  exit {r['exit']}"
                          f"{' TRACEBACK' if r['traceback'] else ''}", flush=True)
        for shape in ("lying", "mimic"):  # convert's base decision; validate's mimic loops (issue 18 §2)
            for n in shaped:
                path = chain_support.write(folder, "urdf", n, shape=shape)
                for command in ("validate", "convert"):
                    out = ["-q", "-o", str(folder / f"out_{shape}_{n}"), "--to", "mjcf"]
                    r = run([command, str(path), *(out if command == "convert" else [])], folder)
                    results["shapes"][f"{command} {shape}:{n}"] = r
                    label = f"{command} {shape}"
                    print(f"{label:<24}{n:>6}{r['seconds']:>9.2f}{1000 * r['seconds'] / n:>9.2f}"
                          f"{r['max_rss_mb']:>9.0f}{r['tree_rss_mb']:>9.0f}{r['tree_rss_mb'] / n:>9.3f}  "
                          f"exit {r['exit']}{' TRACEBACK' if r['traceback'] else ''}", flush=True)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
