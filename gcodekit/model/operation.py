"""Model: Operation, a program's commands paired with their process data.

An Operation holds the parsed commands (a :class:`CommandTable`) and, once a
machine has run them, a table of waypoints: one per command (its end
state), plus intermediate points of commands that pass through several.
``operation.commands[i]`` and ``operation.process_data[i]`` describe the
same step and are built from the columns when indexed.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G21 G90\\nG1 X10 F600\\nG1 Y10\\n", machine="linuxcnc", plan=False)
>>> op.get_bounds()["max"], round(op.get_statistics()["time_s"], 3)
([10.0, 10.0, 0.0], 2.0)
"""

from __future__ import annotations

import os
import warnings
from collections.abc import MutableMapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import Waypoints
from ..errors import Diagnostics
from ..limits import MAX_MOTIONS
from ..parse.commands import Command, Kind
from ..parse.table import MOTION_NAMES, CommandTable
from ..schema import COLUMNS, WAYPOINT_COLUMNS
from ..syntax.flavor import code_label
from ..units import MM_PER_INCH
from . import derived, slicer, statistics
from .process_data import LazyList, ProcessData

if TYPE_CHECKING:
    import pandas as pd

    from ..emulate.presets import MachineConfig
    from ..plan import Plan
    from ..plan.moves import PlannedMoves, PlanResult
    from ..syntax import Flavor
    from .slicer import SlicerFigures


#: Columns only a planned operation has
_PLANNED = ("start_v", "cruise_v", "end_v", "accel")
#: Columns only an operation a cutting simulation has run over has (:meth:`Operation.attach_removal`)
REMOVAL_COLUMNS = ("removed_volume", "removal_rate")


