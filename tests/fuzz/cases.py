"""Fuzz cases: bad, broken and hostile inputs, each with the command that runs it.

A case is a folder of files (the program, sometimes a subroutine file or a
link) and the arguments of one ``gcodekit`` command, or ``["api", ...]`` for
the library's own entry points.  :func:`make_cases` draws them from a seed,
so a failing case is found again from its seed and number.

Kinds:

* ``bytes``: random bytes, random text in odd encodings, NUL-laden data;
* ``container``: corrupt, truncated and bomb-like archives, UTF-16, CR-only
  line ends, over-long lines;
* ``mutated``: real programs (the bundled examples and, when present, the
  LinuxCNC corpus) with bytes flipped, lines doubled or dropped, numbers
  blown up and hostile lines spliced in;
* ``hostile``: programs written to run away or to break the interpreter
  (endless loops, huge repeat counts, tiny pecks, giant arcs, deep
  recursion, expression bombs, paths in subroutine names, ...).
"""

from __future__ import annotations

import bz2
import gzip
import lzma
import random
from dataclasses import dataclass, field
from pathlib import Path

from shared_corpus import CORPUS as SHARED_CORPUS

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
CORPUS = SHARED_CORPUS / "linuxcnc" / "nc_files"

#: Every command runs under this motion limit: it keeps the worst case within the
#: suite's 2 GB memory cap (the default, 50 million, is sized for real programs).
FUZZ_MAX_MOTIONS = "1000000"
KINDS = ("bytes", "container", "mutated", "hostile")


@dataclass
class Case:
    """One input and the command that reads it."""

    name: str
    kind: str
    program: str  # file name of the program inside the case folder
    files: dict[str, bytes] = field(default_factory=dict)
    links: dict[str, str] = field(default_factory=dict)  # name -> target (a link out of the folder)
    args: list[str] = field(default_factory=list)  # the command; "{program}" and "{out}" are filled in


# -- commands ----------------------------------------------------------------------------------

def _commands(program: str, rng: random.Random, *, additive: bool, mill: bool) -> list[list[str]]:
    """The commands one input can go through, each with the fuzz limit."""
    limit = ["--max-motions", FUZZ_MAX_MOTIONS]
    out = [["info", program, *limit], ["info", program, "--json", *limit], ["info", program, "--strict", *limit],
           ["export", program, "--to", "csv", "-o", "{out}/m.csv", *limit],
           ["export", program, "--to", "parquet", "-o", "{out}/m.parquet", *limit],
           ["export", program, "--to", "events", "-o", "{out}/e.csv", *limit],
           ["api", program]]
    if additive:
        out.append(["export", program, "--to", "vtk", "-o", "{out}/p.vtp", *limit])
    if mill:
        out.append(["translate", program, "--stage", str(rng.randrange(7)), "-o", "{out}/t.ngc", *limit])
    if rng.random() < 0.08:
        out.append(["render", program, "-o", "{out}/r.png", "--size", "200x150", *limit])
    if rng.random() < 0.08:
        out.append(["report", program, "-o", "{out}/rep", "--no-pdf", *limit])
    return out


# -- random bytes and odd encodings ------------------------------------------------------------

def _random_bytes(rng: random.Random) -> bytes:
    choice = rng.randrange(5)
    n = rng.choice([0, 1, 17, 512, 4096, 70_000])
    if choice == 0:
        return rng.randbytes(n)
    if choice == 1:  # printable garbage with G-code letters
        return "".join(rng.choice("GXYZMFEIJKRPQ0123456789.-+ ;()#[]<>\n\r\t%/*=@^") for _ in range(n)).encode()
    if choice == 2:  # text in a random encoding
        text = "".join(rng.choice("G1X2Y3 é→中€\n;(comment)") for _ in range(n))
        return text.encode(rng.choice(["utf-8", "utf-16", "utf-32", "latin-1", "cp1252"]), "replace")
    if choice == 3:
        return b"\x00" * n + b"G1 X1\n"
    return bytes(rng.choice(b"\x00\xff\n\r ") for _ in range(n))


