"""Read stage: the vectorized scanner must agree with the reference tokenizer."""

from __future__ import annotations

import gzip

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gcodekit.errors import Diagnostics, GcodeError
from gcodekit.read import Blocks, read_file, read_text
from gcodekit.read.tokenize import LineTokenizer
from gcodekit.read.scan import fast_path_possible
from gcodekit.syntax import list_flavors, load_flavor


def reference_blocks(text: str, flavor_name: str) -> tuple[Blocks, Diagnostics]:
    """Every line through the per-line tokenizer only."""
    flavor = load_flavor(flavor_name)
    diagnostics = Diagnostics()
    tokenizer = LineTokenizer(flavor, diagnostics)
    raw = []
    for number, line in enumerate(text.split("\n")[: text.count("\n") + (0 if text.endswith("\n") else 1)], 1):
        raw.extend(tokenizer.tokenize(line.rstrip("\r"), number))
    return Blocks.from_raw("<string>", raw), diagnostics


def by_line(blocks: Blocks) -> dict[int, tuple]:
    """Words and comments keyed by source line, ignoring empty blocks."""
    out = {}
    for i in range(len(blocks)):
        b = blocks[i]
        if b.words or b.comments or b.flags or b.named:
            out[b.line] = (tuple((w.letter, w.value, w.column) for w in b.words), b.comments, b.flags, b.named)
    return out


number = st.builds(
    lambda sign, whole, frac: sign + whole + frac,
    st.sampled_from(["", "-", "+"]),
    st.text("0123456789", max_size=6),
    st.one_of(st.just(""), st.text("0123456789", max_size=6).map(lambda d: "." + d)),
)
word = st.builds(lambda l, blank, n: l + blank + n, st.sampled_from("GMXYZEFIJKSTPgxy"),
                 st.sampled_from(["", "", " "]), number)
# codes whose argument is the rest of the line (a file name, a message) in some flavor
string_code = st.sampled_from(["M23", "M28", "M30", "M32", "M117", "M118", "M928", "m23", "M023", "M23.0"])
junk = st.sampled_from(["(note)", "\"s\"", "#1", "*12", "=", "[1]", "é", "\t", "  ", "/", "%", "@"])
line = st.lists(st.one_of(word, word, word, junk, string_code), max_size=6).map(" ".join)
comment = st.one_of(st.just(""), st.text(max_size=10).filter(lambda t: "\n" not in t and "\r" not in t).map(lambda t: " ;" + t))
program = st.lists(st.builds(lambda l, c: l + c, line, comment), max_size=12).map(lambda ls: "\n".join(ls) + "\n")


#: Every flavor the fast scanner reads (the others go through the tokenizer alone)
FAST_FLAVORS = [name for name in list_flavors() if fast_path_possible(load_flavor(name))]


@settings(max_examples=300, deadline=None)
@given(program, st.sampled_from(FAST_FLAVORS))
@example("M23 G0\n", "marlin")  # a file name that looks like words (found by a random draw, issue 14)
@example("G1 M23 G0 X1 ;c\n", "klipper")
@example("M28 G0\nM117 G1 X2\n", "reprapfirmware")
@example(" ;\x00\n", "bambu")  # a NUL in a comment of a tiny program: text, not binary (found by explore.sh)
def test_fast_scanner_matches_reference_tokenizer(text, flavor):
    fast = read_text(text, flavor=flavor)
    if any("not program text" in d.message for d in fast.diagnostics):  # the file's rule, before any scanner
        assert text.count("\x00") >= 8
        return
    ref, ref_diag = reference_blocks(text, flavor)
    assert by_line(fast) == by_line(ref)
    assert [str(d) for d in fast.diagnostics] == [str(d) for d in ref_diag]


