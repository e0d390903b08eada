"""A plain ``pip install modelkit`` (what the pre-commit hook installs) validates, trees and converts
without any engine, and ``verify`` then exits 2 with the line that installs what it needs.

The project is copied (tracked and untracked, not ignored files) into a temporary folder and
installed into a fresh virtualenv from PyPI or the index pip is configured with; pip's wheel cache
lives in pytest's cache directory, so later runs do not download again.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from modelkit.verify.engines.registry import install_line, missing_packages

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
TUTORIAL = ROOT / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
HEAVY = ("pybullet", "pinocchio", "matplotlib", "yourdfpy", "pydrake", "glfw", "OpenGL")


def _project_copy(dest: Path) -> Path:
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=ROOT, capture_output=True, check=True).stdout.decode().split("\0")
    for rel in filter(None, listed):
        src = ROOT / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)
    return dest


@pytest.fixture(scope="module")
def light_venv(tmp_path_factory: pytest.TempPathFactory, pytestconfig: pytest.Config) -> Path:
    base = tmp_path_factory.mktemp("light")
    project = _project_copy(base / "project")
    env_dir = base / "venv"
    venv.create(env_dir, with_pip=True)
    cache = getattr(pytestconfig, "cache", None)
    pip_cache = Path(cache.mkdir("modelkit-light-pip")) if cache is not None else base / "pip-cache"
    env = dict(os.environ, PIP_CACHE_DIR=os.environ.get("PIP_CACHE_DIR", str(pip_cache)),
               PIP_DISABLE_PIP_VERSION_CHECK="1")
    done = subprocess.run([str(env_dir / "bin" / "python"), "-m", "pip", "install", "-q", str(project)],
                          env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    return env_dir


def _run(env_dir: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    return subprocess.run([str(env_dir / "bin" / "modelkit"), *args], capture_output=True, text=True,
                          cwd=ROOT, env=env, timeout=300)


def test_the_light_install_has_no_engine(light_venv: Path) -> None:
    code = ("import importlib.util, json, sys; "
            f"print(json.dumps([m for m in {list(HEAVY)!r} if importlib.util.find_spec(m)]))")
    done = subprocess.run([str(light_venv / "bin" / "python"), "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_validate_tree_and_convert_work_without_engines(light_venv: Path, tmp_path: Path) -> None:
    body = TUTORIAL / "mobile_robot_pantilt.body"
    assert _run(light_venv, "validate", str(body)).returncode == 0
    tree = _run(light_venv, "tree", str(ROOT / "samples" / "smartcar" / "urdf" / "myrobot.urdf.xacro"))
    assert tree.returncode == 0 and "root Link: base_link" in tree.stdout, tree.stderr
    for suffix in (".xml", ".urdf", ".sdf"):
        done = _run(light_venv, "convert", str(body), "-o", str(tmp_path / f"robot{suffix}"))
        assert done.returncode == 0, done.stderr
        assert (tmp_path / f"robot{suffix}").stat().st_size > 0
    # MJCF is read through MuJoCo's C library (mujoco-core), also without the full bindings
    back = _run(light_venv, "validate", str(tmp_path / "robot.xml"))
    assert back.returncode == 0, back.stdout + back.stderr


def test_verify_without_the_extra_says_what_to_install(light_venv: Path) -> None:
    done = _run(light_venv, "verify", str(TUTORIAL / "mobile_robot_pantilt.body"))
    assert done.returncode == 2
    assert "MK950" in done.stderr and "pip install 'modelkit[verify]'" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr
    named = _run(light_venv, "verify", "--engines", "drake", str(TUTORIAL / "mobile_robot_pantilt.body"))
    assert named.returncode == 2 and "modelkit[drake]" in named.stderr, named.stderr


def test_missing_packages_names_only_what_the_run_needs() -> None:
    """In the full test environment nothing is missing; an unknown engine asks for nothing."""
    assert missing_packages(("mujoco", "pybullet", "pinocchio", "yourdfpy"), named=True, report=True) == {}
    assert missing_packages(("source",), named=True, report=False) == {}
    assert install_line({"pybullet": "verify", "pydrake": "drake"}) == "pip install 'modelkit[drake,verify]'"
    assert sys.version_info >= (3, 11)
