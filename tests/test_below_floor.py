"""MK888: a welded robot whose moving links reach below z = 0 where the written file starts it.

The user's next step with a fixed-base arm is a floor at z = 0. synriard's "vertical" Alicia arms hang
0.63 m below their mount, so MuJoCo's plane cuts through them and the arm swings through 1 m in 0.15 s;
the leader arm's home folds its wrist 2.5 mm below its base (1.4 mm of drift under its servos). The note
is checked against the consumer: where it is said, MuJoCo's plane touches the robot's moving links at the
written home; where it is not, it touches nothing that moves."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import pytest

from modelkit.api import load
from modelkit.convert.api import write

ARM = """<robot name="arm">{world}
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 {base_z}"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="20" velocity="2"/></joint>
  <link name="upper"><inertial><origin xyz="0 0 {half}"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 {half}"/><geometry><cylinder radius="0.03" length="0.4"/></geometry>
    </collision></link>
</robot>
"""
MOUNT = """
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0 0 1"/></joint>"""


def _source(tmp_path: Path, hanging: bool, mounted: bool = False, base_z: float = 0.05) -> Path:
    path = tmp_path / "arm.urdf"
    text = ARM.format(world=MOUNT if mounted else "", half=-0.25 if hanging else 0.25, base_z=base_z)
    path.write_text(text)
    return path


def _said(source: Path, out: Path) -> list[str]:
    return [n.message for n in write(load(source), out, force=True) if n.code == "MK888"]


def _floor_touches(mjcf: Path) -> set[str]:
    """The bodies MuJoCo's default plane at z = 0 touches at the written home pose."""
    spec = mujoco.MjSpec.from_file(str(mjcf))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05], name="floor")
    model = spec.compile()
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    mujoco.mj_forward(model, data)
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    touched = set()
    for contact in data.contact[: data.ncon]:
        if floor in (contact.geom1, contact.geom2):
            other = contact.geom2 if contact.geom1 == floor else contact.geom1
            touched.add(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[other]))
    return touched


@pytest.mark.parametrize("suffix", ["xml", "urdf", "sdf"])
def test_a_hanging_arm_is_told_how_deep_it_reaches(tmp_path: Path, suffix: str) -> None:
    (message,) = _said(_source(tmp_path, hanging=True), tmp_path / f"out.{suffix}")
    depth = re.search(r"reaches ([0-9.]+) mm below z = 0", message)
    assert depth and float(depth.group(1)) == 450.0, message
    assert "(upper;" in message and ("home pose" in message) == (suffix == "xml")


def test_the_floor_touches_what_the_note_names_in_mujoco(tmp_path: Path) -> None:
    hanging = tmp_path / "hanging.xml"
    assert _said(_source(tmp_path, hanging=True), hanging)
    assert _floor_touches(hanging) == {"upper"}


@pytest.mark.parametrize(("hanging", "mounted", "base_z"), [
    (False, False, 0.05),  # an upright arm
    (True, True, 0.05),  # hanging from a mount 1 m up: 0.55 m of room below
    (False, False, -0.2),  # the welded base itself below z = 0: no simulator collides it with the floor
])
def test_a_robot_clear_of_the_floor_is_not_told(tmp_path: Path, hanging: bool, mounted: bool, base_z: float
                                               ) -> None:
    out = tmp_path / "out.xml"
    assert _said(_source(tmp_path, hanging, mounted, base_z), out) == []
    assert "upper" not in _floor_touches(out)


def test_a_free_robot_is_left_to_the_spawn_notes(tmp_path: Path) -> None:
    from modelkit.convert.options import WriteOptions

    source = _source(tmp_path, hanging=True)
    notes = write(load(source), tmp_path / "out.xml", options=WriteOptions(base="floating"), force=True)
    assert [n for n in notes if n.code == "MK888"] == []
