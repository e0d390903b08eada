"""Bodies, joints, geoms and the rest read from MuJoCo's compiled model (``MjModel``).

Compilation resolves everything MJCF leaves implicit: defaults and classes, ``childclass``,
``<include>``, ``<frame>``, angle units and Euler sequences, ``fromto``, inertia from geoms. Reading
the compiled arrays therefore gives exactly what MuJoCo simulates.

No numpy here: the arrays are read row by row into plain floats (:mod:`modelkit.rot3`), so the same
code reads the ``mujoco`` bindings' numpy arrays and a model whose arrays are plain tuples.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from modelkit import rot3
from modelkit.formats.mjcf.bodies import (
    BODY_PHYSICS_DEFAULTS,
    GEOM_CONTACT_DEFAULTS,
    INTEGER_CONTACT,
    JOINT_PHYSICS_DEFAULTS,
    MUJOCO_FRICTION,
    MjBody,
    MjGeom,
    MjInertial,
    MjJoint,
    MjSite,
    non_default,
    plain,
    pose_of,
    single,
    singles,
    translation,
)
from modelkit.formats.mjcf.transmissions import SOLIMP, SOLREF, general_attributes, tendon_attributes
from modelkit.spatial import Pose

JOINT_KINDS = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
SITE_RGBA = (0.5, 0.5, 0.5, 1.0)  # MuJoCo's default site colour (as stored in float32)
CAMERA_IPD = 0.068  # m: MuJoCo's default inter-pupillary distance of a camera
EQUALITY_SOLVER_DEFAULTS: dict[str, tuple[str, str, tuple[float, ...]]] = {
    "solref": ("eq", "solref", SOLREF),
    "solimp": ("eq", "solimp", SOLIMP),
}


def all_close(a: tuple[float, ...], b: tuple[float, ...], rtol: float = 1e-5, atol: float = 1e-8) -> bool:
    """``numpy.allclose`` for two equally long rows of floats: ``|a − b| ≤ atol + rtol·|b|`` each."""
    return len(a) == len(b) and all(abs(x - y) <= atol + rtol * abs(y) for x, y in zip(a, b, strict=True))


def diagonal(moments: Any) -> rot3.M3:
    """The diagonal matrix of three principal moments."""
    x, y, z = rot3.vec3(moments)
    return rot3.inertia_from_moments(x, 0.0, 0.0, y, 0.0, z)


def enum_word(enum_value: Any, prefix: str) -> str:
    """``mjGEOM_CAPSULE`` → ``capsule``."""
    name = str(getattr(enum_value, "name", enum_value))
    return name[len(prefix) :].lower() if name.startswith(prefix) else name.lower()


MENAGERIE_COLLISION_GROUP = 3
"""The geom group MuJoCo Menagerie's models put their collision shapes in (visuals in group 2)."""


def collides_nothing(m: Any) -> bool:
    """Whether a compiled model collides nothing itself: every geom has ``contype`` and ``conaffinity``
    0 and no ``<pair>`` names one, as MuJoCo Menagerie's Apptronik Apollo, whose scene file pairs the
    soles with its floor. Its geoms in :data:`MENAGERIE_COLLISION_GROUP` are then its collision shapes."""
    return (int(m.npair) == 0 and not any(int(x) for x in m.geom_contype)
            and not any(int(x) for x in m.geom_conaffinity))


