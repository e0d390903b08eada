"""The SDFormat (SDF 1.4–1.11) reader; see :mod:`modelkit.formats.sdf.reader` and ``docs/sdf.md``."""

from modelkit.formats.sdf.reader import read_sdf

__all__ = ["read_sdf"]
