"""xacro: expansion without ROS, legacy (pre-Jade) xacro, diagnostics that point into the sources.

* :mod:`.expand` runs the ``xacro`` package in-process with modelkit's package resolver;
* :mod:`.legacy` finds ``<property>``, ``<include>``, unprefixed macro calls and the like;
* :mod:`.origins` maps each expanded element back to the source line that wrote it;
* :mod:`.errors` turns xacro's exceptions into located diagnostics;
* :mod:`.reader` hands the result to the URDF reader.
"""

from __future__ import annotations

from modelkit.formats.xacro.reader import expand_xacro, read_xacro

__all__ = ["expand_xacro", "read_xacro"]
