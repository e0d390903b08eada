"""Generated serial chains and deep trees in every input format (issue 18 §2).

Every link has mass properties and a box visual; the joints alternate revolute (limited) and
continuous about y, each 0.1 m above its parent and turned 0.1 rad about z, so a chain of any length
is a valid model whose depth equals its link count. Used by the deep-model tests and by
``bench/bench_chain.py``.
"""

from __future__ import annotations

from pathlib import Path

FORMATS = ("urdf", "xacro", "sdf", "body", "mjcf")
SUFFIX = {"urdf": ".urdf", "xacro": ".urdf.xacro", "sdf": ".sdf", "body": ".body", "mjcf": ".xml"}


def _parents(links: int, branches: int) -> list[int]:
    """Parent index of every link but the first: ``branches`` chains of equal length from link 0."""
    if branches <= 1:
        return [i - 1 for i in range(1, links)]
    per = max(1, (links - 1) // branches)
    return [0 if (i - 1) % per == 0 else i - 1 for i in range(1, links)]


def urdf(links: int, branches: int = 1, xacro: bool = False, shape: str = "upright") -> str:
    """``shape``: "upright" (each joint 0.1 m above its parent), "lying" (0.1 m along x: every link on
    the floor, as for convert's base decision), "mimic" (upright, each joint mimicking the one before)."""
    head = '<robot name="chain"'
    out = [head + (' xmlns:xacro="http://www.ros.org/wiki/xacro">' if xacro else ">")]
    if xacro:
        out.append('<xacro:property name="step" value="0.1"/>')
    step = "${step}" if xacro else "0.1"
    for i in range(links):
        out.append(
            f'<link name="link{i}"><inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>'
            '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial>'
            '<visual><geometry><box size="0.05 0.05 0.1"/></geometry></visual></link>'
        )
    for i, parent in enumerate(_parents(links, branches), start=1):
        kind = "revolute" if i % 2 else "continuous"
        limit = '<limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>' if i % 2 else ""
        xyz = f"{step} 0 0" if shape == "lying" else f"0 0 {step}"
        mimic = f'<mimic joint="joint{i - 1}"/>' if shape == "mimic" and i > 1 else ""
        out.append(
            f'<joint name="joint{i}" type="{kind}"><parent link="link{parent}"/><child link="link{i}"/>'
            f'<origin xyz="{xyz}" rpy="0 0 0.1"/><axis xyz="0 1 0"/>{limit}{mimic}</joint>'
        )
    out.append("</robot>")
    return "\n".join(out) + "\n"


def sdf(links: int, branches: int = 1) -> str:
    out = ['<sdf version="1.9"><model name="chain">']
    parents = [-1, *_parents(links, branches)]
    for i in range(links):
        pose = "" if i == 0 else f'<pose relative_to="joint{i}"/>'
        out.append(
            f'<link name="link{i}">{pose}<inertial><pose>0 0 0.05 0 0 0</pose><mass>0.5</mass><inertia>'
            "<ixx>0.001</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.001</iyy><iyz>0</iyz><izz>0.0005</izz>"
            "</inertia></inertial><visual name=\"v\"><geometry><box><size>0.05 0.05 0.1</size></box>"
            "</geometry></visual></link>"
        )
        if i:
            kind = "revolute" if i % 2 else "continuous"
            limit = "<limit><lower>-1.5</lower><upper>1.5</upper></limit>" if i % 2 else ""
            out.append(
                f'<joint name="joint{i}" type="{kind}"><pose relative_to="link{parents[i]}">0 0 0.1 0 0 0.1'
                f"</pose><parent>link{parents[i]}</parent><child>link{i}</child>"
                f"<axis><xyz>0 1 0</xyz>{limit}</axis></joint>"
            )
    out.append("</model></sdf>")
    return "\n".join(out) + "\n"


def body(links: int, branches: int = 1) -> str:
    out = ["format: ChoreonoidBody", "format_version: 2.0", "angle_unit: degree", "name: chain",
           "root_link: link0", "links:"]
    parents = [-1, *_parents(links, branches)]
    for i in range(links):
        out.append(f"  - name: link{i}")
        if i:
            out += [f"    parent: link{parents[i]}", "    joint_type: revolute", f"    joint_id: {i - 1}",
                    "    joint_axis: [0, 1, 0]", "    translation: [0, 0, 0.1]",
                    "    rotation: [0, 0, 1, 5.73]"]
            if i % 2:
                out.append("    joint_range: [-86, 86]")
        else:
            out.append("    joint_type: fixed")
        out += ["    center_of_mass: [0, 0, 0.05]", "    mass: 0.5",
                "    inertia: [0.001, 0, 0, 0, 0.001, 0, 0, 0, 0.0005]", "    elements:",
                "      - type: Shape", "        geometry: { type: Box, size: [0.05, 0.05, 0.1] }"]
    return "\n".join(out) + "\n"


def mjcf(links: int, branches: int = 1) -> str:
    """Nested ``<body>`` elements: the XML itself is ``links`` deep."""
    children: dict[int, list[int]] = {}
    for i, parent in enumerate(_parents(links, branches), start=1):
        children.setdefault(parent, []).append(i)
    out = ['<mujoco model="chain"><compiler angle="radian"/><worldbody>']
    stack: list[tuple[int, bool]] = [(0, False)]
    while stack:
        i, done = stack.pop()
        if done:
            out.append("</body>")
            continue
        pos = "0 0 0" if i == 0 else "0 0 0.1"
        joint = ""
        if i:
            limit = ' range="-1.5 1.5"' if i % 2 else ""
            joint = f'<joint name="joint{i}" type="hinge" axis="0 1 0"{limit}/>'
        out.append(
            f'<body name="link{i}" pos="{pos}" euler="0 0 {0.1 if i else 0}">{joint}'
            '<inertial pos="0 0 0.05" mass="0.5" diaginertia="0.001 0.001 0.0005"/>'
            '<geom type="box" size="0.025 0.025 0.05" contype="0" conaffinity="0"/>'
        )
        stack.append((i, True))
        stack.extend((c, False) for c in reversed(children.get(i, [])))
    out.append("</worldbody></mujoco>")
    return "\n".join(out) + "\n"


def write(folder: Path, fmt: str, links: int, branches: int = 1, shape: str = "upright") -> Path:
    """Write the chain (or ``branches`` chains from one root) as ``fmt`` in ``folder``; ``shape`` as for
    :func:`urdf` (URDF only)."""
    if shape != "upright":
        path = folder / f"chain{links}_{shape}.urdf"
        path.write_text(urdf(links, branches, shape=shape))
        return path
    text = {
        "urdf": lambda: urdf(links, branches),
        "xacro": lambda: urdf(links, branches, xacro=True),
        "sdf": lambda: sdf(links, branches),
        "body": lambda: body(links, branches),
        "mjcf": lambda: mjcf(links, branches),
    }[fmt]()
    path = folder / f"chain{links}_{branches}{SUFFIX[fmt]}"
    path.write_text(text)
    return path
