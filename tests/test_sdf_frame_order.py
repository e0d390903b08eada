"""A massless link under another massless link, the child listed first (qibullet's NAO: the camera's
optical frame before the camera frame), is written as SDF ``<frame>`` elements parents first: Drake
resolves ``relative_to`` in document order and put the child at the parent's link otherwise (5.4 cm
and 0.69 rad off on NAO, silently)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from click.testing import CliRunner
from lxml import etree
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from modelkit.cli import main

URDF = """<robot name="head">
  <link name="head"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="optical"/>
  <joint name="optical_joint" type="fixed"><parent link="camera"/><child link="optical"/>
    <origin rpy="-1.5707963267949 0 -1.5707963267949" xyz="0 0 0"/></joint>
  <link name="camera"/>
  <joint name="camera_joint" type="fixed"><parent link="head"/><child link="camera"/>
    <origin rpy="0 0.692896 0" xyz="0.05071 0 0.01774"/></joint>
</robot>
"""


def test_frames_are_written_parents_first_and_drake_places_them(tmp_path: Path) -> None:
    source = tmp_path / "head.urdf"
    source.write_text(URDF)
    out = tmp_path / "out" / "head.sdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    frames = [f.get("name") for f in etree.parse(str(out)).iter("frame")]
    assert frames == ["camera", "optical"]
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(out))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    head = plant.GetFrameByName("head").CalcPoseInWorld(context)
    optical = head.inverse() @ plant.GetFrameByName("optical").CalcPoseInWorld(context)
    pitch = 0.692896
    c, s = np.cos(pitch), np.sin(pitch)
    camera = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    to_optical = np.array([[0, 0, 1], [-1, 0, 0], [0, -1, 0]])  # rpy (-pi/2, 0, -pi/2)
    assert np.allclose(optical.translation(), [0.05071, 0, 0.01774], atol=1e-12)
    assert np.allclose(optical.rotation().matrix(), camera @ to_optical, atol=1e-9)
