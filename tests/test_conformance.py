"""Conformance: on every real model file, modelkit's verdict is the format's own loader's verdict.

For each model file of the shared corpus (``../shared/corpus``, which grows: every file found is
checked), of ``samples/`` and of pybullet's bundled models (``pybullet_data``: URDF, SDF and MJCF robots
and objects that PyBullet users load; of its 1,000 generated ``random_urdfs`` only the first), the
reference loader runs live here and ``modelkit.api.validate`` runs with the same search paths; the
verdicts must agree (the loader accepts the file <=> modelkit reports no error). The references:

- URDF: Debian's ``check_urdf`` (urdfdom);
- xacro: the ``xacro`` package expands the file, ``check_urdf`` judges the expansion. A file whose
  expansion has no ``<link>`` is a library for other xacro files (materials, macros, Gazebo blocks):
  check_urdf refuses any file without links, so for those modelkit must instead say MK710 (checked
  for xacro errors only) and report no error;
- SDF and Gazebo worlds: libsdformat 12 through the checker compiled in ``test_sdf_reader`` (``Root::Load``
  plus the graph and name checks of ``gz sdf -k``), with ``SDF_PATH`` set as libsdformat's tests set it: the
  model folders next to the file (a ``models/`` folder beside it, or the folder holding its own model folder);
- MJCF: MuJoCo's compiler (``mujoco.MjModel.from_xml_path``);
- Choreonoid ``.body``: no loader runs here; :data:`BODY_VERDICTS` gives Choreonoid's verdict for each
  file with the rule of ``../shared/docs/body-format.md`` it follows. A new .body file in the corpus
  fails the test until it is given a verdict there.

A disagreement is either fixed or listed in :data:`EXCEPTIONS` with its reason; an exception that no
longer disagrees fails the test too, so that the table stays exact.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

from modelkit.api import Validation, validate
from modelkit.diagnostics import Diagnostic
from modelkit.formats.common import ReadOptions
from modelkit.formats.xacro.reader import expand_xacro
from modelkit.model import Mesh
from modelkit.resources import Resolver
from modelkit.textio import read_head

from .conftest import CORPUS, REPO, SAMPLES, TUTORIAL, assert_pybullet_refuses, require_tool
from .test_sdf_reader import sdf_oracle  # noqa: F401  (the compiled libsdformat checker, a fixture)

KINDS = {".urdf": "urdf", ".xacro": "xacro", ".sdf": "sdf", ".world": "sdf", ".body": "body"}

# Choreonoid's verdict on each .body file as it is on disk, with the body-format.md rule it follows.
_ACCEPTS = "a valid Choreonoid body (§1 top-level keys, §2 links, §3 elements all as documented)"
_MISSING_MESH = (
    "refused: the mesh ../meshes/vmega_body.dae is absent from the snapshot, and a Resource whose file "
    'is missing throws "The resource is not found at URI" (§3.6)'
)
BODY_VERDICTS: dict[str, tuple[bool, str]] = {
    "corpus/choreonoid/share/model/GR001/GR001.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/PA10/PA10.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/Robotiq/2F-85.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/SR1/SR1.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/ClosedLinkSample.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/SpringModel.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/box.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/ellipsoid1.body": (
        True,
        "accepted: the inertia is used as given (§2.7 checks neither symmetry nor the triangle inequality)",
    ),
    "corpus/choreonoid/share/model/misc/floor.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/pendulum.body": (True, _ACCEPTS),
    "corpus/choreonoid/share/model/misc/slope.body": (True, _ACCEPTS),
    "corpus/irsl_choreonoid/sample/closed_link_ik.body": (True, _ACCEPTS),
}
for _top in ("corpus/choreonoid_ros2_mobile_robot_tutorial", "samples/choreonoid_ros2_mobile_robot_tutorial"):
    for _name in ("mobile_robot_primitive", "terrain"):
        BODY_VERDICTS[f"{_top}/model/{_name}.body"] = (True, _ACCEPTS)
    for _name in (
        "mobile_robot",
        "mobile_robot_mesh",
        "mobile_robot_pantilt",
        "mobile_robot_sensors",
        "mobile_robot_sensors_ex",
        "mobile_robot_tracks",
    ):
        BODY_VERDICTS[f"{_top}/model/{_name}.body"] = (False, _MISSING_MESH)

_VISUAL_MESH_ABSENT = (
    "project policy (corpus README): a missing mesh used only as visual geometry is a warning so that "
    "the rest can still be converted and simulated; Choreonoid throws on any missing Resource"
)
_LIBSDFORMAT_12_IS_OLD = (
    "SDFormat 1.11: libsdformat 12 reads up to 1.9 and refuses it (\"Unable to convert from SDF version "
    '1.11 to 1.9"); current libsdformat reads it and so does modelkit'
)
_FUEL = (
    "its <include> names a Gazebo Fuel model by https:// URI: Gazebo downloads it when it loads the world; "
    "the checker has no Fuel callback (libsdformat: \"Unable to find uri\"); modelkit reports an info "
    "(MK503) and checks the rest (issue 9 §1)"
)
# Files on which modelkit and the reference loader disagree on purpose or for a known, stated reason.
EXCEPTIONS: dict[str, str] = {
    **{
        f"{top}/choreonoid_ros2_mobile_robot_tutorial/model/{name}.body": _VISUAL_MESH_ABSENT
        for top in ("corpus", "samples")
        for name in (
            "mobile_robot",
            "mobile_robot_pantilt",
            "mobile_robot_sensors",
            "mobile_robot_sensors_ex",
            "mobile_robot_tracks",
        )
    },
    **{
        f"corpus/gz_sim_worlds/examples/worlds/{name}.sdf": _FUEL
        for name in (
            "actor", "camera_sensor", "elevator", "fuel", "gpu_lidar_sensor", "heightmap", "quadcopter"
        )
    },
    "corpus/gz_sim_worlds/examples/worlds/auto_inertia_pendulum.sdf": _LIBSDFORMAT_12_IS_OLD,
    "corpus/gz_sim_worlds/examples/worlds/mimic_fast_slow_pendulums_world.sdf": _LIBSDFORMAT_12_IS_OLD,
    "corpus/gz_sim_worlds/examples/worlds/shapes.sdf": _LIBSDFORMAT_12_IS_OLD,
}


def _pybullet_data() -> Path | None:
    """pybullet's bundled models (robots and objects users load in PyBullet), when pybullet is installed."""
    try:
        import pybullet_data
    except ImportError:  # pragma: no cover - pybullet is in the test environment
        return None
    return Path(pybullet_data.getDataPath())


PYBULLET_DATA = _pybullet_data()
ROOTS = (("corpus", CORPUS), ("samples", SAMPLES), ("pybullet_data", PYBULLET_DATA))


def _kind(path: Path) -> str | None:
    if path.suffix in KINDS:
        return KINDS[path.suffix]
    if path.suffix == ".xml":
        head = read_head(path, 4096) or b""
        return "mjcf" if re.search(rb"<mujoco[\s>]", head) else None
    return None


def model_files() -> list[tuple[str, Path]]:
    """Every model file of the corpus, the samples and pybullet_data, keyed corpus/..., samples/... or
    pybullet_data/..."""
    found = []
    for label, root in ROOTS:
        if root is None or not root.is_dir():
            continue
        for path in sorted(root.rglob("*")):
            if label == "pybullet_data" and "random_urdfs" in path.parts and path.parent.name != "000":
                continue  # 1,000 generated objects of one shape: the first stands for them
            if path.is_file() and _kind(path) is not None:
                found.append((f"{label}/{path.relative_to(root)}", path))
    return found


FILES = model_files()


def sdf_path(path: Path) -> str:
    """SDF_PATH as libsdformat's tests set it: the model folders next to the file."""
    folders = []
    if (path.parent / "models").is_dir():
        folders.append(path.parent / "models")
    if (path.parent / "model.config").is_file():
        folders.append(path.parent.parent)
    return os.pathsep.join(str(f) for f in folders)


def environment(kind: str, path: Path) -> dict[str, str]:
    env = dict(os.environ)
    if kind == "sdf":
        env["SDF_PATH"] = sdf_path(path)
    return env


def check_urdf_accepts(text_path: Path) -> tuple[bool, str]:
    run = subprocess.run([require_tool("check_urdf"), str(text_path)], capture_output=True, timeout=120)
    return run.returncode == 0, run.stderr.decode(errors="replace")[-400:]


def reference(kind: str, path: Path, oracle: Path, scratch: Path) -> tuple[bool | None, str]:
    """The reference loader's verdict (None: the file is not a robot on its own) and its words."""
    if kind == "urdf":
        return check_urdf_accepts(path)
    if kind == "xacro":
        text, findings = expand_xacro(path)
        if text is None:
            return False, f"xacro cannot expand it: {[d.code for d in findings]}"
        if not re.search(r"<link[\s>/]", text):
            return None, "a library for other xacro files: no <link> in the expansion"
        expanded = scratch / (path.stem + ".urdf")
        expanded.write_text(text, encoding="utf-8")
        return check_urdf_accepts(expanded)
    if kind == "sdf":
        run = subprocess.run(
            [str(oracle), str(path)],
            cwd=path.parent,
            env=environment(kind, path),
            capture_output=True,
            text=True,
            timeout=60,
        )
        said = run.stdout + run.stderr
        return run.returncode == 0 and re.search(r"Error \[|Error:", said) is None, said[-400:]
    if kind == "mjcf":
        try:
            mujoco.MjModel.from_xml_path(str(path))
        except ValueError as exc:
            return False, str(exc)[:400]
        return True, ""
    verdict, reason = BODY_VERDICTS[_key(path)]
    return verdict, reason


def _key(path: Path) -> str:
    for label, root in ROOTS:
        if root is not None and path.is_relative_to(root):
            return f"{label}/{path.relative_to(root)}"
    raise AssertionError(path)


def ours(kind: str, path: Path) -> Validation:
    options = ReadOptions(resolver=Resolver(environ=environment(kind, path)))
    return validate(path, options)


@pytest.mark.parametrize(("key", "path"), FILES, ids=[key for key, _ in FILES])
def test_verdict_agrees_with_the_reference_loader(
    key: str, path: Path, sdf_oracle: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch  # noqa: F811
) -> None:
    kind = _kind(path)
    assert kind is not None
    monkeypatch.chdir(tmp_path)  # MuJoCo writes MUJOCO_LOG.TXT into the working folder when it refuses
    theirs, said = reference(kind, path, sdf_oracle, tmp_path)
    v = ours(kind, path)
    errors = sorted(f"{d.code} {d.location}: {d.message}" for d in v.errors)
    if theirs is None:
        assert not errors and "MK710" in {d.code for d in v.diagnostics}, errors
        return
    agree = theirs == (not errors)
    if key in EXCEPTIONS:
        assert not agree, f"{key} now agrees with the reference: remove it from EXCEPTIONS"
        return
    assert agree, (
        f"reference {'accepts' if theirs else 'refuses'} ({said.strip()[-300:]}); "
        f"modelkit: {errors or 'no error'}"
    )


def test_tables_name_real_files() -> None:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not available")
    keys = {key for key, _ in FILES}
    assert set(BODY_VERDICTS) == {key for key, path in FILES if path.suffix == ".body"}
    assert set(EXCEPTIONS) <= keys, set(EXCEPTIONS) - keys


def test_every_format_is_covered() -> None:
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not available")
    kinds = {_kind(path) for _, path in FILES}
    assert kinds == {"urdf", "xacro", "sdf", "mjcf", "body"}
    assert shutil.which("check_urdf") or not os.environ.get("MODELKIT_REQUIRE_ORACLES")
    assert REPO.is_dir()


