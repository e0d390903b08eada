"""`modelkit tree` on URDF input is byte-identical to Debian's check_urdf (run as an oracle).

The corpus files (urdf_tutorial 01-07 and the Choreonoid tutorial's hand-written URDF) and URDFs
generated here for the tricky parts of check_urdf's layout: children ordered by joint name in byte
order rather than document order, a 300-link chain, a link with two parents under one root (printed
twice), non-ASCII names, a single link, and a "world" root. The verdicts are compared too: a file
check_urdf refuses is never accepted by `modelkit validate`.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main

from .conftest import CORPUS, require_tool

CORPUS_URDFS = [
    *sorted((CORPUS / "urdf_tutorial" / "urdf").glob("0[1-7]*.urdf")),
    CORPUS / "choreonoid_ros2_mobile_robot_tutorial" / "model" / "mobile_robot_sensors.urdf",
]
BROKEN = Path(__file__).resolve().parent / "broken_urdf"


def check_urdf(path: Path) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run([require_tool("check_urdf"), str(path)], capture_output=True, timeout=120)


def modelkit_tree(path: Path) -> tuple[int, bytes]:
    result = CliRunner().invoke(main, ["tree", str(path)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stdout_bytes


def assert_same_tree(path: Path, exit_code: int = 0) -> None:
    oracle = check_urdf(path)
    assert oracle.returncode == 0, oracle.stderr.decode()
    code, out = modelkit_tree(path)
    assert code == exit_code
    assert out == oracle.stdout, f"modelkit:\n{out.decode()}\ncheck_urdf:\n{oracle.stdout.decode()}"


@pytest.mark.parametrize("path", CORPUS_URDFS, ids=[p.name for p in CORPUS_URDFS])
def test_corpus_tree_is_byte_identical(path: Path, corpus: Path) -> None:
    assert_same_tree(path)


def _urdf(name: str, links: list[str], joints: list[tuple[str, str, str]], type_: str = "fixed") -> str:
    parts = ['<?xml version="1.0" encoding="utf-8"?>', f'<robot name="{name}">']
    parts += [f'  <link name="{link}"/>' for link in links]
    for joint, parent, child in joints:
        parts.append(
            f'  <joint name="{joint}" type="{type_}"><parent link="{parent}"/><child link="{child}"/></joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


def _chain(n: int) -> str:
    links = [f"l{i}" for i in range(n)]
    joints = [(f"j{i:03d}", f"l{i - 1}", f"l{i}") for i in range(1, n)]
    return _urdf("chain", links, joints)


GENERATED = {
    # joint names sort differently from the document order, and from the child names
    "joint_name_order": _urdf(
        "order",
        ["base", "zeta", "mid", "alpha", "leaf"],
        [
            ("b_joint", "base", "zeta"),
            ("a_joint", "base", "mid"),
            ("c_joint", "base", "alpha"),
            ("0_joint", "mid", "leaf"),
        ],
    ),
    # byte order: upper case before lower case, "_" between them, digits first
    "byte_order": _urdf(
        "bytes",
        ["root", "x1", "x2", "x3", "x4"],
        [("b", "root", "x1"), ("B", "root", "x2"), ("_", "root", "x3"), ("1", "root", "x4")],
    ),
    "deep_chain_300": _chain(300),
    # c hangs below a and below b, which share the root a: check_urdf prints c twice
    "two_parents_one_root": _urdf(
        "two_parents", ["a", "b", "c"], [("j1", "a", "b"), ("j2", "a", "c"), ("j3", "b", "c")]
    ),
    "unicode_names": _urdf(
        "ロボット",
        ["ベース", "腕", "Ärm", "épaule"],
        [("関節", "ベース", "腕"), ("Ägelenk", "ベース", "Ärm"), ("épaule_j", "腕", "épaule")],
    ),
    "single_link": _urdf("only", ["only"], []),
    "world_root": _urdf("welded", ["world", "base", "arm"], [("fix", "world", "base"), ("j", "base", "arm")]),
    "wide_tree": _urdf(
        "wide",
        ["hub", *[f"spoke{i}" for i in range(12)]],
        [(f"j{i}", "hub", f"spoke{i}") for i in range(12)],
        type_="floating",
    ),
}


@pytest.mark.parametrize("name", sorted(GENERATED))
def test_generated_tree_is_byte_identical(name: str, tmp_path: Path) -> None:
    path = tmp_path / f"{name}.urdf"
    path.write_text(GENERATED[name], encoding="utf-8")
    # a second parent is an error (MK220): the same bytes are printed, but tree exits 1 with the code
    assert_same_tree(path, 1 if name == "two_parents_one_root" else 0)


def test_two_parents_tree_prints_the_child_twice_and_validate_refuses(tmp_path: Path) -> None:
    """check_urdf passes a link with two parents under one root; the tree matches, the verdict does not."""
    path = tmp_path / "two_parents.urdf"
    path.write_text(GENERATED["two_parents_one_root"], encoding="utf-8")
    code, out = modelkit_tree(path)
    assert code == 1  # the same tree printed, but a second parent is an error (MK220): tree fails too
    assert out.decode().endswith("    child(1):  b\n        child(1):  c\n    child(2):  c\n")
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert result.exit_code == 1
    assert "MK220" in result.stdout


def test_tree_document_order_differs_from_check_urdf(tmp_path: Path) -> None:
    path = tmp_path / "order.urdf"
    path.write_text(GENERATED["joint_name_order"], encoding="utf-8")
    result = CliRunner().invoke(main, ["tree", "--order", "document", str(path)])
    assert result.exit_code == 0
    lines = [line.strip() for line in result.stdout.splitlines() if line.lstrip().startswith("child(")]
    assert lines == ["child(1):  zeta", "child(2):  mid", "child(1):  leaf", "child(3):  alpha"]


BROKEN_CASES = sorted(p for p in BROKEN.glob("*.urdf"))


@pytest.mark.parametrize("path", BROKEN_CASES, ids=[p.name for p in BROKEN_CASES])
def test_validate_is_never_more_lenient_than_check_urdf(path: Path) -> None:
    """Every broken case check_urdf refuses (exit 255) is an error for `modelkit validate` too."""
    oracle = check_urdf(path)
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert result.exception is None or isinstance(result.exception, SystemExit)
    if oracle.returncode != 0:
        assert result.exit_code == 1, f"check_urdf refuses {path.name}; modelkit exits {result.exit_code}"


def test_clean_base_passes_both(tmp_path: Path) -> None:
    clean = BROKEN / "support" / "clean.urdf"
    assert_same_tree(clean)
    result = CliRunner().invoke(main, ["validate", "--strict", str(clean)])
    assert result.exit_code == 0, result.output


def test_damaged_variants_never_pass_where_check_urdf_fails(tmp_path: Path) -> None:
    """The clean base with each attribute, then each element, removed: check_urdf's refusal ⇒ our error."""
    from .test_urdf_reader import clean_variants

    shutil.copy(BROKEN / "package.xml", tmp_path / "package.xml")
    shutil.copytree(BROKEN / "meshes", tmp_path / "meshes")
    refused = 0
    for i, variant in enumerate(clean_variants()):
        path = tmp_path / f"variant{i}.urdf"
        path.write_text(variant, encoding="utf-8")
        oracle = check_urdf(path)
        if oracle.returncode == 0:
            continue
        refused += 1
        errors = validate(path).errors
        assert errors, f"check_urdf refuses variant {i} ({oracle.stderr.decode()!r}); modelkit passes it"
    assert refused >= 10


def test_cycle_apart_from_the_root_passes_check_urdf_but_not_validate(tmp_path: Path) -> None:
    path = tmp_path / "loop.urdf"
    path.write_text(_urdf("loop", ["a", "p", "q"], [("j1", "p", "q"), ("j2", "q", "p")]), encoding="utf-8")
    assert check_urdf(path).returncode == 0
    assert [d.code for d in validate(path).errors] == ["MK203"]
