"""Which elements and attributes URDF defines, and the pass that reports the others.

One walk over the document, apart from the parsers: an element or attribute the URDF readers
(urdfdom, and so ROS, Gazebo, MuJoCo, PyBullet) ignore is almost always a typo, so it is reported
(MK123) with a "did you mean" hint. An element that may appear once but appears again is reported
too (MK124): urdfdom reads the first and ignores the rest.

Extension blocks are not checked inside: ``<gazebo>`` (libsdformat), ``<transmission>`` (ROS
control), ``<ros2_control>``, ``<mujoco>`` (MuJoCo's URDF extension), ``<sensor>`` (urdfdom's sensor
parser), and any element in a namespace other than the document's own.
"""

from __future__ import annotations

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.diagnostics import did_you_mean
from modelkit.formats.urdf.values import Context

EXTENSIONS = frozenset({"gazebo", "transmission", "ros2_control", "mujoco", "sensor"})
XINCLUDE = "http://www.w3.org/2001/XInclude"
XACRO = frozenset({"http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "http://wiki.ros.org/xacro"})
SHAPES = ("box", "cylinder", "sphere", "mesh", "capsule")

# PyBullet's extension: a link's <contact> (its importer reads these; urdfdom ignores the element).
PYBULLET_CONTACT = (
    "lateral_friction",
    "rolling_friction",
    "spinning_friction",
    "restitution",
    "contact_cfm",
    "contact_erp",
    "stiffness",
    "damping",
    "inertia_scaling",
    "friction_anchor",
)

# Allowed children of each URDF element (by tag; a tag means the same wherever it appears).
CHILDREN: dict[str, tuple[str, ...]] = {
    "robot": ("link", "joint", "material", *sorted(EXTENSIONS)),
    "link": ("inertial", "visual", "collision", "contact"),
    "contact": PYBULLET_CONTACT,
    "inertial": ("origin", "mass", "inertia"),
    "visual": ("origin", "geometry", "material"),
    "collision": ("origin", "geometry"),
    "geometry": SHAPES,
    "material": ("color", "texture"),
    "joint": (
        "origin",
        "parent",
        "child",
        "axis",
        "calibration",
        "dynamics",
        "limit",
        "mimic",
        "safety_controller",
    ),
}
ATTRIBUTES: dict[str, tuple[str, ...]] = {
    "robot": ("name", "version"),
    "link": ("name",),
    "joint": ("name", "type"),
    "material": ("name",),
    "color": ("rgba",),
    "texture": ("filename",),
    "visual": ("name",),
    "collision": ("name",),
    "origin": ("xyz", "rpy", "quat_xyzw"),
    "mass": ("value",),
    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
    "geometry": (),
    "inertial": (),
    "box": ("size",),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
    "mesh": ("filename", "scale"),
    "parent": ("link",),
    "child": ("link",),
    "axis": ("xyz",),
    "calibration": ("rising", "falling", "reference_position"),
    "dynamics": ("damping", "friction"),
    "limit": ("lower", "upper", "effort", "velocity", "acceleration", "deceleration", "jerk"),
    "mimic": ("joint", "multiplier", "offset"),
    "safety_controller": ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"),
    "contact": (),
    **{tag: ("value",) for tag in PYBULLET_CONTACT if tag != "friction_anchor"},
    "friction_anchor": (),
}
# Children that may appear at most once (urdfdom reads the first). Visuals and collisions repeat.
ONCE: dict[str, frozenset[str]] = {
    "link": frozenset({"inertial", "contact"}),
    "contact": frozenset(PYBULLET_CONTACT),
    "inertial": frozenset({"origin", "mass", "inertia"}),
    "visual": frozenset({"origin", "geometry", "material"}),
    "collision": frozenset({"origin", "geometry"}),
    "material": frozenset({"color", "texture"}),
    "joint": frozenset(CHILDREN["joint"]),
}
# Where a known element is misplaced, what the reader does with it.
_MISPLACED_NOTE = {
    ("collision", "material"): "materials are read only in <visual>",
    ("link", "origin"): "a link has no origin; put it in <inertial>, <visual>, <collision> or the joint",
    ("link", "gazebo"): "<gazebo> blocks are read only directly under <robot>, with reference=",
}


def check_structure(ctx: Context, root: Element) -> None:
    """Report unknown, misplaced and repeated elements and unknown attributes below ``<robot>``."""
    _check_attributes(ctx, root, "robot")
    stack: list[tuple[Element, str]] = [(root, "robot")]
    no_once: frozenset[str] = frozenset()
    while stack:
        element, tag = stack.pop()
        allowed = CHILDREN.get(tag)
        if allowed is None:  # a leaf element: nothing below it is read
            _check_leaf(ctx, element, tag)
            continue
        once = ONCE.get(tag, no_once)
        seen: set[str] = set()
        for child in element:
            raw = child.tag
            # a tag without a namespace is URDF's at once (every element is visited: keep this cheap)
            child_tag = raw if type(raw) is str and raw[:1] != "{" else ctx.tag(child)
            if child_tag is None:
                _foreign(ctx, child)
                continue
            if child_tag not in allowed and tag != "geometry":  # an unknown shape: the reader says so
                _unknown(ctx, child, child_tag, tag, allowed)
                continue
            if tag == "robot" and child_tag in EXTENSIONS:
                continue
            if child_tag in once and child_tag in seen:
                ctx.emit(
                    "MK124",
                    f"<{child_tag}> appears more than once in <{tag}>; only the first is read",
                    ctx.loc(child),
                )
            elif tag == "geometry" and seen:
                ctx.emit(
                    "MK124", "<geometry> holds more than one shape; only the first is read", ctx.loc(child)
                )
            seen.add(child_tag)
            if child_tag in allowed:
                _check_attributes(ctx, child, child_tag)
                stack.append((child, child_tag))


# MK123's words for a xacro element in a file read as URDF (convert's MK895 looks for them)
XACRO_INSTRUCTION = "is a xacro instruction"


def _foreign(ctx: Context, element: Element) -> None:
    """Comments and extension namespaces are fine; XInclude and xacro are not processed, so say so."""
    if not isinstance(element.tag, str):
        return
    qname = etree.QName(element)
    if qname.namespace == XINCLUDE:
        ctx.emit(
            "MK123",
            f'<{qname.localname} href="{element.get("href", "")}"> is XInclude, which URDF parsers do not '
            "process; it is not followed and adds nothing",
            ctx.loc(element),
            hint="use xacro:include to compose files",
        )
    elif qname.namespace in XACRO and not ctx.xacro_reported:  # once: the cure is the same for all
        ctx.xacro_reported = True
        ctx.emit(
            "MK123",
            f"<xacro:{qname.localname}> {XACRO_INSTRUCTION}, which URDF parsers ignore: this file must be "
            "expanded by xacro first",
            ctx.loc(element),
            hint="pass --input-format xacro or name the file .xacro (modelkit then expands it), or run xacro "
            "on it",
        )


def _unknown(ctx: Context, child: Element, child_tag: str, parent: str, allowed: tuple[str, ...]) -> None:
    note = _MISPLACED_NOTE.get((parent, child_tag))
    if note is None and (child_tag in CHILDREN or child_tag in ATTRIBUTES or child_tag in EXTENSIONS):
        note = f"<{child_tag}> is not read inside <{parent}>"
    message = f"<{parent}> has a child <{child_tag}> that URDF does not define; it is ignored"
    if note is not None:
        message = f"<{child_tag}> is misplaced in <{parent}>; it is ignored ({note})"
    ctx.emit("MK123", message, ctx.loc(child), hint=did_you_mean(child_tag, allowed))


def _check_attributes(ctx: Context, element: Element, tag: str) -> None:
    known = ATTRIBUTES.get(tag, ())
    for key in element.keys():  # noqa: SIM118  (an lxml element: keys() is its cheapest attribute walk)
        name = key.decode() if isinstance(key, bytes) else key
        if name in known or name.startswith("{"):  # "{ns}name": an attribute of another namespace
            continue
        ctx.emit(
            "MK123",
            f"<{tag}> has an attribute `{name}` that URDF does not define; it is ignored",
            ctx.loc(element, name),
            hint=did_you_mean(name, known),
        )


def _check_leaf(ctx: Context, element: Element, tag: str) -> None:
    """Elements of a leaf (``<box>``, ``<limit>``...) are not read; say so once per leaf."""
    for child in element:
        child_tag = ctx.tag(child)
        if child_tag is not None:
            ctx.emit(
                "MK123",
                f"<{tag}> has a child <{child_tag}>, but <{tag}> takes only attributes; it is ignored",
                ctx.loc(child),
            )
            return
