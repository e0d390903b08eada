"""MK883: a free robot standing on bodies so light that MuJoCo's default contact gives way (issue 17).

MuJoCo softens a contact by the inverse mass it moves, so a 10 g foot under a 26 kg robot sinks into
a default floor: icub-models' iCubLisboa01 (10 g feet) sinks 33 mm and falls within 2 s, while every
robot measured standing has a load ratio (robot mass times the body's ``body_invweight0``) of at most
178. These tests convert a small biped twice, with 10 g and with 0.5 kg feet, and check the warning
against what the user meets: the written file on a default plane, reset to ``home``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from tests.conftest import example_robot

mujoco = pytest.importorskip("mujoco")

BIPED = """<robot name="biped">
  <link name="pelvis">
    <inertial><mass value="25"/><inertia ixx="0.5" iyy="0.5" izz="0.5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.3 0.4 0.2"/></geometry></collision>
  </link>
{legs}
</robot>
"""
LEG = """  <joint name="{side}_hip" type="revolute">
    <parent link="pelvis"/><child link="{side}_shank"/><origin xyz="0 {y} -0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="200" velocity="5"/>
  </joint>
  <link name="{side}_shank">
    <inertial><origin xyz="0 0 -0.25"/><mass value="1"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.25"/>
      <geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
  </link>
  <joint name="{side}_ankle" type="revolute">
    <parent link="{side}_shank"/><child link="{side}_foot"/><origin xyz="0 0 -0.5"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="100" velocity="5"/>
  </joint>
  <link name="{side}_foot">
    <inertial><origin xyz="0.02 0 -0.03"/><mass value="{foot}"/>
      <inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.02 0 -0.03"/><geometry><box size="0.2 0.1 0.04"/></geometry></collision>
  </link>
"""


def biped(tmp_path: Path, foot: float) -> Path:
    legs = "".join(LEG.format(side=side, y=y, foot=foot, i=foot * 1e-3)
                   for side, y in (("l", 0.12), ("r", -0.12)))
    path = tmp_path / f"biped_{foot:g}.urdf"
    path.write_text(BIPED.format(legs=legs))
    return path


def converted(source: Path, out: Path) -> tuple[Path, list[str]]:
    notes = write(load(source), out, force=True)
    return out, [f"{n.code} {n.message}" for n in notes]


def deepest_contact(path: Path, seconds: float = 0.5) -> float:
    """The deepest floor contact (m) while the written file, reset to ``home`` on a default plane, stands
    for ``seconds`` under its own position servos."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    deepest = 0.0
    for _ in range(round(seconds / m.opt.timestep)):
        mujoco.mj_step(m, d)
        deepest = max([deepest, *(-float(c.dist) for c in d.contact[:d.ncon])])
    return deepest


def test_light_feet_are_said_and_sink(tmp_path: Path) -> None:
    light, notes = converted(biped(tmp_path, 0.01), tmp_path / "light" / "r.xml")
    said = [n for n in notes if n.startswith("MK883")]
    assert len(said) == 1, notes
    assert "l_foot (0.01 kg, load ratio" in said[0] and "r_foot (0.01 kg, load ratio" in said[0]
    heavy, notes = converted(biped(tmp_path, 0.5), tmp_path / "heavy" / "r.xml")
    assert not [n for n in notes if n.startswith("MK883")]
    # what the warning is about, on the written files: the light feet sink several times deeper
    sunk, held = deepest_contact(light), deepest_contact(heavy)
    assert sunk > 0.01 and sunk > 5.0 * held, (sunk, held)


@pytest.mark.parametrize(
    "relative",
    [
        "hyq_description/robots/hyq_no_sensors.urdf",  # load ratio 177, the largest measured standing
        "anymal_b_simple_description/robots/anymal-kinova.urdf",  # 137
        "icub_description/robots/icub.urdf",  # a humanoid on flat feet, 11
    ],
)
def test_robots_that_stand_are_not_warned(tmp_path: Path, relative: str) -> None:
    _, notes = converted(example_robot(relative), tmp_path / "r.xml")
    assert not [n for n in notes if n.startswith("MK883")]
