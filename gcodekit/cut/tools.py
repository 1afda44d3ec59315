"""Outputs: the tools a cut uses, from a tool library file (``TOOLS.toml``) or a LinuxCNC tool table.

A ``TOOLS.toml`` holds one table per tool, named ``T`` and its number::

    [T1]
    shape = "endmill"      # endmill, ballend, bullnose, vbit, drill, chamfer
    diameter = 6.0         # mm
    length = 30.0          # cutting length above the tip, mm (default 30)

    [T2]
    shape = "bullnose"
    diameter = 8.0
    corner_radius = 1.0    # bullnose only, mm

    [T3]
    shape = "vbit"
    diameter = 10.0
    angle = 60.0           # included tip angle, degrees (vbit, drill, chamfer)

The loader is strict, as the flavor and machine loaders are: an unknown
table or key, a wrong type or a value out of range raises
:class:`~gcodekit.errors.ConfigError` naming the file, the table and the
key, with a did-you-mean.  A LinuxCNC ``.tbl`` gives flat end mills of its
``D`` diameters; its tool length offsets are the machine's business (the
emulator applies them) and the cut puts each tool's tip at the tool's
table length below the spindle (see :mod:`gcodekit.cut.sweep`).

Examples
--------
>>> lib = ToolLibrary.from_toml_text('[T1]\\nshape = "ballend"\\ndiameter = 6\\n')
>>> lib[1].kind, lib[1].radius
('ballend', 3.0)
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ConfigError, did_you_mean
from ..tool_shapes import SHAPES, ToolShape

#: Keys of a tool's table and the TOML type each takes.
_KEYS = {"shape": str, "diameter": float, "length": float, "corner_radius": float, "angle": float,
         "tip_diameter": float, "comment": str}
_TABLE_NAME = re.compile(r"T(\d+)")


@dataclass
class ToolLibrary:
    """Tool shapes by tool number, and where each came from.

    Parameters
    ----------
    shapes : dict of int to ToolShape
    source : str, default: "<tools>"
        The file (or files) the shapes were read from, for messages.
    offsets : dict of int to float
        Each tool's length (a tool table's Z offset, mm): its tip is that far
        below the spindle's controlled point.  Missing tools have 0.
    """

    shapes: dict[int, ToolShape] = field(default_factory=dict)
    source: str = "<tools>"
    offsets: dict[int, float] = field(default_factory=dict)

    def __getitem__(self, number: int) -> ToolShape:
        return self.shapes[number]

    def __contains__(self, number: object) -> bool:
        return number in self.shapes

    def __len__(self) -> int:
        return len(self.shapes)

    @classmethod
    def from_toml_text(cls, text: str, source: str = "<TOOLS.toml>") -> "ToolLibrary":
        """Read a tool library's text (see the module's docstring)."""
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{source}: not a valid TOML file: {exc}") from None
        shapes: dict[int, ToolShape] = {}
        for name, table in data.items():
            match = _TABLE_NAME.fullmatch(name)
            if not match or not isinstance(table, dict):
                raise ConfigError(f"{source}: [{name}]: each tool is a table named T and its number, e.g. [T1]")
            shapes[int(match.group(1))] = _shape(table, f"{source}: [{name}]")
        return cls(shapes, source)

    @classmethod
    def read(cls, path: str | os.PathLike) -> "ToolLibrary":
        """Read a ``TOOLS.toml`` file."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise ConfigError(f"{path}: a tool library is a UTF-8 TOML text file") from None
        return cls.from_toml_text(text, str(path))

    @classmethod
    def from_tool_table(cls, table) -> "ToolLibrary":
        """Flat end mills of a LinuxCNC tool table's diameters (a :class:`~gcodekit.emulate.tooltable.ToolTable`).

        Tools with no diameter (``D`` missing or 0) are left out: the cut
        says so when the program uses one.
        """
        shapes = {n: ToolShape("endmill", tool.diameter) for n, tool in table.items() if tool.diameter > 0}
        offsets = {n: float(tool.offset[2]) for n, tool in table.items()}
        return cls(shapes, getattr(table, "source", "<tool table>"), offsets)

    def merged(self, other: "ToolLibrary") -> "ToolLibrary":
        """This library with ``other``'s shapes added where this one has none; offsets from both."""
        return ToolLibrary({**other.shapes, **self.shapes}, f"{self.source}, {other.source}",
                           {**other.offsets, **self.offsets})


def _shape(table: dict, where: str) -> ToolShape:
    for key, value in table.items():
        if key not in _KEYS:
            raise ConfigError(f"{where}: unknown key {key!r}{did_you_mean(key, _KEYS)}; "
                              f"a tool has {', '.join(_KEYS)}")
        want = _KEYS[key]
        if want is float and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise ConfigError(f"{where}: {key} must be a number, not {value!r}")
        if want is str and not isinstance(value, str):
            raise ConfigError(f"{where}: {key} must be a string, not {value!r}")
    for key in ("shape", "diameter"):
        if key not in table:
            raise ConfigError(f"{where}: missing key {key!r}")
    kind = table["shape"]
    if kind not in SHAPES:
        raise ConfigError(f"{where}: shape: unknown tool shape {kind!r}{did_you_mean(kind, SHAPES)}; "
                          f"choose one of {', '.join(SHAPES)}")
    for key in ("corner_radius", "angle", "tip_diameter"):
        if key in table and key not in SHAPES[kind]:
            raise ConfigError(f"{where}: {key}: a {kind} has no {key} (it has {', '.join(SHAPES[kind]) or 'none'})")
    if kind == "bullnose" and "corner_radius" not in table:
        raise ConfigError(f"{where}: missing key 'corner_radius' (a bullnose needs it)")
    args = {key: float(value) for key, value in table.items() if key not in ("shape", "comment")}
    try:
        return ToolShape(kind, **args)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
