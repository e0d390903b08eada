"""Mesh and texture references in XML formats (URDF, SDF): resolve the URI and check the file, with
diagnostics.

The `.body` reader has its own variant (Choreonoid's resource nodes carry fragments and metadata);
this one serves formats whose meshes are plain ``uri`` + ``scale``.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from modelkit import rot3
from modelkit.diagnostics import Diagnostic, DiagnosticSink, Severity, SourceLocation
from modelkit.model import Mesh
from modelkit.resources import Resolution, Resolver, found_report, in_folder_or_above
from modelkit.textio import UnreadableFile, check_regular

# what modelkit.geometry.meshfiles.load_mesh reads (its SUPPORTED_EXTENSIONS; a test keeps them equal,
# this module does not import that one's numpy and parsers)
MESH_FILE_EXTENSIONS = frozenset({".stl", ".obj", ".dae", ".wrl", ".glb", ".gltf", ".ply"})
# A mesh file that is missing, names an unknown package, or cannot be loaded.
MESH_PROBLEM_CODES = frozenset({"MK500", "MK501", "MK502", "MK504", "MK506"})
COLLISION_MARK = " (a collision mesh: "
VISUAL_ONLY = " (visual only)"
# A mesh found only by PyBullet's walk up the folders (:meth:`MeshChecker.found_above`): PyBullet loads
# the file, MuJoCo's URDF import does not find the collision mesh.
FOUND_ABOVE = "PyBullet looks in the folders above the model's and reads "
COLLISION_FOUND_ABOVE = "; MuJoCo, Gazebo and ROS tools do not look there, so MuJoCo refuses the file"
VISUAL_FOUND_ABOVE = "; MuJoCo, Gazebo and ROS tools do not look there (a visual mesh)"


def collision_mesh_problem(d: Diagnostic) -> bool:
    """A problem with a collision mesh of a format whose own loader never opens meshes (URDF and its
    xacro: check_urdf; SDF: libsdformat). The loader accepts the file, so ``validate`` warns; MuJoCo
    and PyBullet refuse it, so it is an error for ``--target mjcf`` and ``--target pybullet``, and
    ``convert`` exits 1 (the written robot has no collision there)."""
    return d.code in MESH_PROBLEM_CODES and COLLISION_MARK in d.message


def found_above_refused_by_mujoco(d: Diagnostic) -> bool:
    """A collision mesh that only PyBullet's folder walk finds: MuJoCo's URDF import refuses the file."""
    return d.code == "MK500" and FOUND_ABOVE in d.message and COLLISION_FOUND_ABOVE in d.message


def _symlink_loop(path: Path) -> bool:
    try:
        os.stat(path)
    except OSError as exc:
        return exc.errno == errno.ELOOP
    return False


def not_found(uri: str, path: Path | str, usage: str = "") -> str:
    """The MK500 message for a resource file that does not exist."""
    return f'resource "{uri}" not found at {path}{usage}'


@dataclass
class MeshChecker:
    """Resolves mesh and texture URIs for one model file and loads each mesh file at most once.

    ``resolve`` replaces the resolver's look-up (relative to ``base_dir``) for a format with
    conventions of its own: it gets the URI and where it is written, and may report there.
    """

    resolver: Resolver
    base_dir: Path
    model_file: Path | None
    sink: DiagnosticSink
    check_resources: bool = True
    resolve: Callable[[str, SourceLocation], Resolution] | None = None
    # The simulator that fetches http(s) meshes as it loads the file (SDF: Gazebo, from Gazebo Fuel):
    # there such a mesh is an info (MK503); elsewhere a warning naming the consumers that cannot fetch it.
    web_fetched_by: str | None = None
    # The format's own loader, when it never opens meshes (URDF: check_urdf; SDF: libsdformat): a
    # collision mesh's problem is then a warning (:func:`collision_mesh_problem`), not an error.
    unopened_by: str | None = None
    _loaded: dict[str, str | None] = field(default_factory=dict)
    _textures: set[str] = field(default_factory=set)

    def resolution(self, uri: str, loc: SourceLocation) -> Resolution:
        """Where ``uri`` points."""
        if self.resolve is not None:
            return self.resolve(uri, loc)
        return self.resolver.resolve(uri, self.base_dir, self.model_file)

    def texture(self, uri: str, loc: SourceLocation) -> None:
        """Report a texture file that cannot be found (MK507), once per URI."""
        if not self.check_resources or uri in self._textures:
            return
        self._textures.add(uri)
        resolution = self.resolution(uri, loc)
        path = resolution.path
        if path is not None and _symlink_loop(path):
            self.sink.emit("MK001", f'texture "{uri}": cannot read file: a symlink loop', loc)
            return
        if path is None or not os.path.exists(path):
            why = resolution.message or f"not found at {path}"
            self.sink.emit("MK507", f'texture "{uri}" cannot be found ({why})', loc, hint=resolution.hint)
            return
        try:  # modelkit does not decode images; it refuses only what no loader could read
            check_regular(path)
        except UnreadableFile as exc:
            self.sink.emit(exc.code, f'texture "{uri}": {exc.message}', loc, hint=exc.hint)

    def mesh(
        self,
        uri: str,
        loc: SourceLocation,
        scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
        visual_only: bool = False,
        submesh: str | None = None,
    ) -> Mesh:
        """A :class:`Mesh` for ``uri``; unresolvable or unloadable files are reported at ``loc``.

        A problem with a mesh used only for display is a warning; for collision it is an error, or a
        warning that says who refuses the file where the format's own loader never opens meshes
        (:attr:`unopened_by`).
        """
        resolution = self.resolution(uri, loc)
        severity = Severity.WARNING if visual_only else None
        usage = VISUAL_ONLY if visual_only else ""
        if not visual_only and self.unopened_by:
            severity = Severity.WARNING
            usage = (f"{COLLISION_MARK}{self.unopened_by} never opens meshes and accepts the file; MuJoCo "
                     "and PyBullet refuse it)")
        path = resolution.path
        above = self.found_above(uri, resolution)
        if above is not None:
            relative = self._relative(above)
            self.sink.emit(
                "MK500",
                f'resource "{uri}" not found at {path}; {FOUND_ABOVE}"{relative}", as modelkit does'
                + (VISUAL_FOUND_ABOVE if visual_only else COLLISION_FOUND_ABOVE),
                loc,
                hint=f'write the path relative to the model file: "{relative}"',
                severity=Severity.WARNING,
            )
            path = above
        if resolution.scheme in ("http", "https"):
            self._web_mesh(uri, loc)
        elif resolution.code is not None:
            known = resolution.code in MESH_PROBLEM_CODES or visual_only
            self.sink.emit(
                resolution.code,
                (resolution.message or uri) + (usage if known else ""),
                loc,
                hint=resolution.hint,
                severity=severity if known else None,
            )
        elif path is not None:
            report = found_report(resolution, uri)
            if report is not None:
                code, message, hint, warning = report
                self.sink.emit(code, message, loc, hint=hint, severity=Severity.WARNING if warning else None)
            suffix = path.suffix.lower()
            if not os.path.exists(path):
                self.sink.emit("MK500", not_found(uri, path, usage), loc, severity=severity)
            elif suffix not in MESH_FILE_EXTENSIONS:
                self.sink.emit(
                    "MK506",
                    f'resource "{uri}": {suffix or "no extension"} files are not supported '
                    f"(supported: {' '.join(sorted(MESH_FILE_EXTENSIONS))}){usage}",
                    loc,
                    severity=severity,
                )
            elif self.check_resources:
                problem = self._load(path, submesh)
                if problem:
                    code, message = problem.split("\t", 1)
                    known = code in MESH_PROBLEM_CODES or visual_only
                    self.sink.emit(code, f'resource "{uri}": {message}{usage if known else ""}', loc,
                                   severity=severity if known else None)
        return Mesh(
            uri=uri,
            path=str(path) if path is not None else None,
            fragment=submesh,
            scale=rot3.vec3(scale),
        )

    def found_above(self, uri: str, resolution: Resolution) -> Path | None:
        """A plain relative path that is not beside the model, found as PyBullet finds it: the same path
        under the first folder above the model's that has it (``meshes/link0.stl`` of a URDF in
        ``robot/urdf/`` read from ``robot/meshes/link0.stl``; differentiable-robot-model's Panda and
        iiwa). None when the path is found, is absolute, has a scheme or there is no model file."""
        text = uri.strip()
        path = resolution.path
        if (resolution.code is not None or resolution.scheme or path is None or self.model_file is None
                or text.startswith("${") or Path(text).is_absolute() or os.path.exists(path)):
            return None
        folder = Path(os.path.realpath(self.model_file.parent))
        return in_folder_or_above(folder.parent, text) if folder.parent != folder else None

    def _relative(self, path: Path) -> str:
        folder = self.model_file.parent if self.model_file is not None else self.base_dir
        return Path(os.path.relpath(path, os.path.realpath(folder))).as_posix()

    def _web_mesh(self, uri: str, loc: SourceLocation) -> None:
        """MK503 for a mesh on a web server: the format's loader never opens meshes, so it accepts it."""
        if self.web_fetched_by:
            self.sink.emit(
                "MK503",
                f'mesh "{uri}" is on a web server: {self.web_fetched_by} downloads it when it loads the '
                "model (Gazebo Fuel); modelkit does not fetch it, so it is not checked",
                loc,
                severity=Severity.INFO,
            )
            return
        self.sink.emit(
            "MK503",
            f'mesh "{uri}" is on a web server: check_urdf accepts it (it never opens meshes) and Gazebo '
            "fetches it, but PyBullet and MuJoCo read meshes only from disk; modelkit does not fetch it, so "
            "it is not checked",
            loc,
            hint="for PyBullet or MuJoCo, download the mesh and refer to the local file",
            severity=Severity.WARNING,
        )

    def _load(self, path: Path, fragment: str | None) -> str | None:
        key = f"{path}\t{fragment or ''}"
        if key not in self._loaded:
            from modelkit.geometry import meshfiles

            self._loaded[key] = meshfiles.mesh_problem(path, fragment)
        return self._loaded[key]
