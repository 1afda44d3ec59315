"""Plan stage, compiled: the planners' hot loops written as loops, with Numba.

The NumPy code of :mod:`.scans`, :mod:`.marlin` and :mod:`.klipper` does
each step in passes over whole arrays; here the same arithmetic, in the same
order, runs as one loop over the moves, compiled when Numba is installed
(``pip install 'gcodekit[fast]'``).  It makes no temporaries, so it is
faster and leaner.  The NumPy code stays the reference: the tests plan the
same programs with both engines and require identical arrays, bit for bit.

``np.minimum(a, b)`` is ``a if a < b or a != a else b`` (NaN wins, ``b`` on
a tie, so -0.0 against 0.0 picks ``b``); the loops write it so.

:func:`engine` chooses: the compiled loops for programs of at least
:data:`COMPILED_AFTER_MOVES` moves when Numba is installed (smaller ones
would spend more loading Numba than they save), NumPy otherwise;
:func:`using` forces one.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
from types import SimpleNamespace
from typing import Iterator

import numpy as np

from ..errors import MissingDependencyError, check_choice
from ..jit import compile_loops
from ..columns import RunColumn
from ..parse.table import MOTION_RAPID, DecimalColumn

NO_WORD = int(DecimalColumn.NO_WORD)  # decimal units of no value, as the loops read them

__all__ = ["COMPILED_AFTER_MOVES", "ENGINES", "compiled", "engine", "using"]

#: Programs with at least this many moves are planned by the compiled loops when Numba is installed.
COMPILED_AFTER_MOVES = 300_000
ENGINES = ("auto", "numba", "numpy")
#: The engine :func:`using` chose: per thread and per asyncio task, so one caller's choice never reaches another
_chosen: contextvars.ContextVar[str] = contextvars.ContextVar("gcodekit_plan_engine", default="auto")


@functools.lru_cache(maxsize=1)
def compiled() -> SimpleNamespace | None:
    """The compiled loops, or None when Numba is not installed (compiled on first use, cached on disk)."""
    loops = (_forward_min, _backward_min, _classic_jerk, _klipper_moves, _klipper_cruise, _move_points,
             _marlin_trapezoids, _klipper_trapezoids, _marlin_blocks)
    # error_model="numpy": a division by zero gives inf or NaN, as in the NumPy code, instead of raising
    done = compile_loops(*loops, error_model="numpy")
    return None if done is None else SimpleNamespace(**{f.__name__[1:]: c for f, c in zip(loops, done)})


def engine(n_moves: int) -> SimpleNamespace | None:
    """The compiled loops to plan ``n_moves`` moves with, or None for the NumPy code."""
    chosen = _chosen.get()
    if chosen == "numpy" or (chosen == "auto" and n_moves < COMPILED_AFTER_MOVES):
        return None
    kernels = compiled()
    if kernels is None and chosen == "numba":
        raise MissingDependencyError("the compiled planner needs Numba: pip install 'gcodekit[fast]'")
    return kernels


@contextlib.contextmanager
def using(name: str) -> Iterator[None]:
    """Plan with engine ``name`` inside the block: ``"numba"``, ``"numpy"`` or ``"auto"`` (the default).

    The choice holds in this thread (or asyncio task) only: other threads
    planning meanwhile keep their own.

    Examples
    --------
    >>> import gcodekit
    >>> with using("numpy"):
    ...     op = gcodekit.gcode_to_operation("G1 X10 E1 F600\\n", "marlin")
    """
    check_choice("engine", name, ENGINES)
    token = _chosen.set(name)
    try:
        yield
    finally:
        _chosen.reset(token)


def _forward_min(cap, inc, first, block, out, move_d, accel, accel_runs, pseudo, pseudo_runs, free):
    """:func:`.scans.forward_min` (see it for the rule), block by block with its very roundings, into
    ``out`` (which may be ``cap``: ``cap[k]`` is last read before ``out[k]`` is written).

    The increments are ``inc``, or, ``inc`` empty, made where read as
    :class:`.scans.Increments` makes them: ``2 * move_d * accel`` (the
    least of that and ``2 * move_d * pseudo`` when ``pseudo`` is given;
    ``accel`` and ``pseudo`` may be runs: then ``*_runs`` hold where each
    starts), and where ``free`` the next move's cap (read before it is
    written over).
    """
    n = cap.size

    def value_at(values, runs, k, at):  # the value of waypoint k, and the run it is in (runs walked from `at`)
        if runs.size == 0:
            return values[k], at
        while at > 0 and runs[at] > k:
            at -= 1
        while at + 1 < runs.size and runs[at + 1] <= k:
            at += 1
        return values[at], at

    def increment(k, a_at, p_at):
        if inc.size:
            return inc[k], a_at, p_at
        if free.size and free[k] and k + 1 < n:
            return cap[k + 1], a_at, p_at
        a, a_at = value_at(accel, accel_runs, k, a_at)
        d = (2.0 * move_d[k]) * a
        if pseudo.size:
            pa, p_at = value_at(pseudo, pseudo_runs, k, p_at)
            m = (2.0 * move_d[k]) * pa
            if m < d or m != m:
                d = m
        return d, a_at, p_at

    a_at = p_at = 0
    carry = first
    for start in range(0, n, block):
        stop = min(start + block, n)
        s = 0.0  # increments from the block's first move up to move k (exclusive): np.cumsum's sums
        acc = 0.0  # running minimum of cap - s
        last = -1  # the last move whose cap binds
        base = 0.0  # its cap - s
        s_prev = 0.0
        for k in range(start, stop):
            if k == start:
                bound = cap[k] - s
                if not (bound < carry or bound != bound):
                    bound = carry
                acc = bound
                reach = carry
            else:
                d, a_at, p_at = increment(k - 1, a_at, p_at)
                s = d if k == start + 1 else s + d
                reach = (acc + s_prev) + d
                bound = cap[k] - s
                if not (acc < bound or acc != acc):
                    acc = bound
            s_prev = s
            if cap[k] <= reach:
                last = k
                base = cap[k] - s
                out[k] = cap[k]
            elif last >= 0:
                out[k] = base + s
            else:
                out[k] = carry + s
        d, a_at, p_at = increment(stop - 1, a_at, p_at)
        carry = out[stop - 1] + d
    return out


def _backward_min(cap, inc, last, block, out, move_d, accel, accel_runs, pseudo, pseudo_runs, free):
    """:func:`.scans.backward_min` (see it for the rule), block by block with its very roundings, into
    ``out`` (which may be ``cap``, as in :func:`_forward_min`); the increments as there, but where ``free``
    the move's own cap."""

    def value_at(values, runs, k, at):
        if runs.size == 0:
            return values[k], at
        while at > 0 and runs[at] > k:
            at -= 1
        while at + 1 < runs.size and runs[at + 1] <= k:
            at += 1
        return values[at], at

    def increment(k, a_at, p_at):
        if inc.size:
            return inc[k], a_at, p_at
        if free.size and free[k]:
            return cap[k], a_at, p_at
        a, a_at = value_at(accel, accel_runs, k, a_at)
        d = (2.0 * move_d[k]) * a
        if pseudo.size:
            pa, p_at = value_at(pseudo, pseudo_runs, k, p_at)
            m = (2.0 * move_d[k]) * pa
            if m < d or m != m:
                d = m
        return d, a_at, p_at

    n = cap.size
    a_at = max(accel_runs.size - 1, 0)
    p_at = max(pseudo_runs.size - 1, 0)
    carry = last
    for stop in range(n, 0, -block):
        start = max(stop - block, 0)
        s = 0.0  # increments from the block's end back to move k (inclusive): np.cumsum's sums
        acc = 0.0
        binding = False  # a cap has bound since the block's end
        base = 0.0
        seed = 0.0
        for k in range(stop - 1, start - 1, -1):
            d, a_at, p_at = increment(k, a_at, p_at)
            if k == stop - 1:
                s = d
                bound = cap[k] - s
                if carry < bound:  # Python's min(bound, carry)
                    bound = carry
                acc = bound
                reach = carry + d
                seed = (carry + d) - s
            else:
                reach = (acc + s) + d
                s = s + d
                bound = cap[k] - s
                if not (acc < bound or acc != acc):
                    acc = bound
            if cap[k] <= reach:
                binding = True
                base = cap[k] - s
                out[k] = cap[k]
            elif binding:
                out[k] = base + s
            else:
                out[k] = seed + s
        carry = out[start]
    return out