class CompiledModel:
    """Reads one ``MjModel`` (with the ``MjSpec`` it came from, for mesh file names)."""

    def __init__(self, mujoco: Any, model: Any, spec: Any, model_dir: Path) -> None:
        self.mj = mujoco
        self.m = model
        self.spec = spec
        self.model_dir = model_dir
        self._paired: frozenset[int] | None = None
        self._collisions_elsewhere: bool | None = None

    @property
    def paired(self) -> frozenset[int]:
        """The geoms an explicit ``<contact><pair>`` names: MuJoCo collides them through the pair
        whatever their ``contype`` and ``conaffinity``."""
        if self._paired is None:
            m = self.m
            self._paired = frozenset(int(g) for k in range(int(m.npair))
                                     for g in (m.pair_geom1[k], m.pair_geom2[k]))
        return self._paired

    @property
    def collisions_elsewhere(self) -> bool:
        """:func:`collides_nothing`: the file's collisions are in the scene that includes it."""
        if self._collisions_elsewhere is None:
            self._collisions_elsewhere = collides_nothing(self.m)
        return self._collisions_elsewhere

    def name(self, kind: str, index: int) -> str | None:
        obj = getattr(self.mj.mjtObj, f"mjOBJ_{kind.upper()}")
        name = self.mj.mj_id2name(self.m, obj, int(index))
        return str(name) if name else None

    # -- bodies ------------------------------------------------------------------------------

    def bodies(self) -> list[MjBody]:
        m = self.m
        out = [
            MjBody(
                index=b,
                name=self.name("body", b),
                parent=int(m.body_parentid[b]),
                pose=pose_of(m.body_pos[b], m.body_quat[b]),
                inertial=MjInertial(
                    float(m.body_mass[b]),
                    rot3.vec3(m.body_ipos[b]),
                    rot3.rotate_inertia(diagonal(m.body_inertia[b]), rot3.from_quat_wxyz(m.body_iquat[b])),
                ),
                mocap=int(m.body_mocapid[b]) >= 0,
                physics=non_default(m, BODY_PHYSICS_DEFAULTS, {"body": b}),
            )
            for b in range(1, m.nbody)
        ]
        for j in range(m.njnt):
            out[int(m.jnt_bodyid[j]) - 1].joints.append(self.joint(j))
        for g in range(m.ngeom):
            body = int(m.geom_bodyid[g])
            if body > 0:
                out[body - 1].geoms.append(self.geom(g))
        for s in range(m.nsite):
            body = int(m.site_bodyid[s])
            if body > 0:
                out[body - 1].sites.append(self.site(s))
        return out

    def world_geoms(self) -> list[MjGeom]:
        return [self.geom(g) for g in range(self.m.ngeom) if int(self.m.geom_bodyid[g]) == 0]

    def world_sites(self) -> list[MjSite]:
        return [self.site(s) for s in range(self.m.nsite) if int(self.m.site_bodyid[s]) == 0]

    def joint(self, j: int) -> MjJoint:
        m = self.m
        kind = JOINT_KINDS.get(int(m.jnt_type[j]), "hinge")
        qadr, dadr = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        scalar = kind in ("hinge", "slide")
        return MjJoint(
            index=j,
            name=self.name("joint", j),
            kind=kind,
            pos=rot3.vec3(m.jnt_pos[j]),
            axis=rot3.vec3(m.jnt_axis[j]),
            limited=bool(m.jnt_limited[j]),
            range=(float(m.jnt_range[j][0]), float(m.jnt_range[j][1])),
            ref=float(m.qpos0[qadr]) if scalar else 0.0,
            damping=float(m.dof_damping[dadr]),
            frictionloss=float(m.dof_frictionloss[dadr]),
            armature=float(m.dof_armature[dadr]),
            stiffness=float(m.jnt_stiffness[j]),
            springref=float(m.qpos_spring[qadr]) if scalar else 0.0,
            actfrc=(float(m.jnt_actfrcrange[j][0]), float(m.jnt_actfrcrange[j][1]))
            if bool(m.jnt_actfrclimited[j])
            else None,
            qpos_address=qadr,
            physics=non_default(m, JOINT_PHYSICS_DEFAULTS, {"jnt": j, "dof": dadr}),
        )

    def geom(self, g: int) -> MjGeom:
        m = self.m
        kind = enum_word(self.mj.mjtGeom(int(m.geom_type[g])), "mjGEOM_")
        pose = pose_of(m.geom_pos[g], m.geom_quat[g])
        rgba = singles(m.geom_rgba[g])
        material = None
        look: dict[str, Any] = {}
        matid = int(m.geom_matid[g])
        if matid >= 0:
            material = self.name("material", matid)
            if all_close(rgba, DEFAULT_RGBA):
                rgba = singles(m.mat_rgba[matid])
            look = self._look(matid)
        geom = MjGeom(
            index=g,
            name=self.name("geom", g),
            kind=kind,
            size=rot3.vec3(m.geom_size[g]),
            pose=pose,
            contype=int(m.geom_contype[g]),
            conaffinity=int(m.geom_conaffinity[g]),
            group=int(m.geom_group[g]),
            rgba=(rgba[0], rgba[1], rgba[2], rgba[3]),
            material=material,
            look=look,
            friction=rot3.vec3(m.geom_friction[g]),
            condim=int(m.geom_condim[g]),
            contact=contact_attributes(m, g),
            paired=g in self.paired,
            collision_group=self.collisions_elsewhere and int(m.geom_group[g]) == MENAGERIE_COLLISION_GROUP,
        )
        mesh = int(m.geom_dataid[g])
        if kind == "mesh" and mesh >= 0:
            self._mesh(geom, mesh)
        return geom

    def _look(self, matid: int) -> dict[str, Any]:
        """Material ``matid``'s specular, shininess and emission where not MuJoCo's defaults (0.5, 0.5,
        0), and the file of its colour (RGB role) texture, relative to the model's folder."""
        m = self.m
        out: dict[str, Any] = {}
        for key, default in MATERIAL_DEFAULTS.items():
            value = single(getattr(m, f"mat_{key}")[matid])
            if value != single(default):
                out[key] = value
        try:
            roles = m.mat_texid[matid]
            texture = int(roles[TEXTURE_RGB_ROLE]) if hasattr(roles, "__len__") else int(roles)
            if texture >= 0:
                start = int(m.tex_pathadr[texture])
                written = ""
                if start >= 0 and int(m.tex_type[texture]) == TEXTURE_2D:
                    raw = bytes(int(x) & 0xFF for x in m.paths[start:])
                    written = raw.split(b"\0", 1)[0].decode("utf-8", "replace")
                if written:
                    out["texture"] = str(self.model_dir / written)
                else:  # generated (builtin), or a cube or skybox texture: no image file the model holds
                    out["texture_not_held"] = self.name("texture", texture) or f"#{texture}"
        except (AttributeError, IndexError):
            pass  # an older MuJoCo: no texture paths in the model
        return out

    def _mesh(self, geom: MjGeom, mesh: int) -> None:
        """Name the mesh file and undo MuJoCo's re-centring: the compiled geom frame sits at the
        mesh's centre of mass, on its principal axes; the file's frame is that pose times the
        inverse of (mesh_pos, mesh_quat)."""
        m = self.m
        geom.mesh_name = self.name("mesh", mesh)
        geom.pose = geom.pose @ pose_of(m.mesh_pos[mesh], m.mesh_quat[mesh]).inverse()
        geom.mesh_scale = rot3.vec3(m.mesh_scale[mesh])
        meshes = list(self.spec.meshes)
        if mesh < len(meshes):
            written = str(meshes[mesh].file or "")
            geom.mesh_file = written or None
            if written:
                geom.mesh_path = str(mesh_path(self.model_dir, str(self.spec.meshdir or ""), written))

    def site(self, s: int) -> MjSite:
        m = self.m
        shown: dict[str, Any] = {}  # what MuJoCo shows of the site, when not its default
        if int(m.site_group[s]) != 0:
            shown["group"] = int(m.site_group[s])
        rgba = list(singles(m.site_rgba[s]))
        if not all_close(tuple(rgba), SITE_RGBA, rtol=0.0, atol=1e-7):
            shown["rgba"] = rgba
        return MjSite(
            index=s,
            name=self.name("site", s),
            kind=enum_word(self.mj.mjtGeom(int(m.site_type[s])), "mjGEOM_"),
            pose=pose_of(m.site_pos[s], m.site_quat[s]),
            size=rot3.vec3(m.site_size[s]),
            shown=shown,
        )

    # -- what the model keeps as data ---------------------------------------------------------

    def cameras_and_lights(self) -> list[tuple[int, str, str | None, Pose, dict[str, Any]]]:
        """(body, kind, name, pose in the body frame, parameters) of every camera and light."""
        m = self.m
        out: list[tuple[int, str, str | None, Pose, dict[str, Any]]] = []
        for c in range(m.ncam):
            pose = pose_of(m.cam_pos[c], m.cam_quat[c])
            params: dict[str, Any] = {"fovy": float(m.cam_fovy[c])}
            params.update(self._tracking("cam", c))
            resolution = [int(x) for x in m.cam_resolution[c]]
            if resolution != [1, 1]:
                params["resolution"] = resolution
            if abs(float(m.cam_ipd[c]) - CAMERA_IPD) > 1e-12:
                params["ipd"] = float(m.cam_ipd[c])
            out.append((int(m.cam_bodyid[c]), "camera", self.name("camera", c), pose, params))
        for lt in range(m.nlight):
            pose = translation(m.light_pos[lt])
            params = {
                "dir": [float(x) for x in m.light_dir[lt]],
                "diffuse": list(singles(m.light_diffuse[lt])),
                "type": enum_word(self.mj.mjtLightType(int(m.light_type[lt])), "mjLIGHT_"),
                "castshadow": bool(m.light_castshadow[lt]),
                "active": bool(m.light_active[lt]),
                "attenuation": list(singles(m.light_attenuation[lt])),
                "cutoff": single(m.light_cutoff[lt]),
                "exponent": single(m.light_exponent[lt]),
                "ambient": list(singles(m.light_ambient[lt])),
                "specular": list(singles(m.light_specular[lt])),
            }
            params.update(self._tracking("light", lt))
            out.append((int(m.light_bodyid[lt]), "light", self.name("light", lt), pose, params))
        return out

    def _tracking(self, prefix: str, index: int) -> dict[str, Any]:
        """A camera's or light's ``mode`` and ``target`` body, when it moves otherwise than with its body."""
        m = self.m
        mode = enum_word(self.mj.mjtCamLight(int(getattr(m, f"{prefix}_mode")[index])), "mjCAMLIGHT_")
        if mode == "fixed":
            return {}
        out: dict[str, Any] = {"mode": mode}
        target = int(getattr(m, f"{prefix}_targetbodyid")[index])
        if target >= 0:
            out["target"] = self.name("body", target)
        return out

    def equalities(self) -> list[dict[str, Any]]:
        m = self.m
        out = []
        for e in range(m.neq):
            kind = enum_word(self.mj.mjtEq(int(m.eq_type[e])), "mjEQ_")
            objtype = enum_word(self.mj.mjtObj(int(m.eq_objtype[e])), "mjOBJ_")
            obj1, obj2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
            named = kind if kind in ("joint", "tendon") else objtype  # MuJoCo sets no objtype for these
            out.append(
                {
                    "index": e,
                    "name": self.name("equality", e),
                    "type": kind,
                    "objtype": objtype,
                    "obj1": self._object_name(named, obj1),
                    "obj2": self._object_name(named, obj2),
                    "obj1id": obj1,
                    "obj2id": obj2,
                    "data": [float(x) for x in m.eq_data[e]],
                    "active": bool(m.eq_active0[e]),
                    "solver": non_default(m, EQUALITY_SOLVER_DEFAULTS, {"eq": e}),
                }
            )
        return out

    def _object_name(self, objtype: str, index: int) -> str | None:
        if index < 0 or objtype in ("unknown", ""):
            return None
        try:
            return self.name(objtype, index) or f"{objtype}{index}"
        except AttributeError:
            return f"{objtype}{index}"

    def actuators(self) -> list[dict[str, Any]]:
        m = self.m
        out = []
        for a in range(m.nu):
            trn = enum_word(self.mj.mjtTrn(int(m.actuator_trntype[a])), "mjTRN_")
            target_kind = {"jointinparent": "joint", "slidercrank": "site"}.get(trn, trn)
            entry: dict[str, Any] = {
                "name": self.name("actuator", a),
                "transmission": trn,
                "target": self._object_name(target_kind, int(m.actuator_trnid[a][0])),
                "gear": float(m.actuator_gear[a][0]),
                "gain": enum_word(self.mj.mjtGain(int(m.actuator_gaintype[a])), "mjGAIN_"),
                "bias": enum_word(self.mj.mjtBias(int(m.actuator_biastype[a])), "mjBIAS_"),
            }
            second = int(m.actuator_trnid[a][1])
            if trn in ("site", "slidercrank") and second >= 0:  # the reference site, the slider site
                entry["refsite" if trn == "site" else "slidersite"] = self._object_name("site", second)
            if bool(m.actuator_ctrllimited[a]):
                entry["ctrlrange"] = [float(x) for x in m.actuator_ctrlrange[a]]
            if bool(m.actuator_forcelimited[a]):
                entry["forcerange"] = [float(x) for x in m.actuator_forcerange[a]]
            entry["general"], why = general_attributes(self.mj, m, a)
            if why is not None:
                entry["unwritable"] = why
            out.append(entry)
        return out

    def sensors(self) -> list[dict[str, Any]]:
        m = self.m
        out = []
        for s in range(m.nsensor):
            objtype = enum_word(self.mj.mjtObj(int(m.sensor_objtype[s])), "mjOBJ_")
            entry: dict[str, Any] = {
                "name": self.name("sensor", s),
                "type": enum_word(self.mj.mjtSensor(int(m.sensor_type[s])), "mjSENS_"),
                "objtype": objtype,
                "object": self._object_name(objtype, int(m.sensor_objid[s])),
            }
            reftype = enum_word(self.mj.mjtObj(int(m.sensor_reftype[s])), "mjOBJ_")
            if int(m.sensor_refid[s]) >= 0 and reftype not in ("unknown", ""):
                entry["reftype"] = reftype
                entry["refname"] = self._object_name(reftype, int(m.sensor_refid[s]))
            for key in ("cutoff", "noise"):  # only when set: 0 is MuJoCo's "none"
                value = float(getattr(m, f"sensor_{key}")[s])
                if value > 0.0:
                    entry[key] = value
            out.append(entry)
        return out

    def tendons(self) -> list[dict[str, Any]]:
        m = self.m
        out = []
        for t in range(m.ntendon):
            start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
            wraps = []
            for w in range(start, start + count):
                wtype = enum_word(self.mj.mjtWrap(int(m.wrap_type[w])), "mjWRAP_")
                objtype = {"joint": "joint", "site": "site", "sphere": "geom", "cylinder": "geom"}.get(wtype)
                wrap = {
                    "type": wtype,
                    "object": self._object_name(objtype, int(m.wrap_objid[w])) if objtype else None,
                    "coef": float(m.wrap_prm[w]),
                }
                if objtype == "geom" and float(m.wrap_prm[w]) >= 0.0:  # the side site, by its id
                    wrap["sidesite"] = self._object_name("site", int(m.wrap_prm[w]))
                wraps.append(wrap)
            fixed = all(w["type"] == "joint" for w in wraps)
            out.append(
                {"name": self.name("tendon", t), "kind": "fixed" if fixed else "spatial", "wraps": wraps,
                 "attributes": tendon_attributes(m, t, spatial=not fixed),
                 "length0": float(m.tendon_length0[t])}
            )
        return out

    def keyframes(self) -> list[dict[str, Any]]:
        m = self.m
        out = []
        for k in range(m.nkey):
            key: dict[str, Any] = {
                "name": self.name("key", k),
                "time": float(m.key_time[k]),
                "qpos": [float(x) for x in m.key_qpos[k]],
            }
            if m.nu:
                key["ctrl"] = [float(x) for x in m.key_ctrl[k]]
            out.append(key)
        return out


