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