def _classic_jerk(dx, dy, dz, de, speed_per_mm, nominal_speed, jx, jy, jz, je, rest_before):
    """:func:`.marlin._classic_jerk` move by move (the previous move of the first is itself).

    ``jx``.. ``je`` hold one jerk limit per move, or one for all.
    """
    n = nominal_speed.size
    safe_speed = np.empty(n)
    vmax = np.empty(n)
    for i in range(n):
        p = i - 1 if i > 0 else 0
        previous_nominal_speed = nominal_speed[p]
        v = nominal_speed[i]
        vmax_junction = v if (v < previous_nominal_speed or v != v) else previous_nominal_speed
        exit_scale = speed_per_mm[p] * (vmax_junction / previous_nominal_speed)
        safe_factor = 1.0
        v_factor = 1.0
        for axis in range(4):
            if axis == 0:
                d, limits = dx, jx
            elif axis == 1:
                d, limits = dy, jy
            elif axis == 2:
                d, limits = dz, jz
            else:
                d, limits = de, je
            maxj = limits[i] if limits.size > 1 else limits[0]
            v_entry = d[i] * speed_per_mm[i]
            v_exit = d[p] * exit_scale
            cs = abs(v_entry)
            ratio = maxj / cs if cs > maxj else 1.0
            if not (safe_factor < ratio or safe_factor != safe_factor):
                safe_factor = ratio
            if v_exit > v_entry:
                if v_entry > 0 or v_exit < 0:
                    jerk = v_exit - v_entry
                else:
                    a, b = v_exit, -v_entry
                    jerk = a if (a > b or a != a) else b
            else:
                if v_entry < 0 or v_exit > 0:
                    jerk = v_entry - v_exit
                else:
                    a, b = -v_exit, v_entry
                    jerk = a if (a > b or a != a) else b
            ratio = maxj / jerk if jerk > maxj else 1.0
            if not (v_factor < ratio or v_factor != v_factor):
                v_factor = ratio
        safe_speed[i] = v * safe_factor
        vmax[i] = vmax_junction * v_factor
    for i in range(n):
        p = i - 1 if i > 0 else 0
        threshold = vmax[i] * 0.99
        if rest_before[i] or (safe_speed[p] > threshold and safe_speed[i] > threshold):
            vmax[i] = safe_speed[i]
    return vmax


