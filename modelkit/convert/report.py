"""How a conversion is shown: a readable summary on stderr and the JSON report (``--report``)."""

from __future__ import annotations

import json
from collections import Counter

from modelkit.convert.api import ConversionResult
from modelkit.diagnostics import Severity

REPORT_VERSION = 1


def render_summary(result: ConversionResult, quiet: bool = False) -> str:
    """Notes one per line (info notes left out when ``quiet``), then a count line."""
    lines = [n.render() for n in result.notes if not (quiet and n.severity is Severity.INFO)]
    # every finding printed counts: the reading's diagnostics (printed before) and the notes
    counts = Counter([n.severity.value for n in result.notes]
                     + [d.severity.value for d in result.diagnostics])
    written = ", ".join(result.outputs) if result.outputs else "nothing"
    errors = f"{counts['error']} error(s), " if counts.get("error") else ""
    lines.append(
        f"wrote {written}; notes: {errors}{counts.get('warning', 0)} warning(s), {counts.get('info', 0)} info"
    )
    return "\n".join(lines) + "\n"


def report_json(result: ConversionResult, inputs: list[str]) -> str:
    """Every note and reading finding, deterministic (sorted keys, notes in writer order)."""
    body = {
        "version": REPORT_VERSION,
        "inputs": inputs,
        "outputs": result.outputs,
        "status": result.status,
        "notes": [n.to_json() for n in result.notes],
        "diagnostics": [d.to_json() for d in result.diagnostics],
    }
    return json.dumps(body, indent=2, sort_keys=True, ensure_ascii=False) + "\n"
