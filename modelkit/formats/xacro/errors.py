"""Turning an xacro failure into one diagnostic that points at the right line.

xacro says what went wrong and in which file (sometimes in which macro), never on which line.
While it runs, :mod:`modelkit.formats.xacro.expand` records the innermost element being processed,
the innermost macro call, the last directive whose attributes were read and the text being
evaluated; from those, and a search of the sources for the name at fault, :func:`diagnose` finds
the place.
"""

from __future__ import annotations

import re
import xml.dom.minidom as minidom
from collections.abc import Iterator
from dataclasses import dataclass, field

from modelkit.diagnostics import Diagnostic, SourceLocation, diag
from modelkit.formats.xacro.guard import ExpressionTooLarge, OutsideRead
from modelkit.formats.xacro.origins import ExpansionTooLarge, Origin, OriginMap, attributes, source_elements
from modelkit.textio import UnreadableFile
from modelkit.xmlsource import XmlDocument


class PackageNotFound(Exception):
    """``$(find PKG)`` for a package the resolver cannot find."""

    def __init__(self, package: str) -> None:
        super().__init__(f'package "{package}" cannot be found')
        self.package = package


class YamlFileMissing(Exception):
    """``load_yaml`` of a file that does not exist."""

    def __init__(self, path: str) -> None:
        super().__init__(path)
        self.path = path


class ValueTooLarge(Exception):
    """An evaluated value grew past the size limit (a property that doubles itself)."""


class Reported(Exception):
    """Expansion stopped on a problem already reported as a diagnostic (malformed include...)."""


@dataclass
class FailureContext:
    """What the hooks saw when expansion failed."""

    origins: OriginMap
    docs: list[XmlDocument]  # every source file, the current one first
    fallback: SourceLocation
    failed_node: minidom.Element | None = None
    failed_call: minidom.Element | None = None
    last_directive: minidom.Element | None = None
    failed_text: str | None = None
    macros: list[str] = field(default_factory=list)  # macro stack, innermost last


_CALL_ERRORS = (
    "Undefined parameters",
    "Invalid parameter",
    "Not enough blocks",
    "Unused block",
    "unknown macro",
)
_NAME_ERROR = re.compile(r"name '([^']+)' is not defined")


def _chain(exc: BaseException) -> Iterator[BaseException]:
    seen: set[int] = set()
    todo: list[BaseException | None] = [exc]
    while todo:
        item = todo.pop(0)
        if item is None or id(item) in seen:
            continue
        seen.add(id(item))
        yield item
        inner = getattr(item, "exc", None)
        todo.extend([inner if isinstance(inner, BaseException) else None, item.__cause__, item.__context__])


def _first(exc: BaseException, kind: type[BaseException]) -> BaseException | None:
    return next((e for e in _chain(exc) if isinstance(e, kind)), None)


