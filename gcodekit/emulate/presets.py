"""Emulate stage: machine presets as data (``machines/<name>.toml``).

A preset names the flavor a machine reads and the few facts the emulator
needs that the program does not say: how fast rapids go, what P means in a
dwell, what G28 does, when a tool change happens, the filament.  Unknown
keys are errors naming the file and a did-you-mean, as for flavors.

Examples
--------
>>> load_machine("marlin").dwell_p_unit
'ms'
"""

from __future__ import annotations

import functools
import os
import re
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

from ..errors import ConfigError, did_you_mean

MACHINE_DIR = Path(__file__).with_name("machines")
_CHOICES = {
    "process": ("additive", "subtractive", "generic"),
    "dwell_p_unit": ("s", "ms"),
    "home_mode": ("stored", "select"),
    "tool_change_on": ("M6", "T"),
    "tool_table_units": ("mm", "inch"),
    "cycle_retract": ("initial", "r"),
    "table_axis": ("", "W"),
    "extruder_type": ("filament", "screw", "bead", "wire", "powder"),
}


@dataclass(frozen=True)
class MachineConfig:
    """What a machine does where the program leaves it open.

    Attributes
    ----------
    name, description : str
    flavor : str
        Flavor of the programs this machine reads.
    process : {"additive", "subtractive", "generic"}
        Which Operation subclass emulation produces.
    rapid_feed : float
        Speed of G0 moves in mm/min, used for time until the planner knows
        the axis limits (ignored when ``rapid_is_feed``).
    rapid_is_feed : bool or None
        G0 moves at the modal F (printer firmware); None takes the flavor's.
    initial_feed : float
        Feed rate in force before the program sets one, mm/min; 0 for none
        (a feed move before any F is then reported).
    dwell_p_unit : {"s", "ms"}
        Unit of P in G4 (seconds for LinuxCNC/GRBL, milliseconds for Marlin).
    home_mode : {"stored", "select"}
        ``stored``: G28/G30 go, through the point given by their axis words,
        to the stored position (RS274NGC); ``select``: their axis letters
        choose which axes home to the stored position (printer firmware).
    tool_change_on : {"M6", "T"}
        The word that puts the selected tool in the spindle/extruder.
    radius_arcs : bool
        G2/G3 with R are accepted (Klipper rejects them: the arc is skipped).
    empty_moves : bool
        A G0/G1 with no axis words still makes a zero-length move (LinuxCNC's
        interpreter does; firmware only updates the mode and feed).
    probe_backoff : float
        mm; after a probe move (G38.2-G38.5), which gcodekit lets "trip" at
        its target, the tool stands this far back towards the start without
        a move: 0.254 (0.01 inch) in rs274 run standalone, 0 leaves it at
        the target.
    units_keep_feed : bool
        G20/G21 keep the F number, so the rate changes with the units: ``F30
        G20`` feeds at 30 in/min.  rs274 run standalone does this (its canon
        hands back the number it was given when the interpreter re-reads the
        feed, interp_convert.cc ``convert_length_units``; the LinuxCNC golden
        tests turn it on); LinuxCNC's task, which converts the rate it holds,
        and printer firmware keep the speed (false, the default).
    standalone_canon : bool
        Hand the interpreter back what rs274 run standalone hands back when
        it re-reads its state (its canon, saicanon.cc, keeps numbers as it
        was given them; LinuxCNC's task converts them and knows where the
        machine is).  G20/G21 keep the tool length offset's numbers, so an
        offset set in mm is taken as that many inches when the offset next
        changes (G43, G43.1, G43.2, G49: the program position jumps by the
        difference) and when G28, G30 and G53 aim at machine coordinates.
        After M6 the program position is re-read as the last move's program
        point, moved by later work and G92 offset changes but not by tool
        length offsets or XY rotations.  The next move goes there.  The
        LinuxCNC golden tests and the differential check turn it on (false,
        the default).
    distance_mode_sets_extrusion : bool
        G90/G91 also switch E to absolute/relative, overriding M82/M83
        (Marlin, RepRapFirmware).  Everywhere, E is relative under G91.
    block_delete : bool
        The block-delete switch: lines starting with ``/`` are skipped.
    filament_diameter : float
        mm; turns extruded length into volume.
    filament_density : float
        g/cm^3; turns volume into mass.
    extruder_type : {"filament", "screw", "bead", "wire", "powder"}
        How material reaches the bead: filament drive (FFF), pellet screw
        (LFAM: BAAM; it turns at the spindle speed S while the spindle is
        on, M3), a screw the controller slaves to the path so a programmed
        bead follows it (``bead``: CEAD's ``EXTRUDERSPEED2(w, h, ..)`` and
        ``EM=1``), wire or powder feed (DED).
    work_offsets : mapping of str to list of float
        Initial G54-G59.3 offsets in mm, e.g. ``G55 = [100, 0, 0]``.
    retract_length, unretract_extra_length : float
        Firmware retraction (G10/G11) filament length, mm; 0 disables it.
    retract_speed, unretract_speed : float
        Firmware retraction speeds, mm/s.
    tool_table : str
        Path of a LinuxCNC tool table (``.tbl``) for G43 and G10 L1; ``""``
        for none (every tool then has zero offsets).
    tool_table_units : {"mm", "inch"}
        Units of the tool table's lengths (rs274 standalone reads inches).
    subroutine_path : tuple of str
        Directories searched, after the program's own, for the subroutine
        files a program calls by name (``o<name> call``), like LinuxCNC's
        ``[RS274NGC] SUBROUTINE_PATH``; a string is split at ``:``.
    ini_file : str
        A LinuxCNC INI file: a program reads its values as
        ``#<_ini[SECTION]NAME>``, and its ``[RS274NGC] SUBROUTINE_PATH``
        is searched after ``subroutine_path``.
    dwell_s_seconds : bool
        ``G4 S`` is a dwell in seconds (Marlin, RepRapFirmware); Klipper
        ignores S.
    planner : str
        Motion planner that times the moves (``"klipper"``); ``""`` keeps
        time as length over feed.
    planner_settings : mapping
        The planner's settings (the ``[planner]`` table), e.g. ``max_accel``.
    spline_tolerance : float
        mm; the chords that follow a G5/G5.1/G5.2 curve stay this close to it.
    cycle_retract : {"initial", "r"}
        Where canned cycles retract before a program says G98 or G99: the
        initial level (G98) or the R plane (G99, rs274's own default).
    table_axis : {"", "W"}
        An axis that moves the build table up and down (BAAM's W): the part
        frame's height is then Z - W, so a table drop between layers is a
        layer change.  Absolute positioning only.
    screw_displacement : float
        cm^3 of material a screw extruder delivers per revolution; 0 leaves
        its deposited volume unknown (NaN).
    printer_names : tuple of str
        What slicers call this printer in the files they write (Cura 5's
        ``;TARGET_MACHINE.NAME:``, the Slic3r family's ``; printer_model =``):
        a file naming one is run on this preset when no machine is given.
    laser : bool
        The spindle output drives a laser (GRBL laser mode): S is beam power,
        the ``power`` column shows it on the moves that burn.
    """

    name: str
    description: str = ""
    flavor: str = "rs274ngc"
    process: str = "generic"
    rapid_feed: float = 3000.0
    rapid_is_feed: bool | None = None
    initial_feed: float = 0.0
    dwell_p_unit: str = "s"
    home_mode: str = "stored"
    tool_change_on: str = "M6"
    radius_arcs: bool = True
    empty_moves: bool = False
    probe_backoff: float = 0.0
    units_keep_feed: bool = False
    standalone_canon: bool = False
    distance_mode_sets_extrusion: bool = False
    block_delete: bool = False
    filament_diameter: float = 1.75
    filament_density: float = 1.24
    extruder_type: str = "filament"
    work_offsets: Mapping[str, tuple[float, ...]] = field(default_factory=lambda: MappingProxyType({}))
    retract_length: float = 0.0
    retract_speed: float = 20.0
    unretract_extra_length: float = 0.0
    unretract_speed: float = 10.0
    tool_table: str = ""
    tool_table_units: str = "mm"
    subroutine_path: tuple[str, ...] = ()
    ini_file: str = ""
    dwell_s_seconds: bool = True
    planner: str = ""
    planner_settings: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    spline_tolerance: float = 0.001
    cycle_retract: str = "initial"
    table_axis: str = ""
    screw_displacement: float = 0.0
    printer_names: tuple[str, ...] = ()
    laser: bool = False

    def __hash__(self) -> int:
        return hash(self.name)

    def rapids_at_feed(self, flavor_says: bool) -> bool:
        """Whether G0 moves at the modal F: the preset's ``rapid_is_feed``, else what the flavor says."""
        return flavor_says if self.rapid_is_feed is None else bool(self.rapid_is_feed)


