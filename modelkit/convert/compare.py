"""Is it the same robot? A model-to-model comparison for round trips and conversions.

Compares what a conversion must keep: the link set, the joints (matched by the child link they
move, so a format that invents joint names is still comparable), joint types, axes and limits,
masses, centres of mass, full inertia tensors, and link poses relative to the root at random
joint configurations. Names go through ``renames`` (source name → written name), as the writers'
MK800 notes record them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from modelkit.model import Joint, JointType, Robot
from modelkit.spatial import Pose


@dataclass(frozen=True)
class Difference:
    quantity: str  # "link-set", "joint-type", "axis", "mass", "com", "inertia", "pose", ...
    where: str  # link or joint name (source side)
    detail: str
    error: float = math.inf

    def __str__(self) -> str:
        return f"{self.quantity} {self.where}: {self.detail}"


def _moving_joints(robot: Robot) -> list[Joint]:
    return [j for j in robot.joints if j.type in (JointType.REVOLUTE, JointType.PRISMATIC)]


def random_configuration(robot: Robot, rng: np.random.Generator) -> dict[str, float]:
    """A joint position for every revolute and prismatic joint, inside its limits."""
    q: dict[str, float] = {}
    for joint in _moving_joints(robot):
        lo, hi = joint.limits.lower, joint.limits.upper
        span = math.pi if joint.type is JointType.REVOLUTE else 0.5
        lo = lo if math.isfinite(lo) else -span
        hi = hi if math.isfinite(hi) else span
        q[joint.name] = float(rng.uniform(lo, hi)) if hi > lo else float(lo)
    return q


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(1.0, abs(a), abs(b))


def _limit_equal(a: float, b: float, tol: float) -> bool:
    if math.isinf(a) or math.isinf(b):
        return a == b
    return _rel(a, b) <= tol


def compare_robots(
    a: Robot,
    b: Robot,
    renames: dict[str, str] | None = None,
    tol: float = 1e-9,
    configurations: int = 5,
    seed: int = 0,
    check_limits: bool = True,
    check_velocity_effort: bool = False,
) -> list[Difference]:
    """Differences between source ``a`` and converted ``b`` (an empty list: the same robot).

    Links of ``b`` marked ``synthesised`` are not required in ``a``.
    """
    mapping = renames or {}

    def name(n: str) -> str:
        return mapping.get(n, n)

    out: list[Difference] = []
    a_links = {name(lk.name): lk for lk in a.links}
    b_links = {lk.name: lk for lk in b.links}
    for missing in sorted(set(a_links) - set(b_links)):
        out.append(Difference("link-set", missing, "link missing in the converted model"))
    for extra in sorted(set(b_links) - set(a_links)):
        if not b_links[extra].synthesised:
            out.append(Difference("link-set", extra, "link only in the converted model"))
    b_joint_by_child = {j.child: j for j in b.joints}
    for ja in a.joints:
        child = name(ja.child)
        jb = b_joint_by_child.get(child)
        if jb is None:
            if child in b_links:
                out.append(Difference("joint-set", ja.name, f"no joint moves {child} in the converted model"))
            continue
        if name(ja.parent) != jb.parent:
            out.append(Difference("joint-parent", ja.name, f"parent {name(ja.parent)} became {jb.parent}"))
        if ja.type is not jb.type:
            out.append(Difference("joint-type", ja.name, f"{ja.type.value} became {jb.type.value}"))
            continue
        if ja.type in (JointType.REVOLUTE, JointType.PRISMATIC):
            ax_a = np.asarray(ja.axis, float) / np.linalg.norm(ja.axis)
            ax_b = np.asarray(jb.axis, float) / np.linalg.norm(jb.axis)
            err = float(np.max(np.abs(ax_a - ax_b)))
            if err > tol:
                out.append(Difference("axis", ja.name, f"{ax_a.tolist()} became {ax_b.tolist()}", err))
            if check_limits:
                for attr in ("lower", "upper"):
                    va, vb = getattr(ja.limits, attr), getattr(jb.limits, attr)
                    if not _limit_equal(va, vb, tol):
                        out.append(Difference(f"limit-{attr}", ja.name, f"{va} became {vb}"))
            if check_velocity_effort:
                for attr in ("velocity", "effort"):
                    va, vb = getattr(ja.limits, attr), getattr(jb.limits, attr)
                    if not _limit_equal(va, vb, tol):
                        out.append(Difference(f"limit-{attr}", ja.name, f"{va} became {vb}"))
    for lname, la in sorted(a_links.items()):
        lb = b_links.get(lname)
        if lb is None:
            continue
        ma = la.inertial.mass if la.inertial else 0.0
        mb = lb.inertial.mass if lb.inertial else 0.0
        if _rel(ma, mb) > tol:
            out.append(Difference("mass", lname, f"{ma} became {mb}", _rel(ma, mb)))
            continue
        if ma == 0.0 or la.inertial is None or lb.inertial is None:
            continue
        err = float(np.max(np.abs(np.asarray(la.inertial.com) - np.asarray(lb.inertial.com))))
        if err > tol:
            detail = f"{la.inertial.com.tolist()} became {lb.inertial.com.tolist()}"
            out.append(Difference("com", lname, detail, err))
        ia, ib = np.asarray(la.inertial.inertia), np.asarray(lb.inertial.inertia)
        err = float(np.max(np.abs(ia - ib))) / max(1.0, float(np.max(np.abs(ia))))
        if err > tol:
            out.append(Difference("inertia", lname, f"{ia.tolist()} became {ib.tolist()}", err))
    out.extend(compare_poses(a, b, renames, tol, configurations, seed))
    return out


def _relative_to_root(robot: Robot, q: dict[str, float]) -> dict[str, Pose]:
    poses = robot.world_poses(q)
    if robot.root is None or robot.root not in poses:
        return poses
    base = poses[robot.root].inverse()
    return {k: base @ v for k, v in poses.items()}


def compare_poses(a: Robot, b: Robot, renames: dict[str, str] | None = None, tol: float = 1e-9,
                  configurations: int = 5, seed: int = 0) -> list[Difference]:
    """Link poses relative to the root link at q = 0 and at random configurations of ``a``."""
    renames = renames or {}
    rng = np.random.default_rng(seed)
    b_joint_by_child = {j.child: j for j in b.joints}
    worst: dict[str, Difference] = {}
    for i in range(configurations + 1):
        qa = {} if i == 0 else random_configuration(a, rng)
        qb: dict[str, float] = {}
        for ja in a.joints:
            jb = b_joint_by_child.get(renames.get(ja.child, ja.child))
            if jb is not None and ja.name in qa:
                qb[jb.name] = qa[ja.name]
        pa, pb = _relative_to_root(a, qa), _relative_to_root(b, qb)
        for lname, pose_a in pa.items():
            pose_b = pb.get(renames.get(lname, lname))
            if pose_b is None:
                continue
            err = max(float(np.max(np.abs(pose_a.rotation - pose_b.rotation))),
                      float(np.max(np.abs(pose_a.translation - pose_b.translation))))
            if err > tol and (lname not in worst or err > worst[lname].error):
                detail = f"link pose differs by {err:.3g} at configuration {i}"
                worst[lname] = Difference("pose", lname, detail, err)
    return [worst[k] for k in sorted(worst)]
