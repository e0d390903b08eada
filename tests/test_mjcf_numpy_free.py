"""The MJCF reader turns a compiled model whose arrays are plain tuples into robots without numpy.

``modelkit validate robot.xml`` may read MuJoCo's compiled model through a numpy-free stand-in of
``mujoco.MjModel`` (arrays as tuples of floats and ints). The code from ``CompiledModel`` through
``RobotBuilder.build``, ``add_devices`` and the reader's ``_from_compiled`` must then neither import
numpy nor convert anything to numpy, and must build the same robots as from the bindings' arrays.

Two child processes per run (the test process has imported numpy long ago):

* the *bindings* child reads each file with ``read_mjcf`` through the real ``mujoco`` bindings
  (``MODELKIT_MUJOCO=bindings``), wrapping the module and the ``MjModel`` so that it records every
  model attribute, enum and name the reader asks for; it prints those as plain data (a row of an
  n×3 array a 3-list, an n×1 array scalars), with the robots and the diagnostics it read;
* the *tuples* child puts a finder first on ``sys.meta_path`` that refuses ``numpy`` (an
  ``ImportError``, so an import anywhere fails the read), then reads the same files with
  ``read_mjcf`` through a fake ``mujoco`` module that serves those plain values as tuples, and
  prints its robots and diagnostics.

The robots must agree field by field (names, joint types, origins, axes, limits, masses, COMs,
inertias, geometry kinds and sizes, devices, extras) to 1e-12, and the diagnostics exactly. Files
MuJoCo does not compile are skipped (the reader reads those through the bindings' spec anyway).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

PROJECT = Path(__file__).resolve().parents[1]
CORPUS = PROJECT.parent / "shared" / "corpus"
TOLERANCE = 1e-12


def _files() -> list[Path]:
    found = sorted((PROJECT / "tests" / "mjcf").glob("*.xml"))
    found += [CORPUS / "mujoco_model" / "humanoid" / "humanoid.xml"]
    found += sorted((CORPUS / "dm_control_suite" / "dm_control" / "suite").glob("*.xml"))
    return [p for p in found if p.is_file() and b"<mujoco" in p.read_bytes()[:4000]]


FILES = _files()

# Shared by both children: every field of the robots and diagnostics as JSON-like data, read from
# the instances' __dict__ (an ArrayField's stored value, never its numpy-converting attribute).
PLAIN = textwrap.dedent("""\
    import dataclasses
    import enum
    import math
    from pathlib import Path


    def plain(value, seen=frozenset()):
        from modelkit.diagnostics import SourceLocation  # not before the child's set-up

        if isinstance(value, bool) or value is None or isinstance(value, str):
            return value
        if isinstance(value, enum.Enum):
            return f"{type(value).__name__}.{value.name}"
        if isinstance(value, int):
            return value
        if isinstance(value, float):
            return value if math.isfinite(value) else repr(value)
        if isinstance(value, (Path, SourceLocation)):
            return str(value)
        if hasattr(value, "tolist"):  # a numpy array or scalar (the bindings child only)
            return plain(value.tolist(), seen)
        if isinstance(value, dict):
            return {str(k): plain(v, seen) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [plain(v, seen) for v in value]
        if id(value) in seen:
            return "<cycle>"
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            inner = seen | {id(value)}
            fields = {k.lstrip("_"): plain(v, inner) for k, v in vars(value).items()}
            return {"__class__": type(value).__name__, **fields}
        return str(value)  # a source location (resolved lazily) and the like


    def result_data(result):
        return {
            "robots": [plain(r) for r in result.robots],
            # MuJoCo's own warnings (MK177) come from the bindings' compiler, which the fake does not run
            "diagnostics": [
                [d.code, d.message, str(d.location)] for d in result.diagnostics if d.code != "MK177"
            ],
        }
""")

BINDINGS_CHILD = PLAIN + textwrap.dedent("""\
    import json
    import os
    import sys

    import mujoco
    import numpy as np

    from modelkit.formats.common import ReadOptions
    from modelkit.formats.mjcf import reader


    def scalar(x):
        return int(x) if np.asarray(x).dtype.kind in "iub" else float(x)


    def snapshot(value):
        \"\"\"A model attribute as plain data: a row of an n×k array a k-list, an n×1 array scalars.\"\"\"
        if isinstance(value, np.ndarray):
            if value.ndim == 0:
                return scalar(value)
            if value.ndim == 1:
                return [scalar(x) for x in value]
            if value.ndim == 2 and value.shape[1] == 1:
                return [scalar(row[0]) for row in value]
            return [[scalar(x) for x in row] for row in value]
        if isinstance(value, (bool, int, float, np.generic)):
            return scalar(value)
        raise TypeError(f"unexpected model attribute of type {type(value).__name__}")


    class RecordedModel:
        def __init__(self, model):
            self._model, self._used = model, set()

        def __getattr__(self, name):
            self._used.add(name)
            return getattr(self._model, name)


    class RecordedSpec:
        def __init__(self, spec, log):
            self._spec, self._log = spec, log

        def __getattr__(self, name):
            return getattr(self._spec, name)

        def compile(self):
            model = RecordedModel(self._spec.compile())
            self._log["model"] = model
            return model


    class RecordedMujoco:
        def __init__(self):
            self.log = {"names": {}, "enums": set()}
            outer = self

            class MjSpec:
                @staticmethod
                def from_file(path):
                    return RecordedSpec(mujoco.MjSpec.from_file(path), outer.log)

            self.MjSpec = MjSpec

        def mj_id2name(self, model, obj, index):
            name = mujoco.mj_id2name(model._model, obj, index)
            self.log["names"][f"{int(obj)}:{int(index)}"] = name
            return name

        def __getattr__(self, name):
            if name.startswith("mjt"):
                self.log["enums"].add(name)
            return getattr(mujoco, name)


    mujoco.set_mju_user_warning(lambda message: None)  # never MUJOCO_LOG.TXT in the working directory
    out = {}
    for path in sys.argv[1:]:
        try:
            mujoco.MjModel.from_xml_path(path)
        except ValueError:
            continue  # MuJoCo refuses it: the reader reads the uncompiled spec (not this test's matter)
        recorded = RecordedMujoco()
        reader._import_mujoco = lambda recorded=recorded: recorded
        result = reader.read_mjcf(Path(path), ReadOptions(), Path(path).name)
        model = recorded.log["model"]
        spec = mujoco.MjSpec.from_file(path)
        out[path] = {
            "model": {name: snapshot(getattr(model._model, name)) for name in sorted(model._used)},
            "names": recorded.log["names"],
            "enums": {
                e: {int(member): name for name, member in getattr(mujoco, e).__members__.items()}
                for e in sorted(recorded.log["enums"])
            },
            "meshdir": str(spec.meshdir or ""),
            "meshes": [str(m.file or "") for m in spec.meshes],
            "result": result_data(result),
        }
    json.dump(out, sys.stdout)
""")

TUPLES_CHILD = PLAIN + textwrap.dedent("""\
    import json
    import sys
    import traceback


    class NoNumpy:
        \"\"\"Refuses numpy, and remembers where it was asked for.\"\"\"

        attempts = []

        @classmethod
        def find_spec(cls, fullname, path=None, target=None):
            if fullname.partition(".")[0] == "numpy":
                frames = traceback.extract_stack()[:-1]
                cls.attempts.append([f"{Path(f.filename).name}:{f.lineno} {f.name}" for f in frames
                                     if "modelkit" in f.filename])
                raise ImportError(f"numpy is blocked in this process ({fullname})")
            return None


    sys.meta_path.insert(0, NoNumpy)
    assert "numpy" not in sys.modules

    from modelkit.formats.common import ReadOptions
    from modelkit.formats.mjcf import reader


    def tuples(value):
        return tuple(tuples(v) for v in value) if isinstance(value, list) else value


    class Member:
        def __init__(self, name):
            self.name = name


    class Enum:
        def __init__(self, members):
            self.members = {int(k): v for k, v in members.items()}
            self.by_name = {v: k for k, v in self.members.items()}

        def __call__(self, value):
            return Member(self.members[int(value)])

        def __getattr__(self, name):
            try:
                return self.by_name[name]
            except KeyError:
                raise AttributeError(name) from None


    class TupleModel:
        \"\"\"The compiled model as the numpy-free stand-in gives it: arrays are tuples.\"\"\"

        def __init__(self, arrays):
            for name, value in arrays.items():
                setattr(self, name, tuples(value))


    class Namespace:
        def __init__(self, **kw):
            self.__dict__.update(kw)


    class FakeSpec:
        def __init__(self, data):
            self.compiler = Namespace()
            self.meshdir = data["meshdir"]
            self.meshes = [Namespace(file=f) for f in data["meshes"]]
            self._model = TupleModel(data["model"])

        def compile(self):
            return self._model


    class FakeMujoco:
        def __init__(self, data):
            self._data, self._names = data, data["names"]
            for name, members in data["enums"].items():
                setattr(self, name, Enum(members))
            self._handler = None
            outer = self

            class MjSpec:
                @staticmethod
                def from_file(path):
                    return FakeSpec(outer._data)

            self.MjSpec = MjSpec

        def get_mju_user_warning(self):
            return self._handler

        def set_mju_user_warning(self, handler):
            self._handler = handler

        def mj_id2name(self, model, obj, index):
            return self._names[f"{int(obj)}:{int(index)}"]


    snapshots = json.load(sys.stdin)
    out = {}
    for path, data in snapshots.items():
        fake = FakeMujoco(data)
        reader._import_mujoco = lambda fake=fake: fake
        before = len(NoNumpy.attempts)
        try:
            result = result_data(reader.read_mjcf(Path(path), ReadOptions(), Path(path).name))
        except Exception as exc:  # numpy refused (or a bug): say where
            result = {"error": "".join(traceback.format_exception(exc)[-12:])}
        out[path] = {"result": result, "numpy": NoNumpy.attempts[before:]}
    out["__modules__"] = sorted(m for m in sys.modules if m.partition(".")[0] == "numpy")
    json.dump(out, sys.stdout)
""")


def _child(script: str, args: list[str], stdin: str | None = None) -> Any:
    env = {**os.environ, "MODELKIT_MUJOCO": "bindings"}  # never the ctypes path: these fakes are the input
    done = subprocess.run([sys.executable, "-c", script, *args], cwd=PROJECT, input=stdin, env=env,
                          capture_output=True, text=True, check=False, timeout=600)
    assert done.returncode == 0, f"child failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return json.loads(done.stdout)


@pytest.fixture(scope="module")
def bindings() -> dict[str, Any]:
    if not FILES:
        pytest.skip("no MJCF files")
    out: dict[str, Any] = _child(BINDINGS_CHILD, [str(p) for p in FILES])
    with_robots = [path for path, data in out.items() if data["result"]["robots"]]
    assert len(with_robots) >= 5, f"too few files compiled into robots: {with_robots}"
    return out


@pytest.fixture(scope="module")
def from_tuples(bindings: dict[str, Any]) -> dict[str, Any]:
    """The tuple-fed read with numpy refused, through the reader as it is."""
    snapshots = {path: {k: v for k, v in data.items() if k != "result"} for path, data in bindings.items()}
    out: dict[str, Any] = _child(TUPLES_CHILD, [], json.dumps(snapshots))
    return out


def differences(a: Any, b: Any, where: str = "") -> list[str]:
    """Where two plain data trees differ: numbers beyond ``TOLERANCE`` (relative above 1), anything else."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return [f"{where}: keys {sorted(a.keys() ^ b.keys())}"]
        return [d for k in a for d in differences(a[k], b[k], f"{where}.{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} items ≠ {len(b)}"]
        pairs = enumerate(zip(a, b, strict=True))
        return [d for i, (x, y) in pairs for d in differences(x, y, f"{where}[{i}]")]
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (a, b))
    if numbers and math.isclose(a, b, rel_tol=TOLERANCE, abs_tol=TOLERANCE):
        return []
    return [] if not numbers and a == b else [f"{where}: {a!r} ≠ {b!r}"]


def test_modules_import_without_numpy() -> None:
    script = TUPLES_CHILD.split("from modelkit.formats.common")[0] + textwrap.dedent("""\
        import modelkit.formats.mjcf.bodies
        import modelkit.formats.mjcf.build
        import modelkit.formats.mjcf.compiled
        import modelkit.formats.mjcf.devices
        import modelkit.formats.mjcf.reader
        import modelkit.formats.mjcf.uncompiled

        assert "modelkit.formats.mjcf.build" in sys.modules
        print(json.dumps({"attempts": NoNumpy.attempts, "numpy": [m for m in sys.modules if "numpy" in m]}))
    """)
    report = _child(script, [])
    assert report == {"attempts": [], "numpy": []}


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_tuples_build_the_same_robots_without_numpy(
    path: Path, bindings: dict[str, Any], from_tuples: dict[str, Any]
) -> None:
    if str(path) not in bindings:
        pytest.skip("MuJoCo does not compile it")
    tuples = from_tuples[str(path)]
    assert "error" not in tuples["result"], tuples["result"]["error"]
    assert tuples["numpy"] == [], f"numpy was asked for: {tuples['numpy']}"
    expected = bindings[str(path)]["result"]
    found = differences(expected, tuples["result"])
    assert found == [], "\n".join(d[:300] for d in found[:30])


def test_no_numpy_was_loaded(from_tuples: dict[str, Any]) -> None:
    assert from_tuples["__modules__"] == []


def test_the_comparison_sees_a_changed_value(bindings: dict[str, Any]) -> None:
    """The check works: one inertia moment changed by 1e-9 changes the robots the tuples give."""
    path = next(p for p, data in bindings.items() if data["model"].get("nbody", 0) > 1)
    data = {k: v for k, v in bindings[path].items() if k != "result"}
    moments = data["model"]["body_inertia"]
    moments[1] = [moments[1][0] + 1e-9, *moments[1][1:]]
    out = _child(TUPLES_CHILD, [], json.dumps({path: data}))
    assert "error" not in out[path]["result"]
    found = differences(bindings[path]["result"], out[path]["result"])
    assert found and all(".inertial.inertia[" in d for d in found), found
