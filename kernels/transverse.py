"""Batched transverse drivers: adaptive RK45 (or DOP853) trajectories over the rows of a
parameter table.

`solve_block(params, settings, lo, hi, states, reals, counts, series, ...)` (then the
compile-time switches and the `halt` flag) is the interface the sweep layer uses: rows
lo..hi-1 of `params` (columns in `oscillator`) in, per-point metrics out. Two drivers have
it, with the same results to round-off:

- `solve_block` here: one trajectory after another (the reference);
- `kernels.lanes.solve_block`: LANES trajectories advanced in lock-step in SIMD lanes, each
  with its own step size and accept/reject (the default: several times faster per core).

Both release the GIL; sweep.threads runs blocks on Python threads (no Numba parallel region,
whose compilation alone took ~3 s cold). A point at rest away from zero is left SECOND_PASS;
`settle_second_pass` finishes it (compiled only when a sweep has one).

Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import excitation as ex
from . import metrics as mt
from . import trajectory as tj
from . import dop853
from .dopri5 import DENSE_TERMS, MIN_RTOL, QUARTIC_TERMS, error_norm, rk_step
from .layout import *  # noqa: F401,F403  (settings and output layouts, re-exported)
from .layout import (ACCELERATION, AMPLITUDE, BANDS_PER_OCTAVE, FAILURE_TIME, FIRST_BAND,
                     N_COUNTS, N_REALS, PEAK, PEAK_FREQUENCY, PERIOD, Q_END, SWEPT, V_END,
                     REJECTED, RHS_EVALS, RTOL, SETTLING, STEPS, STOP_TIME, T_END,
                     TOL, WANT_SETTLING, LEVEL_RATE, N_LEVELS, RMS_ACCELERATION,
                     RMS_DEFLECTION, RMS_RELATIVE, RMS_VELOCITY, WINDOW, ZERO_RATE)
from .oscillator import (BOUND, EXCITATION, MASS, N_PARAMS, acceleration, prepare,
                         stiffness)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def integrate(p, settings, track, centre, thr_fixed, thr_rel, series, parametric, base,
              eighth):
    """Integrate one point (p: its prepared row, oscillator.prepare) from t = 0 to t_end with
    SciPy's RK45 or DOP853 (settings[METHOD]), reducing metrics on the fly. base: oscillator's
    base-excitation switch (None or True); eighth: the method's (None: RK45, True: DOP853, as
    settings[METHOD]).

    When `track`, the accumulator's LAST_ABOVE is the last time |q - centre| exceeded
    thr_fixed + thr_rel * (running peak |q|). Returns (accumulator row, extrema buffer).
    """
    rtol = max(settings[RTOL], MIN_RTOL)
    acc = tj.new_accumulator(tj.SCALAR_SLOTS)
    buf = tj.new_buffer()
    K = np.empty((dop853.N_STAGES_EXTENDED if eighth else 7, 2))   # DOP853: room for the
    Qc = np.empty((2, DENSE_TERMS if eighth else QUARTIC_TERMS))     # dense output's stages
    y = np.empty(2)
    y_new = np.empty(2)
    tj.start(p, 0, 1, settings, acc, series, parametric, base)
    while True:
        h = tj.next_attempt(settings, acc)
        if h == 0.0:
            break
        y[0] = acc[tj.Q]
        y[1] = acc[tj.V]
        K[0, 0] = acc[tj.FQ]
        K[0, 1] = acc[tj.FV]
        if eighth is None:
            rk_step(acc[tj.T], y, h, p, K, y_new, parametric, base)
            err = error_norm(K, h, y, y_new, rtol, acc[tj.ATOL_Q], acc[tj.ATOL_V])
        else:
            dop853.rk_step(acc[tj.T], y, h, p, K, y_new, parametric, base)
            err = dop853.error_norm(K, h, y, y_new, rtol, acc[tj.ATOL_Q], acc[tj.ATOL_V])
        if not tj.control(settings, acc, err):
            continue
        if acc[tj.N_EXT] >= buf.shape[0]:
            buf = tj.with_room(buf, acc)
        tj.record_step(p, 0, 1, settings, acc, K, y_new[0], y_new[1], h, Qc, buf, series,
                       track, centre, thr_fixed, thr_rel, -1.0, 0.0, parametric, base, eighth)
    tj.end_series(acc, series)
    return acc, buf


@nb.njit(cache=True, nogil=True, error_model="numpy")
def valid(p):
    """Whether a parameter row can be integrated: finite, positive mass and bound."""
    for j in range(N_PARAMS):
        if not math.isfinite(p[j]):
            return False
    return p[MASS] > 0.0 and p[BOUND] > 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def reject_point(reals, counts, series):
    """Outputs of a point that is not integrated (NaN metrics, zero counts)."""
    for j in range(N_REALS):
        reals[j] = math.nan
    for j in range(N_COUNTS):
        counts[j] = 0
    for j in range(series.shape[0]):
        series[j] = math.nan


@nb.njit(cache=True, nogil=True, error_model="numpy")
def classify(p, o, s, settings, acc, buf, reals, counts, parametric, base):
    """State flag and metrics of a finished trajectory (metrics module); fills reals, counts.
    p[o + column * s]: the point's prepared row (oscillator.prepare). `classify_metrics`'s,
    with the oscillator's at-rest test (`at_rest`)."""
    band = settings[TOL] * acc[tj.TAIL_AMP]
    return classify_metrics(settings, acc, buf, reals, counts, base,
                            at_rest(p, o, s, acc, band, parametric, base))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def classify_metrics(settings, acc, buf, reals, counts, base, resting):
    """State flag and metrics of a finished trajectory of any system from its accumulator and
    extrema (metrics module); fills reals, counts. resting: whether the final state lies
    within the settling band (settings[TOL] x the tail amplitude) of a stable equilibrium (the
    system's own at-rest test: `at_rest` for the oscillator).

    A trajectory that came to rest away from zero without oscillating is integrated a second
    time to find when it settled on its final value (SECOND_PASS). A random record's
    (`base` the records) are its statistics' (`random_outputs`): each kind compiles only its
    own (excitation.by_kind; the response's states cost a record scene 3 s of compile).
    """
    return _metrics_of_kind(settings, acc, buf, reals, counts, resting, base)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _metrics_start(settings, acc, reals, counts, base):
    """What every finished trajectory reports (counts, the end state, amplitude, peak, a
    base excitation's acceleration); returns its status: a failure's, or mt.RUNNING for a
    trajectory that ran to its end."""
    for j in range(N_REALS):
        reals[j] = math.nan
    counts[STEPS] = int(acc[tj.STEPS])
    counts[REJECTED] = int(acc[tj.REJECTED])
    counts[RHS_EVALS] = int(acc[tj.RHS_EVALS])
    status = int(acc[tj.STATUS])
    if status != mt.RUNNING:
        reals[FAILURE_TIME] = acc[tj.T_STOP]
        return status
    reals[Q_END] = acc[tj.Q]
    reals[V_END] = acc[tj.V]
    if acc[tj.T_FINAL] < settings[T_END]:
        reals[STOP_TIME] = acc[tj.T_FINAL]
    reals[AMPLITUDE] = acc[tj.TAIL_AMP]
    reals[PEAK] = acc[tj.PEAK]
    if base is not None:
        reals[ACCELERATION] = acc[tj.ACC_AMP]
    return status


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _record_metrics(settings, acc, buf, reals, counts, resting, base):
    """classify_metrics for a random record: its statistics (`random_outputs`)."""
    status = _metrics_start(settings, acc, reals, counts, base)
    if status != mt.RUNNING:
        return status
    return random_outputs(settings, acc, reals)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _response_metrics(settings, acc, buf, reals, counts, resting, base):
    """classify_metrics for the sine kinds or none: the response's state from its extrema
    (docs/model.md, section 3)."""
    status = _metrics_start(settings, acc, reals, counts, base)
    if status != mt.RUNNING:
        return status
    want_settling = settings[WANT_SETTLING] != 0.0
    tol = settings[TOL]
    t_tail = acc[tj.T_TAIL]          # t_end (1 - tail), or where the point was found steady
    t_end = acc[tj.T_FINAL]
    tail_amp = acc[tj.TAIL_AMP]
    peak = acc[tj.PEAK]
    n_ext = int(acc[tj.N_EXT])
    n_max, n_min, period = mt.tail_counts(buf, n_ext, t_tail)
    reals[PERIOD] = period
    band = tol * tail_amp
    if tail_amp <= tol * peak:
        if want_settling:
            reals[SETTLING] = acc[tj.LAST_ABOVE]
        return mt.DECAYED
    if n_max >= 2 and n_min >= 2:
        t_settle = mt.last_envelope_violation(buf, n_ext, band)
        if t_settle < t_tail:
            if want_settling:
                reals[SETTLING] = t_settle
            return mt.STEADY
        k, t_settle = mt.periodic_order(buf, n_ext, t_tail, band, n_max, n_min)
        if k > 0:
            # A period-k orbit (maxima alternating between k levels): steady, its period k
            # maxima long.
            reals[PERIOD] = mt.orbit_period(buf, n_ext, t_tail, k)
            if want_settling:
                reals[SETTLING] = t_settle
            return mt.STEADY
        if mt.tail_trend(buf, n_ext, t_tail, t_end):
            return mt.UNSETTLED
        return mt.MODULATED
    if acc[tj.TAIL_QMAX] - acc[tj.TAIL_QMIN] <= band and resting:
        # At rest away from zero (e.g. post-buckled): its settling time (on the final value)
        # needs a second integration, left to settle_second_pass so that the drivers do not
        # compile the scalar integrator for a case most sweeps never meet.
        return mt.SECOND_PASS if want_settling else mt.STEADY
    # Too few oscillations in the tail to judge, or a slow motion that has only begun (a run
    # shorter than one period moves little and yet is not at rest).
    return mt.UNSETTLED


