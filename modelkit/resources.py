"""One resolver for the URIs that model files use to name meshes, textures and other files.

Search order for ``package://NAME/REL`` (see docs/resources.md):

1. ``--package-path NAME=DIR`` given by the user;
2. each entry E of ``ROS_PACKAGE_PATH``: ``E/NAME/REL`` (and ``E/REL`` when E is the package itself);
3. each entry E of ``AMENT_PREFIX_PATH``: ``E/share/NAME/REL``;
4. walking up from the model file: the first folder whose ``package.xml`` names NAME, or which holds
   ``NAME/package.xml``;
5. when none of those finds the package: ``NAME/REL`` (or a bare ``package://FILE``) beside the model
   file, as PyBullet looks, or in the first folder above it that has it (a package folder copied
   without its ``package.xml``, as in robosuite's assets). That is reported (a warning, MK504): ROS
   tools and Gazebo will not find it.

``model://NAME/REL`` looks in the ``--resource-path`` folders, then ``GZ_SIM_RESOURCE_PATH``,
``IGN_GAZEBO_RESOURCE_PATH``, ``SDF_PATH`` and ``GAZEBO_MODEL_PATH`` (:data:`MODEL_PATH_VARIABLES`); an SDF
``<include>`` looks a bare name or a relative path up there too when it is not beside the file.
Files are looked up with ``os.path.exists``/``isfile``/``isdir``, which return False where ``Path``'s
raise (a name the file system cannot look up, ENAMETOOLONG); the readers do the same.
``file://`` and plain paths are relative to the referring file's folder. An absolute path that does not
exist, but does under the model's folder, is read there, as PyBullet reads it (a warning, MK500). A plain
relative mesh path of a URDF or SDF file that is not beside the model is looked up in the folders above
it, as PyBullet looks (:func:`in_folder_or_above`, used by :mod:`modelkit.formats.meshref`; MK500).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from modelkit.textio import read_head

_SCHEME_RE = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]*)://(.+)$")
_PACKAGE_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_VARIABLE_RE = re.compile(r"^\$\{([A-Za-z_][A-Za-z0-9_]*)\}")
# Where SDF model folders are looked up, in this order (Gazebo's, then libsdformat's, then Gazebo
# classic's variable), after the folders given with ``--resource-path``.
MODEL_PATH_VARIABLES = ("GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "SDF_PATH", "GAZEBO_MODEL_PATH")


@dataclass(frozen=True)
class Resolution:
    """Where a URI points. ``path`` is None when it cannot be resolved; then ``code`` and
    ``message`` say why (``path`` may also be set for a file that does not exist: check it). A file
    found only by PyBullet's rules (a ``package://`` URI beside the model, an absolute path that exists
    only under the model's folder) has a ``path``, no ``code``, and the warning to give in
    ``fallback_code`` and ``message`` (see :func:`found_report`)."""

    uri: str
    path: Path | None
    scheme: str
    code: str | None = None
    message: str | None = None
    hint: str | None = None
    fallback_code: str | None = None


@dataclass
class Resolver:
    package_paths: dict[str, Path] = field(default_factory=dict)
    path_variables: dict[str, Path] = field(default_factory=dict)
    environ: Mapping[str, str] = field(default_factory=lambda: dict(os.environ))
    resource_paths: list[Path] = field(default_factory=list)
    _package_cache: dict[tuple[str, str], Path | None] = field(default_factory=dict)

    def resolve(self, uri: str, base_dir: Path, model_file: Path | None = None) -> Resolution:
        text = uri.strip()
        variable = _VARIABLE_RE.match(text)
        if variable:
            name = variable.group(1)
            root = self.path_variables.get(name)
            if root is None and name == "HOME" and "HOME" in self.environ:
                root = Path(self.environ["HOME"])
            if root is None:
                return Resolution(
                    uri,
                    None,
                    "variable",
                    "MK505",
                    f'path variable "${{{name}}}" in "{uri}" is not defined',
                    hint=f"define it with --path-variable {name}=DIR",
                )
            text = str(root) + text[variable.end() :]
        match = _SCHEME_RE.match(text)
        if match is None:
            path = Path(text)
            if path.is_absolute():
                return _absolute(uri, path, base_dir)
            return Resolution(uri, _normal(base_dir / path), "")
        scheme, rest = match.group(1).lower(), match.group(2)
        if scheme == "file":
            path = Path(rest)
            return Resolution(uri, _normal(path if path.is_absolute() else base_dir / path), "file")
        if scheme == "package":
            return self._resolve_package(uri, rest, model_file or base_dir / "_")
        if scheme == "model":
            return self._resolve_model(uri, rest)
        return Resolution(
            uri, None, scheme, "MK503", f'the "{scheme}" scheme in URI "{uri}" is not supported'
        )

    def _resolve_package(self, uri: str, rest: str, model_file: Path) -> Resolution:
        package, _, relative = rest.partition("/")
        root = self.find_package(package, model_file.parent)
        # PyBullet strips the scheme and looks the rest up beside the file: ``package://wheel.obj`` too.
        beside = in_folder_or_above(model_file.parent, rest) if root is None else None
        if beside is not None:
            if relative:
                what = f'package "{package}" of "{uri}" cannot be found on the package paths'
                hint = (f"give the package's folder with --package-path {package}=DIR, or add a package.xml "
                        f'naming "{package}"')
            else:  # package://FILE: a file name where a package belongs
                what = f'"{uri}" names no package, only a file'
                hint = f'write the file\'s path relative to the model ("{rest}"), or package://PACKAGE/{rest}'
            return Resolution(
                uri,
                beside,
                "package",
                fallback_code="MK504",
                message=f'{what}; "{rest}" is read from the model\'s folder or one above it ({beside}), as '
                "PyBullet reads it, but ROS tools (RViz, robot_state_publisher) and Gazebo will not find it",
                hint=hint,
            )
        if root is None:
            return Resolution(
                uri,
                None,
                "package",
                "MK504",
                f'package "{package}" of "{uri}" cannot be found',
                hint=f"give its folder with --package-path {package}=DIR, or set ROS_PACKAGE_PATH",
            )
        return Resolution(uri, _normal(root / relative), "package")

    def find_package(self, package: str, start: Path) -> Path | None:
        key = (package, str(start))
        if key in self._package_cache:
            return self._package_cache[key]
        found = self._search_package(package, start)
        self._package_cache[key] = found
        return found

    def _search_package(self, package: str, start: Path) -> Path | None:
        if package in self.package_paths:
            return self.package_paths[package]
        # os.path.isdir, not Path.is_dir: False for a package name too long to look up (ENAMETOOLONG)
        for entry in _split_paths(self.environ.get("ROS_PACKAGE_PATH", "")):
            if os.path.isdir(entry / package):
                return entry / package
            if entry.name == package and os.path.isdir(entry):
                return entry
        for entry in _split_paths(self.environ.get("AMENT_PREFIX_PATH", "")):
            if os.path.isdir(entry / "share" / package):
                return entry / "share" / package
        folder = Path(os.path.realpath(start))  # never raises on a symlink loop
        for candidate in (folder, *folder.parents):
            if _package_name(candidate / "package.xml") == package:
                return candidate
            if _package_name(candidate / package / "package.xml") == package:
                return candidate / package
        return None

    def model_path(self) -> list[Path]:
        """The folders holding SDF model folders: ``--resource-path``, then :data:`MODEL_PATH_VARIABLES`."""
        folders = list(self.resource_paths)
        for var in MODEL_PATH_VARIABLES:
            folders.extend(_split_paths(self.environ.get(var, "")))
        return folders

    def find_on_model_path(self, relative: str) -> Path | None:
        """``relative`` (a model name, maybe with a path inside the model) under the first model folder
        that has it, or None."""
        if not relative or Path(relative).is_absolute():
            return None
        for entry in self.model_path():
            candidate = entry / relative
            if os.path.exists(candidate):
                return _normal(candidate)
        return None

    def _resolve_model(self, uri: str, rest: str) -> Resolution:
        found = self.find_on_model_path(rest)
        if found is not None:
            return Resolution(uri, found, "model")
        model = rest.partition("/")[0]
        return Resolution(
            uri,
            None,
            "model",
            "MK504",
            f'model "{model}" of "{uri}" cannot be found',
            hint="add its parent folder to GZ_SIM_RESOURCE_PATH or give it with --resource-path",
        )


def found_report(resolution: Resolution, uri: str) -> tuple[str, str, str | None, bool] | None:
    """What to say of a resolved URI, if anything: (code, message, hint, is a warning). A file found only
    by PyBullet's rules is a warning (MK504, MK500); one found on the package search path an info (MK510)."""
    if resolution.fallback_code and resolution.message:
        return resolution.fallback_code, resolution.message, resolution.hint, True
    if resolution.scheme == "package":
        return "MK510", f'"{uri}" depends on the package search path; found at {resolution.path}', None, False
    return None


