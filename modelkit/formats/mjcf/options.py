"""An MJCF file's own ``<option>``: the simulator settings its author chose, kept for MJCF output.

Read from the source text (every ``<option>`` section, included files too; a later one's attribute
wins, as MuJoCo merges them): the attributes as written and the ``<flag>`` switches. The MJCF writer
prints their numbers in its own form (``timestep=".005"`` → ``"0.005"``); other targets cannot hold
them and say so (MK853).
"""

from __future__ import annotations

from typing import Any

FLAGS = "flag"  # the key of the <flag> attributes in the kept options


def source_options(index: Any) -> dict[str, Any]:
    """``{attribute: text}`` of the file's ``<option>`` sections, with ``"flag": {name: text}``."""
    out: dict[str, Any] = {}
    flags: dict[str, str] = {}
    for section in index.sections("option"):
        for key, value in section.el.attrib.items():
            out[str(key)] = " ".join(str(value).split())
        for child in index.children(section):
            if child.tag == FLAGS:
                flags.update({str(k): " ".join(str(v).split()) for k, v in child.el.attrib.items()})
    if flags:
        out[FLAGS] = dict(sorted(flags.items()))
    return out


GLOBAL_SECTIONS = ("size", "visual", "statistic")
"""Top-level sections that set MuJoCo itself up rather than the robot: memory and array sizes, the
viewer's look, the model's extent for the free camera. Kept as written for MJCF output; another
simulator has nothing of the robot to miss in them (declared quiet)."""


def source_globals(index: Any) -> list[str]:
    """The file's ``<size>``, ``<visual>`` and ``<statistic>`` sections (included files too), as XML in
    document order, whitespace dropped (the writer indents anew)."""
    from lxml import etree

    from modelkit.xmlsource import bare_copy

    out: list[str] = []
    for tag in GLOBAL_SECTIONS:
        for section in index.sections(tag):
            copy = bare_copy(section.el)
            if len(copy) or copy.attrib:
                out.append(etree.tostring(copy, encoding="unicode"))
    return out