def _text(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _search(doc: XmlDocument, root: object, pattern: re.Pattern[str]) -> SourceLocation | None:
    for element in source_elements(root):  # type: ignore[arg-type]
        for name, value in attributes(element):
            if pattern.search(value):
                return doc.loc(element, name if not name.startswith("{") else None)
        if element.text and pattern.search(element.text):
            return doc.text_loc(element)
        for child in element:
            if child.tail and pattern.search(child.tail):
                return doc.text_loc(element)
    return None


def locate(
    ctx: FailureContext, pattern: re.Pattern[str] | None, node: minidom.Element | None
) -> SourceLocation:
    """The best place for a failure, in this order: the attribute whose value is the text that
    failed; the first attribute or text matching ``pattern`` in the failing element's source
    subtree, then in every source file; the directive being processed; the failing element."""
    text = ctx.failed_text
    for candidate in (ctx.last_directive, node):
        origin = ctx.origins.get(candidate)
        if origin is None or text is None:
            continue
        for name, value in attributes(origin.element):
            if value == text and (pattern is None or pattern.search(value)):
                return origin.loc(name if not name.startswith("{") else None)
    origin = ctx.origins.get(node)
    if pattern is not None:
        if origin is not None:
            found = _search(origin.doc, origin.element, pattern)
            if found is not None:
                return found
        for doc in ctx.docs:
            found = _search(doc, doc.root, pattern)
            if found is not None:
                return found
    if text is not None and text.strip():  # a property's value, evaluated where it is used
        exact = re.compile(rf"\A{re.escape(text)}\Z")
        for doc in ctx.docs:
            found = _search(doc, doc.root, exact)
            if found is not None:
                return found
    directive = ctx.origins.get(ctx.last_directive)
    return _loc(directive) or _loc(origin) or ctx.fallback


def _loc(origin: Origin | None) -> SourceLocation | None:
    return origin.loc() if origin is not None else None


def _in_macro(ctx: FailureContext) -> str:
    return f" (when instantiating macro: {ctx.macros[-1]})" if ctx.macros else ""


def diagnose(exc: BaseException, ctx: FailureContext) -> Diagnostic | None:
    """The diagnostic for an exception out of xacro; None when it was already reported."""
    if _first(exc, Reported) is not None:
        return None
    node = ctx.failed_node
    pattern: re.Pattern[str] | None
    bound = _first(exc, ExpressionTooLarge)
    if bound is not None:
        return diag(
            "MK709",
            f"expression refused: it would build {bound}" + _in_macro(ctx),
            locate(ctx, None, node),
            hint="xacro expressions are bounded in integer size, sequence length and work",
        )
    if _first(exc, ExpansionTooLarge) is not None or _first(exc, ValueTooLarge) is not None:
        return diag(
            "MK709",
            "expansion stopped: it produces too many elements or too long a value" + _in_macro(ctx),
            locate(ctx, None, ctx.failed_call or node),
            hint="a macro or property that multiplies itself at each level",
        )
    if _first(exc, RecursionError) is not None:
        if ctx.macros:
            return diag(
                "MK706",
                f"macro expansion recurses without end in macro {ctx.macros[-1]}",
                _loc(ctx.origins.get(ctx.failed_call or node)) or ctx.fallback,
                hint="a macro calls itself (directly or through another) with no condition that stops it",
            )
        return diag(  # no macro on the stack: files that include each other
            "MK706",
            "expansion recurses without end: the file includes itself (directly or through another)",
            locate(ctx, None, node),
            hint="remove the include that closes the loop",
        )
    outside = _first(exc, OutsideRead)
    if isinstance(outside, OutsideRead):
        return diag(
            "MK711",
            f"refusing to read {outside.path}: it is outside the model's folder tree and the package "
            "paths given",
            locate(ctx, None, node),
            hint="give the folder that holds it with --package-path NAME=DIR (or ROS_PACKAGE_PATH)",
        )
    missing_yaml = _first(exc, YamlFileMissing)
    if isinstance(missing_yaml, YamlFileMissing):
        message = f"load_yaml: {missing_yaml.path} does not exist" + _in_macro(ctx)
        return diag("MK705", message, locate(ctx, None, node))
    unreadable = _first(exc, UnreadableFile)
    if isinstance(unreadable, UnreadableFile):
        return diag(unreadable.code, f"{unreadable.path}: {unreadable.message}", locate(ctx, None, node))
    missing = _first(exc, PackageNotFound)
    if isinstance(missing, PackageNotFound):
        name = missing.package
        pattern = re.compile(rf"\$\(\s*find\s+{re.escape(name)}\s*\)")
        return diag(
            "MK702",
            f'$(find {name}): package "{name}" cannot be found',
            locate(ctx, pattern, node),
            hint=f"give its folder with --package-path {name}=DIR, set ROS_PACKAGE_PATH, or put the file "
            f"under a folder whose package.xml names {name}",
        )
    undefined_arg = _first(exc, _arg_exception())
    if undefined_arg is not None:
        name = str(undefined_arg)
        pattern = re.compile(rf"\$\(\s*arg\s+{re.escape(name)}\s*\)")
        return diag(
            "MK704",
            f"$(arg {name}) is not defined" + _in_macro(ctx),
            locate(ctx, pattern, node),
            hint=f"pass {name}:=VALUE on the command line, "
            f'or declare <xacro:arg name="{name}" default="..."/>',
        )
    os_error = _first(exc, OSError)
    if isinstance(os_error, OSError):
        filename = os_error.filename or ""
        reason = os_error.strerror or _text(os_error)
        return diag("MK705", f"cannot include {filename}: {reason}", locate(ctx, None, node))
    name_error = _first(exc, NameError)
    if name_error is not None:
        match = _NAME_ERROR.search(str(name_error))
        pattern = None
        if match:
            name = re.escape(match.group(1))
            pattern = re.compile(rf"\$\{{[^}}]*(?<![\w.]){name}(?!\w)[^}}]*\}}")
        return diag("MK707", _text(exc) + _in_macro(ctx), locate(ctx, pattern, node))
    substitution = _first(exc, _substitution_exception())
    if substitution is not None:  # $(env) of an unset variable, an unknown $(command), ...
        return diag("MK700", _text(substitution) + _in_macro(ctx), locate(ctx, None, node))
    message = _text(exc)
    if message.startswith(_CALL_ERRORS):
        return diag("MK708", message + _in_macro(ctx), locate(ctx, None, ctx.failed_call or node))
    return diag("MK700", message + _in_macro(ctx), locate(ctx, None, node))


def _arg_exception() -> type[BaseException]:
    from xacro.substitution_args import ArgException

    exception: type[BaseException] = ArgException
    return exception


def _substitution_exception() -> type[BaseException]:
    from xacro.substitution_args import SubstitutionException

    exception: type[BaseException] = SubstitutionException
    return exception
