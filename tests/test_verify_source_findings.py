"""A source inertia that a URDF reader refuses is the source's finding, not a conversion FAIL:
example-robot-data's Go1 ``base`` has all six terms 1e-6 (principal moments 0, 0, 3e-6: singular,
validate's MK302 for the link alone); PyBullet replaces it by zero. verify compares PyBullet with that
zero tensor and says so with the code."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import modelkit
from modelkit.verify.api import verify
from modelkit.verify.layers import approximations

GO1_LIKE = """<?xml version="1.0"?>
<robot name="go1_like">
  <link name="base">
    <inertial><mass value="5"/>
      <inertia ixx="1e-6" ixy="1e-6" ixz="1e-6" iyy="1e-6" iyz="1e-6" izz="1e-6"/></inertial>
  </link>
  <link name="trunk">
    <inertial><mass value="5"/><inertia ixx="0.02" iyy="0.05" izz="0.06" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="floating_base" type="fixed"><parent link="base"/><child link="trunk"/></joint>
  <link name="thigh">
    <inertial><origin xyz="0 0 -0.1"/><mass value="1"/>
      <inertia ixx="0.005" iyy="0.005" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="thigh"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="10"/></joint>
</robot>
"""


def test_the_refused_tensor_is_classified_with_validate_s_code(tmp_path: Path) -> None:
    path = tmp_path / "go1_like.urdf"
    path.write_text(GO1_LIKE)
    robot = modelkit.load(path)
    refused = approximations.refused_inertias("pybullet", "urdf", robot)
    assert set(refused) == {"base"}
    assert refused["base"].code == "MK302"  # a zero principal moment: singular
    assert np.allclose(refused["base"].tensor, 0.0)
    assert approximations.refused_inertias("mujoco", "mjcf", robot) == {}  # the MJCF writer lifts it
    assert approximations.refusal_code((0.19125, 0.19125, 0.45)) == "MK303"  # ClosedLinkSample-like


PULLER = """<?xml version="1.0"?>
<robot name="puller">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0"
    iyz="0"/></inertial></link>
  <link name="link_puller"><inertial><mass value="0.00292784355893436"/>
    <inertia ixx="1.09317111513898E-07" ixy="-9.31929125413026E-13" ixz="-3.36065188387015E-16"
      iyy="1.10835075609816E-15" iyz="1.43669784789342E-12" izz="1.09317110675672E-07"/></inertial></link>
  <link name="bad"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.3" ixy="0" ixz="0"
    iyz="0"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="link_puller"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="turn" type="revolute"><parent link="base"/><child link="bad"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_drake_is_held_to_a_replacement_only_where_drake_refuses(tmp_path: Path) -> None:
    """Hello Robot Stretch's link_puller misses the triangle inequality by 5.3e-23 (validate's exact
    MK303) and Drake keeps it (its own test allows 16 ε): drake-urdf is compared with the source tensor
    there; a clear violation (0.1 + 0.1 < 0.3) is still compared with Drake's substitute sphere."""
    from modelkit.verify.engines.drake import accepts_inertia

    path = tmp_path / "puller.urdf"
    path.write_text(PULLER)
    robot = modelkit.load(path)
    tensors = {link.name: np.asarray(link.inertial.inertia) for link in robot.links if link.inertial}
    assert approximations.triangle_moments(tensors["link_puller"]) is not None  # validate: MK303
    assert accepts_inertia(tensors["link_puller"]) and not accepts_inertia(tensors["bad"])
    assert set(approximations.refused_inertias("drake-urdf", "urdf", robot)) == {"bad"}
    assert set(approximations.refused_inertias("pybullet", "urdf", robot)) == {"link_puller", "bad"}


def _passes(path: Path, text: str) -> Any:
    """verify's report on ``text`` written at ``path`` (MuJoCo, PyBullet, Pinocchio; no driving),
    asserted free of errors and failed checks."""
    path.write_text(text)
    report = verify(path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3, samples=3,
                    driven=False)
    assert not report.errors
    assert [c for c in report.checks if not c.passed] == [], [c for c in report.checks if not c.passed]
    return report


def test_pybullet_refusing_the_source_inertia_is_no_conversion_fail(tmp_path: Path) -> None:
    report = _passes(tmp_path / "go1_like.urdf", GO1_LIKE)
    inertia = [c for c in report.checks if c.engine == "pybullet" and c.quantity == "inertia"]
    assert len(inertia) == 1 and inertia[0].error == 0.0
    (entry,) = [s for s in report.skips if s.engine == "pybullet" and "source finding MK302" in s.reason]
    assert "base" in entry.reason and "holds zero" in entry.reason
    assert "not a conversion fault" in entry.reason
    # the base is welded: its tensor takes part in no dynamics, so the replay runs and passes
    assert [c for c in report.checks if c.quantity == "replay" and c.passed]


