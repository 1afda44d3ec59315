"""Shared fixtures: the reference corpus and seeds outside the repository.

Under CI (``CI`` set) hypothesis runs derandomized: the same examples every
run, so a submission's result does not depend on luck.  Locally it explores.
"""

import os
import sys
from pathlib import Path

import pytest
from hypothesis import settings

sys.path.insert(0, str(Path(__file__).parent))  # test modules share helpers (test_linuxcnc_golden.tool_table)
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """``/work/shared``-style folder with ``corpus/`` and ``seeds/``; skips if absent."""
    path = Path(__file__).resolve().parents[2] / "shared"
    if not path.is_dir():
        pytest.skip(f"reference folder {path} not found")
    return path
