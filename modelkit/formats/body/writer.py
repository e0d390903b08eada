"""The Choreonoid `.body` writer (format 2.0): ``write_body(robot, ctx) -> bytes``.

What it writes, and the choices made (body-format.md is the specification):

* Header ``format: ChoreonoidBody``, ``format_version: 2.0``, ``angle_unit: degree``. Radians are
  refused with version 2.0 (§1.3, MK113), so every angle is written in degrees; ``fmt`` prints 15
  significant digits, so a read-back differs from the model by a few units in the last place.
* Links in Choreonoid's own order (depth-first from the root, siblings in joint order). A link's
  ``translation``/``rotation`` is its joint origin (the root's: ``root_pose``); rotations are
  axis-angle ``[ x, y, z, degrees ]``. Root: ``free`` when ``root_joint`` is FLOATING, ``fixed`` when
  FIXED; a root the source leaves open (URDF) is written ``free`` with an MK814 note.
* Joints: fixed, revolute, prismatic, free (a floating joint inside the tree: Choreonoid splits the
  subtree off as a free body, which is what the model means), pseudo_continuous_track (kept: this
  target has tracks). Planar and ball joints → fixed (MK813). ``joint_name`` only when it differs
  from the link name; ``joint_range`` always for moving joints (``[ unlimited, unlimited ]`` where infinite).
  No joint damping or friction (MK820), armature only on revolute and prismatic joints (MK820), no
  springs (MK854, :mod:`modelkit.convert.joint_springs`).
* Mass: explicit ``mass``/``center_of_mass``/``inertia`` (9 numbers) on every link, ``mass: 0`` for a
  link without an inertial, so no Choreonoid default (1 kg, identity inertia) applies by accident.
  An inertial the source left to those defaults (``Inertial.defaulted``) stays implicit: the keys
  the default covers are omitted, which means the same thing in the written file.
* Shapes (:mod:`write_shapes`), devices (:mod:`write_devices`), loops → ``extra_joints``. Meshes go
  through ``ctx.meshes`` with STL, OBJ and COLLADA readable: STL/OBJ files are copied; COLLADA, which
  Choreonoid reads through Assimp, is copied with ``keep_collada`` and otherwise converted to STL
  with its ``<unit>`` applied (MK804; the shared rule for every target; it loses the file's own
  colours); VRML and meshes with a fragment or metadata are converted.
* Renames (MK800): only an empty or repeated link name, or a repeated joint name, is changed
  (``name_2`` ...); :func:`body_renames` gives the map for comparisons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import describe, link_surface
from modelkit.convert.joint_springs import note_spring_dropped
from modelkit.convert.names import unique_name
from modelkit.formats.body.write_devices import device_node
from modelkit.formats.body.write_shapes import link_elements
from modelkit.formats.body.write_yaml import (
    Flow,
    Num,
    deg,
    dump,
    lengths,
    num,
    nums,
    put_pose,
    rotation_value,
    tensor,
)
from modelkit.model import Inertial, Joint, JointType, Link, Robot

JOINT_WORDS = {
    JointType.FIXED: "fixed",
    JointType.REVOLUTE: "revolute",
    JointType.PRISMATIC: "prismatic",
    JointType.FLOATING: "free",
    JointType.PSEUDO_CONTINUOUS_TRACK: "pseudo_continuous_track",
}
ACTUATION_WORDS = {
    "effort": "joint_effort",
    "displacement": "joint_displacement",
    "velocity": "joint_velocity",
    "link_position": "link_position",
}
LOOP_TYPES = frozenset({"fixed", "hinge", "ball", "piston"})
PLUGIN_EXTRAS = ("gazebo", "transmissions", "ros2_control", "mujoco")


@dataclass
class _Names:
    """Written names: links by object, link names by source name, joint names by object."""

    links: dict[int, str] = field(default_factory=dict)
    by_name: dict[str, str] = field(default_factory=dict)
    joints: dict[int, str] = field(default_factory=dict)
    joint_used: set[str] = field(default_factory=set)
    subtree_mass: dict[str, float] = field(default_factory=dict)  # by source link name, through every joint


def _names(robot: Robot) -> _Names:
    out = _Names()
    used = {lk.name for lk in robot.links if lk.name}
    taken: set[str] = set()
    for link in robot.links:
        if link.name and link.name not in taken:
            name = link.name
            taken.add(name)
        else:
            name = unique_name(link.name or "link", used)
        out.links[id(link)] = name
        out.by_name.setdefault(link.name, name)
    for joint in robot.joints:
        child = out.by_name.get(joint.child, joint.child)
        wanted = child if joint.implicit_name else (joint.name or child)
        out.joints[id(joint)] = unique_name(wanted, out.joint_used)
    return out


def body_renames(robot: Robot) -> dict[str, str]:
    """Source link name → written link name, for the links the writer renames (first of each name)."""
    names = _names(robot)
    return {src: dst for src, dst in names.by_name.items() if src != dst}


def write_body(robot: Robot, ctx: WriteContext) -> bytes:
    from modelkit.checks.masses import lumped_masses

    names = _names(robot)
    names.subtree_mass = lumped_masses(robot, every_joint=True)
    for link in robot.links:
        if names.links[id(link)] != link.name:
            ctx.rename("link", link.name, names.links[id(link)], "link names must be unique and not empty",
                       link.source)
    for joint in robot.joints:
        wanted = joint.name or joint.child
        written = names.joints[id(joint)]
        if not joint.implicit_name and written != wanted:
            ctx.rename("joint", wanted, written, "joint names must be unique", joint.source)
    order, parent_joint = robot.tree_order()
    from_body = robot.source_format == "body"
    root_name = names.by_name.get(robot.root or "", robot.root or "")
    doc: dict[str, Any] = {
        "format": "ChoreonoidBody",
        "format_version": Num("2.0"),
        "angle_unit": "degree",
        "name": robot.name,
        "root_link": root_name,
    }
    nodes = []
    for link in order:
        nodes.append(_link_node(robot, link, parent_joint.get(link.name), names, ctx, from_body))
    for link, extra in _unconnected(robot, order, ctx):
        names.joints[id(extra)] = unique_name(names.links[id(link)], names.joint_used)
        nodes.append(_link_node(robot, link, extra, names, ctx, from_body))
    doc["links"] = nodes
    loops = _extra_joints(robot, names, ctx)
    if loops:
        doc["extra_joints"] = loops
    _plugin_notes(robot, ctx)
    return dump(doc)


def _unconnected(robot: Robot, order: list[Link], ctx: WriteContext) -> list[tuple[Link, Joint]]:
    """Links no joint connects to the root. SDF floats them as separate bodies (or fixes them in a
    static model) at a known initial pose: Choreonoid's non-root `free` joint (§2.3) means exactly
    that, so they are written as `free` (or `fixed`) children of the root at that pose. Any other
    unconnected link has no pose to write and is left out (MK822)."""
    written = {id(lk) for lk in order}
    free_poses = robot.free_link_poses
    static = not robot.free_links_float
    out = []
    for link in robot.links:
        if id(link) in written or robot.root is None:
            continue
        world = free_poses.get(link.name)
        if world is None:
            ctx.note("MK822", f'link "{link.name}" is not connected to the root "{robot.root}" and has no '
                     "pose of its own; it is not written", link.source, None)
            continue
        kind = JointType.FIXED if static else JointType.FLOATING
        joint = Joint(f"{link.name}", kind, robot.root, link.name, robot.root_pose.inverse() @ world,
                      source=link.source)
        joint.implicit_name = True
        ctx.note("MK814", f'link "{link.name}" is not connected to the root by a joint; it is written as a '
                 f"`{JOINT_WORDS[kind]}` child of the root at its initial pose "
                 f"({'fixed in a static model' if static else 'Choreonoid floats it as a separate body'})",
                 link.source, f"link[{link.name}]")
        out.append((link, joint))
    return out


def _link_node(robot: Robot, link: Link, joint: Joint | None, names: _Names, ctx: WriteContext,
               from_body: bool) -> dict[str, Any]:
    name = names.links[id(link)]
    target = f"link[{name}]"
    node: dict[str, Any] = {"name": name}
    if joint is None:
        _root(robot, node, link, ctx, target)
    else:
        _joint(joint, node, names, ctx)
        if "actuation_mode" not in node:
            _actuation_from_actuators(robot, joint, node)
    _inertial(link.inertial, node)
    own = max(link.inertial.mass, 0.0) if link.inertial is not None else 0.0
    # a link not reachable from the root (an SDF free link, written as a free child) carries only itself
    if joint is not None and joint.type.moves and names.subtree_mass.get(link.name, own) <= 0.0:
        _massless_chain(link, node, ctx, target)
    if link.contact_material:
        node["material"] = link.contact_material
    _surface_loss(link, ctx, target)
    elements = link_elements(link, ctx, from_body)
    for i, device in enumerate(link.devices):
        written = device_node(device, from_body, ctx, f"{target}/device[{i}]")
        if written is not None:
            elements.append(written)
    if elements:
        node["elements"] = elements
    return node


def _surface_loss(link: Link, ctx: WriteContext, target: str) -> None:
    """MK851: a `.body` link's friction is a pair of named contact materials (a materials table), so
    the friction a URDF, SDF or MJCF source gives its shapes has no place here."""
    surface, others = link_surface(link)
    if surface is None:
        return
    ctx.note(
        "MK851",
        f"the collisions of link {link.name} have their own friction ({describe(surface)}"
        + "".join(f"; {describe(f)}" for f in others)
        + "), which a .body file cannot hold: Choreonoid takes friction from the pair of the two bodies' "
        "contact materials (a materials table); left out, so the link uses the Default material",
        link.loc("collision"),
        target,
    )


def _root(robot: Robot, node: dict[str, Any], link: Link, ctx: WriteContext, target: str) -> None:
    if robot.root_joint is None:
        # The source leaves it open (URDF): floating, as ROS tools spawn it; but a root body without
        # any mass (a kinematic-only model) cannot float in a simulator, so that one is welded.
        from modelkit.checks.masses import lumped_masses

        massless = lumped_masses(robot).get(link.name, 0.0) <= 0.0
        node["joint_type"] = "fixed" if massless else "free"
        how = ("welded to the world (`joint_type: fixed`): the root body has no mass to float" if massless
               else "a floating root (`joint_type: free`)")
        ctx.note("MK814", f"the source leaves the root open; it is written as {how}", link.source, target)
    else:
        node["joint_type"] = "fixed" if robot.root_joint is JointType.FIXED else "free"
    put_pose(node, robot.root_pose.rotation, robot.root_pose.translation)


KIND_WORDS = {"effort": "joint_effort", "position": "joint_displacement", "velocity": "joint_velocity"}


def _actuation_from_actuators(robot: Robot, joint: Joint, node: dict[str, Any]) -> None:
    """A canonical actuator of another format's source as the joint's ``actuation_mode`` (its kind:
    effort, position → joint_displacement, velocity); gains have no place in the body format."""
    if not joint.type.moves:
        return
    actuator = next((a for a in robot.actuators if a.joint == joint.name), None)
    if actuator is not None:
        node["actuation_mode"] = KIND_WORDS[actuator.kind.value]


def _joint(joint: Joint, node: dict[str, Any], names: _Names, ctx: WriteContext) -> None:
    written = names.joints[id(joint)]
    target = f"joint[{written}]"
    node["parent"] = names.by_name.get(joint.parent, joint.parent)
    if written != node["name"]:
        node["joint_name"] = written
    kind = joint.type
    word = JOINT_WORDS.get(kind)
    if word is None:
        ctx.note("MK813", f'{kind.value} joint "{joint.name}": Choreonoid has no such joint inside a body; '
                 "written as fixed", joint.loc("type"), target)
        word = "fixed"
    node["joint_type"] = word
    if joint.joint_id is not None:
        node["joint_id"] = num(joint.joint_id)
    put_pose(node, joint.origin.rotation, joint.origin.translation)
    moving = kind in (JointType.REVOLUTE, JointType.PRISMATIC)
    if moving or kind is JointType.PSEUDO_CONTINUOUS_TRACK:
        axis = np.asarray(joint.axis, dtype=float)
        norm = float(np.linalg.norm(axis))
        node["joint_axis"] = nums(axis / norm if norm > 0 and abs(norm - 1.0) > 1e-12 else axis, tidy=True)
    if moving:
        _limits(joint, node)
        if joint.initial_position:
            node["joint_displacement"] = _angle_or_length(joint, joint.initial_position)
        if joint.armature:
            node["joint_axis_inertia"] = num(joint.armature)
    if joint.actuation_mode in ACTUATION_WORDS:
        node["actuation_mode"] = ACTUATION_WORDS[joint.actuation_mode]
    dropped = [f"{k} {v:g}" for k, v in (("damping", joint.damping), ("friction", joint.friction)) if v]
    if dropped:
        ctx.note("MK820", f'joint "{joint.name}": Choreonoid\'s body format has no joint '
                 f"{' or '.join(k.split()[0] for k in dropped)} ({', '.join(dropped)}); left out",
                 joint.source, target)
    if joint.armature and not moving:
        ctx.note("MK820", f'joint "{joint.name}": armature {joint.armature:g} left out: it is written as a '
                 f"{word} joint, which has no joint_axis_inertia", joint.source, target)
    note_spring_dropped(ctx, joint, "Choreonoid's body format has no joint spring", target)
    if joint.mimic is not None:
        ctx.note("MK812", f'joint "{joint.name}" mimics "{joint.mimic.joint}" (×{joint.mimic.multiplier:g} '
                 f"{joint.mimic.offset:+g}); Choreonoid's body loader has no mimic joints",
                 joint.mimic.source or joint.source, target)


def _angle_or_length(joint: Joint, value: float) -> Num:
    return deg(value) if joint.type is JointType.REVOLUTE else num(value)


def _bound(joint: Joint, value: float) -> Num | str:
    return "unlimited" if math.isinf(value) else _angle_or_length(joint, value)


def _limits(joint: Joint, node: dict[str, Any]) -> None:
    limits = joint.limits
    lo, hi = limits.lower, limits.upper
    # A scalar `unlimited` is not a range Choreonoid reads (a scalar must be a number): a pair.
    node["joint_range"] = Flow([_bound(joint, lo), _bound(joint, hi)])
    vlo, vhi = limits.velocity_lower, limits.velocity_upper
    if math.isinf(vlo) and math.isinf(vhi) and math.isfinite(limits.velocity):
        vlo, vhi = -abs(limits.velocity), abs(limits.velocity)
    if math.isfinite(vhi) and vlo == -vhi:
        node["max_joint_velocity"] = _angle_or_length(joint, vhi)
    elif math.isfinite(vlo) or math.isfinite(vhi):
        node["joint_velocity_range"] = Flow([_bound(joint, vlo), _bound(joint, vhi)])
    if math.isfinite(limits.effort):
        node["max_joint_effort"] = num(limits.effort)


# What a moving link gets when neither it nor anything below it has mass (a URDF's massless finger chain):
# Choreonoid's forward dynamics needs a positive mass and inertia on each moving body (validate: MK313).
# The values of the MJCF writer's rule for MuJoCo, which refuses the same links.
CHAIN_MASS = 1e-6  # kg
CHAIN_INERTIA = 1e-9  # kg·m², on each axis


def _massless_chain(link: Link, node: dict[str, Any], ctx: WriteContext, target: str) -> None:
    node["mass"] = num(CHAIN_MASS)
    node["center_of_mass"] = nums(np.zeros(3))
    node["inertia"] = nums((np.eye(3) * CHAIN_INERTIA).ravel())
    ctx.note(
        "MK816",
        f"link {link.name} moves but neither it nor anything below it has mass; Choreonoid cannot simulate "
        f"such a joint (validate: MK313), so it gets {CHAIN_MASS:g} kg and {CHAIN_INERTIA:g} kg·m² on each "
        "axis",
        link.loc("mass"),
        target,
    )


def _inertial(inertial: Inertial | None, node: dict[str, Any]) -> None:
    if inertial is None:
        node["mass"] = num(0.0)
        node["center_of_mass"] = nums(np.zeros(3))
        node["inertia"] = nums(np.zeros(9))
        return
    com = np.asarray(inertial.com, dtype=float)
    inertia = np.asarray(inertial.inertia, dtype=float)
    if inertial.defaulted and np.array_equal(inertia, np.eye(3)):
        # Choreonoid's defaults cover the rest: 1 kg at the origin, identity inertia.
        if inertial.mass != 1.0 or np.any(com != 0.0):
            node["mass"] = num(inertial.mass)
            if np.any(com != 0.0):
                node["center_of_mass"] = nums(com)
        return
    node["mass"] = num(inertial.mass)
    node["center_of_mass"] = lengths(com)
    node["inertia"] = tensor(inertia, inertial.mass)


def _extra_joints(robot: Robot, names: _Names, ctx: WriteContext) -> list[dict[str, Any]]:
    out = []
    for loop in robot.loops:
        target = f"extra_joints[{loop.name}]"
        if loop.type not in LOOP_TYPES:
            ctx.note("MK810", f'closed-loop joint "{loop.name}" of type {loop.type}: Choreonoid\'s extra '
                     "joints are fixed, hinge, ball or piston; left out", loop.source, target)
            continue
        node: dict[str, Any] = {
            "name": loop.name,
            "link1_name": names.by_name.get(loop.link1, loop.link1),
            "link2_name": names.by_name.get(loop.link2, loop.link2),
            "joint_type": loop.type,
        }
        if loop.type in ("hinge", "piston"):
            node["axis"] = nums(loop.axis, tidy=True)
        for which, pose in ((1, loop.pose_in_link1), (2, loop.pose_in_link2)):
            if np.any(np.asarray(pose.translation) != 0.0):
                node[f"translation_in_link{which}"] = nums(pose.translation, tidy=True)
            rotation = rotation_value(pose.rotation)
            if rotation is not None:
                node[f"rotation_in_link{which}"] = rotation
        out.append(node)
    return out


def _plugin_notes(robot: Robot, ctx: WriteContext) -> None:
    found = [k for k in PLUGIN_EXTRAS if robot.extras.get(k)]
    nested = any(lk.extras.get("gazebo") for lk in robot.links) or any(
        j.extras.get("gazebo") for j in robot.joints)
    if nested and "gazebo" not in found:
        found.append("gazebo")
    if found:
        ctx.note("MK808", f"{', '.join(found)} data of the source is not carried over to the .body file",
                 robot.source, None)
