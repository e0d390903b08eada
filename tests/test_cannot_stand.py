"""MK887: a free robot that cannot stand on a floor at home (issue 18 §4, faults no loader finds).

roboschool's Fetch has no caster collision and tips onto its chassis in the first half second; no loader
says a word. The rule looks at the robot's centre of mass at home against the region its ground contacts
span seen from above; over a line (two wheels) the note says how far the robot pitches and onto what.
Checked in MuJoCo on the written files: the robot warned tips over, the robot with a caster does not;
sound robots (the tutorial's, example-robot-data's legged robots) are not warned.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from tests.conftest import example_robot
from tests.test_mobile_arm_servos import MOBILE_ARM

TUTORIAL = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
CASTER = '<joint name="caster_joint" type="fixed"><parent link="base"/><child link="caster"/>'


def _without_caster() -> str:
    """The mobile arm with its caster link and joint taken out: it rests on its two wheels."""
    text = MOBILE_ARM
    start = text.index('<link name="caster">')
    text = text[:start] + text[text.index("</link>", start) + len("</link>"):]
    start = text.index(CASTER)
    return text[:start] + text[text.index("</joint>", start) + len("</joint>"):]


def _convert(tmp_path: Path, text: str, name: str) -> tuple[Path, list[str]]:
    source = tmp_path / f"{name}.urdf"
    source.write_text(text)
    out = tmp_path / "out" / f"{name}.xml"
    notes = write(load(source), out, options=WriteOptions(base="floating"))
    return out, [n.message for n in notes if n.code == "MK887"]


def _tilt_on_a_plain_floor(path: Path, seconds: float = 2.0, settled: bool = False) -> float:
    """The base's largest turn about a horizontal axis (rad) in ``seconds`` from ``home`` (``settled``:
    its turn at the end)."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    frame = np.zeros(9)
    mujoco.mju_quat2Mat(frame, d.qpos[3:7])
    start, worst = frame.reshape(3, 3)[:, 2].copy(), 0.0
    for _ in range(round(seconds / m.opt.timestep)):
        mujoco.mj_step(m, d)
        mujoco.mju_quat2Mat(frame, d.qpos[3:7])
        turn = float(np.arccos(np.clip(frame.reshape(3, 3)[:, 2] @ start, -1.0, 1.0)))
        worst = max(worst, turn)
    return turn if settled else worst


def test_two_wheels_without_a_caster_are_said_and_tip(tmp_path: Path) -> None:
    out, said = _convert(tmp_path, _without_caster(), "no_caster")
    assert len(said) == 1, said
    assert "span only a line" in said[0] and "left_wheel, right_wheel" in said[0], said[0]
    assert _tilt_on_a_plain_floor(out) > 0.15
    # where it comes to rest: on its base's box, at the angle said (29.7°; MuJoCo: 31.9°, the contacts'
    # softness and the wheels' give)
    assert "onto the collision shape of base" in said[0], said[0]
    stated = float(said[0].split("pitches ")[1].split("°")[0])
    assert stated == pytest.approx(np.degrees(_tilt_on_a_plain_floor(out, settled=True)), abs=3.0)


def test_with_its_caster_it_stands_and_nothing_is_said(tmp_path: Path) -> None:
    out, said = _convert(tmp_path, MOBILE_ARM, "caster")
    assert said == []
    assert _tilt_on_a_plain_floor(out) < 0.02


def test_a_centre_of_mass_beyond_the_feet_is_said(tmp_path: Path) -> None:
    """A box on the floor with a 20 kg block held 1 m out on an arm (a joint about the vertical): its
    centre of mass lies 0.6 m beyond the box's edge."""
    text = ('<robot name="reach"><link name="base"><inertial><mass value="5"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
            '<collision><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>'
            '<link name="weight"><inertial><mass value="20"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
            '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>'
            '<joint name="arm" type="revolute"><parent link="base"/><child link="weight"/>'
            '<origin xyz="1 0 0.5"/><axis xyz="0 0 1"/>'
            '<limit lower="-1" upper="1" effort="100" velocity="1"/></joint></robot>')
    out, said = _convert(tmp_path, text, "reach")
    assert len(said) == 1 and "mm outside the region" in said[0], said
    outside = float(said[0].split("lies ")[1].split(" mm")[0])
    assert outside == pytest.approx(1000 * (1.0 * 20 / 25 - 0.2), abs=0.1)
    assert _tilt_on_a_plain_floor(out) > 0.15


@pytest.mark.parametrize("source", [
    TUTORIAL / "mobile_robot_pantilt.body", TUTORIAL / "mobile_robot_tracks.body",
    "go1_description/urdf/go1.urdf", "anymal_b_simple_description/robots/anymal.urdf",
    "talos_data/robots/talos_reduced.urdf", "solo_description/robots/solo12.urdf",
], ids=lambda s: Path(str(s)).name)
def test_robots_that_stand_are_not_said(tmp_path: Path, source: Path | str) -> None:
    path = source if isinstance(source, Path) else example_robot(source)
    notes = write(load(path), tmp_path / "robot.xml")
    assert not [n.message for n in notes if n.code == "MK887"]


def test_a_prop_is_not_said(tmp_path: Path) -> None:
    """A thing without a moving joint is a prop, not a robot that should stand: pybullet_data's duck
    rests off-centre on its curved bottom and rocks 0.02 rad before it settles."""
    pybullet_data = pytest.importorskip("pybullet_data")
    notes = write(load(Path(pybullet_data.getDataPath()) / "duck_vhacd.urdf"), tmp_path / "duck.xml")
    assert not [n for n in notes if n.code == "MK887"]


def test_the_support_region_is_the_convex_hull() -> None:
    """The hull (with its filter for many points: a mesh's flat sole) against SciPy's Qhull."""
    from scipy.spatial import ConvexHull

    from modelkit.convert.stance import _area, _hull

    rng = np.random.default_rng(7)
    grid = np.stack(np.meshgrid(np.linspace(0.0, 0.2, 300), np.linspace(0.0, 0.1, 300)), -1).reshape(-1, 2)
    for points in (rng.uniform(-1.0, 1.0, (50, 2)), rng.normal(size=(20000, 2)), grid):
        ours = _hull(points)
        assert _area(ours) == pytest.approx(ConvexHull(points).volume, rel=1e-5)