# -- containers --------------------------------------------------------------------------------

def _program_text(rng: random.Random) -> bytes:
    lines = [f"G1 X{rng.uniform(-50, 50):.3f} Y{rng.uniform(-50, 50):.3f} F{rng.randint(100, 3000)}"
             for _ in range(rng.randint(20, 400))]
    return ("G21 G90\n" + "\n".join(lines) + "\nM2\n").encode()


def _container(rng: random.Random) -> tuple[str, bytes]:
    text = _program_text(rng)
    choice = rng.randrange(10)
    if choice == 0:  # truncated gzip
        data = gzip.compress(text)
        return "p.gcode.gz", data[: rng.randint(0, len(data) - 1)]
    if choice == 1:  # corrupt gzip
        data = bytearray(gzip.compress(text))
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(10, len(data))] = rng.randrange(256)
        return "p.gcode.gz", bytes(data)
    if choice == 2:  # gzip whose contents expand a thousandfold, with no newline
        return "p.gcode.gz", gzip.compress(b"G" * rng.choice([1 << 20, 1 << 24]))
    if choice == 3:
        data = (bz2.compress if rng.random() < 0.5 else lzma.compress)(text)
        return "p.gcode.xz", data[: rng.randint(0, len(data))]
    if choice == 4:  # CR-only line ends
        return "p.ngc", text.replace(b"\n", b"\r")
    if choice == 5:
        return "p.ngc", text.decode().encode("utf-16")
    if choice == 6:  # one over-long line: a comment or a block of words
        body = b";" + b"x" * rng.choice([70_000, 300_000, 5_000_000]) if rng.random() < 0.5 else \
            b"G1 X1 " * rng.choice([20_000, 200_000])
        return "p.gcode", text[:200] + b"\n" + body + b"\n" + text[200:]
    if choice == 7:
        return "p.zip", b"PK\x03\x04" + rng.randbytes(200)
    if choice == 8:  # a gzip of several members, the last truncated
        a, b = gzip.compress(text), gzip.compress(text)
        return "p.gcode.gz", a + b[: len(b) // 2]
    return "p.ngc", b"\xef\xbb\xbf" + text  # UTF-8 byte-order mark


# -- mutated real programs ---------------------------------------------------------------------

def _sources() -> list[Path]:
    found = sorted(p for p in EXAMPLES.iterdir() if p.is_file())
    if CORPUS.is_dir():
        found += sorted(p for p in CORPUS.glob("*.ngc"))[:120]
    return found


def _mutate(rng: random.Random, data: bytes) -> bytes:
    lines = data.split(b"\n")[:3000]
    for _ in range(rng.randint(1, 12)):
        if not lines:
            break
        i = rng.randrange(len(lines))
        edit = rng.randrange(8)
        line = lines[i]
        if edit == 0 and line:  # flip a byte
            j = rng.randrange(len(line))
            lines[i] = line[:j] + bytes([rng.randrange(256)]) + line[j + 1:]
        elif edit == 1:
            lines.insert(i, line)
        elif edit == 2:
            del lines[i]
        elif edit == 3:  # a number blown up or shrunk
            digits = rng.choice([b"999999999", b"0.0000001", b"-1e5", b"1" + b"0" * 300, b"nan", b"0"])
            lines[i] = line + b" " + rng.choice(b"XYZIJKRQLPFSTHDEN").to_bytes(1, "big") + digits
        elif edit == 4:
            lines.insert(i, rng.choice(HOSTILE_LINES))
        elif edit == 5:  # a line cut short
            lines[i] = line[: rng.randint(0, len(line))]
        elif edit == 6:
            lines[i] = line.replace(b" ", b"", 1)
        else:
            lines = lines[:i]  # the file cut short
    return b"\n".join(lines)


# -- hostile programs --------------------------------------------------------------------------

HOSTILE_LINES = [
    b"G83 X1 Y1 Z-100 R1 Q0.00001 F100", b"G81 X1 Y1 Z-1 R1 L999999999 F100", b"M98 P1000 L999999999",
    b"T99999999 M6", b"G43 H99999999", b"o<../../../../etc/passwd> call", b"#1=[1/0]", b"#99999=1",
    b"G2 X0 Y0 I100000000 J0 F1000", b"(" * 50 + b")" * 50, b"[" * 200 + b"1" + b"]" * 200,
    b"M23 G0", b"G76 P1 Z-10 I-0.5 J0.0000001 K1 R1", b"%", b"M30", b"N99999999999999999999 G1",
    b"G10 L2 P999 X1", b"G5.2 X1 Y1 P1 L3", b"G38.2 Z-10 F100", b"M117 " + b"\xe2\x80\xae" * 20,
    b"SET_VELOCITY_LIMIT ACCEL=-1", b"EXTRUDERSPEED2(1e9, 0, 0)", b"DrillGrid 1000000 1000000 1 1 1",
]


def _hostile(rng: random.Random) -> tuple[str, bytes, dict[str, bytes], dict[str, str]]:
    n = lambda lo, hi: rng.choice([lo, hi, rng.randint(lo, hi)])  # noqa: E731
    big = rng.choice([10**6, 10**9, 999999999, 2**31, 10**15])
    extra: dict[str, bytes] = {}
    links: dict[str, str] = {}
    programs = [
        ("loop_idle.ngc", "#1=0\no100 while [1]\n#1=[#1+1]\no100 endwhile\nM2\n"),
        ("loop_moving.ngc", "#1=0\no100 while [1]\nG1 X[#1 MOD 10] F1000\n#1=[#1+1]\no100 endwhile\nM2\n"),
        ("do_while.ngc", "o1 do\nG0 X1\nG0 X0\no1 while [1]\nM2\n"),
        ("repeat.ngc", f"o1 repeat [{big}]\nG1 X1 F100\nG1 X0\no1 endrepeat\nM2\n"),
        ("recursion.ngc", "o<r> sub\no<r> call\no<r> endsub\no<r> call\nM2\n"),
        ("m98_repeat.nc", f"O1\nM98 P1000 L{big}\nM30\nO1000\nG1 X1 F100\nM99\n"),
        ("m98_self.nc", "O1\nM98 P1000\nM30\nO1000\nM98 P1000\nM99\n"),
        ("cycle_repeat.ngc", f"G21 G90 G0 Z5\nG81 X1 Y1 Z-1 R1 L{big} F100\nM2\n"),
        ("cycle_incremental.ngc", f"G21 G91 G0 Z5\nG81 X1 Y1 Z-1 R1 L{big} F100\nM2\n"),
        ("peck.ngc", f"G21 G90 G0 Z5\nG83 X1 Y1 Z-{n(1, 10**6)} R1 Q0.{'0' * n(1, 12)}1 F100\nM2\n"),
        ("thread.ngc", f"G21 G90 G0 X10 Z5 S100 M3\nG76 P1 Z-10 I-0.5 J0.{'0' * n(1, 9)}1 K1 R{rng.choice([1, 3, 9])} "
                       f"H{n(0, 10**9)}\nM2\n"),
        ("arc_klipper.gcode", f"G21\nG90\nG0 X0 Y0\nG2 X0 Y0 I{big} J0 F1000\n"),
        ("arc_r.ngc", f"G21 G90 G0 X0 Y0\nG2 X1 Y0 R{big} F100\nM2\n"),
        ("expr_depth.ngc", "#1=" + "[" * n(10, 5000) + "1" + "]" * n(10, 5000) + "\nM2\n"),
        ("expr_overflow.ngc", "#1=2\no1 repeat [2000]\n#1=[#1*#1]\no1 endrepeat\nG1 X#1 F100\nM2\n"),
        ("expr_math.ngc", "G1 X[SQRT[-1]] Y[LN[0]] Z[1/0] F[ACOS[2]]\nM2\n"),
        ("long_name.ngc", f"o<{'a' * n(100, 100_000)}> call\nM2\n"),
        ("many_words.gcode", "G1 " + " ".join(f"X{i}" for i in range(n(100, 100_000))) + "\n"),
        ("huge_number.ngc", "G1 X" + "9" * n(20, 5000) + " F100\nM2\n"),
        ("tools.ngc", f"T{big} M6\nG43 H{big}\nG1 X1 F100\nM2\n"),
        ("traversal.ngc", "o<../../../../etc/passwd> call\no<..\\\\x> call\nM2\n"),
        ("link.ngc", "o<evil> call\nM2\n"),
        ("params.ngc", f"#{big}=1\n#-1=2\n#<{'n' * 5000}>=3\nG1 X#{big} F100\nM2\n"),
        ("spline.ngc", f"G21 G90 G0 X0 Y0\nG5 I0 J{big} P{big} Q0 X{big} Y0 F100\nM2\n"),
        ("lathe.ngc", f"G18 G21 G90 G0 X10 Z1\nG71 Q100 X10 Z1 D0.{'0' * n(1, 9)}1 I0.{'0' * n(1, 9)}1\n"
                      "M2\no100 sub\nG1 X5 Z0\nG1 Z-20\nG1 X10\no100 endsub\n"),
        ("wizard.ger", f"G21\nDrillGrid {n(1, 10**6)} {n(1, 10**6)} 1 1 1\nM2\n"),
        ("comment_bomb.ngc", "(" * n(2, 100_000) + "\nG1 X1 F100\nM2\n"),
        ("percent.ngc", "%\nG1 X1 F100\n%\n" + "garbage\n" * n(1, 10000)),
        ("klipper_cmds.gcode", "SET_VELOCITY_LIMIT ACCEL=-1 VELOCITY=0\nG1 X10 F-100\nM204 S0\nG4 P-1\n"
                               f"G1 X{big} E{big} F1\n"),
        ("cead.mpf", f"; G-CODE FOR AM FLEXBOT\nEXTRUDERSPEED2({big}, 0, 0)\nEM=1\nG1 X{big} F1\n"),
        ("ded.nc", f"M61\nG1 X{big} A{big} B{big} F1\nM62\n"),
    ]
    name, text = rng.choice(programs)
    if name == "link.ngc":
        links["evil.ngc"] = "/etc/hostname"
    if name == "recursion.ngc" and rng.random() < 0.5:
        extra["r2.ngc"] = b"o<r2> sub\no<r2> call\no<r2> endsub\n"
    return name, text.encode(), extra, links


# -- the whole set -----------------------------------------------------------------------------

def make_cases(count: int, seed: int) -> list[Case]:
    """``count`` cases drawn from ``seed``, the kinds in turn, each with one command."""
    rng = random.Random(seed)
    sources = _sources()
    cases = []
    for k in range(count):
        kind = KINDS[k % len(KINDS)]
        files: dict[str, bytes] = {}
        links: dict[str, str] = {}
        if kind == "bytes":
            program, data = rng.choice(["p.gcode", "p.ngc", "p.nc", "p.mpf"]), _random_bytes(rng)
        elif kind == "container":
            program, data = _container(rng)
        elif kind == "mutated":
            source = rng.choice(sources)
            program, data = source.name, _mutate(rng, source.read_bytes())
        else:
            program, data, files, links = _hostile(rng)
        files[program] = data
        suffix = program.lower()
        additive = suffix.endswith((".gcode", ".gz", ".mpf", ".nc"))
        mill = suffix.endswith((".ngc", ".nc", ".ger", ".xz"))
        args = rng.choice(_commands(program, rng, additive=additive, mill=mill))
        cases.append(Case(f"{seed}-{k:05d}-{kind}-{program}", kind, program, files, links, args))
    return cases
