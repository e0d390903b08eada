"""Semantic mutations of real model files: each mutant is still well-formed XML or YAML, but one model
fact changes (a number, a joint type, an axis, a limit, a shape, a missing or doubled element).

The byte-level cases of :mod:`tests.hostile.cases` mostly make files their loaders refuse; these make
files a loader may well accept, so that ``convert`` and the writers meet them too. Deterministic: the
same (source, seed) gives the same mutant.
"""

from __future__ import annotations

import copy
import random
import re
from collections.abc import Callable
from pathlib import Path

import yaml
from lxml import etree

NUMBERS = ("0", "-1", "-0.5", "1e6", "1e-9", "1e-300", "3.5e38", "12345.678", "-1e6", "0.0000001")
VECTORS = ("0 0 0", "1 1 0", "0 0 -1", "1e-9 0 0", "1e6 1e6 1e6", "-1 -1 -1", "0.5 0.5 0.5")
URDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
SDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "ball", "universal", "screw",
                   "revolute2", "gearbox")
MJCF_JOINT_TYPES = ("hinge", "slide", "ball", "free")
BODY_JOINT_TYPES = ("revolute", "prismatic", "fixed", "free", "pseudo_continuous_track")
URDF_SHAPES = ("box", "sphere", "cylinder", "capsule")
SDF_SHAPES = ("box", "sphere", "cylinder", "capsule", "ellipsoid", "plane")
MJCF_SHAPES = ("box", "sphere", "cylinder", "capsule", "ellipsoid", "plane")


def _numeric(text: str) -> bool:
    parts = text.split()
    if not parts:
        return False
    try:
        [float(p) for p in parts]
    except ValueError:
        return False
    return True


def _number_like(rng: random.Random, old: str) -> str:
    parts = old.split()
    if len(parts) == 3:
        return rng.choice(VECTORS)
    if len(parts) > 1:
        i = rng.randrange(len(parts))
        parts[i] = rng.choice(NUMBERS)
        return " ".join(parts)
    return rng.choice(NUMBERS)


# ---- XML ------------------------------------------------------------------------------------------


def _elements(root: etree._Element) -> list[etree._Element]:
    return [e for e in root.iter() if isinstance(e.tag, str)]


def _pick(root: etree._Element, rng: random.Random, tag: str) -> etree._Element | None:
    """One of the ``tag`` elements, chosen with ``rng``; None when there is none."""
    found = [e for e in _elements(root) if e.tag == tag]
    return rng.choice(found) if found else None


