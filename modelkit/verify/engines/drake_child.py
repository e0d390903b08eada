"""Drake in a child process: :class:`modelkit.verify.engines.drake.DrakeModel` runs there, and verify
talks to it through :class:`modelkit.verify.engines.child.Worker`.

Why: Drake checks some facts of a file with a C++ assertion that aborts the whole process instead of
raising (a joint range with its lower limit above its upper: ``joint.h`` "condition
'(pos_lower_limits.array() <= pos_upper_limits.array()).all()' failed"). A user's SDF may hold such a
range (libsdformat loads it; validate warns, MK307); loaded in verify's own process it ended verify
with exit 1 and no verdict. In a child, such an abort ends the child only, and verify reports it.

Each Drake engine ("drake" reads the SDF, "drake-urdf" the URDF) has its own child, started when
verify starts (``registry.PRESTART``), so that pydrake's import runs while verify reads and converts.

This module imports no pydrake and not :mod:`.drake`: the exceptions :mod:`modelkit.verify.api`
recognises live here, and :mod:`.drake` takes them from here; the child's side of the pipe is
:func:`modelkit.verify.engines.drake.serve_child`.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

from modelkit.model import Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.child import Worker
from modelkit.verify.engines.protocol import Array, EngineError, StaticFacts

Renames = dict[str, dict[str, str]]
DRAKE_CHILD = ("import sys; from modelkit.verify.engines.drake import serve_child; "
               "sys.exit(serve_child())")
# seconds: Drake parses every mesh of the file (ARMAR-4: 89 MB of them); in verify's own process the
# load had no bound, so this one is wide: it only stops a parse that would never end
LOAD_TIMEOUT = 600.0

# What Drake's Joint constructor asserts before it aborts, and why: a reversed range in the written
# file, which the source holds (MK307) when the conversion copied it.
REVERSED_RANGE_ASSERTION = "pos_lower_limits.array() <= pos_upper_limits.array()"
REVERSED_RANGE_REFUSAL = "The lower limit must be lower (or equal) than the upper limit"  # its SDF parser
REVERSED_RANGE_LIMITATION = ("Drake takes no joint range whose lower limit is above its upper: its SDF "
                             "parser refuses the file, and from a URDF its Joint constructor aborts the "
                             "process (a C++ assertion, not an error it reports)")


class DrakeLoadError(RuntimeError):
    """Drake could not load the file, or the file does not hold the expected single model/root."""


LOOP_MESSAGE = "form one or more loops"  # Drake's Finalize() message when the joints form a loop
LOOP_LIMITATION = ("Drake's MultibodyPlant models a tree of joints only: it refuses a file whose joints "
                   "form a loop (it asks for the loop joint to be replaced by a constraint, "
                   "https://drake.mit.edu/troubleshooting.html#mbp-loops-in-graph)")


class DrakeLoopError(DrakeLoadError):
    """Drake refused the file because its bodies and joints form a loop (a closed-loop joint written as
    an extra joint, MK811): a limitation of ``MultibodyPlant``, not a defect of the file (the verifier
    reports it as a skip when the source has loops, see ``modelkit.verify.api``)."""

    loop_refusal = True
    limitation = LOOP_LIMITATION


class DrakeError(EngineError):
    """Drake's child process failed: it died (an abort in Drake's C++), did not answer in time, or
    Drake raised while answering."""


class DrakeReversedRange(DrakeError):
    """Drake refused (:data:`REVERSED_RANGE_REFUSAL`) or its child aborted on
    (:data:`REVERSED_RANGE_ASSERTION`) a reversed joint range in the written file. The verifier reports a
    skip when the source holds such a range (MK307), a failed load otherwise."""

    reversed_range_refusal = True
    limitation = REVERSED_RANGE_LIMITATION


_REFUSALS: dict[str, type[Exception]] = {"DrakeLoadError": DrakeLoadError, "DrakeLoopError": DrakeLoopError,
                                         "DrakeReversedRange": DrakeReversedRange}


def drake_worker(engine: str = "drake") -> Worker:
    """A child, started: it imports pydrake at once, then waits for :class:`DrakeProcessModel`."""
    return Worker([sys.executable, "-P", "-c", DRAKE_CHILD], engine, DrakeError)


def start_drake() -> Worker | None:
    """verify's head start (``registry.PRESTART``): the child, started; None when pydrake is missing
    (the loader then says so, as without a head start)."""
    if importlib.util.find_spec("pydrake") is None:
        return None
    return drake_worker()


class DrakeProcessModel:
    """One written file in Drake (:class:`modelkit.verify.engines.drake.DrakeModel`), held by the child
    process ``worker``, which this model owns from now on. Same methods, same answers."""

    def __init__(self, path: Path, root: str, engine: str, worker: Worker) -> None:
        self.engine, self.path, self.root = engine, path, root
        worker.name = engine
        self._worker = worker
        try:
            reply = worker.request("load", timeout=LOAD_TIMEOUT, path=str(Path(path).resolve()), root=root,
                                   engine=engine)
        except DrakeError as exc:
            worker.close()
            if REVERSED_RANGE_ASSERTION in str(exc):
                raise DrakeReversedRange(f"{path.name}: {exc}") from None
            raise
        except BaseException:
            worker.close()
            raise
        if "refused" in reply:
            worker.close()
            kind, message = reply["refused"]
            raise _REFUSALS.get(kind, DrakeLoadError)(message)
        self.settings: dict[str, Any] = dict(reply["settings"], process="child process")
        self.warnings: list[str] = list(reply["warnings"])
        self._dofs: list[str] = list(reply["dofs"])
        self._dofs_with_balls: list[str] = list(reply["dofs_with_balls"])
        self._static: StaticFacts = reply["static"]

    def _call(self, method: str, *args: Any) -> Any:
        return self._worker.request("call", method=method, args=args)

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def dof_names_with_balls(self) -> list[str]:
        return list(self._dofs_with_balls)

    def static(self) -> StaticFacts:
        return self._static

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        poses: dict[str, Pose] = self._call("link_poses", dict(q))
        return poses

    def mass_matrix(self, q: dict[str, float]) -> Array:
        matrix: Array = self._call("mass_matrix", dict(q))
        return matrix

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        vector: Array = self._call("bias", dict(q), dict(dq))
        return vector

    def mass_matrix_with_balls(self, q: dict[str, float]) -> Array:
        matrix: Array = self._call("mass_matrix_with_balls", dict(q))
        return matrix

    def bias_with_balls(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        vector: Array = self._call("bias_with_balls", dict(q), dict(dq))
        return vector

    def close(self) -> None:
        self._worker.close()


def _load(model: Path | Robot, root: str, engine: str, worker: Worker | None) -> DrakeProcessModel:
    if isinstance(model, Robot):
        raise TypeError("the Drake adapter reads a written SDF or URDF file")
    if importlib.util.find_spec("pydrake") is None:
        if worker is not None:
            worker.close()
        raise ImportError("No module named 'pydrake'")
    if worker is None or not worker.alive():
        worker = drake_worker(engine)
    return DrakeProcessModel(Path(model), root, engine, worker)


def load(model: Path | Robot, renames: Renames, *, root: str, worker: Worker | None = None
         ) -> DrakeProcessModel:
    """The engine plug-in entry point: the written SDF (or, by its suffix, URDF) in Drake, in a child;
    engine "drake" for SDF, "drake-urdf" for URDF."""
    engine = "drake-urdf" if Path(str(model)).suffix.lower() == ".urdf" else "drake"
    return _load(model, root, engine, worker)


def load_urdf(model: Path | Robot, renames: Renames, *, root: str, worker: Worker | None = None
              ) -> DrakeProcessModel:
    """The written URDF in Drake (engine "drake-urdf"), in a child: the second Drake instance."""
    return _load(model, root, "drake-urdf", worker)
