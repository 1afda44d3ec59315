"""Emulate stage: the parts of a LinuxCNC INI file the interpreter reads.

A program reads INI values as ``#<_ini[SECTION]NAME>`` (sections and names
in any case, as LinuxCNC's named parameters are), and the interpreter looks
for subroutine files in ``[RS274NGC] SUBROUTINE_PATH`` (``:``-separated,
relative to the INI file's folder).  As LinuxCNC's ``IniFile`` reads it:
``[SECTION]`` lines, ``NAME = VALUE`` lines, ``#`` and ``;`` comment lines,
and the first of repeated names wins.

Examples
--------
>>> ini = LinuxCncIni.parse("[VARS]\\nTOOLCHANGE_X = 10\\n[RS274NGC]\\nSUBROUTINE_PATH = subs:../lib\\n", "/m/a.ini")
>>> ini.number("vars", "toolchange_x"), ini.number("vars", "missing"), ini.subroutine_path
(10.0, None, ('/m/subs', '/m/../lib'))
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
    def subroutine_path(self) -> tuple[str, ...]:
        """``[RS274NGC] SUBROUTINE_PATH`` as directories, relative ones from the INI file's folder."""
        folder = os.path.dirname(self.path)
        entries = self.values.get(("RS274NGC", "SUBROUTINE_PATH"), "").split(":")
        return tuple(os.path.join(folder, entry) for entry in entries if entry.strip())
