"""Longitudinal waves under a suddenly applied end load: the explicit central difference.

    u_tt = a^2 u_xx,  u(0, t) = 0,  EA u_x(l, t) = -P0 H(t),  u = u_t = 0 at t = 0

on nodes x_j = j dx, j = 0..N (dx = l/N), time levels t_n = n dt, dt = C dx / a. The paper's
Eq.38 with c = C^2:

    u_j^{n+1} = 2 u_j^n - u_j^{n-1} + C^2 (u_{j+1}^n - 2 u_j^n + u_{j-1}^n)

The loaded end uses a ghost node u_{N+1} = u_{N-1} - 2 dx P0/EA in the same update; the first
level is the Taylor step u^1 = u^0 + (C^2/2) D2 u^0 (docs/model.md sec. 4). At C = 1 the nodal values
are d'Alembert's exactly; C > 1 is unstable and is refused by the scene layer.

One span advances through all its time levels while its three levels of nodes sit in cache;
spans run in parallel. Units: x, u in m, t in s, forces in N (compression negative).
"""

import math

import numba as nb
import numpy as np

from .wave_layout import *  # noqa: F401,F403  (the kernel's layouts, re-exported)
from .wave_layout import (ARRIVAL_TIME, AXIAL_STIFFNESS, BOUND, COURANT, FAILURE_TIME,
                          INTERVALS, LENGTH, LEVEL_LIMIT, LOAD, MAX_LEVELS, N_PARAMS, N_REALS,
                          PEAK_END_DISPLACEMENT, PEAK_FIXED_END_FORCE, PERIOD, SAMPLE_DT,
                          T_END, TIME_STEP, WAVE_SPEED)