def _klipper_moves(start, end, gathered, wx, wy, wz, wz_runs, we, scales, summing, idx, chained, speed_v, row, by_waypoint,
                   feed, feed_runs, command, motion, rapid_v, factor, flush, limit_rows,
                   max_velocity, max_accel, square_corner_velocity, minimum_cruise_ratio, initial, z_velocity, z_accel,
                   e_velocity, e_accel, corner_velocity, extrude_only_accel, no_limit_v2):
    """:func:`.klipper._move_block` over all moves: Move.__init__, limit_speed and calc_junction.

    The moves' points are ``start`` and ``end``, or, when ``gathered``, the
    waypoint columns ``wx, wy, wz, we`` at the moves' waypoints ``idx`` (as
    :class:`.points.MoveEnds` takes them, ``chained`` or not); with
    ``summing``, ``we`` holds each waypoint's extrusion and the extruder
    position is its running sum, added up here in ``np.cumsum``'s order as
    the waypoints come (they only grow).  ``wx``, ``wy`` and ``we`` may be
    decimal units (:class:`gcodekit.parse.table.DecimalColumn`): then their
    ``scales`` (``10**places``, three) are not 0, and each unit is read as
    the column reads it, ``units / scale`` (NaN for ``NO_WORD``).  ``wz`` and
    ``feed`` may be stored as runs (:class:`gcodekit.columns.RunColumn`): then ``wz_runs`` and
    ``feed_runs`` hold where each run starts and the columns their values
    (empty, the columns are read as they are).  The limits
    in force come from ``limit_rows`` (sorted) and their columns,
    ``initial`` (max_velocity, max_accel, square_corner_velocity,
    minimum_cruise_ratio) before the first, as :func:`.moves.in_force`.
    Each move's requested speed and command row are ``speed_v`` and ``row``,
    or, ``by_waypoint`` (gathered moves), read at its waypoint as
    :class:`.moves.MoveSource` reads them: ``feed`` over 60 (``rapid_v`` for
    a G0 unless NaN), times ``factor`` (unless empty), and ``command``.
    Returns move_d, accel, max_cruise_v2, cap and junction (the increments
    ``delta_v2`` and ``mcr_delta_v2`` follow from move_d, accel and the
    limits in force: :class:`.scans.Increments` makes them).
    """
    n = idx.size if by_waypoint else speed_v.size
    move_d_out = np.empty(n)
    accel_out = np.empty(n)
    max_cruise_v2_out = np.empty(n)
    cap_out = np.empty(n)
    junction = np.empty(n, np.bool_)
    inf = np.inf
    sqrt2_minus_1 = np.sqrt(2.0) - 1.0
    j = 0  # limit rows before the move's row
    e_at = -1  # with summing: the waypoint the running sum e_sum has reached
    e_sum = 0.0
    x_scale, y_scale, e_scale = scales[0], scales[1], scales[2]

    def read(column, scale, k):  # the value at waypoint k, from decimal units when scale is not 0
        if scale == 0.0:
            return column[k]
        units = column[k]
        return np.nan if units == NO_WORD else units / scale

    z_at = feed_at = 0  # with runs: the run of wz and of feed the last move read
    p_kinematic = False
    p_e_r = p_r0 = p_r1 = p_r2 = p_jd = p_delta_v2 = 0.0
    for i in range(n):
        if by_waypoint:
            w = idx[i]
            r = command[w]
            if feed_runs.size:  # the run holding w: the cursor moves on (back, a search afresh)
                if w < feed_runs[feed_at]:
                    feed_at = np.searchsorted(feed_runs, w, side="right") - 1
                while feed_at + 1 < feed_runs.size and feed_runs[feed_at + 1] <= w:
                    feed_at += 1
                speed = feed[feed_at] / 60.0
            else:
                speed = feed[w] / 60.0
            if rapid_v == rapid_v and motion[w] == MOTION_RAPID:
                speed = rapid_v
            if factor.size:
                speed = speed * factor[w]
        else:
            r = row[i]
            speed = speed_v[i]
        if j > 0 and limit_rows[j - 1] >= r:  # out of order (a loop ran rows again): search afresh
            j = np.searchsorted(limit_rows, r)
        while j < limit_rows.size and limit_rows[j] < r:
            j += 1
        if j > 0:
            max_v, max_a = max_velocity[j - 1], max_accel[j - 1]
            scv, mcr = square_corner_velocity[j - 1], minimum_cruise_ratio[j - 1]
        else:
            max_v, max_a, scv, mcr = initial[0], initial[1], initial[2], initial[3]
        jd = scv * scv * sqrt2_minus_1 / max_a
        if gathered:
            w = idx[i]
            v = idx[i - 1] if chained and i > 0 else w - 1  # the waypoint the move starts from
            if summing:
                while e_at < v:
                    e_at += 1
                    e_sum = read(we, e_scale, 0) if e_at == 0 else e_sum + read(we, e_scale, e_at)
                e_v = e_sum
                while e_at < w:
                    e_at += 1
                    e_sum = read(we, e_scale, 0) if e_at == 0 else e_sum + read(we, e_scale, e_at)
                e_w = e_sum
            else:
                e_v = read(we, e_scale, v) if v >= 0 else 0.0
                e_w = read(we, e_scale, w)
            if wz_runs.size:  # the runs holding v, then w (v < w)
                z_v = 0.0
                if v >= 0:
                    if v < wz_runs[z_at]:
                        z_at = np.searchsorted(wz_runs, v, side="right") - 1
                    while z_at + 1 < wz_runs.size and wz_runs[z_at + 1] <= v:
                        z_at += 1
                    z_v = wz[z_at]
                if w < wz_runs[z_at]:
                    z_at = np.searchsorted(wz_runs, w, side="right") - 1
                while z_at + 1 < wz_runs.size and wz_runs[z_at + 1] <= w:
                    z_at += 1
                z_w = wz[z_at]
            else:
                z_w, z_v = wz[w], wz[v] if v >= 0 else 0.0
            if v < 0:
                dx, dy, dz, de = read(wx, x_scale, w) - 0.0, read(wy, y_scale, w) - 0.0, z_w - 0.0, e_w - 0.0
            else:
                dx = read(wx, x_scale, w) - read(wx, x_scale, v)
                dy = read(wy, y_scale, w) - read(wy, y_scale, v)
                dz, de = z_w - z_v, e_w - e_v
        else:
            dx = end[i, 0] - start[i, 0]
            dy = end[i, 1] - start[i, 1]
            dz = end[i, 2] - start[i, 2]
            de = end[i, 3] - start[i, 3]
        move_d = np.sqrt((dx * dx + dy * dy) + dz * dz)
        kinematic = move_d >= 1e-9
        if not kinematic:
            dx = dy = dz = 0.0
            move_d = abs(de)
        inv_move_d = 1.0 / move_d if move_d > 0 else 0.0
        r0, r1, r2, e_r = dx * inv_move_d, dy * inv_move_d, dz * inv_move_d, de * inv_move_d
        if kinematic:
            velocity = speed if (speed < max_v or speed != speed) else max_v
            accel = max_a
        else:
            velocity = speed
            accel = extrude_only_accel
        max_cruise_v2 = velocity * velocity
        abs_dz = abs(dz)
        z_move = kinematic and abs_dz > 0
        z_ratio = move_d / abs_dz if z_move else inf
        e_limited = de != 0 and ((dx == 0 and dy == 0) or e_r < 0)
        inv_extrude_r = 1.0 / abs(e_r) if e_limited else inf
        a = z_velocity * z_ratio if z_move else inf
        b = e_velocity * inv_extrude_r if e_limited else inf
        speed_cap = a if (a < b or a != a) else b
        b = speed_cap * speed_cap
        if not (max_cruise_v2 < b or max_cruise_v2 != max_cruise_v2):
            max_cruise_v2 = b
        b = z_accel * z_ratio if z_move else inf
        if not (accel < b or accel != accel):
            accel = b
        b = e_accel * inv_extrude_r if e_limited else inf
        if not (accel < b or accel != accel):
            accel = b
        delta_v2 = 2.0 * move_d * accel
        joins = False
        cap = 0.0
        if i > 0:
            diff_r = e_r - p_e_r
            if diff_r != 0:
                ea_v2 = corner_velocity / abs(diff_r)
                ea_v2 = ea_v2 * ea_v2
            else:
                ea_v2 = max_cruise_v2
            p_max_cruise_v2 = max_cruise_v2_out[i - 1]
            cap = max_cruise_v2 if (max_cruise_v2 < p_max_cruise_v2 or max_cruise_v2 != max_cruise_v2) \
                else p_max_cruise_v2
            if not (cap < ea_v2 or cap != cap):
                cap = ea_v2
            if not (cap < no_limit_v2 or cap != cap):
                cap = no_limit_v2
            junction_cos_theta = -((r0 * p_r0 + r1 * p_r1) + r2 * p_r2)
            x = 0.5 * (1.0 - junction_cos_theta)
            sin_theta_d2 = np.sqrt(x if (x > 0.0 or x != x) else 0.0)
            x = 0.5 * (1.0 + junction_cos_theta)
            cos_theta_d2 = np.sqrt(x if (x > 0.0 or x != x) else 0.0)
            one_minus_sin_theta_d2 = 1.0 - sin_theta_d2
            if one_minus_sin_theta_d2 > 0 and cos_theta_d2 > 0:
                R_jd = sin_theta_d2 / one_minus_sin_theta_d2
                quarter_tan_theta_d2 = 0.25 * sin_theta_d2 / cos_theta_d2
                corner = R_jd * jd * accel
                b = R_jd * p_jd * accel_out[i - 1]
                if not (corner < b or corner != corner):
                    corner = b
                b = delta_v2 * quarter_tan_theta_d2
                if not (corner < b or corner != corner):
                    corner = b
                b = p_delta_v2 * quarter_tan_theta_d2
                if not (corner < b or corner != corner):
                    corner = b
                if not (cap < corner or cap != cap):
                    cap = corner
            joins = kinematic and p_kinematic and not flush[i]
        junction[i] = joins
        cap_out[i] = cap if joins else 0.0
        move_d_out[i] = move_d
        accel_out[i] = accel
        max_cruise_v2_out[i] = max_cruise_v2
        p_kinematic, p_e_r, p_r0, p_r1, p_r2, p_jd, p_delta_v2 = kinematic, e_r, r0, r1, r2, jd, delta_v2
    return move_d_out, accel_out, max_cruise_v2_out, cap_out, junction


