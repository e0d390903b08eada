"""Layer 4's plots: one PNG per command profile, six panels, drawn with matplotlib's Agg canvas.

Panels (every engine run and every reference of the profile, from ``VerifyReport.trajectories``):

* **path**: y against x of the root link frame (metres, equal axes);
* **position error** and **yaw error** against time on a log axis: the engines against each other
  (``mujoco~pybullet``) and each engine against the rigid no-slip reference, with the pass
  thresholds as horizontal lines, so a reader sees when and how fast two runs part;
* **wheel angles** (left, right) of every run, and **the other controlled joints** (pan, tilt);
* **wheel-angle difference** between the engines and against the no-slip reference (log).

Styles: MuJoCo blue, PyBullet orange, the no-slip reference black dashed, the ideal unicycle grey
dotted, a run's own wheel odometry thin dotted in the run's colour; the native-wheel runs (report
only) dashed.

matplotlib is imported here only, lazily (``validate``, ``tree`` and ``convert`` never import it):
``Figure`` and ``FigureCanvasAgg`` directly, no pyplot and no global state. The bytes are
deterministic: fixed size, dpi, fonts (DejaVu Sans, shipped with matplotlib), explicit style (no
user ``matplotlibrc`` applies), and no ``Software`` metadata.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from modelkit import safewrite
from modelkit.verify import oneshot

Array = NDArray[np.float64]

DPI = 80
SIZE = (12.0, 7.0)  # inches: 960 × 560 pixels
COLOURS = {"mujoco": "#1f77b4", "pybullet": "#ff7f0e", "noslip": "#000000", "unicycle": "#7f7f7f"}
OTHER = ["#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
DEFAULT_TOLERANCES = {"engines_position": 0.01, "engines_yaw": 0.010, "engines_wheel": 0.02,
                      "noslip_position": 0.015, "noslip_yaw": 0.015}
STYLE = {
    "font.family": "DejaVu Sans", "font.size": 8.0, "axes.titlesize": 9.0, "axes.labelsize": 8.0,
    "legend.fontsize": 7.0, "xtick.labelsize": 7.0, "ytick.labelsize": 7.0, "lines.linewidth": 1.2,
    "axes.grid": True, "grid.alpha": 0.3, "figure.facecolor": "white", "axes.facecolor": "white",
    "savefig.facecolor": "white", "path.simplify": True, "axes.prop_cycle": None,
    # A fixed title position: the automatic one measures every tick label of the axes (a third of
    # the drawing time).
    "axes.titley": 1.0, "axes.titlepad": 3.0,
    "xtick.minor.visible": False, "ytick.minor.visible": False,
}


def _style() -> dict[str, Any]:
    from cycler import cycler

    return dict(STYLE, **{"axes.prop_cycle": cycler(color=OTHER)})


def _colour(source: str) -> str:
    engine = source.split(":", 1)[-1]
    return COLOURS.get(engine, OTHER[sum(map(ord, engine)) % len(OTHER)])


def _label(tr: Any) -> str:
    return tr.source + (f" ({tr.variant})" if tr.variant == "native" else "")


def _line_style(tr: Any) -> dict[str, Any]:
    if tr.source == "noslip":
        return {"color": COLOURS["noslip"], "linestyle": "--", "linewidth": 1.0}
    if tr.source == "unicycle":
        return {"color": COLOURS["unicycle"], "linestyle": ":", "linewidth": 1.2}
    if tr.source.startswith("odometry:"):
        return {"color": _colour(tr.source), "linestyle": ":", "linewidth": 0.8}
    dashed = tr.variant == "native"
    return {"color": _colour(tr.source), "linestyle": "--" if dashed else "-", "linewidth": 1.3}


def _engines(trajectories: Sequence[Any]) -> list[Any]:
    return [t for t in trajectories if t.source not in ("noslip", "unicycle") and ":" not in t.source]


MAX_POINTS = 400  # per line: the samples are 100 Hz over ~10 s; more points only cost drawing time


def _thin(*columns: Array) -> list[Array]:
    """Every k-th sample (and the last) so that a line has at most MAX_POINTS points."""
    n = len(columns[0])
    if n <= MAX_POINTS:
        return list(columns)
    idx = np.unique(np.concatenate([np.arange(0, n, math.ceil(n / MAX_POINTS)), [n - 1]]))
    return [c[idx] for c in columns]


def _positive(values: Array) -> Array:
    """Exact zeros (identical runs, the common start) are left out of a log axis."""
    out = np.asarray(values, dtype=float).copy()
    out[out <= 0.0] = np.nan
    return out


def _on(t: Array, tr: Any, values: Array) -> Array:
    return np.interp(t, np.asarray(tr.t, dtype=float), np.asarray(values, dtype=float))


def pose_errors(a: Any, b: Any) -> tuple[Array, Array, Array]:
    """(t, |Δposition|, |Δyaw| wrapped to ±π) of run ``a`` against run ``b`` on ``a``'s samples
    (``b`` interpolated)."""
    t = np.asarray(a.t, dtype=float)
    dx = np.asarray(a.x, dtype=float) - _on(t, b, b.x)
    dy = np.asarray(a.y, dtype=float) - _on(t, b, b.y)
    dyaw = np.asarray(a.yaw, dtype=float) - _on(t, b, b.yaw)
    dyaw = (dyaw + math.pi) % (2.0 * math.pi) - math.pi
    return t, np.hypot(dx, dy), np.abs(dyaw)


def wheel_error(a: Any, b: Any) -> tuple[Array, Array]:
    t = np.asarray(a.t, dtype=float)
    wa, wb = np.asarray(a.wheels, dtype=float), np.asarray(b.wheels, dtype=float)
    if wa.ndim != 2 or wb.ndim != 2 or wa.shape[1] != 2 or wb.shape[1] != 2:
        return t, np.full(len(t), np.nan)
    diff = np.stack([wa[:, i] - _on(t, b, wb[:, i]) for i in range(2)], axis=1)
    return t, np.max(np.abs(diff), axis=1)


def _pairs(trajectories: Sequence[Any]) -> list[tuple[str, Any, Any, str]]:
    """The comparisons drawn on the error panels: (label, run, against, kind "engines"|"noslip")."""
    engines = _engines(trajectories)
    noslip = next((t for t in trajectories if t.source == "noslip"), None)
    out = []
    for variant in sorted({e.variant for e in engines}, key=lambda v: (v != "sphere", v)):
        runs = sorted((e for e in engines if e.variant == variant), key=lambda e: e.source)
        suffix = f" ({variant})" if variant == "native" else ""
        for i, a in enumerate(runs):
            for b in runs[i + 1:]:
                out.append((f"{a.source}~{b.source}{suffix}", a, b, "engines"))
        if noslip is not None:
            out.extend((f"{a.source} vs no-slip{suffix}", a, noslip, "noslip") for a in runs)
    return out


def _pair_style(label: str, a: Any, b: Any, kind: str) -> dict[str, Any]:
    colour = "#6a3d9a" if kind == "engines" else _colour(a.source)
    return {"color": colour, "linestyle": "--" if a.variant == "native" else "-", "linewidth": 1.2}


def _log_panel(ax: Any, title: str, unit: str) -> None:
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    ax.set_yscale("log", nonpositive="mask")
    ax.yaxis.set_major_locator(LogLocator(base=10.0, numticks=6))
    ax.yaxis.set_minor_locator(NullLocator())  # log minor ticks cost more than the rest of the panel
    ax.yaxis.set_major_formatter(FuncFormatter(_decade))  # plain text: no mathtext to parse and lay out
    ax.set_title(title)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(unit)


SUPERSCRIPT = str.maketrans("-0123456789",
                            "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def _decade(value: float, _: Any = None) -> str:
    """A log axis' tick label as plain text: 10⁻³ (superscript digits, in DejaVu Sans)."""
    if value <= 0.0 or not math.isfinite(value):
        return ""
    exponent = math.log10(value)
    if abs(exponent - round(exponent)) > 1e-9:
        return f"{value:g}"
    return "10" + str(round(exponent)).translate(SUPERSCRIPT)


