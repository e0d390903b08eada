"""The SDFormat element catalogue: which elements and attributes each element may hold.

The table (``modelkit/data/sdf_spec.json``) is generated from libsdformat's own description files
(``/usr/share/sdformat12/1.4`` … ``1.9``, Debian package ``sdformat-sdf``), merged over the versions,
plus the elements that SDFormat 1.10 and 1.11 added (:data:`LATER_ADDITIONS`, transcribed from the
gazebosim/sdformat ``sdf/1.10`` and ``sdf/1.11`` descriptions). Regenerate with::

    python -m modelkit.formats.sdf.spec /usr/share/sdformat12

An element is known by an id: the description file's stem for a file's top element (``link``,
``box_shape``), and ``PARENT/NAME`` for an element declared inline (``joint/axis/limit``).
"""

from __future__ import annotations

import json
import math
import re
import sys
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from lxml.etree import _Element as Element

from modelkit.diagnostics import Diagnostic, DiagnosticSink, closest, diag, did_you_mean
from modelkit.formats.sdf.values import is_custom
from modelkit.xmlsource import XmlDocument

SPEC_FILE = Path(__file__).resolve().parents[2] / "data" / "sdf_spec.json"

# Elements and attributes of SDFormat 1.10/1.11 that the 1.9 descriptions lack:
# id -> (attributes, {child name: (child id, may repeat)}, accepts any content).
LATER_ADDITIONS: dict[str, tuple[list[str], dict[str, tuple[str, bool]], bool]] = {
    "joint": ([], {"screw_thread_pitch": ("joint/screw_thread_pitch", False)}, False),
    "joint/screw_thread_pitch": ([], {}, False),
    "joint/axis": ([], {"mimic": ("mimic", False)}, False),
    "joint/axis2": ([], {"mimic": ("mimic", False)}, False),
    "mimic": (
        ["joint", "axis"],
        {
            "multiplier": ("mimic/multiplier", False),
            "offset": ("mimic/offset", False),
            "reference": ("mimic/reference", False),
        },
        False,
    ),
    "mimic/multiplier": ([], {}, False),
    "mimic/offset": ([], {}, False),
    "mimic/reference": ([], {}, False),
    "inertial": (
        ["auto"],
        {
            "density": ("inertial/density", False),
            "auto_inertia_params": ("auto_inertia_params", False),
        },
        False,
    ),
    "inertial/density": ([], {}, False),
    "auto_inertia_params": ([], {}, True),
    "collision": (
        [],
        {
            "density": ("collision/density", False),
            "material_density": ("collision/density", False),
            "auto_inertia_params": ("auto_inertia_params", False),
        },
        False,
    ),
    "collision/density": ([], {}, False),
    "geometry": ([], {"cone": ("cone_shape", False)}, False),
    "cone_shape": (
        [],
        {"radius": ("cone_shape/radius", False), "length": ("cone_shape/length", False)},
        False,
    ),
    "cone_shape/radius": ([], {}, False),
    "cone_shape/length": ([], {}, False),
    "mesh_shape": (
        ["optimization"],
        {"convex_decomposition": ("mesh_shape/convex_decomposition", False)},
        False,
    ),
    "mesh_shape/convex_decomposition": (
        [],
        {
            "max_convex_hulls": ("mesh_shape/convex_decomposition/max_convex_hulls", False),
            "voxel_resolution": ("mesh_shape/convex_decomposition/voxel_resolution", False),
        },
        False,
    ),
    "mesh_shape/convex_decomposition/max_convex_hulls": ([], {}, False),
    "mesh_shape/convex_decomposition/voxel_resolution": ([], {}, False),
    "model": (["namespace"], {}, False),
    "model/include": (["merge"], {"namespace": ("model/include/namespace", False)}, False),
    "model/include/namespace": ([], {}, False),
    "sensor": (
        [],
        {
            "air_speed": ("air_speed", False),
            "air_flow": ("air_flow", False),
            "frame_id": ("sensor/frame_id", False),
        },
        False,
    ),
    "sensor/frame_id": ([], {}, False),
    "air_speed": ([], {}, True),
    "air_flow": ([], {}, True),
    "camera": (
        [],
        {
            "optical_frame_id": ("camera/optical_frame_id", False),
            "camera_info_topic": ("camera/camera_info_topic", False),
            "triggered": ("camera/triggered", False),
            "trigger_topic": ("camera/trigger_topic", False),
        },
        False,
    ),
    "camera/optical_frame_id": ([], {}, False),
    "camera/camera_info_topic": ([], {}, False),
    "camera/triggered": ([], {}, False),
    "camera/trigger_topic": ([], {}, False),
    "light": ([], {"visualize": ("light/visualize", False)}, False),
    "light/visualize": ([], {}, False),
}


