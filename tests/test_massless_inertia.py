"""URDF: a massless link with a rotational inertia on a fixed joint is read as the loaders that fuse
fixed links read it (modelkit/formats/urdf/massless.py, MK324).

The oracle is Pinocchio's own URDF parser on the source file: MuJoCo's mass matrix of the MJCF that
``convert`` writes must equal it. pybullet_data's Panda gives ``panda_link8`` and
``panda_grasptarget`` mass 0 and 0.1 kg·m² per axis; read as written, both became massless frames in
every output and the mass matrix at joint 4 came out 0.2 kg·m² short (verify's layer 3 failed on it).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load, validate
from modelkit.convert.api import write

mujoco = pytest.importorskip("mujoco")
np = pytest.importorskip("numpy")
pin = pytest.importorskip("pinocchio")
pybullet_data = pytest.importorskip("pybullet_data")

PANDA = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
ARM = [f"panda_joint{i}" for i in range(1, 8)]


def _mujoco_mass_matrix(path: Path, q: dict[str, float]) -> np.ndarray:
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    for name, value in q.items():
        d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]] = value
    mujoco.mj_forward(m, d)
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)  # MuJoCo 4's signature
    dofs = [m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)] for name in ARM]
    return full[np.ix_(dofs, dofs)]


def _pinocchio_mass_matrix(q: dict[str, float]) -> np.ndarray:
    model = pin.buildModelFromUrdf(str(PANDA))
    data = model.createData()
    config = pin.neutral(model)
    for name, value in q.items():
        config[model.joints[model.getJointId(name)].idx_q] = value
    matrix = pin.crba(model, data, config)
    dofs = [model.joints[model.getJointId(name)].idx_v for name in ARM]
    return np.asarray(matrix)[np.ix_(dofs, dofs)]


def test_panda_mass_matrix_equals_pinocchios_reading_of_the_source(tmp_path: Path) -> None:
    said = [d for d in validate(PANDA).diagnostics if d.code == "MK324"]
    assert sorted(d.message.split('"')[1] for d in said) == ["panda_grasptarget", "panda_link8"]
    assert all(d.severity == "warning" for d in said)
    out = tmp_path / "panda.xml"
    write(load(PANDA), out, force=True)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = {name: float(rng.uniform(-1.5, 0.0)) for name in ARM}
        ours, theirs = _mujoco_mass_matrix(out, q), _pinocchio_mass_matrix(q)
        assert np.abs(ours - theirs).max() < 1e-9 * np.abs(theirs).max(), np.abs(ours - theirs).max()


CHAIN = """<robot name="c">
  <link name="base"><inertial><mass value="2"/><origin xyz="0 0 0.1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a"><inertial><mass value="0"/><inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/>
    </inertial></link>
  <link name="b"><inertial><mass value="0"/><inertia ixx="1" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/>
    </inertial></link>
  <joint name="ja" type="fixed"><parent link="base"/><child link="a"/>
    <origin rpy="0 0 1.5707963267948966"/></joint>
  <joint name="jb" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>
"""


def test_a_chain_of_massless_links_ends_in_the_first_with_mass(tmp_path: Path) -> None:
    """b's tensor goes to a, then a's (its own and b's, turned 90° about z) to base; mass and COM stay."""
    path = tmp_path / "c.urdf"
    path.write_text(CHAIN)
    robot = load(path)
    links = {link.name: link for link in robot.links}
    base = links["base"].inertial
    assert base is not None and base.mass == 2.0 and list(base.com) == [0.0, 0.0, 0.1]
    assert np.allclose(np.diag(base.inertia), [0.01 + 0.2, 0.02 + 0.1 + 1.0, 0.03 + 0.3], atol=1e-12)
    for name in ("a", "b"):
        held = links[name].inertial
        assert held is not None and held.mass == 0.0 and not np.any(held.inertia)


def test_no_ancestor_with_mass_leaves_the_file_as_written(tmp_path: Path) -> None:
    path = tmp_path / "c.urdf"
    path.write_text(CHAIN.replace('<mass value="2"/>', '<mass value="0"/>'))
    robot = load(path)
    a = next(link for link in robot.links if link.name == "a").inertial
    assert a is not None and np.allclose(np.diag(a.inertia), [0.1, 0.2, 0.3])
    assert not [d for d in validate(path).diagnostics if d.code == "MK324"]
