"""Reading URDF attribute values with diagnostics: numbers, vectors, origins.

Every helper reports what is wrong at the exact attribute (``file:line:col``) and returns None, so
the caller can carry on with a default. Number syntax is urdfdom's (see :mod:`modelkit.xmlsource`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from lxml import etree
from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation
from modelkit.spatial import Pose
from modelkit.xmlsource import XmlDocument, parse_number, parse_numbers

# URDF versions modelkit reads, and the version that introduced each later feature.
VERSIONS = ("1.0", "1.1", "1.2")


@dataclass
class Context:
    """What every part of the URDF reader shares: the document, the sink and the declared version."""

    doc: XmlDocument
    sink: DiagnosticSink
    version: str = "1.0"
    version_declared: bool = False
    namespace: str | None = None  # the <robot> element's own namespace (a default xmlns), if any
    newer_features: list[tuple[str, str, SourceLocation]] = field(default_factory=list)
    xacro_reported: bool = False

    def loc(self, element: Element, attribute: str | None = None) -> SourceLocation:
        return self.doc.loc(element, attribute)

    def text_loc(self, element: Element) -> SourceLocation:
        return self.doc.text_loc(element)

    def emit(
        self,
        code: str,
        message: str,
        loc: SourceLocation | None,
        hint: str | None = None,
        severity: Severity | None = None,
    ) -> None:
        self.sink.emit(code, message, loc, hint=hint, severity=severity)

    def tag(self, element: Element) -> str | None:
        """The element's URDF name, or None for comments, processing instructions and foreign elements.

        An element in the ``<robot>`` element's own namespace (a default ``xmlns``) counts as URDF;
        an element of any other namespace (``xmlns:drake``...) is an extension and is skipped.
        """
        tag = element.tag
        if not isinstance(tag, str):
            return None
        if not tag.startswith("{"):  # no namespace: the common case, without building a QName
            return tag
        qname = etree.QName(element)
        if qname.namespace is None or qname.namespace == self.namespace:
            return qname.localname
        return None

    def children(self, element: Element, name: str | None = None) -> list[Element]:
        """URDF child elements of ``element`` (all, or those called ``name``), in document order."""
        if name is not None and self.namespace is None:
            # a document without a default namespace: exactly the children whose tag is ``name``
            # (comments, processing instructions and namespaced elements never match), found by lxml
            return list(element.iterchildren(name))
        out = []
        for child in element:
            raw = child.tag
            # no namespace, the common case, at once; comments and namespaced elements by the full rule
            tag = raw if type(raw) is str and not raw.startswith("{") else self.tag(child)
            if tag is not None and (name is None or tag == name):
                out.append(child)
        return out

    def first(self, element: Element, name: str) -> Element | None:
        """The first child called ``name`` (urdfdom reads only the first; repeats are reported apart)."""
        if self.namespace is None:
            return next(element.iterchildren(name), None)  # the first child `children` would give
        found = self.children(element, name)
        return found[0] if found else None

    def uses_feature(self, feature: str, needs: str, loc: SourceLocation) -> None:
        """Note a URDF 1.1/1.2 feature; reported when the document declares an older version."""
        self.newer_features.append((feature, needs, loc))


@dataclass(frozen=True)
class Tolerated:
    """A place where urdfdom logs a number it cannot read and loads the file all the same (check_urdf
    exits 0): such a number is reported with ``code`` (a warning; an error only under the ``validate
    --target`` that refuses it) instead of MK121, and ``consequence`` says what each consumer does.
    ``{atof}`` in it is replaced by what PyBullet reads (C's ``atof`` of the text)."""

    code: str
    consequence: str

    def message(self, what: str, text: str) -> str:
        return f"{what}; " + self.consequence.replace("{atof}", f"{c_atof(text):g}")


_ATOF_PREFIX = re.compile(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)")


def c_atof(text: str) -> float:
    """What C's ``atof`` makes of ``text`` (PyBullet's URDF reader): its longest leading decimal
    number, 0 when it starts with none ("1,5" is 1, "MASS" is 0)."""
    match = _ATOF_PREFIX.match(text)
    return float(match.group(1)) if match else 0.0


def number(
    ctx: Context,
    element: Element,
    attribute: str,
    what: str,
    default: float | None = None,
    required: bool = False,
    tolerated: Tolerated | None = None,
) -> float | None:
    """The attribute as a number; a missing required one or a malformed one is reported (None back;
    ``tolerated``: where urdfdom loads the file all the same, see :class:`Tolerated`)."""
    text = element.get(attribute)
    if text is None:
        if required:
            ctx.emit(
                "MK120",
                f"<{ctx.tag(element)}> has no `{attribute}` attribute ({what})",
                ctx.loc(element),
            )
        return default
    value = parse_number(text)
    if value is None:
        said = f'{what}: `{attribute}="{text}"` is not a number'
        if tolerated is not None:
            ctx.emit(tolerated.code, tolerated.message(said, text), ctx.loc(element, attribute))
        else:
            ctx.emit("MK121", said, ctx.loc(element, attribute))
        return None
    if not math.isfinite(value):
        ctx.emit("MK121", f'{what}: `{attribute}="{text}"` is not finite', ctx.loc(element, attribute))
        return None
    return value


def vector(ctx: Context, element: Element, attribute: str, what: str, count: int = 3,
           tolerated: Tolerated | None = None) -> list[float] | None:
    """The attribute as exactly ``count`` blank-separated numbers; None (reported) otherwise
    (``tolerated``: a word where a number should be, where urdfdom loads the file all the same)."""
    text = element.get(attribute)
    if text is None:
        return None
    values = parse_numbers(text)
    if values is None:
        bad = next((item for item in text.split() if parse_number(item) is None), text)
        where = ctx.loc(element, attribute)
        said = f'{what}: `{attribute}="{text}"`: "{bad}" is not a number'
        if tolerated is not None:
            ctx.emit(tolerated.code, tolerated.message(said, bad), where)
        else:
            ctx.emit("MK121", said, where)
        return None
    if len(values) != count:
        ctx.emit(
            "MK121",
            f'{what}: `{attribute}="{text}"`: expected {count} numbers, found {len(values)}',
            ctx.loc(element, attribute),  # located only when reported: a position costs a scan of the tag
        )
        return None
    if not all(math.isfinite(v) for v in values):
        where = ctx.loc(element, attribute)
        ctx.emit("MK121", f'{what}: `{attribute}="{text}"` has a value that is not finite', where)
        return None
    return values


def origin(ctx: Context, element: Element | None, what: str, tolerated: Tolerated | None = None
           ) -> Pose | None:
    """The pose of an ``<origin xyz rpy quat_xyzw>`` element (identity when absent).

    None when the origin is malformed (already reported); callers fall back to identity.
    ``tolerated``: a word where a number should be, where urdfdom loads the file all the same.
    """
    if element is None:
        return Pose()
    ok = True
    pose = Pose()
    xyz = vector(ctx, element, "xyz", f"{what} origin", tolerated=tolerated)
    if xyz is not None:
        pose.translation = rot3.vec3(xyz)
    elif element.get("xyz") is not None:
        ok = False
    has_rpy = element.get("rpy") is not None
    has_quat = element.get("quat_xyzw") is not None
    if has_rpy and has_quat:
        ctx.emit(
            "MK137",
            f"{what} origin gives both `rpy` and `quat_xyzw`; give one orientation only",
            ctx.loc(element, "quat_xyzw"),
            hint="URDF 1.1 forbids both; tools disagree on which one wins",
        )
        return None
    if has_rpy:
        rpy = vector(ctx, element, "rpy", f"{what} origin", tolerated=tolerated)
        if rpy is None:
            ok = False
        else:
            pose.rotation = rot3.from_rpy(*rpy)
    elif has_quat:
        ctx.uses_feature("`quat_xyzw`", "1.1", ctx.loc(element, "quat_xyzw"))
        quat = vector(ctx, element, "quat_xyzw", f"{what} origin", count=4, tolerated=tolerated)
        if quat is None:
            ok = False
        else:
            norm = math.sqrt(sum(q * q for q in quat))
            if norm == 0.0:
                ctx.emit(
                    "MK121",
                    f"{what} origin: `quat_xyzw` is the zero quaternion, which is no rotation",
                    ctx.loc(element, "quat_xyzw"),
                )
                ok = False
            else:
                x, y, z, w = quat
                pose.rotation = rot3.from_quat_wxyz((w, x, y, z))
    return pose if ok else None
