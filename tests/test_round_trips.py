"""Conversions keep the robot: X → Y → X for every pair of formats, compared as models.

For each source model of format X and each other target Y, the source is written as Y, read
back, written as X again and read back; the final model must equal the source
(:func:`modelkit.convert.compare.compare_robots`: links, joints matched by child link, types,
axes, limits, masses, COMs, inertia tensors, link poses at random configurations; 1e-9), names
mapped through the writers' MK800 renames. Known, documented losses are listed with their reason
in ``EXPECTED_LOSSES`` and nowhere else: any other difference fails.

Also here: the issue's acceptance checks on the tutorial robots (loads in MuJoCo and PyBullet with
the right joint count, total mass and wheel geometry; the Extrusion tracks written as meshes of the
reader's volume), and that outputs carry no absolute path and do not depend on the output folder.
"""

from __future__ import annotations

import copy
import json
import math
import re
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from modelkit.api import validate
from modelkit.convert import convert, write
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.notes import ConversionNote, renames
from modelkit.convert.numbers import fmt
from modelkit.convert.options import WriteOptions
from modelkit.convert.registry import target_info
from modelkit.formats.urdf.write_links import TINY_MASS
from modelkit.model import Cylinder, Joint, JointType, Link, Robot
from modelkit.spatial import Pose

from .conftest import CORPUS, SAMPLES, TUTORIAL

CHOREONOID = CORPUS / "choreonoid" / "share" / "model"
SDF_MODELS = CORPUS / "sdformat_urdf" / "sdformat_test_files" / "models"
SOURCES = {
    "body": [TUTORIAL / f"{n}.body" for n in ("mobile_robot_primitive", "mobile_robot_pantilt",
                                             "mobile_robot_sensors", "mobile_robot")]
    + [CHOREONOID / p for p in ("misc/pendulum.body", "PA10/PA10.body", "GR001/GR001.body", "SR1/SR1.body")],
    "urdf": [CORPUS / "urdf_tutorial" / "urdf" / f for f in ("01-myfirst.urdf", "05-visual.urdf",
                                                             "06-flexible.urdf", "07-physics.urdf")]
    + [CORPUS / "kuka_experimental" / "kuka_kr16_support" / "urdf" / "kr16_2.urdf",
       CORPUS / "urdf_tutorial" / "urdf" / "08-macroed.urdf.xacro",
       SAMPLES / "smartcar" / "urdf" / "myrobot.urdf.xacro"],
    "sdf": [SDF_MODELS / n / f"{n}.sdf" for n in ("graph_tree", "joint_revolute_axis", "link_inertia",
                                                   "joint_prismatic", "geometry_cylinder")]
    + [SAMPLES / "gazebo_unicycle" / "unicycle.sdf"],
    "mjcf": [CORPUS / "dm_control_suite" / "dm_control" / "suite" / f
             for f in ("cartpole.xml", "acrobot.xml", "pendulum.xml", "reacher.xml")]
    + [CORPUS / "mujoco_model" / "humanoid" / "humanoid.xml"],
}
FAMILY_TARGET = {"body": "body", "urdf": "urdf", "sdf": "sdf", "mjcf": "mjcf"}



def _tiny_mass(d: Difference) -> bool:
    """SDF and MJCF cannot hold a massless link that moves or floats (SDF defaults it to 1 kg,
    MuJoCo refuses it), nor can Choreonoid simulate a moving link with nothing of mass below it: the
    writers give it 1e-6 kg with an MK816 note."""
    return d.quantity == "mass" and d.detail == "0.0 became 1e-06"


def _sensor_links(source: Robot) -> Callable[[Difference], bool]:
    """The URDF writer gives each camera, LiDAR and IMU a massless link on a fixed joint, named after
    the device (``_2``... where the name is taken; cameras also ``<name>_optical``; MK847): read back,
    they are links the source did not have. Judged from the source's devices, not the writer's notes."""
    from modelkit.formats.urdf.write_frames import FRAMED_KINDS

    devices = [d for link in source.links for d in link.devices
               if d.canonical in FRAMED_KINDS and d.name != link.name and "xml" not in d.params]
    named = re.compile("|".join(rf"{re.escape(d.name)}(_\d+)?(_optical)?" for d in devices) or "(?!)")
    return lambda d: (d.quantity == "link-set" and named.fullmatch(d.where) is not None
                      and d.detail == "link only in the converted model")


