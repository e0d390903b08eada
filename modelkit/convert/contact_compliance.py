"""PyBullet contact compliance for a wheeled robot that stands on more than three links.

A robot standing on four or more links in one plane (example-robot-data's TIAGo: two drive wheels
and four casters fixed to the base) is statically indeterminate: rigid contact does not fix how its
weight splits among the supports. MuJoCo's soft contacts share it (TIAGo's left drive wheel carries
46–58 N); PyBullet's rigid solver picks a split that leaves that wheel with 0 N, so the written URDF,
loaded on pybullet_data's plane and driven by its own wheels, went backwards and turned (−0.57 m and
−1.69 rad for a 2.85 m straight line). Writing PyBullet's per-link contact stiffness and damping
(URDF ``<contact><stiffness/><damping/>``) on every support makes the split follow the compliance:
the left wheel then carries 54 N and the straight line ends 2 mm off.

The rule: the robot has wheels (:mod:`modelkit.convert.wheels` found some, so its root is free), and
more than three links touch the floor at rest (their collision shapes reach, within
:data:`~modelkit.convert.wheels.GROUND_LEVEL`, the robot's lowest point at q = 0). Each of those ``n``
links gets the stiffness that deflects it :data:`DEFLECTION` under an equal share of the weight,
``k = M g / (n δ)``, and the damping that makes that share critically damped, ``c = 2 √(k M / n)``.
The sink is small because it is not the same on every support: TIAGo's arm puts 163 N on its right
drive wheel and 52 N on its left, so the wheels sink by different depths and, driven by the seed's
torque law, the robot drifts against the rigid no-slip reference (``modelkit verify``, 5 m straight:
7.5 cm off at 4 mm of sink, 1.8 cm at 1 mm, 0.4 cm at 0.25 mm; spin and arc within 2.4 mm and 2.5 mrad
at 0.25 mm). PyBullet's velocity motors hide it (the figures above are the same from 0.1 mm to 3 mm).
At 0.25 mm the load split is the same as at 1 mm (the left wheel 53 N). Other consumers ignore
PyBullet's ``<contact>``; Gazebo and MuJoCo have soft contacts of their own.
"""

from __future__ import annotations

import math

from modelkit.model import Robot

DEFLECTION = 2.5e-4  # m: a support's sink under its equal share of the robot's weight
GRAVITY = 9.81  # m/s²
MIN_SUPPORTS = 4  # three supports are statically determinate


def support_links(robot: Robot) -> list[str]:
    """The links whose collision shapes reach the robot's lowest point at q = 0, in model order."""
    from modelkit.convert.wheels import GROUND_LEVEL, link_lows

    lows = link_lows(robot, robot.world_poses())
    if not lows:
        return []
    floor = min(lows.values())
    return [name for name, low in lows.items() if low - floor <= GROUND_LEVEL]


def pybullet_compliance(robot: Robot) -> tuple[dict[str, tuple[float, float]], str]:
    """Support link → (stiffness N/m, damping N·s/m) for PyBullet, and a sentence saying why (empty
    when the rule does not apply: no wheels, or at most three supports)."""
    from modelkit.convert.wheels import WHEELS_KEY

    wheels = robot.extras.get(WHEELS_KEY)
    if not isinstance(wheels, dict) or not wheels:
        return {}, ""
    supports = support_links(robot)
    if len(supports) < MIN_SUPPORTS:
        return {}, ""
    mass = robot.total_mass()
    if not mass > 0.0:
        return {}, ""
    share = mass / len(supports)
    stiffness = float(f"{share * GRAVITY / DEFLECTION:.3g}")  # made-up values, written short
    damping = float(f"{2.0 * math.sqrt(stiffness * share):.3g}")
    why = (f"the robot stands on {len(supports)} links at rest ({', '.join(supports)}): rigid contact does "
           "not fix how its weight splits among them (PyBullet can leave a drive wheel unloaded), so each "
           f"gets PyBullet's contact stiffness {stiffness:g} N/m and damping {damping:g} N·s/m "
           f"({DEFLECTION * 1e3:g} mm under an equal share of the robot's {mass:.6g} kg, critically damped)")
    return {name: (stiffness, damping) for name in supports}, why
