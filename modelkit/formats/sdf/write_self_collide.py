"""SDF writer, self-collision: ``<self_collide>`` on the model or on links, and a note (MK834).

* A source's own flags (SDF's model and link flags, a URDF's ``<gazebo>`` ``selfCollide``) are written
  as it gave them.
* Any other source gets the policy of :mod:`modelkit.convert.self_collision`, the MJCF writer's as far as
  SDF can say it: when no two links touch at rest, ``<model><self_collide>true`` (every pair of links not
  joined by a joint collides, as in MuJoCo); otherwise each link with collision shapes that touches
  nothing gets ``<link><self_collide>true`` and the links of the touching pairs none. Gazebo classic
  applies the link flags (two links collide when either has it), so every pair collides but pairs of two
  touching-pair links; gz-sim's physics reads the model flag only, so there the robot does not collide
  with itself. When MuJoCo could not check, nothing is written (Gazebo's default: no self-collision).
"""

from __future__ import annotations

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.self_collision import flags
from modelkit.model import Robot

CARRIED = frozenset({"selfCollide", "self_collide", "sensor", "mu1", "mu2"})


def only_carried(entries: object) -> bool:
    """URDF ``<gazebo reference>`` blocks that say nothing but what the SDF writer carries on its own:
    ``selfCollide`` or ``self_collide`` (written as link flags), ``<sensor>``s (the link's devices, with
    their plugins) and ``mu1``/``mu2`` (the collisions' own friction, written as their ``<surface>``)."""
    if not isinstance(entries, list) or not entries:
        return False
    for entry in entries:
        try:
            block = etree.fromstring(str(entry.get("xml", ""))) if isinstance(entry, dict) else None
        except etree.XMLSyntaxError:
            return False
        if block is None or not {c.tag for c in block if isinstance(c.tag, str)} <= CARRIED:
            return False
        if any(not (c.get("name") and c.get("type")) for c in block if c.tag == "sensor"):
            return False  # a sensor the reader could not make a device of (MK620) is not carried
    return True


def _model_flag(model: Element, value: bool = True) -> None:
    el = etree.Element("self_collide")
    el.text = "true" if value else "false"
    model.insert(0, el)


def self_collide_policy(
    robot: Robot, ctx: WriteContext, model: Element, written: set[str]
) -> dict[str, bool]:
    """Write the model flag into ``model``; return the link flags (source link name → value)."""
    chosen = flags(robot, ctx)
    if chosen.model is not None:
        _model_flag(model, chosen.model)
    link_flags = {name: value for name, value in chosen.links.items() if name in written}
    policy = chosen.policy
    if policy is None or not policy.decided:
        return link_flags
    if policy.failure is not None:
        message = ("self-collision left off (Gazebo's default): whether links touch at rest was not checked "
                   f"({policy.failure})")
    elif policy.model:
        message = ("<self_collide> on the model: every pair of links not joined by a joint collides, as in "
                   "the MJCF output (no two links touch at rest)")
    else:
        shown = ", ".join(f"{a}/{b}" for a, b in policy.pairs)
        message = (
            f"{len(policy.pairs)} link pair(s) touch at rest ({shown}); SDF cannot exclude a pair, so "
            f"<self_collide> is on the {len(link_flags)} link(s) that touch nothing and off on the others: "
            "Gazebo classic collides every pair with a flagged link (pairs of two unflagged links do not "
            "collide); gz-sim reads only the model's flag, which stays off, so there the robot does not "
            "collide with itself"
        )
    ctx.note("MK834", message, robot.source, "model/self_collide")
    return link_flags
