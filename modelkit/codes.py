"""The catalogue of diagnostic codes: stable ids, names, default severities, one-line summaries.

This table is data. ``docs/codes.md`` is generated from it (``python -m modelkit.codes``) and a test
checks that the two agree, so a code is documented the moment it exists. Codes are never reused or
renumbered; retired codes stay in the table marked ``retired``.

Ranges: MK0xx file and YAML layer; MK1xx schema and document header; MK2xx kinematic tree;
MK3xx mass properties, joints and transforms; MK4xx geometry; MK5xx resources and materials;
MK6xx devices and scene nodes; MK7xx xacro expansion; MK8xx conversion notes (what a writer
approximated, renamed, dropped or synthesised; MK850-MK889 one block per writer, MK89x the convert
command's own refusals).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class CodeInfo:
    code: str
    name: str
    severity: str  # "error" | "warning" | "info"
    summary: str
    retired: bool = False


_TABLE: tuple[CodeInfo, ...] = (
    # -- MK0xx: reading the file --------------------------------------------------------------
    CodeInfo("MK001", "file-unreadable", "error", "The file does not exist or cannot be read."),
    CodeInfo("MK002", "file-too-large", "error", "The file is larger than the size limit (`--max-bytes`)."),
    CodeInfo(
        "MK003", "not-text", "error", "The file is not UTF-8/UTF-16 text (binary data or a bad encoding)."
    ),
    CodeInfo("MK004", "empty-document", "error", "The file contains no YAML document."),
    CodeInfo(
        "MK005",
        "model-too-large",
        "error",
        "A model has more links or joints than the limit (`--max-links`); it is not read further.",
    ),
    CodeInfo(
        "MK006",
        "list-too-long",
        "error",
        "A YAML list has more items than the limit (`--max-list-items`); the document is refused.",
    ),
    CodeInfo(
        "MK007",
        "mjcf-size-too-large",
        "error",
        "An MJCF `<size>` count (`nkey`, `nuserdata`, `nuser_*`) is over modelkit's cap; refused before "
        "MuJoCo compiles (MuJoCo would build or allocate every one).",
    ),
    CodeInfo(
        "MK008",
        "xacro-include-work",
        "error",
        "xacro includes and `load_yaml` files processed for one file (each inclusion or load of the same "
        "file counted) pass 2,000, or the text they add passes `--max-bytes`: an include diamond, a load "
        "in a loop; refused where the next include or load stands.",
    ),
    CodeInfo(
        "MK009",
        "body-subbody-work",
        "error",
        "SubBodies loaded for one `.body` file (each inclusion of the same file counted) pass 2,000: a "
        "SubBody diamond, which Choreonoid would expand exponentially; refused where the next SubBody "
        "stands. Real models load a handful.",
    ),
    CodeInfo("MK010", "yaml-syntax", "error", "The YAML is malformed."),
    CodeInfo(
        "MK011",
        "yaml-duplicate-key",
        "warning",
        "A mapping repeats a key. Reference: Choreonoid silently keeps the last value and loads the model "
        "(so does modelkit; the message names both lines).",
    ),
    CodeInfo(
        "MK012",
        "yaml-duplicate-anchor",
        "error",
        "An anchor name is defined twice (Choreonoid refuses this).",
    ),
    CodeInfo("MK013", "yaml-undefined-alias", "error", "An alias refers to an anchor that is not defined."),
    CodeInfo("MK014", "yaml-recursive-alias", "error", "An alias refers to a node that contains it."),
    CodeInfo(
        "MK015",
        "yaml-expansion-limit",
        "error",
        "Expanding aliases would produce too many nodes (an alias bomb).",
    ),
    CodeInfo(
        "MK016", "yaml-bad-merge", "error", "A `<<` merge value is not a mapping or a list of mappings."
    ),
    CodeInfo("MK017", "yaml-top-not-mapping", "error", "The top-level YAML node is not a mapping."),
    CodeInfo("MK018", "yaml-empty-key", "error", "A mapping has an empty key."),
    CodeInfo("MK019", "yaml-complex-key", "error", "A mapping key is not a scalar."),
    CodeInfo("MK020", "xml-syntax", "error", "The XML is malformed."),
    CodeInfo(
        "MK021",
        "xml-entity-refused",
        "error",
        "The XML declares entities (`<!ENTITY>`); they are refused (entity bombs, file reads).",
    ),
    CodeInfo("MK022", "xml-root-unexpected", "error", "The top XML element is not the one the format needs."),
    CodeInfo(
        "MK023",
        "xml-too-deep",
        "error",
        "XML elements nest deeper than 250 levels (modelkit's own limit, below lxml's 256); refused unread.",
    ),
    CodeInfo(
        "MK024",
        "xml-too-many-attributes",
        "error",
        "An XML element has more than 1,000 attributes (modelkit's own limit); the document is refused "
        "unread.",
    ),
    CodeInfo(
        "MK025",
        "empty-mass-value",
        "warning",
        "An SDF `<mass>` is written empty; libsdformat silently takes its default, 1 kg.",
    ),
    CodeInfo(
        "MK026",
        "xml-value-too-long",
        "error",
        "One XML text, attribute value, name or comment is longer than 10,000,000 bytes (libxml2's limit, "
        "below `--max-bytes`); the document is refused unread.",
    ),
    CodeInfo(
        "MK027",
        "xml-text-after-root",
        "warning",
        "Text, or a comment never closed, follows a URDF's root element: urdfdom reads the root and ignores "
        "the rest; PyBullet refuses the file, MuJoCo nearly always (an error under `--target mjcf` and "
        "`pybullet`).",
    ),
    # -- MK1xx: schema and header ----------------------------------------------------------
    # MK100-MK119: .body schema and header; MK120-MK129: XML elements and attributes (all XML
    # formats); MK130-MK149: URDF; MK150-MK169: SDF; MK170-MK179: MJCF.
    CodeInfo("MK100", "schema-type", "error", "A value has the wrong type or shape."),
    CodeInfo("MK101", "schema-required", "error", "A required key is missing."),
    CodeInfo("MK102", "schema-enum", "error", "A value is not one of the allowed words."),
    CodeInfo(
        "MK103",
        "unknown-key",
        "warning",
        "A key that the loader ignores (often a typo); a close match is suggested.",
    ),
    CodeInfo("MK104", "schema-violation", "error", "The value breaks another rule of the schema."),
    CodeInfo("MK110", "body-format", "error", "`format` is missing or is not `ChoreonoidBody`."),
    CodeInfo("MK111", "body-version-missing", "error", "`format_version` is not specified."),
    CodeInfo("MK112", "body-version-unsupported", "error", "`format_version` is 2.1 or later."),
    CodeInfo(
        "MK113", "body-radian-v2", "error", "`angle_unit: radian` is not allowed with format version 2.0."
    ),
    CodeInfo("MK114", "body-no-links", "error", "There is no usable `links` list."),
    CodeInfo(
        "MK115",
        "body-wrapper-mode",
        "warning",
        "The file has no `format` key and is a wrapper around another model file.",
    ),
    CodeInfo(
        "MK118",
        "flat-list-remainder",
        "warning",
        "A flat list's length is not a multiple of its tuple size; the extra numbers are dropped.",
    ),
    CodeInfo(
        "MK119",
        "anchor-holder-key",
        "info",
        "A top-level key that only holds YAML anchors; the loader ignores it.",
    ),
    # -- MK12x: XML elements and attributes (URDF, SDF, MJCF) ----------------------------------
    CodeInfo(
        "MK120",
        "xml-attribute-missing",
        "error",
        "A required XML attribute is missing. In SDF, every attribute SDFormat's description requires "
        "(a `<plugin>`'s `filename` and `name`, a `<light>`'s `name` and `type`, a `<noise>`'s or "
        "`<shader>`'s `type`...): libsdformat refuses the file. Reference: a URDF `<texture>` without "
        "`filename` is a warning (urdfdom and PyBullet ignore the element and load the file).",
    ),
    CodeInfo(
        "MK121",
        "xml-value-invalid",
        "error",
        "An XML attribute or text is not a valid value. Reference: in SDF, every typed element is judged as "
        "libsdformat 12 reads it (a leading number is a double, extra vector numbers are ignored; "
        "unparsable, overflowing or out-of-bounds values such as `<mu>-1</mu>` are refused; an empty value "
        "is refused where libsdformat's description marks the element or attribute required, e.g. "
        "`<uri></uri>`, `<size/>`, `name=\"\"`, and otherwise keeps the default, e.g. `<pose></pose>`, "
        "`<mass></mass>`, `<static/>`).",
    ),
    CodeInfo(
        "MK122",
        "xml-element-missing",
        "error",
        "A required XML element is missing. Reference: a visual or collision without a shape is a warning "
        "(libsdformat gives it an empty geometry; urdfdom drops it with a message and loads the file; "
        "PyBullet refuses the URDF, an error under `--target pybullet`); an SDF material `<script>` "
        "without `<uri>` or `<name>` is refused by libsdformat.",
    ),
    CodeInfo(
        "MK123", "xml-element-unknown", "warning", "An XML element or attribute is not part of the format."
    ),
    CodeInfo("MK124", "xml-element-repeated", "warning", "An element that may appear once appears again."),
    # -- MK13x/MK14x: URDF ------------------------------------------------------------------
    # (urdf section)
    CodeInfo(
        "MK125",
        "urdf-limit-range-missing",
        "warning",
        "A revolute or prismatic joint's `<limit>` gives neither `lower` nor `upper`. The URDF spec and "
        "urdfdom read 0 and 0, a locked joint for ROS and MoveIt; MuJoCo's, PyBullet's and Drake's URDF "
        "import leave the joint free (measured), and so does modelkit: `convert` writes it free (MJCF, SDF) "
        "or as it was (URDF). Give both, or make the joint `continuous`.",
    ),
    CodeInfo(
        "MK130",
        "urdf-version-unsupported",
        "error",
        "The `<robot version>` is not 1.0, 1.1 or 1.2.",
    ),
    CodeInfo(
        "MK131", "urdf-robot-name-missing", "error", "`<robot>` has no `name` (urdfdom refuses the file)."
    ),
    CodeInfo("MK132", "urdf-no-links", "error", "The robot has no `<link>` element."),
    CodeInfo("MK133", "urdf-joint-type-unknown", "error", "A joint `type` is not a URDF joint type."),
    CodeInfo(
        "MK134",
        "urdf-joint-limit-missing",
        "error",
        "A revolute or prismatic joint has no `<limit>` (urdfdom refuses the file).",
    ),
    CodeInfo(
        "MK135",
        "urdf-material-undefined",
        "warning",
        "A visual refers to a material name that is not defined before it; the visual gets no colour.",
    ),
    CodeInfo(
        "MK136",
        "urdf-material-unnamed",
        "warning",
        "A `<material>` in a visual has no `name`. Reference: check_urdf loads the file and urdfdom drops "
        "the visual; PyBullet refuses the file (an error under `--target pybullet`); modelkit keeps "
        "the visual with its inline colour.",
    ),
    CodeInfo(
        "MK137",
        "urdf-origin-rpy-and-quat",
        "error",
        "An `<origin>` gives both `rpy` and `quat_xyzw`.",
    ),
    CodeInfo(
        "MK138",
        "urdf-gazebo-reference-unknown",
        "warning",
        "A `<gazebo reference>` names neither a link nor a joint; libsdformat ignores the block.",
    ),
    CodeInfo(
        "MK139",
        "urdf-transmission-joint-unknown",
        "warning",
        "A `<transmission>` drives a joint that does not exist. Reference: check_urdf and PyBullet load the "
        "file, Drake refuses it; `convert` to URDF leaves that transmission out (MK808).",
    ),
    CodeInfo(
        "MK140",
        "urdf-material-duplicate",
        "error",
        "Two top-level materials have the same name (urdfdom refuses the file).",
    ),
    CodeInfo(
        "MK141",
        "urdf-material-empty",
        "warning",
        "A top-level material has neither a colour nor a texture.",
    ),
    CodeInfo(
        "MK142",
        "urdf-feature-newer-than-version",
        "warning",
        "A URDF 1.1/1.2 feature (`quat_xyzw`, `<capsule>`, `<limit acceleration>`...) in a document that "
        "declares an older version; older parsers silently misread it.",
    ),
    CodeInfo(
        "MK143",
        "urdf-shape-unreadable",
        "warning",
        "A URDF `<mesh>` without `filename`, `<box>` without `size`, `<sphere>` without `radius` or "
        "`<cylinder>`/`<capsule>` without `radius` or `length`; modelkit leaves that visual or collision "
        "out. Reference: urdfdom (check_urdf, libsdformat's URDF conversion) logs an error, drops it and "
        "every later visual and collision of the link, and loads the robot; PyBullet and MuJoCo refuse the "
        "file (an error under `--target pybullet|mjcf`).",
    ),
    CodeInfo(
        "MK144",
        "urdf-inertia-incomplete",
        "warning",
        "A URDF `<inertia>` lacks some of `ixy`, `ixz`, `iyz`; modelkit reads them as 0, as PyBullet does. "
        "Reference: urdfdom logs an error, keeps the mass with an all-zero inertia, drops every visual and "
        "collision of the link, and loads the robot (so does libsdformat's URDF conversion); MuJoCo refuses "
        "the file (an error under `--target mjcf`).",
    ),
    CodeInfo(
        "MK145",
        "urdf-inertial-unreadable",
        "warning",
        "A URDF `<inertial>` without `<mass value>` or without `<inertia>`, or an `<inertia>` lacking a "
        "diagonal moment; modelkit leaves the inertial out. Reference: urdfdom logs an error, keeps what it "
        "read before (mass 0 when unread, an all-zero inertia), drops every visual and collision of the "
        "link, and loads the robot; PyBullet and MuJoCo refuse the file (an error under "
        "`--target pybullet|mjcf`).",
    ),
    CodeInfo(
        "MK146",
        "urdf-color-unreadable",
        "warning",
        "A URDF `<color rgba>` does not hold four numbers; modelkit leaves the colour unset. Reference: "
        "urdfdom silently makes the colour black (0 0 0 1) and loads the robot, PyBullet uses its default "
        "colour; MuJoCo refuses the file (an error under `--target mjcf`).",
    ),
    # SRDF beside a URDF (--srdf, --home): modelkit/formats/srdf.py
    CodeInfo(
        "MK147",
        "srdf-home-state",
        "info",
        "The home pose comes from an SRDF `<group_state>` (`--srdf`, `--home`; without `--home` the first of "
        "`home`, `ready`, `default`, `standing`, `half_sitting`, else the SRDF's only state), or none is "
        "found and the home stays q = 0.",
    ),
    CodeInfo(
        "MK148",
        "srdf-state-missing",
        "error",
        "`--home` names a `<group_state>` the SRDF does not hold (the message lists those it holds), or the "
        "file given with `--srdf` is not an SRDF (its top element is not `<robot>`).",
    ),
    CodeInfo(
        "MK126",
        "srdf-pair-unusable",
        "warning",
        "`--srdf`: `<disable_collisions>` pairs that name a link the robot does not have (an SRDF written "
        "for another variant of the robot) are not used; one warning counts them and names the first.",
    ),
    CodeInfo(
        "MK127",
        "urdf-link-not-a-number",
        "warning",
        "A word where a number of a URDF link's `<inertial>` or `<collision>` should be (a mass, an inertia "
        "moment, an origin, a shape's size or a mesh's scale: `MASS`, `1,5`); modelkit leaves that "
        "inertial or collision out. Reference: urdfdom logs an error, keeps what it read of the link before "
        "it (an inertial's mass, with an all-zero inertia), drops the link's later visuals and collisions, "
        "and loads the robot; PyBullet reads the text with C's `atof` (`MASS` is 0, `1,5` is 1); MuJoCo "
        "refuses the file (an error under "
        "`--target mjcf`).",
    ),
    CodeInfo(
        "MK116",
        "urdf-visual-not-a-number",
        "warning",
        "A word where a number of a URDF `<visual>` should be (its origin, its shape's size or scale); "
        "modelkit leaves the visual out. Reference: urdfdom logs an error, drops it and the link's later "
        "visuals and collisions, and loads the robot; PyBullet reads the text with C's `atof`; MuJoCo's "
        "URDF import discards visuals.",
    ),
    CodeInfo(
        "MK128",
        "urdf-contact-not-a-number",
        "warning",
        "A friction of PyBullet's URDF `<contact>` that is not a number; modelkit leaves it out. PyBullet "
        "reads the text with C's `atof` (a word is 0: the link slides); urdfdom and MuJoCo ignore "
        "`<contact>`.",
    ),
    CodeInfo(
        "MK129",
        "urdf-color-not-a-number",
        "warning",
        "The `rgba` of a URDF `<material>` holds a word where a number should be; modelkit keeps the "
        "material without a colour. Reference: urdfdom logs an error, drops the colour and loads the file; "
        "PyBullet reads four parts with C's `atof` (with another count it keeps 0 0 0 0); MuJoCo refuses "
        "the file (an error under `--target mjcf`).",
    ),
    CodeInfo(
        "MK149",
        "srdf-joint-value-unusable",
        "warning",
        "A `<group_state>` joint the robot does not move (no such joint, or a fixed one), or whose value is "
        "not a number, is not used; a value outside the joint's range is used, and the writers put it at "
        "the nearer bound.",
    ),
    # -- MK15x/MK16x: SDF -------------------------------------------------------------------
    # (sdf section)
    CodeInfo("MK150", "sdf-version-missing", "error", "`<sdf>` has no `version` attribute."),
    CodeInfo(
        "MK151",
        "sdf-version-unsupported",
        "error",
        "The SDFormat version is not one modelkit reads (1.2 to 1.12). Reference: libsdformat converts 1.2 "
        "and 1.3 as it loads them (an info; read as 1.4), current libsdformat reads 1.12; 1.0 is refused.",
    ),
    CodeInfo(
        "MK152",
        "sdf-model-without-link",
        "error",
        "A model has no link. Reference: libsdformat requires one in a model that is not static; a static "
        "model without links is accepted (an info).",
    ),
    CodeInfo(
        "MK153",
        "sdf-root-multiple",
        "error",
        "`<sdf>` holds more than one model, light or actor outside a world; only the first is read.",
    ),
    CodeInfo(
        "MK154",
        "sdf-nothing-to-read",
        "warning",
        "The file holds no model (a world without models, or only a light or an actor).",
    ),
    CodeInfo(
        "MK155",
        "sdf-not-modelled",
        "warning",
        "Valid SDF that the robot model cannot hold as written: an actor, a world joint ... (skipped); "
        "a static model nested in a moving one (libsdformat accepts it; its links stay fixed in the "
        "world, held apart from the moving tree; convert writes them as separate bodies).",
    ),
    CodeInfo(
        "MK156",
        "sdf-joint-model-frame",
        "warning",
        "A joint's `<parent>` or `<child>` is the model frame `__model__`. Reference: libsdformat 13 and "
        "later resolve it to the model's canonical link (so does modelkit); libsdformat 12 (Gazebo "
        "Fortress) refuses it.",
    ),
    CodeInfo(
        "MK157",
        "sdf-placement-frame-without-pose",
        "error",
        "An `<include>` has a `<placement_frame>` but no `<pose>` (libsdformat refuses it: the pose says "
        "where the placement frame goes).",
    ),
    CodeInfo(
        "MK158",
        "sdf-world-name-shared",
        "warning",
        "A world's light or actor has the name of one of its models (or a light and an actor share a name). "
        "Reference: libsdformat loads the world and warns that the names of the world's children are not "
        "unique.",
    ),
    # -- MK17x: MJCF ------------------------------------------------------------------------
    # (mjcf section)
    CodeInfo(
        "MK170",
        "mjcf-compile-error",
        "error",
        "MuJoCo refused the MJCF file; its message is given, at the line it names when it names one.",
    ),
    CodeInfo(
        "MK171",
        "mjcf-multi-joint-body",
        "info",
        "A body with several joints becomes a chain of links (one joint each, massless in between).",
    ),
    CodeInfo(
        "MK172",
        "mjcf-element-unsupported",
        "warning",
        "An MJCF element the model cannot hold (tendon, non-joint equality, plane/hfield/sdf geom...); "
        "tendons and tendon equalities are kept as data and written back to MJCF.",
    ),
    CodeInfo(
        "MK173",
        "mjcf-unnamed",
        "info",
        "A body or joint (or the model) has no name; a deterministic name is generated.",
    ),
    CodeInfo(
        "MK174",
        "mjcf-uncompiled-fallback",
        "warning",
        "MuJoCo could not compile the file; the tree was read from the uncompiled spec (no geometry).",
    ),
    CodeInfo(
        "MK175",
        "mjcf-kept-as-data",
        "info",
        "Actuators, sensors, sites, cameras, lights, keyframes, world geoms: kept as data, not in the model.",
    ),
    CodeInfo(
        "MK176",
        "mjcf-several-trees",
        "info",
        "The worldbody holds several body trees; each becomes a robot of its own.",
    ),
    CodeInfo(
        "MK177",
        "mjcf-warning",
        "warning",
        "MuJoCo warned while reading the file (its message is given; nothing goes to MUJOCO_LOG.TXT).",
    ),
    CodeInfo(
        "MK178",
        "mjcf-texture-not-held",
        "info",
        "A robot geom's material has a texture the model cannot hold: one MuJoCo generates (`builtin`: "
        "a checker, gradient or flat pattern) or a cube or skybox texture. Converted files keep the "
        "material's colour, specular, shininess and emission; a 2d texture from a PNG file is carried.",
    ),
    CodeInfo(
        "MK179",
        "mjcf-tendon-actuator-on-joint",
        "info",
        "An MJCF actuator on a fixed tendon whose joints all follow one joint (a parallel gripper: MuJoCo "
        "Menagerie's Panda) is read as the same actuator on that joint, with its gains, ranges and the "
        "control mapped through the coupling (the message gives the mapping): URDF, SDF and `.body` "
        "write it on the joint; MJCF writes the source's element back.",
    ),
    # -- MK18x: .body values -----------------------------------------------------------------
    CodeInfo(
        "MK181",
        "body-number-trailing-text",
        "warning",
        "A `.body` number is followed by text (a C-style suffix such as `0.001f`, a unit). Reference: "
        "Choreonoid reads a list element or `mass` by its leading number (C strtod) and ignores the rest; "
        "other keys it reads only when the whole text is a number, else it keeps the default. modelkit reads "
        "both the same way and names the value it took.",
    ),
    # -- MK2xx: kinematic tree --------------------------------------------------------------
    CodeInfo("MK200", "no-root", "error", "No root link can be found (every link has a parent, or a cycle)."),
    CodeInfo("MK201", "multiple-roots", "error", "More than one link has no parent."),
    CodeInfo("MK202", "parent-undefined", "error", "A link names a parent link that does not exist."),
    CodeInfo("MK203", "cycle", "error", "Parent references form a cycle."),
    CodeInfo("MK204", "duplicate-link-name", "error", "Two links have the same name."),
    CodeInfo("MK205", "duplicate-joint-name", "error", "Two joints have the same name."),
    CodeInfo("MK206", "duplicate-joint-id", "warning", "Two joints have the same `joint_id`."),
    CodeInfo(
        "MK207", "joint-id-gap", "warning", "Joint ids are not dense from 0 (Choreonoid adds dummy joints)."
    ),
    CodeInfo("MK208", "root-link-undefined", "error", "`root_link` names a link that does not exist."),
    CodeInfo("MK209", "root-has-parent", "warning", "The root link also names a parent, which is ignored."),
    CodeInfo("MK210", "nameless-link", "warning", "A link has no name and cannot be referenced."),
    CodeInfo(
        "MK211",
        "link-joint-name-collision",
        "error",
        "A link and a joint share a name. Reference: libsdformat refuses it in SDFormat 1.7+ (an error "
        "there); URDF (check_urdf, PyBullet), SDFormat < 1.7 and .body load it (a warning naming "
        "libsdformat's URDF conversion, an error under `--target sdf`); MuJoCo keeps bodies and joints "
        "apart (info).",
    ),
    CodeInfo(
        "MK212",
        "link-node-type",
        "error",
        "A node in `links` has a type other than Link/SubBody/ContinuousTrack/Skip.",
    ),
    CodeInfo(
        "MK213",
        "non-root-free-joint",
        "warning",
        "A non-root link has a free (floating) joint: its subtree floats separately. MJCF allows a free "
        "joint on a top-level body only and SDF none inside a model; in a URDF, PyBullet welds it and Drake "
        "leaves the child free at the world origin, the joint's origin unread.",
    ),
    CodeInfo(
        "MK214",
        "pseudo-continuous-track",
        "info",
        "A pseudo continuous track is kinematically fixed; other formats cannot model its moving surface.",
    ),
    CodeInfo(
        "MK215",
        "extra-joint-invalid",
        "error",
        "An `extra_joints` entry is incomplete, names a missing link, or joins a link to itself (written to "
        "SDF, libsdformat and Drake refuse such a joint).",
    ),
    CodeInfo(
        "MK216",
        "subbody-invalid",
        "error",
        "A SubBody cannot be loaded (missing uri, recursion, load failure). Reference: Choreonoid refuses a "
        "missing `uri` and a recursive sub-body; a sub-body file it cannot load is skipped with a message, "
        "and the robot loads without that subtree (an error here, as a missing collision mesh is: the "
        "result is not the robot the file describes).",
    ),
    CodeInfo(
        "MK217", "continuous-track-invalid", "error", "A ContinuousTrack node lacks a required key or value."
    ),
    CodeInfo("MK218", "parent-missing", "error", "A link other than the root names no parent."),
    CodeInfo(
        "MK219",
        "deprecated-actuation-mode",
        "warning",
        "`jointSurfaceVelocity` is deprecated; use `joint_type: pseudo_continuous_track`.",
    ),
    CodeInfo(
        "MK220",
        "link-multiple-parents",
        "error",
        "A link is the child of two joints (check_urdf misses it when both parents share a root).",
    ),
    CodeInfo("MK221", "child-undefined", "error", "A joint names a child link that does not exist."),
    CodeInfo(
        "MK222",
        "no-robot",
        "info",
        "The file holds no robot (an xacro macro library, a world without models): `tree` prints no tree "
        "and exits 0, as `validate` does.",
    ),
    CodeInfo(
        "MK223",
        "tree-report-too-large",
        "error",
        "The tree report would pass 1,000,000 lines: check_urdf prints a link once per path from the root, "
        "so links with several parents (MK220) multiply it (a 30-rung ladder: about 400 GB).",
    ),
    # (urdf tree MK224-MK229) (sdf frames and poses MK230-MK249)
    CodeInfo(
        "MK230",
        "sdf-relative-to-undefined",
        "error",
        "A pose's `relative_to` names no frame of its scope (libsdformat error 25).",
    ),
    CodeInfo(
        "MK231", "sdf-pose-cycle", "error", "`relative_to` attributes form a cycle (libsdformat error 26)."
    ),
    CodeInfo(
        "MK232",
        "sdf-attached-to-undefined",
        "error",
        "A frame's `attached_to` names no frame of its scope (libsdformat error 22).",
    ),
    CodeInfo(
        "MK233",
        "sdf-attached-to-cycle",
        "error",
        "Frames' `attached_to` attributes form a cycle (libsdformat error 23).",
    ),
    CodeInfo(
        "MK234",
        "sdf-joint-link-undefined",
        "error",
        "A joint's parent or child names no link or frame, or the child is `world` (errors 19, 20).",
    ),
    CodeInfo(
        "MK235",
        "sdf-joint-parent-is-child",
        "error",
        "A joint's parent and child are the same link or frame, or frames that resolve to the same link "
        "(a frame or joint attached to the child). Reference: libsdformat refuses both (error 21); "
        "libsdformat 12 checks resolved links only for the top model's joints, so in a nested model the "
        "second case is a warning.",
    ),
    CodeInfo(
        "MK236",
        "sdf-canonical-link-invalid",
        "error",
        "`canonical_link` names no link of the model (libsdformat error 15).",
    ),
    CodeInfo(
        "MK237",
        "sdf-name-not-unique",
        "error",
        "Two siblings share a name: links/joints/frames/models of a model (SDF 1.7+), visuals, "
        "collisions, sensors of a link, models, lights, actors, frames of a world, two worlds "
        "(libsdformat and `gz sdf -k` refuse them).",
    ),
    CodeInfo(
        "MK238",
        "sdf-reserved-name",
        "error",
        "A name is reserved (`world`, `__...__` in every SDFormat version libsdformat 12 reads, or `::` "
        "in 1.8+). Reference: libsdformat refuses it (error 3); a link named `world` is left out of the "
        "model so that it causes no follow-on errors.",
    ),
    CodeInfo(
        "MK239",
        "sdf-expressed-in-undefined",
        "error",
        "A joint axis's `expressed_in` names no frame of the model.",
    ),
    CodeInfo(
        "MK240",
        "sdf-placement-frame-undefined",
        "error",
        "A `placement_frame` names no frame of the placed model (libsdformat error 29).",
    ),
    CodeInfo(
        "MK241",
        "sdf-closed-loop",
        "warning",
        "A link is the child of several joints, or the joints form a closed chain in which every link is a "
        "child; the extra joints are kept as loop constraints. Reference: libsdformat loads closed chains "
        "(its own `four_bar.sdf`).",
    ),
    CodeInfo(
        "MK242",
        "duplicate-actuator-name",
        "warning",
        "Two URDF transmissions name the same `<actuator>` for different joints. Reference: check_urdf, "
        "PyBullet and MuJoCo load the file; Drake refuses it (joint actuator names must be unique within "
        "a model). `convert` writes the later one as `<actuator>_<joint>` (MK800).",
    ),
    # -- MK3xx: mass properties, joints, transforms ---------------------------------------------
    CodeInfo("MK300", "mass-not-positive", "error", "A link's mass is zero or negative."),
    CodeInfo(
        "MK301",
        "inertia-asymmetric",
        "warning",
        "A 9-element inertia matrix is not symmetric: an off-diagonal pair differs by more than 1e-4 of "
        "the largest diagonal moment (less is rounding, ignored). Reference: only .body has 9 elements; "
        "Choreonoid loads the file and uses the matrix as given (no rigid body has such a matrix), so a "
        "warning; formats of six numbers get its upper triangle (xy, xz, yz) from `convert`, which is then "
        "judged as any inertia is (MK302, MK303).",
    ),
    CodeInfo(
        "MK302",
        "inertia-not-positive-definite",
        "error",
        "An inertia tensor is not positive definite on a link that moves. A negative principal moment "
        "cannot be simulated meaningfully: an error. A zero one (a rod, or a zero inertia with a mass: a "
        "point mass) is a warning: Choreonoid, check_urdf, PyBullet and libsdformat load it, MuJoCo "
        "refuses it (an error in MJCF and under `--target mjcf`). Moments within MuJoCo's 1e-15 count as "
        "zero. A URDF root not welded to `world` counts as moving (it floats in PyBullet and Gazebo), "
        "and so does an SDF link no joint connects to the tree (it floats as a separate body, MK201). A "
        "warning on a link welded to the world, except for a negative moment in SDF: libsdformat refuses "
        "the whole file for any link's. In URDF, `.body` and MJCF (whose loaders do not judge a "
        "welded link's inertia), links joined by fixed joints are judged as the one rigid body engines "
        "merge them into: a point mass or a rod welded to a sound body is not reported, a welded link's "
        "negative moment is a warning. A mass or inertia that is not a finite number, or above 1e100 (its "
        "sums and products overflow: a 1e308 inertia), is an error on any link.",
    ),
    CodeInfo(
        "MK303",
        "inertia-triangle-inequality",
        "warning",
        "Principal moments violate the triangle inequality (physically impossible). Reference: "
        "Choreonoid, check_urdf and PyBullet load it (a warning); MuJoCo and libsdformat refuse it (an "
        "error in MJCF and SDF files, and under `--target mjcf|sdf`).",
    ),
    CodeInfo(
        "MK304",
        "default-mass-properties",
        "warning",
        "A link has no mass information; Choreonoid uses 1 kg and an identity inertia.",
    ),
    CodeInfo(
        "MK305",
        "joint-axis-zero",
        "error",
        "A joint axis is the zero vector: the joint has no direction of motion and cannot be simulated "
        "meaningfully. Reference: check_urdf and PyBullet load such a URDF; libsdformat and MuJoCo refuse "
        "it.",
    ),
    CodeInfo(
        "MK306",
        "joint-axis-not-unit",
        "warning",
        "A joint axis is not a unit vector, at the line where the file writes it: in `.body` off 1 by more "
        "than 1e-6 (Choreonoid uses it as given), in URDF and SDF by more than 1e-3 (a rounded `0.7071 0 "
        "0.7071` passes). Reference: urdfdom keeps it as written, PyBullet turns the joint about the "
        "normalised axis, MuJoCo normalises it (so MJCF has no such warning); modelkit normalises it.",
    ),
    CodeInfo(
        "MK307",
        "joint-range-reversed",
        "error",
        "A joint range has its lower bound above its upper bound: no position is within it. An error in "
        "MJCF (MuJoCo refuses it: \"range[0] should be smaller than range[1]\"); a warning in URDF "
        "(urdfdom, libsdformat's URDF conversion, PyBullet and MuJoCo load it), SDF (libsdformat loads it) "
        "and `.body` (Choreonoid's loader sets the range as written). The MJCF writer leaves such a joint "
        "unlimited (MK824); the other writers keep the range as it is.",
    ),
    CodeInfo("MK308", "rotation-axis-zero", "error", "A rotation axis is the zero vector."),
    CodeInfo(
        "MK309",
        "empty-vector",
        "error",
        "`rotation: []` or `translation: []` (undefined behaviour in Choreonoid).",
    ),
    CodeInfo(
        "MK310",
        "joint-angle-on-prismatic",
        "warning",
        "`joint_angle` on a prismatic joint is converted as an angle.",
    ),
    CodeInfo(
        "MK311", "joint-keys-on-fixed", "warning", "Joint range/axis keys on a joint that does not move."
    ),
    CodeInfo(
        "MK312",
        "crease-angle-small",
        "warning",
        "A `crease_angle` below 1 in degree mode is probably meant in radians.",
    ),
    CodeInfo(
        "MK313",
        "moving-link-massless",
        "error",
        "A moving link has no mass after merging the links fixed to it. When nothing below it has mass "
        "either, its joint moves nothing and cannot be simulated: an error, except in URDF, whose loader "
        "accepts it (check_urdf loads it, PyBullet freezes the joint, MuJoCo refuses it: a warning, an error "
        "under `--target mjcf`). When links below it have mass, "
        "articulated-body engines (PyBullet, Pinocchio) simulate it and MuJoCo refuses it: a warning (an "
        "error under `--target mjcf`). Reference for a URDF link without `<inertial>`: check_urdf accepts "
        "kinematic-only models, PyBullet gives 1 kg, MuJoCo refuses (a warning; an error under `--target "
        "mjcf`); MuJoCo refuses a massless moving MJCF body.",
    ),
    CodeInfo("MK314", "inertia-count", "error", "An inertia list has neither 6 nor 9 elements."),
    CodeInfo(
        "MK316",
        "inertia-implausible",
        "warning",
        "A link's radius of gyration sqrt(I_max / m) is more than 3 times the largest distance from its "
        "centre of mass to its shapes (boxes around its visuals and collisions; a mass inside its shapes "
        "cannot exceed 1 time), e.g. a unit inertia on a 0.1 kg wheel. Every loader accepts it; the link "
        "then turns far more sluggishly than its shapes suggest. Not judged: bodies without shapes or mass, "
        "with a mesh validate did not load (plain OBJ), or whose shapes cannot hold the mass at osmium's "
        "density (markers).",
    ),
    CodeInfo(
        "MK315",
        "joint-velocity-range-reversed",
        "warning",
        "A velocity range has its lower bound above its upper.",
    ),
    CodeInfo(
        "MK320",
        "mimic-target-undefined",
        "error",
        "A mimic joint follows a joint that does not exist. Reference: in URDF a warning (urdfdom, "
        "libsdformat's URDF conversion, PyBullet and MuJoCo load the robot and the joint moves freely; "
        "modelkit drops the mimic).",
    ),
    CodeInfo(
        "MK321",
        "mimic-target-invalid",
        "error",
        "A mimic joint follows itself, a joint that is not 1-DOF, or a loop of mimic joints.",
    ),
    CodeInfo(
        "MK322",
        "massless-link-dropped",
        "warning",
        "libsdformat (Gazebo) would silently drop this massless URDF link and its subtree.",
    ),
    CodeInfo(
        "MK323",
        "joint-limit-negative",
        "warning",
        "A URDF `<limit>` effort or velocity is negative (they are magnitudes; Choreonoid refuses them).",
    ),
    # (urdf joints and mass MK324-MK339) (sdf joints and inertials MK340-MK359)
    CodeInfo(
        "MK324",
        "massless-link-inertia",
        "warning",
        "URDF: a link on a fixed joint has mass 0 but a rotational inertia (pybullet_data's Panda: "
        "`panda_link8`, 0.1 kg·m² per axis). A body without mass has no rotational inertia; the loaders "
        "that fuse fixed links (MuJoCo's and Pinocchio's URDF imports) add the tensor to the parent link, "
        "and modelkit reads it so: the parent's inertia about its centre of mass grows by the tensor, its "
        "mass and centre of mass unchanged, and the link is a massless frame. Give the link a mass, or "
        "remove its `<inertial>`.",
    ),
    CodeInfo(
        "MK325",
        "mimic-on-fixed-joint",
        "warning",
        "URDF: a `<mimic>` whose joint or leader is fixed (example-robot-data's `talos_reduced.urdf`: "
        "its fixed gripper joints keep the full model's mimics). A fixed joint has no position to follow "
        "or lead; urdfdom, PyBullet and MuJoCo ignore the mimic and Drake refuses the file, so modelkit "
        "drops it and no output repeats it.",
    ),
    CodeInfo(
        "MK326",
        "mimic-range-mismatch",
        "warning",
        "A mimic carries its follower past the follower's position range somewhere in the leader's range "
        "(Fourier's Inspire hand: the thumb's leader ranges over [−0.1, 0.6] rad, its followers at ×1.6 "
        "and ×2.4 from 0). A simulator that holds the coupling (MuJoCo's joint equality, Gazebo's mimic) "
        "then has the follower's limit and the coupling fight there. The hint gives the leader's range the "
        "coupling allows.",
    ),
    CodeInfo(
        "MK327",
        "planar-joint-pybullet",
        "warning",
        "A URDF planar joint's child has its centre of mass off its link frame: PyBullet's URDF importer "
        "places that child by its centre of mass instead of its link frame, so the child and everything "
        "below it sit off by that offset in PyBullet (urdfdom, MuJoCo and Drake follow the file). PyBullet "
        "loads the file, so it stays a warning under `--target pybullet`.",
    ),
    CodeInfo(
        "MK340",
        "sdf-joint-type-unsupported",
        "warning",
        "A universal, revolute2, screw or gearbox joint: the model keeps it as a fixed placeholder.",
    ),
    CodeInfo(
        "MK342",
        "sdf-auto-inertial-computed",
        "info",
        "`<inertial auto=\"true\">`: mass properties computed from the collision shapes.",
    ),
    CodeInfo(
        "MK343",
        "sdf-auto-inertial-unsupported",
        "warning",
        "`<inertial auto=\"true\">` with collisions modelkit cannot integrate (meshes); written values kept.",
    ),
    # -- MK4xx: geometry -------------------------------------------------------------------------
    CodeInfo("MK400", "primitive-invalid", "error", "A primitive's dimensions cannot generate a shape."),
    CodeInfo(
        "MK401",
        "extrusion-too-few-points",
        "error",
        "An Extrusion has fewer than 2 distinct spine or cross-section points (Choreonoid crashes).",
    ),
    CodeInfo(
        "MK402",
        "extrusion-count-mismatch",
        "error",
        "Extrusion `scale`/`orientation` count is neither 0, 1 nor ≥ the spine points (out-of-range access).",
    ),
    CodeInfo(
        "MK403",
        "extrusion-oblique-spine",
        "warning",
        "A straight oblique spine makes Choreonoid shear the cross-section.",
    ),
    CodeInfo(
        "MK404", "extrusion-mirrored-spine", "warning", "A straight −Y spine mirrors the cross-section."
    ),
    CodeInfo(
        "MK405",
        "extrusion-snake-begin-cap",
        "warning",
        "`begin_cap` is ignored by Choreonoid; use `beginCap`.",
    ),
    CodeInfo(
        "MK406",
        "extrusion-open-capped",
        "warning",
        "An open cross-section with caps gives a non-closed surface.",
    ),
    CodeInfo(
        "MK407",
        "elevation-grid-count",
        "error",
        "ElevationGrid `height` count differs from xDimension·zDimension (Choreonoid crashes).",
    ),
    CodeInfo(
        "MK408", "face-index-out-of-range", "error", "A face index refers to a vertex that does not exist."
    ),
    CodeInfo(
        "MK409",
        "face-unterminated",
        "warning",
        "The last IndexedFaceSet polygon lacks its −1 terminator and is dropped.",
    ),
    CodeInfo("MK410", "face-set-empty", "error", "An IndexedFaceSet has no valid polygon."),
    CodeInfo(
        "MK411",
        "collision-repeated",
        "warning",
        "A link's collision shape repeats another of the same link exactly (the same geometry at the same "
        "pose): a copy-paste. Every loader accepts it and engines make a contact for each, so where MuJoCo's "
        "soft contacts press twice as stiff the robot drives differently (a tyre given twice: MuJoCo and "
        "PyBullet 10.9 mrad apart in heading on verify's arc, against 10). None of 360 real files has one.",
    ),
    CodeInfo(
        "MK412",
        "geometry-unknown",
        "error",
        "A geometry type is not known. Reference: in URDF a warning: urdfdom logs an error, drops the shape "
        "and every later visual and collision of the link, and loads the file; PyBullet and MuJoCo refuse "
        "the file (an error under `--target pybullet|mjcf`). PyBullet's own shapes are MK421.",
    ),
    CodeInfo("MK413", "scale-ignored", "warning", "A scalar `scale` is ignored; give three numbers."),
    CodeInfo(
        "MK414", "non-uniform-scale", "info", "A non-uniform scale turns a primitive into a different shape."
    ),
    CodeInfo(
        "MK415",
        "extrusion-axis-not-unit",
        "warning",
        "An Extrusion orientation axis is not unit length (Choreonoid uses it unnormalised).",
    ),
    # (URDF and SDF primitives: a size that is not positive, judged by the consumers that load it)
    CodeInfo(
        "MK416",
        "collision-size-not-positive",
        "warning",
        "A URDF or SDF collision box, sphere, cylinder, capsule or ellipsoid with a zero size (a zero box is "
        "a common way to say \"no collision\"). Reference: check_urdf, libsdformat and PyBullet load it "
        "(PyBullet collides with a point); MuJoCo refuses it (\"size 0 must be positive in geom\"; an "
        "error under `--target mjcf`), and `convert` to MJCF leaves the shape out (MK871). A negative size "
        "is an error: the loaders accept it, but the shape cannot be simulated meaningfully (PyBullet "
        "inverts a negative box's or sphere's bounds and the body falls through the floor).",
    ),
    CodeInfo(
        "MK417",
        "visual-size-not-positive",
        "warning",
        "A URDF or SDF visual box, sphere, cylinder, capsule or ellipsoid with a zero or negative size: it "
        "draws nothing. Reference: check_urdf, libsdformat, PyBullet and MuJoCo's URDF import (which drops "
        "visuals) load it; `convert` to MJCF leaves the shape out (MK871).",
    ),
    CodeInfo(
        "MK418",
        "collision-far-from-visual",
        "warning",
        "A collision shape lies apart from the link's visual shapes: the gap between their bounding boxes "
        "exceeds the larger one's half-diagonal (e.g. a collision origin that repeats the joint origin). "
        "Every loader accepts it; the robot collides where it is not drawn. Meshes count when validate "
        "loaded them (not plain OBJ files).",
    ),
    CodeInfo(
        "MK419",
        "collision-shape-differs",
        "warning",
        "A link's one collision is not its one visual's shape: two cylinders, capsules or cones whose axes "
        "differ by more than 1°, or shapes whose extent along a link axis differs by more than a factor 2 "
        "and by more than a quarter of the larger shape's half-diagonal. Every loader accepts it. Links "
        "with mesh files or several visuals or collisions are not judged.",
    ),
    # (urdf/sdf/mjcf geometry MK420-MK439: urdf MK420-MK429)
    CodeInfo(
        "MK420",
        "mesh-scale-single-number",
        "warning",
        "A URDF mesh `scale` has one or two numbers, or more than three; URDF needs three. modelkit reads "
        "the first as a uniform scale (the first three when there are more), as PyBullet does. Reference: "
        "urdfdom logs an error, drops the shape and every later visual "
        "and collision of the link, and loads the robot; MuJoCo refuses the file (an error under "
        "`--target mjcf`).",
    ),
    CodeInfo(
        "MK421",
        "urdf-shape-pybullet-only",
        "warning",
        "A URDF `<plane>` or `<cdf>` shape: PyBullet's own extension, which PyBullet reads; modelkit leaves "
        "that visual or collision out. Reference: urdfdom logs an error, drops the shape and every later "
        "visual and collision of the link, and loads the robot; MuJoCo refuses the file (an error under "
        "`--target mjcf`).",
    ),
    # (urdf geometry MK422-MK429)
    # (sdf geometry MK430-MK439)
    CodeInfo(
        "MK430",
        "sdf-geometry-not-modelled",
        "warning",
        "A plane, heightmap, image or polyline geometry: the model has no such shape; kept as data.",
    ),
    # -- MK5xx: resources and materials -----------------------------------------------------------
    CodeInfo(
        "MK500",
        "resource-not-found",
        "error",
        "A resource file does not exist (a warning when the mesh is visual-only). A warning also when an "
        "absolute path does not exist but the same path under the model's folder does: PyBullet reads it "
        "there, Gazebo and other tools do not. A warning too when a URDF or SDF mesh's relative path is not "
        "beside the model but is under a folder above it: PyBullet looks there and reads it, and so does "
        "modelkit; MuJoCo does not (an error for `--target mjcf` when it is a collision mesh). In URDF, "
        "xacro and SDF, whose own loaders (check_urdf, "
        "libsdformat) never open meshes, a collision mesh's MK500, MK501, MK502, MK504 or MK506 is a "
        "warning that says MuJoCo and PyBullet refuse the file: an error for `--target mjcf` and "
        "`--target pybullet` (which also refuses a missing visual mesh), and `convert` exits 1.",
    ),
    CodeInfo("MK501", "resource-load-failed", "error",
             "A resource file exists but cannot be loaded (a warning for a URDF or SDF collision mesh: "
             "MK500)."),
    CodeInfo(
        "MK502",
        "resource-fragment-missing",
        "error",
        "A resource `node` fragment does not exist in the file (a warning for a URDF or SDF collision mesh: "
        "MK500).",
    ),
    CodeInfo(
        "MK503",
        "uri-scheme-unsupported",
        "error",
        "A URI scheme is not supported here. An SDF `<include>` or mesh of an `https://` (Gazebo Fuel) URI "
        "is an info: Gazebo downloads it when it loads the world, modelkit does not fetch or check it; a "
        "URDF mesh on a web server is a warning (check_urdf never opens meshes; PyBullet and MuJoCo cannot "
        "fetch it).",
    ),
    CodeInfo(
        "MK504",
        "package-not-found",
        "error",
        "A `package://` URI names a package that cannot be found. A warning when `NAME/REL` (or a bare "
        "`package://FILE`) lies beside the model file, where PyBullet looks (it strips `package://`): the "
        "file is read, but ROS tools and Gazebo will not find it. A warning too for a URDF or SDF mesh, "
        "which check_urdf and libsdformat never resolve (MK500 says when it is an error).",
    ),
    CodeInfo("MK505", "path-variable-undefined", "error", "A `${VAR}` path variable is not defined."),
    CodeInfo("MK506", "resource-extension", "error",
             "A resource file type is not supported (a warning for a URDF or SDF collision mesh: MK500)."),
    CodeInfo("MK507", "texture-unreadable", "warning", "A texture image cannot be found."),
    CodeInfo(
        "MK508",
        "contact-material-unknown",
        "warning",
        "A contact material name is not in the materials table; Default parameters apply.",
    ),
    CodeInfo("MK510", "package-uri", "info", "A `package://` URI depends on the environment."),
    CodeInfo("MK511", "materials-file-invalid", "error", "The contact materials file cannot be read."),
    CodeInfo(
        "MK512",
        "mesh-collada-mujoco",
        "warning",
        "A URDF mesh is COLLADA (.dae), which MuJoCo cannot load.",
    ),
    CodeInfo(
        "MK513",
        "color-out-of-range",
        "warning",
        "A colour has values outside 0..1 (they are clamped): a URDF `rgba` (urdfdom rejects the colour), "
        "a `.body` material's colour, intensity or transparency (Choreonoid loads it; libsdformat refuses "
        "such a colour in the SDF it would become, urdfdom drops it).",
    ),
    CodeInfo(
        "MK514",
        "mesh-gltf-consumers",
        "warning",
        "A URDF mesh is glTF (.glb/.gltf): rviz and gz-sim read it; MuJoCo cannot, PyBullet refuses the "
        "file.",
    ),
    CodeInfo(
        "MK515",
        "mesh-ply-consumers",
        "warning",
        "A URDF mesh is PLY: rviz and gz-sim read it (Assimp); MuJoCo cannot (\"no decoder found\"), "
        "PyBullet refuses the file (\"invalid mesh filename extension\").",
    ),
    # (urdf materials and resources MK516-MK529) (sdf resources MK530-MK549)
    CodeInfo(
        "MK530",
        "sdf-include-invalid",
        "error",
        "An `<include>` target cannot be used (no model.config or SDF file, no model in it, or more than one "
        "model, actor or light: libsdformat refuses that).",
    ),
    CodeInfo(
        "MK531", "sdf-include-cycle", "error", "An `<include>` includes a file that is already being read."
    ),
    CodeInfo(
        "MK532",
        "sdf-model-uri-local",
        "info",
        "A `model://` URI is found beside the model, not on the resource path (GZ_SIM_RESOURCE_PATH).",
    ),
    CodeInfo(
        "MK533",
        "sdf-material-script",
        "info",
        "A visual's colour comes from an OGRE material script; only the script name is kept.",
    ),
    CodeInfo(
        "MK535",
        "sdf-include-no-model-config",
        "error",
        "An `<include>` names a model folder without `model.config` (or the older `manifest.xml`): "
        "libsdformat cannot resolve it and refuses the file. modelkit still reads the folder's `model.sdf` "
        "to check it.",
    ),
    # -- MK6xx: devices and scene nodes ----------------------------------------------------------
    CodeInfo(
        "MK600",
        "camera-without-format",
        "warning",
        "A Camera has no valid `format`, so no device is created.",
    ),
    CodeInfo("MK602", "node-type-unknown", "error", "An element node type is not defined."),
    CodeInfo("MK603", "node-type-optional-skipped", "warning", "An optional unknown node type is skipped."),
    CodeInfo(
        "MK604", "visual-collision-conflict", "error", "A Visual node inside a Collision node, or vice versa."
    ),
    CodeInfo("MK606", "device-scale", "warning", "A device node has `scale`, which corrupts its rotation."),
    CodeInfo(
        "MK607", "range-sensor-bounds", "warning", "A RangeSensor min angle exceeds its max and is ignored."
    ),
    CodeInfo("MK608", "elements-invalid", "error", "An `elements` value is not a list or a mapping."),
    CodeInfo(
        "MK609", "node-type-mismatch", "error", "A node's `type` differs from the key it is placed under."
    ),
    CodeInfo(
        "MK610",
        "shape-material-misplaced",
        "warning",
        "`material` directly in a Shape is ignored; put it under `appearance`.",
    ),
    CodeInfo(
        "MK620",
        "gazebo-sensor-invalid",
        "warning",
        "A `<sensor>` in a URDF `<gazebo>` block lacks its name or type, or has a malformed `<pose>`.",
    ),
    # (urdf gazebo extensions MK621-MK629) (sdf sensors, lights, plugins MK630-MK649)
    CodeInfo(
        "MK630",
        "sdf-device-type-invalid",
        "error",
        "A sensor or light type is missing or not an SDFormat type (libsdformat refuses it).",
    ),
    CodeInfo("MK631", "sdf-plugin-kept", "info", "A `<plugin>` is simulator code; it is kept only as data."),
    # -- MK7xx: xacro -----------------------------------------------------------------------
    # (xacro MK700-MK719)
    CodeInfo(
        "MK700", "xacro-error", "error", "xacro could not expand the file (a bad expression, attribute, tag)."
    ),
    CodeInfo(
        "MK701",
        "xacro-legacy-construct",
        "warning",
        "Pre-Jade xacro without the `xacro:` prefix (`<property>`, `<include>`, an unprefixed macro call); "
        "expanded with a warning, an error with `--no-legacy`.",
    ),
    CodeInfo(
        "MK702", "xacro-package-not-found", "error", "`$(find PKG)` names a package that cannot be found."
    ),
    CodeInfo(
        "MK703", "xacro-warning", "warning", "xacro warned while expanding (or the file printed a message)."
    ),
    CodeInfo(
        "MK704",
        "xacro-arg-undefined",
        "error",
        "`$(arg NAME)` has no value: no `NAME:=VALUE` argument and no `<xacro:arg>` default.",
    ),
    CodeInfo(
        "MK705", "xacro-file-missing", "error", "A file to include (or a YAML file to load) does not exist."
    ),
    CodeInfo("MK706", "xacro-recursion", "error", "Macro expansion recurses without end."),
    CodeInfo(
        "MK707", "xacro-name-undefined", "error", "A `${...}` expression uses a name that is not defined."
    ),
    CodeInfo(
        "MK708",
        "xacro-macro-call",
        "error",
        "A macro call does not match the macro: a missing or unknown parameter, a missing block, "
        "or no such macro.",
    ),
    CodeInfo(
        "MK709",
        "xacro-expansion-limit",
        "error",
        "Expansion produces too many elements or too long a value (a macro or property bomb).",
    ),
    CodeInfo(
        "MK710",
        "xacro-library",
        "info",
        "An xacro file expands to no robot content: a macro library, checked for xacro errors only.",
    ),
    CodeInfo(
        "MK711",
        "xacro-read-outside",
        "error",
        "`include`, `load_yaml` or a `$(find)` path would read a file outside the model's folder tree "
        "and the package paths given; refused unread.",
    ),
    # -- MK8xx: conversion notes ------------------------------------------------------------
    # MK800-MK849 shared by every writer (full: MK854 is shared too); MK850-859 URDF, MK860-869 SDF,
    # MK870-879 MJCF, MK880-889 .body; MK890-899 the convert command (outputs refused, targets that
    # cannot hold).
    CodeInfo(
        "MK800", "renamed", "info", "A name the target forbids or reserves was changed; the note names both."
    ),
    CodeInfo(
        "MK801",
        "default-mass-written",
        "warning",
        "The source gave no mass information; Choreonoid's default (1 kg, identity inertia) is written "
        "explicitly.",
    ),
    CodeInfo(
        "MK802",
        "primitive-as-mesh",
        "info",
        "A primitive the target lacks (cone, capsule, ellipsoid) is written as a triangle mesh file.",
    ),
    CodeInfo(
        "MK803",
        "generated-geometry-as-mesh",
        "info",
        "Generated geometry (Extrusion, ElevationGrid, IndexedFaceSet, TriangleMesh) is written as a "
        "mesh file.",
    ),
    CodeInfo(
        "MK804",
        "mesh-converted",
        "info",
        "A mesh file is converted to a format the target reads (COLLADA, VRML → STL/OBJ), unit scale "
        "applied.",
    ),
    CodeInfo(
        "MK805",
        "mesh-missing",
        "warning",
        "A mesh file could not be found or read (or, for MJCF, MuJoCo cannot read it: an empty file, not a "
        "mesh, non-finite coordinates, over 200,000 STL faces, a flat collision mesh); the shape is left out "
        "and the rest is written. An error (`convert` exits 1) when it was a collision shape.",
    ),
    CodeInfo(
        "MK806",
        "device-dropped",
        "warning",
        "A sensor or light the target cannot hold is left out.",
    ),
    CodeInfo(
        "MK807",
        "device-approximated",
        "warning",
        "A sensor or light is written as the nearest thing the target has; the note says what differs.",
    ),
    CodeInfo(
        "MK808",
        "plugin-dropped",
        "warning",
        "Simulator plugin code or extension data (Gazebo plugins, transmissions) is not carried over.",
    ),
    CodeInfo(
        "MK809",
        "track-approximated",
        "warning",
        "A pseudo continuous track (no target has one) is written as a row of driven rollers.",
    ),
    CodeInfo(
        "MK810",
        "loop-dropped",
        "warning",
        "A closed-loop joint (Choreonoid `extra_joints`) the target cannot hold is left out.",
    ),
    CodeInfo(
        "MK811",
        "loop-approximated",
        "info",
        "A closed-loop joint is written as an equality constraint (hinge: two ball connects on the axis).",
    ),
    CodeInfo("MK812", "mimic-dropped", "warning", "A mimic relation the target cannot hold is left out."),
    CodeInfo(
        "MK813",
        "joint-approximated",
        "warning",
        "A joint type the target lacks (planar, ball, floating inside the tree) is written as the "
        "nearest one.",
    ),
    CodeInfo(
        "MK814",
        "root-convention",
        "info",
        "How the root meets the world follows the target's convention (URDF: floating unless welded "
        "to `world`).",
    ),
    CodeInfo(
        "MK815",
        "fixed-joint-merged",
        "info",
        "`--merge-fixed`: a link on a fixed joint is fused into its parent, mass properties combined.",
    ),
    CodeInfo(
        "MK816",
        "massless-link-frame",
        "info",
        "A link without mass is written as a frame (SDF `<frame>`, MJCF site or massless body; in URDF "
        "a link with a tiny explicit inertial, the root included, as PyBullet gives a link without "
        "`<inertial>` 1 kg and 1 kg·m²), or, where it moves or carries shapes, with a tiny explicit "
        "inertial, so that no consumer drops it or gives it a default mass; the note says which.",
    ),
    CodeInfo(
        "MK817",
        "friction-approximated",
        "info",
        "Contact friction from material pairs is written as the target's per-shape or pair value.",
    ),
    CodeInfo(
        "MK818",
        "appearance-approximated",
        "info",
        "Appearance the target cannot hold (texture, specular, emissive, transparency) is simplified.",
    ),
    CodeInfo(
        "MK819",
        "value-synthesised",
        "info",
        "The target requires a value the source does not give (URDF effort/velocity limits); a "
        "documented value is written.",
    ),
    CodeInfo(
        "MK820",
        "value-dropped",
        "info",
        "A joint or link property the target has no field for (armature, initial position, joint id, "
        "velocity ranges) is left out.",
    ),
    CodeInfo(
        "MK822",
        "world-content-dropped",
        "info",
        "World content that is not the robot (lights, ground, physics settings) is not written.",
    ),
    CodeInfo(
        "MK823",
        "root-pose-dropped",
        "warning",
        "The robot's placement in the world cannot be written in the target (URDF has no root pose).",
    ),
    CodeInfo(
        "MK824",
        "joint-range-inverted-dropped",
        "warning",
        "A joint whose lower limit is above its upper (MK307: no position is within them) is written "
        "without limits where the target needs lower < upper (MJCF's `range`).",
    ),
    CodeInfo(
        "MK825",
        "simulator-options-written",
        "info",
        "Simulator settings the robot needs to drive like its source (MJCF <option>: timestep, integrator, "
        "friction cone, impratio) are written in the file, or named when the target cannot hold them.",
    ),
    CodeInfo(
        "MK826",
        "wheel-collision-approximated",
        "info",
        "A wheel's collision cylinder is written as a sphere or ellipsoid (--wheel-collision), the shape "
        "MuJoCo and PyBullet roll alike on a floor.",
    ),
    CodeInfo(
        "MK827",
        "unactuated-load-bearing-servoed",
        "info",
        "MJCF and SDF: the source names actuators for some joints but leaves load-bearing ones without "
        "(a leg's joints; joints gravity turns at home, on a welded base or, on a free base, with nothing "
        "on the ground below them): with `--source-actuators auto` (the "
        "default) those get the `--actuators` choice where it is a servo, so the robot holds its home "
        "keyframe (example-robot-data's ANYmal-Kinova names the arm's transmissions only; its unactuated "
        "legs folded it onto the floor, 451 mm in 2 s). Other unactuated joints stay passive; "
        "`--source-actuators keep` leaves them all without.",
    ),
    CodeInfo(
        "MK828",
        "mimic-leader-ctrlrange-narrowed",
        "info",
        "MJCF: a mimic leader's position servo gets as `ctrlrange` only the part of its joint's range that "
        "keeps each follower inside the follower's own range (validate's MK326): commanded past it, the "
        "follower's limit and the coupling fight (Fourier's Inspire hand's thumb followers parted 1.0 rad "
        "from their mimic). The joint's range is kept; a follower no position keeps in range narrows "
        "nothing.",
    ),
    CodeInfo(
        "MK830",
        "base-decided",
        "info",
        "The source leaves open whether the root is welded or free (a URDF without `world`): `--base` "
        "decided, `auto` by whether the robot moves itself (wheels, legs) or not (an arm is welded).",
    ),
    CodeInfo(
        "MK831",
        "base-overridden",
        "info",
        "`--base fixed|floating` overrides the source's own answer (a root joint type, a world joint, a "
        "free joint).",
    ),
    CodeInfo(
        "MK832",
        "self-contact-excluded",
        "info",
        "Two bodies whose collision shapes MuJoCo finds touching at the reference configuration (the home "
        "keyframe, or q = 0 without one), and which MuJoCo does not already exclude, get a "
        "`<contact><exclude>` (in every pose): otherwise the robot pushes itself apart at rest.",
    ),
    CodeInfo(
        "MK833",
        "self-contact-unchecked",
        "info",
        "The written MJCF could not be compiled by MuJoCo while converting (the bindings are missing or "
        "the compiler refused it), so touching body pairs were not looked for and none is excluded.",
    ),
    CodeInfo(
        "MK834",
        "self-collision-policy",
        "info",
        "SDF (and URDF for Gazebo) cannot exclude a pair of links from colliding, only flag links or the "
        "whole model (`<self_collide>`): the written flags follow the MJCF output's policy as far as they "
        "can (docs/convert.md, \"Self-collision\"), and the note says what each simulator then does.",
    ),
    CodeInfo(
        "MK835",
        "coupled-joint-armature",
        "info",
        "MJCF: each joint a mimic couples (leader and follower) gets an armature of at least its own inertia "
        "at home where the source gives less, as the leader's motor and linkage give it; without one, "
        "MuJoCo's soft joint equality on light fingers never settled (Fourier's Inspire thumb swung 1.0 "
        "rad about its mimic, dexmate's f5d6 hand 1.7 rad). An MJCF source's own armatures are kept.",
    ),
    CodeInfo(
        "MK840",
        "actuator-gains-made-up",
        "info",
        "A position or velocity actuator the source gave no gains for (URDF transmissions and ros2_control, "
        "Choreonoid actuation modes, SDF controllers, `--actuators auto|position|velocity`) gets gains from "
        "the documented rule (docs/convert.md: a stated bandwidth on each joint's reflected inertia at home, "
        "raised where gravity at home would make the servo sag); the note gives them.",
    ),
    CodeInfo(
        "MK841",
        "actuators-chosen",
        "info",
        "The source says nothing about actuation: every hinge and slide joint that is not a mimic follower "
        "or locked gets the actuator `--actuators` names (`auto` by default: a position servo on a joint "
        "with a range, in a leg or on a welded base, a motor on the others), as an MJCF actuator or, in "
        "SDF, a gz-sim joint controller (not on the wheels a DiffDrive system drives); none with "
        "`--actuators none`.",
    ),
    CodeInfo(
        "MK842",
        "actuator-not-written",
        "warning",
        "A source actuator drives a joint the target cannot drive with one actuator (a fixed, ball or "
        "planar joint, a mimic follower, a locked joint), or an MJCF actuator the model does not hold "
        "(a tendon, site or body transmission, activation dynamics, another law) names an object the "
        "MJCF output does not have, or is a plugin or delayed actuator: it is left out.",
    ),
    CodeInfo(
        "MK843",
        "actuator-reduction-folded",
        "info",
        "A transmission reduction or rotor inertia is not written as such: the actuator acts at the joint "
        "(forces and controls in joint units) and the rotor's reflected inertia is the joint's armature.",
    ),
    CodeInfo(
        "MK844",
        "actuator-details-dropped",
        "info",
        "An actuator is written where the target has no place for its gains, gear or ranges (a URDF "
        "`<transmission>` holds the joint, the interface and the reduction): the note lists what is left "
        "out.",
    ),
    CodeInfo(
        "MK845",
        "home-outside-range",
        "info",
        "MJCF: a joint's home position (its initial position; 0 where the source gives none) lies outside "
        "its range, so the `home` keyframe puts it at the nearest limit, where the joint's own limit would "
        "push it and a position servo can hold it (Panda's joint 4: 0 against [-3.07, -0.07]).",
    ),
    CodeInfo(
        "MK846",
        "joint-keeps-link-name",
        "info",
        "URDF: a joint keeps the name of a link, as in the source and as URDF and ROS allow; libsdformat's "
        "URDF to SDF conversion refuses such a file (`--urdf-distinct-names` renames the joints).",
    ),
    CodeInfo(
        "MK847",
        "sensor-links",
        "info",
        "URDF: cameras, LiDARs and IMUs are written as links on fixed joints (their TF frames; cameras with "
        "a REP-103 optical frame), each with a tiny inertial (1e-6 kg: PyBullet would read a link without "
        "one as 1 kg), the `<gazebo reference>` naming them; the note lists them.",
    ),
    CodeInfo(
        "MK848",
        "gazebo-plugin-other-family",
        "warning",
        "A sensor or model plugin written for the other Gazebo (classic `gazebo_ros` plugins, Gazebo Sim "
        "systems) is left out; `--gazebo` chooses which family the file is written for.",
    ),
    CodeInfo(
        "MK849",
        "sensor-parameter-dropped",
        "warning",
        "A sensor parameter with no element in an SDF sensor (Choreonoid's `detection_rate`, a depth "
        "camera's range...) is left out; the note names each with its value.",
    ),
    CodeInfo(
        "MK850",
        "gazebo-ros-plugin-added",
        "info",
        "Gazebo classic: a sensor the source gave no plugin gets the `gazebo_ros` plugin that publishes it "
        "to ROS 2 (ray sensor, camera or IMU plugin, stamped with its TF frame); the note gives the topics. "
        "`--no-ros-plugins` leaves them out.",
    ),
    # MK856-MK857: MJCF, what a legged robot's home keyframe and actuators cannot do by the source's own
    # data (numbered here, in the free part of the URDF block; docs/convert.md, "Legged robots on a floor").
    CodeInfo(
        "MK856",
        "legged-home-rests-on-body",
        "warning",
        "MJCF: a legged robot's `home` keyframe (its initial positions, 0 where the source gives none) is "
        "not a standing pose: at home its body or hips reach the floor before its feet (pybullet_data's "
        "Spirit40 at q = 0 has its legs folded flat, Vision60 its legs sideways), so on a floor the servos "
        "hold it lying down. Give the joints initial positions of a stance (the source has none; in a URDF, "
        "a ros2_control position `state_interface`'s `initial_value`).",
    ),
    CodeInfo(
        "MK857",
        "legged-motors-limp",
        "warning",
        "MJCF: the source names effort actuators on a legged robot's leg joints (URDF "
        "`EffortJointInterface` transmissions: Unitree's Go1 and A1, HyQ, B1), written as `<motor>`s: at "
        "zero control the legs are limp and the robot lies down on a floor until a controller drives them "
        "(`--source-actuators replace` gives them the `--actuators` choice, and so does the default, "
        "`auto`, for ROS effort interfaces: MK864).",
    ),
    CodeInfo(
        "MK863",
        "effort-motors-sag",
        "warning",
        "MJCF: joints outside a legged robot's legs that the source's effort actuators drive (URDF "
        "`EffortJointInterface` transmissions: example-robot-data's Kinova arm) and that gravity turns at "
        "home, written as `<motor>`s: at zero control the robot sags until a controller drives them "
        "(`--source-actuators replace` gives them the `--actuators` choice, and so does the default, "
        "`auto`, for ROS effort interfaces: MK864).",
    ),
    CodeInfo(
        "MK864",
        "ros-effort-interfaces-servoed",
        "info",
        "MJCF and SDF: the source names ROS effort interfaces (URDF `EffortJointInterface` transmissions, "
        "ros2_control `effort` command interfaces) on joints that `--actuators` gives a servo (with `auto`: "
        "an arm's or a leg's joints, not wheels), and `--source-actuators auto` (the default) writes those "
        "servos instead of `<motor>`s: an effort interface says how a ROS controller commands the joint (its "
        "position or trajectory controller closes a PID over it), and at zero control a `<motor>` leaves an "
        "arm sagging and legs limp. The effort limit, or the interface's `min`/`max`, is the servo's "
        "`forcerange`; `--source-actuators keep` writes the `<motor>`s (MK857, MK863).",
    ),
    CodeInfo(
        "MK865",
        "home-below-base",
        "warning",
        "MJCF: the robot's base is welded and, at the `home` keyframe (the source's initial positions, "
        "else its zero pose put into range), the collision shapes of moving links reach more than 1 mm "
        "below the lowest point of the base's collision shapes: on a table or floor there, where an arm "
        "is mounted, they start inside it, and MuJoCo pushes the robot out at the first step "
        "(example-robot-data's Kinova arm: 45 mm; a UR5's zero pose: its wrist, 41 mm). Only a standing "
        "arm is judged: its moving links start as one chain of 3 or more joints, longer than any branch "
        "after it (a gripper's fingers); a hand, a gripper or an upper body is held by a wrist or a torso, "
        "and a robot whose moving links' centre of mass is not above that point hangs from its base. The "
        "note names the links and depths; the source's initial positions or MoveIt's SRDF (`--srdf`, "
        "`--home`) give a home pose clear of it.",
    ),
    CodeInfo(
        "MK866",
        "srdf-exclusions-written",
        "info",
        "MJCF: the SRDF's `<disable_collisions>` pairs (`--srdf`) written as `<contact><exclude>` between "
        "the bodies that hold the two links; the note counts them by the SRDF's reasons (Adjacent, Default, "
        "Never...) and those not written: MuJoCo already ignores a body and its parent and two links in "
        "one body, a repeated pair is written once, and a pair with the world body or a merged link is "
        "left out.",
    ),
    CodeInfo(
        "MK867",
        "srdf-exclusions-not-written",
        "info",
        "URDF, SDF, `.body`: the SRDF's `<disable_collisions>` pairs (`--srdf`) are not written: these "
        "formats have no exclusion of one link pair (SDF and URDF self-collision flags are per link or "
        "model); the SRDF itself still holds them for MoveIt.",
    ),
    CodeInfo(
        "MK868",
        "servo-below-gravity",
        "warning",
        "MJCF: a position servo's force limit (the joint's effort limit, or the source actuator's force "
        "range, times its gear) is below the gravity load the joint holds at home, less its Coulomb "
        "friction (a leg's joint with its leg's share of the robot's weight standing): the servo saturates "
        "and the robot sags off its home pose whatever its gains, as in any engine that applies the "
        "limit (example-robot-data's PR2: its shoulders need 52 N·m against 30; the real arm has a "
        "counterbalance spring its URDF does not describe). The note names the joints, their loads and "
        "limits; a larger effort limit, or MuJoCo's body `gravcomp`, holds the pose.",
    ),
    CodeInfo(
        "MK869",
        "mimic-coupling-stiffened",
        "info",
        "MJCF: the source's mimic joints (rigid couplings in URDF, SDF and `.body`) are written as MuJoCo "
        "joint equalities with a 5 ms time constant (`solref=\"0.005 1\"`, as MuJoCo Menagerie's "
        "Robotiq 2F-85 couples its drivers) instead of MuJoCo's default 20 ms, under which a follower "
        "lags its servoed leader (a Robotiq 2F-85 commanded from home to mid-range: 0.25 rad apart; "
        "0.076 rad with it). An MJCF source's own equalities keep their settings, and so do the rollers of "
        "the track approximation (MK809), whose tolerances were measured with the default.",
    ),
    CodeInfo(
        "MK858",
        "drive-plugin-written",
        "info",
        "URDF/SDF: the robot rolls on two sides of wheels and the source gives them no controller, so "
        "Gazebo's differential-drive plugin is written (Gazebo Sim's DiffDrive system, or gazebo_ros's "
        "diff drive for Gazebo classic): the note names the wheels, their separation and radius and the "
        "command and odometry topics. `--no-drive-plugin` leaves it out.",
    ),
    CodeInfo(
        "MK859",
        "drive-plugin-not-written",
        "info",
        "URDF/SDF: the robot has wheels but no differential-drive plugin is written, and the note says why "
        "(the source names its own drive plugin, the wheels have the source's actuators, are steered, are "
        "not in pairs, differ in radius, or turn the other way).",
    ),
    CodeInfo(
        "MK855",
        "source-actuators-replaced",
        "info",
        "MJCF: `--source-actuators replace` set the source's own actuators aside (URDF transmissions and "
        "ros2_control interfaces, Choreonoid actuation modes, MJCF actuators, SDF joint controllers) and "
        "gave every hinge and slide the `--actuators` choice instead, as for a source without any; the "
        "note counts both. The joints keep what the source said of them (effort limits as `forcerange`, "
        "rotor inertia as armature).",
    ),
    CodeInfo(
        "MK851",
        "surface-friction-not-held",
        "warning",
        "A collision shape's own friction (MJCF geom friction and condim, a URDF link's PyBullet "
        "`<contact>`, SDF `<surface><friction>`) has a part the target cannot hold: a second sliding "
        "direction, torsional or rolling friction, different values on shapes of one URDF link, or any "
        "friction in `.body` (whose friction is a pair of named contact materials); also PyBullet "
        "`<contact>` parameters other than friction (stiffness, damping, restitution...) outside URDF. "
        "The note gives the value left out.",
    ),
    CodeInfo(
        "MK853",
        "simulator-options-dropped",
        "warning",
        "An MJCF file's own `<option>` settings (timestep, integrator, cone, gravity...) have no place in "
        "the target (URDF, SDF model, `.body`); the note lists them so the user sets them in the "
        "simulator.",
    ),
    CodeInfo(
        "MK861",
        "contact-compliance-written",
        "info",
        "A wheeled robot that stands on more than three links in one plane gets PyBullet contact stiffness "
        "and damping on each (URDF <contact>): rigid contact does not fix how its weight splits among them, "
        "and PyBullet could leave a drive wheel unloaded.",
    ),
    CodeInfo(
        "MK862",
        "pybullet-joint-limit",
        "warning",
        "The URDF has more than 127 joints, fixed ones included: PyBullet loads it, but getJointState "
        "fails for every joint of a body that large (its shared-memory status holds 127); merging fixed "
        "joints or leaving out the sensor frames writes fewer.",
    ),
    CodeInfo(
        "MK852",
        "surface-friction-written",
        "info",
        "A collision shape's own friction from another format is written as the target's per-shape or "
        "per-link value; the note says how the target combines it with the shape it touches.",
    ),
    CodeInfo(
        "MK854",
        "joint-spring-dropped",
        "warning",
        "A joint spring (stiffness and rest position; a ball joint's, towards its zero orientation) the "
        "target has no place for is left out: URDF (any joint), `.body` (any joint), SDF (a ball or fixed "
        "joint, which has no axis to hold it); the note names the joint and the values. The joint no "
        "longer holds its pose under load.",
    ),
    CodeInfo(
        "MK860",
        "sdf-inertia-adjusted",
        "warning",
        "An inertia libsdformat refuses (principal moments violating A + B ≥ C, its whole file then fails to "
        "load) is written as the nearest one it accepts; the note gives the change.",
    ),
    CodeInfo(
        "MK870",
        "mjcf-inertia-adjusted",
        "warning",
        "An inertia MuJoCo refuses (principal moments violating A + B ≥ C, or singular on a moving body) "
        "is written as the nearest one it accepts; the note gives the change.",
    ),
    CodeInfo(
        "MK871",
        "mjcf-shape-size-not-positive",
        "warning",
        "A shape with a zero or negative size, which MuJoCo refuses (\"size must be positive in geom\"), "
        "is left out; the note says whether it was a collision shape (a consumer that loads it, such as "
        "PyBullet, collides with a point there).",
    ),
    CodeInfo(
        "MK872",
        "mjcf-too-deep",
        "warning",
        "The bodies nest deeper than MuJoCo's XML parser reads (496 nested bodies; a serial chain of more "
        "links): the file is written, but MuJoCo refuses it.",
    ),
    CodeInfo(
        "MK873",
        "mjcf-frames-as-sites",
        "info",
        "Massless links on fixed joints that carry nothing (a tool flange, a TCP, a camera's optical frame) "
        "are written as `<site>`s in the body they hang on, at the same pose, as MuJoCo Menagerie writes "
        "them, instead of empty bodies; the note lists them. The other way, an MJCF source's sites that "
        "name frames (used by no sensor, equality, actuator or tendon) become massless links on fixed "
        "joints in URDF, SDF and `.body`. `--frame-bodies` keeps frames as bodies and leaves sites out.",
    ),
    CodeInfo(
        "MK874",
        "sdf-frames-as-links",
        "info",
        "An SDF model's `<frame>`s (named poses attached to a link: a tool flange, a sensor mount) are "
        "written as massless links on fixed joints in URDF and `.body` (a URDF link is a TF frame) and as "
        "`<site>`s in MJCF (MK873), named after the frame; the note lists them. The SDF writer writes such "
        "links back as `<frame>`s.",
    ),
    CodeInfo(
        "MK875",
        "mjcf-camera-fovy-clamped",
        "warning",
        "A camera whose vertical field of view is 180° or more (a panoramic camera), which MuJoCo refuses "
        "(\"fovy too large\"), is written with fovy 179°.",
    ),
    CodeInfo(
        "MK876",
        "mjcf-mesh-shell-inertia",
        "info",
        "A mesh that encloses no volume (flat, or open), for which MuJoCo refuses to compute an inertia "
        "(\"mesh volume is too small\"), is given `inertia=\"shell\"` on its `<mesh>` asset; body inertias "
        "are written explicitly, so nothing changes in the dynamics.",
    ),
    CodeInfo(
        "MK877",
        "mjcf-refused-by-mujoco",
        "error",
        "MuJoCo's compiler refuses the written MJCF (compiled while converting), or the compiled model stops "
        "at its first step (too many collision shapes overlapping at once for MuJoCo's memory), for a "
        "reason no other note explains; the file is written, the note quotes MuJoCo, and convert exits 1.",
    ),
    CodeInfo(
        "MK878",
        "actuators-driven-by-source-plugin",
        "info",
        "SDF from a URDF whose robot-level `<gazebo>` block holds a ros_control plugin "
        "(`gazebo_ros2_control`, `gz_ros2_control`...) of the Gazebo written for: the plugin is written and "
        "drives the joints from the URDF's `<ros2_control>`/`<transmission>` tags, so no joint controllers "
        "are generated beside it.",
    ),
    CodeInfo(
        "MK879",
        "urdf-shape-names-left-out",
        "info",
        "URDF from another format: a link whose `<gazebo>` block gives its visuals or collisions data (an "
        "SDF source's friction, material script, `<cast_shadows>`...) gets those shapes written without "
        "names, because libsdformat's URDF import (Gazebo) applies such data only to unnamed shapes "
        "(sdformat issue 333); the note lists the links.",
    ),
    CodeInfo(
        "MK880",
        "body-shape-size-not-positive",
        "warning",
        "A shape Choreonoid cannot generate (a negative box edge; a zero or negative sphere radius; a "
        "cylinder, cone or capsule with a radius not positive, or a height not positive (negative for a "
        "capsule)) is left out of the written `.body`: Choreonoid refuses the whole file otherwise.",
    ),
    CodeInfo(
        "MK881",
        "flat-collision-as-box",
        "warning",
        "MJCF: a collision mesh whose vertices all lie in one plane (a marker plate) is written as a thin "
        "box spanning it (1 mm thick at most): MuJoCo collides with a mesh's convex hull, and a plane has "
        "none.",
    ),
    CodeInfo(
        "MK882",
        "home-key-rests-on-floor",
        "info",
        "MJCF: the `home` keyframe puts a free robot's base at the height where its lowest collision shape "
        "at home rests on z = 0, the floor a user adds (a URDF's root is at the origin, so its feet or "
        "wheels would start inside that floor); the body's own `pos` stays the source's root pose.",
    ),
    CodeInfo(
        "MK883",
        "soft-floor-contact",
        "warning",
        "MJCF: a free robot stands at home on a body so light that MuJoCo's default contact gives way under "
        "the robot's weight: MuJoCo softens a contact by the inverse mass it moves, and the robot's mass "
        "times the body's `body_invweight0` is above 400 (the robots measured standing reach 177; "
        "icub-models' iCubLisboa01, 10 g feet, 926, sinks 33 mm and falls). The source's masses are kept.",
    ),
    CodeInfo(
        "MK884",
        "spawn-height",
        "info",
        "URDF, SDF, `.body`: a free robot's lowest collision shape at q = 0 starts inside the ground where "
        "the file (or a spawn at z = 0) puts its root; the note gives the root frame's height at which it "
        "stands on z = 0, and how the target's tools take it (Gazebo's and PyBullet's spawn height, an SDF "
        "model pose). MJCF's `home` key does this in the file (MK882).",
    ),
    CodeInfo(
        "MK885",
        "wheel-not-round",
        "warning",
        "A free robot's wheel (a joint turning without end on a horizontal axis, its link on the ground, "
        "its visual round) collides as a shape whose reach from the axis changes as it turns by more than "
        "10 % (Hello Robot Stretch: a box around a round wheel, 50.8 to 71.8 mm): rolling lifts the robot "
        "and drops it, in every simulator. Nothing is changed.",
    ),
    CodeInfo(
        "MK886",
        "chassis-on-ground",
        "warning",
        "A free wheeled robot's chassis (the root link's collision shapes other than those that roll: a "
        "sphere, a cylinder or capsule on its side) reaches the "
        "ground its wheels stand on at q = 0: on a floor it rests there beside them and drags as they "
        "turn, in every simulator. Nothing is changed.",
    ),
    CodeInfo(
        "MK887",
        "cannot-stand",
        "warning",
        "A free robot cannot stand on a floor at its home pose: its centre of mass lies more than 5 mm "
        "outside the region its ground contacts span seen from above (the links whose collision shapes "
        "come within 2 % of its height of its lowest point), or off the line or point they span (two "
        "wheels without a caster). It tips over in every simulator before a controller can act; over a "
        "line, the note says how far it pitches and onto which link's collision shape. Nothing is changed.",
    ),
    CodeInfo(
        "MK888",
        "below-floor",
        "warning",
        "A welded robot's moving links reach below z = 0 where the written file starts it (the MJCF `home` "
        "key; q = 0 elsewhere): a floor added at z = 0 cuts through them and pushes the arm off its pose "
        "(a robot mounted overhead or on a wall). Nothing is changed.",
    ),
    CodeInfo(
        "MK890",
        "output-exists",
        "error",
        "The output file exists; `--force` replaces it.",
    ),
    CodeInfo(
        "MK891",
        "output-is-input",
        "error",
        "The output would overwrite an input file; nothing is written.",
    ),
    CodeInfo(
        "MK892",
        "output-unsafe",
        "error",
        "An output path would leave the output folder or is not a regular file; nothing is written.",
    ),
    CodeInfo(
        "MK893",
        "target-holds-one-robot",
        "info",
        "The input holds several robots; each is written to its own file, named after the model.",
    ),
    CodeInfo(
        "MK894",
        "write-failed",
        "error",
        "Writing an output failed (disk full, permissions); nothing partial is left behind.",
    ),
    CodeInfo(
        "MK895",
        "nothing-to-convert",
        "error",
        "An input holds no robot (an xacro macro library, a world without models, a robot of frames only: no "
        "joint, no mass, shape or device, as a xacro file named .urdf reads as URDF); nothing is written.",
    ),
    CodeInfo(
        "MK896",
        "interrupted",
        "error",
        "`convert` or `verify` was stopped by a signal (Ctrl-C, SIGTERM, SIGHUP); what it had written is "
        "removed and it exits with 128 + the signal's number (130, 143, 129).",
    ),
    CodeInfo(
        "MK897",
        "report-is-output",
        "error",
        "The `--report` file is (or is a link to) a file the conversion writes; nothing is written.",
    ),
    CodeInfo(
        "MK899",
        "internal-error",
        "error",
        "modelkit itself failed on this input: an exception it did not expect, which is a fault of "
        "modelkit, not of the file. The message names the exception and the place in modelkit's code; "
        "the command exits 2 (`validate` goes on with the other files). Please report it with the file; "
        "`MODELKIT_DEBUG=1` prints the whole traceback.",
    ),
    # -- MK9xx: verify scenario files (layer 4 command profiles, `verify --scenario`) ------------------
    CodeInfo("MK900", "scenario-wrong-type", "error", "A value in a scenario file has the wrong type."),
    CodeInfo("MK901", "scenario-unknown-key", "error", "A scenario file has a key the schema lacks."),
    CodeInfo(
        "MK902",
        "scenario-bad-value",
        "error",
        "A scenario value is out of its range (a duration not above 0, command times not increasing...).",
    ),
    CodeInfo("MK903", "scenario-missing-key", "error", "A scenario entry lacks a key it needs."),
    CodeInfo("MK904", "scenario-unknown-profile", "error", "A scenario names an unknown built-in profile."),
    # -- MK95x: verify could not run ------------------------------------------------------------------
    CodeInfo(
        "MK950",
        "verify-needs-engines",
        "error",
        "`verify` needs packages that are not installed (the engines and plots of `modelkit[verify]`, or "
        "Drake's `modelkit[drake]` when named); the message names them and the pip line that installs them.",
    ),
)

CODES: dict[str, CodeInfo] = {c.code: c for c in _TABLE}
CODES_BY_NAME: dict[str, CodeInfo] = {c.name: c for c in _TABLE}


def resolve(code_or_name: str) -> CodeInfo | None:
    """Look a code up by id (``MK103``) or by name (``unknown-key``)."""
    return CODES.get(code_or_name.upper()) or CODES_BY_NAME.get(code_or_name.lower())


def markdown_table() -> str:
    """The catalogue as the Markdown table written into ``docs/codes.md``."""
    lines = ["| code | name | default severity | meaning |", "|---|---|---|---|"]
    for c in _TABLE:
        summary = c.summary.replace("|", "\\|")
        lines.append(
            f"| {c.code} | `{c.name}` | {c.severity} | {summary}{' (retired)' if c.retired else ''} |"
        )
    return "\n".join(lines) + "\n"


def write_docs(path: str = "docs/codes.md") -> None:
    """Replace the generated table in ``docs/codes.md`` (everything after the marker)."""
    from pathlib import Path

    marker = "<!-- generated: codes table -->\n"
    doc = Path(path)
    head = doc.read_text(encoding="utf-8").split(marker, 1)[0]
    doc.write_text(head + marker + markdown_table(), encoding="utf-8")


if __name__ == "__main__":  # pragma: no cover - documentation generator
    import sys

    if "--write" in sys.argv:
        write_docs()
    else:
        print(markdown_table(), end="")
