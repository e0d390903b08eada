"""The part of a mimic leader's range that keeps its follower inside the follower's own range.

A mimic sets ``follower = multiplier × leader + offset``. Used by validate's MK326 (the hint) and by the
MJCF writer, which gives a leader's position servo only that part as its ``ctrlrange`` (MK828).
"""

from __future__ import annotations

MIMIC_RANGE_SLACK = 1e-6
"""rad or m: how far a mimic may carry its follower past the follower's range over the leader's range
before it counts (ranges are often written to 6 digits)."""


def leader_range_within(multiplier: float, offset: float, leader: tuple[float, float],
                        follower: tuple[float, float]) -> tuple[float, float] | None:
    """The part of the leader's range whose image stays in the follower's (None: none)."""
    if multiplier == 0.0:
        return leader if follower[0] <= offset <= follower[1] else None
    bounds = sorted(((follower[0] - offset) / multiplier, (follower[1] - offset) / multiplier))
    low, high = max(leader[0], bounds[0]), min(leader[1], bounds[1])
    return (low + 0.0, high + 0.0) if low <= high else None  # + 0.0: no "-0"
