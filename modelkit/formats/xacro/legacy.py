"""Pre-Jade ("legacy") xacro: finding the constructs current xacro no longer understands.

Until ROS Indigo, xacro accepted its directives without the ``xacro:`` prefix (``<property>``,
``<include filename=...>``, ``<macro>``, ``<arg>``, ``<if>``/``<unless>``, ``<insert_block>``) and
called a macro by its bare name (``<wheel name="left"/>``). Jade deprecated this and xacro 1.13
dropped it: such elements now pass through to the output untouched, and the robot is broken.

Detection needs the whole file set (a macro defined in an included file may be called, unprefixed,
from the top file), so :func:`scan_file_set` follows includes statically before expansion, both
prefixed ones and legacy ones. Include paths are resolved for the common spellings (relative
paths, ``$(find PKG)``, ``$(arg NAME)``, ``$(env VAR)``, ``$(optenv VAR default)``, globs); a path
built from ``${...}`` is met again when xacro includes it, and checked then.
"""

from __future__ import annotations

import glob
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from lxml.etree import _Element as Element

from modelkit.formats.common import ReadOptions
from modelkit.formats.xacro.origins import Origin, attributes, source_elements, tag_name
from modelkit.xmlsource import XmlDocument

# Legacy directive → the attribute it must carry to be taken for one (an `<include>` without
# `filename` is Gazebo's, with a `<uri>` child).
DIRECTIVES: dict[str, str] = {
    "property": "name",
    "include": "filename",
    "macro": "name",
    "arg": "name",
    "if": "value",
    "unless": "value",
    "insert_block": "name",
}

# Elements of URDF and of its ROS extensions. A macro with one of these names would turn every such
# element into a call under the legacy reading; that is too likely a false alarm to report.
FORMAT_ELEMENTS = frozenset(
    "robot link joint inertial origin mass inertia visual collision geometry box cylinder sphere capsule "
    "mesh material color texture parent child axis calibration dynamics limit mimic safety_controller "
    "transmission type actuator hardwareInterface mechanicalReduction gazebo plugin sensor ros2_control "
    "hardware param command_interface state_interface version".split()
)

_SUBSTITUTION = re.compile(r"\$\(\s*(find|arg|env|optenv)\s+([^)\s]+)\s*([^)]*)\)")


@dataclass(frozen=True)
class LegacyConstruct:
    """One legacy element: a directive (``kind`` = its name) or a macro call (``kind`` = "call")."""

    origin: Origin
    kind: str

    @property
    def tag(self) -> str:
        return tag_name(self.origin.element)

    def modern(self) -> str:
        """The element's start tag with the ``xacro:`` prefix, attributes as written."""
        element = self.origin.element
        attrs = "".join(f' {_attribute_name(element, k)}="{v}"' for k, v in attributes(element))
        close = ">" if len(element) else "/>"
        return f"<xacro:{self.tag}{attrs}{close}"

    def message(self) -> str:
        what = f'<{self.tag}> calls macro "{self.tag}"' if self.kind == "call" else f"<{self.tag}>"
        return f"legacy xacro: {what} without the xacro: prefix; current xacro leaves it in the output"


@dataclass
class FileSet:
    """The files an xacro file includes (transitively), parsed, and what legacy xacro they hold."""

    docs: dict[str, XmlDocument] = field(default_factory=dict)  # normalized absolute path → doc
    macro_names: set[str] = field(default_factory=set)
    constructs: list[LegacyConstruct] = field(default_factory=list)
    legacy_elements: set[Element] = field(default_factory=set)

    def add_constructs(self, found: list[LegacyConstruct]) -> list[LegacyConstruct]:
        new = [c for c in found if c.origin.element not in self.legacy_elements]
        self.constructs.extend(new)
        self.legacy_elements.update(c.origin.element for c in new)
        return new


def file_key(path: str | Path) -> str:
    return os.path.normpath(os.path.abspath(path))


def _attribute_name(element: Element, name: str) -> str:
    if not name.startswith("{"):
        return name
    uri, _, local = name[1:].partition("}")
    prefix = next((p for p, u in element.nsmap.items() if u == uri and p), None)
    return f"{prefix}:{local}" if prefix else local


