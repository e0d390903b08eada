"""Reading input files with the checks every input gets (exists, size, text encoding).

Shared by the YAML and XML readers; it imports neither PyYAML nor lxml.
"""

from __future__ import annotations

from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation

# The expanded node count above which a document is treated as an alias bomb. Real Choreonoid
# models stay far below it (the largest sample terrains have a few hundred thousand scalars).
DEFAULT_EXPANSION_LIMIT = 5_000_000
DEFAULT_MAX_BYTES = 64 * 1024 * 1024


def read_bytes(path: Path, sink: DiagnosticSink, max_bytes: int, display: str) -> bytes | None:
    """The bytes of ``path``; a directory, an unreadable file or one over ``max_bytes`` is reported
    (MK001, MK002) at ``display`` and gives None."""
    try:
        if path.is_dir():
            sink.emit("MK001", "cannot read file: it is a directory", SourceLocation(display))
            return None
        size = path.stat().st_size
    except OSError as exc:
        sink.emit("MK001", f"cannot read file: {exc.strerror or exc}", SourceLocation(display))
        return None
    if size > max_bytes:
        sink.emit(
            "MK002",
            f"file is {size} bytes, over the limit of {max_bytes} bytes",
            SourceLocation(display),
            hint="raise the limit with --max-bytes if the file is genuine",
        )
        return None
    try:
        return path.read_bytes()
    except OSError as exc:
        sink.emit("MK001", f"cannot read file: {exc.strerror or exc}", SourceLocation(display))
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