@dataclass
class ElementSpec:
    """What one SDF element may contain."""

    name: str
    attributes: set[str] = field(default_factory=set)
    children: dict[str, tuple[str, bool]] = field(default_factory=dict)  # name -> (id, may repeat)
    any_content: bool = False  # copy_data: arbitrary content (plugins)
    type: str | None = None  # the type of the element's text (libsdformat's description), if it has one
    minimum: float | None = None  # libsdformat refuses a value below ``min`` or above ``max``
    maximum: float | None = None
    # required="1" in the description: libsdformat refuses an empty value ("Empty string used when
    # setting a required parameter"); an empty optional value keeps the default
    required: bool = False
    required_attributes: set[str] = field(default_factory=set)  # likewise for attributes


@lru_cache(maxsize=1)
def catalogue() -> dict[str, ElementSpec]:
    """The element table, loaded once."""
    raw = json.loads(SPEC_FILE.read_text(encoding="utf-8"))
    out: dict[str, ElementSpec] = {}
    for ident, entry in raw["elements"].items():
        out[ident] = ElementSpec(
            name=entry["name"],
            attributes=set(entry.get("attributes", [])),
            children={k: (v[0], bool(v[1])) for k, v in entry.get("children", {}).items()},
            any_content=bool(entry.get("any", False)),
            type=entry.get("type"),
            minimum=entry.get("min"),
            maximum=entry.get("max"),
            required=bool(entry.get("required", False)),
            required_attributes=set(entry.get("required_attributes", [])),
        )
    return out


@lru_cache(maxsize=1)
def _homes() -> dict[str, list[str]]:
    """Element name -> the names of the elements that may hold it (for "belongs in" hints)."""
    table = catalogue()
    out: dict[str, set[str]] = {}
    for spec in table.values():
        for name in spec.children:
            out.setdefault(name, set()).add(spec.name)
    return {k: sorted(v) for k, v in out.items()}


