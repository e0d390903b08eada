"""`modelkit tree` and `modelkit validate` against Debian's `check_urdf`, in the same run.

    python bench/bench_tree.py [--repeat N] [--links N] [--corpus DIR] [--json FILE]

Inputs: the largest URDF under the corpus, and a generated chain of N links (default 1000; each
link with an inertial, a box visual and a cylinder collision, joints alternating revolute and
continuous). For each input, fresh processes take turns: `check_urdf FILE`, `modelkit tree FILE`,
`modelkit validate FILE`. Reported: wall and CPU min/median/max, the ratio of modelkit's medians
to check_urdf's, and whether the two tree reports are byte-identical (they must be).

A benchmark reports, it never fails: exit 0 whatever the figures (2 for bad usage or a missing
check_urdf).
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import sys
import tempfile
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from bench_validate import REPO, cached_bytecode_env, cpu_model, modelkit_command, timed_many

DEFAULT_CORPUS = REPO.parent / "shared" / "corpus"


def chain_urdf(links: int) -> str:
    """A serial chain of ``links`` links, every one with full mass properties and geometry."""
    out = ['<?xml version="1.0"?>', '<robot name="chain">']
    for i in range(links):
        out.append(
            f'  <link name="link{i}"><inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>'
            '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial>'
            '<visual><geometry><box size="0.05 0.05 0.1"/></geometry></visual>'
            '<collision><geometry><cylinder radius="0.03" length="0.1"/></geometry></collision></link>'
        )
        if i:
            kind = "revolute" if i % 2 else "continuous"
            limit = '<limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>' if kind == "revolute" else ""
            out.append(
                f'  <joint name="joint{i:04d}" type="{kind}"><parent link="link{i - 1}"/>'
                f'<child link="link{i}"/><origin xyz="0 0 0.1" rpy="0 0 0.1"/><axis xyz="0 1 0"/>'
                f"{limit}</joint>"
            )
    out.append("</robot>")
    return "\n".join(out) + "\n"


def largest_urdf(corpus: Path) -> Path | None:
    files = sorted(corpus.rglob("*.urdf"), key=lambda p: (-p.stat().st_size, str(p)))
    return files[0] if files else None


def same_tree(check_urdf: str, modelkit: list[str], path: Path, env: dict[str, str]) -> dict[str, Any]:
    """Whether `modelkit tree` prints what `check_urdf` prints (bytes of stdout)."""
    theirs = subprocess.run([check_urdf, str(path)], capture_output=True, check=False)
    ours = subprocess.run([*modelkit, "tree", str(path)], capture_output=True, check=False, env=env)
    return {
        "identical": theirs.stdout == ours.stdout and theirs.returncode == ours.returncode == 0,
        "check_urdf_bytes": len(theirs.stdout),
        "modelkit_bytes": len(ours.stdout),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--links", type=int, default=1000)
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    check_urdf = shutil.which("check_urdf")
    if check_urdf is None:
        print("check_urdf not found (apt-get install liburdfdom-tools)", file=sys.stderr)
        return 2
    modelkit = modelkit_command()
    report: dict[str, Any] = {
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": {
            "cpu_model": cpu_model(),
            "python": platform.python_version(),
            "platform": platform.platform(),
        },
        "repeat": args.repeat,
        "inputs": {},
    }
    with tempfile.TemporaryDirectory() as tmp:
        env = cached_bytecode_env(Path(tmp) / "pycache")
        chain = Path(tmp) / f"chain{args.links}.urdf"
        chain.write_text(chain_urdf(args.links), encoding="utf-8")
        inputs: dict[str, Path] = {f"generated chain, {args.links} links": chain}
        big = largest_urdf(args.corpus)
        if big is not None:
            inputs[f"largest corpus URDF: {big.relative_to(args.corpus)}"] = big
        for label, path in inputs.items():
            jobs = {
                "check_urdf": ([check_urdf, str(path)], env),
                "modelkit tree": ([*modelkit, "tree", str(path)], env),
                "modelkit validate": ([*modelkit, "validate", str(path)], env),
            }
            stats = timed_many(jobs, args.repeat)
            base = stats["check_urdf"]
            for name in ("modelkit tree", "modelkit validate"):
                stats[name]["ratio_median_wall"] = stats[name]["median_s"] / base["median_s"]
                cpu = max(base["cpu_median_s"], 1e-9)
                stats[name]["ratio_median_cpu"] = stats[name]["cpu_median_s"] / cpu
            report["inputs"][label] = {
                "bytes": path.stat().st_size,
                "timings": stats,
                "tree_output": same_tree(check_urdf, modelkit, path, env),
            }
    print_table(report)
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    return 0


def print_table(report: dict[str, Any]) -> None:
    print(f"{report['date']}  {report['machine']['cpu_model']}  Python {report['machine']['python']}")
    print(f"fresh process per run, {report['repeat']} runs each after one warm-up; times in ms\n")
    for label, entry in report["inputs"].items():
        same = "byte-identical" if entry["tree_output"]["identical"] else "DIFFERENT"
        print(f"{label} ({entry['bytes']} bytes); tree vs check_urdf output: {same}")
        print("| command | wall min | wall median | wall max | CPU median | × check_urdf (wall) | exit |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for name, s in entry["timings"].items():
            ratio = f"{s['ratio_median_wall']:.1f}" if "ratio_median_wall" in s else "1"
            codes = ",".join(str(c) for c in s["exit_codes"])
            print(
                f"| {name} | {s['min_s'] * 1e3:.0f} | {s['median_s'] * 1e3:.0f} | {s['max_s'] * 1e3:.0f} "
                f"| {s['cpu_median_s'] * 1e3:.0f} | {ratio} | {codes} |"
            )
        print()


if __name__ == "__main__":
    sys.exit(main())
