"""The code catalogue: documented, used, and stable in form."""

from __future__ import annotations

import re

from modelkit.codes import _TABLE, CODES, markdown_table

from .conftest import REPO


def test_docs_table_is_generated_from_the_catalogue() -> None:
    text = (REPO / "docs" / "codes.md").read_text()
    marker = "<!-- generated: codes table -->\n"
    assert marker in text
    assert text.split(marker, 1)[1] == markdown_table(), (
        "regenerate docs/codes.md with python -m modelkit.codes"
    )


def test_codes_are_well_formed_and_unique() -> None:
    assert len(CODES) == len(_TABLE)
    names = [c.name for c in _TABLE]
    assert len(set(names)) == len(names)
    for c in _TABLE:
        assert re.fullmatch(r"MK\d{3}", c.code)
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", c.name)
        assert c.severity in ("error", "warning", "info")


def test_every_code_is_emitted_somewhere() -> None:
    """A catalogued code that no code path can emit is a documentation lie."""
    source = "\n".join(p.read_text() for p in (REPO / "modelkit").rglob("*.py") if p.name != "codes.py")
    unused = [c.code for c in _TABLE if not c.retired and f'"{c.code}"' not in source]
    assert unused == []
