"""The conversion pipeline: read each input, refuse what cannot be converted, prepare the model
for the target, run the writer, stage every file, check the plan, write it atomically."""

from __future__ import annotations

import copy
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from modelkit import rot3
from modelkit.convert.commit import CommitRefused, Entry, identity
from modelkit.convert.context import WriteContext
from modelkit.convert.extras_notes import note_foreign_extras
from modelkit.convert.meshes import MeshExporter
from modelkit.convert.notes import ConversionNote, NoteSink
from modelkit.convert.numbers import length_scale
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan, safe_file_name, target_problem
from modelkit.convert.registry import TargetInfo, load_writer, target_for_path, target_info
from modelkit.diagnostics import Diagnostic, Severity, SourceLocation, diag
from modelkit.formats.common import ReadOptions
from modelkit.formats.meshref import collision_mesh_problem
from modelkit.formats.urdf.schema import XACRO_INSTRUCTION
from modelkit.model import Robot

if TYPE_CHECKING:
    from modelkit.api import Validation

# Reader errors that do not stop a conversion: the writer deals with them and says so in a note
# (a link and a joint sharing a name are renamed; a missing or unreadable mesh is left out; a
# massless moving link, legal in URDF kinematic models, gets the target's smallest mass, MK816).
CONVERTIBLE_ERRORS = frozenset({"MK211", "MK313", "MK500", "MK501", "MK502", "MK504", "MK506"})
UNREADABLE = frozenset({"MK001", "MK002"})
COMPOUND_SUFFIXES = (".urdf.xacro", ".xacro", ".urdf", ".body", ".sdf", ".world", ".mjcf", ".xml")

HOME_FROM_SRDF = frozenset({"MK147", "MK149"})  # reading infos a convert user needs to see


@dataclass
class ConversionResult:
    """What a conversion did: files written (relative to the output folder's parent as given),
    the notes of every writer, and the reading diagnostics that stopped an input."""

    outputs: list[str] = field(default_factory=list)
    notes: list[ConversionNote] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)
    status: int = 0  # 0 written; 1 an input had errors; 2 could not run (unreadable, output refused)


def output_stem(path: Path) -> str:
    name = path.name
    for suffix in COMPOUND_SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)] or name
    return path.stem


def input_files(robot: Robot, model_path: Path) -> set[Path]:
    """The files a robot was read from: its model file and every mesh it references."""
    found = {model_path}
    for link in robot.links:
        for geom in [*link.visuals, *link.collisions]:
            path = getattr(geom.geometry, "path", None)
            if path:
                found.add(Path(path))
    return found


def prepare(robot: Robot, target: TargetInfo, options: WriteOptions, notes: NoteSink) -> Robot:
    """A copy of ``robot`` shaped for the target: tracks approximated where the target has none,
    wheel collisions as ``options.wheel_collision`` says (MK826), fixed joints merged on request, the
    base settled (welded or free), an MJCF source's named-frame sites made frame links where the target
    has no sites (MK873), an SDF source's frames where it has no frames (MK874). The source model is
    never changed."""
    from modelkit.convert.base import settle_base
    from modelkit.convert.floor import note_below_floor
    from modelkit.convert.merge import merge_fixed_joints
    from modelkit.convert.rolling import note_rolling_faults
    from modelkit.convert.spawn import note_spawn_height
    from modelkit.convert.stance import note_tipping
    from modelkit.convert.tracks import approximate_tracks
    from modelkit.convert.wheels import approximate_wheels
    from modelkit.formats.mjcf.site_frames import sites_as_links
    from modelkit.formats.sdf.frame_links import frames_as_links

    _check_mass_properties(robot)
    note_foreign_extras(robot, target.name, notes)
    if robot.collision_exclusions and not target.pair_exclusions_native:
        notes.note("MK867", f"the SRDF's {len(robot.collision_exclusions)} disabled collision pair(s) are "
                   f"not written: {target.name} has no exclusion of one link pair (MJCF's <contact><exclude> "
                   "has)", robot.collision_exclusions[0].source, "collision")
    out = copy.deepcopy(robot)
    if target.name != "body":
        upper_triangle_inertias(out)
    settle_base(out, options.base, notes)
    note_rolling_faults(out, notes)
    note_tipping(out, notes)
    note_below_floor(out, target, notes)
    if not target.tracks_native:
        approximate_tracks(out, notes)
    approximate_wheels(out, options.wheel_collision, target.name, notes)
    note_spawn_height(out, target, notes)
    if options.frame_sites and not target.sites_native:
        sites_as_links(out, notes)
    if not target.frames_native:
        frames_as_links(out, notes)
    if options.merge_fixed:
        merge_fixed_joints(out, notes)
    return out


