"""URDF, as modelkit reads and writes it (see :mod:`modelkit.formats.declaration`)."""

from modelkit.formats.declaration import ExtrasDeclaration, FormatDeclaration, OutputDeclaration

FORMAT = FormatDeclaration(
    name="urdf",
    description="URDF 1.0-1.2",
    suffixes=(".urdf",),
    reader="modelkit.formats.urdf.reader:read_urdf",
    root_tags=("robot",),
    output=OutputDeclaration(
        writer="modelkit.formats.urdf.writer:write_urdf",
        suffix=".urdf",
        suffixes=(".urdf",),
        auto_wheel="sphere",  # PyBullet loads URDF: a cylinder rolling on a plane gets odd contacts there
    ),
    extras=ExtrasDeclaration(
        dropped_link=(
            ("urdf_contact", "MK851", "PyBullet <contact> parameters other than friction"),
        ),
    ),
)
