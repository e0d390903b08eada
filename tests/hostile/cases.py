"""Deterministic hostile cases for the fuzz test: seeds in every format, mutated (seeded).

Classes: truncations, byte flips, non-finite and absurd numbers, bad encodings, bad names, cycles,
repetition bombs, and special files (FIFOs, symlink loops, folders, device links).
"""

from __future__ import annotations

import os
import random
import re
from pathlib import Path

SEEDS: dict[str, str] = {
    "urdf": (
        '<?xml version="1.0"?>\n<robot name="r">\n'
        '  <link name="base"><inertial><mass value="1.5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" '
        'iyz="0" izz="0.1"/></inertial>\n'
        '    <visual><origin xyz="0 0 0.1" rpy="0 0 1.57"/><geometry><box size="0.2 0.3 0.4"/></geometry>'
        "</visual></link>\n"
        '  <link name="arm"><collision><geometry><cylinder radius="0.05" length="0.5"/></geometry>'
        "</collision></link>\n"
        '  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>'
        '<origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="-1.5" upper="1.5" effort="10" '
        'velocity="2"/></joint>\n</robot>\n'
    ),
    "xacro": (
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:property name="w" value="0.25"/>\n'
        '  <xacro:macro name="leg" params="n x"><link name="leg_${n}"><visual><geometry>'
        '<box size="${w} ${x*2} 0.1"/></geometry></visual></link>\n'
        '  <joint name="j_${n}" type="fixed"><parent link="base"/><child link="leg_${n}"/></joint>'
        "</xacro:macro>\n"
        '  <link name="base"/>\n  <xacro:leg n="a" x="1"/>\n  <xacro:leg n="b" x="${w*4}"/>\n</robot>\n'
    ),
    "sdf": (
        '<?xml version="1.0"?>\n<sdf version="1.9">\n<model name="m">\n'
        '  <link name="a"><pose>0 0 0.5 0 0 0</pose><inertial><mass>2</mass><inertia><ixx>0.1</ixx>'
        "<iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>\n"
        '    <collision name="c"><geometry><sphere><radius>0.3</radius></sphere></geometry></collision>'
        "</link>\n"
        '  <link name="b"><pose relative_to="a">0 0 1 0 0 0</pose></link>\n'
        '  <joint name="j" type="revolute"><parent>a</parent><child>b</child><axis><xyz>0 1 0</xyz>'
        "<limit><lower>-1</lower><upper>1</upper></limit></axis></joint>\n</model>\n</sdf>\n"
    ),
    "mjcf": (
        '<mujoco model="m">\n  <option timestep="0.002"/>\n  <worldbody>\n'
        '    <body name="a" pos="0 0 1"><joint name="h" type="hinge" axis="0 1 0" range="-1 1"/>'
        '<geom type="capsule" size="0.05 0.2" mass="1"/>\n'
        '      <body name="b" pos="0 0 0.4"><joint name="s" type="slide" axis="1 0 0"/>'
        '<geom type="box" size="0.1 0.1 0.1"/></body>\n'
        "    </body>\n  </worldbody>\n</mujoco>\n"
    ),
    "body": (
        "format: ChoreonoidBody\nformat_version: 2.0\nangle_unit: degree\nname: r\nroot_link: base\n"
        "links:\n  - name: base\n    jointType: free\n    mass: 2.0\n    centerOfMass: [0, 0, 0.1]\n"
        "    inertia: [0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1]\n    elements:\n"
        "      - type: Shape\n        geometry: {type: Box, size: [0.2, 0.3, 0.4]}\n"
        "  - name: arm\n    parent: base\n    jointType: revolute\n    jointAxis: Z\n"
        "    jointRange: [-90, 90]\n    translation: [0, 0, 0.3]\n    rotation: [0, 0, 1, 45]\n"
        "    mass: 0.5\n    elements:\n      - type: Shape\n"
        "        geometry: {type: Cylinder, radius: 0.05, height: 0.4}\n"
    ),
}
SUFFIX = {"urdf": ".urdf", "xacro": ".xacro", "sdf": ".sdf", "mjcf": ".xml", "body": ".body"}
BAD_NUMBERS = ("1e400", "-1e400", "nan", "inf", "-inf", "NaN", "1e-400", "0x10", "1_000", "", "9" * 400)
BAD_NAMES = ("", " ", "a::b", "world", "__model__", "é\u202e", "a\x01b", "x" * 5000, "&amp;", "${x}")
_NUMBER = re.compile(rb"-?\d+\.?\d*")
_NAME = re.compile(rb'(name="|name: )([^"\n]*)')


