"""Each format declares itself once, in its own package (``modelkit/formats/<name>/declare.py``), and
everything that lists formats derives from :mod:`modelkit.formats.registry`: a format package without
a declaration, a registry entry no package declares, or a CLI choice list that differs from the
declared names fails here."""

from __future__ import annotations

import importlib
from pathlib import Path

import click
import pytest

from modelkit.cli import main
from modelkit.convert.registry import TARGET_NAMES, TARGETS, load_writer, target_for_path, target_info
from modelkit.formats.declaration import FormatDeclaration
from modelkit.formats.reading import detect_format
from modelkit.formats.registry import DECLARED, FORMAT_NAMES, WRITTEN, declared

FORMATS_DIR = Path(__file__).resolve().parents[1] / "modelkit" / "formats"


def _format_packages() -> list[str]:
    return sorted(p.name for p in FORMATS_DIR.iterdir() if (p / "__init__.py").is_file())


def _declaration_of(package: str) -> FormatDeclaration:
    module = importlib.import_module(f"modelkit.formats.{package}.declare")
    declaration = module.FORMAT
    assert isinstance(declaration, FormatDeclaration), f"{package}/declare.py: FORMAT is not a declaration"
    return declaration


@pytest.mark.parametrize("package", _format_packages())
def test_every_format_package_declares_itself_under_its_own_name(package: str) -> None:
    assert (FORMATS_DIR / package / "declare.py").is_file(), f"modelkit/formats/{package}/ has no declare.py"
    assert _declaration_of(package).name == package


def test_the_registry_lists_exactly_the_declared_formats() -> None:
    packages = _format_packages()
    assert packages, "no format package found"
    assert sorted(d.name for d in DECLARED) == packages
    for d in DECLARED:  # the very object its package declares, not a copy kept in step by hand
        assert d is _declaration_of(d.name)
        assert declared(d.name) is d
    assert len(set(FORMAT_NAMES)) == len(FORMAT_NAMES)


def test_the_targets_are_exactly_the_formats_that_declare_an_output() -> None:
    assert sorted(d.name for d in WRITTEN) == sorted(d.name for d in DECLARED if d.output is not None)
    assert len(set(TARGET_NAMES)) == len(TARGET_NAMES)
    for t in TARGETS:
        out = declared(t.name).output
        assert out is not None
        assert (t.suffix, t.suffixes, t.writer, t.tracks_native, t.auto_wheel) == (
            out.suffix, out.suffixes, out.writer, out.tracks_native, out.auto_wheel)
        assert target_info(t.name) is t and target_for_path(Path(f"robot{t.suffix}")) is t
        assert t.suffix in t.suffixes and out.auto_wheel in ("cylinder", "sphere")
        assert callable(load_writer(t.name))


def test_readers_are_declared_importable_functions() -> None:
    for d in DECLARED:
        module_name, _, function = d.reader.partition(":")
        assert callable(getattr(importlib.import_module(module_name), function)), d.reader


def test_suffixes_and_root_tags_pick_one_format_each() -> None:
    """Detection tries the formats in the registry's order; with no suffix ending another and no root
    tag shared, that order cannot change which format a file is."""
    suffixes = [s for d in DECLARED for s in d.suffixes]
    assert not [(a, b) for a in suffixes for b in suffixes if a != b and a.endswith(b)]
    assert len(set(suffixes)) == len(suffixes)
    tags = [t for d in DECLARED for t in d.root_tags]
    assert len(set(tags)) == len(tags)
    for d in DECLARED:
        for suffix in d.suffixes:
            assert detect_format(Path(f"robot{suffix.upper()}")) == d.name


def _choices(command: str, option: str) -> tuple[str, ...]:
    assert isinstance(main, click.Group)
    cmd = main.commands[command]
    for param in cmd.params:
        if isinstance(param, click.Option) and option in param.opts:
            assert isinstance(param.type, click.Choice)
            return tuple(param.type.choices)
    raise AssertionError(f"{command} has no {option}")


@pytest.mark.parametrize("command", ["validate", "tree", "convert", "verify"])
def test_cli_input_format_choices_are_the_declared_names(command: str) -> None:
    assert _choices(command, "--input-format") == tuple(d.name for d in DECLARED)


def test_cli_to_choices_are_the_formats_that_declare_an_output() -> None:
    assert _choices("convert", "--to") == tuple(d.name for d in WRITTEN)
    assert set(_choices("convert", "--to")) == {d.name for d in DECLARED if d.output is not None}
