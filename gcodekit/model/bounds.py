"""Model: exact axis-aligned bounds of a toolpath, arcs included."""

from __future__ import annotations

import numpy as np

from ..emulate import arcs

def toolpath_bounds(w: dict[str, np.ndarray], selected: np.ndarray, *,
                    with_starts: bool = False) -> dict[str, list[float]] | None:
    """Bounds of the moves ``selected`` (a mask over the waypoints; see :meth:`Operation.get_bounds`).

    ``with_starts`` counts where each selected move starts as well as where it
    ends (the previous waypoint); arcs count with their full sweep.
    """
    sel = np.flatnonzero(selected)
    if sel.size == 0:
        return None
    xyz = np.column_stack([w["x"], w["y"], w["z"]])
    points = [xyz[sel]]
    if with_starts:
        starts = sel[sel > 0] - 1
        points.append(xyz[starts])
    arc_rows = sel[w["motion"][sel] >= 3]
    arc_rows = arc_rows[arc_rows > 0]
    if arc_rows.size:
        points.append(_arc_extremes(w, xyz, arc_rows))
    allp = np.vstack(points)
    return {"min": allp.min(axis=0).tolist(), "max": allp.max(axis=0).tolist()}


def _arc_extremes(w: dict, xyz: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Points where arcs reach their extremes along the plane's two axes."""
    centers = np.column_stack([w["cx"], w["cy"], w["cz"]])
    out = []
    for plane in (17, 18, 19):
        r = rows[w["plane"][rows] == plane]
        if not r.size:
            continue
        (f, g, _), _ = arcs.PLANES[plane]
        start, end, center = xyz[r - 1][:, [f, g]], xyz[r][:, [f, g]], centers[r][:, [f, g]]
        cw = w["motion"][r] == 3
        swept = arcs.sweep(start, end, center, cw, np.ones(r.size))
        a0 = np.arctan2(start[:, 1] - center[:, 1], start[:, 0] - center[:, 0])
        radius = np.hypot(*(start - center).T)
        for q, (cos, sin) in enumerate(((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))):
            angle = q * np.pi / 2
            delta = np.mod(np.where(cw, a0 - angle, angle - a0), arcs.TWO_PI)
            hit = delta <= swept
            p = xyz[r][hit].copy()
            p[:, f] = center[hit, 0] + radius[hit] * cos
            p[:, g] = center[hit, 1] + radius[hit] * sin
            out.append(p)
    return np.vstack(out) if out else np.zeros((0, 3))
