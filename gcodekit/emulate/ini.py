"""Emulate stage: the parts of a LinuxCNC INI file the interpreter reads.

A program reads INI values as ``#<_ini[SECTION]NAME>`` (sections and names
in any case, as LinuxCNC's named parameters are), and the interpreter looks
for subroutine files in ``[RS274NGC] SUBROUTINE_PATH`` (``:``-separated,
relative to the INI file's folder).  ``[RS274NGC] DISABLE_FANUC_STYLE_SUB``
(non-zero) turns Fanuc-style subprograms off: rs274 then refuses M98 and
M99.  As LinuxCNC's ``IniFile`` reads it: ``[SECTION]`` lines, ``NAME =
VALUE`` lines, ``#`` and ``;`` comment lines, and the first of repeated
names wins.

Other ``[RS274NGC]`` options leave what gcodekit emulates as rs274 2.9 run
standalone has it: ``RS274NGC_STARTUP_CODE`` is run by LinuxCNC's task,
not by the interpreter (rs274 alone ignores it, and so does gcodekit: give
the modes in the program, or prepend them), the ``FEATURES`` bits change
nothing gcodekit reads (``#<_ini[...]>`` works whatever they are, as in
rs274 2.9), and ``DISABLE_G92_PERSISTENCE`` concerns the parameter file,
which gcodekit does not keep.

Examples
--------
>>> ini = LinuxCncIni.parse("[VARS]\\nTOOLCHANGE_X = 10\\n[RS274NGC]\\nSUBROUTINE_PATH = subs:../lib\\n", "/m/a.ini")
>>> ini.number("vars", "toolchange_x"), ini.number("vars", "missing"), ini.subroutine_path
(10.0, None, ('/m/subs', '/m/../lib'))
>>> ini.fanuc_subs, LinuxCncIni.parse("[RS274NGC]\\nDISABLE_FANUC_STYLE_SUB = 1\\n", "a.ini").fanuc_subs
(True, False)
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ConfigError

_SECTION = re.compile(r"\s*\[([^\]]+)\]")
_VALUE = re.compile(r"\s*([^=#;\s][^=]*?)\s*=\s*(.*?)\s*$")
_PARAMETER = re.compile(r"_ini\[([^\]]*)\](.+)")


@dataclass(frozen=True)
class LinuxCncIni:
    """Values of an INI file by (SECTION, NAME), both upper case."""

    path: str
    values: dict[tuple[str, str], str] = field(default_factory=dict)

    @classmethod
    def read(cls, path: str | os.PathLike) -> "LinuxCncIni":
        try:
            text = Path(path).read_text("utf-8", errors="replace")
        except OSError as exc:
            raise ConfigError(f"cannot read the INI file {str(path)!r}: {exc.strerror}") from exc
        return cls.parse(text, str(path))

    @classmethod
    def parse(cls, text: str, path: str) -> "LinuxCncIni":
        values: dict[tuple[str, str], str] = {}
        section = ""
        for line in text.splitlines():
            if line.lstrip().startswith(("#", ";")):
                continue
            if match := _SECTION.match(line):
                section = match.group(1).strip().upper()
            elif match := _VALUE.match(line):
                values.setdefault((section, match.group(1).upper()), match.group(2))
        return cls(path, values)

    def number(self, section: str, name: str) -> float | None:
        """The value of NAME in [SECTION] as a number; None when missing or not a number."""
        try:
            return float(self.values[section.upper(), name.upper()])
        except (KeyError, ValueError):
            return None

    def parameter(self, key: str) -> float | None:
        """The value of named parameter ``_ini[section]name`` (normalized: lower case, no spaces), or None."""
        match = _PARAMETER.fullmatch(key)
        return None if match is None else self.number(*match.groups())

    @property
    def fanuc_subs(self) -> bool:
        """Whether Fanuc-style subprograms (M98/M99) run: ``[RS274NGC] DISABLE_FANUC_STYLE_SUB`` unset or 0."""
        return not self.number("RS274NGC", "DISABLE_FANUC_STYLE_SUB")

    @property
    def subroutine_path(self) -> tuple[str, ...]:
        """``[RS274NGC] SUBROUTINE_PATH`` as directories, relative ones from the INI file's folder."""
        folder = os.path.dirname(self.path)
        entries = self.values.get(("RS274NGC", "SUBROUTINE_PATH"), "").split(":")
        return tuple(os.path.join(folder, entry) for entry in entries if entry.strip())
