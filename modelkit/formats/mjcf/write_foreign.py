"""Notes for the robot-level data of other formats that an MJCF file cannot hold.

The MJCF writer writes what the model's fields hold; another format's own data kept in
``Robot.extras`` (a URDF's ``<gazebo>`` plugins, its ``<mujoco>`` compiler hints, an SDF model's
plugins) has no MJCF element, and each key gets one note, with the code and words its format
declares (``EXTRAS_DROPPED``) or MK808. The keys each format declares quiet (``EXTRAS_QUIET``:
bookkeeping, and data the model's fields already carry, such as a URDF's transmissions as actuators)
and what convert's passes record (wheels, tracks) are not noted. Link and joint data are
noted by ``convert`` itself (:func:`modelkit.convert.api.prepare`).
"""

from __future__ import annotations

from modelkit.convert.context import WriteContext
from modelkit.convert.extras_notes import shown_extras
from modelkit.formats.registry import EXTRAS_DROPPED, EXTRAS_QUIET
from modelkit.model import Robot

PASS_KEYS = frozenset({"wheels", "tracks"})
"""What convert's passes record for every writer; the wheels and tracks are written with their links."""


def note_foreign_extras(robot: Robot, ctx: WriteContext) -> None:
    """One note per robot extras key of another format that the MJCF file leaves out."""
    for key in sorted(robot.extras):
        value = robot.extras[key]
        if key.startswith("mjcf_") or key in EXTRAS_QUIET or key in PASS_KEYS:
            continue
        shown = shown_extras(value)
        if not value or not shown:
            continue
        code, what = EXTRAS_DROPPED.get(key, ("MK808", f"<{key}> extension data"))
        ctx.note(code, f"{what} ({shown}): MJCF has no equivalent; left out", robot.source, "mujoco")
