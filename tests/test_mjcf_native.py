"""The MJCF reader's direct path into MuJoCo's C library (:mod:`modelkit.formats.mjcf.native`) reads
exactly what the Python bindings read.

Every MJCF file at hand (``tests/mjcf``, the corpus' MuJoCo and dm_control models, pybullet's MJCF
files) is read twice in this process: through ctypes, and with ``MODELKIT_MUJOCO=bindings`` through
``mujoco.MjSpec``. The robots (every field of every link, joint, geom, inertial and device, and the
extras that keep actuators, sensors, cameras...) and the diagnostics must be identical, number for
number. A file the bindings compile must also have been compiled by the direct path (no silent
fallback). That ``validate``/``tree`` then import neither numpy nor mujoco is checked by
``test_import_hygiene.py``.
"""

from __future__ import annotations

import dataclasses
import enum
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.mjcf import native, read_mjcf
from modelkit.formats.mjcf.cheader import HeaderError, read_headers
from modelkit.formats.mjcf.quiet import collected_warnings
from modelkit.rot3 import ArrayField, peek

PROJECT = Path(__file__).resolve().parents[1]
CORPUS = PROJECT.parent / "shared" / "corpus"


def _files() -> list[Path]:
    found = sorted((PROJECT / "tests" / "mjcf").glob("*.xml"))
    found += sorted((CORPUS / "mujoco_model").rglob("*.xml"))
    found += sorted((CORPUS / "dm_control_suite").glob("*.xml"))
    try:
        import pybullet_data

        found += sorted(Path(pybullet_data.getDataPath(), "mjcf").glob("*.xml"))
    except ImportError:  # pragma: no cover - pybullet is in the test environment
        pass
    return [p for p in found if b"<mujoco" in p.read_bytes()[:4000]]


FILES = _files()


def _compiles(path: Path) -> bool:
    with collected_warnings(mujoco):  # not MUJOCO_LOG.TXT in the working folder
        try:
            mujoco.MjModel.from_xml_path(str(path))
        except ValueError:
            return False
    return True


def plain(value: Any, seen: frozenset[int] = frozenset()) -> Any:
    """Every field, recursively, as JSON-like data; floats by ``repr`` so that ``nan`` compares."""
    if isinstance(value, enum.Enum):
        return f"{type(value).__name__}.{value.name}"
    if isinstance(value, bool | int | str) or value is None:
        return value
    if isinstance(value, float | np.floating):
        return repr(float(value))
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.ndarray):
        return plain(value.tolist(), seen)
    if isinstance(value, list | tuple):
        return [plain(v, seen) for v in value]
    if isinstance(value, dict):
        return {str(k): plain(v, seen) for k, v in value.items()}
    if isinstance(value, Path):
        return str(value)
    if id(value) in seen:
        return "<cycle>"
    seen = seen | {id(value)}
    if dataclasses.is_dataclass(value):
        return {
            f.name: plain(_field(value, f.name), seen) for f in dataclasses.fields(value)
        }
    if hasattr(value, "__dict__"):
        return {k: plain(v, seen) for k, v in vars(value).items()}
    return repr(value)


def _field(value: object, name: str) -> Any:
    """A field as stored (an array field is not converted to numpy on the way)."""
    if any(isinstance(vars(kind).get(name), ArrayField) for kind in type(value).__mro__):
        return peek(value, name)
    return getattr(value, name)


def _read(path: Path, monkeypatch: pytest.MonkeyPatch, through: str) -> ReadResult:
    if through == "bindings":
        monkeypatch.setenv(native.ENVIRONMENT_SWITCH, "bindings")
    else:
        monkeypatch.delenv(native.ENVIRONMENT_SWITCH, raising=False)
    native.library.cache_clear()
    try:
        return read_mjcf(path, ReadOptions(), path.name)
    finally:
        native.library.cache_clear()


def _dump(result: ReadResult) -> dict[str, Any]:
    return {
        "robots": [plain(r) for r in result.robots],
        "diagnostics": [(d.code, d.severity.value, d.message, str(d.location)) for d in result.diagnostics],
    }


def _first_difference(a: Any, b: Any, where: str = "") -> str:
    if type(a) is not type(b):
        return f"{where}: {a!r} != {b!r}"
    if isinstance(a, dict):
        for key in sorted(set(a) | set(b)):
            if a.get(key) != b.get(key):
                return _first_difference(a.get(key), b.get(key), f"{where}.{key}")
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{where}: {len(a)} items != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            if x != y:
                return _first_difference(x, y, f"{where}[{i}]")
    return f"{where}: {a!r} != {b!r}"


def test_the_files_are_there() -> None:
    assert len([p for p in FILES if "tests/mjcf" in str(p)]) >= 6
    if CORPUS.is_dir():
        assert len(FILES) >= 30