# ---- generated real-looking cases for the classes the corpus holds few of ----------------------------

_BOX_MODEL = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="{name}">
    <link name="base">
      <inertial><mass>1</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
    </link>
  </model>
</sdf>
"""


def _model_folder(root: Path, name: str) -> None:
    folder = root / name
    folder.mkdir(parents=True)
    (folder / "model.config").write_text(
        f'<?xml version="1.0"?><model><name>{name}</name><sdf version="1.7">model.sdf</sdf></model>'
    )
    (folder / "model.sdf").write_text(_BOX_MODEL.format(name=name))


def _world(tmp_path: Path, uris: list[str]) -> Path:
    includes = "".join(f"<include><uri>{u}</uri><name>m{i}</name></include>\n" for i, u in enumerate(uris))
    path = tmp_path / "world" / "w.sdf"
    path.parent.mkdir()
    path.write_text(
        f'<?xml version="1.0"?>\n<!-- run with -- gz sim w.sdf -->\n<sdf version="1.7"><world name="w">\n'
        f"{includes}</world></sdf>\n"
    )
    return path


def test_includes_are_looked_up_on_the_model_path(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    from click.testing import CliRunner

    from modelkit.cli import main

    _model_folder(tmp_path / "models", "crate")
    world = _world(tmp_path, ["crate", "model://crate", "file://crate"])
    models = str(tmp_path / "models")
    for var in ("SDF_PATH", "GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "GAZEBO_MODEL_PATH"):
        env = {k: v for k, v in os.environ.items() if not k.endswith(("_PATH", "RESOURCE_PATH"))}
        v = validate(world, ReadOptions(resolver=Resolver(environ={**env, var: models})))
        assert v.errors == [], (var, v.errors)
        assert len(v.robots) == 3
    # libsdformat agrees when SDF_PATH names the folder
    run = subprocess.run(
        [str(sdf_oracle), str(world)], env={**os.environ, "SDF_PATH": models}, capture_output=True, text=True
    )
    assert run.returncode == 0 and "Error" not in run.stdout + run.stderr, run.stdout + run.stderr
    # without the path: MK500 saying where to give it; with --resource-path: found
    model_vars = ("SDF_PATH", "GAZEBO_MODEL_PATH")
    bare = {k: v for k, v in os.environ.items() if "RESOURCE_PATH" not in k and k not in model_vars}
    missing = validate(world, ReadOptions(resolver=Resolver(environ=bare)))
    assert {d.code for d in missing.errors} == {"MK500", "MK504"}
    assert any("--resource-path" in (d.hint or "") for d in missing.errors)
    runner = CliRunner(env={k: None for k in os.environ if k not in bare})
    assert runner.invoke(main, ["validate", str(world)]).exit_code == 1
    found = runner.invoke(main, ["validate", "--resource-path", models, str(world)])
    assert found.exit_code == 0, found.output


def test_fuel_includes_are_an_info_and_the_rest_is_checked(tmp_path: Path) -> None:
    _model_folder(tmp_path / "models", "crate")
    fuel = "https://fuel.gazebosim.org/1.0/OpenRobotics/models/Construction Cone"
    world = _world(tmp_path, [fuel, "crate"])
    v = validate(world, ReadOptions(resolver=Resolver(resource_paths=[tmp_path / "models"])))
    assert v.errors == [], v.errors
    assert [d.code for d in v.warnings] == ["MK020"]  # the "--" in its comment
    assert [r.name for r in v.robots] == ["m1"]  # the local include is read and checked
    (d,) = [d for d in v.diagnostics if d.code == "MK503"]
    assert d.severity.value == "info" and "Fuel" in d.message
    assert d.location is not None and d.location.line == 4


def test_double_hyphen_in_a_comment_is_a_warning_as_tinyxml2_accepts_it(tmp_path: Path) -> None:
    path = tmp_path / "m.sdf"
    comment = "<!-- usage: gz sdf --check m.sdf --> \n<sdf"
    path.write_text(_BOX_MODEL.format(name="m").replace("<sdf", comment, 1))
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == "MK020"]
    assert d.severity.value == "warning" and d.location is not None and d.location.line == 2
    path.write_text(_BOX_MODEL.format(name="m").replace("</sdf>", "<bad></sdf>"))
    assert [d.code for d in validate(path).errors] == ["MK020"]  # real malformations stay errors


@pytest.mark.parametrize(
    ("head", "line", "said"),
    [
        ('<?xml version="0.0" ?>\n', 1, 'names version "0.0"'),  # 26 of pybullet_data's robots
        ('\n<?xml version="1.0" ?>\n', 2, "not at the start"),
    ],
    ids=["version 0.0", "whitespace before it"],
)
def test_xml_declaration_as_tinyxml2_reads_it(tmp_path: Path, head: str, line: int, said: str) -> None:
    """libxml2 refuses these declarations; urdfdom, libsdformat, MuJoCo, PyBullet (TinyXML2) ignore them."""
    path = tmp_path / "r.urdf"
    path.write_text(head + _TRIANGLE_URDF.split("\n", 1)[1])
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == "MK020"]
    assert d.severity.value == "warning" and said in d.message
    assert d.location is not None and (d.location.line, d.location.col) == (line, 1)
    assert [r.name for r in v.robots] == ["r"] and len(v.robots[0].links) == 2
    path.write_text(head + _TRIANGLE_URDF.split("\n", 1)[1].replace("</robot>", "<bad></robot>"))
    assert [d.code for d in validate(path).errors] == ["MK020"]  # a real malformation stays an error


def _read_past_as_tinyxml2(path: Path, kind: str, oracle: Path, said: str) -> tuple[Validation, Diagnostic]:
    """The file's own loader accepts ``path``; validate reads it with no error and one MK020 warning that
    says ``said`` (what TinyXML2 read past)."""
    accepted, words = reference(kind, path, oracle, path.parent)
    assert accepted, words
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == "MK020"]
    assert d.severity.value == "warning" and said in d.message
    return v, d


_MJCF_BALL = ('<mujoco model="m">\n'
              '  <worldbody><body name="b"><freejoint/><geom size="0.1"/></body></worldbody>\n'
              "</mujoco>")
#: what follows the root element's end tag (each of them TinyXML2 reads past and libxml2 refuses), and the
#: column of the line after the root where libxml2 stops (a comment there is XML)
_AFTER_ROOT = {
    "end tag again": ("\n</{root}>\n", 1),  # PyFlyt 0.29's rocket.urdf
    "another end tag": ("\n</foo>\n", 1),
    "a second root": ('\n<{root} name="b"><x/></{root}>\n', 1),
    "an element and a comment": ("\n<!-- c --><junk a='1'/>\n", 11),
    "an end tag, then anything": ("\n</{root}>\ngarbage <b>\n", 1),  # TinyXML2 stops at the end tag
}


@pytest.mark.parametrize("tail", list(_AFTER_ROOT), ids=list(_AFTER_ROOT))
@pytest.mark.parametrize("kind", ["urdf", "mjcf", "sdf"])
def test_markup_after_the_root_element_is_a_warning_as_tinyxml2_reads_it(
    tmp_path: Path, sdf_oracle: Path, kind: str, tail: str  # noqa: F811
) -> None:
    """TinyXML2 (urdfdom, MuJoCo, libsdformat, PyBullet) reads the root element and ignores end tags,
    elements and comments after it; libxml2 refuses the file. PyFlyt's rocket ends with ``</robot>``
    twice. The file's own loader accepts each, so validate warns where it goes on, and reads the robot."""
    model, root, suffix = {"urdf": (_TRIANGLE_URDF, "robot", "urdf"), "mjcf": (_MJCF_BALL, "mujoco", "xml"),
                           "sdf": (_BOX_MODEL.format(name="m"), "sdf", "sdf")}[kind]
    path = tmp_path / f"m.{suffix}"
    after, column = _AFTER_ROOT[tail]
    text = model.rstrip("\n") + after.format(root=root)
    path.write_text(text)
    v, d = _read_past_as_tinyxml2(path, kind, sdf_oracle, "after its root element ends")
    after_root = model.rstrip("\n").count("\n") + 2
    assert d.location is not None and (d.location.line, d.location.col) == (after_root, column)
    assert v.robot is not None and v.robot.name in ("r", "m")
    if kind == "urdf":
        import pybullet

        client = pybullet.connect(pybullet.DIRECT)
        try:
            assert pybullet.loadURDF(str(path), physicsClientId=client) >= 0
        finally:
            pybullet.disconnect(client)


#: text after a URDF's root element, before any stray end tag (TinyXML2 stops at one: _AFTER_ROOT)
_TEXT_AFTER_ROOT = {
    "text": "\ngarbage\n",
    "text with markup characters": "\na < b & c\n",
    "a comment then text": "\n<!-- c --> &amp; x\n",
    "text then an open element": "\ntext <b>\n",
    "a comment never closed": "\n<!-- never closed\n",
    "an element then a comment never closed": "\n<x/>\n<!-- never closed",
    "a comment never closed holding another's start": "\n<!-- a <!-- b\n",
}


@pytest.mark.parametrize("tail", list(_TEXT_AFTER_ROOT), ids=list(_TEXT_AFTER_ROOT))
def test_text_after_a_urdf_root_is_mk027_as_urdfdom_reads_it(tmp_path: Path, tail: str) -> None:
    """urdfdom (TinyXML 1, check_urdf) stops at text after the root element and ignores the rest;
    MuJoCo and PyBullet (TinyXML2) refuse the file. So it is a warning (MK027) and an error under their
    targets."""
    path = tmp_path / "m.urdf"
    path.write_text(_TRIANGLE_URDF.rstrip("\n") + _TEXT_AFTER_ROOT[tail])
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == [] and v.robot is not None and v.robot.name == "r"
    (d,) = [d for d in v.diagnostics if d.code in ("MK020", "MK027")]
    assert d.code == "MK027" and d.severity.value == "warning" and "urdfdom" in d.message
    assert d.location is not None and d.location.line == _TRIANGLE_URDF.rstrip("\n").count("\n") + 2
    clean = tmp_path / "clean.urdf"
    clean.write_text(_TRIANGLE_URDF)
    located = [(d.code, d.location.line, d.location.col) for d in validate(clean).diagnostics if d.location]
    assert [(d.code, d.location.line, d.location.col) for d in v.diagnostics
            if d.location and d.code != "MK027"] == located  # every element where it is, columns too
    with pytest.raises(ValueError, match="XML parse error"):
        mujoco.MjModel.from_xml_path(str(path))
    assert_pybullet_refuses(path)
    for target in ("mjcf", "pybullet"):  # the clean file's errors (MK303) and MK027
        before = sorted(d.code for d in validate(clean, target=target).errors)
        assert sorted(d.code for d in validate(path, target=target).errors) == sorted([*before, "MK027"])
    assert validate(path, target="urdf").errors == []


def test_a_comment_never_closed_inside_a_urdf_root_stays_an_error(tmp_path: Path) -> None:
    """urdfdom's TinyXML reads a comment never closed to the end of the file: inside the root element
    its end tag is then missing, and check_urdf refuses the file, as validate does."""
    path = tmp_path / "m.urdf"
    path.write_text(_TRIANGLE_URDF.replace("</robot>", "<!-- never closed\n</robot>"))
    assert not check_urdf_accepts(path)[0]
    assert [d.code for d in validate(path).diagnostics if d.code in ("MK020", "MK027")] == ["MK020"]
    path.write_text(_TRIANGLE_URDF.replace("</robot>", "<!-- a -- b\n</robot>"))  # "--" in it
    assert not check_urdf_accepts(path)[0]
    assert [d.severity.value for d in validate(path).diagnostics if d.code == "MK020"][-1] == "error"


