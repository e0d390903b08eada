"""The JSON Schema of `.body` files and check_schema: schema errors at YAML positions, unknown keys, speed."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jsonschema
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from modelkit.codes import CODES
from modelkit.diagnostics import Diagnostic, DiagnosticSink, Severity, SourceLocation
from modelkit.formats.body import schema as body_schema
from modelkit.formats.body.schema import check_schema, known_keys, schema
from modelkit.yamltree import YMap, YNode, YSeq, parse_yaml, to_plain

from .conftest import CORPUS, REPO, corpus_bodies

SCHEMA_FILE = REPO / "schemas" / "body.schema.json"
PACKAGED_SCHEMA = REPO / "modelkit" / "data" / "body.schema.json"

# A clean header and the start of one link; link keys follow from line 5, indented by four spaces.
HEAD = "format: ChoreonoidBody\nformat_version: 2.0\nlinks:\n  - name: base\n"


def parse(text: str) -> YNode:
    sink = DiagnosticSink()
    doc = parse_yaml(text, "t.body", sink)
    assert doc.root is not None, [str(d) for d in sink.items]
    return doc.root


def check(text: str) -> list[Diagnostic]:
    return check_schema(parse(text), "t.body")


def standalone_errors(text: str) -> list[jsonschema.ValidationError]:
    """What a plain draft 2020-12 validator says about the document, without check_schema."""
    return list(jsonschema.Draft202012Validator(schema()).iter_errors(to_plain(parse(text))))


def codes(diagnostics: list[Diagnostic]) -> list[str]:
    return [d.code for d in diagnostics]


# ---- the schema itself ------------------------------------------------------------------------------------


def test_schema_is_a_valid_draft_2020_12_schema() -> None:
    document = json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    assert document["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(document)


def test_packaged_schema_is_a_relative_symlink_to_the_schemas_folder() -> None:
    assert PACKAGED_SCHEMA.is_symlink()
    assert not Path(PACKAGED_SCHEMA.readlink()).is_absolute()
    assert PACKAGED_SCHEMA.resolve() == SCHEMA_FILE.resolve()
    assert schema() == json.loads(SCHEMA_FILE.read_text(encoding="utf-8"))
    assert schema() is schema()  # loaded once


def test_every_ref_resolves_and_every_definition_is_described() -> None:
    defs = schema()["$defs"]

    def refs(node: object) -> list[str]:
        if isinstance(node, dict):
            found = [node["$ref"]] if "$ref" in node else []
            return found + [r for v in node.values() for r in refs(v)]
        if isinstance(node, list):
            return [r for v in node for r in refs(v)]
        return []

    for target in refs(schema()):
        assert target.startswith("#/$defs/") and target[len("#/$defs/"):] in defs, target
    for name, definition in defs.items():
        description = definition.get("description")
        assert isinstance(description, str) and description[:1].islower(), name


def test_node_dispatch_covers_exactly_the_node_types() -> None:
    defs = schema()["$defs"]
    element_words = set(defs["elementType"]["enum"])
    assert set(body_schema._element_table()) == element_words
    assert set(body_schema._keyed_element_table()) == element_words
    assert all(target in defs and target[:1].isupper() for target in body_schema._element_table().values())
    assert set(body_schema._geometry_table()) == set(defs["geometryType"]["enum"])
    assert body_schema._geometry_table()["Resource"] == "ResourceGeometry"
    assert set(body_schema._link_table()) == {"Link", "", "SubBody", "ContinuousTrack", "Skip"}
    for name in ("Body Link SubBody ContinuousTrack ExtraJoint Transform Group RigidBody Visual Collision "
                 "Resource Shape Appearance Material Texture Box Sphere Cylinder Capsule Cone Extrusion "
                 "ElevationGrid IndexedFaceSet TriangleMesh ResourceGeometry Camera RangeSensor ForceSensor "
                 "RateGyroSensor AccelerationSensor IMU SpotLight PointLight number integer boolean vector3 "
                 "translation rotation jointRange elements").split():
        assert name in defs, name


def test_known_keys() -> None:
    link = known_keys("Link")
    assert {"joint_type", "jointType", "joint_axis", "jointAxis", "center_of_mass", "centerOfMass", "inertia",
            "max_joint_effort", "elements", "import", "jointMotor", "AMOR"} <= link
    assert "joinType" not in link and "childLinks" not in link and "force_range" not in link
    assert "beginCap" in known_keys("Extrusion") and "begin_cap" not in known_keys("Extrusion")
    assert "material" not in known_keys("Shape") and "material" in known_keys("Appearance")
    assert known_keys("CameraDevice") == known_keys("Camera")
    assert "num_signal_lines" in known_keys("DigitalIO") and "numSignalLines" not in known_keys("DigitalIO")
    assert known_keys("Skip") == frozenset()
    with pytest.raises(KeyError):
        known_keys("NoSuchNode")


# ---- the corpus -----------------------------------------------------------------------------------------

# Every finding of check_schema on the shared corpus; each is a key the loader really ignores.
EXPECTED_CORPUS_FINDINGS = {
    # `appearances:` holds the &BLUE … anchors used by the links
    "choreonoid/share/model/GR001/GR001.body": {("MK119", 7, 1, "appearances"),
                                                # a misspelt, unused top-level key (spec §1.3)
                                                ("MK103", 438, 1, "possileSupportLinks")},
    "choreonoid/share/model/PA10/PA10.body": {("MK103", 418, 1, "possileSupportLinks")},
    # SR1's unused link keys (spec §7.2, §7.3)
    "choreonoid/share/model/SR1/SR1.body": {("MK103", 72, 5, "childLinks"), ("MK103", 432, 5, "force_range")},
}


@pytest.mark.parametrize("path", corpus_bodies(), ids=lambda p: p.name)
def test_corpus_file_has_only_the_expected_findings(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    sink = DiagnosticSink()
    doc = parse_yaml(text, str(path), sink)
    assert doc.root is not None
    diagnostics = check_schema(doc.root, str(path))
    assert not [d for d in diagnostics if d.code in ("MK100", "MK101", "MK102", "MK104", "MK412", "MK602")]
    found = set()
    lines = text.splitlines()
    for d in diagnostics:
        assert d.location is not None and d.location.file == str(path)
        key = d.message.split('"')[1]
        # the position is the key itself
        assert lines[d.location.line - 1][d.location.col - 1:].startswith(f"{key}:"), d
        found.add((d.code, d.location.line, d.location.col, key))
    assert found == EXPECTED_CORPUS_FINDINGS.get(str(path.relative_to(CORPUS)), set())


def test_corpus_is_present_and_complete(corpus: Path) -> None:
    assert corpus == CORPUS
    names = {str(p.relative_to(CORPUS)) for p in corpus_bodies()}
    assert set(EXPECTED_CORPUS_FINDINGS) <= names
    assert len(names) >= 19


# ---- crafted faults: code, position, message ---------------------------------------------------------------

# Prefixes: the elements of the link start at line 6; a Shape/Camera node's keys start at line 7, column 9.
ELEMENTS = HEAD + "    elements:\n"
SHAPE = ELEMENTS + "      - type: Shape\n"
CAMERA = ELEMENTS + "      - type: Camera\n"
HEADER = "format: ChoreonoidBody\nformat_version: 2.0\n"

# (id, document, code, line, column, message fragment, hint fragment or None)
FAULTS: list[tuple[str, str, str, int, int, str, str | None]] = [
    ("mass-not-a-number", HEAD + "    mass: abc\n", "MK100", 5, 11,
     '"mass": expected a number, got "abc"', None),
    ("translation-two-numbers", HEAD + "    translation: [1, 2]\n", "MK100", 5, 18,
     '"translation": expected three numbers [x, y, z], got [1, 2]', None),
    ("rotation-three-numbers", HEAD + "    rotation: [0,0,1]\n", "MK100", 5, 15,
     '"rotation": expected an axis-angle rotation [x, y, z, angle], got [0, 0, 1]', None),
    ("rotation-list-item", HEAD + "    rotation: [[0, 0, 1, 90], [1, 0, 0]]\n", "MK100", 5, 31,
     '"rotation"[1]: expected an axis-angle rotation [x, y, z, angle], got [1, 0, 0]', None),
    ("rotation-scalar", HEAD + "    rotation: 90\n", "MK100", 5, 15,
     '"rotation": expected an axis-angle rotation [x, y, z, angle] or a list of them, got "90"', None),
    ("inertia-mapping", HEAD + "    inertia: {a: 1}\n", "MK100", 5, 14,
     '"inertia": expected a list of nine (3x3 row-major) or six', None),
    ("joint-type", HEAD + "    joint_type: hinge\n", "MK102", 5, 17,
     '"joint_type": "hinge" is not a joint type (allowed: fixed, free, prismatic, pseudo_continuous_track, '
     "pseudoContinuousTrack, revolute, slide)", None),
    ("joint-type-typo", HEAD + "    jointType: revolut\n", "MK102", 5, 16,
     '"revolut" is not a joint type', 'did you mean "revolute"?'),
    ("joint-axis-symbol", HEAD + "    joint_axis: W\n", "MK102", 5, 17,
     '"joint_axis": "W" is not an axis symbol (allowed: X, -X, Y, -Y, Z, -Z, in any case)', None),
    ("joint-axis-mapping", HEAD + "    jointAxis: {x: 1}\n", "MK100", 5, 16,
     '"jointAxis": expected three numbers [x, y, z] or one of X, Y, Z, -X, -Y, -Z, got {x: 1}', None),
    ("actuation-mode", HEAD + "    actuation_mode: jointTorq\n", "MK102", 5, 21,
     "is not an actuation mode", 'did you mean "jointTorque"?'),
    ("optical-frame", CAMERA + "        optical_frame: opencv\n", "MK102", 7, 24,
     '"optical_frame": "opencv" is not an optical frame (allowed: cv, gl, robotics)', None),
    ("lens-type", CAMERA + "        lens_type: fisheye\n", "MK102", 7, 20,
     '"fisheye" is not a lens type', 'did you mean "FISHEYE"?'),
    ("geometry-type", SHAPE + "        geometry: {type: Boxx, size: [1, 1, 1]}\n", "MK412", 7, 26,
     '"type": "Boxx" is not a geometry type (allowed: Box, Capsule, Cone, Cylinder', 'did you mean "Box"?'),
    ("geometry-without-type", SHAPE + "        geometry: {size: [1, 1, 1]}\n", "MK101", 7, 19,
     '"geometry": missing required key "type"', None),
    ("element-type", ELEMENTS + "      - type: Shap\n", "MK602", 6, 15,
     '"type": the node type "Shap" is not defined', 'did you mean "Shape"?'),
    ("element-type-optional", ELEMENTS + "      - type: LaserScanner\n        isOptional: true\n",
     "MK603", 6, 15, 'the node type "LaserScanner" is not defined; Choreonoid skips this optional node',
     None),
    ("element-type-optional-snake", ELEMENTS + "      - type: LaserScanner\n        is_optional: yes\n",
     "MK603", 6, 15, "skips this optional node", None),
    ("element-type-optional-false", ELEMENTS + "      - type: LaserScanner\n        isOptional: false\n",
     "MK602", 6, 15, 'the node type "LaserScanner" is not defined', "is_optional: true"),
    ("resource-without-uri", ELEMENTS + "      - type: Resource\n        node: ARM\n", "MK101", 6, 9,
     '"elements"[0]: missing required key "uri" in Resource', None),
    ("list-element-without-type", ELEMENTS + "      - geometry: {type: Box}\n", "MK101", 6, 9,
     '"elements"[0]: missing required key "type"', None),
    ("keyed-type-mismatch", ELEMENTS + "      Shape:\n        type: Transform\n", "MK609", 7, 15,
     '"type": "Transform" differs from the node type "Shape"', 'make it "Shape"'),
    ("keyed-unknown-type", ELEMENTS + "      Shap:\n        geometry: {type: Box}\n", "MK602", 6, 7,
     'the node type "Shap" is not defined', 'did you mean "Shape"?'),
    ("keyed-unknown-type-optional", ELEMENTS + "      Smoke: {isOptional: true}\n", "MK603", 6, 7,
     'the node type "Smoke" is not defined', None),
    ("elements-scalar", HEAD + "    elements: box\n", "MK608", 5, 15,
     '"elements": expected a list of nodes, a node mapping with "type", or a mapping from node type to '
     'node, got "box"', None),
    ("unknown-key-joinType", HEAD + "    joinType: revolute\n", "MK103", 5, 5,
     'unknown key "joinType" in Link (Choreonoid ignores it)', 'did you mean "jointType"?'),
    ("unknown-key-joitAxis", HEAD + "    joitAxis: Z\n", "MK103", 5, 5,
     'unknown key "joitAxis" in Link', 'did you mean "jointAxis"?'),
    ("unknown-key-centerofMass", HEAD + "    centerofMass: [0, 0, 0]\n", "MK103", 5, 5,
     'unknown key "centerofMass" in Link', 'did you mean "centerOfMass"?'),
    ("unknown-key-centerofMass-in-Transform",
     ELEMENTS + "      - type: Transform\n        centerofMass: [0, 0, 0]\n", "MK103", 7, 9,
     'unknown key "centerofMass" in Transform',
     'did you mean "centerOfMass"? ("centerOfMass" is read in RigidBody, Link'),
    ("unknown-key-mass-in-Transform", ELEMENTS + "      - type: Transform\n        mass: 1\n", "MK103", 7, 9,
     'unknown key "mass" in Transform', '"mass" is read in RigidBody, Link'),
    ("unknown-key-shinines", SHAPE + "        appearance:\n          material: {shinines: 0.2}\n",
     "MK103", 8, 22, 'unknown key "shinines" in Material', 'did you mean "shininess"?'),
    ("unknown-key-extra-joint",
     HEAD + "extra_joints:\n  - {link1Name: a, link2Name: b, jointType: ball, link1LocalPoss: [0, 0, 0]}\n",
     "MK103", 6, 51, 'unknown key "link1LocalPoss" in ExtraJoint', 'did you mean "link1LocalPos"?'),
    ("begin-cap", SHAPE + "        geometry: {type: Extrusion, begin_cap: false}\n", "MK405", 7, 37,
     '"begin_cap" is ignored by Choreonoid: only "beginCap" works', 'rename it to "beginCap"'),
    ("material-in-shape", SHAPE + "        material: {diffuse: [1, 0, 0]}\n", "MK610", 7, 9,
     '"material" directly in a Shape is ignored', 'under "appearance"'),
    ("anchor-holder-top-level", HEAD + "COLORS: &RED {diffuse: [1, 0, 0]}\n", "MK119", 5, 1,
     '"COLORS" only holds YAML anchors; the loader ignores it', None),
    ("anchor-holder-in-a-node", HEAD + "    SHAPES:\n      - &WHEEL {type: Shape}\n", "MK119", 5, 5,
     '"SHAPES" only holds YAML anchors', None),
    ("links-scalar", HEADER + "links: base\n", "MK100", 3, 8,
     '"links": expected a list of link nodes, got "base"', None),
    ("boolean", SHAPE + "        geometry: {type: Cylinder, top: maybe}\n", "MK100", 7, 41,
     '"top": expected a boolean (true/false, yes/no, on/off), got "maybe"', None),
    ("rgba-colour", SHAPE + "        appearance: {material: {diffuse: [1, 0, 0, 1]}}\n", "MK100", 7, 42,
     '"diffuse": expected three numbers [r, g, b] (use transparency for alpha)', None),
    ("joint-range-symbol", HEAD + "    joint_range: [-1, infinite]\n", "MK100", 5, 23,
     '"joint_range"[1]: expected a number or "unlimited", got "infinite"', None),
    ("joint-range-three", HEAD + "    joint_range: [-1, 1, 2]\n", "MK100", 5, 18,
     '"joint_range": expected two numbers [lower, upper]', None),
    # Choreonoid loads it: its "read" accessor ignores "0.1m" and the sphere keeps radius 1 (MK181, a warning)
    ("radius-with-unit", SHAPE + "        geometry: {type: Sphere, radius: 0.1m}\n", "MK181", 7, 42,
     '"radius": "0.1m" is a number followed by text: Choreonoid ignores the value', "write 0.1 alone"),
    ("radius-not-a-number", SHAPE + "        geometry: {type: Sphere, radius: big}\n", "MK100", 7, 42,
     '"radius": expected a number, got "big"', None),
    ("type-not-a-scalar", ELEMENTS + "      - type: {a: 1}\n", "MK100", 6, 15,
     '"type": expected a string, got {a: 1}', None),
    ("extra-joint-type", HEAD + "extra_joints:\n  - {link1_name: a, link2_name: b, joint_type: slider}\n",
     "MK102", 6, 48,
     '"joint_type": "slider" is not an extra joint type (allowed: ball, fixed, hinge, piston)', None),
    ("angle-unit", HEADER + "angle_unit: degrees\nlinks: []\n", "MK102", 3, 13,
     '"angle_unit": "degrees" is not an angle unit (allowed: degree, radian)', 'did you mean "degree"?'),
    ("top-level-not-a-mapping", "- format: ChoreonoidBody\n", "MK017", 1, 1,
     "the top-level node must be a mapping", None),
    ("hold-condition", ELEMENTS + "      - type: Holder\n        hold_condition: distanse\n", "MK102", 7, 25,
     "is not a hold condition", 'did you mean "distance"?'),
]


@pytest.mark.parametrize(("text", "code", "line", "col", "message", "hint"), [f[1:] for f in FAULTS],
                         ids=[f[0] for f in FAULTS])
def test_crafted_fault(text: str, code: str, line: int, col: int, message: str, hint: str | None) -> None:
    diagnostics = check(text)
    found = [(d.code, d.location.line, d.location.col) for d in diagnostics if d.location]
    assert found == [(code, line, col)], [str(d) for d in diagnostics]
    (d,) = diagnostics
    assert message in d.message
    assert d.message[:1] == d.message[:1].lower() or d.message.startswith('"')
    if hint is None:
        assert d.hint is None or code == "MK602"
    else:
        assert d.hint is not None and hint in d.hint
    assert d.severity == Severity(CODES[code].severity)


def test_at_least_25_crafted_faults() -> None:
    assert len(FAULTS) >= 25
    assert len({f[0] for f in FAULTS}) == len(FAULTS)


def test_links_given_a_list_of_scalars() -> None:
    diagnostics = check("format: ChoreonoidBody\nformat_version: 2.0\nlinks:\n  - base\n  - arm\n")
    assert [(d.code, d.location.line, d.location.col) for d in diagnostics if d.location] == [
        ("MK100", 4, 5), ("MK100", 5, 5)]
    assert diagnostics[1].message == '"links"[1]: expected a link node mapping, got "arm"'


def test_several_faults_in_one_document_are_sorted() -> None:
    text = (HEAD + "    mass: heavy\n    joinType: fixed\n    elements:\n"
            "      - type: Shape\n        geometry: {type: Pyramid}\n      - type: Resource\n")
    diagnostics = check(text)
    assert [(d.code, d.location.line, d.location.col) for d in diagnostics if d.location] == [
        ("MK100", 5, 11), ("MK103", 6, 5), ("MK412", 9, 26), ("MK101", 10, 9)]
    assert check(text) == diagnostics  # deterministic


def test_alias_reports_a_fault_once() -> None:
    text = (ELEMENTS + "      - &BAD {type: Shape, geometry: {type: Boxx}, colour: red}\n"
            "      - type: Transform\n        elements: *BAD\n      - *BAD\n")
    diagnostics = check(text)
    assert [(d.code, d.location.line, d.location.col) for d in diagnostics if d.location] == [
        ("MK412", 6, 45), ("MK103", 6, 52)]


def test_scalar_where_mapping_expected_never_raises() -> None:
    for text in (ELEMENTS + "      - 5\n", ELEMENTS + "      Shape: 5\n",
                 SHAPE + "        geometry: 5\n        appearance: red\n", HEAD + "    elements: [[1, 2]]\n",
                 "format: ChoreonoidBody\nlinks: {Link: 5}\n", "just text\n",
                 "format: ChoreonoidBody\nextra_joints: yes\n", "format: ChoreonoidBody\nlinks:\n  - [a]\n"):
        diagnostics = check(text)
        assert diagnostics, text
        assert all(d.code in ("MK017", "MK100", "MK608") for d in diagnostics), [str(d) for d in diagnostics]


def test_alias_use_under_an_unknown_key_is_a_typo_not_an_anchor_holder() -> None:
    text = (SHAPE + "        appearance: &APP {material: {diffuse: [1, 0, 0]}}\n"
            "      - type: Shape\n        appearence: *APP\n")
    (d,) = check(text)
    assert (d.code, d.location.line, d.location.col) == ("MK103", 9, 9)  # type: ignore[union-attr]
    assert d.hint == 'did you mean "appearance"?'


# ---- what check_schema deliberately leaves to the reader, and what is valid ------------------------------


@pytest.mark.parametrize("text", [
    HEAD + "  - type: Joint\n    name: j\n",  # MK212
    HEAD + "  - type: SubBody\n    prefix: R_\n",  # MK216
    HEAD + "  - type: ContinuousTrack\n    name: track\n",  # MK217
    HEAD + "extra_joints:\n  - {link1_name: base, joint_type: ball}\n",  # MK215
], ids=["link-node-type", "subbody-without-uri", "continuous-track-incomplete", "extra-joint-incomplete"])
def test_faults_with_a_reader_code_are_in_the_schema_but_not_reported_twice(text: str) -> None:
    assert standalone_errors(text)
    assert check(text) == []


def test_skip_content_is_not_validated() -> None:
    text = (HEAD + "    elements:\n      - type: Skip\n        geometry: 5\n        typo: 1\n"
            "  - type: Skip\n    name: {a: 1}\n    joinType: x\n    elements: 5\n")
    assert check(text) == []
    assert standalone_errors(text) == []


VALID_SNIPPETS = [
    "    joint_axis: -y\n", "    joint_axis: [0, 1, 0]\n", "    jointRange: 45\n",
    "    jointRange: [unlimited, 1]\n",
    "    max_joint_velocity: unlimited\n", "    joint_id: 1.7\n", "    mass: 2kg\n", "    rotation: []\n",
    "    translation: [[1, 2, 3], [0, 0, 1]]\n", "    rotation: [[0, 1, 0, 90], [0, 0, 1, -90]]\n",
    "    inertia: [1, 0, 0, 1, 0, 1]\n", "    actuation_mode: jointSurfaceVelocity\n",
    "    jointType: pseudoContinuousTrack\n",
    "    elements:\n      - type: Transform\n        scale: 2\n",
    "    elements:\n      - type: Camera\n        format: NO_SUCH_FORMAT\n",
    "    elements: {type: Shape, geometry: {type: Box, size: [1, 1, 1]}}\n",
    "    elements:\n      Visual: {resource: {uri: a.dae}}\n"
    "      Collision: {shape: {geometry: {type: Sphere}}}\n",
    "    elements:\n      - type: CameraDevice\n        format: COLOR\n        lensType: FISHEYE\n",
    "    elements:\n      - type: Shape\n        appearance: {texture: {url: a.png, repeat: [yes, no]}}\n",
    "    elements:\n      - type: Resource\n        uri: a.yaml\n"
    "        metadata: {length_unit: millimeter}\n",
    "    elements:\n      - {type: AGXWireDevice, whatever: 1}\n",
]


@pytest.mark.parametrize("snippet", VALID_SNIPPETS)
def test_valid_values(snippet: str) -> None:
    assert check(HEAD + snippet) == []


@pytest.mark.parametrize("text", ["1", "-1.5", "+.5", "5.", "1e-5", "1E3", " 2 ", "\t3", "inf", "-Infinity",
                                  "nan", "NaN(12)", "0x1A", "0x1.8p1", "-0X.8P-2"])
def test_strtod_numbers_are_accepted(text: str) -> None:
    assert check(HEAD + f"    joint_displacement: {json.dumps(text)}\n") == []


@pytest.mark.parametrize("text", ["abc", "", "--1", "e5", "."])
def test_non_numbers_are_rejected(text: str) -> None:
    (d,) = check(HEAD + f"    joint_displacement: {json.dumps(text)}\n")
    assert d.code == "MK100" and "expected a number" in d.message


@pytest.mark.parametrize(("text", "leading"), [("1e", "1"), ("0x", "0"), ("1.2.3", "1.2"), ("1,5", "1"),
                                               ("2kg", "2"), ("0.001f", "0.001")])
def test_numbers_followed_by_text_are_ignored_with_a_warning(text: str, leading: str) -> None:
    """Choreonoid's "read" accessor ignores such a value and keeps the default (MK181, a warning)."""
    (d,) = check(HEAD + f"    joint_displacement: {json.dumps(text)}\n")
    assert d.code == "MK181" and d.severity.value == "warning" and "keeps the default" in d.message
    assert d.hint == f"write {leading} alone (no C-style suffix such as f, no unit)"


