"""The size and install time of the environment `pip install modelkit` makes: what the pre-commit hook
installs (pre-commit's python hooks are a fresh virtualenv with `pip install .` of the hook repository).

Compares this working tree ("after") with a git revision ("before", default: the last commit whose
core dependencies still held the engines) in the same run. Each is installed twice into fresh
virtualenvs with one shared pip cache: the first run fills the cache (downloads, wheel builds), the
second is the figure (network excluded). Size: the virtualenv's site-packages, pip and setuptools
excluded. Optionally the `[verify]` extra too.

    python bench/bench_install.py [--before REV] [--extra verify] [--json bench/install_baseline.json]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BEFORE = "8935ea0"
NOT_COUNTED = ("pip", "setuptools", "_distutils_hack", "distutils-precedence.pth")


def tree_bytes(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file() and not f.is_symlink())


def site_packages(env_dir: Path) -> Path:
    return next((env_dir / "lib").glob("python3*/site-packages"))


def environment_size(env_dir: Path) -> tuple[int, int]:
    """(bytes, distributions) of what was installed, pip and setuptools left out."""
    site = site_packages(env_dir)
    total, dists = 0, 0
    for entry in site.iterdir():
        if entry.name.startswith(NOT_COUNTED) or entry.name.startswith(("pip-", "setuptools-")):
            continue
        total += tree_bytes(entry) if entry.is_dir() else entry.stat().st_size
        dists += entry.name.endswith(".dist-info")
    return total, dists


def source_tree(rev: str | None, dest: Path) -> Path:
    """The project at ``rev`` (git archive), or the working tree's tracked and untracked files."""
    dest.mkdir(parents=True)
    if rev is not None:
        archive = subprocess.run(["git", "archive", rev], cwd=ROOT, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
        return dest
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=ROOT, capture_output=True, check=True).stdout.decode().split("\0")
    for rel in filter(None, listed):
        if (ROOT / rel).is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, dest / rel)
    return dest


def install(project: Path, extra: str, work: Path, cache: Path, label: str) -> tuple[float, int, int]:
    env_dir = work / f"venv-{label}"
    venv.create(env_dir, with_pip=True)
    target = f"{project}[{extra}]" if extra else str(project)
    env = dict(os.environ, PIP_CACHE_DIR=str(cache), PIP_DISABLE_PIP_VERSION_CHECK="1")
    start = time.perf_counter()
    subprocess.run([str(env_dir / "bin" / "python"), "-m", "pip", "install", "-q", target], env=env,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seconds = time.perf_counter() - start
    size, dists = environment_size(env_dir)
    shutil.rmtree(env_dir)
    return seconds, size, dists


def measure(rev: str | None, extra: str, work: Path, cache: Path, label: str) -> dict[str, float]:
    project = source_tree(rev, work / f"src-{label}")
    install(project, extra, work, cache, f"{label}-warm")
    seconds, size, dists = install(project, extra, work, cache, label)
    return {"seconds": round(seconds, 1), "megabytes": round(size / 2**20, 1), "distributions": dists}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=BEFORE, help="git revision to compare with")
    parser.add_argument("--extra", default="", help="also install this extra (e.g. verify)")
    parser.add_argument("--json", type=Path, default=None, help="write the figures here")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="modelkit-install-") as tmp:
        work = Path(tmp)
        cache = work / "pip-cache"
        rows = {"before": measure(args.before, "", work, cache, "before"),
                "after": measure(None, args.extra, work, cache, "after")}
        if args.extra:
            rows["after (core only)"] = measure(None, "", work, cache, "core")
    print(f"{'':20s} {'install s':>10s} {'MB':>8s} {'dists':>6s}")
    for name, row in rows.items():
        print(f"{name:20s} {row['seconds']:10.1f} {row['megabytes']:8.1f} {row['distributions']:6.0f}")
    if args.json is not None:
        record = {"python": sys.version.split()[0], "before": args.before, "extra": args.extra, **rows}
        args.json.write_text(json.dumps(record, indent=2, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
