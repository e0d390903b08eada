"""Geoms and mesh assets of the MJCF writer.

* Geoms name a ``<default>`` class, as MuJoCo Menagerie's models do: ``class="collision"`` (MuJoCo's
  default ``contype="1" conaffinity="1"``, ``group="3"``, ``priority="1"`` and, for a driven robot,
  the stiff ``solref``/``solimp``) or ``class="visual"`` (``contype="0" conaffinity="0"
  group="1"``; MuJoCo's own URDF importer uses group 1 for visuals). Both are children of a class
  named after the robot (:meth:`GeomWriter.defaults`). The viewer shows groups 0–2 by default, so a
  converted robot looks like its visual model; MuJoCo collides geoms whatever their group.
* Geoms never add mass: the compiler is told ``inertiafromgeom="false"`` and every body's mass
  comes from its ``<inertial>`` (or is zero), so ``body_mass`` is the model's mass exactly.
* Box ``size`` = half extents; sphere ``r``; cylinder and capsule ``r h/2`` (the model's capsule
  length is the cylindrical part, as MuJoCo's); ellipsoid ``rx ry rz``; cones and generated
  geometry become mesh files (MK802/MK803); COLLADA/VRML meshes are converted to STL/OBJ (MK804).
* A primitive with a zero or negative size is left out (MK871): MuJoCo refuses any such geom ("size 0
  must be positive in geom"). A tiny stand-in would invent a contact the source does not mean (a zero
  box is how Gazebo models say "no collision"), and geoms add no mass here, so nothing else changes.
* A mesh asset is named after its source file's stem (``wheel`` for ``wheel.dae``); when a collision
  and a visual mesh come from different files of the same stem (``link0.stl`` and ``link0.dae``), the
  collision one is ``<stem>_collision``; any other clash gets ``_2``... (MK800). One asset per
  (written file, scale). Each ``file`` is relative to the model file; the writer then moves the
  common ``meshes/`` folder into ``<compiler meshdir>`` (:mod:`.writer`).
* Colour: ``rgba`` = (diffuse, 1 − transparency); specular, emissive and textures are not written
  (MK818).
* Friction: a link with a contact material gets, on each collision geom, its friction against
  Choreonoid's floor material ``Ground`` (the pair table's dynamic friction, or Choreonoid's
  √roughness rule) with MuJoCo's default torsional and rolling values, ``friction="mu 0.005
  0.0001"``, ``condim`` 3 (1 for a frictionless material such as the tutorial's caster ``Slider``),
  and an MK817 note. Every collision geom has ``priority="1"``: MuJoCo otherwise combines the two
  geoms of a contact by max(), so a default floor's friction 1 would replace the caster's 0 (measured:
  the tutorial robot then spins 0.06 of 5 rad); with the higher priority the robot geom's friction,
  condim, solref and solimp are the contact's against any floor of MuJoCo's default priority 0.
  The robot file holds no floor, so no ``<pair>`` is written.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import PurePosixPath

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import FLOOR_MATERIAL, PairFriction
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.diagnostics import SourceLocation
from modelkit.formats.mjcf.bodies import GEOM_CONTACT_DEFAULTS
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, set_pose, sub
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, Link, Mesh, Sphere, SurfaceFriction

MESH_READABLE = ("stl", "obj")
COLLISION_GROUP = "3"
VISUAL_GROUP = "1"
VISUAL, COLLISION = "visual", "collision"  # the <default> classes the geoms name
TORSIONAL, ROLLING = 0.005, 0.0001  # MuJoCo's defaults, written out with the sliding friction
CONTACT_PRIORITY = "1"  # above a floor's default 0: the robot geom's friction, condim, solref win


@dataclass
class GeomWriter:
    ctx: WriteContext
    names: NameTable
    asset: Element
    friction: dict[str, PairFriction]
    contact: dict[str, str] = field(default_factory=dict)  # solref/solimp for every collision geom
    mesh_assets: dict[tuple[str, tuple[float, ...]], str] = field(default_factory=dict)
    shared_stems: set[str] = field(default_factory=set)  # stems of both a collision and a visual file
    used: set[str] = field(default_factory=set)  # the classes (VISUAL, COLLISION) a geom names
    surface_links: set[str] = field(default_factory=set)  # links whose geoms got the source's friction
    mujoco_rules: bool = False
    """An MJCF source: its geoms' friction, condim and priority are written as they were, and mix with
    a floor's by MuJoCo's rules as in the source (no collision-class priority above a floor's)."""

    def defaults(self, section: Element, robot_name: str) -> None:
        """``<default class=robot>`` with the ``visual`` and ``collision`` classes the geoms use."""
        if not self.used:
            return
        top = sub(section, "default", **{"class": self.names.claim("default", robot_name or "robot",
                                                                    note=False)})
        if COLLISION in self.used:
            geom = sub(sub(top, "default", **{"class": COLLISION}), "geom", group=COLLISION_GROUP)
            if not self.mujoco_rules:
                geom.set("priority", CONTACT_PRIORITY)
            for key, value in self.contact.items():
                geom.set(key, value)
        if VISUAL in self.used:
            sub(sub(top, "default", **{"class": VISUAL}), "geom", contype="0", conaffinity="0",
                group=VISUAL_GROUP)

    def link_geoms(self, body: Element, link: Link, body_name: str) -> None:
        contact = {e["collision"]: e for e in link.extras.get("mjcf_contact", [])}
        for i, geom in enumerate(link.collisions):
            el = self.geom(body, geom, f"body[{body_name}]/collision[{i}]", link, collision=True)
            if el is not None and i in contact:  # an MJCF source's own solref, solimp, margin...
                for key in (*GEOM_CONTACT_DEFAULTS, "friction", "fluidshape", "fluidcoef"):
                    if key in contact[i]:
                        el.set(key, str(contact[i][key]))
        for i, geom in enumerate(link.visuals):
            self.geom(body, geom, f"body[{body_name}]/visual[{i}]", link, collision=False)

    def geom(self, body: Element, geom: Geom, target: str, link: Link, collision: bool) -> Element | None:
        if refused_by_mujoco(geom.geometry):
            role = (
                "collision shape (a consumer that loads it, such as PyBullet, collides with a point there)"
                if collision
                else "visual shape (it draws nothing)"
            )
            what = f"{type(geom.geometry).__name__.lower()} {fmt_vec(primitive_sizes(geom.geometry))}"
            self.ctx.note(
                "MK871",
                f"{what} of link {link.name} has a size that is not positive, which MuJoCo refuses; this "
                f"{role} is left out",
                geom.source,
                target,
            )
            return None
        shape = self.shape(
            geom, target, f"{link.name}_{target.rsplit('/', 1)[1].replace('[', '').rstrip(']')}", collision
        )
        if shape is None:
            return None
        el = sub(body, "geom")
        if geom.name:
            el.set("name", self.names.claim("geom", geom.name, geom.source, target))
        for key, value in shape.items():
            el.set(key, value)
        set_pose(el, geom.pose)
        role = COLLISION if collision else VISUAL
        el.set("class", role)
        self.used.add(role)
        self.appearance(el, geom, target)
        if collision and geom.friction is not None:
            self.set_surface_friction(el, geom.friction, link, target)
        elif collision and link.name in self.friction:
            self.set_friction(el, link, target)
        return el

    def shape(self, geom: Geom, target: str, file_stem: str,
              collision: bool = False) -> dict[str, str] | None:
        g = geom.geometry
        if isinstance(g, Box):
            return {"type": "box", "size": fmt_vec(np.asarray(g.size, dtype=float) / 2.0)}
        if isinstance(g, Sphere):
            return {"type": "sphere", "size": fmt(g.radius)}
        if isinstance(g, Cylinder):
            return {"type": "cylinder", "size": f"{fmt(g.radius)} {fmt(g.length / 2.0)}"}
        if isinstance(g, Capsule):
            if g.length == 0.0:  # MuJoCo refuses a capsule of half-length 0: it is a sphere
                return {"type": "sphere", "size": fmt(g.radius)}
            return {"type": "capsule", "size": f"{fmt(g.radius)} {fmt(g.length / 2.0)}"}
        if isinstance(g, Ellipsoid):
            return {"type": "ellipsoid", "size": fmt_vec(g.radii)}
        if isinstance(g, Cone):
            ref = self.ctx.meshes.primitive(g, file_stem, target, geom.source)
        elif isinstance(g, Mesh):
            found = self.ctx.meshes.mesh(g, file_stem, target, geom.source, readable=MESH_READABLE,
                                         mujoco=True, collision=collision)
            if found is None:
                return None
            ref = found
        else:  # pragma: no cover - the model has no other geometry
            return None
        stem = source_stem(g) if isinstance(g, Mesh) else None
        if stem is not None and collision and stem in self.shared_stems:
            stem = f"{stem}_{COLLISION}"
        asset = self.mesh_asset(ref.uri, np.asarray(ref.scale, dtype=float), target, ref.hollow, geom.source,
                                stem)
        return {"type": "mesh", "mesh": asset}

    def mesh_asset(self, uri: str, scale: np.ndarray, target: str, hollow: bool = False,
                   source: SourceLocation | None = None, stem: str | None = None) -> str:
        """The asset of the written file ``uri`` at ``scale``, named ``stem`` (the source file's) or
        after ``uri``."""
        key = (uri, tuple(float(x) for x in scale))
        known = self.mesh_assets.get(key)
        if known is not None:
            return known
        stem = stem or PurePosixPath(uri).stem or "mesh"
        name = self.names.claim("mesh", stem, None, f"asset/mesh[{stem}] (for {target})")
        el = sub(self.asset, "mesh", name=name, file=uri)
        if np.any(scale != 1.0):
            el.set("scale", fmt_vec(scale))
        if hollow:  # MuJoCo: "mesh volume is too small"; body inertias are explicit, nothing changes
            el.set("inertia", "shell")
            self.ctx.note("MK876", f"mesh {stem} encloses no volume: its asset gets inertia=\"shell\", "
                          "which MuJoCo needs to load it", source, f"asset/mesh[{name}]")
        self.mesh_assets[key] = name
        return name

    def appearance(self, el: Element, geom: Geom, target: str) -> None:
        material = geom.material
        if material is None:
            return
        rgba = material.rgba
        if rgba is not None:
            el.set("rgba", fmt_vec(rgba))
        dropped = [
            word
            for word, value in (
                ("texture", material.texture),
                ("specular colour", material.specular),
                ("emissive colour", material.emissive),
                ("specular exponent", material.specular_exponent),
            )
            if value is not None
        ]
        if dropped:
            self.ctx.note(
                "MK818",
                f"{', '.join(dropped)} of material {material.name or '(unnamed)'} not "
                "written; the geom has only its rgba",
                geom.source,
                target,
            )

    def set_surface_friction(self, el: Element, friction: SurfaceFriction, link: Link, target: str) -> None:
        """A shape's own friction: ``condim`` says which coefficients act (1 none, 3 sliding, 4 and
        torsional, 6 and rolling) and ``friction`` lists that many (MuJoCo fills the rest)."""
        torsional, rolling = friction.torsional or 0.0, friction.rolling or 0.0
        values = [friction.sliding]
        condim = "3" if friction.sliding > 0.0 else "1"
        if rolling > 0.0:
            condim, values = "6", [friction.sliding, torsional, rolling]
        elif torsional > 0.0:
            condim, values = "4", [friction.sliding, torsional]
        el.set("friction", fmt_vec(values))
        if condim != "3":
            el.set("condim", condim)
        if friction.sliding2 is not None:
            self.ctx.note(
                "MK851",
                f"a collision of link {link.name} has a sliding friction of {fmt(friction.sliding)} in its "
                f"first direction and {fmt(friction.sliding2)} in its second; a MuJoCo geom holds one "
                f"coefficient for both, and {fmt(friction.sliding)} is written",
                link.loc("collision"),
                target,
            )
        self.surface_links.add(link.name)

    def set_friction(self, el: Element, link: Link, target: str) -> None:
        pair = self.friction[link.name]
        el.set("friction", f"{fmt(pair.dynamic)} {fmt(TORSIONAL)} {fmt(ROLLING)}")
        el.set("condim", "3" if pair.dynamic > 0.0 else "1")
        how = "Choreonoid's pair table" if pair.from_table else "Choreonoid's √(roughness·roughness) rule"
        static = (
            f" (static {fmt(pair.static)} not held: MuJoCo has one coefficient)"
            if pair.static != pair.dynamic
            else ""
        )
        self.ctx.note(
            "MK817",
            f"material {pair.material} against {FLOOR_MATERIAL}: sliding friction {fmt(pair.dynamic)} from "
            f"{how}{static}; the geom has priority {CONTACT_PRIORITY}, so MuJoCo uses its friction and "
            f"condim {'3' if pair.dynamic > 0.0 else '1 (frictionless)'} against any floor of priority 0 "
            f"(MuJoCo's default); restitution {fmt(pair.restitution)} is not written",
            link.loc("material"),
            f"body[{target.split('[', 1)[1].split(']', 1)[0]}]",
        )


def primitive_sizes(g: object) -> tuple[float, ...]:
    """A primitive's sizes (box edges, radius, length, radii); () for a mesh or cone (written as a mesh)."""
    if isinstance(g, Box):
        return tuple(float(x) for x in g.size)
    if isinstance(g, Sphere):
        return (float(g.radius),)
    if isinstance(g, (Cylinder, Capsule)):
        return (float(g.radius), float(g.length))
    if isinstance(g, Ellipsoid):
        return tuple(float(x) for x in g.radii)
    return ()


def refused_by_mujoco(g: object) -> bool:
    """MuJoCo refuses a geom whose size is not positive; a capsule of length 0 is written as a sphere."""
    sizes = primitive_sizes(g)
    if isinstance(g, Capsule):
        return sizes[0] <= 0.0 or sizes[1] < 0.0
    return bool(sizes) and min(sizes) <= 0.0


def source_stem(mesh: Mesh) -> str | None:
    """The stem of the file a mesh came from (with its fragment: ``robot_arm``), None when generated."""
    if not mesh.uri:
        return None
    stem = PurePosixPath(mesh.uri.replace("\\", "/")).stem
    if not stem:
        return None
    return f"{stem}_{mesh.fragment}" if mesh.fragment else stem


def shared_stems(links: list[Link]) -> set[str]:
    """Stems that name different collision and visual files (``link0.stl`` and ``link0.dae``)."""
    files: dict[tuple[str, bool], set[str]] = {}
    for link in links:
        for collision, geoms in ((True, link.collisions), (False, link.visuals)):
            for geom in geoms:
                g = geom.geometry
                if not isinstance(g, Mesh):
                    continue
                stem = source_stem(g)
                if stem is not None:
                    files.setdefault((stem, collision), set()).add(g.uri or "")
    return {stem for (stem, collision), uris in files.items()
            if collision and files.get((stem, False), set()) - uris}
