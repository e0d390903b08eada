"""Two massless links of icub-models' iCub (PyPI ``icub-models`` 3.2.0) that MuJoCo could not take.

* ``base_link``: the free root, a massless frame on a fixed joint over ``root_link``, whose 4.72 kg come
  with a zero tensor (MK302). MuJoCo refuses a moving body whose weld group has no inertia, and the
  MJCF writer added its 1e-9 kg·m² to ``base_link``, which has no mass and so got no ``<inertial>``:
  ``convert`` ended with MK877 ("MuJoCo refuses the written file") on Genova03, Lisboa01 and Nancy01.
  The frame now carries the fix itself (``MIN_MASS`` kg with it, MK870).
* ``torso_2``: 0 kg with a 2e-3 kg·m² tensor, on a hinge. Pinocchio reads that tensor; the MJCF writer
  keeps it and adds its own ``MIN_MASS`` and 1e-9 kg·m² (MK816), and ``verify`` compares the engine
  with exactly that instead of calling the kept tensor a fault.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from modelkit.verify.api import verify

mujoco = pytest.importorskip("mujoco")
np = pytest.importorskip("numpy")
pin = pytest.importorskip("pinocchio")

TORSO = 'ixx="0.0005308" ixy="-1.923e-6" ixz="5.095e-5" iyy="0.002031" iyz="-3.849e-7" izz="0.001803"'
ICUB_LIKE = f"""<robot name="frames">
  <link name="base_link"/>
  <link name="root_link"><inertial><mass value="4.72"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><box size="0.1 0.2 0.1"/></geometry></collision></link>
  <joint name="base_fixed" type="fixed"><parent link="base_link"/><child link="root_link"/></joint>
  <link name="torso_2"><inertial><mass value="0"/><inertia {TORSO}/></inertial></link>
  <joint name="torso_roll" type="revolute"><parent link="root_link"/><child link="torso_2"/>
    <origin xyz="0 0 0.1"/><axis xyz="1 0 0"/>
    <limit lower="-0.6" upper="0.6" effort="80" velocity="1"/></joint>
  <link name="chest"><inertial><origin xyz="0 0 0.1"/><mass value="3"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <joint name="torso_yaw" type="revolute"><parent link="torso_2"/><child link="chest"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="80" velocity="1"/></joint>
</robot>
"""


@pytest.fixture()
def source(tmp_path: Path) -> Path:
    path = tmp_path / "frames.urdf"
    path.write_text(ICUB_LIKE)
    return path


def test_mujoco_loads_the_file_and_its_dynamics_are_pinocchios(source: Path, tmp_path: Path) -> None:
    out = tmp_path / "out" / "frames.xml"
    floating = WriteOptions(base="floating")  # as iCub's legs float it
    notes = write(load(source), out, options=floating, force=True)
    codes = {n.code for n in notes}
    assert "MK877" not in codes
    (frame,) = [n for n in notes if n.code == "MK870" and "base_link" in n.message]
    assert "since the link itself has no mass" in frame.message
    (torso,) = [n for n in notes if n.code == "MK816" and "torso_2" in n.message]
    assert "added to the inertia tensor its source gives it" in torso.message
    m = mujoco.MjModel.from_xml_path(str(out))  # refused before: "mass and inertia of moving bodies"
    d = mujoco.MjData(m)
    # the hinges' block of the mass matrix is Pinocchio's reading of the source (its base welded: the
    # block of the joints below a free base is the same)
    model = pin.buildModelFromUrdf(str(source))
    data = model.createData()
    q = np.array([0.3, -0.4])
    expected = pin.crba(model, data, q)
    expected = np.triu(expected) + np.triu(expected, 1).T
    for name, value in zip(("torso_roll", "torso_yaw"), q, strict=True):
        d.qpos[m.jnt_qposadr[m.joint(name).id]] = value
    mujoco.mj_forward(m, d)
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    hinges = [m.jnt_dofadr[m.joint(name).id] for name in ("torso_roll", "torso_yaw")]
    # within the writer's 1e-9 kg·m² per axis: the 2e-3 kg·m² tensor of torso_2 is kept
    assert np.allclose(full[np.ix_(hinges, hinges)], expected, rtol=0.0, atol=5e-9)


def test_verify_passes_with_the_kept_tensor(source: Path, tmp_path: Path) -> None:
    report = verify(source, tmp_path / "verify", engines=("pinocchio", "mujoco"), replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    assert {(c.layer, c.engine, c.quantity) for c in report.checks} >= {(1, "mujoco", "inertia"),
                                                                       (3, "mujoco", "mass-matrix")}


# PyFlyt 0.29's fixed-wing drone: eight links welded to a free base, each a point mass (a mass with a zero
# tensor). Spread over 2 m their group has an inertia, but MuJoCo adds the bodies' own moments and refused
# the written file ("mass and inertia of moving bodies must be larger than mjMINVAL"; convert: MK877).
POINT_MASSES = """<robot name="plane">
  <link name="base_link"><inertial><mass value="0.3"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
""" + "".join(f"""  <link name="part{k}"><inertial><mass value="{mass}"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="fix{k}" type="fixed"><parent link="base_link"/><child link="part{k}"/>
    <origin xyz="{xyz}"/></joint>
""" for k, (mass, xyz) in enumerate([(0.1, "-1.1 0 0"), (0.05, "-1.1 0 0.15"), (0.2, "-0.5 0.95 0"),
                                      (0.2, "-0.5 -0.95 0"), (1.0, "-0.45 0 0")])) + "</robot>\n"


def test_a_free_group_of_point_masses_loads_in_mujoco_with_its_spread_inertia(tmp_path: Path) -> None:
    source = tmp_path / "plane.urdf"
    source.write_text(POINT_MASSES)
    out = tmp_path / "out" / "plane.xml"
    notes = write(load(source), out, force=True)
    assert "MK877" not in {n.code for n in notes}
    (lifted,) = [n for n in notes if n.code == "MK870"]
    assert "base_link" in lifted.message and "point masses" in lifted.message
    m = mujoco.MjModel.from_xml_path(str(out))  # refused before
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    # the group's inertia about its centre of mass is the point masses' spread, to the writer's 1e-9 kg·m²
    model = pin.buildModelFromUrdf(str(source), pin.JointModelFreeFlyer())
    data = model.createData()
    expected = pin.crba(model, data, pin.neutral(model))
    expected = np.triu(expected) + np.triu(expected, 1).T
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    assert np.trace(expected[3:, 3:]) > 0.5  # the spread alone: 0.36, 0.49 and 0.85 kg·m² about the base
    assert np.allclose(full, expected, rtol=0.0, atol=5e-9)
