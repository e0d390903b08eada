"""Writing verify's report files inside its output folder and nowhere else.

``verify -o OUT`` writes ``report.json``, ``report.html``, ``pictures/``, ``plots/`` and (many models)
``summary.json``/``summary.html`` and one folder per model. A symlink planted at any of those names
(or at a folder on the way) would have sent the bytes elsewhere: every path is therefore checked
component by component below ``OUT`` and refused (:class:`UnsafeOutput`, shown as MK892, exit 2)
when one is a symlink or not what it must be. ``OUT`` itself is the user's choice and may be a
symlink. Each file is written to a temporary name in its folder, ``fsync``'d and renamed into
place: a reader never sees half a report, and a failure leaves no temporary file.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path


class UnsafeOutput(Exception):
    """A path under the output folder that must not be written through."""

    def __init__(self, path: Path, message: str) -> None:
        super().__init__(f"{path}: {message}")
        self.path = path
        self.message = message


def _parts(root: Path, path: Path) -> tuple[str, ...]:
    try:
        rel = Path(os.path.normpath(path)).relative_to(os.path.normpath(root))
    except ValueError:
        raise UnsafeOutput(path, f"is outside the output folder {root}; nothing is written there") from None
    if ".." in rel.parts:
        raise UnsafeOutput(path, f"is outside the output folder {root}; nothing is written there")
    return rel.parts


def check(root: Path, path: Path, folder: bool = False) -> None:
    """Raise :class:`UnsafeOutput` unless every existing component of ``path`` below ``root`` is a
    real folder (the last a regular file, or a folder when ``folder``)."""
    parts = _parts(root, path)
    current = Path(root)
    for index, part in enumerate(parts):
        current = current / part
        try:
            info = os.lstat(current)
        except FileNotFoundError:
            return
        last = index == len(parts) - 1
        if stat.S_ISLNK(info.st_mode):
            raise UnsafeOutput(current, "is a symbolic link; verify does not write through links "
                               "(remove it or choose another -o)")
        if (not last or folder) and not stat.S_ISDIR(info.st_mode):
            raise UnsafeOutput(current, "exists and is not a folder")
        if last and not folder and not stat.S_ISREG(info.st_mode):
            raise UnsafeOutput(current, "exists and is not a regular file")


def make_folder(root: Path, folder: Path) -> Path:
    """Create ``folder`` (and the folders to it) below ``root``, refusing links on the way."""
    check(root, folder, folder=True)
    os.makedirs(root, exist_ok=True)
    current = Path(root)
    for part in _parts(root, folder):
        current = current / part
        with contextlib.suppress(FileExistsError):
            os.mkdir(current)
        check(root, current, folder=True)  # a link swapped in meanwhile
    return folder


def write_bytes(root: Path, path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` (below ``root``) atomically: a temporary file in the same folder,
    fsync'd, renamed into place."""
    check(root, path)
    make_folder(root, path.parent)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        os.chmod(tmp, 0o644)
        check(root, path)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


def write_text(root: Path, path: Path, text: str) -> Path:
    return write_bytes(root, path, text.encode("utf-8"))


class Snapshot:
    """What was under a folder before a run, so that an interrupted run can remove what it added
    (files and folders that were not there), and nothing else. Links are not followed."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.existed = self.root.exists() or self.root.is_symlink()
        self.before = self._walk() if self.existed else set()

    def _walk(self) -> set[str]:
        found: set[str] = set()
        for folder, dirs, files in os.walk(self.root, followlinks=False):
            rel = os.path.relpath(folder, self.root)
            for name in [*dirs, *files]:
                found.add(os.path.normpath(os.path.join(rel, name)))
        return found

    def remove_new(self) -> None:
        """Remove every file and folder added under the root since the snapshot (the root too when
        the run created it)."""
        if not (self.root.exists() and self.root.is_dir()):
            return
        added = sorted(self._walk() - self.before, key=lambda p: (-p.count(os.sep), p))
        for rel in added:
            path = self.root / rel
            try:
                if path.is_dir() and not path.is_symlink():
                    os.rmdir(path)  # deepest first: empty once its new files are gone
                else:
                    path.unlink()
            except OSError:
                continue
        if not self.existed:
            with contextlib.suppress(OSError):
                os.rmdir(self.root)