@pytest.mark.parametrize("path", FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_native_reads_what_the_bindings_read(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    through_bindings = _dump(_read(path, monkeypatch, "bindings"))
    through_native = _dump(_read(path, monkeypatch, "native"))
    assert through_native == through_bindings, _first_difference(through_native, through_bindings)
    if _compiles(path) and b"<extension" not in path.read_bytes():
        monkeypatch.delenv(native.ENVIRONMENT_SWITCH, raising=False)
        with native.compiled(path) as result:  # the direct path did the work: no silent fallback
            assert result is not None
            assert result.model.nbody >= 1


def test_arrays_and_sizes_match_the_bindings() -> None:
    """Every array the reader may read equals the bindings' array, for a model that has them all."""
    path = CORPUS / "mujoco_model" / "humanoid" / "humanoid.xml"
    if not path.is_file():
        path = PROJECT / "tests" / "mjcf" / "pendulum.xml"
    with collected_warnings(mujoco):
        bound = mujoco.MjModel.from_xml_path(str(path))
    lib = native.library()
    assert lib is not None
    with native.compiled(path) as result:
        assert result is not None
        model = result.model
        for name in ("nbody", "njnt", "ngeom", "nsite", "ncam", "nlight", "nu", "nsensor", "nkey", "nq"):
            assert getattr(model, name) == getattr(bound, name), name
        checked = 0
        for name in lib.headers.model_arrays:
            expected = getattr(bound, name, None)
            if not isinstance(expected, np.ndarray) or expected.dtype.kind not in "fiub":
                continue
            if expected.size == 0:
                continue
            got = np.array(getattr(model, name), dtype=expected.dtype).reshape(expected.shape)
            assert np.array_equal(got, expected, equal_nan=True), name
            checked += 1
        assert checked > 200
        assert result.mj.mj_id2name(model, result.mj.mjtObj.mjOBJ_BODY, 1) == mujoco.mj_id2name(
            bound, mujoco.mjtObj.mjOBJ_BODY, 1
        )
        assert result.mj.mjtGeom(int(mujoco.mjtGeom.mjGEOM_CAPSULE)).name == "mjGEOM_CAPSULE"


def test_compiler_flags_are_set(tmp_path: Path) -> None:
    """A file asking for static-body fusion and visual discarding keeps both bodies and the visual geom."""
    path = tmp_path / "fused.xml"
    path.write_text(
        '<mujoco model="m"><compiler fusestatic="true" discardvisual="true"/><worldbody>'
        '<body name="a"><freejoint/><geom size=".1" mass="1"/>'
        '<body name="b" pos="0 0 1"><geom size=".1" contype="0" conaffinity="0"/></body></body>'
        "</worldbody></mujoco>"
    )
    with native.compiled(path) as result:
        assert result is not None
        assert result.model.nbody == 3
        assert result.model.ngeom == 2


def test_warnings_are_collected_not_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "warns.xml"
    # a deprecated compiler attribute: MuJoCo 4 accepts it with a warning
    path.write_text(
        '<mujoco model="m"><compiler settotalmass="3"/><worldbody><body name="a"><freejoint/>'
        '<geom size=".1"/></body></worldbody></mujoco>'
    )
    monkeypatch.chdir(tmp_path)
    bindings = _dump(_read(path, monkeypatch, "bindings"))
    direct = _dump(_read(path, monkeypatch, "native"))
    assert direct == bindings
    assert [d[2] for d in direct["diagnostics"] if d[0] == "MK177"] == [
        m for m in [d[2] for d in bindings["diagnostics"] if d[0] == "MK177"] if "settotalmass" in m
    ] != []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["warns.xml"]


def test_unusable_headers_are_refused(tmp_path: Path) -> None:
    """A header this reader does not understand is refused (the bindings are used instead)."""
    include = Path(mujoco.__file__).parent / "include" / "mujoco"
    for name in ("mjtype.h", "mjmodel.h", "mjvisualize.h", "mjspec.h", "mjxmacro.h"):
        (tmp_path / name).write_text((include / name).read_text(encoding="utf-8"), encoding="utf-8")
    read_headers(tmp_path)  # the installed headers are understood
    model = (tmp_path / "mjmodel.h").read_text(encoding="utf-8")
    (tmp_path / "mjmodel.h").write_text(model.replace("mjtNum*   body_pos;", "mjtNum*   body_pos, *x;"))
    with pytest.raises(HeaderError):
        read_headers(tmp_path)


def test_bindings_switch(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(native.ENVIRONMENT_SWITCH, "bindings")
    native.library.cache_clear()
    try:
        assert native.library() is None
    finally:
        native.library.cache_clear()
