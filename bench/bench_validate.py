"""Benchmarks of the `modelkit` command as a user runs it: a fresh process per run.

    python bench/bench_validate.py [--repeat N] [--corpus DIR] [--small FILE] [--json FILE]

Measures
  (a) `modelkit validate SMALL`: wall time of N fresh processes, min/median/max (target <= 0.3 s);
  (b) `modelkit validate ALL.body` in one call over every .body under the corpus, with and
      without --no-resources: files per second;
  (c) `modelkit tree SMALL`: as (a);
  plus the interpreter start-up on its own, the import-time breakdown of the validate path
  (`python -X importtime`), and which of mujoco, pybullet and trimesh `validate` and `tree` load.

A benchmark reports, it never fails: the exit status is 0 whatever the figures (2 only for bad
usage). The corpus defaults to <repo>/../shared/corpus, the repo being this file's grandparent.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

try:
    import resource
except ImportError:  # not on Windows: CPU times are then reported as 0
    resource = None  # type: ignore[assignment]

REPO = Path(__file__).resolve().parents[1]
DEFAULT_CORPUS = REPO.parent / "shared" / "corpus"
DEFAULT_SMALL = DEFAULT_CORPUS / "choreonoid" / "share" / "model" / "misc" / "pendulum.body"
TARGET_SMALL_S = 0.3
WATCHED = ("mujoco", "pybullet", "trimesh")

# Runs a modelkit command in this interpreter and prints the watched modules that were loaded or
# looked for (a finder first on sys.meta_path sees attempts even for packages not installed).
HYGIENE_CHILD = textwrap.dedent("""\
    import json, sys
    watched = set(sys.argv[1].split(","))
    attempted = set()
    class Recorder:
        @staticmethod
        def find_spec(fullname, path=None, target=None):
            if fullname.partition(".")[0] in watched:
                attempted.add(fullname)
            return None
    sys.meta_path.insert(0, Recorder)
    from click.testing import CliRunner
    from modelkit.cli import main
    result = CliRunner().invoke(main, sys.argv[2:])
    loaded = sorted(m for m in sys.modules if m.partition(".")[0] in watched)
    print(json.dumps({"exit_code": result.exit_code, "loaded": loaded, "attempted": sorted(attempted)}))
""")


def modelkit_command() -> list[str]:
    """The console script next to this interpreter (what a user types), else `python -m`."""
    bindir = Path(sys.executable).parent
    for name in ("modelkit", "modelkit.exe"):
        script = bindir / name
        if script.is_file() and os.access(script, os.X_OK):
            return [str(script)]
    return [sys.executable, "-m", "modelkit.cli"]


def cached_bytecode_env(prefix: Path) -> dict[str, str]:
    """The environment with Python's bytecode cache on, kept under `prefix`
    (PYTHONPYCACHEPREFIX) so that the benchmark writes nothing into the source tree."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = str(prefix)
    return env


Job = tuple[Sequence[str], Mapping[str, str]]  # a command and its environment


def _children_cpu() -> float:
    if resource is None:
        return 0.0
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(command: Sequence[str], env: Mapping[str, str]) -> tuple[float, float, int]:
    """Wall time, CPU time (user + system, of the child and its children) and exit code.
    CPU time is much less disturbed than wall time by other load on the machine."""
    cpu = _children_cpu()
    start = time.perf_counter()
    done = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL, check=False, env=env)
    return time.perf_counter() - start, _children_cpu() - cpu, done.returncode