_metrics_of_kind = ex.by_kind(_response_metrics, _record_metrics)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def at_rest(p, o, s, acc, band, parametric, base):
    """Whether the final state (acc's t, q, q') lies within `band` (m) of a stable equilibrium.

    Linearised about the final q: stiffness per unit mass k = d(force)/dq / m
    (`oscillator.stiffness`, at the load's value at t), natural angular frequency
    w = sqrt(k); the equilibrium lies d = (force / m) / k away, and the motion about it has
    amplitude sqrt(d^2 + (q'/w)^2) (m). At rest when that is <= band. A tail that merely moved
    little (a run shorter than one natural period 2 pi / w) is not at rest: d is then of the
    order of q itself. k <= 0 (no stable equilibrium near q): not at rest. p[o + column * s]:
    the prepared row.
    """
    t, q, v = acc[tj.T], acc[tj.Q], acc[tj.V]
    k = stiffness(t, q, p, o, s)
    if not k > 0.0:
        return False
    static = -acceleration(t, q, 0.0, p, o, s, None, parametric, base)   # restoring force per mass
    offset = static / k
    speed = v / math.sqrt(k)
    return math.sqrt(offset * offset + speed * speed) <= band


@nb.njit(cache=True, nogil=True, error_model="numpy")
def settle_second_pass(params, settings, states, reals, counts, parametric, base, eighth):
    """Finish the points a driver left as SECOND_PASS (at rest away from zero): integrate
    again to find the final value, then a second time tracking |q - q_final| against the band
    tol * amplitude; the settling time is the last time q was outside it. The state becomes
    STEADY; counts[RHS_EVALS] gains the second pass's evaluations (as if done in one go).
    Other rows are left as they are. Returns how many points were finished."""
    done = 0
    for i in range(params.shape[0]):
        if states[i] != mt.SECOND_PASS:
            continue
        p = np.empty(N_PARAMS)
        prepare(params[i], p, 0, 1)
        track = bool(True)    # a run-time bool, as solve_point's: integrate compiles once
        first, _ = integrate(p, settings, track, 0.0, 0.0, settings[TOL], np.empty(0),
                             parametric, base, eighth)
        band = settings[TOL] * first[tj.TAIL_AMP]
        second, _ = integrate(p, settings, track, first[tj.Q], band, 0.0, np.empty(0), parametric,
                              base, eighth)
        states[i] = tj.settle(second, reals[i], counts[i])
        done += 1
    return done


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_point(row, settings, reals, counts, series, envelope, parametric, base, eighth):
    """Integrate the point of parameter row `row` and classify it. Never raises for bad
    parameters: they give INVALID_INPUT. With settings[SWEPT] (a swept base frequency) the
    sweep's outputs too (`swept_outputs`: peak frequency, envelope; the state COMPLETED)."""
    if not valid(row):
        reject_point(reals, counts, series)
        for b in range(envelope.shape[0]):
            envelope[b] = math.nan
        return mt.INVALID_INPUT
    p = np.empty(N_PARAMS)
    prepare(row, p, 0, 1)
    acc, buf = integrate(p, settings, settings[WANT_SETTLING] != 0.0, 0.0, 0.0,
                         settings[TOL], series, parametric, base, eighth)
    state = classify(p, 0, 1, settings, acc, buf, reals, counts, parametric, base)
    if settings[SWEPT] != 0.0:
        state = swept_outputs(p, EXCITATION, 1, settings, acc, buf, state, reals, envelope)
    return state


