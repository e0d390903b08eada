"""Agreement of `modelkit validate` with each format's own loader over folders of real model files.

    python bench/bench_agreement.py DIR [DIR ...] [--json FILE] [--package-root DIR]

For every URDF, xacro, SDF/world and MJCF file under the folders, the reference loader runs (the same ones
as `tests/test_conformance.py`: Debian's `check_urdf`, xacro then `check_urdf`, libsdformat through the
checker the tests compile, MuJoCo's compiler) and `modelkit.api.validate` runs in this process with the
same search paths; the verdicts agree when the loader accepts the file <=> modelkit reports no error.
Prints the agreement per folder, every disagreement with modelkit's first error or the loader's words,
and modelkit's slowest files (in-process time, imports already done). `.body` files have no loader here
and are skipped. Use it on a collection the test corpus does not hold (e.g. `pip download
example-robot-data`, unpacked; give its `share` folder's parent with `--package-root` so that its
`package://` URIs resolve through AMENT_PREFIX_PATH). A benchmark reports and never fails (exit 0).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.test_conformance import _kind, ours, reference  # noqa: E402
from tests.test_sdf_reader import ORACLE_SOURCE  # noqa: E402


def sdf_checker(work: Path) -> Path | None:
    """libsdformat's verdict program (as the tests build it), or None without g++/libsdformat."""
    import shutil
    import subprocess

    compiler, pkg_config = shutil.which("g++"), shutil.which("pkg-config")
    if not compiler or not pkg_config:
        return None
    probe = subprocess.run([pkg_config, "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    if probe.returncode != 0:
        return None
    source, binary = work / "sdf_check.cc", work / "sdf_check"
    source.write_text(ORACLE_SOURCE)
    subprocess.run([compiler, "-O0", "-o", str(binary), str(source), *probe.stdout.split()], check=True)
    return binary


def judge(path: Path, kind: str, checker: Path | None, scratch: Path) -> dict[str, Any]:
    if kind == "sdf" and checker is None:
        return {"skipped": "libsdformat not installed"}
    theirs, said = reference(kind, path, checker or Path("/nonexistent"), scratch)
    start = time.perf_counter()
    validation = ours(kind, path)
    seconds = time.perf_counter() - start
    errors = [f"{d.code} {d.message}" for d in validation.errors]
    return {"theirs": theirs, "ours": not errors, "errors": errors[:3], "said": said.strip()[-300:],
            "seconds": seconds}


def run(folders: list[Path], work: Path) -> dict[str, Any]:
    checker = sdf_checker(work)
    results: dict[str, Any] = {}
    old = os.getcwd()
    os.chdir(work)  # MuJoCo writes MUJOCO_LOG.TXT where it runs when it refuses a file
    try:
        for folder in folders:
            rows = {}
            for path in sorted(p for p in folder.rglob("*") if p.is_file()):
                kind = _kind(path)
                if kind is None or kind == "body":
                    continue
                rows[str(path.relative_to(folder))] = {"kind": kind, **judge(path, kind, checker, work)}
            results[str(folder)] = rows
    finally:
        os.chdir(old)
    return results


def report(results: dict[str, Any]) -> None:
    for folder, rows in results.items():
        judged = {k: r for k, r in rows.items() if "skipped" not in r and r["theirs"] is not None}
        agree = [k for k, r in judged.items() if r["theirs"] == r["ours"]]
        share = 100.0 * len(agree) / len(judged) if judged else 0.0
        print(f"\n{folder}\n  {len(agree)} of {len(judged)} files agree ({share:.1f} %); "
              f"{len(rows) - len(judged)} not judged (libraries for other files, or no loader)")
        for key, row in judged.items():
            if row["theirs"] != row["ours"]:
                why = row["errors"][0] if row["errors"] else f"the loader refuses: {row['said'][-160:]}"
                print(f"  - {key}: {why[:220]}")
        slowest = sorted(judged.items(), key=lambda kv: -kv[1]["seconds"])[:3]
        print("  slowest (modelkit, in-process): "
              + ", ".join(f"{k} {r['seconds']:.2f} s" for k, r in slowest))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--json", type=Path, help="also write every verdict as JSON")
    parser.add_argument("--package-root", type=Path, action="append", default=[],
                        help="a prefix holding share/<package> (added to AMENT_PREFIX_PATH)")
    args = parser.parse_args(argv)
    if args.package_root:
        roots = [str(p.resolve()) for p in args.package_root]
        os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join([*roots, os.environ.get("AMENT_PREFIX_PATH", "")])
    with tempfile.TemporaryDirectory() as work:
        results = run([f.resolve() for f in args.folders], Path(work))
    report(results)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
