"""MuJoCo's own parser and compiler, called through ``ctypes`` instead of the Python bindings.

``import mujoco`` costs about eight times the bare interpreter's start-up (numpy and the bindings'
extension modules), so a plain ``modelkit validate robot.xml`` would be dominated by it. The C
library itself loads in about a millisecond. This module calls it directly, with exactly the calls
the bindings make for ``MjSpec.from_file`` and ``MjSpec.compile``:

``mj_parseXML`` → the compiler flags the reader needs (no static-body fusion, keep visual geoms,
free bodies as written) → ``mj_compile``, then hands the reader stand-ins with the attributes it
reads from ``mujoco`` (enums, ``mj_id2name``), ``MjModel`` (sizes and arrays, as plain tuples) and
``MjSpec`` (mesh files, ``meshdir``). Field offsets come from the headers installed with the library
(:mod:`.cheader`), so they describe the library actually loaded.

Anything unusual returns ``None`` and the reader goes through the bindings as before, so the verdict
and the diagnostics are always MuJoCo's: a library or header that cannot be found or read, a parse
or compile error (the bindings then report it, and read the uncompiled spec), and models that use
engine plugins (the bindings load MuJoCo's bundled plugins when imported; this path does not).
"""

from __future__ import annotations

import ctypes
import functools
import importlib.util
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from modelkit.formats.mjcf.cheader import HeaderError, Headers, read_headers

#: Set to ``bindings`` to always read MJCF through MuJoCo's Python bindings.
ENVIRONMENT_SWITCH = "MODELKIT_MUJOCO"

ERROR_SIZE = 1024
MESSAGE_HANDLER = ctypes.CFUNCTYPE(None, ctypes.c_char_p)
#: Compiler flags set exactly as :meth:`modelkit.formats.mjcf.reader._MjcfReader._spec` sets them.
COMPILER_FLAGS = {"fusestatic": False, "discardvisual": False, "alignfree": False}


@dataclass(frozen=True)
class Library:
    """The loaded C library and the layouts read from its headers."""

    dll: ctypes.CDLL
    headers: Headers
    fields: dict[str, tuple[int, Any]]  # offset and type of the spec fields used (see _spec_fields)


def _library_file(folder: Path) -> Path | None:
    patterns = {"win32": "mujoco.dll", "darwin": "libmujoco*.dylib"}
    found = sorted(folder.glob(patterns.get(sys.platform, "libmujoco.so*")))
    return found[0] if found else None


@functools.cache
def library() -> Library | None:
    """MuJoCo's C library from the installed ``mujoco`` package, or ``None`` when it cannot be used."""
    if os.environ.get(ENVIRONMENT_SWITCH) == "bindings":
        return None
    try:
        spec = importlib.util.find_spec("mujoco")  # locates the package without importing it
    except (ImportError, ValueError):
        return None
    folders = list(spec.submodule_search_locations or []) if spec is not None else []
    for folder in map(Path, folders):
        file = _library_file(folder)
        include = folder / "include" / "mujoco"
        if file is None or not include.is_dir():
            continue
        try:
            headers = read_headers(include)
            fields = _spec_fields(headers)
            dll = ctypes.CDLL(str(file))
            _declare(dll)
        except (OSError, HeaderError, ValueError, KeyError, TypeError, AttributeError):
            return None
        return Library(dll, headers, fields)
    return None


def _spec_fields(headers: Headers) -> dict[str, tuple[int, Any]]:
    """Where the compiler flags, ``meshdir`` and a mesh's file name lie. A flag this MuJoCo version does
    not have is left out (its compiler has no such step); ``meshdir`` moved into ``compiler`` in 3.3."""
    fields: dict[str, tuple[int, Any]] = {}
    for flag in COMPILER_FLAGS:
        try:
            fields[flag] = headers.offset("mjSpec", "compiler", flag)
        except (AttributeError, KeyError):
            continue
    for path in (("compiler", "meshdir"), ("meshdir",)):
        try:
            fields["meshdir"] = headers.offset("mjSpec", *path)
            break
        except (AttributeError, KeyError):
            continue
    else:
        raise HeaderError("mjSpec has no meshdir")
    fields["mesh_file"] = headers.offset("mjsMesh", "file")
    return fields


