"""The output folder: every file of a conversion staged first, then written atomically.

Rules (the issue's "nothing is lost"): nothing is written outside the output folder, no input is
ever overwritten (judged by device and inode, so a hard link or another spelling of an input is
refused too), an existing file is replaced only with ``force`` (a mesh with the same bytes is
simply kept), and the files are written as one staged commit (:mod:`modelkit.convert.commit`):
when any file fails nothing of the conversion is left behind.
"""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from modelkit.convert.commit import Entry, commit, identity
from modelkit.diagnostics import Diagnostic, SourceLocation, diag

_SAFE = re.compile(r"[^A-Za-z0-9._-]+")


def safe_file_name(name: str, default: str = "file") -> str:
    """A file name that cannot leave its folder: no separators, no leading dots, ASCII only."""
    cleaned = _SAFE.sub("_", Path(name.replace("\\", "/")).name).strip("._")
    return cleaned[:120] or default


@dataclass
class StagedFile:
    relpath: str  # POSIX path relative to the output folder
    data: bytes
    what: str  # "model" | "mesh" | "texture" | "report"


@dataclass
class OutputPlan:
    """Files to write under ``folder``; ``inputs`` are the files the conversion read (paths) and
    ``opened`` the identities (device, inode) of every file its readers opened."""

    folder: Path
    inputs: set[Path] = field(default_factory=set)
    force: bool = False
    opened: set[tuple[int, int]] = field(default_factory=set)
    files: dict[str, StagedFile] = field(default_factory=dict)
    _by_digest: dict[tuple[str, str], str] = field(default_factory=dict)

    def add(self, relpath: str, data: bytes, what: str) -> str:
        """Stage ``data`` at ``relpath``; an identical file already staged is shared, a different
        one with the same name gets a numbered name (``mesh_2.stl``). Returns the path used."""
        folder, _, name = relpath.rpartition("/")
        digest = hashlib.sha256(data).hexdigest()
        known = self._by_digest.get((folder, digest))
        if known is not None and what != "model":
            return known
        stem, dot, ext = name.rpartition(".")
        if not dot:
            stem, ext = name, ""
        candidate, n = relpath, 1
        while candidate in self.files and self.files[candidate].data != data:
            n += 1
            candidate = (f"{folder}/" if folder else "") + f"{stem}_{n}" + (f".{ext}" if ext else "")
        self.files[candidate] = StagedFile(candidate, data, what)
        self._by_digest.setdefault((folder, digest), candidate)
        return candidate

    def protect(self, path: Path) -> None:
        """Count ``path`` among the inputs: a writer read it (a texture, a mesh it copies)."""
        ident = identity(path)
        if ident is not None:
            self.opened.add(ident)

    def protected(self) -> set[tuple[int, int]]:
        """The identities (device, inode) no output may replace: every input file and every file the
        readers opened (``protect``)."""
        found = set(self.opened)
        for path in self.inputs:
            ident = identity(path)
            if ident is not None:
                found.add(ident)
        return found

    def entries(self) -> list[Entry]:
        return [Entry(self.folder, s.relpath, s.data, s.what) for s in self.files.values()]

    def problems(self) -> list[Diagnostic]:
        """Why the plan must not be written (checked before anything touches the disk)."""
        found: list[Diagnostic] = []
        root = self.folder.resolve()
        protected = self.protected()
        for staged in self.files.values():
            target = (root / staged.relpath).resolve()
            where = SourceLocation(str(self.folder / staged.relpath))
            if root != target and root not in target.parents:
                found.append(diag("MK892", f"{staged.relpath} would be written outside {self.folder}", where))
                continue
            problem = target_problem(self.folder / staged.relpath, staged.data, staged.what, self.force,
                                     protected)
            if problem is not None:
                found.append(problem)
        return found

    def commit(self, extra: list[Entry] | None = None) -> None:
        """Write every staged file (and ``extra``, a report elsewhere) as one staged commit
        (:mod:`modelkit.convert.commit`); raises ``CommitRefused`` or ``OSError`` with nothing
        left behind."""
        commit(self.entries() + list(extra or ()), self.force, self.protected())


def target_problem(path: Path, data: bytes, what: str, force: bool,
                   protected: set[tuple[int, int]]) -> Diagnostic | None:
    """Why ``path`` must not be written with ``data``: an input (by identity), a symlink or special
    file, or an existing file without ``force`` (a mesh with the same bytes is simply kept)."""
    where = SourceLocation(str(path))
    ident = identity(path)
    if ident is not None and ident in protected:
        return diag("MK891", f"{path} is an input of this conversion; it is not overwritten", where)
    # os.path's tests, not pathlib's: they are False for a name too long to look up (ENAMETOOLONG),
    # which the commit then reports as a write that failed (MK894)
    if os.path.islink(path) or (os.path.exists(path) and not os.path.isfile(path)):
        return diag("MK892", f"{path} exists and is not a regular file", where)
    if os.path.exists(path) and not force:
        if what in ("mesh", "texture") and path.read_bytes() == data:
            return None
        return diag("MK890", f"{path} exists; use --force to replace it", where)
    return None
