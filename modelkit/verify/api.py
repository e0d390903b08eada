"""``verify(source, out_dir, ...)``: convert a model, load each conversion into each engine, run the
layers, collect every check and skip into a :class:`~modelkit.verify.report.VerifyReport`.

The engine plug-in contract (what ``engine_<name>.py`` modules provide)
=======================================================================

Engines are found by name in :data:`ENGINES` (``"name": "module:function"``) and imported lazily,
only when ``verify`` runs; an ``ImportError`` while importing the module (the engine's Python
package is not installed) becomes a :class:`~modelkit.verify.engines.protocol.Skip` "not installed", never a
failure. Every module exposes::

    def load(model: Path | Robot, renames: Renames, *, root: str) -> EngineModel

* ``model``: the written file this engine reads (MJCF for MuJoCo, URDF for PyBullet and yourdfpy,
  SDF or URDF for Drake: see :data:`INPUTS`), or the in-memory source :class:`Robot` for the
  engines that read no file (``pinocchio``, ``source``).
* ``renames``: ``{"link": {source name: written name}, "joint": {...}}`` from the conversion notes
  (MK800), for information; an engine reports **written** names in everything it returns (the
  layers map them back). For a ``Robot`` input both maps are empty.
* ``root``: the written name of the root link. The engine welds it to the world at the identity
  (delete a free joint, ``useFixedBase=True``, ``WeldFrames``); the layers compare link poses
  relative to this root, so where the file places it does not matter.
* gravity is always (0, 0, −9.81) m/s² in the world frame; no joint damping, armature or friction
  is added by the adapter (only what the model itself has), and the adapter records every setting
  that matters in ``EngineModel.settings``.
* it raises ``modelkit.verify.engines.protocol.EngineError`` (or any ``Exception``) when the file cannot be
  loaded: that becomes a failed layer-1 ``load`` check for the engine, with the message (an engine
  refusing our file is a conversion defect, not a skip).

A module that can integrate the model (layer 3b, the replay) also exposes::

    def simulator(model: Path, renames: Renames, *, root: str, dt: float) -> Simulator

whose ``replay(law, seconds, dt)`` maps ``law.joints`` (source names) through its own ``renames``
and returns q with one column per ``law.joints`` entry, in that order (MuJoCo's is in
``engines/mujoco.py``). The replay tests inertial data: a simulator leaves the joints' passive terms
out (PyBullet zeroes all damping; MuJoCo zeroes damping, friction loss and stiffness and lists them in
``left_out``, said in a Skip). An engine that collects warnings while running (MuJoCo's
``runtime_warnings``, never ``MUJOCO_LOG.TXT``) has them in its settings in the report; those saying
the simulation went unstable are a failed ``stability`` check. Layer 3b itself is
``modelkit.verify.layers.replay``, imported lazily like the engines (missing → Skip)::

    def default_law(source: Robot) -> TorqueLaw
    def replay_layer(source: Robot, sims: list[Simulator], law: TorqueLaw, seconds: float, dt: float
                     ) -> tuple[list[Check], list[Skip], dict[str, Any]]

(the third value: the calibration of the tolerance per compared engine, ``report.json``'s
``replay``). A simulator that also has ``replay_from(law, seconds, dt, start_q)`` (MuJoCo's) is the
reference whose perturbed replays calibrate the tolerance.

Fault injection (``--inject``) is ``modelkit.verify.layers.inject:apply(spec: str, files: dict[str, Path],
renames: dict[str, Renames]) -> str``: it perturbs the written files in place (``files`` maps "mjcf",
"urdf", "sdf" to paths, ``renames`` maps the same keys to that file's renames) and returns a one-line
description for the report; a bad spec raises ``ValueError`` (exit 2).
"""

from __future__ import annotations

import copy
import dataclasses
import importlib
import os
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.convert.api import upper_triangle_inertias
from modelkit.convert.options import WriteOptions
from modelkit.formats.urdf.massless import TINY_MASS
from modelkit.model import BALL_KEYS, WORLD_LINK, JointType, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.protocol import Check, Skip
from modelkit.verify.engines.registry import DEFAULT_ENGINES, ENGINES, INPUTS, PRESTART
from modelkit.verify.report import VerifyReport
from modelkit.verify.source import VerifyError, read_robot, root_tree_only, welded_copy

Renames = dict[str, dict[str, str]]

SUFFIX = {"mjcf": ".xml", "urdf": ".urdf", "sdf": ".sdf"}
REPLAY = "modelkit.verify.layers.replay:replay_layer"
# The options of the files layers 1-3 read (layer 4 reads convert's defaults): the engines weld the root
# themselves (no URDF `world` link), sensors stay on their links (PyBullet reads a massless link as
# 1 kg), joints the source does not actuate get motors (zero control: the passive robot), and massless
# frames stay bodies in MJCF and an MJCF source's sites stay out of URDF and SDF (link sets are compared).
ENGINE_FILES = WriteOptions(urdf_world_link=False, urdf_sensor_links=False, actuators="motor",
                            frame_sites=False)
INJECT = "modelkit.verify.layers.inject:apply"

# The writers' notes that say what a given file holds where the file itself is checked later: sensor
# frames (MK847, each looked up in the file) and repairs of a source tensor no engine holds (MK860/MK870).
GIVEN_NOTES = ("MK847", "MK860", "MK870", "MK881")
CONFIGURATIONS = 50  # layer 2: q = 0 and this many random configurations
SAMPLES = 20  # layer 3a: random (q, dq)
REPLAY_SECONDS = 10.0
REPLAY_DT = 1e-3


def _resolve(target: str) -> Any:
    from modelkit.interrupt import signals_held

    module, _, name = target.partition(":")
    with signals_held():  # Drake's initialisation would swallow a Ctrl-C; glfw's probe child would print it
        return getattr(importlib.import_module(module), name)


def _reference(welded: Robot, report: VerifyReport) -> Robot:
    """The model the layers compare with: the source, or its track approximation (said in a Skip). An
    SDF source's frames are links of it, as every file verify writes holds them (MK874), so layers 1
    and 2 check each frame's place in every engine."""
    from modelkit.convert.api import prepare
    from modelkit.convert.notes import NoteSink
    from modelkit.convert.registry import target_info
    from modelkit.formats.sdf.frame_links import frames_as_links

    notes = NoteSink()
    prepared = prepare(welded, target_info("mjcf"), WriteOptions(), notes)
    tracks = [n for n in notes.items if n.code == "MK809"]
    if not tracks:
        report.reference = "the source model"
        if any(n.code == "MK874" for n in notes.items):
            welded = copy.deepcopy(welded)
            frames_as_links(welded, NoteSink())
            report.reference = "the source model, its SDF frames as links on fixed joints (MK874)"
        return welded
    report.reference = ("the source model with its tracks approximated by rollers as every writer does "
                        "(MK809): the written files are compared with that approximation")
    for n in tracks:
        report.skips.append(Skip(0, "all", "continuous track not verified, only its approximation: "
                                 + n.message))
    return prepared


