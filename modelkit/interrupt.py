"""Ctrl-C, SIGTERM and SIGHUP as one exception, so that ``convert`` and ``verify`` undo what they
wrote and end with one line and the shell's exit code (128 + the signal: 130, 143, 129).

:class:`Interrupted` derives from ``BaseException``: the ``except Exception`` of code that turns
failures into findings lets it through, and every ``finally`` on the way runs (the staged commit's
undo, the verify workers' ends).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

SIGNALS = tuple(s for s in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", None)) if s is not None)


class Interrupted(BaseException):
    """A signal asked the command to stop."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        self.name = signal.Signals(signum).name
        super().__init__(f"stopped by {self.name}")

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


_received: list[int] = []
_held = [0]  # depth of signals_held blocks
_deferred: list[int] = []  # signals whose handler ran inside one


def _raise(signum: int, _frame: FrameType | None) -> None:
    _received.append(signum)
    if _held[0]:  # the signal came just before the block: Python runs the handler inside it
        _deferred.append(signum)
        return
    raise Interrupted(signum)


def pending() -> int | None:
    """The first signal received within :func:`interruptible`, if any. The exception a signal
    raises can be swallowed by code it lands in (a C++ extension's module initialisation logs and
    ignores it, a library's bare ``except``); the signal is remembered all the same."""
    return _received[0] if _received else None


def check() -> None:
    """Raise :class:`Interrupted` again if a signal was received (see :func:`pending`): called
    before each step that must not start once the user asked to stop (a commit, a report)."""
    signum = pending()
    if signum is not None:
        raise Interrupted(signum)


@contextmanager
def signals_held(deliver: bool = True) -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP back while the block runs; they are delivered when it ends.
    For a step that must not be cut in two (a file moved and its record), and for imports of
    libraries that would swallow the exception (a C++ module's initialisation) or start child
    processes of their own (which inherit the held mask and so never see a Ctrl-C meant for the
    parent).

    Two levels: the signals are blocked in the kernel (children started inside inherit that), and
    a signal that arrived just before the block, whose Python handler only runs inside it, is
    deferred by the handler itself; either is raised as :class:`Interrupted` when the outermost
    block ends (``deliver`` False: dropped, for the clean-up after an interruption). Only the main
    thread can block them in the kernel; elsewhere only the deferral applies."""
    try:
        old: set[int | signal.Signals] | None = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    except (AttributeError, ValueError, OSError):
        old = None
    _held[0] += 1
    try:
        yield
    finally:
        try:
            if old is not None:
                signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a blocked signal's handler runs now
        finally:
            _held[0] -= 1
        if not _held[0] and _deferred:
            signum = _deferred[0]
            _deferred.clear()
            if deliver:
                raise Interrupted(signum)


@contextmanager
def interruptible() -> Iterator[None]:
    """Within the block, SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` (main thread only;
    elsewhere the block runs as it is). The previous handlers come back afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received.clear()
    previous = {s: signal.signal(s, _raise) for s in SIGNALS}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        _received.clear()  # outside the block nothing is pending
        _deferred.clear()