def _declare(dll: ctypes.CDLL) -> None:
    pointer, text = ctypes.c_void_p, ctypes.c_char_p
    signatures: dict[str, tuple[Any, list[Any]]] = {
        "mj_parseXML": (pointer, [text, pointer, text, ctypes.c_int]),
        "mj_compile": (pointer, [pointer, pointer]),
        "mj_deleteSpec": (None, [pointer]),
        "mj_deleteModel": (None, [pointer]),
        "mj_id2name": (text, [pointer, ctypes.c_int, ctypes.c_int]),
        "mjs_firstElement": (pointer, [pointer, ctypes.c_int]),
        "mjs_nextElement": (pointer, [pointer, pointer]),
        "mjs_asMesh": (pointer, [pointer]),
        "mjs_getString": (text, [pointer]),
    }
    for name, (result, arguments) in signatures.items():
        function = getattr(dll, name)
        function.restype = result
        function.argtypes = arguments


# -- the stand-ins the reader reads ------------------------------------------------------------


class EnumMember:
    """What ``enum_word`` reads from a bindings enum value: its ``name``."""

    def __init__(self, name: str) -> None:
        self.name = name


class CEnum:
    """One C enum: ``CEnum(value).name`` and ``CEnum.mjOBJ_BODY`` as the bindings' enums allow."""

    def __init__(self, members: dict[str, int]) -> None:
        self._members = members
        self._names: dict[int, str] = {}
        for name, value in members.items():
            self._names.setdefault(value, name)

    def __call__(self, value: int) -> EnumMember:
        return EnumMember(self._names.get(value, str(value)))

    def __getattr__(self, name: str) -> int:
        try:
            return self._members[name]
        except KeyError:
            raise AttributeError(name) from None


class NativeMujoco:
    """The part of the ``mujoco`` module the compiled-model reader uses."""

    def __init__(self, lib: Library) -> None:
        self._lib = lib
        self._enums: dict[str, CEnum] = {}

    def __getattr__(self, name: str) -> CEnum:
        members = self._lib.headers.enums.get(name)
        if members is None:
            raise AttributeError(name)
        return self._enums.setdefault(name, CEnum(members))

    def mj_id2name(self, model: NativeModel, kind: int, index: int) -> str | None:
        name = self._lib.dll.mj_id2name(model.address, kind, index)
        return name.decode("utf-8", "replace") if name is not None else None


class NativeModel:
    """An ``mjModel`` read like the bindings' ``MjModel``: sizes as ints, arrays as tuples (rows of
    an n×k array are k-tuples; an n×1 array gives scalars). Valid until the model is deleted."""

    def __init__(self, lib: Library, address: int) -> None:
        self.address = address
        self._headers = lib.headers

    def __getattr__(self, name: str) -> Any:
        headers = self._headers
        shape = headers.model_arrays.get(name)
        if shape is None:
            value = self._scalar(name)
        else:
            rows = self._count(shape.rows)
            columns = self._count(shape.columns)
            start = ctypes.c_void_p.from_address(self.address + self._offset(name)).value
            flat = (shape.element * (rows * columns)).from_address(start)[:] if rows * columns else []
            if columns == 1 and not self._is_model_size(shape.columns):
                value = tuple(flat)
            else:
                value = tuple(tuple(flat[r * columns : (r + 1) * columns]) for r in range(rows))
        self.__dict__[name] = value
        return value

    def _is_model_size(self, token: str) -> bool:
        """True when ``token`` is a count of the model (``nq``...), not a fixed width: an ``nkey × nq``
        array stays a tuple of rows even when this model's ``nq`` is 1."""
        headers = self._headers
        return not token.isdigit() and token not in headers.constants and token not in headers.enum_values

    def _offset(self, name: str) -> int:
        return int(getattr(self._headers.structs["mjModel"], name).offset)

    def _scalar(self, name: str) -> Any:
        kind = self._headers.model_fields.get(name)
        if kind is None or kind is ctypes.c_void_p or not hasattr(kind, "from_address"):
            raise AttributeError(name)
        return kind.from_address(self.address + self._offset(name)).value

    def _count(self, token: str) -> int:
        if token.isdigit():
            return int(token)
        constant = self._headers.constants.get(token)
        if constant is None:
            constant = self._headers.enum_values.get(token)
        return int(constant) if constant is not None else int(getattr(self, token))


