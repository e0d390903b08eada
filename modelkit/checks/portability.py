"""Rules about what other tools will do with a model: findings a user wants before converting.

Each rule names the tool whose behaviour it predicts (libsdformat's URDF→SDF conversion, MuJoCo's
URDF loader, PyBullet) so a user knows why a file that passes ``check_urdf`` still fails elsewhere.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import PurePosixPath

from modelkit.checks.masses import lumped_masses, subtree
from modelkit.checks.registry import rule
from modelkit.diagnostics import Diagnostic, diag, did_you_mean
from modelkit.mimics import MIMIC_RANGE_SLACK, leader_range_within
from modelkit.model import WORLD_LINK, Geom, Joint, JointType, Link, Robot

URDF_FORMATS = frozenset({"urdf", "xacro"})
ONE_DOF = frozenset({JointType.REVOLUTE, JointType.PRISMATIC})


@rule("link-multiple-parents", "MK220")
def multiple_parents(robot: Robot) -> Iterator[Diagnostic]:
    """A link is the child of one joint only (check_urdf misses this when both parents share a root).

    MuJoCo refuses such a file, libsdformat drops a joint, PyBullet crashes and yourdfpy raises.
    """
    defined: dict[str, int] = {}
    for link in robot.links:
        defined[link.name] = defined.get(link.name, 0) + 1
    first: dict[str, Joint] = {}
    for joint in robot.joints:
        if defined.get(joint.child, 0) > 1:
            continue  # two links of that name: the duplicate name is the fault (MK204)
        earlier = first.get(joint.child)
        if earlier is None:
            first[joint.child] = joint
            continue
        where = earlier.loc("child")
        line = f" at line {where.line}" if where and where.line else ""
        yield diag(
            "MK220",
            f'link "{joint.child}" has a second parent: joint "{joint.name}" attaches it to '
            f'"{joint.parent}", but joint "{earlier.name}"{line} already attaches it to "{earlier.parent}"',
            joint.loc("child"),
            hint="a kinematic tree gives each link one parent joint; model a closed loop another way",
        )


@rule("mimic-targets", "MK320", "MK321")
def mimic_targets(robot: Robot) -> Iterator[Diagnostic]:
    """A mimic joint follows an existing one-degree-of-freedom joint other than itself, without a loop."""
    by_name: dict[str, Joint] = {}
    for joint in robot.joints:
        by_name.setdefault(joint.name, joint)
    looped = _on_mimic_loops(by_name)
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is None:
            continue
        where = mimic.source or joint.loc("mimic")
        leader = by_name.get(mimic.joint)
        if leader is None:
            yield diag(
                "MK320",
                f'joint "{joint.name}" mimics "{mimic.joint}", which is not a joint of this robot',
                where,
                hint=did_you_mean(mimic.joint, by_name),
            )
        elif leader is joint:
            yield diag("MK321", f'joint "{joint.name}" mimics itself', where)
        elif leader.type not in ONE_DOF:
            yield diag(
                "MK321",
                f'joint "{joint.name}" mimics "{leader.name}", a {leader.type.value} joint; only '
                "revolute, continuous and prismatic joints can be followed",
                where,
            )
        elif (joint.name in looped) if by_name[joint.name] is joint else _mimic_loop(joint, by_name):
            yield diag("MK321", f'joint "{joint.name}" is part of a loop of mimic joints', where)


@rule("mimic-range", "MK326")
def mimic_range(robot: Robot) -> Iterator[Diagnostic]:
    """A mimic keeps its follower inside the follower's range over the whole of the leader's range.

    When it does not, a simulator holding the coupling (MuJoCo's joint equality, Gazebo's mimic) has
    the follower's limit and the coupling fight wherever the leader may go: Fourier's Inspire hand's
    thumb leader ranges over [−0.1, 0.6] rad, its followers at ×1.6 and ×2.4 from 0, and in MuJoCo its
    thumb shook 0.8 rad off its mimic at rest under a stiff coupling."""
    by_name: dict[str, Joint] = {}
    for joint in robot.joints:
        by_name.setdefault(joint.name, joint)
    for joint in robot.joints:
        mimic = joint.mimic
        leader = by_name.get(mimic.joint) if mimic is not None else None
        if mimic is None or leader is None or leader is joint or joint.type not in ONE_DOF \
                or leader.type not in ONE_DOF:
            continue
        low, high = leader.limits.lower, leader.limits.upper
        own_low, own_high = joint.limits.lower, joint.limits.upper
        finite = all(math.isfinite(x) for x in (low, high, own_low, own_high))
        if not finite or low > high or own_low > own_high:
            continue
        ends = sorted((mimic.multiplier * low + mimic.offset, mimic.multiplier * high + mimic.offset))
        past = max(own_low - ends[0], ends[1] - own_high)
        if past <= MIMIC_RANGE_SLACK:
            continue
        reachable = leader_range_within(mimic.multiplier, mimic.offset, (low, high), (own_low, own_high))
        if reachable is None:
            hint = ("no position of the leader keeps the follower in its range: check the mimic's multiplier "
                    "(its sign) and offset")
        elif reachable[1] - reachable[0] <= MIMIC_RANGE_SLACK:
            hint = (f"only the leader at {reachable[0]:.6g} keeps the follower in its range: check the "
                    "mimic's multiplier (its sign) and offset")
        else:
            hint = (f"the coupling allows the leader [{reachable[0]:.6g}, {reachable[1]:.6g}]: narrow its "
                    "range to that, or widen the follower's")
        yield diag(
            "MK326",
            f'joint "{joint.name}" mimics "{leader.name}" ({mimic.multiplier:.6g} × q + {mimic.offset:.6g}): '
            f"over the leader's range [{low:.6g}, {high:.6g}] it would reach [{ends[0]:.6g}, {ends[1]:.6g}], "
            f"past its own range [{own_low:.6g}, {own_high:.6g}] by {past:.3g}; a simulator holding the "
            "coupling makes it fight the limit there",
            mimic.source or joint.loc("mimic"),
            hint=hint,
        )


def _on_mimic_loops(by_name: dict[str, Joint]) -> set[str]:
    """The names of the joints on a loop of mimic joints (each joint follows the next), found in one pass
    over the leader-of map: each name is walked from once, so a chain of 10,000 mimics is linear."""
    looped: set[str] = set()
    done: set[str] = set()
    for start in by_name:
        path: dict[str, None] = {}  # the names walked from ``start`` (ordered)
        name: str | None = start
        while name is not None and name not in done and name not in path:
            path[name] = None
            mimic = by_name[name].mimic
            name = mimic.joint if mimic is not None and mimic.joint in by_name else None
        if name is not None and name in path:  # the walk closed on itself: the names from there loop
            walked = list(path)
            looped.update(walked[walked.index(name):])
        done.update(path)
    return looped


def _mimic_loop(start: Joint, by_name: dict[str, Joint]) -> bool:
    """Whether following the mimics from ``start`` comes back to its name (for a joint whose name an
    earlier joint holds, which :func:`_on_mimic_loops` does not see)."""
    seen = {start.name}
    current: Joint | None = start
    while current is not None and current.mimic is not None:
        current = by_name.get(current.mimic.joint)
        if current is None:
            return False
        if current.name in seen:
            return current.name == start.name
        seen.add(current.name)
    return False


@rule("massless-links-dropped", "MK322")
def massless_links_dropped(robot: Robot) -> Iterator[Diagnostic]:
    """Links libsdformat's URDF→SDF conversion (Gazebo) would drop, with their whole subtree.

    libsdformat first merges every link hung on a fixed joint into its parent (fixed-joint lumping),
    then leaves out any remaining link without ``<inertial>`` or with zero mass, and everything below
    it, with no message on the console. A link named ``world`` is exempt.
    """
    if robot.source_format not in URDF_FORMATS or robot.root is None:
        return
    children = robot.children_of()
    links = {link.name: link for link in robot.links}
    lumped_mass = lumped_masses(robot, lump_into_world=False)
    if robot.root != WORLD_LINK and lumped_mass.get(robot.root, 0.0) <= 0.0 and robot.root in links:
        yield diag(
            "MK322",
            f'the root link "{robot.root}" has no mass, even after merging the links fixed to it: '
            "libsdformat/Gazebo would silently leave out the whole robot",
            links[robot.root].loc("name"),
            hint="give the root an <inertial>, or add a \"world\" root link with a fixed joint",
        )
        return
    stack = [robot.root]
    seen: set[str] = set()
    while stack:
        name = stack.pop()
        if name in seen:
            continue
        seen.add(name)
        for joint in children.get(name, []):
            child = joint.child
            if joint.type is JointType.FIXED and name != WORLD_LINK:
                stack.append(child)  # merged into its parent: judged with it
                continue
            if child != WORLD_LINK and lumped_mass.get(child, 0.0) <= 0.0 and child in links:
                lost = len(subtree(children, child))
                below = f" and the {lost - 1} link(s) below it" if lost > 1 else ""
                yield diag(
                    "MK322",
                    f'link "{child}" has no mass (no <inertial>, or mass 0, after merging the links '
                    f"fixed to it): libsdformat/Gazebo would silently leave it out{below}",
                    links[child].loc("name"),
                    hint="give the link an <inertial> with a small positive mass, or attach it with a "
                    "fixed joint so it is merged into its parent",
                )
                continue
            stack.append(child)


GLTF_SUFFIXES = frozenset({".glb", ".gltf"})


def _urdf_meshes(robot: Robot, suffixes: frozenset[str]) -> Iterator[tuple[Link, Geom, str]]:
    """A URDF's mesh shapes whose file has one of ``suffixes``, each file once (its first shape)."""
    if robot.source_format not in URDF_FORMATS:
        return
    seen: set[str] = set()
    for link in robot.links:
        for geom in [*link.visuals, *link.collisions]:
            uri = getattr(geom.geometry, "uri", None)
            if not uri or PurePosixPath(uri.split("?")[0]).suffix.lower() not in suffixes or uri in seen:
                continue
            seen.add(uri)
            yield link, geom, uri


