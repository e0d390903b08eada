"""A small VRML97 (``.wrl``) reader for the subset Choreonoid's models use, producing triangles.

Read the way Choreonoid's ``VRMLParser`` + ``VRMLToSGConverter`` read it:

* The ``#VRML V2.0 utf8`` header is optional (Choreonoid's own PA10 parts have none); a VRML 1.0
  header is rejected. ``#`` comments, ``,`` as white space.
* ``DEF``/``USE``: a ``USE`` must follow its ``DEF``; a name defined twice keeps its **first**
  definition (Choreonoid stores DEF names in a ``std::map`` with ``insert``).
* Scene nodes: ``Transform`` (full VRML formula T·C·R·SR·S·SR⁻¹·C⁻¹), ``Group``, ``Collision``,
  ``Anchor``, ``Billboard``, ``Switch`` and ``LOD`` (all choices/levels, as Choreonoid's converter treats
  them as groups), ``Shape`` (geometry only; appearance ignored).
* Geometry: ``IndexedFaceSet`` (``coord``/``coordIndex``/``ccw``; polygons ear-clipped), ``Box``,
  ``Sphere``, ``Cylinder``, ``Cone`` (along **Y**, 20 divisions as Choreonoid's MeshGenerator default),
  ``ElevationGrid``.
* Skipped with a note: ``PROTO``/``EXTERNPROTO`` definitions, ``ROUTE``, ``Script``, unknown node types
  (PROTO instances), ``Inline``, ``Extrusion``. Other standard nodes (lights, viewpoints, …) are parsed
  and ignored. An unknown node's body is skipped by matching braces and brackets.

Only DEF names of scene nodes (grouping nodes and ``Shape``) become part names, as in Choreonoid
(where a DEF on a geometry names the mesh, not a node). Nesting is bounded (:data:`MAX_NESTING_DEPTH`
levels of ``{``/``[``, also through ``USE``) so hostile input raises :class:`VrmlError` with a line
number instead of exhausting the stack. Metadata (length unit, upper axis) is not applied here:
Choreonoid does not honour it for VRML.
"""

from __future__ import annotations

import math
import re
from bisect import bisect_right
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from modelkit.geometry.meshfiles import (
    MAX_NESTING_DEPTH,
    MAX_TRIANGLES,
    Mesh,
    MeshSceneNode,
    compact_mesh,
    triangulate_polygons,
)

__all__ = ["DIVISION_NUMBER", "VrmlError", "VrmlScene", "read_vrml"]

#: Segments around the circumference of tessellated primitives (Choreonoid's default).
DIVISION_NUMBER = 20


class VrmlError(Exception):
    """A VRML file cannot be parsed; ``line`` is 1-based (None when unknown)."""

    def __init__(self, message: str, line: int | None = None) -> None:
        super().__init__(f"line {line}: {message}" if line else message)
        self.message = message
        self.line = line


@dataclass
class VrmlScene:
    roots: list[MeshSceneNode]
    notes: list[str] = field(default_factory=list)


# ---- tokens ---------------------------------------------------------------------------------

# white space (incl. ',') and comments; one token (string, punctuation, other run; a lone quote is an error)
_SKIP_RE = re.compile(r"(?:[\s,]+|#[^\n\r]*)*")
_TOKEN_AT_RE = re.compile(r'"(?:[^"\\]|\\.)*"|[{}\[\]]|[^\s,#"{}\[\]]+|"', re.S)
# what matters when skipping a block: strings, comments, brackets
_BLOCK_RE = re.compile(r'"(?:[^"\\]|\\.)*"|#[^\n\r]*|[{}\[\]]|"', re.S)
_NUMERIC_CHARS_RE = re.compile(r"[\s,0-9eE+\-.]*")
_NUMBER_RE = re.compile(r"[+-]?(?:\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|0[xX][0-9a-fA-F]+)\Z")
_KEYWORD_SCALARS = frozenset({"TRUE", "FALSE", "NULL"})
_STATEMENT_KEYWORDS = frozenset({"PROTO", "EXTERNPROTO", "ROUTE"})

