#!/usr/bin/env python3
"""Collect the LinuxCNC programs rs274 refuses into ``errors/`` (with the expected line).

Reference: LinuxCNC 2.9.0~pre1 ``rs274`` (Debian 12 package linuxcnc-uspace),
run headless by ``../shared/tools/linuxcnc/run_rs274.sh``; on an error it
stops and prints the message and the text of the block it was reading, kept
in the corpus as ``X.ngc.canon.err`` (``RESULTS.tsv`` status ``error``).

The expected source line is found from that block text:

* "File ended with no percent sign or program end": ``read_text`` hit the end
  of the file, so the line is the file's last line (its text is the block
  text; an empty text is a blank last line).
* Otherwise the lines of the program whose text equals the block text
  (stripped, case and blanks ignored).  One match is the line; among several,
  the first after the source line of the last motion in ``X.ngc.canon.csv``
  (``canon_to_csv.py --src``), since rs274 stops at the failing block.

Programs whose error comes from something gcodekit does not emulate are
skipped with the reason (see :data:`SKIP` and :data:`KNOWN_GAPS`); ``errors/manifest.tsv`` lists
every error program and ``errors/expected.tsv`` the kept ones:
``program  line  message  block``.

``own_errors/`` holds programs we wrote for rules the corpus lacks, each with
rs274's ``.canon.err`` beside it; they are copied in as ``own__NAME.ngc``
(``--rerun`` runs rs274 on them afresh first).

Usage::

    python tests/golden/linuxcnc/errors.py [--corpus DIR] [--rerun]
"""

from __future__ import annotations

import argparse
import csv
import re
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "errors"
OWN = HERE / "own_errors"
SHARED = HERE.parents[3] / "shared"
REFERENCE = "LinuxCNC 2.9.0~pre1 rs274 (Debian 12 linuxcnc-uspace)"
FILE_ENDED = "File ended with no percent sign"

#: rs274 messages whose cause gcodekit does not emulate at all.
SKIP = {
}

#: Programs gcodekit knows it does not refuse yet, and why.
KNOWN_GAPS = {
}


def squash(text: str) -> str:
    """Block text compared without case and blanks."""
    return re.sub(r"\s+", "", text).lower()


def last_motion_line(csv_path: Path) -> int:
    """Source line of the last motion rs274 made, 0 when none."""
    if not csv_path.exists():
        return 0
    with csv_path.open(newline="") as f:
        lines = [int(float(r["src_line"])) for r in csv.DictReader(f) if r.get("src_line")]
    return lines[-1] if lines else 0


def expected_line(program: Path, message: str, block: str) -> tuple[int | None, str]:
    """(line, how it was found) of the error, or (None, why not)."""
    lines = program.read_text(errors="replace").split("\n")
    if lines and lines[-1] == "":
        lines.pop()  # the newline ending the last line
    if message.startswith(FILE_ENDED):
        if squash(lines[-1]) != squash(block):
            return None, "the block text is not the last line"
        return len(lines), "last line of the file"
    hits = [k + 1 for k, text in enumerate(lines) if squash(text) == squash(block)]
    if len(hits) == 1:
        return hits[0], "the only line with the block text"
    if hits and "before EOF" in message:  # rs274 searched for a subprogram down to the end of the file
        return hits[-1], "last line with the block text (the search ran to the end of the file)"
    after = last_motion_line(program.with_name(program.name + ".canon.csv"))
    later = [k for k in hits if k > after]
    if later:
        return later[0], f"first line with the block text after the last motion (line {after})"
    return None, f"block text found on {len(hits)} lines"


def case_name(program: str) -> str:
    """Flat file name of a case: ``nc_files/a/b.ngc`` -> ``a__b.ngc`` (blanks and '#' as '_')."""
    return re.sub(r"[ #=]", "_", program.removeprefix("nc_files/").replace("/", "__"))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", type=Path, default=SHARED / "corpus" / "linuxcnc")
    ap.add_argument("--rerun", action="store_true", help="run rs274 on the programs of own_errors/ afresh")
    args = ap.parse_args(argv)
    corpus: Path = args.corpus
    with (corpus / "RESULTS.tsv").open(newline="") as f:
        results = [r for r in csv.DictReader(f, delimiter="\t") if r["status"] == "error"]
    own = sorted(OWN.glob("*.ngc"))
    if args.rerun:
        from differential.rs274 import run_rs274

        for program in own:
            refused = run_rs274(program.read_text()).error
            if refused is None:
                ap.error(f"rs274 runs {program} without an error")
            program.with_name(program.name + ".canon.err").write_text("\n".join(refused) + "\n")
    OUT.mkdir(exist_ok=True)
    for old in OUT.iterdir():
        old.unlink()
    manifest, expected = [], []
    for row in results:
        program = corpus / row["file"]
        err = program.with_name(program.name + ".canon.err")
        if not err.exists():
            manifest.append([row["file"], "", "no", "no .canon.err", ""])
            continue
        message, _, block = err.read_text(errors="replace").partition("\n")
        block = block.rstrip("\n")
        reason = next((why for key, why in SKIP.items() if message.startswith(key)), KNOWN_GAPS.get(row["file"]))
        line, how = (None, reason) if reason else expected_line(program, message, block)
        if line is None:
            manifest.append([row["file"], "", "no", how, message])
            continue
        name = case_name(row["file"])
        shutil.copyfile(program, OUT / name)
        shutil.copyfile(err, OUT / (name + ".canon.err"))
        manifest.append([row["file"], line, "yes", how, message])
        expected.append([name, line, message, block.strip()])
    for program in own:
        message, _, block = program.with_name(program.name + ".canon.err").read_text().partition("\n")
        line, how = expected_line(program, message, block.rstrip("\n"))
        name = "own__" + program.name
        shutil.copyfile(program, OUT / name)
        shutil.copyfile(program.with_name(program.name + ".canon.err"), OUT / (name + ".canon.err"))
        manifest.append([f"own_errors/{program.name}", line, "yes", how, message])
        expected.append([name, line, message, block.strip()])
    with (OUT / "manifest.tsv").open("w", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(["program", "line", "kept", "how or why not", "rs274 message"])
        w.writerows(sorted(manifest, key=lambda r: (r[2] != "yes", r[0])))
    with (OUT / "expected.tsv").open("w", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(["case", "line", "message", "block"])
        w.writerows(expected)
    print(f"{len(expected) - len(own)} of {len(results)} corpus error programs kept and {len(own)} of our own "
          f"({REFERENCE})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
