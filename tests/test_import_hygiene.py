"""`modelkit validate` and `modelkit tree` must not import the simulators (mujoco, pybullet), nor
the mesh stack (trimesh) for a model that has no mesh files.

An MJCF file is compiled by MuJoCo, through its C library called directly (``modelkit.formats.mjcf.native``):
a file that compiles imports neither the mujoco bindings nor numpy; one that does not falls back to the
bindings (they report the error and read the uncompiled spec). pybullet is never imported, and other XML
files (a URDF named ``.xml``, told apart by its top element) do not touch MuJoCo.

Each command runs in a fresh interpreter (the test process has imported who knows what). The
child puts a recording finder first on ``sys.meta_path`` before importing modelkit, so an import
*attempt* is caught even where the package is not installed (as in CI, where a guarded
``try: import mujoco`` would otherwise leave no trace in ``sys.modules``); it then runs the
command through ``click.testing.CliRunner`` and reports the exit code, the output, the modules
loaded and the attempts as JSON.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

from modelkit.formats.registry import FORMAT_NAMES

from .conftest import PENDULUM_BODY

PROJECT_ROOT = Path(__file__).resolve().parents[1]
CORPUS = PROJECT_ROOT.parent / "shared" / "corpus"
PENDULUM = CORPUS / "choreonoid" / "share" / "model" / "misc" / "pendulum.body"

SIMULATORS = ("mujoco", "pybullet")
MESH_STACK = ("trimesh",)

# Used when the shared corpus is not next to the checkout (CI): no mesh files.
FALLBACK_BODY = PENDULUM_BODY

CHILD = textwrap.dedent("""\
    import json
    import sys

    WATCHED = set(sys.argv[1].split(","))
    attempted = []


    class Recorder:
        @staticmethod
        def find_spec(fullname, path=None, target=None):
            if fullname.partition(".")[0] in WATCHED:
                attempted.append(fullname)
            return None  # let the real finders decide


    sys.meta_path.insert(0, Recorder)

    from click.testing import CliRunner

    from modelkit.cli import main

    result = CliRunner().invoke(main, sys.argv[2:], catch_exceptions=True)
    json.dump({
        "exit_code": result.exit_code,
        "output": result.output,
        "exception": None if result.exception is None or isinstance(result.exception, SystemExit)
        else repr(result.exception),
        "modules": sorted(sys.modules),
        "attempted": sorted(set(attempted)),
    }, sys.stdout)