def _convert(welded: Robot, out_dir: Path, given: dict[str, Path | None], report: VerifyReport,
             needed: set[str], written: dict[str, list[Any]] | None = None
             ) -> tuple[dict[str, Path], dict[str, Renames]]:
    """Write the files the engines read; ``written`` receives each written file's notes."""
    from modelkit.convert.api import output_stem, write
    from modelkit.convert.notes import renames

    files: dict[str, Path] = {}
    maps: dict[str, Renames] = {}
    stem = output_stem(Path(report.source)) if report.source else "robot"
    # Joint springs are passive terms layers 1-3 leave out (MuJoCo's are zeroed on the compiled model);
    # Drake turns an SDF spring into a force element, and then cannot remove the file's world joint to
    # weld the root. The engines' files are written without them.
    welded = copy.deepcopy(welded)
    for joint in welded.joints:
        joint.spring_stiffness = joint.spring_reference = 0.0
    for fmt in ("mjcf", "urdf", "sdf"):
        user = given.get(fmt)
        if user is not None:
            if not os.path.exists(user):  # False for a name too long to look up
                raise VerifyError(f"--{fmt} {user}: no such file")
            files[fmt] = user
            maps[fmt], held = _given_file(welded, fmt, user, out_dir)
            if written is not None and held:
                written[fmt] = held
            report.files[fmt] = str(user)
            continue
        if fmt not in needed:
            continue
        path = out_dir / f"{stem}{SUFFIX[fmt]}"
        # The engines weld the root themselves (fixed base): no URDF `world` link, the root is the base.
        # Sensors stay on their links: PyBullet reads a massless sensor link as 1 kg (MK816, MK847).
        # Layers 1-3 compare the passive robot: motors (zero control, no force) where the source names
        # no actuators, not the default's position servos, which pull every joint to its home pose.
        try:
            notes = write(welded, path, fmt, ENGINE_FILES, force=True)
        except (FileExistsError, PermissionError) as exc:  # a symlink or an input where the file goes
            raise VerifyError(f"cannot write {path}: {exc}") from exc
        if written is not None:
            written[fmt] = list(notes)
        files[fmt] = path
        maps[fmt] = {"link": renames(notes, "link"), "joint": renames(notes, "joint")}
        report.files[fmt] = path.name
        report.notes[fmt] = sorted({n.code for n in notes})
    report.renames = {fmt: {k: dict(sorted(v.items())) for k, v in m.items() if v} for fmt, m in maps.items()}
    return files, maps


def _given_file(robot: Robot, fmt: str, path: Path, out_dir: Path) -> tuple[Renames, list[Any]]:
    """A file the user gave: its renames, and the writer's notes that say what it holds.

    The renames are those ``convert`` makes for ``fmt`` (its MK800 notes, from a conversion staged in
    memory and never written), each kept where the file has the written name and not the source's (a
    file ``convert`` wrote; SDF renames a joint named like its link, the tutorial's ``RightWheel`` →
    ``RightWheel_joint``). A file from elsewhere keeps the source's names. The notes kept are the
    staged conversion's ball-joint chains (MK813: three joints through two links, URDF) whose joints
    and links are all in the file, so that the layers compare it as they compare the URDF verify
    writes, its sensor links (MK847, each looked up in the file by ``approximations.sensor_frames``),
    its flat collision meshes written as thin boxes (MJCF MK881), and the writer's inertia repairs (SDF
    MK860, MJCF MK870: a source tensor no engine holds, lifted to the nearest valid one): the engines
    are compared with the repaired tensor, as for verify's own files (a file that repairs it otherwise
    fails layer 1 there, as it did against the source's tensor)."""
    from lxml import etree

    from modelkit.convert.api import render_model
    from modelkit.convert.notes import renames
    from modelkit.convert.output import OutputPlan
    from modelkit.verify.layers import approximations, planar

    try:
        notes = render_model(robot, fmt, OutputPlan(out_dir / ".renames"), path.name, WriteOptions())
        parser = etree.XMLParser(resolve_entities=False, no_network=True)
        root = etree.parse(str(path), parser).getroot()
    except Exception:  # the engines' own loading says what is wrong with the file
        return {"link": {}, "joint": {}}, []
    tags = {"link": ("link", "body"), "joint": ("joint",)}
    out: Renames = {}
    names: dict[str, set[str]] = {}
    for kind, elements in tags.items():
        names[kind] = {str(el.get("name")) for el in root.iter(*elements) if el.get("name")}
        out[kind] = {source: written for source, written in renames(notes, kind).items()
                     if written in names[kind] and source not in names[kind]}
    _joints_by_child(robot, fmt, root, out, names["joint"])
    held = [note for note in notes if note.code in GIVEN_NOTES or any(
        set(chain.joints) <= names["joint"] and set(chain.links) <= names["link"]
        for chain in approximations.ball_chains(fmt, [note])) or any(
        set(chain.joints) <= names["joint"] for chain in planar.mjcf_chains(fmt, [note]))]
    held.extend(_merged_links(robot, fmt, path, out_dir, out, names["link"]))
    return out, held


def _merged(robot: Robot) -> Robot:
    """A copy of ``robot`` with its fixed joints merged as ``convert --merge-fixed`` does."""
    from modelkit.convert.merge import merge_fixed_joints
    from modelkit.convert.notes import NoteSink

    out = copy.deepcopy(robot)
    merge_fixed_joints(out, NoteSink())
    return out


def _merged_links(robot: Robot, fmt: str, path: Path, out_dir: Path, renames_of: Renames,
                  written: set[str]) -> list[Any]:
    """The MK815 notes of ``convert --merge-fixed`` when the given file is such a conversion: the source
    links missing from it are exactly those that option fuses into their parents (the layers then
    compare the engines reading it with the source merged the same way); none otherwise (a file that
    holds a massless frame as an MJCF site misses that link, and keeps the others)."""
    from modelkit.convert.api import render_model
    from modelkit.convert.output import OutputPlan

    missing = {link.name for link in robot.links
               if renames_of["link"].get(link.name, link.name) not in written and link.name != WORLD_LINK}
    if not missing:
        return []
    try:
        notes = render_model(robot, fmt, OutputPlan(out_dir / ".merged"), path.name,
                             WriteOptions(merge_fixed=True))
    except Exception:  # the engines' own loading says what is wrong with the file
        return []
    merged = [note for note in notes if note.code == "MK815"]
    fused = {note.message[len("link "):].split(" (fixed joint ", 1)[0] for note in merged}
    return merged if fused == missing else []


def _joints_by_child(robot: Robot, fmt: str, root: Any, out: Renames, written: set[str]) -> None:
    """A source joint the file names otherwise (written with options other than convert's defaults:
    ``--urdf-distinct-names`` gives ``LeftWheel_joint``) is found by the link it moves: in place, the
    file's joint whose child is the source joint's child (under its written name)."""
    child_of: dict[str, str] = {}  # written joint -> written child link
    if fmt == "mjcf":
        for body in root.iter("body"):
            for joint in body.findall("joint"):
                if joint.get("name") and body.get("name"):
                    child_of[str(joint.get("name"))] = str(body.get("name"))
    else:
        for joint in root.iter("joint"):
            child = joint.find("child")
            text = child.get("link") if fmt == "urdf" and child is not None else (
                child.text if child is not None else None)
            if joint.get("name") and text:
                child_of[str(joint.get("name"))] = text.strip()
    by_child: dict[str, list[str]] = {}
    for joint, child in child_of.items():
        by_child.setdefault(child, []).append(joint)
    claimed = set(out["joint"].values())
    for joint in robot.joints:
        if joint.name in written or joint.name in out["joint"]:
            continue
        child = out["link"].get(joint.child, joint.child)
        found = [j for j in by_child.get(child, []) if j not in claimed and j not in
                 {s.name for s in robot.joints}]
        if len(found) == 1:
            out["joint"][joint.name] = found[0]
            claimed.add(found[0])


def _copy_given(files: dict[str, Path], given: dict[str, Path | None], out_dir: Path,
                report: VerifyReport) -> None:
    """``--inject`` edits files: a file the user gave is copied into ``out_dir/injected`` first (its
    relative references made absolute), and the engines load the edited copy."""
    from lxml import etree

    from modelkit.verify.layers.relocate import relocated_copy

    for fmt, user in sorted(given.items()):
        if user is None:
            continue
        try:
            files[fmt] = relocated_copy(user, out_dir / "injected")
        except (OSError, etree.LxmlError) as exc:
            raise VerifyError(f"--{fmt} {user}: cannot copy it to inject faults: {exc}") from exc
        report.injected.append(f"--{fmt} {user} is left as it is: the faults go into the copy "
                               f"injected/{files[fmt].name}")


def _prestart(names: Sequence[str]) -> dict[str, Any]:
    """The child processes of the engines that start ahead (:data:`PRESTART`), started: each imports
    its library on the other core while verify reads and converts. An engine that is not installed
    or whose child cannot start gets none (its loader then says why, as without a head start)."""
    warm: dict[str, Any] = {}
    for name in names:
        if name not in PRESTART:
            continue
        try:
            worker = _resolve(PRESTART[name])()
        except (ImportError, OSError):
            continue
        if worker is not None:
            warm[name] = worker
    return warm