@pytest.mark.parametrize(
    "word", "y Y yes Yes YES true True TRUE on On ON n N no No NO false False FALSE off Off OFF".split())
def test_boolean_words(word: str) -> None:
    assert check(HEAD + f'    elements:\n      - type: SpotLight\n        "on": "{word}"\n') == []


def test_integers() -> None:
    assert check(CAMERA + '        width: " 640 "\n        height: "+480"\n') == []
    (d,) = check(CAMERA + "        width: 640.5\n")
    assert d.code == "MK100" and d.message == '"width": expected an integer, got "640.5"'


def test_merge_keys_are_resolved_before_validation() -> None:
    text = (HEAD + "    elements:\n      - {<<: {type: Resource, uri: a.wrl}, node: ARM}\n"
            "      - {<<: [{type: Shape}, {type: Transform}], geometry: {type: Box}}\n")
    assert check(text) == []


def test_merge_key_in_a_type_keyed_elements_mapping() -> None:
    # the "<<" key stays in Choreonoid's mapping and is taken for a node type: the load fails
    common = "COMMON: &COMMON {Shape: {geometry: {type: Box}}}\n"
    text = HEADER + common + "links:\n  - name: base\n    elements:\n      <<: *COMMON\n"
    diagnostics = check(text)
    assert [(d.code, d.location.line, d.location.col) for d in diagnostics if d.location] == [
        ("MK119", 3, 1), ("MK602", 7, 7)]
    assert '"<<"' in diagnostics[1].message
    # merged into a node mapping, or into a node of the type-keyed form, it is fine
    template = "T: &T {type: Shape}\n"
    text = HEADER + template + "links:\n  - name: base\n    elements:\n      - {<<: *T}\n"
    assert codes(check(text)) == ["MK119"]
    text = HEADER + template + "links:\n  - name: base\n    elements:\n      Shape: {<<: *T}\n"
    assert codes(check(text)) == ["MK119"]


