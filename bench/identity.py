"""Byte-identity harness: convert a broad set of sources to every target and compare two runs.

A refactor that must not change any output (moving data between ``extras`` and model fields, say)
is checked by converting the same sources with the old code and with the new, then comparing every
written file byte for byte and the notes each conversion printed.

    # record: one process; PYTHONPATH chooses whose modelkit is imported
    PYTHONPATH=/work/main python bench/identity.py record /tmp/ident/base
    PYTHONPATH=. python bench/identity.py record /tmp/ident/new
    python bench/identity.py compare /tmp/ident/base /tmp/ident/new

``record`` runs ``modelkit convert SRC -o N/x.SUFFIX`` for every source and target in-process (the
CLI's own entry point, with the working directory set to the output root so paths printed in the
notes are the same in both runs) and saves each run's exit code and output in ``N/log.txt``.
``compare`` lists every file that differs or exists on one side only and exits 1 if any does.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
CORPUS = REPO.parent / "shared" / "corpus"
PY = f"python{sys.version_info.major}.{sys.version_info.minor}"
ERD = Path(sys.prefix) / "lib" / PY / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data"
ERD = ERD / "robots"
TARGETS = ("urdf", "sdf", "xml", "body")

CORPUS_FILES = [
    # .body
    "choreonoid/share/model/GR001/GR001.body",
    "choreonoid/share/model/PA10/PA10.body",
    "choreonoid/share/model/Robotiq/2F-85.body",
    "choreonoid/share/model/SR1/SR1.body",
    "choreonoid/share/model/misc/ClosedLinkSample.body",
    "choreonoid/share/model/misc/SpringModel.body",
    "choreonoid/share/model/misc/box.body",
    "choreonoid/share/model/misc/ellipsoid1.body",
    "choreonoid/share/model/misc/pendulum.body",
    "choreonoid/share/model/misc/slope.body",
    "irsl_choreonoid/sample/closed_link_ik.body",
    # URDF and xacro
    "urdf_tutorial/urdf/07-physics.urdf",
    "urdf_tutorial/urdf/08-macroed.urdf.xacro",
    "urdf_tutorial/urdf/06-flexible.urdf",
    "kuka_experimental/kuka_kr16_support/urdf/kr16_2.urdf",
    "kuka_experimental/kuka_lbr_iiwa_support/urdf/lbr_iiwa_14_r820.xacro",
    "franka_description/robots/fr3/fr3.urdf.xacro",
    "franka_description/end_effectors/franka_hand/franka_hand.urdf.xacro",
    "gazebo_ros_pkgs/gazebo_plugins/test/multi_robot_scenario/xacro/p3dx/pioneer3dx.xacro",
    "gazebo_ros_pkgs/gazebo_plugins/test/tricycle_drive/xacro/tricycle/tricycle.xacro",
    "gazebo_ros_pkgs/gazebo_plugins/test2/urdf/box.urdf",
    "gazebo_ros_pkgs/gazebo_plugins/test2/large_models/smaller_large_model.urdf.xacro",
    "gz_sim_worlds/test/worlds/models/scheme_resource_uri/scheme_resource_uri.urdf",
    # SDF
    "gz_sim_worlds/examples/worlds/joint_controller.sdf",
    "gz_sim_worlds/examples/worlds/diff_drive.sdf",
    "gz_sim_worlds/examples/worlds/nested_model.sdf",
    "gz_sim_worlds/examples/worlds/world_joint.sdf",
    "gz_sim_worlds/examples/worlds/pendulum_links.sdf",
    "gz_sim_worlds/examples/worlds/mimic_fast_slow_pendulums_world.sdf",
    "gz_sim_worlds/examples/worlds/sensors.sdf",
    "gz_sim_worlds/examples/worlds/lights.sdf",
    "gz_sim_worlds/examples/worlds/ackermann_steering.sdf",
    "gz_sim_worlds/test/worlds/tire_drum.sdf",
    "gz_sim_worlds/test/worlds/models/nested_models/model.sdf",
    "sdformat_urdf/sdformat_test_files/models/graph_tree/graph_tree.sdf",
    "sdformat_urdf/sdformat_test_files/models/joint_revolute_axis/joint_revolute_axis.sdf",
    "gazebo_ros_pkgs/gazebo_plugins/test/p3d_test/worlds/double_pendulum.world",
    # MJCF
    "dm_control_suite/dm_control/suite/acrobot.xml",
    "dm_control_suite/dm_control/suite/cartpole.xml",
    "dm_control_suite/dm_control/suite/cheetah.xml",
    "dm_control_suite/dm_control/suite/finger.xml",
    "dm_control_suite/dm_control/suite/hopper.xml",
    "dm_control_suite/dm_control/suite/humanoid.xml",
    "dm_control_suite/dm_control/suite/manipulator.xml",
    "dm_control_suite/dm_control/suite/quadruped.xml",
    "dm_control_suite/dm_control/suite/walker.xml",
    "dm_control_suite/dm_control/suite/ball_in_cup.xml",
    "mujoco_model/car/car.xml",
    "mujoco_model/humanoid/humanoid.xml",
]
ERD_FILES = [
    "ur_description/urdf/ur5_robot.urdf",
    "ur_description/urdf/ur5_gripper.urdf",
    "panda_description/urdf/panda.urdf",
    "go1_description/urdf/go1.urdf",
    "anymal_c_simple_description/urdf/anymal.urdf",
    "talos_data/robots/talos_left_arm.urdf",
    "solo_description/robots/solo12.urdf",
    "romeo_description/urdf/romeo_small.urdf",
    "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "tiago_description/robots/tiago.urdf",
    "icub_description/robots/icub.urdf",
]


def sources() -> list[Path]:
    """Every source, in a fixed order: the samples, the corpus picks, example-robot-data's picks."""
    found = sorted(p for p in (REPO / "samples").rglob("*")
                   if p.suffix in (".body", ".urdf", ".sdf") or p.name.endswith(".urdf.xacro"))
    found += [CORPUS / f for f in CORPUS_FILES]
    found += [ERD / f for f in ERD_FILES]
    return [p for p in found if p.is_file()]


