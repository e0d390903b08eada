"""MJCF to MJCF writes back the source's own sites, cameras, lights and sensors (formats/mjcf/write_own).

Before, they were kept as data only and named in an MK806/MK808 note: dm_control's hopper lost its
2 touch sites, 3 sensors and 2 world cameras, the humanoid 20 sensors and 19 sites. Each corpus case
converts through the CLI, loads source and output in MuJoCo, and compares the counts and, at the
same non-trivial pose and velocity, every sensor's reading by name.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.cli import main

from .conftest import CORPUS

SUITE = CORPUS / "dm_control_suite" / "dm_control" / "suite"
OWN_KINDS = ("MJCF sensors", "MJCF sites", "MJCF cameras", "MJCF lights", "MJCF world sites")
LIFT = 1.0  # m: the root is raised so that no foot reaches the source's floor (not part of the robot)


def _convert(source: Path, out: Path) -> str:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    return result.output


def _name(m: mujoco.MjModel, kind: mujoco.mjtObj, index: int) -> str:
    return str(mujoco.mj_id2name(m, kind, index) or "")


def _sensors(m: mujoco.MjModel) -> dict[str, int]:
    """Sensor name → its type, in MuJoCo's order (that of ``sensordata``)."""
    return {_name(m, mujoco.mjtObj.mjOBJ_SENSOR, s): int(m.sensor_type[s]) for s in range(m.nsensor)}


def _pose(a: mujoco.MjModel, b: mujoco.MjModel) -> tuple[mujoco.MjData, mujoco.MjData]:
    """The same joint positions and velocities in both (joints by name; the free joint, unnamed in
    the output, by being the free one), away from the joint zero and off the floor."""
    da, db = mujoco.MjData(a), mujoco.MjData(b)
    rng = np.random.default_rng(7)
    free, hinge, slide = (int(k) for k in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_HINGE,
                                            mujoco.mjtJoint.mjJNT_SLIDE))
    free_b = [j for j in range(b.njnt) if int(b.jnt_type[j]) == free]
    for j in range(a.njnt):
        name = _name(a, mujoco.mjtObj.mjOBJ_JOINT, j)
        kind = int(a.jnt_type[j])
        k = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
        if kind == free:
            k = free_b[0]
        assert k >= 0, f"joint {name} is not in the output"
        qa, qb, va, vb = a.jnt_qposadr[j], b.jnt_qposadr[k], a.jnt_dofadr[j], b.jnt_dofadr[k]
        if kind == free:
            quat = rng.normal(size=4)
            q = np.r_[0.1, -0.2, 3.0 * LIFT, quat / np.linalg.norm(quat)]
            v = rng.uniform(-1.0, 1.0, size=6)
            da.qpos[qa : qa + 7], db.qpos[qb : qb + 7] = q, q
            da.qvel[va : va + 6], db.qvel[vb : vb + 6] = v, v
            continue
        assert kind in (hinge, slide)
        lo, hi = a.jnt_range[j] if a.jnt_limited[j] else (-0.5, 0.5)
        mid, half = (lo + hi) / 2.0, (hi - lo) / 2.0  # a third of the range about its middle: no
        x = LIFT if name == "rootz" else mid + float(rng.uniform(-half, half)) / 3.0  # self-contact
        da.qpos[qa] = db.qpos[qb] = x
        da.qvel[va] = db.qvel[vb] = float(rng.uniform(-1.0, 1.0))
    mujoco.mj_forward(a, da)
    mujoco.mj_forward(b, db)
    return da, db


def _same_readings(a, da, b, db) -> None:  # type: ignore[no-untyped-def]
    """Every sensor of model ``a`` reads in ``b`` (found by name) what it reads in ``a``, to 1e-9."""
    for s in range(a.nsensor):
        name = _name(a, mujoco.mjtObj.mjOBJ_SENSOR, s)
        t = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_SENSOR, name)
        x = da.sensordata[a.sensor_adr[s] : a.sensor_adr[s] + a.sensor_dim[s]]
        y = db.sensordata[b.sensor_adr[t] : b.sensor_adr[t] + b.sensor_dim[t]]
        np.testing.assert_allclose(y, x, rtol=0.0, atol=1e-9, err_msg=f"sensor {name}")


@pytest.mark.parametrize(
    ("model", "counts"),
    [
        # nsensor, nsite, ncam, nlight of the source (measured: MuJoCo 4.0)
        ("hopper", (3, 2, 2, 1)),
        ("humanoid", (34, 25, 3, 1)),
        ("humanoid_CMU", (8, 5, 3, 1)),
    ],
)
def test_dm_control_sensors_sites_cameras_and_lights_come_back(
    tmp_path: Path, model: str, counts: tuple[int, int, int, int]
) -> None:
    source = SUITE / f"{model}.xml"
    if not source.is_file():
        pytest.skip(f"corpus file {source} not present")
    out = tmp_path / "m" / f"{model}.xml"
    said = _convert(source, out)
    a, b = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    assert (a.nsensor, a.nsite, a.ncam, a.nlight) == counts
    assert (b.nsensor, b.nsite, b.ncam, b.nlight) == counts
    assert list(_sensors(b).items()) == list(_sensors(a).items())  # names, types, source order
    cameras = {_name(a, mujoco.mjtObj.mjOBJ_CAMERA, c): int(a.cam_mode[c]) for c in range(a.ncam)}
    assert {_name(b, mujoco.mjtObj.mjOBJ_CAMERA, c): int(b.cam_mode[c]) for c in range(b.ncam)} == cameras
    da, db = _pose(a, b)
    assert da.ncon == db.ncon == 0  # no floor contact: the touch sensors read what the robot does
    assert np.max(np.abs(da.qvel)) > 0.1 and np.max(np.abs(da.qpos)) > 0.1
    _same_readings(a, da, b, db)
    for kind in OWN_KINDS:
        assert f"{kind}" not in said, f"{model}: a note still says {kind} are not written:\n{said}"


