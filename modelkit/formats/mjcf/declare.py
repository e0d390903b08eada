"""MJCF, as modelkit reads (through mujoco) and writes it; see :mod:`modelkit.formats.declaration`."""

from modelkit.formats.declaration import FormatDeclaration, OutputDeclaration

FORMAT = FormatDeclaration(
    name="mjcf",
    description="MuJoCo MJCF (read through mujoco)",
    suffixes=(".mjcf",),
    reader="modelkit.formats.mjcf.reader:read_mjcf",
    root_tags=("mujoco",),
    output=OutputDeclaration(
        writer="modelkit.formats.mjcf.writer:write_mjcf",
        suffix=".xml",
        suffixes=(".xml", ".mjcf"),
        auto_wheel="sphere",  # MuJoCo: a cylinder rolling on a plane gets odd contacts
        sites_native=True,
    ),
)
