"""xacro: expansion without ROS, legacy (pre-Jade) xacro, diagnostics that point into the sources.

* :mod:`.expand` runs the ``xacro`` package in-process with modelkit's package resolver;
* :mod:`.legacy` finds ``<property>``, ``<include>``, unprefixed macro calls and the like;
* :mod:`.origins` maps each expanded element back to the source line that wrote it;
* :mod:`.errors` turns xacro's exceptions into located diagnostics;
* :mod:`.reader` hands the result to the URDF reader.

``expand_xacro`` and ``read_xacro`` are imported on first use, so that importing the format's
declaration (``declare``) does not import the reader.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.formats.xacro.reader import expand_xacro, read_xacro

__all__ = ["expand_xacro", "read_xacro"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from modelkit.formats.xacro import reader

        return getattr(reader, name)
    raise AttributeError(f"module 'modelkit.formats.xacro' has no attribute {name!r}")
