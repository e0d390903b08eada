"""The `modelkit-validate` pre-commit hook, driven through the real `pre-commit` tool.

`pre-commit try-repo HOOK_REPO modelkit-validate --files F` installs the hook repository into a
fresh virtualenv (pip, from PyPI or the index pip is configured with) and runs the hook in a
temporary git repository, as a user's commit would. The hook repository is a snapshot of this
project's working tree (tracked and untracked, not ignored files) committed into a temporary
git repository: `try-repo` on the project itself would only see committed files plus changes
to *tracked* ones (it copies them with `git add -u`), so a new, not yet committed file -
`.pre-commit-hooks.yaml` itself, or a new module - would be missing, and it would run git in
the project's checkout.

`try-repo` installs the hook into a throwaway store in a temporary directory on every call
(PRE_COMMIT_HOME is not used for it), so each call pays for a virtualenv and a `pip install` of
modelkit with numpy, lxml, trimesh, ... (9-16 s per call on a 2-core machine): the checks are
grouped into two calls. pip's wheel cache lives in pytest's cache directory so that later runs do not
download again (unless PIP_CACHE_DIR is set); pre-commit and virtualenv write under tmp_path.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from .conftest import PENDULUM_BODY

pytest.importorskip("pre_commit")

pytestmark = pytest.mark.slow

PROJECT_ROOT = Path(__file__).resolve().parents[1]
CORPUS = PROJECT_ROOT.parent / "shared" / "corpus"
CORPUS_PENDULUM = CORPUS / "choreonoid" / "share" / "model" / "misc" / "pendulum.body"
HOOK_ID = "modelkit-validate"

CLEAN_BODY = PENDULUM_BODY  # used when the shared corpus is not next to the checkout (CI)

# ARM's parent names a link that does not exist: an error on line 20 (the value of `parent`).
BROKEN_BODY = """\
format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: Broken
root_link: BASE
links:
  -
    name: BASE
    joint_type: fixed
    center_of_mass: [ 0, 0, 0 ]
    mass: 1.0
    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
    elements:
      - { type: Shape, geometry: { type: Box, size: [ 0.1, 0.1, 0.1 ] } }
  -
    name: ARM
    joint_type: revolute
    joint_axis: [ 1, 0, 0 ]
    translation: [ 0, 0, 0.1 ]
    parent: NO_SUCH_LINK
    center_of_mass: [ 0, 0, 0 ]
    mass: 1.0
    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
    elements:
      - { type: Shape, geometry: { type: Box, size: [ 0.1, 0.1, 0.1 ] } }
