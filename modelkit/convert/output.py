"""The output folder: every file of a conversion staged first, then written atomically.

Rules (the issue's "nothing is lost"): nothing is written outside the output folder, no input is
ever overwritten, an existing file is replaced only with ``force`` (a mesh with the same bytes is
simply kept), each file is written to a temporary name in its folder and renamed into place, and
when any file fails nothing of the conversion is left behind.
"""

from __future__ import annotations

import hashlib
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

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
    """Files to write under ``folder``; ``inputs`` are the files the conversion read."""

    folder: Path
    inputs: set[Path] = field(default_factory=set)
    force: bool = False
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

    def problems(self) -> list[Diagnostic]:
        """Why the plan must not be written (checked before anything touches the disk)."""
        found: list[Diagnostic] = []
        root = self.folder.resolve()
        inputs = {p.resolve() for p in self.inputs}
        for staged in self.files.values():
            target = (root / staged.relpath).resolve()
            where = SourceLocation(str(self.folder / staged.relpath))
            if root != target and root not in target.parents:
                found.append(diag("MK892", f"{staged.relpath} would be written outside {self.folder}", where))
            elif target in inputs:
                found.append(diag("MK891", f"{target} is an input of this conversion; it is not overwritten",
                                  where))
            elif target.is_symlink() or (target.exists() and not target.is_file()):
                found.append(diag("MK892", f"{target} exists and is not a regular file", where))
            elif target.exists() and not self.force:
                if staged.what != "model" and target.read_bytes() == staged.data:
                    continue
                found.append(diag("MK890", f"{target} exists; use --force to replace it", where))
        return found

    def commit(self) -> None:
        """Write every staged file: all to temporary names first, then all renamed into place.

        Raises OSError after removing every temporary file when any write fails.
        """
        temps: list[tuple[Path, Path]] = []
        try:
            for relpath in sorted(self.files):
                staged = self.files[relpath]
                target = self.folder / relpath
                target.parent.mkdir(parents=True, exist_ok=True)
                fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name[:100]}.", suffix=".tmp",
                                                  dir=target.parent)  # a 245-byte name stays writable
                temps.append((Path(tmp_name), target))
                with os.fdopen(fd, "wb") as out:
                    out.write(staged.data)
                os.chmod(tmp_name, 0o644)
            for tmp, target in temps:
                os.replace(tmp, target)
        except OSError:
            for tmp, _ in temps:
                tmp.unlink(missing_ok=True)
            raise
