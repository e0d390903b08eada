"""The verdict of a ``verify`` run: the table printed on the terminal and ``report.json``
(schema ``schemas/verify-report.schema.json``). Everything in the JSON is deterministic: the same
input, engines and seed give the same bytes (wall times are printed, never written)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.verify.engines.protocol import Check, Observation, Skip

SCHEMA_ID = "modelkit-verify-report/1"
LAYER_NAMES = {0: "all", 1: "1 static", 2: "2 kinematics", 3: "3 dynamics", 4: "4 driven"}


@dataclass
class VerifyReport:
    source: str
    robot: str = ""
    seed: int = 0
    base: str = ""  # how the base was treated for layers 1–3 (welded at the identity)
    reference: str = ""  # what the layers compare with (the source model, or its track approximation)
    parameters: dict[str, Any] = field(default_factory=dict)
    files: dict[str, str] = field(default_factory=dict)  # "mjcf" → file name (as written or given)
    renames: dict[str, dict[str, dict[str, str]]] = field(default_factory=dict)  # fmt → kind → src → written
    notes: dict[str, list[str]] = field(default_factory=dict)  # fmt → conversion note codes (sorted, unique)
    injected: list[str] = field(default_factory=list)
    engines: dict[str, dict[str, Any]] = field(default_factory=dict)  # label → settings
    checks: list[Check] = field(default_factory=list)
    skips: list[Skip] = field(default_factory=list)
    observations: list[Observation] = field(default_factory=list)  # layer 4: reported, not graded
    replay: dict[str, Any] = field(default_factory=dict)  # layer 3b: the tolerance's calibration per engine
    scenario: dict[str, Any] = field(default_factory=dict)  # layer 4: the scenario as run (plain data)
    drive: dict[str, Any] = field(default_factory=dict)  # layer 4: Drive.as_dict() of the model
    trajectories: list[Any] = field(default_factory=list)  # layer 4: drive.Trajectory, for the plots
    artefacts: dict[str, str] = field(default_factory=dict)  # "html" → report.html, "plot:xy" → png...
    errors: list[str] = field(default_factory=list)  # why the run could not happen (exit 2)
    timings: dict[str, float] = field(default_factory=dict)  # wall seconds; printed, not in report.json
    prepared: Any = field(default=None, repr=False, compare=False)  # html.Prepared: artefacts started early

    @property
    def failed(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]

    @property
    def exit_code(self) -> int:
        if self.errors:
            return 2
        return 1 if self.failed else 0

    @property
    def verdict(self) -> str:
        return {0: "pass", 1: "fail", 2: "error"}[self.exit_code]


def _number(x: float) -> float | None:
    """JSON has no infinity or NaN: those are written as null (the check then fails)."""
    return float(x) if math.isfinite(x) else None


def plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float):
        return _number(value)
    return value


def check_json(c: Check) -> dict[str, Any]:
    return {"layer": c.layer, "engine": c.engine, "quantity": c.quantity, "where": c.where,
            "error": _number(c.error), "tolerance": c.tolerance, "passed": c.passed, "detail": c.detail}


def report_json(report: VerifyReport) -> str:
    data = {
        "schema": SCHEMA_ID,
        "source": report.source,
        "robot": report.robot,
        "verdict": report.verdict,
        "exit_code": report.exit_code,
        "seed": report.seed,
        "base": report.base,
        "reference": report.reference,
        "parameters": plain(report.parameters),
        "files": dict(sorted(report.files.items())),
        "renames": plain(report.renames),
        "notes": plain(report.notes),
        "injected": list(report.injected),
        "engines": plain(report.engines),
        "checks": [check_json(c) for c in report.checks],
        "skips": [{"layer": s.layer, "engine": s.engine, "reason": s.reason} for s in report.skips],
        "observations": [{"layer": o.layer, "engine": o.engine, "quantity": o.quantity, "where": o.where,
                          "value": _number(o.value), "unit": o.unit, "detail": o.detail}
                         for o in report.observations],
        "replay": plain(report.replay),
        "scenario": plain(report.scenario),
        "drive": plain(report.drive),
        "errors": list(report.errors),
    }
    return json.dumps(data, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def _fmt(x: float) -> str:
    if math.isinf(x) or math.isnan(x):
        return str(x)
    if x == 0:
        return "0"
    if x == int(x) and abs(x) < 1e6:
        return str(int(x))
    return f"{x:.2e}"


COMPARISONS = frozenset({"path-position", "path-yaw", "wheel-angle", "pan-tilt-angle", "noslip-position",
                         "noslip-yaw", "skid-position", "skid-yaw"})
"""Layer 4's comparison quantities: graded as checks, or reported as observations (then said so)."""


