"""Plan stage: the lookahead every firmware planner shares -- passes, trapezoids, axis limits.

GRBL, Marlin and RepRapFirmware plan alike: each move's entry speed is
capped by its junction, a reverse pass from the last stop and a forward
pass from the first bound what acceleration allows, and each move is then a
trapezoid.  The firmware modules compute their own caps and call these.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .kernels import engine
from .moves import PlanResult
from .scans import Increments, backward_min, forward_min
from .trapezoids import NextEntry, TrapezoidPlan

__all__ = ["BLOCK", "limit_by_axis_maximum", "lookahead", "trapezoid", "empty_result", "unit_vectors"]

BLOCK = 1 << 14  # element-wise steps run on this many moves at a time: less fresh memory


def limit_by_axis_maximum(max_value, unit_vec) -> np.ndarray:
    """grbl's ``limit_value_by_axis_maximum``: per row, the largest value along
    ``unit_vec`` whose component on every axis stays within that axis's limit.

    ``max_value`` holds one limit per axis (a number, or an array with one
    value per row); ``unit_vec`` is a sequence of per-axis columns.
    """
    limit = np.full(np.shape(unit_vec[0]), np.inf)
    for cap, u in zip(max_value, unit_vec):
        u = np.abs(u)
        ratio = np.divide(cap, u, out=np.full(u.shape, np.inf), where=u > 0)
        np.minimum(limit, ratio, out=limit)
    return limit


def lookahead(max_entry_v2: np.ndarray, delta_v2: np.ndarray | Increments, rest_after: np.ndarray, *,
              rest_v2: float = 0.0, nominal_length: np.ndarray | None = None,
              reuse: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit speeds (squared) after the reverse and forward passes.

    Parameters
    ----------
    max_entry_v2 : ndarray
        Cap on each move's entry speed (the junction limit; for the first
        move after a rest, the speed it may start at).
    delta_v2 : ndarray or Increments
        ``2 * accel * move_d``: what a move can add to (or shed from) v^2
        (:class:`.scans.Increments`: made where the compiled scans read
        them, an array fewer).
    rest_after : ndarray of bool
        The machine stops after this move (the last one is always a stop).
    rest_v2 : float, default: 0
        Speed squared at a stop (Marlin: ``MINIMUM_PLANNER_SPEED`` squared).
    nominal_length : ndarray of bool, optional
        Marlin's ``nominal_length`` flag: such a move always enters at its
        cap, and the next move's entry is not checked against it.
    reuse : bool, default: False
        Write the reverse pass's bounds over ``max_entry_v2`` and the
        forward pass's increments over ``delta_v2`` (float64 arrays the
        caller no longer needs): two arrays fewer at the peak.

    Returns
    -------
    entry_v2 : ndarray
    exit_v2 : NextEntry
        The next move's entry, ``rest_v2`` after a stop (not stored).

    Notes
    -----
    grbl ``planner_recalculate``, reverse then forward::

        for i in reversed(range(n)):   # next entry: rest_v2 after a stop
            entry[i] = min(max_entry[i], entry[i+1] + delta[i])
        for i in range(1, n):          # no limit across a stop
            entry[i] = min(entry[i], entry[i-1] + delta[i-1])

    Both are the scans of :mod:`.scans`.  A stop (or a ``nominal_length``
    move) cuts each recurrence: giving that move an increment equal to its
    own bound makes the minimum pick the bound whatever comes next.
    """
    n = max_entry_v2.size
    free = rest_after.copy()
    if nominal_length is not None:
        free |= nominal_length
    stop = rest_after if nominal_length is None else rest_after & ~nominal_length  # a nominal_length move: its cap
    if isinstance(delta_v2, Increments) and engine(n) is not None:  # the compiled scans make them as they go
        bound = max_entry_v2 if reuse and _writable(max_entry_v2) else np.array(max_entry_v2, float)
        at = np.flatnonzero(stop)
        bound[at] = np.minimum(bound[at], rest_v2 + delta_v2.at(at))
        del stop, at, max_entry_v2
        increments = dataclasses.replace(delta_v2, free=free)
        reverse_v2 = backward_min(bound, increments, out=bound)
        entry_v2 = forward_min(reverse_v2, increments, first=float(reverse_v2[0]), out=reverse_v2) if n else reverse_v2
        return entry_v2, NextEntry(entry_v2, np.flatnonzero(rest_after), rest_v2)
    if isinstance(delta_v2, Increments):  # the NumPy scans read them stored
        delta_v2 = delta_v2.at(slice(None))
    if reuse and _writable(max_entry_v2):
        bound = max_entry_v2
        np.minimum(bound, rest_v2 + delta_v2, out=bound, where=stop)
    else:
        bound = np.where(stop, np.minimum(max_entry_v2, rest_v2 + delta_v2), max_entry_v2)
    del stop, max_entry_v2
    reuse_delta = reuse and _writable(delta_v2)
    if reuse_delta:
        # the reverse pass's increments written over delta_v2: each one that differs is rewritten for the
        # forward pass below (cut), but the last move's, which the forward pass never reads
        increments = delta_v2
        np.copyto(increments, bound, where=free)
    else:
        increments = np.where(free, bound, delta_v2)
    # each pass writes over its bounds (ours, or max_entry_v2 given to reuse), and each array is dropped as
    # soon as it is used: the plan of a large program is memory-bound
    reverse_v2 = backward_min(bound, increments, out=bound)
    del bound, increments
    forward_inc = delta_v2 if reuse_delta else delta_v2.copy()
    del delta_v2
    np.copyto(forward_inc[:-1], reverse_v2[1:], where=free[:-1])  # cut: no index arrays, most moves may be free
    del free
    entry_v2 = forward_min(reverse_v2, forward_inc, first=float(reverse_v2[0]), out=reverse_v2) if n else reverse_v2
    del forward_inc, reverse_v2
    return entry_v2, NextEntry(entry_v2, np.flatnonzero(rest_after), rest_v2)


