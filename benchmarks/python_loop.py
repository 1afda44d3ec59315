"""The per-line ceiling: a plain Python loop that tokenises G-code and tracks position.

Issue 25's yardstick. Any interpreter of G-code written in Python visits
each line at least once; this loop does the least such a visit can do and
still know where the machine is: it strips the comment, splits the words,
follows G90/G91, M82/M83 and G92 and moves X, Y, Z and E.  It plans
nothing, checks nothing and keeps nothing but the last position and a count.
gcodekit's read + emulate + plan is measured against it side by side.

    python benchmarks/python_loop.py FILE.gcode[.gz]
"""

from __future__ import annotations

import gzip
import sys
import time


def run(path: str) -> tuple[int, int, dict[str, float]]:
    """Return (lines, moves, last position) of the program at ``path``."""
    opener = gzip.open if path.endswith(".gz") else open
    pos = {"X": 0.0, "Y": 0.0, "Z": 0.0, "E": 0.0, "F": 0.0}
    absolute, absolute_e = True, True
    lines = moves = 0
    with opener(path, "rt", encoding="utf-8", errors="replace") as f:
        for raw in f:
            lines += 1
            code = raw.split(";", 1)[0].strip()
            if not code:
                continue
            words = code.upper().split()
            head, args = words[0], words[1:]
            if head in ("G0", "G1"):
                moves += 1
                for word in args:
                    axis, value = word[0], float(word[1:])
                    if axis == "F":
                        pos["F"] = value
                    elif axis in pos:
                        relative = not (absolute_e if axis == "E" else absolute)
                        pos[axis] = pos[axis] + value if relative else value
            elif head == "G90":
                absolute = absolute_e = True
            elif head == "G91":
                absolute = absolute_e = False
            elif head == "M82":
                absolute_e = True
            elif head == "M83":
                absolute_e = False
            elif head == "G92":
                for word in args:
                    if word[0] in pos:
                        pos[word[0]] = float(word[1:])
    return lines, moves, pos


if __name__ == "__main__":
    start = time.perf_counter()
    n_lines, n_moves, last = run(sys.argv[1])
    print(f"{n_lines} lines, {n_moves} moves, last {last}, {time.perf_counter() - start:.2f} s")
