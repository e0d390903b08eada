"""modelkit: validate, convert and verify robot model files (Choreonoid .body, URDF/xacro, SDF, MJCF).

The library API (``load``, ``validate``, ``ModelError``, ``Validation``) is imported on first use,
so that ``import modelkit.cli`` (and ``modelkit --help``) does not pay for numpy and the readers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from modelkit.api import ModelError, Validation, load, validate

__all__ = ["ModelError", "Validation", "load", "validate"]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    if name in __all__:
        from modelkit import api

        return getattr(api, name)
    raise AttributeError(f"module 'modelkit' has no attribute {name!r}")
