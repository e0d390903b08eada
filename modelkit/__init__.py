"""modelkit: validate, convert and verify robot model files (Choreonoid .body, URDF/xacro, SDF, MJCF)."""

from modelkit.api import ModelError, Validation, load, validate

__all__ = ["ModelError", "Validation", "load", "validate"]
__version__ = "0.1.0"