def timed_many(jobs: Mapping[str, Job], repeat: int, warmup: int = 1) -> dict[str, dict[str, Any]]:
    """min/median/max wall time (and CPU time) of `repeat` fresh processes per job, after `warmup`
    unrecorded runs (bytecode and page cache warm, as on a user's second run). The jobs take
    turns, so that a burst of other load on the machine hits them all alike."""
    for _ in range(warmup):
        for command, env in jobs.values():
            run_once(command, env)
    walls: dict[str, list[float]] = {name: [] for name in jobs}
    cpus: dict[str, list[float]] = {name: [] for name in jobs}
    codes: dict[str, set[int]] = {name: set() for name in jobs}
    for _ in range(repeat):
        for name, (command, env) in jobs.items():
            wall, cpu, code = run_once(command, env)
            walls[name].append(wall)
            cpus[name].append(cpu)
            codes[name].add(code)
    return {name: {"runs": repeat, "min_s": min(walls[name]), "median_s": statistics.median(walls[name]),
                   "max_s": max(walls[name]), "cpu_median_s": statistics.median(cpus[name]),
                   "exit_codes": sorted(codes[name])}
            for name in jobs}


def timed(command: Sequence[str], env: Mapping[str, str], repeat: int, warmup: int = 1) -> dict[str, Any]:
    return timed_many({"job": (command, env)}, repeat, warmup)["job"]


def throughput(command: Sequence[str], files: Sequence[str], env: Mapping[str, str],
               repeat: int) -> dict[str, Any]:
    stats = timed([*command, *files], env, repeat)
    stats["files"] = len(files)
    stats["files_per_s"] = len(files) / stats["median_s"] if stats["median_s"] > 0 else 0.0
    return stats


def import_times(code: str, env: Mapping[str, str], top: int) -> dict[str, Any]:
    """`python -X importtime -c CODE`: total, the top entries by cumulative time, and the self
    time summed per top-level package (microseconds in, milliseconds out)."""
    subprocess.run([sys.executable, "-c", code], stdin=subprocess.DEVNULL, capture_output=True,
                   check=False, cwd=REPO, env=env)  # warm-up: compile and cache the bytecode
    done = subprocess.run([sys.executable, "-X", "importtime", "-c", code], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, check=False, cwd=REPO, env=env)
    rows: list[tuple[str, int, int, int]] = []  # name, self, cumulative, depth
    for line in done.stderr.splitlines():
        if not line.startswith("import time:") or "self [us]" in line:
            continue
        try:
            self_text, cumulative_text, module = line[len("import time:"):].split("|", 2)
            depth = (len(module) - len(module.lstrip(" ")) - 1) // 2
            rows.append((module.strip(), int(self_text), int(cumulative_text), depth))
        except ValueError:
            continue
    total_us = sum(r[2] for r in rows if r[3] == 0)
    by_package: dict[str, int] = {}
    for name, self_us, _, _ in rows:
        key = name.partition(".")[0]
        by_package[key] = by_package.get(key, 0) + self_us
    biggest = sorted(rows, key=lambda r: r[2], reverse=True)[:top]
    packages = sorted(by_package.items(), key=lambda kv: kv[1], reverse=True)[:top]
    return {
        "code": code,
        "exit_code": done.returncode,
        "modules": len(rows),
        "total_ms": total_us / 1000,
        "top_cumulative": [{"module": n, "self_ms": s / 1000, "cumulative_ms": c / 1000}
                           for n, s, c, _ in biggest],
        "self_by_package": [{"package": p, "self_ms": us / 1000} for p, us in packages],
    }


def hygiene(args: Sequence[str], label: str, env: Mapping[str, str]) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-c", HYGIENE_CHILD, ",".join(WATCHED), *args],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, check=False, cwd=REPO,
                          env=env)
    try:
        report: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, ValueError):
        return {"command": label, "error": (done.stderr or done.stdout).strip()[-500:]}
    report["command"] = label
    # Module lists of a whole package are long: keep a count per top-level package.
    report["loaded"] = _count_packages(report["loaded"])
    report["attempted"] = _count_packages(report["attempted"])
    return report