def _load_engines(names: Sequence[str], reference: Robot, files: dict[str, Path], maps: dict[str, Renames],
                  report: VerifyReport, warm: Mapping[str, Any] | None = None) -> list[Any]:
    """Each engine's model of its file; ``warm``: the children :func:`_prestart` started, by engine."""
    from modelkit.verify.layers.common import Loaded

    loaded: list[Loaded] = []
    for name in names:
        if name not in ENGINES:
            raise VerifyError(f"unknown engine {name!r}; known: {', '.join(sorted(ENGINES))}")
        kind = INPUTS[name]
        renames: Renames = {"link": {}, "joint": {}} if kind == "robot" else maps[kind]
        model_in: Path | Robot = reference if kind == "robot" else files[kind]
        root = renames.get("link", {}).get(str(reference.root), str(reference.root))
        try:
            load = _resolve(ENGINES[name])
        except ImportError as exc:
            report.skips.append(Skip(0, name, f"not installed ({exc})"))
            continue
        extra = {"worker": warm[name]} if warm and name in warm else {}
        try:
            model = load(model_in, renames, root=root, **extra)
        except ImportError as exc:  # an engine whose adapter imports its library only when it loads
            report.skips.append(Skip(0, name, f"not installed ({exc})"))
            continue
        except Exception as exc:
            if getattr(type(exc), "engine_limit", False):  # e.g. Pinocchio's Data, cubic in the joints
                report.skips.append(Skip(0, name, f"not run: {exc}"))
                continue
            source_skip = (_loop_refusal(name, reference, kind, files, exc)
                           or _reversed_range_refusal(name, reference, kind, files, exc))
            if source_skip is not None:
                report.skips.append(source_skip)
                continue
            what = "the source model" if kind == "robot" else f"the written {kind.upper()} {files[kind].name}"
            why = str(exc)
            if kind == "mjcf" and "XML_ELEMENT_DEPTH_EXCEEDED" in why:
                why = (" ".join(why.split()) + " (its bodies nest deeper than MuJoCo's XML parser reads, 496 "
                       "bodies: the conversion said so, MK872)")
            report.checks.append(Check(1, name, "load", "", float("inf"), 0.0,
                                       f"{name} could not load {what}: {type(exc).__name__}: {why}"))
            continue
        report.engines[name] = dict(model.settings)
        loaded.append(Loaded(name, model, renames))
    return loaded


def _loop_refusal(name: str, reference: Robot, kind: str, files: dict[str, Path], exc: Exception
                  ) -> Skip | None:
    """A Skip (all layers, this engine) when an engine that models a tree of joints only refused the
    written file because the source's closed loops (``robot.loops``, written as extra joints, MK811)
    make its joints form a loop; None for any other failure (that stays a failed ``load`` check).
    Only Drake raises this (``drake_child.DrakeLoopError``); it is recognised by its ``loop_refusal`` flag
    so that this module imports no engine."""
    if not reference.loops or not getattr(type(exc), "loop_refusal", False):
        return None
    joints = ", ".join(f"{loop.name} ({loop.type}, {loop.link1}–{loop.link2})" for loop in reference.loops)
    limitation = str(getattr(type(exc), "limitation", ""))
    return Skip(0, name, (
        f"not verified (layers 1, 2 and 3): the source has {len(reference.loops)} closed-loop joint(s), "
        f"{joints}, which the written {kind.upper()} {files[kind].name} keeps as extra joint(s) (MK811); "
        f"{limitation}. Drake said: {exc}"))


def _reversed_range_refusal(name: str, reference: Robot, kind: str, files: dict[str, Path], exc: Exception
                            ) -> Skip | None:
    """A Skip (all layers, this engine) when Drake refused or aborted on a reversed joint range the source
    itself holds (MK307: urdfdom, libsdformat and Choreonoid load such a file, MuJoCo refuses it), so that
    the written file is faithful and the engine cannot read it; None otherwise (a reversed range the
    conversion made stays a failed ``load`` check). Recognised by the ``reversed_range_refusal`` flag
    (``drake_child.DrakeReversedRange``)."""
    if not getattr(type(exc), "reversed_range_refusal", False):
        return None
    reversed_ranges = [joint for joint in reference.joints if joint.limits.lower > joint.limits.upper]
    if not reversed_ranges:
        return None
    joints = ", ".join(f"{joint.name} [{joint.limits.lower:g}, {joint.limits.upper:g}]"
                       for joint in reversed_ranges)
    limitation = str(getattr(type(exc), "limitation", ""))
    return Skip(0, name, (
        f"not verified (layers 1, 2 and 3): the source's joint range(s) {joints} are reversed (MK307), and "
        f"the written {kind.upper()} {files[kind].name} keeps them as the source has them; {limitation}. "
        f"Drake said: {' '.join(str(exc).split())}"))


def verify(
    source: str | Path,
    out_dir: str | Path | None = None,
    engines: Sequence[str] = DEFAULT_ENGINES,
    mjcf: str | Path | None = None,
    urdf: str | Path | None = None,
    sdf: str | Path | None = None,
    inject: Sequence[str] = (),
    seed: int = 0,
    configurations: int = CONFIGURATIONS,
    samples: int = SAMPLES,
    replay: bool = True,
    scenario: str | Path | None = None,
    driven: bool = True,
    progress: Callable[[str], None] | None = None,
    artefacts: bool = False,
    reading: Mapping[str, Any] | None = None,
) -> VerifyReport:
    """Convert ``source`` (or take the given files), load every engine, run layers 1–3, then layer 4
    (the driven scenarios with contact: ``scenario`` is a scenario file, None for the defaults;
    ``driven`` False skips the layer). ``progress`` receives a short line as each phase starts (the
    CLI shows them on a terminal).

    ``out_dir`` receives the written MJCF/URDF/SDF (a temporary folder, deleted afterwards, when
    None). Never raises for a model problem: a failed check is in ``report.checks``; what stops the
    run (unreadable input, a bad option) is in ``report.errors`` (exit 2).

    ``artefacts`` True (the caller will write the report with ``many.save``, which needs ``out_dir``):
    the report's plotting processes and pictures start while the layers run (``report.prepared``).

    ``reading``: the reading options of ``validate`` and ``convert`` as plain data
    (:func:`modelkit.verify.source.read_options`; package paths, xacro arguments, ...), written into
    ``report.parameters["reading"]`` when given.
    """
    report = VerifyReport(str(source), seed=seed)
    report.parameters = {"configurations": configurations, "dynamics_samples": samples,
                         "tolerance": 1e-9, "replay_seconds": REPLAY_SECONDS, "replay_dt": REPLAY_DT,
                         "engines": list(engines)}
    if reading:
        report.parameters["reading"] = dict(reading)
    if out_dir is None:
        with tempfile.TemporaryDirectory(prefix="modelkit-verify-") as tmp:
            _run(report, Path(source), Path(tmp), engines, mjcf, urdf, sdf, inject, seed,
                 configurations, samples, replay, scenario, driven, progress or _silent, reading)
            return report
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if artefacts:
        from modelkit.verify.report.html import Prepared

        report.prepared = Prepared()
    try:
        _run(report, Path(source), out, engines, mjcf, urdf, sdf, inject, seed, configurations, samples,
             replay, scenario, driven, progress or _silent, reading)
    finally:
        if report.prepared is not None and report.errors:  # no report to write (many.save)
            report.prepared.close()
            report.prepared = None
    return report


def _silent(_: str) -> None:
    return None


