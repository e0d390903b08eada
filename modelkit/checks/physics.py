"""Rules about mass properties and joint ranges."""

from __future__ import annotations

import math
from collections.abc import Iterator

from modelkit import rot3
from modelkit.checks.masses import body_mass_properties, lumped_masses, welded_bodies
from modelkit.checks.registry import rule
from modelkit.diagnostics import Diagnostic, Severity, SourceLocation, diag
from modelkit.model import JointType, Link, Robot
from modelkit.spatial import Pose

# Who fills in missing mass properties, per source format (the wording of MK304).
DEFAULTS_APPLIED_BY = {"body": "Choreonoid uses", "sdf": "SDFormat's defaults apply"}
DEFAULTS_HINT = {
    "body": "give mass, center_of_mass and inertia",
    "sdf": "give <inertial> a <mass> and an <inertia>",
}


def moving_links(robot: Robot) -> set[str]:
    """Links that move relative to the world: below a moving joint, the floating root, or a link no joint
    connects to the tree that floats as a separate body (SDF, MK201), with what hangs from it."""
    moving: set[str] = set()
    if robot.root is not None and robot.root_joint is JointType.FLOATING:
        moving.add(robot.root)
    children = robot.children_of()
    stack = [(robot.root, robot.root in moving)] if robot.root else []
    if robot.free_links_float:
        stack += [(name, True) for name in robot.free_link_poses]
    seen: set[str] = set()
    while stack:
        name, moves = stack.pop()
        if name is None or name in seen:
            continue
        seen.add(name)
        if moves:
            moving.add(name)
        for joint in children.get(name, []):
            stack.append((joint.child, moves or joint.type.moves))
    return moving


def _merged_masses(robot: Robot) -> dict[str, float]:
    """Mass of each rigid body, keyed by its top link; a link on a fixed joint counts as massive.

    Links joined by fixed joints form one rigid body. The top link gets the body's total mass; a
    link attached by a fixed joint gets +inf, since its own mass does not matter on its own.
    """
    out = lumped_masses(robot)
    out.update({j.child: float("inf") for j in robot.joints if j.type is JointType.FIXED})
    return out


def _mass_loc(link: Link) -> SourceLocation | None:
    inertial = link.inertial
    if inertial is None:
        return link.source
    return inertial.sources.get("mass", inertial.source or link.source)


@rule("mass", "MK300", "MK304", "MK313")
def mass(robot: Robot) -> Iterator[Diagnostic]:
    """Masses are positive where it matters; default mass properties are flagged."""
    if robot.masses_unknown:
        return  # e.g. MuJoCo could not compile the file: masses it would infer from geoms are unknown
    moving = moving_links(robot)
    merged = _merged_masses(robot)
    carried: dict[str, float] | None = None  # subtree masses, computed when first needed
    for link in robot.links:
        inertial = link.inertial
        if link.synthesised:
            continue  # a link the reader made up (MJCF intermediate frames, a world link to hang from)
        if inertial is None:
            # A link without mass information (URDF/SDF) hung on a fixed joint is part of its
            # parent's rigid body, and engines merge it; the body as a whole needs mass.
            if link.name in moving and merged.get(link.name, 0.0) <= 0.0:
                yield _no_mass_information(robot, link)
            continue
        if inertial.defaulted and link.name in moving:
            what = "no mass information" if "mass" not in inertial.sources else "no inertia"
            who = DEFAULTS_APPLIED_BY.get(robot.source_format, "the format's defaults apply")
            yield diag(
                "MK304",
                f'link "{link.name}" has {what}: {who}: '
                f"{'1 kg and ' if 'mass' not in inertial.sources else ''}an identity inertia (1 kg·m²)",
                _mass_loc(link),
                hint=DEFAULTS_HINT.get(robot.source_format, "give the mass and the inertia"),
            )
        if inertial.mass < 0:
            yield diag(
                "MK300", f'link "{link.name}" has a negative mass ({inertial.mass:g} kg)', _mass_loc(link)
            )
        elif inertial.mass == 0 and link.name in moving and merged.get(link.name, 0.0) <= 0.0:
            if carried is None:
                carried = lumped_masses(robot, every_joint=True)  # each link's subtree
            if carried.get(link.name, 0.0) > 0.0:  # its joint moves the massive links below it
                yield diag(
                    "MK313",
                    f'link "{link.name}" moves but its mass is zero; the links below it have mass, so its '
                    f"joint can be simulated (PyBullet, Pinocchio), but {MASSLESS_BODY_REFUSED}",
                    _mass_loc(link),
                    severity=Severity.WARNING,
                )
                continue
            yield _massless_chain(robot, link)


# A massless body that moves links with mass (MK313, a warning): who refuses it. An error under --target mjcf.
MASSLESS_BODY_REFUSED = "MuJoCo refuses a moving body without mass"


