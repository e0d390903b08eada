"""Which engines `verify` knows, where each adapter lives and which written file it reads.

Data only, so that the CLI can show the defaults without importing numpy or any engine; the
adapters are imported by :mod:`modelkit.verify.api` when a verification runs.
"""

from __future__ import annotations

ENGINES: dict[str, str] = {
    "source": "modelkit.verify.reference:load",
    "pinocchio": "modelkit.verify.engine_pinocchio:load",
    "mujoco": "modelkit.verify.engine_mujoco:load",
    "pybullet": "modelkit.verify.engine_pybullet:load",
    "drake": "modelkit.verify.engine_drake:load",
    "drake-urdf": "modelkit.verify.engine_drake:load_urdf",
    "yourdfpy": "modelkit.verify.reference:load_yourdfpy",
}
DEFAULT_ENGINES = ("mujoco", "pybullet", "pinocchio", "drake", "drake-urdf", "yourdfpy")

# Which written file each engine reads ("robot" = the in-memory source model).
INPUTS: dict[str, str] = {
    "source": "robot",
    "pinocchio": "robot",
    "mujoco": "mjcf",
    "pybullet": "urdf",
    "drake": "sdf",
    "drake-urdf": "urdf",
    "yourdfpy": "urdf",
}
