"""MuJoCo bodies → robots of the model.

The mapping (``docs/mjcf.md`` says it for users):

* each MuJoCo body is a link; the world body is not one;
* the model's link frame is its joint frame, so a body whose joint sits at ``pos`` ≠ 0 gets a link
  frame moved to that point (``extras["mjcf_body_offset"]``), and its inertia, geoms and children
  are re-expressed there;
* the model has one joint per link: a body with n joints becomes a chain of n links, the first
  n − 1 of them massless and named ``<body>__<joint>``; a body with no joint hangs from its
  parent on a synthesised fixed joint ``<parent>_to_<body>``;
* a joint's q is MuJoCo's qpos: a joint ``ref`` is folded into the joint origin;
* each top-level body starts a robot: free joint → floating root, no joint → fixed root at its
  pose, other joints → a synthesised fixed ``world`` link they hang from.

The build imports no numpy: vectors and poses stay plain tuples (:mod:`modelkit.rot3`, and
``Pose.rotation_tuple`` / ``translation_tuple`` rather than the numpy-reading attributes).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.fractions import clamped_fractions
from modelkit.formats.mjcf.bodies import MjBody, MjGeom, MjJoint, MjSite, translation
from modelkit.formats.mjcf.carried import is_linear
from modelkit.formats.mjcf.source import Locator
from modelkit.model import (
    WORLD_LINK,
    Box,
    Capsule,
    Cylinder,
    Ellipsoid,
    Geom,
    Geometry,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    Mesh,
    Mimic,
    Robot,
    Sphere,
    SurfaceFriction,
    VisualMaterial,
)
from modelkit.spatial import Pose

JOINT_TYPES = {
    "hinge": JointType.REVOLUTE,
    "slide": JointType.PRISMATIC,
    "ball": JointType.BALL,
    "free": JointType.FLOATING,
}


DRAWN_GROUPS = 3  # MuJoCo's viewer draws geom groups 0, 1 and 2 unless told otherwise (mjvOption.geomgroup)


def drawn(mg: MjGeom) -> bool:
    """Whether MuJoCo draws the geom by default: a group below :data:`DRAWN_GROUPS` and a colour that is
    not fully transparent. A body whose colliding geoms are all hidden (Menagerie's group 3) has no look
    of its own, and gets no visual copy of them."""
    return mg.group < DRAWN_GROUPS and (mg.rgba is None or mg.rgba[3] > 0.0)


@dataclass
class Names:
    """Deterministic, unique names for links and joints (generated names never shadow real ones)."""

    links: set[str] = field(default_factory=set)
    joints: set[str] = field(default_factory=set)

    @staticmethod
    def unique(wanted: str, taken: set[str]) -> str:
        name, n = wanted, 1
        while name in taken:
            n += 1
            name = f"{wanted}_{n}"
        taken.add(name)
        return name


@dataclass
class Built:
    """The robots of one file and what the build learnt on the way."""

    robots: list[Robot]  # the main robot (the largest tree) first, then the others in file order
    joints: dict[int, Joint]  # MuJoCo joint index → model joint
    robot_of_body: dict[int, Robot]


class RobotBuilder:
    """Turns the records of :mod:`.bodies` into robots, one per top-level body tree."""

    def __init__(self, bodies: list[MjBody], locator: Locator, sink: DiagnosticSink, model_name: str) -> None:
        self.bodies = {b.index: b for b in bodies}
        self.order = [b.index for b in bodies]
        self.loc = locator
        self.sink = sink
        self.model_name = model_name
        self.textures_said: set[str] = set()  # materials whose texture MK178 named
        self.bright_said: set[str] = set()  # materials whose colours MK513 named (once per material)
        self.names = Names()
        self.link_name: dict[int, str] = {}
        self.joint_name: dict[int, str] = {}
        self.offset: dict[int, Pose] = {}
        self.joints: dict[int, Joint] = {}

    # -- names ---------------------------------------------------------------------------------

    def _name_everything(self) -> None:
        """Real names first (so generated ones cannot take them), then the generated ones."""
        for b in self.order:
            body = self.bodies[b]
            if body.name:
                self.link_name[b] = self.names.unique(body.name, self.names.links)
            for joint in body.joints:
                if joint.name:
                    self.joint_name[joint.index] = self.names.unique(joint.name, self.names.joints)
        for b in self.order:
            body = self.bodies[b]
            if not body.name:
                self.link_name[b] = self.names.unique(f"body{b}", self.names.links)
                self.sink.emit(
                    "MK173", f'body {b} has no name; it is called "{self.link_name[b]}"', self.loc.body(b)
                )
            for k, joint in enumerate(body.joints):
                if joint.name:
                    continue
                name = self.names.unique(f"joint{joint.index}", self.names.joints)
                self.joint_name[joint.index] = name
                if not (k == 0 and joint.kind == "free" and body.parent == 0):  # the root's: no Joint
                    self.sink.emit(
                        "MK173",
                        f'a joint of body "{self.link_name[b]}" has no name; it is called "{name}"',
                        self.loc.joint(joint.index),
                    )

    # -- robots --------------------------------------------------------------------------------

    def build(self) -> Built:
        self._name_everything()
        tops = [b for b in self.order if self.bodies[b].parent == 0]
        trees: dict[int, list[int]] = {t: [] for t in tops}
        top_of: dict[int, int] = {}
        for b in self.order:
            parent = self.bodies[b].parent
            top_of[b] = b if parent == 0 else top_of[parent]
            trees[top_of[b]].append(b)
        position = {t: i for i, t in enumerate(tops)}
        main = max(tops, key=lambda t: (*self._size(trees[t]), -position[t])) if tops else None
        robots: list[Robot] = []
        robot_of_body: dict[int, Robot] = {}
        for top in tops:
            name = self.model_name if top == main else self.link_name[top]
            robot = Robot(name=name, source_format="mjcf", source=self.loc.body(top))
            for b in trees[top]:
                self._body(robot, self.bodies[b])
                robot_of_body[b] = robot
            robots.append(robot)
        if main is not None and len(tops) > 1:
            others = ", ".join(f'"{self.link_name[t]}"' for t in tops if t != main)
            self.sink.emit(
                "MK176",
                f"the worldbody holds {len(tops)} body trees; the robot is the largest one, "
                f'"{self.link_name[main]}", and each other tree is a robot of its own: {others}',
                self.loc.body(next(t for t in tops if t != main)),
            )
        ordered = []
        if main is not None:
            ordered = [robot_of_body[main], *(r for r in robots if r is not robot_of_body[main])]
        return Built(ordered, self.joints, robot_of_body)

    def _size(self, tree: list[int]) -> tuple[int, int]:
        """How big a tree is: its bodies, then its joints (a jointed tree beats a static one)."""
        return len(tree), sum(len(self.bodies[b].joints) for b in tree)

    def _body(self, robot: Robot, body: MjBody) -> None:
        joints = body.joints
        movable = [j for j in joints if j.kind != "free"]
        offset = translation(movable[-1].pos) if movable else Pose()
        self.offset[body.index] = offset
        link = self._link(body, offset)
        if body.parent == 0:
            start, pose = self._root(robot, body, joints)
        else:
            parent_offset = self.offset[body.parent]
            start, pose = self.link_name[body.parent], parent_offset.inverse() @ body.pose
        chain = joints[1:] if body.parent == 0 and joints and joints[0].kind == "free" else joints
        self._chain(robot, body, start, pose, chain, link)
        robot.links.append(link)

    def _root(self, robot: Robot, body: MjBody, joints: list[MjJoint]) -> tuple[str, Pose]:
        """Set the robot's root for a top-level body; return the link and pose its chain starts at."""
        if not joints:
            robot.root, robot.root_joint, robot.root_pose = (
                self.link_name[body.index],
                JointType.FIXED,
                body.pose,
            )
            return "", Pose()
        if joints[0].kind == "free":
            robot.root_joint, robot.root_pose = JointType.FLOATING, body.pose
            if len(joints) == 1:
                robot.root = self.link_name[body.index]
                return "", Pose()
            # A free joint followed by others: the free body is a massless link of its own.
            free = joints[0]
            name = self.names.unique(
                f"{self.link_name[body.index]}__{self.joint_name[free.index]}", self.names.links
            )
            robot.root = name
            robot.links.append(self._intermediate(name, body, free))
            return name, Pose()
        world = Link(WORLD_LINK, source=self.loc.body(body.index), synthesised=True)
        world.sources["name"] = self.loc.body(body.index)
        if robot.link(WORLD_LINK) is None:
            robot.links.append(world)
        robot.root, robot.root_joint, robot.root_pose = WORLD_LINK, JointType.FIXED, Pose()
        return WORLD_LINK, body.pose

    def _chain(
        self, robot: Robot, body: MjBody, start: str, pose: Pose, joints: list[MjJoint], link: Link
    ) -> None:
        """Hang ``link`` (the body) from ``start`` through its joints: one link per joint."""
        if not start:
            return
        if not joints:
            name = self.names.unique(f"{start}_to_{link.name}", self.names.joints)
            joint = Joint(
                name, JointType.FIXED, start, link.name, origin=pose, source=self.loc.body(body.index)
            )
            joint.synthesised = True
            joint.sources["name"] = joint.sources["parent"] = self.loc.body(body.index)
            robot.joints.append(joint)
            return
        parent, previous = start, rot3.ZERO3
        links: list[str] = []
        for k, mj in enumerate(joints):
            last = k == len(joints) - 1
            anchor = rot3.ZERO3 if mj.kind == "free" else rot3.vec3(mj.pos)
            step = pose @ translation(anchor) if k == 0 else translation(rot3.sub(anchor, previous))
            origin = step @ self._ref(mj)
            if last:
                child = link.name
            else:
                child = self.names.unique(
                    f"{self.link_name[body.index]}__{self.joint_name[mj.index]}", self.names.links
                )
                robot.links.append(self._intermediate(child, body, mj))
            robot.joints.append(self._joint(mj, parent, child, origin))
            parent, previous = child, anchor
            links.append(child)
        if len(joints) > 1:
            self._report_chain(body, joints, links)

    def _report_chain(self, body: MjBody, joints: list[MjJoint], links: list[str]) -> None:
        names = ", ".join(self.joint_name[j.index] for j in joints)
        chain = " → ".join(f'"{name}"' for name in links)
        self.sink.emit(
            "MK171",
            f'body "{self.link_name[body.index]}" has {len(joints)} joints ({names}); the model holds one '
            f"joint per link, so it becomes a chain of {len(joints)} links, massless but the last: {chain}",
            self.loc.body(body.index),
        )

    @staticmethod
    def _ref(mj: MjJoint) -> Pose:
        """The motion of the joint to q = 0 from its reference position (MuJoCo's body pose is
        the pose at qpos = ref)."""
        norm = rot3.norm(mj.axis)
        if mj.ref == 0.0 or norm == 0.0:
            return Pose()
        if mj.kind == "hinge":
            return Pose(rot3.axis_angle(mj.axis, -mj.ref), rot3.ZERO3)
        if mj.kind == "slide":
            x, y, z = rot3.scale(-mj.ref, rot3.vec3(mj.axis))
            return translation((x / norm, y / norm, z / norm))
        return Pose()

    def _intermediate(self, name: str, body: MjBody, mj: MjJoint) -> Link:
        link = Link(name, source=self.loc.joint(mj.index))
        link.sources["name"] = self.loc.joint(mj.index, "name")
        link.synthesised = True
        link.extras["mjcf_intermediate_of"] = self.link_name[body.index]
        return link

    # -- joints --------------------------------------------------------------------------------

    def _joint(self, mj: MjJoint, parent: str, child: str, origin: Pose) -> Joint:
        loc = self.loc
        norm = rot3.norm(mj.axis)
        x, y, z = rot3.vec3(mj.axis)
        joint = Joint(
            self.joint_name[mj.index],
            JOINT_TYPES[mj.kind],
            parent,
            child,
            origin=origin,
            axis=(x / norm, y / norm, z / norm) if norm > 0 else (x, y, z),
            armature=mj.armature,
            damping=mj.damping,
            friction=mj.frictionloss,
            source=loc.joint(mj.index),
        )
        joint.limits = self._limits(mj, joint)
        for attribute in ("name", "type", "axis", "range", "pos", "ref"):
            joint.sources[attribute] = loc.joint(mj.index, attribute)
        joint.sources["parent"] = loc.joint(mj.index)
        if mj.kind in ("hinge", "slide"):
            joint.initial_position = mj.ref
        extras = {"mjcf_joint_id": mj.index, "mjcf_type": mj.kind}
        if mj.ref:
            extras["mjcf_ref"] = mj.ref
        if mj.stiffness and mj.kind in ("hinge", "slide"):
            joint.spring_stiffness, joint.spring_reference = mj.stiffness, mj.springref
        elif mj.stiffness:
            # MuJoCo pulls a ball (free) joint towards its zero orientation (pose): qpos_spring = qpos0,
            # springref is ignored; the model's reference 0 says so
            joint.spring_stiffness, joint.spring_reference = mj.stiffness, 0.0
        joint.extras.update(extras)
        if mj.physics:  # margin, solreflimit, ... actuatorgravcomp: written back by the MJCF writer only
            joint.extras["mjcf_joint_physics"] = dict(mj.physics)
        self.joints[mj.index] = joint
        return joint

    @staticmethod
    def _limits(mj: MjJoint, joint: Joint) -> JointLimits:
        limits = JointLimits()
        if mj.limited and mj.kind in ("hinge", "slide"):
            limits.lower, limits.upper = mj.range
        elif mj.limited and mj.kind == "ball":
            joint.extras["mjcf_ball_range"] = list(mj.range)
        if mj.actfrc is not None:
            low, high = mj.actfrc
            joint.extras["mjcf_actfrcrange"] = [low, high]
            if low == -high:
                limits.effort = high
        return limits

    # -- links ---------------------------------------------------------------------------------

    def _link(self, body: MjBody, offset: Pose) -> Link:
        b = body.index
        link = Link(self.link_name[b], source=self.loc.body(b))
        link.sources["name"] = self.loc.body(b, "name")
        link.extras["mjcf_body_id"] = b
        shift = offset.translation_tuple
        if any(x != 0.0 for x in shift):
            link.extras["mjcf_body_offset"] = [float(x) for x in shift]
        if body.mocap:
            link.extras["mjcf_mocap"] = True
        if body.physics:  # gravcomp
            link.extras["mjcf_body_physics"] = dict(body.physics)
        back = offset.inverse()
        inertial = body.inertial
        if inertial is not None:
            link.inertial = Inertial(
                inertial.mass,
                com=rot3.add(back.translation_tuple, rot3.vec3(inertial.ipos)),
                # written, or computed by MuJoCo from the geoms: never a default
                inertia=rot3.mat3(inertial.inertia),
                source=self.loc.inertial(b),
            )
            link.inertial.sources["mass"] = self.loc.inertial(b, "mass")
            written = "fullinertia" if "fullinertia" in self._inertial_attributes(b) else "diaginertia"
            link.inertial.sources["inertia"] = self.loc.inertial(b, written)
        self._geoms(link, body, back)
        return link

    def _inertial_attributes(self, body: int) -> Iterable[str]:
        placed = self.loc.inertials.get(body)
        return [str(k) for k in placed.el.attrib] if placed is not None else []

    def _geoms(self, link: Link, body: MjBody, back: Pose) -> None:
        visuals: list[Geom] = []
        collisions: list[Geom] = []
        shown: list[Geom] = []  # the collisions MuJoCo draws: a body's look when it has no visual geom
        for mg in body.geoms:
            geom = self.geom(mg, back)
            if geom is None:
                continue
            if not mg.visual_only and mg.contact:
                entry = {"collision": len(collisions), "name": mg.name, **mg.contact}
                link.extras.setdefault("mjcf_contact", []).append(entry)
            (visuals if mg.visual_only else collisions).append(geom)
            if not mg.visual_only and drawn(mg):
                shown.append(geom)
        link.visuals = visuals if visuals else [self._copy(g) for g in shown]
        link.collisions = collisions

    @staticmethod
    def _copy(geom: Geom) -> Geom:
        return Geom(geom.geometry, geom.pose, geom.name, geom.material, geom.source)

    def geom(self, mg: MjGeom, back: Pose) -> Geom | None:
        """The model geom of a MuJoCo geom (``back`` re-expresses it in the link frame)."""
        geometry = self.geometry(mg)
        where = self.loc.geom(mg.index)
        if geometry is None:
            self.sink.emit(
                "MK172",
                f"{mg.kind} geom{quoted(mg.name)} cannot be held by the model; it is skipped",
                where,
            )
            return None
        material = None
        if mg.rgba is not None:
            rgba = [float(x) for x in mg.rgba]
            clamped, rgba_outside = clamped_fractions(rgba)
            diffuse = (clamped[0], clamped[1], clamped[2])
            material = VisualMaterial(name=mg.material, diffuse=diffuse, transparency=1.0 - clamped[3])
            beyond = _look(material, mg.look, diffuse)
            if beyond and not rgba_outside and f"{mg.material}:{beyond}" in self.bright_said:
                beyond = ""  # the material's own values, said at its first geom
            self.bright_said.add(f"{mg.material}:{beyond}")
            if rgba_outside or beyond:
                shown = " ".join(f"{x:g}" for x in rgba)
                self.sink.emit(
                    "MK513",
                    f"geom{quoted(mg.name)}: " + (f"rgba {shown}" if rgba_outside else beyond)
                    + " has values outside 0..1 (MuJoCo loads it; libsdformat refuses such a colour and "
                    "urdfdom drops it; modelkit clamps it)",
                    where,
                    hint="colours are fractions: 255 is written 1",
                )
            texture = mg.look.get("texture_not_held")
            if texture is not None and mg.material not in self.textures_said:
                self.textures_said.add(str(mg.material))
                self.sink.emit("MK178", f"material {mg.material}: its texture {texture} is generated by "
                               "MuJoCo or not a 2d image; the model holds no such texture, so converted "
                               "files keep the material's colour and look", where)
        friction = None if mg.visual_only else surface_friction(mg)
        return Geom(geometry, back @ mg.pose, mg.name, material, where, friction)

    @staticmethod
    def geometry(mg: MjGeom) -> Geometry | None:
        s = mg.size
        kind = mg.kind
        if kind == "box":
            return Box(rot3.scale(2.0, rot3.vec3(s[:3])))
        if kind == "sphere":
            return Sphere(float(s[0]))
        if kind == "capsule":
            return Capsule(float(s[0]), 2.0 * float(s[1]))
        if kind == "cylinder":
            return Cylinder(float(s[0]), 2.0 * float(s[1]))
        if kind == "ellipsoid":
            return Ellipsoid(rot3.vec3(s[:3]))
        if kind == "mesh" and (mg.mesh_file or mg.mesh_name):
            return Mesh(uri=mg.mesh_file, path=mg.mesh_path, scale=rot3.vec3(mg.mesh_scale))
        return None

    # -- data kept on the robots ---------------------------------------------------------------

    def attached(self, body: int, name: str | None, pose: Pose, **params: Any) -> dict[str, Any]:
        """A site, camera or light of ``body`` as data: its link, and its pose in the link frame."""
        placed = self.offset.get(body, Pose()).inverse() @ pose
        return {
            "name": name,
            "link": self.link_name.get(body),
            "xyz": [float(x) for x in placed.translation_tuple],
            "rotation": [[float(x) for x in row] for row in placed.rotation_tuple],
            **params,
        }

    def sites(self, sites: Iterable[MjSite], body: int) -> list[dict[str, Any]]:
        return [
            self.attached(
                body,
                site.name,
                site.pose,
                type=site.kind,
                size=[float(x) for x in site.size],
                source=str(self.loc.site(site.index)),
                **site.shown,
            )
            for site in sites
        ]


def apply_joint_equalities(
    equalities: list[dict[str, Any]],
    joints: dict[int, Joint],
    refs: dict[int, float],
    sink: DiagnosticSink,
    where: dict[int, SourceLocation],
    actuated: frozenset[int] = frozenset(),
) -> None:
    """Joint-joint equalities become mimics: MuJoCo's ``q1 − ref1 = Σ cᵢ (q2 − ref2)ⁱ`` is the model's
    ``q1 = m·q2 + o`` when only c₀ and c₁ are non-zero. Anything else is reported.

    In MuJoCo both joints keep their freedom and the equality is a constraint between them, so an
    actuator may sit on either; the model's mimic has a direction, and a follower carries no actuator
    of its own (URDF, SDF and the writers' rule). When the source actuates ``joint1`` and not
    ``joint2`` (``actuated``: MuJoCo joint ids with an actuator on the joint itself), the same linear
    constraint is read the other way, ``q2 = (q1 − o) / m``, so that the actuator stays on the leader
    (safety-gymnasium's racecar: its steering servo is on ``joint1``). Only where that makes no chain:
    ``joint2`` follows nothing and leads no other joint.

    A larger group of joints tied by linear equalities, without a loop, with one actuated joint that
    the equalities make follow another, is read from that joint: every other joint of the group follows
    it directly, the linear maps along the way composed (:func:`_rooted_at_the_actuator`; Reachy 2's
    gripper, whose servo is on the finger joint that the equalities tie to a proximal joint, which ties
    the distal joint and two copies)."""
    linear = [eq for eq in equalities if eq["type"] == "joint" and eq["active"]
              and eq["obj2id"] is not None and eq["obj2id"] >= 0]
    followed = [eq["obj2id"] for eq in linear]
    followers = [eq["obj1id"] for eq in linear]
    rooted, covered = _rooted_at_the_actuator(linear, joints, refs, actuated)
    for joint_id, (root, multiplier, offset, index) in sorted(rooted.items()):
        joints[joint_id].mimic = Mimic(joints[root].name, multiplier, offset, source=where.get(index))
    for eq in equalities:
        if eq["type"] != "joint" or not eq["active"] or eq["index"] in covered:
            continue
        follower, leader = joints.get(eq["obj1id"]), joints.get(eq["obj2id"])
        loc = where.get(eq["index"])
        coef = eq["data"][:5]
        if follower is None:
            continue
        if leader is None:
            held = coef[0] + refs.get(eq["obj1id"], 0.0)
            sink.emit(
                "MK172",
                f'joint "{follower.name}" is held at {held:.6g} by an equality with no second joint; '
                "the model cannot hold this (kept as data)",
                loc,
            )
            continue
        if any(abs(c) > 0.0 for c in coef[2:]):
            sink.emit(
                "MK172",
                f'joint "{follower.name}" follows "{leader.name}" through a polynomial of degree '
                f"{max(i for i, c in enumerate(coef) if c)}; a mimic is linear, so it is kept as data",
                loc,
            )
            continue
        ref1, ref2 = refs.get(eq["obj1id"], 0.0), refs.get(eq["obj2id"], 0.0)
        multiplier = coef[1]
        offset = coef[0] + ref1 - multiplier * ref2
        if (multiplier != 0.0 and eq["obj1id"] in actuated and eq["obj2id"] not in actuated
                and eq["obj2id"] not in followers and followed.count(eq["obj2id"]) == 1):
            leader.mimic = Mimic(follower.name, 1.0 / multiplier, -offset / multiplier, source=loc)
            continue
        follower.mimic = Mimic(leader.name, multiplier, offset, source=loc)


def _is_linear(eq: dict[str, Any]) -> bool:
    """Linear and invertible: only c₀ and a non-zero c₁."""
    return is_linear(eq) and eq["data"][1] != 0.0


def _rooted_at_the_actuator(linear: list[dict[str, Any]], joints: dict[int, Joint], refs: dict[int, float],
                            actuated: frozenset[int]
                            ) -> tuple[dict[int, tuple[int, float, float, int]], set[int]]:
    """The groups of joints tied by linear equalities that are read from their one actuated joint
    (:func:`apply_joint_equalities`): ``joint → (actuated joint, m, o, equality index)`` with
    ``q = m·q_actuated + o``, and the indices of the equalities this covers. A group qualifies when its
    equalities make no loop, exactly one of its joints is actuated, and an equality makes that joint
    follow another (otherwise the equalities are read as written)."""
    # joint → (neighbour, m, o, equality index) with q_neighbour = m·q + o
    steps: dict[int, list[tuple[int, float, float, int]]] = {}
    edges = [eq for eq in linear if eq["obj1id"] in joints and eq["obj2id"] in joints and _is_linear(eq)]
    for eq in edges:
        one, two = eq["obj1id"], eq["obj2id"]
        coef = eq["data"]
        multiplier = coef[1]
        offset = coef[0] + refs.get(one, 0.0) - multiplier * refs.get(two, 0.0)  # q1 = m·q2 + o
        steps.setdefault(two, []).append((one, multiplier, offset, eq["index"]))
        steps.setdefault(one, []).append((two, 1.0 / multiplier, -offset / multiplier, eq["index"]))
    rooted: dict[int, tuple[int, float, float, int]] = {}
    covered: set[int] = set()
    seen: set[int] = set()
    for start in sorted(steps):
        if start in seen:
            continue
        group, order = {start}, [start]
        for joint_id in order:
            for neighbour, *_ in steps[joint_id]:
                if neighbour not in group:
                    group.add(neighbour)
                    order.append(neighbour)
        seen |= group
        indices = {index for j in group for *_, index in steps[j]}
        drivers = sorted(group & actuated)
        if len(indices) != len(group) - 1 or len(drivers) != 1:
            continue  # a loop, or no actuated joint or several: the equalities as written
        root = drivers[0]
        if not any(eq["obj1id"] == root for eq in edges if eq["index"] in indices):
            continue  # the actuated joint leads already
        maps: dict[int, tuple[float, float]] = {root: (1.0, 0.0)}
        queue = [root]
        for joint_id in queue:
            m0, o0 = maps[joint_id]
            for neighbour, m, o, index in steps[joint_id]:
                if neighbour not in maps:
                    maps[neighbour] = (m * m0, m * o0 + o)
                    rooted[neighbour] = (root, m * m0, m * o0 + o, index)
                    queue.append(neighbour)
        covered |= indices
    return rooted, covered


def quoted(name: str | None) -> str:
    """`` "name"`` with a leading blank, or "" when there is no name (for messages)."""
    return f' "{name}"' if name else ""


MUJOCO_DEFAULT_FRICTION = SurfaceFriction(1.0, 0.0, 0.0)
"""What a geom of MuJoCo's default ``friction="1 0.005 0.0001"`` and ``condim="3"`` does."""


def surface_friction(mg: MjGeom) -> SurfaceFriction | None:
    """The friction a MuJoCo geom brings to a contact: its sliding coefficient, and its torsional and
    rolling ones where its ``condim`` lets them act (4: torsional, 6: and rolling). MuJoCo mixes two
    geoms of equal priority by the larger condim and the larger coefficients, so a geom's ``condim``
    1 makes only its contacts with other condim-1 geoms frictionless (a humanoid's limbs), not with a
    floor: it is kept with the geom's other contact parameters for MJCF output, not read as a
    friction of 0. None when the coefficients are MuJoCo's default, which the source did not choose."""
    sliding, torsional, rolling = (float(x) for x in mg.friction)
    acting = SurfaceFriction(
        sliding,
        torsional if mg.condim >= 4 else 0.0,
        rolling if mg.condim >= 6 else 0.0,
    )
    return None if acting == MUJOCO_DEFAULT_FRICTION else acting


def _look(material: VisualMaterial, look: dict[str, Any], diffuse: tuple[float, float, float]) -> str:
    """A MuJoCo material's specular, shininess, emission and colour texture in the model's terms:
    specular colour (s, s, s), Phong exponent 127·shininess + 1 (Choreonoid's rule), emissive colour
    emission × the colour, the texture's file. Colours are clamped to 0..1 (an emission above 1 is
    brighter than white); returns what was clamped ("" when nothing was)."""
    beyond = []
    if "specular" in look:
        s = float(look["specular"])
        (clamped_s,), outside = clamped_fractions((s,))
        material.specular = (clamped_s,) * 3
        if outside:
            beyond.append(f"specular {s:g}")
    if "shininess" in look:
        material.specular_exponent = 127.0 * float(look["shininess"]) + 1.0
    if "emission" in look:
        e = float(look["emission"])
        emissive, outside = clamped_fractions(e * c for c in diffuse)
        material.emissive = (emissive[0], emissive[1], emissive[2])
        if outside:
            beyond.append(f"emission {e:g} × colour")
    if "texture" in look:
        material.texture = str(look["texture"])
    return ", ".join(beyond)
