"""Issue 18 §1: nothing lost, nothing written where it must not be (convert, verify).

Every case runs the real command on real files in a temporary folder; where signals are involved
the CLI runs as a real subprocess and is signalled as a user (or a scheduler) would.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit import safewrite
from modelkit.api import validate
from modelkit.cli import main
from modelkit.convert.commit import STAGING_PREFIX

from .conftest import PENDULUM_BODY, REPO, TUTORIAL

MASS = ('<inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
        "</inertial>")


def stl(seed: int, triangles: int = 1) -> bytes:
    """A binary STL of ``triangles`` triangles, different for each seed."""
    import struct

    head = b"test".ljust(80, b" ") + struct.pack("<I", triangles)
    x, y = 1 + seed * 1e-3, 1.0
    return head + b"".join(struct.pack("<12fH", 0, 0, 1, 0, 0, 0, x, 0, 0, 0, y + k * 1e-3, 0, 0)
                           for k in range(triangles))


def urdf_with_meshes(folder: Path, count: int, name: str = "robot", size: int = 0) -> Path:
    """A URDF whose links each have their own mesh file (``size`` pads each mesh to that many
    bytes, so that a commit takes long enough to be caught in the middle)."""
    folder.mkdir(parents=True, exist_ok=True)
    links, joints = [], []
    for i in range(count):
        data = stl(i, max(1, (size - 84) // 50))
        (folder / f"m{i}.stl").write_bytes(data)
        links.append(f'<link name="l{i}">{MASS}<visual><geometry><mesh filename="m{i}.stl"/></geometry>'
                     "</visual></link>")
        if i:
            joints.append(f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/>'
                          f'<child link="l{i}"/></joint>')
    path = folder / f"{name}.urdf"
    path.write_text(f'<robot name="{name}">' + "".join(links + joints) + "</robot>\n")
    return path


def run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(main, list(args))
    assert "Traceback" not in result.output, result.output
    return result.exit_code, result.output


def cli(*args: str) -> list[str]:
    return [sys.executable, "-c", "from modelkit.cli import main; main()", *args]


def env() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=str(REPO), CI="true")


def files_under(folder: Path) -> list[str]:
    if not folder.exists():
        return []
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


# ---------------------------------------------------------------- --report goes through the guard

def test_report_onto_an_input_mesh_is_refused_and_nothing_is_written(tmp_path: Path) -> None:
    source = urdf_with_meshes(tmp_path / "in", 2)
    mesh = tmp_path / "in" / "m0.stl"
    before = mesh.read_bytes()
    code, out = run("convert", str(source), "-o", str(tmp_path / "out" / "robot.xml"), "--report", str(mesh))
    assert code == 2 and "MK891" in out
    assert mesh.read_bytes() == before
    assert files_under(tmp_path / "out") == []
    # with --force too: an input is never overwritten
    code, out = run("convert", str(source), "-o", str(tmp_path / "out" / "robot.xml"), "--report", str(mesh),
                    "--force")
    assert code == 2 and "MK891" in out and mesh.read_bytes() == before


def test_report_onto_the_model_being_written_is_refused(tmp_path: Path) -> None:
    source = urdf_with_meshes(tmp_path / "in", 1)
    model = tmp_path / "out" / "robot.xml"
    code, out = run("convert", str(source), "-o", str(model), "--report", str(model))
    assert code == 2 and "MK897" in out
    assert files_under(tmp_path / "out") == []
    # and onto a mesh it writes, spelled another way
    code, out = run("convert", str(source), "-o", str(model), "--report",
                    str(tmp_path / "out" / "meshes" / ".." / "meshes" / "m0.stl"))
    assert code == 2 and "MK897" in out and files_under(tmp_path / "out") == []


def test_an_existing_report_needs_force(tmp_path: Path) -> None:
    source = urdf_with_meshes(tmp_path / "in", 1)
    report = tmp_path / "notes.json"
    report.write_text("mine\n")
    model = tmp_path / "out" / "robot.xml"
    code, out = run("convert", str(source), "-o", str(model), "--report", str(report))
    assert code == 2 and "MK890" in out and str(report) in out
    assert report.read_text() == "mine\n" and files_under(tmp_path / "out") == []  # checked before anything
    code, out = run("convert", str(source), "-o", str(model), "--report", str(report), "--force")
    assert code == 0, out
    assert json.loads(report.read_text())["outputs"] == [str(model)] and model.is_file()


# ---------------------------------------------------------------- every file a reader opened is protected

def test_mjcf_include_is_protected_with_force(tmp_path: Path) -> None:
    part = tmp_path / "part.xml"
    part.write_text('<mujoco><worldbody><body name="b"><freejoint/><geom type="box" size=".1 .1 .1"/>'
                    "</body></worldbody></mujoco>\n")
    main_file = tmp_path / "main.xml"
    main_file.write_text('<mujoco model="m"><include file="part.xml"/></mujoco>\n')
    assert part.resolve() in {Path(f.path).resolve() for f in validate(main_file).opened}
    before = part.read_bytes()
    code, out = run("convert", str(main_file), "-o", str(part), "--force")
    assert code == 2 and "MK891" in out and part.read_bytes() == before


def test_xacro_include_is_protected_with_force(tmp_path: Path) -> None:
    part = tmp_path / "part.urdf"
    part.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    f'<link name="a">{MASS}</link></robot>\n')
    top = tmp_path / "main.urdf.xacro"
    top.write_text('<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   '<xacro:include filename="part.urdf"/></robot>\n')
    before = part.read_bytes()
    code, out = run("convert", str(top), "-o", str(part), "--force")
    assert code == 2 and "MK891" in out and part.read_bytes() == before


def test_body_subbody_is_protected_with_force_and_resources_are_recorded(tmp_path: Path) -> None:
    arm = tmp_path / "arm.body"
    arm.write_text(PENDULUM_BODY.replace("name: Pendulum", "name: Arm"))
    (tmp_path / "parts.yaml").write_text("- { type: Shape, geometry: { type: Box, size: [ 0.1, 0.2, 0.3 ] } }"
                                         "\n")
    top = tmp_path / "robot.body"
    shape = ("      - { type: Shape, translation: [ 0, 0, 0.1 ], "
             "geometry: { type: Box, size: [ 0.2, 0.2, 0.2 ] } }")
    top.write_text(PENDULUM_BODY.replace(shape, "      - { type: Resource, uri: parts.yaml }")
                   + "  - { type: SubBody, uri: arm.body, parent: ARM, prefix: R_ }\n")
    opened = {Path(f.path).name for f in validate(top).opened}
    assert {"robot.body", "arm.body", "parts.yaml"} <= opened, opened
    before = arm.read_bytes()
    code, out = run("convert", str(top), "-o", str(arm), "--force")
    assert code == 2 and "MK891" in out and arm.read_bytes() == before


def test_a_hard_link_to_an_input_is_the_input(tmp_path: Path) -> None:
    source = urdf_with_meshes(tmp_path / "in", 1)
    (tmp_path / "out").mkdir()
    alias = tmp_path / "out" / "robot.urdf"
    os.link(source, alias)
    before = source.read_bytes()
    code, out = run("convert", str(source), "-o", str(alias), "--force")
    assert code == 2 and "MK891" in out and source.read_bytes() == before
    assert files_under(tmp_path / "out") == ["robot.urdf"]


# ---------------------------------------------------------------- the staged commit

def _commit_under_signal(tmp_path: Path, sig: int, model: str = "robot.xml") -> tuple[int, str, Path]:
    """Convert a 400-mesh model in a subprocess; send ``sig`` as soon as the commit starts moving
    files into place (the first mesh is there)."""
    source = urdf_with_meshes(tmp_path / "in", 400, size=20_000)
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    proc = subprocess.Popen(cli("convert", str(source), "-o", str(out / model), "--force"), env=env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120  # staging 400 meshes takes seconds, more on a loaded machine
    while time.monotonic() < deadline and proc.poll() is None:
        if (out / "meshes").is_dir() and any((out / "meshes").iterdir()):
            break
        time.sleep(0.0002)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    return proc.returncode, err.decode(), out


def _model_has_its_meshes(out: Path, model: str) -> None:
    path = out / model
    if path.exists():
        text = path.read_text()
        meshdir = re.search(r'meshdir="([^"]+)"', text)  # the MJCF's mesh files are relative to it
        folder = out / meshdir.group(1) if meshdir else out
        for name in re.findall(r'file="([^"]+)"', text):
            assert (folder / name).is_file(), f"{model} is there without {name}"


def test_kill_9_mid_commit_leaves_no_model_without_meshes_and_the_next_run_cleans_up(tmp_path: Path) -> None:
    code, _, out = _commit_under_signal(tmp_path, signal.SIGKILL, "a.xml")  # sorts before meshes/
    assert code == -signal.SIGKILL
    _model_has_its_meshes(out, "a.xml")
    staging = [n for n in os.listdir(out) if n.startswith(STAGING_PREFIX)]
    placed = len(list((out / "meshes").iterdir())) if (out / "meshes").is_dir() else 0
    print(f"killed with {placed} of 400 meshes in place, model there: {(out / 'a.xml').exists()}")
    assert staging and 0 < placed < 400, "the kill did not come in the middle of the commit"
    again = subprocess.run(cli("convert", str(tmp_path / "in" / "robot.urdf"), "-o", str(out / "a.xml"),
                               "--force", "-q"), env=env(), capture_output=True)
    assert again.returncode == 0, again.stderr.decode()
    assert [n for n in os.listdir(out) if n.startswith(STAGING_PREFIX)] == []
    assert not [p for p in out.rglob("*.tmp")]
    _model_has_its_meshes(out, "a.xml")
    assert len(list((out / "meshes").iterdir())) == 400


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_mid_commit_undoes_it(tmp_path: Path, sig: int, code: int) -> None:
    status, err, out = _commit_under_signal(tmp_path, sig)
    assert status == code, err
    assert "Traceback" not in err and "MK896" in err and err.count("\n") <= 3, err
    assert files_under(out) == []  # the folder existed before: emptied, kept


def test_two_converts_into_one_folder_one_wins(tmp_path: Path) -> None:
    a = urdf_with_meshes(tmp_path / "a", 50, name="a")
    b = urdf_with_meshes(tmp_path / "b", 50, name="b")
    out = tmp_path / "out" / "robot.urdf"
    procs = [subprocess.Popen(cli("convert", str(src), "-o", str(out), "-q"), env=env(),
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) for src in (a, b)]
    results = [(p.wait(timeout=60), p.stderr.read().decode() if p.stderr else "") for p in procs]
    codes = sorted(code for code, _ in results)
    assert codes == [0, 2], results
    winner = (a, b)[[code for code, _ in results].index(0)]
    loser_err = next(err for code, err in results if code == 2)
    assert "MK890" in loser_err and "Traceback" not in loser_err
    assert f'name="{winner.stem}"' in out.read_text()
    _model_has_its_meshes(out.parent, "robot.urdf")
    assert [n for n in os.listdir(out.parent) if n.startswith(STAGING_PREFIX)] == []


def test_a_failed_forced_commit_brings_the_replaced_files_back(tmp_path: Path) -> None:
    from modelkit.convert.commit import CommitRefused, Entry, commit

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "a.stl").write_bytes(b"old mesh")
    (tmp_path / "robot.xml").mkdir()  # the model cannot go where a folder is
    entries = [Entry(tmp_path, "meshes/a.stl", b"new mesh", "mesh"),
               Entry(tmp_path, "meshes/b.stl", b"b", "mesh"),
               Entry(tmp_path, "robot.xml", b"<mujoco/>", "model")]
    with pytest.raises(CommitRefused) as caught:  # MK892: not a regular file
        commit(entries, force=True)
    assert caught.value.diagnostic.code == "MK892"
    assert (tmp_path / "meshes" / "a.stl").read_bytes() == b"old mesh"
    assert files_under(tmp_path) == ["meshes", "meshes/a.stl", "robot.xml"]


# ---------------------------------------------------------------- verify

SMALL = TUTORIAL / "mobile_robot_primitive.body"
QUICK = ("--no-driven", "--no-replay", "--engines", "mujoco")


@pytest.mark.parametrize("name", ["report.json", "pictures"])
def test_verify_does_not_write_through_a_symlink(tmp_path: Path, name: str) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep.txt").write_text("mine\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / name).symlink_to(elsewhere / "keep.txt" if name == "report.json" else elsewhere)
    code, text = run("verify", str(SMALL), "-o", str(out), *QUICK)
    assert code == 2 and "MK892" in text and "symbolic link" in text
    assert sorted(os.listdir(elsewhere)) == ["keep.txt"] and (elsewhere / "keep.txt").read_text() == "mine\n"


def test_verify_does_not_write_a_model_through_a_symlink(tmp_path: Path) -> None:
    elsewhere = tmp_path / "keep.xml"
    elsewhere.write_text("mine\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / f"{SMALL.stem}.xml").symlink_to(elsewhere)
    code, text = run("verify", str(SMALL), "-o", str(out), *QUICK)
    assert code == 2 and "cannot write" in text, text
    assert elsewhere.read_text() == "mine\n"


def test_safewrite_refuses_links_and_escapes_and_writes_atomically(tmp_path: Path) -> None:
    root = tmp_path / "out"
    (tmp_path / "elsewhere").mkdir()
    root.mkdir()
    (root / "plots").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(safewrite.UnsafeOutput):
        safewrite.write_bytes(root, root / "plots" / "a.png", b"x")
    with pytest.raises(safewrite.UnsafeOutput):
        safewrite.write_bytes(root, root / ".." / "escape.txt", b"x")
    assert os.listdir(tmp_path / "elsewhere") == [] and not (tmp_path / "escape.txt").exists()
    safewrite.write_bytes(root, root / "a" / "b.txt", b"data")
    assert (root / "a" / "b.txt").read_bytes() == b"data" and os.listdir(root / "a") == ["b.txt"]


def _wait_for(predicate: Callable[[], bool], seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


def test_sigint_to_verify_exits_130_and_removes_what_it_wrote(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.Popen(cli("verify", str(SMALL), "-o", str(out), "--no-driven"), env=env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert _wait_for(lambda: any(out.glob("*.xml")), 30), "verify wrote nothing to interrupt"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    text = err.decode()
    assert proc.returncode == 130, text
    assert "Traceback" not in text and "MK896" in text
    assert not out.exists()  # verify made the folder: all of it goes


def _descendants(pid: int) -> set[int]:
    found: set[int] = set()
    todo = [pid]
    while todo:
        current = todo.pop()
        for task in Path(f"/proc/{current}/task").glob("*"):
            try:
                children = (task / "children").read_text().split()
            except OSError:
                continue
            for child in map(int, children):
                if child not in found:
                    found.add(child)
                    todo.append(child)
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_kill_9_of_verify_many_takes_its_children_along(tmp_path: Path) -> None:
    out = tmp_path / "out"
    models = [str(TUTORIAL / "mobile_robot_primitive.body"), str(TUTORIAL / "mobile_robot.body")]
    proc = subprocess.Popen(cli("verify", *models, "-o", str(out), "-j", "2"), env=env(),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    # both workers running, and at least one of them with a child of its own (PyBullet, pictures, plots)
    assert _wait_for(lambda: len(_descendants(proc.pid)) >= 3, 30), "verify started no children"
    children = _descendants(proc.pid)
    proc.kill()
    proc.wait(timeout=10)
    assert _wait_for(lambda: not any(_alive(c) for c in children), 2.0), \
        [c for c in children if _alive(c)]
    time.sleep(1.0)  # nothing writes a report afterwards
    assert not list(out.rglob("report.json")) and not list(out.rglob("summary.json"))


def test_a_swallowed_interruption_is_remembered() -> None:
    """A library that catches the exception (Drake's module initialisation logs and ignores it) does
    not make the run forget the signal: ``check`` raises it again before the next step."""
    from modelkit.interrupt import Interrupted, check, interruptible, pending

    with interruptible():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)
        except BaseException:  # the swallowing library
            pass
        assert pending() == signal.SIGTERM
        with pytest.raises(Interrupted) as caught:
            check()
    assert caught.value.exit_code == 143


def test_a_signal_whose_handler_runs_inside_a_held_step_is_raised_after_it() -> None:
    """A signal that arrives just before a held step has its Python handler run inside the step
    (Python runs handlers between bytecodes, not when the kernel delivers): the step completes and
    the interruption comes when it ends. This was a real leak: one mesh of 400 left after SIGTERM."""
    from modelkit.interrupt import Interrupted, interruptible, signals_held

    steps = []
    with interruptible():
        handler = signal.getsignal(signal.SIGTERM)
        assert callable(handler)
        with pytest.raises(Interrupted), signals_held():
            handler(signal.SIGTERM, None)  # what Python does at the next bytecode
            steps.append("moved")
            steps.append("recorded")
    assert steps == ["moved", "recorded"]
