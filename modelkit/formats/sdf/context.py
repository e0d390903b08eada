"""What the SDF reader shares while it reads one file and the files it includes.

* URI resolution with one SDF convenience: ``model://NAME/...`` that the resource path
  (``GZ_SIM_RESOURCE_PATH``, ``IGN_GAZEBO_RESOURCE_PATH``, ``SDF_PATH``) does not resolve is looked
  up beside the referring file's own model folders (a folder holding ``NAME/`` among the file's
  ancestors), and reported as info (MK532) because it depends on the layout;
* ``<include>`` targets: a directory is a model folder whose ``model.config`` names the SDF file;
  each file is parsed and checked once, however often it is included;
* mesh and texture checking through :class:`~modelkit.formats.meshref.MeshChecker`, with the
  ``model://`` look-up above.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from modelkit.diagnostics import Diagnostic, DiagnosticSink, Severity, SourceLocation
from modelkit.formats.common import ReadOptions
from modelkit.formats.meshref import MeshChecker
from modelkit.formats.sdf.document import MAX_VERSION, SdfDocument, load_document, parse_version
from modelkit.formats.sdf.spec import check_elements
from modelkit.model import Mesh
from modelkit.resources import Resolution
from modelkit.xmlsource import read_xml


@dataclass
class Context:
    options: ReadOptions
    sink: DiagnosticSink
    _meshes: dict[str, MeshChecker] = field(default_factory=dict)
    _documents: dict[str, SdfDocument | None] = field(default_factory=dict)
    # Values libsdformat cannot parse (MK121), found by the element catalogue; the reader adds those at
    # places it has not reported itself (see :meth:`value_faults`).
    _value_faults: list[Diagnostic] = field(default_factory=list)

    # -- documents ---------------------------------------------------------------------------

    def document(self, path: Path, display: str | None = None) -> SdfDocument | None:
        """Load (once) and check an SDF file."""
        key = os.path.normpath(os.path.abspath(path))
        if key not in self._documents:
            src = load_document(
                path, display or os.path.normpath(str(path)), self.sink, self.options.max_bytes
            )
            if src is not None:
                check_elements(src.doc, self.sink, src.version, self._value_faults)
            self._documents[key] = src
        return self._documents[key]

    def add_value_faults(self) -> None:
        """Report the catalogue's value faults, except where the reader already reported the value."""
        reported = {d.location for d in self.sink.items if d.code == "MK121"}
        self.sink.extend(d for d in self._value_faults if d.location not in reported)

    # -- URIs ----------------------------------------------------------------------------------

    def resolve(self, uri: str, src: SdfDocument, loc: SourceLocation) -> Resolution:
        """Resolve ``uri`` as written in ``src``; unresolved ``model://`` URIs get the local look-up."""
        resolution = self.options.resolver.resolve(uri, src.base_dir, src.path)
        if resolution.scheme != "model" or resolution.path is not None:
            return resolution
        local = self._local_model(uri, src.path)
        if local is None:
            return resolution
        folder = local[1]
        self.sink.emit(
            "MK532",
            f'"{uri}" is not on the model resource path; found beside this model at {local[0]}',
            loc,
            hint=f"add {folder} to GZ_SIM_RESOURCE_PATH so that Gazebo finds it too",
        )
        return Resolution(uri, local[0], "model")

    @staticmethod
    def _local_model(uri: str, model_file: Path) -> tuple[Path, Path] | None:
        rest = uri.strip()[len("model://") :]
        name = rest.partition("/")[0]
        if not name:
            return None
        relative = model_file.is_absolute() is False
        for folder in Path(os.path.abspath(model_file)).parents:
            if os.path.isdir(folder / name):
                found = folder / rest
                if relative:
                    found = Path(os.path.relpath(found))
                    folder = Path(os.path.relpath(folder))
                return Path(os.path.normpath(found)), folder
        return None

    def mesh(
        self,
        uri: str,
        src: SdfDocument,
        loc: SourceLocation,
        scale: tuple[float, float, float],
        visual_only: bool,
        submesh: str | None,
    ) -> Mesh:
        return self._files(src).mesh(uri, loc, scale, visual_only=visual_only, submesh=submesh)

    def texture(self, uri: str, src: SdfDocument, loc: SourceLocation) -> None:
        """Report a texture file written in ``src`` that cannot be found (MK507, once per URI)."""
        self._files(src).texture(uri, loc)

    def _files(self, src: SdfDocument) -> MeshChecker:
        """The mesh and texture checker of one file (each mesh file is loaded once per file)."""
        key = str(src.path)
        checker = self._meshes.get(key)
        if checker is None:
            checker = MeshChecker(
                self.options.resolver,
                src.base_dir,
                src.path,
                self.sink,
                self.options.check_resources,
                resolve=lambda uri, loc: self._file_resolution(uri, src, loc),
                web_fetched_by="Gazebo",
                unopened_by="libsdformat",
            )
            self._meshes[key] = checker
        return checker

    def _file_resolution(self, uri: str, src: SdfDocument, loc: SourceLocation) -> Resolution:
        """Where a mesh or texture URI of ``src`` points; a ``model://`` one as an absolute path."""
        if not uri.strip().lower().startswith("model://"):
            return self.options.resolver.resolve(uri, src.base_dir, src.path)
        resolution = self.resolve(uri, src, loc)
        if resolution.path is None:
            return resolution
        return replace(resolution, path=Path(os.path.abspath(resolution.path)))

    # -- includes ------------------------------------------------------------------------------

    def include_file(self, uri: str, src: SdfDocument, loc: SourceLocation) -> Path | None:
        """The SDF file an ``<include><uri>`` names; faults are reported at ``loc``."""
        resolution = self.resolve(uri, src, loc)
        if resolution.scheme in ("http", "https"):
            self.sink.emit(
                "MK503",
                f'included model "{uri.strip()}" is on a web server (Gazebo Fuel): Gazebo downloads it '
                "when it loads the world; modelkit does not fetch it, so it is not checked",
                loc,
                severity=Severity.INFO,
            )
            return None
        if resolution.code is not None or resolution.path is None:
            self.sink.emit(
                resolution.code or "MK504",
                resolution.message or f'cannot resolve "{uri}"',
                loc,
                hint=resolution.hint,
            )
            return None
        path = resolution.path
        if not os.path.exists(path) and resolution.scheme in ("", "file"):
            # libsdformat's findFile: a bare name or relative path not beside the file is looked up on
            # the model path (SDF_PATH, GZ_SIM_RESOURCE_PATH, ...), as Gazebo does.
            text = uri.strip()
            relative = text[len("file://") :] if text.lower().startswith("file://") else text
            path = self.options.resolver.find_on_model_path(relative.rstrip("/")) or path
        if not os.path.exists(path):
            self.sink.emit(
                "MK500",
                f'included model "{uri.strip()}" not found at {path} nor on the model path',
                loc,
                hint="give the folder that holds its model folder with --resource-path DIR, or add it to "
                "SDF_PATH / GZ_SIM_RESOURCE_PATH",
            )
            return None
        if os.path.isdir(path):
            return self._model_folder(uri, path, loc)
        return path

    def _model_folder(self, uri: str, folder: Path, loc: SourceLocation) -> Path | None:
        config = folder / "model.config"
        if not os.path.isfile(config) and os.path.isfile(folder / "manifest.xml"):
            config = folder / "manifest.xml"  # the older name, which libsdformat still reads
        if not os.path.isfile(config):
            fallback = folder / "model.sdf"
            if os.path.isfile(fallback):
                # libsdformat 12 refuses the include ("Unable to resolve uri[...] to model path [...] since
                # it does not contain a model.config file"); the model is still read to check it
                self.sink.emit(
                    "MK535",
                    f'included model "{uri.strip()}": {folder} has no model.config, so libsdformat cannot '
                    "resolve the include and refuses the file; modelkit reads its model.sdf to check it",
                    loc,
                    hint="add a model.config naming it: <model><sdf version=...>model.sdf</sdf></model>",
                )
                return fallback
            self.sink.emit(
                "MK530",
                f'included model "{uri}": {folder} has no model.config (and no model.sdf)',
                loc,
            )
            return None
        scratch = DiagnosticSink()
        doc = read_xml(config, scratch, self.options.max_bytes)
        if doc is None:
            self.sink.emit("MK530", f'included model "{uri}": {config} cannot be read', loc)
            return None
        choices: list[tuple[tuple[int, int] | None, str]] = []
        for el in doc.root.iter("sdf"):
            name = (el.text or "").strip()
            if name:
                choices.append((parse_version(el.get("version")), name))
        if not choices:
            self.sink.emit("MK530", f'included model "{uri}": {config} names no <sdf> file', loc)
            return None
        usable = [c for c in choices if c[0] is not None and c[0] <= MAX_VERSION]
        version_name = max(usable, key=lambda c: c[0] or (0, 0))[1] if usable else choices[0][1]
        target = folder / version_name
        if not os.path.isfile(target):
            self.sink.emit(
                "MK530",
                f'included model "{uri}": {config} names "{version_name}", which does not exist',
                loc,
            )
            return None
        return target
