"""Documented mass approximations: what a written file (or an engine reading it) gives a link that has
no mass in the source, so that the layers compare with it instead of calling it a conversion fault,
and the report lists it instead of passing silently.

A massless link (a frame in the source) cannot always stay massless (MK816):

* the SDF writer gives a massless link that carries geometry or moves an explicit tiny inertial
  (``TINY_MASS`` kg, ``TINY_INERTIA`` kg·m² on each axis, COM at the link origin), because SDF
  would give a link without ``<inertial>`` 1 kg; the note's target is ``link[NAME]/inertial``;
* the MJCF writer gives a moving body whose weld group has no mass ``MIN_MASS`` kg and
  ``MIN_INERTIA`` kg·m² on each axis (MuJoCo refuses a massless moving body); target
  ``body[NAME]/inertial``;
* the URDF writer gives a massless link on a moving joint an explicit tiny inertial
  (``TINY_MASS`` kg, ``TINY_INERTIA`` kg·m² on each axis; target ``link[NAME]/inertial``), and the
  other massless links (frames, the root) the same inertial without a note each;
* a URDF given to ``verify`` (``--urdf``) may hold frames without ``<inertial>`` (URDF's own meaning:
  no mass): **PyBullet** reads such a frame as 1 kg with a unit inertia at the link origin (its URDF
  parser's default); other URDF readers (yourdfpy, Drake) keep it massless.

For each engine, :func:`for_engine` returns these links (source names) with the values the engine
should hold; the caller compares the engine with the source model **with those values applied**
(:func:`applied`): layer 1 checks the engine really holds the documented values (1e-9), layer 3a
uses a Pinocchio reference built from the applied model, and the replay gives MuJoCo PyBullet's
values. :func:`skip` is the report's entry naming every such link, the value and the note code.

Joint limits (MK819): URDF has no unlimited prismatic joint (and no revolute joint limited on one side
only); the URDF writer writes the open bound as ±``SYNTHESISED_POSITION`` = ±1e16, the value
libsdformat writes for an unlimited axis. Every engine reading the URDF (PyBullet, yourdfpy,
``drake-urdf``) must then hold exactly ±1e16 where the source is infinite: :func:`urdf_limits` lists
those joints and bounds, :func:`applied_limits` puts them into the source's static facts for layer 1
(which checks the engine holds them at 1e-9), and :func:`limits_skip` is the report's entry. (The SDF
writer writes ±1e16 too, SDFormat's own "no limit" default before 1.10; the Drake adapter reads a bound
of magnitude ≥ 1e16 in an SDF file as infinite, so the SDF side needs no approximation.)
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from modelkit.convert.notes import ConversionNote
from modelkit.model import BALL_KEYS, Box, Cylinder, Inertial, Joint, JointType, Mesh, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.protocol import Skip, StaticFacts

Renames = dict[str, dict[str, str]]

# kg, kg·m² per axis: PyBullet's UrdfParser default for a link without <inertial>
PYBULLET_NO_INERTIAL = (1.0, 1.0)


@dataclass(frozen=True)
class Approximated:
    """A source-massless link given ``mass`` kg and ``inertia`` kg·m² on each axis at its origin."""

    link: str  # source name
    mass: float
    inertia: float
    code: str
    by: str  # who approximates: "the SDF writer", "the MJCF writer", "PyBullet reading the URDF"
    tensor: tuple[float, ...] | None = None  # a lifted inertia (row-major 3×3): mass and COM kept
    # the engine itself refused the source's tensor and holds its own repair (refused_inertias), as
    # opposed to holding what the writer wrote
    refused_by_engine: bool = False
    # a link massless in the source whose own tensor the writer kept (``tensor``), with ``mass`` kg at
    # its origin (from_notes: the MJCF writer's MK816), as opposed to a lifted tensor (mass, COM kept)
    massless: bool = False


def _source_names(renames: Renames) -> dict[str, str]:
    return {written: source for source, written in renames.get("link", {}).items()}


def from_notes(fmt: str, notes: Iterable[ConversionNote], renames: Renames, source: Robot | None = None
               ) -> dict[str, Approximated]:
    """The writer's own tiny-mass approximations (MK816) in the written ``fmt`` file. The MJCF writer
    keeps a tensor the source gives a massless link (icub-models' iCub: ``torso_2``, 0 kg with 2e-3
    kg·m²) and adds its own to it: the link then holds that sum (``tensor``), with ``MIN_MASS`` at its
    origin."""
    back = _source_names(renames)
    links = {link.name: link for link in source.links} if source is not None else {}
    out: dict[str, Approximated] = {}
    for note in notes:
        # MK870 of a frame: the MJCF writer's lift of a massless link over welded links without inertia
        if not note.target or (note.code != "MK816" and not (fmt == "mjcf" and note.code == "MK870")):
            continue
        if fmt == "sdf":
            from modelkit.formats.sdf.writer import TINY_INERTIA, TINY_MASS

            match = re.fullmatch(r"link\[(.+)\]/inertial", note.target)
            if match:
                name = back.get(match[1], match[1])
                out[name] = Approximated(name, TINY_MASS, TINY_INERTIA, note.code, "the SDF writer")
        elif fmt == "urdf":
            from modelkit.formats.urdf.write_links import TINY_INERTIA, TINY_MASS, TINY_WORDS

            match = re.fullmatch(r"link\[(.+)\]/inertial", note.target)
            if match and TINY_WORDS in note.message:
                name = back.get(match[1], match[1])
                out[name] = Approximated(name, TINY_MASS, TINY_INERTIA, note.code, "the URDF writer")
        elif fmt == "mjcf":
            from modelkit.formats.mjcf.write_bodies import MIN_INERTIA, MIN_MASS

            match = re.fullmatch(r"body\[(.+)\]/inertial", note.target)
            if match and ("moves but has no mass" in note.message
                          or (note.code == "MK870" and "the link itself has no mass" in note.message)):
                name = back.get(match[1], match[1])
                link = links.get(name)
                own = (np.asarray(link.inertial.inertia, dtype=float)
                       if link is not None and link.inertial is not None else np.zeros((3, 3)))
                tensor = None
                if np.any(own != 0.0):
                    tensor = tuple(float(v) for v in (own + MIN_INERTIA * np.eye(3)).ravel())
                out[name] = Approximated(name, MIN_MASS, MIN_INERTIA, note.code, "the MJCF writer", tensor,
                                         massless=tensor is not None)
    return out


BOUND_ROUNDING = "bound-rounding"
"""The code of an engine's refusal of a tensor that validate accepts: its principal moments are on the
triangle bound, and the engine's own eigen-decomposition rounds them over it (PyBullet)."""


