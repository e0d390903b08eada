"""Semantic mutants of real files through ``validate``, ``tree`` and ``convert``, every output opened in
its consumer (issue 17 §8, issue 18 §2).

Properties checked for each mutant (:mod:`tests.hostile.semantic`):

* ``validate`` and ``tree`` end without an exception, a hang or an internal error (MK899);
* when ``validate`` finds no error, ``convert`` to MJCF, URDF, SDF and ``.body`` exits 0 or 1, never with
  an exception or MK899, and exit 1 prints an error;
* every file ``convert`` wrote with exit 0 is accepted by its consumer: MuJoCo (MJCF), check_urdf and
  PyBullet (URDF), libsdformat (SDF, the compiled checker of ``tests/test_sdf_reader.py``), modelkit's
  own reader (``.body``: no error).

Usage (a campaign; the failures as JSON lines, a summary at the end)::

    python -m tests.hostile.outputs_fuzz --seeds 0:40 --oracle /tmp/modelkit-oracles/sdf_check-… FILE...

Each batch runs in a child process (``--child``), so a crash of an engine ends one case, not the run.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import FrameType
from typing import Any

MARK = "@@fuzz "
CASE_SECONDS = 90
MEMORY_LIMIT = 6 << 30
TARGETS = {"mjcf": ".xml", "urdf": ".urdf", "sdf": ".sdf", "body": ".body"}
#: what may make ``convert`` exit 1 (README): an error, or a collision mesh left out (MK500, MK805)
EXIT_1_REASON = re.compile(r" error MK\d+| warning MK(?:500|805) ")


def _expire(signum: int, frame: FrameType | None) -> None:
    raise TimeoutError("case timed out")


class Checker:
    """The consumers, opened once per child process."""

    def __init__(self, oracle: str | None) -> None:
        import pybullet

        self.oracle = oracle
        self.bullet = pybullet
        self.client = pybullet.connect(pybullet.DIRECT)

    def mjcf(self, path: Path) -> str | None:
        import mujoco

        try:
            model = mujoco.MjModel.from_xml_path(str(path))
            data = mujoco.MjData(model)
            mujoco.mj_step(model, data)
        except Exception as exc:
            return f"MuJoCo refuses the MJCF: {exc}"
        return None

    def urdf(self, path: Path) -> str | None:
        run = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True, timeout=60)
        if run.returncode != 0:
            return f"check_urdf refuses the URDF: {(run.stdout + run.stderr).strip()[-400:]}"
        flags = self.bullet.URDF_USE_INERTIA_FROM_FILE | self.bullet.URDF_USE_IMPLICIT_CYLINDER
        try:
            body = self.bullet.loadURDF(str(path), flags=flags, physicsClientId=self.client)
            self.bullet.removeBody(body, physicsClientId=self.client)
        except Exception as exc:
            return f"PyBullet refuses the URDF: {exc}"
        return None

    def sdf(self, path: Path) -> str | None:
        if not self.oracle:
            return None
        run = subprocess.run([self.oracle, path.name], cwd=path.parent, capture_output=True, text=True,
                             timeout=60)
        text = run.stdout + run.stderr
        if run.returncode != 0 or re.search(r"Error \[|Error:", text):
            return f"libsdformat refuses the SDF: {text.strip()[-400:]}"
        return None

    def body(self, path: Path) -> str | None:
        from modelkit.api import validate

        errors = [d for d in validate(path).diagnostics if d.severity.value == "error"]
        if errors:
            return f"modelkit's .body reader refuses the .body: {errors[0].code} {errors[0].message[:300]}"
        return None


def _invoke(runner: Any, cli: Any, args: list[str]) -> tuple[int, str, str | None]:
    result = runner.invoke(cli, args)
    error = result.exception
    exception = None if error is None or isinstance(error, SystemExit) else repr(error)[:400]
    return result.exit_code, result.output, exception


def run_case(source: Path, seed: int, checker: Checker, runner: Any, cli: Any) -> dict[str, Any]:
    from modelkit.api import validate
    from tests.hostile.semantic import mutant

    made = mutant(source, seed)
    record: dict[str, Any] = {"source": str(source), "seed": seed, "problems": []}
    if made is None:
        record["skipped"] = True
        return record
    what, data = made
    record["mutation"] = what
    path = source.with_name(f"{source.stem}__m{seed}{source.suffix}")
    path.write_bytes(data)
    out = Path(tempfile.mkdtemp(prefix="fuzz-out-"))
    problems: list[str] = record["problems"]
    start = time.perf_counter()
    signal.alarm(CASE_SECONDS)
    try:
        try:
            checked = validate(path)
        except Exception as exc:
            problems.append(f"validate raised {exc!r}"[:400])
            return record
        codes = [d.code for d in checked.diagnostics]
        errors = [d for d in checked.diagnostics if d.severity.value == "error"]
        record["errors"] = sorted({d.code for d in errors})
        if "MK899" in codes:
            problems.append("validate: internal error MK899")
        code, output, exception = _invoke(runner, cli, ["tree", str(path)])
        if exception or "MK899" in output:
            problems.append(f"tree: {exception or 'MK899'}")
        if errors:
            return record
        for target, suffix in TARGETS.items():
            written = out / target / f"robot{suffix}"
            code, output, exception = _invoke(runner, cli, ["convert", str(path), "-o", str(written), "-q"])
            if exception:
                problems.append(f"convert {target}: raised {exception}")
                continue
            if "MK899" in output:
                problems.append(f"convert {target}: internal error MK899: {output[-300:]}")
            if code not in (0, 1):
                problems.append(f"convert {target}: exit {code}: {output[-300:]}")
            if code == 1 and not EXIT_1_REASON.search(output):
                problems.append(f"convert {target}: exit 1 without an error: {output[-300:]}")
            if code != 0 or not written.exists():
                record.setdefault("refused", []).append(target)
                continue
            found = getattr(checker, target)(written)
            if found:
                problems.append(f"convert {target} exit 0, but {found}")
    except TimeoutError:
        problems.append(f"timed out after {CASE_SECONDS} s")
    finally:
        signal.alarm(0)
        record["seconds"] = round(time.perf_counter() - start, 2)
        path.unlink(missing_ok=True)
        shutil.rmtree(out, ignore_errors=True)
    return record


def child(oracle: str | None, cases: list[str]) -> None:
    import resource

    from click.testing import CliRunner

    from modelkit.cli import main as cli

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))  # a runaway ends its case only
    signal.signal(signal.SIGALRM, _expire)
    checker = Checker(oracle)
    runner = CliRunner()
    for case in cases:
        source, seed = case.rsplit(":", 1)
        print(MARK + json.dumps({"start": case}), flush=True)
        record = run_case(Path(source), int(seed), checker, runner, cli)
        print(MARK + json.dumps(record), flush=True)


def campaign(files: list[Path], seeds: range, oracle: str | None, batch: int = 25) -> list[dict[str, Any]]:
    """Every (file, seed) through :func:`run_case` in child processes; the records, crashes included."""
    cases = [f"{f}:{s}" for f in files for s in seeds]
    records: list[dict[str, Any]] = []
    while cases:
        chunk, cases = cases[:batch], cases[batch:]
        command = [sys.executable, "-m", "tests.hostile.outputs_fuzz", "--child", "--oracle", oracle or ""]
        run = subprocess.run(command + chunk, capture_output=True, text=True,
                             cwd=Path(__file__).resolve().parents[2])
        done: set[str] = set()
        started = None
        for line in run.stdout.splitlines():
            if not line.startswith(MARK):
                continue
            item = json.loads(line[len(MARK):])
            if "start" in item:
                started = item["start"]
                continue
            done.add(f"{item['source']}:{item['seed']}")
            records.append(item)
        if run.returncode != 0 and started is not None and started not in done:
            source, seed = started.rsplit(":", 1)
            records.append({"source": source, "seed": int(seed),
                            "problems": [f"the child died (exit {run.returncode}): {run.stderr[-400:]}"]})
            rest = chunk[chunk.index(started) + 1:]
            cases = rest + cases
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*")
    parser.add_argument("--seeds", default="0:10")
    parser.add_argument("--oracle", default="")
    parser.add_argument("--child", action="store_true")
    parser.add_argument("--json", default="")
    args = parser.parse_args()
    if args.child:
        child(args.oracle or None, args.files)
        return
    first, last = (int(x) for x in args.seeds.split(":"))
    records = campaign([Path(f).resolve() for f in args.files], range(first, last), args.oracle or None)
    failing = [r for r in records if r["problems"]]
    for r in failing:
        print(json.dumps(r))
    tried = [r for r in records if not r.get("skipped")]
    clean = [r for r in tried if not r.get("errors")]
    print(f"{len(tried)} mutants, {len(clean)} without a validate error, {len(failing)} with a problem",
          file=sys.stderr)
    if args.json:
        Path(args.json).write_text(json.dumps(records, indent=1))
    os._exit(1 if failing else 0)


if __name__ == "__main__":
    main()
