"""The JSON Schema of Choreonoid ``.body`` files and its application to a YAML tree, with line numbers.

The schema (``schemas/body.schema.json``, reached through ``modelkit/data/body.schema.json``) validates
:func:`modelkit.yamltree.to_plain` of the document: dicts, lists and strings only, because Choreonoid reads
every scalar as a string and types it on use. :func:`check_schema` turns schema errors into diagnostics that
point at the YAML source, and adds what a schema cannot say by itself: keys the loader ignores (MK103 and the
special cases MK119, MK405, MK610) and optional nodes of an undefined type, which Choreonoid skips (MK603).

Validation runs in two stages. A small compiled checker (:mod:`.schema_check`, covering exactly the
keywords the schema uses) decides whether the document is valid; only when it is not does ``jsonschema``
run to produce the detailed errors. Valid documents are the common case; the compiled checker needs no
``jsonschema`` import (~25 ms of start-up) and is several times faster; a test keeps the two in agreement.
"""

from __future__ import annotations

import difflib
import json
import re
from collections.abc import Iterable, Iterator
from functools import cache
from importlib import resources
from typing import TYPE_CHECKING, Any

from modelkit.diagnostics import Diagnostic, SourceLocation, diag, sorted_diagnostics
from modelkit.formats.body.schema_check import Check, UnsupportedSchema, compile_schema
from modelkit.yamltree import YMap, YNode, YScalar, YSeq, locate, to_plain

if TYPE_CHECKING:  # jsonschema is imported only to explain an invalid document (see _schema_errors)
    import jsonschema
    from jsonschema.exceptions import ValidationError

__all__ = ["check_schema", "known_keys", "schema"]

_REF_PREFIX = "#/$defs/"

# Definitions whose faults have a dedicated code in the catalogue (see modelkit.codes).
_ENUM_CODES = {"geometryType": "MK412", "elementType": "MK602"}
_TYPE_CODES = {"elements": "MK608"}
# Faults the body reader reports itself with a dedicated code, so check_schema leaves them out (the schema
# keeps the rules, for standalone use): definition → the validators whose errors are dropped.
#   linkNodeType: a links entry of another type (MK212); SubBody without uri (MK216); ContinuousTrack
#   without parent/numJoints/jointOffset (MK217); extra joint without link names or joint type (MK215).
_LEFT_TO_READER: dict[str, frozenset[str | None]] = {
    "linkNodeType": frozenset({"enum"}),
    "SubBody": frozenset({"required"}),
    "ContinuousTrack": frozenset({"required", "anyOf"}),
    "ExtraJoint": frozenset({"anyOf"}),
}

# Enumerations longer than this are not listed in messages (the closest word is suggested instead).
_MAX_LISTED_WORDS = 16


# ----------------------------------------------------------------------------------------------------------
# The schema and the things derived from it, each computed once per process


@cache
def schema() -> dict[str, Any]:
    """The body-file JSON Schema (draft 2020-12), loaded once from the package data."""
    text = resources.files("modelkit").joinpath("data", "body.schema.json").read_text(encoding="utf-8")
    loaded: dict[str, Any] = json.loads(text)
    return loaded


def _defs() -> dict[str, Any]:
    defs: dict[str, Any] = schema()["$defs"]
    return defs


@cache
def _validator() -> jsonschema.Draft202012Validator:
    import jsonschema

    return jsonschema.Draft202012Validator(schema())


@cache
def _compiled() -> Check | None:
    """The compiled yes/no check of the schema, or None when the schema outgrows the compiler."""
    try:
        return compile_schema(schema())
    except UnsupportedSchema:
        return None


def _ref_name(subschema: object) -> str | None:
    """The definition name of a ``{"$ref": "#/$defs/Name"}`` subschema."""
    if isinstance(subschema, dict):
        target = subschema.get("$ref")
        if isinstance(target, str) and target.startswith(_REF_PREFIX):
            return target[len(_REF_PREFIX):]
    return None


def _resolved_def(name: str) -> dict[str, Any]:
    """A definition, following a definition that is only an alias of another (CameraDevice → Camera)."""
    defs = _defs()
    definition: dict[str, Any] = defs[name]
    seen = {name}
    while "properties" not in definition:
        target = _ref_name(definition)
        if target is None or target in seen:
            break
        seen.add(target)
        definition = defs[target]
    return definition


