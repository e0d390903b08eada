"""The rule registry: rules register themselves with their code and name."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from modelkit.codes import CODES
from modelkit.diagnostics import Diagnostic
from modelkit.model import Robot

RuleFunction = Callable[[Robot], Iterable[Diagnostic]]


@dataclass(frozen=True)
class Rule:
    name: str
    codes: tuple[str, ...]
    check: RuleFunction
    doc: str


RULES: list[Rule] = []


def rule(name: str, *codes: str) -> Callable[[RuleFunction], RuleFunction]:
    """Register a rule that may emit the given codes (each must be in the catalogue)."""
    for code in codes:
        if code not in CODES:
            raise KeyError(f"rule {name}: unknown code {code}")

    def register(fn: RuleFunction) -> RuleFunction:
        RULES.append(Rule(name, codes, fn, (fn.__doc__ or "").strip()))
        return fn

    return register


def run_rules(robot: Robot) -> list[Diagnostic]:
    # Importing the rule modules registers their rules.
    from modelkit.checks import physics, plausibility, portability, topology  # noqa: F401

    out: list[Diagnostic] = []
    for r in RULES:
        out.extend(_checked(r, r.check(robot)))
    return out


def _checked(r: Rule, ds: Iterable[Diagnostic]) -> Iterator[Diagnostic]:
    for d in ds:
        assert d.code in r.codes, f"rule {r.name} emitted {d.code}, not declared"
        yield d
