"""The files MuJoCo opens by itself (meshes, height fields, textures, skins), checked first.

MuJoCo reads asset files with a plain ``open``: a FIFO would block it forever and a device or a
huge file would be read without bound. Every asset file that exists is therefore checked to be a
regular file within the size limit (:func:`modelkit.textio.check_regular`) before MuJoCo sees
the model; a file that does not exist is left to MuJoCo, which reports it.
"""

from __future__ import annotations

import os
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink
from modelkit.formats.mjcf.source import Placed, SourceIndex
from modelkit.textio import UnreadableFile, check_regular

# Asset element → its file attributes and the <compiler> folder its relative paths start from.
_ASSETS: dict[str, tuple[tuple[str, ...], str]] = {
    "mesh": (("file",), "meshdir"),
    "skin": (("file",), "meshdir"),
    "hfield": (("file",), "meshdir"),
    "texture": (
        ("file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"),
        "texturedir",
    ),
    "model": (("file",), "assetdir"),
}


def check_asset_files(index: SourceIndex, model_dir: Path, sink: DiagnosticSink, max_bytes: int) -> bool:
    """Report each asset file that exists but must not be opened (MK001, MK002); True when all are
    safe for MuJoCo to open."""
    placed = list(index.iter_all())
    folders: dict[str, str] = {}
    for item in placed:
        if item.tag == "compiler":
            for name in ("meshdir", "texturedir", "assetdir"):
                value = item.el.get(name)
                if value is not None:
                    folders[name] = value
    safe = True
    for item in placed:
        spec = _ASSETS.get(item.tag)
        if spec is None:
            continue
        attributes, folder = spec
        for attribute in attributes:
            written = item.el.get(attribute)
            if not written:
                continue
            for candidate in _candidates(model_dir, written, folders, folder):
                if not os.path.lexists(candidate):  # a file or a symbolic link; False for a name too long
                    continue
                try:
                    check_regular(candidate, max_bytes)
                except UnreadableFile as exc:
                    sink.emit(exc.code, f'{attribute} "{written}": {exc.message}', item.loc(attribute))
                    safe = False
                break
    return safe


def _candidates(model_dir: Path, written: str, folders: dict[str, str], folder: str) -> list[Path]:
    path = Path(written)
    if path.is_absolute():
        return [path]
    out = []
    for name in (folder, "assetdir"):
        base = Path(folders.get(name, ""))
        out.append((base if base.is_absolute() else model_dir / base) / path)
    out.append(model_dir / path)
    return out


# Height-field cells MuJoCo may allocate (4096 × 4096 floats, 64 MB).
MAX_HFIELD_CELLS = 4096 * 4096


def check_sizes(index: SourceIndex, sink: DiagnosticSink, max_links: int) -> bool:
    """Bodies (with ``<replicate count>`` and ``<flexcomp>``/``<composite>`` counts multiplied out)
    and height-field grids, checked before MuJoCo builds them (MK005); True when within bounds."""
    bodies = 0
    top = index.top()
    stack: list[tuple[Placed, int]] = [(top, 1)]
    while stack:
        item, factor = stack.pop()
        if item.tag == "body":
            bodies += factor
        elif item.tag in ("flexcomp", "composite"):
            bodies += factor * _product(item.el.get("count"))
        elif item.tag == "replicate":
            factor *= max(_product(item.el.get("count")), 1)
        elif item.tag == "size" and not _size_within(item, sink):
            return False
        elif item.tag == "hfield":
            cells = _product(item.el.get("nrow")) * _product(item.el.get("ncol"))
            if cells > MAX_HFIELD_CELLS:
                sink.emit(
                    "MK005",
                    f"the height field has {cells} cells, over the limit of {MAX_HFIELD_CELLS}",
                    item.loc("nrow"),
                )
                return False
        if bodies > max_links:
            sink.emit(
                "MK005",
                f"the model has more than {max_links} bodies (counting <replicate> copies), over the "
                "limit; it is not read further",
                item.loc("count") if item.tag in ("replicate", "flexcomp", "composite") else item.loc(),
                hint="raise the limit with --max-links if the model is genuine",
            )
            return False
        stack.extend((child, factor) for child in index.children(item))
    return True


# Caps on <size> counts MuJoCo builds or allocates one by one, at compile time (measured: nkey="1000000"
# runs for minutes, nuserdata="1000000000" takes 4.6 GB). Real models use a handful of keyframes.
SIZE_CAPS: dict[str, int] = {"nkey": 10_000, "nuserdata": 10_000_000}
NUSER_CAP = 1_000  # every nuser_* count: that many numbers on each element of its kind


def _size_within(item: Placed, sink: DiagnosticSink) -> bool:
    """Report the first ``<size>`` count over its cap (MK007); True when all are within."""
    for attribute in item.el.attrib:
        name = str(attribute)
        text = item.el.get(name) or ""
        cap = SIZE_CAPS.get(name, NUSER_CAP if name.startswith("nuser_") else None)
        if cap is None:
            continue
        value = _product(text)
        if value > cap:
            sink.emit(
                "MK007",
                f"<size {name}> is {text.strip()}, over the limit of {cap}; MuJoCo would build every one, "
                "so the model is not compiled",
                item.loc(name),
            )
            return False
    return True


def _product(text: str | None) -> int:
    """The product of the integers written in ``text`` (1 when there are none, 0 for junk)."""
    out = 1
    for word in (text or "").split():
        try:
            value = int(float(word))
        except (ValueError, OverflowError):
            return 0
        out *= max(value, 0)
        if out > 1 << 62:  # already absurd; keep the number small
            return 1 << 62
    return out
