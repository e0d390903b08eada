"""From SDF links and joints to the model's tree, with link frames moved to joint frames.

The model (``modelkit.model``) puts each link's frame at its joint frame. SDF lets the two differ
(a joint's pose is its own), so a child link whose SDF frame is not at its joint frame is
**re-framed**: its frame becomes the joint frame at q = 0, everything it holds is re-expressed in
that frame, and the SDF link frame is remembered as ``link.extras["sdf_link_pose"]`` (its pose in
the new frame) so a writer can restore it. Then ``joint.origin = X_parent⁻¹ · X_joint`` with both
in the model frame, and the axis is expressed in the joint (= new child) frame, normalised.

The root is the canonical link (walked up to a link without parent joint). A model with
``<static>`` is welded to the world; a joint whose parent is ``world`` welds the model there when it
is the only one and is fixed (else a link named ``world`` becomes the root, as URDF writes it);
otherwise the model floats. Links that no joint connects to the root float freely in SDF: they
stay in the model (not in the tree) and are reported (MK201, a warning). A link that is the child
of several joints closes a loop: the extra joints become :class:`LoopConstraint` (MK241).
"""

from __future__ import annotations

from dataclasses import dataclass

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, Severity
from modelkit.formats.sdf.collect import ModelTree, Scope
from modelkit.formats.sdf.joints import AxisSpec, JointData
from modelkit.formats.sdf.links import LinkData
from modelkit.formats.sdf.poses import FrameGraph
from modelkit.model import WORLD_LINK, Inertial, Joint, JointType, Link, LoopConstraint, Robot
from modelkit.rot3 import peek
from modelkit.spatial import Pose

LOOP_TYPES = {
    JointType.FIXED: "fixed",
    JointType.REVOLUTE: "hinge",
    JointType.PRISMATIC: "piston",
    JointType.BALL: "ball",
}


@dataclass
class Placement:
    """Where the model is: its frame in the world and whether it is static."""

    model_pose: Pose
    static: bool