""")


def _run(args: list[str], watched: tuple[str, ...]) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-c", CHILD, ",".join(watched), *args],
                          cwd=PROJECT_ROOT, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          check=False, timeout=300)
    assert done.returncode == 0, f"child failed:\n{done.stdout}\n{done.stderr}"
    report: dict[str, Any] = json.loads(done.stdout)
    assert report["exception"] is None, report["exception"]
    return report


@pytest.fixture(scope="module")
def small_model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """pendulum.body from the corpus: two links, box shapes, no mesh files."""
    if PENDULUM.is_file():
        return PENDULUM
    path = tmp_path_factory.mktemp("hygiene") / "pendulum.body"
    path.write_text(FALLBACK_BODY)
    return path


@pytest.mark.parametrize("command", [["validate"], ["validate", "--no-resources"], ["tree"]],
                         ids=["validate", "validate-no-resources", "tree"])
def test_no_simulator_or_mesh_stack_for_a_model_without_meshes(command: list[str], small_model: Path) -> None:
    watched = SIMULATORS + MESH_STACK
    report = _run([*command, str(small_model)], watched)
    assert report["exit_code"] == 0, report["output"]
    # The check itself works: modelkit ran in this interpreter.
    assert "modelkit.cli" in report["modules"]
    assert "modelkit.formats.body.reader" in report["modules"]
    loaded = [m for m in report["modules"] if m.partition(".")[0] in watched]
    assert loaded == [], f"`modelkit {' '.join(command)}` imported {loaded}"
    assert report["attempted"] == [], f"`modelkit {' '.join(command)}` tried to import {report['attempted']}"


def test_no_simulator_for_the_whole_corpus() -> None:
    """Models with meshes may load trimesh, never a simulator."""
    files = sorted(str(p) for p in CORPUS.rglob("*.body")) if CORPUS.is_dir() else []
    if not files:
        pytest.skip(f"no .body files under {CORPUS}")
    report = _run(["validate", *files], SIMULATORS)
    assert report["exit_code"] in (0, 1), report["output"]
    loaded = [m for m in report["modules"] if m.partition(".")[0] in SIMULATORS]
    assert loaded == [], f"`modelkit validate` imported {loaded}"
    assert report["attempted"] == [], f"`modelkit validate` tried to import {report['attempted']}"


MJCF_MODEL = PROJECT_ROOT / "tests" / "mjcf" / "pendulum.xml"
URDF_AS_XML = """\
<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>
"""


@pytest.mark.parametrize("command", [["validate"], ["tree"]], ids=["validate", "tree"])
def test_mjcf_input_is_read_through_mujocos_library_not_its_bindings(command: list[str]) -> None:
    """An MJCF file is compiled by MuJoCo's C library, called directly (``formats.mjcf.native``): neither
    the mujoco bindings nor numpy are imported for a file that compiles; pybullet never."""
    report = _run([*command, str(MJCF_MODEL)], (*SIMULATORS, "numpy"))
    assert report["exit_code"] == 0, report["output"]
    assert "modelkit.formats.mjcf.native" in report["modules"]
    assert [m for m in report["modules"] if m.partition(".")[0] in ("mujoco", "numpy")] == []
    assert [m for m in report["modules"] if m.partition(".")[0] == "pybullet"] == []
    assert [m for m in report["attempted"] if m.partition(".")[0] == "pybullet"] == []


def test_other_xml_input_does_not_import_mujoco(tmp_path: Path) -> None:
    """Telling MJCF from URDF in a ``.xml`` file reads its top element, not mujoco."""
    path = tmp_path / "robot.xml"
    path.write_text(URDF_AS_XML)
    report = _run(["tree", str(path)], SIMULATORS)
    assert "modelkit.cli" in report["modules"]
    mjcf = [m for m in report["modules"] if m.startswith("modelkit.formats.mjcf")]
    assert mjcf == ["modelkit.formats.mjcf", "modelkit.formats.mjcf.declare"], mjcf  # the declaration only
    loaded = [m for m in report["modules"] if m.partition(".")[0] in SIMULATORS]
    assert loaded == [] and report["attempted"] == []


@pytest.mark.parametrize("suffix", [".urdf", ".sdf", ".body", ".xml"])
def test_convert_imports_no_simulator_but_mujoco_for_mjcf(suffix: str, tmp_path: Path) -> None:
    """`convert` never imports pybullet (nor pinocchio or drake); mujoco only for MJCF in or out."""
    source = tmp_path / "pendulum.body"
    source.write_text(FALLBACK_BODY)
    watched = (*SIMULATORS, "pinocchio", "pydrake")
    report = _run(["convert", str(source), "-o", str(tmp_path / "out" / f"pendulum{suffix}")], watched)
    assert report["exit_code"] == 0, report["output"]
    assert "modelkit.convert.api" in report["modules"]
    allowed = {"mujoco"} if suffix == ".xml" else set()
    loaded = {m.partition(".")[0] for m in report["modules"]} & set(watched)
    attempted = {m.partition(".")[0] for m in report["attempted"]}
    assert loaded <= allowed and attempted <= allowed, (loaded, attempted)


def test_cli_import_and_help_load_no_numpy_and_no_reader() -> None:
    """`import modelkit.cli` (and `modelkit --help`) loads click and the code catalogue only: numpy,
    the readers, yaml, lxml and jsonschema are imported when a file needs them."""
    heavy = ("numpy", "yaml", "lxml", "jsonschema", "trimesh", "mujoco", "pybullet", "pinocchio")
    report = _run(["--help"], heavy)
    assert report["exit_code"] == 0, report["output"]
    loaded = sorted({m.partition(".")[0] for m in report["modules"]} & set(heavy))
    assert loaded == [], f"`modelkit --help` imported {loaded}"
    # Of the formats, only their declarations (data): each format's package (its __init__ imports nothing)
    # and its declare.py, the declaration class and the registry; no reader, writer or shared module.
    declarations = {"modelkit.formats", "modelkit.formats.declaration", "modelkit.formats.registry"}
    declarations |= {f"modelkit.formats.{name}{tail}" for name in FORMAT_NAMES for tail in ("", ".declare")}
    beyond = [m for m in report["modules"] if m.startswith("modelkit.formats") and m not in declarations]
    assert beyond == [] and "modelkit.api" not in report["modules"], beyond


SMALL_URDF = """\
<robot name="r">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0.1" rpy="0 0.1 0"/><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <visual><origin xyz="0 0 0.1" rpy="0.1 0.2 0.3"/><geometry><box size="0.1 0.2 0.3"/></geometry>
      <material name="blue"/></visual>
    <collision><geometry><cylinder radius="0.1" length="0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><geometry><sphere radius="0.05"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.3" rpy="0 0 1.57"/><axis xyz="0 1 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""
