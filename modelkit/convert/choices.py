"""The values convert's options may take: data only, so that the CLI builds its choices at startup
without creating :class:`modelkit.convert.options.WriteOptions` (a frozen dataclass: about 2 ms)."""

from __future__ import annotations

SDF_VERSIONS = ("1.6", "1.7", "1.8", "1.9", "1.10", "1.11")
MESH_FORMATS = ("stl", "obj")
ACTUATOR_CHOICES = ("auto", "motor", "position", "velocity", "none")  # where the source has no actuators
# the source's own actuators: written, except ROS effort interfaces, which get the --actuators choice
# (auto); all written (keep); all set aside for the --actuators choice (replace)
SOURCE_ACTUATORS = ("auto", "keep", "replace")
GAZEBO_CHOICES = ("auto", "classic", "sim")  # convert.gazebo says what each means
WHEEL_COLLISIONS = ("auto", "cylinder", "sphere", "ellipsoid")  # convert.wheels says what each means
SUPPORT_CONTACTS = ("compliant", "rigid")  # convert.contact_compliance says what each means
