"""The body tree of the MJCF writer: bodies, inertials and joints.

* One ``<body>`` per link, nested as the tree, named after the link; ``pos``/``quat`` (w x y z) =
  the joint origin. Fixed joints (and any pseudo continuous track left, MK813) write no joint: the
  body is welded to its parent and kept, never lumped.
* The root body sits at ``root_pose``: ``FLOATING`` → ``<freejoint/>``; ``FIXED`` → no joint;
  None (URDF leaves it open) → ``<freejoint/>`` with an MK814 note. A root link named ``world``
  is MuJoCo's world body itself: its children become top-level bodies (MK814).
* revolute → ``hinge``, prismatic → ``slide`` (``axis`` in the body frame, anchored at the body
  origin; ``range`` only when both limits are finite, ``autolimits`` makes it limited), ball →
  ``ball``, planar → two slides and a hinge named ``<joint>_tx``, ``<joint>_ty``, ``<joint>_rz``
  (MK813). MuJoCo allows a free joint on top-level bodies only, so a floating joint inside the tree
  makes its subtree a top-level body with ``<freejoint/>`` at its pose in the world at q = 0 (as
  Choreonoid's own MuJoCo plugin does; MK813).
* ``damping``, ``frictionloss``, ``armature``, ``stiffness``/``springref`` as given (a ball joint:
  ``stiffness`` only, pulling towards its zero orientation); a finite effort limit →
  ``actuatorfrcrange``; initial positions → the ``home`` keyframe (writer.py).
* Inertials: ``<inertial pos mass diaginertia>`` when the tensor is diagonal, else ``fullinertia="Ixx
  Iyy Izz Ixy Ixz Iyz"``, or ``quat`` and ``diaginertia`` (the principal axes and moments) when a
  product is under 1e-9 kg·m² and that form is clean, or the smallest moment is nearly zero
  (:func:`_principal`), or its numbers are plainer (a source's own ``quat``/``diaginertia``:
  :mod:`.principal_text`); MuJoCo never recomputes them (``inertiafromgeom="false"``). A massless link on
  a fixed joint is a body without ``<inertial>`` (MK816). MuJoCo refuses a moving body whose weld
  group (the body and what is welded to it) has no mass or a singular inertia; such a body gets
  ``MIN_MASS`` kg and/or ``MIN_INERTIA`` kg·m² on each principal axis at its origin (MK816 / MK819,
  the note says the value).
* A chain the MJCF reader made from a multi-joint MuJoCo body is written back as that one body with
  its joints (:mod:`.write_chains`): no massless moving bodies, so no made-up mass.
* Frame links (:func:`modelkit.convert.frames.frame_links`: massless, on fixed joints, carrying
  nothing) are ``<site name pos quat>``s in the nearest body above them, their poses composed up to it,
  written after that body's own contents in tree order (``WriteOptions.frame_sites``; one MK873 note
  lists them); an MJCF source's sites on a frame link go with it, at their pose in it. With
  ``frame_sites`` off they are bodies without ``<inertial>`` (MK816).
* An MJCF source's sites (``mjcf_sites``) in the body of their link, at their pose, with their type,
  size, group and colour: every one of them from an MJCF source (the source's own sensors refer to
  them, :mod:`.write_own`), only those naming a frame from another (:mod:`.site_frames`).
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.frames import frame_links
from modelkit.convert.numbers import clean_inertia, fmt, fmt_direction, fmt_position, fmt_tensor, fmt_vec
from modelkit.convert.servo_gains import home_position
from modelkit.formats.mjcf.principal_text import principal_text
from modelkit.formats.mjcf.site_frames import named_frames, own_sites, site_pose
from modelkit.formats.mjcf.write_chains import Chain, ChainFinder, shifted
from modelkit.formats.mjcf.write_devices import DeviceWriter
from modelkit.formats.mjcf.write_geoms import GeomWriter
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, quat_wxyz, set_pose, sub
from modelkit.model import WORLD_LINK, Inertial, Joint, JointType, Link, Robot
from modelkit.spatial import Pose, combine_mass_properties, principal_moments, rotate_inertia

MIN_MASS = 1e-6  # kg, given to a moving body whose weld group has no mass
MIN_INERTIA = 1e-9  # kg·m², added on each axis when the weld group's inertia is singular
PLATE_MARGIN = 1e-10  # relative: how far above a + b = c a full tensor is raised (mujoco_valid_inertia)
DEFAULT_SITE_SIZE = 0.005  # m: MuJoCo's default site size (a sphere of this radius)
SINGULAR = 1e-12  # below this a mass counts as zero (MuJoCo's mjMINVAL is 1e-15)
# Below these a moving body's smallest principal moment counts as zero: MuJoCo refuses a diagonal
# inertia under mjMINVAL (1e-15) and a fullinertia whose smallest eigenvalue is under mjEPS (1e-14;
# measured: 6.7e-15 refused, 1.3e-14 taken); each with a 10× margin. pybullet_data's thrower.xml has
# a wrist of 7.96e-14 kg·m² that MuJoCo itself compiled: it is written as it is.
SINGULAR_DIAGONAL = 1e-14
SINGULAR_FULL = 1e-13
# kg·m²: a product of inertia under this is written in the tensor's principal form (_principal)
UNREADABLE_PRODUCT = 1e-9
WELL_APART = 1e-6  # relative: principal moments closer than this leave their axes to round-off
PLANAR_NOTE = re.compile(r'planar joint "(?P<joint>.+)" written as two slides and a hinge '
                         r'\("(?P<x>[^"]+)", "(?P<y>[^"]+)", "(?P<z>[^"]+)"\)$')
"""The MK813 note of a planar joint (:meth:`BodyTree._planar`): verify reads the written joints back."""
MOVING = (JointType.REVOLUTE, JointType.PRISMATIC, JointType.BALL, JointType.PLANAR, JointType.FLOATING)

def _principal_form(tensor: np.ndarray) -> bool:
    """A tensor with products of inertia whose smallest principal moment is under
    :data:`SINGULAR_FULL` is written as ``diaginertia`` and ``quat`` (its principal moments and axes):
    MuJoCo checks those against mjMINVAL, while a ``fullinertia`` goes through an eigen-decomposition
    that refuses a smallest eigenvalue under mjEPS. dm_control's fruit fly has leg segments of
    2.5e-13 kg·m² whose smallest moment is 4e-14: they were lifted by 1e-9 kg·m² per axis before."""
    if _diagonal(tensor):
        return False
    return float(np.min(np.linalg.eigvalsh(0.5 * (tensor + tensor.T)))) < SINGULAR_FULL


def _principal(tensor: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The principal moments and axes to write as ``diaginertia`` and ``quat``, or None for
    ``fullinertia``/``diaginertia`` as given.

    * :func:`_principal_form`: a nearly singular tensor (MuJoCo checks a principal form against
      mjMINVAL, a full one against mjEPS).
    * A product of inertia ``fullinertia`` would print under :data:`UNREADABLE_PRODUCT` (a SolidWorks
      export's ``ixz="-3.7e-10"`` beside a finger's 2.6e-6 kg·m²), when the principal form prints
      none: well-defined axes (moments apart by :data:`WELL_APART` of the largest: no eigenvector left
      to round-off) whose quaternion has no component under 1e-9 but 0. It is written as MuJoCo's
      compiler and Menagerie write inertias, to 1e-15 of the same tensor. Otherwise ``fullinertia``
      keeps the source's numbers: ANYmal B's leg adapters have products of 1e-11 beside two moments
      4e-10 apart (axes left to round-off), the hextilt arm's ``-5.0883e-13`` beside moments far apart
      turns the axes by 2e-9 rad (a quaternion component of 9.9e-10)."""
    if _principal_form(tensor):
        return principal_axes_near_link(tensor)
    products = (float(tensor[0, 1]), float(tensor[0, 2]), float(tensor[1, 2]))
    if not any(0.0 < abs(p) < UNREADABLE_PRODUCT for p in products):
        return None
    moments, axes = principal_axes_near_link(tensor)
    ordered = np.sort(moments)
    if float(np.min(np.diff(ordered))) < WELL_APART * float(ordered[-1]):
        return None
    if any(0.0 < abs(q) < UNREADABLE_PRODUCT for q in quat_wxyz(axes)):
        return None
    return moments, axes