KINEMATIC_ONLY = "the URDF has no inertials at all (a kinematic model): its links are massless"
# --base auto welds a robot without mass (MK830): a one-link kinematic model then has no moving body
# for MuJoCo to refuse, so nothing is made up and the MJCF round trip is exact.
WELDED_EXACT = {("01-myfirst.urdf", "mjcf"), ("05-visual.urdf", "mjcf")}
FIXED_EXACT = {("01-myfirst.urdf", "sdf"), ("05-visual.urdf", "sdf")}
MULTI_JOINT = ("MuJoCo's multi-joint bodies read as chains of massless links; a format with one "
               "joint per link keeps them, and coming back to MJCF they need a mass")
# (source file name, through) → (why the model legitimately changes, which differences that allows).
# Every other difference fails the test.
EXPECTED_LOSSES: dict[tuple[str, str], tuple[str, Callable[[Difference], bool]]] = {
    # the SDF writer's tiny mass on a link of a fixed joint reads back from URDF as a massless frame
    # (modelkit.formats.urdf.massless): 01 and 05, all fixed joints, come back exact through SDF
    **{(f, t): (KINEMATIC_ONLY, _tiny_mass) for f in ("01-myfirst.urdf", "05-visual.urdf", "06-flexible.urdf")
       for t in ("sdf", "mjcf") if (f, t) not in WELDED_EXACT and (f, t) not in FIXED_EXACT},
    ("06-flexible.urdf", "body"): (KINEMATIC_ONLY, _tiny_mass),
    **{("humanoid.xml", t): (MULTI_JOINT, _tiny_mass) for t in ("urdf", "sdf", "body")},
}

CASES = [(fam, path, through) for fam, paths in SOURCES.items() for path in paths
         for through in ("urdf", "sdf", "mjcf", "body") if through != FAMILY_TARGET[fam]]


def _read(path: Path) -> Robot:
    checked = validate(path)
    robots = [r for r in checked.robots if r.root is not None]
    assert robots, [str(d) for d in checked.diagnostics]
    return robots[0]


def _trip(source: Robot, through: str, back: str, folder: Path) -> tuple[Robot, list[ConversionNote]]:
    """``source`` written as ``through`` and back. Through SDF with ``--actuators none``: the trip then
    shows that the source's own actuators come back, and that no others are added (by default the SDF
    writer gives a source without actuators the --actuators choice as gz-sim systems, as MJCF does)."""
    mid = folder / "mid" / f"model{target_info(through).suffix}"
    options = WriteOptions(actuators="none") if through == "sdf" else None
    notes = write(source, mid, through, options=options)
    middle = _read(mid)
    end = folder / "end" / f"model{target_info(back).suffix}"
    notes_back = write(middle, end, back)
    return _read(end), [*notes, *notes_back]


def _settled(source: Robot, notes: list[ConversionNote]) -> Robot:
    """A URDF root left open is welded by --base auto (MK830), and a URDF holds a weld as a `world` link
    with a fixed joint: what a trip back to URDF must give."""
    if source.root_joint is not None or not any(n.code == "MK830" and "welded" in n.message for n in notes):
        return source
    out = copy.deepcopy(source)
    root = str(out.root)
    out.links.insert(0, Link("world"))
    out.joints.append(Joint(f"world_to_{root}", JointType.FIXED, "world", root, origin=out.root_pose))
    out.root, out.root_joint, out.root_pose = "world", JointType.FIXED, Pose()
    return out


@pytest.mark.parametrize(("family", "path", "through"), CASES,
                         ids=[f"{p.name}-via-{t}" for _, p, t in CASES])
def test_x_to_y_to_x_keeps_the_robot(family: str, path: Path, through: str, tmp_path: Path) -> None:
    if not path.is_file():
        pytest.skip(f"{path} not available")
    source = _read(path)
    final, notes = _trip(source, through, FAMILY_TARGET[family], tmp_path)
    differences: list[Difference] = compare_robots(_settled(source, notes), final, renames(notes, "link"))
    if through == "urdf":
        differences = [d for d in differences if not _sensor_links(source)(d)]
    expected = EXPECTED_LOSSES.get((path.name, through))
    if expected is not None:
        why, allowed = expected
        assert differences, f"expected a loss ({why}) but the round trip was exact: update EXPECTED_LOSSES"
        differences = [d for d in differences if not allowed(d)]
    assert differences == [], "\n".join(str(d) for d in differences[:20])
    if through == "sdf":  # SDF holds actuators as gz-sim systems (docs/convert.md, "Actuators")
        assert _actuator_kinds(final, renames(notes, "link")) == _actuator_kinds(source, {})


