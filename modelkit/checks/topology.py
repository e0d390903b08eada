"""Rules about the kinematic tree: names, parents, roots, cycles, joint ids."""

from __future__ import annotations

from collections.abc import Iterator

from modelkit.checks.registry import rule
from modelkit.diagnostics import Diagnostic, Severity, diag, did_you_mean
from modelkit.model import Link, Robot


@rule("unique-names", "MK204", "MK205")
def unique_names(robot: Robot) -> Iterator[Diagnostic]:
    """Link names are unique, and so are joint names."""
    first_link: dict[str, int] = {}
    for index, link in enumerate(robot.links):  # not links.index(link): quadratic in links
        if link.name == "":
            continue
        if link.name in first_link:
            where = robot.links[first_link[link.name]].loc("name")
            line = f" (first at line {where.line})" if where and where.line else ""
            yield diag("MK204", f'duplicated link name "{link.name}"{line}', link.loc("name"))
        else:
            first_link[link.name] = index
    first_joint: dict[str, int] = {}
    for i, joint in enumerate(robot.joints):
        if joint.implicit_name:
            continue  # named after its link: a duplicate is already a duplicate link name
        if joint.name in first_joint:
            where = robot.joints[first_joint[joint.name]].loc("name")
            line = f" (first at line {where.line})" if where and where.line else ""
            yield diag("MK205", f'duplicated joint name "{joint.name}"{line}', joint.loc("name"))
        else:
            first_joint[joint.name] = i


@rule("parents-exist", "MK202")
def parents_exist(robot: Robot) -> Iterator[Diagnostic]:
    """Every joint's parent link exists."""
    names = {link.name for link in robot.links}
    for joint in robot.joints:
        if joint.parent in names:
            continue
        if joint.implicit_name:  # .body: the joint is its link
            yield diag(
                "MK202",
                f'parent link "{joint.parent}" of "{joint.child}" is not defined',
                joint.loc("parent"),
            )
        elif joint.parent == "":
            yield diag(
                "MK202",
                f'joint "{joint.name}" names no parent link',
                joint.loc("parent"),
                hint='add <parent link="..."/>',
            )
        else:
            world = joint.parent == "world" and "world" not in names
            yield diag(
                "MK202",
                f'parent link "{joint.parent}" of joint "{joint.name}" is not defined',
                joint.loc("parent"),
                hint=WORLD_HINT if world else did_you_mean(joint.parent, names),
            )


WORLD_HINT = ('declare <link name="world"/> to weld the robot to the world: Drake takes an undeclared '
              '"world" as its world body, but urdfdom (check_urdf, ROS) needs the link')


@rule("single-root", "MK200", "MK201")
def single_root(robot: Robot) -> Iterator[Diagnostic]:
    """Exactly one link has no parent (formats that name their root are checked by the reader)."""
    if robot.root is not None:
        return
    children = {j.child for j in robot.joints}
    roots = [link for link in robot.links if link.name not in children]
    if not roots and robot.links:
        if any(True for _ in no_cycles(robot)):
            return  # every link has a parent because of a cycle: no-cycles reports it, with its path
        defined = {link.name for link in robot.links}
        hanging = sorted({f'"{j.child}" hangs from "{j.parent}"' for j in robot.joints
                          if j.parent and j.parent not in defined})
        why = f" ({'; '.join(hanging)}, which is not defined: MK202)" if hanging else ""
        yield diag("MK200", f"no root link found: every link has a parent{why}", robot.links[0].loc("name"))
    elif len(roots) > 1:
        names = ", ".join(f'"{r.name}"' for r in roots)
        yield diag("MK201", f"{len(roots)} root links found: {names}", roots[1].loc("name"))


@rule("no-cycles", "MK203")
def no_cycles(robot: Robot) -> Iterator[Diagnostic]:
    """Following parents from any link ends at the root, never in a loop.

    Joints are attached in document order, as Choreonoid does, and the joint whose attachment
    closes a loop is the one reported.
    """
    attached: dict[str, str] = {}  # child -> parent, for the joints attached so far (a forest)
    top: dict[str, str] = {}  # union-find towards the topmost ancestor, with path compression

    def topmost(name: str) -> str:
        chain = []
        while name in top:
            chain.append(name)
            name = top[name]
        for item in chain:
            top[item] = name
        return name

    for joint in robot.joints:
        if joint.child in attached:
            continue  # a second parent: not a cycle by itself
        if topmost(joint.parent) != joint.child:
            attached[joint.child] = joint.parent
            top[joint.child] = joint.parent
            continue
        # The child is an ancestor of the parent: this joint would close a loop (it stays out).
        path = [joint.child, joint.parent]
        while path[-1] != joint.child:
            path.append(attached[path[-1]])
        loop = " -> ".join(reversed(path))
        yield diag(
            "MK203",
            f'adding "{joint.child}" to link "{joint.parent}" results in a cyclic reference ({loop})',
            joint.loc("parent"),
        )


