"""A joint the Pinocchio reference cannot hold (a ball) is the reference's limit, not the file's
fault: verify skips Pinocchio with the reason instead of failing its load (dm_control's
model_with_ball_joints.xml failed "pinocchio load" before)."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

BALL = """<mujoco><worldbody><body name="base"><geom size=".1" mass="1"/>
  <body name="arm" pos="0 0 .3"><joint name="shoulder" type="ball"/><geom type="capsule" size=".05"
    fromto="0 0 0 0 0 .3" mass=".5"/></body></body></worldbody></mujoco>"""


def test_a_ball_joint_skips_the_pinocchio_reference(tmp_path: Path) -> None:
    source = tmp_path / "ball.xml"
    source.write_text(BALL)
    report = verify(source, None, ("mujoco", "pinocchio"), configurations=1, samples=1, replay=False)
    assert not [c for c in report.checks if c.engine == "pinocchio" and c.quantity == "load"]
    said = [s.reason for s in report.skips if s.engine == "pinocchio"]
    assert any("'shoulder' is ball" in reason and reason.startswith("not run") for reason in said)
