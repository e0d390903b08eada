"""Layer 4 scenario files: the built-in profiles, a user's own file, and located diagnostics for bad
files (the project's YAML reader, the scenario JSON Schema, codes MK900-MK904)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from modelkit.codes import CODES
from modelkit.diagnostics import render_text
from modelkit.verify.drive import Command
from modelkit.verify.drive.scenario import (
    BUILTIN_PROFILES,
    default_scenario,
    load,
    scenario_dict,
    scenario_from_dict,
    schema,
)

from .conftest import REPO

GOOD = """\
# my own command profiles for modelkit verify
profiles:
  - straight                 # built in
  - name: arc                # built in, shorter
    duration: 5
  - name: slalom
    description: left, right, left
    duration: 6
    commands:
      - [0, 0.3, 0.4]                     # [t, v, w, pan, tilt]
      - {t: 2, v: 0.3, w: -0.4, pan: 0.2}
      - [4, 0.3, 0.4, 0, 0]
  - name: back-and-forth
    graded: false
    duration: 4
    commands: [[0, 0.3], [2, -0.3]]
controller:
  kd: 0.6
contact:
  friction: 1.5
  native_report: false
simulation:
  sample_rate: 50
tolerances:
  engines_position: 0.008
"""


def _write(tmp_path: Path, text: str, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_users_file_is_read(tmp_path: Path) -> None:
    scenario, diagnostics = load(_write(tmp_path, GOOD))
    assert diagnostics == []
    assert scenario is not None
    assert [p.name for p in scenario.profiles] == ["straight", "arc", "slalom", "back-and-forth"]
    straight, arc, slalom, back = scenario.profiles
    assert straight.duration == 10.0 and straight.settle == 0.5 and straight.graded
    assert straight.commands == (Command(0.0, 0.5, 0.0),)
    assert arc.duration == 5.0 and arc.commands == (Command(0.0, 0.3, 0.5),)
    assert slalom.commands == (Command(0.0, 0.3, 0.4), Command(2.0, 0.3, -0.4, 0.2), Command(4.0, 0.3, 0.4))
    assert slalom.description == "left, right, left"
    assert not back.graded and back.at(3.0) == Command(2.0, -0.3)
    assert scenario.kd == 0.6 and scenario.friction == 1.5 and scenario.native_report is False
    assert scenario.sample_rate == 50.0
    assert scenario.tolerances.engines_position == 0.008 and scenario.tolerances.noslip_yaw == 0.015
    assert scenario.source == str(tmp_path / "scenario.yaml")
    # plain data, deterministic, and back
    data = scenario_dict(scenario)
    assert json.loads(json.dumps(data)) == data
    assert scenario_from_dict(data) == scenario


def test_the_default_scenario_is_verification_md_s() -> None:
    plain = default_scenario("wheels", has_pan_tilt=False)
    assert [p.name for p in plain.profiles] == list(BUILTIN_PROFILES) == ["straight", "spin", "arc", "steps"]
    assert [p.graded for p in plain.profiles] == [True, True, True, False]
    assert all(p.duration == 10.0 and p.settle == 0.5 for p in plain.profiles)
    steps = plain.profiles[3]
    assert [(c.t, c.v, c.w) for c in steps.commands] == [
        (0.0, 0.3, 0.0),
        (2.0, 0.3, 0.6),
        (4.0, 0.0, -1.0),
        (6.0, -0.2, 0.0),
        (8.0, 0.4, -0.4),
    ]
    assert plain.controller == "drive" and default_scenario("tracks").controller == "track"
    # pan and tilt move out and back while driving; the drive commands are kept
    moving = default_scenario("wheels", has_pan_tilt=True)
    arc = moving.profiles[2]
    assert arc.at(0.5) == Command(0.0, 0.3, 0.5, 0.0, 0.0)
    assert arc.at(2.0) == Command(1.0, 0.3, 0.5, 0.5, 0.3)
    assert arc.at(4.0) == Command(3.0, 0.3, 0.5, -0.5, -0.3)
    assert arc.at(9.0) == Command(5.0, 0.3, 0.5, 0.0, 0.0)
    steps = moving.profiles[3]
    assert steps.at(4.5) == Command(4.0, 0.0, -1.0, -0.5, -0.3)
    assert json.loads(json.dumps(scenario_dict(moving))) == scenario_dict(moving)


def test_the_schema_is_valid_and_reached_from_the_package() -> None:
    jsonschema.Draft202012Validator.check_schema(schema())
    on_disk = json.loads((REPO / "schemas" / "verify-scenario.schema.json").read_text())
    assert schema() == on_disk
    jsonschema.validate(scenario_dict_as_file(), on_disk)


def scenario_dict_as_file() -> dict[str, object]:
    return {
        "profiles": ["straight", {"name": "mine", "commands": [[0, 0.1], {"t": 1, "w": 0.2}]}],
        "controller": {"type": "drive", "kd": 0.5},
        "contact": {"wheel_proxy": "sphere"},
    }


@pytest.mark.parametrize(
    ("text", "code", "line", "col", "words"),
    [
        # YAML syntax error: the reader's own code and place
        ("profiles:\n  - [straight, spin\n", "MK010", 2, 5, "YAML syntax error"),
        # a wrong type: a quoted number is a string
        (
            'profiles:\n  - name: mine\n    duration: "10"\n    commands: [[0, 0.3]]\n',
            "MK900",
            3,
            15,
            "expected a number",
        ),
        ("controller:\n  kd: fast\n", "MK900", 2, 7, "controller.kd: expected a number"),
        # an unknown key, located at the key, with a suggestion
        ("controller:\n  kdd: 0.4\n", "MK901", 2, 3, 'unknown key "kdd"'),
        ("profiles: [straight]\nfriction: 1\n", "MK901", 2, 1, 'unknown key "friction"'),
        # a negative duration
        (
            "profiles:\n  - name: mine\n    duration: -1\n    commands: [[0, 0.3]]\n",
            "MK902",
            3,
            15,
            "must be above 0",
        ),
        # command times not increasing, and past the duration
        (
            "profiles:\n  - name: mine\n    duration: 4\n    commands:\n      - [1, 0.3]\n      - [1, 0.1]\n",
            "MK902",
            6,
            9,
            "must be after the previous command",
        ),
        (
            "profiles:\n  - name: mine\n    duration: 4\n    commands: [[0, 0.3], [5, 0]]\n",
            "MK902",
            4,
            26,
            "not before the profile's duration",
        ),
        # a profile of one's own without commands; a misspelt built-in
        ("profiles:\n  - name: mine\n    duration: 4\n", "MK903", 2, 5, 'needs "commands"'),
        ("profiles:\n  - stright\n", "MK904", 2, 5, '"stright" is not a built-in profile'),
        ("profiles:\n  - {name: arc, commands: [[0, 1, 2, 3, 4, 5]]}\n", "MK902", 2, 28, "too long"),
        ("profiles: []\n", "MK902", 1, 11, "should be non-empty"),
        ("- straight\n", "MK017", 1, 1, "must be a mapping"),
    ],
)
def test_bad_files_get_located_diagnostics(
    tmp_path: Path, text: str, code: str, line: int, col: int, words: str
) -> None:
    path = _write(tmp_path, text, "bad.yaml")
    scenario, diagnostics = load(path)
    assert scenario is None
    assert diagnostics, text
    first = diagnostics[0]
    rendered = render_text(first)
    assert first.code == code, rendered
    assert first.location is not None and first.location.file == str(path)
    assert (first.location.line, first.location.col) == (line, col), rendered
    assert words in first.message, rendered
    assert first.severity.value == "error"


def test_several_faults_are_all_reported_with_hints(tmp_path: Path) -> None:
    text = (
        "profiles:\n  - stright\n  - name: x\n    duration: -1\n    commands:\n      - [0, 0.3]\n"
        '      - {t: "1", v: fast}\ncontroller:\n  kdd: 0.4\n'
    )
    scenario, diagnostics = load(_write(tmp_path, text))
    assert scenario is None
    assert [(d.code, d.location.line if d.location else 0) for d in diagnostics] == [
        ("MK904", 2),
        ("MK902", 4),
        ("MK900", 7),
        ("MK900", 7),
        ("MK901", 9),
    ]
    assert diagnostics[0].hint == 'did you mean "straight"?'
    assert diagnostics[2].hint is not None and "quoted" in diagnostics[2].hint
    assert diagnostics[4].hint == 'did you mean "kd"?'


def test_missing_file_and_empty_file(tmp_path: Path) -> None:
    scenario, diagnostics = load(tmp_path / "nope.yaml")
    assert scenario is None and diagnostics[0].code == "MK001"
    scenario, diagnostics = load(_write(tmp_path, "# nothing\n"))
    assert scenario is None and diagnostics[0].code == "MK004"


def test_the_scenario_codes_are_catalogued() -> None:
    for code in ("MK900", "MK901", "MK902", "MK903", "MK904"):
        assert CODES[code].name.startswith("scenario-")
