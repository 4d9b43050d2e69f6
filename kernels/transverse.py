"""Batched transverse driver: one adaptive RK45 trajectory per parallel iteration.

`solve_batch(params, settings, states, reals, counts, series)` is the whole interface the
sweep layer uses: rows of `params` (columns in `oscillator`) in, per-point metrics out. A
lock-step SIMD driver can replace the loop below behind the same signature.

Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import metrics as mt
from .dopri5 import (MIN_RTOL, dense_coefficients, dense_root, dense_value, error_norm,
                     initial_step, rk_step, step_factor)
from .oscillator import BOUND, MASS, N_PARAMS, Q0, V0, acceleration

# Entries of the `settings` vector.
RTOL = 0            # relative tolerance
ATOL = 1            # absolute tolerance (m and m/s)
T_END = 2           # end time (s)
MAX_STEPS = 3       # bound on accepted steps
MAX_STEP = 4        # largest step (s); inf for none
FIRST_STEP = 5      # first step (s); 0 for SciPy's automatic choice
TAIL = 6            # tail window as a fraction of t_end, in (0, 1]
TOL = 7             # settling band / decay threshold, relative
SAMPLE_DT = 8       # time-series sample interval (s); used only when series has columns
WANT_SETTLING = 9   # 1.0: compute settling times; 0.0: skip that work
MIN_STEP = 10       # smallest step (s) before STEP_TOO_SMALL; SciPy's 10 ulps of t if larger
N_SETTINGS = 11

# Columns of the `reals` output.
AMPLITUDE = 0       # max |q| over the tail window (m)
PEAK = 1            # max |q| over the whole run (m)
SETTLING = 2        # settling time (s) or NaN
PERIOD = 3          # mean time between maxima of q in the tail (s) or NaN
FAILURE_TIME = 4    # time at which a diverged or failed point stopped (s) or NaN
N_REALS = 5

# Columns of the `counts` output.
STEPS = 0           # accepted steps
REJECTED = 1        # rejected step attempts
RHS_EVALS = 2       # right-hand-side evaluations
N_COUNTS = 3


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _last_time_above(t, h, Q, q_old, q_new, has_ext, xe, qe, centre, thr, last):
    """Update the last time |q - centre| > thr with the step [t, t + h] (see `integrate`)."""
    if abs(q_new - centre) > thr:
        return t + h
    xa = -1.0
    xb = 1.0
    q_a = 0.0
    if has_ext and abs(qe - centre) > thr:
        xa = xe
        q_a = qe
    elif abs(q_old - centre) > thr:
        xa = 0.0
        q_a = q_old
        if has_ext:
            xb = xe
    if xa < 0.0:
        return last
    side = 1.0 if q_a > centre else -1.0
    x = dense_root(q_old, h, Q, 0, centre + side * thr, xa, xb)
    return t + x * h


@nb.njit(cache=True, nogil=True, error_model="numpy")
def integrate(p, settings, track, centre, thr_fixed, thr_rel, series):
    """Integrate one point from t = 0 to t_end, reducing metrics on the fly.

    p: parameter row; settings: the settings vector; series: q samples to fill (may be empty).
    When `track`, also returns the last time |q - centre| exceeded thr_fixed + thr_rel * peak
    (with the running peak |q|), located on the dense output.

    Returns (status, t_stop, steps, rejected, rhs_evals, peak, tail_amp, tail_qmin, tail_qmax,
    last_above, q at t_stop, extrema buffer, number of extrema). status is metrics.RUNNING when
    the run reached t_end.
    """
    rtol = max(settings[RTOL], MIN_RTOL)
    atol = settings[ATOL]
    t_end = settings[T_END]
    max_steps = settings[MAX_STEPS]
    max_step = settings[MAX_STEP]
    t_tail = t_end * (1.0 - settings[TAIL])
    dt_sample = settings[SAMPLE_DT]
    n_samples = series.shape[0]
    bound = p[BOUND]

    K = np.empty((7, 2))
    Q = np.empty((2, 4))
    y = np.empty(2)
    y_new = np.empty(2)
    buf = np.empty((64, 3))
    n_ext = 0

    t = 0.0
    y[0] = p[Q0]
    y[1] = p[V0]
    K[0, 0] = y[1]
    K[0, 1] = acceleration(0.0, y[0], y[1], p)
    rhs_evals = 1
    if settings[FIRST_STEP] > 0.0:
        h_abs = min(settings[FIRST_STEP], t_end)
    else:
        h_abs = initial_step(0.0, y, K[0], t_end, max_step, rtol, atol, p)
        rhs_evals += 1

    peak = abs(y[0])
    tail_amp = 0.0
    tail_qmin = math.inf
    tail_qmax = -math.inf
    if t_tail <= 0.0:
        tail_amp = abs(y[0])
        tail_qmin = y[0]
        tail_qmax = y[0]
    last_above = 0.0
    k = 0
    if n_samples > 0:
        series[0] = y[0]
        k = 1

    status = mt.RUNNING
    t_stop = t_end
    steps = 0
    rejected = 0
    if not abs(y[0]) <= bound:
        status = mt.DIVERGED
        t_stop = 0.0
    while t < t_end and status == mt.RUNNING:
        if steps >= max_steps:
            status = mt.MAX_STEPS
            t_stop = t
            break
        min_step = max(10.0 * abs(np.nextafter(t, math.inf) - t), settings[MIN_STEP])
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        rejected_now = False
        h = 0.0
        t_new = t
        while True:
            if h_abs < min_step:
                status = mt.STEP_TOO_SMALL
                break
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            rk_step(t, y, h, p, K, y_new)
            rhs_evals += 6
            err = error_norm(K, h, y, y_new, rtol, atol)
            h_abs *= step_factor(err, rejected_now)
            if err < 1.0:
                break
            rejected_now = True
            rejected += 1
        if status != mt.RUNNING:
            t_stop = t
            break
        steps += 1
        q_old = y[0]
        v_old = y[1]
        q_new = y_new[0]
        v_new = y_new[1]
        if not (abs(q_new) <= bound and math.isfinite(v_new)):
            status = mt.DIVERGED
            t_stop = t_new
            if math.isfinite(q_new) and abs(q_new) > bound and abs(q_old) <= bound:
                dense_coefficients(K, Q)
                side = 1.0 if q_new > 0.0 else -1.0
                t_stop = t + dense_root(q_old, h, Q, 0, side * bound, 0.0, 1.0) * h
            break

        # The interpolant is built only for steps that need it (an extremum, the tail's start,
        # a sample or a crossing of the tracked threshold).
        has_ext = (v_old > 0.0 and v_new <= 0.0) or (v_old < 0.0 and v_new >= 0.0)
        straddles_tail = t < t_tail <= t_new
        has_sample = k < n_samples and k * dt_sample <= t_new
        thr_now = thr_fixed + thr_rel * max(peak, abs(q_new))
        may_cross = track and abs(q_new - centre) <= thr_now < abs(q_old - centre)
        if has_ext or straddles_tail or has_sample or may_cross:
            dense_coefficients(K, Q)
        xe = 0.0
        qe = 0.0
        if has_ext:
            xe = dense_root(v_old, h, Q, 1, 0.0, 0.0, 1.0)
            te = t + xe * h
            qe = dense_value(q_old, h, Q, 0, xe)
            kind = mt.MAXIMUM if v_old > 0.0 else mt.MINIMUM
            buf = mt.push_extremum(buf, n_ext, te, qe, kind)
            n_ext += 1
            peak = max(peak, abs(qe))
            if te >= t_tail:
                tail_amp = max(tail_amp, abs(qe))
                tail_qmin = min(tail_qmin, qe)
                tail_qmax = max(tail_qmax, qe)
        peak = max(peak, abs(q_new))

        if t_new >= t_tail:
            if straddles_tail:
                qt = dense_value(q_old, h, Q, 0, (t_tail - t) / h)
                peak = max(peak, abs(qt))
                tail_amp = max(tail_amp, abs(qt))
                tail_qmin = min(tail_qmin, qt)
                tail_qmax = max(tail_qmax, qt)
            tail_amp = max(tail_amp, abs(q_new))
            tail_qmin = min(tail_qmin, q_new)
            tail_qmax = max(tail_qmax, q_new)

        if track:
            thr = thr_fixed + thr_rel * peak
            last_above = _last_time_above(t, h, Q, q_old, q_new, has_ext, xe, qe,
                                          centre, thr, last_above)

        while k < n_samples and k * dt_sample <= t_new:
            series[k] = dense_value(q_old, h, Q, 0, (k * dt_sample - t) / h)
            k += 1

        t = t_new
        y[0] = q_new
        y[1] = v_new
        K[0, 0] = K[6, 0]
        K[0, 1] = K[6, 1]

    for j in range(k, n_samples):
        series[j] = math.nan
    return (status, t_stop, steps, rejected, rhs_evals, peak, tail_amp, tail_qmin, tail_qmax,
            last_above, y[0], buf, n_ext)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _valid(p):
    for j in range(N_PARAMS):
        if not math.isfinite(p[j]):
            return False
    return p[MASS] > 0.0 and p[BOUND] > 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_point(p, settings, reals, counts, series):
    """Integrate one point and classify it (metrics module). Fills `reals` and `counts`; returns
    the state flag. Never raises for bad parameters: they give INVALID_INPUT."""
    for j in range(N_REALS):
        reals[j] = math.nan
    for j in range(N_COUNTS):
        counts[j] = 0
    if not _valid(p):
        for j in range(series.shape[0]):
            series[j] = math.nan
        return mt.INVALID_INPUT
    want_settling = settings[WANT_SETTLING] != 0.0
    tol = settings[TOL]
    t_tail = settings[T_END] * (1.0 - settings[TAIL])
    (status, t_stop, steps, rejected, rhs_evals, peak, tail_amp, tail_qmin, tail_qmax,
     last_above, q_end, buf, n_ext) = integrate(p, settings, want_settling, 0.0, 0.0, tol, series)
    counts[STEPS] = steps
    counts[REJECTED] = rejected
    counts[RHS_EVALS] = rhs_evals
    if status != mt.RUNNING:
        reals[FAILURE_TIME] = t_stop
        return status

    reals[AMPLITUDE] = tail_amp
    reals[PEAK] = peak
    n_max, n_min, period = mt.tail_counts(buf, n_ext, t_tail)
    reals[PERIOD] = period
    band = tol * tail_amp
    if tail_amp <= tol * peak:
        if want_settling:
            reals[SETTLING] = last_above
        return mt.DECAYED
    if n_max >= 2 and n_min >= 2:
        t_settle = mt.last_envelope_violation(buf, n_ext, band)
        if t_settle < t_tail:
            if want_settling:
                reals[SETTLING] = t_settle
            return mt.STEADY
        if mt.tail_trend(buf, n_ext, t_tail, settings[T_END]):
            return mt.UNSETTLED
        return mt.MODULATED
    if tail_qmax - tail_qmin <= band:
        # At rest away from zero (e.g. post-buckled): settle on the final value, second pass.
        if want_settling:
            empty = np.empty(0)
            res = integrate(p, settings, True, q_end, band, 0.0, empty)
            reals[SETTLING] = res[9]
            counts[RHS_EVALS] += res[4]
        return mt.STEADY
    return mt.UNSETTLED


@nb.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def solve_batch(params, settings, states, reals, counts, series):
    """Solve every row of `params` (n, N_PARAMS) in parallel, one trajectory per iteration.

    Outputs (preallocated, first axis n): states int8 (metrics flags), reals (n, N_REALS),
    counts (n, N_COUNTS) int64, series (n, n_samples) q samples at k * SAMPLE_DT (n_samples may
    be 0). Each point's result depends only on its own row.
    """
    for i in nb.prange(params.shape[0]):
        states[i] = solve_point(params[i], settings, reals[i], counts[i], series[i])