def upper_triangle_inertias(robot: Robot) -> list[str]:
    """Give each link whose inertia matrix is asymmetric (a ``.body`` file's nine numbers, validate's
    MK301) the symmetric matrix of its upper triangle, in place: the one rule every six-number target
    follows (the URDF, SDF and MJCF writers wrote the upper triangle, the average and the average).
    Returns the links changed. ``.body`` keeps the nine numbers as Choreonoid uses them."""
    changed = []
    for link in robot.links:
        if link.inertial is None:
            continue
        tensor = rot3.mat3(rot3.peek(link.inertial, "inertia"))
        if rot3.all_finite(tensor) and rot3.is_asymmetric(tensor):
            link.inertial.inertia = rot3.upper_symmetric(tensor)
            changed.append(link.name)
    return changed


def _check_mass_properties(robot: Robot) -> None:
    """Raise ``ValueError`` for a mass or inertia no writer can compute with (validate's MK302 error:
    not finite, or above 1e100), instead of a numerical failure deep in a writer (a library caller may
    write a model it never validated; ``convert`` refuses such an input before)."""
    import math

    from modelkit.checks.physics import MAX_MASS_PROPERTY

    for link in robot.links:
        inertial = link.inertial
        if inertial is None:
            continue
        values = [float(inertial.mass), *(float(x) for row in inertial.inertia for x in row)]
        if not all(math.isfinite(x) and abs(x) <= MAX_MASS_PROPERTY for x in values):
            worst = max(values, key=lambda x: abs(x) if math.isfinite(x) else math.inf)
            raise ValueError(f'link "{link.name}": mass or inertia {worst:g} cannot be written (MK302: not '
                             f"finite or above {MAX_MASS_PROPERTY:g}; validate reports it)")


def length_scale_of(robot: Robot) -> float:
    """The robot's size for cleaning positions: the diagonal of the box around its link frames at
    q = 0, at least its longest joint offset (a tree cut in parts); 1 m when it has no size."""
    lengths = [float(np.linalg.norm(j.origin.translation)) for j in robot.joints]
    points = np.array([pose.translation for pose in robot.world_poses().values()], dtype=float).reshape(-1, 3)
    if len(points):
        lengths.append(float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))))
    return max([v for v in lengths if math.isfinite(v)] or [1.0]) or 1.0


def render_model(robot: Robot, target: str, plan: OutputPlan, relpath: str,
                 options: WriteOptions) -> list[ConversionNote]:
    """Run the writer for one robot, staging its model file at ``relpath`` and its meshes."""
    info = target_info(target)
    notes = NoteSink()
    prepared = prepare(robot, info, options, notes)
    ctx = WriteContext(options, notes, MeshExporter(plan, relpath, options, notes), relpath)
    with length_scale(length_scale_of(prepared)):
        data = load_writer(target)(prepared, ctx)
    plan.add(relpath, data, "model")
    return notes.items