# Who loads a moving link whose mass is zero, like everything below it (MK313). Where the file's own loader
# takes it (URDF: check_urdf) it is a warning, an error under --target mjcf; elsewhere an error.
MASSLESS_CHAIN_CONSUMERS = (
    "check_urdf accepts it (urdfdom keeps the zero mass), PyBullet loads it and freezes the joint (a "
    "velocity motor leaves it at 0), MuJoCo refuses it"
)


def _massless_chain(robot: Robot, link: Link) -> Diagnostic:
    """MK313 for a moving link whose joint moves nothing with mass."""
    what = (
        f'link "{link.name}" moves but its mass is zero, and so does everything below it: its joint moves '
        "nothing with mass"
    )
    if robot.source_format == "urdf":
        return diag(
            "MK313",
            f"{what}; {MASSLESS_CHAIN_CONSUMERS}",
            _mass_loc(link),
            hint="give the link its mass and inertia, or make its joint fixed",
            severity=Severity.WARNING,
        )
    return diag("MK313", f"{what}, which cannot be simulated (MuJoCo refuses it)", _mass_loc(link))


# MK313 for a moving link without <inertial> in a format whose loader accepts it (URDF: check_urdf
# reads kinematic-only models): who fills the gap and who refuses it. An error under --target mjcf.
NO_INERTIAL_CONSUMERS = (
    "check_urdf accepts it (a kinematic-only model), PyBullet gives it 1 kg and a tiny inertia, "
    "libsdformat's URDF conversion drops it, MuJoCo refuses it"
)


def _no_mass_information(robot: Robot, link: Link) -> Diagnostic:
    """MK313 for a moving link without ``<inertial>``: a warning where the file's own loader accepts it."""
    if robot.source_format == "urdf":
        return diag(
            "MK313",
            f'link "{link.name}" moves but has no <inertial> (kinematics only, no dynamics); '
            f"{NO_INERTIAL_CONSUMERS}",
            link.loc("name"),
            hint="give it an <inertial> with its mass and inertia to simulate the model",
            severity=Severity.WARNING,
        )
    return diag("MK313", f'link "{link.name}" moves but has no mass', link.loc("name"))


# What a loader does with an asymmetric 9-element inertia (MK301, a warning: Choreonoid loads the file).
ASYMMETRIC_INERTIA_CONSUMERS = (
    "Choreonoid uses the matrix as given, which no rigid body has; convert writes its upper triangle"
)
# Larger masses or inertia components are refused: the parallel-axis sums, the principal moments and
# an engine's mass matrix square and add them, which overflows double precision near 1e154 (a 1e308
# inertia made the eigenvalue solver fail, and its moments came out as zero). No real body is near.
MAX_MASS_PROPERTY = 1e100
# Who loads an inertia that breaks the triangle inequality (MK303), and who refuses it.
IMPOSSIBLE_INERTIA_CONSUMERS = (
    "Choreonoid, check_urdf and PyBullet load it, MuJoCo and libsdformat (Gazebo) refuse it"
)
# Source formats whose own loader refuses such an inertia: there MK303 is an error.
IMPOSSIBLE_INERTIA_REFUSED_BY = frozenset({"mjcf", "sdf"})


# A principal moment at or below MuJoCo's mjMINVAL (kg·m²) counts as zero, also when rounding made it
# slightly negative (-2e-35 beside 2e-35 in a real URDF is a zero inertia, not a negative one).
ZERO_MOMENT = 1e-15


# Who loads a moving body with a zero principal moment (MK302), and who refuses it.
SINGULAR_INERTIA_CONSUMERS = (
    "Choreonoid, check_urdf, PyBullet and libsdformat (Gazebo) load it, MuJoCo refuses it"
)


def _singular_inertia_severity(robot: Robot, severity: Severity | None) -> Severity | None:
    """MK302 for a zero principal moment: an error in MJCF (MuJoCo refuses it), else a warning."""
    if severity is Severity.WARNING or robot.source_format != "mjcf":
        return Severity.WARNING
    return None


def _impossible_inertia_severity(robot: Robot) -> Severity:
    """MK303: an error where the file's own loader refuses it, else a warning (``--target`` raises it)."""
    return Severity.ERROR if robot.source_format in IMPOSSIBLE_INERTIA_REFUSED_BY else Severity.WARNING


