"""An MJCF ball joint's spring is never lost without a word: ``.body``, URDF and SDF have no place for
it and say so (MK854, naming the joint and the stiffness); MJCF writes it back, and MuJoCo compiles
the same ``jnt_stiffness``. Before, the MJCF reader kept it in ``extras`` and only URDF's other joints
looked there: ``.body``, SDF, URDF's ball and MJCF itself dropped it silently."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from modelkit.api import validate
from modelkit.convert.api import write
from modelkit.convert.notes import ConversionNote

SOURCE = """<mujoco model="ballspring">
  <worldbody>
    <body name="base">
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <body name="arm" pos="0 0 0.3">
        <joint name="shoulder" type="ball" stiffness="5" damping="0.5" armature="0.01" frictionloss="0.2"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.03" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _convert(tmp_path: Path, suffix: str) -> tuple[Path, list[ConversionNote]]:
    source = tmp_path / "ball.xml"
    source.write_text(SOURCE)
    robot = validate(source).robot
    assert robot is not None
    out = tmp_path / suffix / f"ball.{suffix}"
    out.parent.mkdir()
    return out, write(robot, out)


@pytest.mark.parametrize("suffix", ["body", "urdf", "sdf"])
def test_a_target_without_ball_springs_says_it_drops_one(suffix: str, tmp_path: Path) -> None:
    _, notes = _convert(tmp_path, suffix)
    spring = [n for n in notes if n.code == "MK854"]
    assert len(spring) == 1, [(n.code, n.message) for n in notes]
    assert spring[0].severity == "warning"
    assert '"shoulder"' in spring[0].message and "stiffness 5 " in spring[0].message, spring[0].message


@pytest.mark.parametrize("suffix", ["body", "urdf", "sdf"])
def test_every_dynamics_value_a_target_cannot_hold_is_named(suffix: str, tmp_path: Path) -> None:
    """Damping 0.5, friction 0.2, armature 0.01: kept where the target holds them (URDF's three
    continuous joints: damping and friction), else named in a note."""
    out, notes = _convert(tmp_path, suffix)
    said = " ".join(n.message for n in notes if n.code in ("MK820", "MK854") and "shoulder" in n.message)
    kept = {"urdf": ("damping", "friction")}.get(suffix, ())
    for word, value in (("damping", "0.5"), ("friction", "0.2"), ("armature", "0.01")):
        if word in kept:
            assert f'{word}="{value}"' in out.read_text(), (suffix, word)
        else:
            assert f"{word} {value}" in said, (suffix, word, said)


def test_mjcf_writes_the_ball_spring_back(tmp_path: Path) -> None:
    out, notes = _convert(tmp_path, "xml")
    assert not [n for n in notes if n.code in ("MK820", "MK854")]
    model = mujoco.MjModel.from_xml_path(str(out))
    source = mujoco.MjModel.from_xml_string(SOURCE)
    for m in (model, source):
        assert m.jnt_stiffness[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "shoulder")] == 5.0
