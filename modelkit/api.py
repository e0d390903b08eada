"""The library API: read, validate and report on model files without the CLI."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from modelkit.checks import run_rules
from modelkit.diagnostics import Diagnostic, Severity, sorted_diagnostics
from modelkit.formats import read_model
from modelkit.formats.common import ReadOptions
from modelkit.formats.meshref import VISUAL_ONLY, collision_mesh_problem, found_above_refused_by_mujoco
from modelkit.model import Robot
from modelkit.textio import OpenedFile

# Consumers a file may be meant for (``validate --target``), and the findings each refuses although the
# file's own loader accepts them: under that target they are errors, since that consumer (and
# ``convert --to`` it) will meet them. Everywhere else they stay warnings that name the consumers.
TARGET_REFUSALS: dict[str, frozenset[str]] = {
    # MuJoCo: a zero principal moment, inertia violating A + B >= C; a moving link, no mass; URDF parts
    # its URDF import refuses (a shape without its size or file, an incomplete inertia or inertial, a
    # short rgba or mesh scale, a word where an inertial, collision or colour number should be); a
    # collision shape of size zero; a shape URDF does not have; a glTF or PLY mesh; text after a URDF's
    # root element
    "mjcf": frozenset(
        {"MK302", "MK303", "MK313", "MK143", "MK144", "MK145", "MK146", "MK127", "MK129", "MK420", "MK416",
         "MK412", "MK421", "MK514", "MK515", "MK027"}
    ),
    "sdf": frozenset({"MK303", "MK211"}),  # libsdformat: the same, and links and joints sharing a name
    "urdf": frozenset(),
    # PyBullet: a URDF visual or collision without a shape, a shape without its size or file, an
    # inertial without mass value, inertia or a diagonal moment, a shape neither URDF nor PyBullet has, a
    # visual's <material> without a name, a glTF or PLY mesh, text after the root element
    "pybullet": frozenset({"MK122", "MK136", "MK143", "MK145", "MK412", "MK514", "MK515", "MK027"}),
}
TARGETS = tuple(TARGET_REFUSALS)


class ModelError(Exception):
    """Raised by :func:`load` when a file has errors; ``.diagnostics`` says which."""

    def __init__(self, path: str, diagnostics: list[Diagnostic]) -> None:
        errors = [d for d in diagnostics if d.severity is Severity.ERROR]
        first = errors[0] if errors else None
        summary = f"{len(errors)} error(s)" + (f"; first: {first.location}: {first.message}" if first else "")
        super().__init__(f"{path}: {summary}")
        self.diagnostics = diagnostics


@dataclass
class Validation:
    """What validating one file found. ``robot`` is the first robot; ``robots`` all of them (an SDF
    world holds several models)."""

    path: str
    robot: Robot | None
    diagnostics: list[Diagnostic]
    robots: list[Robot] = field(default_factory=list)
    opened: list[OpenedFile] = field(default_factory=list)  # every file the read opened

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.severity is Severity.ERROR]

    @property
    def warnings(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.severity is Severity.WARNING]


def validate(
    path: str | Path,
    options: ReadOptions | None = None,
    fmt: str | None = None,
    display: str | None = None,
    target: str | None = None,
) -> Validation:
    """Read a file and run every rule over its model.

    ``target`` (one of :data:`TARGETS`) judges the file as that consumer would: what it refuses is an
    error even where the file's own loader accepts it.
    """
    p = Path(path)
    result = read_model(p, options, fmt, display or str(path))
    diagnostics = list(result.diagnostics)
    for robot in result.robots:
        diagnostics.extend(run_rules(robot))
    if target is not None:
        diagnostics = [_for_target(d, target) for d in diagnostics]
    unique: dict[tuple[object, ...], Diagnostic] = {}
    for d in diagnostics:
        unique.setdefault((d.code, d.location, d.message), d)
    return Validation(display or str(path), result.robot, sorted_diagnostics(unique.values()), result.robots,
                      result.opened)


def _for_target(d: Diagnostic, target: str) -> Diagnostic:
    if d.severity is Severity.ERROR or not (d.code in TARGET_REFUSALS[target] or _mesh_refused(d, target)):
        return d
    return replace(d, severity=Severity.ERROR, message=f"{d.message} [an error for --target {target}]")


def _mesh_refused(d: Diagnostic, target: str) -> bool:
    """A mesh problem the target's loader refuses though the file's own loader does not look: a
    collision mesh (MuJoCo's URDF import and PyBullet load it), and for PyBullet a visual mesh that
    is not found (it refuses the file; MuJoCo's import discards visuals)."""
    if target not in ("mjcf", "pybullet"):
        return False
    if collision_mesh_problem(d) or (target == "mjcf" and found_above_refused_by_mujoco(d)):
        return True
    return target == "pybullet" and d.code in ("MK500", "MK504") and d.message.endswith(VISUAL_ONLY)


def load(path: str | Path, options: ReadOptions | None = None, fmt: str | None = None) -> Robot:
    """Read a file into a :class:`Robot`; raise :class:`ModelError` when it has errors."""
    v = validate(path, options, fmt)
    if v.robot is None or v.errors:
        raise ModelError(str(path), v.diagnostics)
    return v.robot
