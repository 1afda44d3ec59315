"""Shared fixtures: the reference corpus and seeds outside the repository."""

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """``/work/shared``-style folder with ``corpus/`` and ``seeds/``; skips if absent."""
    path = Path(__file__).resolve().parents[2] / "shared"
    if not path.is_dir():
        pytest.skip(f"reference folder {path} not found")
    return path
