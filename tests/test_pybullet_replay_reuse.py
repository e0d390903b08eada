"""Layer 3b reuses the PyBullet child of layers 1-3 (one process start less per verify run) only where
that cannot change the replay: the same file at the same time step. The reused child's replay equals
a fresh child's to the bit after layers 1-3's queries (poses, mass matrix, inverse dynamics at random
states), which leave joint states behind but never step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.convert.api import write
from modelkit.verify.api import ENGINE_FILES, welded_copy
from modelkit.verify.engines.protocol import TorqueLaw

pybullet_engine = pytest.importorskip("modelkit.verify.engines.pybullet")

PANTILT = (Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
           / "mobile_robot_pantilt.body")


@pytest.fixture(scope="module")
def urdf(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    robot = welded_copy(modelkit.load(PANTILT))[0]
    path = tmp_path_factory.mktemp("reuse") / "robot.urdf"
    write(robot, path, "urdf", options=ENGINE_FILES, force=True)
    return path, str(robot.root)


def _law(model: object) -> TorqueLaw:
    joints = tuple(model.dof_names())  # type: ignore[attr-defined]
    n = len(joints)
    phases = tuple(0.3 * i for i in range(n))
    return TorqueLaw(joints, (20.0,) * n, (1.0,) * n, (0.8,) * n, (0.5,) * n, phases)


def test_the_replay_reuses_the_loaded_child_and_integrates_the_same(urdf: tuple[Path, str]) -> None:
    path, root = urdf
    loaded = pybullet_engine.load(path, {}, root=root)
    try:
        rng = np.random.default_rng(7)
        for _ in range(3):  # what layers 1-3 leave behind
            q = {name: float(rng.uniform(-1.0, 1.0)) for name in loaded.dof_names()}
            loaded.link_poses(q)
            loaded.mass_matrix(q)
            loaded.bias(q, {name: float(rng.uniform(-2.0, 2.0)) for name in loaded.dof_names()})
        reused = pybullet_engine.simulator(path, {}, root=root, dt=loaded.dt, loaded=loaded)
        assert reused is loaded
        with pybullet_engine.simulator(path, {}, root=root, dt=loaded.dt) as fresh:
            assert fresh is not loaded
            law = _law(fresh)
            a = reused.replay(law, 2.0, loaded.dt)
            b = fresh.replay(law, 2.0, loaded.dt)
        assert float(np.max(np.abs(b))) > 0.1  # the joints moved
        assert np.array_equal(a, b)
    finally:
        loaded.close()


def test_another_time_step_file_or_a_closed_child_gets_its_own(urdf: tuple[Path, str]) -> None:
    path, root = urdf
    loaded = pybullet_engine.load(path, {}, root=root)
    copy = path.with_name("copy.urdf")  # beside it: the same meshes
    copy.write_bytes(path.read_bytes())
    try:
        for other in (pybullet_engine.simulator(path, {}, root=root, dt=2 * loaded.dt, loaded=loaded),
                      pybullet_engine.simulator(copy, {}, root=root, dt=loaded.dt, loaded=loaded)):
            assert other is not loaded
            other.close()
        loaded.close()
        again = pybullet_engine.simulator(path, {}, root=root, dt=loaded.dt, loaded=loaded)
        assert again is not loaded and again.alive()
        again.close()
    finally:
        loaded.close()
