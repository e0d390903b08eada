"""The `modelkit` command line. Thin: parse options, call the library, render.

Exit codes: 0 clean; 1 findings at error level (or warnings with --strict); 2 the tool could not
run (bad usage, unreadable input).
"""

from __future__ import annotations

import gc
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn, TypeVar

import click

from modelkit.convert.choices import (
    ACTUATOR_CHOICES,
    GAZEBO_CHOICES,
    MESH_FORMATS,
    SDF_VERSIONS,
    SOURCE_ACTUATORS,
    SUPPORT_CONTACTS,
    WHEEL_COLLISIONS,
)
from modelkit.diagnostics import (
    Diagnostic,
    Severity,
    SourceLocation,
    diag,
    render_github,
    render_json,
    render_text,
)
from modelkit.formats.registry import FORMAT_NAMES, TARGET_NAMES
from modelkit.verify.engines.registry import DEFAULT_ENGINES  # data only: no numpy, no engine

F = TypeVar("F", bound=Callable[..., Any])
# MK899: modelkit failed on the input (a fault of its own): the file could not be checked either.
UNREADABLE_CODES = frozenset({"MK001", "MK002", "MK899"})
# Tree errors after which the tree can still be printed as check_urdf prints it: a joint named like a
# link (legal URDF), a link with two parents under one root (check_urdf prints it twice).
TREE_PRINTABLE_CODES = frozenset({"MK211", "MK220"})


def _pairs(values: tuple[str, ...], option: str) -> dict[str, Path]:
    out: dict[str, Path] = {}
    for item in values:
        name, sep, folder = item.partition("=")
        if not sep or not name or not folder:
            raise click.BadParameter(f"expected NAME=DIR, got {item!r}", param_hint=option)
        out[name] = Path(folder)
    return out


def reading_options(fn: F) -> F:
    """Options shared by every command that reads model files."""
    options = [
        click.option(
            "--input-format",
            type=click.Choice(FORMAT_NAMES),
            default=None,
            help="Read files as this format instead of guessing from the extension.",
        ),
        click.option(
            "--package-path",
            "package_paths",
            multiple=True,
            metavar="NAME=DIR",
            help="Where package://NAME/... URIs point (repeatable); searched before ROS_PACKAGE_PATH.",
        ),
        click.option(
            "--resource-path",
            "resource_paths",
            multiple=True,
            type=click.Path(file_okay=False, path_type=Path),
            metavar="DIR",
            help="A folder of SDF model folders for <include> and model:// URIs (repeatable); searched "
            "before SDF_PATH, GZ_SIM_RESOURCE_PATH, IGN_GAZEBO_RESOURCE_PATH and GAZEBO_MODEL_PATH.",
        ),
        click.option(
            "--path-variable",
            "path_variables",
            multiple=True,
            metavar="NAME=DIR",
            help="Value of a ${NAME} path variable in URIs (repeatable).",
        ),
        click.option(
            "--materials",
            "materials",
            type=click.Path(dir_okay=False, path_type=Path),
            default=None,
            help="Contact-materials file (default: Choreonoid's share/default/materials.yaml).",
        ),
        click.option(
            "--srdf",
            type=click.Path(dir_okay=False, path_type=Path),
            default=None,
            help="MoveIt's SRDF of the robot: its <group_state> gives the home pose (the MJCF home "
            "keyframe and servo targets, .body initial angles; MK147), its <disable_collisions> pairs the "
            "MJCF's <contact><exclude> (MK866).",
        ),
        click.option(
            "--home",
            metavar="STATE",
            default=None,
            help="The SRDF <group_state> to use as the home pose [default: the first of home, ready, "
            "default, standing, half_sitting the SRDF holds, else its only state].",
        ),
        click.option(
            "--vrml-extrusion",
            is_flag=True,
            help="Build Extrusions as VRML97 intends instead of reproducing Choreonoid's quirks.",
        ),
        click.option(
            "--legacy/--no-legacy",
            "legacy_xacro",
            default=None,
            help="xacro: expand pre-Jade constructs (<property>, <include>, unprefixed macro calls) "
            "[default: detect them, expand them and warn; --no-legacy expands as current xacro does].",
        ),
        click.option(
            "--max-bytes",
            type=click.IntRange(min=1),
            default=64 * 1024 * 1024,
            show_default=True,
            help="Refuse input files larger than this.",
        ),
        click.option(
            "--max-links",
            type=click.IntRange(min=1),
            default=10_000,
            show_default=True,
            help="Refuse models with more links (or joints, MJCF bodies) than this (MK005).",
        ),
        click.option(
            "--max-list-items",
            type=click.IntRange(min=1),
            default=250_000,
            show_default=True,
            help="Refuse YAML lists (.body) with more items than this (MK006).",
        ),
    ]
    for option in reversed(options):
        fn = option(fn)
    return fn


