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
* the model's ``<allow_auto_disable>`` and ``<enable_wind>``;
* what every visual of a link says alike: its Gazebo material script (the block's ``<material>``, when it
  is one of Gazebo's stock scripts, the only URI libsdformat writes) and its ``<cast_shadows>`` and
  ``<laser_retro>`` (a ``<visual>`` blob, which libsdformat puts into each visual); what every collision
  says alike, its ``<laser_retro>`` and ``<max_contacts>`` (a ``<collision>`` blob, likewise).

A flag at SDFormat's default says nothing and is left out. What a block cannot say (one visual's
script among several, a ``<pbr>``, a joint stop's ``<stiffness>``, which sits in the axis) is still
noted: :func:`materials_left` and :func:`shapes_left` give the note that part (the SDF declaration
names them). The URDF writer calls these functions: SDF's own keys stay in this package.
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.formats.sdf.kept import JOINT_KEY, MODEL_KEY, SHAPE_KEY
from modelkit.formats.sdf.write_gazebo_tags import MATERIAL_URI
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
    script = _shared_script(link)
    if script is not None:
        out.append(_text("material", script))
    for kind in ("visual", "collision"):
        shared = _shared_shape_xml(link, kind)
        if shared is not None:
            out.append(etree.fromstring(shared))
    return out


def _shared_script(link: Link) -> str | None:
    """The stock Gazebo script every visual of ``link`` names, and nothing else beyond its colours."""
    looks = link.extras.get("sdf_materials") or {}
    names = set()
    for visual in link.visuals:
        look = looks.get(visual.name or "") if visual.name else None
        if not isinstance(look, dict) or set(look) != {"script"}:
            return None
        script = look["script"]
        if not isinstance(script, dict) or script.get("uri") != [MATERIAL_URI]:  # libsdformat's only URI
            return None
        names.add(str(script.get("name", "")))
    return names.pop() if len(names) == 1 and "" not in names else None


def _shared_shape_xml(link: Link, kind: str) -> str | None:
    """The kept elements every ``kind`` shape of ``link`` has alike, as ``<kind>`` XML."""
    shapes = link.visuals if kind == "visual" else link.collisions
    kept = {str(e[kind]): str(e.get("xml")) for e in link.extras.get(SHAPE_KEY) or []
            if isinstance(e, dict) and kind in e}
    xml = {kept.get(shape.name or "") for shape in shapes}
    return xml.pop() if shapes and len(xml) == 1 and None not in xml and "None" not in xml else None


def shape_data_kinds(link: Link) -> set[str]:
    """The kinds of shape (``visual``, ``collision``) :func:`link_block` writes data for."""
    kinds = {kind for kind in ("visual", "collision") if _shared_shape_xml(link, kind) is not None}
    if _shared_script(link) is not None:
        kinds.add("visual")
    return kinds


def materials_left(value: Any, link: Link) -> Any:
    """What a URDF drops of a link's ``sdf_materials`` (visual name → material elements): all but a
    script every visual shares (:func:`link_block` writes that one)."""
    if not isinstance(value, dict) or _shared_script(link) is None:
        return value
    return {}


def shapes_left(value: Any, link: Link) -> Any:
    """What a URDF drops of a link's kept shape elements: those of a kind whose shapes differ."""
    if not isinstance(value, list):
        return value
    carried = {kind for kind in ("visual", "collision") if _shared_shape_xml(link, kind) is not None}
    return [e for e in value if not (isinstance(e, dict) and carried & e.keys())]


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
