"""Output stage: the level of detail of a still picture -- only what its pixels can show.

A report picture of a 3 M-line print is about 600 x 500 pixels; most of its
segments lie under others or share their pixels.  These functions keep the
picture and drop the rest, pure NumPy, in three steps
(:func:`gcodekit.visualize.draw_toolpath` runs them):

1. *Painter's order.*  Segments are drawn far to near.  When the camera looks
   down or up at all (``iso``, ``top``), along any line of sight the nearer
   point is the higher one (the lower one from below), so flat segments
   sorted by height are in a true painter's order; within one height, program
   order is kept, so the moves of a layer stay one after another.  For a
   horizontal camera (``front``, ``side``) the segments are sorted by depth.
2. *Visibility.*  Each segment is sampled once a pixel; each pixel
   lists the segments drawn over it.  A segment that is not among the last
   few of any pixel is covered by nearer ones (or outside the picture) and
   is dropped.
3. *Polylines.*  Kept segments that follow one another in that order, join
   end to start and share a style become one polyline; runs that follow one
   another with one style are one path (the pen lifted between them), so
   the drawing library makes a path per batch instead of one per segment.

A picture drawn from the runs differs from the full drawing only where a
dropped segment's anti-aliased edge showed beside the one over it;
``tests/test_lod.py`` compares the two pixel by pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Spacing of the visibility samples along a segment, pixels (half a pixel drew plate150 no closer to its
#: full drawing, and took a third longer).
SAMPLE_PX = 1.0
#: Samples handled at once (bounds the memory of a 3 M-segment picture to about 200 MB).
CHUNK_SAMPLES = 1 << 22


@dataclass
class Polylines:
    """Runs of joined segments, in drawing order.

    Attributes
    ----------
    vertices : ndarray (v, 2)
        Every run's vertices, one run after another.
    offsets : ndarray (r + 1,) int
        Run ``k`` is ``vertices[offsets[k]:offsets[k + 1]]``.
    first : ndarray (r,) int
        The segment (index into the input) each run starts with: its style.
    segments : int
        Segments the runs hold.
    """

    vertices: np.ndarray
    offsets: np.ndarray
    first: np.ndarray
    segments: int

    def runs(self) -> list[np.ndarray]:
        """The runs as a list of (m, 2) arrays (what matplotlib's ``LineCollection`` takes)."""
        return np.split(self.vertices, self.offsets[1:-1])

    def batches(self, style: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
        """Consecutive runs of one style drawn as one path each: fewer, larger paths in the same order.

        Parameters
        ----------
        style : ndarray (r,) or (r, k)
            The style of each run.

        Returns
        -------
        vertices : list of (m, 2) arrays
            One per batch, its runs one after another.
        starts : list of (m,) bool arrays
            True where a run begins (the pen moves there without drawing).
        first : ndarray (b,) int
            The first run of each batch.
        """
        r = self.offsets.size - 1
        new = np.ones(r, bool)
        if r > 1:
            new[1:] = ~(style[1:] == style[:-1]).reshape(r - 1, -1).all(axis=1)
        first = np.flatnonzero(new)
        begins = np.zeros(self.vertices.shape[0], bool)
        begins[self.offsets[:-1]] = True
        cuts = self.offsets[first[1:]]
        return np.split(self.vertices, cuts), np.split(begins, cuts), first


def painter_order(p0: np.ndarray, p1: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """Indices of segments ``p0 -> p1`` (3D) far to near as seen along ``eye`` (towards the viewer).

    Sorted by height when the camera looks down or up at all, program order
    kept among equal keys (see the module's docstring); by depth otherwise.
    """
    key = (p0[:, 2] + p1[:, 2]) * np.sign(eye[2]) if abs(eye[2]) > 1e-9 else (p0 + p1) @ eye
    return np.argsort(key, kind="stable")


def last_drawn(a: np.ndarray, b: np.ndarray, width: int, height: int, depth: int = 6,
               sample_px: float = SAMPLE_PX) -> np.ndarray:
    """Which segments ``a -> b`` (pixel coordinates, in drawing order) are among the last ``depth`` over some pixel.

    Pixel ``(i, j)`` is the square ``i <= x < i + 1``, ``j <= y < j + 1`` of a
    ``width`` x ``height`` picture; samples outside it count for nothing.
    Lines thinner than a pixel cover it only in part, so a pixel's colour
    blends the last few segments drawn over it, each weighted by what the
    later ones leave: ``depth`` of them (six: the seventh shows through
    under 2 %) keep the blend.

    Returns
    -------
    ndarray (n,) bool
    """
    n = a.shape[0]
    a, d = a.astype(np.float32), (b - a).astype(np.float32)
    # k samples at the middles of k equal parts, at most sample_px apart (one for a segment inside a pixel)
    count = np.maximum(np.ceil(np.hypot(d[:, 0], d[:, 1]) / sample_px), 1).astype(np.int64)
    d /= count[:, None]  # from one sample to the next
    a += d / 2
    ends = np.cumsum(count)
    last = np.zeros(0, np.int64)  # the last `depth` (pixel, segment) keys of each pixel so far
    lo = 0
    while lo < n:
        hi = max(int(np.searchsorted(ends, ends[lo] - count[lo] + CHUNK_SAMPLES, side="right")), lo + 1)
        k = count[lo:hi]
        step = (np.arange(int(ends[hi - 1] - ends[lo] + k[0])) - np.repeat(np.cumsum(k) - k, k)).astype(np.float32)
        x = np.repeat(a[lo:hi, 0], k) + step * np.repeat(d[lo:hi, 0], k)
        y = np.repeat(a[lo:hi, 1], k) + step * np.repeat(d[lo:hi, 1], k)
        seg = np.repeat(np.arange(lo, hi, dtype=np.int64), k)
        inside = (x >= 0) & (x < width) & (y >= 0) & (y < height)
        # one number per (pixel, segment), ordered by pixel, then by drawing order
        key = ((y[inside].astype(np.int64) * width + x[inside].astype(np.int64)) << 32) | seg[inside]
        # a straight segment crosses a pixel once: its samples there follow one another
        key = key[np.r_[True, key[1:] != key[:-1]]] if key.size else key
        # later chunks are drawn later: what falls out of a pixel's last few now never comes back, so the memory
        # stays the picture's pixels times `depth` however many samples the segments make (200 k rapids
        # across the whole picture: 100 M samples)
        last = _last_per_pixel(np.sort(np.concatenate([last, key])), depth)
        lo = hi
    keep = np.zeros(n, bool)
    keep[last & 0xFFFFFFFF] = True
    return keep


def _last_per_pixel(key: np.ndarray, depth: int) -> np.ndarray:
    """The keys (pixel << 32 | segment, sorted) among the last ``depth`` of their pixel."""
    if key.size == 0:
        return key
    cell = key >> 32
    first = np.r_[True, cell[1:] != cell[:-1]]
    last = np.r_[np.flatnonzero(first[1:]), cell.size - 1]  # each pixel's last entry
    from_end = last[np.cumsum(first) - 1] - np.arange(cell.size)
    return key[from_end < depth]


def polylines(a: np.ndarray, b: np.ndarray, style: np.ndarray, keep: np.ndarray | None = None) -> Polylines:
    """Join segments ``a -> b`` (in drawing order) into runs: each next one starts where the last ended.

    Parameters
    ----------
    a, b : ndarray (n, 2)
        Segment ends, in drawing order.
    style : ndarray (n,) or (n, k)
        A key per segment (say its colour and width); a run never changes style.
    keep : ndarray (n,) bool, optional
        Segments to draw (default: all); a dropped one ends a run.
    """
    kept = np.flatnonzero(np.ones(a.shape[0], bool) if keep is None else keep)
    a, b, style = a[kept], b[kept], style[kept]
    joins = np.zeros(kept.size, bool)
    if kept.size > 1:
        same = (style[1:] == style[:-1]).reshape(kept.size - 1, -1).all(axis=1)
        joins[1:] = (kept[1:] == kept[:-1] + 1) & same & np.all(a[1:] == b[:-1], axis=1)
    starts = np.flatnonzero(~joins)
    # a run of m segments has m + 1 vertices: every segment's start, then the last one's end
    lengths = np.diff(np.r_[starts, kept.size]) + 1
    offsets = np.r_[0, np.cumsum(lengths)]
    vertices = np.empty((int(offsets[-1]), 2))
    run = np.cumsum(~joins) - 1  # the run of each segment
    position = offsets[run] + np.arange(kept.size) - starts[run]
    vertices[position] = a
    vertices[offsets[1:] - 1] = b[np.r_[starts[1:], kept.size] - 1]
    return Polylines(vertices, offsets, kept[starts], int(kept.size))