def mesh_path(model_dir: Path, meshdir: str, written: str) -> Path:
    """Where MuJoCo opens a mesh file: absolute as written, else under ``meshdir``, itself relative
    to the main model file's folder unless absolute."""
    path = Path(written)
    if path.is_absolute():
        return path
    base = Path(meshdir) if meshdir else Path()
    if not base.is_absolute():
        base = model_dir / base
    return (base / path).absolute()


def contact_attributes(m: Any, g: int) -> dict[str, str]:
    """Geom ``g``'s contact parameters that differ from MuJoCo's defaults, as MJCF attribute text
    (numpy-free: the reader may run on the tuples of the ctypes stand-in)."""
    out: dict[str, str] = {}
    for name, default in GEOM_CONTACT_DEFAULTS.items():
        raw = getattr(m, f"geom_{name}")[g]
        values = tuple(float(x) for x in (raw if hasattr(raw, "__len__") else (raw,)))
        if any(abs(a - b) > 1e-12 * max(1.0, abs(b)) for a, b in zip(values, default, strict=True)):
            out[name] = str(int(values[0])) if name in INTEGER_CONTACT else plain(values)
    friction = tuple(float(x) for x in m.geom_friction[g])
    acting = 3 if int(m.geom_condim[g]) >= 6 else 2 if int(m.geom_condim[g]) >= 4 else 1
    if friction[acting:] != MUJOCO_FRICTION[acting:]:  # coefficients its condim leaves idle, which
        out["friction"] = plain(friction)  # still count when MuJoCo mixes it with a larger condim
    out.update(fluid_attributes(m, g))
    return out


