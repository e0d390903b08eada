"""Shared test fixtures: where the corpus and samples are, and oracle availability."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO.parent / "shared" / "corpus"
SAMPLES = REPO / "samples"
TUTORIAL = SAMPLES / "choreonoid_ros2_mobile_robot_tutorial" / "model"


def corpus_bodies() -> list[Path]:
    return sorted(CORPUS.rglob("*.body")) if CORPUS.is_dir() else []


def require_tool(name: str) -> str:
    """The path of a peer tool used as an oracle; skip without it, unless CI demands oracles."""
    path = shutil.which(name)
    if path is None:
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail(f"{name} is required in CI (MODELKIT_REQUIRE_ORACLES is set) but not installed")
        pytest.skip(f"{name} not installed (apt-get install liburdfdom-tools)")
    return path


@pytest.fixture
def corpus() -> Path:
    if not CORPUS.is_dir():
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail(f"corpus not found at {CORPUS}")
        pytest.skip("shared corpus not available")
    return CORPUS