def _run(report: VerifyReport, source: Path, out_dir: Path, engines: Sequence[str], mjcf: str | Path | None,
         urdf: str | Path | None, sdf: str | Path | None, inject: Sequence[str], seed: int,
         configurations: int, samples: int, replay: bool, scenario_path: str | Path | None,
         driven: bool, progress: Callable[[str], None], reading: Mapping[str, Any] | None = None) -> None:
    chosen = None
    if scenario_path is not None and driven:  # a bad scenario file stops the run before any layer
        from modelkit.diagnostics import render_text
        from modelkit.verify.drive import scenario as scenarios

        chosen, diagnostics = scenarios.load(scenario_path)
        if chosen is None:
            report.errors.extend(f"--scenario: {render_text(d)}" for d in diagnostics)
            return
    progress(f"reading and converting {source.name}; layers 1-3 (static, kinematics, dynamics)")
    warm = _prestart(engines)
    try:
        done = _layers_1_to_3(report, source, out_dir, engines, mjcf, urdf, sdf, inject, seed,
                              configurations, samples, replay, reading, warm)
    except VerifyError as exc:
        report.errors.append(str(exc))
        return
    finally:  # a child no engine took (verify stopped before loading): ended, not waited for
        for worker in warm.values():
            worker.kill()
            worker.close()
    if done is None:
        return
    robot, given = done
    if not driven:
        report.skips.append(Skip(4, "all", "layer 4 (driven scenarios) not run: switched off (--no-driven)"))
        return
    progress("layer 4: driving the robot in MuJoCo and PyBullet")
    if report.prepared is not None:  # the plotting processes import matplotlib while layer 4 runs
        report.prepared.start_plotters()
    _layer4(report, robot, out_dir, engines, inject, chosen, given)


def _too_stiff(robot: Robot, drive: Any, scenario: Any) -> str | None:
    """:func:`~modelkit.verify.drive.reference.law_too_stiff` on the source's no-slip model (wheels)."""
    from modelkit.verify.drive import reference

    if drive.kind != "wheels":
        return None
    return reference.law_too_stiff(reference.planar_model(robot, drive), drive, scenario)


def _layer4(report: VerifyReport, robot: Robot, out_dir: Path, engines: Sequence[str], inject: Sequence[str],
            chosen: Any, given: Mapping[str, tuple[Path, Renames]]) -> None:
    """Layer 4: the source driven by the seed's controllers in MuJoCo and PyBullet, on a floor;
    ``chosen``: the scenario read from the user's file (None: the built-in one); ``given``: the MJCF
    and URDF the user gave (as layers 1-3 loaded them: copies with the faults of ``inject``), which
    the graded runs drive instead of writing them."""
    from modelkit.verify.drive import scenario as scenarios
    from modelkit.verify.drive import vehicle
    from modelkit.verify.layers import layer4

    try:
        drive = vehicle.find_drive(robot, chosen or scenarios.default_scenario())
    except ValueError as exc:
        report.skips.append(Skip(4, "all", f"layer 4 (driven scenarios) not run: {exc}"))
        return
    chosen = chosen or scenarios.default_scenario(drive.kind, bool(drive.pan or drive.tilt))
    why = (vehicle.supported(robot, drive) or vehicle.drivable(robot, drive, chosen)
           or vehicle.caster_drag(robot, drive) or _too_stiff(robot, drive, chosen))
    if why is not None:
        report.skips.append(Skip(4, "all", f"layer 4 (driven scenarios) not run: {why}"))
        return
    t0 = time.perf_counter()
    result = layer4.run(robot, drive, chosen, out_dir / "layer4", list(engines), inject=inject, given=given)
    report.checks.extend(result.checks)
    report.observations.extend(result.observations)
    report.skips.extend(result.skips)
    report.injected.extend(result.injected)
    report.trajectories = list(result.trajectories)
    report.scenario = scenarios.scenario_dict(chosen)
    report.drive = drive.as_dict()
    report.engines["layer4"] = dict(result.settings)
    report.timings.update(result.timings)
    report.timings["layer 4"] = time.perf_counter() - t0