def known_keys(definition: str) -> frozenset[str]:
    """Every key the loader reads for a node of this definition (the ``properties`` of the schema).

    Raises KeyError for a name that is not a definition of the schema.
    """
    return _known_keys(definition)


@cache
def _known_keys(definition: str) -> frozenset[str]:
    if definition not in _defs():
        raise KeyError(f"no definition {definition!r} in the body schema")
    return frozenset(_resolved_def(definition).get("properties", {}))


@cache
def _node_defs() -> tuple[str, ...]:
    """The node definitions, in schema order: named after the node type, so capitalised (``Link``,
    ``Shape``, ``Box`` …); value and dispatch definitions are lower-case (``vector3``, ``elements`` …)."""
    return tuple(name for name in _defs() if name[:1].isupper())


def _chain_table(subschema: object) -> dict[str, str]:
    """Type word → definition name from an if/then/else chain on ``type`` (the schema's dispatch)."""
    table: dict[str, str] = {}
    node = subschema
    while isinstance(node, dict) and "if" in node:
        const = node["if"].get("properties", {}).get("type", {}).get("const")
        target = _ref_name(node.get("then"))
        if isinstance(const, str) and target is not None and const not in table:
            table[const] = target
        node = node.get("else")
    return table


@cache
def _element_table() -> dict[str, str]:
    return _chain_table(_defs()["elementNode"]["then"])


@cache
def _keyed_element_table() -> dict[str, str]:
    props = _defs()["elementsByType"]["properties"]
    return {key: name for key, sub in props.items() if (name := _ref_name(sub)) is not None}


@cache
def _geometry_table() -> dict[str, str]:
    return _chain_table(_defs()["geometry"]["then"])


@cache
def _link_table() -> dict[str, str]:
    return _chain_table(_defs()["linkDispatch"]["else"])


@cache
def _true_word() -> re.Pattern[str]:
    return re.compile(_defs()["trueWord"]["pattern"])


@cache
def _def_names_by_id() -> dict[int, str]:
    """Definition name by the identity of its dict (and of its ``allOf`` parts), to name an error's schema."""
    names: dict[int, str] = {}
    for name, definition in _defs().items():
        names[id(definition)] = name
        if isinstance(definition, dict):
            for part in definition.get("allOf", []):
                names.setdefault(id(part), name)
    return names


@cache
def _key_owners() -> dict[str, tuple[str, ...]]:
    """For every key of a node definition, the node definitions that read it (schema order)."""
    owners: dict[str, list[str]] = {}
    for name in _node_defs():
        for key in _defs()[name].get("properties", {}):  # aliases (CameraDevice) add nothing new
            owners.setdefault(key, []).append(name)
    return {key: tuple(names) for key, names in owners.items()}


@cache
def _spellings_by_norm() -> dict[str, tuple[str, ...]]:
    """Keys of all node definitions grouped by their spelling without case and underscores."""
    groups: dict[str, list[str]] = {}
    for key in sorted(_key_owners()):
        groups.setdefault(_norm(key), []).append(key)
    return {norm: tuple(keys) for norm, keys in groups.items()}


def _norm(key: str) -> str:
    return key.replace("_", "").casefold()


@cache
def _def_family(definition: str) -> str:
    """Which dispatch a node definition belongs to, to rank other nodes that read an unknown key."""
    for family, table in (("geometry", _geometry_table()), ("link", _link_table()),
                          ("element", _element_table())):
        if definition in table.values():
            return family
    return "other"


# ----------------------------------------------------------------------------------------------------------
# Compiled validity check


