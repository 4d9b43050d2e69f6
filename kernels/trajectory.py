"""One trajectory as a small state machine, shared by the scalar and the lock-step drivers.

A trajectory's whole state lives in a float64 accumulator row (slots below) plus its extrema
buffer, so a driver can advance many of them side by side:

    start(...)                         initial state, f(0, y0), the point's absolute
                                       tolerances (`point_atol`), SciPy's initial step
    h = next_attempt(settings, acc)    the step to try now (0.0: the trajectory has ended)
    ... the driver computes one attempt of size h (RK45 or DOP853) and its error norm ...
    buf = finish_attempt(...)          SciPy's accept/reject and step-size update (`control`);
                                       on acceptance the in-kernel metrics (`record_step`)
    classify(...)                      state, amplitude, settling time, period, counts

Each point's attempts are SciPy's RK45's or DOP853's (settings[METHOD]), in SciPy's order,
whatever the driver.
Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import metrics as mt
from . import dop853
from .dopri5 import (ERROR_ESTIMATOR_ORDER, ERROR_EXPONENT, MIN_RTOL, PI_MIN_ERR_PREV,
                     RHS_PER_ATTEMPT,
                     dense_coefficients, dense_root, dense_value, initial_step, pi_log2_err,
                     pi_step_factor, step_factor)
from .layout import (ATOL, ATOL_SCALE, CONTROLLER, FIRST_STEP, MAX_STEP, MAX_STEPS, METHOD,
                     MIN_STEP, RTOL, SAMPLE_DT, TAIL, T_END)
from .oscillator import BOUND, Q0, Q_SCALE, V0, V_SCALE, acceleration
from .vecmath import log2_fast

# Slots of a trajectory's accumulator row.
T = 0               # current time (s)
Q = 1               # q at T (m)
V = 2               # q' at T (m/s)
FQ = 3              # f(T, y), first component (= V)
FV = 4              # f(T, y), second component (q'', m/s^2)
H_ABS = 5           # step size to try next (s)
T_NEW = 6           # end of the attempt in progress (s)
REJECTED_NOW = 7    # 1.0 after a rejection within the current step
STATUS = 8          # metrics.RUNNING until the trajectory ends
T_STOP = 9          # when it ended (s)
STEPS = 10          # accepted steps
REJECTED = 11       # rejected attempts
RHS_EVALS = 12      # right-hand-side evaluations
PEAK = 13           # running max |q| (m)
TAIL_AMP = 14       # max |q| over the tail window so far (m)
TAIL_QMIN = 15      # min q over the tail window (m)
TAIL_QMAX = 16      # max q over the tail window (m)
LAST_ABOVE = 17     # last time |q - centre| > threshold (s)
SAMPLE = 18         # next time-series sample index
N_EXT = 19          # extrema recorded
LOG2_ERR_PREV = 20  # log2 of the last accepted step's error norm (PI controller)
ATOL_Q = 21         # absolute tolerance on q (m): `point_atol`
ATOL_V = 22         # absolute tolerance on q' (m/s)
N_SLOTS = 23

# The PI controller's memory before the first accepted step: pi_log2_err(PI_MIN_ERR_PREV),
# computed once here (the same arithmetic in Python) rather than compiled into `start`.
_LOG2_ERR_PREV_START = log2_fast.py_func(PI_MIN_ERR_PREV)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def new_buffer():
    """An empty extrema buffer, room for 64 extrema (`with_room` grows it)."""
    return np.empty((64, 3))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def with_room(buf, acc):
    """The extrema buffer with room for one more extremum: `buf` itself, or a copy twice its
    size when full. Drivers call it before `record_step`, which never allocates."""
    n = int(acc[N_EXT])
    if n < buf.shape[0]:
        return buf
    bigger = np.empty((2 * buf.shape[0], 3))
    for i in range(n):          # a loop, not a slice copy: that compiles seconds of error text
        for c in range(3):
            bigger[i, c] = buf[i, c]
    return bigger


@nb.njit(cache=True, nogil=True, error_model="numpy")
def point_atol(p, settings, rtol):
    """The absolute tolerances (atol_q in m, atol_v in m/s) of the point with parameter row p:
    settings[ATOL] plus settings[ATOL_SCALE] x rtol x the point's own scales (p[Q_SCALE],
    p[V_SCALE]). With ATOL_SCALE = 0 that is settings[ATOL] for both, as SciPy's scalar atol;
    with ATOL = 0 the error norm is relative to each point's own size, so a response scaled by
    any factor takes the same steps. Both drivers read the tolerances from here (`start`)."""
    c = settings[ATOL_SCALE] * rtol
    return settings[ATOL] + c * p[Q_SCALE], settings[ATOL] + c * p[V_SCALE]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def start(p, settings, acc, series):
    """Set up a trajectory at t = 0 from its parameter row `p`; q(0) goes to series[0]."""
    rtol = max(settings[RTOL], MIN_RTOL)
    t_end = settings[T_END]
    t_tail = t_end * (1.0 - settings[TAIL])
    q = p[Q0]
    v = p[V0]
    acc[T] = 0.0
    acc[Q] = q
    acc[V] = v
    acc[FQ] = v
    acc[FV] = acceleration(0.0, q, v, p)
    acc[RHS_EVALS] = 1.0
    acc[ATOL_Q], acc[ATOL_V] = point_atol(p, settings, rtol)
    if settings[FIRST_STEP] > 0.0:
        acc[H_ABS] = min(settings[FIRST_STEP], t_end)
    else:
        y = np.empty(2)
        f = np.empty(2)
        y[0], y[1] = q, v
        f[0], f[1] = acc[FQ], acc[FV]
        order = dop853.ERROR_ESTIMATOR_ORDER if settings[METHOD] != 0.0 else ERROR_ESTIMATOR_ORDER
        acc[H_ABS] = initial_step(0.0, y, f, t_end, settings[MAX_STEP], rtol, acc[ATOL_Q],
                                  acc[ATOL_V], p, order)
        acc[RHS_EVALS] += 1.0
    acc[T_NEW] = 0.0
    acc[REJECTED_NOW] = 0.0
    acc[STATUS] = mt.RUNNING
    acc[T_STOP] = t_end
    acc[STEPS] = 0.0
    acc[REJECTED] = 0.0
    acc[PEAK] = abs(q)
    acc[TAIL_AMP] = abs(q) if t_tail <= 0.0 else 0.0
    acc[TAIL_QMIN] = q if t_tail <= 0.0 else math.inf
    acc[TAIL_QMAX] = q if t_tail <= 0.0 else -math.inf
    acc[LAST_ABOVE] = 0.0
    acc[SAMPLE] = 0.0
    if series.shape[0] > 0:
        series[0] = q
        acc[SAMPLE] = 1.0
    acc[N_EXT] = 0.0
    acc[LOG2_ERR_PREV] = _LOG2_ERR_PREV_START
    if not abs(q) <= p[BOUND]:
        acc[STATUS] = mt.DIVERGED
        acc[T_STOP] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def next_attempt(settings, acc):
    """The step h (s) to attempt from acc[T], as SciPy's RK45 chooses it; 0.0 when the
    trajectory has ended (reached t_end, or failed: STATUS says which)."""
    if acc[STATUS] != mt.RUNNING:
        return 0.0
    t = acc[T]
    t_end = settings[T_END]
    if t >= t_end:
        return 0.0
    min_step = max(10.0 * abs(np.nextafter(t, math.inf) - t), settings[MIN_STEP])
    h_abs = acc[H_ABS]
    if acc[REJECTED_NOW] == 0.0:
        if acc[STEPS] >= settings[MAX_STEPS]:
            acc[STATUS] = mt.MAX_STEPS
            acc[T_STOP] = t
            return 0.0
        if h_abs > settings[MAX_STEP]:
            h_abs = settings[MAX_STEP]
        elif h_abs < min_step:
            h_abs = min_step
    if h_abs < min_step:
        acc[STATUS] = mt.STEP_TOO_SMALL
        acc[T_STOP] = t
        return 0.0
    t_new = t + h_abs
    if t_new > t_end:
        t_new = t_end
    h = t_new - t
    acc[H_ABS] = abs(h)
    acc[T_NEW] = t_new
    return h


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _above_bracket(q_old, q_new, has_ext, xe, qe, centre, thr):
    """Where in the step |q - centre| last fell to thr, as a bracket for the root finder.

    Returns (xa, xb, side): the crossing lies in [xa, xb] (x = (t - t_old)/h) at
    q = centre + side * thr; xa = 2.0 when |q - centre| ends the step above thr (the step's end
    is the last time above); xa = -1.0 when |q - centre| stays within thr all step.
    """
    if abs(q_new - centre) > thr:
        return 2.0, 1.0, 0.0
    if has_ext and abs(qe - centre) > thr:
        return xe, 1.0, 1.0 if qe > centre else -1.0
    if abs(q_old - centre) > thr:
        return 0.0, xe if has_ext else 1.0, 1.0 if q_old > centre else -1.0
    return -1.0, 1.0, 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def control(settings, acc, err):
    """Accept or reject an attempt with error norm `err` and update the step size: SciPy's
    controller (for RK45 or DOP853, settings[METHOD]), or the PI controller (RK45 only) when
    settings[CONTROLLER] is 1. Counts the attempt. Returns True when it is accepted."""
    eighth = settings[METHOD] != 0.0
    acc[RHS_EVALS] += dop853.RHS_PER_ATTEMPT if eighth else RHS_PER_ATTEMPT
    rejected_before = acc[REJECTED_NOW] != 0.0
    if settings[CONTROLLER] != 0.0:
        acc[H_ABS] *= pi_step_factor(err, acc[LOG2_ERR_PREV], rejected_before)
    else:
        exponent = dop853.ERROR_EXPONENT if eighth else ERROR_EXPONENT
        acc[H_ABS] *= step_factor(err, rejected_before, exponent)
    if not err < 1.0:
        acc[REJECTED_NOW] = 1.0
        acc[REJECTED] += 1.0
        return False
    acc[REJECTED_NOW] = 0.0
    acc[STEPS] += 1.0
    if settings[CONTROLLER] != 0.0:
        acc[LOG2_ERR_PREV] = pi_log2_err(err)
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy")
def finish_attempt(p, settings, acc, K, q_new, v_new, err, h, Qc, buf, series,
                   track, centre, thr_fixed, thr_rel):
    """Accept or reject the attempt of size h (K: its stage derivatives, the last f(t + h,
    y_new); (q_new, v_new): its solution; err: its error norm) and update the step size as
    SciPy does (`control`); on acceptance reduce the step's metrics (`record_step`). Returns
    the extrema buffer (regrown when full). Qc is scratch for the interpolant, shape (2, 5).
    """
    if control(settings, acc, err):
        if acc[N_EXT] >= buf.shape[0]:
            buf = with_room(buf, acc)
        record_step(p[BOUND], settings, acc, K, q_new, v_new, h, Qc, buf, series, track,
                    centre, thr_fixed, thr_rel, -1.0, 0.0)
    return buf


@nb.njit(cache=True, nogil=True, error_model="numpy")
def interpolant(settings, acc, K, q_new, v_new, h, Qc):
    """Qc: the dense output of the accepted step from acc's state to (q_new, v_new), K its
    stage derivatives (only the last, f(t + h, y_new), for DOP853). RK45: its own quartic;
    DOP853: the quintic Hermite interpolant (dop853.hermite_coefficients)."""
    if settings[METHOD] != 0.0:
        dop853.hermite_coefficients(acc[Q], acc[V], acc[FV], q_new, v_new,
                                    K[K.shape[0] - 1, 1], h, Qc)
    else:
        dense_coefficients(K, Qc)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def record_step(bound, settings, acc, K, q_new, v_new, h, Qc, buf, series, track, centre,
                thr_fixed, thr_rel, xe_known, qe_known):
    """Reduce the metrics of an accepted step [acc[T], acc[T_NEW]] on its dense output and
    advance the trajectory to its end. `bound`: the divergence bound on |q| (m); `buf` must
    have room for one more extremum (`with_room`).

    If the driver has already located the step's extremum of q, xe_known in [0, 1] is its
    x = (t - t_old)/h and qe_known q there; xe_known < 0 means: locate it here. The interpolant
    (Qc, `interpolant`) is built only when something needs it.
    """
    t = acc[T]
    t_new = acc[T_NEW]
    q_old = acc[Q]
    v_old = acc[V]
    t_tail = settings[T_END] * (1.0 - settings[TAIL])

    if not (abs(q_new) <= bound and math.isfinite(v_new)):
        acc[STATUS] = mt.DIVERGED
        acc[T_STOP] = t_new
        if math.isfinite(q_new) and abs(q_new) > bound and abs(q_old) <= bound:
            interpolant(settings, acc, K, q_new, v_new, h, Qc)
            side = 1.0 if q_new > 0.0 else -1.0
            acc[T_STOP] = t + dense_root(q_old, h, Qc[0], side * bound, 0.0, 1.0) * h
        return

    n_samples = series.shape[0]
    k = int(acc[SAMPLE])
    dt_sample = settings[SAMPLE_DT]
    peak = acc[PEAK]
    has_ext = (v_old > 0.0 and v_new <= 0.0) or (v_old < 0.0 and v_new >= 0.0)
    have_qc = False
    xe = 0.0
    qe = 0.0
    if has_ext:
        if xe_known >= 0.0:
            xe = xe_known
            qe = qe_known
        else:
            interpolant(settings, acc, K, q_new, v_new, h, Qc)
            have_qc = True
            xe = dense_root(v_old, h, Qc[1], 0.0, 0.0, 1.0)
            qe = dense_value(q_old, h, Qc[0], xe)
        te = t + xe * h
        kind = mt.MAXIMUM if v_old > 0.0 else mt.MINIMUM
        n_ext = int(acc[N_EXT])
        buf[n_ext, mt.EXT_T] = te
        buf[n_ext, mt.EXT_Q] = qe
        buf[n_ext, mt.EXT_KIND] = kind
        acc[N_EXT] = n_ext + 1
        peak = max(peak, abs(qe))
        if te >= t_tail:
            acc[TAIL_AMP] = max(acc[TAIL_AMP], abs(qe))
            acc[TAIL_QMIN] = min(acc[TAIL_QMIN], qe)
            acc[TAIL_QMAX] = max(acc[TAIL_QMAX], qe)
    peak = max(peak, abs(q_new))

    if t_new >= t_tail:
        if t < t_tail:
            if not have_qc:
                interpolant(settings, acc, K, q_new, v_new, h, Qc)
                have_qc = True
            qt = dense_value(q_old, h, Qc[0], (t_tail - t) / h)
            peak = max(peak, abs(qt))
            acc[TAIL_AMP] = max(acc[TAIL_AMP], abs(qt))
            acc[TAIL_QMIN] = min(acc[TAIL_QMIN], qt)
            acc[TAIL_QMAX] = max(acc[TAIL_QMAX], qt)
        acc[TAIL_AMP] = max(acc[TAIL_AMP], abs(q_new))
        acc[TAIL_QMIN] = min(acc[TAIL_QMIN], q_new)
        acc[TAIL_QMAX] = max(acc[TAIL_QMAX], q_new)
    acc[PEAK] = peak

    if track:
        thr = thr_fixed + thr_rel * peak
        xa, xb, side = _above_bracket(q_old, q_new, has_ext, xe, qe, centre, thr)
        if xa > 1.0:
            acc[LAST_ABOVE] = t + h
        elif xa >= 0.0:
            if not have_qc:
                interpolant(settings, acc, K, q_new, v_new, h, Qc)
                have_qc = True
            x = dense_root(q_old, h, Qc[0], centre + side * thr, xa, xb)
            acc[LAST_ABOVE] = t + x * h

    if k < n_samples and k * dt_sample <= t_new:
        if not have_qc:
            interpolant(settings, acc, K, q_new, v_new, h, Qc)
            have_qc = True
        while k < n_samples and k * dt_sample <= t_new:
            series[k] = dense_value(q_old, h, Qc[0], (k * dt_sample - t) / h)
            k += 1
        acc[SAMPLE] = k

    acc[T] = t_new
    acc[Q] = q_new
    acc[V] = v_new
    acc[FQ] = K[K.shape[0] - 1, 0]
    acc[FV] = K[K.shape[0] - 1, 1]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def end_series(acc, series):
    """NaN for the samples a trajectory that stopped early never reached."""
    for j in range(int(acc[SAMPLE]), series.shape[0]):
        series[j] = math.nan
