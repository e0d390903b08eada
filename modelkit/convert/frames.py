"""Frame links: links that are only a named place on another link (a tool flange, a TCP, a camera's
optical frame), which MJCF writes as ``<site>``s rather than bodies (docs/convert.md, "Frames as sites").

A link L is a frame when all of these hold:

* L is not the root and is reached from it; it hangs on a ``fixed`` joint from a link of the model
  that is not the world link ``world``;
* L has no inertial, or one of mass exactly 0, and no visual, collision or device;
* nothing else names L or its joint: no closed loop, no mimic (as follower or leader), no actuator;
  L is no pseudo continuous track (nor one of its rollers) and no link a reader made up;
* every child link of L is a frame too, so a whole massless chain (ANYmal's ``*_camera_parent`` →
  ``*_color_frame`` → ``*_optical_frame``) is frames, and a massless link carrying a real body is not.

:func:`frame_links` gives them in tree order (pre-order from the root, children in joint order).
"""

from __future__ import annotations

from modelkit.model import WORLD_LINK, Joint, JointType, Link, Robot


def _carries_nothing(link: Link) -> bool:
    massless = link.inertial is None or link.inertial.mass == 0.0
    return (massless and not link.visuals and not link.collisions and not link.devices
            and not link.synthesised and not link.extras.get("is_continuous_track")
            and link.track is None)


def _named_elsewhere(robot: Robot) -> tuple[set[str], set[str]]:
    """The links named by loops and the joints named by mimics and actuators."""
    links = {name for loop in robot.loops for name in (loop.link1, loop.link2)}
    joints = {a.joint for a in robot.actuators}
    for joint in robot.joints:
        if joint.mimic is not None:
            joints.update((joint.name, joint.mimic.joint))
    return links, joints


def frame_links(robot: Robot) -> list[str]:
    """The frame links of ``robot`` (module docstring), in tree order."""
    root = robot.root
    links = {link.name: link for link in robot.links}
    if root is None or root not in links:
        return []
    children = robot.children_of()
    incoming: dict[str, list[Joint]] = {}
    for joint in robot.joints:
        incoming.setdefault(joint.child, []).append(joint)
    loop_links, busy_joints = _named_elsewhere(robot)
    order: list[str] = [root]  # pre-order, with a stack of its own (chains of 10,000 links)
    seen = {root}
    stack = [root]
    while stack:
        name = stack.pop()
        if name != root:
            order.append(name)
        for joint in reversed(children.get(name, [])):
            if joint.child in links and joint.child not in seen:
                seen.add(joint.child)
                stack.append(joint.child)
    frame: dict[str, bool] = {}
    for name in reversed(order):  # children before parents
        joints = incoming.get(name, [])
        only: Joint | None = joints[0] if len(joints) == 1 else None
        frame[name] = (
            name != root
            and only is not None
            and only.type is JointType.FIXED
            and only.parent != WORLD_LINK
            and only.parent in links
            and only.name not in busy_joints
            and name not in loop_links
            and _carries_nothing(links[name])
            and all(frame.get(j.child, False) for j in children.get(name, []))
        )
    return [name for name in order if frame[name]]
