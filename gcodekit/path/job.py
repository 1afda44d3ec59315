"""Front end (FreeCAD Path API): compounds and jobs, paths grouped in order with a tool table.

FreeCAD's ``Path::FeatureCompound`` gathers paths in order; with
``UsePlacements`` each child's placement moves its commands (those with a
position) before they are joined.  A FreeCAD project (a ``Job``) is a
compound with a tool table; here each of its operations may name the tool
it cuts with, and the joined path changes tools (``M6 T<n>``) where the
tool changes.

Examples
--------
>>> from gcodekit.path import Command, Path, Placement, Vector
>>> from gcodekit.path.tools import Tool, Tooltable
>>> job = Job(tooltable=Tooltable([Tool("3 mm end mill", tooltype="EndMill", diameter=3)]))
>>> job.add(Path("G0 Z5 G0 X1 G1 Z-1 F100 G1 X2"), tool=1, name="slot")
>>> job.add(Path("G1 X1"), placement=Placement(Vector(10, 0, 0)))
>>> print(job.Path.toGCode(), end="")
(slot)
(T1: 3 mm end mill)
M6 T1.000000
G0 Z5.000000
G0 X1.000000
G1 F100.000000 Z-1.000000
G1 X2.000000
G1 X1.000000
>>> job.UsePlacements = True
>>> job.Path.Commands[-1]
Command G1 [ X:11 ]
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ConfigError
from .command import Command
from .geometry import Placement
from .tools import Tooltable
from .toolpath import Path

__all__ = ["Compound", "Job", "Entry"]

#: Commands that carry a position, which a placement moves (FreeCAD: G0 G1 G2 G3 and the drilling cycles)
_POSITIONED = {"G0", "G00", "G1", "G01", "G2", "G02", "G3", "G03", "G81", "G82", "G83", "G84", "G85", "G86", "G89"}


@dataclass
class Entry:
    """One path of a compound: the path, its placement, the tool it cuts with (0: none), a name."""

    path: Path
    placement: Placement | None = None
    tool: int = 0
    name: str = ""


class Compound:
    """Paths joined in order (``Path::FeatureCompound``): ``Group``, ``UsePlacements``, ``Path``."""

    def __init__(self, paths: "list[Path] | None" = None, *, use_placements: bool = False, name: str = "Compound"):
        self.Label = name
        self.UsePlacements = bool(use_placements)
        self.entries: list[Entry] = []
        for p in paths or []:
            self.add(p)

    def add(self, path: Path, *, placement: Placement | None = None, tool: int = 0, name: str = "") -> None:
        """Append a path, with its placement, tool number and name."""
        if not isinstance(path, Path):
            raise TypeError(f"a compound holds Path objects, not {type(path).__name__}")
        self.entries.append(Entry(path.copy(), placement, int(tool), name))

    @property
    def Group(self) -> list[Path]:  # noqa: N802
        """The paths in order (copies)."""
        return [e.path.copy() for e in self.entries]

    @Group.setter
    def Group(self, paths: list[Path]) -> None:  # noqa: N802
        self.entries = []
        for p in paths:
            self.add(p)

    @property
    def Path(self) -> Path:  # noqa: N802
        """The joined path (placements applied when ``UsePlacements`` is true)."""
        out: list[Command] = []
        tool = 0
        for entry in self.entries:
            if entry.name:
                out.append(Command(f"({entry.name})"))
            if entry.tool and entry.tool != tool:
                out += self._tool_change(entry.tool)
                tool = entry.tool
            for c in entry.path.Commands:
                if self.UsePlacements and entry.placement is not None and c.Name in _POSITIONED:
                    c = c.transform(entry.placement)
                out.append(c)
        return Path(out)

    def _tool_change(self, number: int) -> list[Command]:
        return [Command("M6", {"T": number})]

    def toGCode(self) -> str:  # noqa: N802
        return self.Path.toGCode()

    def __repr__(self) -> str:
        return f"{type(self).__name__} {self.Label!r} [ {len(self.entries)} paths ]"


class Job(Compound):
    """A compound with a tool table (FreeCAD's project/Job): ``Tooltable``; tools change between paths.

    Raises
    ------
    ConfigError
        When a path names a tool the table does not have.
    """

    def __init__(self, paths: "list[Path] | None" = None, *, tooltable: Tooltable | None = None,
                 use_placements: bool = False, name: str = "Job"):
        super().__init__(paths, use_placements=use_placements, name=name)
        self.Tooltable = tooltable if tooltable is not None else Tooltable()

    def add(self, path: Path, *, placement: Placement | None = None, tool: int = 0, name: str = "") -> None:
        if tool and self.Tooltable.getTool(tool) is None:
            raise ConfigError(f"tool {tool} is not in the job's tool table (it has {sorted(self.Tooltable.Tools)})")
        super().add(path, placement=placement, tool=tool, name=name)

    def _tool_change(self, number: int) -> list[Command]:
        tool = self.Tooltable.getTool(number)
        return [Command(f"(T{number}: {tool.Name})"), Command("M6", {"T": number})]