def check_elements(
    doc: XmlDocument,
    sink: DiagnosticSink,
    version: tuple[int, int] = (1, 11),
    values: list[Diagnostic] | None = None,
) -> None:
    """Report elements and attributes that SDFormat does not define where they are written (MK123),
    and elements written twice where the specification allows one (MK124).

    Namespaced elements and attributes (``<gz:...>``) are legal custom content and are skipped, as
    is everything inside ``<plugin>`` and other elements whose content is free. Values that
    libsdformat cannot parse as their element's type, or that are out of its bounds (MK121), go to
    ``values`` when given (the reader reports the values it reads itself; these fill the rest).
    """
    table = catalogue()
    stack: list[tuple[Element, str]] = [(doc.root, "root")]
    while stack:
        element, ident = stack.pop()
        spec = table.get(ident)
        if spec is None:
            continue
        if values is not None:  # also a <plugin>'s own attributes, whatever its free content
            values.extend(_missing_required(doc, element, spec, ident))
        if spec.any_content:
            continue
        _check_attributes(doc, sink, element, spec)
        if values is not None:
            values.extend(_empty_required(doc, element, spec))
        if values is not None and spec.type is not None and len(element) == 0:
            fault = value_fault(spec, element.text)
            if fault is not None:
                values.append(
                    diag(
                        "MK121", f"<{spec.name}> {fault}; libsdformat refuses the file", doc.text_loc(element)
                    )
                )
        if ident == "pose" and version >= (1, 7) and element.get("frame") is not None:
            sink.emit(
                "MK123",
                "attribute frame of <pose> was replaced by relative_to in SDFormat 1.7; it is ignored",
                doc.loc(element, "frame"),
                hint="write relative_to",
            )
        seen: set[str] = set()
        pending: list[tuple[Element, str]] = []
        for child in element:
            tag = child.tag
            if not isinstance(tag, str) or is_custom(child):
                continue
            entry = spec.children.get(tag)
            if entry is None:
                sink.emit(
                    "MK123",
                    f"<{tag}> is not an SDFormat element of <{spec.name}>; libsdformat ignores it",
                    doc.loc(child),
                    hint=_hint(tag, spec),
                )
                continue
            child_id, may_repeat = entry
            if tag in seen and not may_repeat and ident != "root":  # root: MK153 says more
                sink.emit(
                    "MK124",
                    f"<{tag}> appears more than once in <{spec.name}>; only the first is read",
                    doc.loc(child),
                )
            seen.add(tag)
            pending.append((child, child_id))
        stack.extend(reversed(pending))


_LEADING_DOUBLE = re.compile(
    r"[+-]?(?:inf(?:inity)?|nan|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)", re.IGNORECASE
)
_LEADING_INT = re.compile(r"[+-]?\d+")
# Vector types: how many numbers libsdformat reads (it ignores any that follow).
_VECTOR_SIZES = {"vector3": 3, "vector2d": 2, "vector2i": 2, "quaternion": 4}


def _stod(text: str) -> float | None:
    """What ``std::stod`` makes of ``text``: its leading number (None when there is none or it overflows)."""
    match = _LEADING_DOUBLE.match(text.lstrip())
    if match is None:
        return None
    value = float(match.group(0))
    word = match.group(0).lstrip("+-").lower()
    if math.isinf(value) and not word.startswith("inf"):
        return None  # 1e400: std::out_of_range
    return value


def value_fault(spec: ElementSpec, raw: str | None) -> str | None:
    """Why libsdformat 12 (``sdf::Param``) refuses ``raw`` as the value of ``spec``, or None.

    Modelled on what it does, not on what would be tidy: doubles and integers are read by
    ``std::stod``/``std::stoi`` (a leading number is enough: "1x" is 1), vectors by a stream
    (missing numbers fail, extra ones are ignored), colours need 3 or 4 numbers within 0..1, booleans
    are true/false/1/0 in any case; an empty value keeps the default.
    """
    text = (raw or "").strip()
    if not text:
        return None
    kind = spec.type
    if kind in ("double", "float"):
        value = _stod(text)
        if value is None:
            return f'must be a number, not "{text}"'
        return _bounds(spec, value)
    if kind in ("int", "unsigned int"):
        match = _LEADING_INT.match(text)
        if match is None:
            return f'must be an integer, not "{text}"'
        if kind == "unsigned int" and match.group(0).startswith("-"):
            return f'must be an unsigned integer, not "{text}"'
        return _bounds(spec, float(match.group(0)))
    if kind == "bool":
        if text.lower() not in ("true", "false", "1", "0"):
            return f'must be true or false, not "{text}"'
        return None
    if kind in _VECTOR_SIZES:
        count = _VECTOR_SIZES[kind]
        numbers = [float(t) for t in text.split()[:count] if _is_number(t)]
        if len(numbers) < count or len(numbers) != len(text.split()[:count]):
            return f'must be {count} numbers, not "{text}"'
        return None
    if kind == "color":
        items = text.split()
        if len(items) not in (3, 4) or not all(_is_number(t) for t in items):
            return f'must be 3 or 4 numbers (RGB or RGBA), not "{text}"'
        if any(not 0.0 <= float(t) <= 1.0 for t in items):
            return f'must have every component within 0..1, not "{text}"'
        return None
    return None