@rule("inertia", "MK301", "MK302", "MK303")
def inertia(robot: Robot) -> Iterator[Diagnostic]:
    """Inertia tensors are symmetric, positive definite and satisfy the triangle inequality.

    The tolerance is libsdformat's (gz-math ``MassMatrix3::IsValid``): ε = 10 · machine-ε · the
    largest principal moment. Where the file's own loader does not judge inertia link by link (URDF,
    ``.body``), links joined by fixed joints are judged as the one rigid body engines merge them into:
    a point mass on a sensor frame or a tool flange welded to an arm is not a finding.
    """
    moving = moving_links(robot)
    if robot.root is not None and robot.root_joint is None:
        # A root the format leaves open (a URDF root other than "world") floats in PyBullet and Gazebo
        # unless the loader is told to fix it: its inertia matters.
        moving.add(robot.root)
    welded = welded_bodies(robot) if robot.source_format in MERGED_BY_ENGINES else {}
    merged_into = {name: head for head, members in welded.items() if len(members) > 1 for name, _ in members}
    for link in robot.links:
        inertial = link.inertial
        if inertial is None or inertial.mass <= 0:
            continue
        where = inertial.sources.get("inertia", _mass_loc(link))
        tensor = rot3.mat3(rot3.peek(inertial, "inertia"))  # plain floats: no numpy on the validate path
        if not (rot3.all_finite(tensor) and math.isfinite(inertial.mass)):  # e.g. 1e400 in the file
            yield diag("MK302", f'link "{link.name}": the mass or inertia is not a finite number', where)
            continue
        largest = max(inertial.mass, *(abs(x) for row in tensor for x in row))
        if largest > MAX_MASS_PROPERTY:  # e.g. 1e308: finite, but no arithmetic on it stays finite
            yield diag(
                "MK302",
                f'link "{link.name}": the mass or inertia is too large to compute with ({largest:.6g} > '
                f"{MAX_MASS_PROPERTY:g}: sums and products of it overflow)",
                where,
            )
            continue
        # A link welded to the world is never simulated dynamically: its inertia is still wrong, but
        # harmless, so the finding is a warning there.
        severity = None if link.name in moving else Severity.WARNING
        static = "" if link.name in moving else " (the link does not move, so simulators ignore it)"
        if rot3.is_asymmetric(tensor):
            skew = rot3.inertia_skew(tensor)
            yield diag(
                "MK301",
                f'link "{link.name}": the inertia matrix is not symmetric (off-diagonal pairs differ by up '
                f"to {skew:.6g}); {ASYMMETRIC_INERTIA_CONSUMERS}{static}",
                where,
                hint="give the same value to each off-diagonal pair (row-major: xy = yx, xz = zx, yz = zy)",
            )
            # judged further as what every target gets: convert writes the upper triangle
            tensor = rot3.upper_symmetric(tensor)
            upper = " (its upper triangle, which convert writes)"
        else:
            upper = ""
        head = merged_into.get(link.name)
        if head is None:
            what = f'link "{link.name}"{upper}'
            yield from _judge_inertia(robot, what, inertial.mass, tensor, where, severity, static)
        else:
            yield from _negative_moment_in_body(link, tensor, head, where)
    links = {link.name: link for link in robot.links}
    for head, members in welded.items():
        if len(members) < 2:
            continue
        total, _, tensor = body_mass_properties(links, members)
        if total <= 0.0 or total > MAX_MASS_PROPERTY or not rot3.all_finite(tensor) or max(
            abs(x) for row in tensor for x in row
        ) > MAX_MASS_PROPERTY:
            continue  # a massless body is MK313's; a non-finite or huge member was reported above
        names = ", ".join(f'"{name}"' for name, _ in members)
        what = f'the rigid body of link "{head}" (links {names} joined by fixed joints, merged as engines do)'
        severity = None if head in moving else Severity.WARNING
        static = "" if head in moving else " (the body does not move, so simulators ignore it)"
        yield from _judge_inertia(robot, what, total, tensor, _body_loc(links, members), severity, static)


# Source formats whose own loader refuses a negative principal moment on any link, moving or not.
NEGATIVE_MOMENT_REFUSED_BY = {
    "sdf": 'libsdformat refuses the whole file ("A link named ... has invalid inertia")',
}

# Source formats whose loader does not judge a welded link's inertia on its own: there links welded by fixed
# joints are judged as one body. MuJoCo judges only bodies with joints (and refuses the file itself, MK170,
# where such a body alone is too light); libsdformat refuses a bad inertia on any SDF link.
MERGED_BY_ENGINES = frozenset({"urdf", "body", "mjcf"})


