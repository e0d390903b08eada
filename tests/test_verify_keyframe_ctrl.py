"""verify's MuJoCo worlds delete the file's actuators; a ``home`` keyframe's controls go with them
(modelkit.verify.engines.mujoco.drop_actuators). example-robot-data's TIAGo, whose arm gets position
servos and so a keyframe ``ctrl``, failed layer 4 with "keyframe 0: invalid ctrl size" in MuJoCo."""

from __future__ import annotations

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