def test_plugin_devices() -> None:
    # AGX/PhysX/Livox parameters are not enumerated (x-keysComplete: false): no unknown-key warnings there
    assert check(HEAD + "    elements:\n      - {type: PxContinuousTrack, anything: 1}\n") == []
    # the scene-effect devices' parameters are known, so a typo is found
    (d,) = check(HEAD + "    elements:\n      - {type: SmokeDevice, num_particle: 10}\n")
    assert d.code == "MK103" and d.hint == 'did you mean "num_particles"?'
    # StdActionController is registered nowhere: only skipped when optional
    assert codes(check(HEAD + "    elements:\n      - {type: StdActionController}\n")) == ["MK602"]


# ---- robustness -----------------------------------------------------------------

_KEYS = ("type name elements geometry links translation rotation mass joint_type jointAxis uri appearance "
         "material diffuse isOptional is_optional size parent format extra_joints Shape Transform Visual Box "
         "Foo begin_cap numJoints joint_range scale repeat texture metadata shape resource").split()
_WORDS = ["Shape", "Transform", "Visual", "Resource", "Box", "Extrusion", "Link", "SubBody", "Skip", "Camera",
          "Foo", "1", "0.5", "abc", "true", "X", "-y", "unlimited", "", "revolute", "1e-3", "0x1p3", " 2 ",
          "2kg"]

