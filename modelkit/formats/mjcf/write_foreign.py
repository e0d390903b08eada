"""MJCF to MJCF: which of the source's own elements kept as data the output does not hold again.

Sites, cameras, lights and sensors are written back by :mod:`.write_own`, tendons by
:mod:`.write_transmissions`; each says which it could not write. Keyframes other than ``home``,
equalities other than joint couplings and world geoms are not written back, and count as written when
an element of their kind has their name.

Another format's data is noted by ``convert`` itself
(:func:`modelkit.convert.extras_notes.note_foreign_extras`).
"""

from __future__ import annotations

from typing import Any

from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.formats.registry import EXTRAS_DROPPED
from modelkit.model import Robot

OWN_ELEMENTS = {  # an MJCF source's kept lists → the output elements that may hold them again
    "mjcf_sensors": "sensor",
    "mjcf_sites": "site",
    "mjcf_world_sites": "site",
    "mjcf_cameras": "camera",
    "mjcf_lights": "light",
    "mjcf_keyframes": "key",
    "mjcf_equalities": "equality",
    "mjcf_world_geoms": "geom",
    "mjcf_tendons": "tendon",
}
WRITTEN_BACK = frozenset(  # what write_own and write_transmissions write back when what it names is written
    {"mjcf_sensors", "mjcf_sites", "mjcf_world_sites", "mjcf_cameras", "mjcf_lights", "mjcf_tendons"}
)
WHY = "only what the model holds (devices on links, frames, the home keyframe, mimic joints) is"
WHY_WRITE_OWN = (  # the kinds write_own and write_transmissions write back
    "the body each is on, or an object it names (a tendon, a joint not written as one hinge or slide, a body "
    "written at another frame...), is not in the output (user, plugin, contact and tactile sensors are "
    "never written back)"
)


def note_unwritten_own(
    root: Element, robot: Robot, ctx: WriteContext, unwritten: dict[str, list[dict[str, Any]]] | None = None
) -> None:
    """MJCF to MJCF: what of the source's own elements kept as data (sensors, sites, cameras, lights,
    keyframes, equalities, world geoms, tendons) the output does not hold again, by name; one note per
    kind with the code and words the MJCF declaration gives.

    ``unwritten``: for the kinds :mod:`.write_own` writes back, what it could not write (an object a
    sensor names is missing...); the other kinds count as written when an element of their kind has
    their name."""
    if robot.source_format != "mjcf":
        return
    unwritten = unwritten or {}
    written: dict[str, set[str]] = {}
    for element in root.iter():
        if isinstance(element.tag, str) and element.get("name"):
            written.setdefault(_kind(element), set()).add(str(element.get("name")))
    for key in OWN_ELEMENTS:
        kept = robot.extras.get(key) or []
        kind = OWN_ELEMENTS[key]
        lost = unwritten[key] if key in unwritten else [
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
            + (WHY_WRITE_OWN if key in unwritten and key in WRITTEN_BACK else WHY),
            robot.source,
            kind,
        )


def _kind(element: Element) -> str:
    """The kind of a written element as ``OWN_ELEMENTS`` names it (a sensor by its section)."""
    parent = element.getparent()
    if parent is not None and isinstance(parent.tag, str) and parent.tag in ("sensor", "equality"):
        return str(parent.tag)
    return str(element.tag)