def _actuator_kinds(robot: Robot, links: dict[str, str]) -> dict[str, str]:
    """Each actuator's kind by the (source-named) child link of its joint: joints may be renamed."""
    back = {new: old for old, new in links.items()}
    child = {j.name: j.child for j in robot.joints}
    return {back.get(child.get(a.joint, ""), child.get(a.joint, "")): a.kind.value for a in robot.actuators}


# ---- the acceptance checks on the tutorial robots ------------------------------------

PYBULLET_CHILD = textwrap.dedent("""\
    import json, sys
    import pybullet as p
    p.connect(p.DIRECT)
    body = p.loadURDF(sys.argv[1], flags=p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER)
    n = p.getNumJoints(body)
    masses = [p.getDynamicsInfo(body, i)[0] for i in range(-1, n)]
    moving = [p.getJointInfo(body, i)[1].decode() for i in range(n)
              if p.getJointInfo(body, i)[2] != p.JOINT_FIXED]
    shapes = {}
    for i in range(-1, n):
        name = p.getBodyInfo(body)[0].decode() if i == -1 else p.getJointInfo(body, i)[12].decode()
        shapes[name] = [[s[2], list(s[3])] for s in p.getCollisionShapeData(body, i)]
    print(json.dumps({"mass": sum(masses), "moving": moving, "shapes": shapes}))
""")


def _wheel_cylinders(robot: Robot) -> dict[str, tuple[float, float]]:
    out = {}
    for link in robot.links:
        for geom in link.collisions:
            if isinstance(geom.geometry, Cylinder) and "Wheel" in link.name:
                out[link.name] = (geom.geometry.radius, geom.geometry.length)
    return out


def _total_mass(robot: Robot) -> float:
    return sum(lk.inertial.mass for lk in robot.links if lk.inertial)


def _moving(robot: Robot) -> list[str]:
    return [j.name for j in robot.joints if j.type.moves]


@pytest.mark.parametrize("name", ["mobile_robot_primitive", "mobile_robot_pantilt", "mobile_robot_sensors"])
def test_tutorial_robot_loads_in_pybullet_and_mujoco(name: str, tmp_path: Path) -> None:
    import mujoco

    source = _read(TUTORIAL / f"{name}.body")
    wheels = _wheel_cylinders(source)
    assert len(wheels) == 2
    # PyBullet reads a link without <inertial> as 1 kg (MK816): the sensors' TF-frame links (MK847, 3 for
    # the sensor robot) carry a tiny inertial instead, counted in the default (none: urdf_sensor_links=False)
    sensor_links = 3 if name == "mobile_robot_sensors" else 0
    default = convert([TUTORIAL / f"{name}.body"], tmp_path / "default" / f"{name}.urdf")
    run = subprocess.run([sys.executable, "-c", PYBULLET_CHILD, str(tmp_path / "default" / f"{name}.urdf")],
                         capture_output=True, text=True, timeout=120, check=False)
    assert default.status == 0 and run.returncode == 0, run.stderr
    # (PyBullet prints its "No inertial data for link" warnings on stdout, unterminated, before the result)
    loaded = json.loads(run.stdout[run.stdout.rindex('{"mass"'):].splitlines()[0])
    assert math.isclose(loaded["mass"], _total_mass(source) + sensor_links * TINY_MASS, rel_tol=1e-12)
    result = convert([TUTORIAL / f"{name}.body"], tmp_path / f"{name}.urdf",
                     options=WriteOptions(urdf_sensor_links=False))
    assert result.status == 0
    run = subprocess.run([sys.executable, "-c", PYBULLET_CHILD, str(tmp_path / f"{name}.urdf")],
                         capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr
    loaded = json.loads(run.stdout.strip().splitlines()[-1])
    assert math.isclose(loaded["mass"], _total_mass(source), rel_tol=1e-9)
    joint_names = renames(result.notes, "joint")  # the wheel joints share their links' names
    assert sorted(loaded["moving"]) == sorted(joint_names.get(j, j) for j in _moving(source))
    for link, (radius, _length) in wheels.items():  # --wheel-collision auto: a sphere (MK826)
        (geom_type, dims), = loaded["shapes"][link]
        assert geom_type == 2  # GEOM_SPHERE: PyBullet reports (radius, radius, radius)
        assert np.allclose(dims[:1], [radius], rtol=1e-6)
    kept = convert([TUTORIAL / f"{name}.body"], tmp_path / "kept" / f"{name}.urdf",
                   options=WriteOptions(wheel_collision="cylinder", urdf_sensor_links=False))
    assert kept.status == 0
    run = subprocess.run([sys.executable, "-c", PYBULLET_CHILD, str(tmp_path / "kept" / f"{name}.urdf")],
                         capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr
    loaded = json.loads(run.stdout.strip().splitlines()[-1])
    for link, (radius, length) in wheels.items():
        (geom_type, dims), = loaded["shapes"][link]
        assert geom_type == 4  # GEOM_CYLINDER: PyBullet reports (length, radius, 0)
        assert np.allclose(dims[:2], [length, radius], rtol=1e-6)

    result = convert([TUTORIAL / f"{name}.body"], tmp_path / f"{name}.xml")
    assert result.status == 0
    model = mujoco.MjModel.from_xml_path(str(tmp_path / f"{name}.xml"))
    assert math.isclose(float(model.body_mass.sum()), _total_mass(source), rel_tol=1e-9)
    hinge_names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)
                   if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE}
    assert hinge_names == set(_moving(source))
    assert int(np.sum(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)) == 1
    for link, (radius, _length) in wheels.items():
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, link)
        spheres = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body
                   and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE and model.geom_contype[g]]
        assert len(spheres) == 1
        assert np.allclose(model.geom_size[spheres[0]][:1], [radius], rtol=1e-12)


