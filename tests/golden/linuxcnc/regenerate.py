#!/usr/bin/env python3
"""Select and copy the LinuxCNC golden cases from the shared corpus.

Reference: LinuxCNC 2.9.0~pre1 ``rs274`` (Debian 12 package linuxcnc-uspace),
run headless by ``../shared/tools/linuxcnc/run_rs274.sh`` and tabulated by
``canon_to_csv.py --src``.

A program qualifies when ``RESULTS.tsv`` marks it ``ok``, it has motions, all
of them matched to a source line (``line_match`` ok, ``nurbs`` for splines,
or ``order`` for moves rs274 emitted late), no rotary-axis work or G92 offset is active (the CSV
only carries X/Y/Z offsets), its text (comments stripped) uses no feature
gcodekit does not emulate yet (:data:`EXCLUDED_G`;
I/O M-codes, user or unknown
codes, system parameters other than the probe results #5061-#5070 and the
machine-state ones of :mod:`gcodekit.emulate.state_parameters`), and it is
not a :data:`KNOWN_GAPS` program; the subroutine files it calls by name and
rs274 found beside it are scanned too and copied with it.

Usage::

    python tests/golden/linuxcnc/regenerate.py [--corpus DIR] [--rerun]

``--rerun`` re-runs ``/usr/bin/rs274`` on every case first (the corpus
``.canon.csv`` files are used otherwise).  Programs in ``own/`` (ours, for
features the corpus lacks) are always cases; ``--rerun`` refreshes their
``.canon.csv`` too, with the tool table ``own/NAME.tbl`` when there is one.  Writes ``manifest.tsv`` and
``cases/``.
"""

from __future__ import annotations

import argparse
import csv
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from gcodekit.emulate.state_parameters import is_state_parameter

HERE = Path(__file__).resolve().parent
CASES = HERE / "cases"
OWN = HERE / "own"  # programs we wrote for what the corpus lacks, with rs274's output
TABLES = Path(__file__).parent / "tooltables"
MANIFEST = HERE / "manifest.tsv"
SHARED = HERE.parents[3] / "shared"
TOOLS = SHARED / "tools" / "linuxcnc"
RS274 = Path("/usr/bin/rs274")
REFERENCE = "LinuxCNC 2.9.0~pre1 rs274 (Debian 12 linuxcnc-uspace)"

COMMENT = re.compile(r"\([^)]*\)|;.*")
NAMED = re.compile(r"#<([^>]*)>")
ANGLED = re.compile(r"<[^>]*>")
LETTER_RUN = re.compile(r"[A-Z]{2,}")  # functions, operators and O-word keywords
CODE = re.compile(r"(?<![A-Z])([GM])(\d+(?:\.\d+)?)")
COMPUTED_CODE = re.compile(r"(?<![A-Z])[GM][\[#]")
SYSTEM_NUMBERED = re.compile(r"#(5\d{3})(?!\d)")
CALL = re.compile(r"o\s*<\s*([^>]*?)\s*>\s*call", re.I)  # a subroutine called by name

#: Predefined (read-only) named parameters of LinuxCNC 2.9.
SYSTEM_NAMED = frozenset("""
_vmajor _vminor _line _motion_mode _plane _ccomp _metric _imperial _absolute
_incremental _inverse_time _units_per_minute _units_per_rev _coord_system
_tool_offset _retract_r_level _retract_old_z _spindle_rpm_mode _spindle_css_mode
_ijk_absolute_mode _lathe_diameter_mode _lathe_radius_mode _spindle_on
_spindle_cw _mist _flood _speed_override _feed_override _adaptive_feed
_feed_hold _feed _rpm _x _y _z _a _b _c _u _v _w _abs_x _abs_y _abs_z _abs_a
_abs_b _abs_c _current_tool _current_pocket _selected_tool _selected_pocket
_value _value_returned _task _call_level _remap_level
""".split())

#: Predefined parameters the control-flow stage keeps (gcodekit.preprocess.flow).
FLOW_NAMED = frozenset({"_value", "_value_returned", "_call_level"})

#: Programs gcodekit knows it does not reproduce yet, and why.
KNOWN_GAPS: dict[str, str] = {}

#: G-codes (as written, leading zeros dropped) gcodekit does not emulate yet.
EXCLUDED_G: dict[str, str] = {}
ALLOWED_G = frozenset("""
0 1 2 3 4 5 5.1 5.2 5.3 7 8 10 17 33 33.1 70 71 76 71.1 71.2 72 72.1 72.2 17.1 38.2 38.3 38.4 38.5 41.1 42.1 73 74 81 82 83 84 85 86 87 88 89 18 18.1 19 19.1 20 21 28 28.1 30 30.1 40 41 42 43 43.1 43.2 49 52 53 54 55 56 57 58
59 59.1 59.2 59.3 61 61.1 64 80 90 90.1 91 91.1 92 92.1 92.2 92.3 93 94 95 96 97
98 99
""".split())
EXCLUDED_M = {
    # M66 (wait for an input) returns at once in rs274 standalone: only reading #5399 would matter
    **dict.fromkeys(("62", "63", "64", "65", "67", "68"), "digital/analog I/O"),
}
ALLOWED_M = frozenset("0 1 2 3 4 5 6 7 8 9 19 30 48 49 50 51 52 53 60 61 66 70 71 72 73".split())