# Drake's cart-pole (pydrake's examples/multibody/cart_pole/cart_pole.sdf), reduced: libsdformat refuses
# exact zeros, so the cart and the point-mass pole carry 1e-20 on each axis, which validate calls zero
# (MK302) and every writer prints as 0 (clean numbers); MuJoCo's moving bodies get 1e-9 more (MK870).
CART_POLE = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="cart_pole">
    <link name="cart">
      <inertial><mass>10</mass><inertia><ixx>1e-20</ixx><iyy>1e-20</iyy><izz>1e-20</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    </link>
    <link name="pole">
      <pose>0 0 -0.5 0 0 0</pose>
      <inertial><mass>1</mass><inertia><ixx>1e-20</ixx><iyy>1e-20</iyy><izz>1e-20</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
    </link>
    <joint name="slider" type="prismatic"><parent>world</parent><child>cart</child>
      <axis><xyz>1 0 0</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis></joint>
    <joint name="pin" type="revolute"><parent>cart</parent><child>pole</child>
      <pose>0 0 0.5 0 0 0</pose><axis><xyz>0 -1 0</xyz></axis></joint>
  </model>
</sdf>
"""


def test_a_zero_source_inertia_written_clean_is_a_source_finding(tmp_path: Path) -> None:
    """Every engine holds what the writer printed (0, and MuJoCo 1e-9 per axis), which layer 1 checks,
    naming the source's MK302. The replay is not run: the two engines hold different repairs of the
    moving links' tensors (pybullet_data's laikago.urdf, all twelve leg tensors 0, moves 1.5e-7 rad
    apart in 0.5 s from that alone), and the report says so."""
    path = tmp_path / "cart_pole.sdf"
    path.write_text(CART_POLE)
    robot = modelkit.load(path)
    zero = approximations.zero_inertias("urdf", [], {}, robot)
    assert set(zero) == {"cart", "pole"} and zero["cart"].code == "MK302"
    assert np.array_equal(np.asarray(zero["cart"].tensor), np.zeros(9))
    report = verify(path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3, samples=3,
                    driven=False)
    assert not report.errors
    assert [c for c in report.checks if not c.passed] == [], [c for c in report.checks if not c.passed]
    for engine in ("mujoco", "pybullet"):
        (entry,) = [s for s in report.skips if s.engine == engine and "source finding MK302" in s.reason]
        assert "cart" in entry.reason and "pole" in entry.reason
    (mujoco,) = [s for s in report.skips if s.engine == "mujoco" and "MK302" in s.reason]
    assert "1e-9" in mujoco.reason
    assert not [c for c in report.checks if c.quantity == "replay"]
    (replay,) = [s for s in report.skips if "layer 3b (replay) not run: source finding" in s.reason]
    assert "cart, pole" in replay.reason


# Drake's planar gripper (examples/planar_gripper/planar_gripper.sdf), reduced: three fingers, of which
# only the first is joined to the model's first link; the others are free bodies (validate's MK201).
# verify stopped with a KeyError in the replay's law before.
FINGER = """    <link name="{f}_base"><pose>{x} 0 0 0 0 0</pose>
      <inertial><mass>0.5</mass><inertia><ixx>0.001</ixx><iyy>0.001</iyy><izz>0.001</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>
    <link name="{f}_link"><pose>{x} 0 -0.1 0 0 0</pose>
      <inertial><mass>0.1</mass><inertia><ixx>0.0002</ixx><iyy>0.0002</iyy><izz>0.0001</izz>
        <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>
    <joint name="{f}_joint" type="revolute"><parent>{f}_base</parent><child>{f}_link</child>
      <axis><xyz>1 0 0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>