def triangle_moments(tensor: np.ndarray) -> tuple[float, float, float] | None:
    """The principal moments (ascending) of ``tensor`` when they violate a + b ≥ c (MK303), else None;
    None too for a tensor whose moments are all within ``ZERO_MOMENT`` of zero (validate's rule: a
    zero inertia, which the URDF readers hold as zero, as iCub's ``head``: -2.4e-35, 0, 2.4e-35)."""
    from modelkit.verify.layers.common import zero_inertia

    if zero_inertia(tensor):
        return None
    a, b, c = (float(v) for v in np.linalg.eigvalsh(0.5 * (tensor + tensor.T)))
    return (a, b, c) if a + b < c else None


def lifted_inertias(fmt: str, notes: Iterable[ConversionNote], renames: Renames, source: Robot
                    ) -> dict[str, Approximated]:
    """Links whose inertia the writer lifted to satisfy the triangle inequality (SDF MK860, MJCF MK870
    "violate a + b"): the engine must hold exactly the writer's tensor, recomputed here from the source
    tensor by the writer's own rule (mass and COM unchanged)."""
    back = _source_names(renames)
    out: dict[str, Approximated] = {}
    links = {link.name: link for link in source.links}
    for note in notes:
        if not note.target:
            continue
        match = re.fullmatch(r"(?:link|body)\[(.+)\]/inertial", note.target)
        if match is None:
            continue
        written = match[1]
        name = back.get(written, written)
        link = links.get(name)
        if link is None or link.inertial is None:
            continue
        tensor = np.asarray(link.inertial.inertia, dtype=float)
        if fmt == "sdf" and note.code == "MK860":
            from modelkit.formats.sdf.writer import sdformat_valid_inertia

            fixed = sdformat_valid_inertia(tensor)[0]
            by = "the SDF writer"
        elif fmt == "mjcf" and note.code == "MK870" and "violate a + b" in note.message:
            from modelkit.formats.mjcf.write_bodies import mujoco_valid_inertia

            fixed = mujoco_valid_inertia(tensor)[0]
            by = "the MJCF writer"
        else:
            continue
        out[name] = Approximated(name, float(link.inertial.mass), 0.0, note.code, by,
                                 tuple(float(v) for v in np.asarray(fixed, dtype=float).ravel()))
    return out


def zero_inertias(fmt: str, notes: Iterable[ConversionNote], renames: Renames, source: Robot
                  ) -> dict[str, Approximated]:
    """Links whose source tensor ``validate`` calls zero (MK302: every principal moment within its
    tolerance of 0; Drake's cart-pole writes 1e-20 on each axis because libsdformat refuses exact
    zeros) on a link with mass. Every writer prints such a tensor as the clean numbers rule says
    (entries below 1e-12 of the link's mass × the robot's size² are 0:
    :func:`modelkit.convert.numbers.clean_inertia`), and the MJCF writer adds 1e-9 kg·m² on each axis
    where MuJoCo would refuse a moving body's singular inertia (MK870 "singular"). The engine is
    compared with that tensor (mass and COM kept): the source's MK302 is a source finding, not a
    conversion FAIL."""
    from modelkit.convert.api import length_scale_of
    from modelkit.convert.numbers import clean_inertia, length_scale

    back = _source_names(renames)
    lifted: set[str] = set()
    balanced: set[str] = set()  # then raised to satisfy the triangle inequality too (ARMAR-4's armr_sho3)
    for note in notes:
        match = re.fullmatch(r"body\[(.+)\]/inertial", note.target or "")
        if fmt == "mjcf" and note.code == "MK870" and match:
            if "singular" in note.message:
                lifted.add(back.get(match[1], match[1]))
            elif "violate a + b" in note.message:
                balanced.add(back.get(match[1], match[1]))
    out: dict[str, Approximated] = {}
    with length_scale(length_scale_of(source)):
        for link in source.links:
            if link.inertial is None or link.inertial.mass <= 0.0:
                continue
            tensor = np.asarray(link.inertial.inertia, dtype=float)
            low, mid, high = (float(v) for v in np.linalg.eigvalsh(0.5 * (tensor + tensor.T)))
            code = refusal_code((low, mid, high))
            # the MJCF writer's "singular" is MuJoCo's test, which can call a tensor singular that
            # validate calls a triangle violation (Stretch's link_puller, smallest moment 1.08e-15: MK303)
            if code != "MK302" and link.name not in lifted:
                continue
            held = clean_inertia(tensor, float(link.inertial.mass))
            if link.name in lifted:
                from modelkit.formats.mjcf.write_bodies import MIN_INERTIA, mujoco_valid_inertia

                held = held + MIN_INERTIA * np.eye(3)
                if link.name in balanced:
                    held = np.asarray(mujoco_valid_inertia(held)[0], dtype=float)
            if np.array_equal(held, tensor):
                continue
            by = ("the MJCF writer, writing the dust as 0 and adding 1e-9 kg·m² per axis (MK870)"
                  if link.name in lifted else "the writer, printing the dust as 0 (clean numbers)")
            if link.name in lifted and link.name in balanced:
                by += ", then raising the two smaller principal moments to a + b = c (MK870)"
            out[link.name] = Approximated(link.name, float(link.inertial.mass), 0.0, code, by,
                                          tuple(float(v) for v in held.ravel()))
    return out


