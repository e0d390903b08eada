"""``modelkit verify A B C -j N -o reports/``: many models, one report folder each, and a summary.

The unit of work is :func:`run_one` (one model: :func:`~modelkit.verify.api.verify`, then its report
files by :func:`save`), a plain function of a picklable :class:`Job`, so that the same job runs
in-process (``-j 1``), in a fresh local process per model (``-j N``, :func:`run_local`) or as a Ray
task on a cluster (:mod:`modelkit.verify.cluster`). Extend the per-model work there, in one place.

Layout under the output folder::

    reports/<folder>/report.json       each model's report (and its written MJCF/URDF/SDF, report.html)
    reports/summary.json               every model: verdict, exit code, failed checks, folder (sorted)
    reports/summary.html               the same as a self-contained table linking each report.html

Folder names (:func:`folder_names`) come from the input paths alone, deterministically: the file's
stem (``mobile_robot_pantilt``); inputs sharing a stem get their file name (``robot.urdf``,
``robot.body``), then as many parent folders as tell them apart (``a_robot.urdf``, ``b_robot.urdf``).

Isolation. With ``-j N`` > 1 each model runs in its own fresh process (at most N at a time): a model
that crashes an engine, even a segfault, or raises, becomes verdict ``"error"`` with the reason and
the others go on; no state crosses from one model to the next. ``-j 1`` runs the models one after the
other in this process (an exception is still caught; a segfault ends the command).

Determinism: each model's numbers depend only on its input and the options (the seed), never on
``-j``, the order of completion or the machine that ran it; ``summary.json`` is sorted by source and
holds no wall time.

Exit code (:func:`exit_code`): 2 if any model could not be verified (unreadable, not convertible,
crashed), else 1 if any check failed, else 0. "Could not run" takes precedence because that model's
verdict is unknown: it may hide a failure.
"""

from __future__ import annotations

import dataclasses
import html
import json
import multiprocessing
import os
import re
import signal
import tempfile
import time
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import IO, Any, cast

from modelkit import safewrite
from modelkit.lifeline import worker_started

SUMMARY_SCHEMA_ID = "modelkit-verify-summary/1"
RESERVED = {"summary.json", "summary.html"}


@dataclass(frozen=True)
class Job:
    """One model to verify: ``source`` as the user gave it (reported), ``path`` the file to read
    (the same, or absolute for a remote worker), ``folder`` its report folder's name, ``options`` the
    keyword arguments of :func:`~modelkit.verify.api.verify` (engines, seed, replay, inject, ...)."""

    source: str
    folder: str
    options: Mapping[str, Any] = field(default_factory=dict)
    path: str = ""
    # Start the report's plotting and picture processes while the layers run: helps one model at a
    # time; with several models in parallel the cores are already busy and it would oversubscribe them.
    early_report: bool = True

    @property
    def read_path(self) -> str:
        return self.path or self.source


@dataclass
class ModelResult:
    """What the summary says of one model (small, picklable; the full report is its report.json)."""

    source: str
    folder: str
    robot: str = ""
    verdict: str = "error"  # "pass" | "fail" | "error"
    exit_code: int = 2
    checks: int = 0
    failed: int = 0
    skipped: int = 0
    failures: list[str] = field(default_factory=list)  # "layer 1 mujoco mass Chassis: detail"
    errors: list[str] = field(default_factory=list)  # why it could not be verified
    files: list[str] = field(default_factory=list)  # report files written in its folder (sorted)
    seconds: float = 0.0  # wall time; shown on the terminal, never written


# ---------------------------------------------------------------- inputs and folder names

def expand_inputs(paths: Sequence[Path]) -> list[Path]:
    """The model files named by ``paths``: a file as given; a directory gives the model files
    directly inside it (not recursively), those whose format modelkit recognises by extension or,
    for ``.xml``, by the top element; sorted by name. The same file named twice is verified once."""
    from modelkit.formats import detect_format

    out: list[Path] = []
    seen: set[Path] = set()
    for path in paths:
        if os.path.isdir(path):  # False for a name too long to look up: then "no such file" as given
            found = sorted(p for p in path.iterdir() if p.is_file() and detect_format(p) is not None)
        else:
            found = [path]
        for p in found:
            key = p.resolve()
            if key not in seen:
                seen.add(key)
                out.append(p)
    return out


