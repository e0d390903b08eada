"""verify's MuJoCo worlds delete the file's actuators; a ``home`` keyframe's controls go with them
(modelkit.verify.engines.mujoco.drop_actuators). example-robot-data's TIAGo, whose arm gets position
servos and so a keyframe ``ctrl``, failed layer 4 with "keyframe 0: invalid ctrl size" in MuJoCo."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from modelkit.verify.engines.mujoco import drop_actuators

ARM = """<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody>
  <actuator><position joint="j" kp="10"/></actuator>
  <keyframe><key name="home" qpos="0.1" ctrl="0.1"/></keyframe></mujoco>"""


def test_the_keyframe_loses_its_controls_with_the_actuators() -> None:
    spec = mujoco.MjSpec.from_string(ARM)
    for actuator in list(spec.actuators):  # what verify did before
        spec.delete(actuator)
    with pytest.raises(ValueError, match="invalid ctrl size"):
        spec.compile()
    spec = mujoco.MjSpec.from_string(ARM)
    drop_actuators(spec)
    model = spec.compile()
    assert (model.nu, model.nkey) == (0, 1) and model.key_qpos[0][0] == 0.1


SENSED = """<mujoco model="sensed"><worldbody><body name="base"><geom size=".05" mass="1"/>
  <body name="arm" pos="0 0 .1"><joint name="j" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 .2 0 0" size=".02"/>
  <body name="hand" pos=".2 0 0"><joint name="k" axis="0 1 0"/><geom size=".03"/></body></body></body>
  </worldbody>
  <actuator><motor name="A_j" joint="j"/><motor name="A_k" joint="k"/></actuator>
  <sensor><actuatorpos actuator="A_j"/><actuatorfrc name="torque_k" actuator="A_k"/>
    <jointpos joint="k"/></sensor>
</mujoco>"""


def test_sensors_of_deleted_actuators_go_with_them(tmp_path: Path) -> None:
    """gymnasium-robotics' Adroit hand reads its actuators with ``actuatorpos`` sensors: the replay's
    MuJoCo world deleted the actuators and kept the sensors, MuJoCo refused it ("unrecognized name
    'A_WRJ1' of sensorized object"), and verify failed a sound model. Now those sensors go too; a
    sensor of a joint stays, and layer 4's subset keeps the sensors of the actuators it keeps."""
    spec = mujoco.MjSpec.from_string(SENSED)
    drop_actuators(spec)
    model = spec.compile()
    assert (model.nu, model.nsensor) == (0, 1)
    spec = mujoco.MjSpec.from_string(SENSED)
    assert drop_actuators(spec, driven={"j"}) == ["A_k"]
    model = spec.compile()
    assert (model.nu, model.nsensor) == (1, 2)
    from modelkit.verify.api import verify

    source = tmp_path / "sensed.xml"
    source.write_text(SENSED)
    report = verify(source, tmp_path / "out", ("mujoco", "pybullet", "pinocchio"), configurations=2,
                    samples=1, driven=False)
    assert not report.errors and report.failed == [], [c.detail for c in report.failed]
    assert [c for c in report.checks if c.quantity == "replay"]  # the replay ran (PyBullet against MuJoCo)