#: The 54 VRML97 node types (parsed generically, except Script: its field declarations differ).
_STANDARD_NODES = frozenset({
    "Anchor", "Appearance", "AudioClip", "Background", "Billboard", "Box", "Collision", "Color",
    "ColorInterpolator", "Cone", "Coordinate", "CoordinateInterpolator", "Cylinder", "CylinderSensor",
    "DirectionalLight", "ElevationGrid", "Extrusion", "Fog", "FontStyle", "Group", "ImageTexture",
    "IndexedFaceSet", "IndexedLineSet", "Inline", "LOD", "Material", "MovieTexture", "NavigationInfo",
    "Normal", "NormalInterpolator", "OrientationInterpolator", "PixelTexture", "PlaneSensor", "PointLight",
    "PointSet", "PositionInterpolator", "ProximitySensor", "ScalarInterpolator", "Script", "Shape", "Sound",
    "Sphere", "SphereSensor", "SpotLight", "Switch", "Text", "TextureCoordinate", "TextureTransform",
    "TimeSensor", "TouchSensor", "Transform", "Viewpoint", "VisibilitySensor", "WorldInfo",
})

#: Grouping nodes and the field holding their children.
_GROUP_FIELDS = {
    "Transform": "children",
    "Group": "children",
    "Collision": "children",
    "Anchor": "children",
    "Billboard": "children",
    "Switch": "choice",
    "LOD": "level",
}

#: Fields Choreonoid knows for the nodes this reader interprets (others are "Undefined field" errors there).
_KNOWN_FIELDS = {
    "Transform": {"center", "rotation", "scale", "scaleOrientation", "translation", "bboxCenter", "bboxSize",
                  "children", "addChildren", "removeChildren"},
    "Group": {"bboxCenter", "bboxSize", "children", "addChildren", "removeChildren"},
    "Shape": {"appearance", "geometry"},
    "IndexedFaceSet": {"color", "coord", "normal", "texCoord", "ccw", "colorIndex", "colorPerVertex",
                       "convex", "coordIndex", "creaseAngle", "normalIndex", "normalPerVertex", "solid",
                       "texCoordIndex"},
    "Coordinate": {"point"},
    "Box": {"size"},
    "Sphere": {"radius"},
    "Cylinder": {"bottom", "height", "radius", "side", "top"},
    "Cone": {"bottom", "bottomRadius", "height", "side"},
}


def _is_number(tok: str) -> bool:
    return tok[0] in "0123456789+-." and _NUMBER_RE.match(tok) is not None


def _is_scalar(tok: str) -> bool:
    return tok[0] == '"' or tok in _KEYWORD_SCALARS or _is_number(tok)


def _is_identifier(tok: str) -> bool:
    return tok[0] not in '{}[]"' and not _is_number(tok)


def _show(tok: str | None) -> str:
    if tok is None:
        return "end of file"
    return repr(tok if len(tok) <= 40 else tok[:37] + "...")


# ---- parse tree -----------------------------------------------------------------------------

#: A field value: scalar tokens / nodes / None (NULL or a skipped node), or a numeric array read in bulk.
_Value = list["str | _VNode | None"] | NDArray[np.float64]


