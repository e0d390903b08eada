"""SDFormat, as modelkit reads and writes it (see :mod:`modelkit.formats.declaration`)."""

from modelkit.formats.declaration import ExtrasDeclaration, FormatDeclaration, OutputDeclaration

FORMAT = FormatDeclaration(
    name="sdf",
    description="SDFormat 1.2-1.12 (models and worlds)",
    suffixes=(".sdf", ".world"),
    reader="modelkit.formats.sdf.reader:read_sdf",
    root_tags=("sdf",),
    output=OutputDeclaration(
        writer="modelkit.formats.sdf.writer:write_sdf",
        suffix=".sdf",
        suffixes=(".sdf",),
        handles=frozenset({"gazebo"}),  # a URDF's <gazebo> blocks: written or noted (write_self_collide)
    ),
    extras=ExtrasDeclaration(
        quiet=frozenset({"sdf_canonical_link", "sdf_version", "sdf_model_pose", "sdf_world_joint"}),
        quiet_link=frozenset({"sdf_link_pose"}),
        dropped=(
            ("sdf_world", "MK822", "the SDF world around the model"),
            ("sdf_plugins", "MK808", "SDF model plugins"),
        ),
        dropped_link=(
            ("sdf_plugins", "MK808", "SDF plugins of a visual or collision"),
            ("sdf_surface", "MK851", "SDF surface parameters other than friction"),
        ),
    ),
)