class Assembler:
    def __init__(
        self,
        tree: ModelTree,
        graph: FrameGraph,
        links: list[LinkData],
        joints: list[JointData],
        placement: Placement,
        sink: DiagnosticSink,
    ) -> None:
        self.tree = tree
        self.graph = graph
        self.links = links
        self.joints = joints
        self.placement = placement
        self.sink = sink
        self.by_name: dict[str, LinkData] = {}
        for data in links:
            self.by_name.setdefault(data.link.name, data)
        self.frames: dict[str, Pose] = {}  # link -> its (new) frame in the model frame

    def robot(self) -> Robot:
        tree, graph = self.tree, self.graph
        robot = Robot(
            name=tree.name, source_format="sdf", source=tree.scope.src.values.loc(tree.scope.element)
        )
        robot.links = [d.link for d in self.links]
        tree_joints, loops, world_joints, root, free = self._topology()
        synthetic = self._world_root(world_joints)
        if synthetic:
            for jd in world_joints:
                self.frames[jd.child_link or ""] = graph.pose(jd.item.name)
        for ld in self.links:
            parent = tree_joints.get(ld.link.name)
            self.frames.setdefault(
                ld.link.name, graph.pose(parent.item.name) if parent is not None else ld.pose
            )
        for ld in self.links:
            self._reframe(ld)
        for jd in self.joints:
            if tree_joints.get(jd.child_link or "") is jd:
                robot.joints.append(self._joint(jd))
        if synthetic:
            robot.links.insert(0, Link(WORLD_LINK, synthesised=True, extras={"sdf_synthetic_world": True}))
            for jd in world_joints:
                robot.joints.append(self._world_joint(jd))
        for jd in loops:
            robot.loops.append(self._loop(jd))
        self._joint_sensors()
        self._frames_on_links()
        self._root(robot, root, world_joints, synthetic, free)
        return robot

    # -- topology ------------------------------------------------------------------------------

    def _topology(
        self,
    ) -> tuple[dict[str, JointData], list[JointData], list[JointData], str | None, list[str]]:
        """Tree joints by child link, loop-closing joints, joints to the world, the root link and the
        other links without parent (free-floating in SDF).

        Each link hangs from the first joint (in document order) that names it as child; later ones
        close loops. A cycle of such joints is cut at the link written first, which becomes a top.
        """
        static = self.placement.static
        world = [j for j in self.joints if j.parent_link == WORLD_LINK and j.child_link is not None]
        links = [j for j in self.joints if j.valid and j.parent_link != WORLD_LINK]
        incoming: dict[str, JointData] = {}
        loops: list[JointData] = []
        for j in links:
            target = j.child_link or ""
            if target in incoming:
                loops.append(j)
            else:
                incoming[target] = j
        if world and not static:  # a link welded to (or moving on) the world hangs from it
            for j in world:
                first = incoming.pop(j.child_link or "", None)
                if first is not None:
                    loops.append(first)
        children: dict[str, list[JointData]] = {}
        for j in links:
            if incoming.get(j.child_link or "") is j:
                children.setdefault(j.parent_link or "", []).append(j)
        canonical = self.graph.canonical.get(self.tree.scope.frame)
        order = [d.link.name for d in self.links]
        seeds = [j.child_link or "" for j in world] if world and not static else []
        seeds += [self._top_of(canonical, incoming)] if canonical is not None else []
        seeds += [n for n in order if n not in incoming]
        tops: list[str] = []
        visited: set[str] = set()
        cycles: list[JointData] = []

        def cut(link: str) -> None:  # ``link`` is on a cycle of parent joints: cut it here
            joint = incoming.pop(link)
            cycles.append(joint)
            children[joint.parent_link or ""].remove(joint)

        while True:
            for top in seeds:
                if top in visited or top not in self.by_name:
                    continue
                if top in incoming:  # the top of a cycle (every link on it is some joint's child)
                    cut(top)
                tops.append(top)
                stack = [top]
                visited.add(top)
                while stack:  # each link has one tree parent, so a walk from a top never comes back
                    for j in children.get(stack.pop(), []):
                        child = j.child_link or ""
                        if child not in visited:
                            visited.add(child)
                            stack.append(child)
            stranded = [n for n in order if n not in visited]
            if not stranded:
                break
            seeds = [stranded[0]]
        for j in cycles:  # a closed chain (libsdformat loads it, e.g. its four_bar.sdf): not an error
            self.sink.emit(
                "MK241",
                f'joints form a closed chain through link "{j.child_link}": every link on it is the child '
                f'of a joint; joint "{j.item.local}" is kept as a loop constraint and "{j.child_link}" '
                "is taken as the top of the chain",
                j.joint.loc("child"),
            )
        loops = [j for j in self.joints if j in loops or j in cycles]
        for j in (j for j in loops if j not in cycles):
            first = incoming.get(j.child_link or "")
            holder = f'joint "{first.item.local}"' if first is not None else "a cycle of joints"
            self.sink.emit(
                "MK241",
                f'joint "{j.item.local}" closes a kinematic loop: link "{j.child_link}" already hangs from '
                f"{holder}; it is kept as a loop constraint",
                j.joint.loc("child"),
            )
        welded = {j.child_link for j in world} if world and not static else set()
        root = tops[0] if tops else None
        free = [t for t in tops[1:] if t not in welded]
        return incoming, loops, ([] if static else world), root, free

    @staticmethod
    def _top_of(name: str, incoming: dict[str, JointData]) -> str:
        """Walk up the parent joints to a link with no parent (stopping on a cycle)."""
        seen = {name}
        current = name
        while current in incoming:
            parent = incoming[current].parent_link or ""
            if parent in seen:
                break
            current = parent
            seen.add(current)
        return current

    # -- frames ------------------------------------------------------------------------------

    def _reframe(self, data: LinkData) -> None:
        link = data.link
        new = self.frames.get(link.name, data.pose)
        offset = new.inverse() @ data.pose
        if offset.is_identity(1e-12):
            return
        link.extras["sdf_link_pose"] = offset
        for geom in (*link.visuals, *link.collisions):
            geom.pose = offset @ geom.pose
        for device in link.devices:
            device.pose = offset @ device.pose
        for entry in link.extras.get("sdf_geometry", []):
            entry["pose"] = offset @ entry["pose"]
        inertial = link.inertial
        if inertial is not None:
            r = offset.rotation_tuple
            link.inertial = Inertial(
                inertial.mass,
                rot3.add(rot3.matvec(r, rot3.vec3(peek(inertial, "com"))), offset.translation_tuple),
                rot3.rotate_inertia(rot3.mat3(peek(inertial, "inertia")), r),
                inertial.defaulted,
                inertial.source,
                inertial.sources,
            )

    def _axis_in_joint(self, joint_pose: Pose, spec: AxisSpec | None) -> rot3.V3:
        if spec is None:
            return (0.0, 0.0, 1.0)
        xyz = rot3.vec3(spec.xyz)
        if spec.frame:
            frame = self.graph.pose(spec.frame)
            to_joint = rot3.matmul(rot3.transpose(joint_pose.rotation_tuple), frame.rotation_tuple)
            xyz = rot3.matvec(to_joint, xyz)
        norm = rot3.norm(xyz)
        return (xyz[0] / norm, xyz[1] / norm, xyz[2] / norm) if norm > 0.0 else xyz

    def _joint(self, data: JointData) -> Joint:
        joint = data.joint
        pose = self.graph.pose(data.item.name)
        parent = self.frames.get(data.parent_link or "", Pose())
        joint.origin = parent.inverse() @ pose
        joint.axis = self._axis_in_joint(pose, data.axis)
        return joint

    def _world_joint(self, data: JointData) -> Joint:
        joint = data.joint
        pose = self.graph.pose(data.item.name)
        joint.parent = WORLD_LINK
        joint.origin = self.placement.model_pose @ pose
        joint.axis = self._axis_in_joint(pose, data.axis)
        return joint

    def _loop(self, data: JointData) -> LoopConstraint:
        pose = self.graph.pose(data.item.name)
        p = self.frames.get(data.parent_link or "", Pose())
        c = self.frames.get(data.child_link or "", Pose())
        return LoopConstraint(
            name=data.joint.name,
            type=LOOP_TYPES.get(data.joint.type, "fixed"),
            link1=data.parent_link or "",
            link2=data.child_link or "",
            pose_in_link1=p.inverse() @ pose,
            pose_in_link2=c.inverse() @ pose,
            axis=self._axis_in_joint(pose, data.axis),
            source=data.joint.source,
        )

    def _joint_sensors(self) -> None:
        for data in self.joints:
            target = self.by_name.get(data.child_link or "")
            if target is None:
                continue
            frame = self.frames.get(target.link.name, target.pose)
            for device, pose in data.sensors:
                device.pose = frame.inverse() @ pose
                target.link.devices.append(device)

    def _frames_on_links(self) -> None:
        """``<frame>`` elements are kept as named poses on the link they are attached to."""
        for item in self.tree.of_kind("frame"):
            host = self.graph.link_of(item.name)
            data = self.by_name.get(host or "")
            if data is None:
                continue
            frame = self.frames.get(data.link.name, data.pose)
            data.link.extras.setdefault("sdf_frames", {})[item.name] = frame.inverse() @ self.graph.pose(
                item.name
            )

    # -- the root --------------------------------------------------------------------------------

    def _world_root(self, world: list[JointData]) -> bool:
        """Whether the world joints need a synthetic ``world`` link (several, or one that moves)."""
        if not world:
            return False
        return len(world) > 1 or world[0].joint.type is not JointType.FIXED

    def _root(
        self, robot: Robot, root: str | None, world: list[JointData], synthetic: bool, free: list[str]
    ) -> None:
        placement = self.placement
        robot.extras["sdf_model_pose"] = placement.model_pose
        canonical = self.graph.canonical.get(self.tree.scope.frame)
        if canonical is not None:
            robot.extras["sdf_canonical_link"] = canonical
        if synthetic:
            robot.root, robot.root_joint, robot.root_pose = WORLD_LINK, JointType.FIXED, Pose()
        elif root is not None:
            robot.root = root
            robot.root_pose = placement.model_pose @ self.frames.get(root, Pose())
            fixed = placement.static or bool(world)
            robot.root_joint = JointType.FIXED if fixed else JointType.FLOATING
            if world and not placement.static:
                data = world[0]
                robot.extras["sdf_world_joint"] = {
                    "name": data.joint.name,
                    "pose": self.frames.get(root, Pose()).inverse() @ self.graph.pose(data.item.name),
                }
        if placement.static:
            for data in (j for j in self.joints if j.parent_link == WORLD_LINK):
                self.sink.emit(
                    "MK155",
                    f'joint "{data.item.local}" attaches a static model to the world; the model is '
                    "already fixed, the joint is dropped",
                    data.joint.loc("parent"),
                    severity=Severity.INFO,
                )
        floating: dict[str, Pose] = {}
        for name in free:
            link_data = self.by_name[name]
            floating[name] = placement.model_pose @ self.frames.get(name, link_data.pose)
            nested_static = _static_scope(link_data.item.scope)
            if placement.static:
                state = "in a static model it is fixed in the world"
            elif nested_static is not None:
                state = f'its nested model "{nested_static.path}" is static, so it is fixed in the world'
            else:
                state = "in SDF it floats freely as a separate body"
            fixed = placement.static or nested_static is not None
            self.sink.emit(
                "MK201",
                f'link "{link_data.item.local}" is not connected by any joint to the root link '
                f'"{robot.root}"; {state}',
                link_data.link.loc("name"),
                severity=Severity.INFO if fixed else Severity.WARNING,
            )
        if floating:
            robot.free_link_poses = floating


def _static_scope(scope: Scope) -> Scope | None:
    """The innermost static model enclosing ``scope`` (itself included), or None."""
    current: Scope | None = scope
    while current is not None:
        if current.static:
            return current
        current = current.parent
    return None