def _klipper_cruise(start_v2, mcr_start_v2, delta_v2, mcr_delta_v2, max_cruise_v2, flush, tie_r, cruise_v2,
                    move_d, move_accel, accel_runs, pseudo, pseudo_runs):
    """:func:`.klipper._cruise`: each move's cruise speed squared, into ``cruise_v2`` (which may be
    ``max_cruise_v2``: each cap is read before its move's speed is written).

    The increments are ``delta_v2`` and ``mcr_delta_v2``, or, those empty,
    made where read from ``move_d``, ``move_accel`` and ``pseudo`` (the minimum
    cruise ratio's pseudo acceleration) as :class:`.scans.Increments` makes
    them (``*_runs``: where each run starts, for columns kept as runs).

    A backward pass finds, for each move, the nearest move at or after it in
    the same flush that sets a peak (``next_marked``); a forward pass keeps
    the running minimum of a move that cannot accelerate (``segmented_cummin``,
    whose minimum is the earliest of equal values, as here).
    """
    n = start_v2.size

    def value_at(values, runs, k, at):  # the value of move k, and the run it is in (runs walked from `at`)
        if runs.size == 0:
            return values[k], at
        while at > 0 and runs[at] > k:
            at -= 1
        while at + 1 < runs.size and runs[at + 1] <= k:
            at += 1
        return values[at], at

    a_at = max(accel_runs.size - 1, 0)
    p_at = max(pseudo_runs.size - 1, 0)
    can_accel = np.empty(n, np.bool_)
    has_next = False  # a peak-setting move at or after i in i's flush
    peak = 0.0
    for i in range(n - 1, -1, -1):
        if delta_v2.size:
            delta, mcr_delta = delta_v2[i], mcr_delta_v2[i]
        else:
            a, a_at = value_at(move_accel, accel_runs, i, a_at)
            pa, p_at = value_at(pseudo, pseudo_runs, i, p_at)
            delta = (2.0 * move_d[i]) * a
            mcr_delta = (2.0 * move_d[i]) * pa
            if not (mcr_delta < delta or mcr_delta != mcr_delta):
                mcr_delta = delta
        last_of_segment = i == n - 1 or flush[i + 1]
        if last_of_segment:
            next_start = next_mcr = 0.0
            has_next = False  # the next flush's peaks are not this one's
        else:
            next_start, next_mcr = start_v2[i + 1], mcr_start_v2[i + 1]
        reach = next_mcr + mcr_delta
        tie = tie_r * (reach if (reach > 1.0 or reach != reach) else 1.0)
        accel = mcr_start_v2[i] < reach - tie
        can_accel[i] = accel
        pending = not last_of_segment and not can_accel[i + 1]
        if accel and (mcr_start_v2[i] + mcr_delta > next_mcr + tie or pending):
            has_next = True
            peak = (mcr_start_v2[i] + reach) * 0.5
        c = ((next_start + delta) + start_v2[i]) * 0.5
        b = max_cruise_v2[i]
        if not (c < b or c != c):
            c = b
        b = peak if has_next else 0.0
        if not (c < b or c != c):
            c = b
        cruise_v2[i] = c
    acc = 0.0
    for i in range(n):
        if can_accel[i]:
            seed = cruise_v2[i]
        elif flush[i]:
            seed = 0.0
        else:
            seed = start_v2[i]
        if can_accel[i] or flush[i] or i == 0:
            acc = seed
        elif seed < acc or seed != seed:  # np.minimum(seed, acc): the earlier on a tie
            acc = seed
        cruise_v2[i] = acc
    return cruise_v2


