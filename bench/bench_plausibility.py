"""How often the plausibility warnings fire on folders of real model files, with every hit listed to be read.

    python bench/bench_plausibility.py DIR [DIR ...]

For every `.body`, URDF, xacro, SDF/world and MJCF file under the folders, `modelkit.api.validate` runs in
this process and each finding of MK306 (joint axis not unit), MK316 (implausible inertia), MK418 (collision
far from visual) and MK419 (collision shape differs from visual) is printed with its location; the last line
per folder counts the files read, the files with each code and the hits. Give `AMENT_PREFIX_PATH` (or
`ROS_PACKAGE_PATH`) in the environment so that `package://` meshes resolve: meshes that are not found
leave their links unjudged. The counts in docs/validate.md come from this script. A benchmark reports and
never fails (exit 0).
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from modelkit.api import validate  # noqa: E402

CODES = ("MK306", "MK316", "MK418", "MK419")
SUFFIXES = {".body", ".urdf", ".xacro", ".sdf", ".world", ".xml"}


def survey(folder: Path) -> str:
    """Print each hit under ``folder``; return the summary line."""
    files = sorted(p for p in folder.rglob("*") if p.suffix.lower() in SUFFIXES and p.is_file())
    with_code: Counter[str] = Counter()
    hits: Counter[str] = Counter()
    for path in files:
        found = [d for d in validate(path).diagnostics if d.code in CODES]
        for d in found:
            where = f"{d.location.file}:{d.location.line}" if d.location else str(path)
            print(f"{d.code} {where}: {d.message}")
            hits[d.code] += 1
        with_code.update({d.code for d in found})
    counts = ", ".join(f"{code} {with_code[code]} ({hits[code]})" for code in CODES)
    return f"{folder}: {len(files)} files read; files with each code (hits): {counts}"


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__)
        return 0
    summaries = [survey(Path(arg)) for arg in argv]
    print("\n".join(summaries))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