def write(robot: Robot, path: str | Path, fmt: str | None = None, options: WriteOptions | None = None,
          force: bool = False) -> list[ConversionNote]:
    """Write one robot to ``path`` (format from ``fmt`` or the suffix), meshes beside it in
    ``meshes/``; return the conversion notes. Raises ``FileExistsError``/``PermissionError``
    when the output is refused (see :class:`OutputPlan`)."""
    out = Path(path)
    info = target_info(fmt) if fmt else target_for_path(out)
    if info is None:
        raise ValueError(f"cannot tell the target format of {out}; pass fmt=")
    plan = OutputPlan(out.parent, set(), force)
    if robot.source is not None and robot.source.file:
        plan.inputs = input_files(robot, Path(robot.source.file))
    notes = render_model(robot, info.name, plan, out.name, options or WriteOptions())
    problems = plan.problems()
    if problems:
        exc = FileExistsError if all(p.code == "MK890" for p in problems) else PermissionError
        raise exc("; ".join(p.message for p in problems))
    try:
        plan.commit()
    except CommitRefused as refused:
        code = refused.diagnostic.code
        raise (FileExistsError if code == "MK890" else PermissionError)(refused.diagnostic.message) from None
    return notes


def _only_frames(robot: Robot) -> bool:
    """No joint, and no link with mass, a shape or a device: frames only, nothing a target can show or
    simulate (a URDF whose robot is a lone ``world`` link, its arm left in xacro macros it never expands)."""
    return not robot.joints and all(
        not (link.inertial and link.inertial.mass) and not (link.visuals or link.collisions or link.devices)
        for link in robot.links
    )


def _nothing_to_convert(source: Path, checked: Validation) -> str:
    """MK895's words: the input holds no robot, or only frames; with the way out when the input is a
    xacro file read as URDF (its xacro instructions are what would have made the robot)."""
    message = f"{source} holds no robot: nothing to convert"
    frames = [link.name for r in checked.robots for link in r.links]
    if frames:
        named = ", ".join(f'"{name}"' for name in frames[:5]) + (", ..." if len(frames) > 5 else "")
        message = (f"{source} holds no robot, only frames without mass, shape or joint ({named}): nothing "
                   "to convert")
    if any(d.code == "MK123" and XACRO_INSTRUCTION in d.message for d in checked.diagnostics):
        message += "; its xacro instructions would make the robot: convert it with --input-format xacro"
    return message


def _outputs_for(source: Path, robots: list[Robot], output: Path, target: TargetInfo,
                 folder_mode: bool) -> list[str]:
    """File names (relative to the output folder) for the robots of one input."""
    if not folder_mode and len(robots) == 1:
        return [output.name]
    stem = output_stem(source) if folder_mode else output_stem(output)
    if len(robots) == 1:
        return [f"{safe_file_name(stem, 'robot')}{target.suffix}"]
    names = []
    for robot in robots:
        names.append(f"{safe_file_name(stem, 'robot')}_{safe_file_name(robot.name, 'model')}{target.suffix}")
    return names


