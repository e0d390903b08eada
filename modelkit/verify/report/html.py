"""``report.html``: the human-readable report of ``modelkit verify``, one self-contained file.

Everything is inside the file: the plots and pictures as ``data:image/png;base64`` URIs, the CSS
inline, no script at all (``<details>`` folds the long parts), so it opens offline and from a CI
artefact. The same PNGs are also written next to it (``plots/*.png``, ``pictures/*.png``) and
listed in ``report.artefacts``.

Deterministic: the same report gives the same bytes (no time stamps, no wall times; the PNGs are
deterministic too: :mod:`modelkit.verify.report.plots` and :func:`png`).

:func:`write_artefacts` is the entry point ``verify`` calls: plots (layer 4 trajectories),
pictures (every engine's view of the robot, :mod:`modelkit.verify.report.pictures`) and the HTML.
The plots are drawn (in child processes, :class:`~modelkit.verify.report.plots.Plotters`) while
the pictures' child process renders; ``verify(..., artefacts=True)`` starts both early (:class:`Prepared`).
"""

from __future__ import annotations

import base64
import html
import json
import math
import struct
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from modelkit import safewrite
from modelkit.verify.report import LAYER_NAMES, VerifyReport, plain, scope

PICTURE_ENGINES = ("mujoco", "pybullet")


