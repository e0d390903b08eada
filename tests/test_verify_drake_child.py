"""Drake runs in a child process (``engines/drake_child.py``), so that an abort in its C++ ends the child
and not verify: a URDF with a reversed joint range made Drake's Joint constructor abort, and verify ended
with exit 1 and no verdict (found by running verify on semantic-fuzz mutants, 2026-12-04).

Real Drake, real files: the child answers as the in-process adapter does, bit for bit; an abort is a
failed load when the conversion made the range, a skip naming MK307 when the source holds it; the
written MJCF's unlimited joint (MK824) and PyBullet's reading of a reversed range as no limit are
graded as the documented approximations they are.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pydrake", reason="Drake is an optional extra: pip install modelkit[drake]")

import modelkit
from modelkit.convert import write
from modelkit.convert.compare import random_configuration
from modelkit.model import JointType
from modelkit.verify.api import verify
from modelkit.verify.engines import drake as engine_drake
from modelkit.verify.engines import drake_child
from tests.conftest import TUTORIAL

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"

ARM = """<sdf version="1.9"><model name="arm">
  <link name="base"><inertial><mass>2</mass><inertia><ixx>0.02</ixx><iyy>0.02</iyy><izz>0.02</izz>
    </inertia></inertial><collision name="c"><geometry><box><size>0.2 0.2 0.1</size></box></geometry>
    </collision></link>
  <link name="upper"><pose>0 0 0.3 0 0 0</pose><inertial><mass>0.5</mass><inertia><ixx>0.004</ixx>
    <iyy>0.004</iyy><izz>0.001</izz></inertia></inertial><collision name="c"><geometry><cylinder>
    <radius>0.03</radius><length>0.2</length></cylinder></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent>base</parent><child>upper</child>
    <axis><xyz>0 1 0</xyz><limit><lower>LOWER</lower><upper>UPPER</upper></limit></axis></joint>
</model></sdf>"""


def test_the_child_answers_as_the_adapter_in_this_process(tmp_path: Path) -> None:
    robot = copy.deepcopy(modelkit.load(PANTILT))
    robot.root_joint = JointType.FIXED
    for name in ("x.sdf", "x.urdf"):
        write(robot, tmp_path / name)
        here = engine_drake.load(tmp_path / name, {}, root=str(robot.root))
        there = drake_child.load(tmp_path / name, {}, root=str(robot.root))
        try:
            assert there.engine == here.engine and there.settings["process"] == "child process"
            assert there.dof_names() == here.dof_names() and len(here.dof_names()) >= 2
            assert there.dof_names_with_balls() == here.dof_names_with_balls()
            assert there.warnings == here.warnings
            assert sorted(there.static().links) == sorted(here.static().links)
            rng = np.random.default_rng(3)
            q = random_configuration(robot, rng)
            dq = {name: float(rng.uniform(-1, 1)) for name in here.dof_names()}
            assert np.array_equal(there.mass_matrix(q), here.mass_matrix(q))
            assert np.array_equal(there.bias(q, dq), here.bias(q, dq))
            mine, theirs = here.link_poses(q), there.link_poses(q)
            assert sorted(mine) == sorted(theirs)
            for link, pose in mine.items():
                assert pose.rotation_tuple == theirs[link].rotation_tuple, link
                assert pose.translation_tuple == theirs[link].translation_tuple, link
        finally:
            there.close()


def test_an_abort_in_drake_ends_the_child_not_the_caller(tmp_path: Path) -> None:
    """The URDF keeps a reversed range; Drake's URDF parser hands it to the Joint constructor, whose
    assertion aborts. Loaded here, that would end pytest; in the child it is an exception that names
    the assertion."""
    urdf = tmp_path / "arm.urdf"
    source = tmp_path / "arm.sdf"
    source.write_text(ARM.replace("LOWER", "1").replace("UPPER", "-1"))
    write(modelkit.load(source), urdf)
    with pytest.raises(drake_child.DrakeReversedRange, match=r"(?s)died during load.*pos_lower_limits"):
        drake_child.load_urdf(urdf, {}, root="base")


def test_verify_grades_a_source_whose_range_is_reversed(tmp_path: Path) -> None:
    """The source's own reversed range (MK307, which libsdformat loads): verify gives a verdict. Drake
    refuses it in SDF and aborts on it in URDF: both skipped, naming the joint and MK307. MuJoCo holds
    the MJCF writer's unlimited joint (MK824) and PyBullet takes the URDF's reversed range as no limit:
    layer 1 grades exactly those bounds."""
    source = tmp_path / "arm.sdf"
    source.write_text(ARM.replace("LOWER", "1").replace("UPPER", "-1"))
    report = verify(source, tmp_path / "out", configurations=2, samples=1, replay=False, driven=False)
    assert report.errors == [] and report.failed == [], [c.detail for c in report.failed]
    skipped = {s.engine: s.reason for s in report.skips if s.reason.startswith("not verified")}
    assert set(skipped) == {"drake", "drake-urdf"}
    assert all("shoulder [1, -1]" in reason and "MK307" in reason for reason in skipped.values())
    assert "refuses" in skipped["drake"] and "Joint constructor aborts" in skipped["drake-urdf"]
    said = {s.engine: s.reason for s in report.skips if "reversed range" in s.reason}
    assert "MK824" in said["mujoco"] and "as no limit" in said["pybullet"]
    limits = {c.engine: c for c in report.checks if c.quantity == "limits"}
    assert limits["mujoco"].passed and limits["pybullet"].passed


def test_a_reversed_range_the_conversion_made_is_a_failed_load(tmp_path: Path) -> None:
    """The source's range is ordered; the URDF handed to verify (``urdf=``) reverses it: Drake's abort
    is then a fault of that file, a failed load check, and every other engine is still graded."""
    source = tmp_path / "arm.sdf"
    source.write_text(ARM.replace("LOWER", "-1").replace("UPPER", "1"))
    given = tmp_path / "given.urdf"
    write(modelkit.load(source), given)
    text = given.read_text()
    assert 'lower="-1" upper="1"' in text
    given.write_text(text.replace('lower="-1" upper="1"', 'lower="1" upper="-1"'))
    report = verify(source, tmp_path / "out", engines=("mujoco", "drake-urdf"), urdf=given,
                    configurations=2, samples=1, replay=False, driven=False)
    assert report.errors == []
    failed = [c for c in report.failed if c.engine == "drake-urdf"]
    assert [c.quantity for c in failed] == ["load"] and "pos_lower_limits" in failed[0].detail
    assert any(c.engine == "mujoco" and c.layer == 2 and c.passed for c in report.checks)
