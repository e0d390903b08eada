"""The MJCF reader: MuJoCo parses and compiles the file, modelkit maps the result to its model.

Steps:

1. modelkit parses the file itself (:mod:`modelkit.xmlsource`): malformed XML (MK020) and entity
   declarations (MK021) are refused before MuJoCo sees the file, and every element gets a line
   and column;
2. MuJoCo parses it: through its C library directly (:mod:`.native`, no numpy, no bindings) when
   that can be used, else ``mujoco.MjSpec.from_file`` (schema errors → MK170 at MuJoCo's line);
3. the spec is compiled with static-body fusion and visual discarding switched off, so every body
   and geom survives; the compiled ``MjModel`` is read (:mod:`.compiled`);
4. if compilation fails (a missing mesh, a bad inertia...), the error is reported (MK170) and the
   tree is read from the uncompiled spec instead (:mod:`.uncompiled`, MK174);
5. the bodies become robots (:mod:`.build`), paired with their XML elements for source
   locations (:mod:`.source`).

``mujoco`` is imported here only, when an MJCF file is read and the C library cannot be used directly
or the file does not compile.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation, sorted_diagnostics
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.meshref import not_found
from modelkit.formats.mjcf.actuators import OnJoint, read_actuators, tendon_actuators
from modelkit.formats.mjcf.bodies import MjBody, MjGeom
from modelkit.formats.mjcf.build import Built, RobotBuilder, apply_joint_equalities, quoted
from modelkit.formats.mjcf.compiled import CompiledModel, mesh_path
from modelkit.formats.mjcf.devices import add_devices
from modelkit.formats.mjcf.errors import error_location, error_text
from modelkit.formats.mjcf.files import check_asset_files, check_sizes
from modelkit.formats.mjcf.options import source_globals, source_options
from modelkit.formats.mjcf.quiet import collected_warnings
from modelkit.formats.mjcf.source import SourceIndex, TreeShape, locate, pair
from modelkit.formats.mjcf.transmissions import transmission_sites
from modelkit.formats.mjcf.uncompiled import SpecReader
from modelkit.model import Actuator, ActuatorKind, Joint, Robot
from modelkit.xmlsource import read_xml

MUJOCO_DEFAULT_NAME = "MuJoCo Model"


def read_mjcf(path: Path, options: ReadOptions, display: str, compiled: bool = True) -> ReadResult:
    """Read an MJCF file through MuJoCo into robots (one per top-level body tree).

    ``compiled=False`` skips compilation and reads the uncompiled spec, as the fallback after a
    compile error does (the tests compare the two).
    """
    sink = DiagnosticSink()
    robots = _MjcfReader(path, options, display, sink).read(compiled)
    main = robots[0] if robots else None
    return ReadResult(main, sorted_diagnostics(sink.items), robots[1:])


def _import_mujoco() -> Any:
    import mujoco

    return mujoco


class _MjcfReader:
    def __init__(self, path: Path, options: ReadOptions, display: str, sink: DiagnosticSink) -> None:
        # MuJoCo is given the absolute path: from a relative one with folders
        # (``a/b/robot.xml``) it opens an included file's ``../meshes/x.stl`` in the wrong folder
        # (genesis-world's franka_sim: "Error opening file"), which from any absolute path it finds
        self.path = Path(path).absolute()
        self.options = options
        self.display = display
        self.sink = sink

    def read(self, compiled: bool = True) -> list[Robot]:
        doc = read_xml(self.path, self.sink, self.options.max_bytes, self.display)
        if doc is None:
            return []
        if doc.root.tag != "mujoco":
            self.sink.emit("MK022", f"the top element is <{doc.root.tag}>, not <mujoco>", doc.loc(doc.root))
            return []
        index = SourceIndex(doc, self.path.parent, self.sink, self.options.max_bytes)
        list(index.iter_all())  # reads the included files: their XML problems stop here too
        if any(d.code in ("MK001", "MK020", "MK021", "MK002", "MK003") and d.severity is Severity.ERROR
               for d in self.sink.items):  # not MK020's warnings: TinyXML2 (MuJoCo) reads those files
            return []
        if not check_asset_files(index, self.path.parent, self.sink, self.options.max_bytes):
            return []
        if not check_sizes(index, self.sink, self.options.max_links):
            return []
        if compiled and not _uses_plugins(index):
            robots = self._through_native(index)
            if robots is not None:
                return robots
        try:
            mujoco = _import_mujoco()
        except ImportError as exc:  # pragma: no cover - mujoco is a dependency
            self.sink.emit("MK170", f"cannot read MJCF: mujoco is not installed ({exc})", doc.loc(doc.root))
            return []
        with collected_warnings(mujoco) as warnings:  # never MUJOCO_LOG.TXT in the working directory
            robots = self._through_mujoco(mujoco, index, compiled)
        self._report_warnings(warnings, index)
        return robots

    def _report_warnings(self, messages: list[str], index: SourceIndex) -> None:
        """MuJoCo's warnings (each once), whichever way MuJoCo was called."""
        for message in dict.fromkeys(messages):
            self.sink.emit("MK177", f"MuJoCo warned: {message}", index.top().loc())

    def _through_native(self, index: SourceIndex) -> list[Robot] | None:
        """The compiled model through MuJoCo's C library (:mod:`.native`); ``None`` when the bindings
        must read it (they then report any parse or compile error themselves)."""
        from modelkit.formats.mjcf import native

        with native.compiled(self.path) as result:
            if result is None:
                return None
            try:
                name = self._model_name(index)
                return self._from_compiled(result.mj, result.model, result.spec, index, name)
            finally:
                self._report_warnings(result.warnings, index)

    def _through_mujoco(self, mujoco: Any, index: SourceIndex, compiled: bool) -> list[Robot]:
        spec = self._spec(mujoco, index)
        if spec is None:
            return []
        name = self._model_name(index)
        model = self._compile(spec, index) if compiled else None
        if model is not None:
            return self._from_compiled(mujoco, model, spec, index, name)
        return self._from_spec(mujoco, index, name)

    # -- MuJoCo ------------------------------------------------------------------------------

    def _spec(self, mujoco: Any, index: SourceIndex) -> Any:
        try:
            spec = mujoco.MjSpec.from_file(str(self.path))
        except Exception as exc:  # MuJoCo raises ValueError; nothing it raises may escape
            self._mujoco_error(exc, index)
            return None
        spec.compiler.fusestatic = False  # keep every body (and its name)
        spec.compiler.discardvisual = False  # keep visual-only geoms
        spec.compiler.alignfree = False  # keep free bodies' frames as written
        return spec

    def _compile(self, spec: Any, index: SourceIndex) -> Any:
        try:
            return spec.compile()
        except Exception as exc:
            self._mujoco_error(exc, index)
            return None

    def _mujoco_error(self, exc: BaseException, index: SourceIndex) -> None:
        text = error_text(exc)
        self.sink.emit("MK170", f"MuJoCo: {text}", error_location(str(exc), index))

    def _model_name(self, index: SourceIndex) -> str:
        root = index.main.root
        written = root.get("model")
        if written:
            return written
        self.sink.emit(
            "MK173",
            f'the model has no name (<mujoco model="...">); it is called "{self.path.stem}" '
            f'after the file (MuJoCo calls it "{MUJOCO_DEFAULT_NAME}")',
            index.main.loc(root),
        )
        return self.path.stem

    # -- the compiled model ---------------------------------------------------------------------

    def _from_compiled(
        self, mujoco: Any, model: Any, spec: Any, index: SourceIndex, name: str
    ) -> list[Robot]:
        reader = CompiledModel(mujoco, model, spec, self.path.parent)
        bodies = reader.bodies()
        world_geoms = reader.world_geoms()
        locator = locate(index, _shapes(bodies), [(g.index, g.name) for g in world_geoms])
        builder = RobotBuilder(bodies, locator, self.sink, name)
        built = builder.build()
        equalities = reader.equalities()
        where = self._item_locations(index, "equality", [e["name"] for e in equalities])
        refs = {j.index: j.ref for b in bodies for j in b.joints}
        m = reader.m
        on_joints = frozenset(int(m.actuator_trnid[a][0]) for a in range(int(m.nu))
                              if int(m.actuator_trntype[a]) == int(mujoco.mjtTrn.mjTRN_JOINT))
        apply_joint_equalities(equalities, built.joints, refs, self.sink, where, on_joints)
        _home_positions(reader.keyframes(), bodies, built.joints)
        tendons = reader.tendons()
        self._report_unsupported(equalities, tendons, index, where)
        data: dict[str, list[dict[str, Any]]] = {
            "mjcf_actuators": reader.actuators(),
            "mjcf_sensors": reader.sensors(),
            "mjcf_keyframes": reader.keyframes(),
            "mjcf_tendons": tendons,
            "mjcf_equalities": equalities,
            "mjcf_world_geoms": [self._world_geom(builder, g) for g in world_geoms],
            "mjcf_world_sites": builder.sites(reader.world_sites(), 0),
        }
        self._tag_actuators(index, data["mjcf_actuators"])
        self._canonical_actuators(reader, built, data["mjcf_actuators"], index)
        self._keep(reader, built, builder, bodies, data)
        if model.nflex:
            self.sink.emit(
                "MK172",
                f"{model.nflex} flex object(s) (deformable bodies): the model cannot hold them",
                index.top().loc(),
            )
        return built.robots

    def _item_locations(
        self, index: SourceIndex, section: str, names: list[str | None]
    ) -> dict[int, SourceLocation]:
        items = index.section_items(section)
        named = {p.el.get("name", ""): p for p in items if p.el.get("name")}
        paired = pair(names, items, named)
        return {i: p.loc() for i, p in enumerate(paired) if p is not None}

    def _report_unsupported(
        self,
        equalities: list[dict[str, Any]],
        tendons: list[dict[str, Any]],
        index: SourceIndex,
        eq_where: dict[int, SourceLocation],
    ) -> None:
        top = index.top().loc()
        for eq in equalities:
            if eq["type"] == "joint":
                continue
            objtype = "tendon" if eq["type"] == "tendon" else eq["objtype"]
            objects = {"body": "bodies", "xbody": "bodies"}.get(objtype, f"{objtype}s")
            what = f"{eq['type']} equality{quoted(eq['name'])} "
            if eq["obj2"] is None and objtype in ("tendon", "joint"):  # one object, held by a polynomial
                what += f'on {objtype} "{eq["obj1"]}"'
            else:
                what += f'between {objects} "{eq["obj1"]}" and "{eq["obj2"] or "world"}"'
            self.sink.emit(
                "MK172", f"{what}: the model cannot hold it (kept as data)", eq_where.get(eq["index"], top)
            )
        where = self._item_locations(index, "tendon", [t["name"] for t in tendons])
        for i, tendon in enumerate(tendons):
            self.sink.emit(
                "MK172",
                f"{tendon['kind']} tendon{quoted(tendon['name'])}: the model cannot hold tendons "
                "(kept as data; MJCF output writes it back)",
                where.get(i, top),
            )

    def _canonical_actuators(self, reader: CompiledModel, built: Built, kept: list[dict[str, Any]],
                             index: SourceIndex) -> None:
        """The actuators the model can hold, on the robot of their joint's body, in the file's order
        (:mod:`.actuators`); their entries kept as data say so (``canonical``, with the model joint), for
        the writers that write the others back or name them. An actuator on a fixed tendon whose joints
        follow one joint is also read as one on that joint (MK179; its entry says ``as_joint``): the MJCF
        writer writes the source's element back, the other targets the joint's actuator."""
        m = reader.m
        found: list[tuple[int, int, Actuator]] = []
        for a, j, actuator in read_actuators(reader.mj, m, built.joints):
            entry = kept[a] if a < len(kept) else {}
            if entry:
                entry["canonical"] = True
                entry["joint"] = actuator.joint
            actuator.source_kind = entry.get("element", actuator.source_kind)
            found.append((a, j, actuator))
        index_of = {joint.name: j for j, joint in built.joints.items()}
        where = self._item_locations(index, "actuator", [e.get("name") for e in kept])
        for on in tendon_actuators(reader.mj, m, built.joints):
            actuator = on.actuator
            if on.actuator_id < len(kept):
                kept[on.actuator_id]["as_joint"] = actuator.joint
            found.append((on.actuator_id, index_of[actuator.joint], actuator))
            self._said_on_joint(on, where.get(on.actuator_id, index.top().loc()))
        for _, j, actuator in sorted(found, key=lambda item: item[0]):
            robot = built.robot_of_body.get(int(m.jnt_bodyid[j]))
            if robot is not None:
                robot.actuators.append(actuator)

    def _said_on_joint(self, on: OnJoint, where: SourceLocation) -> None:
        """MK179: an actuator on a fixed tendon read as one on the joint the tendon's joints follow."""
        a = on.actuator
        name = f' "{a.name}"' if a.name else ""
        if a.kind is ActuatorKind.POSITION:
            what = f"a position servo (kp {a.kp or 0.0:.6g}, kv {a.kv or 0.0:.6g})"
        elif a.kind is ActuatorKind.VELOCITY:
            what = f"a velocity servo (kv {a.kv or 0.0:.6g})"
        else:
            what = f"an effort actuator of gear {a.gear:.6g}"
        control = ""
        if a.kind is not ActuatorKind.EFFORT and (on.scale != 1.0 or on.offset != 0.0):
            target = "target" if a.kind is ActuatorKind.POSITION else "target velocity"
            control = f"; its control u sets the joint's {target} {on.scale:.6g}·u"
            control += f" {'+' if on.offset >= 0 else '−'} {abs(on.offset):.6g}" if on.offset else ""
            if a.ctrl_range is not None:
                control += f" ({a.ctrl_range[0]:.6g} to {a.ctrl_range[1]:.6g})"
        self.sink.emit(
            "MK179",
            f'MJCF actuator{name} on fixed tendon "{on.tendon}" is read as {what} on joint {a.joint}, which '
            f"every joint of the tendon follows{control}: URDF, SDF and .body get that actuator, MJCF the "
            "source's",
            where,
        )

    def _tag_actuators(self, index: SourceIndex, actuators: list[dict[str, Any]]) -> None:
        """Add the written element (``motor``, ``position``...) to each actuator when it is known."""
        items = index.section_items("actuator")
        named = {p.el.get("name", ""): p for p in items if p.el.get("name")}
        for entry, placed in zip(actuators, pair([a["name"] for a in actuators], items, named), strict=True):
            if placed is not None:
                entry["element"] = placed.tag
                entry["source"] = str(placed.loc())

    @staticmethod
    def _world_geom(builder: RobotBuilder, geom: MjGeom) -> dict[str, Any]:
        return {
            "name": geom.name,
            "type": geom.kind,
            "size": [float(x) for x in geom.size],
            "xyz": [float(x) for x in geom.pose.translation_tuple],
            "rotation": [[float(x) for x in row] for row in geom.pose.rotation_tuple],
            "source": str(builder.loc.geom(geom.index)),
        }

    def _keep(
        self,
        reader: CompiledModel,
        built: Built,
        builder: RobotBuilder,
        bodies: list[MjBody],
        data: dict[str, list[dict[str, Any]]],
    ) -> None:
        """Store what the model does not hold as data on the robots, and say so once.

        Sites, cameras and lights go with the robot of their body (the world's with the main
        robot), in link frames; the rest goes on the main robot.
        """
        if built.robots:
            main = built.robots[0]
            for robot in built.robots:
                robot.extras.update(
                    {"mjcf_compiled": True, "mjcf_sites": [], "mjcf_cameras": [], "mjcf_lights": []}
                )
            used = _used_sites(data)
            for body in bodies:
                sites = builder.sites(body.sites, body.index)
                for site in sites:
                    if site["name"] in used:
                        site["used"] = True  # by a sensor, equality, actuator or tendon of the file
                built.robot_of_body[body.index].extras["mjcf_sites"].extend(sites)
            for body_id, kind, name, pose, params in reader.cameras_and_lights():
                robot = built.robot_of_body.get(body_id, main)
                robot.extras[f"mjcf_{kind}s"].append(builder.attached(body_id, name, pose, **params))
            add_devices(reader.mj, reader.m, builder, built)  # the same, as canonical devices on links
            main.extras.update(data)
            options = source_options(builder.loc.index)
            if options:
                main.extras["mjcf_option"] = options
            settings = source_globals(builder.loc.index)
            if settings:
                main.extras["mjcf_globals"] = settings
            pairs = [{"tag": p.tag, "attributes": {str(k): str(v) for k, v in p.el.attrib.items()}}
                     for p in builder.loc.index.section_items("contact") if p.tag in ("pair", "exclude")]
            if pairs:
                main.extras["mjcf_contact_pairs"] = pairs

        def attached(key: str) -> int:
            return sum(len(r.extras.get(key, [])) for r in built.robots)

        counts = {
            "actuator": len(data["mjcf_actuators"]),
            "sensor": len(data["mjcf_sensors"]),
            "site": attached("mjcf_sites") + len(data["mjcf_world_sites"]),
            "camera": attached("mjcf_cameras"),
            "light": attached("mjcf_lights"),
            "keyframe": len(data["mjcf_keyframes"]),
            "world geom": len(data["mjcf_world_geoms"]),
        }
        kept = [f"{n} {word}{'s' if n != 1 else ''}" for word, n in counts.items() if n]
        if kept:
            self.sink.emit(
                "MK175",
                f"{', '.join(kept)} kept as data in the robot's extras (not part of the model)",
                builder.loc.index.top().loc(),
            )

    # -- the fallback ---------------------------------------------------------------------------

    def _from_spec(self, mujoco: Any, index: SourceIndex, name: str) -> list[Robot]:
        """The tree from a fresh, uncompiled spec (a spec whose compilation failed keeps raising
        the compile error on every access)."""
        try:
            spec = mujoco.MjSpec.from_file(str(self.path))
            bodies = SpecReader(mujoco, spec).bodies()
        except Exception:  # already reported by the first attempt
            return []
        self._missing_meshes(spec, index)
        locator = locate(index, _shapes(bodies), [])
        built = RobotBuilder(bodies, locator, self.sink, name).build()
        for robot in built.robots:
            robot.extras["mjcf_compiled"] = False
            robot.masses_unknown = True
        self.sink.emit(
            "MK174",
            "the kinematic tree was read from the uncompiled model: links have no geometry and only "
            "explicitly written inertials; equalities, actuators and sensors are not read",
            index.top().loc(),
        )
        return built.robots

    def _missing_meshes(self, spec: Any, index: SourceIndex) -> None:
        """Point at each ``<mesh file>`` that does not exist (the usual reason compilation fails)."""
        assets = [p for p in index.section_items("asset") if p.tag == "mesh"]
        by_file = {p.el.get("file", ""): p for p in assets}
        for mesh in spec.meshes:
            written = str(mesh.file or "")
            if not written:
                continue
            path = mesh_path(self.path.parent, str(spec.meshdir or ""), written)
            if not os.path.exists(path):
                placed = by_file.get(written)
                loc = placed.loc("file") if placed is not None else index.top().loc()
                self.sink.emit("MK500", not_found(written, path), loc)