def _clean(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name).strip(".") or "model"


def folder_names(paths: Sequence[Path]) -> list[str]:
    """A distinct folder name per input, from its path alone (see the module docstring)."""
    from modelkit.convert.api import output_stem

    parts = [[("up" if p == ".." else p) for p in Path(os.path.normpath(path)).parts if p not in ("/", ".")]
             for path in paths]
    names = [_clean(output_stem(Path(path))) for path in paths]
    for depth in range(0, 64):
        groups: dict[str, list[int]] = {}
        for i, name in enumerate(names):
            groups.setdefault(name.lower(), []).append(i)  # case-insensitive file systems too
        clashes = [i for members in groups.values() if len(members) > 1 for i in members]
        clashes += [i for i, name in enumerate(names) if name.lower() in RESERVED]
        if not clashes:
            return names
        for i in clashes:
            tail = parts[i][-(depth + 1):] if depth + 1 <= len(parts[i]) else None
            if tail is None:  # no path component left to tell them apart: number them
                names[i] = f"{names[i]}_{i + 1}"
            else:
                names[i] = _clean("_".join(tail))
    raise ValueError("cannot make distinct report folder names")  # pragma: no cover


def make_jobs(paths: Sequence[Path], options: Mapping[str, Any], absolute: bool = False) -> list[Job]:
    """One :class:`Job` per input (``absolute``: read by absolute path, for workers elsewhere)."""
    return [Job(str(p), folder, dict(options), str(p.resolve()) if absolute else "")
            for p, folder in zip(paths, folder_names(paths), strict=True)]


def check_options(options: Mapping[str, Any]) -> None:
    """Raise ``ValueError`` for an option that would make every model fail the same way."""
    from modelkit.verify.engines.registry import ENGINES

    unknown = [e for e in options.get("engines", ()) if e not in ENGINES]
    if unknown:
        raise ValueError(f"unknown engine {unknown[0]!r}; known: {', '.join(sorted(ENGINES))}")
    if options.get("scenario"):
        from modelkit.diagnostics import render_text
        from modelkit.verify.drive.scenario import load

        scenario, diagnostics = load(options["scenario"])
        if scenario is None:
            raise ValueError("--scenario: " + "; ".join(render_text(d) for d in diagnostics))


# ---------------------------------------------------------------- the per-model job

def save(report: Any, out_dir: Path, read_from: str | None = None) -> list[str]:
    """Write a report's files into ``out_dir``: ``report.html`` and its plots when the HTML writer
    (:mod:`modelkit.verify.report.html`) is there and the run happened, then ``report.json``. ``read_from``:
    where the model file is for this process when ``report.source`` (the path shown) is not it (a
    remote worker reads an absolute path). Returns the report files written (sorted, relative)."""
    from modelkit.verify.report import report_json

    safewrite.make_folder(out_dir, out_dir)
    write_artefacts: Callable[..., Any] | None = None
    try:
        from modelkit.verify.report.html import write_artefacts as html_writer
        write_artefacts = html_writer
    except ModuleNotFoundError as exc:
        if exc.name != "modelkit.verify.report.html":
            raise
    if write_artefacts is not None and not report.errors:
        shown = report.source
        report.source = read_from or shown  # the HTML writer reads the model again from it
        try:
            write_artefacts(report, out_dir)
        finally:
            report.source = shown
    safewrite.write_text(out_dir, out_dir / "report.json", report_json(report))
    return sorted(p.relative_to(out_dir).as_posix() for p in out_dir.rglob("report*") if p.is_file())


def _result_of(job: Job, report: Any, files: list[str]) -> ModelResult:
    failures = [f"layer {c.layer} {c.engine} {c.quantity} {c.where}".rstrip() + f": {c.detail}"
                for c in report.failed]
    return ModelResult(job.source, job.folder, report.robot, report.verdict, report.exit_code,
                       len(report.checks), len(report.failed), len(report.skips), failures,
                       list(report.errors), files)