def test_numbers_convert_exactly_like_python_float():
    rng = np.random.default_rng(7)
    values = [f"{v:.{d}f}" for v, d in zip(rng.normal(0, 1000, 2000), rng.integers(0, 9, 2000))]
    text = "".join(f"G1 X{v}\n" for v in values)
    blocks = read_text(text, flavor="marlin")
    xs = blocks.word_value[blocks.word_letter == ord("X")]
    assert xs.tolist() == [float(v) for v in values]


def test_comment_text_and_columns():
    blocks = read_text("G1 X1 ; first\n;TYPE:Perimeter\n  G0 Y-2.5\n", flavor="marlin")
    assert blocks[0].comments == ("first",)
    assert blocks[1].comments == ("TYPE:Perimeter",)
    assert blocks[2].words[1].column == 6
    assert blocks[2].words[1].value == -2.5


def test_paren_comments_and_block_delete_rs274():
    blocks = read_text("/G1 X1 (move) Y2\n(only a comment)\n", flavor="rs274ngc")
    assert [w.letter for w in blocks[0].words] == ["G", "X", "Y"]
    assert blocks[0].comments == ("move",)
    assert blocks[0].deleted
    assert blocks[1].comments == ("only a comment",)


def test_spaces_inside_numbers_only_where_the_flavor_allows():
    assert read_text("G1 X1 0\n", flavor="rs274ngc")[0].words[1].value == 10.0
    lenient = read_text("G1 X1 0\n", flavor="marlin")
    assert lenient[0].words[1].value == 1.0
    assert lenient.diagnostics.items[0].line == 1 and lenient.diagnostics.items[0].column == 7


def test_klipper_extended_commands_are_named():
    blocks = read_text("SET_VELOCITY_LIMIT ACCEL=500 ; why\nG1 X1\n", flavor="klipper")
    assert blocks[0].named == ("SET_VELOCITY_LIMIT", "ACCEL=500")
    assert blocks[0].comments == ("why",)


def test_gzip_and_plain_files_read_the_same(tmp_path):
    text = "G1 X1 Y2\nG1 X3 ; c\n" * 100
    (tmp_path / "a.gcode").write_text(text)
    with gzip.open(tmp_path / "a.gcode.gz", "wt") as f:
        f.write(text)
    plain = read_file(tmp_path / "a.gcode", flavor="marlin")
    packed = read_file(tmp_path / "a.gcode.gz", flavor="marlin")
    assert by_line(plain) == by_line(packed)
    assert len(plain) == 200


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=400), st.sampled_from(["marlin", "rs274ngc", "ger", "beckhoff_ded", "fanuc"]))
def test_random_bytes_never_crash_the_reader(data, flavor):
    text = data.decode("latin-1")
    read_text(text, flavor=flavor)  # lenient: never raises
    try:
        read_text(text, flavor=flavor, mode="strict")
    except GcodeError:
        pass


def test_strict_mode_raises_with_location():
    with pytest.raises(GcodeError) as info:
        read_text("G1 X1\nG1 X$2\n", flavor="marlin", mode="strict")
    d = info.value.diagnostic
    assert (d.line, d.column) == (2, 5)
    assert "<string>:2:5" in str(info.value)


@pytest.mark.parametrize("body", ["G0 X1", "#1 = 1\nG0 X#1"])  # read in chunks, or line by line by the preprocessor
def test_nothing_after_the_closing_percent_is_read(tmp_path, body):
    import gcodekit

    path = tmp_path / "p.ngc"
    path.write_text(f"%\n{body}\n%\n(notes (with a nested comment))\nG0 X9 Q\no2 sub\no2 endsub\n")
    op = gcodekit.gcode_to_operation(path, "linuxcnc", plan=False)
    assert not op.diagnostics.items
    assert op.motions()["x"].tolist() == [1.0]


def test_a_nested_comment_is_one_error():
    blocks = read_text("G0 X1 (a (b) c) Y2\n", flavor="rs274ngc")
    assert [(d.column, d.message) for d in blocks.diagnostics.items] == [(7, "nested comment")]
    assert [w.letter for w in blocks[0].words] == ["G", "X", "Y"]


