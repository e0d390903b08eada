"""MJCF, as modelkit reads (through mujoco) and writes it; see :mod:`modelkit.formats.declaration`."""

from modelkit.formats.declaration import ExtrasDeclaration, FormatDeclaration, OutputDeclaration

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
        pair_exclusions_native=True,  # <contact><exclude>
    ),
    extras=ExtrasDeclaration(
        # mjcf_globals: <size>, <visual>, <statistic>: MuJoCo's memory, viewer and camera extent, nothing
        # of the robot another simulator misses (written back for MJCF only)
        quiet=frozenset({"mjcf_compiled", "mjcf_globals"}),
        quiet_link=frozenset({"mjcf_body_id", "mjcf_body_offset", "mjcf_intermediate_of"}),
        partly_carried=frozenset(
            {"mjcf_actuators", "mjcf_sensors", "mjcf_cameras", "mjcf_lights", "mjcf_sites", "mjcf_equalities"}
        ),
        dropped=(
            ("mjcf_actuators", "MK808", "MJCF actuators"),
            ("mjcf_tendons", "MK808", "MJCF tendons"),
            ("mjcf_equalities", "MK808", "MJCF equality constraints"),
            ("mjcf_sensors", "MK806", "MJCF sensors"),
            ("mjcf_cameras", "MK806", "MJCF cameras"),
            ("mjcf_lights", "MK806", "MJCF lights"),
            ("mjcf_sites", "MK808", "MJCF sites (named frames)"),
            ("mjcf_keyframes", "MK820", "MJCF keyframes (stored joint positions)"),
            ("mjcf_world_geoms", "MK822", "MJCF world geoms"),
            ("mjcf_world_sites", "MK822", "MJCF world sites"),
            ("mjcf_option", "MK853", "MJCF simulator options (<option>)"),
            ("mjcf_contact_pairs", "MK851", "MJCF contact pairs and exclusions (<contact>)"),
        ),
        dropped_link=(
            ("mjcf_contact", "MK851",
             "MJCF contact (and fluid) parameters beyond the friction the target holds"),
            ("mjcf_mocap", "MK808", "MJCF mocap flag, a body the program moves (mocap_pos, mocap_quat)"),
            ("mjcf_body_physics", "MK808", "MJCF gravity compensation"),
        ),
        dropped_joint=(
            ("mjcf_ball_range", "MK820", "the ball joint's cone limit (MJCF range, radians)"),
            ("mjcf_joint_physics", "MK820", "MJCF joint solver parameters"),
        ),
        # the kept lists in part carried by the model's canonical actuators and devices: .carried gives
        # what the other targets still leave out, for their notes
        carried_to=tuple(
            (key, ("urdf", "sdf", "body"), f"modelkit.formats.mjcf.carried:{left}")
            for key, left in (("mjcf_actuators", "actuators_left"), ("mjcf_sensors", "sensors_left"),
                              ("mjcf_cameras", "on_links_left"), ("mjcf_lights", "on_links_left"),
                              ("mjcf_sites", "sites_left"), ("mjcf_equalities", "equalities_left"))
        ),
    ),
)
