"""Pseudo continuous tracks for targets that have none (placeholder until the roller model lands)."""

from __future__ import annotations

from modelkit.convert.notes import NoteSink
from modelkit.model import Robot


def approximate_tracks(robot: Robot, notes: NoteSink) -> None:
    """Replace every pseudo continuous track by a documented approximation, with a note."""
    return None
