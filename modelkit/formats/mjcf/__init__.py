"""The MJCF (MuJoCo) reader: MuJoCo resolves the file, modelkit maps it to its robot model.

``mujoco`` is imported only inside this package, and only when an MJCF file is read. ``read_mjcf`` is
imported on first use, so that importing the format's declaration (``declare``) does not import the
reader.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.formats.mjcf.reader import read_mjcf

__all__ = ["read_mjcf"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from modelkit.formats.mjcf import reader

        return getattr(reader, name)
    raise AttributeError(f"module 'modelkit.formats.mjcf' has no attribute {name!r}")