def profile_figure(profile: str, trajectories: Sequence[Any], tolerances: dict[str, float] | None = None,
                   title: str = "", wheels: Iterable[str] = ()) -> bytes:
    """The PNG bytes of one profile's six panels; ``wheels``: the drive's joints (plotted in the wheel
    panel, left out of the other-joints panel)."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    tol = dict(DEFAULT_TOLERANCES, **(tolerances or {}))
    with matplotlib.rc_context(_style()):  # type: ignore[arg-type]
        fig = Figure(figsize=SIZE, dpi=DPI)
        FigureCanvasAgg(fig)
        axes = fig.subplots(2, 3)
        fig.suptitle(title or f"profile {profile}", fontsize=10)
        _path_panel(axes[0][0], trajectories)
        pairs = _pairs(trajectories)
        _error_panels(axes[0][1], axes[0][2], pairs, tol)
        _wheel_panel(axes[1][0], trajectories)
        _joint_panel(axes[1][1], trajectories, set(wheels))
        _wheel_error_panel(axes[1][2], pairs, tol)
        fig.subplots_adjust(left=0.06, right=0.985, bottom=0.08, top=0.9, wspace=0.28, hspace=0.38)
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=DPI, metadata={"Software": None})
    return buffer.getvalue()


def _path_panel(ax: Any, trajectories: Sequence[Any]) -> None:
    framed: list[Array] = []  # the graded runs and the references set the frame; native runs may leave it
    for tr in trajectories:
        x, y = _thin(np.asarray(tr.x, dtype=float), np.asarray(tr.y, dtype=float))
        ax.plot(x, y, label=_label(tr), **_line_style(tr))
        if tr.variant != "native" and len(x):
            framed.append(np.array([[x.min(), x.max()], [y.min(), y.max()]]))
    ax.plot([0.0], [0.0], marker="o", color="black", markersize=3, linestyle="none")
    if framed:
        lo = np.min([f[:, 0] for f in framed], axis=0)
        hi = np.max([f[:, 1] for f in framed], axis=0)
        half = 0.54 * max(float(np.max(hi - lo)), 0.05)  # a square window around the framed runs
        centre = (lo + hi) / 2.0
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal", adjustable="box")
    ax.set_title("path of the root link (start at 0, 0)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if trajectories:
        ax.legend(loc="upper left")


def _error_panels(pos_ax: Any, yaw_ax: Any, pairs: list[tuple[str, Any, Any, str]], tol: dict[str, float]
                  ) -> None:
    _log_panel(pos_ax, "position error", "|Δp| (m)")
    _log_panel(yaw_ax, "yaw error", "|Δyaw| (rad)")
    for label, a, b, kind in pairs:
        t, dp, dyaw = pose_errors(a, b)
        style = _pair_style(label, a, b, kind)
        t, dp, dyaw = _thin(t, _positive(dp), _positive(dyaw))
        pos_ax.plot(t, dp, label=label, **style)
        yaw_ax.plot(t, dyaw, label=label, **style)
    panels = ((pos_ax, ("engines_position", "noslip_position")), (yaw_ax, ("engines_yaw", "noslip_yaw")))
    for ax, keys in panels:
        _thresholds(ax, [(tol[keys[0]], "engines"), (tol[keys[1]], "no-slip")])
    if pairs:  # one legend for the three comparison panels (the same lines in each)
        pos_ax.legend(loc="lower right")


def _thresholds(ax: Any, lines: Iterable[tuple[float, str]]) -> None:
    lines = list(lines)
    if not ax.lines and lines:  # nothing drawn: a range around the tolerances (a log axis needs one)
        values = [v for v, _ in lines]
        ax.set_ylim(min(values) / 1e3, max(values) * 10.0)
    seen: set[float] = set()
    for value, what in lines:
        if value in seen:
            continue
        seen.add(value)
        ax.axhline(value, color="#b22222", linestyle="-." if what == "no-slip" else ":", linewidth=0.9)
        ax.annotate(f"{what} tolerance {value:g}", xy=(0.01 if what == "engines" else 0.5, value),
                    xycoords=("axes fraction", "data"), fontsize=6.5, color="#b22222", va="bottom")


def _wheel_panel(ax: Any, trajectories: Sequence[Any]) -> None:
    ax.set_title("wheel angles (left solid, right dash-dot; colours as in the path)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("rad")
    for tr in trajectories:
        wheels = np.asarray(tr.wheels, dtype=float)
        if tr.source == "unicycle" or wheels.ndim != 2 or wheels.shape[1] != 2 or len(wheels) == 0:
            continue
        style = _line_style(tr)
        t, left, right = _thin(np.asarray(tr.t, dtype=float), wheels[:, 0], wheels[:, 1])
        ax.plot(t, left, label=f"{_label(tr)} left", **style)
        ax.plot(t, right, label=f"{_label(tr)} right", **dict(style, linestyle="-."))


def _joint_panel(ax: Any, trajectories: Sequence[Any], wheels: set[str]) -> None:
    ax.set_title("other controlled joints (pan, tilt)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("rad")
    names = sorted({name for tr in trajectories for name in tr.joints} - wheels)
    dashes = ["-", "-.", "--", ":"]
    for tr in _engines(trajectories) + [t for t in trajectories if t.source == "noslip"]:
        for i, name in enumerate(names):
            if name not in tr.joints:
                continue
            style = dict(_line_style(tr), linestyle=dashes[i % len(dashes)])
            t, q = _thin(np.asarray(tr.t, dtype=float), np.asarray(tr.joints[name], dtype=float))
            ax.plot(t, q, label=f"{_label(tr)} {name}", **style)
    if ax.lines:
        ax.legend(loc="upper left", ncol=2)
    else:
        ax.text(0.5, 0.5, "no other controlled joints", ha="center", va="center", transform=ax.transAxes)


def _wheel_error_panel(ax: Any, pairs: list[tuple[str, Any, Any, str]], tol: dict[str, float]) -> None:
    _log_panel(ax, "wheel-angle difference (worst wheel)", "|Δθ| (rad)")
    for label, a, b, kind in pairs:
        t, dw = wheel_error(a, b)
        if np.all(np.isnan(dw)):
            continue
        t, dw = _thin(t, _positive(dw))
        ax.plot(t, dw, label=label, **_pair_style(label, a, b, kind))
    _thresholds(ax, [(tol["engines_wheel"], "engines")])


def profiles(trajectories: Sequence[Any]) -> list[str]:
    """The profiles in the order they first appear."""
    return list(dict.fromkeys(t.profile for t in trajectories))


def write_plots(trajectories: Sequence[Any], out_dir: Path, tolerances: dict[str, float] | None = None,
                wheels: Iterable[str] = (), plotters: Plotters | None = None, root: Path | None = None
                ) -> list[tuple[str, Path, bytes]]:
    """One PNG per profile in ``out_dir`` (``<profile>.png``, a file-safe name): (profile, path,
    bytes). The figures are drawn by ``plotters`` (child processes, see :class:`Plotters`; started
    here when None and there are several profiles and cores), the same bytes as drawn here."""
    root = out_dir if root is None else root  # nothing is written through a link below it
    safewrite.make_folder(root, out_dir)
    names = profiles(trajectories)
    jobs = [(p, [t for t in trajectories if t.profile == p], tolerances, tuple(wheels)) for p in names]
    own = plotters is None and len(jobs) > 1 and usable_cores() > 1
    if own:
        plotters = Plotters()
    try:
        figures = plotters.draw(jobs) if plotters is not None else [_draw(job) for job in jobs]
    finally:
        if own and plotters is not None:
            plotters.close()
    written = []
    for profile, data in zip(names, figures, strict=True):
        path = out_dir / f"{safe_name(profile)}.png"
        safewrite.write_bytes(root, path, data)
        written.append((profile, path, data))
    return written


# ---- drawing in child processes -------------------------------------------------------------------
# Each figure costs ~0.3 s of pure-Python matplotlib work (text layout, ticks) and matplotlib's import
# another ~0.3 s: drawn serially, the plots were a third of a verify run. Plotters are plain child
# processes (``sys.executable -c``, no fork: safe in any parent, threads or not) that import matplotlib
# as soon as they start (``verify`` starts them while the layers run) and draw their share of the
# profiles when asked; the parent never imports matplotlib. Any failure of a child falls back to
# drawing here, so the result never depends on the children: the same function draws the same bytes.

PLOTTERS = 2
PLOTTER_TIMEOUT = 120.0
_CHILD = "import sys; from modelkit.verify.report.plots import serve; sys.exit(serve())"


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def _draw(job: tuple[str, list[Any], dict[str, float] | None, tuple[str, ...]]) -> bytes:
    profile, runs, tolerances, wheels = job
    return profile_figure(profile, runs, tolerances, wheels=wheels)


def serve() -> int:
    """A plotter's entry point: import matplotlib, then read one pickled list of jobs (profile, runs,
    tolerances, wheels) on stdin and write the pickled ("ok", [PNG bytes]) or ("error", message)."""
    # The imports are the point: done before the jobs come.
    import matplotlib.backends.backend_agg
    import matplotlib.figure  # noqa: F401

    return oneshot.serve(lambda jobs: [_draw(job) for job in jobs])


class Plotters:
    """``count`` plotting child processes, started at once (they import matplotlib while the caller
    works); :meth:`draw` shares the figures out among them (one request each) and returns the PNG
    bytes in order. Use each once; :meth:`close` ends what is left."""

    def __init__(self, count: int = PLOTTERS) -> None:
        self.children: list[oneshot.Child] = []
        for _ in range(max(1, count)):
            try:
                self.children.append(oneshot.Child(_CHILD))
            except OSError:
                break

    def draw(self, jobs: Sequence[tuple[str, list[Any], dict[str, float] | None, tuple[str, ...]]]
             ) -> list[bytes]:
        children, self.children = self.children, []
        n = max(1, min(len(children), len(jobs)))
        # Largest first, each to the least loaded child (the cost grows with the number of lines).
        order = sorted(range(len(jobs)), key=lambda i: (-len(jobs[i][1]), i))
        shares: list[list[int]] = [[] for _ in range(n)]
        load = [0] * n
        for i in order:
            k = load.index(min(load))
            shares[k].append(i)
            load[k] += len(jobs[i][1]) + 4
        out: list[bytes | None] = [None] * len(jobs)
        sent = []
        for child, share in zip(children, shares, strict=False):
            try:
                child.send([jobs[i] for i in share])
                sent.append((child, share))
            except (OSError, ValueError):
                child.end()
        for child in children[len(shares):]:
            child.end()
        for child, share in sent:
            status, value = child.reply(PLOTTER_TIMEOUT)
            if status == "ok" and len(value) == len(share):
                for i, data in zip(share, value, strict=True):
                    out[i] = data
        return [data if data is not None else _draw(jobs[i]) for i, data in enumerate(out)]

    def close(self) -> None:
        for child in self.children:
            child.end()
        self.children = []


def safe_name(name: str) -> str:
    out = "".join(c if c.isalnum() or c in "-_." else "_" for c in name).strip("._")
    return out or "profile"
