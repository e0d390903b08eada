"""`modelkit verify` layers 1–3 against the real engines (MuJoCo, Pinocchio, yourdfpy; no mocks).

PyBullet and Drake have their own tests (test_verify_pybullet.py, test_verify_drake.py); here the
engines are the ones whose adapters this file's modules own, so a failure points at them.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from modelkit.verify import api
from modelkit.verify.api import verify
from modelkit.verify.report import report_json
from tests.conftest import CORPUS, REPO, TUTORIAL

ENGINES = ("mujoco", "pinocchio", "yourdfpy")
PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
CHOREONOID = CORPUS / "choreonoid" / "share" / "model"
SCHEMA = json.loads((REPO / "schemas" / "verify-report.schema.json").read_text())

MODELS = [
    TUTORIAL / "mobile_robot_primitive.body",
    PANTILT,
    TUTORIAL / "mobile_robot_sensors.body",
    TUTORIAL / "mobile_robot_tracks.body",
    CHOREONOID / "PA10" / "PA10.body",
    CHOREONOID / "GR001" / "GR001.body",
    CORPUS / "urdf_tutorial" / "urdf" / "07-physics.urdf",
    CORPUS / "sdformat_urdf" / "sdformat_test_files" / "models" / "graph_tree" / "graph_tree.sdf",
]


def run(source: Path, out: Path, **kwargs: object) -> api.VerifyReport:
    """Layers 1-3 (layer 4, the driven scenarios, has its own tests: test_verify_layer4.py)."""
    kwargs.setdefault("driven", False)
    return verify(source, out, ENGINES, replay=False, **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize("source", MODELS, ids=lambda p: p.name)
def test_layers_1_to_3_pass(source: Path, tmp_path: Path) -> None:
    report = run(source, tmp_path)
    assert report.errors == []
    assert [f"{c.engine} {c.quantity} {c.where}: {c.detail}" for c in report.failed] == []
    seen = {(c.layer, c.engine) for c in report.checks}
    for engine in ("mujoco", "pinocchio", "yourdfpy"):
        assert (1, engine) in seen and (2, engine) in seen
    assert (3, "mujoco") in seen  # the mass matrix and bias against Pinocchio on the source
    assert {c.quantity for c in report.checks if c.engine == "mujoco"} >= {
        "link-set", "joint-set", "joint-type", "axis", "limits", "mass", "com", "inertia",
        "pose-position", "pose-rotation", "mass-matrix", "bias"}
    assert any(s.engine == "yourdfpy" and s.layer == 3 for s in report.skips)
    assert "welded to the world at the identity" in report.base


def test_tracks_say_what_is_skipped(tmp_path: Path) -> None:
    report = run(TUTORIAL / "mobile_robot_tracks.body", tmp_path)
    tracks = [s for s in report.skips if "continuous track not verified" in s.reason]
    assert [(s.layer, s.engine) for s in tracks] == [(0, "all"), (0, "all")]
    assert "LeftTracks" in tracks[0].reason and "RightTracks" in tracks[1].reason
    assert "approximated by rollers" in report.reference


def test_armature_the_urdf_cannot_hold_is_said(tmp_path: Path) -> None:
    # PA10's rotor inertias reach MuJoCo (armature) and Pinocchio, not URDF: said, per engine
    from modelkit.api import validate

    source = CHOREONOID / "PA10" / "PA10.body"
    with_armature = [j.name for j in validate(source).robots[0].joints if j.armature != 0.0]
    assert with_armature  # the case this test is about
    report = verify(source, tmp_path, ("mujoco", "pinocchio", "pybullet"), replay=False)
    assert report.exit_code == 0
    said = [s for s in report.skips if "armature" in s.reason]
    assert [s.engine for s in said] == ["pybullet"]  # MuJoCo holds it: compared with it, not excused
    assert all(name in said[0].reason for name in with_armature) and "MK820" in said[0].reason
    assert any(c.layer == 3 and c.engine == "mujoco" and c.quantity == "mass-matrix" for c in report.checks)


def test_report_json_valid_and_reproducible(tmp_path: Path) -> None:
    a = run(PANTILT, tmp_path / "a")
    b = run(PANTILT, tmp_path / "b")
    ja, jb = report_json(a), report_json(b)
    jsonschema.validate(json.loads(ja), SCHEMA)
    assert ja == jb
    data = json.loads(ja)
    assert data["verdict"] == "pass" and data["exit_code"] == 0
    assert data["engines"]["mujoco"]["version"] and data["engines"]["pinocchio"]["version"]
    assert data["files"] == {"mjcf": "mobile_robot_pantilt.xml", "urdf": "mobile_robot_pantilt.urdf"}


def test_missing_engine_is_skipped_not_failed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(api.ENGINES, "nosuch", "modelkit.verify.engine_nosuch:load")
    monkeypatch.setitem(api.INPUTS, "nosuch", "mjcf")
    report = verify(PANTILT, tmp_path, ("mujoco", "pinocchio", "nosuch"), replay=False)
    assert report.exit_code == 0
    assert any(s.engine == "nosuch" and "not installed" in s.reason for s in report.skips)


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "modelkit.cli", "verify", *args], capture_output=True,
                          text=True, cwd=REPO, check=False)


def _mjcf(tmp_path: Path) -> Path:
    from modelkit.api import load
    from modelkit.convert.api import write
    from modelkit.verify.api import welded_copy

    path = tmp_path / "given" / "pantilt.xml"
    write(welded_copy(load(PANTILT))[0], path)
    return path


def test_cli_pass_writes_report(tmp_path: Path) -> None:
    out = tmp_path / "r"
    result = _cli(str(PANTILT), "-o", str(out), "--engines", ",".join(ENGINES), "--no-replay")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "PASS" in result.stdout and "mass-matrix" in result.stdout
    jsonschema.validate(json.loads((out / "report.json").read_text()), SCHEMA)


def test_cli_given_mjcf_with_a_wrong_mass_fails(tmp_path: Path) -> None:
    given = _mjcf(tmp_path)
    ok = _cli(str(PANTILT), "--mjcf", str(given), "--engines", "mujoco,pinocchio", "--no-replay")
    assert ok.returncode == 0, ok.stdout
    text = given.read_text()
    # PanLink's COM lies on the vertical pan axis, so with the base welded its mass changes no joint
    # torque: layer 1 must catch it. Its Izz enters M[pan, pan]: layer 3a must catch that.
    pattern = r'(<body name="PanLink".*?<inertial pos="0 0 0.03" mass=")1(" diaginertia="0.002 0.002 )0.003'
    edited = re.sub(pattern, r"\g<1>1.01\g<2>0.0031", text, flags=re.S)
    assert edited != text
    given.write_text(edited)
    bad = _cli(str(PANTILT), "--mjcf", str(given), "--engines", "mujoco,pinocchio", "--no-replay")
    assert bad.returncode == 1, bad.stdout
    assert re.search(r"FAIL layer 1 mujoco mass PanLink: mass 1 kg read back as 1.01 kg", bad.stdout)
    assert re.search(r"FAIL layer 1 mujoco inertia PanLink", bad.stdout)
    assert re.search(r"FAIL layer 3 mujoco mass-matrix PanJoint: sample \d+: M\[2,2\]", bad.stdout)


def test_cli_unreadable_input_exits_2(tmp_path: Path) -> None:
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'>")
    assert _cli(str(broken), "--engines", "mujoco").returncode == 2
    assert _cli(str(tmp_path / "absent.body")).returncode == 2
    assert _cli(str(PANTILT), "--engines", "nosuch").returncode == 2


def test_validate_and_convert_do_not_import_engines() -> None:
    code = ("import sys, modelkit.cli, modelkit.api, modelkit.convert.api; "
            "print(sorted(m for m in ('mujoco', 'pinocchio', 'pybullet', 'pydrake') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, check=True)
    assert out.stdout.strip() == "[]"


def _emitted_quantities() -> set[str]:
    """Every quantity a layer can emit: the third argument of each ``Check(...)`` and ``Worst.check(...)``
    call in ``modelkit/verify``, and the second of layer 4's ``record(...)`` (a literal, so that this
    list cannot miss one)."""
    import ast

    found: set[str] = set()
    for path in sorted((REPO / "modelkit" / "verify").rglob("*.py")):  # the subpackages too
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call) or len(node.args) < 2:
                continue
            func = node.func
            if isinstance(func, ast.Name) and func.id == "record" and path.name == "layer4.py":
                quantity = node.args[1]
                assert isinstance(quantity, ast.Constant) and isinstance(quantity.value, str), (
                    f"{path.name}:{node.lineno}: a check's quantity must be a literal")
                found.add(quantity.value)
                continue
            if len(node.args) < 3:
                continue
            if (isinstance(func, ast.Name) and func.id == "Check") or (
                    isinstance(func, ast.Attribute) and func.attr == "check"):
                quantity = node.args[2]
                if isinstance(quantity, ast.Name) and quantity.id == "quantity":
                    continue  # a helper forwarding its caller's literal (layers.Worst.check)
                assert isinstance(quantity, ast.Constant) and isinstance(quantity.value, str), (
                    f"{path.name}:{node.lineno}: a check's quantity must be a literal")
                found.add(quantity.value)
    return found


def test_every_emitted_quantity_is_in_the_schema() -> None:
    enum = set(SCHEMA["$defs"]["check"]["properties"]["quantity"]["enum"])
    emitted = _emitted_quantities()
    assert {"load", "engine-error", "stability", "replay", "shape-pose", "limits"} <= emitted
    assert emitted - enum == set()
    assert enum - emitted == set()  # no stale entry either


def test_cli_default_engines_are_the_api_default() -> None:
    from modelkit.cli import verify as command

    (option,) = [p for p in command.params if p.name == "engines"]
    assert tuple(str(option.default).split(",")) == api.DEFAULT_ENGINES
    assert "drake-urdf" in api.DEFAULT_ENGINES


def test_two_full_runs_write_the_same_report(tmp_path: Path) -> None:
    """Every layer (the replay and the driven scenarios included): report.json is the same bytes from
    run to run (wall times and engine speeds are printed, never written)."""
    from modelkit.verify.many import save

    texts = []
    for name in ("a", "b"):
        report = verify(PANTILT, tmp_path / name, ("mujoco", "pybullet", "pinocchio"))
        assert report.verdict == "pass", [c.detail for c in report.failed]
        assert any(c.layer == 4 for c in report.checks) and any(c.layer == 3 for c in report.checks)
        save(report, tmp_path / name)
        texts.append((tmp_path / name / "report.json").read_bytes())
    assert texts[0] == texts[1]


def _cli_on_a_terminal(*args: str, env: dict[str, str]) -> str:
    """The CLI's whole output when stdout and stderr are a terminal (a pseudo-terminal)."""
    import os
    import pty

    pid, fd = pty.fork()
    if pid == 0:  # pragma: no cover (the child)
        os.chdir(REPO)
        os.execve(sys.executable, [sys.executable, "-m", "modelkit.cli", "verify", *args], env)
    chunks = []
    while True:
        try:
            data = os.read(fd, 65536)
        except OSError:
            break
        if not data:
            break
        chunks.append(data)
    os.waitpid(pid, 0)
    return b"".join(chunks).decode()


