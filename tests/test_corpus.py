"""Every .body file of the shared corpus: loads, gives the right tree, and only true errors."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from modelkit.api import validate
from modelkit.tree import tree_report

from .conftest import CORPUS, corpus_bodies

# The only error-level finding in the corpus, a real fault:
# - mobile_robot_mesh.body: the chassis mesh vmega_body.dae is absent from the snapshot, and this model
#   uses it as collision geometry too (the other tutorial models use it as visual only: a warning).
EXPECTED_ERRORS = {
    ("choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_mesh.body", "MK500", 20, 14),
}
# ellipsoid1.body: its free-floating BASE has principal moments 0.004, 0.015, 0.1 (0.004 + 0.015 < 0.1), an
# inertia no rigid body can have. Choreonoid loads it, MuJoCo and libsdformat refuse it: a warning naming
# them, an error when the file is judged for MuJoCo (--target mjcf).
IMPOSSIBLE_INERTIA = ("choreonoid/share/model/misc/ellipsoid1.body", "MK303", 11, 14)


def test_corpus_errors_are_exactly_the_true_ones(corpus: Path) -> None:
    found = set()
    for path in corpus_bodies():
        for d in validate(path).errors:
            assert d.location is not None
            found.add((str(path.relative_to(corpus)), d.code, d.location.line, d.location.col))
    assert found == EXPECTED_ERRORS


def test_impossible_inertia_is_a_warning_unless_judged_for_mujoco(corpus: Path) -> None:
    name, code, line, col = IMPOSSIBLE_INERTIA
    for target, severity in ((None, "warning"), ("urdf", "warning"), ("mjcf", "error"), ("sdf", "error")):
        found = [
            (d.severity.value, d.location.line, d.location.col)
            for d in validate(corpus / name, target=target).diagnostics
            if d.code == code and d.location is not None
        ]
        assert found == [(severity, line, col)], target
    (d,) = [d for d in validate(corpus / name).diagnostics if d.code == code]
    assert "MuJoCo and libsdformat" in d.message and "Choreonoid" in d.message


def test_missing_visual_meshes_are_warnings_at_the_uri_line(corpus: Path) -> None:
    for name in (
        "mobile_robot",
        "mobile_robot_sensors",
        "mobile_robot_sensors_ex",
        "mobile_robot_tracks",
        "mobile_robot_pantilt",
    ):
        path = corpus / "choreonoid_ros2_mobile_robot_tutorial" / "model" / f"{name}.body"
        missing = [d for d in validate(path).diagnostics if d.code == "MK500"]
        assert len(missing) == 1
        (d,) = missing
        assert d.severity.value == "warning" and "vmega_body.dae" in d.message
        line = path.read_text().splitlines()[d.location.line - 1]  # type: ignore[union-attr]
        assert line.strip() == 'uri: "../meshes/vmega_body.dae"'


def _plain_tree(path: Path) -> str:
    """An independent tree: straight from the YAML `parent` keys, without modelkit's reader."""
    doc = yaml.load(path.read_text(), Loader=yaml.CSafeLoader)
    links = [n for n in doc["links"] if n.get("type", "Link") == "Link"]
    root = doc.get("root_link", doc.get("rootLink", links[0]["name"]))
    kids: dict[str, list[tuple[str, str]]] = {}
    for node in links:
        if node["name"] != root:
            kids.setdefault(node["parent"], []).append((node.get("joint_name", node["name"]), node["name"]))
    lines = [
        f"robot name is: {doc.get('name', path.stem)}",
        "---------- Successfully Parsed XML ---------------",
        f"root Link: {root} has {len(kids.get(root, []))} child(ren)",
    ]

    def walk(link: str, level: int) -> None:
        level += 2
        for i, (_, child) in enumerate(sorted(kids.get(link, []), key=lambda jc: jc[0].encode()), 1):
            lines.append(f"{'  ' * level}child({i}):  {child}")
            walk(child, level)

    walk(root, 0)
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("path", corpus_bodies(), ids=lambda p: p.name)
def test_corpus_tree_matches_independent_reading(path: Path) -> None:
    v = validate(path)
    assert v.robot is not None
    assert tree_report(v.robot) == _plain_tree(path)


def test_corpus_is_present(corpus: Path) -> None:
    """The corpus the parametrised tests above run over is there (CI fails without it)."""
    assert corpus == CORPUS
    assert len(corpus_bodies()) >= 19
