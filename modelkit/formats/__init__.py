"""The formats: one package per format (``body``, ``urdf``, ``xacro``, ``sdf``, ``mjcf``), each declaring
itself in its ``declare.py`` (collected by :mod:`modelkit.formats.registry`), with its reader and writer.

Importing this package (or a declaration) imports no reader: ``read_model``, ``detect_format`` and
``FORMATS`` come from :mod:`modelkit.formats.reading` on first use, so that the CLI can read the
declarations without loading numpy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.formats.reading import FORMATS, detect_format, read_model

_HOMES = {
    "FORMATS": "modelkit.formats.reading",
    "detect_format": "modelkit.formats.reading",
    "read_model": "modelkit.formats.reading",
}
__all__ = ["FORMATS", "detect_format", "read_model"]


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'modelkit.formats' has no attribute {name!r}")
