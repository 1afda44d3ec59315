"""Model: exact axis-aligned bounds of a toolpath, arcs included."""

from __future__ import annotations

import numpy as np

from ..emulate import arcs

_SELECT = {
    "motion": lambda w: w["motion"] > 0,
    "feed": lambda w: w["motion"] >= 2,
    "extrude": lambda w: (w["motion"] > 0) & (w["de"] > 0),
}


def toolpath_bounds(w: dict[str, np.ndarray], which: str = "motion") -> dict[str, list[float]] | None:
    """Bounds of the selected moves (see :meth:`Operation.get_bounds`)."""
    from ..errors import check_choice

    check_choice("which", which, _SELECT)
    sel = np.flatnonzero(_SELECT[which](w))
    if sel.size == 0:
        return None
    xyz = np.column_stack([w["x"], w["y"], w["z"]])
    points = [xyz[sel]]
    if which != "motion":  # a cut or a bead starts where the previous step ended
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