def test_tracks_become_meshes_of_the_readers_volume(tmp_path: Path) -> None:
    import trimesh

    from modelkit.geometry.generated import signed_volume
    from modelkit.model import Mesh

    source = _read(TUTORIAL / "mobile_robot_tracks.body")
    volumes = sorted(abs(signed_volume(g.geometry.data)) for lk in source.links for g in lk.collisions
                     if isinstance(g.geometry, Mesh) and g.geometry.generator == "Extrusion"
                     and g.geometry.data is not None)
    assert len(volumes) == 2 and volumes[0] > 0
    result = convert([TUTORIAL / "mobile_robot_tracks.body"], tmp_path / "tracks.urdf")
    assert result.status == 0
    codes = [n.code for n in result.notes]
    assert codes.count("MK809") == 2 and "MK803" in codes
    written = sorted(trimesh.load(p, force="mesh").volume for p in (tmp_path / "meshes").glob("*.stl"))
    track_meshes = [v for v in written if any(math.isclose(v, w, rel_tol=1e-6) for w in volumes)]
    assert len(track_meshes) >= 1, (written, volumes)
    tracks = _read(tmp_path / "tracks.urdf")
    assert not any(j.type is JointType.PSEUDO_CONTINUOUS_TRACK for j in tracks.joints)
    # the sensors' TF frames (MK847): LiDAR, RealSense and its optical frame, written with the tiny
    # inertial and read back as massless frames
    frames = {lk.name for lk in tracks.links if lk.inertial is None}
    assert frames == {"LiDAR", "RealSense", "RealSense_optical"}, frames
    text = (tmp_path / "tracks.urdf").read_text()
    assert text.count(f'<mass value="{fmt(TINY_MASS)}"/>') == 3
    assert math.isclose(_total_mass(tracks), _total_mass(source), rel_tol=1e-12)


@pytest.mark.parametrize("target", ["urdf", "sdf", "mjcf", "body"])
def test_outputs_do_not_depend_on_the_folder(target: str, tmp_path: Path) -> None:
    """Two machines, two folders: the same bytes, and no absolute path in any file."""
    suffix = target_info(target).suffix
    outputs = []
    for folder in ("first/deeper", "second"):
        out = tmp_path / folder
        result = convert([TUTORIAL / "mobile_robot_sensors.body", TUTORIAL / "mobile_robot_tracks.body"],
                         out, target)
        assert result.status == 0
        files = {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
        for name, data in files.items():
            for needle in (str(tmp_path), str(SAMPLES), str(Path.home()), "/tmp/"):
                assert needle.encode() not in data, f"{name} contains {needle}"
        outputs.append(files)
    assert outputs[0] == outputs[1]
    assert any(name.endswith(suffix) for name in outputs[0])
