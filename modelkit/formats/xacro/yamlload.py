"""xacro's ``load_yaml`` with bounds: the value xacro would get, or coded diagnostics.

xacro reads the file with PyYAML's ``safe_load``. That refuses Python tags, but an alias bomb
(anchors of lists of aliases of anchors...) loads into a small graph of shared objects which the
first ``str()`` or loop in an expression expands to billions of items; the pure-Python loader also
takes seconds per 100 kB. Here the text goes through the same checks a ``.body`` gets before
anything is built: list length and nesting on the event stream (MK006, MK010), then the composed
node graph is measured with every alias counted as a copy (MK015, MK014 for a node that contains
itself). Only then is the value constructed, by libyaml's safe loader with xacro's unit tags
(``!degrees`` ...), which gives the values ``safe_load`` gives.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import yaml

from modelkit.diagnostics import Diagnostic, SourceLocation, diag
from modelkit.yamltree import measure_composed, scan_structure


class YamlRefused(Exception):
    """The YAML file was refused; ``diagnostic`` says why and where."""

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def _loc(path: str, mark: Any) -> SourceLocation:
    if mark is None:
        return SourceLocation(path)
    return SourceLocation(path, mark.line + 1, mark.column + 1)


def _loader_class(units: Iterable[Any]) -> type[yaml.CSafeLoader]:
    """libyaml's safe loader with xacro's unit constructors, on a class of our own (PyYAML's
    ``SafeLoader``, which every other user shares, is left as it is)."""

    class Loader(yaml.CSafeLoader):
        pass

    for unit in units:
        Loader.add_constructor(unit.value.tag, unit.constructor)
    return Loader


def load_bounded(
    text: str, path: str, units: Iterable[Any], max_list_items: int, expansion_limit: int
) -> Any:
    """The first and only YAML document of ``text`` (``path`` names it in diagnostics) as xacro's
    ``safe_load`` builds it; raises :class:`YamlRefused` for what it would not load or what is too
    large. Exceptions raised by a unit tag's expression (xacro's own) pass through."""
    scan = scan_structure(text, path, max_list_items)
    if scan.problem is not None:
        raise YamlRefused(scan.problem)
    loader = _loader_class(units)(text)
    try:
        try:
            node = loader.get_single_node()
        except yaml.MarkedYAMLError as exc:
            raise YamlRefused(_syntax(exc, path)) from exc
        except yaml.YAMLError as exc:  # pragma: no cover - libyaml's errors carry marks
            raise YamlRefused(diag("MK010", f"YAML error: {exc}", SourceLocation(path))) from exc
        if node is None:
            return None  # an empty file: safe_load gives None too
        found = measure_composed(node, expansion_limit) if scan.aliases else None
        if found is not None:
            kind, where = found
            if kind == "recursive":
                raise YamlRefused(diag(
                    "MK014",
                    "an alias refers to a node that contains it (a recursive structure); refusing the file",
                    _loc(path, where.start_mark),
                ))
            raise YamlRefused(diag(
                "MK015",
                f"expanding the aliases would produce more than {expansion_limit:,} nodes (an alias bomb); "
                "refusing the file",
                _loc(path, where.start_mark),
                hint="xacro would expand it when an expression uses the value",
            ))
        try:
            return loader.construct_document(node)
        except yaml.MarkedYAMLError as exc:  # a tag safe_load refuses (!!python/object ...)
            raise YamlRefused(diag(
                "MK700",
                f"xacro: load_yaml cannot build this value: {exc.problem}",
                _loc(path, exc.problem_mark or exc.context_mark),
                hint="load_yaml reads YAML with PyYAML's safe loader: plain data and xacro's unit tags only",
            )) from exc
        except (ValueError, OverflowError) as exc:  # an integer of more digits than Python converts
            raise YamlRefused(diag(
                "MK700", f"xacro: load_yaml cannot build a value: {exc}", _loc(path, node.start_mark)
            )) from exc
    finally:
        loader.dispose()


def _syntax(exc: yaml.MarkedYAMLError, path: str) -> Diagnostic:
    problem = exc.problem or "malformed YAML"
    message = f"{exc.context}: {problem}" if exc.context else problem
    return diag("MK010", f"YAML error: {message}", _loc(path, exc.problem_mark or exc.context_mark))