@dataclass
class Entry:
    """One corpus program and the verdict on it."""

    program: str
    motions: int
    golden: bool
    reason: str
    subroutines: tuple[Path, ...] = ()  # files of subroutines it calls, copied next to the case


def normalize(code: str) -> str:
    """``"01"`` -> ``"1"``, ``"38.20"`` -> ``"38.2"``."""
    whole, _, frac = code.partition(".")
    frac = frac.rstrip("0")
    return str(int(whole)) + ("." + frac if frac else "")


def scan_text(text: str) -> tuple[list[str], list[str]]:
    """Return (exclusion reasons, codes used) for a program's text."""
    reasons: dict[str, None] = {}
    body = "\n".join(COMMENT.sub("", line) for line in text.upper().splitlines())
    body = re.sub(r"[ \t\r]", "", body)
    for name in NAMED.findall(body):
        key = name.lower()
        if (key in SYSTEM_NAMED and not (is_state_parameter(key) or key in FLOW_NAMED)) \
                or key.startswith(("_ini[", "_hal[")):
            reasons[f"system parameter #<{key}>"] = None
    body = ANGLED.sub("<>", body)
    body = LETTER_RUN.sub(" ", body)
    # probe results #5061-#5070 and the machine's state are emulated
    if any(not (5061 <= int(k) <= 5070 or is_state_parameter(int(k))) for k in SYSTEM_NUMBERED.findall(body)):
        reasons["system parameter #5xxx"] = None
    if COMPUTED_CODE.search(body):
        reasons["computed G/M code"] = None
    used: dict[str, None] = {}
    for letter, raw in CODE.findall(body):
        code = normalize(raw)
        used[letter + code] = None
        excluded, allowed = (EXCLUDED_G, ALLOWED_G) if letter == "G" else (EXCLUDED_M, ALLOWED_M)
        why = excluded.get(code) or (None if code in allowed else "unknown, user or remapped code")
        if why:
            reasons[f"{why} ({letter}{code})"] = None
    return list(reasons), sorted(used, key=lambda c: (c[0], float(c[1:])))


def scan_canon(canon: Path) -> list[str]:
    """Exclusion reasons found in the raw canon stream (offsets the CSV lacks)."""
    reasons = []
    for line in canon.read_text(errors="replace").splitlines():
        for name in ("SET_G5X_OFFSET", "SET_G92_OFFSET"):
            if name + "(" in line:
                args = [float(v) for v in line.split("(", 1)[1].rstrip(") ").split(",")]
                abc = args[4:7] if name == "SET_G5X_OFFSET" else args[3:6]
                if any(abc):
                    reasons.append("rotary-axis offset not in the CSV")
    return sorted(set(reasons))


def scan_csv(path: Path) -> tuple[int, list[str]]:
    """Return (motion count, exclusion reasons) of a ``.canon.csv``."""
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    # "order": rs274 emitted the motion late (cutter compensation queues moves);
    # its position in the sequence still counts, its source line is not checked.
    # "nurbs": a spline (NURBS_FEED), its line and end point from the gcode module.
    bad = sum(r["line_match"] not in ("ok", "order", "nurbs") for r in rows)
    reasons = [f"{bad} motion(s) with line_match not ok/order/nurbs"] if bad else []
    if not rows:
        reasons.append("no motions")
    return len(rows), reasons


def rerun(program: Path, table: Path | None, canon: Path) -> None:
    """Run rs274 on ``program`` into ``canon`` and tabulate it into ``canon`` + ``.csv``."""
    cmd = [str(TOOLS / "run_rs274.sh"), str(program)] + ([str(table)] if table else [])
    with canon.open("w") as f:
        subprocess.run(cmd, stdout=f, check=True)
    python = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable  # has LinuxCNC's gcode
    cmd = [python, str(TOOLS / "canon_to_csv.py"), str(canon), "-o", f"{canon}.csv",
           "--src", str(program)] + (["--tbl", str(table)] if table else [])
    subprocess.run(cmd, check=True)


def read_tables(corpus: Path) -> dict[str, Path]:
    """Per-program tool tables from ``TOOLTABLE_OVERRIDES.tsv``."""
    tables = {}
    for line in (corpus / "TOOLTABLE_OVERRIDES.tsv").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            program, table = line.split("\t")[:2]
            tables[program] = corpus / table
    return tables


def case_name(program: str) -> str:
    """Flat file name of a case: ``nc_files/a/b.ngc`` -> ``a__b.ngc``."""
    return program.removeprefix("nc_files/").replace("/", "__")