def _move_points(x, y, z, z_runs, de, scales, motion, homing, distance, with_points):
    """:func:`.moves.firmware_moves`' choice of moves and :class:`.points.MoveEnds`' points, in two passes.

    A waypoint is a move when it moves (``motion > 0``), is no homing move,
    and changes X, Y, Z or the extruder position (the running sum of ``de``,
    as ``np.cumsum``) or is a full circle.  Returns the moves' waypoints,
    their start and end points (rows of one array of points when each move
    starts where the one before ended, ``chained``, else two arrays; none
    without ``with_points``) and ``chained``.  ``x``, ``y`` and ``de`` may
    be decimal units and ``z`` runs, read as :func:`_klipper_moves` reads
    them (``scales`` of x, y and de; ``z_runs``).
    """
    n = motion.size

    def read(column, scale, k):  # the value at waypoint k, from decimal units when scale is not 0
        if scale == 0.0:
            return column[k]
        units = column[k]
        return np.nan if units == NO_WORD else units / scale

    def z_at(k, at):  # z at waypoint k, and its run (the waypoints come in order)
        if z_runs.size == 0:
            return z[k], at
        while at + 1 < z_runs.size and z_runs[at + 1] <= k:
            at += 1
        return z[at], at

    x_scale, y_scale, e_scale = scales[0], scales[1], scales[2]
    is_move = np.zeros(n, np.bool_)
    count = 0
    chained = True
    e = 0.0
    px = py = pz = pe = 0.0  # the waypoint before
    lx = ly = lz = le = 0.0  # the last move's end
    at = 0
    for i in range(n):
        e = read(de, e_scale, i) if i == 0 else e + read(de, e_scale, i)
        xi, yi = read(x, x_scale, i), read(y, y_scale, i)
        zi, at = z_at(i, at)
        if i == 0:
            changed = xi != 0 or yi != 0 or zi != 0 or e != 0
        else:
            changed = xi != px or yi != py or zi != pz or e != pe
        if motion[i] > 0 and not homing[i] and (changed or (motion[i] >= 3 and distance[i] > 0)):
            if count > 0 and not (px == lx and py == ly and pz == lz and pe == le):
                chained = False  # this move does not start where the last one ended
            is_move[i] = True
            count += 1
            lx, ly, lz, le = xi, yi, zi, e
        px, py, pz, pe = xi, yi, zi, e
    idx = np.empty(count, np.int64)
    m = count if with_points else 0
    start = np.empty((m + 1 if chained else m, 4))
    end = start[1:] if chained else np.empty((m, 4))
    k = 0
    e = 0.0
    px = py = pz = pe = 0.0
    at = 0
    for i in range(n):
        e = read(de, e_scale, i) if i == 0 else e + read(de, e_scale, i)
        if with_points:
            xi, yi = read(x, x_scale, i), read(y, y_scale, i)
            zi, at = z_at(i, at)
        else:  # the moves' waypoints alone
            xi = yi = zi = 0.0
        if is_move[i]:
            idx[k] = i
            if with_points:
                if k == 0 or not chained:
                    if i == 0:
                        start[k, 0] = start[k, 1] = start[k, 2] = start[k, 3] = 0.0
                    else:
                        start[k, 0], start[k, 1], start[k, 2], start[k, 3] = px, py, pz, pe
                end[k, 0], end[k, 1], end[k, 2], end[k, 3] = xi, yi, zi, e
            k += 1
        px, py, pz, pe = xi, yi, zi, e
    return idx, (start[:m] if chained else start), end, chained