@nb.njit(cache=True, nogil=True, error_model="numpy")
def random_outputs(settings, acc, reals):
    """A random base acceleration's statistics over the window of a trajectory that ran to
    its end (kernels.trajectory.observe_random): the RMS of q, q', q'' and q'' + a_b, the
    up-crossing rates of zero and of settings' levels of |q|, the window's length. A random
    response has no settling to judge: the state is COMPLETED."""
    span = acc[tj.W_END] - acc[tj.W_START]
    if acc[tj.IN_WINDOW] == 0.0 or not span > 0.0:
        return mt.COMPLETED
    reals[RMS_DEFLECTION] = math.sqrt(acc[tj.SUM_Q2] / span)
    reals[RMS_VELOCITY] = math.sqrt(acc[tj.SUM_V2] / span)
    absolute, relative = tj.acceleration_squares(acc)
    reals[RMS_ACCELERATION] = math.sqrt(absolute / span)
    reals[RMS_RELATIVE] = math.sqrt(relative / span)
    reals[ZERO_RATE] = acc[tj.UP_ZERO] / span
    for k in range(int(settings[N_LEVELS])):
        reals[LEVEL_RATE + k] = acc[tj.UP_LEVEL + k] / span
    reals[WINDOW] = span
    return mt.COMPLETED