def run_one(job: Job, out_root: Path | None) -> ModelResult:
    """Verify one model into ``out_root/job.folder`` (a temporary folder when ``out_root`` is None);
    never raises: an exception is verdict "error" with its reason."""
    t0 = time.perf_counter()
    try:
        if out_root is None:
            with tempfile.TemporaryDirectory(prefix="modelkit-verify-") as tmp:
                result = _verify_into(job, Path(tmp) / job.folder)
        else:
            safewrite.check(out_root, out_root / job.folder, folder=True)
            result = _verify_into(job, out_root / job.folder)
    except Exception as exc:
        last = traceback.extract_tb(exc.__traceback__)[-1:] if exc.__traceback__ else []
        where = f" (at {Path(last[0].filename).name}:{last[0].lineno})" if last else ""
        result = ModelResult(job.source, job.folder,
                             errors=[f"verify raised {type(exc).__name__}: {exc}{where}"])
    result.seconds = time.perf_counter() - t0
    return result


def _verify_into(job: Job, out_dir: Path) -> ModelResult:
    from modelkit.verify.api import verify

    report = verify(job.read_path, out_dir, artefacts=job.early_report, **dict(job.options))
    report.source = job.source  # the path as the user gave it, wherever the job ran
    files = save(report, out_dir, job.read_path)
    return _result_of(job, report, files)


def run_collected(job: Job) -> tuple[ModelResult, dict[str, bytes]]:
    """:func:`run_one` in a temporary folder, returning the folder's files too (path → bytes): the
    job of a remote worker whose disk the caller cannot see."""
    with tempfile.TemporaryDirectory(prefix="modelkit-verify-") as tmp:
        result = run_one(job, Path(tmp))
        folder = Path(tmp) / job.folder
        files = ({p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
                  if p.is_file()} if folder.is_dir() else {})
    return result, files


def unpack(files: Mapping[str, bytes], out_dir: Path) -> None:
    """Write a remote job's files (from :func:`run_collected`) into ``out_dir``."""
    for name, data in files.items():
        target = out_dir / name
        if ".." in Path(name).parts or Path(name).is_absolute():
            raise ValueError(f"refusing to write {name!r} outside {out_dir}")
        safewrite.write_bytes(out_dir, target, data)


def crashed(job: Job, how: str) -> ModelResult:
    return ModelResult(job.source, job.folder, errors=[how])


# ---------------------------------------------------------------- running many

Progress = Callable[[ModelResult, int, int], None]


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover (not Linux)
        return max(1, os.cpu_count() or 1)


def warm_up(jobs: Sequence[Job]) -> None:
    """Import, once in this process, what every model's verification imports (the readers, the
    writers, the layers, the engines' adapters and their packages), so that the forked workers
    inherit it instead of each paying it again. Only imports: no engine is started. An engine that
    is not installed is left alone (each job then skips it as usual)."""
    import importlib

    from modelkit.formats import FORMATS
    from modelkit.verify import api

    modules = {info.reader.partition(":")[0] for info in FORMATS}
    modules |= {f"modelkit.formats.{fmt}.writer" for fmt in ("mjcf", "urdf", "sdf")}
    modules |= {"modelkit.convert.api", "modelkit.verify.layers.static", "modelkit.verify.layers.kinematics",
                "modelkit.verify.layers.dynamics", "modelkit.verify.engines.reference",
                "modelkit.verify.layers.approximations", "modelkit.verify.layers.shapes",
                "modelkit.verify.layers.inject",
                api.REPLAY.partition(":")[0], "yourdfpy", "trimesh"}
    for job in jobs:
        engines = job.options.get("engines", api.DEFAULT_ENGINES)
        modules |= {api.ENGINES[e].partition(":")[0] for e in engines if e in api.ENGINES}
    from modelkit.interrupt import signals_held

    for name in sorted(modules):
        try:
            with signals_held():  # see verify.api._resolve
                importlib.import_module(name)
        except Exception:  # not installed, or broken: the job says so in its own report
            continue


def _child(job: Job, out_root: Path | None, conn: Connection, parent: int) -> None:
    worker_started(parent)  # killed with the parent; Ctrl-C is the parent's to handle
    result = run_one(job, out_root)
    conn.send(result)
    conn.close()


