"""Facts about mimic couplings (``follower = multiplier × leader + offset``) that several parts ask.

* :func:`leader_range_within`: the part of a leader's range that keeps its follower inside the
  follower's own range: validate's MK326 hint, and the MJCF writer's leader ``ctrlrange`` (MK828);
* :func:`followers_by_leader`: each leader's hinge and slide followers: the MJCF writer's ``ctrlrange``;
* :func:`coupled_joints`: the hinges and slides a mimic couples, leaders and followers: the MJCF
  writer's armature floor (MK835), and verify's reading of it.
"""

from __future__ import annotations

from modelkit.model import Joint, JointType, Robot

SLIDERS = (JointType.REVOLUTE, JointType.PRISMATIC)

MIMIC_RANGE_SLACK = 1e-6
"""rad or m: how far a mimic may carry its follower past the follower's range over the leader's range
before it counts (ranges are often written to 6 digits)."""


def leader_range_within(multiplier: float, offset: float, leader: tuple[float, float],
                        follower: tuple[float, float]) -> tuple[float, float] | None:
    """The part of the leader's range whose image stays in the follower's (None: none)."""
    if multiplier == 0.0:
        return leader if follower[0] <= offset <= follower[1] else None
    bounds = sorted(((follower[0] - offset) / multiplier, (follower[1] - offset) / multiplier))
    low, high = max(leader[0], bounds[0]), min(leader[1], bounds[1])
    return (low + 0.0, high + 0.0) if low <= high else None  # + 0.0: no "-0"


def followers_by_leader(robot: Robot) -> dict[str, list[Joint]]:
    """Leader name → the hinges and slides that mimic it, in document order."""
    out: dict[str, list[Joint]] = {}
    for joint in robot.joints:
        if joint.mimic is not None and joint.type in SLIDERS:
            out.setdefault(joint.mimic.joint, []).append(joint)
    return out


def coupled_joints(robot: Robot) -> dict[str, Joint]:
    """Name → joint, for every hinge or slide a mimic couples to another hinge or slide (leaders and
    followers, in the order the followers come; a name held twice counts once, as its first joint)."""
    by_name: dict[str, Joint] = {}
    for joint in robot.joints:
        by_name.setdefault(joint.name, joint)
    out: dict[str, Joint] = {}
    for joint in robot.joints:
        leader = by_name.get(joint.mimic.joint) if joint.mimic is not None else None
        if leader is None or leader is joint or joint.type not in SLIDERS or leader.type not in SLIDERS:
            continue
        out.setdefault(joint.name, joint)
        out.setdefault(leader.name, leader)
    return out
