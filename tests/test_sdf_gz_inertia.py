"""The SDF writer's inertia test is libsdformat's own (gz-math ``MassMatrix3::IsValid``, redone in
:mod:`modelkit.formats.sdf.gz_inertia`): it agrees with libsdformat on tensors at the edge of the
triangle inequality, and a tensor it repairs is accepted. Hello Robot's Stretch gripper puller (moments
1.08e-15 and two near 1.0931711e-7) was written lifted to meet A + B ≥ C by numpy's eigenvalues, and
libsdformat refused the whole file ("link_puller has invalid inertia"): gz-math's closed-form moments
are less precise when two coincide."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.cli import main
from modelkit.formats.sdf.gz_inertia import libsdformat_accepts
from modelkit.formats.sdf.writer import as_written, sdformat_valid_inertia
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

# The puller's tensor as hello-robot-stretch-urdf 0.1.2 gives it (RE2V0, tool_stretch_gripper).
PULLER = np.array([[1.09317111513898e-07, -9.31929125413026e-13, -3.36065188387015e-16],
                   [-9.31929125413026e-13, 1.10835075609816e-15, 1.43669784789342e-12],
                   [-3.36065188387015e-16, 1.43669784789342e-12, 1.09317110675672e-07]])


def _rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def _edge_tensors() -> list[np.ndarray]:
    """Tensors on both sides of A + B = C, turned and not, with two moments far apart or coinciding."""
    out = [PULLER]
    for seed, (a, b, gap) in enumerate([(0.2, 0.3, 0.0), (0.2, 0.3, 1e-15), (0.2, 0.3, -1e-15),
                                        (0.2, 0.3, 1e-10), (0.2, 0.3, -1e-10), (1e-15, 1e-7, 0.0),
                                        (1e-15, 1e-7, 5e-16), (1e-15, 1e-7, -5e-16), (0.0, 1.0, 0.0),
                                        (0.0, 1.0, -1e-12)]):
        moments = np.diag([a, b, a + b - gap])
        out.append(moments)
        turned = _rotation(seed) @ moments @ _rotation(seed).T
        out.append(as_written(turned))
    rng = np.random.default_rng(7)
    for seed in range(100, 130):  # the puller's kind: one tiny moment, two nearly equal
        b = 10.0 ** rng.uniform(-8, 0)
        a = b * 10.0 ** rng.uniform(-9, -6)
        moments = np.diag([a, b, a + b - a * rng.uniform(-3.0, 3.0)])
        out.append(as_written(_rotation(seed) @ moments @ _rotation(seed).T))
    return out


def _sdf(tensor: np.ndarray) -> str:
    keys = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
    values = "".join(f"<{k}>{float(tensor[i, j])!r}</{k}>" for k, (i, j) in keys.items())
    return (f'<sdf version="1.9"><model name="m"><link name="l"><inertial><mass>1</mass>'
            f"<inertia>{values}</inertia></inertial></link></model></sdf>")


def test_the_emulation_agrees_with_libsdformat(sdf_oracle: Path, tmp_path: Path) -> None:  # noqa: F811
    verdicts = []
    for index, tensor in enumerate(_edge_tensors()):
        path = tmp_path / f"t{index}.sdf"
        path.write_text(_sdf(tensor))
        accepted = not oracle_has_errors(sdf_oracle, path)
        assert libsdformat_accepts(tensor) == accepted, (index, tensor)
        verdicts.append(accepted)
    assert verdicts.count(True) >= 10 and verdicts.count(False) >= 10  # both sides of the edge, often


def test_the_puller_was_refused_and_its_repair_is_accepted(sdf_oracle: Path, tmp_path: Path) -> None:  # noqa: F811
    assert not libsdformat_accepts(as_written(PULLER))
    numpy_moments = np.linalg.eigvalsh(PULLER)
    assert numpy_moments[0] + numpy_moments[1] < numpy_moments[2]  # the source breaks A + B ≥ C by 5e-23
    repaired, moments, fixed = sdformat_valid_inertia(PULLER)
    assert not np.array_equal(moments, fixed)
    path = tmp_path / "repaired.sdf"
    path.write_text(_sdf(as_written(repaired)))
    assert not oracle_has_errors(sdf_oracle, path)
    assert np.max(np.abs(repaired - PULLER)) < 1e-14  # kg·m²: on a 3 g part, nothing a simulation sees


ACCEPTED = [np.diag([0.2, 0.3, 0.4]), np.diag([0.0, 1.0, 1.0])]


@pytest.mark.parametrize("tensor", ACCEPTED, ids=["box", "rod"])
def test_a_tensor_libsdformat_accepts_is_written_as_it_is(tensor: np.ndarray) -> None:
    written, moments, fixed = sdformat_valid_inertia(tensor)
    assert np.array_equal(written, tensor) and np.array_equal(moments, fixed)


URDF = """<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="puller"><inertial><mass value="0.00292784355893436"/>
    <inertia ixx="1.09317111513898E-07" ixy="-9.31929125413026E-13" ixz="-3.36065188387015E-16"
             iyy="1.10835075609816E-15" iyz="1.43669784789342E-12" izz="1.09317110675672E-07"/>
  </inertial></link>
  <joint name="j" type="prismatic"><parent link="base"/><child link="puller"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.1" effort="10" velocity="1"/></joint>
</robot>
"""


def test_convert_writes_an_sdf_libsdformat_loads(sdf_oracle: Path, tmp_path: Path) -> None:  # noqa: F811
    source = tmp_path / "r.urdf"
    source.write_text(URDF)
    out = tmp_path / "out" / "r.sdf"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert 'MK860 link "puller"' in result.output
    assert not oracle_has_errors(sdf_oracle, out)
