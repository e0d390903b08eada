"""MJCF to MJCF: the source's tendons, and the actuators the model does not hold, written back.

The reader keeps them as data with their compiled attributes (:mod:`.transmissions`):

* each tendon is written as ``<fixed>`` (joint coefficients) or ``<spatial>`` (sites, wrapping spheres
  and cylinders with their side sites, pulleys) in ``<tendon>``, when every joint, site and geom it
  names is written as the source has it: a joint as one hinge or slide, a wrapping geom as a sphere or
  cylinder. Left out otherwise, named in the MK808 note (:func:`.write_foreign.note_unwritten_own`);
* each actuator that is not one of the model's (a tendon, site, slider-crank or body transmission,
  activation dynamics, a muscle, another gain or bias law) is written as ``<general>`` with the
  compiled dynamics, gain and bias laws and parameters, gear and ranges, when the object it drives is
  written; left out with MK842 saying why otherwise (and always for a plugin or delayed actuator);
* each tendon equality whose tendons are written is written with its polynomial and solver settings.

The actuators keep the source's order (MuJoCo lays ``ctrl`` out in it, and a controller written for
the source indexes it): the model's actuators, written by :mod:`.write_actuators`, and these are
placed as in the source, and the ``home`` keyframe's ``ctrl`` follows, with the source's own ``home``
control for these. With ``--source-actuators replace`` the source's actuators are set aside, these
too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.convert.actuator_choice import CHOSEN, FILLED, SERVOED
from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.convert.tracks import TRACK_ROLLER
from modelkit.diagnostics import SourceLocation
from modelkit.formats.mjcf.write_actuators import ActuatorWriter
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_refs import WrittenObjects
from modelkit.formats.mjcf.write_xml import Element, sub
from modelkit.model import Robot

WRAPPING = ("sphere", "cylinder")  # the geom types a spatial tendon wraps around
MADE_UP = (CHOSEN, TRACK_ROLLER, SERVOED, FILLED)  # written actuators that are not the source's
Placed = tuple[float, int, Element, float]  # source rank, order written, element, home ctrl


@dataclass
class TransmissionWriter:
    robot: Robot
    ctx: WriteContext
    names: NameTable
    refs: WrittenObjects
    tendon: Element  # the <tendon> section
    equality: Element  # the <equality> section
    actuators: ActuatorWriter
    equalities: list[dict[str, Any]] = field(default_factory=list)  # the source's, written back

    def write(self) -> dict[str, list[dict[str, Any]]]:
        """Write them; returns the tendons that could not be written (``mjcf_tendons``)."""
        tendons = self.robot.extras.get("mjcf_tendons") or []
        lost = [tendon for tendon in tendons if not self._tendon(tendon)]
        for eq in self.robot.extras.get("mjcf_equalities") or []:
            if eq.get("type") == "tendon":
                self._tendon_equality(eq)
            elif eq.get("type") in ("connect", "weld"):
                self._frame_equality(eq)
        if not self.actuators.set_aside:
            self._generals()
        return {"mjcf_tendons": lost}

    def _tendon_equality(self, eq: dict[str, Any]) -> None:
        """A tendon equality (``l1 − l1₀ = Σ cᵢ (l2 − l2₀)ⁱ``), when its tendons are written. The
        lengths l₀ are the tendons' at qpos0, which the written joints' references move (the writer
        bakes a source joint's ``ref`` into its body's pose): the polynomial is rebased on the written
        file's lengths (:func:`rebased`)."""
        first = self.refs.object("tendon", str(eq.get("obj1")))
        second = self.refs.object("tendon", str(eq.get("obj2"))) if eq.get("obj2") else None
        if first is None or (eq.get("obj2") and second is None):
            return
        shift1 = self._length0_shift(str(eq.get("obj1")))
        shift2 = self._length0_shift(str(eq.get("obj2"))) if second is not None else 0.0
        if shift1 is None or shift2 is None:
            return
        el = sub(self.equality, "tendon")
        if eq.get("name"):
            wanted = str(eq["name"])
            el.set("name", self.names.claim("equality", wanted, None, f"equality/tendon[{wanted}]"))
        el.set("tendon1", first)
        if second is not None:
            el.set("tendon2", second)
        el.set("polycoef", fmt_vec(rebased([float(x) for x in eq["data"][:5]], shift1, shift2)))
        if not eq.get("active", True):
            el.set("active", "false")
        for key, value in (eq.get("solver") or {}).items():
            el.set(key, str(value))
        self.equalities.append(eq)

    def _frame_equality(self, eq: dict[str, Any]) -> None:
        """A connect or weld equality between two bodies (or a body and the world) or two sites, when
        they are written where the source has them: a closed loop the model does not hold (Menagerie's
        Robotiq 2F-85 ties each follower to its coupler), written back with MuJoCo's compiled data.
        connect: ``anchor`` in body1's frame; weld: ``anchor``, ``relpose`` and ``torquescale``."""
        objtype = str(eq.get("objtype"))
        if objtype not in ("body", "xbody", "site"):
            return
        # a weld's relative pose holds only between bodies written at their source frames; a connect's
        # anchor is moved into the written body's frame
        kind = "site" if objtype == "site" else "xbody" if eq["type"] == "weld" else "body"
        first = self.refs.object(kind, str(eq.get("obj1")))
        second = self.refs.object(kind, str(eq.get("obj2"))) if eq.get("obj2") else None
        if first is None or (eq.get("obj2") and second is None) or (kind == "site" and second is None):
            return
        data = [float(x) for x in eq["data"]]
        if kind == "body":
            frame = self.refs.source_frame(str(eq.get("obj1")))
            if frame is None:
                return
            data[0:3] = [float(x) for x in frame.rotation @ np.asarray(data[0:3]) + frame.translation]
        el = sub(self.equality, str(eq["type"]))
        if eq.get("name"):
            wanted = str(eq["name"])
            el.set("name", self.names.claim("equality", wanted, None, f"equality/{eq['type']}[{wanted}]"))
        if kind == "site":
            el.set("site1", first)
            el.set("site2", str(second))
        else:
            el.set("body1", first)
            if second is not None:
                el.set("body2", second)
            el.set("anchor", fmt_vec(data[0:3]))
            if eq["type"] == "weld":
                el.set("relpose", fmt_vec(data[3:10]))
        if eq["type"] == "weld" and data[10] != 1.0:
            el.set("torquescale", fmt(data[10]))
        if not eq.get("active", True):
            el.set("active", "false")
        for key, value in (eq.get("solver") or {}).items():
            el.set(key, str(value))
        self.equalities.append(eq)

    # -- tendons ---------------------------------------------------------------------------------

    def _tendon(self, tendon: dict[str, Any]) -> bool:
        children: list[tuple[str, dict[str, str]]] = []
        for wrap in tendon.get("wraps") or []:
            child = self._wrap(wrap)
            if child is None:
                return False
            children.append(child)
        el = sub(self.tendon, str(tendon.get("kind", "fixed")))
        if tendon.get("name"):
            wanted = str(tendon["name"])
            el.set("name", self.names.claim("tendon", wanted, None, f"tendon[{wanted}]"))
        for key, value in (tendon.get("attributes") or {}).items():
            el.set(key, str(value))
        for tag, attributes in children:
            sub(el, tag, **attributes)
        return True

    def _wrap(self, wrap: dict[str, Any]) -> tuple[str, dict[str, str]] | None:
        """One path element as its tag and attributes under the written names; None when an object it
        names is not written as the source has it."""
        kind, obj = str(wrap.get("type")), str(wrap.get("object"))
        if kind == "joint":
            joint = self.refs.scalar_joint(obj)
            return None if joint is None else ("joint", {"joint": joint, "coef": fmt(float(wrap["coef"]))})
        if kind == "site":
            site = self.refs.object("site", obj)
            return None if site is None else ("site", {"site": site})
        if kind == "pulley":
            return "pulley", {"divisor": fmt(float(wrap["coef"]))}
        if kind in WRAPPING:
            geom = self.refs.object("geom", obj)
            if geom is None or self._geom_type(geom) not in WRAPPING:
                return None
            attributes = {"geom": geom}
            if wrap.get("sidesite"):
                side = self.refs.object("site", str(wrap["sidesite"]))
                if side is None:
                    return None
                attributes["sidesite"] = side
            return "geom", attributes
        return None

    def _geom_type(self, name: str) -> str | None:
        for el in self.tendon.getroottree().iter("geom"):
            if el.get("name") == name:
                return str(el.get("type", "sphere"))  # MuJoCo's default geom type
        return None

    def _length0_shift(self, name: str) -> float | None:
        """The source tendon's length at qpos0 minus the written one's: a fixed tendon's written length
        at qpos0 is 0 (the written joints have no reference); a spatial tendon's is the source's when
        no joint has a reference, and not known here otherwise (None)."""
        tendon = next((t for t in self.robot.extras.get("mjcf_tendons") or [] if t.get("name") == name), None)
        if tendon is None:
            return None
        if tendon.get("kind") == "fixed":
            return float(tendon.get("length0", 0.0))
        if any(j.extras.get("mjcf_ref") for j in self.robot.joints):
            return None
        return 0.0

    # -- actuators -------------------------------------------------------------------------------

    def _generals(self) -> None:
        kept = self.robot.extras.get("mjcf_actuators") or []
        keys = self.robot.extras.get("mjcf_keyframes") or []
        home: dict[str, Any] = next((k for k in keys if k.get("name") == "home"), {})
        home_ctrl = [float(x) for x in home.get("ctrl") or []]
        section = self.actuators.section
        placed: list[Placed] = []
        for index, entry in enumerate(kept):
            if entry.get("canonical"):
                continue
            el = self._general(section, entry)
            if el is not None:
                ctrl = home_ctrl[index] if index < len(home_ctrl) else 0.0
                placed.append((index, len(placed), el, ctrl))
        if placed:
            self._source_order(kept, placed)

    def _general(self, section: Element, entry: dict[str, Any]) -> Element | None:
        name = str(entry.get("name") or "")
        transmission = self._transmission(entry)
        why = entry.get("unwritable")
        if why is None and transmission is None:
            what = {"joint": "joint", "jointinparent": "joint", "tendon": "tendon", "body": "body"}.get(
                str(entry.get("transmission")), "site")
            why = f"its {what} {entry.get('target')} is not written as the source has it"
        if why is not None or transmission is None:
            shown = f' "{name}"' if name else ""
            self.ctx.note("MK842", f"MJCF actuator{shown} left out: {why}", _where(entry, self.robot),
                          "actuator")
            return None
        el = sub(section, "general")
        if name:
            el.set("name", self.names.claim("actuator", name, None, f"actuator[{name}]"))
        for key, value in transmission.items():
            el.set(key, value)
        for key, value in (entry.get("general") or {}).items():
            el.set(key, str(value))
        return el

    def _transmission(self, entry: dict[str, Any]) -> dict[str, str] | None:
        """The transmission attributes under the written names, or None when an object is not written."""
        kind, target = str(entry.get("transmission")), str(entry.get("target"))
        if kind in ("joint", "jointinparent"):
            joint = self.refs.object("joint", target)
            return None if joint is None else {kind: joint}
        if kind == "tendon":
            tendon = self.refs.object("tendon", target)
            return None if tendon is None else {"tendon": tendon}
        if kind == "body":
            body = self.refs.object("body", target)
            return None if body is None else {"body": body}
        if kind not in ("site", "slidercrank"):
            return None
        first = self.refs.object("site", target)
        if first is None:
            return None
        out = {"site" if kind == "site" else "cranksite": first}
        second_key = "refsite" if kind == "site" else "slidersite"
        if entry.get(second_key):
            second = self.refs.object("site", str(entry[second_key]))
            if second is None:
                return None
            out[second_key] = second
        return out

    def _source_order(self, kept: list[dict[str, Any]], placed: list[Placed]) -> None:
        """All written actuators, and the home ``ctrl``, in the source's order. The model's actuators
        are found among the kept entries the reader marked canonical, in order (by joint and name);
        actuators the writer made up (none beside the source's own, but a track's rollers) go last."""
        canonical = [(i, e) for i, e in enumerate(kept) if e.get("canonical")]
        start = 0
        ranked = list(placed)
        offset = len(placed)
        for seq, ((actuator, el), ctrl) in enumerate(zip(self.actuators.elements, self.actuators.ctrl,
                                                         strict=True)):
            rank = math.inf
            if actuator.source_kind not in MADE_UP:
                for k in range(start, len(canonical)):
                    i, entry = canonical[k]
                    if entry.get("joint") == actuator.joint and entry.get("name") == actuator.name:
                        rank, start = i, k + 1
                        break
            ranked.append((rank, offset + seq, el, ctrl))
        ranked.sort(key=lambda item: (item[0], item[1]))
        section = self.actuators.section
        for _, _, el, _ in ranked:
            section.append(el)  # lxml moves the element to the end
        self.actuators.ctrl = [ctrl for _, _, _, ctrl in ranked]


def _where(entry: dict[str, Any], robot: Robot) -> SourceLocation | None:
    """The actuator's place in the source (the reader keeps it as ``file:line:col``), else the robot's."""
    text = str(entry.get("source") or "")
    parts = text.rsplit(":", 2)
    if len(parts) == 3 and parts[1].isdigit() and parts[2].isdigit():
        return SourceLocation(parts[0], int(parts[1]), int(parts[2]))
    return robot.source


def rebased(coefficients: list[float], shift1: float, shift2: float) -> list[float]:
    """The polynomial of ``l1 − l1₀ = Σ cᵢ (l2 − l2₀)ⁱ`` on other base lengths l₀' = l₀ − shift:
    ``l1 − l1₀' = shift1 + Σ cᵢ ((l2 − l2₀') − shift2)ⁱ``, expanded in powers of ``l2 − l2₀'``."""
    out = [0.0] * len(coefficients)
    for i, c in enumerate(coefficients):
        for k in range(i + 1):
            out[k] += c * math.comb(i, k) * (-shift2) ** (i - k)
    out[0] += shift1
    return out