@rule("joint-ids", "MK206", "MK207")
def joint_ids(robot: Robot) -> Iterator[Diagnostic]:
    """Joint ids are unique and dense from 0 (Choreonoid pads gaps with dummy joints)."""
    seen: dict[int, str] = {}
    for joint in robot.joints:
        if joint.joint_id is None:
            continue
        if joint.joint_id in seen:
            yield diag(
                "MK206",
                f'joint id {joint.joint_id} of "{joint.child}" is duplicated (also "{seen[joint.joint_id]}")',
                joint.loc("id"),
            )
        else:
            seen[joint.joint_id] = joint.child
    if seen:
        missing = sorted(set(range(max(seen) + 1)) - set(seen))
        if missing:
            first = min((j for j in robot.joints if j.joint_id is not None), key=lambda j: j.joint_id or 0)
            ids = ", ".join(str(i) for i in missing[:10]) + (" ..." if len(missing) > 10 else "")
            yield diag(
                "MK207",
                f"joint id(s) {ids} are not specified; Choreonoid fills them with dummy joints",
                first.loc("id"),
            )


def _name_collision_verdict(robot: Robot) -> tuple[Severity, str]:
    """How bad a link/joint name collision is for this file's own format, and who breaks on it.

    Only SDFormat 1.7+ makes links and joints share one namespace (libsdformat refuses the file); URDF,
    older SDFormat, MJCF and .body keep them apart, so there the collision is a portability problem.
    """
    fmt = robot.source_format
    if fmt == "sdf":
        version = str(robot.extras.get("sdf_version", ""))
        major, _, minor = version.partition(".")
        if major.isdigit() and minor.isdigit() and (int(major), int(minor)) < (1, 7):
            return Severity.WARNING, (
                f"legal in SDFormat {version}, but libsdformat refuses it once the file is SDFormat 1.7+"
            )
        return Severity.ERROR, "SDFormat 1.7+ (libsdformat, Gazebo) refuses this"
    if fmt == "mjcf":
        return Severity.INFO, (
            "legal MJCF (MuJoCo names bodies and joints apart); SDFormat 1.7+ would refuse it"
        )
    if fmt in ("urdf", "xacro"):
        return Severity.WARNING, (
            "legal URDF (check_urdf, ROS and PyBullet load it), but libsdformat's URDF conversion "
            "(Gazebo) refuses it"
        )
    return Severity.WARNING, "SDFormat 1.7+ (libsdformat, Gazebo) would refuse it after conversion"


@rule("link-joint-name-collision", "MK211")
def link_joint_collision(robot: Robot) -> Iterator[Diagnostic]:
    """A joint named like a link (other than its own implicit name): fatal only in SDFormat 1.7+."""
    links: dict[str, Link] = {}
    for link in robot.links:
        links.setdefault(link.name, link)
    severity, consumers = _name_collision_verdict(robot)
    for joint in robot.joints:
        if joint.implicit_name:
            continue
        same = links.get(joint.name)
        if same is not None:
            where = same.loc("name")
            line = f" (the link is at line {where.line})" if where and where.line else ""
            yield diag(
                "MK211",
                f'joint "{joint.name}" has the same name as a link{line}; {consumers}',
                joint.loc("name"),
                hint=f'rename the joint, e.g. "{joint.name}_joint"',
                severity=severity,
            )


@rule("special-joints", "MK213", "MK214")
def special_joints(robot: Robot) -> Iterator[Diagnostic]:
    """Joint kinds that other formats cannot express exactly."""
    from modelkit.model import JointType

    for joint in robot.joints:
        if joint.type is JointType.FLOATING:
            # measured with PyBullet 3.2.7 and Drake on a URDF floating joint below the root
            consumers = (' (in this URDF: PyBullet welds it, "joint unsupported, creating a fixed joint '
                         f'instead", and Drake leaves "{joint.child}" free at the world origin, the joint\'s '
                         "origin unread; urdfdom and MuJoCo follow the file)"
                         if robot.source_format in ("urdf", "xacro") else "")
            yield diag(
                "MK213",
                f'"{joint.child}" has a free joint below the root: its subtree floats as a separate body; '
                f"MJCF allows a free joint on a top-level body only, SDF none inside a model{consumers}",
                joint.loc("type"),
            )
        elif joint.type is JointType.PSEUDO_CONTINUOUS_TRACK:
            yield diag(
                "MK214",
                f'"{joint.child}" is a pseudo continuous track: kinematically fixed, its contact '
                "surface moves; URDF/SDF/MJCF have no equivalent",
                joint.loc("type"),
            )