def _mutations(fmt: str, seed: bytes, rng: random.Random) -> list[tuple[str, bytes]]:
    out: list[tuple[str, bytes]] = []
    numbers = list(_NUMBER.finditer(seed))
    for i in range(60):
        cut = rng.randrange(1, len(seed))
        out.append((f"truncate{i}", seed[:cut]))
    for i in range(100):
        data = bytearray(seed)
        for _ in range(rng.randint(1, 4)):
            data[rng.randrange(len(data))] = rng.randrange(256)
        out.append((f"flip{i}", bytes(data)))
    for i, bad in enumerate(BAD_NUMBERS):
        match = rng.choice(numbers)
        out.append((f"number{i}", seed[: match.start()] + bad.encode() + seed[match.end() :]))
        everywhere = _NUMBER.sub(bad.encode() or b"x", seed)
        out.append((f"numbers{i}", everywhere))
    for i, bad in enumerate(BAD_NAMES):
        found = _NAME.search(seed)
        assert found is not None
        out.append((f"name{i}", seed[: found.start(2)] + bad.encode() + seed[found.end(2) :]))
    out.append(("latin1", seed.replace(b"r", "\xe9".encode("latin-1"), 3)))
    out.append(("utf16_no_bom", seed.decode().encode("utf-16-le")))
    out.append(("utf16_bom", seed.decode().encode("utf-16")))
    out.append(("nul", seed[:20] + b"\x00" + seed[20:]))
    out.append(("empty", b""))
    out.append(("blank", b"   \n\n"))
    out.append(("binary", bytes(rng.randrange(256) for _ in range(512))))
    out.append(("duplicate_all", seed + seed))
    middle = len(seed) // 2
    out.append(("repeat_middle", seed[:middle] + seed[middle - 40 : middle] * 2000 + seed[middle:]))
    out.append(("deep", seed[:middle] + (b"<a>" * 3000 if fmt != "body" else b"[" * 3000) + seed[middle:]))
    return out


