"""An engine in a child process: the framed request loop both sides share.

PyBullet runs in a child because it keeps global state and can crash; yourdfpy runs in one because its
import (trimesh, scipy, networkx: ≈ 0.5 s) would otherwise sit on verify's critical path, while in a
child started early it runs on the other core. The child answers requests on stdin; framing, both
ways: a 4-byte big-endian length, then a pickle. A request is ``(command, kwargs)``, a reply
``("ok", result)`` or ``("error", message)``. Libraries print to file descriptor 1, so the replies go to
a duplicate of the original stdout and fd 1 is pointed at stderr before the engine is made.

This module imports only the standard library (and :mod:`modelkit.lifeline`): the PyBullet child
imports it before PyBullet.
"""

from __future__ import annotations

import os
import pickle
import select
import struct
import subprocess
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Sequence
from typing import IO, Any, BinaryIO

from modelkit.lifeline import preexec

DEFAULT_TIMEOUT = 60.0  # seconds for one request


def _read(stream: BinaryIO, n: int) -> bytes | None:
    data = b""
    while len(data) < n:
        chunk = stream.read(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def _send(stream: BinaryIO, message: Any) -> None:
    payload = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(struct.pack(">I", len(payload)) + payload)
    stream.flush()


def serve(make_engine: Callable[[], Any]) -> int:
    """The child's side: each request ``(command, kwargs)`` calls ``engine.command(**kwargs)`` on the
    object ``make_engine()`` returns, until ``quit`` or the parent closes the pipe. Every failure
    goes back to the parent as a message."""
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # the engine's own prints go to stderr, never into the reply stream
    requests = sys.stdin.buffer
    engine = make_engine()
    while True:
        header = _read(requests, 4)
        if header is None:
            return 0
        body = _read(requests, struct.unpack(">I", header)[0])
        if body is None:
            return 0
        command, kwargs = pickle.loads(body)
        if command == "quit":
            _send(replies, ("ok", None))
            return 0
        try:
            result = getattr(engine, command)(**kwargs)
        except Exception as exc:
            _send(replies, ("error", f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=3)}"))
            continue
        _send(replies, ("ok", result))


class Worker:
    """The parent's side: the child process ``argv`` and its framed pickle pipe. ``name`` is the
    engine's name in messages; ``error`` the exception type a crash, a refusal or a timeout raises
    (never a hang: every request has a timeout)."""

    def __init__(self, argv: Sequence[str], name: str, error: type[Exception]) -> None:
        self.name, self.error = name, error
        self._stderr: IO[bytes] = tempfile.TemporaryFile()  # noqa: SIM115 (closed in close())
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen(
            list(argv), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=self._stderr, env=env, close_fds=True, preexec_fn=preexec(),
        )

    def _stderr_tail(self, since: int = 0) -> str:
        """The last lines the child printed (PyBullet explains a refused file there, not in the
        exception)."""
        self._stderr.seek(since)
        text = self._stderr.read().decode(errors="replace")
        self._stderr.seek(0, os.SEEK_END)
        lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("pybullet build time")]
        return "\n".join(lines[-12:])

    def _died(self, what: str) -> Exception:
        code = self.proc.wait(timeout=5)
        how = f"killed by signal {-code}" if code < 0 else f"exit status {code}"
        tail = self._stderr_tail()
        message = f"{self.name} child process died during {what} ({how})"
        return self.error(message + (f":\n{tail}" if tail else ""))

    def _read_exactly(self, n: int, deadline: float, what: str) -> bytes:
        assert self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        data = b""
        while len(data) < n:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self.kill()
                raise self.error(f"{self.name} did not answer {what} within the timeout; child killed")
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(fd, n - len(data))
            if not chunk:
                raise self._died(what)
            data += chunk
        return data

    def request(self, command: str, timeout: float = DEFAULT_TIMEOUT, **kwargs: Any) -> Any:
        return self.receive(command, self.send(command, **kwargs), timeout)

    def send(self, command: str, **kwargs: Any) -> int:
        """Send a request without waiting for its answer (the child works while the parent does
        something else); returns where the child's stderr stood, for :meth:`receive`."""
        if self.proc.poll() is not None:
            raise self._died(command)
        printed = self._stderr.seek(0, os.SEEK_END)
        payload = pickle.dumps((command, kwargs), protocol=pickle.HIGHEST_PROTOCOL)
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write(struct.pack(">I", len(payload)) + payload)
            self.proc.stdin.flush()
        except BrokenPipeError:
            raise self._died(command) from None
        return int(printed)

    def receive(self, command: str, printed: int, timeout: float = DEFAULT_TIMEOUT) -> Any:
        """The answer to the request :meth:`send` sent (``printed``: what it returned)."""
        deadline = time.monotonic() + timeout
        size = struct.unpack(">I", self._read_exactly(4, deadline, command))[0]
        status, result = pickle.loads(self._read_exactly(size, deadline, command))
        if status != "ok":
            said = self._stderr_tail(printed)
            raise self.error(f"{self.name} {command} failed: {result}".rstrip()
                             + (f"\n{self.name} printed:\n{said}" if said else ""))
        return result

    def alive(self) -> bool:
        """Whether the child still runs (it ends at :meth:`close`, :meth:`kill`, or when it crashed)."""
        return self.proc.poll() is None

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=5)

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.request("quit", timeout=5.0)
                self.proc.wait(timeout=5)
            except (self.error, subprocess.TimeoutExpired, OSError):
                self.kill()
        for stream in (self.proc.stdin, self.proc.stdout):
            if stream is not None:
                stream.close()
        self._stderr.close()