def split_xacro_args(items: tuple[str, ...]) -> tuple[tuple[Path, ...], dict[str, str]]:
    """Split command-line words into files and xacro ``key:=value`` arguments (as xacro takes them)."""
    files: list[Path] = []
    args: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition(":=")
        if sep and key and "/" not in key:
            args[key] = value
        else:
            files.append(Path(item))
    return tuple(files), args


def _read_options(kwargs: dict[str, Any], check_resources: bool, xacro_args: dict[str, str]) -> Any:
    from modelkit.formats.common import ReadOptions
    from modelkit.resources import Resolver

    resolver = Resolver(
        package_paths=_pairs(kwargs["package_paths"], "--package-path"),
        path_variables=_pairs(kwargs["path_variables"], "--path-variable"),
        resource_paths=list(kwargs.get("resource_paths") or ()),
    )
    if kwargs.get("home") is not None and kwargs.get("srdf") is None:
        raise click.BadParameter("--home names an SRDF state: give the SRDF with --srdf", param_hint="--home")
    return ReadOptions(
        resolver=resolver,
        srdf=kwargs.get("srdf"),
        home=kwargs.get("home"),
        xacro_args=xacro_args,
        legacy_xacro=kwargs["legacy_xacro"],
        materials_path=kwargs["materials"],
        faithful_extrusion=not kwargs["vrml_extrusion"],
        check_resources=check_resources,
        max_bytes=kwargs["max_bytes"],
        max_links=kwargs["max_links"],
        max_list_items=kwargs["max_list_items"],
    )


def _no_mujoco_rendering() -> None:
    """``validate`` and ``tree`` only compile MJCF: MuJoCo's import then skips its OpenGL back end
    (glfw, ~50 ms), unless the user chose one or MuJoCo is already imported. The variable is removed
    again when the command ends, so a program that runs the command in its own process (click's
    test runner, a script calling ``main``) keeps its environment (child processes of verify's
    pictures read it)."""
    if "MUJOCO_GL" in os.environ or "mujoco" in sys.modules:
        return
    os.environ["MUJOCO_GL"] = "disable"
    click.get_current_context().call_on_close(lambda: os.environ.pop("MUJOCO_GL", None))


def internal_error(exc: Exception, where: str) -> Diagnostic:
    """MK899: ``exc`` escaped modelkit's own code on ``where`` (a bug, not a fault of the input), named
    with the innermost place in modelkit's sources that raised it."""
    import traceback

    package = Path(__file__).resolve().parent
    place = ""
    for frame in reversed(traceback.extract_tb(exc.__traceback__)):
        path = Path(frame.filename).resolve()
        if path.is_relative_to(package):
            place = f" (modelkit/{path.relative_to(package).as_posix()}:{frame.lineno})"
            break
    message = (f"modelkit failed on this input: {type(exc).__name__}: {exc}"[:600] + f"{place}; this is a "
               "fault of modelkit, not of the file: please report it with the file (MODELKIT_DEBUG=1 shows "
               "the traceback)")
    return diag("MK899", message, SourceLocation(where))