"""
BROKEN_LINE = 20
BROKEN_COLUMN = BROKEN_BODY.splitlines()[BROKEN_LINE - 1].index("NO_SUCH_LINK") + 1

# Project files that are never part of the hook repository, even if not git-ignored.
SKIPPED_PARTS = frozenset({".git", ".venv", "venv", "__pycache__", ".mypy_cache", ".ruff_cache",
                           ".pytest_cache", "build", "dist", "out"})


@dataclass
class Sandbox:
    """A hook repository, a repository to run it in, and the environment to run pre-commit with."""

    hook_repo: Path
    work_repo: Path
    env: dict[str, str]
    clean: str
    broken: str


def _git(args: list[str], cwd: Path, env: dict[str, str]) -> str:
    done = subprocess.run(["git", *args], cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"git {' '.join(args)} failed:\n{done.stdout}\n{done.stderr}"
    return done.stdout


def _project_files(env: dict[str, str]) -> list[Path]:
    """The files of the project's working tree: tracked and untracked-but-not-ignored (read-only
    git commands only); a copy of everything but caches and virtualenvs when it is no checkout."""
    if (PROJECT_ROOT / ".git").exists() and shutil.which("git"):
        listed = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            cwd=PROJECT_ROOT, env=env, stdin=subprocess.DEVNULL, capture_output=True, check=False)
        if listed.returncode == 0:
            names = [n for n in listed.stdout.decode("utf-8", "surrogateescape").split("\0") if n]
            return [Path(n) for n in names if not SKIPPED_PARTS.intersection(Path(n).parts)]
    out: list[Path] = []
    for path in PROJECT_ROOT.rglob("*"):
        relative = path.relative_to(PROJECT_ROOT)
        if path.is_file() and not SKIPPED_PARTS.intersection(relative.parts) \
                and not any(p.endswith(".egg-info") for p in relative.parts):
            out.append(relative)
    return out


def _isolated_env(base: Path, pip_cache: Path) -> dict[str, str]:
    """The environment for git and pre-commit: CI=true, no colour, no user or system git config,
    pre-commit's and virtualenv's files under `base`. The user's pip configuration (index,
    proxy, certificates: PIP_* and pip.conf) is kept, or the hook could not be installed."""
    tmp = base / "tmp"  # try-repo's store, pip's build directories
    tmp.mkdir()
    gitconfig = base / "gitconfig"
    gitconfig.write_text("[init]\n\tdefaultBranch = main\n[advice]\n\tdetachedHead = false\n")
    # GIT_DIR, GIT_INDEX_FILE, ... are set when the tests run inside a git hook: drop them.
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("GIT_", "PRE_COMMIT", "VIRTUALENV_"))
           and k not in {"PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "CONDA_PREFIX"}}
    env.setdefault("PIP_CACHE_DIR", str(pip_cache))
    env.update({
        "CI": "true",
        "TERM": "dumb",
        "NO_COLOR": "1",
        "TMPDIR": str(tmp),
        "PRE_COMMIT_HOME": str(base / "pre-commit-home"),
        "PRE_COMMIT_COLOR": "never",
        "PIP_NO_INPUT": "1",
        "PIP_PROGRESS_BAR": "off",
        "PIP_DISABLE_PIP_VERSION_CHECK": "1",
        "VIRTUALENV_OVERRIDE_APP_DATA": str(base / "virtualenv-app-data"),
        "GIT_CONFIG_GLOBAL": str(gitconfig),
        "GIT_CONFIG_NOSYSTEM": "1",
        "GIT_TERMINAL_PROMPT": "0",
        "GIT_AUTHOR_NAME": "modelkit tests",
        "GIT_AUTHOR_EMAIL": "tests@modelkit.invalid",
        "GIT_COMMITTER_NAME": "modelkit tests",
        "GIT_COMMITTER_EMAIL": "tests@modelkit.invalid",
    })
    # pre-commit must run from this interpreter's environment, whatever PATH says.
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", os.defpath)])
    return env


def _init_repo(path: Path, env: dict[str, str]) -> None:
    path.mkdir(parents=True, exist_ok=True)
    _git(["init", "-q"], path, env)
    _git(["config", "user.name", "modelkit tests"], path, env)
    _git(["config", "user.email", "tests@modelkit.invalid"], path, env)
    _git(["config", "commit.gpgsign", "false"], path, env)


def _pip_cache(config: pytest.Config, fallback: Path) -> Path:
    cache = getattr(config, "cache", None)
    if cache is None:  # -p no:cacheprovider
        return fallback
    return Path(cache.mkdir("modelkit-precommit-pip"))


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory: pytest.TempPathFactory, pytestconfig: pytest.Config) -> Iterator[Sandbox]:
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    base = tmp_path_factory.mktemp("precommit")
    env = _isolated_env(base, _pip_cache(pytestconfig, base / "pip-cache"))

    hook_repo = base / "hook-repo"
    _init_repo(hook_repo, env)
    for relative in _project_files(env):
        source = PROJECT_ROOT / relative
        if not source.is_file():  # listed but deleted in the working tree
            continue
        target = hook_repo / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target)
    assert (hook_repo / ".pre-commit-hooks.yaml").is_file()
    _git(["add", "-A"], hook_repo, env)
    _git(["commit", "-q", "--no-verify", "-m", "snapshot of the modelkit working tree"], hook_repo, env)

    work_repo = base / "work-repo"
    _init_repo(work_repo, env)
    (work_repo / "models").mkdir()
    clean = "models/pendulum.body"
    if CORPUS_PENDULUM.is_file():
        shutil.copyfile(CORPUS_PENDULUM, work_repo / clean)
    else:
        (work_repo / clean).write_text(CLEAN_BODY)
    broken = "models/broken.body"
    (work_repo / broken).write_text(BROKEN_BODY)
    (work_repo / "README.txt").write_text("not a model\n")
    _git(["add", "-A"], work_repo, env)
    _git(["commit", "-q", "--no-verify", "-m", "models"], work_repo, env)
    yield Sandbox(hook_repo, work_repo, env, clean, broken)


def _try_repo(box: Sandbox, *files: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "pre_commit", "try-repo", str(box.hook_repo), HOOK_ID,
               "--color", "never", "--verbose", "--files", *files]
    done = subprocess.run(command, cwd=box.work_repo, env=box.env, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, check=False, timeout=1800)
    if done.returncode not in (0, 1):
        pre_commit_log = Path(box.env["PRE_COMMIT_HOME"]) / "pre-commit.log"
        extra = pre_commit_log.read_text(errors="replace") if pre_commit_log.is_file() else ""
        pytest.fail(f"pre-commit could not run the hook (exit {done.returncode}):\n"
                    f"{done.stdout}\n{done.stderr}\n{extra}")
    return done


def test_clean_file_passes_and_other_files_are_not_checked(sandbox: Sandbox) -> None:
    done = _try_repo(sandbox, sandbox.clean, "README.txt")
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert "modelkit validate" in output and "Passed" in output, output
    # --verbose shows the hook's own summary: README.txt was filtered out by `files:`.
    assert "1 file(s) checked: 0 error(s), 0 warning(s)" in output, output


def test_broken_file_fails_with_the_diagnostic(sandbox: Sandbox) -> None:
    done = _try_repo(sandbox, sandbox.clean, sandbox.broken)
    output = done.stdout + done.stderr
    assert done.returncode == 1, output
    assert "Failed" in output, output
    location = f"{sandbox.broken}:{BROKEN_LINE}:{BROKEN_COLUMN}: error "
    lines = [line for line in output.splitlines() if line.startswith(location)]
    assert lines, f"no diagnostic at {location!r} in:\n{output}"
    code = lines[0][len(location):].split()[0]
    assert code == "MK202", lines[0]
    assert "NO_SUCH_LINK" in lines[0]
    assert not any(line.startswith(sandbox.clean + ":") for line in output.splitlines()), output
