"""The URDF reader (URDF 1.0, 1.1 and 1.2)."""
