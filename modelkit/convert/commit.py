"""One staged commit: every file of a conversion written, made durable, then moved into place.

The promise (issue 18 §1): nothing of an input is lost and nothing half-written is left.

* Every file is first written into a staging folder inside its destination folder
  (``.modelkit-staging-<pid>-<random>``) and ``fsync``'d; only then is anything moved into place.
* Files are moved into place in the order meshes (and textures), models, report: a model never
  sits in the folder without the meshes it references, even when the process is killed half way.
* Without ``force`` a file is created exclusively (``os.link`` of the staged file, which fails
  when the name exists): of two conversions racing into one folder one wins and the other is
  refused with nothing of it left. Commits into one folder are also serialised with ``flock`` on
  the folder, so that the loser's undo can never remove a file the winner relies on.
* With ``force`` an existing file is kept aside (a hard link in the staging folder) until the
  whole commit succeeded. A file that is an input of the conversion (by device and inode: hard
  links and other spellings of the same file included) is never replaced.
* Each change (a folder made, a file moved) is recorded as it is made, with SIGINT, SIGTERM and
  SIGHUP held for that one step, so that an interruption always finds the record complete.
* On any failure, and on any signal that reaches Python (Ctrl-C, SIGTERM, SIGHUP through
  :mod:`modelkit.interrupt`), everything already moved is undone, replaced files come back, the
  folders the commit created are removed and the staging folder goes. ``kill -9`` cannot be caught:
  its staging folder is removed by the next commit into the same folder (its pid is dead).
"""

from __future__ import annotations

import errno
import fcntl
import os
import shutil
import stat
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from modelkit.diagnostics import Diagnostic, SourceLocation, diag
from modelkit.interrupt import check, signals_held

STAGING_PREFIX = ".modelkit-staging-"
ORDER = {"mesh": 0, "texture": 0, "model": 1, "report": 2}
_NO_LINK = frozenset({errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK})


@dataclass(frozen=True)
class Entry:
    """One file to write: ``root / relpath`` (``relpath`` POSIX, inside ``root``)."""

    root: Path
    relpath: str
    data: bytes
    what: str  # "mesh" | "texture" | "model" | "report"

    @property
    def target(self) -> Path:
        return self.root / self.relpath


class CommitRefused(Exception):
    """The commit met a file it must not replace (it appeared after the plan was checked, or another
    conversion won the race); nothing of the commit is left."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def identity(path: Path) -> tuple[int, int] | None:
    """(device, inode) of ``path`` (symlinks followed), None when it does not exist."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    return (info.st_dev, info.st_ino)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        return True
    return True