def _layers_1_to_3(report: VerifyReport, source: Path, out_dir: Path, engines: Sequence[str],
                   mjcf: str | Path | None, urdf: str | Path | None, sdf: str | Path | None,
                   inject: Sequence[str], seed: int, configurations: int, samples: int, replay: bool,
                   reading: Mapping[str, Any] | None = None, warm: Mapping[str, Any] | None = None
                   ) -> tuple[Robot, dict[str, tuple[Path, Renames]]] | None:
    """Layers 1–3 on the welded model; returns the source model as read and the MJCF and URDF the user
    gave, as the engines loaded them, with their renames (None when nothing ran)."""
    from modelkit.verify.engines.reference import SourceModel, dof_joints, source_static
    from modelkit.verify.layers import (
        approximations,
        coupled_armature,
        dynamics,
        kinematics,
        planar,
        shapes,
        static,
    )

    t0 = time.perf_counter()
    try:
        robot = read_robot(source, reading)
        report.robot = robot.name
        welded, report.base = welded_copy(robot)
        asymmetric = upper_triangle_inertias(welded)
        if asymmetric:
            report.skips.append(Skip(1, "all", (
                f"approximation: the source's inertia matrix of {', '.join(asymmetric)} is not symmetric "
                "(MK301: Choreonoid uses it as given); every written file holds its upper triangle, which "
                "the engines are compared with")))
        apart = root_tree_only(welded)
        if apart:
            report.skips.append(Skip(1, "all", (
                f"{len(apart)} link(s) not connected to the root link {welded.root!r} (free bodies of "
                f"the source, MK201: {', '.join(apart)}) not graded by layers 1-3, which compare the "
                "root's tree")))
        reference = _reference(welded, report)
        given = {"mjcf": Path(mjcf) if mjcf else None, "urdf": Path(urdf) if urdf else None,
                 "sdf": Path(sdf) if sdf else None}
        needed = {INPUTS[e] for e in engines if e in INPUTS} - {"robot"}
        written: dict[str, list[Any]] = {}
        files, maps = _convert(welded, out_dir, given, report, needed, written)
        t1 = time.perf_counter()
        if inject:
            _copy_given(files, given, out_dir, report)
        for spec in inject:
            try:
                apply = _resolve(INJECT)
            except ImportError as exc:
                raise VerifyError(f"--inject {spec}: fault injection is not available ({exc})") from exc
            try:
                report.injected.append(str(apply(spec, files, maps)))
            except ValueError as exc:
                raise VerifyError(f"--inject {spec}: {exc}") from exc
        if report.prepared is not None:  # the pictures of the files as verified, on another core
            report.prepared.start_pictures(report, out_dir, welded, files)
        loaded = _load_engines(engines, reference, files, maps, report, warm)
    except VerifyError as exc:
        report.errors.append(str(exc))
        return None
    t2 = time.perf_counter()
    report.timings["convert"] = t1 - t0
    report.timings["load"] = t2 - t1

    src = SourceModel(reference)
    report.engines["source"] = dict(src.settings)
    src_static = source_static(reference)
    # A URDF engine reading convert's default file holds its sensors as links on fixed joints (MK847):
    # layers 1-3 compare it with the source holding them (``models``), the report says so.
    models: dict[str, Robot] = {}
    floors: dict[str, dict[str, float]] = {}  # engine → coupled joint → the MJCF's armature (MK835)
    for eng in loaded:
        kind = INPUTS.get(eng.label, "robot")
        notes = written.get(kind, [])
        frames = [] if kind == "robot" else approximations.sensor_frames(kind, notes, reference, maps[kind],
                                                                         files[kind])
        models[eng.label] = approximations.applied_frames(reference, frames)
        if any(note.code == "MK815" for note in notes):  # a given file written with --merge-fixed
            models[eng.label] = _merged(models[eng.label])
            report.skips.append(Skip(1, eng.label, (
                "the given file fuses links on fixed joints into their parents (convert --merge-fixed, "
                "MK815): layers 1-3 compare this engine with the source merged the same way")))
        frames_entry = approximations.frames_skip(eng.label, frames)
        if frames_entry is not None:
            report.skips.append(frames_entry)
        if kind == "mjcf":  # the MJCF writer's armature on mimic-coupled joints (MK835)
            floors[eng.label] = coupled_armature.written(files[kind], reference, maps[kind])
            models[eng.label] = coupled_armature.applied(models[eng.label], floors[eng.label])
            floors_entry = coupled_armature.skip(eng.label, floors[eng.label])
            if floors_entry is not None:
                report.skips.append(floors_entry)
    approx = _approximations(models, loaded, files, maps, written, report)
    # A URDF engine holds each ball joint as the writer's chain of three joints (MK813): layer 1
    # compares it with the source holding those chains, layer 2 turns the chain, the report says so.
    chains_of = {eng.label: approximations.ball_chains(INPUTS.get(eng.label, "robot"),
                                                       written.get(INPUTS.get(eng.label, "robot"), []))
                 for eng in loaded}
    # A planar joint is the MJCF writer's two slides and a hinge, or the SDF writer's free child (MK813).
    planar_of = {eng.label: planar.held_by(kind, written.get(kind, []))
                 for eng in loaded for kind in [INPUTS.get(eng.label, "robot")]}
    for eng in loaded:
        # An engine holding a documented approximation (MK816 tiny masses, PyBullet's 1 kg) is
        # compared with the source with that approximation applied; the report lists it.
        kind = INPUTS.get(eng.label, "robot")
        chains = chains_of[eng.label]
        chains_entry = approximations.chains_skip(eng.label, chains)
        if chains_entry is not None:
            report.skips.append(chains_entry)
        # A file given with --mjcf/--urdf is usually convert's default, with sphere wheels (MK826).
        wheels = approximations.wheel_proxies(robot, _engine_shapes(eng), eng.link)
        wheels_entry = approximations.wheels_skip(eng.label, wheels)
        if wheels_entry is not None:
            report.skips.append(wheels_entry)
        plates = approximations.flat_collisions(kind, written.get(kind, []), maps.get(kind, {}))
        plates_entry = approximations.plates_skip(eng.label, plates)
        if plates_entry is not None:
            report.skips.append(plates_entry)
        planar_entry = planar.skip(eng.label, planar_of[eng.label])
        if planar_entry is not None:
            report.skips.append(planar_entry)
        held = planar_of[eng.label].applied(approximations.applied_chains(models[eng.label], chains),
                                            maps.get(kind, {}))
        if wheels is not None:
            held = approximations.applied_wheels(held, robot, wheels)
        held = approximations.applied_plates(held, plates)
        eng_static = (source_static(approximations.applied(held, approx[eng.label]))
                      if approx[eng.label] or chains or wheels or plates or planar_of[eng.label]
                      or models[eng.label] is not reference
                      else src_static)
        # ... and so is one holding the URDF writer's ±1e16 for an infinite position bound (MK819), or a
        # reversed range as no limit (MK824 in MJCF; PyBullet).
        stand_ins = approximations.limits_for_engine(kind, reference, eng.label)
        eng_static = approximations.applied_limits(eng_static, stand_ins)
        limits_entry = approximations.limits_skip(eng.label, stand_ins)
        if limits_entry is not None:
            report.skips.append(limits_entry)
        report.checks.extend(_guarded(1, eng, lambda eng=eng, st=eng_static: static.layer1(st, eng)))
        report.skips.extend(_guarded(1, eng, lambda eng=eng, st=eng_static: static.massless_skips(st, eng),
                                     report.checks))
        report.skips.extend(shapes.skips(src_static, eng))
    report.checks[:] = _explain_invalid_inertia(reference, loaded, report.checks)
    t3 = time.perf_counter()
    configs = kinematics.configurations(reference, configurations, seed)
    # a subtree hanging by a floating (planar) joint inside the tree, which some engines hold as a free
    # body (MK813)
    subtrees = {label: approximations.detached_subtrees(reference, detaching.kinds)
                for label, detaching in approximations.DETACHED_BY.items()}
    detached_in = {label for label, links in subtrees.items() if links}
    for eng in loaded:
        chain_joints = {c.joint + key: written_joint for c in chains_of[eng.label]
                        for key, written_joint in zip(BALL_KEYS, c.joints, strict=True)}
        fk = src if models[eng.label] is reference else SourceModel(models[eng.label])
        held_free = subtrees.get(eng.label, {})
        report.checks.extend(_guarded(2, eng, lambda eng=eng, cj=chain_joints, fk=fk, hf=held_free:
                                      kinematics.layer2(fk, eng, configs, cj, hf)))
    t4 = time.perf_counter()
    pin_ref = next((e.model for e in loaded if e.label == "pinocchio"), None)
    balls = [j.name for j in reference.joints if j.type is JointType.BALL]
    ball_only = bool(balls) and all(j.type is JointType.BALL for j in reference.joints if j.type.moves)
    if dynamics.kinematic_only(reference):
        report.skips.append(Skip(3, "all", "no link moved by a joint has mass in the source (a kinematic "
                                           "model): no dynamics to verify"))
        replay = False
    elif not dof_joints(reference) and not ball_only:
        others = sorted({j.type.value for j in reference.joints if j.type.moves})
        report.skips.append(Skip(3, "all", (
            f"its moving joints are {' and '.join(others)} joints only: layer 3 compares the revolute, "
            "prismatic and ball degrees of freedom with the Pinocchio reference; these dynamics are not "
            "verified")
            if others else ("no revolute or prismatic joint: the mass matrix and bias forces are empty and "
                            "nothing moves, no dynamics to verify")))
        replay = False
    elif pin_ref is None:
        report.skips.append(Skip(3, "all", "layer 3a needs Pinocchio (the dynamics reference built from the "
                                           "source model), which is not among the loaded engines"))
    else:
        state = dynamics.states(reference, pin_ref.dof_names(), samples, seed)
        with_armature = [j.name for j in reference.joints if j.armature != 0.0]
        for eng in loaded:
            if eng.label == "pinocchio":
                continue
            if eng.label in detached_in:
                detaching = approximations.DETACHED_BY[eng.label]
                heads = ", ".join(sorted(set(subtrees[eng.label].values())))
                kinds = " or ".join(sorted(kind.value for kind in detaching.kinds))
                report.skips.append(Skip(3, eng.label, (
                    f"not compared: the subtree(s) of {heads} hang by a {kinds} joint, and {detaching.why}; "
                    "its mass matrix over the other joints then leaves the subtree out, which the "
                    "reference's chain carries")))
                continue
            dropped = bool(with_armature) and INPUTS.get(eng.label) in ("urdf", "sdf")
            # an engine holding each ball joint as the URDF writer's chain (MK813) is compared with the
            # source holding those chains, whose three joints are revolute degrees of freedom
            chains = chains_of[eng.label]
            renames_of = maps.get(INPUTS.get(eng.label, "robot"), {})
            chained = approximations.applied_chains(models[eng.label], chains)
            held_planar = planar_of[eng.label].applied(chained, renames_of)
            model = approximations.applied(held_planar, approx[eng.label])
            ref = (_without_armature(model) if dropped
                   else pin_ref if model is reference else _pinocchio(model))
            held_state = [(approximations.chain_configuration(q, chains), dq) for q, dq in state]
            # an engine holding each ball as a ball (MuJoCo) gives it in the chain's coordinates too
            with_balls = (bool(balls) and not chains and dynamics.holds_balls_as_chains(eng.model)
                          and dynamics.holds_balls_as_chains(ref))
            if balls and not chains and not with_balls:
                report.skips.append(Skip(3, eng.label, (
                    f"ball joint(s) {', '.join(balls)}: {eng.label} parametrises a ball's velocity its own "
                    "way, so layer 3a compares "
                    + ("nothing for it (only ball joints move)" if ball_only else
                       "its revolute and prismatic degrees of freedom only, each ball at rest at a sampled "
                       "orientation"))))
                if ball_only:
                    continue
            try:
                last = {chain.joint: chain.joints[2] for chain in chains}
                last.update({chain.joint: chain.joints[2] for chain in planar_of[eng.label].chains})
                report.checks.extend(_guarded(3, eng, lambda eng=eng, ref=ref, st=held_state, last=last,
                                              wb=with_balls: dynamics.layer3a(ref, eng, st, last, wb)))
                report.engines[eng.label] = dict(eng.model.settings)  # a route layer 3a chose, said
                if dropped:
                    report.skips.append(Skip(3, eng.label, (
                        f"joint armature (rotor inertia) of {', '.join(with_armature)} cannot be written in "
                        "URDF/SDF (MK820): the mass matrix is compared with the Pinocchio reference "
                        "without it")))
            except NotImplementedError as exc:
                report.skips.append(dynamics.no_dynamics(eng, str(exc)))
        for label, armature in sorted(floors.items()):
            report.checks.extend(coupled_armature.rule_checks(label, reference, armature, pin_ref))
    t5 = time.perf_counter()
    if replay:
        _replay(reference, files, maps, loaded, report, approx, models.get("pybullet"),
                chains_of.get("pybullet", []), sorted(floors.get("mujoco", {})))
    t6 = time.perf_counter()
    for eng in loaded:
        messages = list(getattr(eng.model, "runtime_warnings", []))
        report.checks.extend(engine_warnings(report, eng.label, messages, "runtime_warnings", "layers 1-3a"))
        eng.model.close()
    report.timings.update({"layer 1": t3 - t2, "layer 2": t4 - t3, "layer 3a": t5 - t4, "layer 3b": t6 - t5})
    return robot, {fmt: (files[fmt], maps[fmt]) for fmt in ("mjcf", "urdf") if given[fmt] is not None}


