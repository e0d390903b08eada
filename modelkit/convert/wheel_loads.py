"""What a drive wheel's servo carries besides the wheel: its share of the robot it pushes.

The joint-space mass matrix sees a wheel joint as the wheel alone (the base is free), but on the floor
the wheel accelerates the robot: each of the ``n`` wheels :mod:`modelkit.convert.wheels` found pushes
``M / n`` of the robot's mass ``M`` at its radius ``r``, a reflected inertia of ``(M / n) r²`` about its
axis. :func:`carried_inertias` gives that per wheel joint, and
:func:`modelkit.convert.servo_gains.joint_loads` adds it, so a velocity servo made up for a wheel
tracks its speed with the robot on it. Measured on example-robot-data's TIAGo (66 kg, wheels of
0.0985 m, velocity interfaces in its ros2_control): from the wheel's own 0.0084 kg·m² the servo's kv
was 1.58 N·m·s/rad, so the heavier-loaded right wheel lagged 0.1 rad/s behind the left one while the
robot accelerated, and it turned 0.09 rad off a straight line in MuJoCo.
"""

from __future__ import annotations

from modelkit.model import Cylinder, Ellipsoid, Robot, Sphere


def _radius(robot: Robot, link_name: str) -> float:
    """The largest round collision radius of a wheel link (0 when it has none)."""
    link = robot.link(link_name)
    if link is None:
        return 0.0
    radii = [g.geometry.radius for g in link.collisions if isinstance(g.geometry, Cylinder | Sphere)]
    radii += [max(g.geometry.radii[0], g.geometry.radii[1]) for g in link.collisions
              if isinstance(g.geometry, Ellipsoid)]
    return max(radii, default=0.0)


def carried_inertias(robot: Robot) -> dict[str, float]:
    """Wheel joint → ``(M / n) r²`` (kg·m²) for the wheels recorded by ``convert.wheels``."""
    from modelkit.convert.wheels import WHEELS_KEY

    wheels = robot.extras.get(WHEELS_KEY)
    if not isinstance(wheels, dict) or not wheels:
        return {}
    mass = robot.total_mass()
    share = mass / len(wheels)
    out = {}
    for link_name, joint_name in wheels.items():
        radius = _radius(robot, str(link_name))
        if radius > 0.0:
            out[str(joint_name)] = share * radius * radius
    return out
