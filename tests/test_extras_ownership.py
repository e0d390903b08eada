"""``extras`` hold one format's own data: only that format's reader and writer name its keys.

A format's keys are ``<format>_...`` (``mjcf_sites``, ``sdf_world``...) and, for URDF, its extension
blocks (``gazebo``, ``transmissions``, ``ros2_control``, ``mujoco``). Anything outside
``modelkit/formats/<format>/`` that names one (a string constant of a prefixed key anywhere; an
unprefixed URDF key read from ``.extras``) must be listed in :data:`EXCEPTIONS` with its reason.
The test fails on a new use and on a stale entry, so the list can only shrink.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "modelkit"
PREFIXED = re.compile(r"^(mjcf|sdf|urdf|body)_[a-z0-9_]+$")
URDF_BLOCKS = frozenset({"gazebo", "transmissions", "ros2_control", "mujoco"})

EXCEPTIONS: dict[tuple[str, str], str] = {
    ("checks/topology.py", "sdf_version"):
        "MK211's verdict on a joint named like a link depends on the SDF file's version",
    ("convert/gazebo.py", "sdf_plugins"):
        "Gazebo plugins are the same XML in SDF and in URDF <gazebo> blocks: which Gazebo they are for",
    ("convert/drive_plugin.py", "sdf_plugins"):
        "a drive plugin the source names and the output keeps (an SDF model plugin) stands in for the "
        "writer's: no second one",
    ("convert/drive_plugin.py", "gazebo"):
        "the same for a URDF source's robot-level <gazebo> block (kept by the URDF writer, its plugins "
        "copied by the SDF writer)",
    ("formats/urdf/write_gazebo.py", "sdf_plugins"): "an SDF model's plugins are written as <gazebo> blocks",
    ("formats/urdf/writer.py", "sdf_plugins"): "the same: written, so no MK808 note",
    ("model.py", "sdf_world_joint"):
        "Robot.free_links_float: a model fixed without a world joint is a static SDF model, whose free links "
        "stay fixed (the .body writer and the inertia rule ask it)",
    ("formats/body/writer.py", "gazebo"): "URDF extension blocks are noted as not carried over",
    ("formats/body/writer.py", "transmissions"): "the same",
    ("formats/body/writer.py", "ros2_control"): "the same",
    ("formats/body/writer.py", "mujoco"): "the same",
    ("formats/sdf/writer.py", "gazebo"):
        "URDF <gazebo> blocks are written as libsdformat converts them (a link's, a joint's, the robot's: "
        "write_gazebo_tags), and what SDF cannot hold is noted",
    ("formats/sdf/writer.py", "transmissions"): "URDF transmissions are noted as not carried over",
    ("verify/engines/reference.py", "mjcf_sites"):
        "layer 1: a source's named frames are no extra link in an engine that lists them (Drake on SDF); "
        "MJCF sites stay out of verify's files (frame_sites=False)",
}


def _owner(key: str) -> str:
    return "urdf" if key in URDF_BLOCKS else key.split("_", 1)[0]


def _extras_keys(tree: ast.AST) -> set[str]:
    """Unprefixed URDF keys read from an ``extras`` dict: ``x.extras.get("k")``, ``x.extras["k"]``,
    ``"k" in x.extras``, and the strings of a module-level ``..._EXTRAS`` tuple or set."""
    found: set[str] = set()

    def is_extras(node: ast.AST) -> bool:
        return isinstance(node, ast.Attribute) and node.attr == "extras"

    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and is_extras(node.func.value):
            args = node.args[:1]
        elif isinstance(node, ast.Subscript) and is_extras(node.value):
            args = [node.slice]
        elif isinstance(node, ast.Compare) and any(is_extras(c) for c in node.comparators):
            args = [node.left]
        elif isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id.endswith("EXTRAS") for t in node.targets):
            args = [e for e in ast.walk(node.value) if isinstance(e, ast.Constant)]
        elif isinstance(node, ast.For) and isinstance(node.iter, ast.Tuple):
            args = [e for e in ast.walk(node.iter) if isinstance(e, ast.Constant)]
        else:
            continue
        found |= {a.value for a in args if isinstance(a, ast.Constant) and a.value in URDF_BLOCKS}
    return found


def uses() -> set[tuple[str, str]]:
    """(module path under modelkit/, key) for every use of a format's key outside its own package."""
    out: set[tuple[str, str]] = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        keys = {n.value for n in ast.walk(tree)
                if isinstance(n, ast.Constant) and isinstance(n.value, str) and PREFIXED.match(n.value)}
        keys |= _extras_keys(tree)
        for key in keys:
            if not rel.startswith(f"formats/{_owner(key)}/"):
                out.add((rel, key))
    return out


def test_no_module_names_another_formats_extras_keys() -> None:
    found = uses()
    new = sorted(found - EXCEPTIONS.keys())
    stale = sorted(EXCEPTIONS.keys() - found)
    assert not new, f"another format's extras keys used (own them, or list them with a reason): {new}"
    assert not stale, f"exceptions no longer used (remove them from EXCEPTIONS): {stale}"


def test_the_scan_sees_what_it_must() -> None:
    """The scan finds a prefixed key anywhere and an unprefixed URDF key read from extras."""
    tree = ast.parse('x = robot.extras.get("gazebo")\ny = "mjcf_sites"\nz = options.gazebo\n')
    assert _extras_keys(tree) == {"gazebo"}
    assert [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and PREFIXED.match(str(n.value))] \
        == ["mjcf_sites"]