def _writable(a) -> bool:
    return isinstance(a, np.ndarray) and a.dtype == np.float64 and a.flags.writeable


def trapezoid(move_d: np.ndarray, accel: np.ndarray, entry_v2: np.ndarray, nominal_v2: np.ndarray,
              exit_v2: np.ndarray) -> PlanResult:
    """Phase speeds and durations of trapezoidal moves.

    Accelerate from the entry speed, cruise at the nominal speed, brake to
    the exit speed; a move too short to cruise peaks where accelerating and
    braking meet (Marlin's ``intersection_distance``, grbl's ``st_prep_buffer``
    ramp).  An entry above what the move can brake from is clipped, as the
    firmware's step generator does.  Every field at once, a block of moves
    at a time (:class:`.trapezoids.TrapezoidPlan`, which Marlin's planner
    keeps instead, to compute them when read).
    """
    return TrapezoidPlan(_trapezoid_block, move_d, np.asarray(accel, float), entry_v2, nominal_v2, exit_v2).phases()


def _trapezoid_block(move_d, accel, entry_v2, nominal_v2, exit_v2, result: PlanResult, sl: slice) -> None:
    half_inv_accel = 0.5 / accel
    accel_d = (nominal_v2 - entry_v2) * half_inv_accel
    decel_d = (nominal_v2 - exit_v2) * half_inv_accel
    short = accel_d + decel_d > move_d
    # where they meet: entry_v2 + 2 a x = exit_v2 + 2 a (d - x)
    meet_d = np.clip((move_d + (exit_v2 - entry_v2) * half_inv_accel) * 0.5, 0.0, move_d)
    accel_d = np.where(short, meet_d, np.maximum(accel_d, 0.0))
    cruise_v2 = np.where(short, entry_v2 + 2.0 * accel * meet_d, nominal_v2)
    start_v2 = np.minimum(np.minimum(entry_v2, nominal_v2), cruise_v2)
    decel_d = np.where(short, move_d - meet_d, np.clip(decel_d, 0.0, move_d - accel_d))
    end_v2 = np.maximum(cruise_v2 - 2.0 * accel * decel_d, 0.0)
    cruise_d = np.maximum(move_d - accel_d - decel_d, 0.0)
    start_v, cruise_v, end_v = np.sqrt(start_v2), np.sqrt(cruise_v2), np.sqrt(end_v2)
    with np.errstate(divide="ignore", invalid="ignore"):
        result.accel_t[sl] = np.where(accel_d > 0, (cruise_v - start_v) / accel, 0.0)
        result.cruise_t[sl] = np.where(cruise_d > 0, cruise_d / cruise_v, 0.0)
        result.decel_t[sl] = np.where(decel_d > 0, (cruise_v - end_v) / accel, 0.0)
    result.start_v[sl], result.cruise_v[sl], result.end_v[sl] = start_v, cruise_v, end_v


def empty_result() -> PlanResult:
    empty = np.zeros(0)
    return PlanResult(empty, empty, empty, empty, empty, empty, empty)


def unit_vectors(columns) -> tuple[np.ndarray, list[np.ndarray]]:
    """Length and unit-vector columns of the vectors given as per-axis columns (zero vectors stay zero)."""
    length = np.sqrt(sum(c * c for c in columns))
    inverse = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0)
    return length, [c * inverse for c in columns]