class _LineIndex:
    """Offset → 1-based line number, built on first use (only errors and notes need lines)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._newlines: list[int] | None = None

    def line(self, offset: int) -> int:
        if self._newlines is None:
            self._newlines = [m.start() for m in re.finditer("\n", self.text)]
        return bisect_right(self._newlines, offset - 1) + 1


class _VNode:
    """A parsed node of a standard type: raw field values, kept until interpretation."""

    __slots__ = ("def_name", "field_offsets", "fields", "height", "offset", "src", "type")

    def __init__(self, node_type: str, offset: int, src: _LineIndex) -> None:
        self.type = node_type
        self.offset = offset
        self.src = src
        self.fields: dict[str, _Value] = {}
        self.field_offsets: dict[str, int] = {}
        self.def_name: str | None = None
        self.height = 1  # levels of nodes below and including this one (through USE too)

    @property
    def line(self) -> int:
        return self.src.line(self.offset)


class _Parser:
    """Recursive-descent parser over the text (tokens are scanned on demand; a bracketed list of plain
    numbers is read in one step, which is what makes large IndexedFaceSets fast)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.n = len(text)
        self.src = _LineIndex(text)
        self.p = 0  # offset of the next unread character
        self._tok: tuple[str, int, int] | None = None  # the next token (text, start, end), once scanned
        self.depth = 0
        self.defs: dict[str, _VNode | None] = {}
        self.def_lines: dict[str, int] = {}
        self.notes: list[str] = []
        self.skipped_types: dict[str, int] = {}
        self.skipped_statements: dict[str, int] = {}

    # -- scanning
    def _scan(self) -> tuple[str, int, int] | None:
        if self._tok is not None:
            return self._tok
        skipped = _SKIP_RE.match(self.text, self.p)  # always matches (possibly empty)
        q = skipped.end() if skipped else self.p
        if q >= self.n:
            return None
        m = _TOKEN_AT_RE.match(self.text, q)
        assert m is not None  # every character starts some token
        tok = m.group()
        if tok == '"':
            raise VrmlError("string is not closed with '\"'", self.src.line(q))
        self._tok = (tok, q, m.end())
        return self._tok

    def peek(self) -> str | None:
        t = self._scan()
        return t[0] if t else None

    def here(self) -> int:
        """Offset of the next token (end of text at the end)."""
        t = self._scan()
        return t[1] if t else self.n

    def take(self, context: str) -> str:
        t = self._scan()
        if t is None:
            raise self.error(f"unexpected end of file ({context})")
        self.p = t[2]
        self._tok = None
        return t[0]

    def jump(self, offset: int) -> None:
        self.p = offset
        self._tok = None

    def error(self, message: str, offset: int | None = None) -> VrmlError:
        return VrmlError(message, self.src.line(self.here() if offset is None else offset))

    def enter(self, at: int, weight: int = 1) -> None:
        """Count one more level of nesting: 1 for '[', 2 for a node body (a node costs more Python stack)."""
        self.depth += weight
        if self.depth > MAX_NESTING_DEPTH:
            raise self.error(f"nesting deeper than {MAX_NESTING_DEPTH} levels of braces/brackets", at)

    # -- statements
    def parse_file(self) -> list[_VNode]:
        roots: list[_VNode] = []
        while (tok := self.peek()) is not None:
            if tok == "}":
                raise self.error("extra closing brace '}'")
            if tok == "]":
                raise self.error("extra closing bracket ']'")
            item = self.statement()
            if item is not None:
                roots.append(item)
        return roots

    def statement(self) -> _VNode | None:
        """A node, ``USE name``, or a PROTO/EXTERNPROTO/ROUTE statement (which yields None)."""
        tok = self.peek()
        if tok == "PROTO":
            self.skip_proto()
            return None
        if tok == "EXTERNPROTO":
            self.skip_externproto()
            return None
        if tok == "ROUTE":
            self.skip_route()
            return None
        return self.node()

    def identifier(self, what: str) -> str:
        at = self.here()
        tok = self.take(what)
        if not _is_identifier(tok):
            raise self.error(f"expected {what}, found {_show(tok)}", at)
        return tok

    def node(self) -> _VNode | None:
        at = self.here()
        tok = self.take("a node was expected")
        if tok == "USE":
            name = self.identifier("a name after USE")
            if name not in self.defs:
                raise self.error(f'USE "{name}": no node was defined with DEF "{name}" before this point', at)
            return self.defs[name]
        def_name: str | None = None
        if tok == "DEF":
            def_name = self.identifier("a name after DEF")
            at = self.here()
            tok = self.take("a node type was expected after the DEF name")
        if not _is_identifier(tok) or tok in _KEYWORD_SCALARS:
            raise self.error(f"expected a node type, found {_show(tok)}", at)
        open_at = self.here()
        if self.take(f"'{{' after {tok}") != "{":
            raise self.error(f"the {_show(tok)} node does not begin with '{{'", open_at)
        result: _VNode | None
        if tok in _STANDARD_NODES and tok != "Script":
            result = self.node_body(tok, at)
        else:
            self.skip_block("{", open_at)
            self.skipped_types[tok] = self.skipped_types.get(tok, 0) + 1
            result = None
        if def_name is not None:
            line = self.src.line(at)
            if def_name in self.defs:
                self.notes.append(
                    f'DEF "{def_name}" defined again at line {line} (first at line '
                    f"{self.def_lines[def_name]}): USE refers to the first definition, as in Choreonoid"
                )
            else:
                self.defs[def_name] = result
                self.def_lines[def_name] = line
            if result is not None and result.def_name is None:
                result.def_name = def_name
        return result

    def node_body(self, node_type: str, at: int) -> _VNode:
        self.enter(at, 2)
        node = _VNode(node_type, at, self.src)
        while True:
            j = self.here()
            tok = self.peek()
            if tok is None:
                raise self.error(f"the {node_type} node opened at line {node.line} is not closed with '}}'")
            if tok == "}":
                self.take("}")
                break
            if tok in _STATEMENT_KEYWORDS:
                self.statement()
                continue
            self.take("a field name")
            if not _is_identifier(tok) or tok in _KEYWORD_SCALARS:
                found = _show(tok)
                raise self.error(f"expected a field name or '}}' in the {node_type} node, found {found}", j)
            value = self.value(tok, node_type)
            node.fields[tok] = value
            node.field_offsets[tok] = j
            if isinstance(value, list):
                for item in value:
                    if isinstance(item, _VNode) and item.height + 1 > node.height:
                        node.height = item.height + 1
        if node.height > MAX_NESTING_DEPTH:
            raise self.error(f"nesting deeper than {MAX_NESTING_DEPTH} levels (through USE)", at)
        self.depth -= 2
        return node

    def _numeric_list(self) -> NDArray[np.float64] | None:
        """After '[': a list of plain numbers up to ']' read in one step, or None (use the token path)."""
        end = self.text.find("]", self.p)
        if end < 0:
            return None
        m = _NUMERIC_CHARS_RE.match(self.text, self.p, end)
        if m is None or m.end() != end:
            return None
        parts = self.text[self.p : end].replace(",", " ").split()
        try:
            values = np.array(parts, dtype=np.float64)
        except ValueError:
            return None
        self.jump(end + 1)
        return values

    def value(self, field_name: str, node_type: str) -> _Value:
        j = self.here()
        tok = self.peek()
        if tok is None:
            raise self.error(f"field {field_name} of the {node_type} node has no value (end of file)")
        if tok == "[":
            self.take("[")
            bulk = self._numeric_list()
            if bulk is not None:
                return bulk
            self.enter(j)
            items: list[str | _VNode | None] = []
            while True:
                t = self.peek()
                if t is None:
                    at = self.src.line(j)
                    raise self.error(f"'[' of field {field_name} (line {at}) is not closed with ']'")
                if t == "]":
                    self.take("]")
                    break
                if t in ("{", "}", "["):
                    raise self.error(f"unexpected {_show(t)} in field {field_name} of the {node_type} node")
                if _is_scalar(t):
                    items.append(t)
                    self.take(t)
                elif t[0] in "0123456789+-.":
                    raise self.error(f"malformed number {_show(t)} in field {field_name}")
                else:
                    items.append(self.statement())
            self.depth -= 1
            return items
        if tok in ("{", "}", "]"):
            raise self.error(f"field {field_name} of the {node_type} node has no value", j)
        if _is_scalar(tok):
            run: list[str | _VNode | None] = []
            while (t := self.peek()) is not None and _is_scalar(t):
                run.append(t)
                self.take(t)
            return run
        return [self.statement()]

    # -- skipping
    def skip_block(self, opener: str, open_at: int) -> None:
        """Skip from an opener (already taken) to its matching closer, minding strings and comments."""
        stack = [(opener, open_at)]
        closers = {"{": "}", "[": "]"}
        for m in _BLOCK_RE.finditer(self.text, self.p):
            tok = m.group()
            c = tok[0]
            if c == "#" or len(tok) > 1:  # comment or string
                continue
            if c == '"':
                raise self.error("string is not closed with '\"'", m.start())
            if c in closers:
                stack.append((c, m.start()))
                continue
            o, at = stack.pop()
            if closers[o] != c:
                raise self.error(f"'{o}' at line {self.src.line(at)} is closed by '{c}'", m.start())
            if not stack:
                self.jump(m.end())
                return
        o, at = stack[-1]
        raise self.error(f"'{o}' at line {self.src.line(at)} is never closed", self.n)

    def _expect_block(self, opener: str, what: str) -> None:
        at = self.here()
        if self.take(what) != opener:
            raise self.error(f"expected '{opener}' in {what}", at)
        self.skip_block(opener, at)

    def skip_proto(self) -> None:
        self.take("PROTO")
        name = self.identifier("a PROTO name")
        self._expect_block("[", f"PROTO {name} (interface)")
        self._expect_block("{", f"PROTO {name} (body)")
        self.skipped_statements["PROTO"] = self.skipped_statements.get("PROTO", 0) + 1

    def skip_externproto(self) -> None:
        self.take("EXTERNPROTO")
        name = self.identifier("an EXTERNPROTO name")
        self._expect_block("[", f"EXTERNPROTO {name} (interface)")
        at = self.here()
        tok = self.take(f"EXTERNPROTO {name} URL")
        if tok == "[":
            self.skip_block("[", at)
        elif tok[0] != '"':
            raise self.error(f"expected the URL of EXTERNPROTO {name}, found {_show(tok)}", at)
        self.skipped_statements["EXTERNPROTO"] = self.skipped_statements.get("EXTERNPROTO", 0) + 1

    def skip_route(self) -> None:
        at = self.here()
        self.take("ROUTE")
        self.identifier("the source of a ROUTE")
        if self.take("ROUTE ... TO ...") != "TO":
            raise self.error("ROUTE without TO", at)
        self.identifier("the destination of a ROUTE")
        self.skipped_statements["ROUTE"] = self.skipped_statements.get("ROUTE", 0) + 1

    def summary_notes(self) -> list[str]:
        notes = list(self.notes)
        for kind, count in sorted(self.skipped_statements.items()):
            notes.append(f"{count} {kind} statement(s) skipped (not supported)")
        for node_type, count in sorted(self.skipped_types.items()):
            why = "Script is not supported" if node_type == "Script" else "unknown type (PROTO instance?)"
            notes.append(f"{count} {node_type} node(s) skipped: {why}")
        return notes


