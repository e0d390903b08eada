"""The MJCF writer's armature on the joints a mimic couples (MK835), as a documented approximation.

The MJCF writer gives each joint a mimic couples (leader and follower) at least its own inertia at home
as armature, where the source gives less: MuJoCo's soft joint equality on light fingers never settles
without it (:mod:`modelkit.formats.mjcf.coupling_armature`). The source model has no such armature, so
the MuJoCo engine is compared with the source holding the file's values on those joints, read from the
written file (a file given with ``--mjcf`` comes without the writer's notes): layer 3a's mass matrix
then checks that MuJoCo holds exactly them (Pinocchio built with them), and the replay runs MuJoCo
without any armature, as PyBullet's URDF holds none. Only coupled joints are taken: an armature the
writer put anywhere else is still a difference.

The values themselves are checked against the rule, independently of the writer: each must be the
larger of the source's armature and the joint's own inertia at home, which Pinocchio's composite
rigid-body algorithm gives as the mass matrix's diagonal (:func:`rule_checks`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from lxml import etree

from modelkit.mimics import SLIDERS, coupled_joints
from modelkit.model import Robot
from modelkit.verify.engines.protocol import Check, Skip

Renames = dict[str, dict[str, str]]
RULE_TOLERANCE = 1e-9  # relative: the written armature against the joint's own inertia at home


def written(mjcf: Path, source: Robot, renames: Renames) -> dict[str, float]:
    """Source joint name → the armature the MJCF file gives it, for the coupled joints whose armature
    there is above the source's."""
    coupled = set(coupled_joints(source))
    if not coupled or source.source_format == "mjcf":
        return {}
    back = {name: src for src, name in renames.get("joint", {}).items()}
    own = {joint.name: joint.armature for joint in source.joints}
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    out: dict[str, float] = {}
    for el in etree.parse(str(mjcf), parser).iter("joint"):
        name = back.get(str(el.get("name")), str(el.get("name")))
        value = el.get("armature")
        if name in coupled and value is not None and float(value) > own.get(name, 0.0):
            out[name] = float(value)
    return out


def applied(robot: Robot, armature: Mapping[str, float]) -> Robot:
    """A copy of ``robot`` with those joints' armature."""
    if not armature:
        return robot
    out = copy.deepcopy(robot)
    for joint in out.joints:
        if joint.name in armature:
            joint.armature = armature[joint.name]
    return out


def skip(engine: str, armature: Mapping[str, float]) -> Skip | None:
    """The report's entry (never a silent pass)."""
    if not armature:
        return None
    shown = ", ".join(f"{name} {value:.3g}" for name, value in sorted(armature.items())[:8])
    more = f" ... ({len(armature)} in all)" if len(armature) > 8 else ""
    return Skip(1, engine, (
        f"approximation: the MJCF gives the {len(armature)} joint(s) a mimic couples an armature of their "
        f"own inertia at home (MK835; kg·m², kg for a slide: {shown}{more}). Layer 3a compares this engine "
        "with the source holding it, and checks the values against Pinocchio's inertia at home; the replay "
        "runs MuJoCo without armature, as PyBullet's URDF holds none"))


def rule_checks(engine: str, source: Robot, armature: Mapping[str, float], reference: Any) -> list[Check]:
    """Each written armature against the rule: the larger of the source's armature and the joint's own
    inertia at home (``reference``: the Pinocchio model of the source, whose mass matrix at the home
    configuration has those inertias on its diagonal)."""
    if not armature:
        return []
    from modelkit.convert.servo_gains import home_position

    home = {joint.name: home_position(joint) for joint in source.joints if joint.type in SLIDERS}
    matrix = reference.mass_matrix(home)  # the source's armature on its diagonal
    diagonal = {name: float(matrix[i, i]) for i, name in enumerate(reference.dof_names())}
    own = {joint.name: joint.armature for joint in source.joints}
    checks = []
    for name, value in sorted(armature.items()):
        if name not in diagonal:
            continue
        inertia = diagonal[name] - own.get(name, 0.0)
        expected = max(own.get(name, 0.0), inertia)
        error = abs(value - expected) / max(abs(expected), 1e-300)
        detail = (f"armature {value:.9g} written, the joint's own inertia at home {inertia:.9g} "
                  f"(Pinocchio's mass matrix diagonal), the source's armature {own.get(name, 0.0):.9g}")
        checks.append(Check(3, engine, "coupled-armature", name, error, RULE_TOLERANCE, detail))
    return checks
