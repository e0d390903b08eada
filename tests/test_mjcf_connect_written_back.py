"""MJCF to MJCF keeps a source's ``connect`` equalities between bodies: a closed linkage the model
does not hold (MK172) is written back with its anchor moved into the written body's frame (Menagerie's
Robotiq 2F-85 ties each follower to its coupler; without the two connects the written gripper
collapsed, 45 mm in 2 s where the source holds within 0.1 mm).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from click.testing import CliRunner

from modelkit.cli import main

# A four-bar: the crank and the rocker hang from the base on hinges whose joints sit off their body
# frames (the reader puts the link frame at the joint, so the written bodies' frames move); the coupler
# rides the crank, and the rocker's tip (the anchor, in the rocker's frame) is tied to its end.
LINKAGE = """<mujoco model="linkage">
  <option gravity="0 0 -9.81"/>
  <default><default class="ghost"><geom contype="0" conaffinity="0"/></default></default>
  <worldbody>
    <body name="base">
      <geom type="box" size="0.05 0.05 0.01" mass="1" class="ghost"/>
      <body name="crank" pos="0 -0.03 0">
        <joint name="drive" axis="1 0 0" pos="0 0.01 0" damping="0.01"/>
        <geom type="capsule" fromto="0 0.01 0 0 0.01 0.04" size="0.004" mass="0.02" class="ghost"/>
        <body name="coupler" pos="0 0.01 0.04">
          <joint name="knee" axis="1 0 0" damping="0.001"/>
          <geom type="capsule" fromto="0 0 0 0 0.04 0" size="0.004" mass="0.02" class="ghost"/>
        </body>
      </body>
      <body name="rocker" pos="0 0.03 0">
        <joint name="rock" axis="1 0 0" pos="0 -0.01 0" damping="0.001"/>
        <geom type="capsule" fromto="0 -0.01 0 0 -0.01 0.04" size="0.004" mass="0.02" class="ghost"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="tie" body1="rocker" body2="coupler" anchor="0 -0.01 0.04" solref="0.005 1"/>
  </equality>
  <actuator>
    <motor name="turn" joint="drive" gear="1" ctrlrange="-1 1"/>
  </actuator>
</mujoco>
"""


def _run(xml: Path) -> np.ndarray:
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    d.ctrl[0] = 0.002
    out = []
    for step in range(int(1.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        if step % 50 == 0:
            out.append([d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)]]
                        for n in ("drive", "knee", "rock")])
    return np.array(out)


def test_a_connect_is_written_back_and_the_linkage_moves_as_the_source(tmp_path: Path) -> None:
    source = tmp_path / "linkage.xml"
    source.write_text(LINKAGE)
    out = tmp_path / "out" / "linkage.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "MK808" not in result.output  # the connect is written, not left out
    written = out.read_text()
    assert '<connect name="tie" body1="rocker" body2="coupler"' in written
    want, got = _run(source), _run(out)
    assert np.ptp(want[:, 2]) > 0.05  # the rocker moves: the loop carries the motion
    assert np.max(np.abs(got - want)) < 1e-6, np.max(np.abs(got - want))