# ---- field access ---------------------------------------------------------------------------


def _field_line(v: _VNode, name: str) -> int:
    return v.src.line(v.field_offsets.get(name, v.offset))


def _numbers(v: _VNode, name: str) -> NDArray[np.float64] | None:
    items = v.fields.get(name)
    if items is None:
        return None
    if isinstance(items, np.ndarray):
        return items
    toks: list[str] = []
    for it in items:
        if not isinstance(it, str) or not _is_number(it):
            shown = it if isinstance(it, str) else "a node"
            raise VrmlError(f"field {name} of the {v.type} node must contain numbers, found {shown!r}",
                            _field_line(v, name))
        toks.append(it)
    try:
        return np.array(toks, dtype=np.float64)
    except ValueError:  # hexadecimal integers
        return np.array([float(int(t, 0)) if "x" in t.lower() else float(t) for t in toks], dtype=np.float64)


def _vector(v: _VNode, name: str, n: int, default: tuple[float, ...]) -> NDArray[np.float64]:
    vals = _numbers(v, name)
    if vals is None:
        return np.array(default, dtype=np.float64)
    if len(vals) != n:
        raise VrmlError(f"field {name} of the {v.type} node needs {n} numbers, found {len(vals)}",
                        _field_line(v, name))
    return vals