def remove_stale_staging(folder: Path) -> list[Path]:
    """Remove the staging folders in ``folder`` left by commits whose process is dead (killed with
    SIGKILL, power loss); returns those removed."""
    removed: list[Path] = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in sorted(names):
        if not name.startswith(STAGING_PREFIX):
            continue
        pid_text = name[len(STAGING_PREFIX):].split("-", 1)[0]
        if not pid_text.isdigit() or _pid_alive(int(pid_text)):
            continue
        path = folder / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write_new(path: Path, data: bytes) -> None:
    """Create ``path`` exclusively with ``data``, mode 0644, fsync'd."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o644)
    try:
        os.fchmod(fd, 0o644)
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        os.fsync(fd)
    finally:
        os.close(fd)


def _same_bytes(path: Path, data: bytes) -> bool:
    try:
        info = os.lstat(path)
        return stat.S_ISREG(info.st_mode) and info.st_size == len(data) and path.read_bytes() == data
    except OSError:
        return False


class _Commit:
    def __init__(self, entries: Sequence[Entry], force: bool, protected: set[tuple[int, int]]) -> None:
        self.entries = sorted(entries, key=lambda e: (ORDER.get(e.what, 1), str(e.root), e.relpath))
        self.force = force
        self.protected = protected
        self.created_dirs: list[Path] = []
        self.locks: list[int] = []
        self.staging: dict[Path, Path] = {}
        self.staged: list[Path] = []
        self.done: list[tuple[Path, Path | None]] = []  # (target, the replaced file kept aside)

    def _mkdirs(self, folder: Path) -> None:
        missing = []
        probe = folder
        while not os.path.exists(probe) and probe != probe.parent:
            missing.append(probe)
            probe = probe.parent
        for path in reversed(missing):
            try:
                os.mkdir(path)
            except FileExistsError:
                continue
            self.created_dirs.append(path)

    def _lock(self, root: Path) -> None:
        fd = os.open(root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0))
        self.locks.append(fd)
        fcntl.flock(fd, fcntl.LOCK_EX)

    def prepare(self) -> None:
        roots = sorted({e.root for e in self.entries}, key=lambda p: str(p.resolve()))
        for root in roots:
            with signals_held():  # each change is recorded with it, so that the undo knows it
                self._mkdirs(root)
            self._lock(root)  # may wait for another conversion into the folder: Ctrl-C still works
            remove_stale_staging(root)
            with signals_held():
                prefix = f"{STAGING_PREFIX}{os.getpid()}-"
                self.staging[root] = Path(tempfile.mkdtemp(prefix=prefix, dir=root))
        for index, entry in enumerate(self.entries):
            path = self.staging[entry.root] / f"f{index}"
            _write_new(path, entry.data)
            self.staged.append(path)
        for folder in self.staging.values():
            _fsync_dir(folder)

    def _refuse(self, entry: Entry, code: str, message: str) -> CommitRefused:
        return CommitRefused(diag(code, message, SourceLocation(str(entry.target))))

    def _place(self, index: int, entry: Entry) -> None:
        target = entry.target
        staged = self.staged[index]
        self._mkdirs(target.parent)
        for _ in range(3):  # a file appearing or vanishing between the look and the move: look again
            try:
                info = os.lstat(target)
            except FileNotFoundError:
                info = None
            if info is None:
                try:
                    os.link(staged, target)
                except FileExistsError:
                    continue
                except OSError as exc:
                    if exc.errno not in _NO_LINK:
                        raise
                    try:
                        _write_new(target, entry.data)
                    except FileExistsError:
                        continue
                self.done.append((target, None))
                return
            if not stat.S_ISREG(info.st_mode):
                raise self._refuse(entry, "MK892", f"{target} exists and is not a regular file")
            if (info.st_dev, info.st_ino) in self.protected:
                raise self._refuse(entry, "MK891",
                                   f"{target} is an input of this conversion; it is not overwritten")
            if entry.what in ("mesh", "texture") and _same_bytes(target, entry.data):
                return  # the same file is there already (an earlier conversion's mesh): kept
            if not self.force:
                raise self._refuse(entry, "MK890", f"{target} exists; use --force to replace it")
            aside = self.staging[entry.root] / f"old{index}"
            try:
                os.link(target, aside)
            except FileNotFoundError:
                continue
            except OSError as exc:
                if exc.errno not in _NO_LINK:
                    raise
                os.rename(target, aside)
            os.replace(staged, target)
            self.done.append((target, aside))
            return
        raise self._refuse(entry, "MK890",
                           f"{target} keeps changing while it is written; nothing was written")

    def run(self) -> None:
        try:
            check()  # a signal some library swallowed while the files were made: nothing is written
            self.prepare()
            for index, entry in enumerate(self.entries):
                with signals_held():  # a move and its record in ``done`` are one step for a signal
                    self._place(index, entry)
            for folder in sorted({target.parent for target, _ in self.done}):
                _fsync_dir(folder)
        except BaseException:
            with signals_held():
                self.undo()
                self.finish()
                self.remove_created_dirs()
            raise
        with signals_held():
            self.finish()

    def undo(self) -> None:
        for target, aside in reversed(self.done):
            try:
                if aside is not None:
                    os.replace(aside, target)
                else:
                    target.unlink()
            except OSError:
                continue
        self.done = []

    def remove_created_dirs(self) -> None:
        for folder in reversed(self.created_dirs):
            try:
                os.rmdir(folder)
            except OSError:
                continue

    def finish(self) -> None:
        for folder in self.staging.values():
            shutil.rmtree(folder, ignore_errors=True)
        self.staging = {}
        for fd in self.locks:
            os.close(fd)
        self.locks = []


def commit(entries: Sequence[Entry], force: bool = False,
           protected: set[tuple[int, int]] | None = None) -> None:
    """Write ``entries`` as one staged commit (see the module's text). Raises :class:`CommitRefused`
    (a file that must not be replaced) or ``OSError`` (disk full, permissions) after undoing
    everything; any other exception (an interruption) is re-raised after the same undo."""
    if entries:
        _Commit(entries, force, set(protected or ())).run()