def _engine_shapes(eng: Any) -> dict[str, list[Any]]:
    """The collision shapes an engine reports, by link (none when it cannot report its facts: layer 1
    then fails it with the reason)."""
    from modelkit.verify.engines.protocol import EngineError

    try:
        return dict(eng.model.static().shapes)
    except EngineError:
        return {}


def _held(approximated: Any) -> tuple[float, ...] | None:
    """The tensor an engine holds instead of the source's (None: the source's own)."""
    return approximated.tensor if approximated is not None else None


def _source_finding(*approximations: Any) -> bool:
    """Whether any engine's approximation of a link is a source finding (validate's MK302/MK303)."""
    return any(a is not None and a.code in ("MK302", "MK303") for a in approximations)


def _explain_invalid_inertia(reference: Robot, loaded: list[Any], checks: list[Check]) -> list[Check]:
    """A failed layer-1 ``inertia`` check of PyBullet or drake-urdf at a link whose source inertia
    violates the triangle inequality (MK303) stays failed (the consumer refuses the source's data;
    the URDF keeps that data as it is), but its message says what the engine made of it and why."""
    from modelkit.verify.layers.approximations import triangle_moments

    labels = {e.label for e in loaded}
    links = {link.name: link for link in reference.links}
    out = []
    for check in checks:
        link = links.get(check.where)
        if (check.layer == 1 and check.quantity == "inertia" and not check.passed and link is not None
                and link.inertial is not None and check.engine in labels
                and check.engine in ("pybullet", "drake-urdf")):
            moments = triangle_moments(np.asarray(link.inertial.inertia, dtype=float))
            if moments is not None:
                if check.engine == "pybullet":
                    note = _resolve("modelkit.verify.engines.pybullet:invalid_inertia_note")
                    why = str(note(link.name, moments))
                else:
                    why = str(_resolve("modelkit.verify.engines.drake:invalid_inertia_note")(
                        link.name, moments, link.inertial.mass))
                check = dataclasses.replace(check, detail=f"{check.detail}: {why}")
        out.append(check)
    return out


def _guarded(layer: int, eng: Any, run: Any, checks: list[Check] | None = None) -> list[Any]:
    """``run()``'s result, or, when the engine raises (a crash, a refusal, a None where numbers were
    due), a failed check with the message: an engine failing on our file is a finding, never a crash
    of the run. The check goes into the result, or into ``checks`` when the result holds skips."""
    try:
        return list(run())
    except NotImplementedError:
        raise
    except Exception as exc:
        failed = Check(layer, eng.label, "engine-error", "", float("inf"), 0.0,
                       f"{eng.label} failed during layer {layer}: {type(exc).__name__}: {exc}")
        if checks is not None:
            checks.append(failed)
            return []
        return [failed]


def _approximations(models: Mapping[str, Robot], loaded: list[Any], files: dict[str, Path],
                    maps: dict[str, Renames], written: dict[str, list[Any]], report: VerifyReport
                    ) -> dict[str, Any]:
    """Per loaded engine, the documented mass approximations it holds (see ``approximations``) against
    ``models`` (the source as that engine's file holds it), each listed in the report."""
    from modelkit.verify.layers import approximations

    out: dict[str, Any] = {}
    for eng in loaded:
        kind = INPUTS.get(eng.label, "robot")
        if kind == "robot":
            out[eng.label] = {}
            continue
        out[eng.label] = approximations.for_engine(eng.label, kind, written.get(kind, []), files[kind],
                                                   models[eng.label], maps[kind])
        entry = approximations.skip(eng.label, out[eng.label])
        if entry is not None:
            report.skips.append(entry)
    return out


def _ball_chain_replay(reference: Robot, chains: Sequence[Any], maps: dict[str, Renames],
                       inertials: dict[str, tuple[float, float]], frames: dict[str, tuple[str, Any]],
                       report: VerifyReport) -> dict[str, Renames]:
    """The replay of a model whose ball joints PyBullet reads as the URDF writer's chains (MK813):
    the law's ball entries (``NAME#x``...) renamed to the chain's joints for PyBullet, and the chain
    links' tiny mass (MK816, at the pivot) added to the ball's parent body in MuJoCo, where it is the
    same mass; their 1e-12 kg·m² per axis turns with the chain's first angles, which no MuJoCo ball
    can hold, so PyBullet's worker zeroes it for the replay (said in the report). ``inertials`` and
    ``frames`` are completed in place; returns the renames to replay with."""
    written = maps["mjcf"].get("link", {})
    by_name = {joint.name: joint for joint in reference.joints}
    urdf_joints = dict(maps.get("urdf", {}).get("joint", {}))
    masses = []
    for chain in chains:
        ball = by_name.get(chain.joint)
        if ball is None:
            continue
        for key, joint in zip(BALL_KEYS, chain.joints, strict=True):
            urdf_joints[chain.joint + key] = joint
        parent = written.get(ball.parent, ball.parent)
        frames[chain.links[0]] = (parent, ball.origin)
        frames[chain.links[1]] = (chain.links[0], Pose())
        for link in chain.links:
            mass = inertials.get(link, (TINY_MASS, 0.0))[0]
            inertials[link] = (mass, 0.0)
            masses.append(mass)
    if masses:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"replay of {len(chains)} ball joint(s) against PyBullet's chains (MK813): the {len(masses)} "
            f"links between a chain's joints keep their {max(masses):g} kg at the pivot in both engines "
            "(MuJoCo: on the ball's parent body) and have their 1e-12 kg·m² per axis zeroed in PyBullet, "
            "which a MuJoCo ball cannot hold; the two engines integrate a ball in different coordinates, so "
            "the replay is graded by the step ladder (see the replay check)")))
    return {**maps, "urdf": {**maps.get("urdf", {}), "joint": urdf_joints}}


def _frame_placements(held: Robot, inertials: Mapping[str, Any], renames: Renames
                      ) -> dict[str, tuple[str, Any]]:
    """Where each link of ``inertials`` (MJCF names) hangs in ``held``, when it hangs by a fixed joint:
    the parent (MJCF name) and the link's pose in it. The MJCF may hold such a link not as a body (a
    massless frame as a ``<site>``, MK873; a sensor as its device), and MuJoCo's replay then adds the
    mass to the body it hangs from, at that pose."""
    written = renames.get("link", {})
    back = {w: source for source, w in written.items()}
    joints = {joint.child: joint for joint in held.joints if joint.type is JointType.FIXED}
    out: dict[str, tuple[str, Any]] = {}
    for name in inertials:
        joint = joints.get(back.get(name, name))
        if joint is not None:
            out[name] = (written.get(joint.parent, joint.parent), joint.origin)
    return out


