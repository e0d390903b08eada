"""A mimic of a mimic (ManiSkill 3.0's Inspire hand: the thumb's IP joint mimics its MCP joint, which mimics
CMC pitch, written so on purpose for PhysX tendons).

urdfdom, MuJoCo, PyBullet and Pinocchio follow the chain. yourdfpy takes a leader that is itself a mimic
as 0 and logs a warning for every configuration it is asked: `verify` failed layer 2 for yourdfpy on both
Inspire hands (the thumb tip 8 mm off, 0.36 rad) and printed 104 warning lines. yourdfpy is now skipped
for such a file, with the reason; the other engines grade it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.verify.api import verify
from modelkit.verify.engines.reference import mimic_chain, yourdfpy_limit

pytest.importorskip("yourdfpy")
pytest.importorskip("mujoco")

_LINK = ('<link name="{name}"><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" '
         'ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry><box size="0.04 0.01 0.01"/></geometry>'
         "</visual></link>\n")
THUMB = ("<robot name=\"thumb\">\n" + _LINK.format(name="palm") + _LINK.format(name="proximal")
         + _LINK.format(name="middle") + _LINK.format(name="distal") + """
  <joint name="cmc" type="revolute"><parent link="palm"/><child link="proximal"/><origin xyz="0.04 0 0"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.6" effort="1" velocity="1"/></joint>
  <joint name="mcp" type="revolute"><parent link="proximal"/><child link="middle"/><origin xyz="0.04 0 0"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.8" effort="1" velocity="1"/>
    <mimic joint="cmc" multiplier="1.3333" offset="-0.0814"/></joint>
  <joint name="ip" type="revolute"><parent link="middle"/><child link="distal"/><origin xyz="0.04 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-0.4" upper="0.4" effort="1" velocity="1"/>
    <mimic joint="mcp" multiplier="0.5" offset="0"/></joint>
</robot>
""")


def test_the_chain_is_found(tmp_path: Path) -> None:
    path = tmp_path / "thumb.urdf"
    path.write_text(THUMB)
    assert mimic_chain(path) == ("ip", "mcp")
    path.write_text(THUMB.replace('<mimic joint="mcp"', '<mimic joint="cmc"'))
    assert mimic_chain(path) is None


def test_verify_skips_yourdfpy_on_a_mimic_chain_and_passes(tmp_path: Path,
                                                           capfd: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "thumb.urdf"
    source.write_text(THUMB)
    report = verify(source, tmp_path / "verify", engines=("mujoco", "pybullet", "pinocchio", "yourdfpy"),
                    replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    (skip,) = [s for s in report.skips if s.engine == "yourdfpy"]
    assert "ip mimics mcp, itself a mimic" in skip.reason
    # the chain is graded by the engines that follow it: the distal link's pose in MuJoCo and PyBullet
    graded = {(c.engine, c.quantity) for c in report.checks if c.layer == 2}
    assert {("mujoco", "pose-position"), ("pybullet", "pose-position")} <= graded
    assert "yourdfpy" not in capfd.readouterr().err


PLANAR = ("<robot name=\"base\">\n<link name=\"footprint\"/>\n" + _LINK.format(name="chassis")
          + _LINK.format(name="arm") + """
  <joint name="base_joint" type="planar"><parent link="footprint"/><child link="chassis"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="chassis"/><child link="arm"/><origin xyz="0.1 0 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""")


def test_a_planar_joint_is_a_yourdfpy_limit(tmp_path: Path) -> None:
    """yourdfpy counts a planar joint as two coordinates and places its child at the joint's origin
    whatever they are, which shifts every later joint's coordinate: roboplan's reachback (a planar
    ``base_joint``) failed yourdfpy's layer 2 by 6.2 m. yourdfpy is skipped for such a file, saying why."""
    path = tmp_path / "base.urdf"
    path.write_text(PLANAR)
    said = yourdfpy_limit(path)
    assert said is not None and "joint base_joint is planar" in said
    assert yourdfpy_limit(tmp_path / "missing.urdf") is None
    path.write_text(PLANAR.replace('type="planar"', 'type="fixed"'))
    assert yourdfpy_limit(path) is None
    path.write_text(PLANAR.replace('type="planar"', 'type="floating"'))
    assert "joint base_joint is floating" in str(yourdfpy_limit(path))
    path.write_text(THUMB)
    assert "ip mimics mcp, itself a mimic" in str(yourdfpy_limit(path))


def test_verify_skips_yourdfpy_on_a_planar_joint(tmp_path: Path) -> None:
    source = tmp_path / "base.urdf"
    source.write_text(PLANAR)
    report = verify(source, tmp_path / "verify", engines=("yourdfpy",), replay=False, driven=False)
    (skip,) = [s for s in report.skips if s.engine == "yourdfpy"]
    assert "joint base_joint is planar" in skip.reason
    assert not [c for c in report.checks if c.engine == "yourdfpy"]
