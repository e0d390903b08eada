"""``--merge-fixed``: fuse links on fixed joints into their parents (placeholder)."""

from __future__ import annotations

from modelkit.convert.notes import NoteSink
from modelkit.model import Robot


def merge_fixed_joints(robot: Robot, notes: NoteSink) -> None:
    """Fuse every link hanging on a fixed joint into its parent, mass properties combined."""
    return None
