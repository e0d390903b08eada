"""The Choreonoid body format, as modelkit reads and writes it (see :mod:`modelkit.formats.declaration`)."""

from modelkit.formats.declaration import ExtrasDeclaration, FormatDeclaration, OutputDeclaration

FORMAT = FormatDeclaration(
    name="body",
    description="Choreonoid body file (YAML), format 1.0 and 2.0",
    suffixes=(".body",),
    reader="modelkit.formats.body.reader:read_body",
    output=OutputDeclaration(
        writer="modelkit.formats.body.writer:write_body",
        suffix=".body",
        suffixes=(".body",),
        tracks_native=True,  # Choreonoid simulates pseudo continuous tracks (AISTSimulator)
        handles=frozenset({"gazebo", "mujoco"}),  # noted with the URDF's other blocks (_plugin_notes)
        spawn=("the root link's `translation` z = {z}, or that height for the body item in a Choreonoid "
               "project"),
        places_root=True,  # the root link's translation/rotation is the root pose
    ),
    extras=ExtrasDeclaration(
        quiet_link=frozenset({"is_continuous_track"}),
    ),
)
