"""Reading any model file: its format detected from the declarations (:mod:`modelkit.formats.registry`),
and that format's reader.

Readers are imported lazily so that `validate` and `tree` load only what the input needs (mujoco
only for MJCF input, which it reads).
"""

from __future__ import annotations

import gc
import importlib
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.declaration import FormatDeclaration
from modelkit.formats.registry import DECLARED
from modelkit.textio import OpenedFile, UnreadableFile, check_regular, recording

FORMATS: tuple[FormatDeclaration, ...] = DECLARED
"""Every format's declaration (:mod:`modelkit.formats.registry`), in the order detection tries them."""


def detect_format(path: Path, explicit: str | None = None) -> str | None:
    """The format of ``path``: by extension, else by its top XML element (``.xml`` files)."""
    if explicit:
        return explicit
    name = path.name.lower()
    for info in FORMATS:
        if any(name.endswith(s) for s in info.suffixes):
            return info.name
    from modelkit.xmlsource import sniff_root_tag

    tag = sniff_root_tag(path)
    for info in FORMATS:
        if tag is not None and tag in info.root_tags:
            return info.name
    return None


def read_model(
    path: Path, options: ReadOptions | None = None, fmt: str | None = None, display: str | None = None
) -> ReadResult:
    """Read any supported model file; an unknown format is a diagnostic, not an exception.

    ``ReadResult.opened`` lists every regular file the read opened (see :func:`modelkit.textio.recording`)."""
    with recording() as opened:
        result = _read_model(path, options, fmt, display)
        if options is not None and options.srdf is not None and result.robot is not None:
            from modelkit.diagnostics import DiagnosticSink
            from modelkit.formats.srdf import apply_srdf

            sink = DiagnosticSink()
            apply_srdf(result.robot, options.srdf, options.home, sink, options.max_bytes)
            result.diagnostics.extend(sink.items)
    result.opened = _unique(opened)
    return result


def _unique(opened: list[OpenedFile]) -> list[OpenedFile]:
    seen: set[tuple[int, int]] = set()
    out = []
    for item in opened:
        if item.identity not in seen:
            seen.add(item.identity)
            out.append(item)
    return out


def _read_model(path: Path, options: ReadOptions | None, fmt: str | None, display: str | None) -> ReadResult:
    shown = display or str(path)
    sink = DiagnosticSink()
    try:  # before any reader (or MuJoCo) opens it: only a regular file within the size limit
        check_regular(path, (options or ReadOptions()).max_bytes)
    except UnreadableFile as exc:
        sink.emit(exc.code, exc.message, SourceLocation(shown), hint=exc.hint)
        return ReadResult(None, sink.items)
    kind = detect_format(path, fmt)
    for info in FORMATS:
        if info.name == kind:
            module_name, _, function = info.reader.partition(":")
            reader = getattr(importlib.import_module(module_name), function)
            # Reading builds a large, acyclic object graph (parser nodes, then the model): the cyclic
            # garbage collector's passes over it free nothing and cost a third of the time of a big file.
            collecting = gc.isenabled()
            gc.disable()
            try:
                result: ReadResult = reader(path, options or ReadOptions(), shown)
            finally:
                if collecting:
                    gc.enable()
            return result
    from modelkit.xmlsource import sniff_root_tag

    fragment = FRAGMENT_TAGS.get(str(sniff_root_tag(path))) if fmt is None else None
    if fragment is not None:
        sink.emit("MK001", f"this file is {fragment}, not a model: it is read as part of the model that "
                  "includes it; give that model's file instead", SourceLocation(shown))
        return ReadResult(None, sink.items)
    known = ", ".join(s for info in FORMATS for s in info.suffixes)
    tags = [f"<{tag}>" for info in FORMATS for tag in info.root_tags]
    message = f"cannot tell the format of this file (supported: {known}, or .xml with a "
    message += f"{', '.join(tags[:-1])} or {tags[-1]} top element); use --input-format"
    sink.emit("MK001", message, SourceLocation(shown))
    return ReadResult(None, sink.items)


FRAGMENT_TAGS = {
    "mujocoinclude": "an MJCF include fragment (<mujocoinclude>, the body of an <include file=...>)",
}
"""Top elements of files that are pieces of a model, each with what it is (said instead of "cannot tell
the format": gymnasium-robotics' adroit_model.xml is one)."""