def record(root: Path) -> int:
    from click.testing import CliRunner

    from modelkit.cli import main

    root.mkdir(parents=True, exist_ok=False)
    os.chdir(root)
    runner = CliRunner()
    log: list[str] = []
    for index, src in enumerate(sources()):
        for target in TARGETS:
            out = f"{index:03d}-{target}/x.{target}"
            result = runner.invoke(main, ["convert", str(src), "-o", out], catch_exceptions=True)
            log.append(f"=== {src} -> {out}: exit {result.exit_code}")
            log.append(result.output)
            if result.exception is not None and not isinstance(result.exception, SystemExit):
                log.append(f"EXCEPTION {type(result.exception).__name__}: {result.exception}")
        print(f"{index:03d} {src}", file=sys.stderr)
    (root / "log.txt").write_text("\n".join(log), encoding="utf-8")
    return 0


def compare(a: Path, b: Path) -> int:
    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    differ = sorted(files_a ^ files_b)
    same = 0
    for rel in sorted(files_a & files_b):
        if (a / rel).read_bytes() != (b / rel).read_bytes():
            differ.append(rel)
        else:
            same += 1
    for rel in differ:
        print(f"DIFFERS {rel}")
    conversions = (a / "log.txt").read_text(encoding="utf-8").count("\n=== ") + 1
    print(f"{conversions} conversions, {same} files identical, {len(differ)} differ")
    return 1 if differ else 0


def cli() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("record").add_argument("root", type=Path)
    cmp = sub.add_parser("compare")
    cmp.add_argument("a", type=Path)
    cmp.add_argument("b", type=Path)
    sub.add_parser("list")
    args = parser.parse_args()
    if args.command == "record":
        with contextlib.redirect_stdout(io.StringIO()):
            return record(args.root.resolve())
    if args.command == "list":
        for src in sources():
            print(src)
        return 0
    return compare(args.a, args.b)


if __name__ == "__main__":
    sys.exit(cli())
