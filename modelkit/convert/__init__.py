"""Conversion: the writers' shared machinery (notes, numbers, output folder, meshes) and the
``convert`` pipeline (read, check, write every robot of every input into one output folder).

The pipeline (``convert``, ``write``...) is imported on first use, so that the CLI can read this
package's option tables without loading numpy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.convert.api import ConversionResult, convert, write
    from modelkit.convert.notes import ConversionNote
    from modelkit.convert.options import WriteOptions

_HOMES = {
    "ConversionResult": "modelkit.convert.api",
    "convert": "modelkit.convert.api",
    "write": "modelkit.convert.api",
    "ConversionNote": "modelkit.convert.notes",
    "WriteOptions": "modelkit.convert.options",
}
__all__ = ["ConversionNote", "ConversionResult", "WriteOptions", "convert", "write"]


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'modelkit.convert' has no attribute {name!r}")
