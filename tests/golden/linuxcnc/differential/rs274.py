"""Run LinuxCNC's standalone rs274 on a program and read its canonical output.

rs274 (LinuxCNC 2.9.0~pre1, Debian 12 ``linuxcnc-uspace``) prints one
canonical call per line (``   12 N..... STRAIGHT_FEED(1.0000, ...)``) on
standard output and, when it refuses a block, the message and the block's
text on standard error.  :func:`run_rs274` runs it with the default tool table
(inches, as rs274 reads tables), an empty parameter file and its own
``HOME`` (rs274 writes ``~/.tool.mmap``), and :func:`canon_motions` turns the
canon into one row per motion with the offsets in force, in the columns of
``tests/golden/linuxcnc/cases/*.canon.csv`` (see ``test_linuxcnc_golden``).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

RS274 = Path("/usr/bin/rs274")
TOOL_TABLE = Path(__file__).resolve().parents[1] / "tooltables" / "tool.tbl"
_CALL = re.compile(r"^\s*\d+\s+N[.\d]*\s*([A-Z_][A-Z_0-9]*)\((.*)\)\s*$")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
MOTIONS = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED", "STRAIGHT_PROBE", "RIGID_TAP", "NURBS_FEED")


@dataclass(frozen=True)
class Reference:
    """rs274's reading of one program: its motions and, if it refused a block, why and which."""

    motions: list[dict]
    error: tuple[str, str] | None  # (message, block text)
    timed_out: bool = False


def available() -> bool:
    """True when rs274 is installed."""
    return RS274.exists() and shutil.which("timeout") is not None


def run_rs274(text: str, *, timeout: float = 30.0, table: Path = TOOL_TABLE) -> Reference:
    """rs274's motions (and error) for program ``text``, run in a fresh temporary folder."""
    with tempfile.TemporaryDirectory(prefix="gk_rs274_") as tmp:
        folder = Path(tmp)
        program = folder / "program.ngc"
        program.write_text(text)
        (folder / "params.var").write_text("")
        command = ["timeout", "-k", "5", str(timeout), str(RS274), "-g", "-n", "2", "-t", str(table),
                   "-v", str(folder / "params.var"), str(program)]
        done = subprocess.run(command, cwd=folder, capture_output=True, text=True, errors="replace",
                              stdin=subprocess.DEVNULL, env={"HOME": tmp, "PATH": "/usr/bin:/bin"})
    messages = [line for line in done.stderr.splitlines() if line.strip() and line.strip() != "executing"]
    error = None
    if done.returncode != 0 and done.returncode != 124:
        error = (messages[0] if messages else f"rs274 exit {done.returncode}", messages[1] if len(messages) > 1 else "")
    return Reference(canon_motions(done.stdout.splitlines()), error, timed_out=done.returncode == 124)


def canon_motions(lines: list[str]) -> list[dict]:
    """One dict per motion: type, end point and arc in program coordinates, and the state in force.

    Keys follow the ``.canon.csv`` columns: ``type x y z a b c feed feed_mode units plane arc_rotation
    arc_cx arc_cy arc_cz g5x_x g5x_y g5x_z g92_x g92_y g92_z xy_rot tlo_x tlo_y tlo_z``.

    Examples
    --------
    >>> rows = canon_motions(["  1 N..... USE_TOOL_LENGTH_OFFSET(0.1, 0.0, 0.5, 0, 0, 0, 0, 0, 0)",
    ...                       "  2 N..... STRAIGHT_FEED(1.0000, 2.0000, 3.0000, 0, 0, 0)"])
    >>> rows[0]["type"], rows[0]["x"], rows[0]["tlo_z"]
    ('STRAIGHT_FEED', 1.0, 0.5)
    """
    # offsets are kept in mm: the canon gives them in the units in force when they are set, and
    # rs274 does not send them again when G20/G21 change the units (a machine converts them on receipt)
    state = {"feed": 0.0, "feed_mode": 0, "units": "mm", "plane": "XY", "g5x": (0.0,) * 3, "g92": (0.0,) * 3,
             "xy_rot": 0.0, "tlo": (0.0,) * 3}
    mm = 1.0  # mm per unit of the numbers the canon prints now
    position = [0.0] * 6
    rows = []
    for line in lines:
        match = _CALL.match(line)
        if not match:
            continue
        name, args = match.groups()
        values = [float(v) for v in _NUMBER.findall(args)]
        if name == "USE_LENGTH_UNITS":
            state["units"] = "in" if "INCH" in args else "mm"
            mm = 25.4 if state["units"] == "in" else 1.0
        elif name == "SELECT_PLANE":
            state["plane"] = args.strip().replace("CANON_PLANE_", "")
        elif name == "SET_FEED_RATE":
            state["feed"] = values[0]
        elif name == "SET_FEED_MODE":
            state["feed_mode"] = int(values[-1])
        elif name == "SET_G5X_OFFSET":
            state["g5x"] = tuple(v * mm for v in values[1:4])
        elif name == "SET_G92_OFFSET":
            state["g92"] = tuple(v * mm for v in values[0:3])
        elif name == "SET_XY_ROTATION":
            state["xy_rot"] = values[0]
        elif name == "USE_TOOL_LENGTH_OFFSET":
            state["tlo"] = tuple(v * mm for v in values[0:3])
        if name not in MOTIONS:
            continue
        row = {"type": name, "feed": "" if name == "STRAIGHT_TRAVERSE" else state["feed"],
               "feed_mode": state["feed_mode"], "units": state["units"], "plane": state["plane"],
               "arc_rotation": "", "arc_cx": "", "arc_cy": "", "arc_cz": "", "xy_rot": state["xy_rot"],
               **{f"g5x_{k}": v / mm for k, v in zip("xyz", state["g5x"])},
               **{f"g92_{k}": v / mm for k, v in zip("xyz", state["g92"])},
               **{f"tlo_{k}": v / mm for k, v in zip("xyz", state["tlo"])}}
        if name == "ARC_FEED":
            first, second, first_axis, second_axis, rotation, axis_end = values[0:6]
            # the plane's (first, second | normal) axes: XY -> (x, y | z), YZ -> (y, z | x), XZ -> (z, x | y)
            if state["plane"] == "XY":
                end, centre = (first, second, axis_end), (first_axis, second_axis, "")
            elif state["plane"] == "YZ":
                end, centre = (axis_end, first, second), ("", first_axis, second_axis)
            else:
                end, centre = (second, axis_end, first), (second_axis, "", first_axis)
            row.update(arc_rotation=int(rotation), arc_cx=centre[0], arc_cy=centre[1], arc_cz=centre[2])
            position = list(end) + values[6:9]
        elif name == "RIGID_TAP":
            position = values[0:3] + position[3:6]
        elif name != "NURBS_FEED":
            position = values[0:6]
        row.update(zip("xyzabc", position))
        rows.append(row)
    return rows