@pytest.mark.parametrize("tail", ["\n<b> text\n", "\n</x> <b>\n"])
def test_an_open_element_after_a_urdf_root_stays_an_error(tmp_path: Path, tail: str) -> None:
    """An element left open before any text: urdfdom's TinyXML refuses it, also after a stray end tag
    (where TinyXML2, which stops there, would read the file)."""
    path = tmp_path / "m.urdf"
    path.write_text(_TRIANGLE_URDF.rstrip("\n") + tail)
    assert not check_urdf_accepts(path)[0]
    assert [d.code for d in validate(path).errors] == ["MK020"]


@pytest.mark.parametrize("kind", ["mjcf", "sdf"])
def test_text_after_the_root_element_stays_an_error(tmp_path: Path, sdf_oracle: Path, kind: str) -> None:  # noqa: F811
    """Text outside any element after the root: MuJoCo and libsdformat refuse it (TinyXML2's
    XML_ERROR_PARSING_TEXT), and so does validate; so do unfinished tags."""
    model, suffix = {"mjcf": (_MJCF_BALL, "xml"), "sdf": (_BOX_MODEL.format(name="m"), "sdf")}[kind]
    path = tmp_path / f"m.{suffix}"
    for tail in ("\ngarbage\n", "\n<!-- c -->\n&amp;\n", "\n<x\n"):
        path.write_text(model.rstrip("\n") + tail)
        if tail != "\n<x\n":
            assert reference(kind, path, sdf_oracle, tmp_path)[0] is False
        assert [d.code for d in validate(path).errors] == ["MK020"], tail


def test_an_undeclared_namespace_prefix_in_a_urdf_is_a_warning_as_tinyxml2_reads_it(tmp_path: Path) -> None:
    """airo-models' UR3e/UR5e URDFs carry Drake's ``drake:acceleration`` and
    ``<drake:collision_filter_group>`` without declaring ``xmlns:drake``: urdfdom reads them (TinyXML2
    ignores namespaces), lxml refuses the document. The robot is read, the warning points at the
    first use, and converting it writes a file MuJoCo loads."""
    path = tmp_path / "r.urdf"
    limit = '\n    <limit effort="1" velocity="1" drake:acceleration="2"/>'
    group = ('  <drake:collision_filter_group name="g"><drake:member link="arm"/>'
             '</drake:collision_filter_group>\n')
    text = _TRIANGLE_URDF.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/>' + limit)
    path.write_text(text.replace("</robot>", group + "</robot>"))
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == "MK020"]
    assert d.severity.value == "warning" and "drake:" in d.message and 'xmlns:drake="http' in (d.hint or "")
    assert d.location is not None and (d.location.line, d.location.col) == (8, 36)  # drake:acceleration
    assert [r.name for r in v.robots] == ["r"] and len(v.robots[0].links) == 2
    mujoco = pytest.importorskip("mujoco")
    from modelkit.convert.api import write

    write(v.robots[0], tmp_path / "out" / "r.xml", force=True)
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "r.xml")).joint("j").type == 3  # a hinge
    path.write_text(path.read_text().replace("</robot>", "<bad></robot>"))
    assert [d.code for d in validate(path).errors] == ["MK020"]  # a real malformation stays an error


def test_package_uri_found_beside_the_model_as_pybullet_looks(tmp_path: Path) -> None:
    """``package://NAME/REL`` with no package NAME anywhere: PyBullet reads NAME/REL beside the file."""
    (tmp_path / "arm_description" / "meshes").mkdir(parents=True)
    (tmp_path / "arm_description" / "meshes" / "m.stl").write_text(_TRIANGLE_STL)
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_part(
        '<collision><geometry><mesh filename="package://arm_description/meshes/m.stl"/></geometry></collision>'
    )))
    assert check_urdf_accepts(path)[0]
    _pybullet_reads_it_and_we_warn(path, "MK504", "as PyBullet reads it")
    moved = tmp_path / "robot" / "urdf"  # the package folder above the model, without package.xml
    moved.mkdir(parents=True)
    (moved / "r.urdf").write_text(path.read_text())
    v = validate(moved / "r.urdf")
    assert v.errors == [] and [d.severity.value for d in v.diagnostics if d.code == "MK504"] == ["warning"]
    geometries = [g.geometry for link in v.robots[0].links for g in link.collisions]
    (mesh,) = [g for g in geometries if isinstance(g, Mesh)]
    assert mesh.path == str(tmp_path / "arm_description" / "meshes" / "m.stl")
    (tmp_path / "arm_description" / "meshes" / "m.stl").unlink()
    _missing_collision_mesh(path, "MK504")


def test_bare_package_uri_of_a_file_beside_the_model_as_pybullet_looks(tmp_path: Path) -> None:
    """``package://wheel.obj`` (Genesis's wheel assets): no package, only a file name, which PyBullet finds
    beside the URDF and loads; without the file PyBullet refuses the URDF and so do we."""
    (tmp_path / "wheel.stl").write_text(_TRIANGLE_STL)
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_part('<collision><geometry><mesh filename="package://wheel.stl"/></geometry></collision>')))
    assert check_urdf_accepts(path)[0]
    _pybullet_reads_it_and_we_warn(path, "MK504", "names no package, only a file")
    (mesh,) = [g.geometry for link in validate(path).robots[0].links for g in link.collisions]
    assert isinstance(mesh, Mesh) and mesh.path == str(tmp_path / "wheel.stl")
    (tmp_path / "wheel.stl").unlink()
    command = [sys.executable, "-c", _PYBULLET_LOADS, str(path)]
    assert subprocess.run(command, capture_output=True, timeout=60).returncode != 0
    _missing_collision_mesh(path, "MK504")


def _missing_collision_mesh(path: Path, code: str) -> None:
    """The collision mesh is nowhere: check_urdf accepts the file (it never opens meshes), so ``code`` is
    a warning that says who refuses it, and an error for ``--target pybullet`` and ``--target mjcf``."""
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == code]
    assert d.severity.value == "warning" and "MuJoCo and PyBullet refuse it" in d.message, d
    for target in ("pybullet", "mjcf"):
        assert [(d.code, d.severity.value) for d in validate(path, target=target).errors] == [(code, "error")]


def _pybullet_reads_it_and_we_warn(path: Path, code: str, said: str) -> None:
    """PyBullet loads the file (live); modelkit reports no error and one ``code`` warning saying ``said``."""
    command = [sys.executable, "-c", _PYBULLET_LOADS, str(path)]
    loads = subprocess.run(command, capture_output=True, timeout=60)
    assert loads.returncode == 0, loads.stderr[-400:]
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.diagnostics if d.code == code]
    assert d.severity.value == "warning" and said in d.message, d


def test_absolute_path_found_under_the_model_folder_as_pybullet_looks(tmp_path: Path) -> None:
    """``/meshes/m.stl`` (as in pybullet's KUKA SDF files): PyBullet reads it under the model's folder."""
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "m.stl").write_text(_TRIANGLE_STL)
    written = "/meshes/m.stl"
    assert not Path(written).exists()
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_part(f'<collision><geometry><mesh filename="{written}"/></geometry></collision>')))
    _pybullet_reads_it_and_we_warn(path, "MK500", "absolute path")
    (tmp_path / "meshes" / "m.stl").unlink()
    _missing_collision_mesh(path, "MK500")


@pytest.mark.parametrize("depth", [1, 2])
def test_relative_mesh_path_found_above_the_model_folder_as_pybullet_looks(tmp_path: Path,
                                                                          depth: int) -> None:
    """``meshes/m.stl`` written in ``robot/urdf/r.urdf`` for ``robot/meshes/m.stl`` (differentiable-robot-
    model's Panda and iiwa): PyBullet tries the path under every folder above the model's and loads it;
    MuJoCo's URDF import does not, and refuses it. modelkit reads the mesh PyBullet reads, warns
    (MK500, with the path to write), and makes it an error for ``--target mjcf`` only when it is a
    collision mesh; ``convert`` copies it and the written MJCF loads."""
    robot = tmp_path / "robot"
    (robot / "meshes").mkdir(parents=True)
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box((0.1, 0.1, 0.1)).export(robot / "meshes" / "m.stl")
    folder = robot.joinpath(*["urdf"] * depth)
    folder.mkdir(parents=True)
    path = folder / "r.urdf"
    shapes = '<geometry><mesh filename="meshes/m.stl"/></geometry>'
    path.write_text(_urdf(_part(f"<visual>{shapes}</visual><collision>{shapes}</collision>")))
    assert check_urdf_accepts(path)[0]
    with pytest.raises(ValueError, match=r"meshes/m\.stl"):
        mujoco.MjModel.from_xml_path(str(path))
    command = [sys.executable, "-c", _PYBULLET_LOADS, str(path)]
    loads = subprocess.run(command, capture_output=True, timeout=60)
    assert loads.returncode == 0, loads.stderr[-400:]
    v = validate(path)
    assert v.errors == []
    said = [d for d in v.diagnostics if d.code == "MK500"]
    written = "../" * depth + "meshes/m.stl"
    assert len(said) == 2 and all(d.severity.value == "warning" and f'reads "{written}"' in d.message
                                  and written in (d.hint or "") for d in said), said
    assert ["visual mesh" in d.message for d in said] == [True, False]
    meshes = [g.geometry for link in v.robots[0].links for g in [*link.visuals, *link.collisions]]
    assert [m.path for m in meshes if isinstance(m, Mesh)] == [str(robot / "meshes" / "m.stl")] * 2
    assert validate(path, target="pybullet").errors == []
    (refused,) = validate(path, target="mjcf").errors
    assert refused.code == "MK500" and "visual mesh" not in refused.message
    from modelkit.convert.api import write

    write(v.robots[0], tmp_path / "out" / "r.xml", force=True)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "r.xml"))
    assert model.nmesh == 1 and model.ngeom == 2
    path.write_text(_urdf(_part(f"<collision>{shapes}</collision>")))
    (robot / "meshes" / "m.stl").unlink()
    _missing_collision_mesh(path, "MK500")  # found nowhere: PyBullet refuses it too


