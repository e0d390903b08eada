"""The SDF writer: one robot as one SDFormat ``<model>`` (SDFormat 1.6–1.11, default 1.9).

Frames. From SDFormat 1.7 a child link's ``<pose relative_to="PARENT">`` is its joint origin and
the joint's own pose is left out (the joint frame is the child link frame, as in the model); the
axis ``<xyz>`` is expressed in that frame (the default since 1.7). For 1.6, which has no
``relative_to``, link poses are composed into the model frame (the root link frame) here.

The root. A robot welded to the world (``root_joint`` FIXED) gets a fixed joint from ``world``
to its root (that keeps the model's dynamics; ``<static>`` would freeze every joint) and the
model ``<pose>`` = ``root_pose``; a floating root is a free model at ``root_pose``; a root the
source leaves open (URDF) floats in SDF, which is noted (MK814). A root link named ``world`` (MJCF,
a URDF world link, SDF world joints) is SDF's world itself: it is not written, its joints are
written with ``<parent>world</parent>``.

Massless links (no inertial, or mass 0). SDF gives a link without ``<inertial>`` 1 kg, and
libsdformat's URDF import drops massless links, so neither is truthful. The rule (MK816):

* a massless link that carries nothing (no visual, collision or device), hangs from a fixed joint
  of a written link or frame, and whose children are all such links too, is written as a
  ``<frame name attached_to="PARENT">`` with its pose (SDFormat ≥ 1.7): the frame keeps its name
  and place, and no simulator sees a body;
* any other massless link (it carries geometry, moves, has moving children, or the version is
  1.6) is written as a link with an explicit tiny inertial: mass 1e-6 kg, inertia 1e-12 kg·m²
  (valid for every SDF consumer, negligible against any real part), and noted as such.

Names are made unique and legal by :mod:`write_names`; geometry by :mod:`write_geometry`;
sensors, lights and plugins by :mod:`write_devices`; the actuators as gz-sim joint controllers by
:mod:`write_actuators`; ``<self_collide>`` by :mod:`write_self_collide`.
"""

from __future__ import annotations

import math
import re

import numpy as np
from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.drive_plugin import planned_drive, plugin_elements
from modelkit.convert.friction import floor_friction
from modelkit.convert.gazebo import gazebo_family
from modelkit.convert.joint_springs import note_spring_dropped
from modelkit.convert.numbers import clean_inertia, fmt, fmt_direction, fmt_inertia, fmt_vec
from modelkit.convert.servo_gains import with_written_masses
from modelkit.formats.sdf.gz_inertia import libsdformat_accepts
from modelkit.formats.sdf.kept import JOINT_KEY, LIMIT_KEY, MODEL_KEY, write_back
from modelkit.formats.sdf.write_actuators import ActuatorWriter
from modelkit.formats.sdf.write_devices import DeviceWriter, is_sdf_native
from modelkit.formats.sdf.write_gazebo_tags import (
    source_ros_control,
    why_left_out,
    write_joint_tags,
    write_link_tags,
    write_model_blocks,
)
from modelkit.formats.sdf.write_geometry import GeomWriter
from modelkit.formats.sdf.write_names import Names
from modelkit.formats.sdf.write_self_collide import only_carried, self_collide_policy
from modelkit.formats.sdf.write_xml import add_pose, data_element, num, sub
from modelkit.model import WORLD_LINK, DeviceKind, Joint, JointType, Link, LoopConstraint, Robot
from modelkit.spatial import Mat3, Pose, Vec3

TINY_MASS = 1e-6
TINY_INERTIA = 1e-12
INERTIA_MARGIN = 1e-12  # relative slack first kept in A + B ≥ C, far above libsdformat's 10 machine epsilons
MARGIN_TRIES = 8  # up to 1e-5 of the largest moment (the Stretch puller needs 1e-8: gz-math's closed form)
UNLIMITED = 1e16  # SDF's "no position limit" before 1.11
LOOP_TYPES = {"fixed": "fixed", "hinge": "revolute", "ball": "ball", "piston": "prismatic"}
SDF_NATIVE_ONLY = ("universal", "revolute2", "screw", "gearbox")


def parse_version(text: str) -> tuple[int, int]:
    major, _, minor = text.partition(".")
    return int(major), int(minor or 0)


