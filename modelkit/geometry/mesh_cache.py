"""A mesh check's outcome kept on disk between runs, so that validating an unchanged robot again (the
pre-commit hook, CI on the next commit) does not parse its meshes again.

Parsing is what a real robot's validation spends its time on: example-robot-data's B1 with its Z1
arm holds 50 MB of COLLADA text, 1.7 s of the 2.4 s ``validate`` takes on the 2-core VM. An entry
holds what :func:`modelkit.geometry.meshfiles.mesh_problem` learns from a file: the outcome (None,
or "CODE\\tmessage") and the corners of its triangles (the rules' mesh extent). It is keyed, as the
in-process cache is, by the resolved path, modification time (ns), size, the fragment, the size limit
and the file's name as given (its suffix picks the parser), and also by modelkit's version,
:data:`SCHEMA` and the modification times of the mesh-checking modules (meshfiles, dae_sources,
objcheck, glbcheck, vrml): a changed mesh file, a new modelkit or an edited checker never reads an old
outcome.

Who: the ``validate`` command (and the pre-commit hook, which runs it) turns it on with :func:`enable`;
``convert``, ``verify``, ``tree`` and the library write nothing outside their outputs (they parse a
mesh they write or simulate anyway).

Where: ``$MODELKIT_CACHE_DIR`` if set (``off`` turns the cache off), else ``$XDG_CACHE_HOME/modelkit``
or ``~/.cache/modelkit``; one small JSON file per mesh under ``meshes/``, written atomically. The
folder may be deleted at any time. Any failure to read or write it (read-only home, a damaged entry)
is the same as no entry: the mesh is checked as if the cache did not exist.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any

SCHEMA = 1  # raise when what an entry means changes
OFF = "off"
_enabled = False


def enable() -> None:
    """Use the cache in this process (the ``validate`` command does)."""
    global _enabled
    _enabled = True

Corners = tuple[tuple[float, float, float], tuple[float, float, float]]


def folder() -> Path | None:
    """The cache's folder, or None when the cache is off (not enabled, or ``MODELKIT_CACHE_DIR=off``)."""
    if not _enabled:
        return None
    given = os.environ.get("MODELKIT_CACHE_DIR")
    if given is not None:
        return None if given.strip().lower() in (OFF, "") else Path(given) / "meshes"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "modelkit" / "meshes"


def _checker_stamp() -> str:
    """The schema, modelkit's version and the modification times of the modules a mesh check runs."""
    from modelkit import __version__
    from modelkit.geometry import dae_sources, glbcheck, meshfiles, objcheck, vrml

    stamps = []
    for module in (meshfiles, dae_sources, objcheck, glbcheck, vrml):
        try:
            stamps.append(str(os.stat(str(module.__file__)).st_mtime_ns))
        except (OSError, TypeError):
            stamps.append("0")
    return f"{SCHEMA}|{__version__}|{','.join(stamps)}"


def _entry(key: tuple[Any, ...]) -> Path | None:
    where = folder()
    if where is None:
        return None
    digest = hashlib.sha256(f"{_checker_stamp()}|{key!r}".encode()).hexdigest()
    return where / digest[:2] / f"{digest}.json"


def lookup(key: tuple[Any, ...]) -> tuple[bool, str | None, Corners | None]:
    """(found, outcome, corners) for ``key``; found False when there is no usable entry."""
    path = _entry(key)
    if path is None:
        return False, None, None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get("key") != repr(key):
            return False, None, None
        outcome = data["outcome"]
        corners = data.get("corners")
        if outcome is not None and not isinstance(outcome, str):
            return False, None, None
        kept = None
        if corners is not None:
            low, high = ([float(v) for v in corner] for corner in corners)
            if len(low) != 3 or len(high) != 3:
                return False, None, None
            kept = ((low[0], low[1], low[2]), (high[0], high[1], high[2]))
        return True, outcome, kept
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        return False, None, None


def store(key: tuple[Any, ...], outcome: str | None, corners: Corners | None) -> None:
    """Keep ``outcome`` and ``corners`` for ``key`` (silently nothing when the folder is not writable)."""
    path = _entry(key)
    if path is None:
        return
    text = json.dumps({"key": repr(key), "outcome": outcome, "corners": corners})
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=".", suffix=".tmp")
        try:
            with os.fdopen(handle, "w", encoding="utf-8") as out:
                out.write(text)
            os.replace(temporary, path)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise
    except OSError:
        return
