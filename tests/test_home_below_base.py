"""MK865: a welded arm whose home pose reaches below its base is said at conversion, with the depth.

On a table or floor the base stands on, such a pose starts inside it and MuJoCo pushes the arm out at
the first step. The test arms are a base box (its bottom at z = 0) and one link on a hinge whose
capsule hangs down or stands up at q = 0; the Kinova arm of example-robot-data has the fault in its
zero pose and not in its SRDF's ``arm_up``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from click.testing import CliRunner

from modelkit.api import load
from modelkit.cli import main
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from tests.conftest import example_robot

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')

ARM = f"""<robot name="arm">
  <link name="base">{INERTIAL}
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper">{INERTIAL}
    <collision><origin xyz="0.2 0 OFFSET"/><geometry><cylinder radius="0.03" length="0.3"/></geometry>
    </collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
</robot>
"""


def _notes(tmp_path: Path, offset: float, base: str = "auto") -> list:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace("OFFSET", str(offset)))
    return write(load(path), tmp_path / "out" / "arm.xml", options=WriteOptions(base=base), force=True)


def test_a_link_hanging_below_the_base_is_said_with_its_depth(tmp_path: Path) -> None:
    # the upper link's cylinder (axis along z, half length 0.15) centred 0.2 below the shoulder, which is
    # 0.1 above the base's bottom: its lowest point is 0.1 - 0.2 - 0.15 = -0.25 m, 250 mm below the base
    (said,) = [n for n in _notes(tmp_path, -0.2) if n.code == "MK865"]
    assert said.severity == "warning"
    assert "1 moving bod(ies)" in said.message and "upper 250 mm" in said.message
    assert "--srdf" in said.message


def test_a_link_above_the_base_or_just_touching_its_plane_is_not_said(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, 0.3) if n.code == "MK865"]
    # centred 0.0495 above the shoulder: its lowest point 0.1 + 0.0495 - 0.15 is 0.5 mm below the base's
    # bottom, within the 1 mm a mesh's or a rounding's slack may take
    assert not [n for n in _notes(tmp_path, 0.0495) if n.code == "MK865"]


def test_a_robot_hanging_from_its_base_is_not_judged(tmp_path: Path) -> None:
    """The moving link's mass at the cylinder's centre, 0.1 m below the base's bottom: the robot hangs
    from its base (a finger under its frame, an arm on a shoulder), so no floor is under it."""
    path = tmp_path / "arm.urdf"
    hanging = ARM.replace("OFFSET", "-0.2").replace(
        f'<link name="upper">{INERTIAL}',
        '<link name="upper">' + INERTIAL.replace("<inertial>", '<inertial><origin xyz="0.2 0 -0.2"/>'))
    path.write_text(hanging)
    notes = write(load(path), tmp_path / "out" / "arm.xml", force=True)
    assert not [n for n in notes if n.code == "MK865"]


def test_a_floating_robot_is_not_judged(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, -0.2, base="floating") if n.code == "MK865"]


@pytest.mark.parametrize("with_srdf", [False, True])
def test_the_kinova_zero_pose_is_said_and_its_srdf_pose_is_not(tmp_path: Path, with_srdf: bool) -> None:
    urdf = example_robot("kinova_description/robots/kinova.urdf")
    srdf = example_robot("kinova_description/srdf/kinova.srdf")
    out = tmp_path / "kinova.xml"
    extra = ["--srdf", str(srdf)] if with_srdf else []
    result = CliRunner().invoke(main, ["convert", str(urdf), "--package-path",
                                       f"example-robot-data={urdf.parents[3]}", *extra, "-o", str(out)])
    assert result.exit_code == 0, result.output
    said = [line for line in result.output.splitlines() if "MK865" in line]
    if with_srdf:
        assert not said
        return
    (line,) = said
    assert "j2s6s200_link_2 45 mm" in line and "j2s6s200_link_3 45 mm" in line
    # the written file itself: on a plane at the base's bottom (z = 0), MuJoCo finds the links inside it
    spec = mujoco.MjSpec.from_file(str(out))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[2, 2, 0.1])
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    depth = max(-data.contact[i].dist for i in range(data.ncon))
    assert 0.040 < depth < 0.050
