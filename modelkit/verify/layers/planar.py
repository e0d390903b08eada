"""How the written files hold a planar joint, so that the layers compare each engine with that model.

No target but URDF has a planar joint (MK813):

* the MJCF writer writes it as two slides and a hinge in the child's body (``<joint>_tx``, ``_ty``,
  ``_rz`` about the axes of ``formats.mjcf.write_bodies.planar_axes``); the MuJoCo adapter reads a
  body with three joints as a chain of three links, the first two ``<body>__<joint>`` and massless
  (the MJCF reader's rule), so :func:`applied_mjcf` gives the source the same chain;
* the SDF writer leaves the child without a joint: it floats, placed at its initial pose. Drake
  gives such a body its own free joint, so :func:`applied_sdf` makes the source's joint floating.

Kinematically and dynamically both are the planar joint at its zero (layers 1 and 2 move the other
joints); the report says so (:func:`skip`)."""

from __future__ import annotations

import copy
from collections.abc import Iterable
from dataclasses import dataclass

from modelkit.convert.notes import ConversionNote, note_matches
from modelkit.model import Joint, JointType, Robot
from modelkit.verify.engines.protocol import Skip
from modelkit.verify.layers.approximations import ChainPieces, with_chains

Renames = dict[str, dict[str, str]]

@dataclass(frozen=True)
class PlanarChain:
    """A source planar joint as the MJCF writer wrote it: two slides and a hinge (written names)."""

    joint: str  # source name
    joints: tuple[str, str, str]  # the written slides along u and v, then the hinge about the normal


@dataclass(frozen=True)
class PlanarHeld:
    """How one engine's file holds the source's planar joints: the MJCF's chains, or the source joints
    whose child the SDF leaves floating (both empty for a URDF, which has planar joints)."""

    chains: list[PlanarChain]
    floated: list[str]

    def applied(self, robot: Robot, renames: Renames) -> Robot:
        """``robot`` as the file holds it (:func:`applied_mjcf`, :func:`applied_sdf`)."""
        return applied_sdf(applied_mjcf(robot, self.chains, renames), self.floated)

    def __bool__(self) -> bool:
        return bool(self.chains or self.floated)


def held_by(fmt: str, notes: Iterable[ConversionNote]) -> PlanarHeld:
    """How a file of ``fmt`` holds the planar joints, read from its writer's MK813 notes."""
    notes = list(notes)
    return PlanarHeld(mjcf_chains(fmt, notes), sdf_floated(fmt, notes))


def mjcf_chains(fmt: str, notes: Iterable[ConversionNote]) -> list[PlanarChain]:
    """The MJCF writer's planar chains, read from its MK813 notes (none for another format)."""
    if fmt != "mjcf":
        return []
    from modelkit.formats.mjcf.write_bodies import PLANAR_NOTE

    return [PlanarChain(match["joint"], (match["x"], match["y"], match["z"]))
            for match in note_matches(notes, "MK813", PLANAR_NOTE)]


def sdf_floated(fmt: str, notes: Iterable[ConversionNote]) -> list[str]:
    """The source planar joints whose child the SDF writer left floating (none for another format)."""
    if fmt != "sdf":
        return []
    from modelkit.formats.sdf.writer import UNJOINTED_NOTE

    return [m["joint"] for m in note_matches(notes, "MK813", UNJOINTED_NOTE) if m["type"] == "planar"]


def applied_mjcf(robot: Robot, chains: list[PlanarChain], renames: Renames) -> Robot:
    """A copy of ``robot`` whose planar joints are the MJCF's chains, as the MuJoCo adapter reads them:
    a slide from the parent at the joint's origin to ``<body>__<x>``, a slide to ``<body>__<y>``,
    a hinge (keeping the source joint's name) to the child, the two added links massless."""
    from modelkit.formats.mjcf.write_bodies import planar_axes

    kinds = (JointType.PRISMATIC, JointType.PRISMATIC, JointType.REVOLUTE)
    by_joint = {chain.joint: chain for chain in chains}

    def pieces(planar: Joint) -> ChainPieces | None:
        chain = by_joint.get(planar.name)
        if chain is None:
            return None
        body = renames.get("link", {}).get(planar.child, planar.child)
        return ((chain.joints[0], chain.joints[1]), [f"{body}__{name}" for name in chain.joints[:2]],
                list(zip(kinds, planar_axes(planar.axis), strict=True)))

    return with_chains(robot, JointType.PLANAR, pieces) if chains else robot


def applied_sdf(robot: Robot, floated: list[str]) -> Robot:
    """A copy of ``robot`` whose planar joints the SDF left out are floating joints."""
    if not floated:
        return robot
    out = copy.deepcopy(robot)
    for joint in out.joints:
        if joint.name in floated and joint.type is JointType.PLANAR:
            joint.type = JointType.FLOATING
    return out


def skip(engine: str, held: PlanarHeld) -> Skip | None:
    """The report's entry for an engine holding planar joints another way (never a silent pass)."""
    chains, floated = held.chains, held.floated
    if chains:
        shown = "; ".join(f"{c.joint} as {', '.join(c.joints)}" for c in chains)
        return Skip(1, engine, f"approximation: the MJCF writer writes {len(chains)} planar joint(s) as two "
                    f"slides and a hinge in the child's body (MK813; MJCF has no planar joint): {shown}. "
                    "Layer 1 compares this engine with the source holding these chains")
    if floated:
        return Skip(1, engine, f"approximation: the SDF writer leaves the child of planar joint(s) "
                    f"{', '.join(floated)} free-floating (MK813; SDF has no planar joint). Layer 1 "
                    "compares this engine with the source holding floating joints there")
    return None
