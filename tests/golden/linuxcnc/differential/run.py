#!/usr/bin/env python3
"""Agreement of gcodekit with rs274 on random programs, with the differences clustered.

Runs :func:`generate.generate` for seeds ``SEED .. SEED+COUNT-1``, judges
each program with :func:`compare.judge` and prints the agreement rate, the
verdicts by kind, the clusters of differences (largest first, with example
seeds) and, per feature the generator used, how many of the programs using
it disagree.  ``--shrink N`` reduces the first program of the N largest
clusters to a minimal reproducer (``--out DIR`` writes them as files).

Usage::

    .venv/bin/python tests/golden/linuxcnc/differential/run.py --count 1000 --seed 0 [--workers 2]
        [--shrink 5] [--out DIR] [--show SEED]

``--show SEED`` prints one program and its verdict.  Needs ``/usr/bin/rs274``
(``apt-get install -y --no-install-recommends linuxcnc-uspace``).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter, defaultdict
from dataclasses import dataclass
from multiprocessing import Pool
from pathlib import Path

if __package__ in (None, ""):  # run as a script: import the package beside this file
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    __package__ = "differential"

from .compare import Verdict, judge  # noqa: E402
from .generate import generate  # noqa: E402
from .rs274 import RS274, available  # noqa: E402


@dataclass(frozen=True)
class Outcome:
    """One program's seed, features and verdict."""

    seed: int
    features: frozenset[str]
    verdict: Verdict


def check_seed(seed: int) -> Outcome:
    """Generate and judge the program of ``seed``."""
    program = generate(seed)
    return Outcome(seed, program.features, judge(program.text))


def check_seeds(seeds: list[int], workers: int = 1) -> list[Outcome]:
    """:func:`check_seed` for every seed, on ``workers`` processes."""
    if workers <= 1:
        return [check_seed(seed) for seed in seeds]
    with Pool(workers) as pool:
        return pool.map(check_seed, seeds, chunksize=4)


def report(outcomes: list[Outcome], first_seed: int) -> str:
    """The agreement rate, verdicts by kind, clusters and disagreement by feature, as text."""
    total = len(outcomes)
    agreeing = sum(o.verdict.agree for o in outcomes)
    out = [f"{agreeing} of {total} programs agree with rs274 ({100 * agreeing / total:.1f} %), "
           f"seeds {first_seed}..{first_seed + total - 1}"]
    kinds = Counter(o.verdict.kind for o in outcomes)
    out.append("verdicts: " + ", ".join(f"{kind} {n}" for kind, n in kinds.most_common()))
    clusters: dict[str, list[int]] = defaultdict(list)
    for o in outcomes:
        if not o.verdict.agree:
            clusters[o.verdict.cluster].append(o.seed)
    if clusters:
        out.append("clusters of differences (programs, example seeds):")
        for cluster, seeds in sorted(clusters.items(), key=lambda item: (-len(item[1]), item[0])):
            out.append(f"  {len(seeds):4d}  {cluster}   seeds {' '.join(map(str, seeds[:6]))}")
    use: Counter[str] = Counter()
    bad: Counter[str] = Counter()
    for o in outcomes:
        for feature in o.features:
            use[feature] += 1
            bad[feature] += not o.verdict.agree
    out.append("by feature (programs using it, of them disagreeing):")
    for feature in sorted(use, key=lambda f: (-bad[f] / use[f], f)):
        out.append(f"  {feature:32s} {use[feature]:5d} {bad[feature]:5d}")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    ap.add_argument("--count", type=int, default=100, help="programs (default 100)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--shrink", type=int, default=0, metavar="N", help="shrink an example of the N largest clusters")
    ap.add_argument("--out", type=Path, help="write the shrunk reproducers into this folder")
    ap.add_argument("--show", type=int, metavar="SEED", help="print one program and its verdict")
    args = ap.parse_args(argv)
    if not available():
        ap.error(f"needs {RS274}: apt-get install -y --no-install-recommends linuxcnc-uspace")
    if args.show is not None:
        program = generate(args.show)
        verdict = judge(program.text)
        numbered = "\n".join(f"{k:4d}  {line}" for k, line in enumerate(program.text.splitlines(), 1))
        print(f"{numbered}\n\n{verdict.kind}: {verdict.cluster}\n{verdict.detail}")
        return 0
    outcomes = check_seeds(list(range(args.seed, args.seed + args.count)), args.workers)
    print(report(outcomes, args.seed))
    if args.shrink:
        from .shrink import shrink

        examples: dict[str, Outcome] = {}
        for o in outcomes:
            if not o.verdict.agree:
                examples.setdefault(o.verdict.cluster, o)
        sizes = Counter(o.verdict.cluster for o in outcomes if not o.verdict.agree)
        if args.out:
            args.out.mkdir(parents=True, exist_ok=True)
        for cluster, _ in sizes.most_common(args.shrink):
            o = examples[cluster]
            small, verdict = shrink(generate(o.seed).text, o.verdict)
            print(f"\n== seed {o.seed}: {cluster}\n{small}-- {verdict.detail}")
            if args.out:
                (args.out / f"seed{o.seed}.ngc").write_text(small)
    return 0


if __name__ == "__main__":
    sys.exit(main())
