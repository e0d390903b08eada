"""MuJoCo's struct layouts, enums and model-array shapes, read from the C headers it installs.

:mod:`.native` calls MuJoCo's C library directly, so it must know where each field of ``mjModel``,
``mjSpec`` and ``mjsMesh`` lies and what MuJoCo's enum values are called. Both are read here, at run
time, from the headers shipped with the installed ``mujoco`` package (``mujoco/include/mujoco``), so
they always describe the library actually loaded. ``ctypes`` then computes the offsets with the
platform's C alignment rules.

Only the plain C that MuJoCo's headers use is understood: scalar and pointer fields, fixed arrays
sized by numbers or ``#define`` constants, named and anonymous nested structs, enums with literal,
shifted or earlier-member values. Anything else raises :class:`HeaderError`, and the caller falls
back to MuJoCo's Python bindings.
"""

from __future__ import annotations

import ast
import ctypes
import operator
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

# The headers read, in include order. MuJoCo 4 moved the enums into mjtype.h; MuJoCo 3 has mjtnum.h.
HEADERS = ("mjtnum.h", "mjtype.h", "mjmodel.h", "mjvisualize.h", "mjspec.h", "mjxmacro.h")
REQUIRED = ("mjmodel.h", "mjspec.h", "mjxmacro.h")

SCALARS: dict[str, Any] = {
    "double": ctypes.c_double,
    "float": ctypes.c_float,
    "int": ctypes.c_int,
    "char": ctypes.c_char,
    "mjtNum": ctypes.c_double,
    "mjtByte": ctypes.c_ubyte,
    "mjtBool": ctypes.c_bool,
    "mjtSize": ctypes.c_int64,
    "uint64_t": ctypes.c_uint64,
    "int64_t": ctypes.c_int64,
    "size_t": ctypes.c_size_t,
}

_OPERATORS: dict[type, Any] = {
    ast.BitOr: operator.or_,
    ast.LShift: operator.lshift,
    ast.Add: operator.add,
    ast.Sub: operator.sub,
}

_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_DEFINE = re.compile(r"^\s*#define\s+(mj\w+)\s+(\d+)\b", re.M)
_ENUM = re.compile(r"typedef\s+enum\s+\w*\s*\{(.*?)\}\s*(\w+)\s*;", re.S)
_DECLARATION = re.compile(r"^(?:const\s+)?(?:struct\s+)?(\w+)\s*(\*?)\s*(\w+)\s*((?:\[\s*\w+\s*\])*)$")
_NESTED = re.compile(r"\s*struct\s*\{")
_DIMENSION = re.compile(r"\[\s*(\w+)\s*\]")
_BRACE = re.compile(r"[{}]")
_STRUCT_START = re.compile(r"\bstruct\s+(\w+?)_?\s*\{")
_SIZE = r"\s*(?:MJ_M\()?(\w+)\)?\s*"  # a number, a size field, or MJ_M(size field)
_POINTER_ROW = re.compile(rf"\bX\w*\s*\(\s*(\w+)\s*,\s*(\w+)\s*,{_SIZE},{_SIZE}\)")


class HeaderError(Exception):
    """The headers hold something this reader does not understand."""


@dataclass(frozen=True)
class ArrayShape:
    """One ``mjModel`` array: element type, and its rows and columns (a size field or a number)."""

    element: Any
    rows: str
    columns: str


@dataclass
class Headers:
    """What :mod:`.native` needs from the headers: struct types, enums, constants, array shapes."""

    structs: dict[str, type[ctypes.Structure]]
    enums: dict[str, dict[str, int]]
    constants: dict[str, int]
    model_arrays: dict[str, ArrayShape]
    enum_values: dict[str, int] = field(default_factory=dict)  # every member of every enum
    model_fields: dict[str, Any] = field(default_factory=dict)  # mjModel's fields by name, with their types

    def __post_init__(self) -> None:
        for members in self.enums.values():
            self.enum_values.update(members)
        self.model_fields.update(field_types(self.structs["mjModel"]))

    def offset(self, struct: str, *path: str) -> tuple[int, Any]:
        """Byte offset and ctypes type of a (nested) field, e.g. ``("mjSpec", "compiler", "fusestatic")``."""
        kind: Any = self.structs[struct]
        total = 0
        for name in path:
            described = getattr(kind, name)
            total += described.offset
            kind = field_types(kind)[name]
        return total, kind


def field_types(struct: type[ctypes.Structure]) -> dict[str, Any]:
    """A struct's fields by name, with their ctypes types."""
    return {entry[0]: entry[1] for entry in struct._fields_}


def read_headers(folder: Path) -> Headers:
    """Parse MuJoCo's headers in ``folder``; raises :class:`HeaderError` or ``OSError``."""
    raw = {name: (folder / name).read_text(encoding="utf-8") for name in HEADERS
           if name in REQUIRED or (folder / name).is_file()}
    text = "\n".join(_COMMENTS.sub(" ", body) for name, body in raw.items() if name != "mjxmacro.h")
    constants = {name: int(value) for name, value in _DEFINE.findall(text)}
    enums = {name: _enum_members(body) for body, name in _ENUM.findall(text)}
    layouts = _StructBuilder(text, constants, set(enums))
    structs = {name: layouts.named(name) for name in ("mjModel", "mjSpec", "mjsMesh")}
    arrays = _model_arrays(raw["mjxmacro.h"], structs["mjModel"])
    return Headers(structs, enums, constants, arrays)


