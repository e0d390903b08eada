"""The URDF writer: a robot model → URDF 1.0 bytes, with a conversion note for every loss.

Element order: robot-level materials, links (model order, then links the writer adds), joints
(model order, then joints the writer adds), ``<gazebo>`` blocks, transmissions and other kept
extensions. Pretty-printed with two-space indentation, numbers through
:func:`modelkit.convert.numbers.fmt`. The parts live in ``write_names`` (unique names, MK800),
``write_links`` (inertials, geometry, materials), ``write_joints`` (joint types, synthesised limits),
``write_frames`` (sensor links and optical frames, MK847), ``write_gazebo`` (sensors, friction,
kept extension blocks) and ``write_self_collide`` (Gazebo's self-collision flags, MK834).

How the root meets the world: URDF has no root pose and its consumers float the root unless it
hangs from a link named ``world``. A welded root (``--base``, settled in ``modelkit/convert/base.py``)
hangs from a ``world`` link by a fixed joint at ``root_pose``; with ``WriteOptions.urdf_world_link`` a
floating root hangs from it by a floating joint too; otherwise a floating root's placement is an
MK823 note. Links the tree does not reach (an SDF model's free links) hang
from the root by ``floating`` joints (MK813), since a URDF has exactly one root.
"""

from __future__ import annotations

from collections.abc import Iterable

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.contact_compliance import pybullet_compliance
from modelkit.convert.context import WriteContext
from modelkit.convert.friction import floor_friction
from modelkit.convert.notes import ConversionNote, renames
from modelkit.convert.numbers import fmt
from modelkit.convert.simulator import pybullet_settings
from modelkit.formats.registry import (
    EXTRAS_DROPPED,
    EXTRAS_DROPPED_LINK,
    EXTRAS_QUIET,
    EXTRAS_QUIET_LINK,
    carried_by,
    declared_function,
    partly_carried_by,
)
from modelkit.formats.urdf.write_frames import frame_link, sensor_frames
from modelkit.formats.urdf.write_gazebo import unnamed_shapes, write_extensions
from modelkit.formats.urdf.write_joints import joint_elements
from modelkit.formats.urdf.write_links import (
    CONTACT_EXTRAS,
    TINY_INERTIA,
    TINY_MASS,
    MaterialTable,
    link_element,
    moving_massless_inertial,
    origin_element,
)
from modelkit.formats.urdf.write_names import NameTable
from modelkit.formats.urdf.write_self_collide import write_self_collision
from modelkit.model import WORLD_LINK, JointType, Link, Robot
from modelkit.spatial import Pose

__all__ = ["urdf_renames", "write_urdf"]

# Robot extras this writer writes itself: URDF's own blocks, and SDF's plugins as <gazebo> blocks
# (write_gazebo). Other formats' keys are described by their own declarations (EXTRAS_QUIET...).
WRITTEN_EXTRAS = frozenset(
    {"materials", "urdf_version", "gazebo", "transmissions", "ros2_control", "mujoco", "sensor",
     "sdf_plugins"}
)
# What convert's passes record for every writer (modelkit.convert.wheels' WHEELS_KEY, tracks' TRACKS_KEY):
# the wheels and tracks themselves are written through their links, so nothing is left out. Noted as
# "extension data ... left out" before (MK808 on the tutorial's pan-tilt and tracked robots).
PASS_EXTRAS = frozenset({"wheels", "tracks"})
# Other formats' keys this writer carries through their own code (an SDF model's flags in <gazebo> blocks).
SILENT_EXTRAS = WRITTEN_EXTRAS | EXTRAS_QUIET | PASS_EXTRAS | carried_by("urdf")
# Link extras written elsewhere: URDF's <gazebo> blocks.
# Link extras other formats declare dropped are noted by convert itself (convert.api._foreign_extras).
SILENT_LINK_EXTRAS = (
    frozenset({"gazebo", CONTACT_EXTRAS}) | EXTRAS_QUIET_LINK | frozenset(EXTRAS_DROPPED_LINK)
)


def urdf_renames(notes: Iterable[ConversionNote]) -> dict[str, str]:
    """Source link name → written link name, from a conversion's MK800 notes (for compare_robots)."""
    return renames(notes, "link")


