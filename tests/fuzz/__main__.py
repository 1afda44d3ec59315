"""The fuzz suite on demand: ``python -m fuzz`` with ``tests/`` on the path (see ``scripts/fuzz.sh``).

Prints the figures (cases, verdicts by kind, time, slowest case, peak
memory) as JSON and exits 1 when any case crashed, hung, went past the
memory limit or was rejected without naming where.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
from pathlib import Path

from .cases import make_cases
from .runner import FAILURES, load_case, run_cases, summary


def main() -> int:
    p = argparse.ArgumentParser(prog="fuzz", description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=2000, help="cases to run (default: 2000)")
    p.add_argument("--seed", default="random", help="a number, or 'random' for a fresh one (default)")
    p.add_argument("--timeout", type=float, default=60.0, help="seconds a case may take (default: 60)")
    p.add_argument("--memory-mb", type=float, default=2048.0, help="peak memory a case may use (default: 2048)")
    p.add_argument("--jobs", type=int, default=1, help="cases run at once (default: 1)")
    p.add_argument("--keep", type=Path, default=Path("fuzz-failures"), help="where failing cases are saved")
    p.add_argument("--json", type=Path, help="also write the figures here")
    p.add_argument("--rerun", type=Path, nargs="+", metavar="FOLDER", help="run saved failing cases again")
    args = p.parse_args()
    if args.rerun:
        for outcome in run_cases([load_case(folder) for folder in args.rerun], timeout=args.timeout,
                                 memory_mb=args.memory_mb):
            print(f"{outcome.name}: {outcome.verdict}, status {outcome.status}, {outcome.seconds} s, "
                  f"{outcome.peak_mb} MB\n{outcome.stderr}")
        return 0
    seed = random.SystemRandom().randrange(1 << 32) if args.seed == "random" else int(args.seed)
    started = time.monotonic()
    outcomes = run_cases(make_cases(args.count, seed), timeout=args.timeout, memory_mb=args.memory_mb,
                         jobs=args.jobs, keep=args.keep)
    figures = {"seed": seed, **summary(outcomes, time.monotonic() - started)}
    text = json.dumps(figures, indent=1)
    print(text)
    if args.json:
        args.json.write_text(text)
    failed = sum(o.verdict in FAILURES for o in outcomes)
    if failed:
        print(f"{failed} failing cases saved in {args.keep}; turn each into a regression example "
              "in tests/test_fuzz.py", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
