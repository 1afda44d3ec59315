"""Program files that are not plain text: damaged archives, encodings, line ends, over-long lines.

Each problem is said once, naming the file (and the line where reading
stopped), and nothing is read wrongly: a line cut off by a damaged archive
is dropped rather than read as a shorter number.
"""

from __future__ import annotations

import bz2
import gzip
import lzma

import pytest
from cli_helpers import run

import gcodekit
import gcodekit.pipeline.source
from gcodekit.errors import GcodeError, ProgramFileError
from gcodekit.read import MAX_LINE_LENGTH

PROGRAM = "".join(f"G1 X{k}.5 Y{2 * k} F600\n" for k in range(1, 2001))  # 2000 feed moves, distinct X


@pytest.fixture(autouse=True, params=["serial", "read ahead"])
def reader(request, monkeypatch):
    """Each test twice: read on the calling thread, and read ahead on a second thread (large files' way)."""
    if request.param == "read ahead":
        monkeypatch.setattr(gcodekit.pipeline.source, "READ_AHEAD_BYTES", 0)
    else:
        monkeypatch.setattr(gcodekit.pipeline.source, "READ_AHEAD_BYTES", 1 << 62)


def xs(op) -> list[float]:
    return op.motions()["x"].tolist()


def test_a_truncated_gzip_is_reported_and_its_cut_line_dropped(tmp_path):
    data = gzip.compress(PROGRAM.encode())
    path = tmp_path / "cut.gcode.gz"
    path.write_bytes(data[: len(data) * 2 // 3])
    op = gcodekit.gcode_to_operation(path, "marlin", plan=False)
    (error,) = op.diagnostics.errors
    read = len(op.motions())
    assert 0 < read < 2000
    assert error.file == str(path) and error.line == read + 1 and error.column == 1
    assert "truncated" in error.message and f"only its first {read} lines were read" in error.message
    # every move read is whole: X of move k is k + 0.5, never a cut-off number
    assert xs(op) == [k + 0.5 for k in range(1, read + 1)]
    with pytest.raises(ProgramFileError, match=r"cut\.gcode\.gz:\d+:1: .*truncated"):
        gcodekit.gcode_to_operation(path, "marlin", mode="strict")


def test_a_corrupt_gzip_is_reported_by_every_command(tmp_path, capsys):
    data = bytearray(gzip.compress(PROGRAM.encode()))
    data[len(data) // 2: len(data) // 2 + 8] = b"\x00" * 8
    path = tmp_path / "bad.ngc.gz"
    path.write_bytes(bytes(data))
    op = gcodekit.gcode_to_operation(path, "linuxcnc", plan=False)
    assert any("corrupt" in d.message and d.file == str(path) for d in op.diagnostics.errors)
    for args in (["info", path], ["export", path, "--to", "csv", "-o", tmp_path / "m.csv"],
                 ["translate", path, "-o", tmp_path / "t.ngc"]):
        status, _, err = run(args, capsys)
        assert "Traceback" not in err and "internal error" not in err
        assert status == 0  # lenient: what could be read is read, the damage is reported
    status, out, _ = run(["info", path], capsys)
    assert "bad.ngc.gz" in out and "corrupt" in out


@pytest.mark.parametrize("compress, suffix", [(bz2.compress, ".bz2"), (lzma.compress, ".xz")])
def test_bzip2_and_xz_programs_are_read(tmp_path, compress, suffix):
    path = tmp_path / f"p.gcode{suffix}"
    path.write_bytes(compress(PROGRAM.encode()))
    op = gcodekit.gcode_to_operation(path, "marlin", plan=False)
    assert len(op.motions()) == 2000 and not op.diagnostics.errors


def test_old_mac_line_ends_are_lines(tmp_path):
    path = tmp_path / "mac.ngc"
    path.write_bytes(b"G21 G90\rG0 X1\rG1 X2 F100\rG1 Y3\rM2\r")
    op = gcodekit.gcode_to_operation(path, "linuxcnc", plan=False)
    assert op.motions()[["x", "y"]].values.tolist() == [[1, 0], [2, 0], [2, 3]]
    assert op.motions()["line"].tolist() == [2, 3, 4]
    (note,) = op.diagnostics.items
    assert note.severity == "info" and "CR alone" in note.message


def test_utf16_and_byte_order_marks(tmp_path):
    for encoding, name in (("utf-16", "u16.gcode"), ("utf-8-sig", "bom.gcode")):
        path = tmp_path / name
        path.write_text("G21\nG1 X1 F100\nG1 X2\n", encoding=encoding)
        op = gcodekit.gcode_to_operation(path, "marlin", plan=False)
        assert xs(op) == [1.0, 2.0] and not op.diagnostics.errors


def test_binary_data_and_zip_archives_are_refused_in_one_message(tmp_path):
    binary = tmp_path / "image.gcode"
    binary.write_bytes(b"\x00\x01\x02\x00" * 5000)
    archive = tmp_path / "job.gcode"
    archive.write_bytes(b"PK\x03\x04" + bytes(300))
    for path, words in ((binary, "binary data"), (archive, "ZIP archive")):
        op = gcodekit.gcode_to_operation(path, "marlin", plan=False)
        assert [d.message for d in op.diagnostics] == [m for m in [op.diagnostics.items[0].message] if words in m]
        assert len(op.motions()) == 0


def test_an_over_long_line_is_skipped_without_holding_it(tmp_path):
    """A 20 MB comment is read in bounded pieces and skipped; the lines after keep their numbers."""
    path = tmp_path / "long.ngc"
    with open(path, "w") as f:
        f.write("G21 G90\nG0 X1\n(" + "a" * 20_000_000 + ")\nG1 X2 F100\nM2\n")
    op = gcodekit.gcode_to_operation(path, "linuxcnc", plan=False)
    (error,) = op.diagnostics.errors
    assert (error.line, error.column) == (3, 1) and f"longer than {MAX_LINE_LENGTH}" in error.message
    assert op.motions()[["line", "x"]].values.tolist() == [[2, 1], [4, 2]]


def test_a_file_of_over_long_lines_exports_an_empty_table(tmp_path, capsys):
    """Issue 14: the first 256 KiB all over-long lines once made Operation.motions fail (IndexError)."""
    path = tmp_path / "long.gcode"
    path.write_text(("X" * 70_000 + "\n") * 4)
    status, out, err = run(["export", path, "--to", "csv"], capsys)
    assert status == 0 and "Traceback" not in err
    assert out.splitlines()[0].startswith("line,motion,x,y,z") and len(out.splitlines()) == 1
    assert err.count("longer than") == 4


def test_a_strict_read_of_a_damaged_file_raises_gcodekits_error(tmp_path):
    path = tmp_path / "bad.gcode.gz"
    path.write_bytes(gzip.compress(b"G1 X1\n")[:15])
    with pytest.raises(GcodeError) as caught:
        gcodekit.gcode_to_operation(path, "marlin", mode="strict")
    assert isinstance(caught.value, OSError) and "bad.gcode.gz:1:1" in str(caught.value)
