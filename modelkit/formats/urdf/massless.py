"""URDF: a link without mass that has a rotational inertia, on a fixed joint, read as its loaders read it.

pybullet_data's ``franka_panda/panda.urdf`` gives ``panda_link8`` and ``panda_grasptarget`` mass 0 and
an inertia of 0.1 kg·m² per axis. A body without mass has no rotational inertia, but the URDF loaders
that fuse links on fixed joints (MuJoCo's and Pinocchio's imports) keep the tensor on the parent, so
the Panda's seventh link turns with 0.2 kg·m² more than its own. Read as written, the link would be
a massless frame to every writer (MK816: an MJCF site, an SDF frame, a URDF link without
``<inertial>``) and its tensor lost: verify's layer 3 found the mass matrix 0.2 off at joint 4.

So the reader does what those loaders do (MK324, a warning: the file should give a mass or no
tensor): leaves first, so that a chain of such links ends in the first ancestor with mass, each
link's tensor, rotated into the parent's frame, is added to the parent's inertia about its centre of
mass (no parallel-axis term without mass; the parent's mass and centre of mass are unchanged), and
the link keeps mass 0 with a zero tensor. A link with no ancestor with mass over fixed joints is left
as written.

The other way, the URDF writer gives a massless link a tiny explicit inertial (:data:`TINY_MASS`,
:data:`TINY_INERTIA`; PyBullet gives a link without ``<inertial>`` 1 kg and a unit inertia), and the
reader takes exactly that inertial, on the root or a fixed joint, as what it stands for: a massless
frame (:func:`read_tiny_frames`), so that an MJCF site or an SDF frame comes back as one. Pure Python
(:mod:`modelkit.rot3`): the validate path does not import numpy.
"""

from __future__ import annotations

import dataclasses

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink
from modelkit.model import Inertial, Joint, JointType, Link, Robot
from modelkit.rot3 import peek

# The explicit inertial the URDF and SDF writers give a massless link: 1e-6 kg at the link origin,
# 1e-12 kg·m² on each axis.
TINY_MASS = 1e-6  # kg
TINY_INERTIA = 1e-12  # kg·m², each principal moment
_TINY_TENSOR = ((TINY_INERTIA, 0.0, 0.0), (0.0, TINY_INERTIA, 0.0), (0.0, 0.0, TINY_INERTIA))


def read_tiny_frames(robot: Robot) -> None:
    """In place: the root or a link on a fixed joint whose inertial is exactly the tiny one is a
    massless frame."""
    moving = {joint.child for joint in robot.joints if joint.type is not JointType.FIXED}
    for link in robot.links:
        inertial = link.inertial
        if (
            inertial is not None
            and link.name not in moving
            and inertial.mass == TINY_MASS
            and rot3.mat3(peek(inertial, "inertia")) == _TINY_TENSOR
            and tuple(float(x) for x in peek(inertial, "com")) == (0.0, 0.0, 0.0)
        ):
            link.inertial = None


def fold_massless_inertia(robot: Robot, sink: DiagnosticSink) -> None:
    """In place: each massless link's tensor on a fixed joint moved to its parent (module docstring)."""
    order, by_child = robot.tree_order()
    links = {link.name: link for link in order}
    for link in reversed(order):
        inertial = link.inertial
        joint = by_child.get(link.name)
        if inertial is None or inertial.mass != 0.0 or joint is None or joint.type is not JointType.FIXED:
            continue
        tensor = rot3.mat3(peek(inertial, "inertia"))
        parent = links.get(joint.parent)
        if tensor == rot3.ZERO33 or parent is None or not _held_above(parent, by_child, links):
            continue
        rotated = rot3.rotate_inertia(tensor, joint.origin.rotation_tuple)
        held = parent.inertial or Inertial(0.0)
        summed = rot3.mat_add(rot3.mat3(peek(held, "inertia")), rotated)
        parent.inertial = dataclasses.replace(held, inertia=summed)
        link.inertial = dataclasses.replace(inertial, inertia=rot3.ZERO33)
        diagonal = ", ".join(f"{tensor[i][i]:g}" for i in range(3))
        sink.emit(
            "MK324",
            f'link "{link.name}" has mass 0 but an inertia (diagonal {diagonal} kg·m²): read as part of '
            f'its parent "{parent.name}"\'s inertia, as MuJoCo\'s and Pinocchio\'s URDF imports fuse it '
            "(mass and centre of mass unchanged); the link is a massless frame",
            inertial.source or link.source,
            hint="give the link its mass, or remove its <inertial>",
        )


def _held_above(parent: Link, by_child: dict[str, Joint], links: dict[str, Link]) -> bool:
    """Whether ``parent``, or an ancestor over fixed joints, has mass to hold the tensor."""
    seen: set[str] = set()
    link: Link | None = parent
    while link is not None and link.name not in seen:
        if link.inertial is not None and link.inertial.mass > 0.0:
            return True
        seen.add(link.name)
        up = by_child.get(link.name)
        if up is None or up.type is not JointType.FIXED:
            return False
        link = links.get(up.parent)
    return False