def _xml_number(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    spots: list[tuple[etree._Element, str | None]] = []
    for e in _elements(root):
        for name, value in e.attrib.items():
            if _numeric(value):
                spots.append((e, name))
        if e.text and _numeric(e.text) and not len(e):
            spots.append((e, None))
    if not spots:
        return None
    e, name = rng.choice(spots)
    if name is None:
        old = e.text or ""
        e.text = _number_like(rng, old)
        return f"{e.tag} text {old!r} -> {e.text!r}"
    old = e.get(name) or ""
    e.set(name, _number_like(rng, old))
    return f"{e.tag}@{name} {old!r} -> {e.get(name)!r}"


def _xml_joint_type(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    joints = [e for e in _elements(root) if e.tag == "joint" and e.get("type")]
    if kind == "mjcf":
        joints = [e for e in _elements(root) if e.tag == "joint"]
    if not joints:
        return None
    joint = rng.choice(joints)
    types = {"urdf": URDF_JOINT_TYPES, "sdf": SDF_JOINT_TYPES, "mjcf": MJCF_JOINT_TYPES}[kind]
    old = joint.get("type", "hinge")
    new = rng.choice([t for t in types if t != old])
    joint.set("type", new)
    return f"joint {joint.get('name')!r} type {old!r} -> {new!r}"


def _xml_shape(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    if kind == "mjcf":
        geom = _pick(root, rng, "geom")
        if geom is None:
            return None
        old = geom.get("type", "sphere")
        new = rng.choice([t for t in MJCF_SHAPES if t != old])
        geom.set("type", new)
        return f"geom {geom.get('name')!r} type {old!r} -> {new!r}"
    shapes = URDF_SHAPES if kind == "urdf" else SDF_SHAPES
    geometries = [e for e in _elements(root)
                  if e.tag == "geometry" and any(isinstance(c.tag, str) for c in e)]
    if not geometries:
        return None
    geometry = rng.choice(geometries)
    shape = next(c for c in geometry if isinstance(c.tag, str))
    old = shape.tag
    new = rng.choice([t for t in shapes if t != old])
    shape.tag = new
    return f"geometry {old!r} -> {new!r} (attributes kept)"


_KEEP = {"robot", "sdf", "mujoco", "model", "world", "worldbody"}


def _xml_delete(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    candidates = [e for e in _elements(root)[1:] if e.tag not in _KEEP and e.getparent() is not None]
    if not candidates:
        return None
    e = rng.choice(candidates)
    parent = e.getparent()
    assert parent is not None
    parent.remove(e)
    return f"deleted <{e.tag} name={e.get('name')!r}> from <{parent.tag}>"


def _xml_drop_attribute(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    spots = [(e, name) for e in _elements(root) for name in e.attrib if name != "version"]
    if not spots:
        return None
    e, name = rng.choice(spots)
    del e.attrib[name]
    return f"dropped {e.tag}@{name}"


def _xml_duplicate(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    candidates = [e for e in _elements(root)[1:] if e.tag not in _KEEP and e.getparent() is not None]
    if not candidates:
        return None
    e = rng.choice(candidates)
    twin = copy.deepcopy(e)
    if twin.get("name") and rng.random() < 0.7:
        twin.set("name", twin.get("name", "") + "_twin")
    e.addnext(twin)
    return f"duplicated <{e.tag} name={e.get('name')!r}>"


def _xml_limits(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    if kind == "urdf":
        limit = _pick(root, rng, "limit")
        if limit is None:
            return None
        lower, upper = rng.choice([("1", "-1"), ("0", "0"), ("-1e9", "1e9"), ("3", "3.1"), ("-7", "7")])
        limit.set("lower", lower)
        limit.set("upper", upper)
        return f"limit lower {lower} upper {upper}"
    if kind == "mjcf":
        joint = _pick(root, rng, "joint")
        if joint is None:
            return None
        value = rng.choice(["1 -1", "0 0", "-1e9 1e9", "-400 400"])
        joint.set("range", value)
        joint.set("limited", rng.choice(["true", "auto"]))
        return f"joint {joint.get('name')!r} range {value}"
    limit = _pick(root, rng, "limit")
    if limit is None:
        return None
    lower, upper = rng.choice([("1", "-1"), ("0", "0"), ("-1e16", "1e16")])
    for tag, value in (("lower", lower), ("upper", upper)):
        found = limit.find(tag)
        if found is None:
            found = etree.SubElement(limit, tag)
        found.text = value
    return f"sdf limit lower {lower} upper {upper}"


def _xml_reparent(root: etree._Element, rng: random.Random, kind: str) -> str | None:
    if kind in ("urdf", "sdf"):
        links = [str(e.get("name")) for e in _elements(root) if e.tag == "link" and e.get("name")]
        joint = _pick(root, rng, "joint") if links else None
        parent = joint.find("parent") if joint is not None else None
        if joint is None or parent is None:
            return None
        new = rng.choice(links if kind == "urdf" else [*links, "world"])
        if kind == "urdf":
            parent.set("link", new)
        else:
            parent.text = new
        return f"joint {joint.get('name')!r} parent -> {new!r}"
    bodies = [e for e in _elements(root) if e.tag == "body"]
    if len(bodies) < 2:
        return None
    body, target = rng.sample(bodies, 2)
    if body in target.iterancestors() or body is target:
        return None
    parent = body.getparent()
    assert parent is not None
    parent.remove(body)
    target.append(body)
    return f"body {body.get('name')!r} moved under {target.get('name')!r}"


XML_MUTATORS: dict[str, Callable[[etree._Element, random.Random, str], str | None]] = {
    "number": _xml_number,
    "joint_type": _xml_joint_type,
    "shape": _xml_shape,
    "delete": _xml_delete,
    "drop_attribute": _xml_drop_attribute,
    "duplicate": _xml_duplicate,
    "limits": _xml_limits,
    "reparent": _xml_reparent,
}


# ---- .body (YAML) ---------------------------------------------------------------------------------


def _walk(node: object, path: tuple[object, ...] = ()) -> list[tuple[tuple[object, ...], object]]:
    out: list[tuple[tuple[object, ...], object]] = [(path, node)]
    if isinstance(node, dict):
        for k, v in node.items():
            out.extend(_walk(v, (*path, k)))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.extend(_walk(v, (*path, i)))
    return out


def _container(doc: object, path: tuple[object, ...]) -> object:
    node = doc
    for key in path[:-1]:
        node = node[key]  # type: ignore[index]
    return node


def _body_mutate(doc: object, rng: random.Random, how: str) -> str | None:
    spots = _walk(doc)
    if how == "number":
        numbers = [(p, v) for p, v in spots if p and isinstance(v, int | float) and not isinstance(v, bool)]
        if not numbers:
            return None
        path, old = rng.choice(numbers)
        new = float(rng.choice(NUMBERS))
        _container(doc, path)[path[-1]] = new  # type: ignore[index]
        return f"{'/'.join(map(str, path))} {old!r} -> {new!r}"
    if how == "joint_type":
        found = [p for p, v in spots if p and p[-1] == "jointType"]
        if not found:
            return None
        path = rng.choice(found)
        new_type = rng.choice(BODY_JOINT_TYPES)
        _container(doc, path)[path[-1]] = new_type  # type: ignore[index]
        return f"{'/'.join(map(str, path))} -> {new_type}"
    if how == "axis":
        found = [p for p, v in spots if p and p[-1] == "jointAxis"]
        if not found:
            return None
        path = rng.choice(found)
        new_axis = rng.choice([[0, 0, 0], [1, 1, 0], "-Z", [1e-9, 0, 0], "Q"])
        _container(doc, path)[path[-1]] = new_axis  # type: ignore[index]
        return f"{'/'.join(map(str, path))} -> {new_axis!r}"
    if how == "delete":
        keys = [p for p, v in spots if len(p) > 1]
        if not keys:
            return None
        path = rng.choice(keys)
        holder = _container(doc, path)
        if isinstance(holder, dict):
            del holder[path[-1]]
        elif isinstance(holder, list):
            del holder[path[-1]]  # type: ignore[call-overload]
        return f"deleted {'/'.join(map(str, path))}"
    if how == "geometry":
        found = [p for p, v in spots if p and p[-1] == "type" and isinstance(v, str)
                 and v in ("Box", "Sphere", "Cylinder", "Capsule", "Cone", "Extrusion", "IndexedFaceSet")]
        if not found:
            return None
        path = rng.choice(found)
        new_shape = rng.choice(["Box", "Sphere", "Cylinder", "Capsule", "Cone", "Ellipsoid"])
        _container(doc, path)[path[-1]] = new_shape  # type: ignore[index]
        return f"{'/'.join(map(str, path))} -> {new_shape}"
    if how == "duplicate":
        lists = [(p, v) for p, v in spots if isinstance(v, list) and v and isinstance(v[0], dict)]
        if not lists:
            return None
        path, items = rng.choice(lists)
        i = rng.randrange(len(items))
        items.insert(i + 1, copy.deepcopy(items[i]))  # type: ignore[union-attr]
        return f"duplicated {'/'.join(map(str, path))}[{i}]"
    return None


BODY_MUTATIONS = ("number", "number", "joint_type", "axis", "delete", "geometry", "duplicate")


# ---- mutants --------------------------------------------------------------------------------------


def kind_of(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix == ".body":
        return "body"
    if suffix in (".urdf", ".xacro"):  # a xacro source mutated as the URDF it expands to
        return "urdf"
    if suffix in (".sdf", ".world"):
        return "sdf"
    return "mjcf"


def mutant(source: Path, seed: int) -> tuple[str, bytes] | None:
    """(what changed, the mutant's bytes) for ``source`` and ``seed``; None when the chosen mutation has
    nothing to act on. One to three mutations each."""
    rng = random.Random(f"{source.name}:{seed}")
    kind = kind_of(source)
    done: list[str] = []
    if kind == "body":
        try:
            doc = yaml.safe_load(source.read_text(encoding="utf-8"))
        except yaml.YAMLError:
            return None
        for _ in range(rng.choice((1, 1, 2, 3))):
            what = _body_mutate(doc, rng, rng.choice(BODY_MUTATIONS))
            if what:
                done.append(what)
        if not done:
            return None
        return "; ".join(done), yaml.safe_dump(doc, sort_keys=False).encode()
    parser = etree.XMLParser(remove_blank_text=False, resolve_entities=False, no_network=True)
    # TinyXML2 (urdfdom, libsdformat, MuJoCo) takes a declaration after a comment; libxml2 does not
    text = re.sub(rb"<\?xml[^>]*\?>", b"", source.read_bytes(), count=1)
    try:
        root = etree.fromstring(text, parser)
    except etree.XMLSyntaxError:  # "--" inside a comment (gz-sim's worlds): recovered, comments dropped
        recovering = etree.XMLParser(recover=True, remove_comments=True, resolve_entities=False,
                                     no_network=True)
        root = etree.fromstring(text, recovering)
        if root is None:
            return None
    tree = root.getroottree()
    names = sorted(XML_MUTATORS)
    for _ in range(rng.choice((1, 1, 2, 3))):
        what = XML_MUTATORS[rng.choice(names)](root, rng, kind)
        if what:
            done.append(what)
    if not done:
        return None
    return "; ".join(done), etree.tostring(tree, xml_declaration=True, encoding="utf-8")
