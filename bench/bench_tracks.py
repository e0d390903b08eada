"""The converted tracked tutorial robot on a plain floor: how far MuJoCo and PyBullet turn it under
the seed's track controller, against the skid-steer reference (docs/verify.md, "Skid-steer reference").

    python bench/bench_tracks.py [--json FILE] [--defaults]

`modelkit convert` writes MJCF and URDF (default options) into a temporary folder; the harness
(tests/tracks_support.py) drives the written files for 10 s per profile (straight 0.3 m/s, spin
0.5 rad/s, arc 0.3 m/s + 0.3 rad/s). Prints the final pose of each engine, of the skid reference
with both contact layouts and of the ideal unicycle, the derived tolerance, and the largest gap of
each engine to the reference. MuJoCo keeps the file's `<option impratio>`, PyBullet runs with
`enableConeFriction=0` as MK809 asks; `--defaults` adds both engines with their own defaults
(MuJoCo impratio 1, PyBullet cone friction on). A benchmark reports and never fails (exit 0).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402

import modelkit  # noqa: E402
from modelkit.verify.drive import Command, Profile, vehicle  # noqa: E402
from modelkit.verify.drive.reference_skid import skid_model, skid_reference, skid_tolerance  # noqa: E402
from modelkit.verify.drive.scenario import default_scenario  # noqa: E402
from modelkit.verify.layers import layer4  # noqa: E402
from tests import tracks_support as support  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path)
    parser.add_argument("--defaults", action="store_true")
    args = parser.parse_args()
    source = layer4.floating(modelkit.load(support.TRACKS))
    prepared = vehicle.prepare_tracks(source)
    scenario = default_scenario("tracks", True)
    drive = vehicle.find_drive(source, scenario, prepared)
    results: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        files = support.convert(Path(tmp))
        tracks = support.track_info()
        for profile in support.PROFILES:
            p = Profile(profile.name, profile.duration, (Command(0.0, profile.v, profile.w),))
            refs = {layout: skid_reference(skid_model(prepared, drive, layout=layout), p, scenario, drive)
                    for layout in ("rollers", "uniform")}
            nominal = skid_model(prepared, drive)
            tol = skid_tolerance(nominal, p, scenario, drive, prepared)
            runs = {"mujoco": support.run_mujoco(files["mjcf"], tracks, profile),
                    "pybullet": support.run_pybullet(files["urdf"], tracks, profile)}
            if args.defaults:
                runs["mujoco-impratio-1"] = support.run_mujoco(files["mjcf"], tracks, profile, impratio=1.0)
                runs["pybullet-cone"] = support.run_pybullet(files["urdf"], tracks, profile, True)
            row: dict[str, Any] = {"profile": profile.name, "ideal_yaw": profile.w * profile.duration,
                                   "tolerance": tol.as_dict()}
            for name, ref in refs.items():
                row[f"skid:{name}"] = [float(ref.x[-1]), float(ref.y[-1]), float(ref.yaw[-1])]
            for name, run in runs.items():
                ref = refs["rollers"]
                n = min(len(run.t), len(ref.t))
                gap = np.hypot(run.x[:n] - ref.x[:n], run.y[:n] - ref.y[:n])
                row[name] = {"final": list(run.final()), "gap_position": float(gap.max()),
                             "gap_yaw": float(np.abs(run.yaw[:n] - ref.yaw[:n]).max())}
            results.append(row)
            print(f"{profile.name:8s} ideal yaw {row['ideal_yaw']:.2f} rad; "
                  f"tolerance {tol.position * 100:.1f} cm / {tol.yaw * 1e3:.0f} mrad")
            for name in refs:
                x, y, th = row[f"skid:{name}"]
                print(f"    skid:{name:9s} x {x:7.3f} y {y:7.3f} yaw {th:7.3f}")
            for name in runs:
                x, y, th = row[name]["final"]
                gap_cm, gap_mrad = row[name]["gap_position"] * 100, row[name]["gap_yaw"] * 1e3
                print(f"    {name:17s} x {x:7.3f} y {y:7.3f} yaw {th:7.3f}   "
                      f"gap {gap_cm:7.1f} cm / {gap_mrad:6.0f} mrad")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
