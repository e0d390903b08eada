"""Notes for another format's own data (``extras``) that a target cannot hold, and how they name it.

Each format declares its keys once (``ExtrasDeclaration``: ``dropped``, ``dropped_link``,
``dropped_joint``, ``partly_carried``); :func:`note_foreign_extras` gives one note per such key a
conversion meets, for every target but the owner, unless the target's writer notes the key itself
(``OutputDeclaration.handles``; ``walks_extras``: the URDF writer, which notes every robot key).
A note lists what is lost, not what the model carries.
"""

from __future__ import annotations

from typing import Any

from modelkit.convert.notes import NoteSink
from modelkit.model import Robot

CARRIED_BLOCK_TAGS = frozenset({"mu1", "mu2", "selfCollide", "self_collide", "sensor"})
"""Children of a kept extension block (a URDF ``<gazebo>``) the model holds in its own fields: the
shapes' friction, the link's self-collision flag, the link's devices. They are written, not lost."""


BOOKKEEPING = frozenset({"collision", "name", "source", "reference"})
"""Keys of a kept entry that place it rather than hold data (a collision's index, a block's link)."""


def shown_extras(value: Any, records: bool = False) -> str:
    """An extras value in a note ("" when nothing of it is lost): a kept XML block by its children's
    tags (those the model carries left out), a plugin by its library, a dict's non-empty values as
    ``key value``, a list item by item; with ``records``, a list of a reader's records (a robot's MJCF
    tendons, equalities, keyframes) by their names, or their count."""
    if isinstance(value, list) and value and all(isinstance(v, int | float) for v in value):
        return _plain(value)  # numbers: a range, a vector
    if records and isinstance(value, list) and value and all(_record(v) for v in value):
        # a reader's records (MJCF tendons, equalities, keyframes): their names, else how many
        names = [str(v["name"]) for v in value if v.get("name")]
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        return f"{len(value)}: {shown}" if names else str(len(value))
    if isinstance(value, list):
        return "; ".join(text for text in (shown_extras(v) for v in value) if text)
    if isinstance(value, dict) and "element" in value and "data" in value:
        text = f"<{value['element']}>"  # an element kept only as data (an SDF link's <audio_sink>)
    elif isinstance(value, dict) and "xml" in value and (value.get("filename") or value.get("name")):
        text = str(value.get("filename") or value.get("name"))  # a plugin: by its library or name
    elif isinstance(value, dict) and "xml" in value:
        from lxml import etree

        try:
            block = etree.fromstring(str(value.get("xml", "")))
        except etree.XMLSyntaxError:
            return "an extension block"
        tags = [c.tag for c in block if isinstance(c.tag, str) and c.tag not in CARRIED_BLOCK_TAGS]
        text = ", ".join(f"<{t}>" for t in dict.fromkeys(tags))
    elif isinstance(value, dict):
        items = sorted(
            ((k, v) for k, v in value.items() if v not in (None, "", [], {}) and k not in BOOKKEEPING),
            key=lambda kv: str(kv[0]),
        )
        text = ", ".join(f"{k} {_plain(v)}".rstrip() for k, v in items)
    else:
        text = _plain(value)
    return text if len(text) <= 120 else text[:117] + "..."


def _record(value: Any) -> bool:
    """A dict that is a reader's record of one element (not a kept XML block, plugin or data element)."""
    return isinstance(value, dict) and "xml" not in value and not {"element", "data"} <= value.keys()


def _plain(value: Any) -> str:
    """A kept value as a person writes it: ``true``, ``0.1``, ``1 0 0 1``, ``(linear 0.1)``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list | tuple) and all(isinstance(v, int | float) for v in value):
        return " ".join(_plain(float(v)) if not isinstance(v, bool) else _plain(v) for v in value)
    if isinstance(value, dict):
        return "(" + ", ".join(f"{k} {_plain(v)}" for k, v in value.items()) + ")"
    if isinstance(value, list | tuple):
        return " ".join(_plain(v) for v in value)
    return str(value)


def note_foreign_extras(robot: Robot, target: str, notes: NoteSink) -> None:
    """One note per robot, link and joint extras key another format declares dropped."""
    from modelkit.formats.registry import (
        EXTRAS_DEFAULTS,
        EXTRAS_DROPPED,
        EXTRAS_DROPPED_JOINT,
        EXTRAS_DROPPED_LINK,
        EXTRAS_OWNER,
        EXTRAS_PARTLY_CARRIED,
        carried_by,
        declared,
        declared_function,
        partly_carried_by,
    )

    output = declared(target).output
    carried = carried_by(target)
    handled = (output.handles if output is not None else frozenset()) | carried
    handled_joint = (output.handles_joint if output is not None else frozenset()) | carried
    found: list[tuple[str, str, str, Any, Any, str]] = []  # owner, code, words, value, source, target
    # a dict value's entries that say only the owner's default are no loss (EXTRAS_DEFAULTS)
    partly = partly_carried_by(target)
    if output is None or not output.walks_extras:
        for key in sorted(robot.extras):
            if key not in EXTRAS_OWNER or key in handled:
                continue
            if key in EXTRAS_PARTLY_CARRIED and key not in partly:
                continue  # only a writer that walks extras can count what it carries of it
            code, what = EXTRAS_DROPPED[key]
            value = _without_defaults(robot.extras[key], EXTRAS_DEFAULTS.get(key))
            if key in partly:  # what the target's writer carries of it is no loss
                value = declared_function(partly[key])(value, robot)
            found.append((EXTRAS_OWNER[key], code, what, value, robot.source, "robot"))
    elements: list[tuple[str, Any, dict[str, tuple[str, str, str]], frozenset[str]]] = [
        *(("link", link, EXTRAS_DROPPED_LINK, handled) for link in robot.links),
        *(("joint", joint, EXTRAS_DROPPED_JOINT, handled_joint) for joint in robot.joints),
    ]
    for kind, element, table, skip in elements:
        for key in sorted(element.extras):
            if key in table and key not in skip:
                owner, code, what = table[key]
                value = _without_defaults(element.extras[key], EXTRAS_DEFAULTS.get(key))
                if key in partly:  # what the target's writer carries of it is no loss
                    value = declared_function(partly[key])(value, element)
                found.append((owner, code, f"{kind} {element.name}: {what}", value,
                              element.source, f"{kind}[{element.name}]"))
    for owner, code, what, value, source, where in found:
        shown = shown_extras(value, records=where == "robot") if owner != target and value else ""
        if shown:
            notes.note(code, f"{what} ({shown}): no {target} equivalent; left out", source, where)


def _without_defaults(value: Any, defaults: dict[str, object] | None) -> Any:
    """``value`` without the dict entries equal to the owning format's defaults."""
    if not defaults or not isinstance(value, dict):
        return value
    return {k: v for k, v in value.items() if k not in defaults or defaults[k] != v}