def write_sdf(robot: Robot, ctx: WriteContext) -> bytes:
    """The SDF file of ``robot``; meshes go through ``ctx.meshes``, losses are notes."""
    root = _ModelWriter(robot, ctx).build()
    body = etree.tostring(root, encoding="unicode", pretty_print=True)
    return ('<?xml version="1.0"?>\n' + body).encode("utf-8")


def massless(link: Link) -> bool:
    return link.inertial is None or link.inertial.mass <= 0.0



def sdformat_valid_inertia(m: Mat3) -> tuple[Mat3, Vec3, Vec3]:
    """``m`` (symmetrised) when libsdformat accepts it as written (:func:`libsdformat_accepts`, gz-math's
    own test on the decimals the writer writes), else the nearest tensor it accepts: the two smaller
    principal moments lifted until A + B ≥ C holds with a relative margin that gz-math's closed-form
    moments still see (none for a diagonal tensor, whose moments gz-math reads as they are; else from
    1e-12 of the largest moment, ten times more at each try).
    Returns the tensor, the original principal moments and the written ones (equal: unchanged)."""
    m = 0.5 * (m + m.T)
    diagonal = not np.any(m - np.diag(np.diag(m)))
    moments, axes = np.linalg.eigh(m)
    if diagonal:  # exact moments and axes
        order = np.argsort(np.diag(m), kind="stable")
        moments, axes = np.diag(m)[order], np.eye(3)[:, order]
    if libsdformat_accepts(as_written(m)):
        return m, moments, moments
    top = max(0.0, float(moments[-1]))
    margin = 0.0 if diagonal else INERTIA_MARGIN  # a diagonal's moments are exact: A + B = C is accepted
    adjusted, fixed = m, moments
    for _ in range(MARGIN_TRIES):
        fixed = np.maximum(moments, 0.0)
        short = float(fixed[2] - fixed[0] - fixed[1])
        lift = max(0.5 * short, 0.0) + top * margin
        fixed[0] += lift
        fixed[1] += lift
        adjusted = axes @ np.diag(fixed) @ axes.T
        adjusted = 0.5 * (adjusted + adjusted.T)
        if libsdformat_accepts(as_written(adjusted)):
            break
        margin = 10.0 * margin if margin else INERTIA_MARGIN
    return adjusted, moments, fixed


def as_written(m: Mat3) -> Mat3:
    """The symmetric tensor the SDF writer's decimals give back (``fmt`` of each element)."""
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(i, 3):
            out[i, j] = out[j, i] = float(fmt(0.5 * (m[i, j] + m[j, i])))
    return out


UNJOINTED_NOTE = re.compile(r'joint "(?P<joint>.+)" is (?P<type>planar|floating): SDF has no such joint '
                            r"inside a model; ")
"""The MK813 note of a joint whose child is written without a joint (:meth:`_joint`): verify reads it."""