_TYPES = {f.name: f.type for f in fields(MachineConfig)}


def list_machines() -> list[str]:
    """Names of the bundled machine presets."""
    return sorted(p.stem for p in MACHINE_DIR.glob("*.toml"))


def load_machine(name_or_path: str | os.PathLike[str], **overrides) -> MachineConfig:
    """Load a bundled preset by name, or a preset file by path.

    Keyword arguments override the file's values (``rapid_feed=5000``).
    """
    path = Path(name_or_path)
    if path.suffix != ".toml":
        path = MACHINE_DIR / f"{name_or_path}.toml"
        if not path.exists():
            raise ConfigError(f"unknown machine {str(name_or_path)!r}; choose one of "
                              f"{', '.join(list_machines())}" + did_you_mean(str(name_or_path), list_machines()))
    config = _load(path.resolve())
    if overrides:
        config = _build({**_as_dict(config), **overrides}, path)
    return config


def with_options(config: MachineConfig, **options) -> MachineConfig:
    """``config`` with ``options`` replaced, checked and normalised as a preset file's values are."""
    return _build({**_as_dict(config), **options}, Path(f"<machine {config.name}>"))


@functools.lru_cache(maxsize=None)
def _load(path: Path) -> MachineConfig:
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read machine preset: {exc}") from exc
    if isinstance(data.get("planner"), dict):  # a [planner] table: its name is given by `name`
        table = dict(data.pop("planner"))
        data["planner"] = table.pop("name", "")
        data["planner_settings"] = table
    return _build(data, path)


