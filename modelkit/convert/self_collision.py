"""Which links may collide with each other, for targets that only say it per link (SDF, URDF for Gazebo).

The MJCF writer lets every pair of bodies collide except parent and child (MuJoCo's rule) and the
pairs whose collision shapes touch at rest (MK832, :mod:`modelkit.convert.self_contact`). SDF cannot
exclude a pair: it has a model flag (``<model><self_collide>``: every pair of links not joined by a
joint collides) and a link flag (two links collide when either has ``<self_collide>``; links joined by
a joint never collide). The closest policy: a link that touches nothing at rest is flagged, a link
in a touching pair is not, so every pair MuJoCo keeps collides except pairs of two such unflagged
links. When nothing touches, the model flag says it all.

The touching pairs come from MuJoCo, exactly as for MJCF: the robot is written as MJCF in memory (a
throw-away output plan; nothing reaches the disk and the MJCF writer's notes are dropped) and read
back for its ``<contact><exclude>`` elements.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from lxml import etree

from modelkit.convert.context import WriteContext
from modelkit.model import Robot

MIN_LINKS = 3  # two links with shapes are joined or apart: a pair needs a third to be non-adjacent


@dataclass
class SelfCollision:
    """``model``: the model flag; ``links``: source link names to flag one by one; ``pairs``: the
    touching pairs (source link names); ``failure``: why nothing was checked (None: checked)."""

    model: bool = False
    links: list[str] = field(default_factory=list)
    pairs: list[tuple[str, str]] = field(default_factory=list)
    failure: str | None = None
    decided: bool = False  # False: nothing to say (fewer than MIN_LINKS links with collision shapes)


def source_flags(robot: Robot) -> tuple[bool | None, dict[str, bool]]:
    """What the source itself says: the model's flag (None: nothing) and each link's.

    SDF: ``<model><self_collide>`` and ``<link><self_collide>``; URDF: ``<gazebo reference="L">
    <selfCollide>`` and a robot-level ``<gazebo><self_collide>`` (what libsdformat's import reads)."""
    links = {link.name: link.self_collide for link in robot.links if link.self_collide is not None}
    return robot.self_collide, links


@dataclass
class Flags:
    """What a per-link target writes: the model flag (None: none), the link flags (source link name →
    value), and ``policy`` when they come from :func:`plan` rather than from the source."""

    model: bool | None = None
    links: dict[str, bool] = field(default_factory=dict)
    policy: SelfCollision | None = None


def flags(robot: Robot, ctx: WriteContext) -> Flags:
    """The source's own flags when it has any, else :func:`plan`'s: the model flag when nothing touches
    at rest, else the flag on every link with collision shapes outside the touching pairs; none when
    MuJoCo could not check or there are too few links to say anything."""
    model, links = source_flags(robot)
    if model is not None or links:
        return Flags(model, links)
    policy = plan(robot, ctx)
    if not policy.decided or policy.failure is not None:
        return Flags(policy=policy)
    if policy.model:
        return Flags(True, {}, policy)
    return Flags(None, dict.fromkeys(policy.links, True), policy)


def colliding_links(robot: Robot) -> list[str]:
    return [link.name for link in robot.links if link.collisions]


def plan(robot: Robot, ctx: WriteContext) -> SelfCollision:
    """The policy for ``robot`` (already prepared for the target)."""
    shaped = colliding_links(robot)
    if len(shaped) < MIN_LINKS:
        return SelfCollision()
    pairs, failure = touching(robot, ctx)
    if failure is not None:
        return SelfCollision(failure=failure, decided=True)
    in_pairs = {name for pair in pairs for name in pair}
    if not pairs:
        return SelfCollision(model=True, decided=True)
    return SelfCollision(links=[n for n in shaped if n not in in_pairs], pairs=pairs, decided=True)


def touching(robot: Robot, ctx: WriteContext) -> tuple[list[tuple[str, str]], str | None]:
    """The link pairs MuJoCo finds touching at rest (source names), or why they are unknown."""
    from modelkit.convert.meshes import MeshExporter
    from modelkit.convert.notes import NoteSink, renames
    from modelkit.convert.output import OutputPlan
    from modelkit.formats.mjcf.writer import write_mjcf

    notes = NoteSink()
    relpath = ctx.model_relpath.rpartition("/")[0]
    relpath = f"{relpath}/self_contact.xml" if relpath else "self_contact.xml"
    options = replace(ctx.options, actuators="none")
    draft_plan = OutputPlan(Path("/nonexistent-self-contact-draft"))
    draft = WriteContext(options, notes, MeshExporter(draft_plan, relpath, options, notes), relpath)
    try:
        xml = write_mjcf(robot, draft)
    except Exception as exc:  # the MJCF writer refusing this robot must not stop the real target
        return [], f"the MJCF draft could not be written ({type(exc).__name__}: {exc})"
    unchecked = [n.message for n in notes.items if n.code == "MK833"]
    if unchecked:
        return [], unchecked[0].removeprefix("self-contact at rest not checked: ")
    written = {new: old for old, new in renames(notes.items, "link").items()}
    root = etree.fromstring(xml)
    pairs: list[tuple[str, str]] = []
    for exclude in root.iter("exclude"):
        a, b = exclude.get("body1") or "", exclude.get("body2") or ""
        pairs.append((written.get(a, a), written.get(b, b)))
    return pairs, None
