"""Running the ``xacro`` package in-process, without ROS, with every failure as a diagnostic.

xacro is a module full of global state (file and macro stacks, substitution arguments, the global
symbol table, a shared text node), prints its warnings to stderr and finds packages through
``ament_index_python``. One expansion therefore happens under a lock, with that state reset, a few
of xacro's module functions wrapped or replaced for the duration, and the originals put back:

* ``parse`` reads every file (the top one and each include) through :mod:`modelkit.xmlsource`
  first (size limit, entity refusal, exact syntax errors), records element origins
  (:mod:`.origins`) and, unless ``--no-legacy``, rewrites legacy constructs to their prefixed form;
* ``$(find PKG)`` uses modelkit's resolver, ``$(env)``/``$(optenv)`` its environment;
* ``warning``/``message``/``error`` become diagnostics, nothing reaches the terminal;
* ``eval_all``, ``handle_macro_call`` and friends record where xacro is, so that an exception can be
  placed on a line (:mod:`.errors`).
"""

from __future__ import annotations

import contextlib
import errno
import importlib
import io
import os
import sys
import threading
import xml.dom.minidom as minidom
import xml.parsers.expat
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

from modelkit.diagnostics import Diagnostic, DiagnosticSink, Severity, SourceLocation, diag
from modelkit.formats.common import ReadOptions
from modelkit.formats.xacro import splice
from modelkit.formats.xacro.errors import (
    FailureContext,
    PackageNotFound,
    Reported,
    ValueTooLarge,
    YamlFileMissing,
    diagnose,
)
from modelkit.formats.xacro.guard import ExpressionGuard, Sandbox, model_root
from modelkit.formats.xacro.legacy import (
    FileSet,
    LegacyConstruct,
    file_key,
    find_legacy,
    find_package,
    macro_names,
    scan_file_set,
)
from modelkit.formats.xacro.origins import OriginMap, dom_elements
from modelkit.formats.xacro.pretty import pretty_xml
from modelkit.formats.xacro.text import evaluator as split_once_eval_text
from modelkit.textio import UnreadableFile, decode_text, read_regular, real_path
from modelkit.xmlsource import XmlDocument, read_xml

# Elements that macro and block expansion may create (a macro bomb stops here); a lower
# ``ReadOptions.expansion_limit`` lowers it. xacro's own cost grows with the square of the number
# of sibling elements (minidom's insertBefore), so a bomb of siblings takes a while to reach it.
CLONE_BUDGET = 100_000

_LOCK = threading.Lock()


class _Deferred(ModuleType):
    """A stand-in for a module in another module's namespace: the real module is imported (an ordinary
    import, the one module object every importer shares) when an attribute is first used."""

    def __getattr__(self, attribute: str) -> Any:
        if sys.modules.get(self.__name__) is self:  # still registered (another thread, mid-import)
            del sys.modules[self.__name__]
        return getattr(importlib.import_module(self.__name__), attribute)


def substitution_args() -> Any:
    """``xacro.substitution_args`` (``$(find)``, ``$(arg)`` ...), imported without importing PyYAML.

    The module imports ``yaml`` at its top for one rare case (an argument converted as yaml); PyYAML is a
    tenth of a small xacro file's start-up. When nothing has imported PyYAML yet, the module is imported
    with a :class:`_Deferred` ``yaml``, which imports PyYAML if that case ever comes; ``sys.modules`` is
    left as it was, so any other ``import yaml`` is the ordinary one."""
    if "xacro.substitution_args" not in sys.modules and "yaml" not in sys.modules:
        stand_in = _Deferred("yaml")
        sys.modules["yaml"] = stand_in
        try:
            import xacro.substitution_args  # noqa: F401  (imported with the stand-in)
        finally:
            if sys.modules.get("yaml") is stand_in:
                del sys.modules["yaml"]
    import xacro.substitution_args as sa

    return sa


@dataclass
class Expanded:
    """The URDF text xacro produced and, per element in document order, where it comes from."""

    text: str
    origins: list[SourceLocation]


def legacy_diagnostic(construct: LegacyConstruct, mode: bool | None) -> Diagnostic:
    """MK701 for one legacy construct: a warning (auto), info (--legacy) or error (--no-legacy)."""
    hint = f"use {construct.modern()}"
    if mode is False:
        hint += "; without --no-legacy modelkit expands it as pre-Jade xacro did"
    severity = {None: Severity.WARNING, True: Severity.INFO, False: Severity.ERROR}[mode]
    return diag("MK701", construct.message(), construct.origin.loc(), hint=hint, severity=severity)


# Includes processed for one top file (each inclusion counted; real robots: a few dozen; each costs
# about 0.5 ms, so the bound is about 1 s of work).
MAX_INCLUDES = 2_000