@dataclass(frozen=True)
class NativeMesh:
    file: str


@dataclass(frozen=True)
class NativeSpec:
    """The part of ``MjSpec`` the compiled-model reader uses: mesh files and ``meshdir``."""

    meshes: list[NativeMesh]
    meshdir: str


@dataclass(frozen=True)
class Compiled:
    """A compiled model and what came with it."""

    mj: NativeMujoco
    model: NativeModel
    spec: NativeSpec
    warnings: list[str]


@contextmanager
def compiled(path: Path) -> Iterator[Compiled | None]:
    """Parse and compile ``path`` with MuJoCo's C library; ``None`` when the bindings must do it.

    The model and spec are freed when the block ends: read everything inside it.
    """
    lib = library()
    if lib is None:
        yield None
        return
    dll = lib.dll
    with _collected_warnings(dll) as warnings:
        error = ctypes.create_string_buffer(ERROR_SIZE)
        spec = dll.mj_parseXML(os.fsencode(path), None, error, ERROR_SIZE)
        model = None
        try:
            if spec:
                _set_compiler_flags(lib, spec)
                model = dll.mj_compile(spec, None)
            if not model:
                yield None
                return
            yield Compiled(NativeMujoco(lib), NativeModel(lib, model), _spec_view(lib, spec), warnings)
        finally:
            if model:
                dll.mj_deleteModel(model)
            if spec:
                dll.mj_deleteSpec(spec)


def _set_compiler_flags(lib: Library, spec: int) -> None:
    for flag, value in COMPILER_FLAGS.items():
        if flag in lib.fields:
            offset, kind = lib.fields[flag]
            kind.from_address(spec + offset).value = value


def _spec_view(lib: Library, spec: int) -> NativeSpec:
    dll, headers = lib.dll, lib.headers
    meshdir_at, file_at = lib.fields["meshdir"][0], lib.fields["mesh_file"][0]
    mesh_kind = headers.enums["mjtObj"]["mjOBJ_MESH"]
    meshes = []
    element = dll.mjs_firstElement(spec, mesh_kind)
    while element:
        mesh = dll.mjs_asMesh(element)
        meshes.append(NativeMesh(_string(dll, ctypes.c_void_p.from_address(mesh + file_at).value)))
        element = dll.mjs_nextElement(spec, element)
    return NativeSpec(meshes, _string(dll, ctypes.c_void_p.from_address(spec + meshdir_at).value))


def _string(dll: ctypes.CDLL, mj_string: int | None) -> str:
    if not mj_string:
        return ""
    text = dll.mjs_getString(mj_string)
    return text.decode("utf-8", "replace") if text else ""


@contextmanager
def _collected_warnings(dll: ctypes.CDLL) -> Iterator[list[str]]:
    """MuJoCo's warnings collected instead of written to ``MUJOCO_LOG.TXT`` (as :mod:`.quiet` does
    through the bindings); the previous handlers are restored afterwards.

    A fatal MuJoCo error outside the compiler (which catches its own) would, by MuJoCo's default,
    write ``MUJOCO_LOG.TXT`` and wait for Enter on the console: here it ends the command with exit
    code 2 and the message instead. A handler cannot unwind into C, so there is no way back.
    """
    messages: list[str] = []

    def collect(message: bytes | None) -> None:
        messages.append(_text(message))

    def fatal(message: bytes | None) -> None:  # pragma: no cover - never reached by a test model
        sys.stderr.write(f"modelkit: MuJoCo stopped with a fatal error: {_text(message)}\n")
        sys.stderr.flush()
        os._exit(2)

    handlers = {"mju_user_warning": MESSAGE_HANDLER(collect), "mju_user_error": MESSAGE_HANDLER(fatal)}
    slots = {name: ctypes.c_void_p.in_dll(dll, name) for name in handlers}
    previous = {name: slot.value for name, slot in slots.items()}
    for name, slot in slots.items():
        slot.value = ctypes.cast(handlers[name], ctypes.c_void_p).value
    try:
        yield messages
    finally:
        for name, slot in slots.items():
            slot.value = previous[name]


def _text(message: bytes | None) -> str:
    return (message or b"").decode("utf-8", "replace").strip()