def units_of(column) -> tuple[np.ndarray, float]:
    """A column as the compiled loops read it: decimal units and their scale (``10**places``), or its values
    and 0."""
    if isinstance(column, DecimalColumn):
        return column.units, 10.0 ** column.places
    return np.asarray(column, float), 0.0


def runs_of(column) -> tuple[np.ndarray, np.ndarray]:
    """A column as the compiled loops read it: its values, and where its runs start (none for an array; one
    run for a zero-stride view)."""
    if isinstance(column, RunColumn):
        return np.asarray(column.values, float), column.starts.astype(np.int64)
    if np.asarray(column).strides == (0,) and len(column):
        return np.asarray(column[:1], float).copy(), np.zeros(1, np.int64)
    return np.ascontiguousarray(column, float), NO_RUNS


NO_RUNS = np.zeros(0, np.int64)  # a column read as it is


def _marlin_trapezoids(move_d, accel, entry_v2, nominal_v2, exit_v2, start_v, cruise_v, end_v, accel_t, cruise_t,
                       decel_t, duration_t):
    """:func:`.lookahead._trapezoid_block` move by move.

    The outputs are the speeds (all three or none, by ``start_v``'s size),
    the phase times (likewise) and their sums; an output of size 0 is not
    computed.
    """
    for i in range(move_d.size):
        d, a, entry, nominal, exit_ = move_d[i], accel[i], entry_v2[i], nominal_v2[i], exit_v2[i]
        half_inv_accel = 0.5 / a
        accel_d = (nominal - entry) * half_inv_accel
        decel_d = (nominal - exit_) * half_inv_accel
        short = accel_d + decel_d > d
        meet_d = (d + (exit_ - entry) * half_inv_accel) * 0.5
        if meet_d == meet_d:  # np.clip(meet_d, 0.0, d): NumPy's maximum, then minimum, NaN kept
            meet_d = meet_d if meet_d > 0.0 else 0.0
            meet_d = meet_d if (meet_d < d or meet_d != meet_d) else d
        if short:
            accel_d = meet_d
            cruise_v2 = entry + 2.0 * a * meet_d
        else:
            accel_d = accel_d if (accel_d > 0.0 or accel_d != accel_d) else 0.0
            cruise_v2 = nominal
        start_v2 = entry if (entry < nominal or entry != entry) else nominal
        if not (start_v2 < cruise_v2 or start_v2 != start_v2):
            start_v2 = cruise_v2
        if short:
            decel_d = d - meet_d
        elif decel_d == decel_d:  # np.clip(decel_d, 0.0, d - accel_d)
            decel_d = decel_d if decel_d > 0.0 else 0.0
            hi = d - accel_d
            decel_d = decel_d if (decel_d < hi or decel_d != decel_d) else hi
        end_v2 = cruise_v2 - 2.0 * a * decel_d
        end_v2 = end_v2 if (end_v2 > 0.0 or end_v2 != end_v2) else 0.0
        cruise_d = d - accel_d - decel_d
        cruise_d = cruise_d if (cruise_d > 0.0 or cruise_d != cruise_d) else 0.0
        sv, cv, ev = np.sqrt(start_v2), np.sqrt(cruise_v2), np.sqrt(end_v2)
        at = (cv - sv) / a if accel_d > 0 else 0.0
        ct = cruise_d / cv if cruise_d > 0 else 0.0
        dt = (cv - ev) / a if decel_d > 0 else 0.0
        if start_v.size:
            start_v[i], cruise_v[i], end_v[i] = sv, cv, ev
        if accel_t.size:
            accel_t[i], cruise_t[i], decel_t[i] = at, ct, dt
        if duration_t.size:
            duration_t[i] = at + ct + dt