EXTRA: dict[str, list[tuple[str, str]]] = {
    "urdf": [
        (
            "cycle",
            '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
            '<parent link="a"/><child link="b"/></joint><joint name="k" type="fixed"><parent link="b"/>'
            '<child link="a"/></joint></robot>',
        ),
        ("entity", '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]><robot name="&b;"/>'),
        ("external", '<!DOCTYPE r SYSTEM "file:///etc/passwd"><robot name="r"><link name="a"/></robot>'),
    ],
    "sdf": [
        (
            "cycle",
            '<sdf version="1.9"><model name="m"><link name="a"/><link name="b"/>'
            '<joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>'
            '<joint name="k" type="fixed"><parent>b</parent><child>a</child></joint></model></sdf>',
        ),
        (
            "pose_cycle",
            '<sdf version="1.9"><model name="m"><link name="a"><pose relative_to="b"/></link>'
            '<link name="b"><pose relative_to="a"/></link></model></sdf>',
        ),
        (
            "frame_chain",
            '<sdf version="1.9"><model name="m"><link name="a"/>'
            + "".join(f'<frame name="f{i}" attached_to="{f"f{i - 1}" if i else "a"}"/>' for i in range(5000))
            + "</model></sdf>",
        ),
        (
            "attributes",
            '<sdf version="1.9"><model name="m"><link name="a" '
            + " ".join(f'a{i}="1"' for i in range(100_000))
            + "/></model></sdf>",
        ),
        ("empty_mass", '<sdf version="1.9"><model name="m"><link name="a"><inertial><mass></mass></inertial>'
                       "</link></model></sdf>"),
        (
            "include_self",
            '<sdf version="1.9"><world name="w"><include><uri>case.sdf</uri></include></world></sdf>',
        ),
    ],
    "xacro": [
        (
            "recursion",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="m">'
            "<xacro:m/></xacro:macro><xacro:m/></robot>",
        ),
        (
            "pow",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${9**9**9}"/></robot>',
        ),
        (
            "power_tower",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            '<link name="${9**9**9**9}"/></robot>',
        ),
        (
            "include_twice_self",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            '<xacro:include filename="case.xacro"/><xacro:include filename="case.xacro"/></robot>',
        ),
        (
            "passwd",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
            '<xacro:include filename="/etc/passwd"/></robot>',
        ),
        (
            "yaml",
            '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="'
            "${xacro.load_yaml('/etc/hostname')}\"/></robot>",
        ),
    ],
    "mjcf": [
        (
            "replicate",
            '<mujoco><worldbody><replicate count="100000"><replicate count="100000"><body>'
            '<geom size="1"/></body></replicate></replicate></worldbody></mujoco>',
        ),
        (
            "timestep",
            '<mujoco><option timestep="-1"/><worldbody><body><geom size="nan"/></body></worldbody></mujoco>',
        ),
        (
            "hfield",
            '<mujoco><asset><hfield name="h" nrow="99999" ncol="99999" size="1 1 1 1"/></asset>'
            "<worldbody/></mujoco>",
        ),
        ("size_nkey", '<mujoco><size nkey="100000000"/><worldbody><body><joint/><geom size="1"/></body>'
                      "</worldbody></mujoco>"),
        ("size_nuserdata", '<mujoco><size nuserdata="1000000000"/><worldbody/></mujoco>'),
    ],
    "body": [
        (
            "alias_bomb",
            "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
            "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
            "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
            "g: [*f, *f, *f, *f, *f, *f, *f, *f, *f]\n",
        ),
        ("recursive_alias", "a: &a [*a]\n"),
        (
            "nan_pose",
            "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: r\n"
            "    translation: [nan, inf, -inf]\n    mass: 1e400\n    jointAxis: [NaN, 0, 1]\n",
        ),
        (
            "cycle",
            "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: r\n"
            "  - name: a\n    parent: b\n  - name: b\n    parent: a\n",
        ),
        (
            "sub_body_self",
            "format: ChoreonoidBody\nformat_version: 2.0\nname: r\nlinks:\n  - name: r\n"
            "  - type: SubBody\n    uri: case.body\n    parent: r\n",
        ),
    ],
}
SPECIAL = ("fifo", "loop", "folder", "dev_zero")


def make_cases(root: Path, seed: int = 9) -> list[Path]:
    """Write every case into its own folder under ``root``; return the model files, in order."""
    rng = random.Random(seed)
    cases: list[tuple[str, str, bytes | str]] = []
    for fmt, text in SEEDS.items():
        cases.append((fmt, "seed", text.encode()))
        cases.extend((fmt, name, data) for name, data in _mutations(fmt, text.encode(), rng))
        cases.extend((fmt, name, data.encode()) for name, data in EXTRA.get(fmt, []))
        cases.extend((fmt, f"special_{kind}", kind) for kind in SPECIAL)
    paths = []
    for index, (fmt, name, data) in enumerate(cases):
        folder = root / f"{index:04d}_{fmt}_{name}"
        folder.mkdir(parents=True)
        path = folder / f"case{SUFFIX[fmt]}"
        if isinstance(data, bytes):
            path.write_bytes(data)
        elif data == "fifo":
            os.mkfifo(path)
        elif data == "loop":
            path.symlink_to(path.name)
        elif data == "folder":
            path.mkdir()
        else:
            path.symlink_to("/dev/zero")
        paths.append(path)
    return paths
