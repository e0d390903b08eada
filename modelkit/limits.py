"""Size limits every reader applies before it builds a model (see docs/validate.md, "Limits").

The byte limit (MK002) is applied when a file is read (:mod:`modelkit.textio`), the list limit
(MK006) while YAML is scanned (:mod:`modelkit.yamltree`); the link limit (MK005) is applied here,
on counts taken from the parsed document before any per-link work starts.
"""

from __future__ import annotations

from modelkit.diagnostics import DiagnosticSink, SourceLocation


def too_many_links(sink: DiagnosticSink, where: SourceLocation, links: int, joints: int, limit: int) -> bool:
    """Report MK005 and give True when ``links`` or ``joints`` passes ``limit``."""
    if links <= limit and joints <= limit:
        return False
    what = f"{links} links" if links > limit else f"{joints} joints"
    sink.emit(
        "MK005",
        f"the model has {what}, over the limit of {limit}; it is not read further",
        where,
        hint="raise the limit with --max-links if the model is genuine",
    )
    return True