def urdf_frames(urdf: Path, source: Robot, renames: Renames, engine: str) -> dict[str, Approximated]:
    """Links of a URDF that are massless in the source and that its readers give a mass: those with
    the URDF writer's tiny inertial (every massless link it writes, MK816; the URDF reader reads it
    back as none, the engines as written), and, for PyBullet, those without ``<inertial>`` (URDF's own
    meaning: no mass; a URDF given to verify), which PyBullet reads as 1 kg with a unit inertia."""
    from modelkit.formats.urdf.write_links import TINY_INERTIA, TINY_MASS

    back = _source_names(renames)
    massless = {link.name for link in source.links if link.inertial is None or link.inertial.mass == 0.0}
    tree = etree.parse(str(urdf))
    out: dict[str, Approximated] = {}
    for el in tree.iterfind("./link"):
        written = str(el.get("name"))
        name = back.get(written, written)
        if name not in massless:
            continue
        inertial = el.find("inertial")
        if inertial is None:
            if engine == "pybullet":
                out[name] = Approximated(name, *PYBULLET_NO_INERTIAL, "MK816", "PyBullet reading the URDF")
        elif _is_tiny(inertial, TINY_MASS, TINY_INERTIA):
            out[name] = Approximated(name, TINY_MASS, TINY_INERTIA, "MK816", "the URDF writer")
    return out


def sdf_frames(sdf: Path, source: Robot, renames: Renames) -> dict[str, Approximated]:
    """Links of an SDF that are massless in the source and hold the SDF writer's tiny inertial (a
    massless link it keeps, MK816), read from the file: a file given to verify comes without the
    writer's notes, and Drake reads the mass as written."""
    from modelkit.formats.sdf.writer import TINY_INERTIA, TINY_MASS

    back = _source_names(renames)
    massless = {link.name for link in source.links if link.inertial is None or link.inertial.mass == 0.0}
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    out: dict[str, Approximated] = {}
    for el in etree.parse(str(sdf), parser).iter("link"):
        written = str(el.get("name"))
        name = back.get(written, written)
        inertial = el.find("inertial")
        if name in massless and inertial is not None and _is_sdf_tiny(inertial, TINY_MASS, TINY_INERTIA):
            out[name] = Approximated(name, TINY_MASS, TINY_INERTIA, "MK816", "the SDF writer")
    return out