@pytest.mark.parametrize("flavor", ["rs274ngc", "fanuc"])
def test_any_blank_inside_a_number_is_skipped(flavor):
    """Found by the fuzz suite (seed 7): a CR inside a number made float() fail in flavors whose
    numbers may hold blanks, as RS274NGC's do."""
    blocks = read_text("G1 X1 6\r7 Y2\f3 Z\v4\n", flavor=flavor)
    assert [(w.letter, w.value) for w in blocks[0].words] == [("G", 1.0), ("X", 167.0), ("Y", 23.0), ("Z", 4.0)]
    assert not blocks.diagnostics.items


@pytest.mark.parametrize("flavor", ["marlin", "klipper", "reprapfirmware"])
def test_an_f_without_a_number_leaves_the_feed_rate(flavor):
    """Printer firmware reads a missing number as 0 and sets the feed only from an F above 0 (Marlin's
    ``parser.floatval('F') > 0``): ``G1 F X20`` moves at the feed in force.  Before, the F was a flag
    worth 0, so the feed fell to 0, and a CAM program's ``( FrameBottom )`` (its F) on a Klipper machine
    planned an infinite time."""
    import gcodekit

    op = gcodekit.gcode_to_operation("G1 F800 X10\nG1 F X20\n( FrameBottom )\nG0 Z3\n", flavor, plan=False)
    assert op.waypoints["feed"].tolist() == [800.0] * len(op.waypoints["feed"])
    said = [(d.line, d.column, d.severity) for d in op.diagnostics if d.message.startswith("word 'F'")]
    assert said == [(2, 4, "warning"), (3, 3, "warning")]
    assert np.isfinite(gcodekit.gcode_to_operation("G1 F800 X10\n( FrameBottom )\nG0 Z3\n", flavor)
                       .waypoints["time"]).all()


def test_nul_bytes_binary_data_utf16_and_padding(tmp_path):
    def read(data: bytes):
        path = tmp_path / "p.gcode"
        path.write_bytes(data)
        blocks = read_file(path, flavor="marlin")
        return blocks, [(d.severity, d.line, d.message) for d in blocks.diagnostics]

    # a stray NUL in a comment: the program is read, the comment keeps it
    blocks, said = read(b"G1 X1 ;a\x00b\nG1 X2\n")
    assert said == [] and len(by_line(blocks)) == 2 and blocks[0].comments == ("a\x00b",)
    # one outside a comment is a character the words cannot hold, named at its column
    blocks, said = read(b"G1 X1\nG1\x00 X2\n")
    assert said == [("error", 2, "unexpected character '\\x00'")]
    # padding after the last line (an SD card's, a transfer's): ignored, said as an info
    blocks, said = read(b"G1 X1 F600\nG1 X2\n" + b"\x00" * 10)
    assert said == [("info", 3, "the file ends in 10 NUL bytes after its last line (padding, as an SD card or a "
                                "file transfer can leave); ignored")]
    assert [w.value for b in (blocks[0], blocks[1]) for w in b.words if w.letter == "X"] == [1.0, 2.0]
    # UTF-16 without its byte-order mark, and binary data: nothing read, the reason said
    _, said = read("G1 X1\nG1 X2\n".encode("utf-16-le"))
    assert said == [("error", 1, "the file holds UTF-16 text without its byte-order mark (save it as UTF-8, or "
                                 "with the mark), not program text; nothing read")]
    _, said = read("G1 X1\n".encode("utf-16-be"))
    assert said[0][2].startswith("the file holds UTF-16 text without its byte-order mark")
    # small integers as int32: three NULs in four bytes, but not text between them
    _, said = read(np.arange(1, 300, dtype=np.int32).tobytes())
    assert said == [("error", 1, "the file holds binary data (NUL bytes), not program text; nothing read")]
