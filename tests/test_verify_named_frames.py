"""A source's named frame is no link: Drake's acrobot (pydrake's examples/acrobot/Acrobot.sdf) has a
model-level ``<frame name="hand">``; the SDF writer keeps it as a frame and Drake lists a file's frames
with its bodies, so layer 1 reported an extra link "hand" in Drake (link-set FAIL) before."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

ACROBOT = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="acrobot">
    <link name="base_link">
      <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    </link>
    <joint name="base_weld" type="fixed"><parent>world</parent><child>base_link</child></joint>
    <link name="upper_link">
      <pose>0 0 -0.5 0 0 0</pose>
      <inertial><mass>1</mass><inertia><ixx>0.083</ixx><iyy>0.083</iyy><izz>0.001</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    </link>
    <joint name="shoulder" type="revolute"><parent>base_link</parent><child>upper_link</child>
      <pose>0 0 0.5 0 0 0</pose><axis><xyz>0 1 0</xyz></axis></joint>
    <frame name="hand">
      <pose relative_to="upper_link">0 0 -0.6 0 0 0</pose>
    </frame>
  </model>
</sdf>
"""


def test_a_source_frame_is_no_extra_link_in_drake(tmp_path: Path) -> None:
    path = tmp_path / "acrobot.sdf"
    path.write_text(ACROBOT)
    report = verify(path, engines=("mujoco", "drake"), configurations=3, samples=3, replay=False,
                    driven=False)
    assert not report.errors
    link_sets = [c for c in report.checks if c.quantity == "link-set"]
    assert {c.engine for c in link_sets} == {"mujoco", "drake"}
    assert all(c.passed for c in link_sets), link_sets
    assert [c for c in report.checks if not c.passed] == []