def _count_packages(modules: Sequence[str]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for name in modules:
        top = name.partition(".")[0]
        counts[top] = counts.get(top, 0) + 1
    return counts


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.partition(":")[2].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def machine() -> dict[str, Any]:
    try:
        from importlib.metadata import version

        modelkit_version = version("modelkit")
    except Exception:  # a benchmark reports, it does not fail
        modelkit_version = "unknown"
    return {
        "nproc": os.cpu_count(),
        "usable_cpus": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "cpu_model": cpu_model(),
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
        "platform": platform.platform(),
        "modelkit": modelkit_version,
        "load_average_at_start": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }


def _relative(part: str) -> str:
    """A command word, relative to the repository when it lies inside it."""
    try:
        return str(Path(part).relative_to(REPO))
    except ValueError:
        return part


def display(path: Path) -> str:
    try:
        return str(path.relative_to(REPO.parent))
    except ValueError:
        return str(path)


def run(repeat: int, corpus: Path, small: Path, top: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="modelkit-bench-pycache-") as prefix:
        return _run(repeat, corpus, small, top, cached_bytecode_env(Path(prefix)))


def _run(repeat: int, corpus: Path, small: Path, top: int, env: Mapping[str, str]) -> dict[str, Any]:
    mk = modelkit_command()
    files = sorted(str(p) for p in corpus.rglob("*.body")) if corpus.is_dir() else []
    results: dict[str, Any] = {
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": machine(),
        "command": [_relative(part) for part in mk],
        "small_file": display(small),
        "corpus": display(corpus),
        "target_small_s": TARGET_SMALL_S,
        "environment_as_is": {"PYTHONDONTWRITEBYTECODE": os.environ.get("PYTHONDONTWRITEBYTECODE")},
    }
    # The environment as it is: with PYTHONDONTWRITEBYTECODE set and no __pycache__ in the
    # source tree (an editable install), every run compiles modelkit's sources again.
    as_is = dict(os.environ)
    results.update(timed_many({
        "python_startup": ([sys.executable, "-c", "pass"], env),
        "import_cli": ([sys.executable, "-c", "import modelkit.cli"], env),
        "validate_small": ([*mk, "validate", str(small)], env),
        "tree_small": ([*mk, "tree", str(small)], env),
        "validate_small_env_as_is": ([*mk, "validate", str(small)], as_is),
        "tree_small_env_as_is": ([*mk, "tree", str(small)], as_is),
    }, repeat))
    if files:
        batch_repeat = max(3, repeat // 4)
        results["validate_corpus"] = throughput([*mk, "validate"], files, env, batch_repeat)
        results["validate_corpus_no_resources"] = throughput([*mk, "validate", "--no-resources"], files,
                                                             env, batch_repeat)
    results["importtime_cli"] = import_times("import modelkit.cli", env, top)
    results["importtime_validate"] = import_times(
        "import sys; from modelkit.cli import main; sys.argv = ['modelkit', 'validate', "
        f"{str(small)!r}]\ntry:\n    main()\nexcept SystemExit:\n    pass", env, top)
    checks = [(["validate", str(small)], "validate SMALL"),
              (["validate", "--no-resources", str(small)], "validate --no-resources SMALL"),
              (["tree", str(small)], "tree SMALL")]
    if files:
        checks.append((["validate", *files], f"validate CORPUS ({len(files)} files)"))
    results["import_hygiene"] = [hygiene(args, label, env) for args, label in checks]
    results["load_average_at_end"] = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    return results


def _row(label: str, stats: dict[str, Any], extra: str = "") -> str:
    return (f"{label:<44} {stats['min_s'] * 1000:8.1f} {stats['median_s'] * 1000:8.1f} "
            f"{stats['max_s'] * 1000:8.1f} {stats['cpu_median_s'] * 1000:8.1f}  {extra}")


def _load(values: Sequence[float] | None) -> str:
    return "/".join(f"{v:.2f}" for v in values) if values else "n/a"


def _packages(counts: Mapping[str, int]) -> str:
    return ", ".join(f"{p} ({n} modules)" for p, n in sorted(counts.items())) or "none"


def report(results: dict[str, Any]) -> str:
    m = results["machine"]
    lines = [
        f"machine: {m['nproc']} CPU(s) ({m['usable_cpus']} usable), {m['cpu_model']}, "
        f"{m['implementation']} {m['python']}",
        f"load average (1/5/15 min) at start {_load(m['load_average_at_start'])}, "
        f"at end {_load(results['load_average_at_end'])}",
        f"command: {' '.join(results['command'])}; small file: {results['small_file']}",
        "bytecode cached (PYTHONPYCACHEPREFIX, after a warm-up run) unless marked [as is]: "
        f"PYTHONDONTWRITEBYTECODE={results['environment_as_is']['PYTHONDONTWRITEBYTECODE']}",
        "",
        f"{'fresh process each run':<44} {'wall ms':>8} {'':>8} {'':>8} {'CPU ms':>8}",
        f"{'':<44} {'min':>8} {'median':>8} {'max':>8} {'median':>8}",
    ]
    target = results["target_small_s"]
    n = results["validate_small"]["runs"]
    lines.append(_row(f"python -c pass (x{n})", results["python_startup"]))
    lines.append(_row(f"python -c 'import modelkit.cli' (x{n})", results["import_cli"]))
    for key, label in (("validate_small", "modelkit validate SMALL"), ("tree_small", "modelkit tree SMALL"),
                       ("validate_small_env_as_is", "modelkit validate SMALL [as is]"),
                       ("tree_small_env_as_is", "modelkit tree SMALL [as is]")):
        stats = results[key]
        verdict = "within" if stats["median_s"] <= target else "OVER"
        lines.append(_row(f"{label} (x{n})", stats,
                          f"{verdict} the {target:.1f} s target; exit {stats['exit_codes']}"))
    for key, label in (("validate_corpus", "modelkit validate CORPUS"),
                       ("validate_corpus_no_resources", "modelkit validate --no-resources CORPUS")):
        if key in results:
            stats = results[key]
            lines.append(_row(f"{label} (x{stats['runs']})", stats,
                              f"{stats['files']} files, {stats['files_per_s']:.1f} files/s (median); "
                              f"exit {stats['exit_codes']}"))
    for key in ("importtime_cli", "importtime_validate"):
        imp = results[key]
        title = "import modelkit.cli" if key == "importtime_cli" else "modelkit validate SMALL (all imports)"
        lines += ["", f"-X importtime, {title}: {imp['modules']} modules, {imp['total_ms']:.1f} ms",
                  f"  {'module (top by cumulative)':<44} {'self ms':>8} {'cum ms':>8}"]
        lines += [f"  {r['module']:<44} {r['self_ms']:8.1f} {r['cumulative_ms']:8.1f}"
                  for r in imp["top_cumulative"]]
        lines.append("  self time by top-level package: " + ", ".join(
            f"{r['package']} {r['self_ms']:.1f}" for r in imp["self_by_package"]))
    lines += ["", f"import hygiene ({', '.join(WATCHED)} loaded or looked for):"]
    for h in results["import_hygiene"]:
        shown = h["command"]
        if "error" in h:
            lines.append(f"  modelkit {shown}: could not run: {h['error']}")
        else:
            lines.append(f"  modelkit {shown}: exit {h['exit_code']}, loaded {_packages(h['loaded'])}, "
                         f"looked for {_packages(h['attempted'])}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=20,
                        help="runs per single-file measurement (default 20)")
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS, help="folder searched for .body files")
    parser.add_argument("--small", type=Path, default=DEFAULT_SMALL, help="the small file for (a) and (c)")
    parser.add_argument("--top", type=int, default=12, help="import-time entries to list")
    parser.add_argument("--json", type=Path, default=None, metavar="FILE", help="also write the figures here")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    if not args.small.is_file():
        parser.error(f"small file not found: {args.small}")
    results = run(args.repeat, args.corpus, args.small, args.top)
    print(report(results))
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(results, indent=2) + "\n")
        print(f"\nwrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
