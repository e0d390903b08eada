"""A drive wheel's made-up servo carries its share of the robot it pushes (modelkit.convert.wheel_loads).

The user's step: example-robot-data's TIAGo converted to MJCF with defaults, put on a plain floor,
driven by its own velocity actuators (the ones its ros2_control names) with a 1 s ramp to the
profile's wheel speeds. With the wheel's own inertia alone (kv 1.58 N·m·s/rad) the heavier-loaded
right wheel lagged while the robot accelerated and it ended 0.25 m and 0.09 rad off a straight line;
with its share of the robot (kv 61.8) it follows the ideal unicycle."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from modelkit.convert.api import convert
from modelkit.convert.servo_gains import natural_frequency

from .conftest import example_robot

RADIUS = 0.0985  # m, TIAGo's wheels
TRACK = 0.4044  # m, between the wheels' centres
RAMP = 1.0  # s


@pytest.fixture(scope="module")
def tiago(tmp_path_factory: pytest.TempPathFactory) -> tuple[mujoco.MjModel, str]:
    out = tmp_path_factory.mktemp("tiago") / "tiago.xml"
    result = convert([example_robot("tiago_description/robots/tiago_no_hand.urdf")], out)
    said = [n.message for n in result.notes if n.code == "MK840" and "wheel_left_joint" in n.message]
    floor = out.with_name("on_floor.xml")  # the written file with a default plane added, as a user does
    plane = '<worldbody><geom type="plane" size="0 0 1"/>'
    floor.write_text(out.read_text().replace("<worldbody>", plane, 1))
    return mujoco.MjModel.from_xml_path(str(floor)), said[0] if said else ""


def _set_kv(model: mujoco.MjModel, kv: float) -> None:
    """A velocity actuator's gain kv (and its bias −kv·q̇) on both wheels."""
    for name in ("wheel_left_motor", "wheel_right_motor"):
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        model.actuator_gainprm[a, 0], model.actuator_biasprm[a, 2] = kv, -kv


def _yaw(q: np.ndarray) -> float:
    w, x, y, z = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _drive(model: mujoco.MjModel, v: float, w: float) -> tuple[np.ndarray, np.ndarray]:
    """(end x, y, unwrapped yaw) of the robot and of the ideal unicycle after 10 s."""
    left = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "wheel_left_motor")
    right = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "wheel_right_motor")
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    ideal = np.zeros(3)
    yaw, last = 0.0, 0.0
    while data.time < 10.0:
        scale = min(1.0, data.time / RAMP)
        data.ctrl[left] = scale * (v - w * TRACK / 2) / RADIUS
        data.ctrl[right] = scale * (v + w * TRACK / 2) / RADIUS
        mujoco.mj_step(model, data)
        speed = scale * v
        turn = ideal[2]
        ideal += model.opt.timestep * np.array([speed * math.cos(turn), speed * math.sin(turn), scale * w])
        now = _yaw(data.qpos[3:7])
        yaw += math.remainder(now - last, 2 * math.pi)
        last = now
    return np.array([data.qpos[0], data.qpos[1], yaw]), ideal


def test_the_wheel_servo_gain_counts_the_robot_it_pushes(tiago: tuple[mujoco.MjModel, str]) -> None:
    model, said = tiago
    a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "wheel_left_motor")
    kv = float(model.actuator_gainprm[a, 0])
    mass = float(sum(model.body_mass))
    assert kv > mass / 2 * RADIUS**2 * natural_frequency()  # the share alone, before the wheel's own
    assert "its share of the robot it pushes as a drive wheel" in said


@pytest.mark.parametrize(("v", "w"), [(0.3, 0.0), (0.0, 0.5), (0.3, 0.3)], ids=["straight", "spin", "arc"])
def test_tiago_drives_like_the_unicycle_on_its_own_actuators(tiago: tuple[mujoco.MjModel, str], v: float,
                                                             w: float) -> None:
    end, ideal = _drive(tiago[0], v, w)
    assert float(np.linalg.norm(end[:2] - ideal[:2])) < 0.02, (end, ideal)
    assert abs(end[2] - ideal[2]) < 0.01 * max(1.0, abs(ideal[2])), (end, ideal)


def test_with_the_wheel_alone_it_veers(tiago: tuple[mujoco.MjModel, str]) -> None:
    """The gain of the wheel's own inertia (what the rule gave before) fails the same straight line."""
    model = tiago[0]
    a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "wheel_left_motor")
    kept = float(model.actuator_gainprm[a, 0])
    _set_kv(model, 1.58)
    try:
        end, ideal = _drive(model, 0.3, 0.0)
    finally:
        _set_kv(model, kept)  # the module's model, for the other tests
    assert float(np.linalg.norm(end[:2] - ideal[:2])) > 0.1
