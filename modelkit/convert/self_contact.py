"""Body pairs that touch at rest in a written MJCF model, found by compiling it with MuJoCo.

A URDF arm is drawn with its links' collision meshes overlapping where they meet (Panda's hand and
link 5 at q = 0, its two fingers), and MuJoCo collides the convex hulls of meshes, which overlap more.
MuJoCo already ignores contacts between a parent and its child body and between bodies welded
together; any other pair that touches at rest pushes the robot apart at the first step. The MJCF
writer gives each such pair a ``<contact><exclude>`` (MK832).

The model is compiled from memory (the writer's XML and the mesh files staged for the output, MuJoCo's
virtual file system), the reference configuration is applied (the ``home`` keyframe, the robot's
initial joint positions, when there is one; else ``qpos0``, i.e. q = 0) and ``mj_forward`` runs
collision detection: every contact there is
between two of the robot's own bodies, since the file holds no floor. MuJoCo's Python bindings come with
the core install (``mujoco-core``); when they cannot be imported or the compiler refuses the file,
:func:`touching_pairs` says why and the writer notes that nothing was checked (MK833).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Touching:
    """Two bodies in contact at rest (names as written, in tree order), and how deep."""

    body1: str
    body2: str
    depth: float  # m: the deepest penetration between their geoms (0 when they only touch)
    where: str  # "home" or "q = 0"


@dataclass(frozen=True)
class Checked:
    pairs: list[Touching]
    failure: str | None = None  # why nothing was checked
    refused: bool = False  # the failure is MuJoCo's compiler refusing the file


def touching_pairs(xml: bytes, assets: dict[str, bytes]) -> Checked:
    """The body pairs of the MJCF ``xml`` whose collision geoms touch at the ``home`` key, or at q = 0
    when it has none.

    ``assets`` maps each file name as MuJoCo resolves it (``meshes/link0.stl``) to its bytes."""
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - mujoco-core is a core dependency
        return Checked([], f"MuJoCo's Python bindings cannot be imported ({exc})")
    from modelkit.formats.mjcf.quiet import collected_warnings

    with collected_warnings(mujoco):  # never MUJOCO_LOG.TXT in the working directory, nor stderr
        return _touching(mujoco, xml, assets)


def _touching(mujoco: Any, xml: bytes, assets: dict[str, bytes]) -> Checked:
    try:
        model = mujoco.MjModel.from_xml_string(xml.decode("utf-8"), assets)
    except Exception as exc:  # MuJoCo raises ValueError with its compiler's message
        return Checked([], f"MuJoCo did not compile the written file ({' '.join(str(exc).split())})", True)
    data = mujoco.MjData(model)
    found: dict[tuple[int, int], tuple[float, set[str]]] = {}
    home = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    # a home key that is q = 0 (servo controls only) is named so: the user's "at rest" is q = 0 there
    zero = home < 0 or bool((model.key_qpos[home] == model.qpos0).all())
    states: list[tuple[str, Any]] = [("q = 0" if zero else "home", home if home >= 0 else None)]
    for label, key in states:
        if key is None:
            mujoco.mj_resetData(model, data)
        else:
            mujoco.mj_resetDataKeyframe(model, data, key)
        mujoco.mj_forward(model, data)
        for i in range(data.ncon):
            contact = data.contact[i]
            b1, b2 = (int(model.geom_bodyid[contact.geom[0]]), int(model.geom_bodyid[contact.geom[1]]))
            if b1 == b2:
                continue
            pair = (min(b1, b2), max(b1, b2))
            depth, labels = found.get(pair, (0.0, set()))
            found[pair] = (max(depth, max(0.0, -float(contact.dist))), labels | {label})

    def name(body: int) -> str:
        return str(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or "world")

    pairs = [
        Touching(name(b1), name(b2), depth, " and ".join(s for s, _ in states if s in labels))
        for (b1, b2), (depth, labels) in sorted(found.items())
    ]
    return Checked(pairs)
