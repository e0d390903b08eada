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
        walks_extras=True,
        spawn=("ros_gz_sim's `create -z {z}` (Gazebo), gazebo_ros's `spawn_entity.py -z {z}` (Gazebo "
               "classic), `loadURDF(..., basePosition=[0, 0, {z}])` (PyBullet)"),
    ),
    extras=ExtrasDeclaration(
        # the version is bookkeeping; the named materials, transmissions and <ros2_control> are kept for
        # writing URDF back, while the model's own fields (colours, actuators) carry them to other targets
        quiet=frozenset({"urdf_version", "materials", "transmissions", "ros2_control"}),
        dropped=(
            ("gazebo", "MK808", "the robot's <gazebo> blocks"),
            ("mujoco", "MK808", "MuJoCo's URDF extension (<mujoco>)"),
            ("sensor", "MK806", "urdfdom <sensor> elements"),
        ),
        dropped_link=(
            ("urdf_contact", "MK851", "PyBullet <contact> parameters other than friction"),
            ("gazebo", "MK808", "<gazebo> block"),
        ),
        dropped_joint=(
            ("safety_controller", "MK820", "<safety_controller> (soft limits and their gains)"),
            ("calibration", "MK820", "<calibration>"),
            ("gazebo", "MK808", "<gazebo> block"),
        ),
    ),
)
