"""xacro's evaluation of a text (``${expr}``, ``$(arg x)``, the ``$${`` escape), with each text split once.

xacro's ``eval_text`` runs its regular-expression lexer over a text each time the text is evaluated, so a
macro called 1,200 times lexes the same attribute texts 1,200 times. How a text splits into pieces depends
on the text alone, so the split is kept (:func:`split`); the pieces are then evaluated as xacro does, in
its order, through the module's current ``safe_eval``, ``eval_text`` and ``eval_extension`` (the hooks of
:mod:`modelkit.formats.xacro.expand`), with xacro's own exceptions and messages.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from functools import lru_cache
from types import ModuleType
from typing import Any

Piece = tuple[int, str]  # (the lexer's kind of piece, its text)
INVALID = -1  # a text the lexer refuses from here on: the piece's text is xacro's message


@lru_cache(maxsize=16384)
def split(text: str) -> tuple[Piece, ...]:
    """The pieces xacro's lexer reads from ``text``, in order.

    When the lexer refuses the rest of the text, xacro raises while fetching the piece *before* the
    refused rest (its lexer looks one piece ahead), so that piece is never evaluated: it is left out
    here and an :data:`INVALID` piece carrying xacro's message takes its place."""
    import xacro

    lexer = xacro.QuickLexer(xacro.LEXER)
    pieces: list[Piece] = []
    try:
        lexer.lex(text)
        while lexer.peek():
            pieces.append(lexer.next())
    except xacro.XacroException as refused:
        pieces.append((INVALID, str(refused.args[0])))
    return tuple(pieces)


def evaluator(xacro: ModuleType) -> Callable[[Any, Any], Any]:
    """``xacro.eval_text`` with the text's split kept: the same value, or the same exception."""
    original = xacro.eval_text
    lexer = xacro.LEXER
    expression, extension, plain, escaped = lexer.EXPR, lexer.EXTENSION, lexer.TEXT, lexer.DOLLAR_DOLLAR_BRACE

    def eval_text(text: Any, symbols: Any) -> Any:
        if type(text) is not str:  # xacro's lexer fails on these its own way
            return original(text, symbols)
        results: list[Any] = []
        for kind, piece in split(text):
            if kind == plain:
                results.append(piece)
            elif kind == expression:
                inner = piece[2:-1]
                try:
                    results.append(xacro.safe_eval(xacro.eval_text(inner, symbols), symbols))
                except Exception as exc:  # as xacro: the expression named in the message
                    raise xacro.XacroException(
                        exc=exc, suffix=os.linesep + f"when evaluating expression '{inner}'"
                    ) from exc
            elif kind == extension:
                results.append(xacro.eval_extension(f"$({xacro.eval_text(piece[2:-1], symbols)})"))
            elif kind == escaped:
                results.append(piece[1:])
            else:
                raise xacro.XacroException(piece)
        if len(results) == 1:
            return results[0]  # a single piece keeps its type (a number stays a number)
        return "".join(map(str, results))

    return eval_text
