"""How a note names extras data a target leaves out: short, and without what the model carries."""

from __future__ import annotations

from typing import Any

CARRIED_BLOCK_TAGS = frozenset({"mu1", "mu2", "selfCollide", "sensor"})
"""Children of a kept extension block (a URDF ``<gazebo>``) the model holds in its own fields: the
shapes' friction, the link's self-collision flag, the link's devices. They are written, not lost."""


BOOKKEEPING = frozenset({"collision", "name", "source", "reference"})
"""Keys of a kept entry that place it rather than hold data (a collision's index, a block's link)."""


def shown_extras(value: Any) -> str:
    """An extras value in a note ("" when nothing of it is lost): a kept XML block by its children's
    tags (those the model carries left out), a plugin by its library, a dict's non-empty values as
    ``key value``, a list item by item."""
    if isinstance(value, list):
        return "; ".join(text for text in (shown_extras(v) for v in value) if text)
    if isinstance(value, dict) and "xml" in value and (value.get("filename") or value.get("name")):
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
        text = ", ".join(f"{k} {v}".rstrip() for k, v in items)
    else:
        text = str(value)
    return text if len(text) <= 120 else text[:117] + "..."
