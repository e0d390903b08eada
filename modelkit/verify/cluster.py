"""``modelkit verify MODELS --cluster ray://HOST:PORT``: the per-model job of
:mod:`modelkit.verify.many` as Ray tasks, scheduled by Ray (no scheduler of our own).

Ray is an optional extra (``pip install 'modelkit[cluster]'``, which is ``ray[client]``), imported
only here and only when ``--cluster`` is given; without it :class:`ClusterError` says how to get it
(exit 2).

Addresses: ``ray://HOST:PORT`` connects to a running cluster through the Ray client (the head's
client server, ``ray start --head`` opens it on port 10001 by default); ``local`` starts a private
Ray instance on this machine for the run and stops it afterwards (to try the cluster path; ``-j``
is the simpler way to use one machine).

Contract with the cluster: its workers have modelkit installed (with the engines, at the same
version) and read the model files **at the same absolute paths** as this machine (a shared file
system or the same checkout at the same path, the usual set-up of a CI runner pool). Each task
verifies one model in a temporary folder on its worker and returns the summary line plus the
folder's files, which are written here under ``-o``: the layout is that of a local run, and so are
the numbers. A task that dies (a worker crash, a segfault in an engine) is not retried: the model
gets verdict "error" with Ray's reason and the others go on.
"""

from __future__ import annotations

import contextlib
import logging
import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from modelkit.verify.many import Job, ModelResult, Progress, crashed, run_collected, unpack

INSTALL_HINT = "pip install 'modelkit[cluster]' (Ray with its client)"


class ClusterError(Exception):
    """The cluster cannot be used: Ray missing, a bad address, no connection (exit 2)."""


def _ray() -> Any:
    try:
        import ray
    except ImportError as exc:
        raise ClusterError(f"--cluster needs Ray, which is not installed ({exc}): {INSTALL_HINT}") from exc
    return ray


def connect(address: str, num_cpus: int | None = None) -> Any:
    """``ray.init`` for ``address`` (``ray://HOST:PORT`` or ``local``); returns the ``ray`` module."""
    ray = _ray()
    if address == "local":
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                                  "logging_level": logging.WARNING}
        if num_cpus is not None:
            kwargs["num_cpus"] = num_cpus
    elif address.startswith("ray://"):
        kwargs = {"address": address, "logging_level": logging.WARNING, "log_to_driver": False}
    else:
        raise ClusterError(f"--cluster {address!r}: expected ray://HOST:PORT or local")
    for attempt in range(CONNECT_ATTEMPTS):
        try:
            ray.init(**kwargs)
            break
        except ConnectionAbortedError as exc:  # "Initialization failure from server" (see below)
            if not address.startswith("ray://") or attempt == CONNECT_ATTEMPTS - 1:
                raise _unreachable(address, exc) from exc
            with contextlib.suppress(Exception):
                ray.shutdown()
            time.sleep(CONNECT_PAUSE)
        except Exception as exc:
            raise _unreachable(address, exc) from exc
    return ray


CONNECT_ATTEMPTS = 3
CONNECT_PAUSE = 1.0  # seconds between attempts
"""The Ray client's proxy starts a server process for each connection; when that process dies at
start, the proxy answers "Initialization failure from server" (seen in this project's CI: the proxy
found the process a zombie, ``psutil.ZombieProcess``, while another connection of the same test
session had just ended), and the next connection gets a new one. So a ``ConnectionAbortedError`` is
tried again, a refused address or a bad token is not."""


def _unreachable(address: str, exc: Exception) -> ClusterError:
    hint = ""
    if address.startswith("ray://") and os.environ.get("RAY_AUTH_MODE", "").lower() != "token":
        hint = (" (if the cluster uses token authentication, as Ray's local clusters do by default, set "
                "RAY_AUTH_MODE=token and its token in RAY_AUTH_TOKEN or ~/.ray/auth_token)")
    return ClusterError(f"--cluster {address}: cannot connect: {type(exc).__name__}: {exc}{hint}")


def run_ray(jobs: Sequence[Job], out_root: Path | None, address: str,
            progress: Progress | None = None) -> list[ModelResult]:
    """Verify every job as a Ray task (one CPU each); results in completion order, each model's files
    written under ``out_root/folder`` (nothing written when ``out_root`` is None)."""
    ray = connect(address)
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(run_collected)
        refs = {task.remote(job): job for job in jobs}
        results: list[ModelResult] = []
        while refs:
            ready, _ = ray.wait(list(refs), num_returns=1)
            for ref in ready:
                job = refs.pop(ref)
                try:
                    result, files = ray.get(ref)
                except Exception as exc:  # the task died: a worker crash, an engine segfault
                    result, files = crashed(job, f"the Ray task verifying this model failed: "
                                                 f"{type(exc).__name__}: {_first_line(exc)}"), {}
                if out_root is not None and files:
                    unpack(files, out_root / job.folder)
                results.append(result)
                if progress is not None:
                    progress(result, len(results), len(jobs))
        return results
    finally:
        ray.shutdown()


def _first_line(exc: Exception) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else ""
