"""An SDF source's Gazebo data as the children of a URDF's ``<gazebo>`` blocks.

libsdformat's URDF import (what Gazebo runs on a URDF, and ``gz sdf -p``) copies every child of a
``<gazebo reference="LINK">`` block it has no special rule for into that link, a joint block's into
the joint and a robot-level block's into the model; ``gravity`` and ``kinematic`` it reads as the link's
flags. So SDF data a URDF has no element for still travels through a URDF and comes back in Gazebo, and
in ``convert`` back to SDF (:mod:`modelkit.formats.sdf.write_gazebo_tags` does what libsdformat does):

* a link's flags (``<gravity>``, ``<kinematic>``, ``<enable_wind>``, ``<must_be_base_link>``,
  ``<velocity_decay>``) and the elements validate keeps only as data (``<battery>``, ``<projector>``,
  ``<audio_sink>``..., MK155);
* a joint's ``<physics>`` (ODE's ``cfm``, ``erp``, ``provide_feedback``...);
* the model's ``<allow_auto_disable>`` and ``<enable_wind>``.

A flag at SDFormat's default says nothing and is left out. What stays SDF-only (a visual's
``<cast_shadows>``, a collision's ``<laser_retro>``: a block's ``<visual>`` would set every visual of
the link; a joint stop's ``<stiffness>``, which sits in the axis) is still noted by the URDF writer.
The URDF writer calls these functions: SDF's own keys stay in this package.
"""

from __future__ import annotations

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.formats.sdf.kept import JOINT_KEY, MODEL_KEY
from modelkit.formats.sdf.write_xml import data_element
from modelkit.model import Joint, Link, Robot

# SDFormat's defaults of the link flags (the reader keeps the flags a file gives, defaults included).
FLAG_DEFAULTS = {"gravity": True, "kinematic": False, "enable_wind": False, "must_be_base_link": False}


def link_block(link: Link) -> list[Element]:
    """The SDF elements of ``link`` a ``<gazebo reference>`` block carries (none: no block needed)."""
    out: list[Element] = []
    for key, value in (link.extras.get("sdf_link") or {}).items():
        if isinstance(value, bool):
            if FLAG_DEFAULTS.get(str(key)) is not value:
                out.append(_text(str(key), "true" if value else "false"))
        else:
            out.append(data_element(str(key), value))
    for entry in link.extras.get("sdf_other") or []:
        if isinstance(entry, dict) and entry.get("element"):
            out.append(data_element(str(entry["element"]), entry.get("data")))
    return out


def joint_block(joint: Joint) -> list[Element]:
    """The SDF elements of ``joint`` a ``<gazebo reference>`` block carries: its ``<physics>``."""
    return _kept(joint.extras.get(JOINT_KEY))


def model_block(robot: Robot) -> list[Element]:
    """The SDF model elements a robot-level ``<gazebo>`` block carries."""
    return _kept(robot.extras.get(MODEL_KEY))


def _kept(value: object) -> list[Element]:
    """The children of a kept entry (``{"xml": "<wrapper>…</wrapper>"}``, :mod:`.kept`)."""
    xml = value.get("xml") if isinstance(value, dict) else None
    if not isinstance(xml, str):
        return []
    try:
        wrapper = etree.fromstring(xml)
    except etree.XMLSyntaxError:
        return []
    return [node for node in wrapper if isinstance(node.tag, str)]


def _text(tag: str, text: str) -> Element:
    el = etree.Element(tag)
    el.text = text
    return el