def write_urdf(robot: Robot, ctx: WriteContext) -> bytes:
    """The URDF file of ``robot``; meshes and textures are staged through ``ctx``."""
    # A welded root always hangs from `world` (URDF consumers float a root that does not); a floating
    # one does so only with the option.
    add_world = (
        (ctx.options.urdf_world_link
         or (ctx.options.urdf_world_link is None and robot.root_joint is JointType.FIXED))
        and robot.root not in (None, WORLD_LINK)
        and robot.root_joint in (JointType.FIXED, JointType.FLOATING)
    )
    names = NameTable(robot, ctx, reserved=(WORLD_LINK,) if add_world else ())
    materials = MaterialTable()
    links = etree.Element("links")
    if add_world:
        etree.SubElement(links, "link", name=WORLD_LINK)
    friction = floor_friction(robot)
    moving = _moving_links(robot)
    compliance, why = pybullet_compliance(robot) if ctx.options.support_contact == "compliant" else ({}, "")
    if compliance:
        ctx.note("MK861", why, robot.source, "link")
    left_unnamed: list[str] = []
    for index, link in enumerate(robot.links):
        unnamed = {kind for kind in unnamed_shapes(link, robot, friction)
                   if any(g.name for g in (link.visuals if kind == "visual" else link.collisions))}
        if unnamed:
            left_unnamed.append(f"{link.name} ({', '.join(sorted(unnamed))})")
        link_element(links, link, names.links[index], robot, ctx, materials, friction.get(link.name),
                     link.name in moving, compliance.get(link.name), unnamed)
        _link_extras(link.extras, link.name, names.links[index], ctx)
    if left_unnamed:
        ctx.note("MK879", f"{len(left_unnamed)} link(s) get their visuals or collisions written without "
                 "names, because their <gazebo> blocks give those shapes data (friction, a material "
                 "script...) and libsdformat's URDF import (Gazebo) applies it only to unnamed shapes: "
                 + ", ".join(left_unnamed[:8]) + (" ..." if len(left_unnamed) > 8 else ""), robot.source,
                 "link")
    joints: list[Element] = []
    extra_links: list[Link] = []
    for index, joint in enumerate(robot.joints):
        joints.extend(joint_elements(joint, index, names, ctx, extra_links))
    joints.extend(_root(robot, names, ctx, add_world))
    joints.extend(_free_links(robot, names, ctx))
    frames = sensor_frames(robot, names, ctx)
    joints.extend(frames.joints)
    for link in extra_links:  # a ball joint's intermediate links: massless, moving
        element = etree.SubElement(links, "link", name=link.name)
        moving_massless_inertial(element, link, ctx, f"link[{link.name}]")
    for name in frames.links:
        links.append(frame_link(name))

    out = etree.Element("robot", name=robot.name or "robot")
    materials.write(out)
    if materials.appearance_dropped:
        ctx.note(
            "MK818",
            "URDF materials hold only a colour and a texture; "
            + ", ".join(materials.appearance_dropped)
            + " left out",
            robot.source,
            "material",
        )
    for el in list(links):
        out.append(el)
    for el in joints:
        out.append(el)
    write_extensions(out, robot, names, frames, ctx)
    write_self_collision(out, robot, names.link_map, ctx)
    _pybullet_joint_limit(len(joints), robot, ctx)
    _massless(robot, names, ctx)
    _notes(robot, ctx)
    settings = pybullet_settings(robot)
    if settings:
        ctx.note(
            "MK825",
            "a URDF cannot carry simulator settings; in PyBullet set "
            + ", ".join(f"setPhysicsEngineParameter({k}={v})" for k, v in settings.items())
            + " for this robot to drive like its source (the tracks' rollers skid only then; MK809)",
            robot.source,
            "robot",
        )
    etree.indent(out, space="  ")
    text = etree.tostring(out, encoding="unicode")
    return ('<?xml version="1.0"?>\n' + text + "\n").encode("utf-8")


def _root(robot: Robot, names: NameTable, ctx: WriteContext, add_world: bool) -> list[Element]:
    """The joint to ``world`` (with the option), or the notes on what URDF cannot say about the root."""
    if robot.root is None or robot.root == WORLD_LINK:
        return []
    root = names.link(robot.root)
    out: list[Element] = []
    where = robot.root_joint_source or robot.source
    if add_world:
        word = "fixed" if robot.root_joint is JointType.FIXED else "floating"
        wanted = robot.root_joint_name or f"{WORLD_LINK}_to_{root}"
        el = etree.Element("joint", name=names.fresh(str(wanted)), type=word)
        origin_element(el, robot.root_pose)
        etree.SubElement(el, "parent", link=WORLD_LINK)
        etree.SubElement(el, "child", link=root)
        out.append(el)
        ctx.note(
            "MK814",
            f'the root "{root}" hangs from a "{WORLD_LINK}" link by the {word} joint '
            f'"{el.get("name")}" at the robot\'s placement',
            where,
            f"joint[{el.get('name')}]",
        )
        return out
    if robot.root_joint is JointType.FIXED:
        ctx.note(
            "MK814",
            f'the root "{root}" is welded to the world in the source; URDF consumers float '
            f'the root unless it hangs from a "{WORLD_LINK}" link (option urdf_world_link)',
            where,
            f"link[{root}]",
        )
    if not robot.root_pose.is_identity():
        ctx.note(
            "MK823",
            f'the robot\'s placement in the world (root "{root}") cannot be written in URDF; '
            "it is left out (option urdf_world_link writes it as the world joint's origin)",
            where,
            f"link[{root}]",
        )
    return out


