"""xacro, as modelkit reads it: expanded to URDF (see :mod:`modelkit.formats.declaration`); never written."""

from modelkit.formats.declaration import FormatDeclaration

FORMAT = FormatDeclaration(
    name="xacro",
    description="xacro macro file, expanded to URDF (legacy xacro detected)",
    suffixes=(".xacro",),
    reader="modelkit.formats.xacro.reader:read_xacro",
)
