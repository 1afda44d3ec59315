"""Output: the Abaqus AM event series of a program -- where material (or heat) is laid, and when.

Examples
--------
>>> import gcodekit
>>> df = gcodekit.gcode_file_to_dataframe("M83\\nG1 X10 E1 F600\\nG1 X20\\n", "marlin", plan=False)
>>> event_series(df).values.tolist()
[[0.0, 0.0, 0.0, 0.0, 1.0], [1.0, 10.0, 0.0, 0.0, 0.0], [2.0, 20.0, 0.0, 0.0, 0.0]]
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ..errors import check_choice

if TYPE_CHECKING:
    import pandas as pd

    from ..model.operation import Operation

__all__ = ["event_series", "write_event_series", "gcode_dataframe_to_event_series"]


def event_series(df: "pd.DataFrame", source: str = "material") -> "pd.DataFrame":
    """An Abaqus AM event series from a waypoint DataFrame (``Operation.to_dataframe``).

    Parameters
    ----------
    df : DataFrame
        Needs ``x, y, z, de, distance, time, elapsed_time, motion`` (and
        ``laser`` for ``source="heat"``); an additive operation's frame also
        has ``deposited_volume``, which then decides where material is laid.
    source : {"material", "heat"}, default: "material"
        ``material``: 1 while material is deposited (filament pushed on a
        move, or for DED a feed move with the heat source on); ``heat``: 1 while the laser/weld heat source is on during a move
        (DED, M61/M62).

    Returns
    -------
    DataFrame with ``time, x, y, z, value``: at each time the source is at
    that point with that value until the next event, moving in a straight
    line between events (how Abaqus reads an event series).  The last event
    switches the source off.

    """
    import pandas as pd

    check_choice("source", source, ("material", "heat"))
    motion = np.asarray(df["motion"].cat.codes if hasattr(df["motion"], "cat") else df["motion"])
    moved = np.flatnonzero(motion > 0)
    if moved.size == 0:
        return pd.DataFrame(columns=["time", "x", "y", "z", "value"])
    xyz = df[["x", "y", "z"]].to_numpy(float)
    end_t = df["elapsed_time"].to_numpy(float)[moved]
    start_t = end_t - np.nan_to_num(df["time"].to_numpy(float)[moved])
    start_xyz = np.vstack([np.zeros((1, 3)), xyz[:-1]])[moved]
    if source == "material" and "deposited_volume" in df:  # an additive operation's frame: screws, beads too
        volume = df["deposited_volume"].to_numpy(float)[moved]
        value = ((volume > 0) | np.isnan(volume)) & (df["distance"].to_numpy(float)[moved] > 0)
    elif source == "material":  # filament pushed, or (DED, no E words) the heat source on during a feed move
        value = (df["de"].to_numpy(float)[moved] > 0) & (df["distance"].to_numpy(float)[moved] > 0)
        if "laser" in df:
            value |= (df["laser"].to_numpy()[moved] == 1) & (motion[moved] >= 2)
    else:
        value = (df["laser"].to_numpy()[moved] == 1) & (motion[moved] >= 2)
    events = pd.DataFrame({"time": np.r_[start_t, end_t[-1]],
                           "x": np.r_[start_xyz[:, 0], xyz[moved[-1], 0]],
                           "y": np.r_[start_xyz[:, 1], xyz[moved[-1], 1]],
                           "z": np.r_[start_xyz[:, 2], xyz[moved[-1], 2]],
                           "value": np.r_[value.astype(float), 0.0]})
    # a run of travel moves is one "off" event: the source is off wherever it is
    off = events["value"].to_numpy() == 0
    repeat = off & np.r_[False, off[:-1]]
    repeat[-1] = False
    return events[~repeat].reset_index(drop=True)


#: The seed's name for :func:`event_series`.
gcode_dataframe_to_event_series = event_series


def write_event_series(op: "Operation", output_path: str | os.PathLike, *, source: str = "material") -> "pd.DataFrame":
    """Write ``op``'s event series (``time, x, y, z, value`` lines, no header, as Abaqus reads them)."""
    events = event_series(op.to_dataframe(), source)
    events.to_csv(output_path, header=False, index=False, float_format="%.6f")
    return events
