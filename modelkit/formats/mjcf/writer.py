"""The MJCF (MuJoCo XML) writer: ``write_mjcf(robot, ctx) -> bytes``.

The file is built with lxml, 2-space indented, sections in a fixed order (``compiler``, ``option``,
``default``, ``asset``, ``worldbody``, ``contact``, ``equality``, ``actuator``, ``sensor``,
``keyframe``; empty ones left out); numbers through :func:`modelkit.convert.numbers.fmt`. MuJoCo is
not imported here; :mod:`modelkit.convert.self_contact` compiles the finished file once to find the
body pairs touching at rest. The style is MuJoCo Menagerie's (docs/convert.md, "MJCF style").

* ``<compiler angle="radian" autolimits="true" inertiafromgeom="false" meshdir="meshes"/>``: angles
  in radians, a ``range`` makes a joint limited, and inertia comes from the ``<inertial>`` elements
  only (geoms never add mass). ``meshdir`` when every mesh file is in the written ``meshes/`` folder
  (each ``file`` is then a name in it); otherwise each ``file`` is relative to the model file.
* ``<default>``: a class named after the robot, with the ``visual`` and ``collision`` classes its
  geoms name (:mod:`.write_geoms`).
* ``<option>``: MuJoCo's defaults, except for a driven robot: wheels get timestep 1 ms,
  ``implicitfast``, elliptic cones and ``impratio`` 10; pseudo continuous tracks the same with their
  ``impratio`` (``convert.tracks.TRACK_IMPRATIO``: soft friction, so that the track rollers skid as
  Coulomb friction says; MK809). One writer merges both: :mod:`modelkit.convert.simulator` (MK825).
* The body tree, joints and inertials: :mod:`.write_bodies`; geoms, meshes, colours and friction:
  :mod:`.write_geoms`; sensors and lights: :mod:`.write_devices`.
* Mimic joints → ``<equality><joint joint1=follower joint2=leader polycoef="offset multiplier 0 0
  0"/>`` (MK812 when the leader is not a written hinge/slide).
* Closed loops (``robot.loops``) → equality constraints between sites placed at the loop joint's
  frame in each link (``<link>_<loop>``): fixed → ``weld``, ball → ``connect``, hinge → two
  ``connect`` at ±``HINGE_HALF_SPAN`` m along the axis (as Choreonoid's MuJoCo plugin; MK811),
  piston → left out (MK810).
* Actuators: the source's own (position, velocity, effort), else the ``--actuators`` choice on every
  hinge and slide (a ``<motor>`` by default: zero control applies no force, so the passive model is
  unchanged): :mod:`.write_actuators`. Position actuators put ``ctrl`` in the ``home`` keyframe; position
  or velocity servos set ``<option integrator="implicitfast">`` (MK825) unless an integrator is set.
* A multi-joint MuJoCo body that the MJCF reader made a chain of links is written back as one body
  with its joints (:mod:`.write_chains`).
* From an MJCF source, its own sites, cameras, lights and sensors that the model keeps as data are
  written back where every object they name is written (:mod:`.write_own`); the rest is named in an
  MK806/MK808 note (:mod:`.write_foreign`).
* Massless frame links (a tool flange, a TCP, an optical frame) are ``<site>``s in the body they hang
  on (:mod:`.write_bodies`, MK873), unless ``WriteOptions.frame_sites`` is off.
* The ``home`` keyframe (:mod:`.write_home`): initial positions, servo targets, and a free robot's
  base at the height where it rests on z = 0 (MK882), found in the same MuJoCo pass as self-contact.
* Self-collision follows MuJoCo's defaults (parent–child and welded pairs never collide), and any
  other body pair whose collision shapes MuJoCo finds touching at the ``home`` keyframe (q = 0 without one)
  gets ``<contact><exclude>`` (MK832; :mod:`modelkit.convert.self_contact` compiles the file; MK833
  when it cannot).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import floor_friction
from modelkit.convert.meshes import MESH_FOLDER
from modelkit.convert.numbers import fmt, fmt_text
from modelkit.convert.self_contact import SOFT_LOAD_RATIO, BelowBase, Lowest, touching_pairs
from modelkit.convert.servo_gains import with_written_masses
from modelkit.convert.simulator import CONTACT, mujoco_contact, mujoco_options
from modelkit.convert.tracks import roller_names
from modelkit.formats.mjcf.carried import held_by_mimics, is_linear
from modelkit.formats.mjcf.coupling_armature import floor_coupled_armature
from modelkit.formats.mjcf.write_actuators import ActuatorWriter
from modelkit.formats.mjcf.write_bodies import MIN_INERTIA, MIN_MASS, BodyTree
from modelkit.formats.mjcf.write_contact_pairs import write_source_pairs
from modelkit.formats.mjcf.write_devices import DeviceWriter
from modelkit.formats.mjcf.write_exclusions import write_exclusions
from modelkit.formats.mjcf.write_foreign import note_unwritten_own
from modelkit.formats.mjcf.write_geoms import COLLISION, CONTACT_PRIORITY, GeomWriter, shared_stems
from modelkit.formats.mjcf.write_home import HomeKey
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_own import OwnWriter
from modelkit.formats.mjcf.write_transmissions import TransmissionWriter
from modelkit.formats.mjcf.write_xml import EULER_SEQUENCE, Element, indent, set_pose, sub
from modelkit.model import WORLD_LINK, LoopConstraint, Robot
from modelkit.spatial import Pose

SECTIONS = (
    "compiler", "option", "default", "asset", "worldbody", "contact", "equality", "tendon", "actuator",
    "sensor", "keyframe",
)
SERVO_INTEGRATOR = "implicitfast"  # with position/velocity servos: kv taken implicitly (as Menagerie's arms)
DEFAULT_TIMESTEP = 0.002  # s: MuJoCo's, when <option> names none
EULER_DAMPING_LIMIT = 2.0  # damping/inertia × timestep past which explicit Euler's damping diverges
MIMIC_SOLREF = "0.005 1"
"""A mimic's joint equality (not a track approximation's rollers, whose skid-steer tolerances were
measured with MuJoCo's default coupling: docs/verify.md): time constant 5 ms (MuJoCo Menagerie's
Robotiq 2F-85 couples its drivers so; MuJoCo's default 20 ms lets a follower lag its servoed leader).
Measured, a gripper's servos held at home 2 s then stepped to mid-range: the worst mimic violation fell
from 0.25 to 0.076 rad (airo's Robotiq 2F-85), 0.28 to 0.073 (pybullet_data's xArm gripper), 0.33 to
0.18 (PR2), 2.5 to 1.0 (Fourier's Inspire hand); held at home, 0.036 to 0.0078 rad (Inspire). At least
2 time steps at every step the writer sets (1 or 2 ms)."""
HINGE_HALF_SPAN = 0.05  # m: the two connects of a hinge loop sit this far either side of the joint
# MuJoCo's XML parser (TinyXML2, 500 levels) reads at most this many nested <body> elements inside
# <mujoco><worldbody> (measured with MuJoCo 3.x and 4.0: 496 load, 497 are refused).
MUJOCO_MAX_BODY_DEPTH = 496


def write_mjcf(robot: Robot, ctx: WriteContext) -> bytes:
    return MjcfWriter(robot, ctx).write()


class MjcfWriter:
    def __init__(self, robot: Robot, ctx: WriteContext) -> None:
        self.robot = robot
        self.ctx = ctx
        self.names = NameTable(ctx)
        self._refusal_explained = False  # a note already says why MuJoCo refuses the file (MK872)
        self.written_equalities: list[dict[str, Any]] = []  # an MJCF source's, written back
        self.written_mimics: dict[str, str] = {}  # follower → leader, the mimics written as equalities
        self.stiff_mimics = 0  # mimics written with MIMIC_SOLREF (MK869)
        self.root = etree.Element("mujoco", model=robot.name)
        self.sections = {tag: sub(self.root, tag) for tag in SECTIONS}
        compiler = self.sections["compiler"]
        compiler.set("angle", "radian")
        compiler.set("autolimits", "true")
        compiler.set("inertiafromgeom", "false")
        self.geoms = GeomWriter(ctx, self.names, self.sections["asset"], floor_friction(robot),
                                mujoco_contact(robot), shared_stems=shared_stems(robot.links),
                                mujoco_rules=robot.source_format == "mjcf",
                                texture_base=Path(robot.source.file).parent
                                if robot.source is not None and robot.source.file else None)
        self.devices = DeviceWriter(ctx, self.names, self.sections["sensor"])
        self.tree = BodyTree(robot, ctx, self.names, self.geoms, self.devices)
        self.home_key = HomeKey(robot, ctx, self.sections["keyframe"], self.sections["worldbody"],
                                self.tree.body_pose)
        options, why = mujoco_options(robot)  # wheels or tracks (convert.simulator says why)
        for key, value in options.items():
            self.sections["option"].set(key, value)
        own = robot.extras.get("mjcf_option") or {}  # an MJCF source's own settings win
        for key, value in sorted(own.items()):
            if isinstance(value, dict):  # <flag>
                sub(self.sections["option"], key, **{k: str(v) for k, v in sorted(value.items())})
            else:
                self.sections["option"].set(key, fmt_text(str(value)))
        if options:
            stiff = (f"; the collision geoms have solref {CONTACT['solref']!r} and solimp "
                     f"{CONTACT['solimp']!r} (stiff contact: the wheels keep their rolling radius)"
                     if mujoco_contact(robot) else "")
            ctx.note(
                "MK825",
                f"<option {' '.join(f'{k}={v!r}' for k, v in options.items())}>: {why}{stiff}; a scene that "
                "includes this file keeps these settings (MuJoCo merges <option>), and the robot drives "
                "like its source with them (docs/convert.md)",
                robot.source,
                "option",
            )

    def write(self) -> bytes:
        floor_coupled_armature(self.robot, self.ctx)  # before the joints and the servo gains are written
        self.tree.write(self.sections["worldbody"])
        self._frame_note()
        self._depth()
        self._joint_ids()
        self._mimics()
        if self.stiff_mimics:
            self.ctx.note(
                "MK869",
                f"{self.stiff_mimics} mimic joint(s) written as joint equalities with "
                f"solref=\"{MIMIC_SOLREF}\" (MuJoCo's default 0.02 s time constant lets a follower lag a "
                "servoed leader; a mimic is rigid in the source): fast finger commands still part a light "
                "follower from its leader for a moment (docs/convert.md, \"Mimic joints in MuJoCo\")",
                self.robot.source,
                "equality",
            )
        for joint, value in self.tree.locked:
            sub(
                self.sections["equality"],
                "joint",
                name=self.names.claim("equality", f"{joint}_locked"),
                joint1=joint,
                polycoef=f"{fmt(value)} 0 0 0 0",
            )
        for loop in self.robot.loops:
            self._loop(loop)
        self._actuators()
        self.geoms.defaults(self.sections["default"], self.robot.name)
        self._surface_note()
        lost = self._own() if self.robot.source_format == "mjcf" else {}
        self._home()
        note_unwritten_own(self.root, self.robot, self.ctx, lost)
        write_source_pairs(self.root, self.sections["contact"], self.robot, self.ctx)
        write_exclusions(self.robot, self.tree, self.sections["contact"], self.ctx)
        self._meshdir()
        if any(el.get("euler") is not None for el in self.root.iter()):
            self.sections["compiler"].set("eulerseq", EULER_SEQUENCE)  # set_pose's euler: URDF's rpy
        self._self_contact()
        return self._text()

    def _own(self) -> dict[str, list[dict[str, Any]]]:
        """MJCF to MJCF: the source's own cameras, lights, world sites (:mod:`.write_own`), tendons and
        other actuators (:mod:`.write_transmissions`), then its sensors, which may name any of them."""
        own = OwnWriter(self.robot, self.ctx, self.names, self.tree, self.devices, self.sections["worldbody"],
                        self.sections["sensor"])
        lost = own.write_places()
        sections = self.sections
        transmissions = TransmissionWriter(self.robot, self.ctx, self.names, own.refs, sections["tendon"],
                                           sections["equality"], self.actuators)
        lost.update(transmissions.write())
        lost.update(own.write_sensors())
        written = {id(eq) for eq in self.written_equalities + transmissions.equalities}
        lost["mjcf_equalities"] = [eq for eq in self.robot.extras.get("mjcf_equalities") or []
                                   if id(eq) not in written and not held_by_mimics(eq, self.written_mimics)]
        return lost

    def _surface_note(self) -> None:
        """Once per file: how MuJoCo combines the source's shape frictions the geoms now hold."""
        links = sorted(self.geoms.surface_links)
        if not links or self.robot.source_format == "mjcf":
            return
        self.ctx.note(
            "MK852",
            f"the source's own friction of the collision shapes of {len(links)} link(s) "
            f"({', '.join(links[:5])}{', ...' if len(links) > 5 else ''}) is written as geom friction "
            f"and condim; the collision geoms have priority {CONTACT_PRIORITY}, so against a floor of "
            "MuJoCo's default priority 0 the robot's values are used; the source's engine may combine "
            "two shapes' values otherwise "
            "(PyBullet multiplies them, so against pybullet_data's plane.urdf, friction 1, the numbers "
            "agree; Gazebo/ODE takes the smaller)",
            self.robot.source,
            "default",
        )

    def _text(self) -> bytes:
        for tag in SECTIONS:
            el = self.sections[tag]
            if tag not in ("compiler", "worldbody") and len(el) == 0 and not el.attrib:
                self.root.remove(el)
        # an MJCF source's <size>, <visual>, <statistic> (memory, viewer, extent), after <compiler>/<option>
        at = self.root.index(self.sections["compiler"]) + 1
        if self.sections["option"].getparent() is self.root:
            at = self.root.index(self.sections["option"]) + 1
        for offset, kept in enumerate(self.robot.extras.get("mjcf_globals") or []):
            self.root.insert(at + offset, etree.fromstring(kept))
        indent(self.root, space="  ")
        text: bytes = etree.tostring(self.root, xml_declaration=False, encoding="utf-8", pretty_print=True)
        return text

    def _self_contact(self) -> None:
        """``<contact><exclude>`` for body pairs touching at rest (MK832), found by compiling the file
        as written so far with MuJoCo (MK833 when that fails)."""
        if not any(g.get("class") == COLLISION for g in self.sections["worldbody"].iter("geom")):
            return  # nothing collides
        draft = etree.tostring(self.root, encoding="utf-8")
        checked = touching_pairs(draft, self._assets())
        if checked.failure is not None:
            self.ctx.note("MK833", f"self-contact at rest not checked: {checked.failure}", self.robot.source,
                          "contact")
            if checked.unusable is not None and not self._refusal_explained:
                self.ctx.note("MK877", checked.unusable, self.robot.source, "mujoco")
            return
        links = {el.get("name"): link for link, el in self.tree.bodies.items()}
        self._below_base(checked.below, links)
        self.home_key.rest_on_floor(checked.lowest)
        self._soft_support(checked.lowest, links)
        for pair in checked.pairs:
            sub(self.sections["contact"], "exclude", body1=pair.body1, body2=pair.body2)
            link = self.robot.link(links.get(pair.body2) or "")
            mm = round(pair.depth * 1000.0, 3)
            depth = f"overlapping by {fmt(mm)} mm" if mm > 0.0 else "touching (overlap below 0.001 mm)"
            self.ctx.note(
                "MK832",
                f"bodies {pair.body1} and {pair.body2} collide at rest ({pair.where}: MuJoCo finds their "
                f"collision shapes {depth}); MuJoCo would push them apart, so the pair is excluded (in "
                "every pose)",
                link.source if link is not None else self.robot.source,
                f"contact/exclude[{pair.body1},{pair.body2}]",
            )

    def _below_base(self, below: list[BelowBase], links: dict[str | None, str]) -> None:
        """MK865: a welded robot whose home pose puts moving collision shapes below its base."""
        if not below:
            return
        deepest = max(below, key=lambda each: each.depth)
        shown = ", ".join(f"{each.body} {each.depth * 1000.0:.0f} mm" for each in below[:4])
        link = self.robot.link(links.get(deepest.body) or "")
        self.ctx.note(
            "MK865",
            f"at home the collision shapes of {len(below)} moving bod(ies) reach below the welded base's "
            f"lowest point ({shown}{' ...' if len(below) > 4 else ''}): on a table or floor there, "
            "where an arm is mounted, they start inside it, and MuJoCo pushes the robot out at the first "
            "step; a home pose clear of it comes from the source's initial positions, or from MoveIt's "
            "SRDF (--srdf FILE, --home STATE)",
            link.source if link is not None else self.robot.source,
            "keyframe",
        )

    def _soft_support(self, lowest: Lowest | None, links: dict[str | None, str]) -> None:
        """MK883: a free robot stands at home on bodies so light that MuJoCo's contact gives way."""
        if lowest is None or not lowest.soft:
            return
        first = max(lowest.soft, key=lambda each: each.ratio)
        shown = " and ".join(f"{each.body} ({fmt(round(each.mass, 6))} kg, load ratio {each.ratio:.0f})"
                             for each in lowest.soft)
        link = self.robot.link(links.get(first.body) or "")
        self.ctx.note(
            "MK883",
            f"the robot ({first.robot_mass:.4g} kg) stands at home on {shown}: MuJoCo softens a contact "
            "by the inverse mass it moves, and this load ratio (the robot's mass times the body's "
            f"body_invweight0) is above {SOFT_LOAD_RATIO:.0f}, where the robots measured standing on a "
            "default floor reach 177 at most (HyQ's feet, 10.9 mm deep); with MuJoCo's default contact the "
            "robot sinks into the floor and may fall (icub-models' iCubLisboa01, 10 g feet, load ratio "
            "926: 33 mm, falls within 2 s). The source's masses are kept; a body as heavy as the "
            "hardware's, or a stiffer solimp on its collision geoms (0.99 0.999), holds the robot",
            link.source if link is not None else self.robot.source,
            f"body[{first.body}]",
        )

    def _assets(self) -> dict[str, bytes]:
        """The staged files as MuJoCo resolves the model's references (``meshes/link0.stl``)."""
        folder = self.ctx.model_relpath.rpartition("/")[0]
        out: dict[str, bytes] = {}
        for relpath, staged in self.ctx.meshes.plan.files.items():
            if staged.what == "model":
                continue
            if folder:
                ups = folder.count("/") + 1
                out["../" * ups + relpath] = staged.data
            else:
                out[relpath] = staged.data
        return out

    def _meshdir(self) -> None:
        """``<compiler meshdir="meshes">`` when every mesh file is in the written ``meshes/`` folder
        (a kept ``package://`` URI, or a file elsewhere, leaves every path as it is)."""
        meshes = list(self.sections["asset"].iter("mesh"))
        prefix = f"{MESH_FOLDER}/"
        files = [el.get("file", "") for el in meshes]
        if not meshes or not all(f.startswith(prefix) and "/" not in f[len(prefix):] for f in files):
            return
        self.sections["compiler"].set("meshdir", MESH_FOLDER)
        for el, name in zip(meshes, files, strict=True):
            el.set("file", name[len(prefix):])

    def _frame_note(self) -> None:
        """One MK873 note naming the frame links written as sites (write_bodies)."""
        sites = self.tree.sites
        if not sites:
            return
        listed = ", ".join(
            f"{link} (in {self.tree.body_name.get(body, body)})" if site == link
            else f"{link} as site {site} (in {self.tree.body_name.get(body, body)})"
            for link, (site, body) in sites.items()
        )
        self.ctx.note(
            "MK873",
            f"{len(sites)} massless frame link(s) on fixed joints written as <site>s in the body they hang "
            f"on, at the same pose (MuJoCo Menagerie's way: no empty bodies): {listed}; --frame-bodies "
            "(WriteOptions.frame_sites=False) writes them as bodies",
            self.robot.source,
            "site",
        )

    def _depth(self) -> None:
        """MK872 when the bodies nest deeper than MuJoCo reads: the file is written all the same."""
        deepest: tuple[int, Element | None] = (0, None)
        stack: list[tuple[Element, int]] = [(self.sections["worldbody"], 0)]
        while stack:
            el, depth = stack.pop()
            for child in el.iterchildren("body"):
                if depth + 1 > deepest[0]:
                    deepest = (depth + 1, child)
                stack.append((child, depth + 1))
        depth, body = deepest
        if depth <= MUJOCO_MAX_BODY_DEPTH or body is None:
            return
        name = body.get("name", "")
        link = next((lk for lk, el in self.tree.bodies.items() if el is body), None)
        found = self.robot.link(link) if link is not None else None
        source = found.source if found is not None else self.robot.source
        self._refusal_explained = True
        self.ctx.note(
            "MK872",
            f"the bodies nest {depth} deep (body {name}); MuJoCo's XML parser reads at most "
            f"{MUJOCO_MAX_BODY_DEPTH} nested bodies and refuses this file",
            source,
            f"body[{name}]",
        )

    # -- joints across the tree ----------------------------------------------------------------

    def _home(self) -> None:
        """The ``home`` keyframe (:mod:`.write_home`): initial positions and the servos' targets."""
        self.home_key.write(self.tree.home, self.actuators.ctrl, self.actuators.any_position)

    def _joint_ids(self) -> None:
        ids = [j for j in self.robot.joints if j.joint_id is not None]
        if ids:
            self.ctx.note(
                "MK820",
                f"joint ids of {len(ids)} joint(s) not written (MuJoCo numbers joints in tree order)",
                ids[0].loc("joint_id"),
                "worldbody",
            )

    def _mimics(self) -> None:
        written = set(self.tree.scalar_joints)
        rollers = roller_names(self.robot, "rollers")  # they keep MuJoCo's default coupling
        couplings: list[tuple[str, str, float, float]] = []  # follower, leader, multiplier, offset
        for joint in self.robot.joints:
            mimic = joint.mimic
            if mimic is None:
                continue
            follower = self.tree.joint_names.get(joint.name, [])
            leader = self.tree.joint_names.get(mimic.joint, [])
            target = f"equality/joint[{joint.name}]"
            if (
                len(follower) != 1
                or len(leader) != 1
                or follower[0] not in written
                or leader[0] not in written
            ):
                self.ctx.note(
                    "MK812",
                    f"joint {joint.name} mimics {mimic.joint}, but MuJoCo's joint equality needs "
                    "two hinge or slide joints; left out",
                    mimic.source or joint.source,
                    target,
                )
                continue
            source = self._source_equality(joint.name, mimic.joint)
            first, second, offset, multiplier = follower[0], leader[0], mimic.offset, mimic.multiplier
            named = joint.name
            if source is not None and source.get("obj1") == mimic.joint and mimic.multiplier != 0.0:
                # the reader read this equality the other way (its actuator is on joint1): the same
                # constraint, written as the source wrote it
                first, second, named = leader[0], follower[0], mimic.joint
                offset, multiplier = -mimic.offset / mimic.multiplier, 1.0 / mimic.multiplier
            el = sub(
                self.sections["equality"],
                "joint",
                name=self.names.claim("equality", str((source or {}).get("name") or f"{named}_mimic")),
                joint1=first,
                joint2=second,
                polycoef=f"{fmt(offset)} {fmt(multiplier)} 0 0 0",
            )
            # a mimic the reader composed along a group of the source's equalities (no equality of its
            # own) keeps their solver settings: the source's coupling was as soft as they are
            group = self._group_equality(joint.name) if source is None else None
            solver = (source or group or {}).get("solver") or {}
            for key, value in solver.items():
                el.set(key, str(value))
            if source is None and group is None and joint.name not in rollers:  # rigid in the source
                el.set("solref", MIMIC_SOLREF)
                self.stiff_mimics += 1
            couplings.append((follower[0], leader[0], mimic.multiplier, mimic.offset))
            self.written_mimics[joint.name] = mimic.joint
        self._home_coupled(couplings)

    def _home_coupled(self, couplings: list[tuple[str, str, float, float]]) -> None:
        """Each mimic follower's home at its leader's image (offset + multiplier × the leader's home), so
        that the ``home`` keyframe satisfies the equalities: TIAGo Pro's ros2_control starts its gripper's
        leader at 0.15 rad and names no position for the followers, which then snapped 0.15–0.19 rad at
        the first step. Along a chain (a follower of a follower) each follower is placed after its
        leader, once; a loop of mimics keeps the homes it has."""
        home = self.tree.home
        leader_of = {follower: (leader, multiplier, offset)
                     for follower, leader, multiplier, offset in couplings}
        placed: set[str] = set()
        for start in leader_of:
            chain = []  # from ``start`` up to the first joint that follows nothing (or a loop)
            joint = start
            while joint in leader_of and joint not in placed and joint not in chain:
                chain.append(joint)
                joint = leader_of[joint][0]
            if joint in chain:  # a loop of mimics
                placed.update(chain)
                continue
            for follower in reversed(chain):
                leader, multiplier, offset = leader_of[follower]
                value = offset + multiplier * home.get(leader, 0.0)
                if home.get(follower, 0.0) != value:
                    home[follower] = value
                placed.add(follower)

    def _source_equality(self, follower: str, leader: str) -> dict[str, Any] | None:
        """An MJCF source's joint equality the reader made this mimic of (its name and solver settings
        are written back; it counts as written, :attr:`written_equalities`)."""
        for eq in self.robot.extras.get("mjcf_equalities") or []:
            if eq.get("type") == "joint" and (eq.get("obj1"), eq.get("obj2")) in ((follower, leader),
                                                                                   (leader, follower)):
                self.written_equalities.append(eq)
                return dict(eq)
        return None

    def _group_equality(self, follower: str) -> dict[str, Any] | None:
        """An MJCF source's linear joint equality that names ``follower`` (the first), for a mimic the
        reader composed along several of them (it does not count as written)."""
        for eq in self.robot.extras.get("mjcf_equalities") or []:
            if eq.get("type") == "joint" and follower in (eq.get("obj1"), eq.get("obj2")) and is_linear(eq):
                return dict(eq)
        return None

    def _loop(self, loop: LoopConstraint) -> None:
        target = f"equality/{loop.name}"
        bodies = self.tree.bodies
        missing = [n for n in (loop.link1, loop.link2) if n not in bodies and n != WORLD_LINK]
        if missing:
            self.ctx.note(
                "MK810",
                f"closed loop {loop.name}: link {missing[0]} is not written; left out",
                loop.source,
                target,
            )
            return
        if loop.type == "piston":
            self.ctx.note(
                "MK810",
                f"closed loop {loop.name} is a piston joint; MuJoCo has no equality for it, left out",
                loop.source,
                target,
            )
            return
        equality = self.sections["equality"]
        if loop.type in ("fixed", "ball"):
            s1 = self._site(loop.link1, loop.pose_in_link1, f"{loop.name}_1", loop)
            s2 = self._site(loop.link2, loop.pose_in_link2, f"{loop.name}_2", loop)
            tag = "weld" if loop.type == "fixed" else "connect"
            sub(
                equality,
                tag,
                name=self.names.claim("equality", loop.name, loop.source, target),
                site1=s1,
                site2=s2,
            )
            return
        if loop.type != "hinge":
            self.ctx.note(
                "MK810",
                f"closed loop {loop.name} of type {loop.type}: no MuJoCo equality; left out",
                loop.source,
                target,
            )
            return
        axis = np.asarray(loop.axis, dtype=float)
        axis = axis / float(np.linalg.norm(axis))
        for sign, suffix in ((1.0, "a"), (-1.0, "b")):
            shift = Pose(np.eye(3), sign * HINGE_HALF_SPAN * axis)
            s1 = self._site(loop.link1, loop.pose_in_link1 @ shift, f"{loop.name}_{suffix}1", loop)
            s2 = self._site(loop.link2, loop.pose_in_link2 @ shift, f"{loop.name}_{suffix}2", loop)
            sub(
                equality,
                "connect",
                name=self.names.claim("equality", f"{loop.name}_{suffix}", loop.source, target),
                site1=s1,
                site2=s2,
            )
        self.ctx.note(
            "MK811",
            f"closed hinge loop {loop.name} written as two connect constraints "
            f"{fmt(HINGE_HALF_SPAN)} m either side of the joint on its axis",
            loop.source,
            target,
        )

    def _site(self, link: str, pose: Pose, wanted: str, loop: LoopConstraint) -> str:
        parent = self.tree.bodies.get(link, self.sections["worldbody"])
        name = self.names.claim("site", wanted, loop.source, f"site[{wanted}]")
        el = sub(parent, "site", name=name, size="0.005")
        set_pose(el, self.tree.frame(link) @ pose)
        return name

    def _actuators(self) -> None:
        as_written = with_written_masses(self.robot, frozenset(self.tree.lifted), MIN_MASS, MIN_INERTIA)
        self.actuators = ActuatorWriter(self.robot, self.ctx, self.names, self.sections["actuator"],
                                        self.tree.joint_names, as_written)
        self.actuators.write(self.tree.home)
        option = self.sections["option"]
        # An MJCF source's own servos keep the integrator its author ran them with (MuJoCo's default
        # Euler when it names none); the servos a writer makes, or another format's, get implicitfast
        ours = self.robot.source_format != "mjcf" or self.actuators.made_up
        if self.actuators.servos and option.get("integrator") is None and ours:
            option.set("integrator", SERVO_INTEGRATOR)
            self.ctx.note(
                "MK825",
                f'<option integrator="{SERVO_INTEGRATOR}">: the file has {self.actuators.servos} position or '
                "velocity servo(s), whose damping (kv) MuJoCo's default Euler integrator takes explicitly (a "
                "stiff servo then rings; measured on UR5: 5.6 mm off its home pose after 2 s, 0.56 mm with "
                "implicitfast); a scene that includes this file keeps this setting",
                self.robot.source,
                "option",
            )
        elif self.actuators.servos and option.get("integrator") is None:
            self._euler_diverges(option)

    def _euler_diverges(self, option: Element) -> None:
        """An MJCF source's own servos under MuJoCo's default Euler integrator, when Euler cannot take
        their damping at the file's timestep (damping/inertia × dt over 2: the file goes NaN within
        milliseconds). A robot file written to be included by a scene that sets the integrator does so
        (robotblockset's Unitree B2: kv 200 on 0.05 kg·m² calves at 2 ms; its scene sets implicitfast).
        The written file stands alone, so it gets implicitfast, and MK825 says why."""
        worst = self.actuators.euler_rate()
        timestep = float(option.get("timestep") or DEFAULT_TIMESTEP)
        if worst is None or worst[3] * timestep <= EULER_DAMPING_LIMIT:
            return
        joint, damping, inertia, rate = worst
        option.set("integrator", SERVO_INTEGRATOR)
        self.ctx.note(
            "MK825",
            f'<option integrator="{SERVO_INTEGRATOR}">: the source\'s servos diverge under MuJoCo\'s default '
            f"Euler integrator at its {fmt(timestep)} s step (joint {joint}: damping {damping:.3g} on "
            f"{inertia:.3g} kg·m² at home, damping/inertia × step = {rate * timestep:.3g}, over "
            f"{fmt(EULER_DAMPING_LIMIT)}: the file alone goes NaN); a scene that includes it and sets its "
            "own integrator keeps that",
            self.robot.source,
            "option",
        )
