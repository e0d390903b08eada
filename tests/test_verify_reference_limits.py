"""Joints the Pinocchio reference once refused, which it now holds: a ball joint (dm_control's
model_with_ball_joints.xml failed "pinocchio load", then was skipped) and a planar joint (skipped
until 2026-12-03: roboplan's reachback and Stretch 4 ran no dynamics)."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

BALL = """<mujoco><worldbody><body name="base"><geom size=".1" mass="1"/>
  <body name="arm" pos="0 0 .3"><joint name="shoulder" type="ball"/><geom type="capsule" size=".05"
    fromto="0 0 0 0 0 .3" mass=".5"/></body></body></worldbody></mujoco>"""


def test_a_ball_joint_is_held_by_the_pinocchio_reference(tmp_path: Path) -> None:
    """The reference holds a ball joint as three revolute joints (before, it refused the model and
    was skipped): its layers 1 and 2 pass, the ball turned in layer 2; a model whose only moving
    joint is a ball gets layer 3a over the ball's three angles (MuJoCo in the URDF chain's
    coordinates; before, it had no layer 3)."""
    source = tmp_path / "ball.xml"
    source.write_text(BALL)
    report = verify(source, None, ("mujoco", "pinocchio"), configurations=2, samples=1, replay=False)
    assert not [c for c in report.checks if c.engine == "pinocchio" and c.quantity == "load"]
    assert not [s for s in report.skips if s.engine == "pinocchio" and s.reason.startswith("not run")]
    mine = {(c.layer, c.quantity): c for c in report.checks if c.engine == "pinocchio"}
    assert mine[(1, "joint-type")].passed and mine[(2, "pose-rotation")].passed
    assert report.failed == []
    layer3 = {c.quantity: c for c in report.checks if c.layer == 3 and c.engine == "mujoco"}
    assert layer3["mass-matrix"].passed and layer3["bias"].passed
    assert "3 dofs" in layer3["mass-matrix"].detail and "three angles" in layer3["mass-matrix"].detail


PLANAR = """<robot name="slider"><link name="base"><inertial><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="puck"><inertial><mass value="0.5"/>
  <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="glide" type="planar"><parent link="base"/><child link="puck"/><axis xyz="0 0 1"/></joint>
</robot>"""


def test_a_planar_joint_is_held_by_the_pinocchio_reference(tmp_path: Path) -> None:
    """The reference holds the planar joint (two slides and a hinge, at rest): it loads and passes
    layers 1 and 2 beside MuJoCo (which holds the MJCF's chain); a model whose only moving joint is
    planar has no revolute or prismatic dynamics to compare, which layer 3 says."""
    source = tmp_path / "slider.urdf"
    source.write_text(PLANAR)
    report = verify(source, None, ("mujoco", "pinocchio"), configurations=1, samples=1, replay=False)
    assert not [c for c in report.checks if c.engine == "pinocchio" and c.quantity == "load"]
    assert not [s for s in report.skips if s.engine == "pinocchio" and s.reason.startswith("not run")]
    mine = {(c.layer, c.quantity): c for c in report.checks if c.engine == "pinocchio"}
    assert mine[(1, "joint-type")].passed and mine[(2, "pose-position")].passed
    assert report.failed == [], [c.detail for c in report.failed]
    said = [s.reason for s in report.skips if s.layer == 3]
    assert any("planar joints only" in reason for reason in said), said