def _scalar(v: _VNode, name: str, default: float) -> float:
    return float(_vector(v, name, 1, (default,))[0])


def _items(v: _VNode, name: str, what: str) -> list[str | _VNode | None] | None:
    """A field's value as a token/node list (for non-numeric fields); an empty ``[]`` is an empty list."""
    items = v.fields.get(name)
    if isinstance(items, np.ndarray):
        if items.size:
            message = f"field {name} of the {v.type} node must be {what}, found numbers"
            raise VrmlError(message, _field_line(v, name))
        return []
    return items


def _bool(v: _VNode, name: str, default: bool) -> bool:
    items = _items(v, name, "TRUE or FALSE")
    if items is None:
        return default
    if len(items) == 1 and items[0] in ("TRUE", "FALSE"):
        return items[0] == "TRUE"
    raise VrmlError(f"field {name} of the {v.type} node must be TRUE or FALSE", _field_line(v, name))


def _sfnode(v: _VNode, name: str) -> _VNode | None:
    items = _items(v, name, "a node")
    if not items:
        return None
    node = items[0]
    if isinstance(node, _VNode):
        return node
    if node is None or node == "NULL":
        return None
    raise VrmlError(f"field {name} of the {v.type} node must be a node", _field_line(v, name))


def _mfnodes(v: _VNode, name: str) -> list[_VNode]:
    items = _items(v, name, "nodes") or []
    for it in items:
        if isinstance(it, str) and it != "NULL":
            raise VrmlError(f"field {name} of the {v.type} node must contain nodes, found {it!r}",
                            _field_line(v, name))
    return [it for it in items if isinstance(it, _VNode)]


def _rotation(v: _VNode, name: str) -> NDArray[np.float64]:
    """SFRotation as a 3×3 matrix; a zero axis is an error, as in Choreonoid."""
    r = _vector(v, name, 4, (0.0, 0.0, 1.0, 0.0))
    axis = r[:3]
    norm = float(np.linalg.norm(axis))
    if norm < 1e-6:
        raise VrmlError(f"field {name} of the {v.type} node: rotation axis is the zero vector",
                        _field_line(v, name))
    a = axis / norm
    c, s = math.cos(r[3]), math.sin(r[3])
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    out: NDArray[np.float64] = c * np.eye(3) + (1.0 - c) * np.outer(a, a) + s * k
    return out