def _free_links(robot: Robot, names: NameTable, ctx: WriteContext) -> list[Element]:
    """Floating joints from the root to links the tree does not reach (URDF has one root)."""
    if robot.root is None:
        return []
    children = {j.child for j in robot.joints}
    reached = set(robot.world_poses())
    free_poses = robot.free_link_poses
    out: list[Element] = []
    for index, link in enumerate(robot.links):
        if link.name in reached or link.name in children or link.name == robot.root:
            continue
        name = names.links[index]
        placed = free_poses.get(link.name)
        origin = robot.root_pose.inverse() @ placed if placed is not None else Pose()
        el = etree.Element("joint", name=names.fresh(f"{name}_free"), type="floating")
        origin_element(el, origin)
        etree.SubElement(el, "parent", link=names.link(robot.root))
        etree.SubElement(el, "child", link=name)
        out.append(el)
        ctx.note(
            "MK813",
            f'link "{link.name}" is not connected to the root; URDF has one root, so it hangs '
            f'from "{names.link(robot.root)}" by the floating joint "{el.get("name")}"',
            link.source,
            f"joint[{el.get('name')}]",
        )
    return out


def _moving_links(robot: Robot) -> set[str]:
    """The links on a joint that is not fixed."""
    return {joint.child for joint in robot.joints if joint.type is not JointType.FIXED}


# PyBullet 3.2.7 answers getJointState for a multibody of at most 127 joints, fixed ones included (its
# shared-memory status holds MAX_DEGREE_OF_FREEDOM values; measured on serial chains: 127 answer, 128
# fail with "getJointState failed" for every joint; example-robot-data's tiago_dual written with its
# sensor frames, 129 joints: every one fails).
PYBULLET_MAX_JOINTS = 127


def _pybullet_joint_limit(count: int, robot: Robot, ctx: WriteContext) -> None:
    """MK862 when PyBullet will load the file but not report its joint states."""
    if count <= PYBULLET_MAX_JOINTS:
        return
    ctx.note(
        "MK862",
        f"the URDF has {count} joints (fixed ones included); PyBullet loads it but reports the joint "
        f"states of a body of at most {PYBULLET_MAX_JOINTS} (getJointState fails for every joint): "
        "--merge-fixed or --no-urdf-sensor-links write fewer",
        robot.source,
        "joint",
    )


def _massless(robot: Robot, names: NameTable, ctx: WriteContext) -> None:
    """One note for the source's massless links that do not move (those that move have a note each):
    each carries the tiny inertial (``write_links.TINY_MASS``), so that PyBullet does not give it 1 kg
    and a unit inertia. On a massless root that is what ROS tools do not expect: KDL warns that it
    ignores an inertia on the root link; without it the robot turns on PyBullet's 1 kg·m²."""
    moving = _moving_links(robot)
    frames = [
        names.links[index]
        for index, link in enumerate(robot.links)
        if (link.inertial is None or link.inertial.mass <= 0.0) and link.name != WORLD_LINK
        and link.name not in moving
    ]
    if not frames:
        return
    text = (
        f"{len(frames)} massless link(s) written with a tiny explicit inertial ({fmt(TINY_MASS)} kg, "
        f"{fmt(TINY_INERTIA)} kg·m²; PyBullet gives a link without <inertial> 1 kg and a unit inertia): "
        f"{_listed(frames)}"
    )
    root = names.link(robot.root) if robot.root is not None else None
    if root in frames:
        text += (
            f'; on the root "{root}" robot_state_publisher (KDL) warns that it ignores the inertia '
            "(PyBullet's unit inertia on a floating root made example-robot-data's TIAGo turn 240 mrad "
            "short in 10 s)"
        )
    ctx.note("MK816", text, robot.source, "link")


def _listed(names: list[str], shown: int = 8) -> str:
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return ", ".join(f'"{n}"' for n in names[:shown]) + more


def _link_extras(extras: dict[str, object], source_name: str, name: str, ctx: WriteContext) -> None:
    for key, value in sorted(extras.items()):
        if key in SILENT_LINK_EXTRAS or not value:
            continue
        ctx.note(
            "MK808",
            f'link "{source_name}": {key} ({_short(value)}) has no URDF equivalent; left out',
            None,
            f"link[{name}]",
        )


def _short(value: object) -> str:
    text = str(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _notes(robot: Robot, ctx: WriteContext) -> None:
    """Closed loops and robot-level data of other formats that URDF cannot hold."""
    for loop in robot.loops:
        ctx.note(
            "MK810",
            f'closed-loop joint "{loop.name}" ({loop.type}) between "{loop.link1}" and '
            f'"{loop.link2}": URDF holds a tree only; it is left out',
            loop.source,
            "robot",
        )
    partly = partly_carried_by("urdf")
    for key, value in sorted(robot.extras.items()):
        if key in partly:
            # the part the model's own fields carry (an MJCF file's canonical actuators, written as
            # transmissions; cameras, lights and sensors that are devices of links) is written with them
            value = declared_function(partly[key])(value, robot)
        if key in SILENT_EXTRAS or not value:
            continue
        code, what = EXTRAS_DROPPED.get(key, ("MK808", f"extension data {key}"))
        count = f"{len(value)} " if isinstance(value, list) else ""
        ctx.note(code, f"{count}{what}: URDF has no equivalent; left out", robot.source, "robot")