@nb.njit(cache=True, nogil=True, error_model="numpy")
def swept_outputs(p, o, s, settings, acc, buf, state, reals, envelope):
    """A swept point's state and outputs once `classify_metrics` has run: the peak frequency
    (reals[PEAK_FREQUENCY], Hz) and the envelope (metrics.sweep_metrics; p[o + column * s]
    its excitation block), NaN where the point failed; the state of a point that ran the whole
    sweep is COMPLETED (a sweep has no settling to judge). Returns the state."""
    failed = state == mt.DIVERGED or state == mt.STEP_TOO_SMALL or state == mt.MAX_STEPS
    f_peak = mt.sweep_metrics(p, o, s, buf, int(acc[tj.N_EXT]), settings[BANDS_PER_OCTAVE],
                              settings[FIRST_BAND], envelope)
    if failed:
        for b in range(envelope.shape[0]):
            envelope[b] = math.nan
        return state
    reals[PEAK_FREQUENCY] = f_peak
    reals[SETTLING] = math.nan
    return mt.COMPLETED


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_block(params, settings, lo, hi, states, reals, counts, series, parametric, base,
                eighth, halt):
    """Solve rows lo..hi-1 of `params` (n, N_PARAMS), one trajectory after another.

    Outputs (preallocated, first axis n): states int8 (metrics flags), reals (n, N_REALS),
    counts (n, N_COUNTS) int64, series (n, n_samples) q samples at k * SAMPLE_DT (n_samples may
    be 0). Each point's result depends only on its own row. Releases the GIL: the sweep layer
    runs blocks on several threads (sweep.threads). Points left SECOND_PASS are finished by
    settle_second_pass. base: oscillator's base-excitation switch, None or True (True when
    settings[BASE] is 1: the sweep layer passes it, so that Numba compiles only one); eighth
    likewise, True when settings[METHOD] is 1 (DOP853). halt: as kernels.lanes.solve_block's (an
    interrupt starts no further row).
    """
    none = np.empty(0)
    for i in range(lo, hi):
        if halt[0] != 0:
            return
        states[i] = solve_point(params[i], settings, reals[i], counts[i], series[i], none,
                                parametric, base, eighth)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_swept_block(params, settings, lo, hi, states, reals, counts, series, envelope,
                      parametric, base, eighth):
    """`solve_block` for a swept base frequency (settings[SWEPT] = 1), with the response
    envelope: envelope (n, n_bands) (m; n_bands may be 0, `swept_outputs`)."""
    for i in range(lo, hi):
        states[i] = solve_point(params[i], settings, reals[i], counts[i], series[i],
                                envelope[i], parametric, base, eighth)