def transform_matrix(v: _VNode) -> NDArray[np.float64]:
    """The VRML97 Transform: P' = T · C · R · SR · S · SR⁻¹ · C⁻¹ · P."""

    def homog(linear: NDArray[np.float64] | None = None, shift: NDArray[np.float64] | None = None
              ) -> NDArray[np.float64]:
        m = np.eye(4)
        if linear is not None:
            m[:3, :3] = linear
        if shift is not None:
            m[:3, 3] = shift
        return m

    t = _vector(v, "translation", 3, (0.0, 0.0, 0.0))
    c = _vector(v, "center", 3, (0.0, 0.0, 0.0))
    s = _vector(v, "scale", 3, (1.0, 1.0, 1.0))
    r = _rotation(v, "rotation")
    sr = _rotation(v, "scaleOrientation")
    return (
        homog(shift=t) @ homog(shift=c) @ homog(r) @ homog(sr) @ homog(np.diag(s))
        @ homog(sr.T) @ homog(shift=-c)
    )


# ---- primitives (Y axis, as VRML) -----------------------------------------------------------


def _mesh(vertices: list[list[float]] | NDArray[np.float64], faces: list[tuple[int, int, int]]) -> Mesh:
    return (np.asarray(vertices, dtype=np.float64).reshape(-1, 3),
            np.asarray(faces, dtype=np.int64).reshape(-1, 3))


