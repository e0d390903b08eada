"""Reading an xacro file: expand it to URDF (:mod:`.expand`), then read that with the URDF reader.

Every element of the expanded document carries the place in the xacro sources it comes from
(``XmlDocument.origins``), so what the URDF reader and the rules report points into the .xacro files.
"""

from __future__ import annotations

from pathlib import Path

from modelkit.diagnostics import Diagnostic, DiagnosticSink, SourceLocation, sorted_diagnostics
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.xacro.expand import expand
from modelkit.formats.xacro.origins import source_elements
from modelkit.xmlsource import XmlDocument, parse_xml_bytes


def expand_document(
    path: Path, options: ReadOptions, display: str, sink: DiagnosticSink
) -> XmlDocument | None:
    """The expanded URDF as a parsed document whose elements point back into the xacro sources."""
    expanded = expand(path, options, display, sink)
    if expanded is None:
        return None
    scratch = DiagnosticSink()
    # Every element gets its place in the xacro sources below: no positions in the generated text needed.
    doc = parse_xml_bytes(expanded.text.encode("utf-8"), display, scratch, path, positions=False)
    if doc is None:  # e.g. <xacro:element xacro:name="..."> gave a name XML does not allow
        first = scratch.items[0].message if scratch.items else "it cannot be parsed"
        where = expanded.origins[0] if expanded.origins else SourceLocation(display)
        sink.emit("MK700", f"the expanded document is not well-formed XML: {first}", where)
        return None
    elements = source_elements(doc.root)
    if len(elements) == len(expanded.origins):
        doc.origins.update(zip(elements, expanded.origins, strict=True))
    else:  # never expected: point everything at the top file rather than at the generated text
        top = expanded.origins[0] if expanded.origins else SourceLocation(display)
        doc.origins.update((element, top) for element in elements)
    return doc


def expand_xacro(path: Path, options: ReadOptions | None = None) -> tuple[str | None, list[Diagnostic]]:
    """The URDF text an xacro file expands to (None when it cannot be expanded) and the findings."""
    sink = DiagnosticSink()
    expanded = expand(path, options or ReadOptions(), str(path), sink)
    return (expanded.text if expanded else None), sorted_diagnostics(sink.items)


def read_xacro(path: Path, options: ReadOptions, display: str) -> ReadResult:
    """Read an xacro file into a robot: expand it, then read the URDF it expands to."""
    from modelkit.formats.urdf.reader import read_urdf_document

    sink = DiagnosticSink()
    doc = expand_document(path, options, display, sink)
    robot = None
    if doc is not None and is_macro_library(doc):
        sink.emit(
            "MK710",
            "this xacro file expands to no robot content (a library of macros, properties, materials "
            "or <gazebo> blocks for other xacro files): it was checked for xacro errors only",
            doc.loc(doc.root),
        )
    elif doc is not None:
        robot = read_urdf_document(doc, options, sink, path.parent, path)
    return ReadResult(robot, sorted_diagnostics(sink.items))


# Top-level elements a file of shared definitions may hold without being a robot itself.
LIBRARY_ELEMENTS = frozenset({"material", "gazebo"})


def is_macro_library(doc: XmlDocument) -> bool:
    """True when the expansion holds no robot content: nothing, or only ``<material>``/``<gazebo>`` blocks.

    Such files (``materials.xacro``, ``*_macro.xacro``, a robot's ``*.gazebo.xacro``) are included by
    others; on their own they are not robots, and reporting "no links" or "no robot name" on them would
    be noise (check_urdf refuses them, but nobody loads them alone).
    """
    return all(child.tag in LIBRARY_ELEMENTS for child in doc.root if isinstance(child.tag, str))