def _is_number(token: str) -> bool:
    try:
        return math.isfinite(float(token))
    except ValueError:
        return False


def _bounds(spec: ElementSpec, value: float) -> str | None:
    if spec.minimum is not None and value < spec.minimum:
        return f"is {value:g}, below the minimum {spec.minimum:g}"
    if spec.maximum is not None and value > spec.maximum:
        return f"is {value:g}, above the maximum {spec.maximum:g}"
    return None


def _empty_required(doc: XmlDocument, element: Element, spec: ElementSpec) -> list[Diagnostic]:
    """Empty values libsdformat refuses: those of elements and attributes its description requires."""
    out = []
    if spec.required and len(element) == 0 and not (element.text or "").strip():
        out.append(
            diag(
                "MK121",
                f"<{spec.name}> is empty; libsdformat refuses an empty value for a required element",
                doc.text_loc(element),
            )
        )
    for name in sorted(spec.required_attributes):
        raw = element.get(name)
        if raw is not None and not raw.strip():
            out.append(
                diag(
                    "MK121",
                    f"attribute {name} of <{spec.name}> is empty; libsdformat refuses an empty required "
                    "attribute",
                    doc.loc(element, name),
                )
            )
    return out


# Required attributes the reader itself reports when they are missing (MK120, with the element's place in
# the robot): the generic check below leaves them to it.
_REPORTED_BY_READER = {
    "root": {"version"}, "world": {"name"}, "model": {"name"}, "link": {"name"}, "joint": {"name", "type"},
    "frame": {"name"}, "visual": {"name"}, "collision": {"name"}, "sensor": {"name", "type"},
}


def _missing_required(doc: XmlDocument, element: Element, spec: ElementSpec, ident: str) -> list[Diagnostic]:
    """MK120 for each attribute the description requires (``required="1"``) that the element lacks:
    libsdformat refuses the file ("Required attribute[filename] in element[plugin] is not specified in
    SDF"): a ``<plugin>`` without ``filename``, a ``<light>`` without ``type``, a ``<noise>`` or a
    ``<shader>`` without ``type``..."""
    skipped = _REPORTED_BY_READER.get(ident, set())
    return [
        diag(
            "MK120",
            f"<{spec.name}> has no {name} attribute; libsdformat refuses the file (the attribute is "
            "required)",
            doc.loc(element),
        )
        for name in sorted(spec.required_attributes - skipped)
        if element.get(name) is None
    ]


def _check_attributes(doc: XmlDocument, sink: DiagnosticSink, element: Element, spec: ElementSpec) -> None:
    for name in element.attrib:
        key = str(name)
        if key.startswith("{") or key in spec.attributes:
            continue
        sink.emit(
            "MK123",
            f'attribute "{key}" is not defined for <{spec.name}>; libsdformat ignores it',
            doc.loc(element, key),
            hint=did_you_mean(key, spec.attributes),
        )


def _hint(tag: str, spec: ElementSpec) -> str | None:
    close = closest(tag, spec.children)
    if close is not None:
        return f"did you mean <{close}>?"
    homes = _homes().get(tag)
    if homes:
        shown = ", ".join(f"<{h}>" for h in homes[:3]) + (" ..." if len(homes) > 3 else "")
        return f"<{tag}> belongs in {shown}"
    if spec.children:
        return "known here: " + ", ".join(f"<{c}>" for c in sorted(spec.children)[:12])
    return None


# ---- generator ----------------------------------------------------------------------------------