def _uses_plugins(index: SourceIndex) -> bool:
    """Whether the model names an engine plugin, which only the bindings load (see :mod:`.native`)."""
    return any(placed.tag in ("extension", "plugin") for placed in index.iter_all())


def _shapes(bodies: list[MjBody]) -> list[TreeShape]:
    return [
        TreeShape(
            b.index,
            b.name,
            b.parent,
            [(j.index, j.name) for j in b.joints],
            [(g.index, g.name) for g in b.geoms],
            [(s.index, s.name) for s in b.sites],
        )
        for b in bodies
    ]


def _home_positions(keyframes: list[dict[str, Any]], bodies: list[MjBody], joints: dict[int, Joint]) -> None:
    """A keyframe named ``home`` holds the initial joint positions (as modelkit's MJCF writer puts them)."""
    home = next((k for k in keyframes if k.get("name") == "home"), None)
    if home is None:
        return
    qpos = home["qpos"]
    for body in bodies:
        for mj in body.joints:
            joint = joints.get(mj.index)
            address = mj.qpos_address
            if joint is None or address is None or mj.kind not in ("hinge", "slide") or address >= len(qpos):
                continue
            joint.initial_position = float(qpos[address])


def _used_sites(data: dict[str, list[dict[str, Any]]]) -> set[str]:
    """Names of the sites a sensor, equality, actuator transmission or tendon of the file names."""
    used: set[str] = set()
    for sensor in data.get("mjcf_sensors", []):
        if sensor.get("objtype") == "site" and sensor.get("object"):
            used.add(str(sensor["object"]))
    for eq in data.get("mjcf_equalities", []):
        if eq.get("objtype") == "site":
            used.update(str(eq[key]) for key in ("obj1", "obj2") if eq.get(key))
    return used | transmission_sites(data.get("mjcf_actuators", []), data.get("mjcf_tendons", []))
