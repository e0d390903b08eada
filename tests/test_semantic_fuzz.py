"""Semantic mutants of real files (``tests/hostile/semantic.py``) through validate, tree and convert, every
output opened in its consumer (``tests/hostile/outputs_fuzz.py``): a fixed sample of the campaign that
found the runaway track (an Extrusion point at 3.5e38 m asked for ~1e38 rollers) and the SDF link whose
negative moment validate let through. Issue 17 §8, issue 18 §2."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.hostile.outputs_fuzz import campaign

from .conftest import CORPUS, SAMPLES, require_tool
from .test_sdf_reader import sdf_oracle  # noqa: F401  (the compiled libsdformat checker, a fixture)

# (folder copied into the test's tmp folder, file inside it)
SOURCES = [
    (SAMPLES / "choreonoid_ros2_mobile_robot_tutorial", "model/mobile_robot_tracks.body"),
    (SAMPLES / "choreonoid_ros2_mobile_robot_tutorial", "model/mobile_robot_pantilt.body"),
    (SAMPLES / "gazebo_unicycle", "unicycle.sdf"),
    (CORPUS / "sdformat_urdf" / "sdformat_test_files" / "models" / "joint_revolute", "joint_revolute.sdf"),
    (CORPUS / "urdf_tutorial", "urdf/06-flexible.urdf"),
    (CORPUS / "dm_control_suite" / "dm_control" / "suite", "cartpole.xml"),
]
SEEDS = range(0, 3)
# (folder, file, seeds) of the mutants that once failed, beyond SEEDS
REGRESSIONS = [
    # a universal joint re-parented: the plausibility rule compared a numpy translation with a tuple
    (CORPUS / "gz_sim_worlds" / "examples" / "worlds", "auto_inertia_pendulum.sdf", [11]),
]


def test_semantic_mutants_convert_to_files_their_consumers_load(tmp_path: Path,
                                                                 sdf_oracle: Path) -> None:  # noqa: F811
    require_tool("check_urdf")
    files = []
    for folder, relative in SOURCES:
        if not (folder / relative).is_file():
            pytest.fail(f"{folder / relative} is missing: the fuzz sample needs it")
        copy = tmp_path / f"{len(files)}_{folder.name}"
        shutil.copytree(folder, copy)
        files.append(copy / relative)
    records = campaign(files, SEEDS, str(sdf_oracle), batch=len(files) * len(SEEDS))
    assert len(records) == len(files) * len(SEEDS)
    for folder, relative, seeds in REGRESSIONS:
        copy = tmp_path / f"regression_{folder.name}"
        shutil.copytree(folder, copy)
        records += campaign([copy / relative], seeds, str(sdf_oracle))
    tried = [r for r in records if not r.get("skipped")]
    converted = [r for r in tried if not r.get("errors")]
    assert len(converted) >= len(records) // 3, "too few mutants reach convert for the sample to say much"
    failing = [(r["source"].split("/")[-1], r["seed"], r.get("mutation"), r["problems"]) for r in records
               if r["problems"]]
    assert not failing, failing


# (folder, file, seed, exit) of the mutants verify once ended without a verdict (tests/hostile/verify_fuzz.py)
VERIFY_REGRESSIONS = [
    # SDF limits reversed on `joint` (and camera_joint made a ball): Drake's Joint constructor aborted
    # verify's process; now Drake runs in a child, and the source's own reversed range is a skip
    (SAMPLES / "gazebo_unicycle", "unicycle.sdf", 2, 0),
    # a wheel of 3.5e38 kg (and an axis reversed): the engines blow up, a check's error is NaN, and the
    # table raised ValueError printing it (MK899)
    (SAMPLES / "choreonoid_ros2_mobile_robot_tutorial", "model/mobile_robot_primitive.body", 7, 1),
]


@pytest.mark.parametrize(("folder", "relative", "seed", "code"), VERIFY_REGRESSIONS,
                         ids=[f"{name.split('/')[-1]}-{seed}" for _, name, seed, _ in VERIFY_REGRESSIONS])
def test_verify_gives_a_verdict_on_mutants(tmp_path: Path, folder: Path, relative: str, seed: int,
                                           code: int) -> None:
    import sys

    from tests.hostile.verify_fuzz import run_case

    copy = tmp_path / folder.name
    shutil.copytree(folder, copy)
    record = run_case(copy / relative, seed, [sys.executable, "-m", "modelkit.cli", "verify"])
    assert record["problems"] == [] and record["exit"] == code, record