def judge(corpus: Path, row: dict[str, str], tables: dict[str, Path],
          rerun_dir: Path | None) -> Entry:
    """Decide on one ``RESULTS.tsv`` row; with ``rerun_dir``, run rs274 afresh into it."""
    program = row["file"]
    path = corpus / program
    if row["status"] != "ok":
        error = " ".join(row["error"].split())[:80]
        return Entry(program, int(row["motions"] or 0), False, f"rs274 {row['status']}: {error}")
    reasons, used = scan_text(path.read_text(errors="replace"))
    subroutines = called_files(path)
    for sub in subroutines:  # rs274 ran in the program's directory and found these there
        more, more_used = scan_text(sub.read_text(errors="replace"))
        reasons += [f"{why} in {sub.name}" for why in more]
        used = sorted(set(used) | set(more_used), key=lambda c: (c[0], float(c[1:])))
    canon = path.with_name(path.name + ".canon")
    if rerun_dir is not None and not reasons:
        canon = rerun_dir / (case_name(program) + ".canon")
        rerun(path, tables.get(program), canon)
    reasons += scan_canon(canon)
    motions, csv_reasons = scan_csv(canon.with_name(canon.name + ".csv"))
    reasons += csv_reasons
    if program in KNOWN_GAPS:
        reasons.append(KNOWN_GAPS[program])
    return Entry(program, motions, not reasons, "; ".join(reasons) or "uses " + " ".join(used),
                 tuple(subroutines))


def called_files(path: Path) -> list[Path]:
    """Files ``name.ngc`` beside ``path`` of the subroutines it calls by name but does not define."""
    found: list[Path] = []
    todo = [path]
    while todo:
        text = "\n".join(COMMENT.sub("", line) for line in todo.pop().read_text(errors="replace").splitlines())
        defined = {m.lower() for m in re.findall(r"o\s*<\s*([^>]*?)\s*>\s*sub", text, re.I)}
        for name in CALL.findall(text):
            sub = path.with_name(name.lower() + ".ngc")
            if name.lower() not in defined and sub.exists() and sub not in found:
                found.append(sub)
                todo.append(sub)
    return found


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", type=Path, default=SHARED / "corpus" / "linuxcnc")
    ap.add_argument("--rerun", action="store_true", help=f"re-run {RS274} for every case")
    args = ap.parse_args(argv)
    if args.rerun and not RS274.exists():
        ap.error(f"--rerun needs {RS274}: apt-get install -y --no-install-recommends "
                 "linuxcnc-uspace")
    corpus: Path = args.corpus
    tables = read_tables(corpus)
    with (corpus / "RESULTS.tsv").open(newline="") as f:
        results = list(csv.DictReader(f, delimiter="\t"))

    entries: list[Entry] = []
    with tempfile.TemporaryDirectory() as tmp:
        chosen: list[str] = []
        for row in results:
            entry = judge(corpus, row, tables, Path(tmp) if args.rerun else None)
            entries.append(entry)
            if entry.golden:
                chosen.append(entry.program)
        CASES.mkdir(exist_ok=True)
        for old in CASES.iterdir():
            old.unlink()
        for entry in entries:
            for sub in entry.subroutines if entry.golden else ():
                shutil.copyfile(sub, CASES / sub.name)  # found beside the case, as rs274 found it
        for program in chosen:
            name = case_name(program)
            fresh = Path(tmp) / (name + ".canon.csv")
            expected = fresh if args.rerun else corpus / (program + ".canon.csv")
            shutil.copyfile(corpus / program, CASES / name)
            shutil.copyfile(expected, CASES / (name + ".canon.csv"))
        for program in sorted(OWN.glob("*.ngc")):
            table = program.with_suffix(".tbl")  # a table of its own beside it, else rs274's default
            if args.rerun:
                rerun(program, table if table.exists() else None, Path(tmp) / (program.name + ".canon"))
                shutil.copyfile(Path(tmp) / (program.name + ".canon.csv"), OWN / (program.name + ".canon.csv"))
            if table.exists():
                shutil.copyfile(table, CASES / ("own__" + table.name))
            shutil.copyfile(program, CASES / ("own__" + program.name))
            shutil.copyfile(OWN / (program.name + ".canon.csv"), CASES / ("own__" + program.name + ".canon.csv"))
            chosen.append(f"own/{program.name}")
    # the tool tables rs274 ran with (inches), and which case used which
    TABLES.mkdir(exist_ok=True)
    for table in (corpus / "tooltables").glob("*.tbl"):
        shutil.copyfile(table, TABLES / table.name)
    shutil.copyfile(corpus / "TOOLTABLE_OVERRIDES.tsv", TABLES / "overrides.tsv")
    with MANIFEST.open("w", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(["program", "motions", "golden", "reason"])
        for e in sorted(entries, key=lambda e: (not e.golden, e.program)):
            w.writerow([e.program, e.motions, "yes" if e.golden else "no", e.reason])
    own = sum(program.startswith("own/") for program in chosen)
    print(f"{len(chosen) - own} of {len(entries)} corpus programs and {own} of our own are golden cases ({REFERENCE})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
