"""Syntax stage: the Flavor record that describes one G-code dialect.

A flavor is data, loaded from ``flavors/<name>.toml`` by :mod:`.loader`.  It
says how text is cut into words (comments, separators, case, line numbers)
and what each code and word means in gcodekit's normalized vocabulary
(:data:`COMMANDS`, :data:`PARAMETERS`), which is all later stages look at.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

#: How the words of one block become commands.
#: ``modal``: RS274NGC, one command per modal group, run in the
#: interpreter's order of execution; ``single``: printer firmware, the first
#: G/M/T word is the command and every other word its parameter;
#: ``sequential``: GER, every G/M code starts a new statement in text order.
BLOCK_SPLITS = ("modal", "single", "sequential")
#: What firmware does with an F at or below 0 (see :attr:`Flavor.zero_feed`).
ZERO_FEEDS = ("refused", "kept", "minimum_speed", "stops")

#: Normalized command names a flavor's ``[codes]`` table may map to.
COMMANDS = frozenset(
    """
    rapid linear arc_cw arc_ccw dwell spline_cubic spline_quadratic nurbs_start nurbs_end thread
    plane_xy plane_zx plane_yz units_inch units_mm
    distance_absolute distance_incremental arc_distance_absolute arc_distance_incremental
    feed_inverse_time feed_per_minute feed_per_rev
    machine_coordinates
    work_offset_1 work_offset_2 work_offset_3 work_offset_4 work_offset_5
    work_offset_6 work_offset_7 work_offset_8 work_offset_9
    set_position clear_position_offset suspend_position_offset restore_position_offset
    home home_secondary store_home store_home_secondary
    extrude_absolute extrude_relative firmware_retract firmware_unretract
    set_flow set_speed_factor
    tool_change spindle_cw spindle_ccw spindle_off
    coolant_mist coolant_flood coolant_off
    program_stop optional_stop program_end
    tool_length_offset tool_length_offset_dynamic tool_length_offset_add cancel_tool_length
    coordinate_data local_offset polar_on polar_off diameter_mode radius_mode
    cutter_comp_off cutter_comp_left cutter_comp_right cutter_comp_left_dynamic cutter_comp_right_dynamic
    cancel_cycle exact_stop path_blending retract_initial retract_r
    cycle_drill cycle_drill_dwell cycle_peck cycle_chip_break cycle_bore cycle_bore_stop cycle_bore_dwell
    cycle_tap cycle_tap_left cycle_back_bore cycle_bore_manual cycle_thread rigid_tap
    lathe_finish lathe_rough lathe_rough_no_pockets lathe_rough_pockets lathe_face lathe_face_no_pockets lathe_face_pockets
    set_hotend_temp wait_hotend_temp set_bed_temp wait_bed_temp set_chamber_temp
    fan_on fan_off
    set_max_accel set_max_feed set_accel set_jerk set_junction_deviation wait_moves
    mesh_level motors_off message progress set_kinematic_position
    weld_start laser_on laser_off deposition_switch set_bead
    probe
    """.split()
)

#: Normalized parameter names a flavor's ``[words]`` table may map to.
PARAMETERS = frozenset(
    "x y z a b c u v w e feed speed tool p q r i j k l d h line_number".split()
)


def code_label(letter: str, tenths: int) -> str:
    """How codes are written in flavor files: ``("G", 921)`` -> ``"G92.1"``, ``("G", 10)`` -> ``"G1"``.

    Code numbers are carried as integers in tenths, so ``G92.1`` stays exact.
    """
    whole, tenth = divmod(int(tenths), 10)
    return f"{letter}{whole}" if tenth == 0 else f"{letter}{whole}.{tenth}"


@dataclass(frozen=True)
class DetectRules:
    """Evidence that a program is written in this flavor.

    Attributes
    ----------
    header : tuple of str
        Regular expressions searched in the first lines (slicer banners,
        ``;FLAVOR:`` lines); a match is strong evidence.
    hints : tuple of str
        Regular expressions searched in the code (comments left out) that
        suggest the dialect without proving it (LinuxCNC's bracketed
        expressions, which Fanuc macros share).
    against : tuple of str
        Regular expressions searched in the first lines that the dialect
        cannot read as written (text after ``;``, Fanuc's end of block):
        a match is strong evidence against it.
    codes : tuple of str
        Codes typical of the dialect (``M82``, ``SET_VELOCITY_LIMIT``).
    extensions : tuple of str
        File suffixes of the dialect's own (``.ngc``): weak evidence that
        tips an even balance and confirms what the content chose.
    shared_extensions : tuple of str
        File suffixes it shares with unrelated dialects (``.nc``, ``.tap``,
        ``.gcode``): a hint only.
    comment : str
        The comment style the dialect mostly uses: ``";"``, ``"("`` or ``""``.
    priority : int
        Tie-breaker: higher wins when the evidence is equal.
    """

    header: tuple[str, ...] = ()
    hints: tuple[str, ...] = ()
    against: tuple[str, ...] = ()
    codes: tuple[str, ...] = ()
    extensions: tuple[str, ...] = ()
    shared_extensions: tuple[str, ...] = ()
    comment: str = ""
    priority: int = 0


@dataclass(frozen=True)
class Flavor:
    """One dialect: how to read its text and what its codes mean.

    Attributes (syntax)
    -------------------
    line_comments : tuple of str
        Characters that start a comment running to the end of the line.
    paren_comments : bool
        ``( ... )`` is a comment.
    multiline_comments : bool
        A parenthesised comment may span lines (GER).
    statement_separators : tuple of str
        Characters that end a statement inside a line (GER's ``;``).  A
        character cannot be both a separator and a line comment.
    line_number_letter : str
        Letter of the optional block number word, ``"N"`` or ``""``.
    block_delete : bool
        A leading ``/`` marks a block that may be skipped.
    checksum : bool
        Host-protocol checksums ``*nn`` end the line (Marlin, RepRapFirmware).
    case_sensitive : bool
        Lower-case letters are not words (Klipper's extended commands keep
        their case either way).
    spaces_in_numbers : bool
        Whitespace inside a word is ignored (RS274NGC: ``X 1 0`` is ``X10``).
    parameters : bool
        ``#`` parameters and ``[...]`` expressions are part of the language.
    percent_delimiter : bool
        A line holding only ``%`` starts or ends the program.
    block_split : {"modal", "single", "sequential"}
        See :data:`BLOCK_SPLITS`.
    rs274ngc_block_checks : bool
        RS274NGC's block checks: two codes of one modal group (``G90 G91``,
        ``M3 M5``) or a word no code of the block uses (``G1 X1 R5``) are
        errors; otherwise the last code wins and a stray word is ignored.
    string_codes : frozenset of str
        Codes whose remaining text is one string argument (``M117 Hello``).
    other_codes : frozenset of str
        Codes the dialect knows that have no normalized command yet: kept as
        generic commands with a warning.  When not empty, the dialect's code
        list is complete and any other G/M code is an error (LinuxCNC's
        "Unknown g code used").
    extended_commands : bool
        Klipper-style ``NAME KEY=VALUE`` commands are accepted.
    wizards : bool
        GER wizard calls (a name of two or more letters then arguments).
    code_assignments : bool
        A code may carry a value after ``=`` (Beckhoff ``M60=1``); the value
        becomes the command's ``value`` parameter.
    assignments : bool
        Siemens Sinumerik 840D value assignments and calls: ``NAME=value``
        in a block (``EM=1``, ``R1=2.5``, ``H[10]=1``) becomes a named
        command whose ``value`` parameter is the number, run before the
        block's motion; a line starting ``NAME(arguments)``
        (``CYCLE832(2,_finish,1)``) is a named command with the argument
        text.  ``[codes]`` may map these names to commands.
    required_axes : str
        Letters every G0/G1 must carry; a motion missing one is reported
        (the Beckhoff DED dialect writes X, Y and Z on every move).
    polar_words : bool
        ``@`` (distance) and ``^`` (angle, degrees) words give X and Y in polar
        form (LinuxCNC).
    polar_incremental_only : bool
        G16 polar moves only in G91, and no change of program zero while
        G16 is on (GER); otherwise Fanuc's rules (G90: pole at the origin).
    directive_prefix : str
        Lines starting with this text are controller directives kept as
        named commands (Beckhoff ``#TRAFO ON``); ``""`` for none.
    state_parameters : {"", "linuxcnc"}
        Parameters a program reads the machine's state from: ``"linuxcnc"``
        for ``#5420``-``#5428``, ``#<_x>``, ``#<_imperial>``, ... (see
        :mod:`gcodekit.emulate.state_parameters`); ``""`` for none.

    Attributes (semantics)
    ----------------------
    words : mapping of str to str
        Word letter to normalized parameter (:data:`PARAMETERS`).
    codes : mapping of str to str
        Code such as ``"G0"`` or ``"M104"`` to normalized command
        (:data:`COMMANDS`); numbers are written without leading zeros.
    firmware_codes : mapping of str to str
        Codes the firmware knows that gcodekit does not model, to what each
        does (``"M105": "report temperatures"``): kept as generic commands
        with at most one info per code, never a warning, since the program
        is right to use them.
    units : {"mm", "inch"}
        Units in force at program start.
    extrusion : {"absolute", "relative", ""}
        E mode at program start; ``""`` when the dialect does not extrude.
    rapid_is_feed : bool
        G0 moves at the programmed feed (Marlin), not at the rapid rate.
    zero_feed : {"refused", "kept", "minimum_speed", "stops"}
        What the firmware does with an F at or below 0: ``"refused"``, its
        feed moves are refused (GRBL's error 22, LinuxCNC, a Fanuc's
        alarm); ``"kept"``, the F is ignored and the feed rate stays (Marlin
        and Prusa's firmware set it only from an F above 0);
        ``"minimum_speed"``, the F is taken and the moves crawl at the
        minimum movement speed (RepRapFirmware's M203 I); ``"stops"``, a
        G0-G3 carrying it is an error that makes no move, and a print from
        the SD card stops there (Klipper's "Invalid speed").
    initial_motion : {"", "rapid", "linear"}
        Motion mode in force at program start (GER starts in G0), so axis
        words alone move; ``""`` when they need a motion code first.
    layer_comments : tuple of str
        Regular expressions on comment text marking a new layer.
    feature_comment : str
        Regular expression whose first group names the feature being made.
    detect : DetectRules
    lineage : tuple of str
        The flavors this one inherits from, nearest first (klipper:
        ``("marlin",)``); the loader sets it from ``inherit``, no file
        writes it.
    """

    name: str
    description: str = ""
    line_comments: tuple[str, ...] = (";",)
    paren_comments: bool = False
    multiline_comments: bool = False
    statement_separators: tuple[str, ...] = ()
    line_number_letter: str = "N"
    block_delete: bool = False
    checksum: bool = False
    case_sensitive: bool = False
    spaces_in_numbers: bool = False
    parameters: bool = False
    percent_delimiter: bool = False
    block_split: str = "single"
    rs274ngc_block_checks: bool = False
    string_codes: frozenset[str] = frozenset()
    other_codes: frozenset[str] = frozenset()
    extended_commands: bool = False
    wizards: bool = False
    code_assignments: bool = False
    assignments: bool = False
    directive_prefix: str = ""
    state_parameters: str = ""
    polar_words: bool = False
    polar_incremental_only: bool = False
    required_axes: str = ""
    words: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    codes: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    firmware_codes: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    units: str = "mm"
    extrusion: str = ""
    rapid_is_feed: bool = False
    zero_feed: str = "refused"
    initial_motion: str = ""
    layer_comments: tuple[str, ...] = ()
    feature_comment: str = ""
    detect: DetectRules = DetectRules()
    lineage: tuple[str, ...] = ()

    @property
    def family(self) -> str:
        """The flavor at the root of its inheritance (prusa, klipper, bambu: ``"marlin"``): one family's
        dialects share their syntax and base codes."""
        return self.lineage[-1] if self.lineage else self.name

    def command(self, code: str) -> str | None:
        """Normalized command name of a code such as ``"G1"``, or None."""
        return self.codes.get(code)

    def codes_for(self, command: str) -> tuple[str, ...]:
        """Every code of this flavor that means ``command``."""
        return tuple(c for c, n in self.codes.items() if n == command)

    def __repr__(self) -> str:
        return f"Flavor({self.name!r})"

    def __hash__(self) -> int:  # the mapping fields are not hashable; names are unique
        return hash(self.name)