class _Commands(click.Group):
    """The command group; an exception that escapes a command (a bug of modelkit's) becomes one MK899
    line on stderr and exit 2 instead of a traceback, unless ``MODELKIT_DEBUG`` is set."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.exceptions.Abort):
            raise
        except Exception as exc:
            if os.environ.get("MODELKIT_DEBUG"):
                raise
            command = ctx.invoked_subcommand or "modelkit"
            click.echo(render_text(internal_error(exc, f"modelkit {command}")), err=True)
            sys.exit(2)


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="modelkit")
def main() -> None:
    """Validate, convert and verify robot model files (Choreonoid .body, URDF/xacro, SDF, MJCF)."""


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector while one file is read, checked and reported.

    The model is a large graph that lives until the file is done and is freed by reference counting
    (it holds no cycles); collections over it free nothing. With the collector on, the young-generation
    passes that follow the read walk the whole model twice (a quarter of `tree` on a 1000-link chain).
    Whatever cyclic garbage the file left (xacro's DOM) stays young and goes at the next collection."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if collecting:
            gc.enable()


def _validate_one(path: Path, options: Any, input_format: str | None, target: str | None) -> list[Diagnostic]:
    """The findings of one file (a top-level function, so that worker processes can run it). Mesh
    checks are kept between runs (:mod:`modelkit.geometry.mesh_cache`)."""
    from modelkit.api import validate as validate_file
    from modelkit.geometry import mesh_cache

    mesh_cache.enable()
    with _collector_paused():
        try:
            return list(validate_file(path, options, input_format, str(path), target).diagnostics)
        except Exception as exc:  # a fault of modelkit's: this file is said, the others still checked
            if os.environ.get("MODELKIT_DEBUG"):
                raise
            return [internal_error(exc, str(path))]


def _validate_all(
    files: tuple[Path, ...], options: Any, input_format: str | None, target: str | None, jobs: int
) -> Iterator[list[Diagnostic]]:
    """The findings of every file, in input order; with ``jobs`` > 1 the files are checked in
    that many processes (each file whole in one process, so its findings are those of -j 1)."""
    if jobs <= 1 or len(files) <= 1:
        for path in files:
            yield _validate_one(path, options, input_format, target)
        return
    from concurrent.futures import ProcessPoolExecutor

    import modelkit.api  # noqa: F401  (imported once here, inherited by forked workers)

    n = len(files)
    workers = min(jobs, n)
    with ProcessPoolExecutor(max_workers=workers) as pool:
        chunk = max(1, n // (workers * 4))
        yield from pool.map(
            _validate_one, files, [options] * n, [input_format] * n, [target] * n, chunksize=chunk
        )


@main.command()
@click.argument("words", nargs=-1, required=True, metavar="FILES... [KEY:=VALUE]...")
@click.option(
    "--format",
    "output_format",
    type=click.Choice(["text", "json", "github"]),
    default="text",
    show_default=True,
    help="How to print findings.",
)
@click.option("--strict", is_flag=True, help="Fail (exit 1) on warnings too.")
@click.option("--show-info", is_flag=True, help="Also print info-level findings.")
@click.option("--no-resources", is_flag=True, help="Do not open mesh files to check that they load.")
@click.option(
    "--target",
    type=click.Choice(["mjcf", "sdf", "urdf", "pybullet"]),
    default=None,
    help="Judge the files as this consumer would: what it refuses (e.g. an inertia breaking A + B >= C "
    "for mjcf and sdf) is an error even where the file's own loader accepts it.",
)
@click.option(
    "--ignore",
    "ignored",
    multiple=True,
    metavar="CODE",
    help="Silence a code (MK103) or name (unknown-key); repeatable.",
)
@click.option(
    "-j",
    "--jobs",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Check the files in this many processes; findings are printed in input order, as with -j 1.",
)
@reading_options
def validate(
    words: tuple[str, ...],
    output_format: str,
    strict: bool,
    show_info: bool,
    no_resources: bool,
    target: str | None,
    ignored: tuple[str, ...],
    jobs: int,
    **kwargs: Any,
) -> None:
    """Check model files and print file:line:col findings with stable codes.

    FILES may be .body, .urdf, .xacro, .sdf/.world or MJCF (.xml/.mjcf); KEY:=VALUE words are
    passed to xacro as arguments.
    """
    from modelkit.codes import resolve

    _no_mujoco_rendering()

    silenced: set[str] = set()
    for item in ignored:
        info = resolve(item)
        if info is None:
            raise click.BadParameter(f"unknown code {item!r}", param_hint="--ignore")
        silenced.add(info.code)
    files, xacro_args = split_xacro_args(words)
    if not files:
        raise click.UsageError("no model file given")
    options = _read_options(kwargs, not no_resources, xacro_args)
    findings: list[Diagnostic] = []
    unreadable = False
    for diagnostics in _validate_all(files, options, kwargs["input_format"], target, jobs):
        for d in diagnostics:
            if d.code in silenced:
                continue
            if d.code in UNREADABLE_CODES:
                unreadable = True
            findings.append(d)
    shown = [d for d in findings if show_info or d.severity is not Severity.INFO]
    if output_format == "json":
        click.echo(render_json(shown, [str(f) for f in files]))
    else:
        render = render_github if output_format == "github" else render_text
        for d in shown:
            click.echo(render(d))
    errors = sum(1 for d in findings if d.severity is Severity.ERROR)
    warnings = sum(1 for d in findings if d.severity is Severity.WARNING)
    if output_format == "text":
        click.echo(f"{len(files)} file(s) checked: {errors} error(s), {warnings} warning(s)", err=True)
    if unreadable:
        sys.exit(2)
    sys.exit(1 if errors or (strict and warnings) else 0)


@main.command()
@click.argument("file", type=click.Path(path_type=Path))
@click.argument("xacro_words", nargs=-1, metavar="[KEY:=VALUE]...")
@click.option(
    "--order",
    type=click.Choice(["joint-name", "document"]),
    default="joint-name",
    show_default=True,
    help="Child order: by joint name as check_urdf prints it, or as written in the file.",
)
@click.option(
    "--format",
    "output_format",
    type=click.Choice(["text", "json"]),
    default="text",
    show_default=True,
    help="text: the check_urdf report; json: the tree with joint types and origins.",
)
@reading_options
def tree(file: Path, xacro_words: tuple[str, ...], order: str, output_format: str, **kwargs: Any) -> None:
    """Print the kinematic tree exactly as check_urdf does.

    Works for every format. An SDF world prints one report per model, in document order.
    """
    with _collector_paused():  # the model is freed when _tree returns, before collections resume
        _tree(file, xacro_words, order, output_format, **kwargs)


def _tree(file: Path, xacro_words: tuple[str, ...], order: str, output_format: str, **kwargs: Any) -> None:
    _no_mujoco_rendering()
    from modelkit.api import validate as validate_file
    from modelkit.tree import TreeTooLarge, json_chunks, report_chunks

    extra_files, xacro_args = split_xacro_args(xacro_words)
    if extra_files:
        raise click.UsageError(
            f"tree takes one file; unexpected {extra_files[0]} (xacro arguments are KEY:=VALUE)"
        )
    options = _read_options(kwargs, False, xacro_args)
    result = validate_file(file, options, kwargs["input_format"], str(file))
    if not result.robots and not result.errors:  # no robot (a macro library): validate exits 0 too
        for d in result.diagnostics:
            click.echo(render_text(d), err=True)
        click.echo(render_text(diag("MK222", "no robot in this file: there is no kinematic tree to print",
                                    SourceLocation(str(file)))), err=True)
        return
    blocking = [
        d
        for d in result.diagnostics
        if d.severity is Severity.ERROR
        and d.code not in TREE_PRINTABLE_CODES
        and (d.code.startswith("MK2") or d.code.startswith("MK0") or result.robot is None)
    ]
    if not result.robots or any(r.root is None for r in result.robots) or blocking:
        shown = blocking or result.errors
        for d in shown or result.diagnostics:
            click.echo(render_text(d), err=True)
        if not shown:  # every failure carries a code, even one no reader explained
            click.echo(render_text(diag("MK200", "no root link: the kinematic tree cannot be built",
                                        SourceLocation(str(file)))), err=True)
        click.echo("ERROR: the kinematic tree cannot be built", err=True)
        sys.exit(2 if any(d.code in UNREADABLE_CODES for d in result.diagnostics) else 1)
    render = json_chunks if output_format == "json" else report_chunks
    reports: list[Iterator[str]] = []
    for robot in result.robots:  # every report is sized before the first is printed
        try:
            reports.append(render(robot, order))  # type: ignore[arg-type]
        except TreeTooLarge as exc:
            message = (f'the tree report of "{robot.name}" would pass {exc.limit:,} lines: check_urdf prints '
                       "a link once per path from the root, and links with several parents (MK220) "
                       f'multiply the paths (at link "{exc.link}")')
            click.echo(render_text(diag("MK223", message, SourceLocation(str(file)),
                                        hint="give every link one parent joint")), err=True)
            click.echo("ERROR: the kinematic tree cannot be printed", err=True)
            sys.exit(1)
    for chunks in reports:  # streamed: a deep chain's report is far larger than the model
        for text in chunks:
            click.echo(text, nl=False)
    # Printed as far as it could be built; an error in the model itself (a cycle, a second parent, a
    # value that is not a number) still fails the command. Meshes and textures (MK5xx) are not the tree's.
    faults = [d for d in result.errors if not d.code.startswith("MK5")]
    if faults:
        for d in faults:
            click.echo(render_text(d), err=True)
        click.echo(f"ERROR: {file} has {len(faults)} error(s); the tree above is what could be built",
                   err=True)
        sys.exit(1)
    if result.errors:
        click.echo(f"note: {file} has {len(result.errors)} resource error(s); run `modelkit validate {file}`",
                   err=True)


@main.command()
@click.argument("words", nargs=-1, required=True, metavar="INPUTS... [KEY:=VALUE]...")
@click.option("-o", "--output", type=click.Path(path_type=Path), required=True,
              help="Output file (its suffix picks the target: .urdf .sdf .xml .body) or folder (with --to).")
@click.option("--to", "target", type=click.Choice(TARGET_NAMES), default=None,
              help="Target format (default: from the output file's suffix).")
@click.option("--report", "report_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write every conversion note and reading finding to this JSON file.")
@click.option("--strict", is_flag=True, help="Exit 1 when a note at --strict-level or above was made.")
@click.option("--strict-level", type=click.Choice(["info", "warning"]), default="warning", show_default=True,
              help="The note severity --strict fails on.")
@click.option("--force", is_flag=True, help="Replace output files that exist.")
@click.option("--quiet", "-q", is_flag=True, help="Print only warnings and errors, no info notes.")
@click.option("--sdf-version", type=click.Choice(SDF_VERSIONS),
              default="1.9", show_default=True,
              help="SDFormat version to write (1.6 for Gazebo 9 / libsdformat 6 users).")
@click.option("--mesh-format", type=click.Choice(MESH_FORMATS), default="stl", show_default=True,
              help="File format of meshes modelkit writes (generated geometry, converted COLLADA/VRML).")
@click.option("--keep-collada", is_flag=True,
              help="URDF/SDF/.body: copy COLLADA meshes as they are (MJCF always converts).")
@click.option("--keep-package-uris", is_flag=True,
              help="Keep package:// and model:// mesh references instead of copying the meshes.")
@click.option("--merge-fixed", is_flag=True, help="Fuse links on fixed joints into their parents.")
@click.option("--frame-sites/--frame-bodies", default=True, show_default=True,
              help="MJCF: massless links on fixed joints that carry nothing (a tool flange, a TCP, an "
                   "optical frame) as <site>s in the body they hang on, as MuJoCo Menagerie writes them "
                   "(MK873); --frame-bodies writes them as empty bodies.")
@click.option("--urdf-world-link", is_flag=True,
              help="URDF: hang a floating root from a `world` link too (a welded root always does).")
@click.option("--urdf-distinct-names", is_flag=True,
              help="URDF: rename a joint named like a link <name>_joint (libsdformat's URDF to SDF "
                   "conversion refuses the shared name, which URDF and ROS allow; MK846).")
@click.option("--urdf-sensor-links/--no-urdf-sensor-links", default=True, show_default=True,
              help="URDF: each camera, LiDAR and IMU a massless link on a fixed joint, cameras with a "
                   "REP-103 optical frame (MK847); --no-urdf-sensor-links keeps them on their links "
                   "(PyBullet gives a massless link 1 kg).")
@click.option("--gazebo", type=click.Choice(GAZEBO_CHOICES), default="auto", show_default=True,
              help="URDF <gazebo> blocks and SDF sensors for Gazebo classic (ray, depth, gazebo_ros plugins) "
                   "or Gazebo Sim (gpu_lidar, rgbd_camera, gz-sim systems); auto: what the source used, "
                   "Sim when it says nothing (MK848).")
@click.option("--ros-plugins/--no-ros-plugins", default=True, show_default=True,
              help="Gazebo classic: a sensor the source gave no plugin gets the gazebo_ros plugin that "
                   "publishes it to ROS 2 (LaserScan/PointCloud2, camera and depth images, Imu; MK850).")
@click.option("--drive-plugin/--no-drive-plugin", default=True, show_default=True,
              help="URDF/SDF: a robot on two sides of wheels that the source gives no controller gets "
                   "Gazebo's differential-drive plugin (Sim's DiffDrive or classic's gazebo_ros diff "
                   "drive, by --gazebo), driven by a Twist on cmd_vel (MK858).")
@click.option("--wheel-collision", type=click.Choice(WHEEL_COLLISIONS), default="auto", show_default=True,
              help="Collision shape of wheels (auto: a sphere for MJCF and URDF, the cylinder for SDF and "
                   ".body; MK826).")
@click.option("--support-contact", type=click.Choice(SUPPORT_CONTACTS), default="compliant",
              show_default=True,
              help="URDF: a wheeled robot standing on more than three links (drive wheels and casters) gets "
                   "PyBullet contact stiffness and damping on each, so that PyBullet shares its weight among "
                   "them (MK861); rigid leaves PyBullet's rigid contacts, which can leave a drive wheel "
                   "unloaded.")
@click.option("--base", type=click.Choice(["auto", "fixed", "floating"]), default="auto", show_default=True,
              help="Weld the root to the world or let it float; auto keeps the source's answer and, where "
                   "it has none (URDF), floats robots with wheels or legs and welds the others.")
@click.option("--actuators", type=click.Choice(ACTUATOR_CHOICES), default="auto", show_default=True,
              help="MJCF and SDF (gz-sim joint controllers): the actuator of every hinge and slide joint "
                   "when the source has no actuators; "
                   "auto: a position servo on each joint with a range or in a leg (the model holds its home "
                   "pose), a motor on each other (wheels: torque-driven). Servos get gains from each joint's "
                   "reflected inertia (MK840, MK841). A source's own actuators are written as "
                   "--source-actuators says.")
@click.option("--source-actuators", type=click.Choice(SOURCE_ACTUATORS), default="auto", show_default=True,
              help="MJCF and SDF: what becomes of the source's own actuators. auto: written as they are, "
                   "except ROS "
                   "effort interfaces (URDF transmissions, ros2_control), which get the --actuators choice "
                   "(position servos on an arm's and a leg's joints, MK864), since a ROS controller closes "
                   "its own loop over them; keep: all written as they are (effort interfaces as <motor>s, "
                   "limp at zero control: MK857, MK863); replace: all set aside for the --actuators choice "
                   "(MK855).")
@reading_options
def convert(
    words: tuple[str, ...],
    output: Path,
    target: str | None,
    report_path: Path | None,
    strict: bool,
    strict_level: str,
    force: bool,
    quiet: bool,
    sdf_version: str,
    mesh_format: str,
    keep_collada: bool,
    keep_package_uris: bool,
    merge_fixed: bool,
    frame_sites: bool,
    urdf_world_link: bool,
    urdf_distinct_names: bool,
    urdf_sensor_links: bool,
    gazebo: str,
    ros_plugins: bool,
    drive_plugin: bool,
    wheel_collision: str,
    support_contact: str,
    base: str,
    actuators: str,
    source_actuators: str,
    **kwargs: Any,
) -> None:
    """Convert model files to URDF, SDF, MJCF or .body; every approximation is reported.

    The output folder gets the model file(s) and every mesh they need (in meshes/), referenced by
    relative paths. Exit 0 written; 1 an input has errors (or --strict notes); 2 could not run.
    """
    from modelkit.convert import WriteOptions
    from modelkit.convert import convert as run_convert
    from modelkit.convert.report import render_summary

    files, xacro_args = split_xacro_args(words)
    if not files:
        raise click.UsageError("no input file given")
    options = WriteOptions(
        sdf_version=sdf_version,
        mesh_format=mesh_format,
        keep_collada=keep_collada,
        keep_package_uris=keep_package_uris,
        merge_fixed=merge_fixed,
        frame_sites=frame_sites,
        urdf_world_link=True if urdf_world_link else None,
        urdf_distinct_names=urdf_distinct_names,
        urdf_sensor_links=urdf_sensor_links,
        gazebo=gazebo,
        ros_plugins=ros_plugins,
        drive_plugin=drive_plugin,
        wheel_collision=wheel_collision,
        support_contact=support_contact,
        base=base,
        actuators=actuators,
        source_actuators=source_actuators,
    )
    with _interruptible("convert", output):
        result = run_convert(files, output, target, _read_options(kwargs, True, xacro_args), options, force,
                             kwargs["input_format"], report=report_path)
    for d in result.diagnostics:
        click.echo(render_text(d), err=True)
    click.echo(render_summary(result, quiet), err=True, nl=False)
    if result.status:
        sys.exit(result.status)
    threshold = Severity(strict_level).rank
    if strict and any(n.severity.rank >= threshold for n in result.notes):
        sys.exit(1)


@contextmanager
def _interruptible(command: str, where: Path | None, snapshot: Any = None) -> Iterator[None]:
    """Ctrl-C, SIGTERM and SIGHUP end ``command`` with one MK896 line and exit 128 + the signal
    (130, 143, 129), no traceback. What the command wrote is undone on the way out (convert's staged
    commit does it itself; ``snapshot``, a :class:`modelkit.safewrite.Snapshot`, removes the files a
    verify run added)."""
    from modelkit.interrupt import Interrupted, interruptible, pending, signals_held

    def stop(signum: int, finished: bool = False) -> NoReturn:
        with signals_held(deliver=False):  # a second Ctrl-C does not cut the clean-up short
            if snapshot is not None:
                snapshot.remove_new()
                finished = False
            exc = Interrupted(signum)
            message = f"{command} stopped by {exc.name}; "
            message += ("it had already finished: its files are written" if finished
                        else "what it had written is removed")
            click.echo(render_text(diag("MK896", message, SourceLocation(str(where or command)))), err=True)
            sys.stdout.flush()
            sys.stderr.flush()
        sys.exit(exc.exit_code)

    try:
        with interruptible():
            try:
                yield
            finally:
                signum = pending()  # also when some library swallowed the exception and the run went on
    except Interrupted as exc:
        stop(exc.signum)
    except SystemExit:
        if signum is not None:
            stop(signum)
        raise
    if signum is not None:  # the signal came as the work ended (or an exception was swallowed)
        stop(signum, finished=True)


def _unsafe_output(exc: Exception) -> None:
    """A report file verify must not write through (a symlink, a path out of -o): MK892, exit 2."""
    from modelkit.safewrite import UnsafeOutput

    assert isinstance(exc, UnsafeOutput)
    click.echo(render_text(diag("MK892", f"{exc.message}; the report is not written",
                                SourceLocation(str(exc.path)))), err=True)
    sys.exit(2)


@main.command()
@click.argument("sources", nargs=-1, required=True, type=click.Path(path_type=Path), metavar="MODELS...")
@click.option("-o", "--output", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder for the written MJCF/URDF/SDF and report.json (default: a temporary folder, "
              "no report); with many models, one folder per model in it plus summary.json and summary.html.")
@click.option("--engines", default=",".join(DEFAULT_ENGINES), show_default=True,
              help="Comma-separated engines to run; those not installed are skipped.")
@click.option("--mjcf", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Verify this MJCF (a conversion already made) instead of writing one (one model only).")
@click.option("--urdf", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Verify this URDF instead of writing one (one model only).")
@click.option("--sdf", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Verify this SDF instead of writing one (one model only).")
@click.option("--inject", multiple=True, metavar="FAULT",
              help="Perturb the written files as a buggy converter would (inertia:LINK:1%, com:LINK:DX, "
              "axis:JOINT:flip, cylinder-y:LINK, wheel-radius:LINK:5%, mass:LINK:10%); repeatable.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the random configurations.")
@click.option("--no-replay", is_flag=True, help="Skip layer 3b (the MuJoCo/PyBullet torque replay).")
@click.option("--scenario", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Layer 4's scenario file (command profiles, controller gains, contact, tolerances: "
              "docs/scenarios.md); default: the built-in profiles.")
@click.option("--no-driven", is_flag=True, help="Skip layer 4 (the driven scenarios with contact).")
@click.option("-j", "--jobs", type=click.IntRange(min=1), default=None,
              help="Many models: verify this many at a time, each in its own process (default: the number "
              "of cores; 1 runs them one after the other in this process).")
@click.option("--cluster", metavar="ADDRESS", default=None,
              help="Many models: run each model as a Ray task on this cluster (ray://HOST:PORT, or local "
              "for a private Ray on this machine); needs modelkit[cluster].")
@reading_options
def verify(sources: tuple[Path, ...], output: Path | None, engines: str, mjcf: Path | None, urdf: Path | None,
           sdf: Path | None, inject: tuple[str, ...], seed: int, no_replay: bool, scenario: Path | None,
           no_driven: bool, jobs: int | None, cluster: str | None, **kwargs: Any) -> None:
    """Prove a conversion is the same robot: static facts, kinematics and dynamics in real engines.

    MODELS: one model file, or many (files, or folders: the model files directly inside), verified
    in parallel with one report folder each and a summary. KEY:=VALUE words among them are xacro
    arguments, and the reading options are those of validate and convert.

    Exit 0 every check passed; 1 a check failed; 2 could not run (unreadable input, bad option; with
    many models: any model that could not be verified, which takes precedence over a failed check).
    """
    names = tuple(e.strip() for e in engines.split(",") if e.strip())
    _require_engines(names, output is not None)
    sources, xacro_args = split_xacro_args(tuple(str(s) for s in sources))
    if not sources:
        raise click.UsageError("no model given (only xacro KEY:=VALUE arguments)")
    reading = _reading(kwargs, xacro_args)
    from modelkit import safewrite

    snapshot = None
    if output is not None:
        try:  # refused before minutes of checks, not after
            for name in ("report.json", "report.html", "pictures", "plots", "summary.json", "summary.html"):
                safewrite.check(output, output / name, folder=name in ("pictures", "plots"))
        except safewrite.UnsafeOutput as exc:
            _unsafe_output(exc)
        snapshot = safewrite.Snapshot(output)
    with _interruptible("verify", output, snapshot):
        _verify(sources, output, names, mjcf, urdf, sdf, inject, seed, no_replay, scenario, no_driven, jobs,
                cluster, reading)


def _verify(sources: tuple[Path, ...], output: Path | None, names: tuple[str, ...], mjcf: Path | None,
            urdf: Path | None, sdf: Path | None, inject: tuple[str, ...], seed: int, no_replay: bool,
            scenario: Path | None, no_driven: bool, jobs: int | None, cluster: str | None,
            reading: dict[str, Any]) -> None:
    from modelkit.interrupt import check
    from modelkit.safewrite import UnsafeOutput

    if len(sources) == 1 and not os.path.isdir(sources[0]) and cluster is None:
        from modelkit.verify.api import verify as run_verify
        from modelkit.verify.many import progress_wanted, save
        from modelkit.verify.report import render_table

        shown = progress_wanted(sys.stderr)

        def progress(line: str) -> None:
            check()  # between layers: a Ctrl-C a library swallowed stops the run here
            if shown:
                click.echo(f"verify: {line} ...", err=True)

        report = run_verify(sources[0], output, names, mjcf, urdf, sdf, inject, seed, replay=not no_replay,
                            scenario=scenario, driven=not no_driven, progress=progress,
                            artefacts=output is not None, reading=reading)
        check()
        click.echo(render_table(report), nl=False)
        if output is not None and not report.errors:
            progress("writing the report (plots, pictures, report.html)")
            try:
                save(report, output)
            except UnsafeOutput as exc:
                _unsafe_output(exc)
            click.echo(f"wrote {output / 'report.json'}")
            if "html" in report.artefacts:
                click.echo(f"report: {output / report.artefacts['html']}")
        sys.exit(report.exit_code)
    if mjcf or urdf or sdf:
        raise click.UsageError("--mjcf/--urdf/--sdf name the conversion of one model: give one model")
    _verify_many(sources, output, {"engines": list(names), "inject": list(inject), "seed": seed,
                                   "replay": not no_replay, "driven": not no_driven,
                                   "scenario": str(scenario.resolve()) if scenario else None,
                                   **({"reading": reading} if reading else {})}, jobs, cluster)


def _reading(kwargs: dict[str, Any], xacro_args: dict[str, str]) -> dict[str, Any]:
    """verify's reading options as plain data (``modelkit.verify.source.read_options`` builds the
    ``ReadOptions`` from it, in this process or in a worker), only those that differ from the
    defaults, so that report.json and summary.json name what the user chose."""
    defaults = {"max_bytes": 64 * 1024 * 1024, "max_links": 10_000, "max_list_items": 250_000}
    out: dict[str, Any] = {
        "input_format": kwargs["input_format"],
        "package_paths": {k: str(v) for k, v in _pairs(kwargs["package_paths"], "--package-path").items()},
        "path_variables": {k: str(v) for k, v in _pairs(kwargs["path_variables"], "--path-variable").items()},
        "resource_paths": [str(p) for p in kwargs["resource_paths"]],
        "xacro_args": dict(xacro_args),
        "legacy_xacro": kwargs["legacy_xacro"],
        "materials": str(kwargs["materials"]) if kwargs["materials"] is not None else None,
        "vrml_extrusion": bool(kwargs["vrml_extrusion"]),
        **{k: kwargs[k] for k in defaults if kwargs[k] != defaults[k]},
    }
    return {k: v for k, v in out.items() if v not in (None, {}, [], False)}


def _require_engines(names: tuple[str, ...], report: bool) -> None:
    """Exit 2 with the pip line when the engines (or the report's plots) are not installed."""
    from modelkit.verify.engines.registry import install_line, missing_packages

    source = click.get_current_context().get_parameter_source("engines")
    named = source is not None and source is not click.core.ParameterSource.DEFAULT
    missing = missing_packages(names, named, report)
    if missing:
        message = (f"verify needs {', '.join(sorted(missing))}, not installed: {install_line(missing)} "
                   "(validate, tree and convert work without them)")
        click.echo(render_text(diag("MK950", message, SourceLocation("modelkit verify"))), err=True)
        sys.exit(2)


def _verify_many(sources: tuple[Path, ...], output: Path | None, options: dict[str, Any], jobs: int | None,
                 cluster: str | None) -> None:
    from modelkit.verify import many

    try:
        many.check_options(options)
    except ValueError as exc:
        raise click.UsageError(str(exc)) from exc
    paths = many.expand_inputs(sources)
    if not paths:
        raise click.UsageError("no model file found in " + ", ".join(str(s) for s in sources))
    progress = many.progress_printer(sys.stderr) if many.progress_wanted(sys.stderr) else None
    if cluster is not None:
        from modelkit.verify.cluster import ClusterError, run_ray

        try:
            results = run_ray(many.make_jobs(paths, options, absolute=True), output, cluster, progress)
        except ClusterError as exc:
            click.echo(f"error: {exc}", err=True)
            sys.exit(2)
    else:
        workers = min(jobs or many.default_workers(), len(paths))
        if progress is not None:
            click.echo(f"verifying {len(paths)} models, {workers} at a time", err=True)
        results = many.run_local(many.make_jobs(paths, options), output, workers, progress)
    click.echo(many.render_summary(results), nl=False)
    if output is not None:
        from modelkit.safewrite import UnsafeOutput

        try:
            written = many.write_summary(results, options, output)
        except UnsafeOutput as exc:
            _unsafe_output(exc)
        for path in written:
            click.echo(f"wrote {path}")
    sys.exit(many.exit_code(results))


if __name__ == "__main__":  # pragma: no cover
    main()
