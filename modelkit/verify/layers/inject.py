"""Fault injection: perturb a written MJCF, URDF or SDF file the way a buggy converter would, so
that users and tests can watch each verification layer catch the fault.

Spec grammar (``modelkit verify --inject SPEC``; NAME is a source link or joint name, or a name as
written in the file; it may itself contain ``:``)::

    inertia:LINK:P%        scale the link's whole inertia tensor (all six moments) by 1 + P/100
    mass:LINK:P%           scale the link's mass by 1 + P/100 (COM and inertia tensor kept)
    com:LINK:DX            shift the link's centre of mass by DX metres along the link frame's x
    axis:JOINT:flip        negate the joint axis (a revolute or prismatic joint)
    cylinder-y:LINK        turn every cylinder of the link (collision and visual) by 90° about its
                           own x axis: the cylinder's axis becomes its former local y, which is what
                           a converter writes when it leaves Choreonoid's Y-axis cylinders unconverted
    wheel-radius:LINK:P%   scale the radius of every cylinder and sphere of the link (collision and
                           visual) by 1 + P/100
    swap:JOINT:OTHER       exchange the names of two joints everywhere the file names them (a
                           converter that mixed up the left and right wheel: the joint named
                           ``LeftWheel`` is the right one)

P is a signed decimal (``1%``, ``-5%``, ``2.5%``), non-zero, with 1 + P/100 > 0; DX a signed
non-zero decimal, optionally followed by ``m``. A bad spec raises :class:`InjectError` (a
``ValueError``), whose message says what is wrong, then shows the spec with a caret under the
offending part; an unknown link or joint lists the valid names (source names where the file renamed
them).

:func:`apply` is what ``verify --inject`` calls (every written file, one description line);
:func:`inject` edits one written file in place (lxml; the rest of the file is kept as written)
and returns an :class:`Injection` describing every value it changed, for the report. One function
per fault and file format does the edit (``_inertia_mjcf``, ``_inertia_urdf``, ``_inertia_sdf``,
...). Names are mapped through the conversion's renames for that file
(``{"link": {source: written}, "joint": {...}}``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from lxml import etree

from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.formats.mjcf.write_xml import quat_wxyz
from modelkit.spatial import Mat3, axis_angle, matrix_from_quat_wxyz, matrix_from_rpy, rot_x, rpy_from_matrix

Element = etree._Element
Renames = Mapping[str, Mapping[str, str]]

KINDS: dict[str, str] = {  # kind -> what it names
    "inertia": "link",
    "mass": "link",
    "com": "link",
    "axis": "joint",
    "cylinder-y": "link",
    "wheel-radius": "link",
    "swap": "joint",
}
_VALUE_KINDS = {
    "inertia": "percent", "mass": "percent", "wheel-radius": "percent", "com": "metres", "axis": "flip",
}
_NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?")
GRAMMAR = (
    "inertia:LINK:P% | mass:LINK:P% | com:LINK:DX | axis:JOINT:flip | cylinder-y:LINK | wheel-radius:LINK:P% "
    "| swap:JOINT:OTHER"
)


class InjectError(ValueError):
    """A bad ``--inject`` spec, or one naming something the file lacks; ``str()`` locates it."""

    def __init__(self, spec: str, column: int, message: str) -> None:
        self.spec = spec
        self.column = column
        self.message = message
        super().__init__(f"{message}\n    {spec}\n    {' ' * column}^")


@dataclass(frozen=True)
class Fault:
    """A parsed spec: ``amount`` is the factor 1 + P/100 for percentages, metres for ``com``."""

    kind: str
    target: str
    amount: float | None
    spec: str
    name_column: int = 0
    other: str = ""  # swap: the second joint
    other_column: int = 0


@dataclass
class Injection:
    """What :func:`inject` changed in one file."""

    spec: str
    file: str
    format: str
    kind: str
    target: str  # source name (as in the spec)
    written: str  # the name in the file
    changes: list[str] = field(default_factory=list)  # "element: attribute old → new"

    @property
    def description(self) -> str:
        return f"{self.spec} in {self.file} ({self.format}, {self.written!r}): " + "; ".join(self.changes)


def apply(spec: str, files: Mapping[str, Path], renames: Mapping[str, Renames] | None = None) -> str:
    """Inject one fault into every written file (``files``: "mjcf"/"urdf"/"sdf" → path, ``renames``:
    the same keys → that file's renames); the one-line description for the report."""
    fault = parse(spec)
    done = [inject(path, fault, (renames or {}).get(key)) for key, path in sorted(files.items())]
    return f"{spec}: " + " | ".join(f"{d.file}: " + "; ".join(d.changes) for d in done)


def parse(spec: str) -> Fault:
    """Parse one spec (see the module docstring for the grammar)."""
    kind, sep, rest = spec.partition(":")
    if kind not in KINDS:
        raise InjectError(spec, 0, f"unknown fault {kind!r}; expected one of: {GRAMMAR}")
    if not sep or not rest:
        raise InjectError(spec, len(spec), f"missing the {KINDS[kind]} name: {_usage(kind)}")
    start = len(kind) + 1
    if kind == "cylinder-y":
        return Fault(kind, rest, None, spec, start)
    name, sep, value = rest.rpartition(":")
    if not sep or not name:
        raise InjectError(spec, len(spec), f"missing the value: {_usage(kind)}")
    column = start + len(name) + 1
    if kind == "swap":
        if not value or value == name:
            raise InjectError(spec, column, f"expected a second, different joint: {_usage(kind)}")
        return Fault(kind, name, None, spec, start, value, column)
    what = _VALUE_KINDS[kind]
    amount: float | None
    if what == "flip":
        if value != "flip":
            raise InjectError(spec, column, f"expected 'flip': {_usage(kind)}")
        amount = None
    elif what == "percent":
        if not value.endswith("%") or not _NUMBER.fullmatch(value[:-1]):
            raise InjectError(spec, column, f"expected a percentage such as 1% or -5%: {_usage(kind)}")
        percent = float(value[:-1])
        if percent == 0.0 or 1.0 + percent / 100.0 <= 0.0:
            raise InjectError(spec, column, "the percentage must be non-zero and above -100%")
        amount = 1.0 + percent / 100.0
    else:
        text = value[:-1] if value.endswith("m") else value
        if not _NUMBER.fullmatch(text) or float(text) == 0.0:
            raise InjectError(
                spec, column, f"expected a non-zero distance in metres such as 0.01: {_usage(kind)}"
            )
        amount = float(text)
    return Fault(kind, name, amount, spec, start)


def _usage(kind: str) -> str:
    return next(part.strip() for part in GRAMMAR.split("|") if part.strip().startswith(kind + ":"))


def file_format(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix == ".urdf":
        return "urdf"
    if suffix == ".sdf":
        return "sdf"
    if suffix in (".xml", ".mjcf"):
        return "mjcf"
    raise ValueError(f"{path.name}: cannot inject into a {suffix or 'suffix-less'} file (MJCF, URDF or SDF)")


def inject(path: Path, fault: Fault | str, renames: Renames | None = None) -> Injection:
    """Apply one fault to one written file, in place; ``renames`` maps source to written names."""
    if isinstance(fault, str):
        fault = parse(fault)
    path = Path(path)
    fmt_name = file_format(path)
    parser = etree.XMLParser(remove_blank_text=False, remove_comments=False)
    tree = etree.parse(str(path), parser)
    root = tree.getroot()
    kind = KINDS[fault.kind]
    names = _NAMES[fmt_name][kind](root)
    mapping = dict((renames or {}).get(kind, {}))
    written = mapping.get(fault.target, fault.target)
    if written not in names:
        back = {w: s for s, w in mapping.items()}
        valid = sorted(back.get(n, n) for n in names)
        raise InjectError(
            fault.spec, fault.name_column,
            f"{path.name} has no {kind} {fault.target!r}; its {kind}s: {', '.join(valid) or '(none)'}",
        )
    result = Injection(fault.spec, path.name, fmt_name, fault.kind, fault.target, written)
    if fault.kind == "swap":
        other = mapping.get(fault.other, fault.other)
        if other not in names:
            back = {w: s for s, w in mapping.items()}
            valid = sorted(back.get(n, n) for n in names)
            raise InjectError(fault.spec, fault.other_column, f"{path.name} has no joint {fault.other!r}; "
                              f"its joints: {', '.join(valid) or '(none)'}")
        _swap_names(root, fmt_name, written, other, result.changes)
        save(path, tree)
        return result
    edit = _EDITS[(fault.kind, fmt_name)]
    try:
        edit(root, written, fault.amount, result.changes)
    except _NotApplicable as exc:
        raise InjectError(fault.spec, fault.name_column, f"{path.name}: {exc}") from None
    if not result.changes:  # a zero inertia or mass scaled: the file would not change
        raise InjectError(fault.spec, fault.name_column, f"{path.name}: {fault.kind} of {written!r} is zero; "
                          "the fault would change nothing")
    save(path, tree)
    return result


def save(path: Path, tree: etree._ElementTree, like: Path | None = None) -> None:
    """Write the tree with the XML declaration (if any) of ``like`` (default: the file it replaces)
    and a final newline."""
    head = (like or path).read_bytes()[:200].lstrip()
    declaration = head.split(b"?>", 1)[0] + b"?>\n" if head.startswith(b"<?xml") else b""
    body = etree.tostring(tree.getroot(), encoding="utf-8")
    path.write_bytes(declaration + body + b"\n")


class _NotApplicable(Exception):
    """The named element exists but lacks what the fault changes (no inertial, no cylinder...)."""


# ----------------------------------------------------------------------------------------------------
# helpers


def _floats(text: str | None) -> list[float]:
    return [float(x) for x in (text or "").split()]


def _set_attr(el: Element, attr: str, value: str, where: str, changes: list[str]) -> None:
    old = el.get(attr)
    el.set(attr, value)
    if old != value:
        changes.append(f"{where} {attr}: {old if old is not None else '(absent)'} → {value}")


def _set_text(el: Element, value: str, where: str, changes: list[str]) -> None:
    old = (el.text or "").strip()
    el.text = value
    if old != value:
        changes.append(f"{where}: {old or '(absent)'} → {value}")


def _named(root: Element, xpath: str, name: str) -> Element:
    for el in root.iterfind(xpath):
        if el.get("name") == name:
            return el
    raise _NotApplicable(f"no element {xpath} named {name!r}")


def _turned(rotation: Mat3) -> Mat3:
    """The cylinder's rotation turned 90° about its own x axis (local z → local −y)."""
    return np.asarray(rotation, dtype=float) @ rot_x(math.pi / 2.0)


def _names_mjcf_links(root: Element) -> list[str]:
    return [str(b.get("name")) for b in root.iter("body") if b.get("name")]


def _names_mjcf_joints(root: Element) -> list[str]:
    return [str(j.get("name")) for j in root.iterfind(".//body/joint") if j.get("name")]


def _names_urdf(tag: str) -> Callable[[Element], list[str]]:
    return lambda root: [str(e.get("name")) for e in root.findall(tag) if e.get("name")]


def _names_sdf(tag: str) -> Callable[[Element], list[str]]:
    return lambda root: [str(e.get("name")) for e in root.findall(f"model/{tag}") if e.get("name")]


_NAMES: dict[str, dict[str, Callable[[Element], list[str]]]] = {
    "mjcf": {"link": _names_mjcf_links, "joint": _names_mjcf_joints},
    "urdf": {"link": _names_urdf("link"), "joint": _names_urdf("joint")},
    "sdf": {"link": _names_sdf("link"), "joint": _names_sdf("joint")},
}

# ----------------------------------------------------------------------------------------------------
# MJCF


def _mjcf_inertial(root: Element, body: str) -> Element:
    el = _named(root, ".//body", body).find("inertial")
    if el is None:
        raise _NotApplicable(f"body {body!r} has no <inertial>")
    return el


def _inertia_mjcf(root: Element, body: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    el = _mjcf_inertial(root, body)
    attr = "fullinertia" if el.get("fullinertia") is not None else "diaginertia"
    if el.get(attr) is None:
        raise _NotApplicable(f"body {body!r}: <inertial> has no diaginertia or fullinertia")
    scaled = fmt_vec([factor * x for x in _floats(el.get(attr))])
    _set_attr(el, attr, scaled, f"body[{body}]/inertial", changes)


def _mass_mjcf(root: Element, body: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    el = _mjcf_inertial(root, body)
    _set_attr(el, "mass", fmt(factor * float(el.get("mass", "0"))), f"body[{body}]/inertial", changes)


def _com_mjcf(root: Element, body: str, dx: float | None, changes: list[str]) -> None:
    assert dx is not None
    el = _mjcf_inertial(root, body)
    pos = _floats(el.get("pos")) or [0.0, 0.0, 0.0]
    pos[0] += dx
    _set_attr(el, "pos", fmt_vec(pos), f"body[{body}]/inertial", changes)


def _axis_mjcf(root: Element, joint: str, _: float | None, changes: list[str]) -> None:
    el = _named(root, ".//body/joint", joint)
    if el.get("type", "hinge") not in ("hinge", "slide"):
        raise _NotApplicable(f"joint {joint!r} is a {el.get('type')} joint: no axis to flip")
    axis = _floats(el.get("axis")) or [0.0, 0.0, 1.0]  # MuJoCo's default axis
    _set_attr(el, "axis", fmt_vec([-x for x in axis]), f"joint[{joint}]", changes)


def _mjcf_rotation(root: Element, geom: Element, where: str) -> Mat3:
    """The geom's rotation from the orientation attribute our writer (or a person) used."""
    compiler = root.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") == "degree"
    scale = math.pi / 180.0 if degrees else 1.0
    if geom.get("fromto") is not None or geom.get("xyaxes") is not None:
        raise _NotApplicable(f"{where}: orientation by fromto/xyaxes is not supported by the injector")
    if geom.get("quat") is not None:
        return matrix_from_quat_wxyz(_floats(geom.get("quat")))
    if geom.get("axisangle") is not None:
        values = _floats(geom.get("axisangle"))
        return axis_angle(values[:3], values[3] * scale)
    if geom.get("euler") is not None:
        sequence = compiler.get("eulerseq", "xyz") if compiler is not None else "xyz"
        r, p, y = (a * scale for a in _floats(geom.get("euler")))
        if sequence == "XYZ":  # fixed axes: what our writer uses (URDF's rpy)
            return matrix_from_rpy(r, p, y)
        if sequence != "xyz":
            raise _NotApplicable(f"{where}: euler with eulerseq other than xyz or XYZ is not supported")
        return rot_x(r) @ axis_angle([0, 1, 0], p) @ axis_angle([0, 0, 1], y)  # intrinsic x-y-z
    if geom.get("zaxis") is not None:
        z = np.array(_floats(geom.get("zaxis")), dtype=float)
        z = z / np.linalg.norm(z)
        c = np.cross([0.0, 0.0, 1.0], z)
        s = float(np.linalg.norm(c))
        angle = math.atan2(s, float(z[2]))
        return axis_angle(c if s > 1e-15 else [1.0, 0.0, 0.0], angle) if angle != 0.0 else np.eye(3)
    return np.eye(3)


def _mjcf_geoms(root: Element, body: str, types: tuple[str, ...]) -> list[tuple[int, Element]]:
    el = _named(root, ".//body", body)
    geoms = [(i, g) for i, g in enumerate(el.findall("geom")) if g.get("type", "sphere") in types]
    if not geoms:
        raise _NotApplicable(f"body {body!r} has no {' or '.join(types)} geom")
    return geoms


def _cylinder_y_mjcf(root: Element, body: str, _: float | None, changes: list[str]) -> None:
    for i, geom in _mjcf_geoms(root, body, ("cylinder",)):
        where = f"body[{body}]/geom[{i}]"
        turned = _turned(_mjcf_rotation(root, geom, where))
        old = geom.get("quat") or " ".join(f"{a}={geom.get(a)}" for a in ("axisangle", "euler", "zaxis")
                                          if geom.get(a) is not None) or "(identity)"
        for attr in ("axisangle", "euler", "zaxis"):
            if attr in geom.attrib:
                del geom.attrib[attr]
        geom.set("quat", fmt_vec(quat_wxyz(turned)))
        changes.append(f"{where} orientation: {old} → quat {geom.get('quat')}")


def _wheel_radius_mjcf(root: Element, body: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    for i, geom in _mjcf_geoms(root, body, ("cylinder", "sphere")):
        size = _floats(geom.get("size"))
        size[0] *= factor
        _set_attr(geom, "size", fmt_vec(size), f"body[{body}]/geom[{i}]", changes)


# ----------------------------------------------------------------------------------------------------
# URDF


def _urdf_inertial(root: Element, link: str) -> Element:
    el = _named(root, "link", link).find("inertial")
    if el is None:
        raise _NotApplicable(f"link {link!r} has no <inertial>")
    return el


def _inertia_urdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    el = _urdf_inertial(root, link).find("inertia")
    if el is None:
        raise _NotApplicable(f"link {link!r}: <inertial> has no <inertia>")
    for attr in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        _set_attr(el, attr, fmt(factor * float(el.get(attr, "0"))), f"link[{link}]/inertial/inertia", changes)


def _mass_urdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    el = _urdf_inertial(root, link).find("mass")
    if el is None:
        raise _NotApplicable(f"link {link!r}: <inertial> has no <mass>")
    _set_attr(el, "value", fmt(factor * float(el.get("value", "0"))), f"link[{link}]/inertial/mass", changes)


def _com_urdf(root: Element, link: str, dx: float | None, changes: list[str]) -> None:
    assert dx is not None
    inertial = _urdf_inertial(root, link)
    origin = inertial.find("origin")
    if origin is None:
        origin = etree.Element("origin")
        inertial.insert(0, origin)
    xyz = _floats(origin.get("xyz")) or [0.0, 0.0, 0.0]
    xyz[0] += dx
    _set_attr(origin, "xyz", fmt_vec(xyz), f"link[{link}]/inertial/origin", changes)


def _axis_urdf(root: Element, joint: str, _: float | None, changes: list[str]) -> None:
    el = _named(root, "joint", joint)
    if el.get("type") not in ("revolute", "continuous", "prismatic"):
        raise _NotApplicable(f"joint {joint!r} is a {el.get('type')} joint: no axis to flip")
    axis = el.find("axis")
    if axis is None:
        axis = etree.SubElement(el, "axis")
    xyz = _floats(axis.get("xyz")) or [1.0, 0.0, 0.0]  # URDF's default axis
    _set_attr(axis, "xyz", fmt_vec([-x for x in xyz]), f"joint[{joint}]/axis", changes)


def _shapes(
    root: Element, link_path: str, link: str, tags: tuple[str, ...]
) -> list[tuple[str, Element, Element]]:
    """(where, visual/collision element, shape element) for every ``tags`` shape of a link; shared by
    URDF (``link_path="link"``) and SDF (``"model/link"``, whose items are named)."""
    el = _named(root, link_path, link)
    out: list[tuple[str, Element, Element]] = []
    for role in ("collision", "visual"):
        for i, item in enumerate(el.findall(role)):
            for tag in tags:
                shape = item.find(f"geometry/{tag}")
                if shape is not None:
                    out.append((f"link[{link}]/{role}[{item.get('name') or i}]", item, shape))
    if not out:
        raise _NotApplicable(f"link {link!r} has no {' or '.join(tags)}")
    return out


def _urdf_shapes(root: Element, link: str, tags: tuple[str, ...]) -> list[tuple[str, Element, Element]]:
    return _shapes(root, "link", link, tags)


def _cylinder_y_urdf(root: Element, link: str, _: float | None, changes: list[str]) -> None:
    for where, item, _shape in _urdf_shapes(root, link, ("cylinder",)):
        origin = item.find("origin")
        if origin is None:
            origin = etree.Element("origin")
            item.insert(0, origin)
        rpy = _floats(origin.get("rpy")) or [0.0, 0.0, 0.0]
        turned = _turned(matrix_from_rpy(*rpy))
        _set_attr(origin, "rpy", fmt_vec(rpy_from_matrix(turned)), f"{where}/origin", changes)


def _wheel_radius_urdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    for where, _item, shape in _urdf_shapes(root, link, ("cylinder", "sphere")):
        radius = fmt(factor * float(shape.get("radius", "0")))
        _set_attr(shape, "radius", radius, f"{where}/{shape.tag}", changes)


# ----------------------------------------------------------------------------------------------------
# SDF


def _sdf_inertial(root: Element, link: str) -> Element:
    el = _named(root, "model/link", link).find("inertial")
    if el is None:
        raise _NotApplicable(f"link {link!r} has no <inertial>")
    return el


def _sdf_child(parent: Element, tag: str, where: str) -> Element:
    el = parent.find(tag)
    if el is None:
        raise _NotApplicable(f"{where} has no <{tag}>")
    return el


def _inertia_sdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    inertia = _sdf_child(_sdf_inertial(root, link), "inertia", f"link {link!r} <inertial>")
    for tag in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        el = inertia.find(tag)
        if el is None:  # SDFormat's defaults: 1 on the diagonal, 0 off it
            el = etree.SubElement(inertia, tag)
            el.text = "1" if tag in ("ixx", "iyy", "izz") else "0"
        _set_text(el, fmt(factor * float(el.text or 0)), f"link[{link}]/inertial/inertia/{tag}", changes)


def _mass_sdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    el = _sdf_child(_sdf_inertial(root, link), "mass", f"link {link!r} <inertial>")
    _set_text(el, fmt(factor * float(el.text or 1)), f"link[{link}]/inertial/mass", changes)


def _sdf_pose(parent: Element, where: str) -> tuple[Element, list[float]]:
    """The ``<pose>`` child (created when absent) as x y z roll pitch yaw (radians)."""
    pose = parent.find("pose")
    if pose is None:
        pose = etree.Element("pose")
        pose.text = "0 0 0 0 0 0"
        parent.insert(0, pose)
    values = _floats(pose.text) or [0.0] * 6
    if pose.get("rotation_format", "euler_rpy") == "quat_xyzw":
        x, y, z, qx, qy, qz, qw = values
        values = [x, y, z, *rpy_from_matrix(matrix_from_quat_wxyz([qw, qx, qy, qz]))]
        del pose.attrib["rotation_format"]
    elif pose.get("degrees") == "true":
        values = values[:3] + [math.radians(a) for a in values[3:]]
        del pose.attrib["degrees"]
    if len(values) != 6:
        raise _NotApplicable(f"{where}: cannot read <pose>{pose.text}</pose>")
    return pose, values


def _com_sdf(root: Element, link: str, dx: float | None, changes: list[str]) -> None:
    assert dx is not None
    inertial = _sdf_inertial(root, link)
    pose, values = _sdf_pose(inertial, f"link {link!r} <inertial>")
    if pose.get("relative_to") not in (None, "", link):
        frame = pose.get("relative_to")
        raise _NotApplicable(f"link {link!r}: an inertial pose relative to {frame!r} is not supported")
    old = pose.text
    values[0] += dx
    pose.text = fmt_vec(values)
    changes.append(f"link[{link}]/inertial/pose: {old} → {pose.text}")


def _axis_sdf(root: Element, joint: str, _: float | None, changes: list[str]) -> None:
    el = _named(root, "model/joint", joint)
    if el.get("type") not in ("revolute", "continuous", "prismatic"):
        raise _NotApplicable(f"joint {joint!r} is a {el.get('type')} joint: no axis to flip")
    axis = el.find("axis")
    if axis is None:
        axis = etree.SubElement(el, "axis")
    xyz = axis.find("xyz")
    if xyz is None:
        xyz = etree.SubElement(axis, "xyz")
        xyz.text = "0 0 1"  # SDFormat's default axis
    _set_text(xyz, fmt_vec([-x for x in _floats(xyz.text)]), f"joint[{joint}]/axis/xyz", changes)


def _sdf_shapes(root: Element, link: str, tags: tuple[str, ...]) -> list[tuple[str, Element, Element]]:
    return _shapes(root, "model/link", link, tags)


def _cylinder_y_sdf(root: Element, link: str, _: float | None, changes: list[str]) -> None:
    for where, item, _shape in _sdf_shapes(root, link, ("cylinder",)):
        pose, values = _sdf_pose(item, where)
        old = pose.text
        turned = _turned(matrix_from_rpy(*values[3:]))
        pose.text = fmt_vec([*values[:3], *rpy_from_matrix(turned)])
        changes.append(f"{where}/pose: {old} → {pose.text}")


def _wheel_radius_sdf(root: Element, link: str, factor: float | None, changes: list[str]) -> None:
    assert factor is not None
    for where, _item, shape in _sdf_shapes(root, link, ("cylinder", "sphere")):
        radius = _sdf_child(shape, "radius", where)
        _set_text(radius, fmt(factor * float(radius.text or 0)), f"{where}/{shape.tag}/radius", changes)


# Where each format names a joint: the joint's own name, and the attributes that refer to one.
_JOINT_REFERENCES: dict[str, tuple[tuple[str, str], ...]] = {
    "mjcf": ((".//joint", "name"), (".//*[@joint]", "joint"), (".//*[@joint1]", "joint1"),
             (".//*[@joint2]", "joint2"), (".//*[@jointinparent]", "jointinparent")),
    "urdf": (("joint", "name"), (".//mimic", "joint"), (".//transmission/joint", "name")),
    "sdf": (("model/joint", "name"),),
}


def _swap_names(root: Element, fmt_name: str, a: str, b: str, changes: list[str]) -> None:
    """Exchange joint names ``a`` and ``b`` in every place the format names a joint."""
    swap = {a: b, b: a}
    for xpath, attr in _JOINT_REFERENCES[fmt_name]:
        for el in root.iterfind(xpath):
            old = el.get(attr)
            if old in swap:
                el.set(attr, swap[old])
                changes.append(f"{el.tag}[{old}] {attr}: {old} → {swap[old]}")
    if fmt_name == "sdf":  # <mimic joint="..."> and <joint_name> texts in SDF
        for el in root.iter("joint_name"):
            if (el.text or "").strip() in swap:
                old = (el.text or "").strip()
                el.text = swap[old]
                changes.append(f"joint_name: {old} → {swap[old]}")


_Edit = Callable[[Element, str, "float | None", list[str]], None]
_EDITS: dict[tuple[str, str], _Edit] = {
    ("inertia", "mjcf"): _inertia_mjcf,
    ("inertia", "urdf"): _inertia_urdf,
    ("inertia", "sdf"): _inertia_sdf,
    ("mass", "mjcf"): _mass_mjcf,
    ("mass", "urdf"): _mass_urdf,
    ("mass", "sdf"): _mass_sdf,
    ("com", "mjcf"): _com_mjcf,
    ("com", "urdf"): _com_urdf,
    ("com", "sdf"): _com_sdf,
    ("axis", "mjcf"): _axis_mjcf,
    ("axis", "urdf"): _axis_urdf,
    ("axis", "sdf"): _axis_sdf,
    ("cylinder-y", "mjcf"): _cylinder_y_mjcf,
    ("cylinder-y", "urdf"): _cylinder_y_urdf,
    ("cylinder-y", "sdf"): _cylinder_y_sdf,
    ("wheel-radius", "mjcf"): _wheel_radius_mjcf,
    ("wheel-radius", "urdf"): _wheel_radius_urdf,
    ("wheel-radius", "sdf"): _wheel_radius_sdf,
}
