"""The layout of ``modelkit/verify`` (issue 16 item 9): no import cycle, no private name used across
modules, and every module importable first in a fresh interpreter.

The graph is read from the source with ``ast``: module-level and function-level imports count alike
(a function-level import only postpones a cycle to the first call), and so do the lazy
``"modelkit.verify.x:name"`` strings that ``api``, ``layer4`` and ``variant`` resolve with
``importlib``. Imports under ``if TYPE_CHECKING:`` are for the type checker only and do not count.
Importing ``a.b.c`` first imports the packages ``a.b`` and ``a``, so a module also depends on every
package ``__init__`` above it: a package's ``__init__`` must therefore import none of its own
subpackages' modules.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import modelkit.verify

VERIFY = Path(modelkit.verify.__file__).parent
PACKAGE = "modelkit.verify"
LAZY = re.compile(r"^(modelkit\.verify(?:\.\w+)*):\w+$")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(VERIFY).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join([PACKAGE, *parts])


MODULES = {module_name(p): p for p in sorted(VERIFY.rglob("*.py"))}


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _runtime_nodes(tree: ast.AST) -> list[ast.AST]:
    """Every node except those under ``if TYPE_CHECKING:``."""
    out: list[ast.AST] = []
    stack: list[ast.AST] = [tree]
    while stack:
        node = stack.pop()
        out.append(node)
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                stack.extend(child.orelse)
                continue
            stack.append(child)
    return out


def _parents(name: str) -> list[str]:
    """The packages importing ``name`` imports first, inside modelkit.verify."""
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(2, len(parts)) if ".".join(parts[:i]) in MODULES]


def imports(name: str) -> tuple[set[str], list[str], dict[str, str]]:
    """``name``'s verify dependencies, the private names it imports from other verify modules
    (``"line: from x import _y"``), and {local alias: verify module} for the attribute check."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    deps: set[str] = set(_parents(name))
    private: list[str] = []
    aliases: dict[str, str] = {}

    def depend(target: str) -> None:
        if target in MODULES:
            deps.add(target)
            deps.update(_parents(target))

    for node in _runtime_nodes(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith(PACKAGE):
                    depend(a.name)
                    if a.asname:
                        aliases[a.asname] = a.name
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if not node.module.startswith(PACKAGE):
                continue
            depend(node.module)
            for a in node.names:
                sub = f"{node.module}.{a.name}"
                if sub in MODULES:  # `from package import module`
                    depend(sub)
                    aliases[a.asname or a.name] = sub
                elif a.name.startswith("_") and node.module != name:
                    private.append(f"{node.lineno}: from {node.module} import {a.name}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            m = LAZY.match(node.value)
            if m:
                depend(m.group(1))
    deps.discard(name)
    for node in _runtime_nodes(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
                and isinstance(node.value, ast.Name) and node.value.id in aliases):
            private.append(f"{node.lineno}: {node.value.id}.{node.attr} ({aliases[node.value.id]})")
    return deps, private, aliases


def graph() -> dict[str, set[str]]:
    return {name: imports(name)[0] for name in MODULES}


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One cycle as [a, b, ..., a], or None."""
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt):], nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(edges):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_the_layout_is_the_one_documented() -> None:
    """The subpackages exist and the old flat modules are gone (so the checks below see the layout)."""
    for sub in ("engines", "layers", "drive", "report"):
        assert f"{PACKAGE}.{sub}" in MODULES, sub
    assert f"{PACKAGE}.engines.mujoco" in MODULES
    assert not (VERIFY / "engine_mujoco.py").exists()
    assert len(MODULES) >= 29


def test_cycle_finder_finds_a_cycle() -> None:
    """The finder itself can fail: a known cycle is reported, an acyclic graph is not."""
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


def test_import_graph_has_no_cycle() -> None:
    edges = graph()
    assert sum(len(d) for d in edges.values()) > 50  # the graph was really read
    cycle = find_cycle(edges)
    assert cycle is None, "import cycle in modelkit/verify: " + " -> ".join(cycle or [])


def test_no_private_name_crosses_modules() -> None:
    found = {name: imports(name)[1] for name in MODULES}
    found = {k: v for k, v in found.items() if v}
    assert not found, f"private names used across modelkit/verify modules: {found}"


CHILD = """
import importlib, sys
try:
    importlib.import_module(sys.argv[1])
except ModuleNotFoundError as exc:  # an optional engine not installed (pydrake) is not a layout fault
    if not exc.name or exc.name.startswith("modelkit"):
        raise
"""

DRIVER = """
import subprocess, sys
failed = []
for name in sys.argv[1:]:
    r = subprocess.run([sys.executable, "-c", {child!r}, name], capture_output=True, text=True)
    if r.returncode:
        tail = (r.stderr.strip().splitlines() or ["exit " + str(r.returncode)])[-1]
        failed.append(name + ": " + tail)
print("\\n".join(failed))
sys.exit(1 if failed else 0)
"""


def test_every_module_imports_first() -> None:
    """Each module imported first, alone, in a fresh interpreter (one driver process runs them in
    turn). A cycle that the graph test misses (say, through a name built at run time) shows here as
    an ImportError on a partly initialised module."""
    names = sorted(MODULES)
    root = str(VERIFY.parents[1])
    r = subprocess.run([sys.executable, "-c", DRIVER.format(child=CHILD), *names], capture_output=True,
                       text=True, timeout=300, cwd=root, env=_env(root))
    assert r.returncode == 0, f"modules that cannot be imported first:\n{r.stdout}{r.stderr}"


def _env(root: str) -> dict[str, str]:
    import os

    env = dict(os.environ)
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env
