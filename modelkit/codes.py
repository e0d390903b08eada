"""The catalogue of diagnostic codes: stable ids, names, default severities, one-line summaries.

This table is data. ``docs/codes.md`` is generated from it (``python -m modelkit.codes``) and a test
checks that the two agree, so a code is documented the moment it exists. Codes are never reused or
renumbered; retired codes stay in the table marked ``retired``.

Ranges: MK0xx file and YAML layer; MK1xx schema and document header; MK2xx kinematic tree;
MK3xx mass properties, joints and transforms; MK4xx geometry; MK5xx resources and materials;
MK6xx devices and scene nodes; MK7xx xacro expansion.
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
    CodeInfo("MK010", "yaml-syntax", "error", "The YAML is malformed."),
    CodeInfo(
        "MK011",
        "yaml-duplicate-key",
        "error",
        "A mapping repeats a key; Choreonoid silently keeps the last value.",
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
    CodeInfo("MK120", "xml-attribute-missing", "error", "A required XML attribute is missing."),
    CodeInfo("MK121", "xml-value-invalid", "error", "An XML attribute or text is not a valid value."),
    CodeInfo("MK122", "xml-element-missing", "error", "A required XML element is missing."),
    CodeInfo(
        "MK123", "xml-element-unknown", "warning", "An XML element or attribute is not part of the format."
    ),
    CodeInfo("MK124", "xml-element-repeated", "warning", "An element that may appear once appears again."),
    # -- MK13x/MK14x: URDF ------------------------------------------------------------------
    # (urdf section)
    # -- MK15x/MK16x: SDF -------------------------------------------------------------------
    # (sdf section)
    # -- MK17x: MJCF ------------------------------------------------------------------------
    # (mjcf section)
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
        "warning",
        "A link and a joint share a name (fatal in SDF 1.7+ and Gazebo).",
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
        "A non-root link has a free joint: its subtree floats separately (no URDF/MJCF equivalent).",
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
        "An `extra_joints` entry is incomplete or names a missing link.",
    ),
    CodeInfo(
        "MK216",
        "subbody-invalid",
        "error",
        "A SubBody cannot be loaded (missing uri, recursion, load failure).",
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
    # (urdf tree MK221-MK229) (sdf frames and poses MK230-MK249)
    # -- MK3xx: mass properties, joints, transforms ---------------------------------------------
    CodeInfo("MK300", "mass-not-positive", "error", "A link's mass is zero or negative."),
    CodeInfo("MK301", "inertia-asymmetric", "error", "A 9-element inertia matrix is not symmetric."),
    CodeInfo(
        "MK302", "inertia-not-positive-definite", "error", "An inertia tensor is not positive definite."
    ),
    CodeInfo(
        "MK303",
        "inertia-triangle-inequality",
        "error",
        "Principal moments violate the triangle inequality (physically impossible).",
    ),
    CodeInfo(
        "MK304",
        "default-mass-properties",
        "warning",
        "A link has no mass information; Choreonoid uses 1 kg and an identity inertia.",
    ),
    CodeInfo("MK305", "joint-axis-zero", "error", "A joint axis is the zero vector."),
    CodeInfo(
        "MK306",
        "joint-axis-not-unit",
        "warning",
        "A joint axis is not a unit vector (Choreonoid uses it as given).",
    ),
    CodeInfo(
        "MK307", "joint-range-reversed", "error", "A joint range has its lower bound above its upper bound."
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
        "MK313", "moving-link-massless", "error", "A moving link has no mass (engines cannot simulate it)."
    ),
    CodeInfo("MK314", "inertia-count", "error", "An inertia list has neither 6 nor 9 elements."),
    CodeInfo(
        "MK315",
        "joint-velocity-range-reversed",
        "warning",
        "A velocity range has its lower bound above its upper.",
    ),
    CodeInfo("MK320", "mimic-target-undefined", "error", "A mimic joint follows a joint that does not exist."),
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
    # (urdf joints and mass MK323-MK339) (sdf joints and inertials MK340-MK359)
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
    CodeInfo("MK412", "geometry-unknown", "error", "A geometry type is not known."),
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
    # (urdf/sdf/mjcf geometry MK420-MK439)
    # -- MK5xx: resources and materials -----------------------------------------------------------
    CodeInfo(
        "MK500",
        "resource-not-found",
        "error",
        "A resource file does not exist (a warning when the mesh is visual-only).",
    ),
    CodeInfo("MK501", "resource-load-failed", "error", "A resource file exists but cannot be loaded."),
    CodeInfo(
        "MK502",
        "resource-fragment-missing",
        "error",
        "A resource `node` fragment does not exist in the file.",
    ),
    CodeInfo("MK503", "uri-scheme-unsupported", "error", "A URI scheme is not supported here."),
    CodeInfo(
        "MK504", "package-not-found", "error", "A `package://` URI names a package that cannot be found."
    ),
    CodeInfo("MK505", "path-variable-undefined", "error", "A `${VAR}` path variable is not defined."),
    CodeInfo("MK506", "resource-extension", "error", "A resource file type is not supported."),
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
    # (urdf materials and resources MK513-MK529) (sdf resources MK530-MK549)
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
    # (urdf gazebo extensions MK620-MK629) (sdf sensors, lights, plugins MK630-MK649)
    # -- MK7xx: xacro -----------------------------------------------------------------------
    # (xacro MK700-MK719)
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
