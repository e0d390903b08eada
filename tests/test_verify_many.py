"""`modelkit verify` on many models: parallel processes, one report folder each, summary.json/html,
a crashing or broken model not stopping the others, exit codes, progress only on a terminal, the
same numbers whatever -j, and the same job through a local Ray cluster. Real runs, no mocks: the
crash is a real segfault in an engine plug-in registered for the test."""

from __future__ import annotations

import ctypes
import json
import os
import pty
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from modelkit.verify import api, many
from tests.conftest import REPO, TUTORIAL

PRIMITIVE = TUTORIAL / "mobile_robot_primitive.body"
PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
TRACKS = TUTORIAL / "mobile_robot_tracks.body"
QUICK = {"engines": ["mujoco", "pinocchio"], "replay": False, "configurations": 5, "samples": 3}
QUICK_CLI = ["--engines", "mujoco,pinocchio", "--no-replay"]


def _segfault(model: Any, renames: Any, *, root: str) -> Any:
    """An engine plug-in that crashes the process as a broken native engine does."""
    return ctypes.string_at(0)  # reads address 0: SIGSEGV


def _broken(tmp_path: Path) -> Path:
    path = tmp_path / "broken.urdf"
    path.write_text("<robot name='x'><link name='a'>")
    return path


def _cli(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "modelkit.cli", "verify", *args], capture_output=True,
                          text=True, cwd=REPO, check=False, env=env)


def _numbers(report: Path) -> list[tuple[Any, ...]]:
    """A report's graded numbers (the details also hold wall-clock rates and the output path)."""
    data = json.loads(report.read_text())
    return [(c["layer"], c["engine"], c["quantity"], c["where"], c["error"], c["tolerance"], c["passed"])
            for c in data["checks"]]


def test_folder_names_are_distinct_readable_and_from_the_paths_alone() -> None:
    paths = [Path("a/robot.urdf"), Path("b/robot.urdf"), Path("a/robot.body"), Path("x/arm.urdf.xacro"),
             Path("summary.json.urdf"), Path("c d/wheel (1).sdf")]
    names = many.folder_names(paths)
    assert names == ["a_robot.urdf", "b_robot.urdf", "robot.body", "arm", "summary.json.urdf", "wheel__1_"]
    assert names[4] not in many.RESERVED and len({n.lower() for n in names}) == len(names)
    assert many.folder_names(paths) == names  # deterministic
    assert many.folder_names([Path("robot.urdf"), Path("robot.body")]) == ["robot.urdf", "robot.body"]
    assert many.folder_names([PRIMITIVE, PANTILT]) == ["mobile_robot_primitive", "mobile_robot_pantilt"]


def test_a_directory_gives_the_model_files_directly_inside_it(tmp_path: Path) -> None:
    shutil.copy(PRIMITIVE, tmp_path / "b.body")
    shutil.copy(PANTILT, tmp_path / "a.body")
    (tmp_path / "robot.xml").write_text("<robot name='r'><link name='l'/></robot>")
    (tmp_path / "package.xml").write_text("<package><name>p</name></package>")  # not a model
    (tmp_path / "notes.txt").write_text("hello")
    (tmp_path / "sub").mkdir()
    shutil.copy(PRIMITIVE, tmp_path / "sub" / "c.body")  # not recursive
    found = many.expand_inputs([tmp_path, tmp_path / "a.body"])  # a.body named twice: verified once
    assert [p.name for p in found] == ["a.body", "b.body", "robot.xml"]


