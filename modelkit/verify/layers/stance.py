"""Layer 4: a drive wheel an engine leaves unloaded on a statically indeterminate stance.

A robot standing on more than three links (TIAGo: two drive wheels and four casters in one plane)
is statically indeterminate: rigid contact does not fix how the weight splits. Bullet's solver
picks one split, and may leave a drive wheel touching the floor with no load; that wheel then
spins in place and the robot does not follow its commands. MuJoCo's soft contacts split the weight
by penetration, so the same file drives there. Such a run measures the engine's contact solver,
not the conversion: the engine's layer-4 comparisons are reported, not graded, and a skip says why
with the loads. A wheel that does not touch at all, or that no engine loads, stays graded (a wrong
radius or pose in the written file looks like that)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from modelkit.verify.drive import Drive, Trajectory

UNLOADED_SHARE = 0.05
"""A drive wheel carrying less than this fraction of the mean load per touching link is unloaded; a
wheel carrying at least this much in another engine is loaded there."""

DETERMINATE_SUPPORTS = 3
"""Three touching links or fewer fix the split of the weight: the check does not apply."""

ENGINE_NAMES = {"mujoco": "MuJoCo", "pybullet": "PyBullet"}


@dataclass(frozen=True)
class UnloadedWheel:
    """An engine leaving a drive wheel unloaded where another engine loads it."""

    engine: str
    wheel: str  # the link's name in the engine's file
    load: float  # N, in ``engine``
    other: str
    other_load: float  # N, in ``other``
    supports: tuple[str, ...]  # the links touching the floor in ``engine``

    def reason(self) -> str:
        name, other = ENGINE_NAMES.get(self.engine, self.engine), ENGINE_NAMES.get(self.other, self.other)
        return (
            f"layer 4 not graded for {name}: at rest its rigid contacts leave the drive wheel {self.wheel} "
            f"touching the floor with {self.load:.3g} N, while {other}'s carries {self.other_load:.3g} N. "
            f"The robot stands on {len(self.supports)} links ({', '.join(self.supports)}), a statically "
            f"indeterminate stance whose split of the weight rigid contact does not fix, and {name}'s "
            "solver puts it on the others, so that wheel spins in place. This measures the engine's "
            f"contact solver, not the conversion: {name}'s layer-4 comparisons are reported, not graded "
            f"(a user driving this robot in {name} needs suspension or fewer supports)"
        )


def unloaded_wheel(
    runs: Mapping[str, Trajectory], drive: Drive, link_names: Mapping[str, Mapping[str, str]]
) -> UnloadedWheel | None:
    """The first engine (in name order) that leaves a drive wheel unloaded on an indeterminate stance
    while another engine loads it, or None. ``link_names``: per engine, source link → name in its file."""
    if drive.kind != "wheels":
        return None
    for engine, run in sorted(runs.items()):
        support = run.support
        if len(support) <= DETERMINATE_SUPPORTS:
            continue
        share = sum(support.values()) / len(support)
        for wheel in drive.wheel_links:
            name = link_names.get(engine, {}).get(wheel, wheel)
            load = support.get(name)
            if load is None or load >= UNLOADED_SHARE * share:
                continue
            for other, other_run in sorted(runs.items()):
                if other == engine:
                    continue
                other_name = link_names.get(other, {}).get(wheel, wheel)
                other_load = other_run.support.get(other_name, 0.0)
                other_share = sum(other_run.support.values()) / max(1, len(other_run.support))
                if other_load >= UNLOADED_SHARE * other_share:
                    return UnloadedWheel(engine, name, load, other, other_load, tuple(sorted(support)))
    return None