from .wave_layout import COMPLETED, DIVERGED, INVALID_INPUT, MAX_STEPS, STATES  # noqa: F401


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _valid(p, n_intervals, courant):
    for j in range(N_PARAMS):
        if not math.isfinite(p[j]):
            return False
    return (p[LENGTH] > 0.0 and p[WAVE_SPEED] > 0.0 and p[AXIAL_STIFFNESS] > 0.0
            and p[T_END] > 0.0 and p[BOUND] > 0.0 and n_intervals >= 2
            and 0.0 < courant <= 1.0)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _snapshot(u_prev, u_cur, u_next, dt, dx, ea, load, first, snap_u, snap_f, snap_v):
    """Store u, N = EA u_x and v = u_t at the current level (velocity centred in time)."""
    n = u_cur.shape[0] - 1
    for j in range(n + 1):
        snap_u[j] = u_cur[j]
        snap_v[j] = 0.0 if first else (u_next[j] - u_prev[j]) / (2.0 * dt)
    snap_f[0] = ea * (u_cur[1] - u_cur[0]) / dx
    for j in range(1, n):
        snap_f[j] = ea * (u_cur[j + 1] - u_cur[j - 1]) / (2.0 * dx)
    snap_f[n] = -load


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_span(p, settings, snapshot_times, reals, hist_u, hist_f, snap_u, snap_f, snap_v):
    """Advance one span through all its time levels; fill its metrics, histories, snapshots.

    Returns (state flag, number of time steps taken).
    """
    for j in range(N_REALS):
        reals[j] = math.nan
    hist_u[:] = math.nan
    hist_f[:] = math.nan
    snap_u[:] = math.nan
    snap_f[:] = math.nan
    snap_v[:] = math.nan
    n_int = int(settings[INTERVALS])
    courant = settings[COURANT]
    if not _valid(p, n_int, courant):
        return INVALID_INPUT, 0

    length, a, ea, load = p[LENGTH], p[WAVE_SPEED], p[AXIAL_STIFFNESS], p[LOAD]
    dx = length / n_int
    dt = courant * dx / a
    c2 = courant * courant
    ghost = 2.0 * dx * load / ea          # u_{N+1} = u_{N-1} - ghost
    # The number of levels to t_end as a float first: a count beyond int64 (t_end / dt of
    # 1e19 or more, or dt underflowed to 0) would wrap round in int() and run nothing.
    levels = np.ceil(p[T_END] / dt - 1e-9) if dt > 0.0 else math.inf
    if not math.isfinite(levels):
        return INVALID_INPUT, 0
    budget = min(settings[MAX_LEVELS], LEVEL_LIMIT)
    if levels > budget:                    # runs `budget` levels, then MAX_STEPS
        n_levels = int(budget)
        n_needed = n_levels + 1
    else:
        n_levels = int(levels)
        n_needed = n_levels
    reals[TIME_STEP] = dt

    n_snap = snapshot_times.shape[0]
    snap_level = np.empty(n_snap, np.int64)
    last_level = n_levels
    for s in range(n_snap):
        ratio = snapshot_times[s] / dt
        # A time past the levels this span takes is NaN (never reached); int() of a ratio
        # beyond int64 would wrap round.
        snap_level[s] = int(round(ratio)) if ratio <= n_levels else n_levels + 1
        if snap_level[s] <= n_levels:
            last_level = max(last_level, snap_level[s] + 1)   # centred velocity needs n + 1

    u_prev = np.zeros(n_int + 1)
    u_cur = np.zeros(n_int + 1)
    u_next = np.zeros(n_int + 1)
    for s in range(n_snap):
        if snap_level[s] == 0:
            _snapshot(u_cur, u_cur, u_cur, dt, dx, ea, load, True, snap_u[s], snap_f[s],
                      snap_v[s])

    abs_load = abs(load)
    peak_u = 0.0
    peak_f = 0.0
    arrival = math.nan
    first_rise = math.nan
    last_rise = math.nan
    rises = 0
    armed = True
    f_old = 0.0
    u_end_old = 0.0
    dt_sample = settings[SAMPLE_DT]
    n_hist = hist_u.shape[0]
    if n_hist > 0:
        hist_u[0] = 0.0
        hist_f[0] = 0.0
    k = 1
    state = COMPLETED
    level = 0
    while level < last_level:
        # Level n + 1 from levels n and n - 1 (the first step is the Taylor step).
        if level == 0:
            for j in range(1, n_int):
                u_next[j] = u_cur[j] + 0.5 * c2 * (u_cur[j + 1] - 2.0 * u_cur[j] + u_cur[j - 1])
            u_next[n_int] = u_cur[n_int] + c2 * (u_cur[n_int - 1] - u_cur[n_int] - 0.5 * ghost)
        else:
            for j in range(1, n_int):
                u_next[j] = (2.0 * u_cur[j] - u_prev[j]
                             + c2 * (u_cur[j + 1] - 2.0 * u_cur[j] + u_cur[j - 1]))
            u_next[n_int] = (2.0 * u_cur[n_int] - u_prev[n_int]
                             + c2 * (2.0 * u_cur[n_int - 1] - ghost - 2.0 * u_cur[n_int]))
        u_next[0] = 0.0

        for s in range(n_snap):
            if snap_level[s] == level and level > 0:
                _snapshot(u_prev, u_cur, u_next, dt, dx, ea, load, False, snap_u[s],
                          snap_f[s], snap_v[s])

        level += 1
        t_new = level * dt
        if level > n_levels:              # extra level only for a velocity snapshot
            u_prev, u_cur, u_next = u_cur, u_next, u_prev
            continue
        u_end = u_next[n_int]
        f_fixed = ea * u_next[1] / dx
        if not (abs(u_end) <= p[BOUND] and math.isfinite(f_fixed)):
            state = DIVERGED
            reals[FAILURE_TIME] = t_new
            break
        # The metrics end at t_end: a last level past it (t_end not a whole number of steps)
        # counts with its value interpolated back to t_end, as the histories take it.
        span = dt                         # from the level before to the one seen
        u_seen = u_end
        f_seen = f_fixed
        if level == n_levels and t_new > p[T_END]:
            span = p[T_END] - (t_new - dt)
            w_seen = span / dt
            u_seen = u_end_old + w_seen * (u_end - u_end_old)
            f_seen = f_old + w_seen * (f_fixed - f_old)
        peak_u = max(peak_u, abs(u_seen))
        peak_f = max(peak_f, abs(f_seen))
        if abs_load > 0.0:
            if armed and abs(f_seen) >= abs_load:
                t_cross = t_new - dt + span * (abs_load - abs(f_old)) / (abs(f_seen) - abs(f_old))
                if rises == 0:
                    arrival = t_cross
                    first_rise = t_cross
                last_rise = t_cross
                rises += 1
                armed = False
            elif not armed and abs(f_seen) < 0.5 * abs_load:
                armed = True
        # The last level stands for t_end, which level * dt may miss by rounding (n_needed
        # allows 1e-9 dt): samples up to t_end (+1e-9 of a sample, as the sweep counts them)
        # take its value rather than staying NaN.
        t_reach = t_new
        if level == n_needed:
            t_reach = max(t_new, p[T_END] + 1e-9 * dt_sample)
        while k < n_hist and k * dt_sample <= t_reach:
            w = min((k * dt_sample - (t_new - dt)) / dt, 1.0)
            hist_u[k] = u_end_old + w * (u_end - u_end_old)
            hist_f[k] = f_old + w * (f_fixed - f_old)
            k += 1
        f_old = f_fixed
        u_end_old = u_end
        u_prev, u_cur, u_next = u_cur, u_next, u_prev

    if state == COMPLETED and n_levels < n_needed:
        state = MAX_STEPS
        reals[FAILURE_TIME] = n_levels * dt
    reals[PEAK_END_DISPLACEMENT] = peak_u
    reals[PEAK_FIXED_END_FORCE] = peak_f
    reals[ARRIVAL_TIME] = arrival
    if rises >= 2:
        reals[PERIOD] = (last_rise - first_rise) / (rises - 1)
    if state == DIVERGED:
        for j in range(PEAK_END_DISPLACEMENT, PERIOD + 1):
            reals[j] = math.nan
    return state, min(level, n_levels)


@nb.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def solve_batch(params, settings, snapshot_times, states, reals, steps, hist_u, hist_f,
                snap_u, snap_f, snap_v):
    """Solve every span (row of `params`) in parallel, one span per iteration.

    Outputs (first axis n): states int8, reals (n, N_REALS), steps int64, histories
    (n, n_hist) of u(l, t) and N(0, t) at k * SAMPLE_DT, snapshots (n, n_snap, N + 1) of
    u, N and v at the time levels nearest `snapshot_times` (NaN past a span's end).
    """
    for i in nb.prange(params.shape[0]):
        state, n = solve_span(params[i], settings, snapshot_times, reals[i], hist_u[i],
                              hist_f[i], snap_u[i], snap_f[i], snap_v[i])
        states[i] = state
        steps[i] = n