def _assimp_only(robot: Robot, code: str, kind: str, suffixes: frozenset[str]) -> Iterator[Diagnostic]:
    """A URDF's meshes of a format only Assimp's consumers (rviz, gz-sim) read: MuJoCo has no decoder
    ("no decoder found for mesh file") and PyBullet refuses the whole URDF; one finding per file."""
    for link, geom, uri in _urdf_meshes(robot, suffixes):
        role = "collision" if geom in link.collisions else "visual"
        yield diag(
            code,
            f'{role} mesh "{uri}" is {kind}, read by rviz and gz-sim (Assimp): MuJoCo cannot load it and '
            "PyBullet refuses the whole URDF",
            geom.source or link.loc("name"),
            hint="`modelkit convert` writes it as STL/OBJ for every target",
        )


@rule("gltf-meshes", "MK514")
def gltf_meshes(robot: Robot) -> Iterator[Diagnostic]:
    """glTF meshes in a URDF (PyBullet: "failed to parse link"), measured with MuJoCo 3.14 and PyBullet
    3.2.7 on dexmate's grippers."""
    return _assimp_only(robot, "MK514", "glTF", GLTF_SUFFIXES)


@rule("ply-meshes", "MK515")
def ply_meshes(robot: Robot) -> Iterator[Diagnostic]:
    """PLY meshes in a URDF (ManiSkill's SO-100 collides its jaws with them; PyBullet: "invalid mesh
    filename extension '.ply'"), measured with MuJoCo 3.14 and PyBullet 3.2.7."""
    return _assimp_only(robot, "MK515", "PLY", frozenset({".ply"}))


