"""URDF writer, self-collision: ``<gazebo>`` flags for Gazebo and a note for PyBullet (MK834).

URDF has no self-collision element. Two consumers decide it themselves:

* Gazebo (classic and Sim) reads a URDF through libsdformat, which turns ``<gazebo reference="L">
  <selfCollide>true</selfCollide></gazebo>`` into link ``L``'s ``<self_collide>`` and copies the children
  of a ``<gazebo>`` without reference into the model (so ``<self_collide>true</self_collide>`` there is the
  model's flag). The flags follow :mod:`modelkit.convert.self_collision`, as the SDF writer's do: the model
  flag when no two links touch at rest, else the flag on every link with collision shapes that touches
  nothing.
* PyBullet ignores self-collision unless loaded with ``URDF_USE_SELF_COLLISION`` (a loader flag, not
  file content; with it a parent and its child never collide, measured, MuJoCo's rule); the note names
  the touching pairs for ``setCollisionFilterPair``.

An SDF source's own flags are written as such. A URDF source is left as it is: its kept ``<gazebo>``
blocks (with or without ``selfCollide``) are its author's answer for Gazebo, and URDF → URDF stays
byte-stable.
"""

from __future__ import annotations

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.self_collision import flags
from modelkit.model import Robot

PYBULLET = ("PyBullet ignores self-collision unless the URDF is loaded with URDF_USE_SELF_COLLISION "
            "(then a parent and its child never collide, as in MuJoCo)")


def _block(robot_el: Element, reference: str | None, tag: str, value: bool) -> None:
    el = etree.SubElement(robot_el, "gazebo")
    if reference is not None:
        el.set("reference", reference)
    etree.SubElement(el, tag).text = "true" if value else "false"


def write_self_collision(
    robot_el: Element, robot: Robot, link_names: dict[str, str], ctx: WriteContext
) -> None:
    """``link_names``: source link name → written name."""
    if robot.source_format == "urdf":
        return  # its own <gazebo> blocks (or their absence) are written back as they were
    chosen = flags(robot, ctx)
    if chosen.model is not None:
        _block(robot_el, None, "self_collide", chosen.model)
    flagged = [link_names[name] for name in chosen.links if name in link_names]
    for name, value in chosen.links.items():
        if name in link_names:
            _block(robot_el, link_names[name], "selfCollide", value)
    policy = chosen.policy
    if policy is None or not policy.decided:
        return
    if policy.failure is not None:
        message = ("no self-collision flags written (Gazebo's default: off): whether links touch at rest was "
                   f"not checked ({policy.failure})")
    elif policy.model:
        message = ("a robot-level <gazebo><self_collide> (libsdformat copies it into the model): in Gazebo "
                   "every pair of links not joined by a joint collides, as in the MJCF output (no two links "
                   f"touch at rest); {PYBULLET}")
    else:
        shown = ", ".join(f"{link_names.get(a, a)}/{link_names.get(b, b)}" for a, b in policy.pairs)
        message = (
            f"{len(policy.pairs)} link pair(s) touch at rest ({shown}); URDF cannot exclude a pair, so "
            f"<gazebo><selfCollide> is on the {len(flagged)} link(s) that touch nothing: Gazebo classic "
            "collides every pair with a flagged link, gz-sim reads only the model's flag (off: no "
            f"self-collision); {PYBULLET}, then setCollisionFilterPair(..., enableCollision=0) on those pairs"
        )
    ctx.note("MK834", message, robot.source, "gazebo")
