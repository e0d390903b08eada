"""The split-once text evaluation (:mod:`modelkit.formats.xacro.text`) gives what xacro's own ``eval_text``
gives: the same value and type, or the same exception with the same message, including texts the lexer
refuses part-way (xacro raises before evaluating the piece in front of the refused rest)."""

from __future__ import annotations

from typing import Any

import pytest
import xacro

from modelkit.formats.xacro.text import INVALID, evaluator, split

TEXTS = [
    "",
    "plain",
    "${x}",
    "${x + 1}",
    "${x} and ${y}",
    "${name}_joint",
    "$${escaped}",
    "$$(escaped)",
    "a$b",
    "cost: $",
    "${x",
    "${undefined} then ${",
    "${undefined}${",
    "text ${x} ${",
    "${",
    "${1/0}",
    "${'a' * 3}",
    "${[1, 2]}",
    "${x * 0.5} ${y}",
    "$(arg missing)",
]


def _outcome(function: Any, text: str) -> tuple[str, Any]:
    symbols = xacro.Table({"x": 2, "y": 0.25, "name": "wheel"})
    try:
        value = function(text, symbols)
    except Exception as exc:  # the type and the message are what a user sees
        return "raised", (type(exc).__name__, str(exc), type(getattr(exc, "exc", None)).__name__)
    return "value", (type(value).__name__, value)


@pytest.mark.parametrize("text", TEXTS)
def test_same_value_or_exception_as_xacro(text: str) -> None:
    ours = _outcome(evaluator(xacro), text)
    theirs = _outcome(xacro.eval_text, text)
    assert ours == theirs


def test_a_refused_rest_drops_the_piece_in_front_of_it() -> None:
    pieces = split("${undefined} then ${")
    assert [kind for kind, _ in pieces] == [xacro.LEXER.EXPR, INVALID]
    assert pieces[-1][1] == "invalid expression: ${"
    # Evaluated in order: the expression in front fails first, as in xacro.
    assert _outcome(evaluator(xacro), "${undefined} then ${")[1][0] == "XacroException"
    assert "undefined" in _outcome(evaluator(xacro), "${undefined} then ${")[1][1]
    # With nothing evaluable in front, the refusal itself.
    assert _outcome(evaluator(xacro), "${undefined}${")[1][1] == "invalid expression: ${"


def test_a_text_is_split_once() -> None:
    split.cache_clear()
    run = evaluator(xacro)
    symbols = xacro.Table({"x": 2})
    for _ in range(5):
        run("${x}_link", symbols)
    info = split.cache_info()
    assert (info.misses, info.hits) == (1, 4)