def _show(value: object, limit: int = 60) -> str:
    """A value the way it would be written in YAML flow style, shortened."""
    text = _flow(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _flow(value: object) -> str:
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(_flow_item(v) for v in value[:12]) + (", …" if len(value) > 12 else "") + "]"
    if isinstance(value, dict):
        items = list(value.items())
        inner = ", ".join(f"{k}: {_flow_item(v)}" for k, v in items[:6])
        return "{" + inner + (", …" if len(items) > 6 else "") + "}"
    return repr(value)


def _flow_item(value: object) -> str:
    if isinstance(value, str):
        return value if value and re.fullmatch(r"[\w.+\-]+", value) else json.dumps(value, ensure_ascii=False)
    return _flow(value)


def _label(path: tuple[str | int, ...]) -> str:
    """``"size"[1]`` for the path (..., "size", 1): the last key, then the list indices below it."""
    if not path:
        return "the document"
    last_key = max((i for i, step in enumerate(path) if isinstance(step, str)), default=-1)
    head = f'"{path[last_key]}"' if last_key >= 0 else "the document"
    return head + "".join(f"[{step}]" for step in path[last_key + 1:])


def _allowed_text(words: list[str]) -> str:
    """The allowed words for a message; case variants of one word (axis symbols) are shown once."""
    groups: dict[str, list[str]] = {}
    for word in words:
        groups.setdefault(word.casefold(), []).append(word)
    if len(groups) < len(words) and all(len(group) > 1 for group in groups.values()):
        shown = [next((w for w in group if w != w.lower()), group[0]) for group in groups.values()]
        return ", ".join(sorted(shown, key=lambda w: (w.lstrip("+-"), w.startswith("-")))) + ", in any case"
    return ", ".join(sorted(words, key=lambda w: (w.casefold(), w)))


def _closest(word: str, candidates: Iterable[str], cutoff: float = 0.6) -> str | None:
    """The candidate closest to ``word``: same spelling ignoring case and underscores first, then difflib."""
    pool = sorted(candidates)
    same = [candidate for candidate in pool if _norm(candidate) == _norm(word)]
    if same:  # several spellings of the key (centerOfMass, center_of_mass): the one written most alike
        return max(same, key=lambda c: difflib.SequenceMatcher(None, word, c).ratio())
    matches = difflib.get_close_matches(word, pool, n=1, cutoff=cutoff)
    if matches:
        return matches[0]
    folded = {c.casefold(): c for c in pool}
    matches = difflib.get_close_matches(word.casefold(), list(folded), n=1, cutoff=cutoff)
    return folded[matches[0]] if matches else None


def _did_you_mean(word: str, candidates: Iterable[str], cutoff: float = 0.6) -> str | None:
    match = _closest(word, candidates, cutoff)
    return f'did you mean "{match}"?' if match is not None and match != word else None


# ----------------------------------------------------------------------------------------------------------
# Schema errors → diagnostics


class _Reporter:
    """Collects diagnostics for one document, one per location and fault."""

    def __init__(self, root: YNode, path: str) -> None:
        self.root = root
        self.path = path
        self.items: list[Diagnostic] = []
        self.seen: set[tuple[object, ...]] = set()

    def loc(self, node: YNode | None) -> SourceLocation:
        where = (node or self.root).loc
        return SourceLocation(self.path, where.line, where.col)

    def emit(self, fault: tuple[object, ...], code: str, message: str, node: YNode | None,
             hint: str | None = None) -> None:
        """Add a diagnostic unless the same fault was already reported at the same place.

        ``fault`` identifies the problem independently of the wording and the code, so that the same value
        reached twice (through an alias, or by an outer and an inner definition) is reported once.
        """
        location = self.loc(node)
        key = (location.line, location.col, *fault)
        if key in self.seen:
            return
        self.seen.add(key)
        self.items.append(diag(code, message, location, hint))

    # -- jsonschema errors ----------------------------------------------------------------------------------

    def schema_error(self, error: ValidationError) -> None:
        path = tuple(error.absolute_path)
        value_node, key_node = locate(self.root, path)
        kind = error.validator
        label = _label(path)
        description = _description(error.schema)
        if kind in _LEFT_TO_READER.get(_def_names_by_id().get(id(error.schema), ""), ()):
            return
        if kind is None and error.schema is False:
            self._undefined_keyed_node(path, key_node or value_node)
        elif kind in ("type", "pattern", "minItems", "maxItems"):
            self._wrong_type(path, label, description, error, value_node)
        elif kind == "enum":
            self._not_allowed(label, error, value_node)
        elif kind == "const":
            self._mismatch(path, error, value_node)
        elif kind == "required":
            assert isinstance(error.validator_value, list)
            for missing in error.validator_value:
                if isinstance(error.instance, dict) and missing not in error.instance:
                    self.emit(("required", missing), "MK101",
                              f'{label}: missing required key "{missing}"{_in_node(error.schema)}',
                              value_node)
        elif kind == "anyOf" and _is_required_alternatives(error.validator_value):
            self._missing_alternatives(label, error, value_node)
        elif kind in ("anyOf", "oneOf", "allOf") and error.context:
            from jsonschema.exceptions import best_match

            self.schema_error(best_match(error.context))
        else:
            self.emit(("other", kind), "MK104", f"{label}: {error.message}", value_node)

    def _wrong_type(self, path: tuple[str | int, ...], label: str, description: str | None,
                    error: ValidationError, node: YNode | None) -> None:
        name = _def_names_by_id().get(id(error.schema))
        if not path:
            got = _show(error.instance)
            self.emit(("type",), "MK017", f"the top-level node must be a mapping, got {got}", node)
            return
        if name == "number" and isinstance(error.instance, str):
            leading = _leading_number(error.instance)
            if leading is not None:  # "0.5f" where Choreonoid reads with a "read" accessor: it is ignored
                self.emit(("type",), "MK181",
                          f'{label}: "{error.instance}" is a number followed by text: Choreonoid ignores the '
                          "value (it reads this key only when the whole text is a number) and keeps the "
                          "default (so does modelkit)", node,
                          f"write {leading} alone (no C-style suffix such as f, no unit)")
                return
        code = _TYPE_CODES.get(name or "", "MK100")
        expected = description or _generic_description(error.schema)
        self.emit(("type",), code, f"{label}: expected {expected}, got {_show(error.instance)}", node)

    def _not_allowed(self, label: str, error: ValidationError, value_node: YNode | None) -> None:
        name = _def_names_by_id().get(id(error.schema), "")
        words = [w for w in error.validator_value if isinstance(w, str)]
        description = _description(error.schema) or "one of the allowed words"
        value = error.instance
        if not isinstance(value, str):
            self.emit(("type",), "MK100", f"{label}: expected {description}, got {_show(value)}", value_node)
            return
        if name == "elementType":
            self.emit(("enum", value), "MK602", f'{label}: the node type "{value}" is not defined',
                      value_node, _undefined_type_hint(value, words))
            return
        code = _ENUM_CODES.get(name, "MK102")
        listed = f" (allowed: {_allowed_text(words)})" if len(words) <= _MAX_LISTED_WORDS else ""
        self.emit(("enum", value), code, f'{label}: "{value}" is not {description}{listed}', value_node,
                  _did_you_mean(value, words))

    def _mismatch(self, path: tuple[str | int, ...], error: ValidationError, node: YNode | None) -> None:
        expected = error.validator_value
        parent_key = path[-2] if len(path) >= 2 else expected
        self.emit(("const",), "MK609",
                  f'"type": {_show(error.instance)} differs from the node type "{parent_key}" given by the '
                  f'key it is placed under', node, f'remove the "type" key or make it "{expected}"')

    def _undefined_keyed_node(self, path: tuple[str | int, ...], node: YNode | None) -> None:
        key = str(path[-1]) if path else "?"
        self.emit(("undefined", key), "MK602",
                  f'"{key}": the node type "{key}" is not defined '
                  '(a key of this "elements" mapping is a node type)',
                  node, _undefined_type_hint(key, _keyed_element_table()))

    def _missing_alternatives(self, label: str, error: ValidationError, node: YNode | None) -> None:
        spellings = [key for branch in error.validator_value for key in branch["required"]]
        shown = " or ".join(f'"{key}"' for key in spellings)
        self.emit(("required", spellings[0]), "MK101",
                  f"{label}: missing required key {shown}{_in_node(error.schema)}", node)


def _leading_number(text: str) -> str | None:
    from modelkit.formats.body.values import leading_number_text

    return leading_number_text(text)


def _undefined_type_hint(type_name: str, known: Iterable[str]) -> str:
    skip = 'a node with "is_optional: true" is skipped instead of failing the load'
    match = _closest(type_name, known)
    return f'did you mean "{match}"? Otherwise note that {skip}' if match is not None else skip


def _in_node(subschema: object) -> str:
    """`` in Resource`` for a required key of a node definition (or of one of its ``allOf`` parts)."""
    name = _def_names_by_id().get(id(subschema))
    if name is None or not name[:1].isupper():
        return ""
    return " in " + _display_name(name)


def _display_name(definition: str) -> str:
    return "Resource geometry" if definition == "ResourceGeometry" else definition


def _description(subschema: object) -> str | None:
    if isinstance(subschema, dict):
        text = subschema.get("description")
        if isinstance(text, str):
            return text
    return None


def _generic_description(subschema: object) -> str:
    names = {"string": "a scalar", "array": "a list", "object": "a mapping"}
    if isinstance(subschema, dict):
        kinds = subschema.get("type")
        if isinstance(kinds, str):
            return names.get(kinds, kinds)
        if isinstance(kinds, list):
            return " or ".join(names.get(str(k), str(k)) for k in kinds)
    return "another value"


def _is_required_alternatives(branches: object) -> bool:
    return isinstance(branches, list) and bool(branches) and all(
        isinstance(b, dict) and set(b) == {"required"} for b in branches)


# ----------------------------------------------------------------------------------------------------------
# Unknown keys and optional nodes: a walk of the YAML tree along the schema's node dispatch


class _KeyWalker:
    def __init__(self, reporter: _Reporter) -> None:
        self.reporter = reporter
        self.visited: set[tuple[int, str]] = set()
        self.node_defs = _node_defs()

    def node(self, node: YNode, definition: str) -> None:
        if not isinstance(node, YMap):
            return
        token = (id(node), definition)
        if token in self.visited:
            return
        self.visited.add(token)
        resolved = _resolved_def(definition)
        props: dict[str, Any] = resolved.get("properties", {})
        complete = resolved.get("x-keysComplete", True) is not False
        for key, (key_node, value) in node.entries.items():
            sub = props.get(key)
            if sub is None:
                if complete:
                    self.unknown_key(definition, key, key_node, value, props)
                continue
            self.value(value, sub)

    def value(self, value: YNode, subschema: object) -> None:
        target = _ref_name(subschema)
        if target is None:
            return
        if target == "elements":
            self.elements(value)
        elif target == "links":
            self.links(value)
        elif target == "geometry":
            self.geometry(value)
        elif target == "extraJoints":
            if isinstance(value, YSeq):
                for item in value.items:
                    self.node(item, "ExtraJoint")
        elif target == "resourceMetadata":
            self.node(value, "ResourceMetadata")
        elif target in self.node_defs:
            self.node(value, target)

    def elements(self, value: YNode) -> None:
        if isinstance(value, YSeq):
            for item in value.items:
                self.element_node(item)
        elif isinstance(value, YMap):
            if "type" in value.entries:
                self.element_node(value)
                return
            if value.merged_keys:
                # Choreonoid keeps the "<<" key itself and reads it here as a node type (spec §1.1).
                self.reporter.emit(("merge-in-keyed-elements",), "MK602",
                                   'a "<<" merge in a type-keyed "elements" mapping: Choreonoid keeps the '
                                   '"<<" key and reads it as the undefined node type "<<"', value,
                                   'use the list form of "elements", or write the merged nodes out')
            table = _keyed_element_table()
            for key, (key_node, child) in value.entries.items():
                target = table.get(key)
                if target is not None:
                    if target != "Skip":
                        self.node(child, target)
                elif isinstance(child, YMap) and _is_optional(child):
                    self.optional_skipped(key, key_node)

    def element_node(self, node: YNode) -> None:
        if not isinstance(node, YMap):
            return
        type_node = node.get("type")
        if not isinstance(type_node, YScalar):
            return
        target = _element_table().get(type_node.value)
        if target is None:
            if _is_optional(node):
                self.optional_skipped(type_node.value, type_node)
        elif target != "Skip":
            self.node(node, target)

    def links(self, value: YNode) -> None:
        table = _link_table()
        if isinstance(value, YSeq):
            for item in value.items:
                if not isinstance(item, YMap):
                    continue
                type_node = item.get("type")
                if type_node is None:
                    self.node(item, "Link")
                elif isinstance(type_node, YScalar):
                    target = table.get(type_node.value)
                    if target is not None and target != "Skip":
                        self.node(item, target)
        elif isinstance(value, YMap):
            for key, child in value.items():
                target = table.get(key)
                if target is not None and target != "Skip":
                    self.node(child, target)

    def geometry(self, value: YNode) -> None:
        if isinstance(value, YMap):
            type_node = value.get("type")
            if isinstance(type_node, YScalar):
                target = _geometry_table().get(type_node.value)
                if target is not None:
                    self.node(value, target)

    def optional_skipped(self, type_name: str, node: YNode) -> None:
        self.reporter.emit(("optional", type_name), "MK603",
                           f'the node type "{type_name}" is not defined; Choreonoid skips this optional node',
                           node)

    def unknown_key(self, definition: str, key: str, key_node: YScalar, value: YNode,
                    props: dict[str, Any]) -> None:
        report = self.reporter.emit
        if definition == "Extrusion" and key == "begin_cap":
            report(("key", key), "MK405", '"begin_cap" is ignored by Choreonoid: only "beginCap" works',
                   key_node, 'rename it to "beginCap"')
        elif definition == "Shape" and key == "material":
            report(("key", key), "MK610", '"material" directly in a Shape is ignored by Choreonoid', key_node,
                   'move it under "appearance"')
        elif _defines_anchor(value, key_node):
            report(("key", key), "MK119", f'"{key}" only holds YAML anchors; the loader ignores it', key_node)
        else:
            report(("key", key), "MK103",
                   f'unknown key "{key}" in {_display_name(definition)} (Choreonoid ignores it)', key_node,
                   _unknown_key_hint(definition, key, props))


def _unknown_key_hint(definition: str, key: str, props: Iterable[str]) -> str | None:
    """A close key of this node, else the nodes that do read this key (or a differently spelled one)."""
    match = _closest(key, props, cutoff=0.75)
    if match is not None:
        return f'did you mean "{match}"?'
    owners = _key_owners()
    spelling = key
    if key not in owners:
        spellings = _spellings_by_norm().get(_norm(key))
        if not spellings:
            return None
        spelling = max(spellings, key=lambda c: difflib.SequenceMatcher(None, key, c).ratio())
    family = _def_family(definition)
    # nodes of the same kind first (a geometry for a geometry key), plugin devices last
    readers = sorted(owners[spelling],
                     key=lambda name: ("x-plugin" in _defs()[name], _def_family(name) != family))
    shown = ", ".join(_display_name(name) for name in readers[:3]) + (", …" if len(readers) > 3 else "")
    where = f'"{spelling}" is read in {shown}, not in {_display_name(definition)}'
    return where if spelling == key else f'did you mean "{spelling}"? ({where})'


def _is_optional(node: YMap) -> bool:
    flag = node.get("is_optional", "isOptional")
    return isinstance(flag, YScalar) and _true_word().search(flag.value) is not None


def _defines_anchor(value: YNode, key_node: YScalar) -> bool:
    """Whether an anchor is defined inside ``value`` (not merely used through an alias).

    An alias can only refer to an anchor defined earlier, so an anchored node that starts at or after the key
    is defined under it; nodes that start before the key are shared from elsewhere and are not searched.
    """
    start = (key_node.loc.line, key_node.loc.col)
    stack = [value]
    seen: set[int] = set()
    while stack:
        node = stack.pop()
        if id(node) in seen or (node.loc.line, node.loc.col) < start:
            continue
        seen.add(id(node))
        if node.anchor is not None:
            return True
        if isinstance(node, YSeq):
            stack.extend(node.items)
        elif isinstance(node, YMap):
            stack.extend(child for _, child in node.entries.values())
    return False


# ----------------------------------------------------------------------------------------------------------
# Entry point


def check_schema(root: YNode, path: str) -> list[Diagnostic]:
    """Validate a parsed ``.body`` document against the schema; diagnostics sorted by line, column, code.

    ``root`` is the document root from :func:`modelkit.yamltree.parse_yaml` (after its alias checks);
    ``path`` is the file name used in the locations.
    """
    reporter = _Reporter(root, path)
    try:
        instance = to_plain(root)
        for error in _schema_errors(instance):
            reporter.schema_error(error)
        _KeyWalker(reporter).node(root, "Body")
    except RecursionError:
        # Only a pathologically deep document gets here (real models nest a few dozen levels).
        reporter.emit(("depth",), "MK104",
                      "the document is nested too deeply to be checked against the schema", root)
    return sorted_diagnostics(reporter.items)


def _schema_errors(instance: object) -> Iterator[ValidationError]:
    # Valid documents (the common case) are decided by the compiled check alone; jsonschema explains the
    # others. The two agree on validity (tests/test_body_schema.py).
    compiled = _compiled()
    if compiled is not None and compiled(instance):
        return
    # jsonschema's order (schema keyword order) is kept: where two errors hit the same value, the first
    # one comes from the outer definition (e.g. "type" before the if/then of jointAxis) and wins.
    yield from _validator().iter_errors(instance)
