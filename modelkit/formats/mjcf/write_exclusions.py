"""MJCF writer, the robot's collision exclusions (MoveIt SRDF ``<disable_collisions>``, read with
``--srdf``) as ``<contact><exclude body1 body2>``.

Each pair's links are mapped to the bodies that hold them (a frame link written as a site is in its
body). A pair is not written when MuJoCo already ignores it (the two links in one body, or a body and
its parent: MuJoCo's ``filterparent``), when it repeats another pair or an ``<exclude>`` already in
the file, when a link is not written as a body of its own or a site (merged by ``--merge-fixed``, a
chain's intermediate link), or when a link is MuJoCo's world body (an exclusion there would also
exclude the floor a user adds). MK866 counts what was written, by the SRDF's reasons, and what was
not and why. The exclusions go in before the self-contact check (MK832), which then finds only the
touching pairs the SRDF does not already disable.
"""

from __future__ import annotations

from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.formats.mjcf.write_bodies import BodyTree
from modelkit.formats.mjcf.write_xml import sub
from modelkit.model import Robot


def write_exclusions(robot: Robot, tree: BodyTree, contact: Element, ctx: WriteContext) -> None:
    if not robot.collision_exclusions:
        return
    done = {frozenset((el.get("body1"), el.get("body2"))) for el in contact.iter("exclude")}
    reasons: dict[str, int] = {}
    skipped: dict[str, int] = {}
    for pair in robot.collision_exclusions:
        first, second = _element(tree, pair.link1), _element(tree, pair.link2)
        why = _unwritten(first, second)
        if why is None:
            assert first is not None and second is not None
            names = frozenset((first.get("name"), second.get("name")))
            if names in done:
                why = "repeated"
            else:
                done.add(names)
                sub(contact, "exclude", body1=str(first.get("name")), body2=str(second.get("name")))
                reason = pair.reason or "no reason given"
                reasons[reason] = reasons.get(reason, 0) + 1
                continue
        skipped[why] = skipped.get(why, 0) + 1
    written = sum(reasons.values())
    by_reason = ", ".join(f"{reason} {count}" for reason, count in sorted(reasons.items()))
    not_written = "; ".join(f"{count} {why}" for why, count in sorted(skipped.items()))
    ctx.note("MK866", f"{written} of the SRDF's {len(robot.collision_exclusions)} disabled collision pair(s) "
             f"written as <contact><exclude>" + (f" ({by_reason})" if by_reason else "")
             + (f"; not written: {not_written}" if not_written else ""),
             robot.collision_exclusions[0].source or robot.source, "contact/exclude")


def _element(tree: BodyTree, link: str) -> Element | None:
    """The body element that holds ``link`` (its own, or the one its site is in), if any."""
    if link in tree.bodies:
        return tree.bodies[link]
    site = tree.sites.get(link)
    if site is not None:
        return tree.bodies.get(site[1])
    return None


def _unwritten(first: Element | None, second: Element | None) -> str | None:
    """Why an exclusion between these bodies is not written (None: it is)."""
    if first is None or second is None:
        return "with a link not written as a body or site (merged)"
    if first.get("name") in (None, "world") or second.get("name") in (None, "world"):
        return "with the world body (it would also exclude a floor)"
    if first is second:
        return "within one body"
    if first.getparent() is second or second.getparent() is first:
        return "between a body and its parent (MuJoCo ignores those)"
    return None