SMALL_XACRO = """\
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="m" value="0.5"/>
  <xacro:macro name="limb" params="name">
    <link name="${name}">
      <inertial><mass value="${m}"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
      <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
    </link>
  </xacro:macro>
  <xacro:limb name="base"/>
  <xacro:limb name="arm"/>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 ${m}" rpy="0 0 0.5"/><axis xyz="1 0 0"/></joint>
</robot>
"""
SMALL_SDF = """\
<sdf version="1.9">
  <model name="r">
    <link name="base">
      <pose>0 0 0.1 0 0 0.3</pose>
      <inertial><pose>0 0 0.05 0.1 0 0</pose><mass>1</mass>
        <inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>
      <visual name="v"><geometry><box><size>0.1 0.2 0.3</size></box></geometry>
        <material><diffuse>0 0 1 1</diffuse><ambient>0 0 0.5 1</ambient></material></visual>
      <collision name="c"><pose>0 0 0.1 0 0 0</pose><geometry><sphere><radius>0.1</radius></sphere></geometry>
      </collision>
    </link>
    <link name="arm">
      <pose relative_to="j">0 0 0 0 0 0</pose>
      <inertial><mass>0.5</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
    </link>
    <joint name="j" type="revolute"><pose relative_to="base">0 0 0.3 0 0 1.57</pose>
      <parent>base</parent><child>arm</child>
      <axis><xyz expressed_in="base">0 1 0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis>
    </joint>
  </model>
</sdf>
"""


@pytest.mark.parametrize(("name", "text"), [("r.urdf", SMALL_URDF), ("r.urdf.xacro", SMALL_XACRO),
                                            ("r.sdf", SMALL_SDF)], ids=["urdf", "xacro", "sdf"])
@pytest.mark.parametrize("command", [["validate"], ["tree"]], ids=["validate", "tree"])
def test_small_urdf_xacro_sdf_without_numpy(name: str, text: str, command: list[str], tmp_path: Path) -> None:
    """Start-up (issue 9 §3): the readers and the rules build and judge the model with plain tuples
    (modelkit.rot3); numpy (3× the interpreter's start-up by itself) is for meshes, writers and verify."""
    path = tmp_path / name
    path.write_text(text)
    report = _run([*command, str(path)], ("numpy",))
    assert report["exit_code"] == 0, report["output"]
    assert "modelkit.checks.physics" in report["modules"] or command == ["tree"]
    assert any(m.startswith("modelkit.formats.") and m.endswith(".reader") for m in report["modules"])
    loaded = [m for m in report["modules"] if m.partition(".")[0] == "numpy"]
    assert loaded == [], f"`modelkit {command[0]} {name}` imported numpy"


def test_valid_body_file_does_not_import_jsonschema(small_model: Path) -> None:
    """A valid .body document is decided by the compiled schema check; jsonschema only explains errors."""
    report = _run(["validate", str(small_model)], ("jsonschema",))
    assert report["exit_code"] == 0, report["output"]
    assert "modelkit.formats.body.schema" in report["modules"]
    assert [m for m in report["modules"] if m.partition(".")[0] == "jsonschema"] == []


PRIMITIVE_BODY = PROJECT_ROOT / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model" / \
    "mobile_robot_primitive.body"


@pytest.mark.parametrize("which", ["pendulum", "primitive"])
@pytest.mark.parametrize("command", [["validate"], ["tree"]], ids=["validate", "tree"])
def test_small_body_without_numpy(which: str, command: list[str], small_model: Path) -> None:
    """Start-up (issue 9 §3): the `.body` reader composes its transforms with plain tuples
    (modelkit.rot3); a file of primitives (boxes, cylinders, a material colour) imports neither numpy
    nor lxml. Meshes and generated geometry (Extrusion ...) import numpy when a file has them."""
    path = small_model if which == "pendulum" else PRIMITIVE_BODY
    report = _run([*command, str(path)], ("numpy", "lxml"))
    assert report["exit_code"] == 0, report["output"]
    assert "modelkit.formats.body.reader" in report["modules"]
    assert "modelkit.checks.physics" in report["modules"] or command == ["tree"]
    loaded = sorted({m.partition(".")[0] for m in report["modules"]} & {"numpy", "lxml"})
    assert loaded == [], f"`modelkit {command[0]} {path.name}` imported {loaded}"
