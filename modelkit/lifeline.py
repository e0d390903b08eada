"""Child processes die with their parent.

``verify`` starts worker processes (one per model with ``-j``), and they start children of their
own (PyBullet's worker, the picture and plot renderers). When the parent is killed with SIGKILL
nobody ends them: they ran on and wrote reports into a folder the user thought abandoned. On
Linux each child therefore asks the kernel for SIGKILL when its parent dies
(``prctl(PR_SET_PDEATHSIG, SIGKILL)``), and leaves Ctrl-C to the parent (SIGINT ignored: the
parent ends its children itself and reports one line, not one traceback per process).

Elsewhere (no ``prctl``) these functions only set the signals; the parent's own cleanup remains.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
from collections.abc import Callable
from functools import cache

PR_SET_PDEATHSIG = 1


@cache
def _prctl() -> Callable[..., int] | None:
    """libc's ``prctl``, loaded once in the parent (a child after ``fork`` only calls it)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        function: Callable[..., int] = libc.prctl
    except (OSError, AttributeError):
        return None
    return function


def die_with_parent(parent: int) -> None:
    """In a child: be killed (SIGKILL) when the parent process ``parent`` dies, and exit at once
    when it is already gone (it died between the fork and this call)."""
    prctl = _prctl()
    if prctl is not None:
        prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


def child_signals() -> None:
    """In a child: Ctrl-C is the parent's business (SIGINT ignored; a Python child started with it
    ignored keeps ignoring it), SIGTERM and SIGHUP end the child as usual (a forked worker inherited
    the parent's Python handlers for them)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_DFL)


def worker_started(parent: int) -> None:
    """First thing in a forked worker process (``multiprocessing``): die with ``parent``, leave
    Ctrl-C to it."""
    die_with_parent(parent)
    child_signals()


def preexec() -> Callable[[], None]:
    """A ``preexec_fn`` for ``subprocess.Popen``: the new process dies with this one and leaves
    Ctrl-C to it. Runs in the child between fork and exec: only system calls."""
    parent = os.getpid()
    prctl = _prctl()

    def setup() -> None:
        if prctl is not None:
            prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != parent:
            os._exit(1)
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    return setup