def _death(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        return (f"the worker process verifying this model died from {name} (an engine crashed); "
                "the other models were not affected")
    return f"the worker process verifying this model exited with status {exitcode} without a result"


def run_local(jobs: Sequence[Job], out_root: Path | None, workers: int,
              progress: Progress | None = None) -> list[ModelResult]:
    """Run ``jobs``: in this process one after the other when ``workers`` is 1, else each in a fresh
    process, at most ``workers`` at a time. Results in completion order (see :func:`summary`)."""
    total = len(jobs)
    results: list[ModelResult] = []

    def done(result: ModelResult) -> None:
        results.append(result)
        if progress is not None:
            progress(result, len(results), total)

    if workers <= 1 or total <= 1:
        for job in jobs:
            done(run_one(job, out_root))
        return results
    jobs = [dataclasses.replace(job, early_report=False) for job in jobs]
    methods = multiprocessing.get_all_start_methods()
    ctx: Any = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    if "fork" in methods:
        warm_up(jobs)
    pending = list(jobs)
    running: dict[Connection, tuple[Any, Job]] = {}
    try:
        while pending or running:
            while pending and len(running) < workers:
                job = pending.pop(0)
                receive, send = ctx.Pipe(duplex=False)
                process = ctx.Process(target=_child, args=(job, out_root, send, os.getpid()),
                                      name=f"verify {job.folder}")
                process.start()
                send.close()  # the child holds the only write end: EOF when it dies
                running[receive] = (process, job)
            for ready in wait(list(running)):
                conn = cast(Connection, ready)
                process, job = running.pop(conn)
                try:
                    result: ModelResult | None = conn.recv()
                except (EOFError, OSError):
                    result = None
                conn.close()
                process.join()
                done(result if result is not None else crashed(job, _death(process.exitcode)))
    finally:
        for process, _ in running.values():
            process.kill()
            process.join()
    return results


# ---------------------------------------------------------------- the summary

def exit_code(results: Iterable[ModelResult]) -> int:
    codes = {r.exit_code for r in results}
    return 2 if 2 in codes else 1 if 1 in codes else 0


def _ordered(results: Iterable[ModelResult]) -> list[ModelResult]:
    return sorted(results, key=lambda r: (r.source, r.folder))


def summary(results: Iterable[ModelResult], parameters: Mapping[str, Any]) -> dict[str, Any]:
    """The summary as plain data (sorted by source; no wall time: the same inputs give the same bytes)."""
    ordered = _ordered(results)
    code = exit_code(ordered)
    counts = {v: sum(1 for r in ordered if r.verdict == v) for v in ("pass", "fail", "error")}
    models = []
    for r in ordered:
        models.append({
            "source": r.source, "folder": r.folder, "robot": r.robot, "verdict": r.verdict,
            "exit_code": r.exit_code, "checks": r.checks, "failed": r.failed, "skipped": r.skipped,
            "failures": list(r.failures), "errors": list(r.errors),
            "report": f"{r.folder}/report.json" if "report.json" in r.files else None,
            "html": f"{r.folder}/report.html" if "report.html" in r.files else None,
        })
    return {"schema": SUMMARY_SCHEMA_ID, "verdict": {0: "pass", 1: "fail", 2: "error"}[code],
            "exit_code": code, "counts": counts, "parameters": _plain(parameters), "models": models}


def _plain(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in sorted(value.items())}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def summary_json(results: Iterable[ModelResult], parameters: Mapping[str, Any]) -> str:
    return json.dumps(summary(results, parameters), indent=2, ensure_ascii=False) + "\n"


_CSS = """body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}
td,th{border:1px solid #ccc;padding:.3em .6em;text-align:left;vertical-align:top}
.pass{background:#e6f4e6}.fail{background:#fbe3e3}.error{background:#fdf0d5}
td.n{text-align:right}ul{margin:0;padding-left:1.2em}"""


def summary_html(results: Iterable[ModelResult], parameters: Mapping[str, Any]) -> str:
    """A self-contained page (no script, no external resource): one row per model, linking its
    report.html when it exists (else its report.json)."""
    data = summary(results, parameters)
    e = html.escape
    rows = []
    for m in data["models"]:
        link = m["html"] or m["report"]
        name = f'<a href="{e(link)}">{e(m["folder"])}</a>' if link else e(m["folder"])
        notes = m["errors"] + m["failures"][:5] + (
            [f"... and {len(m['failures']) - 5} more failed checks"] if len(m["failures"]) > 5 else [])
        detail = "<ul>" + "".join(f"<li>{e(n)}</li>" for n in notes) + "</ul>" if notes else ""
        numbers = "".join(f'<td class="n">{m[k]}</td>' for k in ("checks", "failed", "skipped"))
        rows.append(f'<tr class="{e(m["verdict"])}"><td>{name}</td><td>{e(m["source"])}</td>'
                    f'<td>{e(m["robot"])}</td><td>{e(m["verdict"].upper())}</td>{numbers}<td>{detail}</td></tr>')
    counts = ", ".join(f"{n} {v}" for v, n in data["counts"].items())
    params = e(json.dumps(data["parameters"], ensure_ascii=False))
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>modelkit verify: {len(data['models'])} models</title><style>{_CSS}</style></head>\n"
            f"<body><h1>modelkit verify: {e(data['verdict'].upper())}</h1>\n"
            f"<p>{len(data['models'])} models: {e(counts)}; exit code {data['exit_code']}.</p>\n"
            f"<p>parameters: <code>{params}</code></p>\n"
            "<table><thead><tr><th>report</th><th>source</th><th>robot</th><th>verdict</th><th>checks</th>"
            "<th>failed</th><th>skipped</th><th>why</th></tr></thead><tbody>\n"
            + "\n".join(rows) + "\n</tbody></table></body></html>\n")