_trees = st.recursive(
    st.sampled_from(_WORDS),
    lambda children: (st.lists(children, max_size=4)
                      | st.dictionaries(st.sampled_from(_KEYS), children, max_size=5)),
    max_leaves=40,
)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=_trees, links=_trees)
def test_never_raises_on_random_documents(tree: Any, links: Any) -> None:
    for document in (tree, {"format": "ChoreonoidBody", "links": links, "extra": tree},
                     {"links": [{"name": "a", "elements": tree}, links]}):
        text = yaml.safe_dump(document)
        sink = DiagnosticSink()
        doc = parse_yaml(text, "t.body", sink)
        if doc.root is None:
            continue
        diagnostics = check_schema(doc.root, "t.body")
        assert diagnostics == sorted(diagnostics, key=Diagnostic.sort_key)
        assert all(d.code in CODES for d in diagnostics)


def test_deep_nesting_is_reported_not_raised() -> None:
    # libyaml refuses documents nested much deeper than ~100 levels, so build the tree directly
    root = parse(HEAD + "    elements: []\n")
    inner: YNode = YSeq(SourceLocation("t.body", 5, 15))
    for _ in range(5000):
        inner = YSeq(SourceLocation("t.body", 5, 15), items=[inner])
    assert isinstance(root, YMap)
    link = root.get("links").items[0]  # type: ignore[union-attr]
    link.entries["elements"] = (link.entries["elements"][0], inner)
    diagnostics = check_schema(root, "t.body")
    assert [(d.code, d.message) for d in diagnostics] == [
        ("MK104", "the document is nested too deeply to be checked against the schema")]


