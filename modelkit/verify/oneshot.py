"""One call in a child process: verify's report renders its pictures and draws its plots this way.

The parent starts ``python -c CODE`` at once, so the child imports what it needs (matplotlib,
MuJoCo with the GL back end chosen for that process) while the parent works; later it sends one
pickled request on stdin and reads one pickled reply, ``("ok", value)`` or ``("error", message)``.
The child side is :func:`serve`. Callers fall back to doing the work themselves when a child fails.
"""

from __future__ import annotations

import contextlib
import pickle
import subprocess
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from modelkit.lifeline import preexec


def serve(work: Callable[[Any], Any]) -> int:
    """The child's side: the pickled request on stdin, ``work(request)``'s pickled reply on stdout.
    Nothing is written when the parent went away without asking."""
    raw = sys.stdin.buffer.read()
    if not raw:
        return 0
    try:
        reply: tuple[str, Any] = ("ok", work(pickle.loads(raw)))
    except Exception as exc:
        reply = ("error", f"{type(exc).__name__}: {exc}")
    sys.stdout.buffer.write(pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL))
    sys.stdout.buffer.flush()
    return 0


class Child:
    """The parent's side: a child running ``code`` (raises ``OSError`` when it cannot start)."""

    def __init__(self, code: str, env: Mapping[str, str] | None = None,
                 cwd: str | Path | None = None) -> None:
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     env=dict(env) if env is not None else None, cwd=cwd,
                                     preexec_fn=preexec())

    def send(self, request: Any) -> None:
        """Send the one request (raises ``OSError``, ``ValueError`` or ``pickle.PicklingError``)."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(pickle.dumps(request, protocol=pickle.HIGHEST_PROTOCOL))
        self.proc.stdin.close()
        self.proc.stdin = None  # communicate() must not flush it again

    def reply(self, timeout: float) -> tuple[str, Any]:
        """``("ok", value)``, or ``("error", why)``: the child's message, a timeout, an unreadable
        reply, or the last line the child printed on stderr when it replied nothing."""
        try:
            out, err = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.end()
            return "error", "timed out"
        if not out:
            tail = err.decode(errors="replace").strip().splitlines()
            return "error", tail[-1] if tail else f"exit status {self.proc.returncode}"
        try:
            status, value = pickle.loads(out)
        except Exception as exc:
            return "error", f"unreadable reply ({exc})"
        return str(status), value

    def end(self) -> None:
        """Stop the child unasked (or collect one that has finished)."""
        if self.proc.poll() is None:
            self.proc.kill()
        with contextlib.suppress(Exception):
            self.proc.communicate(timeout=10.0)