def _judge_inertia(
    robot: Robot,
    what: str,
    mass: float,
    tensor: rot3.M3,
    where: SourceLocation | None,
    severity: Severity | None,
    static: str,
) -> Iterator[Diagnostic]:
    """MK302 (zero or not positive definite) or MK303 (triangle inequality) for one link or welded body.

    A negative principal moment cannot be simulated meaningfully: an error where the body moves. A zero
    one (a point mass, a rod) is physically impossible but loaded by Choreonoid, check_urdf, PyBullet and
    libsdformat (gz-math takes a moment near zero) and refused by MuJoCo: an error in MJCF, else a
    warning naming MuJoCo (``--target mjcf`` raises it).
    """
    moments = rot3.symmetric_eigenvalues(tensor)  # of the symmetric part: rounding asymmetry ignored
    zero = max(rot3.inertia_tolerance(moments), ZERO_MOMENT)
    listed = ", ".join(f"{m:.6g}" for m in moments)
    if moments[0] < -zero:  # indefinite: a negative moment
        said = f"{what}: the inertia is not positive definite (principal moments {listed}){static}"
        if static and robot.source_format in NEGATIVE_MOMENT_REFUSED_BY:  # libsdformat: any link
            said = (f"{what}: the inertia is not positive definite (principal moments {listed}); the link "
                    f"does not move, but {NEGATIVE_MOMENT_REFUSED_BY[robot.source_format]}")
            severity = None
        yield diag("MK302", said, where, severity=severity)
        return
    if moments[0] <= zero:  # no finite acceleration about that axis
        singular = _singular_inertia_severity(robot, severity)
        refused = f"; {SINGULAR_INERTIA_CONSUMERS}" if singular is Severity.WARNING and not static else ""
        if all(abs(m) <= zero for m in moments):
            said = f"{what} has mass {mass:g} kg but a zero inertia{static}{refused}"
        else:
            said = (f"{what}: the inertia is not positive definite (a zero principal moment) (principal "
                    f"moments {listed}){static}{refused}")
        yield diag("MK302", said, where, severity=singular)
        return
    eps = rot3.inertia_tolerance(moments)
    a, b, c = moments
    if a + b < c - eps:
        yield diag(
            "MK303",
            f"{what}: principal moments {a:.6g}, {b:.6g}, {c:.6g} violate the triangle inequality "
            f"({a:.6g} + {b:.6g} < {c:.6g}){static}; {IMPOSSIBLE_INERTIA_CONSUMERS}",
            where,
            severity=_impossible_inertia_severity(robot),
        )


def _negative_moment_in_body(
    link: Link, tensor: rot3.M3, head: str, where: SourceLocation | None
) -> Iterator[Diagnostic]:
    """A welded link's own inertia is judged only for impossible data (a negative principal moment); a
    point mass or a rod welded to a body is physical."""
    moments = rot3.symmetric_eigenvalues(tensor)
    if moments[0] < -rot3.inertia_tolerance(moments):
        yield diag(
            "MK302",
            f'link "{link.name}": the inertia is not positive definite (principal moments '
            f"{', '.join(f'{m:.6g}' for m in moments)}); engines merge the link into the rigid body of "
            f'"{head}", which is judged as a whole',
            where,
            severity=Severity.WARNING,
        )


def _body_loc(links: dict[str, Link], members: list[tuple[str, Pose]]) -> SourceLocation | None:
    """Where a welded body's inertia is written: its heaviest link's inertia."""
    heaviest = max(
        (link for link in (links.get(name) for name, _ in members) if link is not None and link.inertial),
        key=lambda link: link.inertial.mass if link.inertial else 0.0,
    )
    inertial = heaviest.inertial
    return inertial.sources.get("inertia", _mass_loc(heaviest)) if inertial else heaviest.source


# The formats whose own loader takes a joint range with its lower limit above its upper (MK307: a
# warning there), and who loads it. MuJoCo refuses it ("range[0] should be smaller than range[1]").
REVERSED_RANGE_LOADED_BY = {
    "urdf": "urdfdom, libsdformat's URDF conversion, PyBullet and MuJoCo load it",
    "sdf": "libsdformat and its checker `gz sdf -k` load it",
    "body": "Choreonoid's body loader takes it and sets the range as written",
}


@rule("joint-ranges", "MK307", "MK315")
def joint_ranges(robot: Robot) -> Iterator[Diagnostic]:
    """Joint position and velocity ranges are ordered."""
    for joint in robot.joints:
        limits = joint.limits
        if limits.lower > limits.upper:
            loaded_by = REVERSED_RANGE_LOADED_BY.get(robot.source_format or "")
            yield diag(
                "MK307",
                f'joint "{joint.name}": lower limit {limits.lower:.6g} is above upper limit '
                f"{limits.upper:.6g}"
                + (f"; no position is within the limits ({loaded_by})" if loaded_by else ""),
                joint.loc("range"),
                severity=Severity.WARNING if loaded_by else None,
            )
        if limits.velocity_lower > limits.velocity_upper:
            yield diag(
                "MK315",
                f'joint "{joint.name}": velocity range [{limits.velocity_lower:.6g}, '
                f"{limits.velocity_upper:.6g}] is reversed",
                joint.loc("velocity_range"),
            )