def write_summary(results: Sequence[ModelResult], parameters: Mapping[str, Any], out_root: Path
                  ) -> list[Path]:
    paths = [out_root / "summary.json", out_root / "summary.html"]
    safewrite.write_text(out_root, paths[0], summary_json(results, parameters))
    safewrite.write_text(out_root, paths[1], summary_html(results, parameters))
    return paths


def render_summary(results: Iterable[ModelResult]) -> str:
    """The terminal table: one row per model (sorted by source), then what failed, then the verdict."""
    ordered = _ordered(results)
    header = ("verdict", "checks", "failed", "skipped", "folder", "source")
    rows = [(r.verdict.upper(), str(r.checks), str(r.failed), str(r.skipped), r.folder, r.source)
            for r in ordered]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(v.ljust(w) for v, w in zip(row, widths, strict=True)).rstrip()
             for row in [header, *rows]]
    for r in ordered:
        lines += [f"{r.folder}: FAIL {f}" for f in r.failures]
        lines += [f"{r.folder}: error: {e}" for e in r.errors]
    code = exit_code(ordered)
    counts = {v: sum(1 for r in ordered if r.verdict == v) for v in ("pass", "fail", "error")}
    lines.append(f"{ {0: 'PASS', 1: 'FAIL', 2: 'ERROR'}[code] }: {len(ordered)} models, "
                 f"{counts['pass']} passed, {counts['fail']} failed, {counts['error']} could not be verified")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- progress on a terminal

def progress_wanted(stream: IO[str], environ: Mapping[str, str] | None = None) -> bool:
    """Progress only for a person: ``stream`` is a terminal and not in CI (``CI`` set and not false)."""
    env = os.environ if environ is None else environ
    ci = env.get("CI", "").strip().lower()
    if ci and ci not in ("0", "false", "no"):
        return False
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


def progress_printer(stream: IO[str]) -> Progress:
    """One line per finished model on ``stream``: ``[2/4] PASS mobile_robot_pantilt (75 checks, 1.8 s)``."""
    def show(result: ModelResult, done: int, total: int) -> None:
        what = (f"{result.failed} of {result.checks} checks failed" if result.verdict == "fail"
                else result.errors[0] if result.errors else f"{result.checks} checks")
        width = len(str(total))
        stream.write(f"[{done:>{width}}/{total}] {result.verdict.upper():5} {result.folder} "
                     f"({what}, {result.seconds:.1f} s)\n")
        stream.flush()
    return show


__all__ = ["Job", "ModelResult", "check_options", "default_workers", "exit_code",
           "expand_inputs", "folder_names", "make_jobs", "progress_printer", "progress_wanted",
           "render_summary", "run_collected", "run_local", "run_one", "save", "summary", "summary_html",
           "summary_json", "write_summary"]
