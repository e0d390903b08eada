"""Layer 4's harness overhead: each driver against a bare loop of its own engine (``bench/``).

Above the engines and the variant writer (it drives both engines), so that neither imports the
other.
"""

from __future__ import annotations

from pathlib import Path

from modelkit.model import Robot
from modelkit.verify.drive import Drive, Profile, Scenario
from modelkit.verify.drive.variant import write_variant
from modelkit.verify.engines import mujoco as engine_mujoco
from modelkit.verify.engines import pybullet as engine_pybullet


def bench(robot: Robot, drive: Drive, scenario: Scenario, out_dir: Path, profile: Profile | None = None,
          factory: str | None = None) -> dict[str, float]:
    """Layer 4's harness overhead on one model: wall seconds of one profile (settle + duration) run by
    each driver (controllers every step, samples) and of a bare stepping loop of the same engine on the
    same world over the same simulated time; ``*_ratio`` = bare / harness (1 = no overhead),
    ``*_realtime`` = simulated seconds per wall second inside the harness; ``*_closed_ratio`` =
    a minimal hand-written closed loop with the same controllers (read, control, step: verification.md
    §4's "closed loop") / harness, i.e. the harness's own overhead. PyBullet's figures are the
    child's own loop times (no pipe)."""
    profile = profile or scenario.profiles[0]
    files, maps = write_variant(robot, drive, scenario, out_dir, "sphere")
    simulated = profile.settle + profile.duration
    out: dict[str, float] = {"simulated_s": simulated}
    mj = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=drive, scenario=scenario, factory=factory)
    mj.run(profile, scenario, drive)  # warm-up
    mj.run(profile, scenario, drive)
    harness, loops = mj.last_wall, mj.bench(simulated)
    bare, closed = loops["bare"], loops["closed_loop"]
    out.update(mujoco_harness_s=harness, mujoco_bare_s=bare, mujoco_ratio=bare / harness,
               mujoco_closed_loop_s=closed, mujoco_closed_ratio=closed / harness,
               mujoco_realtime=simulated / harness, mujoco_bare_realtime=simulated / bare)
    pb = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=drive, scenario=scenario, factory=factory)
    try:
        pb.start([profile, profile], scenario, drive)
        pb.result()
        harness, loops = pb.last_wall[-1], pb.bench(simulated, (profile.commands or (None,))[0])
        bare, closed = loops["bare"], loops["closed_loop"]
    finally:
        pb.close()
    out.update(pybullet_harness_s=harness, pybullet_bare_s=bare, pybullet_ratio=bare / harness,
               pybullet_closed_loop_s=closed, pybullet_closed_ratio=closed / harness,
               pybullet_realtime=simulated / harness, pybullet_bare_realtime=simulated / bare)
    return out