def _absolute(uri: str, path: Path, base_dir: Path) -> Resolution:
    """An absolute path; when it does not exist but the same path under the model's folder does, that
    file, as PyBullet reads it (``/meshes/link_0.stl`` in pybullet's KUKA SDF files)."""
    written = _normal(path)
    if not os.path.exists(written):
        beside = _normal(base_dir / str(path).lstrip("/\\"))
        if os.path.isfile(beside):
            return Resolution(
                uri,
                beside,
                "",
                fallback_code="MK500",
                message=f'"{uri}" is an absolute path that does not exist; the file is read from the '
                f"model's folder ({beside}), as PyBullet reads it, but Gazebo and other tools will not "
                "find it",
                hint="write the path relative to the model file",
            )
    return Resolution(uri, written, "")


def in_folder_or_above(folder: Path, relative: str) -> Path | None:
    """``relative`` in ``folder`` or the first folder above it that has the file, or None: how PyBullet
    looks up a mesh it does not find beside the model (``package://NAME/REL`` with the scheme dropped, or
    a plain relative path), from the model's folder up to the file system's root."""
    start = Path(os.path.realpath(folder))  # never raises on a symlink loop
    for candidate in (start, *start.parents):
        path = _normal(candidate / relative)
        if os.path.isfile(path):
            return path
    return None


def _split_paths(value: str) -> list[Path]:
    return [Path(p) for p in value.split(os.pathsep) if p]


def _normal(path: Path) -> Path:
    return Path(os.path.normpath(path))


def _package_name(package_xml: Path) -> str | None:
    data = read_head(package_xml, 65536)
    if data is None:
        return None
    head = data.decode("utf-8", errors="replace")
    match = _PACKAGE_NAME_RE.search(head)
    return match.group(1) if match else None
