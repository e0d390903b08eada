"""An MJCF source's own numbers come back as written (issue 17 §5, §6): MuJoCo Menagerie, mjlab and
robosuite give body orientations as six-digit quaternions, inertias as ``quat`` + ``diaginertia`` and
capsules as ``fromto``. ``convert`` to MJCF wrote them as ``euler="0 -0.174899984293942 0"``,
``fullinertia="0.0089369971999583 ..."`` and ``size="0.055 0.0761577310586391" pos quat``: the same
robot in numbers nobody wrote. Each is now written in the source's form when that form gives the
same model, and the compiled models are compared to be sure of it.
"""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
from click.testing import CliRunner

from modelkit.cli import main

SOURCE = """<mujoco model="leg">
  <worldbody>
    <body name="hip" pos="0 0 1">
      <freejoint/>
      <inertial pos="0 0 -0.07605" quat="1 0 -0.000399148 0" mass="3.813"
                diaginertia="0.010549 0.0093089 0.0079184"/>
      <geom type="box" size="0.1 0.1 0.05"/>
      <body name="thigh" pos="0 0.052 -0.030465" quat="0.996179 0 -0.0873386 0">
        <joint name="hip_pitch" axis="0 1 0" range="-1 1"/>
        <inertial pos="-0.057709 -0.010981 -0.15078" quat="0.600598 0.15832 0.223482 0.751181" mass="1.702"
                  diaginertia="0.00776166 0.00717575 0.00160139"/>
        <geom name="thigh_capsule" type="capsule" size="0.055" fromto="0 0 -0.03 -0.06 0 -0.17"/>
        <body name="shin" pos="-0.078273 0.0021489 -0.17734" quat="0.996179 0 0.0873386 0">
          <joint name="knee" axis="0 1 0" range="0 2"/>
          <inertial pos="0.005457 0.003964 -0.12074" quat="0.923418 -0.0327699 0.0158246 0.382067"
                    mass="1.932" diaginertia="0.0113804 0.0112778 0.00146458"/>
          <geom name="foot_capsule" type="capsule" size="0.01" fromto="0.1 -0.026 -0.025 0.05 -0.027 -0.025"/>
          <geom name="shin_cylinder" type="cylinder" size="0.03" fromto="0.01 0 0 0.01 0.02 -0.15"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _convert(tmp_path: Path) -> tuple[Path, Path]:
    source = tmp_path / "leg.xml"
    source.write_text(SOURCE)
    written = tmp_path / "out" / "leg.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(written)])
    assert result.exit_code == 0, result.output
    return source, written


def _compiled(path: Path) -> dict[str, np.ndarray]:
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    tensors = []
    for body in range(m.nbody):
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, m.body_iquat[body])
        r = rotation.reshape(3, 3)
        tensors.append(r @ np.diag(m.body_inertia[body]) @ r.T)
    geoms = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)
             for n in ("thigh_capsule", "foot_capsule", "shin_cylinder")]
    return {"xpos": d.xpos.copy(), "xmat": d.xmat.copy(), "inertia": np.array(tensors),
            "geom_xpos": d.geom_xpos[geoms].copy(), "geom_xmat": d.geom_xmat[geoms].copy(),
            "geom_size": m.geom_size[geoms].copy()}


def test_the_written_model_is_the_source_model(tmp_path: Path) -> None:
    source, written = _convert(tmp_path)
    theirs, ours = _compiled(source), _compiled(written)
    for key, value in theirs.items():
        assert np.allclose(ours[key], value, rtol=0.0, atol=1e-12), key


def test_body_orientations_are_the_sources_quaternions(tmp_path: Path) -> None:
    text = _convert(tmp_path)[1].read_text()
    assert re.search(r'<body name="thigh"[^>]* quat="0.996179 0 -0.0873386 0"', text), text
    assert re.search(r'<body name="shin"[^>]* quat="0.996179 0 0.0873386 0"', text), text
    assert "euler=" not in text


def test_inertias_keep_their_principal_form(tmp_path: Path) -> None:
    text = _convert(tmp_path)[1].read_text()
    assert "fullinertia" not in text
    inertials = re.findall(r"<inertial [^>]*/>", text)
    assert len(inertials) == 3
    for element in inertials:
        quat, diagonal = (re.search(rf'{key}="([^"]*)"', element) for key in ("quat", "diaginertia"))
        assert quat and diagonal, element
        # the source's digits (six), whichever of the equivalent axis orders is written
        assert all(len(v.replace("-", "").replace(".", "").lstrip("0").split("e")[0]) <= 6
                   for v in (*quat.group(1).split(), *diagonal.group(1).split())), element
    assert 'diaginertia="0.010549 0.0093089 0.0079184"' in text


def test_capsules_and_cylinders_keep_their_ends(tmp_path: Path) -> None:
    text = _convert(tmp_path)[1].read_text()
    for name, ends in (("thigh_capsule", "0 0 -0.03 -0.06 0 -0.17"),
                       ("foot_capsule", "0.1 -0.026 -0.025 0.05 -0.027 -0.025"),
                       ("shin_cylinder", "0.01 0 0 0.01 0.02 -0.15")):
        element = re.search(rf'<geom name="{name}"[^>]*/>', text)
        assert element, name
        assert f'fromto="{ends}"' in element.group(0), element.group(0)
        assert " pos=" not in element.group(0) and " quat=" not in element.group(0)


def test_a_urdf_wheel_keeps_its_roll(tmp_path: Path) -> None:
    """A URDF's ``rpy="1.5708 0 0"`` cylinder is not a plainer ``fromto`` (its axis is 3.7e-6 off Y):
    the written form stays the source's roll."""
    urdf = tmp_path / "wheel.urdf"
    urdf.write_text("""<robot name="w"><link name="base"><inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
      <collision><origin xyz="0 0.1 0" rpy="1.5708 0 0"/><geometry><cylinder radius="0.1" length="0.05"/>
      </geometry></collision></link></robot>""")
    written = tmp_path / "out" / "wheel.xml"
    result = CliRunner().invoke(main, ["convert", str(urdf), "-o", str(written)])
    assert result.exit_code == 0, result.output
    geom = re.search(r'<geom type="cylinder"[^>]*/>', written.read_text())
    assert geom and 'euler="1.5708 0 0"' in geom.group(0) and "fromto" not in geom.group(0), geom
