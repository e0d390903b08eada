"""Mesh-check outcomes kept on disk between runs (modelkit.geometry.mesh_cache): a second run reads the
outcome and the mesh's extent instead of parsing the file, gives the same diagnostics, and never
serves an outcome for a file that changed since."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from modelkit.geometry import mesh_cache, meshfiles


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("MODELKIT_CACHE_DIR", str(folder))
    monkeypatch.setattr(mesh_cache, "_enabled", True)
    meshfiles.clear_mesh_cache()
    yield folder
    meshfiles.clear_mesh_cache()


def _box(path: Path, extent: float = 0.2) -> Path:
    path.write_bytes(trimesh.creation.box(extents=(extent, extent, extent)).export(file_type="stl"))
    return path


def _no_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the mesh was parsed again")

    monkeypatch.setattr(meshfiles, "load_mesh", refuse)


def test_a_second_run_reads_the_outcome_and_the_extent(cache: Path, tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    mesh = _box(tmp_path / "box.stl")
    assert meshfiles.mesh_problem(mesh) is None
    corners = meshfiles.known_bounds(mesh)
    assert corners is not None and corners[1][0] == pytest.approx(0.1)
    assert len(list(cache.rglob("*.json"))) == 1
    meshfiles.clear_mesh_cache()  # as a new process
    _no_parsing(monkeypatch)
    assert meshfiles.mesh_problem(mesh) is None
    assert meshfiles.known_bounds(mesh) == corners


def test_a_broken_mesh_gives_the_same_diagnostic_from_the_cache(cache: Path, tmp_path: Path,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    mesh = tmp_path / "broken.stl"
    mesh.write_bytes(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\n")
    first = meshfiles.mesh_problem(mesh)
    assert first is not None and first.startswith("MK5")
    meshfiles.clear_mesh_cache()
    _no_parsing(monkeypatch)
    assert meshfiles.mesh_problem(mesh) == first


def test_a_changed_file_is_checked_again(cache: Path, tmp_path: Path) -> None:
    mesh = _box(tmp_path / "box.stl")
    assert meshfiles.mesh_problem(mesh) is None
    meshfiles.clear_mesh_cache()
    mesh.write_bytes(b"not a mesh at all")
    os.utime(mesh, ns=(os.stat(mesh).st_atime_ns, os.stat(mesh).st_mtime_ns + 1_000_000))
    assert meshfiles.mesh_problem(mesh) is not None
    meshfiles.clear_mesh_cache()
    _box(tmp_path / "box.stl", extent=0.4)
    assert meshfiles.mesh_problem(mesh) is None
    corners = meshfiles.known_bounds(mesh)
    assert corners is not None and corners[1][0] == pytest.approx(0.2)


def test_a_damaged_entry_is_no_entry(cache: Path, tmp_path: Path) -> None:
    mesh = _box(tmp_path / "box.stl")
    meshfiles.mesh_problem(mesh)
    (entry,) = cache.rglob("*.json")
    entry.write_text('{"key": 1, "outcome": 5')
    meshfiles.clear_mesh_cache()
    assert meshfiles.mesh_problem(mesh) is None
    assert meshfiles.known_bounds(mesh) is not None


def test_off_writes_nothing_and_an_unwritable_folder_is_no_error(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    mesh = _box(tmp_path / "box.stl")
    monkeypatch.setattr(mesh_cache, "_enabled", True)
    monkeypatch.setenv("MODELKIT_CACHE_DIR", "off")
    assert mesh_cache.folder() is None
    meshfiles.clear_mesh_cache()
    assert meshfiles.mesh_problem(mesh) is None
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("MODELKIT_CACHE_DIR", str(blocker))  # a file where the folder should be
    meshfiles.clear_mesh_cache()
    assert meshfiles.mesh_problem(mesh) is None
    meshfiles.clear_mesh_cache()


def test_validate_prints_the_same_cold_and_warm(tmp_path: Path) -> None:
    _box(tmp_path / "box.stl")
    robot = tmp_path / "robot.urdf"
    robot.write_text('<robot name="r"><link name="a"><visual><geometry><mesh filename="box.stl"/>'
                     '</geometry></visual><collision><origin xyz="3 0 0"/><geometry>'
                     '<mesh filename="box.stl"/></geometry></collision></link></robot>')
    env = {**os.environ, "MODELKIT_CACHE_DIR": str(tmp_path / "cache")}
    runs = [subprocess.run([sys.executable, "-m", "modelkit.cli", "validate", str(robot)],
                           capture_output=True, text=True, env=env, check=False) for _ in range(2)]
    assert list((tmp_path / "cache").rglob("*.json"))
    assert runs[0].stdout == runs[1].stdout and runs[0].returncode == runs[1].returncode
    assert "MK418" in runs[1].stdout  # the far collision, judged from the mesh's extent read from the cache


def test_convert_writes_no_cache_entry(tmp_path: Path) -> None:
    """Only validate keeps outcomes: convert writes nothing outside its output."""
    _box(tmp_path / "box.stl")
    robot = tmp_path / "robot.urdf"
    robot.write_text('<robot name="r"><link name="a"><collision><geometry><mesh filename="box.stl"/>'
                     '</geometry></collision></link></robot>')
    env = {**os.environ, "MODELKIT_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-m", "modelkit.cli", "convert", str(robot), "-o",
                           str(tmp_path / "out" / "r.xml")], capture_output=True, text=True, env=env,
                          check=False)
    assert done.returncode in (0, 1), done.stderr
    assert (tmp_path / "out" / "r.xml").exists()
    assert not (tmp_path / "cache").exists()


def test_two_names_of_one_file_are_two_meshes(cache: Path, tmp_path: Path) -> None:
    """The suffix as given picks the parser and the message names the file: a link named .dae to an
    STL is judged as COLLADA (and fails), the .stl link to the same bytes loads."""
    mesh = _box(tmp_path / "box.stl")
    as_dae = tmp_path / "box.dae"
    as_dae.symlink_to(mesh)
    assert meshfiles.mesh_problem(mesh) is None
    judged = meshfiles.mesh_problem(as_dae)
    assert judged is not None and "box.dae" in judged
    meshfiles.clear_mesh_cache()
    assert meshfiles.mesh_problem(mesh) is None
    assert meshfiles.mesh_problem(as_dae) == judged