def _klipper_trapezoids(move_d, accel, start_v2, cruise_v2, next_start_v2, start_v, cruise_v, end_v, accel_t,
                        cruise_t, decel_t, duration_t):
    """:func:`.klipper._set_junction_block` move by move, into the outputs as :func:`_marlin_trapezoids`."""
    for i in range(move_d.size):
        a, c2 = accel[i], cruise_v2[i]
        s2 = start_v2[i] if (start_v2[i] < c2 or start_v2[i] != start_v2[i]) else c2
        e2 = next_start_v2[i] if (next_start_v2[i] < c2 or next_start_v2[i] != next_start_v2[i]) else c2
        half_inv_accel = 0.5 / a
        accel_d = (c2 - s2) * half_inv_accel
        decel_d = (c2 - e2) * half_inv_accel
        cruise_d = move_d[i] - accel_d - decel_d
        sv, cv, ev = np.sqrt(s2), np.sqrt(c2), np.sqrt(e2)
        at = accel_d / ((sv + cv) * 0.5) if accel_d > 0 else 0.0
        ct = cruise_d / cv if cruise_d != 0 else 0.0
        dt = decel_d / ((ev + cv) * 0.5) if decel_d > 0 else 0.0
        if start_v.size:
            start_v[i], cruise_v[i], end_v[i] = sv, cv, ev
        if accel_t.size:
            accel_t[i], cruise_t[i], decel_t[i] = at, ct, dt
        if duration_t.size:
            duration_t[i] = at + ct + dt



