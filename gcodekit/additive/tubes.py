"""Output stage: the deposited beads as closed tubes of their cross-section, one triangle mesh in program order.

Each deposition path of an :class:`~gcodekit.additive.AdditivePart` (its
points, arcs followed every 5 degrees) is swept by its bead's
cross-section (:meth:`AdditivePart.bead_geometry`: width and height per
deposition segment, the shape of the part's :class:`Bead`, a stadium when
the bead comes from the program): a ring of ``sides`` points at every point
of the path, the nozzle at the top of the bead, joined to the next ring by
quadrilaterals (two triangles each) and closed by a cap at both ends of the
path.  Where the path turns, the ring lies in the plane that halves the
turn and is widened so that the bead keeps its width on both sides (a
mitre joint); where it turns by more than 120 degrees (a mitre would
widen it more than twice) one tube ends with a cap and the next begins.
So a bead's volume is its outline's area times its centre line's length.

The triangles are in program order and each knows the waypoint whose move
laid it, so the beads laid up to any move are the first
:meth:`BeadTubes.count_through` triangles: a view that follows a slider
slices them, and never builds the geometry again.

Examples
--------
>>> import gcodekit
>>> from gcodekit.additive import AdditivePart, Bead
>>> op = gcodekit.gcode_to_operation("M83\\nG1 Z0.2 F600\\nG1 X10 E0.5\\n", machine="marlin", plan=False)
>>> tubes = bead_tubes(AdditivePart(op, Bead(0.4, 0.2, "rectangle")), sides=4)
>>> tubes.triangles.shape, round(tubes.polydata().volume, 6)    # 0.4 x 0.2 x 10 mm
((12, 3), 0.8)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ConfigError
from .bead import bead_outline, bead_width

if TYPE_CHECKING:
    import pyvista as pv

    from .part import AdditivePart

#: Triangles a bead mesh may have at most (about 100 bytes each to build, and what vtk.js is sent).
MAX_TRIANGLES = 8_000_000
#: How far a mitre joint may widen a bead where the path turns sharply.
MAX_MITRE = 2.0


@dataclass
class BeadTubes:
    """The beads of a part as a triangle mesh in program order.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        mm, machine coordinates.
    normals : ndarray, shape (n, 3)
        Unit normals of the outline at each point (for smooth shading).
    triangles : ndarray, shape (m, 3)
        Point indices, counter-clockwise seen from outside.
    triangle_row : ndarray, shape (m,)
        The waypoint whose move laid each triangle (non-decreasing).
    point_row : ndarray, shape (n,)
        The waypoint whose move laid each point's ring.
    notes : list of str
        What had to be assumed (a bead width the program does not give).
    """

    points: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    triangle_row: np.ndarray
    point_row: np.ndarray
    notes: list[str]

    def count_through(self, row: int) -> int:
        """How many triangles the moves up to and including waypoint ``row`` laid."""
        return int(np.searchsorted(self.triangle_row, row, side="right"))

    def polydata(self, count: int | None = None) -> "pv.PolyData":
        """The first ``count`` triangles (default all) as a PyVista mesh with point normals and ``waypoint``."""
        from ..export.vtk import import_pyvista

        pv = import_pyvista()
        mesh = pv.PolyData(self.points, faces=faces_array(self.triangles[:count]))
        mesh.point_data["Normals"] = self.normals
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["waypoint"] = self.point_row
        return mesh


def faces_array(triangles: np.ndarray) -> np.ndarray:
    """VTK's flat face list ``[3, a, b, c, 3, ...]`` of ``(m, 3)`` triangles."""
    return np.column_stack([np.full(len(triangles), 3, np.int64), triangles]).ravel()