def convert(
    inputs: Sequence[str | Path],
    output: str | Path,
    to: str | None = None,
    read_options: ReadOptions | None = None,
    options: WriteOptions | None = None,
    force: bool = False,
    input_format: str | None = None,
    report: str | Path | None = None,
) -> ConversionResult:
    """Convert every robot of every input into ``output`` (a file, or a folder with ``to``).

    ``report``: also write the JSON report there, through the same guard as the outputs (never an
    input, never a file this conversion writes, an existing file only with ``force``) and in the
    same commit, last. Nothing is written when the report is refused."""
    from modelkit.api import validate

    result = ConversionResult()
    options = options or WriteOptions()
    out = Path(output)
    by_suffix = target_for_path(out)
    folder_mode = by_suffix is None or len(inputs) > 1 or os.path.isdir(out)  # False for a name too long
    target = target_info(to) if to else by_suffix
    if target is None:
        result.diagnostics.append(diag("MK892", f"cannot tell the target format of {out}: name a file "
                                       "ending in .urdf, .sdf, .xml or .body, or pass --to",
                                       SourceLocation(str(out))))
        result.status = 2
        return result
    folder = out if folder_mode else out.parent
    plan = OutputPlan(folder, {Path(item) for item in inputs}, force)
    input_errors = False  # errors the writer dealt with (a missing mesh left out): written, exit 1
    for item in inputs:
        source = Path(item)
        checked = validate(source, read_options, input_format, str(source))
        plan.opened |= {f.identity for f in checked.opened}
        blocking = [d for d in checked.errors if d.code not in CONVERTIBLE_ERRORS]
        result.diagnostics.extend(d for d in checked.diagnostics if d.severity is not Severity.INFO)
        # which SRDF state became the home pose (an info of the read) is said with the conversion's notes
        result.notes.extend(ConversionNote(d.code, d.severity, d.message, d.location, None)
                            for d in checked.diagnostics
                            if d.code in HOME_FROM_SRDF and d.severity is Severity.INFO)
        if any(d.code in UNREADABLE for d in checked.diagnostics):
            result.status = 2
            continue
        robots = [r for r in checked.robots if r.root is not None and not _only_frames(r)]
        if blocking or not robots:
            if not checked.errors:  # a macro library, a world without models: say why nothing is written
                result.diagnostics.append(diag("MK895", _nothing_to_convert(source, checked),
                                               SourceLocation(str(source))))
            result.status = max(result.status, 1)
            continue
        # a collision mesh the format's loader never opens (a warning for validate) is left out of the
        # written robot, which then has no collision there: an input error for convert
        input_errors = input_errors or bool(checked.errors) or any(
            collision_mesh_problem(d) for d in checked.diagnostics)
        plan.inputs |= {p for r in robots for p in input_files(r, source)}
        names = _outputs_for(source, robots, out, target, folder_mode)
        if len(robots) > 1:
            result.notes.append(ConversionNote(
                "MK893", Severity.INFO,
                f"{source} holds {len(robots)} models; each is written to its own file: " + ", ".join(names),
                SourceLocation(str(source)), None))
        for robot, name in zip(robots, names, strict=True):
            result.notes.extend(render_model(robot, target.name, plan, name, options))
            result.outputs.append(str(folder / name))
    report_path = Path(report) if report is not None else None
    if report_path is not None:
        refused = _report_problem(report_path, plan)
        if refused is not None:  # checked before anything is written: nothing is
            result.diagnostics.append(refused)
            result.outputs = []
            result.status = 2
            return result
    if not result.status:
        problems = plan.problems()
        if problems:
            result.diagnostics.extend(problems)
            result.status = 2
    if result.status:
        result.outputs = []
        plan.files = {}  # the report alone, if one was asked for
    extra = [_report_entry(report_path, result, inputs)] if report_path is not None else []
    try:
        plan.commit(extra)
    except CommitRefused as exc:
        result.diagnostics.append(exc.diagnostic)
        result.outputs = []
        result.status = 2
        return result
    except OSError as exc:
        result.diagnostics.append(diag("MK894", f"writing into {folder} failed: {exc}; nothing was written",
                                       SourceLocation(str(folder))))
        result.outputs = []
        result.status = 2
        return result
    if not result.status and (input_errors or any(n.severity is Severity.ERROR for n in result.notes)):
        result.status = 1  # written, but not the whole robot: README's "an input has errors"
    return result


def _report_problem(path: Path, plan: OutputPlan) -> Diagnostic | None:
    """Why the report must not be written at ``path``: it is (or is a link to) a file this
    conversion writes, an input, a symlink or special file, or it exists and ``force`` is off."""
    where = SourceLocation(str(path))
    mine = path.resolve()
    ident = identity(path)
    for relpath in plan.files:
        target = plan.folder / relpath
        if target.resolve() == mine or (ident is not None and identity(target) == ident):
            return diag("MK897", f"--report {path} is {target}, a file this conversion writes; nothing is "
                        "written", where, hint="name a report file outside the files written")
    return target_problem(path, b"", "report", plan.force, plan.protected())


def _report_entry(path: Path, result: ConversionResult, inputs: Sequence[str | Path]) -> Entry:
    from modelkit.convert.report import report_json

    data = report_json(result, [str(f) for f in inputs]).encode("utf-8")
    return Entry(path.parent, path.name, data, "report")