_TRIANGLE_URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.004" iyy="0.015" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
</robot>
"""


#: a model with two attributes glued to the previous one's closing quote (robotblockset's inspection cell:
#: ``type="box"size="0.02 0.15 0.35"``), and where libxml2 stops: the first glued attribute
_GLUED = {
    "urdf": (_TRIANGLE_URDF.replace("/></joint>", '/>\n    <limit effort="1"velocity="2"/></joint>'),
             "urdf", (8, 22)),
    "mjcf": (_MJCF_BALL.replace('<geom size="0.1"/>', '<geom type="box"size="0.1 0.2 0.3"rgba="1 0 0 1"/>'),
             "xml", (2, 57)),
    "sdf": (_BOX_MODEL.format(name="m").replace('<collision name="c">', "<collision name='c'>").replace(
        '<model name="m">', '<model name="m"><!-- a="1"b="2" -->').replace(
        '<sdf version="1.7">', '<sdf version="1.7"xmlns:x="http://x">'), "sdf", (2, 19)),
}


@pytest.mark.parametrize("kind", list(_GLUED))
def test_attributes_without_a_space_between_are_a_warning_as_tinyxml2_reads_them(
    tmp_path: Path, sdf_oracle: Path, kind: str  # noqa: F811
) -> None:
    """TinyXML2 (urdfdom, MuJoCo, libsdformat, PyBullet) reads an attribute glued to the previous one's
    closing quote; libxml2 refuses the file (\"attributes construct error\"). The file's own loader accepts
    it, so validate warns at the first one and reads the attributes' values; a comment is left as written."""
    text, suffix, at = _GLUED[kind]
    path = tmp_path / f"m.{suffix}"
    path.write_text(text)
    v, d = _read_past_as_tinyxml2(path, kind, sdf_oracle, "without a space between them")
    assert d.location is not None and (d.location.line, d.location.col) == at
    robot = v.robot
    assert robot is not None
    if kind == "urdf":
        (joint,) = robot.joints
        assert (joint.limits.effort, joint.limits.velocity) == (1.0, 2.0)
    if kind == "mjcf":
        (geom,) = [c for link in robot.links for c in link.collisions]
        assert tuple(geom.geometry.size) == pytest.approx((0.2, 0.4, 0.6))
    path.write_text(text.replace("</", "<bad></", 1))
    assert [d.code for d in validate(path).errors] == ["MK020"]  # a real malformation stays an error


def test_impossible_inertia_is_an_error_only_for_consumers_that_refuse_it(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from modelkit.cli import main

    path = tmp_path / "r.urdf"
    path.write_text(_TRIANGLE_URDF)
    assert check_urdf_accepts(path)[0]  # the file's own loader takes it
    (d,) = [d for d in validate(path).diagnostics if d.code == "MK303"]
    assert d.severity.value == "warning" and "MuJoCo and libsdformat" in d.message
    runner = CliRunner()
    assert runner.invoke(main, ["validate", str(path)]).exit_code == 0
    assert runner.invoke(main, ["validate", "--strict", str(path)]).exit_code == 1
    for target, code in (("mjcf", 1), ("sdf", 1), ("urdf", 0), ("pybullet", 0)):
        result = runner.invoke(main, ["validate", "--target", target, str(path)])
        assert result.exit_code == code, (target, result.output)
    # an SDF file with that inertia is refused by libsdformat itself: an error without any option
    sdf = tmp_path / "r.sdf"
    sdf.write_text(
        _BOX_MODEL.format(name="r").replace("<ixx>1</ixx><iyy>1</iyy><izz>1</izz>", "<ixx>0.004</ixx>"
                                            "<iyy>0.015</iyy><izz>0.1</izz>")
    )
    assert [d.code for d in validate(sdf).errors] == ["MK303"]


def test_name_collisions_by_format(tmp_path: Path) -> None:
    mjcf = tmp_path / "m.xml"
    mjcf.write_text(
        '<mujoco><worldbody><body name="arm"><joint name="arm" type="hinge"/>'
        '<geom type="sphere" size="0.1"/></body></worldbody></mujoco>'
    )
    mujoco.MjModel.from_xml_path(str(mjcf))  # MuJoCo takes it
    (d,) = [d for d in validate(mjcf).diagnostics if d.code == "MK211"]
    assert d.severity.value == "info"
    for version, severity in (("1.6", "warning"), ("1.7", "error")):
        sdf = tmp_path / f"s{version}.sdf"
        sdf.write_text(
            _BOX_MODEL.format(name="s").replace('version="1.7"', f'version="{version}"').replace(
                "</model>",
                '<link name="arm"><inertial><mass>1</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz>'
                '</inertia></inertial></link><joint name="arm" type="revolute"><parent>base</parent>'
                "<child>arm</child><axis><xyz>0 0 1</xyz></axis></joint></model>",
            )
        )
        found = [d.severity.value for d in validate(sdf).diagnostics if d.code == "MK211"]
        assert found == [severity], version


def test_xacro_files_of_materials_or_gazebo_blocks_are_libraries(tmp_path: Path) -> None:
    path = tmp_path / "materials.xacro"
    path.write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <material name="black"><color rgba="0 0 0 1"/></material>\n'
        '  <gazebo reference="base"><material>Gazebo/Black</material></gazebo>\n</robot>\n'
    )
    v = validate(path)
    assert v.errors == [] and [d.code for d in v.diagnostics] == ["MK710"]


# ---- issue 9 §1: the remaining verdict classes, each judged by the live reference loader --------------

_LINK = (
    '<link name="{0}"><inertial><mass>1</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia>'
    "</inertial></link>"
)


def _sdf(version: str, body: str) -> str:
    return f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n'


def _libsdformat_accepts(oracle: Path, path: Path, env: dict[str, str] | None = None) -> bool:
    run = subprocess.run(
        [str(oracle), path.name], cwd=path.parent, env=env, capture_output=True, text=True, timeout=60
    )
    return run.returncode == 0 and re.search(r"Error \[|Error:", run.stdout + run.stderr) is None


def _codes(v: Validation, severity: str) -> list[str]:
    return [d.code for d in v.diagnostics if d.severity.value == severity]


def _urdf(body: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="r">\n{body}\n</robot>\n'


_URDF_BASE = (
    '<link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
    "</inertial></link>"
)


def test_texture_without_filename_is_a_warning_as_urdfdom_ignores_it(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(
        _urdf(
            '<material name="plain"><color rgba="1 0 0 1"/><texture/></material>\n'
            + _URDF_BASE.replace("</link>", '<visual><geometry><box size="1 1 1"/></geometry>'
                                 '<material name="plain"/></visual></link>')
        )
    )
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == [] and _codes(v, "warning") == ["MK120"]
    assert "urdfdom and PyBullet ignore it" in v.warnings[0].message


def test_static_models_need_no_link(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    world = tmp_path / "w.sdf"
    world.write_text(
        _sdf("1.7", '<world name="w"><model name="marker"><static>true</static><frame name="f"/></model>'
             f'<model name="box">{_LINK.format("l")}</model></world>')
    )
    assert _libsdformat_accepts(sdf_oracle, world)
    v = validate(world)
    assert v.errors == [] and _codes(v, "info").count("MK152") == 1
    moving = tmp_path / "m.sdf"  # a nested model that is not static itself needs a link
    moving.write_text(
        _sdf("1.7", f'<model name="outer"><static>true</static>{_LINK.format("l")}'
             '<model name="inner"><frame name="f"/></model></model>')
    )
    assert not _libsdformat_accepts(sdf_oracle, moving)
    assert [d.code for d in validate(moving).errors] == ["MK152"]


def test_visual_or_collision_without_geometry(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    from click.testing import CliRunner

    from modelkit.cli import main

    sdf = tmp_path / "m.sdf"
    sdf.write_text(
        _sdf("1.6", '<model name="m"><link name="l"><visual name="v"/><collision name="c">'
             "<geometry/></collision></link></model>")
    )
    assert _libsdformat_accepts(sdf_oracle, sdf)  # libsdformat fills in an empty geometry
    v = validate(sdf)
    assert v.errors == [] and _codes(v, "warning").count("MK122") == 2
    urdf = tmp_path / "r.urdf"
    urdf.write_text(_urdf(_URDF_BASE.replace("</link>", '<visual><origin xyz="0 0 0"/></visual></link>')))
    assert check_urdf_accepts(urdf)[0]  # urdfdom logs an error, drops the visual and loads the robot
    v = validate(urdf)
    assert v.errors == [] and _codes(v, "warning") == ["MK122"]
    assert "PyBullet refuses" in v.warnings[0].message
    runner = CliRunner()
    assert runner.invoke(main, ["validate", str(urdf)]).exit_code == 0
    assert runner.invoke(main, ["validate", "--target", "pybullet", str(urdf)]).exit_code == 1


@pytest.mark.parametrize(
    ("version", "libsdformat_12", "ours"),
    [
        ("1.0", False, False),  # libsdformat 12: "Unable to convert from SDF version 1.0"
        ("1.2", True, True),  # converted as it is loaded
        ("1.3", True, True),
        ("1.9", True, True),
        ("1.12", False, True),  # libsdformat 12 is older than 1.12; current libsdformat reads it
        ("1.13", False, False),
    ],
)
def test_sdf_versions_as_libsdformat_reads_them(
    version: str, libsdformat_12: bool, ours: bool, tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    path = tmp_path / "m.sdf"
    path.write_text(_sdf(version, f'<model name="m">{_LINK.format("l")}</model>'))
    assert _libsdformat_accepts(sdf_oracle, path) == libsdformat_12
    v = validate(path)
    assert (v.errors == []) == ours, v.errors
    if version in ("1.2", "1.3"):
        assert _codes(v, "info") == ["MK151"]


def test_zero_principal_moment_on_a_moving_link_is_refused_by_mujoco_only(
    tmp_path: Path, sdf_oracle: Path, monkeypatch: pytest.MonkeyPatch  # noqa: F811
) -> None:
    """Issue 9 §1: a zero principal moment (a rod, a point mass) is physically impossible; check_urdf,
    PyBullet and libsdformat load it, MuJoCo refuses it: a warning naming MuJoCo, an error under
    --target mjcf; a negative moment cannot be simulated at all: an error."""
    finger = (
        '<link name="finger"><inertial><mass value="0.1"/><inertia ixx="0" iyy="0.001" izz="0.001" ixy="0" '
        'ixz="0" iyz="0"/></inertial></link>'
    )
    moving = (
        '<joint name="j" type="continuous"><parent link="base"/><child link="finger"/>'
        '<axis xyz="0 0 1"/></joint>'
    )
    monkeypatch.chdir(tmp_path)  # MuJoCo writes MUJOCO_LOG.TXT where it runs when it refuses a file
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_URDF_BASE + finger + moving))
    assert check_urdf_accepts(path)[0]
    assert _consumers_refusing(path, sdf_oracle) == {"mjcf"}  # libsdformat's URDF conversion loads it
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.warnings if d.code == "MK302"]
    assert "zero principal moment" in d.message and "MuJoCo refuses it" in d.message
    assert [d.code for d in validate(path, target="mjcf").errors] == ["MK302"]
    for target in ("sdf", "urdf", "pybullet"):
        assert validate(path, target=target).errors == [], target
    path.write_text(_urdf(_URDF_BASE + finger.replace('ixx="0"', 'ixx="-0.001"') + moving))
    assert [d.code for d in validate(path).errors] == ["MK302"]  # negative: an error whatever the target
    # libsdformat takes a zero moment (gz-math: near-positive) in an SDF link too: a warning there as well
    sdf = tmp_path / "r.sdf"
    sdf.write_text(_BOX_MODEL.format(name="r").replace("<ixx>1</ixx>", "<ixx>0</ixx>"))
    assert _libsdformat_accepts(sdf_oracle, sdf)
    v = validate(sdf)
    assert v.errors == [] and "MK302" in _codes(v, "warning")
    assert [d.code for d in validate(sdf, target="mjcf").errors] == ["MK302"]
    welded = moving.replace('type="continuous"', 'type="fixed"')
    path.write_text(_urdf(_URDF_BASE + finger + welded))
    v = validate(path)  # a rod welded to the base: engines merge it, and the merged body is sound
    assert v.errors == [] and "MK302" not in _codes(v, "warning")


def test_links_welded_by_fixed_joints_are_judged_as_the_body_engines_merge(tmp_path: Path) -> None:
    """Issue 9: mass properties are judged after lumping fixed subtrees, as the engines do."""
    def link(name: str, inertia: str, mass: str = "1") -> str:
        moments = f'<inertia {inertia} ixy="0" ixz="0" iyz="0"/>'
        return f'<link name="{name}"><inertial><mass value="{mass}"/>{moments}</inertial></link>'

    def joint(kind: str, parent: str, child: str, xyz: str = "0 0 0") -> str:
        return (f'<joint name="{parent}_{child}" type="{kind}"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="0 0 1"/></joint>')

    rod = 'ixx="0" iyy="0.001" izz="0.001"'
    point = 'ixx="0" iyy="0" izz="0"'
    sound = 'ixx="0.01" iyy="0.01" izz="0.01"'
    path = tmp_path / "r.urdf"
    # a moving arm made of a point mass (tool frame, 0.01 kg) welded to a sound link: no finding
    path.write_text(_urdf(_URDF_BASE + link("arm", sound) + link("tool", point, "0.01")
                          + joint("continuous", "base", "arm") + joint("fixed", "arm", "tool", "0 0 0.5")))
    v = validate(path)
    assert v.errors == [] and [d for d in v.diagnostics if d.code == "MK302"] == []
    # two rods along x welded together on the x axis: the merged body has no moment about x either
    path.write_text(_urdf(_URDF_BASE + link("arm", rod) + link("tip", rod)
                          + joint("continuous", "base", "arm") + joint("fixed", "arm", "tip", "0.5 0 0")))
    v = validate(path)
    assert v.errors == []
    (d,) = [d for d in v.warnings if d.code == "MK302"]
    assert 'rigid body of link "arm"' in d.message and "zero principal moment" in d.message
    assert [d.code for d in validate(path, target="mjcf").errors] == ["MK302"]
    assert d.location is not None and d.location.line > 0
    # the same rods offset along y: merged, the body has a moment about x (parallel axes): sound
    path.write_text(_urdf(_URDF_BASE + link("arm", rod) + link("tip", rod)
                          + joint("continuous", "base", "arm") + joint("fixed", "arm", "tip", "0 0.5 0")))
    assert validate(path).errors == []
    # a member's own inertia that is impossible (a negative moment) is still worth a warning
    negative = 'ixx="-0.001" iyy="0.01" izz="0.01"'
    path.write_text(_urdf(_URDF_BASE + link("arm", sound) + link("tool", negative, "0.01")
                          + joint("continuous", "base", "arm") + joint("fixed", "arm", "tool")))
    v = validate(path)
    assert v.errors == [] and _codes(v, "warning").count("MK302") == 1


def test_a_massless_moving_link_is_an_error_only_when_it_moves_nothing_with_mass(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A massless link between two joints (a differential wrist, a floating root above the robot):
    articulated-body engines simulate it, MuJoCo refuses it; a massless leaf moves nothing."""
    monkeypatch.chdir(tmp_path)  # MuJoCo writes MUJOCO_LOG.TXT where it runs when it refuses a file
    zero = '<inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>'
    one = '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
    joints = (
        '<joint name="j1" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>'
        '<joint name="j2" type="continuous"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/>'
        '<axis xyz="1 0 0"/></joint>'
    )
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_URDF_BASE + f'<link name="a">{zero}</link><link name="b">{one}</link>' + joints))
    assert check_urdf_accepts(path)[0]
    command = [sys.executable, "-c", _PYBULLET_LOADS, str(path)]
    loads = subprocess.run(command, capture_output=True, timeout=60)
    assert loads.returncode == 0, loads.stderr[-400:]
    with pytest.raises(ValueError, match="mass and inertia of moving bodies"):
        mujoco.MjModel.from_xml_path(str(path))
    v = validate(path)
    assert v.errors == [] and [d.code for d in v.warnings if d.code == "MK313"] == ["MK313"]
    assert [d.code for d in validate(path, target="mjcf").errors] == ["MK313"]
    # nothing with mass moves: check_urdf still accepts it, so a warning; MuJoCo refuses it (--target mjcf)
    path.write_text(_urdf(_URDF_BASE + f'<link name="a">{zero}</link><link name="b">{zero}</link>' + joints))
    assert check_urdf_accepts(path)[0]
    with pytest.raises(ValueError, match="mass and inertia of moving bodies"):
        mujoco.MjModel.from_xml_path(str(path))
    v = validate(path)
    assert v.errors == [] and sorted(d.code for d in v.warnings if d.code == "MK313") == ["MK313", "MK313"]
    assert sorted(d.code for d in validate(path, target="mjcf").errors) == ["MK313", "MK313"]


def test_singular_inertia_on_a_urdf_root_counts_as_moving(tmp_path: Path) -> None:
    root = _URDF_BASE.replace('ixx="1" iyy="1" izz="1"', 'ixx="0" iyy="0" izz="0"')
    arm = _URDF_BASE.replace('"base"', '"arm"') + (
        '<joint name="j" type="continuous"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/></joint>'
    )
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(root + arm))  # the root floats in PyBullet and Gazebo: judged as moving
    (d,) = [d for d in validate(path).warnings if d.code == "MK302"]
    assert "MuJoCo refuses it" in d.message and "does not move" not in d.message
    assert [d.code for d in validate(path, target="mjcf").errors] == ["MK302"]
    welded = (
        '<link name="world"/><joint name="w" type="fixed"><parent link="world"/><child link="base"/></joint>'
    )
    path.write_text(_urdf(welded + root + arm))
    v = validate(path)
    assert v.errors == [] and _codes(v, "warning") == ["MK302"]
    assert "does not move" in v.warnings[0].message


_BOX = "<box><size>1 1 1</size></box>"
_REFUSED_SDF: dict[str, tuple[str, str]] = {
    "duplicate joint": (
        "1.6",
        f'<model name="m">{_LINK.format("a")}{_LINK.format("b")}{_LINK.format("c")}'
        '<joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>'
        '<joint name="j" type="fixed"><parent>b</parent><child>c</child></joint></model>',
    ),
    "two lights of one name": (
        "1.7",
        '<world name="w"><light name="l" type="point"/><light name="l" type="point"/>'
        f'<model name="m">{_LINK.format("a")}</model></world>',
    ),
    "a link named world (1.6)": (
        "1.6",
        f'<model name="m">{_LINK.format("world")}{_LINK.format("b")}</model>',
    ),
    "two worlds of one name": ("1.6", f'<world name="w"><model name="m">{_LINK.format("a")}</model></world>'
                               '<world name="w"/>'),
    "a world without a name": ("1.6", f'<world><model name="m">{_LINK.format("a")}</model></world>'),
    "a world frame attached to nothing": (
        "1.7",
        f'<world name="w"><frame name="f" attached_to="nothere"/><model name="m">{_LINK.format("a")}</model>'
        "</world>",
    ),
    "a material script without uri": (
        "1.6",
        f'<model name="m"><link name="a"><visual name="v"><geometry>{_BOX}</geometry><material><script>'
        "<name>Gazebo/Red</name></script></material></visual></link></model>",
    ),
    "a malformed vector": ("1.9", f'<world name="w"><gravity>0 0</gravity><model name="m">{_LINK.format("a")}'
                           "</model></world>"),
    "a malformed double": (
        "1.9",
        '<model name="m"><link name="a"><sensor name="s" type="imu"><update_rate>fast</update_rate>'
        "</sensor>"
        "</link></model>",
    ),
    "a malformed boolean": (
        "1.9",
        '<model name="m"><link name="a"><sensor name="s" type="imu"><always_on>yes</always_on></sensor>'
        "</link></model>",
    ),
    "a colour out of range": ("1.9", f'<world name="w"><scene><ambient>2 0.1 0.1 1</ambient></scene>'
                              f'<model name="m">{_LINK.format("a")}</model></world>'),
    "a negative friction": (
        "1.6",
        f'<model name="m"><link name="a"><collision name="c"><geometry>{_BOX}</geometry><surface><friction>'
        "<ode><mu>-1</mu></ode></friction></surface></collision></link></model>",
    ),
    # an empty value where libsdformat's description requires one ("Empty string used when setting a
    # required parameter")
    "an empty mesh uri": (
        "1.7",
        '<model name="m"><link name="a"><visual name="v"><geometry><mesh><uri></uri></mesh></geometry>'
        "</visual></link></model>",
    ),
    "an empty box size": (
        "1.7",
        '<model name="m"><link name="a"><collision name="c"><geometry><box><size/></box></geometry>'
        "</collision></link></model>",
    ),
    "an empty gravity": ("1.7", f'<world name="w"><gravity></gravity><model name="m">{_LINK.format("a")}'
                         "</model></world>"),
    "an empty include uri": ("1.8", "<world name=\"w\"><include><uri></uri></include></world>"),
    "an empty model name": ("1.7", f'<model name="">{_LINK.format("a")}</model>'),
    "an empty joint axis": (
        "1.7",
        f'<model name="m">{_LINK.format("a")}{_LINK.format("b")}<joint name="j" type="revolute"><parent>a'
        "</parent><child>b</child><axis><xyz></xyz></axis></joint></model>",
    ),
    # a joint's parent frame that resolves to its child link (libsdformat error 21; its own
    # joint_invalid_resolved_parent_same_as_child.sdf)
    "a parent frame attached to the child": (
        "1.7",
        f'<model name="m">{_LINK.format("a")}{_LINK.format("c")}<frame name="f" attached_to="c"/>'
        '<joint name="j" type="revolute"><parent>f</parent><child>c</child><axis><xyz>0 0 1</xyz></axis>'
        '</joint><joint name="k" type="fixed"><parent>a</parent><child>c</child></joint></model>',
    ),
    "a parent joint resolving to the child": (
        "1.8",
        f'<model name="m">{_LINK.format("a")}{_LINK.format("b")}<joint name="j1" type="prismatic"><parent>a'
        "</parent><child>j2</child><axis><xyz>1 0 0</xyz></axis></joint>"
        '<joint name="j2" type="prismatic"><parent>j1</parent><child>b</child><axis><xyz>0 1 0</xyz>'
        "</axis></joint></model>",
    ),
    # libsdformat's Material::Load (its material_normal_map_missing.sdf), also on a visual without geometry
    "a normal-map shader without a normal map": (
        "1.6",
        '<model name="m"><link name="a"><visual name="v"><material><shader type="normal_map_tangent_space">'
        "</shader></material></visual></link></model>",
    ),
    "an unknown shader type": (
        "1.6",
        f'<model name="m"><link name="a"><visual name="v"><geometry>{_BOX}</geometry><material>'
        '<shader type="Pixel"/></material></visual></link></model>',
    ),
}
# Values libsdformat 12 reads although they look wrong (std::stod takes a leading number, a vector
# ignores extra numbers, booleans are case-insensitive): no error.
_ACCEPTED_SDF: dict[str, tuple[str, str]] = {
    # a zero size: libsdformat loads it (a warning, MK416/MK417; MuJoCo would refuse it)
    "a collision box of size zero": (
        "1.7",
        '<model name="m"><link name="a"><collision name="c"><geometry><box><size>0 0 0</size></box>'
        "</geometry></collision></link></model>",
    ),
    "a collision sphere and cylinder of radius zero": (
        "1.7",
        '<model name="m"><link name="a"><collision name="s"><geometry><sphere><radius>0</radius></sphere>'
        '</geometry></collision><collision name="c"><geometry><cylinder><radius>0</radius><length>1</length>'
        "</cylinder></geometry></collision></link></model>",
    ),
    "a visual box of negative size": (
        "1.7",
        '<model name="m"><link name="a"><visual name="v"><geometry><box><size>-1 1 1</size></box></geometry>'
        "</visual></link></model>",
    ),
    "a double with trailing text": (
        "1.9",
        f'<world name="w"><physics type="ode"><max_step_size>0.001s</max_step_size></physics>'
        f'<model name="m">{_LINK.format("a")}</model></world>',
    ),
    "a vector with an extra number": ("1.9", f'<world name="w"><gravity>0 0 -9.8 1</gravity>'
                                      f'<model name="m">{_LINK.format("a")}</model></world>'),
    "a capitalised boolean": (
        "1.9",
        '<model name="m"><link name="a"><sensor name="s" type="imu"><visualize>True</visualize></sensor>'
        "</link></model>",
    ),
    # an empty value of an element the description does not require keeps the default
    "empty optional values": (
        "1.7",
        '<model name="m"><static></static><pose></pose><link name="a"><pose/><inertial><mass></mass>'
        "</inertial></link></model>",
    ),
    "both spellings of the normal-map shaders": (
        "1.6",
        f'<model name="m"><link name="a"><visual name="v"><geometry>{_BOX}</geometry><material><shader '
        'type="normal_map_objectspace"><normal_map>n.png</normal_map></shader></material></visual>'
        f'<visual name="w"><geometry>{_BOX}</geometry><material><shader type="normal_map_tangent_space">'
        "<normal_map>n.png</normal_map></shader></material></visual></link></model>",
    ),
    # libsdformat 12 checks resolved parent and child links only for the top model's joints
    "a nested model's joint between two frames of one link": (
        "1.8",
        f'<model name="top">{_LINK.format("a")}<model name="n">{_LINK.format("l")}{_LINK.format("b")}'
        '<frame name="f" attached_to="l"/><joint name="j" type="revolute"><parent>f</parent><child>l</child>'
        '<axis><xyz>0 0 1</xyz></axis></joint><joint name="k" type="fixed"><parent>b</parent><child>l</child>'
        '</joint></model><joint name="m" type="fixed"><parent>a</parent><child>n</child></joint></model>',
    ),
    # a closed chain in which every link is a joint's child (libsdformat's four_bar.sdf): a warning
    "a closed chain of four links": (
        "1.6",
        '<model name="m">' + "".join(_LINK.format(n) for n in ("l1", "l2", "l3", "l4")) + "".join(
            f'<joint name="j{i}" type="revolute"><parent>l{i}</parent><child>l{i % 4 + 1}</child>'
            "<axis><xyz>0 0 1</xyz></axis></joint>"
            for i in range(1, 5)
        ) + "</model>",
    ),
}


@pytest.mark.parametrize("case", sorted(_REFUSED_SDF))
def test_what_libsdformat_refuses_is_an_error(case: str, tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    version, body = _REFUSED_SDF[case]
    path = tmp_path / "m.sdf"
    path.write_text(_sdf(version, body))
    assert not _libsdformat_accepts(sdf_oracle, path), case
    assert validate(path).errors, case


@pytest.mark.parametrize("case", sorted(_ACCEPTED_SDF))
def test_odd_values_libsdformat_reads_are_not_errors(case: str, tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    version, body = _ACCEPTED_SDF[case]
    path = tmp_path / "m.sdf"
    path.write_text(_sdf(version, body))
    assert _libsdformat_accepts(sdf_oracle, path), case
    assert validate(path).errors == [], case


def test_an_include_of_several_models_is_refused(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    folder = tmp_path / "models" / "pair"
    folder.mkdir(parents=True)
    (folder / "model.config").write_text(
        '<?xml version="1.0"?><model><name>pair</name><sdf version="1.7">model.sdf</sdf></model>'
    )
    (folder / "model.sdf").write_text(
        _sdf("1.7", f'<model name="a">{_LINK.format("l")}</model><model name="b">{_LINK.format("l")}</model>')
    )
    world = _world(tmp_path, ["model://pair"])
    models = str(tmp_path / "models")
    assert not _libsdformat_accepts(sdf_oracle, world, {**os.environ, "SDF_PATH": models})
    v = validate(world, ReadOptions(resolver=Resolver(resource_paths=[tmp_path / "models"])))
    assert [d.code for d in v.errors] == ["MK530"] and "more than one" in v.errors[0].message


def test_web_meshes_are_not_errors(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    uri = "https://fuel.gazebosim.org/1.0/OpenRobotics/models/Radio/4/files/meshes/Radio.dae"
    sdf = tmp_path / "m.sdf"
    sdf.write_text(
        _sdf("1.9", f'<model name="m"><link name="a"><collision name="c"><geometry><mesh><uri>{uri}</uri>'
             "</mesh></geometry></collision></link></model>")
    )
    assert _libsdformat_accepts(sdf_oracle, sdf)  # it never opens meshes; Gazebo fetches them from Fuel
    v = validate(sdf)
    assert v.errors == [] and _codes(v, "info") == ["MK503"]
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        _urdf(_URDF_BASE.replace("</link>", f'<collision><geometry><mesh filename="{uri[:-3]}stl"/>'
                                 "</geometry></collision></link>"))
    )
    assert check_urdf_accepts(urdf)[0]
    v = validate(urdf)
    assert v.errors == [] and _codes(v, "warning") == ["MK503"]
    assert "PyBullet and MuJoCo" in v.warnings[0].message


def test_kinematic_only_urdf_is_a_warning_and_an_error_for_mujoco(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from modelkit.cli import main

    path = tmp_path / "r.urdf"
    path.write_text(
        _urdf('<link name="base"/><link name="arm"/><joint name="j" type="continuous"><parent link="base"/>'
              '<child link="arm"/><axis xyz="0 0 1"/></joint>')
    )
    assert check_urdf_accepts(path)[0]
    v = validate(path)
    assert v.errors == [] and "MK313" in _codes(v, "warning")
    (d,) = [d for d in v.diagnostics if d.code == "MK313"]
    assert "PyBullet gives it 1 kg" in d.message and "MuJoCo refuses it" in d.message
    runner = CliRunner()
    for target, code in (("mjcf", 1), ("pybullet", 0), ("urdf", 0)):
        result = runner.invoke(main, ["validate", "--target", target, str(path)])
        assert result.exit_code == code, (target, result.output)
    # an explicit zero mass on a leaf that moves: check_urdf accepts it, PyBullet loads it and freezes the
    # joint (a velocity motor leaves it at 0), MuJoCo refuses it: a warning, an error for --target mjcf
    path.write_text(
        _urdf(_URDF_BASE + '<link name="arm"><inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" '
              'ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="j" type="continuous">'
              '<parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>')
    )
    assert check_urdf_accepts(path)[0]
    frozen = subprocess.run(
        [sys.executable, "-c", _PYBULLET_FROZEN, str(path)], capture_output=True, timeout=60
    )
    assert frozen.returncode == 0 and frozen.stdout.split() == [b"0.0"], frozen.stderr[-400:]
    v = validate(path)
    assert v.errors == [] and [d.code for d in v.warnings if d.code == "MK313"] == ["MK313"]
    (d,) = [d for d in v.warnings if d.code == "MK313"]
    assert "check_urdf accepts it" in d.message and "freezes the joint" in d.message
    for target, code in (("mjcf", 1), ("pybullet", 0), ("urdf", 0)):
        result = runner.invoke(main, ["validate", "--target", target, str(path)])
        assert result.exit_code == code, (target, result.output)
    # MJCF: MuJoCo itself refuses a moving body without mass, and so does modelkit
    mjcf = tmp_path / "m.xml"
    mjcf.write_text(
        '<mujoco><worldbody><body name="b"><joint name="j" type="hinge"/></body></worldbody></mujoco>'
    )
    with pytest.raises(ValueError, match="mass and inertia of moving bodies"):
        mujoco.MjModel.from_xml_path(str(mjcf))
    assert validate(mjcf).errors


def test_a_link_named_world_is_one_error(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """One root cause, one error: no follow-on duplicate-link (MK204) or second-root (MK201) findings."""
    path = tmp_path / "m.sdf"
    for version in ("1.6", "1.9"):
        path.write_text(
            _sdf(
                version,
                f'<model name="m"><link name="world"/>{_LINK.format("base")}{_LINK.format("arm")}'
                '<joint name="fix" type="revolute"><parent>world</parent><child>base</child><axis><xyz>0 0 1'
                '</xyz></axis></joint><joint name="j" type="revolute"><parent>base</parent><child>arm</child>'
                "<axis><xyz>0 0 1</xyz></axis></joint></model>",
            )
        )
        assert not _libsdformat_accepts(sdf_oracle, path)  # "The supplied link name [world] is reserved."
        v = validate(path)
        assert [d.code for d in v.errors] == ["MK238"] and _codes(v, "warning") == [], v.diagnostics


def test_model_frame_as_joint_end_is_an_exception_for_libsdformat_12(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """libsdformat 12 refuses ``__model__`` as a joint's parent or child; current libsdformat loads it (its
    own joint_parent_model_frame.sdf and joint_child_model_frame.sdf are valid test files), as modelkit."""
    path = tmp_path / "m.sdf"
    for ends in ("<parent>__model__</parent><child>b</child>", "<parent>b</parent><child>__model__</child>"):
        path.write_text(
            _sdf("1.8", f'<model name="m">{_LINK.format("a")}{_LINK.format("b")}<joint name="j" type="fixed">'
                 f"{ends}</joint></model>")
        )
        assert not _libsdformat_accepts(sdf_oracle, path)
        assert validate(path).errors == []


# ---- URDF parts urdfdom logs an error for, drops, and loads the robot anyway --------------------------
# Each case: the robot's extra text, the code and severity modelkit gives, and which consumers refuse
# the file (checked live below: check_urdf always accepts; PyBullet in a child process, MuJoCo's URDF
# import and libsdformat's URDF conversion, which runs the same urdfdom). ``--target`` makes the finding
# an error exactly for the consumers that refuse it.

_ARM = (
    '<link name="arm"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
    "</inertial></link>"
)
_HINGE = (
    '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="{axis}"/>'
    '<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>{mimic}</joint>'
)


def _hinge(axis: str = "0 0 1", lower: str = "-1", upper: str = "1", mimic: str = "") -> str:
    return _ARM + _HINGE.format(axis=axis, lower=lower, upper=upper, mimic=mimic)


def _part(part: str) -> str:
    return _URDF_BASE.replace("</link>", part + "</link>") + _hinge()


def _inertial(inertial: str) -> str:
    """The base and a moving arm whose inertial is ``inertial`` (and a collision box)."""
    arm = f'<link name="arm">{inertial}<collision><geometry><box size="1 1 1"/></geometry></collision></link>'
    return _URDF_BASE + _hinge().replace(_ARM, arm)


_MESH = "m.stl"
_TRIANGLE_STL = (
    "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
    "endsolid t\n"
)
_URDFDOM_TOLERATED: dict[str, tuple[str, str, str, frozenset[str]]] = {
    # case: (robot text, code, severity, consumers that refuse the file)
    "a mesh without filename": (
        _part("<collision><geometry><mesh/></geometry></collision>"), "MK143", "warning",
        frozenset({"pybullet", "mjcf"}),
    ),
    "a box without size": (
        _part("<collision><geometry><box/></geometry></collision>"), "MK143", "warning",
        frozenset({"pybullet", "mjcf"}),
    ),
    "a cylinder without radius": (
        _part('<collision><geometry><cylinder length="1"/></geometry></collision>'), "MK143", "warning",
        frozenset({"pybullet", "mjcf"}),
    ),
    "a mesh scale of two numbers": (
        _part(f'<collision><geometry><mesh filename="{_MESH}" scale="0.5 0.5"/></geometry></collision>'),
        "MK420", "warning", frozenset({"mjcf"}),
    ),
    "a mesh scale of four numbers": (
        _part(f'<collision><geometry><mesh filename="{_MESH}" scale="1 1 1 1"/></geometry></collision>'),
        "MK420", "warning", frozenset({"mjcf"}),
    ),
    "a shape URDF does not have": (
        _part('<collision><geometry><ball radius="1"/></geometry></collision>'), "MK412", "warning",
        frozenset({"pybullet", "mjcf"}),
    ),
    "PyBullet's plane shape": (
        _part('<collision><geometry><plane normal="0 0 1"/></geometry></collision>'), "MK421", "warning",
        frozenset({"mjcf"}),
    ),
    "an inertia without its off-diagonal terms": (
        _inertial('<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1"/></inertial>'), "MK144",
        "warning", frozenset({"mjcf"}),
    ),
    "an inertia without ixx": (
        _inertial('<inertial><mass value="1"/><inertia iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'),
        "MK145", "warning", frozenset({"pybullet", "mjcf"}),
    ),
    "a mass without value": (
        _inertial('<inertial><mass/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'),
        "MK145", "warning", frozenset({"pybullet", "mjcf"}),
    ),
    "an inertial without inertia": (
        _inertial('<inertial><mass value="1"/></inertial>'), "MK145", "warning",
        frozenset({"pybullet", "mjcf"}),
    ),
    "a colour of three numbers": (
        _part('<visual><geometry><box size="1 1 1"/></geometry><material name="red"><color rgba="1 0 0"/>'
              "</material></visual>"),
        "MK146", "warning", frozenset({"mjcf"}),
    ),
    "a mimic of a joint that does not exist": (
        _URDF_BASE + _hinge(mimic='<mimic joint="nothere"/>'), "MK320", "warning", frozenset(),
    ),
    "a lower limit above the upper": (
        _URDF_BASE + _hinge(lower="1", upper="-1"), "MK307", "warning", frozenset(),
    ),
    # a zero size (Gazebo models' way to say "no collision"): MuJoCo's URDF import refuses it ("size 0
    # must be positive in geom"); on a visual it is dropped with all visuals, so MuJoCo loads the file
    "a collision box of size zero": (
        _part('<collision><geometry><box size="0 0 0"/></geometry></collision>'), "MK416", "warning",
        frozenset({"mjcf"}),
    ),
    "a collision sphere of radius zero": (
        _part('<collision><geometry><sphere radius="0"/></geometry></collision>'), "MK416", "warning",
        frozenset({"mjcf"}),
    ),
    "a collision cylinder of radius zero": (
        _part('<collision><geometry><cylinder radius="0" length="1"/></geometry></collision>'), "MK416",
        "warning", frozenset({"mjcf"}),
    ),
    "a visual box of size zero": (
        _part('<visual><geometry><box size="0 0 0"/></geometry></visual>'), "MK417", "warning", frozenset(),
    ),
    # not simulable: every loader but MuJoCo takes a negative size; PyBullet inverts the shape's bounds and
    # the body falls through the floor (test_negative_sizes_cannot_be_simulated)
    "a collision box of negative size": (
        _part('<collision><geometry><box size="-1 1 1"/></geometry></collision>'), "MK416", "error",
        frozenset({"mjcf"}),
    ),
    # not simulable: the joint has no direction of motion (an error by the policy; PyBullet loads it)
    "a zero axis on a revolute joint": (
        _URDF_BASE + _hinge(axis="0 0 0"), "MK305", "error", frozenset({"sdf", "mjcf"}),
    ),
}

_PYBULLET_LOADS = """
import sys
import pybullet
pybullet.connect(pybullet.DIRECT)
try:
    pybullet.loadURDF(sys.argv[1])
except pybullet.error:
    sys.exit(3)
"""

# PyBullet on a URDF whose only joint moves a massless leaf: the joint position after one second of a
# velocity motor asking for 1 rad/s (printed; 0.0 when the engine freezes the joint).
_PYBULLET_FROZEN = """
import sys
import pybullet
pybullet.connect(pybullet.DIRECT)
body = pybullet.loadURDF(sys.argv[1], useFixedBase=True)
pybullet.setJointMotorControl2(body, 0, pybullet.VELOCITY_CONTROL, targetVelocity=1, force=10)
for _ in range(240):
    pybullet.stepSimulation()
print(pybullet.getJointState(body, 0)[0])
"""


def _consumers_refusing(path: Path, oracle: Path) -> set[str]:
    """Which of PyBullet, MuJoCo's URDF import and libsdformat's URDF conversion refuse the file, live."""
    refused = set()
    run = subprocess.run(
        [sys.executable, "-c", _PYBULLET_LOADS, str(path)], capture_output=True, timeout=60
    )
    assert run.returncode in (0, 3), run.stderr[-400:]
    if run.returncode == 3:
        refused.add("pybullet")
    try:
        mujoco.MjModel.from_xml_path(str(path))
    except ValueError:
        refused.add("mjcf")
    # urdfdom's console lines ("Error: ... at line N in urdf_parser/src/link.cpp") are logs, not
    # refusals: libsdformat's verdict is its exit status
    if subprocess.run([str(oracle), path.name], cwd=path.parent, capture_output=True, timeout=60).returncode:
        refused.add("sdf")
    return refused


@pytest.mark.parametrize("case", sorted(_URDFDOM_TOLERATED))
def test_urdf_parts_urdfdom_tolerates(
    case: str, tmp_path: Path, sdf_oracle: Path, monkeypatch: pytest.MonkeyPatch  # noqa: F811
) -> None:
    body, code, severity, refusing = _URDFDOM_TOLERATED[case]
    monkeypatch.chdir(tmp_path)  # MuJoCo writes MUJOCO_LOG.TXT where it runs when it refuses a file
    (tmp_path / _MESH).write_text(_TRIANGLE_STL)
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(body))
    assert check_urdf_accepts(path)[0], case  # urdfdom logs an error at most, and loads the robot
    assert _consumers_refusing(path, sdf_oracle) == refusing, case
    v = validate(path)
    found = [(d.code, d.severity.value) for d in v.diagnostics if d.code == code]
    assert found == [(code, severity)], (case, v.diagnostics)
    assert [d.code for d in v.errors] == ([code] if severity == "error" else []), (case, v.errors)
    for target in ("pybullet", "mjcf", "sdf", "urdf"):
        judged = validate(path, target=target)
        expected = severity == "error" or (target in refusing and target != "sdf")
        assert bool(judged.errors) == expected, (case, target, judged.errors)


_PYBULLET_DROP = """
import sys
import pybullet
pybullet.connect(pybullet.DIRECT)
pybullet.setGravity(0, 0, -10)
pybullet.createMultiBody(0, pybullet.createCollisionShape(pybullet.GEOM_PLANE))
body = pybullet.loadURDF(sys.argv[1], [0, 0, 2])
low, high = pybullet.getAABB(body)
for _ in range(480):
    pybullet.stepSimulation()
print(low[0] <= high[0], pybullet.getBasePositionAndOrientation(body)[0][2])
"""


@pytest.mark.parametrize(
    ("shape", "z"),
    [('<box size="1 1 1"/>', 0.5), ('<box size="-1 1 1"/>', -0.5), ('<sphere radius="-0.5"/>', -0.5)],
)
def test_negative_sizes_cannot_be_simulated(
    shape: str, z: float, tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """Every loader but MuJoCo takes a negative size, but PyBullet inverts the shape's bounds and the body
    sinks through the floor (a 1 m box dropped from 2 m rests at z = 0.5 with a positive size): an error by
    the policy (the model cannot be simulated meaningfully)."""
    path = tmp_path / "r.urdf"
    collision = f"<collision><geometry>{shape}</geometry></collision></link>"
    path.write_text(_urdf(_URDF_BASE.replace("</link>", collision)))
    assert check_urdf_accepts(path)[0]
    run = subprocess.run([sys.executable, "-c", _PYBULLET_DROP, str(path)], capture_output=True, text=True,
                         timeout=60)
    bounds_ordered, rest = run.stdout.split()[-2:]
    assert (bounds_ordered == "True") == (z > 0) and abs(float(rest) - z) < 0.01, run.stdout
    errors = [d.code for d in validate(path).errors]
    assert errors == ([] if z > 0 else ["MK416"]), errors
    sdf = tmp_path / "m.sdf"
    sdf.write_text(_sdf("1.7", '<model name="m"><link name="a"><collision name="c"><geometry>'
                        "<sphere><radius>-0.5</radius></sphere></geometry></collision></link></model>"))
    assert _libsdformat_accepts(sdf_oracle, sdf)
    assert [d.code for d in validate(sdf).errors] == ["MK416"]


def test_a_zero_collision_box_is_a_warning_naming_mujoco(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from modelkit.cli import main

    path = tmp_path / "r.urdf"
    path.write_text(_urdf(_part('<collision><geometry><box size="0 0 0"/></geometry></collision>')))
    (d,) = validate(path).warnings
    assert d.code == "MK416" and "MuJoCo refuses it" in d.message and "PyBullet" in d.message
    assert d.location is not None and d.location.col > 0
    runner = CliRunner()
    cases: list[tuple[list[str], int]] = [
        ([], 0), (["--strict"], 1), (["--target", "mjcf"], 1), (["--target", "pybullet"], 0)
    ]
    for options, code in cases:
        result = runner.invoke(main, ["validate", *options, str(path)])
        assert result.exit_code == code, (options, result.output)


_PIONEER = CORPUS / "gazebo_ros_pkgs/gazebo_plugins/test/multi_robot_scenario/xacro/p3dx/pioneer3dx.xacro"


def test_zero_boxes_are_kept_for_consumers_that_accept_them(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """URDF and SDF keep a zero collision box as written (check_urdf and libsdformat load it); only the MJCF
    writer leaves it out (tests/test_mjcf_writer.py)."""
    from click.testing import CliRunner

    from modelkit.cli import main

    if not _PIONEER.is_file():
        pytest.skip("shared corpus not available")
    for suffix, zero in ((".urdf", 'size="0 0 0"'), (".sdf", "<size>0 0 0</size>")):
        out = tmp_path / suffix[1:] / f"p3dx{suffix}"
        result = CliRunner().invoke(main, ["convert", str(_PIONEER), "-o", str(out)])
        assert result.exit_code == 0 and "MK871" not in result.output, result.output
        assert out.read_text().count(zero) == 5
        accepted = check_urdf_accepts(out)[0] if suffix == ".urdf" else _libsdformat_accepts(sdf_oracle, out)
        assert accepted, suffix
        v = validate(out)
        assert v.errors == [] and _codes(v, "warning").count("MK416") == 5, v.diagnostics


def test_unreadable_urdf_parts_keep_the_rest_of_the_link(tmp_path: Path) -> None:
    """urdfdom stops reading a link at its first unreadable part: the visuals after a bad visual and every
    collision are gone, an unreadable inertia zeroes the inertia and drops the link's geometry (seen in
    libsdformat's URDF conversion, which runs the same urdfdom). modelkit keeps the readable parts and says
    what urdfdom drops."""
    path = tmp_path / "r.urdf"
    path.write_text(
        _urdf(
            '<link name="base"><inertial><mass value="2"/><inertia ixx="1" iyy="1" izz="1"/></inertial>'
            '<collision name="kept_not"><geometry><sphere radius="1"/></geometry></collision></link>'
            '<link name="b2"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
            'iyz="0"/></inertial><visual name="first"><geometry><box size="1 1 1"/></geometry></visual>'
            '<visual><geometry><mesh/></geometry></visual><visual name="after"><geometry>'
            '<box size="2 2 2"/></geometry></visual><collision name="c"><geometry><sphere radius="1"/>'
            '</geometry></collision></link><joint name="j" type="continuous"><parent link="base"/>'
            '<child link="b2"/><axis xyz="0 0 1"/></joint>'
        )
    )
    v = validate(path)
    assert v.errors == [] and sorted(_codes(v, "warning")) == ["MK143", "MK144"]
    for d in v.warnings:
        assert "every" in d.message and "urdfdom" in d.message, d.message
    robot = v.robot
    assert robot is not None
    b2 = next(link for link in robot.links if link.name == "b2")
    assert len(b2.visuals) == 2 and len(b2.collisions) == 1  # modelkit keeps the readable parts


def test_nameless_visual_material_is_judged_like_check_urdf_and_an_error_for_pybullet(tmp_path: Path) -> None:
    """MK136 (issue 18 item 3): check_urdf loads a visual <material> without a name (urdfdom drops that
    visual), PyBullet refuses the file: a warning, an error under --target pybullet."""
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(
        _URDF_BASE.replace('"base">', '"base"><visual><geometry><box size="1 1 1"/></geometry>'
                           '<material><color rgba="1 0 0 1"/></material></visual>', 1)
    ))
    accepted, said = check_urdf_accepts(path)
    assert accepted and "Visual material must contain a name attribute" in said
    command = [sys.executable, "-c", _PYBULLET_LOADS, str(path)]
    loads = subprocess.run(command, capture_output=True, timeout=60)
    assert loads.returncode == 3, loads.stderr[-400:]  # PyBullet refuses it
    v = validate(path)
    assert v.errors == [] and _codes(v, "warning") == ["MK136"]
    (d,) = validate(path, target="pybullet").errors
    assert d.code == "MK136" and "PyBullet refuses the file" in d.message
    assert d.location is not None and d.location.line == 3
    assert validate(path, target="mjcf").errors == []


def test_asymmetric_body_inertia_is_a_warning_and_converts_its_upper_triangle(tmp_path: Path) -> None:
    """MK301 (issue 18 item 3): Choreonoid loads a 9-element inertia that is not symmetric and uses it as
    given; validate warns and passes, convert writes the upper triangle (the row-major xy, xz, yz)."""
    from click.testing import CliRunner

    from modelkit.cli import main

    source = REPO / "tests" / "broken_body" / "inertia_asymmetric.body"  # arm: xy 0.005, yx 0
    v = validate(source)
    # its upper triangle (principal moments 0.016, 0.026, 0.0005) breaks the triangle inequality: MK303
    assert v.errors == [] and _codes(v, "warning") == ["MK301", "MK303"]
    out = tmp_path / "p.urdf"
    result = CliRunner().invoke(main, ["convert", "-o", str(out), str(source)])
    assert result.exit_code == 0, result.output
    assert 'ixx="0.021" ixy="0.005" ixz="0" iyy="0.021" iyz="0" izz="0.0005"' in out.read_text()


def test_an_asymmetric_body_inertia_is_judged_as_the_upper_triangle_convert_writes(tmp_path: Path) -> None:
    """A semantic-fuzz mutant of the tutorial's mobile_robot.body: its left wheel's iyz (row-major index 5)
    set to 3.5e38, zy left 0. validate warned MK301 and stopped judging the link; convert wrote the upper
    triangle, a tensor with principal moments ±3.5e38, and MuJoCo refused the MJCF ("inertia must satisfy
    A + B >= C"). The written tensor is now judged: MK302, an error (the wheel moves)."""
    text = (TUTORIAL / "mobile_robot_primitive.body").read_text()
    wheel = """    inertia: [ 0.0012, 0,      0,
               0,      0.0023, 0,
               0,      0,      0.0012 ]
    material: Tire"""
    assert text.count(wheel) == 2
    source = tmp_path / "wheel.body"
    source.write_text(text.replace(wheel, wheel.replace("0.0023, 0,", "0.0023, 0.05,"), 1))
    v = validate(source)
    assert _codes(v, "warning") == ["MK301"]
    (error,) = v.errors
    assert error.code == "MK302" and '"LeftWheel" (its upper triangle, which convert writes)' in error.message
    # a small asymmetry whose upper triangle is a physical tensor stays a warning only
    source.write_text(text.replace(wheel, wheel.replace("0.0023, 0,", "0.0023, 0.0001,"), 1))
    assert validate(source).errors == []


_BAD_INERTIA = (
    '<link name="{0}"><inertial><mass>12.3</mass><inertia><ixx>0.205</ixx><iyy>0.17425</iyy>'
    "<izz>0.05125</izz><iyz>-0.5</iyz></inertia></inertial></link>"
)


@pytest.mark.parametrize("case", ["free_link", "static_model", "world_joint_child_elsewhere"])
def test_a_negative_moment_on_any_sdf_link_is_an_error_as_libsdformat_refuses_it(
    case: str, tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """A semantic fuzz mutant of sdformat_urdf's joint_revolute.sdf: the joint's parent turned to `world`
    left `link_1` unconnected (it floats, MK201) with a negative principal moment. validate called the link
    static and warned; libsdformat refuses the file, and the .body convert wrote was refused by modelkit's
    own reader (a free link with that inertia)."""
    static = "<static>true</static>" if case == "static_model" else ""
    joint = ('<joint name="j" type="revolute"><parent>world</parent><child>b</child><axis><xyz>1 0 0</xyz>'
             "</axis></joint>")
    body = f'<model name="m">{static}{_BAD_INERTIA.format("a")}{_LINK.format("b")}{joint}</model>'
    path = tmp_path / "m.sdf"
    path.write_text(_sdf("1.7", body))
    assert not _libsdformat_accepts(sdf_oracle, path)
    found = [d for d in validate(path).diagnostics if d.code == "MK302"]
    assert [d.severity.value for d in found] == ["error"], found
    if case == "static_model":
        assert "libsdformat refuses the whole file" in found[0].message


def test_a_negative_moment_on_a_welded_urdf_link_stays_a_warning(tmp_path: Path) -> None:
    """urdfdom and PyBullet load it, and no engine simulates a link welded to the world."""
    path = tmp_path / "r.urdf"
    path.write_text(_urdf(
        '<link name="world"/><joint name="w" type="fixed"><parent link="world"/><child link="a"/></joint>'
        '<link name="a"><inertial><mass value="12.3"/><inertia ixx="0.205" iyy="0.17425" izz="0.05125" '
        'ixy="0" ixz="0" iyz="-0.5"/></inertial></link>'))
    found = [d for d in validate(path).diagnostics if d.code == "MK302"]
    assert found and {d.severity.value for d in found} == {"warning"}, found


def test_a_reversed_sdf_joint_range_is_a_warning_as_libsdformat_loads_it(tmp_path: Path,
                                                                         sdf_oracle: Path) -> None:  # noqa: F811
    """The SDF convert wrote from a URDF with lower 1 > upper -1 (a semantic fuzz mutant): libsdformat
    says "Valid.", and validate called the written file an error."""
    joint = ('<joint name="j" type="revolute"><parent>a</parent><child>b</child><axis><xyz>0 0 1</xyz>'
             "<limit><lower>1</lower><upper>-1</upper></limit></axis></joint>")
    path = tmp_path / "m.sdf"
    path.write_text(_sdf("1.9", f'<model name="m">{_LINK.format("a")}{_LINK.format("b")}{joint}</model>'))
    assert _libsdformat_accepts(sdf_oracle, path)
    found = [d for d in validate(path).diagnostics if d.code == "MK307"]
    assert [d.severity.value for d in found] == ["warning"], found
    assert "libsdformat" in found[0].message
    assert not [d for d in validate(path).diagnostics if d.severity.value == "error"]


def test_a_reversed_mjcf_joint_range_stays_an_error_as_mujoco_refuses_it(tmp_path: Path) -> None:
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><worldbody><body><joint name="j" range="1 -1" limited="true"/>'
                    '<geom size="0.1"/></body></worldbody></mujoco>')
    with pytest.raises(ValueError, match="range"):
        mujoco.MjModel.from_xml_path(str(path))
    found = [d for d in validate(path).diagnostics if d.code == "MK307"]
    assert [d.severity.value for d in found] == ["error"], found


@pytest.mark.parametrize(("fragment", "tag", "attribute"), [
    ('<sensor name="s" type="imu"><plugin name="p"/></sensor>', "plugin", "filename"),
    ('<sensor name="s" type="imu"><plugin filename="libp.so"/></sensor>', "plugin", "name"),
    ('<light name="l"><diffuse>1 1 1 1</diffuse></light>', "light", "type"),
    ('<visual name="v"><geometry><box><size>1 1 1</size></box></geometry><material><shader/></material>'
     "</visual>", "shader", "type"),
    ('<sensor name="s" type="imu"><imu><angular_velocity><x><noise/></x></angular_velocity></imu></sensor>',
     "noise", "type"),
])
def test_a_missing_required_sdf_attribute_is_an_error_as_libsdformat_refuses_it(
    fragment: str, tag: str, attribute: str, tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """A semantic fuzz mutant of the lecture's unicycle: a `<plugin>` without `filename` passed validate
    and convert wrote an SDF libsdformat refused ("Required attribute[filename] in element[plugin] is not
    specified in SDF")."""
    path = tmp_path / "m.sdf"
    path.write_text(_sdf("1.9", f'<model name="m"><link name="a">{fragment}</link></model>'))
    assert not _libsdformat_accepts(sdf_oracle, path)
    found = [d for d in validate(path).diagnostics if d.code == "MK120" and d.severity.value == "error"]
    assert [d.message.split(";")[0] for d in found] == [f"<{tag}> has no {attribute} attribute"], found


def test_required_sdf_attributes_present_are_not_said(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    path = tmp_path / "m.sdf"
    path.write_text(_sdf("1.9", '<model name="m"><link name="a"><sensor name="s" type="imu">'
                                '<plugin name="p" filename="libp.so"/></sensor>'
                                '<light name="l" type="point"><diffuse>1 1 1 1</diffuse></light>'
                                "</link></model>"))
    assert _libsdformat_accepts(sdf_oracle, path)
    assert not [d for d in validate(path).diagnostics if d.code == "MK120"]


def test_every_six_number_target_gets_the_same_upper_triangle(tmp_path: Path) -> None:
    """An asymmetric nine-number .body inertia (MK301): the URDF writer wrote its upper triangle, the SDF
    and MJCF writers the average of the two halves, so one source gave two robots (a semantic-fuzz
    mutant of PA10 failed verify: each engine held another tensor, and Pinocchio refused the source's).
    ``convert`` now gives every six-number target the upper triangle; verify compares with it and says
    so; .body keeps the nine numbers as Choreonoid uses them."""
    from click.testing import CliRunner

    import modelkit
    from modelkit.cli import main
    from modelkit.verify.api import verify

    text = (TUTORIAL / "mobile_robot_primitive.body").read_text()
    wheel = """    inertia: [ 0.0012, 0,      0,
               0,      0.0023, 0,
               0,      0,      0.0012 ]
    material: Tire"""
    source = tmp_path / "wheel.body"
    source.write_text(text.replace(wheel, wheel.replace("0.0023, 0,", "0.0023, 0.0001,"), 1))
    assert _codes(validate(source), "warning") == ["MK301"]
    held = {}
    for suffix in ("urdf", "sdf", "xml", "body"):
        out = tmp_path / f"out.{suffix}"
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
        assert result.exit_code == 0, result.output
        (link,) = [link for link in modelkit.load(out).links if link.name == "LeftWheel"]
        assert link.inertial is not None
        held[suffix] = [[round(float(x), 12) for x in row] for row in link.inertial.inertia]
    upper = [[0.0012, 0.0, 0.0], [0.0, 0.0023, 0.0001], [0.0, 0.0001, 0.0012]]
    assert held["urdf"] == held["sdf"] == held["xml"] == upper, held
    assert held["body"] == [[0.0012, 0.0, 0.0], [0.0, 0.0023, 0.0001], [0.0, 0.0, 0.0012]]
    report = verify(source, tmp_path / "v", ("mujoco", "pinocchio", "drake"), configurations=2, samples=1,
                    replay=False, driven=False)
    assert report.failed == [], [c.detail for c in report.failed]
    assert any("LeftWheel is not symmetric (MK301" in s.reason for s in report.skips)
