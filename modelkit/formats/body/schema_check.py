"""A compiled yes/no check of a JSON Schema (draft 2020-12), for the keywords the ``.body`` schema uses.

:func:`modelkit.formats.body.schema.check_schema` asks this check first and runs ``jsonschema`` only when
the document is invalid, to produce the detailed errors: valid documents are the common case, and this
check neither imports ``jsonschema`` (about 25 ms of start-up) nor walks its generic machinery (two thirds
of the time of a 10,000-link file). It must agree with ``jsonschema`` exactly on valid/invalid;
``tests/test_body_schema.py`` checks that on every ``.body`` file of the tests and the corpus.

Each schema node becomes a Python closure. A keyword this module does not know makes :func:`compile_schema`
raise :class:`UnsupportedSchema`; the caller then always uses ``jsonschema`` (a schema change can make this
check slower to use, never wrong).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any

Check = Callable[[Any], bool]

# Keywords that never affect validity.
_ANNOTATIONS = frozenset({"$schema", "$id", "$defs", "$comment", "title", "description", "default",
                          "examples"})
_DEFS_PREFIX = "#/$defs/"


class UnsupportedSchema(ValueError):
    """The schema uses a keyword (or a reference) this compiler does not implement."""


def _equal(a: Any, b: Any) -> bool:
    """JSON equality as jsonschema decides it: booleans are not numbers; containers compared deeply."""
    if isinstance(a, bool) or isinstance(b, bool):
        return isinstance(a, bool) and isinstance(b, bool) and a is b
    if isinstance(a, str) or isinstance(b, str):
        return isinstance(a, str) and isinstance(b, str) and a == b
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, (dict, list)) or isinstance(b, (dict, list)):
        return False
    return bool(a == b)


def _is_type(value: Any, name: str) -> bool:
    if name == "string":
        return isinstance(value, str)
    if name == "object":
        return isinstance(value, dict)
    if name == "array":
        return isinstance(value, list)
    if name == "null":
        return value is None
    if name == "boolean":
        return isinstance(value, bool)
    if name == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if name == "integer":
        if isinstance(value, bool):
            return False
        return isinstance(value, int) or (isinstance(value, float) and value.is_integer())
    raise UnsupportedSchema(f"type {name!r}")


class _Compiler:
    def __init__(self, root: Mapping[str, Any]) -> None:
        self.root = root
        self.defs: Mapping[str, Any] = root.get("$defs", {})
        self.compiled: dict[str, Check] = {}

    def ref(self, target: str) -> Check:
        if not target.startswith(_DEFS_PREFIX) or "/" in target[len(_DEFS_PREFIX):]:
            raise UnsupportedSchema(f"$ref {target!r}")
        name = target[len(_DEFS_PREFIX):]
        if name not in self.defs:
            raise UnsupportedSchema(f"$ref to a missing definition {target!r}")
        compiled = self.compiled

        def check(value: Any) -> bool:
            return compiled[name](value)

        return check

    def node(self, schema: Any) -> Check:  # one branch per keyword
        if schema is True:
            return lambda value: True
        if schema is False:
            return lambda value: False
        if not isinstance(schema, dict):
            raise UnsupportedSchema(f"schema node {schema!r}")
        checks: list[Callable[..., bool]] = []  # closures take their constants as default arguments
        for key in schema:
            if key in _ANNOTATIONS or key.startswith("x-") or key in ("then", "else"):
                continue
            if key == "$ref":
                checks.append(self.ref(schema["$ref"]))
            elif key == "type":
                kinds = schema["type"]
                names = [kinds] if isinstance(kinds, str) else list(kinds)
                for name in names:
                    _is_type(None, name)  # raises for an unknown type name
                checks.append(lambda value, names=names: any(_is_type(value, n) for n in names))
            elif key == "const":
                expected = schema["const"]
                if isinstance(expected, str):
                    checks.append(lambda value, e=expected: type(value) is str and value == e)
                else:
                    checks.append(lambda value, e=expected: _equal(value, e))
            elif key == "enum":
                words = list(schema["enum"])
                if all(isinstance(w, str) for w in words):
                    word_set = frozenset(words)
                    checks.append(lambda value, s=word_set: type(value) is str and value in s)
                else:
                    checks.append(lambda value, ws=words: any(_equal(value, w) for w in ws))
            elif key == "pattern":
                search = re.compile(schema["pattern"]).search
                checks.append(lambda value, s=search: not isinstance(value, str) or s(value) is not None)
            elif key == "required":
                names = list(schema["required"])
                checks.append(lambda value, ns=names: not isinstance(value, dict) or all(
                    n in value for n in ns))
            elif key == "minItems":
                low = int(schema["minItems"])
                checks.append(lambda value, n=low: not isinstance(value, list) or len(value) >= n)
            elif key == "maxItems":
                high = int(schema["maxItems"])
                checks.append(lambda value, n=high: not isinstance(value, list) or len(value) <= n)
            elif key == "properties":
                checks.append(self.properties(schema))
            elif key == "additionalProperties":
                if "patternProperties" in schema:
                    raise UnsupportedSchema("patternProperties")
                known = frozenset(schema.get("properties", {}))
                extra = self.node(schema["additionalProperties"])
                checks.append(lambda value, k=known, sub=extra: not isinstance(value, dict) or all(
                    sub(v) for name, v in value.items() if name not in k))
            elif key == "propertyNames":
                names_check = self.node(schema["propertyNames"])
                checks.append(lambda value, sub=names_check: not isinstance(value, dict) or all(
                    sub(name) for name in value))
            elif key == "prefixItems":
                prefix = [self.node(s) for s in schema["prefixItems"]]
                checks.append(lambda value, p=prefix: not isinstance(value, list) or all(
                    sub(item) for sub, item in zip(p, value, strict=False)))
            elif key == "items":
                start = len(schema.get("prefixItems", []))
                item_check = self.node(schema["items"])
                if start:
                    checks.append(lambda value, sub=item_check, s=start: not isinstance(value, list) or all(
                        sub(item) for item in value[s:]))
                else:
                    checks.append(lambda value, sub=item_check: not isinstance(value, list) or all(
                        sub(item) for item in value))
            elif key == "if":
                condition = self.node(schema["if"])
                then = self.node(schema["then"]) if "then" in schema else None
                other = self.node(schema["else"]) if "else" in schema else None
                checks.append(self.conditional(condition, then, other))
            elif key == "allOf":
                parts = [self.node(s) for s in schema["allOf"]]
                checks.append(lambda value, ps=parts: all(p(value) for p in ps))
            elif key == "anyOf":
                parts = [self.node(s) for s in schema["anyOf"]]
                checks.append(lambda value, ps=parts: any(p(value) for p in ps))
            elif key == "oneOf":
                parts = [self.node(s) for s in schema["oneOf"]]
                checks.append(lambda value, ps=parts: sum(1 for p in ps if p(value)) == 1)
            elif key == "not":
                negated = self.node(schema["not"])
                checks.append(lambda value, sub=negated: not sub(value))
            else:
                raise UnsupportedSchema(f"keyword {key!r}")
        if not checks:
            return lambda value: True
        if len(checks) == 1:
            return checks[0]

        def check_all(value: Any, cs: tuple[Callable[..., bool], ...] = tuple(checks)) -> bool:
            return all(c(value) for c in cs)

        return check_all

    def properties(self, schema: Mapping[str, Any]) -> Check:
        subs = {name: self.node(sub) for name, sub in schema["properties"].items()}

        def check(value: Any) -> bool:
            if not isinstance(value, dict):
                return True
            if len(value) < len(subs):
                for name, v in value.items():
                    sub = subs.get(name)
                    if sub is not None and not sub(v):
                        return False
                return True
            return all(sub(value[name]) for name, sub in subs.items() if name in value)

        return check

    @staticmethod
    def conditional(condition: Check, then: Check | None, other: Check | None) -> Check:
        def check(value: Any) -> bool:
            if condition(value):
                return then is None or then(value)
            return other is None or other(value)

        return check


def compile_schema(schema: Mapping[str, Any]) -> Check:
    """A function telling whether an instance is valid against ``schema`` (local ``#/$defs/`` references).

    Raises :class:`UnsupportedSchema` when the schema uses something this compiler does not implement.
    """
    compiler = _Compiler(schema)
    for name, definition in compiler.defs.items():
        compiler.compiled[name] = compiler.node(definition)
    return compiler.node(schema)
