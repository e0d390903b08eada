"""Run hostile cases through ``validate`` and ``tree`` in this process, under limits.

Usage: ``python runner.py LIMIT_BYTES CASE...``; prints one JSON line per case. Each case runs with
a watchdog (SIGALRM) in an empty working directory; the address space is capped with RLIMIT_AS.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import sys
import tempfile
import time
from types import FrameType

CASE_SECONDS = 20


def _expire(signum: int, frame: FrameType | None) -> None:
    raise TimeoutError("case timed out")


def own_peak_kib() -> int:
    """This process's own peak resident set, in KiB.

    Not ``getrusage(RUSAGE_SELF).ru_maxrss``: Linux carries the forking parent's peak across
    fork and exec into it, so a child of a large pytest process reports the parent's peak.
    ``VmHWM`` belongs to the memory map that exec created.
    """
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    raise RuntimeError("no VmHWM in /proc/self/status")


def main() -> None:
    limit = int(sys.argv[1])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    from click.testing import CliRunner

    from modelkit.cli import main as cli

    signal.signal(signal.SIGALRM, _expire)
    runner = CliRunner()
    for case in sys.argv[2:]:
        record: dict[str, object] = {"case": case}
        with tempfile.TemporaryDirectory() as cwd:
            os.chdir(cwd)
            start = time.perf_counter()
            for command in ("validate", "tree"):
                args = [command, "--format", "json", case] if command == "validate" else [command, case]
                signal.alarm(CASE_SECONDS)
                try:
                    result = runner.invoke(cli, args)
                finally:
                    signal.alarm(0)
                error = result.exception
                record[command] = {
                    "exit": result.exit_code,
                    "exception": None if error is None or isinstance(error, SystemExit) else repr(error),
                    "stdout": result.stdout,
                    "stderr": result.stderr,
                }
            record["seconds"] = time.perf_counter() - start
            record["stray"] = sorted(os.listdir(cwd))
            os.chdir("/")
        print(json.dumps(record), flush=True)
    print(json.dumps({"peak_kib": own_peak_kib()}), flush=True)


if __name__ == "__main__":
    main()