def _enum_members(body: str) -> dict[str, int]:
    members: dict[str, int] = {}
    following = 0
    for entry in body.split(","):
        entry = entry.strip()
        if not entry:
            continue
        name, _, expression = (part.strip() for part in entry.partition("="))
        if not re.fullmatch(r"\w+", name):
            raise HeaderError(f"enum member {entry!r}")
        value = _enum_value(expression, members) if expression else following
        members[name] = value
        following = value + 1
    return members


def _enum_value(expression: str, members: dict[str, int]) -> int:
    """An enum value written as a number, an earlier member, or ``|``, ``<<``, ``+``, ``-`` of those."""
    if expression in members:
        return members[expression]
    if expression.isdigit():
        return int(expression)
    try:
        tree = ast.parse(" ".join(expression.split()), mode="eval")
    except SyntaxError:
        raise HeaderError(f"enum value {expression!r}") from None
    return _evaluate(tree.body, members, expression)


def _evaluate(node: ast.expr, members: dict[str, int], expression: str) -> int:
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return node.value
    if isinstance(node, ast.Name) and node.id in members:
        return members[node.id]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return -_evaluate(node.operand, members, expression)
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
        left = _evaluate(node.left, members, expression)
        right = _evaluate(node.right, members, expression)
        return int(_OPERATORS[type(node.op)](left, right))
    raise HeaderError(f"enum value {expression!r}")


class _StructBuilder:
    """ctypes Structure classes for the named structs of the headers, built on demand."""

    def __init__(self, text: str, constants: dict[str, int], enums: set[str]) -> None:
        self.text = text
        self.constants = constants
        self.enums = enums
        self.built: dict[str, type[ctypes.Structure]] = {}
        self.starts = {m.group(1): m.end() for m in _STRUCT_START.finditer(text)}

    def named(self, name: str) -> type[ctypes.Structure]:
        if name not in self.built:
            self.built[name] = self._structure(name, self._body_of(name))
        return self.built[name]

    def _body_of(self, name: str) -> str:
        start = self.starts.get(name)
        if start is None:
            raise HeaderError(f"struct {name} not found")
        return self.text[start : _closing_brace(self.text, start)]

    def _structure(self, name: str, body: str) -> type[ctypes.Structure]:
        fields = [(field, kind) for field, kind in self._fields(body)]
        return type(name, (ctypes.Structure,), {"_fields_": fields})

    def _fields(self, body: str) -> list[tuple[str, Any]]:
        fields: list[tuple[str, Any]] = []
        at = 0
        while True:
            nested = _NESTED.match(body, at)
            if nested:
                close = _closing_brace(body, nested.end())
                end = body.index(";", close)
                name = body[close + 1 : end].strip()
                inner = self._structure(f"anonymous_{name}", body[nested.end() : close])
                fields.append((name, inner))
                at = end + 1
                continue
            end = body.find(";", at)
            if end < 0:
                if body[at:].strip():
                    raise HeaderError(f"unterminated declaration {body[at:].strip()!r}")
                return fields
            fields.append(self._declaration(" ".join(body[at:end].split())))
            at = end + 1

    def _declaration(self, text: str) -> tuple[str, Any]:
        parsed = _DECLARATION.match(text)
        if parsed is None:
            raise HeaderError(f"declaration {text!r}")
        type_name, star, name, dims = parsed.groups()
        kind: Any = ctypes.c_void_p if star else self._type(type_name)
        for dim in reversed(_DIMENSION.findall(dims)):
            kind = kind * self._number(dim)
        return name, kind

    def _type(self, name: str) -> Any:
        if name in SCALARS:
            return SCALARS[name]
        if name in self.enums:
            return ctypes.c_int
        return self.named(name)

    def _number(self, token: str) -> int:
        if token.isdigit():
            return int(token)
        if token in self.constants:
            return self.constants[token]
        raise HeaderError(f"array size {token!r}")


def _closing_brace(text: str, start: int) -> int:
    """The index of the ``}`` closing the ``{`` just before ``start``."""
    depth = 1
    for brace in _BRACE.finditer(text, start):
        depth += 1 if brace.group() == "{" else -1
        if depth == 0:
            return brace.start()
    raise HeaderError("unbalanced braces")


def _model_arrays(xmacro: str, model: type[ctypes.Structure]) -> dict[str, ArrayShape]:
    """The shape of every ``mjModel`` pointer field, from ``MJMODEL_POINTERS`` in ``mjxmacro.h``."""
    fields = field_types(model)
    arrays: dict[str, ArrayShape] = {}
    for block in re.split(r"\n\s*#define\s+", xmacro):
        if not block.startswith("MJMODEL_POINTERS") or block.startswith("MJMODEL_POINTERS_PREAMBLE"):
            continue
        for type_name, name, rows, columns in _POINTER_ROW.findall(block):
            if name not in fields or fields[name] is not ctypes.c_void_p:
                raise HeaderError(f"mjModel has no pointer field {name}")
            element = SCALARS.get(type_name, ctypes.c_int)
            arrays[name] = ArrayShape(element, rows, columns)
    unknown = [name for name, kind in fields.items() if kind is ctypes.c_void_p and name not in arrays]
    if unknown != ["buffer"]:
        raise HeaderError(f"mjModel pointer fields without a shape in mjxmacro.h: {unknown}")
    return arrays
