"""URDF writer, actuators: the canonical actuators of a non-URDF source as ROS ``<transmission>`` elements.

A URDF source's own ``<transmission>`` and ``<ros2_control>`` blocks are carried over as they were
(:mod:`.write_gazebo`); for any other source each actuator on a written joint becomes

``<transmission name="<joint>_trans"><type>transmission_interface/SimpleTransmission</type>
<joint name="J"><hardwareInterface>hardware_interface/PositionJointInterface</hardwareInterface></joint>
<actuator name="..."><mechanicalReduction>r</mechanicalReduction></actuator></transmission>``

(``Velocity``/``Effort`` for the other kinds), which the URDF reader reads back as the same kind and
reduction. A transmission has no place for gains, gear or ranges: MK844 names what is left out.
"""

from __future__ import annotations

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt
from modelkit.model import ActuatorKind, Robot

INTERFACES = {
    ActuatorKind.POSITION: "hardware_interface/PositionJointInterface",
    ActuatorKind.VELOCITY: "hardware_interface/VelocityJointInterface",
    ActuatorKind.EFFORT: "hardware_interface/EffortJointInterface",
}


def unique_motor(name: str, joint: str, taken: set[str]) -> str:
    """``name``, or ``<name>_<joint>`` (then with ``_`` appended) when another transmission already
    has an actuator of that name (MK242: Drake refuses two), recorded in ``taken``."""
    out = name if name not in taken else f"{name}_{joint}"
    while out in taken:
        out += "_"
    taken.add(out)
    return out


def rename_motor(ctx: WriteContext, old: str, new: str, joint: str) -> None:
    """The MK800 note of :func:`unique_motor`'s renaming."""
    ctx.rename("actuator", old, new, f'another transmission already names actuator "{old}" (joint "{joint}" '
               "is driven by its own; Drake refuses two joint actuators of one name)", None, "transmission")


def write_transmissions(robot_el: Element, robot: Robot, joint_map: dict[str, str], ctx: WriteContext) -> int:
    """Write the transmissions; return how many. Nothing when the source kept its own blocks."""
    if robot.extras.get("transmissions") or robot.extras.get("ros2_control"):
        return 0
    taken: set[str] = set()
    motors: set[str] = set()
    written = 0
    lost: list[str] = []
    for actuator in robot.actuators:
        joint = joint_map.get(actuator.joint)
        if joint is None:
            continue
        name = f"{joint}_trans"
        while name in taken:
            name += "_"
        taken.add(name)
        el = etree.SubElement(robot_el, "transmission", name=name)
        etree.SubElement(el, "type").text = "transmission_interface/SimpleTransmission"
        joint_el = etree.SubElement(el, "joint", name=joint)
        etree.SubElement(joint_el, "hardwareInterface").text = INTERFACES[actuator.kind]
        wanted = actuator.name or f"{joint}_motor"
        motor_name = unique_motor(wanted, joint, motors)
        if motor_name != wanted:
            rename_motor(ctx, wanted, motor_name, joint)
        motor = etree.SubElement(el, "actuator", name=motor_name)
        etree.SubElement(motor, "mechanicalReduction").text = fmt(actuator.reduction)
        written += 1
        dropped = [f"{k} {fmt(v)}" for k, v in (("kp", actuator.kp), ("kv", actuator.kv)) if v]
        if actuator.gear != 1.0:
            dropped.append(f"gear {fmt(actuator.gear)}")
        ranges = (("ctrlrange", actuator.ctrl_range), ("forcerange", actuator.force_range))
        dropped += [f"{what} {fmt(r[0])} {fmt(r[1])}" for what, r in ranges if r is not None]
        if dropped:
            lost.append(f"{joint} ({', '.join(dropped)})")
    if lost:
        ctx.note(
            "MK844",
            f"{len(lost)} actuator(s) written as transmissions without what a transmission cannot hold: "
            + "; ".join(lost),
            robot.source,
            "transmission",
        )
    return written
