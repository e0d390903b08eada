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
* Colour: ``rgba`` = (diffuse, 1 − transparency). A visual geom whose material has a specular or
  emissive colour, a specular exponent or a texture also gets a ``<material>`` asset (one per distinct
  look, named after the source's material): MuJoCo's scalar ``specular`` (the colour's mean),
  ``shininess`` = (exponent − 1)/127, ``emission`` (the emissive colour over the colour, means' ratio)
  and a ``<texture type="2d">`` of the image copied into ``textures/`` (PNG only: MuJoCo reads no
  other). What that only approximates (a coloured specular...) is noted (MK818).
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
from pathlib import Path, PurePosixPath

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import FLOOR_MATERIAL, PairFriction
from modelkit.convert.meshes import MeshRef, Plate
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.diagnostics import SourceLocation
from modelkit.formats.mjcf.bodies import GEOM_CONTACT_DEFAULTS
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, set_pose, sub, use_fromto
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Ellipsoid,
    Geom,
    Link,
    Mesh,
    Sphere,
    SurfaceFriction,
    VisualMaterial,
)
from modelkit.spatial import Pose

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
    materials: dict[tuple[tuple[str, str], ...], str] = field(default_factory=dict)  # attributes → asset
    textures: dict[str, str] = field(default_factory=dict)  # the source's image → its <texture> asset
    texture_base: Path | None = None  # the source model's folder (relative texture paths)
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
        file_stem = f"{link.name}_{target.rsplit('/', 1)[1].replace('[', '').rstrip(']')}"
        if not collision and geom.material is None and isinstance(geom.geometry, Mesh):
            parts = self.ctx.meshes.coloured_parts(geom.geometry, target, geom.source, MESH_READABLE,
                                                   mujoco=True)
            if parts is not None:
                return self._coloured_geoms(body, geom, target, parts)
        found = self.shape(geom, target, file_stem, collision)
        if found is None:
            return None
        shape, offset = found
        el = sub(body, "geom")
        if geom.name:
            el.set("name", self.names.claim("geom", geom.name, geom.source, target))
        for key, value in shape.items():
            el.set(key, value)
        set_pose(el, geom.pose @ offset)
        if isinstance(geom.geometry, Cylinder | Capsule) and shape["type"] != "sphere":
            use_fromto(el, geom.pose @ offset, geom.geometry.length / 2.0)
        role = COLLISION if collision else VISUAL
        el.set("class", role)
        self.used.add(role)
        self.appearance(el, geom, target, collision)
        if collision and geom.friction is not None:
            self.set_surface_friction(el, geom.friction, link, target)
        elif collision and link.name in self.friction:
            self.set_friction(el, link, target)
        return el

    def shape(self, geom: Geom, target: str, file_stem: str,
              collision: bool = False) -> tuple[dict[str, str], Pose] | None:
        """The geom's type and size attributes, and the pose of the written shape in the geom's frame
        (the identity but for a flat collision mesh written as a thin box, MK881)."""
        attributes = self._shape(geom, target, file_stem, collision)
        if isinstance(attributes, Plate):
            plate = attributes
            box = {"type": "box", "size": fmt_vec(np.asarray(plate.size, dtype=float) / 2.0)}
            return box, Pose(np.asarray(plate.rotation, dtype=float), np.asarray(plate.centre, dtype=float))
        return None if attributes is None else (attributes, Pose())

    def _shape(self, geom: Geom, target: str, file_stem: str,
               collision: bool) -> dict[str, str] | Plate | None:
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
            if found.plate is not None:
                return found.plate
            ref = found
        else:  # pragma: no cover - the model has no other geometry
            return None
        stem = source_stem(g) if isinstance(g, Mesh) else None
        if stem is not None and collision and stem in self.shared_stems:
            stem = f"{stem}_{COLLISION}"
        asset = self.mesh_asset(ref.uri, np.asarray(ref.scale, dtype=float), target, ref.hollow, geom.source,
                                stem)
        return {"type": "mesh", "mesh": asset}

    def _coloured_geoms(self, body: Element, geom: Geom, target: str,
                        parts: list[tuple[MeshRef, tuple[float, float, float, float] | None]]) -> Element:
        """A visual mesh whose file gives colours (COLLADA, glTF), as one visual geom per colour
        (:meth:`MeshExporter.coloured_parts`): the first is returned (it carries the source's name)."""
        assert isinstance(geom.geometry, Mesh)
        stem = source_stem(geom.geometry)
        first: Element | None = None
        for k, (ref, rgba) in enumerate(parts):
            name = stem if stem is None or len(parts) == 1 else f"{stem}_{k}"
            scale = np.asarray(ref.scale, dtype=float)
            asset = self.mesh_asset(ref.uri, scale, target, ref.hollow, geom.source, name)
            el = sub(body, "geom")
            if first is None and geom.name:
                el.set("name", self.names.claim("geom", geom.name, geom.source, target))
            el.set("type", "mesh")
            el.set("mesh", asset)
            set_pose(el, geom.pose)
            el.set("class", VISUAL)
            if rgba is not None:
                el.set("rgba", fmt_vec(rgba))
            first = first if first is not None else el
        self.used.add(VISUAL)
        assert first is not None  # coloured_parts gives at least one part
        return first

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

    def appearance(self, el: Element, geom: Geom, target: str, collision: bool = False) -> None:
        """``rgba``; on a visual geom also a ``<material>`` with MuJoCo's scalar specular, shininess and
        emission (:func:`mujoco_material`); what MuJoCo cannot hold is noted (MK818)."""
        material = geom.material
        if material is None:
            return
        rgba = material.rgba
        if rgba is not None:
            el.set("rgba", fmt_vec(rgba))
        if collision:
            return  # the visual geom carries the look (a collision geom is hidden, group 3)
        attributes, approximated = mujoco_material(material)
        if material.texture is not None:
            texture = self._texture(material.texture, geom, target)
            if texture is not None:
                attributes["texture"] = texture
        if attributes:
            key = tuple(sorted(attributes.items()))
            name = self.materials.get(key)
            if name is None:
                name = self.names.claim("material", material.name or "material", None,
                                        f"asset/material (for {target})", note=False)
                sub(self.asset, "material", name=name, **dict(key))
                self.materials[key] = name
            el.set("material", name)
        if approximated:
            self.ctx.note(
                "MK818",
                f"material {material.name or '(unnamed)'}: {'; '.join(approximated)} (a MuJoCo material "
                "holds a colour and a scalar specular, shininess and emission)",
                geom.source,
                target,
            )

    def _texture(self, uri: str, geom: Geom, target: str) -> str | None:
        """A ``<texture type="2d">`` asset of the image copied into the output (PNG only: MuJoCo reads no
        other), named after its file; None (MK818 said why) when it cannot be."""
        known = self.textures.get(uri)
        if known is not None:
            return known
        written = self.ctx.meshes.texture(uri, self.texture_base, target, geom.source, png_only=True)
        if written is None:
            return None
        name = self.names.claim("texture", PurePosixPath(written).stem or "texture", None,
                                f"asset/texture (for {target})", note=False)
        sub(self.asset, "texture", name=name, type="2d", file=written)
        self.textures[uri] = name
        return name

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


def mujoco_material(material: VisualMaterial) -> tuple[dict[str, str], list[str]]:
    """MuJoCo ``<material>`` attributes for the model's material, and what they only approximate.

    MuJoCo's specular is one number (the colour's mean), its shininess (exponent − 1) / 127 (the
    inverse of Choreonoid's and modelkit's reader's exponent = 127·shininess + 1) and its emission the
    emissive colour as a multiple of the colour (the means' ratio); a texture is not written."""
    out: dict[str, str] = {}
    approximated: list[str] = []
    if material.specular is not None:
        specular = [float(x) for x in material.specular]
        out["specular"] = fmt(min(max(sum(specular) / 3.0, 0.0), 1.0))
        if max(specular) - min(specular) > 1e-9:
            approximated.append(f"specular colour {fmt_vec(specular)} written as its mean")
    if material.specular_exponent is not None:
        shininess = (float(material.specular_exponent) - 1.0) / 127.0
        out["shininess"] = fmt(min(max(shininess, 0.0), 1.0))
        if not 0.0 <= shininess <= 1.0:
            approximated.append(f"specular exponent {fmt(float(material.specular_exponent))} clamped to "
                                "MuJoCo's shininess range")
    if material.emissive is not None:
        emissive = [float(x) for x in material.emissive]
        diffuse = [float(x) for x in material.diffuse] if material.diffuse is not None else [1.0, 1.0, 1.0]
        base = sum(diffuse) / 3.0
        if base > 0.0 and any(emissive):
            ratio = (sum(emissive) / 3.0) / base
            out["emission"] = fmt(ratio)
            if any(abs(e - ratio * d) > 1e-9 for e, d in zip(emissive, diffuse, strict=True)):
                approximated.append(f"emissive colour {fmt_vec(emissive)} written as {fmt(ratio)} × the "
                                    "colour")
        elif any(emissive):
            approximated.append(f"emissive colour {fmt_vec(emissive)} left out (the colour is black)")
    return out, approximated