def _left_out(sims: list[Any], maps: dict[str, Renames]) -> list[str]:
    """What the MuJoCo simulator zeroed for the replay (damping, friction loss, stiffness, a tendon's
    passive terms, a body's gravity compensation; armature is said by its own entry), per quantity,
    with the joints, tendons or bodies by source name and their values."""
    back = {w: src for src, w in maps.get("mjcf", {}).get("joint", {}).items()}
    back_links = {w: src for src, w in maps.get("mjcf", {}).get("link", {}).items()}
    out = []
    for sim in sims:
        for quantity, objects in sorted(getattr(sim, "left_out", {}).items()):
            if quantity == "armature":
                continue
            kind = quantity.split(" ", 1)[0] if quantity.startswith(("tendon ", "body ")) else "joint"
            names_back = back_links if kind == "body" else back
            names = sorted(names_back.get(o, o) for o in objects)
            values = {names_back.get(o, o): v for o, v in objects.items()}
            shown = ", ".join(f"{n} {values[n]:g}" for n in names[:8]) + (
                f" and {len(names) - 8} more" if len(names) > 8 else "")
            what = quantity if kind != "joint" else f"joint {quantity}"
            out.append(f"{what} of {len(names)} {'bodies' if kind == 'body' else kind + '(s)'} ({shown})")
    return out


def _pinocchio(robot: Robot) -> Any:
    from modelkit.verify.engines.pinocchio import PinocchioModel

    return PinocchioModel(robot)


def _without_armature(robot: Robot) -> Any:
    from modelkit.verify.engines.pinocchio import PinocchioModel

    model = PinocchioModel(robot)
    model.model.armature[:] = 0.0
    model.ball_armature.clear()  # a ball's a·JᵀJ too: URDF and SDF cannot hold it either
    model.settings["armature"] = "zeroed (the file's format cannot hold it)"
    return model


def _replay(reference: Robot, files: dict[str, Path], maps: dict[str, Renames], loaded: list[Any],
            report: VerifyReport, approx: dict[str, Any] | None = None, held: Robot | None = None,
            chains: Sequence[Any] = (), coupled: Sequence[str] = ()) -> None:
    """Layer 3b through the replay module (MuJoCo against PyBullet), when it is there; ``held``: the
    source as PyBullet's file holds it (its sensor frames), where PyBullet's approximated links hang;
    ``chains``: the ball joints as PyBullet's file holds them (MK813); ``coupled``: the joints the MJCF
    gives an armature the source does not (MK835)."""
    names = [e.label for e in loaded if e.label in ("mujoco", "pybullet")]
    if len(names) < 2:
        report.skips.append(Skip(3, "mujoco+pybullet", "layer 3b (replay) needs both MuJoCo and PyBullet "
                                 "loaded"))
        return
    try:
        layer3b = _resolve(REPLAY)
        default_law = _resolve("modelkit.verify.layers.replay:default_law")
    except ImportError as exc:
        report.skips.append(Skip(3, "mujoco+pybullet", f"layer 3b (replay) is not available: {exc}"))
        return
    sims = []
    # Armature (rotor inertia) reaches the MJCF but not the URDF PyBullet reads (MK820): the replay
    # runs both without it, as layer 3a compares PyBullet with a reference without it.
    with_armature = [j.name for j in reference.joints if j.armature != 0.0 or j.name in coupled]
    # PyBullet's documented mass approximations (its 1 kg for a URDF link without <inertial>, MK816)
    # are given to MuJoCo for the replay, so that both integrate the same robot (listed in the report).
    pb_approx = (approx or {}).get("pybullet", {})
    mj_approx = (approx or {}).get("mujoco", {})
    # a source tensor the engines repair differently (PyBullet zero or the writer's clean zero, MuJoCo a
    # lifted tensor or 1e-9 per axis, MK870): laikago's all-zero inertias move the legs 1.5e-7 rad apart
    # in 0.5 s, so the two engines do not integrate the same robot there
    refused = sorted(link for link in {**pb_approx, **mj_approx}
                     if _source_finding(pb_approx.get(link), mj_approx.get(link))
                     and _held(pb_approx.get(link)) != _held(mj_approx.get(link)))
    moving = [link for link in refused if link not in _welded_to_root(reference)]
    if moving:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"layer 3b (replay) not run: source finding (MK302/MK303) at moving link(s) {', '.join(moving)} "
            "(their inertia is singular or violates the triangle inequality): PyBullet holds zero there and "
            "the MJCF writer a lifted tensor (MK870), so the two engines integrate different repairs of the "
            "source's data; layers 1 and 3a compare each engine with its own repair")))
        return
    inertials: dict[str, tuple[float, float]] = {}
    if "mjcf" in maps:
        for link, a in pb_approx.items():
            if a.code in ("MK302", "MK303"):  # refused on the welded root: takes part in no dynamics
                continue
            mine = mj_approx.get(link)
            if mine is None or (mine.mass, mine.inertia) != (a.mass, a.inertia):
                inertials[maps["mjcf"].get("link", {}).get(link, link)] = (a.mass, a.inertia)
    principal = _diagonalised(loaded, maps) if "mjcf" in maps else {}
    frames = _frame_placements(held or reference, inertials, maps.get("mjcf", {}))
    balls = [joint.name for joint in reference.joints if joint.type is JointType.BALL]
    unheld = sorted(set(balls) - {chain.joint for chain in chains})
    if unheld:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"layer 3b (replay) not run: PyBullet's file holds ball joint(s) {', '.join(unheld)} not as the "
            "URDF writer's chain of three joints (MK813), so the replay cannot drive them the same way")))
        return
    planes = [joint.name for joint in reference.joints
              if joint.type in (JointType.PLANAR, JointType.FLOATING)]
    if planes:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"layer 3b (replay) not run: joint(s) {', '.join(planes)} let a part of the robot move in a "
            "plane or in space, driven by nothing: the replay would compare how each engine moves that "
            "base under the arm's reaction, through joints held differently (PyBullet's planar joint, "
            "whose inverse dynamics it does not implement; the MJCF's two slides and a hinge; the SDF's "
            "free body), which layer 3a does not check. Layers 1-3a compare each engine with the source "
            "at that joint's zero")))
        return
    if chains and "mjcf" in maps:
        maps = _ball_chain_replay(reference, chains, maps, inertials, frames, report)
    for name in names:
        kind = INPUTS[name]
        root = maps[kind].get("link", {}).get(str(reference.root), str(reference.root))
        extra: dict[str, Any] = {}
        if kind == "mjcf":
            extra = {**({"armature": False} if with_armature else {}),
                     **({"inertials": inertials} if inertials else {}),
                     **({"principal": principal} if principal else {}),
                     **({"frames": frames} if frames else {})}
        elif name == "pybullet":  # its child from layers 1-3, reused when it holds the same file
            extra = {"loaded": next(e.model for e in loaded if e.label == name)}
        try:
            make = _resolve(ENGINES[name].replace(":load", ":simulator"))
            sims.append(make(files[kind], maps[kind], root=root, dt=REPLAY_DT, **extra))
        except Exception as exc:
            for sim in sims:
                sim.close()
            if getattr(type(exc), "engine_limit", False):  # e.g. PyBullet's 127 moving joints
                report.skips.append(Skip(3, "mujoco+pybullet", f"layer 3b (replay) not run: {name}: {exc}"))
                return
            report.checks.append(Check(3, name, "replay", "", float("inf"), 1e-8,
                                       f"{name} could not load the model for the replay: "
                                       f"{type(exc).__name__}: {exc}"))
            return
    equalities = sum(int(getattr(sim, "equalities", 0)) for sim in sims)
    if equalities:
        mimics = [j.name for j in reference.joints if j.mimic is not None]
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"replay of the open tree: MuJoCo's {equalities} equality constraint(s) are disabled "
            + (f"(mimic joints {', '.join(mimics)} follow their leaders there) " if mimics else "")
            + "because PyBullet does not read URDF <mimic> and a URDF holds no closed loop; the couplings "
            "themselves are not verified by the replay")))
    if principal:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"replay with PyBullet's diagonalised inertia given to MuJoCo too: {len(principal)} link(s) with "
            "products of inertia hold the principal moments and axes PyBullet's URDF importer computed "
            "(btMatrix3x3::diagonalize, threshold 1e-6) in both engines, so the replay compares the "
            "integration of the same numbers; layer 3a compares each engine's tensor with the source")))
    chain_links = {link for chain in chains for link in chain.links}  # said by the ball-chain entry
    approximated = sorted(link for link in inertials if link not in chain_links)
    if approximated:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            "replay with PyBullet's documented approximation given to MuJoCo too: "
            f"{len(approximated)} link(s) massless in the source ({', '.join(approximated[:8])}) hold "
            "PyBullet's values in both engines (MK816, see the layer 1 approximation entry)")))
    left_out = _left_out(sims, maps)
    if left_out:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            "replay without the joints' passive terms (it tests inertial data; PyBullet's worker zeroes "
            "all damping, its 0.04 default and the URDF's <dynamics damping>; a URDF holds no gravity "
            "compensation): MuJoCo's "
            + "; ".join(left_out) + " zeroed on the compiled model")))
    if with_armature:
        report.skips.append(Skip(3, "mujoco+pybullet", (
            f"replay without the joint armature (rotor inertia) of {', '.join(with_armature)}: the URDF "
            "PyBullet reads cannot hold it (MK820), so MuJoCo replays with it zeroed; MuJoCo's armature "
            "is verified by layer 3a (mass matrix against Pinocchio with armature)")))
    try:
        law = default_law(reference)
    except ValueError as exc:  # replay.UnstableLaw: no gains make the linearised loop contract
        for sim in sims:
            sim.close()
        report.skips.append(Skip(3, "mujoco+pybullet", f"layer 3b (replay) not run: {exc}"))
        return
    # MuJoCo's layer 3a (no integration) says the written MJCF holds the source's dynamics
    dynamics = [c for c in report.checks if c.layer == 3 and c.engine == sims[0].engine
                and c.quantity in ("mass-matrix", "bias")]
    sound = bool(dynamics) and all(c.passed for c in dynamics)
    try:
        checks, skips, calibration, softened = _conditioned_replay(reference, sims, law, layer3b, sound)
        report.replay = calibration
    finally:
        for sim in sims:
            sim.close()
    report.checks.extend(checks)
    report.skips.extend(skips)
    if softened:
        report.skips.append(Skip(3, "mujoco+pybullet", softened))
    for sim in sims:
        messages = list(getattr(sim, "runtime_warnings", []))
        report.checks.extend(engine_warnings(report, sim.engine, messages, "replay_warnings",
                                             "the replay (layer 3b)"))