def _marlin_blocks(dx, dy, dz, de, speed_v, fx, fy, fz, fe, ax, ay, az, ae, min_feedrate, min_travel_feedrate,
                   acceleration, travel_acceleration, retract_acceleration, minimum_planner_speed):
    """:func:`.marlin._populate_blocks`' length, nominal speed, speed per mm and acceleration, move by move.

    Each limit holds one value per move, or one for all (size 1).
    Returns millimeters, nominal_speed, speed_per_mm and acceleration.
    """
    n = dx.size
    millimeters = np.empty(n)
    nominal_speed = np.empty(n)
    speed_per_mm = np.empty(n)
    accel_out = np.empty(n)
    big = np.finfo(np.float64).max
    for i in range(n):
        d0, d1, d2, d3 = dx[i], dy[i], dz[i], de[i]
        xyz_moves = d0 != 0 or d1 != 0 or d2 != 0
        esteps = d3 != 0
        mm = np.sqrt((d0 * d0 + d1 * d1) + d2 * d2) if xyz_moves else abs(d3)
        v = speed_v[i]
        if v != v:  # np.nan_to_num
            v = 0.0
        elif v == np.inf:
            v = big
        elif v == -np.inf:
            v = -big
        b = (min_feedrate[i if min_feedrate.size > 1 else 0] if esteps
             else min_travel_feedrate[i if min_travel_feedrate.size > 1 else 0])
        fr = v if (v > b or v != v) else b
        fr = fr if (fr > minimum_planner_speed or fr != fr) else minimum_planner_speed
        inverse_millimeters = 1.0 / mm
        feed_limit = np.inf  # limit_by_axis_maximum of the feed rates
        accel_limit = np.inf  # and of the accelerations
        for axis in range(4):
            if axis == 0:
                u, f, a = abs(d0), fx, ax
            elif axis == 1:
                u, f, a = abs(d1), fy, ay
            elif axis == 2:
                u, f, a = abs(d2), fz, az
            else:
                u, f, a = abs(d3), fe, ae
            ratio = f[i if f.size > 1 else 0] / u if u > 0 else np.inf
            if not (feed_limit < ratio or feed_limit != feed_limit):
                feed_limit = ratio
            ratio = a[i if a.size > 1 else 0] / u if u > 0 else np.inf
            if not (accel_limit < ratio or accel_limit != accel_limit):
                accel_limit = ratio
        factor = feed_limit * mm / fr
        factor = factor if (factor < 1.0 or factor != factor) else 1.0
        nominal = fr * factor
        accel = (acceleration[i if acceleration.size > 1 else 0] if esteps
                 else travel_acceleration[i if travel_acceleration.size > 1 else 0])
        b = accel_limit * mm
        accel = accel if (accel < b or accel != accel) else b
        millimeters[i] = mm
        nominal_speed[i] = nominal
        speed_per_mm[i] = nominal * inverse_millimeters
        accel_out[i] = accel if xyz_moves else retract_acceleration[i if retract_acceleration.size > 1 else 0]
    return millimeters, nominal_speed, speed_per_mm, accel_out
