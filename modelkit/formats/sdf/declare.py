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
        frames_native=True,
        handles=frozenset({"gazebo"}),  # a URDF's <gazebo> blocks: written or noted (write_self_collide)
        handles_joint=frozenset({"gazebo"}),  # a URDF joint's: written as libsdformat does, or noted
        spawn=("a model <pose> (or an <include>'s <pose> in a world) at z = {z}, or ros_gz_sim's "
               "`create -z {z}`"),
        places_root=True,  # the model <pose> is the root pose
    ),
    extras=ExtrasDeclaration(
        quiet=frozenset({"sdf_canonical_link", "sdf_version", "sdf_model_pose", "sdf_world_joint"}),
        quiet_link=frozenset({"sdf_link_pose"}),
        dropped=(
            ("sdf_world", "MK822", "the SDF world around the model"),
            ("sdf_plugins", "MK808", "SDF model plugins"),
            ("sdf_model_elements", "MK808", "SDF model flags"),
        ),
        dropped_link=(
            ("sdf_plugins", "MK808", "SDF plugins of a visual or collision"),
            ("sdf_surface", "MK851", "SDF surface parameters other than friction"),
            ("sdf_link", "MK808", "SDF link flags"),
            ("sdf_other", "MK808", "SDF link elements kept only as data by validate's MK155"),
            ("sdf_shape_elements", "MK808", "SDF visual and collision elements"),
            ("sdf_materials", "MK818", "SDF material elements beyond the colours"),
        ),
        dropped_joint=(
            ("sdf_joint_elements", "MK820", "SDF joint solver parameters"),
            ("sdf_limit_elements", "MK820", "SDF joint stop parameters"),
        ),
        # an SDF link's flags at SDFormat's defaults say nothing a target misses
        defaults=(("sdf_link", (("gravity", True), ("kinematic", False), ("enable_wind", False),
                                ("must_be_base_link", False))),),
        # written into a URDF's <gazebo> blocks, which libsdformat copies back (formats/sdf/gazebo_blocks)
        carried_to=(("sdf_link", ("urdf",), ""), ("sdf_other", ("urdf",), ""),
                    ("sdf_model_elements", ("urdf",), ""), ("sdf_joint_elements", ("urdf",), ""),
                    ("sdf_materials", ("urdf",), "modelkit.formats.sdf.gazebo_blocks:materials_left"),
                    ("sdf_shape_elements", ("urdf",), "modelkit.formats.sdf.gazebo_blocks:shapes_left")),
    ),
)