def test_many_models_in_parallel_one_crashing_one_raising_one_broken(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(api.ENGINES, "segfault", "tests.test_verify_many:_segfault")
    monkeypatch.setitem(api.INPUTS, "segfault", "robot")
    jobs = [
        many.Job(str(PRIMITIVE), "ok", QUICK),
        many.Job(str(PANTILT), "injected", {**QUICK, "inject": ["mass:Chassis:10%"]}),
        many.Job(str(_broken(tmp_path)), "unreadable", QUICK),
        many.Job(str(tmp_path / "absent.body"), "absent", QUICK),
        many.Job(str(PRIMITIVE), "crash", {**QUICK, "engines": ["mujoco", "segfault"]}),
        many.Job(str(PRIMITIVE), "raises", {**QUICK, "no_such_option": 1}),
    ]
    out = tmp_path / "reports"
    results = many.run_local(jobs, out, workers=2)
    by = {r.folder: r for r in results}
    assert sorted(by) == sorted(j.folder for j in jobs)
    assert (by["ok"].verdict, by["ok"].exit_code, by["ok"].failed) == ("pass", 0, 0) and by["ok"].checks > 10
    assert by["injected"].verdict == "fail" and by["injected"].failed > 0
    assert any("mass Chassis" in f for f in by["injected"].failures)
    assert by["unreadable"].verdict == "error" and "malformed XML" in by["unreadable"].errors[0]
    assert by["absent"].verdict == "error" and "no such file" in by["absent"].errors[0]
    assert by["crash"].verdict == "error" and "SIGSEGV" in by["crash"].errors[0]
    assert by["raises"].verdict == "error" and "TypeError" in by["raises"].errors[0]
    # the others got their reports; the crashed and raising ones have none
    for folder in ("ok", "injected", "unreadable"):
        assert json.loads((out / folder / "report.json").read_text())["verdict"] == by[folder].verdict
    assert not (out / "crash" / "report.json").exists() and not (out / "raises" / "report.json").exists()
    assert many.exit_code(results) == 2

    many.write_summary(results, {"engines": QUICK["engines"]}, out)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["schema"] == many.SUMMARY_SCHEMA_ID and summary["exit_code"] == 2
    import jsonschema

    schema = json.loads((REPO / "schemas" / "verify-summary.schema.json").read_text())
    jsonschema.validate(summary, schema)
    assert schema["properties"]["schema"]["const"] == many.SUMMARY_SCHEMA_ID
    assert summary["counts"] == {"pass": 1, "fail": 1, "error": 4}
    assert [m["source"] for m in summary["models"]] == sorted(m["source"] for m in summary["models"])
    row = {m["folder"]: m for m in summary["models"]}
    assert row["ok"]["report"] == "ok/report.json" and row["crash"]["report"] is None
    assert row["injected"]["failed"] == by["injected"].failed and row["crash"]["errors"] == by["crash"].errors
    assert "seconds" not in json.dumps(summary)
    page = (out / "summary.html").read_text()
    link = "ok/report.html" if (out / "ok" / "report.html").exists() else "ok/report.json"
    assert row["ok"]["html"] == (link if link.endswith(".html") else None)
    assert f'<a href="{link}">ok</a>' in page and "SIGSEGV" in page
    assert "<script" not in page and "http" not in page  # self-contained


def test_exit_code_precedence() -> None:
    def r(code: int) -> many.ModelResult:
        return many.ModelResult("s", "f", exit_code=code)

    assert many.exit_code([r(0), r(0)]) == 0
    assert many.exit_code([r(0), r(1)]) == 1
    assert many.exit_code([r(1), r(2), r(0)]) == 2


def test_cli_exit_codes_and_no_progress_when_not_a_terminal(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    out = tmp_path / "r"
    mixed = _cli(str(PRIMITIVE), str(_broken(tmp_path)), "-j", "2", "-o", str(out), *QUICK_CLI, env=env)
    assert mixed.returncode == 2, mixed.stdout + mixed.stderr
    assert (out / "mobile_robot_primitive" / "report.json").is_file()
    summary = json.loads((out / "summary.json").read_text())
    expected = sorted([(str(_broken(tmp_path)), "broken", "error"), (str(PRIMITIVE), "mobile_robot_primitive",
                                                                      "pass")])  # sorted by source path
    assert [(m["folder"], m["verdict"]) for m in summary["models"]] == [(f, v) for _, f, v in expected]
    assert "[1/2]" not in mixed.stderr + mixed.stdout and "at a time" not in mixed.stderr  # stderr is a pipe
    assert "PASS" in mixed.stdout and "broken: error:" in mixed.stdout

    failing = _cli(str(PRIMITIVE), str(PANTILT), "-j", "2", "--inject", "mass:Chassis:10%", *QUICK_CLI)
    assert failing.returncode == 1, failing.stdout + failing.stderr
    assert "mobile_robot_pantilt: FAIL layer 1 mujoco mass Chassis" in failing.stdout
    passing = _cli(str(PRIMITIVE), str(PANTILT), "-j", "2", *QUICK_CLI)
    assert passing.returncode == 0, passing.stdout + passing.stderr
    assert _cli(str(PRIMITIVE), str(PANTILT), "--mjcf", str(tmp_path / "x.xml")).returncode == 2
    assert _cli(str(PRIMITIVE), str(PANTILT), "--engines", "nosuch").returncode == 2
    assert _cli(str(PRIMITIVE), str(PANTILT), "--cluster", "tcp://x").returncode == 2


def test_progress_on_a_terminal_only_outside_ci(tmp_path: Path) -> None:
    def run(ci: str | None) -> str:
        env = {k: v for k, v in os.environ.items() if k != "CI"}
        if ci is not None:
            env["CI"] = ci
        controller, terminal = pty.openpty()
        try:
            command = [sys.executable, "-m", "modelkit.cli", "verify", str(PRIMITIVE), str(PANTILT),
                       "-j", "2", *QUICK_CLI]
            proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=terminal, text=True, cwd=REPO,
                                  env=env, check=False)
            os.close(terminal)
            terminal = -1
            seen = b""
            while True:
                try:
                    chunk = os.read(controller, 65536)
                except OSError:  # the terminal side is closed: all read
                    break
                if not chunk:
                    break
                seen += chunk
        finally:
            os.close(controller)
            if terminal >= 0:
                os.close(terminal)
        assert proc.returncode == 0
        assert "[1/2]" not in proc.stdout  # never in the machine-readable output
        return seen.decode()

    shown = run(None)
    assert "verifying 2 models, 2 at a time" in shown and "[1/2] PASS" in shown and "[2/2] PASS" in shown
    assert "[1/2]" not in run("true")


def test_same_numbers_whatever_j_at_defaults(tmp_path: Path) -> None:
    """End to end at the defaults (every engine, the replay): -j 1 in-process, -j 2 in processes."""
    outs = {}
    for j in ("1", "2"):
        outs[j] = tmp_path / f"j{j}"
        done = _cli(str(PRIMITIVE), str(TRACKS), "-j", j, "-o", str(outs[j]))
        assert done.returncode == 0, done.stdout + done.stderr
    assert (outs["1"] / "summary.json").read_bytes() == (outs["2"] / "summary.json").read_bytes()
    for folder in ("mobile_robot_primitive", "mobile_robot_tracks"):
        a, b = _numbers(outs["1"] / folder / "report.json"), _numbers(outs["2"] / folder / "report.json")
        assert a == b and len(a) > 50
        assert (outs["1"] / folder / f"{folder}.xml").read_bytes() == (outs["2"] / folder / f"{folder}.xml"
                                                                       ).read_bytes()


def test_without_ray_the_cluster_option_says_how_to_get_it() -> None:
    code = ("import sys; sys.modules['ray'] = None; sys.argv = ['modelkit'] + sys.argv[1:]; "
            "from modelkit.cli import main; main()")
    done = subprocess.run([sys.executable, "-c", code, "verify", str(PRIMITIVE), str(PANTILT),
                           "--cluster", "local"], capture_output=True, text=True, cwd=REPO, check=False)
    assert done.returncode == 2
    assert "modelkit[cluster]" in done.stderr


def test_a_ray_server_that_fails_to_start_is_tried_again_a_refusal_is_not(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The connection policy alone (Ray's client stands in: the failure is Ray's proxy's, which no
    local cluster produces on demand). CI saw "Initialization failure from server" once, a
    ``ConnectionAbortedError`` from the proxy whose per-client server process had died at start; the
    next connection gets a new server. Any other error is said at once."""
    from modelkit.verify import cluster

    class Client:
        def __init__(self, failures: list[Exception]) -> None:
            self.failures, self.calls, self.shutdowns = failures, 0, 0

        def init(self, **kwargs: Any) -> None:
            self.calls += 1
            if self.failures:
                raise self.failures.pop(0)

        def shutdown(self) -> None:
            self.shutdowns += 1

    monkeypatch.setattr(cluster, "CONNECT_PAUSE", 0.0)
    transient = Client([ConnectionAbortedError("Initialization failure from server")])
    monkeypatch.setattr(cluster, "_ray", lambda: transient)
    assert cluster.connect("ray://127.0.0.1:1") is transient
    assert (transient.calls, transient.shutdowns) == (2, 1)
    lasting = Client([ConnectionAbortedError("down")] * 5)
    monkeypatch.setattr(cluster, "_ray", lambda: lasting)
    with pytest.raises(cluster.ClusterError, match="cannot connect: ConnectionAbortedError: down"):
        cluster.connect("ray://127.0.0.1:1")
    assert lasting.calls == cluster.CONNECT_ATTEMPTS
    refused = Client([ConnectionRefusedError("refused")])
    monkeypatch.setattr(cluster, "_ray", lambda: refused)
    with pytest.raises(cluster.ClusterError, match="ConnectionRefusedError: refused"):
        cluster.connect("ray://127.0.0.1:1")
    assert refused.calls == 1


# ---------------------------------------------------------------- Ray

def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


RAY_ENV: dict[str, str] = {}  # the test cluster's token authentication, for the head and its clients


@pytest.fixture
def ray_cluster() -> Iterator[str]:
    """A one-node Ray cluster (2 CPUs) started for the test, in its own process group, killed after.
    Token authentication with a token of its own (``RAY_AUTH_MODE=token``, ``RAY_AUTH_TOKEN``), given
    to the clients too: whatever ``~/.ray/auth_token`` holds (a local ``ray.init()`` writes one, and a
    head then requires it from clients that do not send it), the test means the same thing."""
    ray_bin = Path(sys.executable).with_name("ray")
    if not ray_bin.exists():
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail("ray is required in CI but not installed (pip install 'modelkit[cluster]')")
        pytest.skip("ray not installed (pip install 'modelkit[cluster]')")
    temp = Path(tempfile.mkdtemp(prefix="mkray", dir="/tmp"))  # short: Ray's socket paths are limited
    gcs, client = _free_port(), _free_port()
    RAY_ENV.update({"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": os.urandom(16).hex()})
    env = {**os.environ, **RAY_ENV}
    head = subprocess.Popen([str(ray_bin), "start", "--head", "--block", f"--port={gcs}",
                             f"--ray-client-server-port={client}", "--num-cpus=2", f"--temp-dir={temp}",
                             "--include-dashboard=false", "--disable-usage-stats"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                            env=env)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", client), timeout=1).close()
                break
            except OSError:
                if head.poll() is not None or time.monotonic() > deadline:
                    pytest.fail("the local Ray cluster did not start")
                time.sleep(0.2)
        address = f"ray://127.0.0.1:{client}"
        # The client port accepts connections before the head can serve a client (it starts a server
        # process per client): wait until one connection goes through, as a user of a busy head would.
        probe = f"import ray; ray.init({address!r}, logging_level='ERROR'); ray.shutdown()"
        while subprocess.run([sys.executable, "-c", probe], capture_output=True, check=False, env=env,
                             timeout=180).returncode != 0:
            if head.poll() is not None or time.monotonic() > deadline + 120:
                pytest.fail("the local Ray cluster does not accept clients")
        yield address
    finally:
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(head.pid, sig)
            except ProcessLookupError:
                break
            time.sleep(2 if sig == signal.SIGTERM else 0)
        head.wait(timeout=30)
        shutil.rmtree(temp, ignore_errors=True)
        RAY_ENV.clear()


def test_ray_cluster_gives_the_local_numbers(tmp_path: Path, ray_cluster: str) -> None:
    broken = _broken(tmp_path)
    local, remote = tmp_path / "local", tmp_path / "ray"
    t0 = time.perf_counter()
    on_ray = _cli(str(PRIMITIVE), str(PANTILT), str(broken), "--cluster", ray_cluster, "-o", str(remote),
                  *QUICK_CLI, env={**os.environ, **RAY_ENV})
    seconds = time.perf_counter() - t0
    assert on_ray.returncode == 2 and (remote / "summary.json").exists(), on_ray.stdout + on_ray.stderr
    here = _cli(str(PRIMITIVE), str(PANTILT), str(broken), "-j", "2", "-o", str(local), *QUICK_CLI)
    assert here.returncode == 2
    assert (remote / "summary.json").read_bytes() == (local / "summary.json").read_bytes()
    for folder in ("mobile_robot_primitive", "mobile_robot_pantilt"):
        assert _numbers(remote / folder / "report.json") == _numbers(local / folder / "report.json")
        written = f"{folder}.xml"
        assert (remote / folder / written).read_bytes() == (local / folder / written).read_bytes()
    print(f"3 models through Ray: {seconds:.1f} s")
