"""The source model a verification starts from: read it as ``validate`` does (:func:`read_robot`,
with :func:`read_options` built from plain data) and weld its root (:func:`welded_copy`).

Shared by the run (:mod:`modelkit.verify.api`) and the report (:mod:`modelkit.verify.report.html`
re-reads the source when it is given a report alone).
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from modelkit.model import JointType, Robot
from modelkit.spatial import Pose


class VerifyError(Exception):
    """The run could not happen: unreadable input, no robot, a bad option (exit 2)."""


def read_options(reading: Mapping[str, Any] | None) -> tuple[Any, str | None]:
    """The ``ReadOptions`` and input format of verify's reading options given as plain data (the
    keys of ``modelkit verify``'s options: input_format, package_paths {NAME: DIR}, path_variables,
    resource_paths, xacro_args {KEY: VALUE}, legacy_xacro, materials, vrml_extrusion, max_bytes,
    max_links, max_list_items; absent = the default, as in ``validate`` and ``convert``)."""
    from modelkit.formats.common import ReadOptions
    from modelkit.resources import Resolver

    r = dict(reading or {})
    resolver = Resolver(package_paths={k: Path(v) for k, v in r.get("package_paths", {}).items()},
                        path_variables={k: Path(v) for k, v in r.get("path_variables", {}).items()},
                        resource_paths=[Path(p) for p in r.get("resource_paths", [])])
    options = ReadOptions(resolver=resolver, xacro_args=dict(r.get("xacro_args", {})),
                          legacy_xacro=r.get("legacy_xacro"),
                          materials_path=Path(r["materials"]) if r.get("materials") else None,
                          faithful_extrusion=not r.get("vrml_extrusion", False))
    for limit in ("max_bytes", "max_links", "max_list_items"):
        if limit in r:
            setattr(options, limit, int(r[limit]))
    return options, r.get("input_format")


def read_robot(source: Path, reading: Mapping[str, Any] | None = None) -> Robot:
    """The first robot of ``source`` read as ``validate`` reads it; :class:`VerifyError` when the file
    cannot be read or converted."""
    from modelkit.api import validate
    from modelkit.convert.api import CONVERTIBLE_ERRORS, UNREADABLE

    if not os.path.exists(source):  # False for a name too long to look up, as for a missing file
        raise VerifyError(f"{source}: no such file")
    options, fmt = read_options(reading)
    checked = validate(source, options, fmt)
    if any(d.code in UNREADABLE for d in checked.diagnostics):
        raise VerifyError(f"{source}: cannot be read: "
                          + "; ".join(d.message for d in checked.diagnostics if d.code in UNREADABLE))
    blocking = [d for d in checked.errors if d.code not in CONVERTIBLE_ERRORS]
    robots = [r for r in checked.robots if r.root is not None]
    if blocking or not robots:
        why = "; ".join(f"{d.code} {d.message}" for d in blocking[:3]) or "no robot with a root link"
        raise VerifyError(f"{source}: cannot be converted: {why}")
    return robots[0]


def welded_copy(robot: Robot) -> tuple[Robot, str]:
    """The robot with its root welded to the world at the identity, and the sentence that says so.

    A URDF's empty ``world`` link welded to the robot is absorbed first, as ``convert`` does (the
    written files' root is the robot's first link, so the reference's must be too)."""
    from modelkit.convert.base import absorb_world_weld

    out = copy.deepcopy(robot)
    absorb_world_weld(out)
    was = out.root_joint.value if out.root_joint is not None else "left open by the format"
    out.root_joint = JointType.FIXED
    out.root_pose = Pose()
    return out, (f"root link {out.root!r} ({was} in the source) welded to the world at the identity "
                 "for layers 1-3")


def root_tree_only(robot: Robot) -> list[str]:
    """Remove from ``robot`` (in place) every link the root's tree does not reach, with the joints,
    loops and actuators that touch them; return the removed links' names, in document order.

    An SDF model may hold links no joint connects to the root (MK201): each is a free body of its
    own. Layers 1-3 compare one tree welded at its root, which those bodies are not part of, so they
    are taken out before the files are written and the report says they were not graded."""
    reached = set(robot.world_poses({})) if robot.root is not None else set()
    removed = [link.name for link in robot.links if link.name not in reached]
    if not removed:
        return []
    gone = set(removed)
    robot.links = [link for link in robot.links if link.name not in gone]
    dropped = {j.name for j in robot.joints if j.parent in gone or j.child in gone}
    robot.joints = [j for j in robot.joints if j.name not in dropped]
    for joint in robot.joints:
        if joint.mimic is not None and joint.mimic.joint in dropped:
            joint.mimic = None
    robot.loops = [loop for loop in robot.loops if loop.link1 not in gone and loop.link2 not in gone]
    robot.actuators = [a for a in robot.actuators if a.joint not in dropped]
    robot.free_link_poses = {k: v for k, v in robot.free_link_poses.items() if k not in gone}
    return removed
