"""PyBullet contact compliance on the links a wheeled robot stands on (modelkit.convert.contact_compliance,
MK861, ``--support-contact``).

The user's step: example-robot-data's TIAGo converted to URDF with defaults, loaded on pybullet_data's
plane.urdf, driven by PyBullet's velocity motors at its wheels' effort (6 N·m) with a 1 s ramp. With
PyBullet's rigid contacts (``--support-contact rigid``, what convert wrote before) the left drive wheel
carries 0 N at rest of TIAGo's six coplanar supports, and the robot went backwards and turned
(−0.57 m, −1.69 rad for a 2.85 m straight line)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet
import pybullet_data
import pytest

from modelkit.convert.api import convert
from modelkit.convert.options import WriteOptions
from modelkit.model import Robot

from .conftest import TUTORIAL, example_robot

RADIUS = 0.0985
TRACK = 0.4044
SUPPORTS = {"wheel_right_link", "wheel_left_link", "caster_front_right_2_link", "caster_front_left_2_link",
            "caster_back_right_2_link", "caster_back_left_2_link"}


def _tiago(folder: Path, contact: str) -> tuple[Path, list[str]]:
    out = folder / contact / "tiago.urdf"
    result = convert([example_robot("tiago_description/robots/tiago_no_hand.urdf")], out,
                     options=WriteOptions(support_contact=contact))
    return out, [n.message for n in result.notes if n.code == "MK861"]


def _drive(urdf: Path, v: float, w: float) -> tuple[dict[str, float], np.ndarray]:
    """Each support's load at rest (N), and (x, y, yaw) after a 1 s ramp and 9 s at (v, w)."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        p = {"physicsClientId": client}
        pybullet.setAdditionalSearchPath(pybullet_data.getDataPath(), **p)
        pybullet.setGravity(0, 0, -9.81, **p)
        pybullet.loadURDF("plane.urdf", **p)
        body = pybullet.loadURDF(str(urdf), flags=pybullet.URDF_USE_INERTIA_FROM_FILE
                                 | pybullet.URDF_USE_IMPLICIT_CYLINDER, **p)
        info = [pybullet.getJointInfo(body, i, **p) for i in range(pybullet.getNumJoints(body, **p))]
        joints = {row[1].decode(): row[0] for row in info}
        links = {row[0]: row[12].decode() for row in info}
        dt = 1.0 / 240.0
        for _ in range(240):
            pybullet.stepSimulation(**p)
        loads: dict[str, float] = {}
        for contact in pybullet.getContactPoints(body, **p):
            name = links.get(contact[3], "base")
            loads[name] = loads.get(name, 0.0) + contact[9]
        start, _ = pybullet.getBasePositionAndOrientation(body, **p)
        t, yaw, last = 0.0, 0.0, 0.0
        while t < 10.0:
            scale = min(1.0, t)
            speeds = (("wheel_left_joint", v - w * TRACK / 2), ("wheel_right_joint", v + w * TRACK / 2))
            for name, speed in speeds:
                pybullet.setJointMotorControl2(body, joints[name], pybullet.VELOCITY_CONTROL,
                                               targetVelocity=scale * speed / RADIUS, force=6.0, **p)
            pybullet.stepSimulation(**p)
            t += dt
            position, orientation = pybullet.getBasePositionAndOrientation(body, **p)
            now = pybullet.getEulerFromQuaternion(orientation)[2]
            yaw += math.remainder(now - last, 2 * math.pi)
            last = now
        return loads, np.array([position[0] - start[0], position[1] - start[1], yaw])
    finally:
        pybullet.disconnect(client)


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, list[str]]]:
    folder = tmp_path_factory.mktemp("support")
    return {contact: _tiago(folder, contact) for contact in ("compliant", "rigid")}


def test_each_support_gets_stiffness_and_damping_and_a_note(
        written: dict[str, tuple[Path, list[str]]]) -> None:
    from lxml import etree

    urdf, said = written["compliant"]
    tree = etree.parse(str(urdf))
    stiff = {link.get("name") for link in tree.iterfind("link") if link.find("contact/stiffness") is not None}
    assert stiff == SUPPORTS
    assert len(said) == 1 and "stands on 6 links" in said[0]
    rigid, said_rigid = written["rigid"]
    assert "<stiffness" not in rigid.read_text() and not said_rigid


