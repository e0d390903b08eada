"""Loading one SDF file: XML with positions, the ``<sdf>`` root and its version.

SDF files often use namespaced custom elements (``<gz:...>``, ``<ignition:...>``) without
declaring the prefix: libsdformat's XML parser (tinyxml2) ignores namespaces, lxml refuses the
document. When that is the only problem the prefixes are declared (:mod:`modelkit.xml_prefixes`),
silently: every SDF consumer reads the file through libsdformat.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from modelkit.diagnostics import DiagnosticSink, Severity
from modelkit.formats.sdf.values import Values, local_name
from modelkit.xml_prefixes import read_declaring_prefixes
from modelkit.xmlsource import XmlDocument

MIN_VERSION = (1, 2)
MAX_VERSION = (1, 12)
SUPPORTED = "1.2-1.12"
# libsdformat converts SDFormat 1.2 and 1.3 files to its own version as it loads them; from 1.3 to 1.4
# only world <physics> elements move, so modelkit reads them with the semantics of 1.4.
OLDEST_SEMANTICS = (1, 4)
_VERSION = re.compile(r"\s*(\d+)\.(\d+)\s*")


@dataclass
class SdfDocument:
    """A parsed SDF file and the version its semantics follow."""

    doc: XmlDocument
    path: Path
    version: tuple[int, int]
    values: Values

    @property
    def display(self) -> str:
        return self.doc.display

    @property
    def base_dir(self) -> Path:
        return self.path.parent

    def at_least(self, major: int, minor: int) -> bool:
        return self.version >= (major, minor)


def parse_version(text: str | None) -> tuple[int, int] | None:
    match = _VERSION.fullmatch(text or "")
    return (int(match.group(1)), int(match.group(2))) if match else None


def version_text(version: tuple[int, int]) -> str:
    return f"{version[0]}.{version[1]}"


def load_document(path: Path, display: str, sink: DiagnosticSink, max_bytes: int) -> SdfDocument | None:
    """Read ``path`` as SDF; faults become diagnostics and the result is None when unusable.

    An unsupported or missing version is reported, and reading goes on with the nearest version
    modelkit knows, so that the rest of the file is still checked.
    """
    doc = read_declaring_prefixes(path, display, sink, max_bytes).doc
    if doc is None:
        return None
    root = doc.root
    values = Values(doc, sink)
    if local_name(root) != "sdf":
        hint = "this looks like URDF; read it as URDF" if local_name(root) == "robot" else None
        sink.emit("MK022", f"the top element is <{local_name(root)}>, not <sdf>", doc.loc(root), hint=hint)
        return None
    raw = root.get("version")
    version = parse_version(raw)
    if raw is None:
        sink.emit(
            "MK150",
            "<sdf> has no version attribute; libsdformat refuses the file",
            doc.loc(root),
            hint='add version="1.11" (or the version the file was written for)',
        )
        version = MAX_VERSION
    elif version is None or not MIN_VERSION <= version <= MAX_VERSION:
        sink.emit(
            "MK151",
            f'SDFormat version "{raw}" is not supported (modelkit reads {SUPPORTED})',
            doc.loc(root, "version"),
            hint="convert older files with `gz sdf -p`" if version and version < MIN_VERSION else None,
        )
        version = MIN_VERSION if version is not None and version < MIN_VERSION else MAX_VERSION
    elif version < OLDEST_SEMANTICS:
        sink.emit(
            "MK151",
            f"SDFormat {raw}: libsdformat converts it as it loads it (only world <physics> elements "
            "moved in 1.4); modelkit reads it as 1.4",
            doc.loc(root, "version"),
            severity=Severity.INFO,
        )
    return SdfDocument(doc, path, max(version, OLDEST_SEMANTICS), values)
