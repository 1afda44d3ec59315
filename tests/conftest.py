"""Shared fixtures: the reference corpus and seeds outside the repository.

Property tests are deterministic by default: hypothesis runs the
``deterministic`` profile (a fixed derivation of examples from each test, no
example database), so whether a change lands never depends on a random draw.
``./scripts/explore.sh`` runs them with the ``explore`` profile instead: fresh
random examples each run.  A failing example found either way is added to
its test as an explicit ``@example``.
"""

import sys
from pathlib import Path

import pytest
from hypothesis import settings

sys.path.insert(0, str(Path(__file__).parent))  # test modules share helpers (test_linuxcnc_golden.tool_table)
from shared_corpus import SHARED  # noqa: E402 -- from that folder

settings.register_profile("deterministic", derandomize=True, database=None, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile("deterministic")  # pytest's --hypothesis-profile=explore overrides it


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """``/work/shared``-style folder with ``corpus/`` and ``seeds/``; skips if absent."""
    path = SHARED
    if not path.is_dir():
        pytest.skip(f"reference folder {path} not found (set GCODEKIT_SHARED)")
    return path


def _missing_reference_folder() -> str:
    return (f"reference folder {SHARED} NOT FOUND: the tests on the corpus and the references skipped "
            "(set GCODEKIT_SHARED to the folder holding corpus/ and seeds/)")


def pytest_report_header() -> str:
    """Said first (in verbose runs): without the reference folder the tests on real programs and references skip."""
    return f"reference folder: {SHARED}" if SHARED.is_dir() else _missing_reference_folder()


def pytest_terminal_summary(terminalreporter) -> None:
    """Said last, in quiet runs too, when the reference folder is missing."""
    if not SHARED.is_dir():
        terminalreporter.write_line(_missing_reference_folder(), yellow=True, bold=True)
