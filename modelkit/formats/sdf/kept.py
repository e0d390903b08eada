"""SDF elements the robot model does not hold, kept as XML: the SDF writer writes them back, and every
other target says it drops them (``declare.py``'s ``dropped`` keys; before, they vanished without a
word in every target, SDF included).

Which (each only where it differs from SDFormat's default, so a file that spells out a default costs no
note):

* a model's ``<allow_auto_disable>`` and ``<enable_wind>`` (``robot.extras["sdf_model_elements"]``);
* a joint's ``<physics>`` (ODE's ``cfm``, ``erp``, ``provide_feedback``...; ``joint.extras
  ["sdf_joint_elements"]``) and its limit's ``<stiffness>`` and ``<dissipation>`` (the joint stop's
  contact; ``joint.extras["sdf_limit_elements"]``);
* a collision's ``<laser_retro>`` and ``<max_contacts>``, a visual's ``<cast_shadows>`` and
  ``<laser_retro>`` (``link.extras["sdf_shape_elements"]``, one entry per visual or collision).

Each value is ``{"xml": "<TAG>…children…</TAG>"}`` (a shape's entry also names it: ``{"collision":
NAME, …}``), the form the notes show by its children's tags.
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.xmlsource import bare_copy

MODEL_KEY = "sdf_model_elements"
JOINT_KEY = "sdf_joint_elements"
LIMIT_KEY = "sdf_limit_elements"
SHAPE_KEY = "sdf_shape_elements"

# tag -> SDFormat's default value (None: no default; kept whenever given)
MODEL_TAGS: dict[str, str | None] = {"allow_auto_disable": "true", "enable_wind": "false"}
JOINT_TAGS: dict[str, str | None] = {"physics": None}
LIMIT_TAGS: dict[str, str | None] = {"stiffness": "1e8", "dissipation": "1"}
SHAPE_TAGS: dict[str, dict[str, str | None]] = {
    "collision": {"laser_retro": "0", "max_contacts": "10"},
    "visual": {"cast_shadows": "true", "laser_retro": "0"},
}


def _is_default(element: Element, default: str | None) -> bool:
    if default is None or len(element):
        return False
    text = (element.text or "").strip().lower()
    if default in ("true", "false"):
        return {"1": "true", "0": "false"}.get(text, text) == default
    try:
        return float(text) == float(default)
    except ValueError:
        return False


def kept(element: Element, tags: dict[str, str | None], wrapper: str) -> str | None:
    """``element``'s children named in ``tags`` whose value is not the default, as ``<wrapper>`` XML
    (whitespace dropped: the writer indents anew); None when there are none."""
    out = etree.Element(wrapper)
    for node in element:
        if isinstance(node.tag, str) and node.tag in tags and not _is_default(node, tags[node.tag]):
            out.append(bare_copy(node))
    return etree.tostring(out, encoding="unicode") if len(out) else None


def keep(extras: dict[str, Any], key: str, element: Element, tags: dict[str, str | None],
         wrapper: str) -> None:
    """Store :func:`kept` under ``key`` when there is anything to keep."""
    xml = kept(element, tags, wrapper)
    if xml is not None:
        extras[key] = {"xml": xml}


def keep_shape(extras: dict[str, Any], kind: str, name: str | None, element: Element) -> None:
    """A visual's or collision's kept elements, appended to ``extras[SHAPE_KEY]`` with its name."""
    xml = kept(element, SHAPE_TAGS[kind], kind)
    if xml is not None and name is not None:
        extras.setdefault(SHAPE_KEY, []).append({kind: name, "xml": xml})


def write_back(parent: Element, value: Any) -> None:
    """Append the kept children of ``value`` (a ``{"xml": ...}`` entry) to ``parent``."""
    if isinstance(value, dict) and value.get("xml"):
        for node in etree.fromstring(str(value["xml"])):
            parent.append(node)


def shape_entries(extras: dict[str, Any], kind: str) -> dict[str, Any]:
    """Shape name → its kept entry, for one kind (``visual`` or ``collision``)."""
    return {str(e[kind]): e for e in extras.get(SHAPE_KEY, []) if isinstance(e, dict) and kind in e}
