"""A joint's spring as writers see it, and the note for a target that cannot hold it (MK854).

The model keeps a joint's spring in ``Joint.spring_stiffness``/``spring_reference``; a ball joint's
(MJCF only) pulls towards the joint's zero orientation (MuJoCo: ``qpos_spring`` = ``qpos0``, the
``springref`` attribute is ignored), which its reference 0 stands for. :func:`note_spring_dropped` is
the warning a writer gives when its target has no place for a spring (a joint that held its pose
under load no longer does), naming the joint and the values.
"""

from __future__ import annotations

from dataclasses import dataclass

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt
from modelkit.model import Joint, JointType


@dataclass(frozen=True)
class Spring:
    stiffness: float  # N·m/rad or N/m
    reference: float | None  # the joint position at rest; None: a ball joint's zero orientation


def joint_spring(joint: Joint) -> Spring | None:
    """The joint's spring, or None when it has none."""
    if not (joint.spring_stiffness or joint.spring_reference):
        return None
    ball = joint.type is JointType.BALL
    return Spring(float(joint.spring_stiffness), None if ball else float(joint.spring_reference))


def spring_text(spring: Spring) -> str:
    """``stiffness 5, reference 0.2`` (a ball joint: ``stiffness 5 towards its zero orientation``)."""
    if spring.reference is None:
        return f"stiffness {fmt(spring.stiffness)} towards its zero orientation"
    return f"stiffness {fmt(spring.stiffness)}, reference {fmt(spring.reference)}"


def note_spring_dropped(ctx: WriteContext, joint: Joint, why: str, target: str) -> None:
    """MK854 for ``joint``'s spring, if it has one: ``why`` says what the target lacks."""
    spring = joint_spring(joint)
    if spring is not None:
        ctx.note("MK854", f'joint "{joint.name}": spring ({spring_text(spring)}) left out: {why}',
                 joint.source, target)
