"""The names of the input formats, importable without any reader (nor numpy): the CLI's
``--input-format`` choices. :mod:`modelkit.formats` registers a reader for each."""

from __future__ import annotations

FORMAT_NAMES: tuple[str, ...] = ("body", "urdf", "xacro", "sdf", "mjcf")