class Operation:
    """Commands of a program and, after emulation, their process data.

    Parameters
    ----------
    commands : CommandTable
    waypoints : dict of str to ndarray, optional
        Columns from :meth:`Machine.run`; None before emulation.
    file : str
    flavor : Flavor
    machine : MachineConfig, optional
    diagnostics : Diagnostics
    max_motions : int, default: :data:`gcodekit.limits.MAX_MOTIONS`
        The moves a planner may cut the program's arcs into (see :mod:`gcodekit.limits`).
    """

    process_data_class: type[ProcessData] = ProcessData
    #: The kind of process, as machine presets name it: ``"additive"``, ``"subtractive"`` or ``"generic"``.
    process: str = "generic"

    def __init__(self, commands: CommandTable, waypoints: dict[str, np.ndarray] | None = None, *,
                 file: str = "<string>", flavor: "Flavor | None" = None,
                 machine: "MachineConfig | None" = None, diagnostics: Diagnostics | None = None,
                 n_lines: int = 0, max_motions: int = MAX_MOTIONS):
        self.table = commands
        self.max_motions = max_motions
        self._derived: dict[str, Any] = {}
        self.waypoints = waypoints
        self.file = file
        self.flavor = flavor
        self.machine = machine
        self.diagnostics = diagnostics if diagnostics is not None else Diagnostics(file)
        self.n_lines = n_lines
        self.plan: tuple[PlannedMoves, PlanResult] | None = None  # once a motion planner has run

    @property
    def waypoints(self) -> Waypoints | None:
        """The waypoint columns (see :attr:`columns`), each read as an array; None before emulation."""
        return self._waypoints

    @waypoints.setter
    def waypoints(self, columns: MutableMapping[str, np.ndarray] | None) -> None:
        self._waypoints = columns if columns is None or isinstance(columns, Waypoints) else Waypoints(columns)
        self._derived.clear()  # layers, features ... belong to the old columns

    # -- derived columns, computed once --------------------------------------------

    def _kept(self, name: str, make) -> Any:
        if name not in self._derived:
            self._derived[name] = make()
        return self._derived[name]

    @property
    def moving(self) -> np.ndarray:
        """Per waypoint, whether it moves the tool (a motion of some length; see :mod:`gcodekit.model.derived`)."""
        return self._kept("moving", lambda: derived.moving(self.waypoints))

    @property
    def work(self) -> np.ndarray:
        """Per waypoint, whether the move does the process's work: what pictures draw as the part.

        Feed moves (G1-G3 and the like) of some length here; an additive
        operation's depositing moves from the first layer on.  The other
        moves are travel.
        """
        return self._kept("work", lambda: self.moving & (np.asarray(self.waypoints["motion"]) >= 2))

    @property
    def depositing(self) -> np.ndarray:
        """Per waypoint, whether the step lays material (see :mod:`gcodekit.model.derived`).

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("M83\\nG1 X10 E1 F600\\nG1 X20\\n", "marlin", plan=False)
        >>> op.depositing.tolist()
        [False, True, False]
        """
        return self._kept("depositing", lambda: derived.depositing_of(self))

    @property
    def features(self) -> np.ndarray:
        """Per waypoint, the slicer feature (``;TYPE:``) or DED fraction in force, ``""`` before the first."""
        return self._kept("features", lambda: derived.features(self))

    @property
    def feature_codes(self) -> tuple[np.ndarray, list[str]]:
        """:attr:`features` as an index per waypoint into a list of names (see :func:`~gcodekit.model.derived.feature_codes`)."""
        return self._kept("feature_codes", lambda: derived.feature_codes(self))

    @property
    def layers(self) -> np.ndarray:
        """Per waypoint, its layer (0 first, -1 before the first; see :mod:`gcodekit.model.derived`).

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("M83\\nG1 Z0.2 F600\\nG1 X10 E1\\nG1 Z0.4\\nG1 X0 E1\\n", "marlin", plan=False)
        >>> op.layers.tolist(), op.n_layers  # a layer begins at its first extruding move
        ([-1, -1, 0, 0, 1], 2)
        """
        return self._kept("layers", lambda: derived.layers(self).astype(np.int32))

    @property
    def n_layers(self) -> int:
        """How many layers: the last layer plus one (0 for a program that lays nothing)."""
        return int(self.layers.max()) + 1 if self.layers.size else 0

    @property
    def columns(self) -> "pd.DataFrame":
        """The schema of :meth:`to_dataframe`'s columns: name, unit, dtype and meaning.

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("G1 X1 F600\\n", "linuxcnc", plan=False)
        >>> op.columns.loc["feed"].tolist()
        ['mm/min', 'float64', 'feed rate in force']
        """
        import pandas as pd

        w = self.waypoints or {}
        shown = [c for c in COLUMNS.values() if (self.plan is not None or c.name not in _PLANNED)
                 and (c.name in w or c.name not in REMOVAL_COLUMNS)]
        return pd.DataFrame({"unit": [c.unit for c in shown], "dtype": [c.dtype for c in shown],
                             "meaning": [c.meaning for c in shown]},
                            index=pd.Index([c.name for c in shown], name="column"))

    def slicer_figures(self) -> "SlicerFigures":
        """What the slicer wrote into the file: its name, estimated time, filament, layers and progress marks.

        See :mod:`gcodekit.model.slicer`; computed once.
        """
        return self._kept("slicer_figures", lambda: slicer.slicer_figures(self))

    def summary(self) -> dict[str, Any]:
        """The one summary record (see :func:`gcodekit.model.statistics.summary`)."""
        return statistics.summary(self)

    # -- the seed's object API ---------------------------------------------------

    @property
    def commands(self) -> Sequence[Command]:
        """Typed commands, made when indexed."""
        return LazyList(len(self.table), self.table.command)

    @property
    def process_data(self) -> Sequence[ProcessData]:
        """Process data of each command; empty before emulation."""
        if self.waypoints is None:
            return []
        # one view's columns are derived once, so iterating is linear in the program
        mapping = self._waypoint_of_command()
        columns = self._process_columns()

        def make(i: int) -> ProcessData:
            k = int(mapping[i])
            return self.process_data_class(**self._process_fields(k, columns))

        return LazyList(len(self.table), make)

    @property
    def emulated(self) -> bool:
        return self.waypoints is not None

    def __len__(self) -> int:
        return len(self.table)

    def __repr__(self) -> str:
        state = "emulated" if self.emulated else "not emulated"
        return f"<{type(self).__name__} {self.file!r}: {len(self)} commands, {state}>"

    def _waypoint_of_command(self) -> np.ndarray:
        """Index of each command's own (last) waypoint."""
        cmd = self.waypoints["command"]
        last = np.r_[cmd[1:] != cmd[:-1], True]
        return np.flatnonzero(last)

    def _process_columns(self) -> dict[str, np.ndarray]:
        """Whole-program columns the process data of one waypoint is read from."""
        return {"elapsed_time": self.elapsed_time()}

    def _process_fields(self, k: int, columns: dict[str, np.ndarray]) -> dict[str, Any]:
        w = self.waypoints
        return dict(
            location=tuple(float(w[a][k]) for a in "xyzabc"),
            feed_rate=float(w["feed"][k]),
            elapsed_time=float(columns["elapsed_time"][k]),
            distance=float(w["distance"][k]),
            duration=float(w["time"][k]),
            motion=MOTION_NAMES[int(w["motion"][k])],
        )

    def elapsed_time(self) -> np.ndarray:
        """Time at the end of each waypoint, s (NaN steps count as zero)."""
        return self._kept("elapsed_time", lambda: np.cumsum(np.nan_to_num(self.waypoints["time"])))

    def attach_plan(self, plan: "Plan") -> None:
        """Take a motion planner's result: its per-waypoint ``time`` and, as :attr:`plan`, the per-move plan."""
        self.waypoints["time"] = plan.time
        self.plan = (plan.moves, plan.result)
        self._derived.pop("elapsed_time", None)

    def attach_removal(self, removed_volume: np.ndarray, removal_rate: np.ndarray) -> None:
        """Take a cutting simulation's per-waypoint columns: ``removed_volume`` (mm^3) and ``removal_rate`` (mm^3/min).

        :func:`gcodekit.cut.cut` (and :meth:`gcodekit.cut.CutSimulation.run`)
        call this once the whole program is cut; the columns then show in
        :meth:`to_dataframe`, :meth:`volumes` and the process data.

        Raises
        ------
        ValueError
            Before emulation, or columns of another length than the waypoints.
        """
        if self.waypoints is None:
            raise ValueError(f"{self.file}: attach_removal() needs an emulated operation")
        n = len(self.waypoints["x"])
        columns = {"removed_volume": removed_volume, "removal_rate": removal_rate}
        for name, values in columns.items():
            values = np.asarray(values, COLUMNS[name].dtype)
            if values.shape != (n,):
                raise ValueError(f"{name} has {values.shape} values for {n} waypoints")
            self.waypoints[name] = values

    # -- summaries ----------------------------------------------------------------

    def _require_emulation(self, what: str) -> bool:
        if self.waypoints is None:
            warnings.warn(f"{what} needs process data: run a machine on this operation first "
                          "(gcode_to_operation does)", stacklevel=3)
            return False
        return True

    def get_bounds(self, which: str = "motion") -> dict[str, list[float]] | None:
        """Axis-aligned bounds of the toolpath in machine coordinates, mm.

        Parameters
        ----------
        which : {"motion", "feed", "extrude"}, default: "motion"
            All moves, only feed (cutting) moves, or only extruding moves.
            Arcs count with their full sweep, not only their end points.

        Returns
        -------
        dict with ``min`` and ``max`` lists ``[x, y, z]``, or None (with a
        warning) before emulation or when nothing moved.
        """
        if not self._require_emulation("get_bounds()"):
            return None
        from ..errors import check_choice
        from .bounds import toolpath_bounds

        check_choice("which", which, ("motion", "feed", "extrude"))
        motion = np.asarray(self.waypoints["motion"])
        selected = {"motion": motion > 0, "feed": motion >= 2, "extrude": self.depositing}[which]
        # a cut or a bead starts where the previous step ended
        return toolpath_bounds(self.waypoints, selected, with_starts=which != "motion")

    def get_statistics(self) -> dict[str, Any] | None:
        """Counts, distances, time and (additive) layers and filament.

        Returns None with a warning before emulation.
        """
        if not self._require_emulation("get_statistics()"):
            return None
        return statistics.operation_statistics(self)

    # -- tables -------------------------------------------------------------------

    def time_by(self, key: str = "layer") -> "pd.DataFrame":
        """Time, distance and filament per ``"layer"``, ``"feature"`` or ``"tool"``."""
        import pandas as pd

        if not self._require_emulation("time_by()"):
            return pd.DataFrame()
        from ..analysis import time_by

        return time_by(self, key)

    def slicer_layer_times(self, mode: str = "normal") -> "pd.DataFrame":
        """Planned time by layer beside the slicer's progress marks (see :func:`gcodekit.analysis.slicer_layer_times`)."""
        import pandas as pd

        if not self._require_emulation("slicer_layer_times()"):
            return pd.DataFrame()
        from ..analysis import slicer_layer_times

        return slicer_layer_times(self, mode)

    def velocity_profile(self) -> "pd.DataFrame":
        """Planned and commanded speed over time (see :func:`gcodekit.analysis.velocity_profile`)."""
        import pandas as pd

        if not self._require_emulation("velocity_profile()"):
            return pd.DataFrame()
        from ..analysis import velocity_profile

        return velocity_profile(self)

    # -- outputs, one call away (each imports its output module when called) ------

    def plot(self, scalars: str | None = None, **options) -> np.ndarray | None:
        """Draw the toolpath in 3D (see :func:`gcodekit.visualize.plot_operation` for the options).

        Off-screen by default: returns the picture as an RGB array, and
        writes it to ``screenshot=`` when given.
        """
        from ..visualize import plot_operation

        return plot_operation(self, scalars, **options)

    def volumes(self) -> np.ndarray:
        """Material each waypoint moves, mm^3: laid (additive) or removed (subtractive); NaN where unknown."""
        return np.full(len(self.waypoints["x"]), np.nan)

    def to_vtk(self, path: str | os.PathLike | None = None, **options):
        """The toolpath as a PyVista mesh of poly-lines, written to ``path`` (``.vtp``/``.vtk``) when given.

        See :meth:`gcodekit.export.vtk.VTKExporter.toolpath_to_polydata` for
        the cells and their data (feed, speed, tool, source line, tool
        direction); an additive operation writes its deposition paths instead.
        """
        from ..export.vtk import VTKExporter

        if options:
            raise TypeError(f"to_vtk() of a {self.process} operation takes no options, not {', '.join(options)}")
        if path is not None:
            VTKExporter.toolpath_to_vtk(self, path)
        return VTKExporter.toolpath_to_polydata(self)

    def to_gcode(self, flavor: str = "rs274ngc") -> str:
        """The commands written back as G-code of ``flavor`` (see :class:`gcodekit.export.gcode.GcodeExporter`)."""
        from ..export.gcode import GcodeExporter

        return GcodeExporter(flavor).to_gcode(self)

    def to_dataframe(self) -> "pd.DataFrame":
        """One row per waypoint: command columns then process columns.

        Columns: ``line``, ``command`` (row in ``commands``), ``code``,
        ``kind``, then the waypoint columns (see :data:`gcodekit.schema.WAYPOINT_COLUMNS`),
        ``elapsed_time`` and the other derived columns (``power`` on laser
        machines).  Before emulation, one row per command with only the
        command columns and the parameters.
        """
        import pandas as pd

        t = self.table
        if self.waypoints is None:
            frame = pd.DataFrame({"line": t.line, "code": self._codes(), "kind": self._kinds()})
            for letter in sorted(t.params):
                frame[letter] = t.param(letter)
            return frame
        w = self.waypoints
        rows = w["command"]
        data = {"line": t.line[rows], "command": rows, "code": self._codes()[rows], "kind": self._kinds()[rows]}
        for column in WAYPOINT_COLUMNS:
            data[column.name] = w[column.name]
        data["motion"] = pd.Categorical.from_codes(w["motion"], categories=["none", *MOTION_NAMES[1:]])
        if getattr(self, "plan", None) is not None:
            from ..plan import waypoint_speeds

            data.update(waypoint_speeds(self.plan, len(w["x"])))
        data["elapsed_time"] = self.elapsed_time()
        data["start_time"] = data["elapsed_time"] - np.nan_to_num(np.asarray(w["time"], float))
        data["layer"], data["feature"], data["depositing"] = self.layers, self.features, self.depositing
        for name in ("power", *REMOVAL_COLUMNS):  # laser machines; once a cut has run
            if name in w:
                data[name] = w[name]
        return pd.DataFrame(data, copy=False)

    def _codes(self) -> np.ndarray:
        t = self.table
        letters = t.letter.astype(np.int64)
        numbers = t.number.astype(np.int64)
        keys = letters * 1_000_000 + np.maximum(numbers, 0)
        uniq, inverse = np.unique(keys, return_inverse=True)
        labels = []
        for key in uniq.tolist():
            letter, number = divmod(key, 1_000_000)
            if letter in (0, ord("@")):
                labels.append("")
            else:
                labels.append(code_label(chr(letter), number))
        codes = np.array(labels, dtype=object)[inverse]
        for row, (name, _) in t.named.items():
            codes[row] = name
        return codes

    def _kinds(self) -> "pd.Categorical":
        import pandas as pd

        names = [k.name.lower() for k in Kind]
        return pd.Categorical.from_codes(self.table.kind.astype(np.int64), categories=names)

    def motions(self) -> "pd.DataFrame":
        """One row per motion, in the program's units in force at each move.

        Columns ``line, motion, x, y, z, a, b, c, feed, cx, cy, cz, plane,
        units, time, t_end``: end points and arc centres in machine
        coordinates (all offsets applied), lengths in the units in force (mm
        or inch), feed in those units per minute (empty for rapids), plane
        ``XY``/``XZ``/``YZ``, the move's duration and the time at its end (s).
        A planned operation adds ``start_v, cruise_v, end_v`` (units/s).
        """
        import pandas as pd

        if not self._require_emulation("motions()"):
            return pd.DataFrame()
        w = self.waypoints
        moved = np.flatnonzero(w["motion"] > 0)
        rows = w["command"][moved]
        inch = w["units"][moved] == 1
        scale = np.where(inch, 1.0 / MM_PER_INCH, 1.0)
        frame = {"line": self.table.line[rows],
                 "motion": np.array(MOTION_NAMES, dtype=object)[w["motion"][moved]]}
        for key in "xyz":
            frame[key] = w[key][moved] * scale
        for key in "abc":
            frame[key] = w[key][moved]
        feed = w["feed"][moved] * scale
        frame["feed"] = np.where(w["motion"][moved] == 1, np.nan, feed)
        for key in ("cx", "cy", "cz"):
            frame[key] = w[key][moved] * scale
        frame["plane"] = np.array(["", "XY", "XZ", "YZ"], dtype=object)[w["plane"][moved] - 16]
        frame["units"] = np.where(inch, "in", "mm")
        frame["time"] = w["time"][moved]
        frame["t_end"] = self.elapsed_time()[moved]
        if getattr(self, "plan", None) is not None:  # planned by the machine's firmware model
            from ..plan import waypoint_speeds

            for key, values in waypoint_speeds(self.plan, len(w["x"])).items():
                if key != "accel":
                    frame[key] = values[moved] * scale
        return pd.DataFrame(frame)