# ---- speed -----------------------------------------------------------------------------------------------


# ---- the compiled validity check agrees with jsonschema ----------------------------------------------------
# check_schema decides validity with the compiled check (modelkit.formats.body.schema_check) and runs
# jsonschema only for invalid documents: a document the compiled check passes wrongly would lose its
# diagnostics, so the two must agree on every document.


def _agree(instance: Any) -> tuple[bool, bool]:
    from modelkit.formats.body.schema_check import compile_schema

    compiled = compile_schema(schema())(instance)
    reference = jsonschema.Draft202012Validator(schema()).is_valid(instance)
    return compiled, reference


def _plain_of(text: str) -> Any:
    doc = parse_yaml(text, "t.body", DiagnosticSink())
    return None if doc.root is None else to_plain(doc.root)


def test_the_compiled_check_covers_the_whole_schema() -> None:
    assert body_schema._compiled() is not None  # an unsupported keyword would make every file use jsonschema


def test_compiled_check_agrees_with_jsonschema_on_files() -> None:
    files = [*sorted((REPO / "tests").rglob("*.body")), *sorted(REPO.glob("samples/**/*.body")),
             *corpus_bodies()]
    verdicts = {True: 0, False: 0}
    for path in files:
        instance = _plain_of(path.read_text(encoding="utf-8", errors="replace"))
        if instance is None:
            continue
        compiled, reference = _agree(instance)
        assert compiled == reference, path
        verdicts[reference] += 1
    assert verdicts[True] >= 10 and verdicts[False] >= 5, verdicts  # both verdicts exercised


@pytest.mark.parametrize("text", [f[1] for f in FAULTS], ids=[f[0] for f in FAULTS])
def test_compiled_check_agrees_with_jsonschema_on_crafted_faults(text: str) -> None:
    instance = _plain_of(text)
    compiled, reference = _agree(instance)
    assert compiled == reference


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=_trees, links=_trees)
def test_compiled_check_agrees_with_jsonschema_on_random_documents(tree: Any, links: Any) -> None:
    for document in (tree, {"format": "ChoreonoidBody", "links": links, "extra": tree},
                     {"format": "ChoreonoidBody", "links": [{"name": "a", "elements": tree}, links]}):
        compiled, reference = _agree(document)
        assert compiled == reference, document
