"""SDF writer: a URDF link's ``<gazebo reference>`` tags written as the SDF elements Gazebo reads them as.

A URDF made for Gazebo keeps its simulation settings in ``<gazebo reference="LINK">`` blocks, and
libsdformat's URDF parser (what ``gz sdf -p`` and Gazebo's URDF spawning run) turns each tag into an
SDF element. ``convert`` from URDF to SDF does the same for the tags below; before, only ``mu1``,
``mu2``, ``selfCollide`` and ``<sensor>`` were carried and the rest of the block was dropped with one
note ("not carried over"):

* ``gravity`` → the link's ``<gravity>``; ``turnGravityOff`` → ``<gravity>`` negated;
* ``kinematic`` → ``<kinematic>``; ``dampingFactor`` → ``<velocity_decay>`` ``<linear>`` and
  ``<angular>``, both that factor (libsdformat's own rule);
* on every collision of the link: ``maxContacts`` → ``<max_contacts>``, ``laserRetro`` →
  ``<laser_retro>``, ``kp``/``kd``/``maxVel``/``minDepth`` → ``<surface><contact><ode>`` ``kp``, ``kd``,
  ``max_vel``, ``min_depth``, ``fdir1`` → ``<surface><friction><ode><fdir1>``;
* ``material`` (a Gazebo classic material script name, ``Gazebo/Red``) → each visual's ``<material>``
  ``<script>`` with that name and Gazebo's stock ``gazebo.material`` URI (the colour stays as the
  diffuse colour, which gz-sim uses).

A joint's block (:func:`write_joint_tags`): ``provideFeedback`` → ``<physics><provide_feedback>`` and
``<physics><ode><provide_feedback>``, ``implicitSpringDamper``, ``cfmDamping``, ``fudgeFactor`` →
``<physics><ode>`` ``implicit_spring_damper``, ``cfm_damping``, ``fudge_factor``, ``stopCfm``/``stopErp``
→ ``<physics><ode><limit>`` ``cfm``/``erp``, ``springStiffness``/``springReference`` → ``<axis><dynamics>``
``spring_stiffness``/``spring_reference``.

What else a block holds (``<plugin>``, ``<visual>``...) is named in one MK808 note per link or joint.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.formats.sdf.write_self_collide import CARRIED
from modelkit.formats.sdf.write_xml import child_or_sub, sub

LINK_FLAGS = {"gravity": "gravity", "kinematic": "kinematic"}
COLLISION_TAGS = {"maxContacts": ("max_contacts",), "laserRetro": ("laser_retro",),
                  "kp": ("surface", "contact", "ode", "kp"), "kd": ("surface", "contact", "ode", "kd"),
                  "maxVel": ("surface", "contact", "ode", "max_vel"),
                  "minDepth": ("surface", "contact", "ode", "min_depth"),
                  "fdir1": ("surface", "friction", "ode", "fdir1")}
OTHER_TAGS = frozenset({"turnGravityOff", "dampingFactor", "material"})
MATERIAL_URI = "file://media/materials/scripts/gazebo.material"
WRITTEN = frozenset(LINK_FLAGS) | frozenset(COLLISION_TAGS) | OTHER_TAGS | CARRIED


def _tags(entries: object) -> Iterator[tuple[str, str, bool]]:
    """Each tag of the kept ``<gazebo>`` blocks: its name, its text, and whether it is a plain value (a
    text and no child elements), in order."""
    for entry in entries if isinstance(entries, list) else []:
        try:
            block = etree.fromstring(str(entry.get("xml", ""))) if isinstance(entry, dict) else None
        except etree.XMLSyntaxError:
            continue
        for tag_el in block if block is not None else []:
            if isinstance(tag_el.tag, str):
                text = " ".join((tag_el.text or "").split())
                yield tag_el.tag, text, bool(text) and not len(tag_el)


def _truth(text: str) -> bool:
    return text.lower() in ("true", "1")


def write_link_tags(link_el: Element, entries: object) -> list[str]:
    """Write the tags of a link's ``<gazebo>`` blocks into ``link_el`` (its visuals and collisions are
    written already); return the tags left out, in order."""
    left: list[str] = []
    for tag, text, plain in _tags(entries):
        if tag in CARRIED:
            continue
        if not plain:
            if tag not in left:
                left.append(tag)
            continue
        if tag in LINK_FLAGS:
            _set(link_el, LINK_FLAGS[tag], "true" if _truth(text) else "false")
        elif tag == "turnGravityOff":
            _set(link_el, "gravity", "false" if _truth(text) else "true")
        elif tag == "dampingFactor":
            decay = child_or_sub(link_el, "velocity_decay")
            _set(decay, "linear", text)
            _set(decay, "angular", text)
        elif tag in COLLISION_TAGS:
            for collision in link_el.findall("collision"):
                _set_path(collision, COLLISION_TAGS[tag], text)
        elif tag == "material":
            for visual in link_el.findall("visual"):
                _set_path(visual, ("material", "script", "uri"), MATERIAL_URI)
                _set_path(visual, ("material", "script", "name"), text)
        elif tag not in left:
            left.append(tag)
    return left


JOINT_TAGS = {"provideFeedback": (("physics", "provide_feedback"), ("physics", "ode", "provide_feedback")),
              "implicitSpringDamper": (("physics", "ode", "implicit_spring_damper"),),
              "cfmDamping": (("physics", "ode", "cfm_damping"),),
              "fudgeFactor": (("physics", "ode", "fudge_factor"),),
              "stopCfm": (("physics", "ode", "limit", "cfm"),),
              "stopErp": (("physics", "ode", "limit", "erp"),)}
AXIS_TAGS = {"springStiffness": "spring_stiffness", "springReference": "spring_reference"}
BOOLEAN_JOINT_TAGS = frozenset({"provideFeedback", "implicitSpringDamper", "cfmDamping"})


def write_joint_tags(joint_el: Element, entries: object) -> list[str]:
    """Write the tags of a joint's ``<gazebo>`` blocks into ``joint_el`` (its axis written already);
    return the tags left out, in order (a spring on a joint without an axis among them)."""
    left: list[str] = []
    axis = joint_el.find("axis")
    for tag, text, plain in _tags(entries):
        if plain and tag in JOINT_TAGS:
            value = ("true" if _truth(text) else "false") if tag in BOOLEAN_JOINT_TAGS else text
            for path in JOINT_TAGS[tag]:
                _set_path(joint_el, path, value)
        elif plain and tag in AXIS_TAGS and axis is not None:
            _set_path(axis, ("dynamics", AXIS_TAGS[tag]), text)
        elif tag not in left:
            left.append(tag)
    return left


def _set_path(root: Element, path: tuple[str, ...], text: str) -> None:
    """The element at ``path`` below ``root`` (made where missing) holding ``text``."""
    for part in path[:-1]:
        root = child_or_sub(root, part)
    _set(root, path[-1], text)


def _set(parent: Element, tag: str, text: str) -> None:
    """``parent``'s child ``tag`` holding ``text`` (a later block's value wins, as in libsdformat)."""
    found: Any = parent.find(tag)
    if found is None:
        found = sub(parent, tag)
    found.text = text