def _in_gazebo(element: Element) -> bool:
    return any(tag_name(a) == "gazebo" for a in element.iterancestors())


def macro_names(doc: XmlDocument) -> set[str]:
    """Names of the macros a file defines (``<xacro:macro>`` and legacy ``<macro>``)."""
    names: set[str] = set()
    for element in source_elements(doc.root):
        if tag_name(element) in ("xacro:macro", "macro") and element.get("name"):
            name = element.get("name", "").removeprefix("xacro:")
            if "$" not in name and "." not in name:
                names.add(name)
    return names


def find_legacy(doc: XmlDocument, macros: set[str]) -> list[LegacyConstruct]:
    """The legacy constructs of one file, given the macro names of the whole file set."""
    found: list[LegacyConstruct] = []
    for element in source_elements(doc.root):
        if element.prefix or element is doc.root:
            continue
        tag = tag_name(element)
        if tag in DIRECTIVES:
            kind = tag if element.get(DIRECTIVES[tag]) is not None else ""
        else:
            kind = "call" if tag in macros and tag not in FORMAT_ELEMENTS else ""
        if kind and not _in_gazebo(element):
            found.append(LegacyConstruct(Origin(doc, element), kind))
    return found


def _include_elements(doc: XmlDocument) -> list[Element]:
    return [
        e
        for e in source_elements(doc.root)
        if e.get("filename") is not None
        and (tag_name(e) == "xacro:include" or (tag_name(e) == "include" and not _in_gazebo(e)))
    ]


def _arg_defaults(doc: XmlDocument, args: dict[str, str]) -> None:
    for element in source_elements(doc.root):
        if tag_name(element) in ("xacro:arg", "arg"):
            name, default = element.get("name"), element.get("default")
            if name and default is not None and "$" not in default:
                args.setdefault(name, default)


def resolve_spec(
    spec: str, including: Path, args: dict[str, str], options: ReadOptions, top: Path
) -> list[Path]:
    """The files an include's ``filename`` names, when that can be known before expansion."""

    def substitute(match: re.Match[str]) -> str:
        command, name, rest = match.group(1), match.group(2), match.group(3).strip()
        if command == "find":
            root = find_package(options, name, including, top)
            if root is None:
                raise LookupError(name)
            return str(root)
        if command == "arg":
            return args[name]
        environ = options.resolver.environ
        if command == "env":
            return environ[name]
        return environ.get(name, rest)

    try:
        text = _SUBSTITUTION.sub(substitute, spec)
    except LookupError:
        return []
    if "$" in text:
        return []
    path = Path(text)
    if not path.is_absolute():
        path = including.parent / path
    if re.search(r"[*?\[]", text):
        return [Path(p) for p in sorted(glob.glob(str(path)))]
    return [path]


def find_package(options: ReadOptions, name: str, current: Path, top: Path) -> Path | None:
    """A package's folder: searched from the file being processed, then from the top file."""
    resolver = options.resolver
    found = resolver.find_package(name, current.parent)
    if found is None and current.parent != top.parent:
        found = resolver.find_package(name, top.parent)
    return None if found is None else Path(os.path.abspath(found))


def scan_file_set(
    top_doc: XmlDocument,
    top: Path,
    options: ReadOptions,
    load: Callable[[Path], XmlDocument | None],
) -> FileSet:
    """Parse the top file's includes transitively, collect macro names, find the legacy constructs."""
    files = FileSet()
    args = dict(options.xacro_args)
    pending: list[tuple[Path, XmlDocument]] = [(top, top_doc)]
    files.docs[file_key(top)] = top_doc
    order: list[XmlDocument] = []
    while pending:
        path, doc = pending.pop(0)
        order.append(doc)
        _arg_defaults(doc, args)
        for element in _include_elements(doc):
            for target in resolve_spec(element.get("filename", ""), path, args, options, top):
                key = file_key(target)
                if key in files.docs or not os.path.isfile(target):
                    continue
                included = load(target)
                if included is not None:
                    files.docs[key] = included
                    pending.append((target, included))
    for doc in order:
        files.macro_names |= macro_names(doc)
    for doc in order:
        files.add_constructs(find_legacy(doc, files.macro_names))
    return files