def png(image: NDArray[np.uint8]) -> bytes:
    """A deterministic PNG of an (H, W, 3) uint8 image (no metadata, zlib level 6)."""
    h, w, _ = image.shape
    raw = b"".join(b"\x00" + image[row].tobytes() for row in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


@dataclass
class Artefacts:
    """What :func:`write_artefacts` made, for the HTML: (caption, relative path, PNG bytes)."""

    plots: list[tuple[str, str, bytes]] = field(default_factory=list)
    pictures: Any = None  # pictures.PictureSet | None
    picture_files: dict[tuple[str, str, int], tuple[str, bytes]] = field(default_factory=dict)
    differences: dict[tuple[str, str, int], tuple[str, bytes, float]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


# ---- the artefacts --------------------------------------------------------------------------------


def _robot_and_files(report: VerifyReport, out_dir: Path, robot: Any, files: dict[str, Path] | None
                     ) -> tuple[Any, dict[str, Path]]:
    if robot is None:
        from modelkit.verify.source import read_robot, welded_copy

        robot, _ = welded_copy(read_robot(Path(report.source)))
    if files is None:
        files = {}
        for fmt, name in report.files.items():
            path = Path(name)
            files[fmt] = path if path.is_absolute() or path.exists() else out_dir / name
    return robot, files


def _picture_job(report: VerifyReport, out_dir: Path, robot: Any, files: dict[str, Path] | None) -> Any:
    """The pictures' child process (:class:`~modelkit.verify.report.pictures.PictureJob`), started."""
    from modelkit.verify.layers.kinematics import configurations
    from modelkit.verify.report.pictures import PictureJob

    model, paths = _robot_and_files(report, out_dir, robot, files)
    engines = tuple(e for e in PICTURE_ENGINES if e in report.parameters.get("engines", PICTURE_ENGINES))
    return PictureJob(model, paths, report.renames, configurations(model, 1, report.seed), engines)


@dataclass
class Prepared:
    """The report's slow parts started early (``verify(..., artefacts=True)``): the plotting children
    import matplotlib and the pictures are made on another core while the layers run;
    :func:`write_artefacts` takes them from ``report.prepared``. Not part of report.json."""

    plotters: Any = None  # plots.Plotters | None
    pictures: Any = None  # pictures.PictureJob | None

    def start_plotters(self) -> None:
        from modelkit.verify.report.plots import PLOTTERS, Plotters, usable_cores

        if usable_cores() > 1:
            self.plotters = Plotters(PLOTTERS)

    def start_pictures(self, report: VerifyReport, out_dir: Path, robot: Any, files: dict[str, Path]) -> None:
        """``robot``: the model verified, root welded; ``files``: the written (and injected) files."""
        try:
            self.pictures = _picture_job(report, out_dir, robot, files)
        except Exception:  # made again (or the failure noted) by write_artefacts
            self.pictures = None

    def close(self) -> None:
        for job in (self.plotters, self.pictures):
            if job is not None:
                job.close()
        self.plotters = self.pictures = None


def write_artefacts(report: VerifyReport, out_dir: Path, robot: Any = None,
                    files: dict[str, Path] | None = None, pictures: bool = True) -> Path:
    """Plots, pictures and ``report.html`` in ``out_dir``; returns the HTML's path and records every
    file in ``report.artefacts`` (relative to ``out_dir``). ``robot``: the model verified, root welded
    (read again from ``report.source`` when None); ``files``: the written MJCF/URDF ("mjcf", "urdf" →
    path; from ``report.files`` relative to ``out_dir`` when None)."""
    from modelkit.verify.report.pictures import difference

    out_dir = Path(out_dir)
    safewrite.make_folder(out_dir, out_dir)
    for name in ("report.html", "pictures", "plots"):  # refused before minutes of drawing, not after
        safewrite.check(out_dir, out_dir / name, folder=name != "report.html")
    art = Artefacts()
    t0 = time.perf_counter()
    prepared = report.prepared if isinstance(report.prepared, Prepared) else Prepared()
    report.prepared = None
    job = prepared.pictures
    try:
        if pictures and job is None:
            try:
                job = _picture_job(report, out_dir, robot, files)
            except Exception as exc:  # pictures are an aid: never the reason a verify run fails
                art.notes.append(f"pictures could not be made: {type(exc).__name__}: {exc}")
        if report.trajectories:
            from modelkit.verify.report.plots import write_plots

            tolerances = report.scenario.get("tolerances") if isinstance(report.scenario, dict) else None
            try:
                drive = report.drive if isinstance(report.drive, dict) else {}
                wheels = [drive.get("left"), drive.get("right"),
                          *[j for rollers in drive.get("rollers", {}).values() for j in rollers]]
                for profile, path, data in write_plots(report.trajectories, out_dir / "plots", tolerances,
                                                       wheels=[w for w in wheels if w],
                                                       plotters=prepared.plotters, root=out_dir):
                    rel = path.relative_to(out_dir).as_posix()
                    art.plots.append((profile, rel, data))
                    report.artefacts[f"plot:{profile}"] = rel
            except safewrite.UnsafeOutput:
                raise
            except Exception as exc:
                art.notes.append(f"plots could not be drawn: {type(exc).__name__}: {exc}")
        t1 = time.perf_counter()
        report.timings["plots"] = t1 - t0
        if pictures and job is not None:
            try:
                art.pictures = job.result()
            except Exception as exc:  # pictures are an aid: never the reason a verify run fails
                art.notes.append(f"pictures could not be made: {type(exc).__name__}: {exc}")
            report.timings["pictures (after plots)"] = time.perf_counter() - t1
    finally:
        prepared.close()
        if job is not None:
            job.close()
    ps = art.pictures
    if ps is not None:
        folder = safewrite.make_folder(out_dir, out_dir / "pictures")
        for p in ps.pictures:
            name = f"{p.kind}-q{p.config}-{p.engine}.png"
            data = png(p.image)
            safewrite.write_bytes(out_dir, folder / name, data)
            art.picture_files[(p.engine, p.kind, p.config)] = (f"pictures/{name}", data)
            report.artefacts[f"picture:{p.kind}:q{p.config}:{p.engine}"] = f"pictures/{name}"
            source = ps.get("source", p.kind, p.config)
            if p.engine != "source" and source is not None:
                img, size = difference(source.mask, p.mask)
                dname = f"{p.kind}-q{p.config}-{p.engine}-difference.png"
                ddata = png(img)
                safewrite.write_bytes(out_dir, folder / dname, ddata)
                art.differences[(p.engine, p.kind, p.config)] = (f"pictures/{dname}", ddata, size)
                report.artefacts[f"picture:{p.kind}:q{p.config}:{p.engine}-difference"] = f"pictures/{dname}"
    path = out_dir / "report.html"
    report.artefacts["html"] = "report.html"
    safewrite.write_text(out_dir, path, render_html(report, art))
    report.timings["report"] = time.perf_counter() - t0
    return path


def write_html(report: VerifyReport, out_dir: Path) -> Path:
    """``report.html`` only (plots and pictures as they are: use :func:`write_artefacts` for all)."""
    return write_artefacts(report, out_dir, pictures=False)


# ---- the page -------------------------------------------------------------------------------------

CSS = """
body{font-family:"DejaVu Sans",Arial,sans-serif;margin:1.2em 2em;color:#222;font-size:14px}
h1{font-size:1.5em;margin-bottom:.2em} h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
h3{font-size:1.05em}
.verdict{padding:.7em 1em;font-size:1.3em;font-weight:bold;border-radius:4px;margin:.6em 0}
.pass{background:#d7f0d7;color:#135213} .fail{background:#f8d3d3;color:#8a1010}
.error{background:#e4e4e4;color:#333}
table{border-collapse:collapse;margin:.5em 0;font-size:12.5px}
th,td{border:1px solid #ccc;padding:2px 6px;text-align:left;vertical-align:top}
th{background:#f0f0f0} td.num{text-align:right;font-family:monospace}
tr.failed td{background:#fbe0e0} td.ok{color:#135213} td.bad{color:#a00;font-weight:bold}
.meta td:first-child{font-weight:bold;white-space:nowrap}
.detail{color:#555;font-size:11.5px}
figure{margin:.6em 0} figcaption{font-size:12px;color:#444}
.plot img{max-width:100%;border:1px solid #ddd}
.pictures{display:flex;flex-wrap:wrap;gap:6px}
.pictures figure{margin:0;width:19%;min-width:180px}
.pictures img{width:100%;border:1px solid #ddd;image-rendering:auto}
pre{background:#f7f7f7;padding:.5em;overflow-x:auto;font-size:11.5px}
.note{color:#7a4b00}
"""


def _e(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _num(x: float) -> str:
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    if isinstance(x, float) and math.isnan(x):
        return "nan"
    if x == 0:
        return "0"
    if float(x) == int(x) and abs(x) < 1e6:
        return str(int(x))
    return f"{x:.3g}" if 1e-3 <= abs(x) < 1e4 else f"{x:.2e}"


def _img(data: bytes, alt: str) -> str:
    return f'<img alt="{_e(alt)}" src="data:image/png;base64,{base64.b64encode(data).decode()}">'


def _checks_table(checks: list[Any]) -> str:
    rows = ["<table><tr><th>layer</th><th>engine</th><th>quantity</th><th>worst error</th><th>tolerance</th>"
            "<th></th><th>where</th><th>detail</th></tr>"]
    for c in checks:
        ok = c.passed
        rows.append(
            f'<tr class="{"passed" if ok else "failed"}"><td>{_e(LAYER_NAMES.get(c.layer, c.layer))}</td>'
            f"<td>{_e(c.engine)}</td><td>{_e(c.quantity)}</td><td class=num>{_num(c.error)}</td>"
            f'<td class=num>{_num(c.tolerance)}</td>'
            f'<td class="{"ok" if ok else "bad"}">{"ok" if ok else "FAIL"}</td>'
            f'<td>{_e(c.where)}</td><td class="detail">{_e(c.detail)}</td></tr>')
    rows.append("</table>")
    return "\n".join(rows)


def _skips_table(skips: list[Any]) -> str:
    rows = ["<table><tr><th>layer</th><th>engine</th><th>reason</th></tr>"]
    rows += [f"<tr><td>{_e(LAYER_NAMES.get(s.layer, s.layer))}</td><td>{_e(s.engine)}</td>"
             f"<td>{_e(s.reason)}</td></tr>" for s in skips]
    rows.append("</table>")
    return "\n".join(rows)


def _observations_table(observations: list[Any]) -> str:
    rows = ["<table><tr><th>layer</th><th>engine</th><th>quantity</th><th>where</th><th>value</th>"
            "<th>unit</th><th>detail</th></tr>"]
    rows += [f"<tr><td>{_e(LAYER_NAMES.get(o.layer, o.layer))}</td><td>{_e(o.engine)}</td>"
             f"<td>{_e(o.quantity)}</td><td>{_e(o.where)}</td><td class=num>{_num(o.value)}</td>"
             f"<td>{_e(o.unit)}</td>"
             f'<td class="detail">{_e(o.detail)}</td></tr>' for o in observations]
    rows.append("</table>")
    return "\n".join(rows)


def _json_block(value: Any) -> str:
    return f"<pre>{_e(json.dumps(plain(value), indent=2, sort_keys=True, ensure_ascii=False))}</pre>"


def _pictures_section(art: Artefacts) -> list[str]:
    from modelkit.verify.report.pictures import ENGINES, KINDS

    ps = art.pictures
    out = ["<h2>The robot as each engine sees it</h2>"]
    if ps is None:
        out.append('<p class="note">No pictures: ' + _e("; ".join(art.notes) or "not requested") + "</p>")
        return out
    out.append("<p>Source model (drawn by modelkit from its shapes), MuJoCo (offscreen renderer) and "
               "PyBullet (TinyRenderer), root link welded at the identity, the same camera "
               f"(eye {_e([round(v, 4) for v in ps.camera.eye])}, target "
               f"{_e([round(v, 4) for v in ps.camera.target])}, vertical field of view "
               f"{ps.camera.fovy:g}°). "
               "The difference pictures compare each engine's silhouette with the source's: grey both, "
               "<b style='color:#dc1e1e'>red</b> only the engine, <b style='color:#1e3cdc'>blue</b> only "
               "the source. Collision shapes are drawn in one colour everywhere.</p>")
    for note in ps.notes:
        out.append(f'<p class="note">{_e(note)}</p>')
    for index, q in enumerate(ps.configurations):
        shown = ", ".join(f"{k} {v:.4f}" for k, v in sorted(q.items())) or "every joint at 0"
        for kind in KINDS:
            out.append(f'<h3 id="pictures-{kind}-{index}">{_e(kind)} shapes, configuration {index} '
                       f"(q: {_e(shown)})</h3><div class=pictures>")
            for engine in ENGINES:
                item = art.picture_files.get((engine, kind, index))
                if item is None:
                    out.append(f"<figure><figcaption>{_e(engine)}: not rendered (see the notes)</figcaption>"
                               "</figure>")
                    continue
                out.append(f"<figure>{_img(item[1], f'{engine} {kind} {index}')}<figcaption>{_e(engine)}"
                           "</figcaption></figure>")
            for engine in ENGINES[1:]:
                diff = art.differences.get((engine, kind, index))
                if diff is None:
                    continue
                out.append(f"<figure>{_img(diff[1], f'{engine} difference')}<figcaption>{_e(engine)} "
                           f"vs source: {100.0 * diff[2]:.2f} % of the silhouette differs"
                           "</figcaption></figure>")
            out.append("</div>")
    return out


def _replay_calibration(replay: dict[str, Any]) -> list[str]:
    """Layer 3b's calibrated tolerance per compared engine: the envelope (the reference engine's own
    spread from a start moved by 1e-12 rad), the amplification, the strict horizon and the margin."""
    if not replay:
        return []
    rows = ["<h3>Layer 3b, the replay's tolerance</h3><p>1e-8 rad times the model's own amplification of "
            "a start difference, measured at run time: the reference engine replays from starts moved by "
            "1e-12 rad, and the tolerance at each step is 1e-8 × max(1, spread / 1e-12) by then.</p>"
            "<table><tr><th>engine</th><th>against</th><th>envelope at the end</th><th>amplification</th>"
            "<th>strict (≤ 10×) up to</th><th>worst ratio at</th><th>error / tolerance there</th>"
            "<th>margin</th><th>largest difference</th></tr>"]
    ladders = {engine: r for engine, r in replay.items() if r.get("method") == "step ladder"}
    if ladders:
        return _ladder_calibration(ladders)
    for engine, r in sorted(replay.items()):
        envelope = r.get("envelope_end")
        margin = r.get("margin")
        rows.append(
            f"<tr><td>{_e(engine)}</td><td>{_e(r['reference'])}</td>"
            f"<td>{_num(envelope) if envelope is not None else 'not measured'}</td>"
            f"<td>×{_num(r['amplification_end'])}</td><td>{r['strict_until']:.3f} s</td>"
            f"<td>{r['worst_ratio_time']:.3f} s</td>"
            f"<td>{_num(r['worst_ratio_error'])} / {_num(r['worst_ratio_tolerance'])}</td>"
            f"<td>{'×' + _num(margin) if margin is not None else 'no difference'}</td>"
            f"<td>{_num(r['largest_error'])} at {r['largest_error_time']:.3f} s</td></tr>")
    rows.append("</table>")
    return rows


def _ladder_calibration(replay: dict[str, Any]) -> list[str]:
    """Layer 3b of a model with ball joints: the engines' difference extrapolated to dt → 0 from the
    step ladder, against the extrapolation's last correction."""
    rows = ["<h3>Layer 3b, the replay's tolerance (ball joints: the step ladder)</h3><p>MuJoCo turns a ball "
            "by its quaternion, PyBullet the URDF's three joints by their angles: two first-order schemes "
            "that part by O(dt) even for the same robot. The replay runs at dt, dt/2, dt/4 and dt/8; the "
            "engines' difference is extrapolated to dt → 0 (Richardson) and must stay within the "
            "extrapolation's last correction (at least 1e-8 rad). A difference of the models survives the "
            "extrapolation.</p><table><tr><th>engine</th><th>against</th><th>time steps</th>"
            "<th>compared</th><th>difference at dt</th><th>worst ratio at</th>"
            "<th>extrapolated / tolerance there</th><th>margin</th><th>largest extrapolated</th></tr>"]
    for engine, r in sorted(replay.items()):
        margin = r.get("margin")
        rows.append(
            f"<tr><td>{_e(engine)}</td><td>{_e(r['reference'])}</td>"
            f"<td>{', '.join(_num(h) for h in r['time_steps'])} s</td><td>{r['compared_seconds']:.3f} s</td>"
            f"<td>{_num(r['difference_at_dt'])}</td><td>{r['worst_ratio_time']:.3f} s</td>"
            f"<td>{_num(r['worst_ratio_error'])} / {_num(r['worst_ratio_tolerance'])}</td>"
            f"<td>{'×' + _num(margin) if margin is not None else 'no difference'}</td>"
            f"<td>{_num(r['largest_error'])} at {r['largest_error_time']:.3f} s</td></tr>")
    rows.append("</table>")
    return rows


def _scope(report: VerifyReport) -> str:
    what = scope(report)
    return f" ({what})" if what else ""


def render_html(report: VerifyReport, art: Artefacts | None = None) -> str:
    art = art or Artefacts()
    verdict = report.verdict
    n_fail = len(report.failed)
    headline = {"pass": f"PASS: {len(report.checks)} checks passed",
                "fail": f"FAIL: {n_fail} of {len(report.checks)} checks failed",
                "error": "ERROR: the verification could not run"}[verdict]
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>modelkit verify: {_e(report.robot or report.source)}</title>",
           f"<style>{CSS}</style></head><body>",
           f"<h1>modelkit verify: {_e(report.robot or '(no robot)')}</h1>",
           f'<div class="verdict {verdict}">{_e(headline)}, {len(report.skips)} skipped, '
           f"{len(report.observations)} observations{_e(_scope(report))}</div>",
           '<table class="meta">',
           f"<tr><td>source</td><td>{_e(report.source)}</td></tr>",
           f"<tr><td>base</td><td>{_e(report.base)}</td></tr>",
           f"<tr><td>reference</td><td>{_e(report.reference)}</td></tr>",
           f"<tr><td>seed</td><td>{report.seed}</td></tr>"]
    if report.injected:
        out.append(f"<tr><td>injected faults</td><td>{_e('; '.join(report.injected))}</td></tr>")
    out.append("</table>")
    for e in report.errors:
        out.append(f'<p class="verdict error">{_e(e)}</p>')
    if report.failed:
        out.append("<h2>Failed checks</h2><ul>")
        out += [f"<li><b>layer {c.layer} {_e(c.engine)} {_e(c.quantity)} {_e(c.where)}</b>: {_e(c.detail)} "
                f"(error {_num(c.error)} &gt; tolerance {_num(c.tolerance)})</li>" for c in report.failed]
        out.append("</ul>")
    static = [c for c in report.checks if c.layer != 4]
    driven = [c for c in report.checks if c.layer == 4]
    out.append("<h2>Layers 1–3: static, kinematics, dynamics</h2>")
    if static:  # a long table: folded when every check passed, open when one failed
        failed = sum(1 for c in static if not c.passed)
        state = f"{failed} of {len(static)} checks failed" if failed else f"all {len(static)} checks passed"
        out.append(f"<details{' open' if failed else ''}><summary>{state} (the table)</summary>"
                   + _checks_table(static) + "</details>")
    else:
        out.append("<p>No checks.</p>")
    out += _replay_calibration(report.replay)
    out.append("<h2>Layer 4: driven on a floor</h2>")
    if driven:
        out.append(_checks_table(driven))
    if report.observations:
        out.append("<h3>Observations (reported, not graded)</h3>" + _observations_table(report.observations))
    if not driven and not report.observations:
        out.append("<p>No layer 4 results (see the skips).</p>")
    if art.plots:
        out.append("<h3>Trajectories</h3><p>Per profile: the path of the root link, the position and yaw "
                   "errors on a log axis (engines against each other, each engine against the rigid "
                   "no-slip reference; the red lines are the tolerances), the wheel angles, the other "
                   "controlled joints and the wheel-angle differences.</p>")
        for profile, rel, data in art.plots:
            out.append(f'<figure class="plot" id="plot-{_e(Path(rel).stem)}">'
                       f'{_img(data, f"profile {profile}")}<figcaption>profile '
                       f"{_e(profile)} ({_e(rel)})</figcaption></figure>")
    if report.scenario or report.drive:
        out.append("<details><summary>scenario and drive as run</summary>"
                   + _json_block({"scenario": report.scenario, "drive": report.drive}) + "</details>")
    if report.skips:
        out.append("<h2>Skipped (never a silent pass)</h2>" + _skips_table(report.skips))
    out += _pictures_section(art)
    for note in art.notes:
        out.append(f'<p class="note">{_e(note)}</p>')
    out.append("<h2>Engines and their settings</h2>")
    for name, settings in sorted(report.engines.items()):
        out.append(f"<details><summary>{_e(name)}</summary>{_json_block(settings)}</details>")
    if art.pictures is not None:
        out.append("<details><summary>pictures</summary>" + _json_block(art.pictures.settings) + "</details>")
    out.append("<h2>Files and conversion notes</h2><table><tr><th>format</th><th>file</th><th>note codes</th>"
               "<th>renames</th></tr>")
    for fmt, name in sorted(report.files.items()):
        renames = report.renames.get(fmt, {})
        shown = "; ".join(f"{kind}: " + ", ".join(f"{a} → {b}" for a, b in sorted(m.items()))
                          for kind, m in sorted(renames.items()) if m)
        codes = ", ".join(report.notes.get(fmt, []))
        out.append(f"<tr><td>{_e(fmt)}</td><td>{_e(name)}</td><td>{_e(codes)}</td>"
                   f"<td>{_e(shown)}</td></tr>")
    out.append("</table>")
    if report.parameters:
        out.append("<details><summary>parameters</summary>" + _json_block(report.parameters) + "</details>")
    if report.artefacts:
        out.append("<details><summary>files written with this report</summary><ul>")
        out += [f"<li>{_e(k)}: {_e(v)}</li>" for k, v in sorted(report.artefacts.items())]
        out.append("</ul></details>")
    out.append("</body></html>")
    return "\n".join(out) + "\n"