class _Run:
    """One expansion: what xacro's hooks share while it runs."""

    def __init__(self, path: Path, display: str, options: ReadOptions, sink: DiagnosticSink) -> None:
        self.path = path
        self.display = display
        self.options = options
        self.sink = sink
        self.files = FileSet()
        self.origins = OriginMap(min(CLONE_BUDGET, options.expansion_limit))
        self.stack: list[minidom.Element] = []
        self.failed_node: minidom.Element | None = None
        self.failed_call: minidom.Element | None = None
        self.failed_text: str | None = None
        self.last_directive: minidom.Element | None = None
        self.xacro: Any = None
        self.sandbox = _sandbox(path, options)
        self.parses = 0  # files parsed by xacro (the top file and every include processed)
        self.parsed_bytes = 0

    # -- files ---------------------------------------------------------------------------------

    def display_for(self, path: Path) -> str:
        """How an included file is named in diagnostics: like the top file, relative or absolute."""
        key = file_key(path)
        if key == file_key(self.path):
            return self.display
        if os.path.isabs(self.display):
            return key
        relative = os.path.relpath(key)
        return key if relative.startswith("..") else relative

    def load(self, path: Path, sink: DiagnosticSink | None = None) -> XmlDocument | None:
        if not self.sandbox.allows(path):  # refused (MK711) when xacro itself includes it
            return None
        return read_xml(path, sink or DiagnosticSink(), self.options.max_bytes, self.display_for(path))

    def report_legacy(self, constructs: list[LegacyConstruct]) -> None:
        for construct in constructs:
            self.sink.add(legacy_diagnostic(construct, self.options.legacy_xacro))

    def parse(self, filename: str) -> minidom.Document:
        """xacro's ``parse`` of a file: our checks, origins and legacy rewriting, then a minidom tree."""
        xacro = self.xacro
        path = Path(filename)
        if not os.path.exists(path) or os.path.isdir(path):
            xacro.filestack.pop()  # as xacro does: the missing file is not "the current file"
            code = errno.EISDIR if os.path.isdir(path) else errno.ENOENT
            error = OSError(code, os.strerror(code), filename)
            raise xacro.XacroException(f"{error.strerror}: {filename}", exc=error)
        self.sandbox.check(path)
        key = file_key(path)
        doc = self.files.docs.get(key)
        if doc is None:
            doc = self.load(path, self.sink)
            if doc is None:
                raise Reported()
            self.files.docs[key] = doc
            self.files.macro_names |= macro_names(doc)
            self.report_legacy(self.files.add_constructs(find_legacy(doc, self.files.macro_names)))
        self._count_parse(filename, len(doc.text))
        try:
            dom = minidom.parseString(doc.text)
        except xml.parsers.expat.ExpatError as exc:
            where = SourceLocation(doc.display, exc.lineno or 0, (exc.offset or 0) + 1)
            self.sink.emit("MK020", f"malformed XML: {xml.parsers.expat.ErrorString(exc.code)}", where)
            raise Reported() from exc
        root = dom.documentElement
        assert root is not None  # parseString of a document that lxml accepted
        pairs = self.origins.adopt(root, doc)
        if self.options.legacy_xacro is not False:
            for node, element in pairs:
                if element in self.files.legacy_elements:
                    node.tagName = node.nodeName = "xacro:" + node.tagName
        return dom

    def _count_parse(self, filename: str, size: int) -> None:
        """Bound the work of includes (MK008): a file included twice by each of 30 nested files is
        parsed 2^30 times though each file is read once."""
        self.parses += 1
        self.parsed_bytes += size
        limit = self.options.max_bytes
        if self.parses - 1 > MAX_INCLUDES or self.parsed_bytes > limit:
            what = (f"more than {MAX_INCLUDES:,} includes" if self.parses - 1 > MAX_INCLUDES
                    else f"more than {limit:,} bytes of included text")
            self.sink.emit(
                "MK008",
                f'including "{os.path.basename(filename)}" here would make {what} processed for this file '
                "(the same file included over and over, e.g. a diamond of includes); expansion stopped",
                self.here(),
                hint="include each file once (xacro files are usually included once and their macros called)",
            )
            raise Reported()

    # -- hooks ---------------------------------------------------------------------------------

    def tracked(self, function: Callable[..., Any], call: bool = False) -> Callable[..., Any]:
        """Wrap a function of xacro's that takes the element it works on first."""

        def wrapper(node: minidom.Element, *args: Any, **kwargs: Any) -> Any:
            self.stack.append(node)
            self.last_directive = None  # a directive is "current" only until xacro moves on
            try:
                return function(node, *args, **kwargs)
            except BaseException:
                if self.failed_node is None:
                    self.failed_node = node
                if call and self.failed_call is None:
                    self.failed_call = node
                raise
            finally:
                self.stack.pop()
                if self.failed_node is None:
                    self.last_directive = None

        wrapper.__wrapped__ = function  # type: ignore[attr-defined]
        return wrapper

    def eval_text(self, function: Callable[..., Any]) -> Callable[..., Any]:
        limit = self.options.max_bytes

        def wrapper(text: Any, symbols: Any) -> Any:
            if type(text) is str and "$" not in text:
                result: Any = text  # what xacro's lexer gives back for plain text, without lexing it
            else:
                try:
                    result = function(text, symbols)
                except BaseException:
                    if self.failed_text is None and isinstance(text, str):
                        self.failed_text = text
                    raise
            if isinstance(result, str) and len(result) > limit:
                self.failed_text = text if isinstance(text, str) else None
                raise ValueTooLarge()
            return result

        return wrapper

    def check_attrs(self, function: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(tag: minidom.Element, *args: Any) -> Any:
            self.last_directive = tag
            return function(tag, *args)

        return wrapper

    def here(self) -> SourceLocation:
        """Where xacro is now: the element it works on, else the file."""
        origin = self.origins.get(self.stack[-1]) if self.stack else None
        if origin is not None:
            return origin.loc()
        current = (self.xacro.filestack or [None])[-1] if self.xacro else None
        return SourceLocation(self.display_for(Path(current)) if current else self.display)

    def say(self, severity: Severity, args: tuple[object, ...]) -> None:
        text = " ".join(str(a) for a in args).strip()
        if not text:
            return
        code = "MK700" if severity is Severity.ERROR else "MK703"
        self.sink.emit(code, f"xacro: {' '.join(text.split())}", self.here(), severity=severity)

    def substitutions(self) -> dict[str, Callable[..., str]]:
        sa = substitution_args()

        environ = self.options.resolver.environ

        def find(package: str) -> str:
            current = (self.xacro.filestack or [None])[-1]
            found = find_package(self.options, package, Path(current or self.path), self.path)
            if found is None:
                raise PackageNotFound(package)
            self.sandbox.allow(found)
            return str(found)

        def env(name: str) -> str:
            if name not in environ:
                raise sa.SubstitutionException(f"environment variable '{name}' is not set")
            return environ[name]

        def optenv(name: str, default: str = "") -> str:
            return environ.get(name, default)

        return {"find": find, "env": env, "optenv": optenv}

    def load_yaml(self, filename: str) -> Any:
        """xacro's ``load_yaml``, reading only regular files inside the sandbox, counted with the
        includes (MK008) and refused when the YAML is too large or an alias bomb (:mod:`.yamlload`)."""
        from modelkit.formats.xacro.yamlload import YamlRefused, load_bounded  # imports PyYAML

        xacro = self.xacro
        filename = xacro.abs_filename_spec(filename)
        self.sandbox.check(filename)
        if not os.path.lexists(filename):
            raise YamlFileMissing(filename)
        try:
            data = read_regular(filename, self.options.max_bytes)
        except UnreadableFile as exc:
            exc.path = filename
            raise
        display = self.display_for(Path(filename))
        text = decode_text(data, display, self.sink)
        if text is None:
            raise Reported()
        self._count_parse(filename, len(text))
        xacro.filestack.append(filename)
        try:
            value = load_bounded(
                text, display, xacro.ConstructUnits, self.options.max_list_items, self.options.expansion_limit
            )
        except YamlRefused as refused:
            self.sink.add(refused.diagnostic)
            raise Reported() from refused
        finally:
            xacro.filestack.pop()
            xacro.all_includes.append(filename)
        return xacro.YamlListWrapper.wrap(value)

    # -- running -------------------------------------------------------------------------------

    def messages(self) -> dict[str, Callable[..., Any]]:
        def warning(*args: object, **kwargs: object) -> None:
            self.say(Severity.WARNING, args)

        def message(*args: object, **kwargs: object) -> None:
            self.say(Severity.INFO, args)

        def error(*args: object, **kwargs: object) -> None:
            self.say(Severity.ERROR, args)

        def print_location(*args: object, **kwargs: object) -> None:
            return None

        return {"warning": warning, "message": message, "error": error, "print_location": print_location}

    @contextlib.contextmanager
    def patched(self) -> Iterator[None]:
        """xacro with our hooks and fresh state; everything restored afterwards."""
        import xacro

        sa = substitution_args()
        self.xacro = xacro
        saved: list[tuple[Any, str, Any]] = []

        def put(target: Any, name: str, value: Any) -> None:
            saved.append((target, name, getattr(target, name)))
            setattr(target, name, value)

        try:
            put(xacro, "parse", _with_original(self.parse, xacro.parse))
            for name in ("eval_all", "process_include", "grab_property", "grab_macro"):
                put(xacro, name, self.tracked(getattr(xacro, name)))
            put(xacro, "handle_macro_call", self.tracked(xacro.handle_macro_call, call=True))
            put(xacro, "eval_text", self.eval_text(split_once_eval_text(xacro)))
            put(xacro, "check_attrs", self.check_attrs(xacro.check_attrs))
            put(xacro, "safe_eval", ExpressionGuard(xacro.XacroException).safe_eval)
            put(xacro, "load_yaml", self.load_yaml)
            put(xacro, "replace_node", splice.replace_node)  # xacro's own is quadratic in siblings
            for name, function in self.messages().items():
                put(xacro, name, function)
            substitutions = self.substitutions()
            for name, function in substitutions.items():
                put(sa, f"_eval_{name}", function)
            saved.append((sa, "_eval_dict", sa._eval_dict))
            sa._eval_dict = {**sa._eval_dict, **substitutions}
            put(xacro, "all_includes", [])
            put(xacro, "substitution_args_context", {})
            put(xacro, "filestack", None)
            put(xacro, "macrostack", None)
            put(xacro, "root_dir", os.curdir)
            put(xacro, "verbosity", 1)
            dummy = minidom.getDOMImplementation().createDocument(None, "dummy", None)
            put(xacro, "_empty_text_node", dummy.createTextNode("\n\n"))
            put(xacro, "_global_symbols", xacro.create_global_symbols())
            yield
        finally:
            for target, name, value in reversed(saved):
                setattr(target, name, value)

    def context(self) -> FailureContext:
        current = (self.xacro.filestack or [None])[-1]
        docs = list(self.files.docs.values())
        if current:
            first = self.files.docs.get(file_key(current))
            if first is not None:
                docs = [first] + [d for d in docs if d is not first]
        macros = [m.body.getAttribute("name") for m in (self.xacro.macrostack or [])]
        return FailureContext(
            origins=self.origins,
            docs=docs,
            fallback=SourceLocation(self.display_for(Path(current)) if current else self.display),
            failed_node=self.failed_node,
            failed_call=self.failed_call,
            last_directive=self.last_directive,
            failed_text=self.failed_text,
            macros=macros,
        )

    def run(self, top: XmlDocument) -> Expanded | None:
        self.files = scan_file_set(top, self.path, self.options, self.load)
        self.report_legacy(self.files.constructs)
        stray = io.StringIO()
        elements: list[minidom.Element] = []
        try:
            with _LOCK, self.patched(), contextlib.redirect_stdout(stray), contextlib.redirect_stderr(stray):
                try:
                    doc = self.xacro.process_file(
                        str(self.path), mappings=dict(self.options.xacro_args), verbosity=1
                    )
                except Exception as exc:
                    found = diagnose(exc, self.context())
                    if found is not None:
                        self.sink.add(found)
                    return None
                finally:
                    for line in stray.getvalue().splitlines():
                        self.say(Severity.WARNING, (line,))
                fallback = self.origins.get(doc.documentElement)
                top_loc = fallback.loc() if fallback else SourceLocation(self.display)
                origins = []
                elements = list(dom_elements(doc.documentElement))
                # The clones of one macro body element share its Origin: one location each.
                located: dict[int, SourceLocation] = {}
                for node in elements:
                    origin = self.origins.get(node)
                    if origin is None:
                        origins.append(top_loc)
                        continue
                    loc = located.get(id(origin))
                    if loc is None:
                        loc = located[id(origin)] = origin.loc()
                    origins.append(loc)
                return Expanded(pretty_xml(doc), origins)
        finally:
            self.origins.release(elements)  # the DOMs go now, by reference counting, not in a collection


def _sandbox(path: Path, options: ReadOptions) -> Sandbox:
    """Where xacro may read: the model's folder tree and the package folders given (``$(find)``
    adds each package it finds)."""
    sandbox = Sandbox()
    sandbox.allow(real_path(path).parent)
    sandbox.allow(model_root(path))
    resolver = options.resolver
    for folder in resolver.package_paths.values():
        sandbox.allow(folder)
    for entry in resolver.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            sandbox.allow(entry)
    for entry in resolver.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if entry:
            sandbox.allow(Path(entry) / "share")
    return sandbox


def _with_original(hook: Callable[..., Any], original: Callable[..., Any]) -> Callable[..., Any]:
    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is not None or filename is None:
            return original(inp, filename)
        return hook(filename)

    return parse


def expand(path: Path, options: ReadOptions, display: str, sink: DiagnosticSink) -> Expanded | None:
    """Expand an xacro file; diagnostics go to ``sink``; None when it cannot be expanded."""
    top = read_xml(path, sink, options.max_bytes, display)
    if top is None:
        return None
    return _Run(path, display, options, sink).run(top)


__all__ = ["Expanded", "expand", "legacy_diagnostic"]
