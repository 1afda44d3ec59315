"""Pass counts of the golden cases by feature, for issue 4's closing notes.

Each case is checked as ``test_linuxcnc_golden`` checks its motions and
feeds, and counted under every feature its program text uses (comments left
out; the subroutine files a case calls are not read).

Usage::

    .venv/bin/python tests/golden/linuxcnc/feature_counts.py
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2]))  # this checkout's gcodekit
sys.path.insert(0, str(HERE.parents[1]))  # tests/, for the golden test's helpers

from test_linuxcnc_golden import AXES, CENTRE, PROGRAMS, CASES, first_difference, motions  # noqa: E402

#: Feature -> pattern on a program's text, comments removed and upper-cased
FEATURES = {
    "arcs G2/G3": r"\bG0*[23](?![\d.])",
    "planes G18/G19": r"\bG1[89](?![\d.])",
    "inch units G20": r"\bG20\b",
    "incremental G91": r"\bG91(?![\d.])",
    "work offsets G54-G59.3 / G10 L2/L20": r"\bG5[4-9]|\bG10\s*L0*2",
    "XY rotation G10 L2 R": r"\bG10\s*L0*2[^\n]*R",
    "G92 / G52": r"\bG92|\bG52\b",
    "tool length G43/G49": r"\bG4[39]",
    "cutter compensation G41/G42": r"\bG4[12](?![\d])|\bG4[12]\.1",
    "drilling cycles G73/G74/G81-G89": r"\bG(?:73|74|8[1-9])(?![\d.])",
    "lathe cycles G70-G72": r"\bG7[0-2](?![\d])",
    "threading G33/G76": r"\bG33|\bG76\b",
    "splines G5.x": r"\bG5(?:\.[123])?(?![\d])",
    "polar @ ^ / G16": r"[@^]|\bG16\b",
    "lathe diameter G7": r"\bG7(?![\d.])",
    "probing G38.x": r"\bG38\.",
    "homing G28/G30": r"\bG(?:28|30)(?![\d])",
    "parameters and expressions": r"#|\[",
    "O-word subroutines and flow": r"\bO\s*[<\d]",
    "state parameters #5xxx, #<_...>": r"#\s*5\d{3}|#<_",
}
_COMMENT = re.compile(r"\([^)]*\)|;.*")


def passes(name: str) -> bool:
    ours, ref, _ = motions(name)
    if first_difference(ours, ref, ["motion", "units", "plane"], AXES + CENTRE) is not None:
        return False
    keep = (ref["feed_mode"] == 0).to_numpy() & ~ours["synced"].to_numpy()
    return first_difference(ours[keep].fillna({"feed": -1.0}), ref[keep].fillna({"feed": -1.0}), [], ["feed"]) is None


def main() -> int:
    counts = {feature: [0, 0] for feature in FEATURES}
    failed = []
    for name in PROGRAMS:
        text = _COMMENT.sub("", (CASES / name).read_text(errors="replace")).upper()
        ok = passes(name)
        failed += [] if ok else [name]
        for feature, pattern in FEATURES.items():
            if re.search(pattern, text):
                counts[feature][0] += ok
                counts[feature][1] += 1
    print(f"{len(PROGRAMS) - len(failed)} of {len(PROGRAMS)} golden cases pass")
    for feature, (ok, total) in counts.items():
        print(f"{feature:40s} {ok:3d} of {total:3d}")
    if failed:
        print("failing:", ", ".join(failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
