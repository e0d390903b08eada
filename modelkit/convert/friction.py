"""Contact friction for writers: Choreonoid's material pairs turned into numbers a target holds.

A `.body` link names a contact material; the friction of a contact is a property of the *pair*
of materials (``materials.yaml``), or, for a pair the table lacks, Choreonoid's rule
clamp(√(roughness₁·roughness₂), 0, 100). Targets hold friction per shape and combine two shapes'
values by their own rule (MuJoCo: max; PyBullet and Gazebo/ODE: product or min), so a writer asks
here for each link's friction against the floor material and writes it with a note (MK817).

A shape of a URDF, SDF or MJCF source carries its own friction instead (``Geom.friction``): the
writers put it on the same shape where the target holds friction per shape (MJCF, SDF), on the link
where it holds one per link (URDF), and note what the target cannot hold (MK851).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink
from modelkit.model import Link, Robot, SurfaceFriction

FLOOR_MATERIAL = "Ground"  # what Choreonoid's floors and terrains use


@dataclass(frozen=True)
class PairFriction:
    material: str
    against: str
    static: float
    dynamic: float
    restitution: float
    from_table: bool  # False: Choreonoid's √roughness rule for a pair the table lacks


def _canonical(name: str) -> str:
    return "Default" if name.lower() == "default" else name


def pair_friction(a: str, b: str, materials_path: Path | None = None) -> PairFriction:
    """The friction Choreonoid uses between materials ``a`` and ``b``."""
    from modelkit.formats.body.materials import ContactMaterial, load_materials

    table = load_materials(materials_path, DiagnosticSink())
    a, b = _canonical(a), _canonical(b)
    for pair in table.pairs:
        if {_canonical(pair.names[0]), _canonical(pair.names[1])} == {a, b}:
            return PairFriction(a, b, pair.static_friction, pair.dynamic_friction, pair.restitution, True)
    default = table.materials.get("Default", ContactMaterial("Default", 1.0, 1.0))
    ma, mb = table.materials.get(a, default), table.materials.get(b, default)
    mu = min(max(math.sqrt(max(ma.roughness * mb.roughness, 0.0)), 0.0), 100.0)
    restitution = math.sqrt(max((1.0 - ma.viscosity) * (1.0 - mb.viscosity), 0.0))
    return PairFriction(a, b, mu, mu, restitution, False)


def floor_friction(robot: Robot, floor: str = FLOOR_MATERIAL) -> dict[str, PairFriction]:
    """Link name → its friction against the floor material, for links that name a material."""
    out: dict[str, PairFriction] = {}
    for link in robot.links:
        if link.contact_material:
            out[link.name] = pair_friction(link.contact_material, floor, robot.materials_file)
    return out


def link_surface(link: Link) -> tuple[SurfaceFriction | None, list[SurfaceFriction]]:
    """For a target that holds one friction per link (URDF's ``<contact>`` and ``<gazebo>``): the
    friction of the link's first collision that has one, and the other, different ones the link's
    collisions have (which such a target cannot hold)."""
    found: list[SurfaceFriction] = []
    for geom in link.collisions:
        if geom.friction is not None and geom.friction not in found:
            found.append(geom.friction)
    if not found:
        return None, []
    return found[0], found[1:]


def describe(friction: SurfaceFriction) -> str:
    """``sliding 0.3, torsional 0.01`` — the coefficients a source gave, for notes."""
    from modelkit.convert.numbers import fmt

    parts = [f"sliding {fmt(friction.sliding)}"]
    if friction.sliding2 is not None:
        parts.append(f"second direction {fmt(friction.sliding2)}")
    for name, value in (("torsional", friction.torsional), ("rolling", friction.rolling)):
        if value:
            parts.append(f"{name} {fmt(value)} m")
    return ", ".join(parts)