def test_one_model_shows_progress_on_a_terminal_only(tmp_path: Path) -> None:
    import os

    args = (str(PANTILT), "--engines", "mujoco,pybullet", "--no-replay", "-o", str(tmp_path / "a"))
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    shown = _cli_on_a_terminal(*args, env=env)
    assert "verify: layer 4: driving the robot in MuJoCo and PyBullet ..." in shown
    assert "verify: writing the report" in shown and "report: " in shown
    quiet = _cli_on_a_terminal(*args, env={**env, "CI": "true"})
    assert "verify: " not in quiet and "PASS" in quiet
    piped = _cli(*args)  # not a terminal
    assert "verify: " not in piped.stdout + piped.stderr and piped.returncode == 0


def test_a_check_whose_error_is_nan_fails_and_is_printed() -> None:
    """An engine that blew up gives NaN errors (a fuzz mutant's 3.5e38 kg wheel in PyBullet's layer 4):
    the check fails, and the table and report.json say so (the table raised ValueError, MK899)."""
    from modelkit.verify.engines.protocol import Check
    from modelkit.verify.report import VerifyReport, render_table

    report = VerifyReport("x.body")
    report.checks.append(Check(4, "pybullet", "noslip-position", "straight", float("nan"), 0.015, "path"))
    assert not report.checks[0].passed and report.exit_code == 1
    table = render_table(report)
    assert "nan" in table and "FAIL" in table
    assert json.loads(report_json(report))["checks"][0]["error"] is None