def principal_axes_near_link(tensor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The principal moments and axes (a rotation, columns), the axes ordered and signed to be nearest
    the link's own: a tensor with products of 1e-11 beside moments of 1e-3 gets a quaternion within
    1e-8 of the identity, not a permutation of the axes (eigh's ascending order)."""
    moments, vectors = np.linalg.eigh(0.5 * (tensor + tensor.T))
    order = max(itertools.permutations(range(3)),
                key=lambda p: sum(abs(float(vectors[i, p[i]])) for i in range(3)))
    axes = vectors[:, list(order)].copy()
    for i in range(3):
        if axes[i, i] < 0.0:
            axes[:, i] = -axes[:, i]
    if np.linalg.det(axes) < 0.0:  # a reflection left: turn the axis least aligned with its own
        worst = int(np.argmin(np.abs(np.diag(axes))))
        axes[:, worst] = -axes[:, worst]
    return moments[list(order)], axes


def _diagonal(tensor: np.ndarray) -> bool:
    """Whether the tensor is written as ``diaginertia`` (no product of inertia)."""
    return not any(float(tensor[i, j]) != 0.0 for i, j in ((0, 1), (0, 2), (1, 2)))


# A body still to write: (parent element, link, pose in the parent body, incoming joint, free_top,
# detached); or a floating joint whose child is split off as a top-level body when its turn comes.
_Pending = tuple[Element, str, Pose, Joint | None, bool, bool] | Joint


def mujoco_valid_inertia(tensor: np.ndarray) -> tuple[np.ndarray, tuple[float, float, float], float]:
    """The tensor, or the nearest one with principal moments a + b ≥ c that MuJoCo accepts: the two
    smaller moments are raised equally, the axes and the largest moment kept. Returns the tensor,
    the original moments (ascending) and the raise (0 when nothing changed).

    MuJoCo checks a full tensor after its own eigen-decomposition, without tolerance: a flat plate
    (a + b = c exactly) fails on rounding, so a full tensor needs a small margin (PLATE_MARGIN).
    """
    sym = 0.5 * (tensor + tensor.T)
    values, vectors = np.linalg.eigh(sym)
    a, b, c = (float(v) for v in values)
    diagonal = not np.any(sym - np.diag(np.diag(sym)))
    need = c if diagonal else c * (1.0 + PLATE_MARGIN)
    if a + b >= need:
        return tensor, (a, b, c), 0.0
    delta = (need - a - b) / 2.0
    fixed: np.ndarray = vectors @ np.diag([a + delta, b + delta, c]) @ vectors.T
    return fixed, (a, b, c), delta


@dataclass
class BodyTree:
    robot: Robot
    ctx: WriteContext
    names: NameTable
    geoms: GeomWriter
    devices: DeviceWriter
    body_name: dict[str, str] = field(default_factory=dict)
    joint_names: dict[str, list[str]] = field(default_factory=dict)  # model joint → written joint(s)
    scalar_joints: list[str] = field(default_factory=list)  # written hinge/slide names, tree order
    bodies: dict[str, Element] = field(default_factory=dict)
    locked: list[tuple[str, float]] = field(default_factory=list)  # written joint, value it is held at
    frames: dict[str, Pose] = field(default_factory=dict)  # link frame in its body's frame, when not equal
    home: dict[str, float] = field(default_factory=dict)  # written hinge/slide → initial position
    body_pose: dict[Element, Pose] = field(default_factory=dict)  # body → its pose in its parent
    sites: dict[str, tuple[str, str]] = field(default_factory=dict)  # frame link → (site, link of its body)
    lifted: set[str] = field(default_factory=set)  # massless moving links written with MIN_MASS (MK816)

    def __post_init__(self) -> None:
        self.children = self.robot.children_of()
        self.links = {lk.name: lk for lk in self.robot.links}
        self.parent_joint = {j.child: j for j in self.robot.joints}
        self.chains = ChainFinder(self.robot, self.children)
        self.absorbed: set[str] = set()  # intermediate links written as joints of their chain's body
        self.frame_links = set(frame_links(self.robot)) if self.ctx.options.frame_sites else set()
        self.kept_sites: dict[str, list[dict[str, Any]]] = {}  # an MJCF source's sites, by link
        self.written_sites: list[dict[str, Any]] = []  # those written, in the order written
        mjcf = self.robot.source_format == "mjcf"
        for site in own_sites(self.robot) if mjcf else named_frames(self.robot):
            self.kept_sites.setdefault(str(site["link"]), []).append(site)
        for joint in self.robot.joints:
            chain = self.chains.below(joint)
            if chain is not None:
                self.absorbed.update(chain.links)

    def frame(self, link: str) -> Pose:
        """The link's frame in the frame of the body it is written in (identity but for chain ends)."""
        return self.frames.get(link, Pose())

    # -- the tree ------------------------------------------------------------------------------

    def write(self, worldbody: Element) -> None:
        robot = self.robot
        root = robot.root
        if root is None or root not in self.links:
            return
        self._claim_names()
        split: list[tuple[Joint, Pose]] = []
        if root == WORLD_LINK:
            world = self.links[root]
            self.ctx.note(
                "MK814",
                'the root link "world" is MuJoCo\'s world body: its children are top-level '
                "bodies, its geoms and devices are written in <worldbody>",
                world.source,
                "worldbody",
            )
            self.body_name[root] = "world"
            self._contents(worldbody, world, "world", static=True)
            for joint in self.children.get(root, []):
                self._body(worldbody, joint.child, robot.root_pose @ joint.origin, joint, split)
        else:
            self._body(worldbody, root, robot.root_pose, None, split)
        for link in self.robot.links:
            incoming = self.parent_joint.get(link.name)
            if (
                link.name in self.bodies
                or link.name in self.absorbed
                or link.name == root
                or (incoming is not None and incoming.parent in self.links)
            ):
                continue
            free = self.robot.free_link_poses
            pose = free.get(link.name, robot.root_pose)
            static = robot.root_joint is JointType.FIXED
            how = "welded to the world, as the root is" if static else "with <freejoint/>"
            self._claim_subtree(link.name)
            self.ctx.note(
                "MK813",
                f"link {link.name} is not connected to the root; written as a top-level body {how}",
                link.source,
                f"body[{self.body_name[link.name]}]",
            )
            self._body(worldbody, link.name, pose, None, split, free_top=not static, detached=static)
        poses: dict[str, Pose] | None = None
        while split:
            joint, _ = split.pop(0)
            poses = poses if poses is not None else robot.world_poses()
            pose = poses.get(joint.child, Pose())
            self.ctx.note(
                "MK813",
                f"floating joint {joint.name} inside the tree: MuJoCo allows free joints on "
                f"top-level bodies only, so body {self.body_name[joint.child]} and its subtree are a "
                "top-level body with <freejoint/> at its pose at q = 0",
                joint.source,
                f"body[{self.body_name[joint.child]}]",
            )
            self._body(worldbody, joint.child, pose, joint, split, free_top=True)

    def _claim_subtree(self, start: str) -> None:
        for name in self._subtree(start):
            if name not in self.body_name and name not in self.absorbed and name not in self.frame_links:
                link = self.links[name]
                self.body_name[name] = self.names.claim("body", name, link.loc("name"), f"body[{name}]")

    def _subtree(self, start: str) -> list[str]:
        order = [start]
        seen = set(order)
        i = 0
        while i < len(order):
            for joint in self.children.get(order[i], []):
                if joint.child not in seen and joint.child in self.links:
                    seen.add(joint.child)
                    order.append(joint.child)
            i += 1
        return order

    def _claim_names(self) -> None:
        """Body names in tree order, so that renames are deterministic."""
        for name in self._subtree(self.robot.root) if self.robot.root else []:
            if (name == WORLD_LINK and name == self.robot.root) or name in self.absorbed:
                continue
            if name in self.frame_links:
                continue
            link = self.links[name]
            self.body_name[name] = self.names.claim("body", name, link.loc("name"), f"body[{name}]")

    def _body(
        self,
        parent: Element,
        link_name: str,
        pose: Pose,
        joint: Joint | None,
        split: list[tuple[Joint, Pose]],
        free_top: bool = False,
        detached: bool = False,
    ) -> None:
        """Write the body of ``link_name`` and its subtree, depth first, with a stack of its own: a
        chain of 10,000 links is as deep as a tree gets, far beyond Python's recursion limit. The
        order is that of a recursive pre-order walk (children in joint order), so names and notes are
        claimed as before; a floating child joins ``split`` when its turn comes."""
        stack: list[_Pending] = [(parent, link_name, pose, joint, free_top, detached)]
        while stack:
            item = stack.pop()
            if isinstance(item, Joint):
                split.append((item, Pose()))
                continue
            stack.extend(reversed(self._one_body(*item)))

    def _one_body(
        self,
        parent: Element,
        link_name: str,
        pose: Pose,
        joint: Joint | None,
        free_top: bool,
        detached: bool,
    ) -> list[_Pending]:
        """One body: its element, joint, inertial and contents; returns its children, still to write."""
        link = self.links.get(link_name)
        if link is None:
            return []
        chain = self.chains.below(joint) if joint is not None and not (free_top or detached) else None
        if chain is not None:
            return self._chain_body(parent, chain, pose @ chain.entry.inverse())
        name = self.body_name[link_name]
        el = sub(parent, "body", name=name)
        set_pose(el, pose)
        self.body_pose[el] = pose
        self.bodies[link_name] = el
        if free_top and joint is None:
            sub(el, "freejoint")
            moving = True
        elif detached:
            moving = False
        elif joint is None:
            moving = self._root_joint(el, link, name)
        elif free_top:
            el_joint = sub(
                el,
                "freejoint",
                name=self.names.claim("joint", joint.name, joint.loc("name"), f"body[{name}]/freejoint"),
            )
            self.joint_names[joint.name] = [el_joint.get("name", "")]
            moving = True
        else:
            moving = self._joint(el, joint, name)
        if link.extras.get("mjcf_mocap") and not moving and parent.tag == "worldbody":
            el.set("mocap", "true")  # an MJCF source's mocap body (moved by the program), written back
        for attribute, value in (link.extras.get("mjcf_body_physics") or {}).items():
            el.set(attribute, str(value))  # gravcomp
        return self._fill(el, link, name, moving)

    def _chain_body(self, parent: Element, chain: Chain, pose: Pose) -> list[_Pending]:
        """One body for a multi-joint MuJoCo body the reader made a chain of (:mod:`.write_chains`)."""
        link = self.links[chain.end]
        name = self.body_name[chain.end]
        el = sub(parent, "body", name=name)
        set_pose(el, pose)
        self.bodies[chain.end] = el
        if not chain.shift.is_identity(tol=0.0):
            self.frames[chain.end] = chain.shift
        for joint, anchor in zip(chain.joints, chain.positions, strict=True):
            self._joint(el, joint, name, anchor)
        return self._fill(el, shifted(link, chain.shift), name, True, chain.shift)

    def _fill(
        self,
        el: Element,
        link: Link,
        name: str,
        moving: bool,
        frame: Pose | None = None,
    ) -> list[_Pending]:
        """A body's inertial, geoms and devices; returns its child bodies to write, in order (a floating
        child as its joint, for ``split``). ``frame``: the link's frame in the body's."""
        self._inertial(el, link, name, moving)
        self._contents(el, link, name, static=False)
        pending: list[_Pending] = []
        frames: list[tuple[str, Pose]] = []
        for child in self.children.get(link.name, []):
            if child.type is JointType.FLOATING:
                pending.append(child)
                continue
            origin = child.origin if frame is None else frame @ child.origin
            if child.child in self.frame_links:
                frames.append((child.child, origin))
                continue
            pending.append((el, child.child, origin, child, False, False))
        self._kept_sites(el, link.name, frame or Pose())
        self._frame_sites(el, link.name, frames)
        return pending

    def _kept_sites(self, el: Element, link: str, frame: Pose) -> None:
        """An MJCF source's sites written back (:mod:`.site_frames`): those that name frames, and from
        an MJCF source every site, with its group and colour (the source's sensors may use it)."""
        for site in self.kept_sites.get(link, []):
            self.kept_site(el, site, frame)
            self.written_sites.append(site)

    def kept_site(self, el: Element, site: dict[str, Any], frame: Pose) -> None:
        """One kept site in ``el`` (``frame``: its link's frame in the body's)."""
        written = sub(el, "site")
        if site.get("name"):
            wanted = str(site["name"])
            written.set("name", self.names.claim("site", wanted, None, f"site[{wanted}]"))
        set_pose(written, frame @ site_pose(site))
        kind = str(site.get("type") or "sphere")
        if kind != "sphere":
            written.set("type", kind)
        size = [float(v) for v in site.get("size") or []]
        used = {"sphere": 1, "capsule": 2, "cylinder": 2}.get(kind, 3)
        if size and size[:used] != [DEFAULT_SITE_SIZE] * used:
            written.set("size", fmt_vec(size[:used]))
        if site.get("group") is not None:
            written.set("group", str(int(site["group"])))
        if site.get("rgba") is not None:
            written.set("rgba", fmt_vec([float(v) for v in site["rgba"]]))

    def _frame_sites(self, el: Element, body_link: str, frames: list[tuple[str, Pose]]) -> None:
        """The frame links below a body as its ``<site>``s, each frame's chain in pre-order."""
        stack = list(reversed(frames))
        while stack:
            name, pose = stack.pop()
            link = self.links[name]
            site = self.names.claim("site", name, link.loc("name"), f"site[{name}]", note=False)
            if site != name:
                self.ctx.rename("link", name, site, "the site name is taken", link.loc("name"),
                                f"site[{site}]")
            set_pose(sub(el, "site", name=site), pose)
            self.sites[name] = (site, body_link)
            self._kept_sites(el, name, pose)  # the frame's own sites (robosuite's grip_site on eef)
            stack.extend((j.child, pose @ j.origin) for j in reversed(self.children.get(name, [])))

    def _contents(self, el: Element, link: Link, name: str, static: bool) -> None:
        self.geoms.link_geoms(el, link, name)
        self.devices.link_devices(el, link, name)

    def _root_joint(self, el: Element, link: Link, name: str) -> bool:
        kind = self.robot.root_joint
        if kind is JointType.FIXED:
            return False
        if kind is None:
            self.ctx.note(
                "MK814",
                "the source leaves the root open (URDF): written floating, with <freejoint/>",
                link.source,
                f"body[{name}]/freejoint",
            )
        sub(el, "freejoint")
        return True

    # -- joints --------------------------------------------------------------------------------

    def _joint(self, body: Element, joint: Joint, body_name: str, anchor: np.ndarray | None = None) -> bool:
        """Write the joint (``anchor``: its ``pos`` in the body frame; None: the body origin)."""
        target = f"body[{body_name}]/joint[{joint.name}]"
        kind = joint.type
        if kind is JointType.PSEUDO_CONTINUOUS_TRACK:
            self.ctx.note(
                "MK813",
                f"pseudo continuous track {joint.name} written as a weld (MuJoCo has no moving "
                "contact surface)",
                joint.source,
                f"body[{body_name}]",
            )
            return False
        if kind is JointType.FIXED:
            return False
        if kind is JointType.PLANAR:
            self._planar(body, joint, body_name)
            return True
        name = self.names.claim("joint", joint.name, joint.loc("name"), target)
        self.joint_names[joint.name] = [name]
        if kind is JointType.BALL:
            el = sub(body, "joint", name=name, type="ball")
            self._anchor(el, anchor)
            cone = joint.extras.get("mjcf_ball_range")  # an MJCF source's cone limit, written back
            if cone:
                el.set("range", f"0 {fmt(float(cone[1]))}")
            self._dynamics(el, joint, target)
            return True
        el = sub(body, "joint", name=name, type="hinge" if kind is JointType.REVOLUTE else "slide")
        self._anchor(el, anchor)
        el.set("axis", fmt_direction(joint.axis))
        self.scalar_joints.append(name)
        limits = joint.limits
        if math.isfinite(limits.lower) and math.isfinite(limits.upper) and limits.lower < limits.upper:
            el.set("range", f"{fmt(limits.lower)} {fmt(limits.upper)}")
        elif math.isfinite(limits.lower) and limits.lower == limits.upper:
            self.locked.append((name, limits.lower))
            self.ctx.note(
                "MK820",
                f"joint {joint.name} is locked (both limits {fmt(limits.lower)}); MuJoCo needs "
                "range[0] < range[1], so it is written unlimited and held at that value by a joint "
                "equality",
                joint.loc("limits"),
                target,
            )
        elif math.isfinite(limits.lower) and math.isfinite(limits.upper) and limits.lower > limits.upper:
            self.ctx.note(
                "MK824",
                f"joint {joint.name}: lower limit {fmt(limits.lower)} is above upper limit "
                f"{fmt(limits.upper)} (no position is within them, MK307); written unlimited",
                joint.loc("limits"),
                target,
            )
        elif limits.position_limited:
            self.ctx.note(
                "MK820",
                f"joint {joint.name} is limited on one side only ({limits.lower}, "
                f"{limits.upper}); MuJoCo needs both, so it is written unlimited",
                joint.loc("limits"),
                target,
            )
        self._dynamics(el, joint, target)
        home = self._home_in_range(joint, target)
        if home:
            self.home[name] = home  # the `home` keyframe (writer.py)
        return True

    def _home_in_range(self, joint: Joint, target: str) -> float:
        """The joint's home position, at the nearest limit when it lies outside the written range (MK845):
        there the joint's own limit would push it, and a position servo (whose control range is the
        joint's) can hold it."""
        nearest = home_position(joint)
        if nearest != joint.initial_position:
            limits = joint.limits
            self.ctx.note(
                "MK845",
                f"joint {joint.name}: home position {fmt(joint.initial_position)} is outside its range "
                f"[{fmt(limits.lower)}, {fmt(limits.upper)}]; the home keyframe puts it at {fmt(nearest)}",
                joint.loc("limits"),
                target,
            )
        return nearest

    @staticmethod
    def _anchor(el: Element, anchor: np.ndarray | None) -> None:
        if anchor is not None and np.any(anchor != 0.0):
            el.set("pos", fmt_position(anchor))

    def _planar(self, body: Element, joint: Joint, body_name: str) -> None:
        u, v, normal = planar_axes(joint.axis)
        written = []
        for suffix, kind, axis in (("_tx", "slide", u), ("_ty", "slide", v), ("_rz", "hinge", normal)):
            target = f"body[{body_name}]/joint[{joint.name}{suffix}]"
            name = self.names.claim("joint", joint.name + suffix, joint.loc("name"), target, note=False)
            el = sub(body, "joint", name=name, type=kind, axis=fmt_direction(axis))
            self._dynamics(el, joint, target)
            written.append(name)
        self.joint_names[joint.name] = written
        self.ctx.note(
            "MK813",
            f'planar joint "{joint.name}" written as two slides and a hinge '
            f'({", ".join(f"{chr(34)}{name}{chr(34)}" for name in written)})',
            joint.source,
            f"body[{body_name}]",
        )

    def _dynamics(self, el: Element, joint: Joint, target: str) -> None:
        if joint.damping:
            el.set("damping", fmt(joint.damping))
        if joint.friction:
            el.set("frictionloss", fmt(joint.friction))
        if joint.armature:
            el.set("armature", fmt(joint.armature))
        if joint.type is JointType.BALL:
            if joint.spring_stiffness:  # towards the zero orientation: MuJoCo's, springref ignored
                el.set("stiffness", fmt(joint.spring_stiffness))
        elif joint.spring_stiffness or joint.spring_reference:
            el.set("stiffness", fmt(joint.spring_stiffness))
            el.set("springref", fmt(joint.spring_reference))
        effort = joint.limits.effort
        if math.isfinite(effort) and effort > 0.0 and joint.type is not JointType.BALL:
            el.set("actuatorfrcrange", f"{fmt(-effort)} {fmt(effort)}")
        elif math.isfinite(effort) and effort <= 0.0:
            self.ctx.note(
                "MK820",
                f"joint {joint.name}: effort limit {fmt(effort)} not written (it would forbid "
                "any actuator force)",
                joint.loc("limits"),
                target,
            )
        for attribute, value in (joint.extras.get("mjcf_joint_physics") or {}).items():
            el.set(attribute, str(value))  # an MJCF source's margin, solreflimit... written back
        lost = []
        if math.isfinite(joint.limits.velocity) or math.isfinite(joint.limits.velocity_upper):
            lost.append("velocity limit")
        if lost:
            self.ctx.note(
                "MK820",
                f"joint {joint.name}: {' and '.join(lost)} not written (MJCF joints have no such field)",
                joint.source,
                target,
            )

    # -- inertials -----------------------------------------------------------------------------

    def _inertial(self, body: Element, link: Link, name: str, moving: bool) -> None:
        inertial = link.inertial
        target = f"body[{name}]/inertial"
        if inertial is not None and inertial.defaulted:
            self.ctx.note(
                "MK801",
                f"link {link.name} has no mass information; Choreonoid's default "
                f"{fmt(inertial.mass)} kg is written",
                link.loc("mass"),
                target,
            )
        mass = inertial.mass if inertial is not None else 0.0
        com = np.asarray(inertial.com, dtype=float) if inertial is not None else np.zeros(3)
        tensor = clean_inertia(inertial.inertia, inertial.mass) if inertial is not None else np.zeros((3, 3))
        if moving:
            group_mass, moments, own = self._weld_group(link)
            if group_mass < SINGULAR:
                kept = bool(np.any(tensor != 0.0))  # a tensor the source gives without mass is kept
                self.ctx.note(
                    "MK816",
                    f"link {link.name} moves but has no mass (nor anything welded to it); "
                    f"MuJoCo refuses that, so it gets {fmt(MIN_MASS)} kg and {fmt(MIN_INERTIA)} kg·m² "
                    "on each axis" + (" added to the inertia tensor its source gives it" if kept else ""),
                    link.loc("mass"),
                    target,
                )
                mass, com = mass + MIN_MASS, com if mass > 0.0 else np.zeros(3)
                self.lifted.add(link.name)
                tensor = tensor + MIN_INERTIA * np.eye(3)
            elif (singular := float(np.min(moments)) < (
                    SINGULAR_DIAGONAL if _diagonal(tensor) or _principal_form(tensor) else SINGULAR_FULL)
            ) or own < SINGULAR_DIAGONAL:
                # a massless frame over welded links with mass but no inertia carries the fix itself
                # (icub-models' iCub: a free base_link over root_link's 4.72 kg with a zero tensor)
                frame = mass <= 0.0
                why = ("its inertia (with what is welded to it) is singular" if singular else
                       "neither it nor what is welded to it has an inertia of its own (point masses, whose "
                       "spread alone gives the group its inertia)")
                self.ctx.note(
                    "MK870",
                    f"link {link.name} moves but {why}; MuJoCo refuses that, so {fmt(MIN_INERTIA)} kg·m² is "
                    "added on each axis"
                    + (f" (with {fmt(MIN_MASS)} kg, since the link itself has no mass)" if frame else ""),
                    link.loc("inertia"),
                    target,
                )
                if frame:
                    mass, com = MIN_MASS, np.zeros(3)
                    self.lifted.add(link.name)
                tensor = tensor + MIN_INERTIA * np.eye(3)
        if mass > 0.0:
            tensor = self._triangle(tensor, link, target)
        if mass <= 0.0:
            if inertial is None or inertial.mass == 0.0:
                self.ctx.note(
                    "MK816",
                    f"link {link.name} has no mass: written as a massless body (a frame)",
                    link.source,
                    f"body[{name}]",
                )
            return
        el = sub(body, "inertial", pos=fmt_position(com), mass=fmt(mass))
        off = (tensor[0, 1], tensor[0, 2], tensor[1, 2])
        principal = _principal(tensor)
        if principal is not None:
            moments, axes = principal
            el.set("quat", fmt_vec(quat_wxyz(axes)))
            el.set("diaginertia", fmt_tensor(moments, tensor))
        elif any(v != 0.0 for v in off):
            plain = principal_text(tensor, *principal_axes_near_link(tensor))
            if plain is not None:
                el.set("quat", plain[0])
                el.set("diaginertia", plain[1])
            else:
                el.set("fullinertia", fmt_tensor([tensor[0, 0], tensor[1, 1], tensor[2, 2], *off], tensor))
        else:
            el.set("diaginertia", fmt_tensor([tensor[0, 0], tensor[1, 1], tensor[2, 2]], tensor))

    def _triangle(self, tensor: np.ndarray, link: Link, target: str) -> np.ndarray:
        """The tensor, or MuJoCo's nearest acceptable one (:func:`mujoco_valid_inertia`), noted."""
        fixed, (a, b, c), delta = mujoco_valid_inertia(tensor)
        if delta == 0.0:
            return tensor
        why = (
            "no rigid body has them; MuJoCo refuses them"
            if a + b < c * (1.0 - PLATE_MARGIN)
            else "a flat plate: MuJoCo's eigen-decomposition rounds it below the limit and refuses it"
        )
        self.ctx.note(
            "MK870",
            f"link {link.name}: principal moments {fmt(a)}, {fmt(b)}, {fmt(c)} violate "
            f"a + b ≥ c ({why}); the two smaller are raised by {fmt(delta)} kg·m², the principal axes "
            "kept",
            link.loc("inertia"),
            target,
        )
        return fixed

    def _weld_group(self, link: Link) -> tuple[float, np.ndarray, float]:
        """Mass and principal moments of ``link`` and every link welded to it (fixed joints down), and
        the largest of their own smallest principal moments (0 when every one of them is a point mass:
        MuJoCo adds the bodies' own moments without the spread of their centres and refuses such a group,
        PyFlyt's fixed-wing's eight point masses)."""
        parts: list[tuple[float, np.ndarray, np.ndarray]] = []
        own = 0.0
        stack: list[tuple[str, Pose]] = [(link.name, Pose())]
        while stack:
            name, pose = stack.pop()
            lk = self.links.get(name)
            if lk is None:
                continue
            inertial: Inertial | None = lk.inertial
            if inertial is not None and inertial.mass > 0.0:
                parts.append(
                    (
                        inertial.mass,
                        pose.rotation @ np.asarray(inertial.com, dtype=float) + pose.translation,
                        rotate_inertia(inertial.inertia, pose.rotation),
                    )
                )
                own = max(own, float(np.min(principal_moments(np.asarray(inertial.inertia, dtype=float)))))
            for joint in self.children.get(name, []):
                if joint.type not in MOVING:
                    stack.append((joint.child, pose @ joint.origin))
        mass, _, inertia = combine_mass_properties(parts)
        return mass, principal_moments(inertia), own


def planar_axes(normal: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The two slide axes ``u``, ``v`` and the hinge axis ``n`` of a planar joint about ``normal``
    (in the joint frame): ``u`` ⟂ ``n`` from the first of X, Y not near ``n``, ``v = n × u``, so
    (u, v, n) is right-handed."""
    n = np.asarray(normal, dtype=float)
    n = n / float(np.linalg.norm(n))
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, n)
    u = u / float(np.linalg.norm(u))
    return u, np.cross(n, u), n