class _ModelWriter:
    def __init__(self, robot: Robot, ctx: WriteContext) -> None:
        self.robot = robot
        self.ctx = ctx
        self.version = parse_version(ctx.options.sdf_version)
        self.frames_ok = self.version >= (1, 7)
        self.lifted: set[str] = set()  # massless links written with TINY_MASS (MK816): the gains carry it
        self.names = Names(ctx)
        self.geoms = GeomWriter(ctx, self.version, robot.source_format)
        self.devices = DeviceWriter(
            ctx, self.version, robot.source_format, gazebo_family(robot, ctx.options.gazebo)
        )
        self.children = robot.children_of()
        self.joint_of = {j.child: j for j in robot.joints}
        self.links = {lk.name: lk for lk in robot.links}
        self.world_root = robot.root == WORLD_LINK
        self.as_frame: set[str] = set()
        self.unjointed: set[str] = set()  # links whose joint SDF cannot hold: they float
        self.model_poses: dict[str, Pose] = {}  # link → pose in the model frame at q = 0 (SDF 1.6)
        self.ft_to_joint: dict[str, list[tuple[object, Pose]]] = {}
        self.axis_joints: dict[str, str] = {}  # source joint → written revolute/prismatic joint
        self.self_collide: dict[str, bool] = {}  # link → its <self_collide> (write_self_collide)

    # -- plan --------------------------------------------------------------------------------

    def _plan(self) -> None:
        robot = self.robot
        poses = robot.world_poses()
        base = poses.get(robot.root or "", Pose()).inverse()
        self.model_poses = {name: base @ pose for name, pose in poses.items()}
        for joint in robot.joints:
            if joint.type in (JointType.FLOATING, JointType.PLANAR):
                self.unjointed.add(joint.child)
        if self.frames_ok:
            for link in robot.links:
                if self._frameable(link.name, set()):
                    self.as_frame.add(link.name)

    def _frameable(self, name: str, seen: set[str]) -> bool:
        link = self.links.get(name)
        joint = self.joint_of.get(name)
        if link is None or joint is None or name in seen or name == self.robot.root:
            return False
        seen.add(name)
        if not massless(link) or link.visuals or link.collisions or link.devices:
            return False
        if (
            joint.type not in (JointType.FIXED, JointType.PSEUDO_CONTINUOUS_TRACK)
            or joint.parent == WORLD_LINK
        ):
            return False
        if any(name in (lp.link1, lp.link2) for lp in self.robot.loops):
            return False
        if any(j.mimic is not None and j.mimic.joint == joint.name for j in self.robot.joints):
            return False
        return all(self._frameable(j.child, seen) for j in self.children.get(name, []))

    # -- the document ----------------------------------------------------------------------------

    def build(self) -> Element:
        robot, ctx = self.robot, self.ctx
        self._plan()
        sdf = etree.Element("sdf", version=ctx.options.sdf_version)
        model = sub(sdf, "model", name=robot.name or "robot")
        written_links = [lk for lk in self._ordered_links() if lk.name not in self.as_frame]
        for link in written_links:
            self.names.claim("link", link.name, link.loc("name"))
        if self.frames_ok and not self.world_root and robot.root in self.links:
            model.set("canonical_link", self.names.links[robot.root or ""])
        self._root(model)
        write_back(model, robot.extras.get(MODEL_KEY))  # <allow_auto_disable>, <enable_wind> (kept.py)
        self.self_collide = self_collide_policy(robot, ctx, model, {lk.name for lk in written_links})
        for link in written_links:
            self._link(model, link)
        for link in self._parents_first([lk for lk in self._ordered_links() if lk.name in self.as_frame]):
            self._frame_link(model, link)
        for joint in robot.joints:
            self._joint(model, joint)
        for loop in robot.loops:
            self._loop(model, loop)
        self._model_extras(model)
        return sdf

    def _parents_first(self, frames: list[Link]) -> list[Link]:
        """``frames`` in their order, except that a frame attached to another frame comes right after
        it when it would come before. SDFormat allows any order, but Drake (1.51) resolves a frame's
        ``relative_to`` in document order and silently places a frame written before its parent frame
        at the parent's link instead (measured: qibullet's NAO, ``CameraBottom_optical_frame`` 5.4 cm
        and 0.69 rad off)."""
        names = {lk.name for lk in frames}
        emitted: set[str] = set()
        waiting: dict[str, list[Link]] = {}
        out: list[Link] = []
        for link in frames:
            parent = self.joint_of[link.name].parent
            if parent in names and parent not in emitted:
                waiting.setdefault(parent, []).append(link)
                continue
            stack = [link]
            while stack:
                frame = stack.pop()
                out.append(frame)
                emitted.add(frame.name)
                stack.extend(reversed(waiting.pop(frame.name, [])))
        return out

    def _ordered_links(self) -> list[Link]:
        """The root first (SDF's default canonical link), then the others in model order."""
        out = [lk for lk in self.robot.links if lk.name == self.robot.root and not self.world_root]
        out += [lk for lk in self.robot.links if lk.name != self.robot.root]
        return out

    def _root(self, model: Element) -> None:
        robot, ctx = self.robot, self.ctx
        add_pose(model, robot.root_pose)
        if self.world_root:
            world = self.links.get(WORLD_LINK)
            if world is not None and not world.synthesised:
                ctx.note(
                    "MK814",
                    'the link "world" is SDF\'s world itself: it is not written as a link; the joints '
                    "that hang from it are written with <parent>world</parent>",
                    world.loc("name"),
                    "model/joint[parent=world]",
                )
            if world is not None and (world.visuals or world.collisions or world.devices):
                ctx.note(
                    "MK822",
                    "shapes and devices attached to the world (floor, scenery, world lights) are "
                    "world content, not the robot; they are not written",
                    world.loc("name"),
                    "model",
                )
            return
        if robot.root_joint is JointType.FIXED:
            info = robot.extras.get("sdf_world_joint")
            wanted = (info.get("name") if isinstance(info, dict) and info.get("name")
                      else robot.root_joint_name or "world_joint")
            name = self.names.claim("joint", str(wanted), robot.root_joint_source)
            joint = sub(model, "joint", name=name, type="fixed")
            sub(joint, "parent", WORLD_LINK)
            sub(joint, "child", self.names.links[robot.root or ""])
        elif robot.root_joint is None:
            ctx.note(
                "MK814",
                f'the source leaves the root "{robot.root}" open (URDF convention: it floats '
                "unless welded to a world link); in SDF it is a free-floating model",
                robot.source,
                "model",
            )

    # -- links ---------------------------------------------------------------------------------

    def _link_pose(self, el: Element, name: str) -> None:
        """The link's frame: relative to its parent link (≥ 1.7) or in the model frame (1.6)."""
        joint = self.joint_of.get(name)
        if name == self.robot.root or joint is None:
            free = self.robot.free_link_poses
            if name in free:
                add_pose(el, self.robot.root_pose.inverse() @ free[name])
            return
        parent = joint.parent
        if not self.frames_ok or parent == WORLD_LINK or parent not in self.links:
            add_pose(el, self.model_poses.get(name, joint.origin))
            return
        parent_name = self.names.links.get(parent) or self.names.frames.get(parent) or parent
        add_pose(el, joint.origin, parent_name)

    def _link(self, model: Element, link: Link) -> None:
        ctx = self.ctx
        name = self.names.links[link.name]
        el = sub(model, "link", name=name)
        self._link_pose(el, link.name)
        if link.name in self.self_collide:
            sub(el, "self_collide", "true" if self.self_collide[link.name] else "false")
        self._own_link_elements(el, link)
        self._inertial(el, link, name)
        friction = floor_friction(self.robot).get(link.name) if link.contact_material else None
        self.geoms.link_geoms(el, link, name, Pose(), None, friction)
        used: set[str] = set()
        for device in link.devices:
            joint = self.joint_of.get(link.name)
            to_joint = (
                device.params.get("sdf_joint")
                if is_sdf_native(device, self.robot.source_format)
                else (joint is not None and device.canonical is DeviceKind.FORCE_TORQUE)
            )
            if to_joint and joint is not None and link.name not in self.unjointed:
                self.ft_to_joint.setdefault(link.name, []).append((device, device.pose))
                continue
            self.devices.device(el, device, device.pose, None, f"link[{name}]", used)
        for plugin in link.extras.get("sdf_plugins", []):
            ctx.note(
                "MK808",
                f'plugin "{plugin.get("name", "")}" of {plugin.get("owner", "a shape")} is not '
                "carried over (shape plugins are not written back)",
                link.source,
                f"link[{name}]",
            )
        if link.extras.get("gazebo") and not only_carried(link.extras["gazebo"]):
            left = write_link_tags(el, link.extras["gazebo"])  # gravity, maxContacts, kp... as SDF elements
            if left:
                ctx.note(
                    "MK808",
                    f'<gazebo> extension of link "{link.name}": {", ".join(f"<{t}>" for t in left)} not '
                    "carried over (its other tags are written as the SDF elements libsdformat makes of them)"
                    + why_left_out(left),
                    link.source,
                    f"link[{name}]",
                )
        for frame_name, pose in sorted(link.extras.get("sdf_frames", {}).items()):
            if self.frames_ok:
                fname = self.names.claim("frame", frame_name, link.source)
                frame = sub(model, "frame", name=fname, attached_to=name)
                add_pose(frame, pose, name)
            else:
                self.ctx.note("MK820", f'frame "{frame_name}" of link "{link.name}" is left out: SDFormat '
                              f"{self.ctx.options.sdf_version} has no <frame>", link.source, f"link[{name}]")

    @staticmethod
    def _own_link_elements(el: Element, link: Link) -> None:
        """An SDF source link's flags (``<gravity>``, ``<kinematic>``, ``<velocity_decay>``...) and the
        elements validate keeps only as data (``<battery>``, ``<audio_sink>``..., MK155), written back."""
        for key, value in (link.extras.get("sdf_link") or {}).items():
            if isinstance(value, bool):
                sub(el, str(key), "true" if value else "false")
            else:
                el.append(data_element(str(key), value))
        for entry in link.extras.get("sdf_other") or []:
            if isinstance(entry, dict) and entry.get("element"):
                el.append(data_element(str(entry["element"]), entry.get("data")))

    def _inertial(self, el: Element, link: Link, name: str) -> None:
        inertial = link.inertial
        inertial_el = sub(el, "inertial")
        if inertial is None or inertial.mass <= 0.0:
            why = (
                "it moves or carries geometry" if self.frames_ok else "SDFormat 1.6 has no attachable frames"
            )
            self.ctx.note(
                "MK816",
                f'link "{link.name}" has no mass; SDF would give it 1 kg, and {why}, so it is '
                f"written as a link with a tiny explicit inertial (mass {fmt(TINY_MASS)} kg, inertia "
                f"{fmt(TINY_INERTIA)} kg·m²)",
                link.loc("mass"),
                f"link[{name}]/inertial",
            )
            num(inertial_el, "mass", TINY_MASS)
            self.lifted.add(link.name)
            tensor = sub(inertial_el, "inertia")
            for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                num(tensor, key, TINY_INERTIA if key in ("ixx", "iyy", "izz") else 0.0)
            return
        if inertial.defaulted:
            self.ctx.note(
                "MK801",
                f'link "{link.name}": the source gives no mass; its default (mass '
                f"{fmt(inertial.mass)} kg) is written explicitly",
                inertial.source or link.source,
                f"link[{name}]/inertial",
            )
        add_pose(inertial_el, Pose(np.eye(3), np.asarray(inertial.com, dtype=float)))
        num(inertial_el, "mass", inertial.mass)
        tensor = sub(inertial_el, "inertia")
        m = self._valid_inertia(link, name, clean_inertia(inertial.inertia, inertial.mass))
        for key, (i, j) in (
            ("ixx", (0, 0)),
            ("ixy", (0, 1)),
            ("ixz", (0, 2)),
            ("iyy", (1, 1)),
            ("iyz", (1, 2)),
            ("izz", (2, 2)),
        ):
            sub(tensor, key, fmt_inertia(0.5 * (m[i, j] + m[j, i]) if i != j else m[i, j], m))

    def _valid_inertia(self, link: Link, name: str, m: Mat3) -> Mat3:
        """``m``, or libsdformat's nearest acceptable tensor (:func:`sdformat_valid_inertia`), noted."""
        adjusted, moments, fixed = sdformat_valid_inertia(m)
        if np.array_equal(fixed, moments):
            return adjusted
        self.ctx.note(
            "MK860",
            f'link "{link.name}": principal moments {fmt_vec(moments)} violate A + B ≥ C or meet it '
            "within rounding (libsdformat refuses the whole file); written as the nearest valid tensor, "
            f"moments {fmt_vec(fixed)} about the same axes",
            link.loc("inertia"),
            f"link[{name}]/inertial",
        )
        return adjusted

    def _frame_link(self, model: Element, link: Link) -> None:
        joint = self.joint_of[link.name]
        parent = self.names.links.get(joint.parent) or self.names.frames.get(joint.parent)
        if parent is None:  # a frame under a frame: parents are claimed first (document order)
            parent = self.names.claim("frame", joint.parent, None)
        name = self.names.claim("frame", link.name, link.loc("name"))
        frame = sub(model, "frame", name=name, attached_to=parent)
        add_pose(frame, joint.origin, parent)
        self.ctx.note(
            "MK816",
            f'link "{link.name}" has no mass and carries nothing; it is written as a frame '
            f'attached to "{parent}" (its fixed joint "{joint.name}" is the frame\'s pose), so no '
            "simulator gives it a body or drops it",
            link.loc("name"),
            f"frame[{name}]",
        )

    # -- joints --------------------------------------------------------------------------------

    def _joint(self, model: Element, joint: Joint) -> None:
        ctx = self.ctx
        if joint.extras.get("gazebo") and (joint.child in self.as_frame or joint.child in self.unjointed):
            ctx.note("MK808", f'<gazebo> extension of joint "{joint.name}" not carried over: the joint is '
                     "not written as an SDF joint", joint.source, f"joint[{joint.name}]")
        if joint.child in self.as_frame:
            return
        if joint.child in self.unjointed:
            ctx.note(
                "MK813",
                f'joint "{joint.name}" is {joint.type.value}: SDF has no such joint inside a model; '
                f'link "{joint.child}" is written without a joint (free-floating, placed at its initial '
                "pose)",
                joint.loc("type"),
                f"link[{self.names.links.get(joint.child, joint.child)}]",
            )
            return
        parent = WORLD_LINK if joint.parent == WORLD_LINK else self.names.links.get(joint.parent)
        child = self.names.links.get(joint.child)
        if parent is None or child is None:
            return
        name = self.names.claim("joint", joint.name, joint.loc("name"))
        kind = self._joint_type(joint, name)
        el = sub(model, "joint", name=name, type=kind)
        sub(el, "parent", parent)
        sub(el, "child", child)
        if kind in ("revolute", "continuous", "prismatic"):
            self._axis(el, joint, name)
            if joint.mimic is None:
                self.axis_joints[joint.name] = name
        else:
            self._axisless_dynamics(joint, kind, name)
        write_back(el, joint.extras.get(JOINT_KEY))  # <physics> (kept.py)
        if joint.extras.get("gazebo"):  # a URDF joint's <gazebo> block, as libsdformat converts it
            left = write_joint_tags(el, joint.extras["gazebo"])
            if left:
                ctx.note("MK808", f'<gazebo> extension of joint "{joint.name}": '
                         f'{", ".join(f"<{t}>" for t in left)} not carried over', joint.source,
                         f"joint[{name}]")
        if joint.armature:
            ctx.note(
                "MK820",
                f'joint "{joint.name}": armature {fmt(joint.armature)} has no SDF field',
                joint.source,
                f"joint[{name}]",
            )
        used: set[str] = set()
        for device, pose in self.ft_to_joint.get(joint.child, []):
            self.devices.device(el, device, pose, None, f"joint[{name}]", used)  # type: ignore[arg-type]

    def _axisless_dynamics(self, joint: Joint, kind: str, name: str) -> None:
        """A ball or fixed joint has no ``<axis>``, where SDF keeps damping, friction and springs."""
        why = f"a {kind} joint has no <axis><dynamics> in SDF"
        lost = [f"{word} {fmt(value)}" for word, value in (("damping", joint.damping),
                                                            ("friction", joint.friction)) if value]
        if lost:
            self.ctx.note("MK820", f'joint "{joint.name}": {", ".join(lost)} left out: {why}', joint.source,
                          f"joint[{name}]")
        note_spring_dropped(self.ctx, joint, why, f"joint[{name}]")

    def _joint_type(self, joint: Joint, name: str) -> str:
        t = joint.type
        if t is JointType.REVOLUTE:
            if joint.extras.get("sdf_type") == "continuous" and not joint.limits.position_limited:
                return "continuous"
            return "revolute"
        if t is JointType.PRISMATIC:
            return "prismatic"
        if t is JointType.BALL:
            return "ball"
        original = joint.extras.get("sdf_type")
        if original in SDF_NATIVE_ONLY:
            self.ctx.note(
                "MK813",
                f'joint "{joint.name}" was a {original} joint, which the model holds only as a '
                "fixed placeholder; it is written as fixed",
                joint.loc("type"),
                f"joint[{name}]",
            )
        return "fixed"

    def _axis(self, el: Element, joint: Joint, name: str) -> None:
        axis = sub(el, "axis")
        vec = np.asarray(joint.axis, dtype=float)
        norm = float(np.linalg.norm(vec))
        sub(axis, "xyz", fmt_direction(vec / norm if norm > 0 else vec))
        lim = joint.limits
        limited = joint.type is JointType.PRISMATIC or lim.position_limited
        finite_rates = math.isfinite(lim.effort) or math.isfinite(lim.velocity)
        if joint.initial_position:
            # SDFormat's axis/initial_position "has no known implementation" (the spec's words): it is
            # deprecated in 1.8 and 1.9 and removed from 1.10 on, and libsdformat 13+ (Drake's) refuses
            # it in a 1.9 file (it converts to its newest version). No consumer reads it: dropped.
            self.ctx.note(
                "MK820",
                f'joint "{joint.name}": initial position {fmt(joint.initial_position)} (the joint\'s '
                "reference position) is left out: SDFormat's <axis><initial_position> is deprecated "
                "(1.8, 1.9), removed from 1.10 on and read by no consumer",
                joint.source,
                f"joint[{name}]/axis",
            )
        stop = joint.extras.get(LIMIT_KEY)  # the stop's <stiffness>, <dissipation> (kept.py)
        if limited or finite_rates or self._continuous_as_revolute(joint) or stop:
            limit = sub(axis, "limit")
            num(limit, "lower", lim.lower if math.isfinite(lim.lower) else -UNLIMITED)
            num(limit, "upper", lim.upper if math.isfinite(lim.upper) else UNLIMITED)
            if math.isfinite(lim.effort):
                num(limit, "effort", lim.effort)
            if math.isfinite(lim.velocity):
                num(limit, "velocity", lim.velocity)
            write_back(limit, stop)
        spring = joint.spring_stiffness or joint.spring_reference
        if joint.damping or joint.friction or spring:
            dyn = sub(axis, "dynamics")
            num(dyn, "damping", joint.damping)
            num(dyn, "friction", joint.friction)
            if spring:
                num(dyn, "spring_reference", joint.spring_reference)
                num(dyn, "spring_stiffness", joint.spring_stiffness)
        if joint.mimic is not None:
            leader = self.names.joints.get(joint.mimic.joint) or self._leader_name(joint.mimic.joint)
            if self.version >= (1, 11) and leader is not None:
                mimic = sub(axis, "mimic", joint=leader, axis="axis")
                num(mimic, "multiplier", joint.mimic.multiplier)
                num(mimic, "offset", joint.mimic.offset)
                num(mimic, "reference", 0.0)
            else:
                why = "needs SDFormat 1.11" if leader is not None else "its leader joint is not written"
                self.ctx.note(
                    "MK812",
                    f'joint "{joint.name}" mimics "{joint.mimic.joint}" (×{fmt(joint.mimic.multiplier)}'
                    f" + {fmt(joint.mimic.offset)}); <mimic> {why}",
                    joint.mimic.source or joint.source,
                    f"joint[{name}]/axis",
                )

    def _leader_name(self, leader: str) -> str | None:
        for j in self.robot.joints:
            if j.name == leader and j.child not in self.unjointed and j.child not in self.as_frame:
                return self.names.claim("joint", leader, j.loc("name"))
        return None

    def _continuous_as_revolute(self, joint: Joint) -> bool:
        return joint.type is JointType.REVOLUTE and joint.extras.get("sdf_type") != "continuous"

    def _loop(self, model: Element, loop: LoopConstraint) -> None:
        ctx = self.ctx
        kind = LOOP_TYPES.get(loop.type)
        link1, link2 = self.names.links.get(loop.link1), self.names.links.get(loop.link2)
        if kind is None or link1 is None or link2 is None:
            why = f"type {loop.type} has no SDF joint" if kind is None else "one of its links is not written"
            ctx.note("MK810", f'closed-loop joint "{loop.name}" is left out: {why}', loop.source, "model")
            return
        name = self.names.claim("joint", loop.name, loop.source)
        el = sub(model, "joint", name=name, type=kind)
        if self.frames_ok:
            add_pose(el, loop.pose_in_link2)
        else:
            add_pose(el, loop.pose_in_link2)
        sub(el, "parent", link1)
        sub(el, "child", link2)
        if kind in ("revolute", "prismatic"):
            axis = sub(el, "axis")
            vec = np.asarray(loop.axis, dtype=float)
            sub(axis, "xyz", fmt_direction(vec / float(np.linalg.norm(vec))))
            limit = sub(axis, "limit")
            num(limit, "lower", -UNLIMITED)
            num(limit, "upper", UNLIMITED)
        ctx.note(
            "MK811",
            f'closed-loop joint "{loop.name}" ({loop.type}) is written as an extra <joint> between '
            f'"{link1}" and "{link2}": the model is no longer a tree. Gazebo Classic (ODE) simulates it as a '
            "constraint; tools that need a tree (sdformat_urdf, URDF export, some gz-sim physics engines) "
            "refuse or ignore it",
            loop.source,
            f"joint[{name}]",
        )

    # -- model-level data ------------------------------------------------------------------------

    def _drive_plugin(self, model: Element) -> None:
        """Gazebo's differential drive for a robot on wheels without a controller (convert.drive_plugin)."""
        robot = self.robot
        family = self.devices.gazebo
        drive = planned_drive(robot, "sdf", family, str(model.get("name")), self.ctx.notes)
        if drive is None:
            return
        filename, name, children = plugin_elements(drive, family, self.axis_joints,
                                                   self.names.links[drive.base])
        plugin = sub(model, "plugin", filename=filename, name=name)
        for tag, text in children:
            sub(plugin, tag).text = text

    def _model_blocks(self, model: Element) -> None:
        """A URDF's robot-level ``<gazebo>`` blocks, copied into the model as libsdformat does."""
        robot, ctx, family = self.robot, self.ctx, self.devices.gazebo
        done = write_model_blocks(model, robot.extras.get("gazebo"), family)
        for other in sorted({each[2] for each in done.other_family}):
            plugins = [f'"{name}" ({filename})' for name, filename, of in done.other_family if of == other]
            ctx.note("MK848", f"{len(plugins)} model plugin(s) of the URDF's robot-level <gazebo> blocks are "
                     f"Gazebo {other} code and this file is written for Gazebo {family} (--gazebo {other} "
                     f"keeps them); left out: {', '.join(plugins)}", robot.source, "model/plugin")
        if done.left:
            ctx.note(
                "MK808",
                f"robot-level <gazebo> block: {', '.join(f'<{t}>' for t in done.left)} not carried over (an "
                "SDF model holds no such element; its plugins and model elements are written)",
                robot.source,
                "model",
            )

    def _model_extras(self, model: Element) -> None:
        robot, ctx = self.robot, self.ctx
        family = self.devices.gazebo
        ros_control = (source_ros_control(robot.extras.get("gazebo"), family)
                       if robot.source_format == "urdf" else None)
        if ros_control is not None and robot.actuators:
            ctx.note(
                "MK878",
                f'the source\'s plugin "{ros_control.get("name", "")}" ({ros_control.get("filename", "")}) '
                "drives the joints from the URDF's <ros2_control> or <transmission> tags (ROS publishes them "
                "as robot_description); it is written, and no joint controllers are generated beside it for "
                f"the {len(robot.actuators)} actuator(s)",
                robot.source,
                "model/plugin",
            )
        else:
            as_written = with_written_masses(robot, frozenset(self.lifted), TINY_MASS, TINY_INERTIA)
            ActuatorWriter(robot, ctx, family, self.axis_joints, as_written).write(model)
        if ctx.options.drive_plugin:
            self._drive_plugin(model)
        for plugin in robot.extras.get("sdf_plugins", []):
            if plugin.get("actuates"):
                continue  # written from the canonical actuators (write_actuators)
            if robot.source_format == "sdf":
                self.devices.plugin(model, plugin, "model")
            else:
                ctx.note(
                    "MK808", f'plugin "{plugin.get("name", "")}" is not carried over', robot.source, "model"
                )
        if robot.extras.get("gazebo"):
            self._model_blocks(model)
        if robot.extras.get("transmissions"):
            carried = ((" (the source's ros_control plugin, written, drives them)" if ros_control is not None
                        else " (the actuators they name are written as gz-sim joint controllers)")
                       if robot.actuators else "")
            ctx.note(
                "MK808",
                "<transmission> elements of the source are simulator or controller data; they are not "
                "carried over" + carried,
                robot.source,
                "model",
            )
        world = robot.extras.get("sdf_world")
        if isinstance(world, dict) and (world.get("lights") or world.get("plugins")):
            ctx.note(
                "MK822",
                f'world "{world.get("name", "")}" content (lights, plugins, physics) is not the '
                "robot; only the model is written",
                robot.source,
                "model",
            )
        if robot.extras.get("sdf_geometry"):
            ctx.note("MK822", "plane and heightmap shapes are not written", robot.source, "model")