def _is_sdf_tiny(inertial: etree._Element, mass: float, moment: float) -> bool:
    """Whether an SDF ``<inertial>`` is exactly ``mass`` kg at the link origin with ``moment`` on each
    axis (its ``<pose>``, if any, moves no COM: a rotation of an isotropic tensor changes nothing)."""
    try:
        got = float((inertial.findtext("mass") or "nan").strip())
        pose = [float(v) for v in (inertial.findtext("pose") or "0 0 0").split()[:3]]
        tensor = inertial.find("inertia")
        moments = [float((tensor.findtext(k) if tensor is not None else None) or "0")
                   for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")]
    except ValueError:
        return False
    return got == mass and pose == [0.0, 0.0, 0.0] and moments == [moment, moment, moment, 0.0, 0.0, 0.0]


def _is_tiny(inertial: etree._Element, mass: float, moment: float) -> bool:
    """Whether an ``<inertial>`` is exactly ``mass`` kg at the link origin with ``moment`` on each axis."""
    mass_el, tensor, origin = inertial.find("mass"), inertial.find("inertia"), inertial.find("origin")
    if mass_el is None or tensor is None:
        return False
    xyz = (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()
    try:
        got = float(mass_el.get("value", "nan"))
        moments = [float(tensor.get(k, "0")) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")]
        at_origin = all(float(v) == 0.0 for v in xyz)
    except ValueError:
        return False
    return got == mass and at_origin and moments == [moment, moment, moment, 0.0, 0.0, 0.0]


# validate's codes of a tensor a URDF reader refuses: singular (a zero principal moment, MK302) or
# violating the triangle inequality (MK303)
REFUSED = ("MK302", "MK303")


def refusal_code(moments: tuple[float, float, float]) -> str:
    """MK302 when the smallest principal moment is zero within validate's tolerance, else MK303."""
    from modelkit import rot3
    from modelkit.checks.physics import ZERO_MOMENT

    return "MK302" if moments[0] <= max(rot3.inertia_tolerance(list(moments)), ZERO_MOMENT) else "MK303"


def refused_inertias(engine: str, fmt: str, source: Robot) -> dict[str, Approximated]:
    """Links whose source inertia, taken alone, violates the triangle inequality (``validate``'s MK303,
    or MK302 when a principal moment is zero: a source finding): the URDF keeps the source's tensor
    as it is, and its readers refuse it. PyBullet
    replaces it by zero ("Bad inertia tensor properties"; measured on ClosedLinkSample's WAIST and
    Go1's ``base``, whose six terms are all 1e-6); Drake's URDF parser by its plausible-guess solid
    sphere of the link's mass at water density. The engine is compared with that replacement (mass
    and COM kept), so the source's fault is reported as the source's, not as a conversion FAIL."""
    if fmt != "urdf" or engine not in ("pybullet", "drake-urdf"):
        return {}
    out: dict[str, Approximated] = {}
    for link in source.links:
        if link.inertial is None or link.inertial.mass <= 0.0:
            continue
        tensor = np.asarray(link.inertial.inertia, dtype=float)
        moments = triangle_moments(tensor)
        code = ""
        if engine == "pybullet":
            from modelkit.verify.engines.bullet_inertia import refuses
            from modelkit.verify.layers.common import zero_inertia

            # PyBullet's own test, on the moments its diagonalisation finds: a tensor on the triangle
            # bound can fail it by rounding where validate finds nothing (Robotiq 2F-85's knuckles)
            if zero_inertia(tensor) or not refuses(tensor):
                continue
            if moments is None:
                code = BOUND_ROUNDING
        elif moments is None:
            continue
        if engine == "drake-urdf":
            from modelkit.verify.engines.drake import accepts_inertia

            if accepts_inertia(tensor):  # within Drake's own rounding allowance: it keeps the tensor
                continue
        if engine == "pybullet":
            fixed = np.zeros((3, 3))
            by = ("PyBullet, refusing it (\"Bad inertia tensor properties\"), holds zero" if not code else
                  "PyBullet's importer, whose diagonalisation puts its principal moments (on the triangle "
                  "bound, a + b = c) over it by rounding, refuses it (\"Bad inertia tensor properties\") and "
                  "holds zero")
        else:
            from modelkit.verify.engines.drake import substitute_moment

            moment = substitute_moment(float(link.inertial.mass))
            fixed = moment * np.eye(3)
            by = ("Drake's URDF parser, refusing it, holds its plausible-guess solid sphere at water "
                  f"density ({moment:.9g} kg·m² per axis)")
        out[link.name] = Approximated(link.name, float(link.inertial.mass), 0.0,
                                      code or refusal_code(moments or (0.0, 0.0, 0.0)), by,
                                      tuple(float(v) for v in fixed.ravel()), refused_by_engine=True)
    return out


def for_engine(engine: str, fmt: str, notes: Iterable[ConversionNote], file: Path, source: Robot,
               renames: Renames) -> dict[str, Approximated]:
    """What ``engine`` (reading the written ``fmt`` file) holds instead of no mass, or instead of a
    source inertia it refuses (:func:`refused_inertias`), by source link."""
    notes = list(notes)
    out = from_notes(fmt, notes, renames, source)
    out.update(lifted_inertias(fmt, notes, renames, source))
    out.update(zero_inertias(fmt, notes, renames, source))
    if fmt == "urdf":
        out.update(urdf_frames(file, source, renames, engine))
    elif fmt == "sdf":
        out.update(sdf_frames(file, source, renames))
    out.update(refused_inertias(engine, fmt, source))
    return out


def applied(robot: Robot, approx: dict[str, Approximated]) -> Robot:
    """A copy of ``robot`` whose approximated links hold the approximation's mass and inertia."""
    if not approx:
        return robot
    out = copy.deepcopy(robot)
    for link in out.links:
        a = approx.get(link.name)
        if a is not None and a.tensor is not None and a.massless:
            link.inertial = Inertial(a.mass, np.zeros(3), np.asarray(a.tensor, dtype=float).reshape(3, 3))
        elif a is not None and a.tensor is not None and link.inertial is not None:
            link.inertial = Inertial(link.inertial.mass, np.asarray(link.inertial.com, dtype=float),
                                     np.asarray(a.tensor, dtype=float).reshape(3, 3))
        elif a is not None:
            link.inertial = Inertial(a.mass, np.zeros(3), a.inertia * np.eye(3))
    return out


def skip(engine: str, approx: dict[str, Approximated]) -> Skip | None:
    """The report's entry for an engine's approximations (never a silent pass)."""
    if not approx:
        return None
    groups: dict[tuple[str, str, float, float], list[str]] = {}
    lifts = []
    findings = []
    for a in sorted(approx.values(), key=lambda a: a.link):
        if a.code == BOUND_ROUNDING:
            findings.append(f"{a.by} for {a.link} (validate finds no fault there): compared with that, not a "
                            "conversion fault")
            continue
        if a.code in REFUSED:
            what = "is singular" if a.code == "MK302" else "violates the triangle inequality"
            findings.append(f"source finding {a.code} (the source inertia of {a.link}, taken alone, {what}); "
                            f"{a.by} for it: compared with that, not a conversion fault")
            continue
        if a.tensor is None:
            groups.setdefault((a.by, a.code, a.mass, a.inertia), []).append(a.link)
            continue
        if a.massless:
            lifts.append(f"{a.by} gives {a.link}, massless in the source, {a.mass:g} kg and adds "
                         f"{a.inertia:g} kg·m² per axis to the inertia tensor the source gives it ({a.code})")
            continue
        lifted = np.linalg.eigvalsh(np.asarray(a.tensor).reshape(3, 3))
        lifts.append(f"{a.by} lifts the inertia of {a.link}, whose principal moments violate the triangle "
                     f"inequality in the source (MK303), to moments {', '.join(f'{v:.9g}' for v in lifted)} "
                     f"kg·m² about the same axes ({a.code})")
    parts = []
    for (by, code, mass, inertia), links in sorted(groups.items()):
        shown = ", ".join(links[:8]) + (f" and {len(links) - 8} more" if len(links) > 8 else "")
        parts.append(f"{by} gives {len(links)} link(s) massless in the source {mass:g} kg and "
                     f"{inertia:g} kg·m² per axis at the link origin ({code}): {shown}")
    parts += lifts
    if findings and not parts:
        return Skip(1, engine, "; ".join(findings) + ". Layers 1 and 3 compare this engine with the source "
                    "model with that tensor applied (layer 1 checks the engine holds it)")
    parts += findings
    return Skip(1, engine, "approximation: " + "; ".join(parts) + ". Layers 1 and 3 compare this engine with "
                "the source model with these values applied (layer 1 checks the engine holds them)")


@dataclass(frozen=True)
class LimitStandIn:
    """A source joint whose position bounds the engine holds otherwise, as documented: an infinite
    bound written with a finite stand-in, or a reversed range held as no limit."""

    joint: str  # source name
    lower: float  # what the file (and the engine reading it) holds
    upper: float
    code: str
    what: str  # the report's phrase, "{n}" standing for the number of joints


FINITE_STAND_IN = ("the URDF writer writes the infinite position bounds of {n} joint(s) as ±1e16 (MK819: "
                   "URDF has no unlimited prismatic joint)")
REVERSED_UNLIMITED = {
    "mjcf": ("MK824", "the MJCF writer writes the reversed range (MK307) of {n} joint(s) unlimited (MK824: "
                      "MuJoCo refuses a range whose lower limit is above its upper)"),
    "pybullet": ("MK307", "PyBullet holds the reversed range (MK307) of {n} joint(s), which the URDF keeps "
                          "as the source has it, as no limit (it enforces a range only when lower <= upper)"),
}


def urdf_limits(source: Robot) -> dict[str, LimitStandIn]:
    """The URDF writer's MK819 position bounds: a prismatic joint, or a revolute joint limited on one
    side only (both sides open is ``continuous``), gets ±1e16 for each infinite bound."""
    from modelkit.formats.urdf.write_joints import SYNTHESISED_POSITION

    out: dict[str, LimitStandIn] = {}
    for joint in source.joints:
        lo, hi = joint.limits.lower, joint.limits.upper
        if joint.type is JointType.PRISMATIC or (joint.type is JointType.REVOLUTE
                                                  and (math.isfinite(lo) or math.isfinite(hi))):
            if math.isfinite(lo) and math.isfinite(hi):
                continue
            out[joint.name] = LimitStandIn(joint.name, lo if math.isfinite(lo) else -SYNTHESISED_POSITION,
                                           hi if math.isfinite(hi) else SYNTHESISED_POSITION, "MK819",
                                           FINITE_STAND_IN)
    return out


def reversed_unlimited(source: Robot, holder: str) -> dict[str, LimitStandIn]:
    """The source's reversed ranges (MK307) that ``holder`` (a key of :data:`REVERSED_UNLIMITED`) holds
    as no limit."""
    code, what = REVERSED_UNLIMITED[holder]
    return {joint.name: LimitStandIn(joint.name, -math.inf, math.inf, code, what)
            for joint in source.joints if joint.limits.lower > joint.limits.upper}


def limits_for_engine(fmt: str, source: Robot, engine: str = "") -> dict[str, LimitStandIn]:
    """The bounds an engine reading the written ``fmt`` file holds in place of the source's, by source
    joint: the URDF writer's finite stand-ins, and a reversed range where the MJCF writer or PyBullet
    takes it as no limit."""
    if fmt == "mjcf":
        return reversed_unlimited(source, "mjcf")
    if fmt != "urdf":
        return {}
    out = urdf_limits(source)
    if engine == "pybullet":
        out.update(reversed_unlimited(source, "pybullet"))
    return out


def applied_limits(facts: StaticFacts, stand_ins: dict[str, LimitStandIn]) -> StaticFacts:
    """A copy of the source's static facts whose joints hold the stand-in bounds."""
    if not stand_ins:
        return facts
    joints = dict(facts.joints)
    for name, s in stand_ins.items():
        if name in joints:
            joints[name] = dataclasses.replace(joints[name], lower=s.lower, upper=s.upper)
    return StaticFacts(facts.links, joints, facts.shapes)


def limits_skip(engine: str, stand_ins: dict[str, LimitStandIn]) -> Skip | None:
    """The report's entry for an engine's limit stand-ins (never a silent pass)."""
    if not stand_ins:
        return None
    parts = []
    for what in sorted({s.what for s in stand_ins.values()}):
        names = sorted(n for n, s in stand_ins.items() if s.what == what)
        shown = ", ".join(f"{n} [{stand_ins[n].lower:g}, {stand_ins[n].upper:g}]" for n in names[:8]) + (
            f" and {len(names) - 8} more" if len(names) > 8 else "")
        parts.append(f"{what.format(n=len(names))}: {shown}")
    return Skip(1, engine, f"approximation: {'; '.join(parts)}. Layer 1 checks this engine holds exactly "
                "these bounds")


@dataclass(frozen=True)
class Detaching:
    """The joints whose child an engine holds as a free body left where it is at q = 0, and why."""

    kinds: frozenset[JointType]
    why: str


# The engines that hold a subtree hanging by a floating (or planar) joint inside the tree as a free body at
# its pose at q = 0 (PyBullet welds a floating joint and yourdfpy does not move one: neither is run).
DETACHED_BY = {
    "mujoco": Detaching(frozenset({JointType.FLOATING}), "the MJCF writer makes it a top-level body with "
                        "<freejoint/> (MK813: MuJoCo allows a free joint on a top-level body only)"),
    "drake": Detaching(frozenset({JointType.FLOATING, JointType.PLANAR}), "the SDF writer leaves its head "
                       "link without a joint, free-floating (MK813: SDF has no floating or planar joint "
                       "inside a model)"),
    "drake-urdf": Detaching(frozenset({JointType.FLOATING}), "Drake's URDF parser leaves the child of a "
                            "floating joint a free body"),
}


def detached_subtrees(source: Robot, kinds: frozenset[JointType] = frozenset({JointType.FLOATING})
                      ) -> dict[str, str]:
    """Link → the head of its subtree, for every link below a joint of ``kinds`` inside the tree whose
    parent another joint moves (the head: that joint's child; a link below two such joints belongs to the
    nearer). Such a joint on the root's rigid body leaves its subtree where the source has it either way."""
    children = source.children_of()
    up = {joint.child: joint for joint in source.joints}

    def carried(link: str) -> bool:  # a joint not of ``kinds`` moves ``link``
        seen: set[str] = set()
        while link in up and link not in seen:
            seen.add(link)
            joint = up[link]
            if joint.type.moves and joint.type not in kinds:
                return True
            link = joint.parent
        return False

    out: dict[str, str] = {}
    for joint in source.joints:
        if joint.type not in kinds or not carried(joint.parent):
            continue
        stack = [joint.child]
        while stack:
            link = stack.pop()
            out[link] = joint.child
            stack.extend(j.child for j in children.get(link, []) if j.type not in kinds)
    return out


@dataclass(frozen=True)
class BallChain:
    """A source ball joint as the URDF writer wrote it (MK813): three continuous joints about the
    child's X, Y and Z axes through two links that carry only the writer's tiny inertial (MK816)."""

    joint: str  # source name
    joints: tuple[str, str, str]  # the written X, Y and Z joints
    links: tuple[str, str]  # the written links between them


def ball_chains(fmt: str, notes: Iterable[ConversionNote]) -> list[BallChain]:
    """The URDF writer's ball-joint chains, read from its MK813 notes (none for another format)."""
    if fmt != "urdf":
        return []
    from modelkit.convert.notes import note_matches
    from modelkit.formats.urdf.write_joints import BALL_NOTE

    return [BallChain(m["joint"], (m["x"], m["y"], m["z"]), (m["link_x"], m["link_y"]))
            for m in note_matches(notes, "MK813", BALL_NOTE)]


SENSOR_FRAME = re.compile(r'"(?P<frame>[^"]+)" on "(?P<parent>[^"]+)"'
                          r'(?: \(the name "(?P<wanted>[^"]+)" is taken\))?'
                          r'(?: with its optical frame "(?P<optical>[^"]+)")?')
"""One sensor in the URDF writer's MK847 note (``formats/urdf/write_frames.sensor_frames`` writes it)."""


@dataclass(frozen=True)
class SensorFrame:
    """A sensor the URDF writer wrote as a link of its own on a fixed joint (MK847): the frame link,
    the link it hangs from (a source name; a camera's optical frame hangs from the camera's frame),
    the written fixed joint, and the frame's pose in that link, taken from the source's device (the
    optical frame's is REP-103's), so that the layers compare where the file put it."""

    link: str
    parent: str
    joint: str
    origin: Pose


def sensor_frames(fmt: str, notes: Iterable[ConversionNote], source: Robot, renames: Renames,
                  file: Path) -> list[SensorFrame]:
    """The URDF writer's sensor frames that ``file`` holds, read from its MK847 note (none for another
    format, or where the file has no such link on a joint)."""
    notes = [note for note in notes if note.code == "MK847"]
    if fmt != "urdf" or not notes:
        return []
    from modelkit.formats.urdf.write_frames import OPTICAL_POSE

    back = _source_names(renames)
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    joint_of = {str(child.get("link")): str(joint.get("name"))
                for joint in etree.parse(str(file), parser).iterfind("./joint")
                for child in joint.iterfind("child")}
    out: list[SensorFrame] = []
    for note in notes:
        for match in SENSOR_FRAME.finditer(note.message):
            parent = back.get(match["parent"], match["parent"])
            link = source.link(parent)
            wanted = match["wanted"] or match["frame"]
            devices = link.devices if link is not None else []
            device = next((d for d in devices if (d.name or d.canonical.value) == wanted), None)
            if device is None or match["frame"] not in joint_of:
                continue
            out.append(SensorFrame(match["frame"], parent, joint_of[match["frame"]], device.pose))
            if match["optical"] and match["optical"] in joint_of:
                optical = match["optical"]
                out.append(SensorFrame(optical, match["frame"], joint_of[optical], OPTICAL_POSE))
    return out


def applied_frames(robot: Robot, frames: list[SensorFrame]) -> Robot:
    """A copy of ``robot`` holding the sensor frames as massless links on fixed joints, as the URDF
    does (the writer's tiny inertial comes with :func:`applied`)."""
    if not frames:
        return robot
    from modelkit.model import Joint, Link

    out = copy.deepcopy(robot)
    for frame in frames:
        out.links.append(Link(frame.link))
        out.joints.append(Joint(frame.joint, JointType.FIXED, frame.parent, frame.link, origin=frame.origin,
                                synthesised=True))
    return out


def frames_skip(engine: str, frames: list[SensorFrame]) -> Skip | None:
    """The report's entry for an engine holding sensor frames (never a silent pass)."""
    if not frames:
        return None
    shown = ", ".join(f"{f.link} on {f.parent}" for f in frames)
    return Skip(1, engine, (
        f"approximation: the URDF writes {len(frames)} sensor frame(s) as links on fixed joints (MK847; the "
        f"TF frames ROS tools need): {shown}. Layers 1-3 compare this engine with the source holding them "
        "at the sensors' poses, with the writer's tiny inertial"))


def applied_chains(robot: Robot, chains: list[BallChain]) -> Robot:
    """A copy of ``robot`` whose ball joints are the written chains: the model as the URDF holds it.
    The first joint keeps the ball's origin, the last one keeps the source joint's name and child,
    the two added links have no mass (the writer's tiny inertial comes with :func:`applied`)."""
    from modelkit.formats.urdf.write_joints import BALL_AXES

    turns = [(JointType.REVOLUTE, axis) for _, axis in BALL_AXES]
    by_joint = {chain.joint: chain for chain in chains}

    def pieces(ball: Joint) -> ChainPieces | None:
        chain = by_joint.get(ball.name)
        return None if chain is None else ((chain.joints[0], chain.joints[1]), list(chain.links), turns)

    return with_chains(robot, JointType.BALL, pieces) if chains else robot


ChainPieces = tuple[tuple[str, str], list[str], list[tuple[JointType, Any]]]
"""The first two joints' names, the two links between the three joints, each joint's type and axis."""


def with_chains(robot: Robot, kind: JointType, pieces: Callable[[Joint], ChainPieces | None]) -> Robot:
    """A copy of ``robot`` with each joint of type ``kind`` for which ``pieces`` gives a chain replaced
    by that chain of three joints (:func:`in_chain`)."""
    out = copy.deepcopy(robot)
    for joint in list(out.joints):
        chain = pieces(joint) if joint.type is kind else None
        if chain is not None:
            in_chain(out, joint, *chain)
    return out


def in_chain(robot: Robot, joint: Joint, first_two: tuple[str, str], links: Sequence[str],
             pieces: Sequence[tuple[JointType, Any]]) -> None:
    """Replace ``joint`` in ``robot`` by three single-axis joints (``pieces``: type and axis) through
    ``links``, massless and added: the first keeps the joint's origin, the last its name and child."""
    from modelkit.model import JointLimits, Link

    frames = [joint.parent, *links, joint.child]
    names = [*first_two, joint.name]
    added = [Joint(names[i], kind, frames[i], frames[i + 1], origin=joint.origin if i == 0 else Pose(),
                   axis=np.asarray(axis, dtype=float), limits=JointLimits(), damping=joint.damping,
                   synthesised=i < 2, source=joint.source) for i, (kind, axis) in enumerate(pieces)]
    index = robot.joints.index(joint)
    robot.joints[index:index + 1] = added
    robot.links.extend(Link(name, synthesised=True, source=joint.source) for name in links)


def chain_configuration(q: dict[str, float], chains: list[BallChain]) -> dict[str, float]:
    """A configuration of the source in the terms of :func:`applied_chains`' model: each ball's three
    angles (``NAME#x``..., ``BALL_KEYS``) on its chain's three joints (the last keeps the ball's name)."""
    if not chains:
        return q
    out = dict(q)
    for chain in chains:
        names = (*chain.joints[:2], chain.joint)
        for key, name in zip(BALL_KEYS, names, strict=True):
            out[name] = out.pop(chain.joint + key, 0.0)
    return out


def chains_skip(engine: str, chains: list[BallChain]) -> Skip | None:
    """The report's entry for the ball joints an engine reads as chains (never a silent pass)."""
    if not chains:
        return None
    shown = "; ".join(f"{c.joint} as {', '.join(c.joints)} through {', '.join(c.links)}"
                      for c in chains[:4]) + (f" and {len(chains) - 4} more" if len(chains) > 4 else "")
    return Skip(1, engine, f"approximation: the URDF writer writes {len(chains)} ball joint(s) as three "
                f"continuous joints each (MK813; URDF has no ball joint): {shown}. Layer 1 compares this "
                "engine with the source model holding these chains (link and joint sets, types, axes, the "
                "added links' tiny inertials)")


@dataclass(frozen=True)
class WheelProxy:
    """``convert``'s wheel collision (MK826) held by an engine in place of the source's cylinders or
    round meshes."""

    shape: str  # "sphere" or "ellipsoid" (--wheel-collision)
    links: tuple[str, ...]  # source names
    replaced: str = "cylinder"  # what the source holds: "cylinder", "round mesh" or both, in words


def wheel_proxies(source: Robot, engine_shapes: Mapping[str, Sequence[Any]],
                  written: Callable[[str], str]) -> WheelProxy | None:
    """The wheel collision an engine holds for every wheel of ``source`` (the model as read, its root
    not welded) whose collision is a cylinder or a round mesh there, when it is one of ``convert``'s
    choices for it (``--wheel-collision auto`` writes spheres for MJCF and URDF, MK826). Found from the
    engine's own shapes: a file given with ``--mjcf/--urdf`` carries no notes, and is usually
    ``convert``'s default."""
    from modelkit.convert.wheels import find_wheels

    shapes = {link: _collision(source, link, wheel.index) for link, wheel in find_wheels(source).items()}
    wheels = {link: shape for link, shape in shapes.items() if isinstance(shape, Cylinder | Mesh)}
    held = set()
    for link in sorted(wheels):
        kinds = {shape.type for shape in engine_shapes.get(written(link), [])}
        proxy = [kind for kind in ("sphere", "ellipsoid") if kind in kinds]
        if "cylinder" in kinds or "mesh" in kinds or len(proxy) != 1:
            return None
        held.add(proxy[0])
    if len(held) != 1:
        return None
    kinds = {"cylinder" if isinstance(shape, Cylinder) else "round mesh" for shape in wheels.values()}
    return WheelProxy(held.pop(), tuple(sorted(wheels)), " or ".join(sorted(kinds)))


def applied_wheels(robot: Robot, source: Robot, proxy: WheelProxy) -> Robot:
    """``robot`` (the reference) with the wheels' cylinders and round meshes of ``source`` replaced by
    ``proxy``'s shape,
    as ``convert`` writes them."""
    from modelkit.convert.wheels import find_wheels, rolling_shapes, wheel_proxy

    wheels = find_wheels(source)
    out = copy.deepcopy(robot)
    links = {link.name: link for link in out.links}
    for name, wheel, index, roundness in rolling_shapes(wheels):
        if name not in proxy.links or name not in links:
            continue
        link = links[name]
        geom = link.collisions[index]
        if isinstance(geom.geometry, Cylinder | Mesh):
            link.collisions[index] = wheel_proxy(geom, wheel, proxy.shape, roundness)[0]
    return out


def flat_collisions(fmt: str, notes: Iterable[ConversionNote], renames: Renames) -> dict[str, set[int]]:
    """The collision meshes (source link → collision indices) the MJCF writer wrote as thin boxes
    because they are flat (MK881: MuJoCo has no convex hull of a plane)."""
    if fmt != "mjcf":
        return {}
    back = _source_names(renames)
    out: dict[str, set[int]] = {}
    for note in notes:
        match = re.fullmatch(r"body\[(.+)\]/collision\[(\d+)\]", note.target or "")
        if note.code == "MK881" and match:
            out.setdefault(back.get(match[1], match[1]), set()).add(int(match[2]))
    return out


def applied_plates(robot: Robot, plates: Mapping[str, set[int]]) -> Robot:
    """``robot`` with each flat collision mesh of ``plates`` replaced by the box the MJCF writer wrote
    for it, recomputed from the source's mesh file (``convert.meshes.plate_of``)."""
    if not plates:
        return robot
    from modelkit.convert.meshes import plate_of
    from modelkit.geometry.meshfiles import load_mesh

    out = copy.deepcopy(robot)
    for link in out.links:
        for index in sorted(plates.get(link.name, ())):
            if index >= len(link.collisions) or not isinstance(link.collisions[index].geometry, Mesh):
                continue
            geom = link.collisions[index]
            mesh = geom.geometry
            assert isinstance(mesh, Mesh)
            data = mesh.data if mesh.data is not None else load_mesh(Path(str(mesh.path)), mesh.fragment).mesh
            vertices = np.asarray(data.vertices, dtype=float)
            corners = vertices[np.asarray(data.faces, dtype=np.int64)]
            plate = plate_of(corners, mesh.scale)
            offset = Pose(np.asarray(plate.rotation, dtype=float), np.asarray(plate.centre, dtype=float))
            box = Box(np.asarray(plate.size, dtype=float))
            link.collisions[index] = dataclasses.replace(geom, geometry=box, pose=geom.pose @ offset)
    return out


def plates_skip(engine: str, plates: Mapping[str, set[int]]) -> Skip | None:
    """The report's entry for an engine holding flat collision meshes as thin boxes (MK881)."""
    if not plates:
        return None
    return Skip(1, engine, "approximation: the MJCF writer wrote flat collision mesh(es) as thin boxes in "
                           "their planes (MK881; MuJoCo has no convex hull of a plane) on "
                           f"{', '.join(sorted(plates))}; layer 1 compares the engine's shapes with those "
                           "boxes")


def wheels_skip(engine: str, proxy: WheelProxy | None) -> Skip | None:
    """The report's entry for an engine holding ``convert``'s wheel collisions."""
    if proxy is None:
        return None
    return Skip(1, engine, "approximation: the file holds convert's wheel collision (MK826, "
                           f"--wheel-collision): a {proxy.shape} in place of the source's {proxy.replaced} "
                           "on "
                           f"{', '.join(proxy.links)}; layer 1 compares its shapes with those")


def _collision(robot: Robot, link_name: str, index: int) -> object:
    link = robot.link(link_name)
    if link is None or index >= len(link.collisions):
        return None
    return link.collisions[index].geometry