"""


def test_links_apart_from_the_root_tree_are_said_not_graded(tmp_path: Path) -> None:
    fingers = "".join(FINGER.format(f=f"finger{i}", x=0.2 * i) for i in (1, 2, 3))
    path = tmp_path / "gripper.sdf"
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="1.7"><model name="gripper">\n{fingers}'
                    "  </model>\n</sdf>\n")
    report = verify(path, engines=("mujoco", "pybullet", "pinocchio"), configurations=3, samples=3,
                    driven=False)
    assert not report.errors
    assert [c for c in report.checks if not c.passed] == [], [c for c in report.checks if not c.passed]
    (entry,) = [s for s in report.skips if "not connected to the root link" in s.reason]
    assert "finger2_base, finger2_link, finger3_base, finger3_link" in entry.reason
    assert "not graded" in entry.reason
    assert [c for c in report.checks if c.quantity == "replay" and c.passed]


def test_a_tensor_near_the_triangle_bound_verifies_in_every_engine(tmp_path: Path) -> None:
    """The same model verified: Drake keeps link_puller's tensor, PyBullet zeroes it, and the MJCF
    writer adds 1e-9 kg·m² per axis, calling it singular as MuJoCo does (MK870) though validate calls
    it MK303; each engine is compared with what it holds. Before, drake-urdf failed layers 1 and 3
    (compared with a substitute sphere Drake never made) and MuJoCo failed layer 1 (the writer's 1e-9
    was expected only for an MK302 tensor)."""
    path = tmp_path / "puller.urdf"
    path.write_text(PULLER)
    report = verify(path, tmp_path / "out", ("mujoco", "pybullet", "drake-urdf", "pinocchio"),
                    configurations=2, samples=2, driven=False)
    assert report.failed == [], [c.detail for c in report.failed]
    checked = {(c.engine, c.quantity) for c in report.checks if c.layer == 1 and c.quantity == "inertia"}
    assert {("mujoco", "inertia"), ("drake-urdf", "inertia"), ("pybullet", "inertia")} <= checked


def test_pybullet_s_own_rounding_refusal_is_predicted() -> None:
    """PyBullet tests the moments its diagonalisation finds (btMatrix3x3::diagonalize, threshold 1e-6),
    exactly: Robotiq 2F-85's knuckle tensor sits on the triangle bound (8.77e-7 + 9.123e-6 = 1e-5),
    validate finds no fault, and PyBullet refuses it by rounding."""
    from modelkit.verify.engines.bullet_inertia import refuses

    knuckle = np.array([[9e-6, -1e-6, 0.0], [-1e-6, 1e-6, 0.0], [0.0, 0.0, 1e-5]])
    assert approximations.triangle_moments(knuckle) is None and refuses(knuckle)
    assert refuses(np.diag([0.1, 0.1, 0.3])) and not refuses(np.diag([1.0, 1.0, 2.0]))
    assert not refuses(np.diag([0.02, 0.05, 0.06]))


def test_a_corpus_gripper_pybullet_refuses_by_rounding_verifies(tmp_path: Path) -> None:
    """Choreonoid's Robotiq 2F-85 (corpus): PyBullet zeroes both knuckles' tensors; its layer 3a
    failed by 9.5e-2 (M[0,0] short by the knuckle's 1e-5 kg·m²) and the replay by 3.6e-3 rad. Now
    PyBullet is compared with the zero it holds, and MuJoCo's replay holds the same zero."""
    from tests.conftest import CORPUS

    source = CORPUS / "choreonoid" / "share" / "model" / "Robotiq" / "2F-85.body"
    report = verify(source, tmp_path / "out", ("mujoco", "pybullet", "pinocchio"), configurations=2,
                    samples=3, driven=False)
    assert report.failed == [], [c.detail for c in report.failed]
    (replay,) = [c for c in report.checks if c.quantity == "replay"]
    assert replay.error < 1e-12, replay.detail
    said = [s.reason for s in report.skips if s.engine == "pybullet" and "by rounding" in s.reason]
    assert said and "Finger1_knuckle" in said[0] and "validate finds no fault" in said[0]


# ARMAR-4's right shoulder (armar 1.1.0 on PyPI): ixx 0 beside iyy 0.0575 and izz 0.0195, singular and
# off the triangle bound at once; and its ankles' collision spheres of radius 0.
ARMAR_LIKE = """<?xml version="1.0"?>
<robot name="armar_like">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0"
    iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.00"/></geometry></collision>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="sho3"><inertial><origin xyz="0 -0.0575318 0.0134998"/><mass value="0.51"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0.0575321" iyz="0" izz="0.0195"/></inertial></link>
  <joint name="world_mount" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="world"/>
  <joint name="sho3_joint" type="revolute"><parent link="base"/><child link="sho3"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.2" rpy="0.3 0.2 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


def test_a_tensor_singular_and_off_the_triangle_and_a_radius_0_sphere_are_source_findings(
        tmp_path: Path) -> None:
    """The MJCF writer adds 1e-9 per axis (singular) and then raises the two smaller moments (a + b ≥
    c), both MK870; layer 1 expected only the first and failed ARMAR-4 at 0.33 (and its mass matrix
    and bias by 7e-3). The sphere of radius 0 (validate's MK416), which MuJoCo refuses and the writer
    leaves out (MK871), failed MuJoCo's shape-set. Both are now the source's findings, said."""
    report = _passes(tmp_path / "armar_like.urdf", ARMAR_LIKE)
    (inertia,) = [c for c in report.checks if c.engine == "mujoco" and c.quantity == "inertia"]
    assert inertia.error < 1e-12
    (said,) = [s for s in report.skips if s.engine == "mujoco" and "MK302" in s.reason]
    assert "sho3" in said.reason and "a + b = c" in said.reason
    (shape,) = [s for s in report.skips if s.engine == "mujoco" and "MK416" in s.reason]
    assert "base" in shape.reason and "MK871" in shape.reason
    (shape_set,) = [c for c in report.checks if c.engine == "mujoco" and c.quantity == "shape-set"]
    assert shape_set.error == 0.0
    assert not [s for s in report.skips if s.engine == "pybullet" and "MK416" in s.reason]  # a point there
