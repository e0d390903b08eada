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

from lxml.etree import _Element as Element

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


OWN_ELEMENTS = {  # an MJCF source's kept lists → the output elements that may hold them again
    "mjcf_sensors": ("sensor", None),
    "mjcf_sites": ("site", None),
    "mjcf_world_sites": ("site", None),
    "mjcf_cameras": ("camera", None),
    "mjcf_lights": ("light", None),
    "mjcf_keyframes": ("key", None),
    "mjcf_equalities": ("equality", None),
    "mjcf_world_geoms": ("geom", None),
}


def note_unwritten_own(root: Element, robot: Robot, ctx: WriteContext) -> None:
    """MJCF to MJCF: what of the source's own elements kept as data (sensors, sites, cameras, lights,
    keyframes, equalities, world geoms) the output does not hold again, by name; one note per kind
    with the code and words the MJCF declaration gives (a tendon is reported by the reader, MK172)."""
    if robot.source_format != "mjcf":
        return
    written: dict[str, set[str]] = {}
    for element in root.iter():
        if isinstance(element.tag, str) and element.get("name"):
            written.setdefault(_kind(element), set()).add(str(element.get("name")))
    for key in OWN_ELEMENTS:
        kept = robot.extras.get(key) or []
        kind = OWN_ELEMENTS[key][0]
        lost = [
            item
            for item in kept
            if not isinstance(item, dict) or item.get("name") not in written.get(kind, set())
        ]
        if not lost:
            continue
        code, what = EXTRAS_DROPPED.get(key, ("MK808", key))
        shown = ", ".join(
            sorted({str(i.get("name") or i.get("type") or "unnamed") for i in lost if isinstance(i, dict)})[
                :6
            ]
        )
        ctx.note(
            code,
            f"{len(lost)} of {len(kept)} {what} not written ({shown}{', ...' if len(lost) > 6 else ''}): "
            "only what the model holds (devices on links, frames, the home keyframe, mimic joints) is",
            robot.source,
            kind,
        )


def _kind(element: Element) -> str:
    """The kind of a written element as ``OWN_ELEMENTS`` names it (a sensor by its section)."""
    parent = element.getparent()
    if parent is not None and isinstance(parent.tag, str) and parent.tag in ("sensor", "equality"):
        return str(parent.tag)
    return str(element.tag)