def box_mesh(size: NDArray[np.float64]) -> Mesh:
    x, y, z = (float(a) / 2.0 for a in size)
    verts = [[sx * x, sy * y, sz * z] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    # corner index = 4·(x>0) + 2·(y>0) + (z>0); outward, counter-clockwise seen from outside
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return _mesh(verts, faces)


def _ring(radius: float, y: float, n: int) -> list[list[float]]:
    """n points on a circle of the plane y = const, starting on +Z, counter-clockwise seen from +Y."""
    angles = [2.0 * math.pi * i / n for i in range(n)]
    return [[radius * math.sin(a), y, radius * math.cos(a)] for a in angles]


def cylinder_mesh(radius: float, height: float, top: bool, bottom: bool, side: bool,
                  n: int = DIVISION_NUMBER) -> Mesh:
    h = height / 2.0
    verts = _ring(radius, -h, n) + _ring(radius, h, n) + [[0.0, -h, 0.0], [0.0, h, 0.0]]
    cb, ct = 2 * n, 2 * n + 1
    faces: list[tuple[int, int, int]] = []
    for i in range(n):
        j = (i + 1) % n
        if side:
            faces += [(i, j, n + j), (i, n + j, n + i)]
        if top:
            faces.append((ct, n + i, n + j))
        if bottom:
            faces.append((cb, j, i))
    return compact_mesh(*_mesh(verts, faces))


def cone_mesh(radius: float, height: float, bottom: bool, side: bool, n: int = DIVISION_NUMBER) -> Mesh:
    h = height / 2.0
    verts = [*_ring(radius, -h, n), [0.0, h, 0.0], [0.0, -h, 0.0]]
    apex, cb = n, n + 1
    faces: list[tuple[int, int, int]] = []
    for i in range(n):
        j = (i + 1) % n
        if side:
            faces.append((i, j, apex))
        if bottom:
            faces.append((cb, j, i))
    return compact_mesh(*_mesh(verts, faces))


def sphere_mesh(radius: float, n: int = DIVISION_NUMBER) -> Mesh:
    bands = max(n // 2, 2)
    verts: list[list[float]] = [[0.0, radius, 0.0]]
    for b in range(1, bands):
        phi = math.pi * b / bands
        verts += _ring(radius * math.sin(phi), radius * math.cos(phi), n)
    verts.append([0.0, -radius, 0.0])
    bottom = len(verts) - 1
    faces: list[tuple[int, int, int]] = []

    def ring(b: int, i: int) -> int:  # vertex i of latitude ring b (1 .. bands-1)
        return 1 + (b - 1) * n + (i % n)

    for i in range(n):
        faces.append((0, ring(1, i), ring(1, i + 1)))
        for b in range(1, bands - 1):
            faces += [(ring(b, i), ring(b + 1, i), ring(b + 1, i + 1)),
                      (ring(b, i), ring(b + 1, i + 1), ring(b, i + 1))]
        faces.append((bottom, ring(bands - 1, i + 1), ring(bands - 1, i)))
    return _mesh(verts, faces)


# ---- conversion to the scene graph ----------------------------------------------------------


class _Converter:
    def __init__(self) -> None:
        self.nodes: dict[int, MeshSceneNode | None] = {}
        self.meshes: dict[int, Mesh | None] = {}
        self.notes: list[str] = []
        self.unsupported: dict[str, int] = {}
        self.bad_polygons = 0
        self.switches: set[str] = set()
        self.unknown_fields: set[tuple[str, str]] = set()

    def _check_fields(self, v: _VNode) -> None:
        known = _KNOWN_FIELDS.get(v.type)
        if known is None:
            return
        for name in v.fields:
            if name not in known:
                self.unknown_fields.add((v.type, name))

    def scene_node(self, v: _VNode) -> MeshSceneNode | None:
        key = id(v)
        if key in self.nodes:
            return self.nodes[key]
        self._check_fields(v)
        out: MeshSceneNode | None = None
        if v.type in _GROUP_FIELDS:
            if v.type in ("Switch", "LOD"):
                self.switches.add(v.type)
            kids: list[MeshSceneNode] = []
            for child in _mfnodes(v, _GROUP_FIELDS[v.type]):  # a plain loop: one stack frame per level
                converted = self.scene_node(child)
                if converted is not None:
                    kids.append(converted)
            matrix = transform_matrix(v) if v.type == "Transform" else np.eye(4)
            if kids:  # Choreonoid drops empty groups (so their DEF names cannot be selected)
                out = MeshSceneNode(name=v.def_name, matrix=matrix, children=kids)
        elif v.type == "Shape":
            geometry = _sfnode(v, "geometry")
            mesh = self.geometry(geometry) if geometry is not None else None
            if mesh is not None:
                out = MeshSceneNode(name=v.def_name, meshes=[mesh])
        elif v.type == "Inline":
            self.unsupported["Inline"] = self.unsupported.get("Inline", 0) + 1
        self.nodes[key] = out
        return out

    def geometry(self, g: _VNode) -> Mesh | None:
        key = id(g)
        if key in self.meshes:
            return self.meshes[key]
        self._check_fields(g)
        mesh: Mesh | None = None
        t = g.type
        if t == "IndexedFaceSet":
            mesh = self.indexed_face_set(g)
        elif t == "Box":
            size = _vector(g, "size", 3, (2.0, 2.0, 2.0))
            if np.any(size < 0):
                raise VrmlError("Box size must not be negative", _field_line(g, "size"))
            mesh = box_mesh(size)
        elif t == "Sphere":
            r = _scalar(g, "radius", 1.0)
            if r <= 0:
                raise VrmlError("Sphere radius must be positive", _field_line(g, "radius"))
            mesh = sphere_mesh(r)
        elif t == "Cylinder":
            r, h = _scalar(g, "radius", 1.0), _scalar(g, "height", 2.0)
            if r <= 0 or h <= 0:
                raise VrmlError("Cylinder radius and height must be positive", g.line)
            top, bottom, side = _bool(g, "top", True), _bool(g, "bottom", True), _bool(g, "side", True)
            mesh = cylinder_mesh(r, h, top, bottom, side)
        elif t == "Cone":
            r, h = _scalar(g, "bottomRadius", 1.0), _scalar(g, "height", 2.0)
            if r <= 0 or h <= 0:
                raise VrmlError("Cone bottomRadius and height must be positive", g.line)
            mesh = cone_mesh(r, h, _bool(g, "bottom", True), _bool(g, "side", True))
        elif t == "ElevationGrid":
            mesh = self.elevation_grid(g)
        elif t in ("IndexedLineSet", "PointSet", "Text"):
            mesh = None  # no triangles (Text is not rendered as a mesh)
        else:
            self.unsupported[t] = self.unsupported.get(t, 0) + 1
        self.meshes[key] = mesh
        return mesh

    def indexed_face_set(self, g: _VNode) -> Mesh | None:
        coord = _sfnode(g, "coord")
        if coord is None:
            return None
        points = _numbers(coord, "point")
        index = _numbers(g, "coordIndex")
        if points is None or index is None or len(points) == 0 or len(index) == 0:
            return None
        if len(points) % 3:
            raise VrmlError(f"Coordinate point has {len(points)} numbers, not a multiple of 3",
                            _field_line(coord, "point"))
        if np.any(index != np.round(index)):
            raise VrmlError("coordIndex must contain integers", _field_line(g, "coordIndex"))
        verts = points.reshape(-1, 3)
        idx = index.astype(np.int64)
        neg = idx < 0  # any negative index ends a polygon (as Choreonoid); the last -1 is optional
        ends = np.nonzero(neg)[0]
        seg_start = np.concatenate([[0], ends + 1])
        seg_stop = np.concatenate([ends, [len(idx)]])
        counts = seg_stop - seg_start
        counts = counts[counts > 0]
        flat = idx[~neg]
        if not _bool(g, "ccw", True):  # reverse every polygon
            starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
            poly = np.repeat(np.arange(len(counts)), counts)
            local = np.arange(len(flat)) - starts[poly]
            flat = flat[starts[poly] + counts[poly] - 1 - local]
        faces, bad = triangulate_polygons(verts, counts, flat)
        self.bad_polygons += bad
        return compact_mesh(verts, faces)

    def elevation_grid(self, g: _VNode) -> Mesh | None:
        nx = int(_scalar(g, "xDimension", 0))
        nz = int(_scalar(g, "zDimension", 0))
        dx, dz = _scalar(g, "xSpacing", 1.0), _scalar(g, "zSpacing", 1.0)
        heights = _numbers(g, "height")
        heights = np.zeros(0) if heights is None else heights
        if nx < 2 or nz < 2 or len(heights) != nx * nz:
            self.notes.append(f"ElevationGrid at line {g.line} has inconsistent dimensions; skipped")
            return None
        if 2 * (nx - 1) * (nz - 1) > MAX_TRIANGLES:
            raise VrmlError(f"ElevationGrid of {nx} x {nz} points is too large", g.line)
        xs, zs = np.meshgrid(np.arange(nx) * dx, np.arange(nz) * dz)
        verts = np.stack([xs.ravel(), heights, zs.ravel()], axis=1)
        x, z = np.meshgrid(np.arange(nx - 1), np.arange(nz - 1))
        p00 = (z * nx + x).ravel()  # (x, z)
        p01, p10, p11 = p00 + nx, p00 + 1, p00 + nx + 1  # (x, z+1), (x+1, z), (x+1, z+1)
        if _bool(g, "ccw", True):
            tris = np.stack([np.stack([p00, p01, p11], 1), np.stack([p00, p11, p10], 1)], axis=1)
        else:
            tris = np.stack([np.stack([p00, p11, p01], 1), np.stack([p00, p10, p11], 1)], axis=1)
        return verts, tris.reshape(-1, 3).astype(np.int64)

    def summary_notes(self) -> list[str]:
        notes = list(self.notes)
        for t, count in sorted(self.unsupported.items()):
            what = "external file not followed" if t == "Inline" else "geometry not supported"
            notes.append(f"{count} {t} node(s) skipped ({what})")
        if self.bad_polygons:
            notes.append(f"{self.bad_polygons} IndexedFaceSet polygon(s) with fewer than 3 vertices "
                         "or an index out of range skipped")
        for t in sorted(self.switches):
            notes.append(f"{t}: every choice/level is included "
                         "(Choreonoid's VRML converter treats it as a group)")
        for node_type, name in sorted(self.unknown_fields):
            notes.append(f'unknown field "{name}" in a {node_type} node ignored (Choreonoid rejects it: '
                         '"Undefined field")')
        return notes


# ---- entry point ----------------------------------------------------------------------------


def read_vrml(data: bytes | str) -> VrmlScene:
    """Parse a VRML97 file and convert it to a :class:`MeshSceneNode` graph (metres, Y-up primitives)."""
    text = data.decode("utf-8", errors="replace") if isinstance(data, bytes) else data
    if text.startswith("\ufeff"):
        text = text[1:]
    if text.startswith("#VRML"):
        header = text.split("\n", 1)[0].strip()
        if not header.startswith("#VRML V2.0"):
            shown = header[:40]
            raise VrmlError(f"unsupported VRML version ({shown!r}); only VRML97 (#VRML V2.0) is read", 1)
    parser = _Parser(text)
    top = parser.parse_file()
    conv = _Converter()
    roots: list[MeshSceneNode] = []
    for v in top:
        converted = conv.scene_node(v)
        if converted is not None:
            roots.append(converted)
    return VrmlScene(roots, parser.summary_notes() + conv.summary_notes())
