"""MJCF writer, mimic couplings: an armature floor on the joints a mimic couples (MK835).

A mimic is rigid in URDF, SDF and `.body`; MuJoCo holds it as a joint equality, a soft constraint whose
impedance it sets from the diagonal of the constraint space's inverse inertia. On a hand whose fingers
weigh a few grams and whose followers hang from one another (Fourier's Inspire thumb: a leader and two
followers at ×1.6 and ×2.4, the last with 5.7e-7 kg·m² about its axis) that diagonal is a poor stand-in,
and the coupled joints never settle: commanded away from 0, the thumb's followers swung 1.0 rad about
their mimic for as long as the command held, dexmate's f5d6 hand's 1.7 rad.

Real coupled joints are driven through a linkage or a tendon by the leader's motor, whose reflected
inertia they carry; MuJoCo Menagerie gives its Robotiq 2F-85's drivers an armature of 0.005 kg·m²,
three thousand times the driver link's own. A URDF, SDF or `.body` source gives none, so each joint a
written mimic couples (leader and follower) gets at least its own inertia at home as armature
(:data:`COUPLED_ARMATURE` times the subtree's inertia about its axis, kg for a slide): the coupling then
settles. An MJCF source's own equalities and armatures are its author's and are kept; so are a track
approximation's rollers. The servo gains are computed afterwards, so they include the armature.
"""

from __future__ import annotations

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt
from modelkit.convert.servo_gains import joint_loads
from modelkit.convert.tracks import roller_names
from modelkit.mimics import coupled_joints
from modelkit.model import Robot

COUPLED_ARMATURE = 1.0
"""The armature each coupled joint gets at least, as a multiple of its own inertia at home. Measured on
seven grippers and hands held at home and commanded to 25, 50 and 100 % of their ranges: the worst mimic
violation one second after a command went from 1.0 rad (Inspire) and 1.7 rad (f5d6) to 0.0006 rad;
0.5 left the transients twice as large, and followers alone or leaders alone half as good
(docs/convert.md, "Mimic joints in MuJoCo")."""


def floor_coupled_armature(robot: Robot, ctx: WriteContext) -> None:
    """Raise the armature of every joint a mimic couples to :data:`COUPLED_ARMATURE` × its own inertia
    at home, in place (the writer's own copy of the model), with one MK835 note listing them."""
    if robot.source_format == "mjcf":
        return
    rollers = roller_names(robot, "rollers")
    coupled = {name: joint for name, joint in coupled_joints(robot).items() if name not in rollers}
    if not coupled:
        return
    loads = joint_loads(robot)
    raised: list[str] = []
    for name, joint in coupled.items():
        load = loads.get(name)
        if load is None:
            continue
        own = load.inertia - joint.armature - load.pushed
        floor = COUPLED_ARMATURE * own
        if floor > joint.armature:
            joint.armature = floor
            raised.append(f"{name} {fmt(floor)}")
    if raised:
        shown = ", ".join(raised[:6]) + (f", ... ({len(raised)} in all)" if len(raised) > 6 else "")
        ctx.note(
            "MK835",
            f"{len(raised)} joint(s) coupled by a mimic get an armature equal to their own inertia at home "
            f"(kg·m², kg for a slide: {shown}), as a leader's motor and linkage give them; with none, "
            "MuJoCo's soft coupling of light fingers never settles (docs/convert.md, \"Mimic joints in "
            "MuJoCo\")",
            robot.source,
            "joint/armature",
        )
