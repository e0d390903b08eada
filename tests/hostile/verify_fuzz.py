"""Semantic mutants of real files (:mod:`tests.hostile.semantic`) through ``modelkit verify`` as a user
runs it: the command in its own process, with its report (issue 18: no runaway, never a traceback).

Properties checked for each mutant:

* ``verify`` ends within :data:`CASE_SECONDS`, with exit 0 (PASS), 1 (FAIL) or 2 (could not run: an
  input error), never with an exception, an internal error (MK899) or a signal;
* exit 0 or 1 prints its verdict line (``PASS: …`` or ``FAIL: …``) and writes ``report.json`` with the
  same verdict; exit 2 prints why.

A FAIL is not a finding by itself: a mutant is often a robot the engines cannot agree on (a 1e6 kg·m²
chassis, a track of garbled cross-section), and saying so is verify's job. The FAILs of a campaign are
read one by one; each that was modelkit's fault became a test (a tyre given twice, an asymmetric
inertia, a reversed range that aborted Drake).

Usage (a campaign; one JSON line per mutant, the problems marked, a summary at the end)::

    python -m tests.hostile.verify_fuzz --seeds 0:10 FILE...

The mutant is written beside its source (a ``.body`` or URDF names its meshes relative to itself) as
``STEM__vSEED.EXT`` and removed afterwards; verify's output goes to a temporary folder.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from tests.hostile.semantic import mutant

CASE_SECONDS = 300
VERDICT = re.compile(r"^(PASS|FAIL): ", re.MULTILINE)


def run_case(source: Path, seed: int, command: list[str]) -> dict[str, Any]:
    """One mutant of ``source`` through ``command`` (``modelkit verify``, as a list) and what was wrong."""
    made = mutant(source, seed)
    if made is None:
        return {"source": str(source), "seed": seed, "skipped": True, "problems": []}
    what, data = made
    path = source.with_name(f"{source.stem}__v{seed}{source.suffix}")
    path.write_bytes(data)
    out = Path(tempfile.mkdtemp(prefix="modelkit-verify-fuzz-"))
    record: dict[str, Any] = {"source": str(source), "seed": seed, "mutation": what, "problems": []}
    try:
        run = subprocess.run([*command, str(path), "-o", str(out / "report")], capture_output=True,
                             text=True, timeout=CASE_SECONDS)
    except subprocess.TimeoutExpired:
        record["problems"].append(f"no answer within {CASE_SECONDS} s")
        return record
    finally:
        path.unlink()
    try:
        record.update(judge(run.returncode, run.stdout + run.stderr, out / "report" / "report.json"))
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return record


def judge(code: int, printed: str, report: Path) -> dict[str, Any]:
    """The exit code, the verdict line and the problems of one run."""
    problems: list[str] = []
    verdicts = VERDICT.findall(printed)
    if code not in (0, 1, 2):
        problems.append(f"exit {code}")
    if "Traceback" in printed or "MK899" in printed:
        problems.append("an internal error: " + printed[-600:])
    if code in (0, 1):
        if verdicts != [("PASS" if code == 0 else "FAIL")]:
            problems.append(f"exit {code} without its verdict line: " + printed[-600:])
        elif not report.is_file():
            problems.append("no report.json")
        elif json.loads(report.read_text())["verdict"] != verdicts[0].lower():
            problems.append("report.json's verdict is not the printed one")
    elif code == 2 and not printed.strip():
        problems.append("exit 2 without a word of why")
    line = next((ln for ln in printed.splitlines() if VERDICT.match(ln)), "")
    return {"exit": code, "verdict": line[:200], "problems": problems}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="+")
    parser.add_argument("--seeds", default="0:10")
    parser.add_argument("--json", default="")
    args = parser.parse_args()
    first, last = (int(x) for x in args.seeds.split(":"))
    command = [sys.executable, "-m", "modelkit.cli", "verify"]
    records = []
    for name in args.files:
        for seed in range(first, last):
            record = run_case(Path(name).resolve(), seed, command)
            records.append(record)
            print(json.dumps(record), flush=True)
    tried = [r for r in records if not r.get("skipped")]
    failing = [r for r in tried if r["problems"]]
    counts = {code: sum(1 for r in tried if r.get("exit") == code) for code in (0, 1, 2)}
    print(f"{len(tried)} mutants: {counts[0]} PASS, {counts[1]} FAIL, {counts[2]} could not run; "
          f"{len(failing)} with a problem", file=sys.stderr)
    if args.json:
        Path(args.json).write_text(json.dumps(records, indent=1))
    sys.exit(1 if failing else 0)


if __name__ == "__main__":
    main()