def _as_dict(config: MachineConfig) -> dict:
    return {f.name: getattr(config, f.name) for f in fields(MachineConfig)}


def _build(data: dict, path: Path) -> MachineConfig:
    for key, value in data.items():
        if key not in _TYPES:
            raise ConfigError(f"{path}: unknown key {key!r}" + did_you_mean(key, _TYPES))
        if key in _CHOICES and value not in _CHOICES[key]:
            raise ConfigError(f"{path}: {key} = {value!r} is not one of {', '.join(_CHOICES[key])}")
        if key in ("rapid_feed", "filament_diameter", "filament_density"):
            if not isinstance(value, (int, float)) or isinstance(value, bool) or value <= 0:
                raise ConfigError(f"{path}: {key} must be a positive number, not {value!r}")
    offsets = {}
    for code, vector in dict(data.get("work_offsets", {})).items():
        if code not in _WORK_OFFSET_CODES or len(vector) > 6:
            raise ConfigError(f"{path}: [work_offsets] {code} must be one of G54..G59.3 with up to 6 values"
                              + did_you_mean(code, _WORK_OFFSET_CODES))
        offsets[code] = tuple(float(v) for v in vector)
    path_list = data.get("subroutine_path", ())
    if isinstance(path_list, str):
        path_list = [p for p in path_list.split(":") if p]
    data = {**data, "work_offsets": MappingProxyType(offsets), "subroutine_path": tuple(map(str, path_list)),
            "printer_names": tuple(map(str, data.get("printer_names", ()))),
            "planner_settings": MappingProxyType(dict(data.get("planner_settings", data.pop("planner_table", {}))))}
    if "name" not in data:
        data["name"] = path.stem
    return MachineConfig(**data)


_WORK_OFFSET_CODES = ("G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3")


_PRINTER_NAME = re.compile(r"^;\s*(?:TARGET_MACHINE\.NAME:|printer_model\s*=)\s*(.+?)\s*$", re.M)


def machine_named_in(head: str, flavor: str) -> str | None:
    """The preset of ``flavor`` whose ``printer_names`` has the printer a file's header names, or None.

    Examples
    --------
    >>> machine_named_in(";FLAVOR:Marlin\\n;TARGET_MACHINE.NAME:Creality Ender-3\\n", "marlin")
    'creality_ender3'
    """
    named = {m[1].casefold() for m in _PRINTER_NAME.finditer(head)}
    if not named:
        return None
    for name in list_machines():
        config = _load((MACHINE_DIR / f"{name}.toml").resolve())
        if config.flavor == flavor and named & {p.casefold() for p in config.printer_names}:
            return name
    return None


def default_machine_for(flavor: str) -> str:
    """The preset that runs a flavor when the user names no machine: the one named after it, else the first."""
    if (MACHINE_DIR / f"{flavor}.toml").exists() and _load((MACHINE_DIR / f"{flavor}.toml").resolve()).flavor == flavor:
        return flavor
    for name in list_machines():
        if _load((MACHINE_DIR / f"{name}.toml").resolve()).flavor == flavor and name != "generic":
            return name
    return "generic"