@rule("planar-joint-pybullet", "MK327")
def planar_joint_pybullet(robot: Robot) -> Iterator[Diagnostic]:
    """A URDF planar joint whose child's centre of mass is off its link frame: PyBullet 3.2.7 puts that
    centre of mass where the link frame belongs (measured; a fixed joint in the planar's place is
    right). Hello Robot's Stretch 4 and roboplan's reachback ride on planar joints."""
    if robot.source_format not in URDF_FORMATS:
        return
    links = {link.name: link for link in robot.links}
    for joint in robot.joints:
        child = links.get(joint.child)
        if joint.type is not JointType.PLANAR or child is None or child.inertial is None:
            continue
        offset = math.hypot(*(float(v) for v in child.inertial.com))
        if offset <= 1e-9:
            continue
        yield diag(
            "MK327",
            f'joint "{joint.name}" is planar and its child "{child.name}" has its centre of mass '
            f"{offset * 1000:.3g} mm from its link frame: PyBullet places the child by its centre of "
            f'mass, so "{child.name}" and every link below it sit {offset * 1000:.3g} mm off in PyBullet '
            "(urdfdom, MuJoCo and Drake follow the file)",
            joint.loc("type"),
            hint="for PyBullet, make the planar joint's child a frame whose centre of mass is its origin "
            "(a link of tiny mass, with the body on a fixed joint below it)",
        )


@rule("collada-for-mujoco", "MK512")
def collada_for_mujoco(robot: Robot) -> Iterator[Diagnostic]:
    """COLLADA meshes in a URDF: MuJoCo cannot load them ("no decoder found for mesh file")."""
    for link, geom, uri in _urdf_meshes(robot, frozenset({".dae"})):
        yield diag(
            "MK512",
            f'mesh "{uri}" is COLLADA: MuJoCo cannot load it from this URDF',
            geom.source or link.loc("name"),
            hint="`modelkit convert` writes it as STL/OBJ for MuJoCo; or use an STL/OBJ copy in the URDF",
        )
