"""Multi-joint MuJoCo bodies, found again: the chains the MJCF reader made, written as one body.

The model holds one joint per link, so the MJCF reader turns a body with joints j1..jn into a chain
of n links: n − 1 synthesised, massless links ``<body>__<joint>`` (``extras["mjcf_intermediate_of"]``
= the body's link) and the body's own link last. Joint k > 1 of the chain is a pure translation, the
step between the anchors (``pos``) of joints k − 1 and k in the body frame (a slide's ``ref`` folds
in as a translation too); joint 1 carries the body's pose.

Written back as one ``<body>`` with the joints in order, each at its ``pos`` in the body frame, the
reader makes the very same chain again, and no massless moving body needs a made-up mass (MuJoCo's
``body_mass`` is the model's exactly). A chain is only taken for one when it is unmistakably the
reader's: every intermediate link synthesised for this body, named as the reader names it, massless,
without geoms, devices or loop ends, with one child joint (hinge, slide or ball) whose origin has no
rotation, and the body is one MuJoCo accepts: at most ``MAX_DOFS`` degrees of freedom, no hinge or
ball after a ball ("ball followed by rotation"). Anything
else is written link by link, as before: in particular a top-level body with a free joint and others
(the reader's floating root ``<body>__<free joint>``), which MuJoCo refuses as one body (more than 6
degrees of freedom), so it can only come from a source MuJoCo did not compile.

The body frame: the end link's frame moved back by the reader's ``mjcf_body_offset`` (the last
joint's ``pos`` in the source), so the written ``pos`` attributes are the source's (but for the
joints before a slide with a ``ref``: the written file has no ``ref``, so they move by ref · axis);
the end link's contents are then written shifted into the body frame (:func:`shifted`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace

import numpy as np

from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose, rotate_inertia

BODY_JOINTS = (JointType.REVOLUTE, JointType.PRISMATIC, JointType.BALL)
INTERMEDIATE_OF = "mjcf_intermediate_of"
BODY_OFFSET = "mjcf_body_offset"
DOFS = {JointType.REVOLUTE: 1, JointType.PRISMATIC: 1, JointType.BALL: 3}
MAX_DOFS = 6  # MuJoCo: "more than 6 dofs in body"


@dataclass(frozen=True)
class Chain:
    """One multi-joint body: its links (intermediates first), joints and frames."""

    end: str  # the link that is the MuJoCo body (mass, geoms, children)
    links: tuple[str, ...]  # the synthesised intermediate links it absorbs, in order
    joints: tuple[Joint, ...]  # the body's hinge/slide/ball joints in order
    positions: tuple[np.ndarray, ...]  # each joint's anchor (``pos``) in the body frame
    entry: Pose  # the chain's first link in the body frame (body pose = its pose @ entry⁻¹)
    shift: Pose  # the end link's frame in the body frame


class ChainFinder:
    def __init__(self, robot: Robot, children: dict[str, list[Joint]]) -> None:
        self.robot = robot
        self.children = children
        self.links = {lk.name: lk for lk in robot.links}
        self.loop_links = {n for loop in robot.loops for n in (loop.link1, loop.link2)}

    def below(self, joint: Joint) -> Chain | None:
        """The chain that ``joint`` (hinge, slide or ball) enters, if its child is an intermediate."""
        start = self.links.get(joint.child)
        if joint.type not in BODY_JOINTS or start is None:
            return None
        end = start.extras.get(INTERMEDIATE_OF)
        if not isinstance(end, str) or not self._absorbable(start, end, joint.name):
            return None
        walked = self._walk(start, end)
        if walked is None:
            return None
        links, rest = walked
        joints = (joint, *rest)
        if not accepted(joints):
            return None
        offset = self.links[end].extras.get(BODY_OFFSET)
        anchor = np.asarray(offset if offset is not None else np.zeros(3), dtype=float)
        positions = [anchor]
        for step in reversed(rest):
            anchor = anchor - step.origin.translation
            positions.insert(0, anchor)
        return Chain(
            end,
            links,
            joints,
            tuple(positions),
            Pose(np.eye(3), positions[0].copy()),
            Pose(np.eye(3), positions[-1].copy()),
        )

    def _walk(self, start: Link, end: str) -> tuple[tuple[str, ...], tuple[Joint, ...]] | None:
        """From an absorbable ``start`` down to ``end``: the intermediates and the joints after it."""
        links = [start.name]
        joints: list[Joint] = []
        current = start
        while True:
            out = self.children.get(current.name, [])
            if len(out) != 1:
                return None
            step = out[0]
            if step.type not in BODY_JOINTS or not np.array_equal(step.origin.rotation, np.eye(3)):
                return None
            joints.append(step)
            if step.child == end:
                return (tuple(links), tuple(joints)) if end in self.links else None
            nxt = self.links.get(step.child)
            if (
                nxt is None
                or nxt.extras.get(INTERMEDIATE_OF) != end
                or not self._absorbable(nxt, end, step.name)
            ):
                return None
            links.append(nxt.name)
            current = nxt

    def _absorbable(self, link: Link, end: str, incoming: str) -> bool:
        inertial = link.inertial
        return bool(
            link.synthesised
            and link.name == f"{end}__{incoming}"
            and (inertial is None or (inertial.mass == 0.0 and not np.any(inertial.inertia)))
            and not (link.visuals or link.collisions or link.devices)
            and link.name not in self.loop_links
        )


def accepted(joints: tuple[Joint, ...]) -> bool:
    """Whether MuJoCo takes these joints in one body (≤ 6 dofs, no rotation after a ball)."""
    if sum(DOFS[j.type] for j in joints) > MAX_DOFS:
        return False
    kinds = [j.type for j in joints]
    ball = kinds.index(JointType.BALL) if JointType.BALL in kinds else len(kinds)
    return all(k is JointType.PRISMATIC for k in kinds[ball + 1 :])


def shifted(link: Link, shift: Pose) -> Link:
    """``link`` with its inertial, geoms and devices expressed in the frame where it sits at ``shift``."""
    if np.array_equal(shift.rotation, np.eye(3)) and not np.any(shift.translation):
        return link
    moved = copy.copy(link)
    moved.visuals = [replace(g, pose=shift @ g.pose) for g in link.visuals]
    moved.collisions = [replace(g, pose=shift @ g.pose) for g in link.collisions]
    moved.devices = [replace(d, pose=shift @ d.pose) for d in link.devices]
    inertial = link.inertial
    if inertial is not None:
        moved.inertial = replace(
            inertial,
            com=shift.rotation @ np.asarray(inertial.com, dtype=float) + shift.translation,
            inertia=rotate_inertia(inertial.inertia, shift.rotation),
        )
    return moved