def _unit(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    norm = np.linalg.norm(v, axis=1)
    return v / np.where(norm > 0, norm, 1.0)[:, None], norm


def bead_tubes(part: "AdditivePart", *, sides: int = 8, layers: tuple[int, int] | None = None) -> BeadTubes:
    """The deposited beads of ``part`` as closed tubes (see the module's description).

    Parameters
    ----------
    part : AdditivePart
    sides : int, default: 8
        Points on each cross-section's outline (:func:`~gcodekit.additive.bead.bead_outline`).
    layers : (int, int), default: None
        Only the beads of layers ``first..last`` (both included); None: all.

    Raises
    ------
    ConfigError
        ``sides`` below 3, or a mesh of more than :data:`MAX_TRIANGLES`
        triangles (the message says how many and what to give instead).
    """
    if sides < 3:
        raise ConfigError(f"a bead's outline needs at least 3 sides, not {sides}")
    points, offsets, rows = part.deposition_points()
    geometry = part.bead_geometry()
    dep_layer = part.depositions["layer"].to_numpy()
    keep = np.ones(dep_layer.size, bool) if layers is None else (dep_layer >= layers[0]) & (dep_layer <= layers[1])
    counts = np.diff(offsets)
    keep &= counts >= 2
    segments = int((counts[keep] - 1).sum())
    triangles = 2 * sides * segments + 2 * (sides - 2) * int(keep.sum())
    if triangles > MAX_TRIANGLES:
        raise ConfigError(f"the beads would be {triangles:,} triangles (at most {MAX_TRIANGLES:,}): show fewer "
                          f"layers (layers=(first, last); the part has {part.n_layers}) or fewer sides")
    notes: list[str] = []
    width, height, shape = _cross_sections(part, geometry, notes)
    take = np.repeat(keep, counts)
    path = np.repeat(np.arange(counts.size), counts)[take]
    P, rows = points[take], rows[take]
    counts = counts[keep]
    width, height = width[keep], height[keep]
    if P.shape[0] == 0:
        empty = np.zeros((0, 3))
        return BeadTubes(empty, empty, np.zeros((0, 3), np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), notes)
    w, h = np.repeat(width, counts), np.repeat(height, counts)
    first = np.zeros(P.shape[0], bool)
    first[np.r_[0, np.cumsum(counts)[:-1]]] = True
    P, rows, path, w, h, first = _split_sharp_turns(P, rows, path, w, h, first)
    n = P.shape[0]
    starts = np.flatnonzero(first)
    last = np.r_[first[1:], True]
    # the direction in and out of each point (zero at a path's ends, and over repeated points)
    step, _ = _unit(np.diff(P, axis=0))
    d_in = np.zeros_like(P)
    d_out = np.zeros_like(P)
    d_in[1:] = step
    d_out[:-1] = step
    d_in[first] = 0.0
    d_out[last] = 0.0
    tangent, size = _unit(d_in + d_out)
    # a path that doubles back on itself: take the way out (or in, at its end)
    back = size < 1e-9
    tangent[back] = np.where(np.linalg.norm(d_out[back], axis=1, keepdims=True) > 0, d_out[back], d_in[back])
    normal = np.asarray(part.layer_normal, float)
    lateral, size = _unit(np.cross(tangent, normal))
    flat = size < 1e-9  # a move along the layer normal: any lateral direction will do
    lateral[flat] = _unit(np.cross(tangent[flat] + 1e-3 * np.array([1.0, 0.3, 0.0]), normal))[0]
    up = np.cross(lateral, tangent)
    # the mitre: the ring's half width grows as 1 / cos(half the turn)
    along = np.where(np.linalg.norm(d_out, axis=1) > 0, np.einsum("ij,ij->i", tangent, d_out),
                     np.einsum("ij,ij->i", tangent, d_in))
    mitre = 1.0 / np.clip(along, 1.0 / MAX_MITRE, 1.0)
    mitre[back] = 1.0
    lat, vert = bead_outline(w, h, shape, sides)
    # the nozzle lays the bead's top: the centre is half a bead below the path
    centre = P - up * (h / 2.0)[:, None]
    ring = (centre[:, None, :] + (lat * mitre[:, None])[..., None] * lateral[:, None, :]
            + vert[..., None] * up[:, None, :])
    # each outline point's normal: across the chord between its neighbours, outwards (the outline turns
    # counter-clockwise), as the ring is widened
    chord_lat = (np.roll(lat, -1, axis=1) - np.roll(lat, 1, axis=1)) * mitre[:, None]
    chord_vert = np.roll(vert, -1, axis=1) - np.roll(vert, 1, axis=1)
    ring_normal = chord_vert[..., None] * lateral[:, None, :] - chord_lat[..., None] * up[:, None, :]
    ring_normal /= np.maximum(np.linalg.norm(ring_normal, axis=2, keepdims=True), 1e-300)
    k = np.arange(sides)
    # quadrilaterals between ring i and ring i + 1 of the same path (i not a path's last point)
    joined = np.flatnonzero(~last)
    a0 = joined[:, None] * sides + k
    a1 = joined[:, None] * sides + (k + 1) % sides
    b0, b1 = a0 + sides, a1 + sides
    quads = np.stack([np.stack([a0, b0, b1], -1), np.stack([a0, b1, a1], -1)], axis=2).reshape(len(joined), -1, 3)
    # a fan over each end ring: facing back at the start, forward at the end
    fan = np.stack([np.zeros(sides - 2, np.int64), np.arange(1, sides - 1), np.arange(2, sides)], -1)
    start_caps = starts[:, None, None] * sides + fan
    end_caps = np.flatnonzero(last)[:, None, None] * sides + fan[:, ::-1]
    # program order: a path's start cap, its quadrilaterals, its end cap
    seg_row = rows[joined + 1]  # a piece of path belongs to the move it ends
    pieces = [(start_caps, rows[starts + 1], path[starts], 0), (quads, seg_row, path[joined], 1),
              (end_caps, rows[last], path[last], 2)]
    tris = np.concatenate([p[0].reshape(-1, 3) for p in pieces])
    tri_row = np.concatenate([np.repeat(p[1], p[0].shape[1]) for p in pieces])
    key_path = np.concatenate([np.repeat(p[2], p[0].shape[1]) for p in pieces])
    key_kind = np.concatenate([np.full(p[0].shape[0] * p[0].shape[1], p[3]) for p in pieces])
    order = np.lexsort((key_kind, tri_row, key_path))
    point_row = np.where(first, np.r_[rows[1:], rows[-1]], rows)
    return BeadTubes(ring.reshape(-1, 3), ring_normal.reshape(-1, 3), tris[order].astype(np.int64),
                     tri_row[order].astype(np.int64), np.repeat(point_row, sides).astype(np.int64), notes)


def _split_sharp_turns(P, rows, path, w, h, first):
    """End a tube and start the next at each point where the path turns more than a mitre joint can take.

    A mitre widens the bead by 1 / cos(half the turn); beyond :data:`MAX_MITRE`
    (a turn of more than 120 degrees, as infill doubling back makes) the
    point is repeated, ending one tube with a cap and starting the next, so
    both keep their width and their volume.
    """
    step, length = _unit(np.diff(P, axis=0))
    inner = ~first[1:-1] & ~first[2:] if P.shape[0] > 2 else np.zeros(0, bool)  # points with a step in and out
    along = np.einsum("ij,ij->i", step[:-1], step[1:]) if P.shape[0] > 2 else np.zeros(0)
    half_cos = np.sqrt(np.clip((1.0 + along) / 2.0, 0.0, 1.0))
    sharp = np.zeros(P.shape[0], bool)
    sharp[1:-1] = inner & (length[:-1] > 0) & (length[1:] > 0) & (half_cos < 1.0 / MAX_MITRE)
    if not sharp.any():
        return P, rows, path, w, h, first
    repeat = np.where(sharp, 2, 1)
    index = np.repeat(np.arange(P.shape[0]), repeat)
    again = np.r_[False, index[1:] == index[:-1]]  # the second copy starts the next tube
    new_first = first[index] & ~again | again
    # the next tube's first point carries the waypoint of its first piece (set from the point after it)
    return P[index], rows[index], path[index], w[index], h[index], new_first


def _cross_sections(part: "AdditivePart", geometry: dict[str, np.ndarray],
                    notes: list[str]) -> tuple[np.ndarray, np.ndarray, str]:
    """Width and height of each deposition segment's bead, and the outline's shape."""
    if part.bead is not None:
        return geometry["bead_width"], geometry["bead_height"], part.bead.shape
    height = np.asarray(geometry["bead_height"], float)
    area = np.asarray(geometry["bead_area"], float)
    width = bead_width(area, height, "stadium")
    unknown_h = ~(height > 0)
    if unknown_h.any():
        known = height[~unknown_h]
        fill = float(np.median(known)) if known.size else 1.0
        notes.append(f"{int(unknown_h.sum())} beads' height is not known from the layers: drawn {fill:g} mm high")
        height = np.where(unknown_h, fill, height)
        width = bead_width(area, height, "stadium")
    unknown_w = ~(width > 0)
    if unknown_w.any():
        notes.append(f"the program does not say how much material {int(unknown_w.sum())} beads lay: drawn as wide "
                     "as they are high (give bead=Bead(width, height) for their size)")
        width = np.where(unknown_w, height, width)
    return width, height, "stadium"
