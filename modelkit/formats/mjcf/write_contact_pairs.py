"""An MJCF source's own ``<contact>`` section (``<pair>`` and ``<exclude>``), written back.

The reader keeps each element's attributes as written (``robot.extras["mjcf_contact_pairs"]``); an
element is written when every geom and body it names is in the output (names the writer kept), its
numbers in the writers' form (:func:`modelkit.convert.numbers.fmt_text`), and otherwise left out with
MK851. They go in before the self-contact check, which then finds only the
touching pairs the source does not already exclude.
"""

from __future__ import annotations

from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt_text
from modelkit.formats.mjcf.write_xml import sub
from modelkit.model import Robot

KEY = "mjcf_contact_pairs"
REFERENCES = {"pair": ("geom1", "geom2"), "exclude": ("body1", "body2")}
NAMES = {"name", "geom1", "geom2", "body1", "body2"}  # written as they are; the numbers in the writers' form


def write_source_pairs(root: Element, contact: Element, robot: Robot, ctx: WriteContext) -> None:
    kept = robot.extras.get(KEY) or []
    if not kept:
        return
    names = {
        "geom1": {g.get("name") for g in root.iter("geom")},
        "body1": {b.get("name") for b in root.iter("body")} | {"world"},
    }
    names["geom2"], names["body2"] = names["geom1"], names["body1"]
    for entry in kept:
        tag = str(entry.get("tag"))
        attributes = {str(k): str(v) for k, v in dict(entry.get("attributes", {})).items() if k != "class"}
        refs = REFERENCES.get(tag, ())
        missing = [attributes.get(ref, "") for ref in refs if attributes.get(ref) not in names[ref]]
        if not refs or missing:
            ctx.note("MK851", f"<contact><{tag}> {' '.join(f'{k}={v!r}' for k, v in attributes.items())} is "
                     f"not written: {', '.join(repr(m) for m in missing) or 'its kind'} is not in the "
                     "written file", robot.source, f"contact/{tag}")
            continue
        sub(contact, tag, **{k: v if k in NAMES else fmt_text(v) for k, v in attributes.items()})