LAW_SOFTENINGS = 3  # at most this many halvings of the replay law's bandwidth when the reference blows up


def _conditioned_replay(reference: Robot, sims: list[Any], law: Any, replay_layer: Any, sound: bool = False
                        ) -> tuple[list[Check], list[Skip], dict[str, Any], str]:
    """Layer 3b with a law the reference engine (the first simulator, MuJoCo) can integrate: when its
    replay turns non-finite or MuJoCo warns that it went unstable, the law's bandwidth is halved
    (kp/4, kd/2, damping ratio kept; :func:`replay.soften`) and the replay run again, at most
    :data:`LAW_SOFTENINGS` times. The linearised check of ``default_law`` cannot see every such run:
    robosuite's GR1 humanoid, whose layers 1–3a agree to 1e-15, blew up in MuJoCo at 4.48 s at full
    bandwidth (the engines 2.6e4 rad apart), and at half bandwidth the engines agreed to 2.6e-13 rad.
    The last value says what was softened and why ("" when nothing was); a failure that remains after
    the last halving is reported as before, unless ``sound`` (MuJoCo's layer 3a found the written
    file's mass matrix and bias equal to the source's): then the dynamics the replay integrates (no
    armature, damping, limits or contact) are what no engine can integrate, not what the conversion
    wrote, and the replay is skipped with the engine's message and time. dm_control's CMU humanoid
    and rodent: swinging free without them, MuJoCo blows up on the source itself (the CMU humanoid at
    1.25 s, also at a timestep of 0.125 ms); they passed before only because PyBullet's 1 kg for a
    massless URDF link added 1 kg to each of the bodies' intermediate joint links."""
    from modelkit.verify.engines.mujoco import unstable

    soften = _resolve("modelkit.verify.layers.replay:soften")
    why: list[str] = []
    for attempt in range(LAW_SOFTENINGS + 1):
        before = [len(getattr(sim, "runtime_warnings", [])) for sim in sims]
        checks, skips, calibration = replay_layer(reference, sims, law, REPLAY_SECONDS, REPLAY_DT)
        ref = sims[0].engine if sims else ""
        blown = [c.message for c in checks if c.engine == ref and c.quantity == "engine-error"]
        for sim, start in zip(sims, before, strict=True):
            new = unstable(list(dict.fromkeys(getattr(sim, "runtime_warnings", [])[start:])))
            if sim.engine == ref and new:
                blown.append(f"{sim.engine} warned: {new[0]}")
        if not blown or attempt == LAW_SOFTENINGS:
            break
        for sim, start in zip(sims, before, strict=True):  # this attempt's warnings are not the run's
            warnings = getattr(sim, "runtime_warnings", None)
            if isinstance(warnings, list):
                del warnings[start:]
        why.append(blown[0])
        law = soften(law)
    if not why:
        return checks, skips, calibration, ""
    if blown and sound:
        for sim in sims:
            warnings = getattr(sim, "runtime_warnings", None)
            if isinstance(warnings, list):
                warnings.clear()
        return [], skips, calibration, (
            f"layer 3b (replay) not graded: the reference engine cannot integrate the robot as the replay "
            f"strips it (no armature, joint damping, limits or contact), even with the law's bandwidth "
            f"halved {len(why)}× ({blown[0]}); MuJoCo's layer 3a found the written file's mass matrix and "
            "bias equal to the source's, so this is the source's dynamics, not the conversion (layers 1-3a "
            "graded the data)")
    return checks, skips, calibration, (
        f"layer 3b's law softened {len(why)}× (bandwidth halved each time, damping ratio kept): at the "
        f"higher bandwidth the reference engine could not integrate it ({why[0]}); the comparison above "
        f"is at {0.5 ** len(why):g}× the bandwidth")


def _diagonalised(loaded: list[Any], maps: dict[str, Renames]) -> dict[str, Any]:
    """PyBullet's diagonalised link inertias (``PyBulletModel.diagonalised_inertials``), by the MJCF's
    body names; empty when PyBullet is not loaded."""
    engine = next((e.model for e in loaded if e.label == "pybullet"), None)
    held = getattr(engine, "diagonalised_inertials", None)
    if held is None:
        return {}
    source_of = {written: source for source, written in maps.get("urdf", {}).get("link", {}).items()}
    mjcf = maps["mjcf"].get("link", {})
    out = {}
    for written, value in held().items():
        source = source_of.get(written, written)
        out[mjcf.get(source, source)] = value
    return out


def _welded_to_root(robot: Robot) -> set[str]:
    """The root link and the links fixed to it (with the base welded they never move)."""
    out = {str(robot.root)}
    grew = True
    while grew:
        grew = False
        for j in robot.joints:
            if j.type is JointType.FIXED and j.parent in out and j.child not in out:
                out.add(j.child)
                grew = True
    return out


def engine_warnings(report: VerifyReport, label: str, messages: list[str], key: str, during: str
                    ) -> list[Check]:
    """An engine's collected warnings (MuJoCo's, never written to ``MUJOCO_LOG.TXT``) go into its
    settings in the report under ``key``; those saying the simulation went unstable are a failed
    ``stability`` check (the numbers of that run are not to be trusted)."""
    if not messages:
        return []
    from modelkit.verify.engines.mujoco import unstable

    unique = list(dict.fromkeys(messages))
    report.engines.setdefault(label, {})[key] = unique
    bad = unstable(unique)
    if not bad:
        return []
    layer = 3 if key == "replay_warnings" else 1
    return [Check(layer, label, "stability", "", float(len(bad)), 0.0,
                  f"{label} warned during {during} that the simulation is unstable: " + "; ".join(bad[:3]))]
