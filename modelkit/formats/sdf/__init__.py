"""The SDFormat (SDF 1.4–1.11) reader and writer; see :mod:`modelkit.formats.sdf.reader` and ``docs/sdf.md``.

``read_sdf`` is imported on first use, so that importing the format's declaration (``declare``) does
not import the reader.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.formats.sdf.reader import read_sdf

__all__ = ["read_sdf"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from modelkit.formats.sdf import reader

        return getattr(reader, name)
    raise AttributeError(f"module 'modelkit.formats.sdf' has no attribute {name!r}")
