"""Where the reference folder is: ``shared/`` beside the checkout (``corpus/``, ``seeds/``), or ``$GCODEKIT_SHARED``.

One definition for every test module: a checkout elsewhere (a git worktree,
say) names the folder with ``GCODEKIT_SHARED``; without it the tests on
real programs and references skip, and the run's summary says so.
"""

from __future__ import annotations

import os
from pathlib import Path

SHARED = Path(os.environ.get("GCODEKIT_SHARED") or Path(__file__).resolve().parents[2] / "shared")
CORPUS = SHARED / "corpus"
