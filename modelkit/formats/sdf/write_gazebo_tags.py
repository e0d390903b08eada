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

A joint's block (:func:`write_joint_tags`): ``provideFeedback`` → ``<physics><provide_feedback>`` (not
also ``<physics><ode><provide_feedback>`` as libsdformat writes it: SDFormat 1.9 does not define that
one), ``implicitSpringDamper``, ``cfmDamping``, ``fudgeFactor`` →
``<physics><ode>`` ``implicit_spring_damper``, ``cfm_damping``, ``fudge_factor``, ``stopCfm``/``stopErp``
→ ``<physics><ode><limit>`` ``cfm``/``erp``, ``springStiffness``/``springReference`` → ``<axis><dynamics>``
``spring_stiffness``/``spring_reference``.

Element tags ("blobs") go where libsdformat puts them:

* ``<visual>``: each of its children into every visual of the link, a ``<material>`` replacing the
  visual's own (the URDF colour): how gz-sim users give a URDF visual its PBR or ambient/diffuse colours.
  libsdformat itself skips a visual the URDF named (its issue #333); the SDFormat documentation says
  every visual, and that is what is written here;
* ``<collision>``: each child into every collision of the link, a ``<surface>`` replacing the collision's
  own, after which the block's ``mu1``/``mu2``/``kp``... are applied again, in libsdformat's order;
* an element an SDF ``<link>`` may hold (``<light>``, ``<battery>``, ``<velocity_decay>``...): into the
  link. A ``<plugin>`` is not one (libsdformat copies it there, and Gazebo ignores it): it is noted.

What else a block holds is named in one MK808 note per link or joint.

A robot-level block (no reference, :func:`write_model_blocks`): libsdformat copies each child into the
model. Written: its ``<plugin>``s of the Gazebo the file is written for (or of neither; another Gazebo's
are named, MK848), ``<static>``, ``<allow_auto_disable>``, ``<enable_wind>`` and ``<gripper>``; its
``<self_collide>`` is the model's flag. A ros_control plugin kept this way drives the joints itself, so no
joint controllers are generated beside it (:func:`source_ros_control`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.gazebo import plugin_family
from modelkit.formats.sdf.write_self_collide import CARRIED
from modelkit.formats.sdf.write_xml import child_or_sub, sub

Copy = Any  # an lxml element copied into the SDF (lxml-stubs type it loosely)

LINK_FLAGS = {"gravity": "gravity", "kinematic": "kinematic"}
COLLISION_TAGS = {"maxContacts": ("max_contacts",), "laserRetro": ("laser_retro",),
                  "kp": ("surface", "contact", "ode", "kp"), "kd": ("surface", "contact", "ode", "kd"),
                  "maxVel": ("surface", "contact", "ode", "max_vel"),
                  "minDepth": ("surface", "contact", "ode", "min_depth"),
                  "fdir1": ("surface", "friction", "ode", "fdir1")}
MATERIAL_URI = "file://media/materials/scripts/gazebo.material"


def _blocks(entries: object) -> Iterator[Element]:
    """The kept ``<gazebo>`` blocks, parsed, in order."""
    for entry in entries if isinstance(entries, list) else []:
        try:
            block = etree.fromstring(str(entry.get("xml", ""))) if isinstance(entry, dict) else None
        except etree.XMLSyntaxError:
            continue
        if block is not None:
            yield block


def _block_tags(block: Element) -> Iterator[tuple[Element, str, str, bool]]:
    """Each tag of one block: the element, its name, its text, and whether it is a plain value (a text
    and no child elements), in order."""
    for tag_el in block:
        if isinstance(tag_el.tag, str):
            text = " ".join((tag_el.text or "").split())
            yield tag_el, tag_el.tag, text, bool(text) and not len(tag_el)


def _truth(text: str) -> bool:
    return text.lower() in ("true", "1")


# What an SDF <link> may hold that a block can give as a blob (sensor is carried as a device, the flags
# gravity, kinematic and self_collide as plain tags). Not <plugin>: libsdformat copies it into the link, but
# SDFormat defines no link plugins and Gazebo loads none there (the note says so).
LINK_BLOBS = frozenset({"light", "projector", "battery", "audio_source", "audio_sink",
                        "particle_emitter", "velocity_decay", "enable_wind", "must_be_base_link"})
SHAPE_BLOBS = {"visual": "material", "collision": "surface"}  # the one child each replaces


def write_link_tags(link_el: Element, entries: object) -> list[str]:
    """Write the tags of a link's ``<gazebo>`` blocks into ``link_el`` (its visuals and collisions are
    written already); return the tags left out, in order."""
    left: list[str] = []
    for block in _blocks(entries):
        tags = list(_block_tags(block))
        for tag_el, tag, _, _ in tags:  # libsdformat: a block's shape blobs first, then its plain tags
            if tag in SHAPE_BLOBS:
                _insert_into_shapes(link_el, tag_el, tag)
        surface_blob = any(tag == "collision" and tag_el.find("surface") is not None
                           for tag_el, tag, _, _ in tags)
        for tag_el, tag, text, plain in tags:
            if tag in SHAPE_BLOBS:
                continue
            if tag in CARRIED:
                if surface_blob and plain and tag in ("mu1", "mu2"):  # the blob's surface replaced them
                    for collision in link_el.findall("collision"):
                        _set_path(collision, ("surface", "friction", "ode", "mu" if tag == "mu1" else "mu2"),
                                  text)
                continue
            if not plain:
                if tag in LINK_BLOBS:
                    link_el.append(_copy(tag_el))
                elif tag not in left:
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
            elif tag in LINK_BLOBS:
                link_el.append(_copy(tag_el))
            elif tag not in left:
                left.append(tag)
    return left


def why_left_out(left: list[str]) -> str:
    """What the note on a link block's left-out tags adds for the tags it knows: a plugin (SDFormat has
    no link plugins) and a joint's tags (libsdformat reads them only in a joint's block)."""
    said = ""
    if "plugin" in left:
        said += ("; SDFormat has no link plugins and Gazebo loads none from a link: put the plugin in a "
                 "<gazebo> block without reference (the model)")
    misplaced = [tag for tag in left if tag in JOINT_TAGS or tag in AXIS_TAGS]
    if misplaced:
        said += (f"; {', '.join(f'<{t}>' for t in misplaced)} is a joint's tag, which libsdformat (and so "
                 "Gazebo) reads only in a joint's block: move it to <gazebo reference=\"JOINT\">")
    return said


def _insert_into_shapes(link_el: Element, blob: Element, kind: str) -> None:
    """Each child of a ``<visual>`` or ``<collision>`` blob into every such shape of the link; the
    blob's ``<material>`` (``<surface>``) replaces the shape's own."""
    replaced = SHAPE_BLOBS[kind]
    for shape in link_el.findall(kind):
        for child in blob:
            if not isinstance(child.tag, str):
                continue
            if child.tag == replaced:
                for old in shape.findall(replaced):
                    shape.remove(old)
            shape.append(_copy(child))


def _copy(element: Element) -> Copy:
    """A copy of a blob element without its source's tail text, comments or namespace declarations."""
    copied: Copy = etree.fromstring(etree.tostring(element, with_tail=False))
    for comment in copied.xpath("//comment()"):
        comment.getparent().remove(comment)
    etree.cleanup_namespaces(copied)  # the URDF's xmlns:xacro... declarations, which nothing here uses
    return copied


# provideFeedback: libsdformat's own URDF parser also writes <physics><ode><provide_feedback>, which
# SDFormat 1.9 (the version written) does not define: libsdformat copies it with a warning, Drake refuses
# the file (example-robot-data's TIAGo, converted, failed verify's Drake load on it). Only the defined one.
JOINT_TAGS = {"provideFeedback": (("physics", "provide_feedback"),),
              "implicitSpringDamper": (("physics", "ode", "implicit_spring_damper"),),
              "cfmDamping": (("physics", "ode", "cfm_damping"),),
              "fudgeFactor": (("physics", "ode", "fudge_factor"),),
              "stopCfm": (("physics", "ode", "limit", "cfm"),),
              "stopErp": (("physics", "ode", "limit", "erp"),)}
AXIS_TAGS = {"springStiffness": "spring_stiffness", "springReference": "spring_reference"}
BOOLEAN_JOINT_TAGS = frozenset({"provideFeedback", "implicitSpringDamper", "cfmDamping"})


JOINT_BLOBS = frozenset({"physics"})  # what libsdformat copies into the joint that a joint holds once


def write_joint_tags(joint_el: Element, entries: object) -> list[str]:
    """Write the tags of a joint's ``<gazebo>`` blocks into ``joint_el`` (its axis written already);
    return the tags left out, in order (a spring on a joint without an axis among them). A block's
    ``<physics>`` (what a URDF written from SDF carries, :mod:`.gazebo_blocks`) goes into the joint first,
    replacing one written before; the block's ``stopCfm``... then set their values in it."""
    left: list[str] = []
    axis = joint_el.find("axis")
    for block in _blocks(entries):
        tags = list(_block_tags(block))
        for tag_el, tag, _, plain in tags:
            if tag in JOINT_BLOBS and not plain:
                for old in joint_el.findall(tag):
                    joint_el.remove(old)
                joint_el.append(_copy(tag_el))
        for _, tag, text, plain in tags:
            if tag in JOINT_BLOBS and not plain:
                continue
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


# What a URDF robot-level <gazebo> block (no reference) may give an SDF <model>: libsdformat copies every
# child into the model. These are written: a plugin of the Gazebo the file is written for (or of neither),
# and the model elements below; self_collide is the model's flag (written by the self-collision policy).
MODEL_BLOBS = frozenset({"static", "allow_auto_disable", "enable_wind", "gripper"})
ROS_CONTROL_WORDS = ("ros_control", "ros2_control")


@dataclass
class ModelBlocks:
    """What :func:`write_model_blocks` did: the plugins left out as another Gazebo's (name, filename,
    family) and the other tags left out."""

    other_family: list[tuple[str, str, str]] = field(default_factory=list)
    left: list[str] = field(default_factory=list)


def _tag_name(element: Element) -> str:
    """The tag as written: ``controller:gazebo_ros_p3d`` for Gazebo 1.0's namespaced elements."""
    qname = etree.QName(element)
    return f"{element.prefix}:{qname.localname}" if element.prefix else qname.localname


def _kept_plugin(element: Element, family: str) -> bool:
    """A robot-level block's ``<plugin>`` of the Gazebo ``family`` or of neither."""
    return plugin_family(element.get("filename", "")) in (None, family)


def source_ros_control(entries: object, family: str) -> Element | None:
    """The URDF's robot-level ros_control plugin (``gazebo_ros2_control``, ``gz_ros2_control``...) that
    :func:`write_model_blocks` writes for Gazebo ``family``, if any: it drives the joints itself."""
    for block in _blocks(entries):
        if block.get("reference"):
            continue
        for tag_el, tag, _, _ in _block_tags(block):
            text = f'{tag_el.get("filename", "")} {tag_el.get("name", "")}'.lower()
            if tag == "plugin" and _kept_plugin(tag_el, family) and any(w in text for w in ROS_CONTROL_WORDS):
                return tag_el
    return None


def write_model_blocks(model_el: Element, entries: object, family: str) -> ModelBlocks:
    """Write the children of a URDF's robot-level ``<gazebo>`` blocks into ``model_el`` as libsdformat
    does (a copy each), except a plugin of the other Gazebo and what an SDF model cannot hold."""
    done = ModelBlocks()
    for block in _blocks(entries):
        if block.get("reference"):
            continue
        for tag_el, _, _, _ in _block_tags(block):
            name = _tag_name(tag_el)
            if name == "self_collide":
                continue
            if name == "plugin":
                filename = tag_el.get("filename", "")
                if _kept_plugin(tag_el, family):
                    model_el.append(_copy(tag_el))
                else:
                    done.other_family.append((tag_el.get("name", ""), filename,
                                              plugin_family(filename) or ""))
            elif name in MODEL_BLOBS:
                model_el.append(_copy(tag_el))
            elif name not in done.left:
                done.left.append(name)
    return done