@pytest.mark.parametrize(("v", "w", "ideal"), [(0.3, 0.0, (2.85, 0.0, 0.0)), (0.0, 0.5, (0.0, 0.0, 4.75))],
                         ids=["straight", "spin"])
def test_tiago_drives_in_pybullet(written: dict[str, tuple[Path, list[str]]], v: float, w: float,
                                  ideal: tuple[float, float, float]) -> None:
    loads, end = _drive(written["compliant"][0], v, w)
    assert loads.get("wheel_left_link", 0.0) > 20.0 and loads.get("wheel_right_link", 0.0) > 20.0, loads
    assert float(np.hypot(end[0] - ideal[0], end[1] - ideal[1])) < 0.02, end
    assert abs(end[2] - ideal[2]) < 0.02 * max(1.0, ideal[2]), end


def test_with_rigid_supports_a_drive_wheel_is_unloaded_and_it_does_not_drive(
        written: dict[str, tuple[Path, list[str]]]) -> None:
    loads, end = _drive(written["rigid"][0], 0.3, 0.0)
    assert loads.get("wheel_left_link", 0.0) < 1.0, loads
    assert float(np.hypot(end[0] - 2.85, end[1])) > 0.5, end


def test_three_supports_get_nothing(tmp_path: Path) -> None:
    """The tutorial's pan-tilt robot stands on two wheels and a caster: determinate, left rigid."""
    out = tmp_path / "r.urdf"
    result = convert([TUTORIAL / "mobile_robot_pantilt.body"], out)
    assert "<stiffness" not in out.read_text()
    assert not [n for n in result.notes if n.code == "MK861"]


def test_support_links_of_tiago() -> None:
    import modelkit
    from modelkit.convert.contact_compliance import support_links

    robot = modelkit.load(example_robot("tiago_description/robots/tiago_no_hand.urdf"))
    assert isinstance(robot, Robot)
    assert set(support_links(robot)) == SUPPORTS


def _four_wheels(own: str) -> str:
    """A 10 kg box on four cylinder wheels (continuous joints about Y); the front-left wheel's
    <contact> is ``own``."""
    wheels = []
    for name, x, y in (("fl", 0.2, 0.2), ("fr", 0.2, -0.2), ("bl", -0.2, 0.2), ("br", -0.2, -0.2)):
        contact = own if name == "fl" else ""
        wheels.append(
            f'<link name="{name}"><inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" '
            'ixy="0" ixz="0" iyz="0"/></inertial><collision><origin rpy="1.5707963267948966 0 0"/>'
            f'<geometry><cylinder radius="0.05" length="0.03"/></geometry></collision>{contact}</link>'
            f'<joint name="{name}_joint" type="continuous"><parent link="base"/><child link="{name}"/>'
            f'<origin xyz="{x} {y} 0"/><axis xyz="0 1 0"/></joint>')
    return ('<robot name="cart"><link name="base"><inertial><mass value="10"/><inertia ixx="0.1" iyy="0.1" '
            'izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.5 0.3 0.05"/>'
            f'</geometry></collision></link>{"".join(wheels)}</robot>')


def test_a_source_stiffness_is_kept(tmp_path: Path) -> None:
    from lxml import etree

    source = tmp_path / "cart.urdf"
    source.write_text(_four_wheels('<contact><stiffness value="5000"/><damping value="10"/></contact>'))
    out = tmp_path / "out" / "cart.urdf"
    result = convert([source], out)
    tree = etree.parse(str(out))
    stiffness = {link.get("name"): float(link.find("contact/stiffness").get("value"))
                 for link in tree.iterfind("link") if link.find("contact/stiffness") is not None}
    assert stiffness["fl"] == 5000.0  # the source's own
    assert set(stiffness) == {"fl", "fr", "bl", "br"}
    assert stiffness["fr"] == pytest.approx(12 * 9.81 / 4 / 2.5e-4, rel=1e-2)  # 12 kg on four, 0.25 mm
    assert [n for n in result.notes if n.code == "MK861"]