def scope(report: VerifyReport) -> str:
    """What layer 4 graded and what it only reported, for the verdict line (so that nothing
    report-only hides inside a PASS); that it did not run, when a skip says so."""
    graded = sorted({c.where for c in report.checks if c.layer == 4})
    not_run = any(s.layer == 4 and s.engine == "all" and " not run" in s.reason for s in report.skips)
    if not graded and not_run:
        return "layer 4 not run: see its skip"
    reported = sorted({o.where for o in report.observations
                       if o.layer == 4 and o.quantity.removeprefix("native-") in COMPARISONS} - set(graded))
    files = report.engines.get("layer4", {}).get("files", {})
    given = set(report.engines.get("layer4", {}).get("given", []))
    parts = []
    if graded:
        named = [f"{'the given' if kind in given else 'the written'} {name}"
                 for kind, name in sorted(files.items())]
        on = f" on {', '.join(named)}" if named else ""
        skid = any(c.layer == 4 and c.quantity.startswith("skid-") for c in report.checks)
        against = " against the skid-steer reference" if skid else ""
        parts.append(f"layer 4 graded {', '.join(graded)}{against}{on}")
    if reported:
        parts.append(f"not graded (reported only): {', '.join(reported)}")
    checked = {(c.engine, c.where) for c in report.checks if c.layer == 4}
    engines_out = sorted({o.engine for o in report.observations
                          if o.layer == 4 and o.quantity in COMPARISONS and o.where in graded
                          and (o.engine, o.where) not in checked and "~" not in o.engine})
    for engine in engines_out:
        parts.append(f"{engine} not graded on layer 4 (see its skip)")
    return "; ".join(parts)


def render_table(report: VerifyReport) -> str:
    """The verdict table: one row per layer × engine × quantity, then the skips and the verdict."""
    lines = [f"verify {report.source} ({report.robot}): {report.base}"]
    if report.reference:
        lines.append(f"reference: {report.reference}")
    if report.injected:
        lines.append("injected: " + "; ".join(report.injected))
    header = ("layer", "engine", "quantity", "worst error", "tolerance", "", "where")
    rows = [(LAYER_NAMES.get(c.layer, str(c.layer)), c.engine, c.quantity, _fmt(c.error), _fmt(c.tolerance),
             "ok" if c.passed else "FAIL", c.where) for c in report.checks]
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    lines.append("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip())
    for r in rows:
        lines.append("  ".join(str(v).ljust(w) for v, w in zip(r, widths, strict=True)).rstrip())
    for c in report.failed:
        lines.append(f"FAIL layer {c.layer} {c.engine} {c.quantity} {c.where}: {c.detail} "
                     f"(error {_fmt(c.error)} > tolerance {_fmt(c.tolerance)})")
    for o in report.observations:
        value = "inf" if not math.isfinite(o.value) else f"{o.value:.3g} {o.unit}"
        lines.append(f"reported (not graded): layer 4 {o.engine} {o.quantity} {o.where}: {value}")
    for s in report.skips:
        lines.append(f"skipped: layer {LAYER_NAMES.get(s.layer, s.layer)}, {s.engine}: {s.reason}")
    for e in report.errors:
        lines.append(f"error: {e}")
    if report.timings:
        lines.append("wall time: " + ", ".join(f"{k} {v:.2f} s" for k, v in report.timings.items()))
    n_fail = len(report.failed)
    verdict = {"pass": f"PASS: {len(report.checks)} checks passed",
               "fail": f"FAIL: {n_fail} of {len(report.checks)} checks failed",
               "error": "could not run"}[report.verdict]
    what = scope(report)
    lines.append(f"{verdict}, {len(report.skips)} skipped" + (f" ({what})" if what else ""))
    return "\n".join(lines) + "\n"
