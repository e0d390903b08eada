"""Reading input files with the checks every input gets (exists, size, text encoding).

Shared by the YAML and XML readers; it imports neither PyYAML nor lxml.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation

# The expanded node count above which a document is treated as an alias bomb. Real Choreonoid
# models stay far below it (the largest sample terrains have a few hundred thousand scalars).
DEFAULT_EXPANSION_LIMIT = 5_000_000
DEFAULT_MAX_BYTES = 64 * 1024 * 1024
# Items in one YAML list (numbers of a mesh, a terrain): each costs about 40 µs and 1 KB to compose
# and check, so this keeps a .body file within about 10 s and 300 MB.
DEFAULT_MAX_LIST_ITEMS = 250_000
# Links (and joints) in one model: a .body link costs about 1 ms to read and check.
DEFAULT_MAX_LINKS = 10_000


class UnreadableFile(Exception):
    """A file that must not or cannot be read: ``code`` is MK001 (missing, not a regular file,
    unreadable) or MK002 (over the size limit); ``message`` says which."""

    def __init__(self, code: str, message: str, hint: str | None = None) -> None:
        super().__init__(message)
        self.code = code
        self.message = message
        self.hint = hint
        self.path = ""  # set by callers that report it away from the file itself


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


@dataclass(frozen=True)
class OpenedFile:
    """A file a reader opened: its path as opened and its identity (device, inode), which names the
    file whatever the spelling of its path (``..``, symlinks, hard links)."""

    path: str
    dev: int
    ino: int

    @property
    def identity(self) -> tuple[int, int]:
        return (self.dev, self.ino)


_RECORD: ContextVar[list[OpenedFile] | None] = ContextVar("modelkit_opened_files", default=None)


@contextmanager
def recording() -> Iterator[list[OpenedFile]]:
    """Record every regular file opened through this module while the block runs (model files,
    includes, xacro includes, ``$(find)`` and ``load_yaml`` files, resources, materials, meshes,
    asset files checked for MuJoCo): the list yielded fills as they are opened. Nested blocks each
    get their own list and also report to the outer one."""
    outer = _RECORD.get()
    mine: list[OpenedFile] = []
    token = _RECORD.set(mine)
    try:
        yield mine
    finally:
        _RECORD.reset(token)
        if outer is not None:
            outer.extend(mine)


def _open_regular(path: Path | str) -> tuple[int, os.stat_result]:
    """An open descriptor on ``path`` and its ``fstat``, once it is known to be a regular file.

    ``O_NONBLOCK`` keeps the open of a FIFO from waiting for a writer; the type is judged on the
    open descriptor, so a file swapped after a ``stat`` of its name cannot slip through."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise UnreadableFile("MK001", f"cannot read file: {exc.strerror or exc}") from exc
    try:
        info = os.fstat(fd)
    except OSError as exc:
        os.close(fd)
        raise UnreadableFile("MK001", f"cannot read file: {exc.strerror or exc}") from exc
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        kind = next((name for test, name in _KINDS if test(info.st_mode)), "a special file")
        raise UnreadableFile("MK001", f"cannot read file: it is {kind}, not a regular file")
    record = _RECORD.get()
    if record is not None:
        record.append(OpenedFile(os.fspath(path), info.st_dev, info.st_ino))
    return fd, info


def _too_large(size: int | str, max_bytes: int) -> UnreadableFile:
    return UnreadableFile(
        "MK002",
        f"file is {size} bytes, over the limit of {max_bytes} bytes",
        hint="raise the limit with --max-bytes if the file is genuine",
    )


def real_path(path: Path | str) -> Path:
    """``path`` with symlinks resolved, as far as they resolve: unlike ``Path.resolve`` on Python
    3.11, a symlink loop gives a path (that later fails to open) rather than a RuntimeError."""
    return Path(os.path.realpath(path))


def read_regular(path: Path | str, max_bytes: int = DEFAULT_MAX_BYTES) -> bytes:
    """The bytes of the regular file ``path``, read once with a bound: the one way modelkit reads
    an input file (model, include, mesh, texture, resource).

    Raises :class:`UnreadableFile` for a missing file, a directory, a FIFO, a device, a socket, a
    symlink loop (MK001) and a file over ``max_bytes`` (MK002, judged by ``fstat`` and again
    while reading, so a file that grows or lies about its size is stopped at the limit)."""
    fd, info = _open_regular(path)
    try:
        if info.st_size > max_bytes:
            raise _too_large(info.st_size, max_bytes)
        chunks: list[bytes] = []
        total = 0
        while True:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:
                raise _too_large(f"more than {max_bytes}", max_bytes)
        return b"".join(chunks)
    except OSError as exc:
        raise UnreadableFile("MK001", f"cannot read file: {exc.strerror or exc}") from exc
    finally:
        os.close(fd)


def read_head(path: Path | str, limit: int) -> bytes | None:
    """At most the first ``limit`` bytes of a regular file (to sniff its kind); None for anything
    else (missing, special, unreadable)."""
    try:
        fd, _ = _open_regular(path)
    except UnreadableFile:
        return None
    try:
        return os.read(fd, limit)
    except OSError:
        return None
    finally:
        os.close(fd)


def check_regular(path: Path | str, max_bytes: int = DEFAULT_MAX_BYTES) -> None:
    """Raise :class:`UnreadableFile` unless ``path`` is a regular file within ``max_bytes``; for
    files that another library (MuJoCo) will open itself."""
    fd, info = _open_regular(path)
    os.close(fd)
    if info.st_size > max_bytes:
        raise _too_large(info.st_size, max_bytes)


def read_bytes(path: Path, sink: DiagnosticSink, max_bytes: int, display: str) -> bytes | None:
    """The bytes of ``path`` (:func:`read_regular`); a file that cannot be read is reported (MK001,
    MK002) at ``display`` and gives None."""
    try:
        return read_regular(path, max_bytes)
    except UnreadableFile as exc:
        sink.emit(exc.code, exc.message, SourceLocation(display), hint=exc.hint)
        return None


def decode_text(data: bytes, name: str, sink: DiagnosticSink) -> str | None:
    """``data`` as text (UTF-8, with or without a BOM, or UTF-16 with a BOM); binary data and
    invalid encodings are reported (MK003) and give None."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            sink.emit(
                "MK003", "the file starts with a UTF-16 mark but is not valid UTF-16", SourceLocation(name)
            )
            return None
    if b"\x00" in data:
        offset = data.index(b"\x00")
        line = data.count(b"\n", 0, offset) + 1
        sink.emit(
            "MK003", "the file contains NUL bytes: it is binary, not text", SourceLocation(name, line, 1)
        )
        return None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        sink.emit(
            "MK003",
            f"the file is not valid UTF-8 (byte 0x{data[exc.start]:02x})",
            SourceLocation(name, line, col),
        )
        return None
    return text
