"""An MJCF source's own ``<contact>`` section (``<pair>`` and ``<exclude>``), written back.

The reader keeps each element's attributes as written (``robot.extras["mjcf_contact_pairs"]``); an
element is written when every geom and body it names is in the output (names the writer kept), its
numbers in the writers' form (:func:`modelkit.convert.numbers.fmt_text`), and otherwise left out with
MK851. They go in before the self-contact check, which then finds only the
touching pairs the source does not already exclude.

A ``<pair>`` between a robot geom and a world geom (the source's floor, which a robot file does not
hold) is left out too; but where the robot geom collides through such pairs alone (``contype`` and
``conaffinity`` without bit 0, as MJX models such as jaxterity's G1 write their feet), it would then
fall through any floor the user adds. That geom gets bit 0 in ``contype`` (a default floor,
``contype="1" conaffinity="1"``, then collides with it; the geom's ``conaffinity`` is kept, so robot
geoms that did not touch it still do not, unless their own ``conaffinity`` has bit 0) and the pair's
``condim``, ``friction`` (sliding, spin and roll: one sliding coefficient where the pair had two),
``solref``, ``solimp``, ``margin`` and ``gap``, which its collision class's priority makes the
contact's against a floor of default priority. The MK851 note says so.
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
    world = {str(g.get("name")) for g in robot.extras.get("mjcf_world_geoms") or [] if g.get("name")}
    floored: set[str] = set()
    for entry in kept:
        tag = str(entry.get("tag"))
        attributes = {str(k): str(v) for k, v in dict(entry.get("attributes", {})).items() if k != "class"}
        refs = REFERENCES.get(tag, ())
        missing = [attributes.get(ref, "") for ref in refs if attributes.get(ref) not in names[ref]]
        if not refs or missing:
            instead = ""
            if tag == "pair" and len(missing) == 1 and missing[0] in world:
                robot_side = next(attributes[ref] for ref in refs if attributes[ref] != missing[0])
                if robot_side not in floored:
                    floored.add(robot_side)
                    instead = _touch_any_floor(root, robot_side, attributes)
            ctx.note("MK851", f"<contact><{tag}> {' '.join(f'{k}={v!r}' for k, v in attributes.items())} is "
                     f"not written: {', '.join(repr(m) for m in missing) or 'its kind'} is not in the "
                     f"written file{instead}", robot.source, f"contact/{tag}")
            continue
        sub(contact, tag, **{k: v if k in NAMES else fmt_text(v) for k, v in attributes.items()})


# the pair's attributes a geom holds too, written on the geom when it takes the pair's place
_GEOM_CONTACT = ("condim", "solref", "solimp", "margin", "gap")
_PAIR_FRICTION = (1.0, 1.0, 0.005, 0.0001, 0.0001)  # MuJoCo's: tangent 1 and 2, spin, roll 1 and 2


def _touch_any_floor(root: Element, name: str, pair: dict[str, str]) -> str:
    """Let the robot geom ``name`` of a pair with the source's floor collide with any default floor,
    with the pair's contact parameters (the module's docstring); what to add to the note, or "" when the
    geom already collides with a default floor."""
    geom = next((g for g in root.iter("geom") if g.get("name") == name), None)
    if geom is None:
        return ""
    contype, conaffinity = (int(float(geom.get(key, "1"))) for key in ("contype", "conaffinity"))
    if (contype | conaffinity) & 1:
        return ""
    geom.set("contype", str(contype | 1))
    carried = [key for key in _GEOM_CONTACT if key in pair]
    for key in carried:
        geom.set(key, fmt_text(pair[key]))
    lost = ""
    if "friction" in pair:
        given = [float(x) for x in pair["friction"].split()]
        five = [*given, *_PAIR_FRICTION[len(given):]][:5]
        geom.set("friction", fmt_text(f"{five[0]!r} {five[2]!r} {five[3]!r}"))
        carried.append("friction")
        if five[1] != five[0] or five[4] != five[3]:
            lost = f" (the pair's second sliding and rolling coefficients {five[1]:g}, {five[4]:g} are not)"
    said = f" and the pair's {', '.join(carried)}" if carried else ""
    return (f"; geom {name!r}, which collides through pairs alone, now collides with any floor the user "
            f"adds: contype {contype | 1}, conaffinity {conaffinity} kept{said}{lost}")