def _generate(spec_root: Path) -> dict[str, dict[str, object]]:
    table: dict[str, ElementSpec] = {}
    attribute_required: dict[tuple[str, str], bool] = {}  # a later version's description wins

    def entry(ident: str, name: str) -> ElementSpec:
        return table.setdefault(ident, ElementSpec(name))

    def many(required: str | None) -> bool:
        return required not in ("0", "1")

    def walk(el: Element, ident: str, folder: Path) -> None:
        item = entry(ident, str(el.get("name")))
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if child.tag == "attribute":
                item.attributes.add(str(child.get("name")))
                attribute_required[(ident, str(child.get("name")))] = child.get("required") == "1"
            elif child.tag == "include":
                stem = Path(str(child.get("filename"))).stem
                top = _top(folder / f"{stem}.sdf")
                if top is not None:
                    item.children[str(top.get("name"))] = (stem, many(child.get("required")))
            elif child.tag == "element":
                if child.get("copy_data") == "true":
                    item.any_content = True
                    continue
                name = str(child.get("name"))
                ref = child.get("ref")
                child_id = ref if ref else f"{ident}/{name}"
                item.children[name] = (child_id, many(child.get("required")))
                walk(child, child_id, folder)
                typed(child, child_id)

    def typed(el: Element, ident: str) -> None:
        """The element's value type and bounds; a later version's description wins."""
        item = entry(ident, str(el.get("name")))
        kind = el.get("type")
        if kind and kind != "string" and len([c for c in el if c.tag == "element"]) == 0:
            item.type = str(kind)
            item.minimum, item.maximum = _bound(el.get("min")), _bound(el.get("max"))
        item.required = bool(kind) and el.get("required") == "1" and not any(c.tag == "element" for c in el)

    for folder in sorted(
        (p for p in spec_root.iterdir() if p.is_dir() and p.name in _VERSIONS), key=lambda p: _version(p.name)
    ):
        for path in sorted(folder.glob("*.sdf")):
            top = _top(path)
            if top is not None:
                walk(top, path.stem, folder)
                typed(top, path.stem)
    for ident, (attributes, children, any_content) in LATER_ADDITIONS.items():
        item = entry(ident, ident.rsplit("/", 1)[-1].removesuffix("_shape"))
        item.attributes.update(attributes)
        item.children.update(children)
        item.any_content = item.any_content or any_content
    for (ident, name), required in attribute_required.items():
        if required:
            table[ident].required_attributes.add(name)
    return {
        ident: {
            "name": spec.name,
            "attributes": sorted(spec.attributes),
            "children": {k: list(v) for k, v in sorted(spec.children.items())},
            "any": spec.any_content,
            **({"type": spec.type} if spec.type else {}),
            **({"min": spec.minimum} if spec.minimum is not None else {}),
            **({"max": spec.maximum} if spec.maximum is not None else {}),
            **({"required": True} if spec.required else {}),
            **({"required_attributes": sorted(spec.required_attributes)} if spec.required_attributes else {}),
        }
        for ident, spec in sorted(table.items())
    }


def _bound(text: str | None) -> float | None:
    try:
        return float(text) if text else None
    except ValueError:
        return None  # a vector bound ("0 0"): not checked


def _version(name: str) -> tuple[int, ...]:
    return tuple(int(part) for part in name.split("."))


_VERSIONS = ("1.4", "1.5", "1.6", "1.7", "1.8", "1.9")


def _top(path: Path) -> Element | None:
    from lxml import etree

    if not path.is_file():
        return None
    root = etree.parse(str(path)).getroot()
    return root if root.tag == "element" else None


def main(argv: list[str]) -> int:  # pragma: no cover - regenerates the data file
    if len(argv) != 1:
        print("usage: python -m modelkit.formats.sdf.spec SPEC_ROOT (e.g. /usr/share/sdformat12)")
        return 2
    source = "libsdformat 1.4-1.9 descriptions + SDFormat 1.10/1.11 additions"
    data = {"source": source, "elements": _generate(Path(argv[0]))}
    SPEC_FILE.write_text(json.dumps(data, indent=0, sort_keys=False) + "\n", encoding="utf-8")
    print(f"wrote {SPEC_FILE} ({len(data['elements'])} elements)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main(sys.argv[1:]))
