"""Which engines `verify` knows, where each adapter lives and which written file it reads.

Data only, so that the CLI can show the defaults without importing numpy or any engine; the
adapters are imported by :mod:`modelkit.verify.api` when a verification runs.
"""

from __future__ import annotations

ENGINES: dict[str, str] = {
    "source": "modelkit.verify.engines.reference:load",
    "pinocchio": "modelkit.verify.engines.pinocchio:load",
    "mujoco": "modelkit.verify.engines.mujoco:load",
    "pybullet": "modelkit.verify.engines.pybullet:load",
    "drake": "modelkit.verify.engines.drake_child:load",
    "drake-urdf": "modelkit.verify.engines.drake_child:load_urdf",
    "yourdfpy": "modelkit.verify.engines.reference:load_yourdfpy",
}
DEFAULT_ENGINES = ("mujoco", "pybullet", "pinocchio", "drake", "drake-urdf", "yourdfpy")
# Engines whose child process starts when verify starts (it imports its library while verify reads and
# converts); the loader takes it as ``worker=``. The function returns None when the engine is missing.
# Drake runs in a child whether or not it started ahead: an abort in its C++ must not end verify.
PRESTART: dict[str, str] = {"yourdfpy": "modelkit.verify.engines.reference:start_yourdfpy",
                            "drake": "modelkit.verify.engines.drake_child:start_drake",
                            "drake-urdf": "modelkit.verify.engines.drake_child:start_drake"}

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

# What each engine imports, and the extra that installs it. ``find_spec`` looks the module up
# without importing it, so the check costs nothing.
MODULES: dict[str, str] = {
    "pinocchio": "pinocchio",
    "mujoco": "mujoco",
    "pybullet": "pybullet",
    "drake": "pydrake",
    "drake-urdf": "pydrake",
    "yourdfpy": "yourdfpy",
}
EXTRAS: dict[str, str] = {"drake": "drake", "drake-urdf": "drake"}  # the rest come with modelkit[verify]
# The report's plots (``-o``) and the PyBullet worker of layer 4 need these as well.
REPORT_MODULES = ("matplotlib",)
OPTIONAL_BY_DEFAULT = frozenset({"drake", "drake-urdf"})  # skipped, not refused, when not named


def _installed(module: str) -> bool:
    import importlib.util

    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent package missing, or a broken install
        return False


def missing_packages(engines: tuple[str, ...], named: bool, report: bool) -> dict[str, str]:
    """What a verify run with ``engines`` lacks: {module: the extra that installs it}.

    ``named``: the user chose the engines (``--engines``): every one must be there. Otherwise the
    default set is run and the optional extras (Drake) are skipped when missing, as before.
    """
    missing: dict[str, str] = {}
    for engine in engines:
        module = MODULES.get(engine)
        if module is None or (not named and engine in OPTIONAL_BY_DEFAULT):
            continue
        if not _installed(module):
            missing[module.partition(".")[0]] = EXTRAS.get(engine, "verify")
    if report:
        for module in REPORT_MODULES:
            if not _installed(module):
                missing[module] = "verify"
    return missing


def install_line(missing: dict[str, str]) -> str:
    """The pip command that installs what ``missing`` lacks."""
    extras = ",".join(sorted(set(missing.values())))
    return f"pip install 'modelkit[{extras}]'"

