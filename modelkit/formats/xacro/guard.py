"""Bounds on what an xacro file may make modelkit compute and read.

xacro evaluates every ``${...}`` with Python's ``eval``. Builtins are hidden, but plain arithmetic
is enough to hang or exhaust memory: ``${10**10**10}``, ``${[0]*10**9}``, ``${'a'*10**10}``,
``${sum(range(10**12))}``. :class:`ExpressionGuard` replaces xacro's ``safe_eval``: each expression
is parsed, its operators that can grow a value (``**``, ``*``, ``<<``, ``%``), its calls and its
comprehension loops are rewritten into calls of checking functions, and only then evaluated. The
checks bound integer size, sequence length and the total iteration work of one expansion; a
breach raises :class:`ExpressionTooLarge` (reported as MK709).

:class:`Sandbox` holds the folders xacro may read from (``include``, ``load_yaml``): the model's
own folder tree (its package, when it is in one) and the package folders given or found. Anything
else, ``/etc/passwd`` for one, is refused (MK711) before a byte of it is read.
"""

from __future__ import annotations

import ast
import functools
import math
import os
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import CodeType
from typing import Any

# An integer may have at most this many bits (real xacro files stay within 64).
MAX_INT_BITS = 4096
# A string, list or tuple built by repetition, a ``range`` and a padded format have at most this
# many items.
MAX_SEQUENCE = 1_000_000
# Items all ranges and comprehension loops of one expansion may step through together.
MAX_WORK = 20_000_000
# Arguments above this make math.factorial/comb/perm slow.
MAX_COMBINATORIC = 20_000

# A padding width of a million or more in a %-format or a str.format field.
_WIDTH = re.compile(r"%[-+ #0]*\d{7,}|\{[^{}]*:[^{}]*?\d{7,}[^{}]*\}")
_PADDING_METHODS = frozenset({"ljust", "rjust", "center", "zfill", "expandtabs"})
_GROWING_OPS: dict[type[ast.operator], str] = {
    ast.Pow: "__mk_pow",
    ast.Mult: "__mk_mul",
    ast.LShift: "__mk_lshift",
    ast.Mod: "__mk_mod",
    ast.Add: "__mk_add",
}


class ExpressionTooLarge(Exception):
    """An xacro expression would build a value or do work beyond the bounds above."""


class OutsideRead(Exception):
    """xacro was asked to read a file outside the folders it may read."""

    def __init__(self, path: str) -> None:
        super().__init__(path)
        self.path = path


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _length(value: object) -> int | None:
    if isinstance(value, str | bytes | list | tuple):
        return len(value)
    return None


class _Rewriter(ast.NodeTransformer):
    """Routes growing operators, calls and comprehension iterables through the guard functions."""

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        name = _GROWING_OPS.get(type(node.op))
        if name is None:
            return node
        return ast.copy_location(ast.Call(ast.Name(name, ast.Load()), [node.left, node.right], []), node)

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        call = ast.Call(ast.Name("__mk_call", ast.Load()), [node.func, *node.args], node.keywords)
        return ast.copy_location(call, node)

    def visit_JoinedStr(self, node: ast.JoinedStr) -> ast.AST:
        self.generic_visit(node)
        return ast.copy_location(ast.Call(ast.Name("__mk_sized", ast.Load()), [node], []), node)

    def visit_comprehension(self, node: ast.comprehension) -> ast.AST:
        self.generic_visit(node)
        node.iter = ast.copy_location(ast.Call(ast.Name("__mk_iter", ast.Load()), [node.iter], []), node.iter)
        return node


