"""The MJCF (MuJoCo) reader: MuJoCo resolves the file, modelkit maps it to its robot model.

``mujoco`` is imported only inside this package, and only when an MJCF file is read.
"""

from modelkit.formats.mjcf.reader import read_mjcf

__all__ = ["read_mjcf"]