MATERIAL_DEFAULTS = {"specular": 0.5, "shininess": 0.5, "emission": 0.0}  # MuJoCo's <material> defaults
TEXTURE_RGB_ROLE = 1  # mjTEXROLE_RGB: the colour texture among a material's texture roles
TEXTURE_2D = 0  # mjTEXTURE_2D
FLUID_COEFFICIENTS = (0.5, 0.25, 1.5, 1.0, 1.0)  # MuJoCo's fluidcoef default (blunt, slender, angular
# drag, Kutta lift, Magnus lift)


def fluid_attributes(m: Any, g: int) -> dict[str, str]:
    """Geom ``g``'s ellipsoid fluid model (``fluidshape``, ``fluidcoef``), which acts when the option's
    ``density`` or ``viscosity`` is set: compiled ``geom_fluid`` is (shape flag, five coefficients,
    virtual mass and inertia MuJoCo derives)."""
    try:
        row = m.geom_fluid[g]
    except AttributeError:
        return {}
    if float(row[0]) <= 0.0:
        return {}
    coefficients = tuple(float(x) for x in row[1:6])
    out = {"fluidshape": "ellipsoid"}
    if any(abs(a - b) > 1e-12 for a, b in zip(coefficients, FLUID_COEFFICIENTS, strict=True)):
        out["fluidcoef"] = plain(coefficients)
    return out