@dataclass
class ExpressionGuard:
    """xacro's ``safe_eval`` with bounds; one per expansion (the work budget is shared)."""

    exception: Callable[[str], BaseException]  # xacro's XacroException, for xacro's own refusals
    work: int = 0
    max_work: int = MAX_WORK
    _builtins: dict[str, Any] | None = field(default=None, init=False, repr=False, compare=False)

    def builtins(self) -> dict[str, Any]:
        """The guard functions the rewritten code calls, made once per guard (expressions cannot reach
        ``__builtins__``: dunder names are refused)."""
        if self._builtins is None:
            self._builtins = self._make_builtins()
        return self._builtins

    def _make_builtins(self) -> dict[str, Any]:
        return {
            "__mk_pow": self.pow,
            "__mk_mul": self.mul,
            "__mk_lshift": self.lshift,
            "__mk_mod": self.mod,
            "__mk_add": self.add,
            "__mk_sized": self.sized,
            "__mk_call": self.call,
            "__mk_iter": self.iterate,
        }

    def safe_eval(self, expr: str, globals: dict[str, Any], locals: Any = None) -> Any:
        code = _checked_code(expr.strip())
        if isinstance(code, tuple):
            raise self.exception("Use of invalid name(s): " + ", ".join(code))
        globals.update(__builtins__=self.builtins())
        return eval(code, globals, locals)

    # -- checks --------------------------------------------------------------------------------

    def _spend(self, items: int) -> None:
        self.work += items
        if self.work > self.max_work:
            raise ExpressionTooLarge(f"expressions step through more than {self.max_work} items")

    def _int_ok(self, value: int) -> int:
        if value.bit_length() > MAX_INT_BITS:
            raise ExpressionTooLarge(f"an integer of more than {MAX_INT_BITS} bits")
        return value

    def _items_ok(self, count: int) -> None:
        if count > MAX_SEQUENCE:
            raise ExpressionTooLarge(f"a sequence of {count} items (the limit is {MAX_SEQUENCE})")
        self._spend(count)

    def pow(self, base: Any, exponent: Any) -> Any:
        growing = _is_int(base) and _is_int(exponent) and exponent > 0 and abs(base) > 1
        if growing and exponent * math.log2(abs(base)) > MAX_INT_BITS:
            raise ExpressionTooLarge(f"a power of more than {MAX_INT_BITS} bits")
        return base**exponent

    def mul(self, left: Any, right: Any) -> Any:
        if _is_int(left) and _is_int(right):
            if left.bit_length() + right.bit_length() > MAX_INT_BITS + 1:
                raise ExpressionTooLarge(f"a product of more than {MAX_INT_BITS} bits")
            return left * right
        for seq, times in ((left, right), (right, left)):
            size = _length(seq)
            if size is not None and _is_int(times):
                self._items_ok(size * max(times, 0))
        return left * right

    def lshift(self, left: Any, right: Any) -> Any:
        if _is_int(left) and _is_int(right) and left and left.bit_length() + right > MAX_INT_BITS:
            raise ExpressionTooLarge(f"a shift to more than {MAX_INT_BITS} bits")
        return left << right

    def mod(self, left: Any, right: Any) -> Any:
        if isinstance(left, str):
            _check_widths(left)
        return self.sized(left % right)

    def add(self, left: Any, right: Any) -> Any:
        sizes = (_length(left), _length(right))
        if sizes[0] is not None and sizes[1] is not None:
            self._items_ok(sizes[0] + sizes[1])
        return left + right

    def sized(self, value: Any) -> Any:
        """A value just built (a call's result, a formatted string): its items count as work, so
        turning a large shared value (a YAML file's anchors) into text again and again stops."""
        size = _length(value)
        if size is not None:
            self._spend(size)
        return value

    def call(self, function: Any, *args: Any, **kwargs: Any) -> Any:
        if function is range:
            try:
                size = len(range(*args, **kwargs))
            except OverflowError as exc:
                raise ExpressionTooLarge("a range too long to count") from exc
            self._items_ok(size)
        elif function in (math.factorial, math.comb, math.perm):
            if any(_is_int(a) and abs(a) > MAX_COMBINATORIC for a in args):
                raise ExpressionTooLarge(f"{function.__name__} of a number over {MAX_COMBINATORIC}")
        elif isinstance(getattr(function, "__self__", None), str):
            name = getattr(function, "__name__", "")
            if name in _PADDING_METHODS and any(_is_int(a) and a > MAX_SEQUENCE for a in args):
                raise ExpressionTooLarge(f"str.{name} to more than {MAX_SEQUENCE} characters")
            if name in ("format", "format_map"):
                _check_widths(function.__self__)
        result = function(*args, **kwargs)
        if _is_int(result):
            self._int_ok(result)
        return self.sized(result)

    def iterate(self, iterable: Iterable[Any]) -> Iterator[Any]:
        for item in iterable:
            self._spend(1)
            yield item


@functools.lru_cache(maxsize=4096)
def _checked_code(expr: str) -> CodeType | tuple[str, ...]:
    """The guarded code of one expression, or the invalid (dunder) names it uses.

    A pure function of the text, so cached: a macro called a thousand times evaluates the same
    expressions a thousand times. A syntax error is raised (and not cached)."""
    tree = ast.parse(expr, "<expression>", "eval")
    invalid = sorted(
        {
            name
            for node in ast.walk(tree)
            for name in (_name_of(node),)
            if name is not None and name.startswith("__")
        }
    )
    if invalid:
        return tuple(invalid)
    try:
        return compile(ast.fix_missing_locations(_Rewriter().visit(tree)), "<expression>", "eval")
    except RecursionError as exc:  # thousands of chained operators
        raise ExpressionTooLarge("an expression nested too deeply to evaluate") from exc


def _name_of(node: ast.AST) -> str | None:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return node.attr
    return None


def _check_widths(template: str) -> None:
    if _WIDTH.search(template):
        raise ExpressionTooLarge(f"a format width of {MAX_SEQUENCE} characters or more")


@dataclass
class Sandbox:
    """The folders xacro may read files from; paths are compared after resolving symlinks."""

    roots: list[str] = field(default_factory=list)

    def allow(self, folder: Path | str) -> None:
        real = os.path.realpath(folder)
        if real not in self.roots:
            self.roots.append(real)

    def allows(self, path: Path | str) -> bool:
        real = os.path.realpath(path)
        return any(real == root or real.startswith(root.rstrip(os.sep) + os.sep) for root in self.roots)

    def check(self, path: Path | str) -> None:
        if not self.allows(path):
            raise OutsideRead(str(path))


def model_root(top: Path) -> Path:
    """The model's folder tree: the package that holds ``top`` (the nearest folder with a
    ``package.xml``), else ``top``'s own folder."""
    folder = Path(os.path.realpath(top)).parent
    for candidate in (folder, *folder.parents):
        if (candidate / "package.xml").is_file():
            return candidate
    return folder