OWN = """<mujoco model="own">
  <worldbody>
    <camera name="overview" pos="0 -3 1" xyaxes="1 0 0 0 0.3 1" mode="targetbody" target="arm" fovy="60"/>
    <light name="sun" pos="0 0 4" dir="0 0.2 -1" directional="true" castshadow="false"/>
    <site name="marker" pos="1 0 0" size="0.02"/>
    <body name="arm" pos="0 0 1">
      <joint name="swing" type="hinge" axis="0 1 0" range="-2 2"/>
      <geom name="rod" type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
      <site name="tip" pos="0 0 -0.5" type="box" size="0.02 0.03 0.04" rgba="1 0 0 1" group="2"/>
      <site name="anchor" pos="0 0 -0.2"/>
      <camera name="eye" pos="0 0 -0.5" mode="trackcom"/>
    </body>
  </worldbody>
  <tendon><spatial name="cable"><site site="marker"/><site site="anchor"/></spatial></tendon>
  <actuator><motor name="drive" joint="swing" gear="2"/></actuator>
  <sensor>
    <touch name="tip_touch" site="tip"/>
    <framepos name="tip_in_marker" objtype="site" objname="tip" reftype="site" refname="marker"/>
    <framequat name="tip_quat" objtype="geom" objname="rod"/>
    <jointvel name="swing_vel" joint="swing" cutoff="3"/>
    <actuatorfrc name="drive_force" actuator="drive"/>
    <tendonpos name="cable_length" tendon="cable"/>
    <subtreecom name="arm_com" body="arm"/>
    <clock name="time"/>
    <user name="custom" dim="1" needstage="pos" datatype="real"/>
  </sensor>
</mujoco>"""


def test_each_kind_comes_back_and_only_what_names_a_missing_object_is_noted(tmp_path: Path) -> None:
    """A user sensor (it needs the program's callback: never written) stays named in the MK806 note;
    the others, the tendon its sensor reads (between a world site and a body's), the sites (shape,
    colour and group kept), the world camera (its mode, target and fovy) and light are written, and
    read the same."""
    source = tmp_path / "own.xml"
    source.write_text(OWN)
    out = tmp_path / "m" / "own.xml"
    said = _convert(source, out)
    a, b = mujoco.MjModel.from_xml_path(str(source)), mujoco.MjModel.from_xml_path(str(out))
    assert set(_sensors(b)) == set(_sensors(a)) - {"custom"}
    notes = [line for line in said.splitlines() if "MK806" in line and "MJCF sensors" in line]
    assert len(notes) == 1 and "1 of 9 MJCF sensors not written (custom)" in notes[0]
    assert b.ntendon == 1 and "MJCF tendons" not in said
    assert not any(kind in said for kind in OWN_KINDS[1:])
    assert (b.nsite, b.ncam, b.nlight) == (a.nsite, a.ncam, a.nlight) == (3, 2, 1)
    tip_a = mujoco.mj_name2id(a, mujoco.mjtObj.mjOBJ_SITE, "tip")
    tip_b = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_SITE, "tip")
    for field in ("site_type", "site_size", "site_rgba", "site_group"):
        np.testing.assert_allclose(getattr(b, field)[tip_b], getattr(a, field)[tip_a], err_msg=field)
    camera = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_CAMERA, "overview")
    assert b.cam_mode[camera] == mujoco.mjtCamLight.mjCAMLIGHT_TARGETBODY and b.cam_fovy[camera] == 60.0
    assert _name(b, mujoco.mjtObj.mjOBJ_BODY, int(b.cam_targetbodyid[camera])) == "arm"
    eye = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_CAMERA, "eye")
    assert b.cam_mode[eye] == mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM
    sun = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_LIGHT, "sun")
    assert b.light_type[sun] == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL and not b.light_castshadow[sun]
    da, db = _pose(a, b)
    da.ctrl[:] = db.ctrl[:] = 0.7
    mujoco.mj_forward(a, da)
    mujoco.mj_forward(b, db)
    _same_readings(b, db, a, da)
    assert b.sensor_cutoff[mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_SENSOR, "swing_vel")] == 3.0


def test_a_renamed_object_is_referred_to_by_its_written_name(tmp_path: Path) -> None:
    """A site that clashes with a device's site is renamed (MK800); the sensor follows it."""
    source = tmp_path / "r.xml"
    source.write_text("""<mujoco model="r"><worldbody>
      <body name="b" pos="0 0 1"><freejoint/><geom size="0.1" mass="1"/>
        <site name="imu"/><site name="acc" pos="0.1 0 0"/></body></worldbody>
      <sensor><accelerometer name="acc" site="imu"/><framepos name="p" objtype="site" objname="acc"/></sensor>
    </mujoco>""")
    out = tmp_path / "m" / "r.xml"
    _convert(source, out)
    b = mujoco.MjModel.from_xml_path(str(out))
    p = mujoco.mj_name2id(b, mujoco.mjtObj.mjOBJ_SENSOR, "p")
    site = int(b.sensor_objid[p])
    assert _name(b, mujoco.mjtObj.mjOBJ_SITE, site) == "acc_2"
    np.testing.assert_allclose(b.site_pos[site], [0.1, 0.0, 0.0])
