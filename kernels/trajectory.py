"""One trajectory as a small state machine, shared by the scalar and the lock-step drivers.

A trajectory's whole state lives in a float64 accumulator row (slots below) plus its extrema
buffer, so a driver can advance many of them side by side:

    start(...)                         initial state, f(0, y0), the point's absolute
                                       tolerances (`point_atol`), SciPy's initial step
    h = next_attempt(settings, acc)    the step to try now (0.0: the trajectory has ended)
    ... the driver computes one attempt of size h (RK45 or DOP853) and its error norm ...
    control(settings, acc, err)        SciPy's accept/reject and step-size update; on
    record_step(...)                   acceptance the in-kernel metrics (the extrema
                                       buffer regrown first where full: `with_room`)
    transverse.classify(...)           state, amplitude, settling time, period, counts

Each point's attempts are SciPy's RK45's or DOP853's (settings[METHOD]), in SciPy's order,
whatever the driver.
Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import excitation as ex
from . import metrics as mt
from . import dop853
from .dopri5 import (ERROR_ESTIMATOR_ORDER, ERROR_EXPONENT, MIN_RTOL,
                     PI_MIN_ERR_PREV, RHS_PER_ATTEMPT, dense_coefficients, dense_extremum,
                     dense_root, dense_value, initial_step, pi_log2_err, pi_step_factor,
                     step_factor)
from .flags import CONTRACT
from .layout import (ATOL, ATOL_SCALE, CONTROLLER, FIRST_STEP, MAX_STEP, MAX_STEPS, METHOD,
                     LEVEL_0, MAX_LEVELS, MIN_STEP, N_LEVELS, RTOL, SAMPLE_DT,
                     STEADY_PERIODS, STEADY_TOL, STOP_STEADY, TAIL, T_END)
from .layout import RHS_EVALS as EVALS_COLUMN, SETTLING
from .oscillator import (BOUND, DAMPING, EXCITATION, PARTICIPATION, Q0, Q_SCALE, V0, V_SCALE,
                         acceleration, base_acceleration)
from .stages import InlineWhereTrue
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
ACC_AMP = 23        # max |q'' + a_b| over the tail window so far (m/s^2; base excitation only)
# The last three step-end samples of the absolute acceleration (base excitation only), newest
# first: sample k's fields at ACC_SAMPLES + k * SAMPLE_SIZE + (S_T, S_A, S_Q, S_V, S_F). A local
# extremum among three consecutive steps' ends is refined on the polynomial through q, q' and q''
# at the three ends (`samples_interpolant`, `refine_acceleration_peak`).
ACC_SAMPLES = 24
S_T = 0             # the step end's time (s)
S_A = 1             # q'' + a_b there (m/s^2); NaN: no sample (not a consecutive step's end)
S_Q = 2             # q (m)
S_V = 3             # q' (m/s)
S_F = 4             # q'' (m/s^2)
SAMPLE_SIZE = 5
ACC_STEP = ACC_SAMPLES + 3 * SAMPLE_SIZE   # the accepted-step count of the newest sample
ACC_TURN = ACC_STEP + 1   # 1.0: the middle sample is an extremum to refine (pending)
INTERP = ACC_TURN + 1     # 9 slots: the samples' interpolant (`samples_interpolant`), scratch
INTERP_T = INTERP + 9     # ... its first node's time (s)
INTERP_SPAN = INTERP + 10  # ... the time from its first node to its last (s)
INTERP_X1 = INTERP + 11   # ... its middle node, (t_1 - t_first) / span
T_TAIL = INTERP + 12   # this trajectory's tail window start (s): t_end (1 - tail), or, once
                        # found steady (settings STOP_STEADY), the maximum where it was found so
T_FINAL = T_TAIL + 1    # this trajectory's end time (s): t_end, or the moved tail window's end
N_SLOTS = T_FINAL + 1
# The record kind's statistics (a random base acceleration, kernels.excitation), after the
# slots every driver keeps: the drivers that run records (the scalar ones, the multi-mode
# lanes) allocate SCALAR_SLOTS, and `record_window` zeroes them. The window starts with the
# first step that starts at or after the tail window's start and ends with the run; over it
# (`observe_random`; the accelerations' parts: `acceleration_squares`):
IN_WINDOW = N_SLOTS      # 1.0 once the window has started
W_START = IN_WINDOW + 1  # when it started (s)
W_END = W_START + 1      # the last step end in it (s)
SUM_Q2 = W_END + 1       # integral of q^2 dt (m^2 s), on the step's quintic Hermite
SUM_V2 = SUM_Q2 + 1      # integral of q'^2 dt (m^2/s), on the same quintic's slope
SUM_F2 = SUM_V2 + 1      # integral of q''^2 dt (m^2/s^3), on the quintic's second derivative
SUM_FB = SUM_F2 + 1      # integral of q'' a_b dt (m^2/s^3), Simpson's rule, the quintic's q''
SUM_R2 = SUM_FB + 1      # integral of r^2 dt (m^2/s^3), r = q'' + G a_b the acceleration the
                         # span's own forces give (G: a_b's share of q''), Simpson's rule on
                         # each step through r's middle value that its exact integral gives
SUM_RB = SUM_R2 + 1      # integral of r a_b dt (m^2/s^3), Simpson's rule on the same nodes
SUM_B2 = SUM_RB + 1      # integral of a_b^2 dt (m^2/s^3), exact on the record's interpolant
SHARE = SUM_B2 + 1       # G (1): q'' = r - G a_b (the participation of the watched deflection)
STEP_AB = SHARE + 1      # the last step's a_b at its start, middle and end (m/s^2) and its
                         # integral over it (m/s) in STEP_AB + 0..3 (`record_statistics`; the
                         # modes' curvature squares read them: modal_driver)
AT_END = STEP_AB + 4     # the time (s) of the last step end whose integrals of a_b and a_b^2
                         # from 0 (m/s, m^2/s^3) AT_END + 1, + 2 hold (`step_integrals`)
UP_ZERO = AT_END + 3     # up-crossings of q = 0
UP_LEVEL = UP_ZERO + 1   # level k's crossings of |q| upwards through settings[LEVEL_0 + k]
SCALAR_SLOTS = UP_LEVEL + MAX_LEVELS

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


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def point_atol(p, o, s, settings, rtol):
    """The absolute tolerances (atol_q in m, atol_v in m/s) of the point with parameter row p:
    settings[ATOL] plus settings[ATOL_SCALE] x rtol x the point's own scales (p[Q_SCALE],
    p[V_SCALE]). With ATOL_SCALE = 0 that is settings[ATOL] for both, as SciPy's scalar atol;
    with ATOL = 0 the error norm is relative to each point's own size, so a response scaled by
    any factor takes the same steps. Both drivers read the tolerances from here (`start`).
    The row is read at p[o + column * s] (oscillator's accessor)."""
    c = settings[ATOL_SCALE] * rtol
    return settings[ATOL] + c * p[o + Q_SCALE * s], settings[ATOL] + c * p[o + V_SCALE * s]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def start(p, o, s, settings, acc, series, parametric, base):
    """Set up a trajectory at t = 0 from its prepared parameter row at p[o + column * s]
    (oscillator.prepare); q(0) goes to series[0]. base: oscillator's switch."""
    rtol = max(settings[RTOL], MIN_RTOL)
    t_end = settings[T_END]
    q = p[o + Q0 * s]
    v = p[o + V0 * s]
    fv = acceleration(0.0, q, v, p, o, s, None, parametric, base)
    atol_q, atol_v = point_atol(p, o, s, settings, rtol)
    evals = 1.0
    if settings[FIRST_STEP] > 0.0:
        h_abs = min(settings[FIRST_STEP], t_end)
    else:
        y = np.empty(2)
        f = np.empty(2)
        y[0], y[1] = q, v
        f[0], f[1] = v, fv
        order = dop853.ERROR_ESTIMATOR_ORDER if settings[METHOD] != 0.0 else ERROR_ESTIMATOR_ORDER
        h_abs = initial_step(0.0, y, f, t_end, settings[MAX_STEP], rtol, atol_q, atol_v,
                             p, o, s, order, parametric, base)
        evals += 1.0
    a0 = fv
    if base is not None:
        a0 += base_acceleration(0.0, p, o, s, None, base)
    begin(settings, acc, series, q, v, fv, a0, atol_q, atol_v, h_abs, evals, p[o + BOUND * s])
    if ex.is_record(base):
        record_window(acc, p[o + (EXCITATION + ex.RECORD_START) * s],
                      p[o + (EXCITATION + ex.RAMP) * s], p[o + PARTICIPATION * s])


@nb.njit(cache=True, nogil=True, error_model="numpy")
def new_accumulator(slots):
    """A zeroed accumulator of `slots` for one trajectory, typed as a strided view (Numba's
    layout 'A'), as a lanes driver's column W[j::LANES] is: every function that takes an
    accumulator then compiles once for the scalar and the lanes drivers, not once each."""
    return np.zeros((slots, 1))[:, 0]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def record_window(acc, start, ramp, share):
    """A random record's own statistics window: the tail window starts no earlier than
    `start` (s, the row's start-up transient's end), so that a point's statistics depend on
    its own row only, not on the grid's slowest point, nor before the record's level ramp
    (s) has ended; the statistics' slots (IN_WINDOW .. SCALAR_SLOTS) zeroed, for a lanes
    driver's accumulator that held a row before, and SHARE set to `share`, the participation
    G of the watched deflection (q'' = r - G a_b). Called right after `begin`."""
    for k in range(N_SLOTS, SCALAR_SLOTS):
        acc[k] = 0.0
    acc[SHARE] = share
    start = max(start, ramp)
    if start <= acc[T_TAIL]:
        return
    acc[T_TAIL] = start
    acc[TAIL_AMP] = 0.0
    acc[TAIL_QMIN] = math.inf
    acc[TAIL_QMAX] = -math.inf
    acc[ACC_AMP] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def begin(settings, acc, series, q, v, fv, a0, atol_q, atol_v, h_abs, evals, bound):
    """Write a trajectory's accumulator at t = 0 for any system whose observed quantity is q
    (m) with rate v (m/s) and second derivative fv (m/s^2): `start`'s for the oscillator, and
    the multi-mode driver's for the midspan deflection. a0: the absolute acceleration fv + a_b
    at t = 0 (m/s^2; fv without base excitation); atol_q, atol_v: the absolute tolerances
    (`point_atol`); h_abs: the first step to try (s); evals: the right-hand sides spent so far;
    bound: the divergence bound on |q| (m). q(0) goes to series[0]."""
    t_end = settings[T_END]
    t_tail = t_end * (1.0 - settings[TAIL])
    acc[T] = 0.0
    acc[Q] = q
    acc[V] = v
    acc[FQ] = v
    acc[FV] = fv
    acc[RHS_EVALS] = evals
    acc[ATOL_Q] = atol_q
    acc[ATOL_V] = atol_v
    acc[H_ABS] = h_abs
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
    acc[ACC_AMP] = abs(a0) if t_tail <= 0.0 else 0.0
    for k in range(3):
        for field in range(SAMPLE_SIZE):
            acc[ACC_SAMPLES + k * SAMPLE_SIZE + field] = math.nan
    newest = ACC_SAMPLES
    acc[newest + S_T] = 0.0
    acc[newest + S_A] = a0
    acc[newest + S_Q] = q
    acc[newest + S_V] = v
    acc[newest + S_F] = fv
    acc[ACC_STEP] = 0.0
    acc[ACC_TURN] = 0.0
    acc[T_TAIL] = t_tail
    acc[T_FINAL] = t_end
    if not abs(q) <= bound:
        acc[STATUS] = mt.DIVERGED
        acc[T_STOP] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def next_attempt(settings, acc):
    """The step h (s) to attempt from acc[T], as SciPy's RK45 chooses it; 0.0 when the
    trajectory has ended (reached t_end, or failed: STATUS says which)."""
    if acc[STATUS] != mt.RUNNING:
        return 0.0
    t = acc[T]
    t_end = acc[T_FINAL]
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


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def next_attempts(W, L, H, FLAG, settings, n_run):
    """`next_attempt` across the lanes of a lock-step driver (W: the lanes' accumulators,
    slot k of lane l at W[k * L + l]) whose step is ordinary: running, before their own end
    (T_FINAL), within max_steps and far above the minimum step (10 ulps of t or
    solver.min_step), so SciPy's clamp and failure cannot apply: H[l] the step (s), FLAG[l]
    0. Other lanes get H[l] = 0 and FLAG[l] = 1 (the scalar `next_attempt`'s turn) and are
    left as they are. One loop of straight-line arithmetic across the lanes, which LLVM
    vectorises only where L is a compile-time constant: each driver's LANES (`literally`
    compiles one version for each)."""
    L = nb.literally(L)
    max_step = settings[MAX_STEP]
    max_steps = settings[MAX_STEPS]
    min_user = settings[MIN_STEP]
    for l in range(n_run):
        t_end = W[T_FINAL * L + l]
        t = W[T * L + l]
        h_abs = W[H_ABS * L + l]
        fresh = W[REJECTED_NOW * L + l] == 0.0
        h_try = min(h_abs, max_step) if fresh else h_abs
        ok = ((W[STATUS * L + l] == mt.RUNNING) & (t < t_end)
              & ((not fresh) | (W[STEPS * L + l] < max_steps))
              & (h_try > 1e-14 * t) & (h_try > min_user) & (h_try > 1e-300))
        t_new = min(t + h_try, t_end)
        h = t_new - t
        H[l] = h if ok else 0.0
        W[H_ABS * L + l] = abs(h) if ok else h_abs
        W[T_NEW * L + l] = t_new if ok else W[T_NEW * L + l]
        FLAG[l] = 0.0 if ok else 1.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def lane_moves(H, top, moves):
    """How a lock-step driver packs its running lanes (H[l] > 0: a step to attempt) among
    lanes 0..top-1 into the lowest ones, once its block has no more points to load (the
    vector loops then cover only those): moves[m] = (from, to), the highest running lane into
    the lowest idle one, for m < the count returned; and the lanes running, the new top."""
    running = 0
    for l in range(top):
        running += 1 if H[l] > 0.0 else 0
    m = 0
    k = top - 1
    for i in range(running):
        if H[i] > 0.0:
            continue
        while H[k] <= 0.0:
            k -= 1
        moves[m, 0] = k
        moves[m, 1] = i
        m += 1
        k -= 1
    return m, running


@nb.njit(cache=True, nogil=True, error_model="numpy")
def move_books(k, i, bufs, capacity, point):
    """A lane's books move with it (`lane_moves`): its extrema buffer, the buffer's rows and
    its point from lane k to lane i, lane k left without a point."""
    bufs[i] = bufs[k]
    capacity[i] = capacity[k]
    point[i] = point[k]
    point[k] = -1


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def settle(second, reals, counts):
    """A point's outputs (its rows of reals and counts) after its second pass, the run that
    tracked |q - final| against the band tol * amplitude (`second`, its accumulator): the
    settling time is the last time the trajectory was outside the band, and the pass's
    evaluations add to the first run's (as if done in one go). Returns the point's state,
    STEADY."""
    reals[SETTLING] = second[LAST_ABOVE]
    counts[EVALS_COLUMN] += int(second[RHS_EVALS])
    return mt.STEADY


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
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


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
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


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fsal_row(K):
    """The row of K that holds f(t + h, y_new): the last, or row dop853.N_STAGES of DOP853's
    extended K (whose rows after it are the dense output's extra stages)."""
    return dop853.N_STAGES if K.shape[0] == dop853.N_STAGES_EXTENDED else K.shape[0] - 1


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base, eighth):
    """Qc (2, QUARTIC_TERMS) for RK45, (2, DENSE_TERMS) for DOP853: the dense output of the
    accepted step from acc's state to (q_new, v_new), K its stage derivatives. `eighth`, the
    method's switch (None: RK45, True: DOP853, as settings[METHOD]; a switch, so a scene
    compiles one method's interpolants). RK45: its own quartic. DOP853 with the extended K
    (dop853.N_STAGES_EXTENDED rows: the one-mode drivers), rtol below
    dop853.SEVENTH_ORDER_BELOW_RTOL and a sine excitation or none: its own seventh-order
    interpolant, whose three extra right-hand sides are computed here (and counted); otherwise
    (a looser rtol, the modal drivers' midspan projection, or a random record, whose
    statistics, extrema and samples it serves as well at a step of a few samples: the
    spectra's bands agree to 5e-4, and the seventh order cost the spectra's samples 80 % more
    a step) the quintic Hermite interpolant (dop853.hermite_coefficients).
    p[o + column * s]: the point's prepared row."""
    if eighth is None:
        dense_coefficients(K, Qc)
    elif not _seventh_order(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base):
        dop853.hermite_coefficients(acc[Q], acc[V], acc[FV], q_new, v_new,
                                    K[fsal_row(K), 1], h, Qc)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _seventh_order_sine(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base):
    """DOP853's own seventh-order interpolant into Qc where `interpolant` takes it (the
    extended K, rtol below dop853.SEVENTH_ORDER_BELOW_RTOL), its three extra right-hand sides
    counted: returns whether it did. (fast None: the extra stages evaluate the row's own
    excitation (a sweep, a level table, the sweep's end), not the fixed sine the lanes'
    vector loop assumes.)"""
    if not (K.shape[0] == dop853.N_STAGES_EXTENDED
            and settings[RTOL] < dop853.SEVENTH_ORDER_BELOW_RTOL):
        return False
    dop853.dense_output(acc[T], acc[Q], acc[V], q_new, v_new, h, p, o, s, K, Qc, None,
                        parametric, base)
    acc[RHS_EVALS] += dop853.RHS_DENSE
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _hermite_only(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base):
    """A random record's interpolant is always the quintic Hermite (`interpolant`)."""
    return False


# the seventh order for the sine kinds or none; a record never compiles it (excitation.by_kind)
_seventh_order = ex.by_kind(_seventh_order_sine, _hermite_only)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _take_sample(acc, a, sa, src, dst, keep, take):
    """Sample slot src's fields into slot dst (ACC_SAMPLES layout), where `take`; its
    acceleration NaN unless `keep` (the samples are not consecutive steps' ends)."""
    old = acc[a + (dst + S_T) * sa]
    acc[a + (dst + S_T) * sa] = acc[a + (src + S_T) * sa] if take else old
    old = acc[a + (dst + S_Q) * sa]
    acc[a + (dst + S_Q) * sa] = acc[a + (src + S_Q) * sa] if take else old
    old = acc[a + (dst + S_V) * sa]
    acc[a + (dst + S_V) * sa] = acc[a + (src + S_V) * sa] if take else old
    old = acc[a + (dst + S_F) * sa]
    acc[a + (dst + S_F) * sa] = acc[a + (src + S_F) * sa] if take else old
    old = acc[a + (dst + S_A) * sa]
    acc[a + (dst + S_A) * sa] = (acc[a + (src + S_A) * sa] if keep else math.nan) if take else old


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def observe_acceleration(acc, a, sa, t_new, q_new, v_new, fv_new, a3, t_tail, take):
    """The Observer's base-excitation metric at an accepted step's end (t_new, s), where the
    state is (q_new m, v_new m/s, q'' = fv_new m/s^2) and the absolute midspan acceleration
    q'' + a_b is a3 (m/s^2), accumulator at acc[a + slot * sa] as `observe_step_end`'s: the
    tail's peak absolute midspan acceleration |q'' + a_b| (m/s^2) from the step-end samples
    (ACC_AMP), and the last three samples (ACC_SAMPLES). Where the middle one of three
    consecutive steps' ends is an extremum of q'' + a_b away from zero, ending in the tail
    window, ACC_TURN is set: the driver then calls `refine_acceleration_peak`, which finds the
    extremum between the samples. Only where `take`; straight-line selects (the lanes drivers
    run it in their vector loops, and refine the few lanes with a turn one by one). Returns
    whether it set ACC_TURN."""
    steps = acc[a + STEPS * sa]                # this step counted
    consecutive = acc[a + ACC_STEP * sa] == steps - 1.0
    middle = ACC_SAMPLES + SAMPLE_SIZE
    oldest = middle + SAMPLE_SIZE
    _take_sample(acc, a, sa, middle, oldest, consecutive, take)
    _take_sample(acc, a, sa, ACC_SAMPLES, middle, consecutive, take)
    newest = ACC_SAMPLES
    acc[a + (newest + S_T) * sa] = t_new if take else acc[a + (newest + S_T) * sa]
    acc[a + (newest + S_A) * sa] = a3 if take else acc[a + (newest + S_A) * sa]
    acc[a + (newest + S_Q) * sa] = q_new if take else acc[a + (newest + S_Q) * sa]
    acc[a + (newest + S_V) * sa] = v_new if take else acc[a + (newest + S_V) * sa]
    acc[a + (newest + S_F) * sa] = fv_new if take else acc[a + (newest + S_F) * sa]
    acc[a + ACC_STEP * sa] = steps if take else acc[a + ACC_STEP * sa]
    a1 = acc[a + (middle + S_A) * sa]
    a2 = acc[a + (oldest + S_A) * sa]
    turn = take & ((a1 - a2) * (a3 - a1) < 0.0) & ((a1 - a2) * a1 > 0.0) & (t_new > t_tail)
    acc[a + ACC_TURN * sa] = (1.0 if turn else 0.0) if take else acc[a + ACC_TURN * sa]
    amp = acc[a + ACC_AMP * sa]
    acc[a + ACC_AMP * sa] = max(amp, abs(a3) if take & (t_new >= t_tail) else 0.0)
    return turn


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def samples_interpolant(acc, a, sa):
    """The polynomial through q, q' and q'' at the last step-end samples (ACC_SAMPLES), written
    to the INTERP slots: Newton coefficients over x = (t - t_first) / span on the nodes
    0, 0, 0, x1, x1, x1, 1, 1, 1. With three consecutive samples (the oldest's
    acceleration not NaN) it is of degree 8 over the last two steps; otherwise the quintic
    Hermite interpolant of the last step (x1 = 1, the last three coefficients 0). Its q'' is
    far closer to the solution's than one step's quintic: for a sinusoid at omega h = 0.5 a
    step, 2.4e-8 of the peak against 2.9e-5. The divided differences are written out (nodes
    repeated three times: the first and second derivatives over their factorials)."""
    three = not math.isnan(acc[a + (ACC_SAMPLES + 2 * SAMPLE_SIZE + S_A) * sa])
    first = ACC_SAMPLES + (2 if three else 1) * SAMPLE_SIZE
    middle = ACC_SAMPLES + SAMPLE_SIZE
    t_first = acc[a + (first + S_T) * sa]
    span = acc[a + (ACC_SAMPLES + S_T) * sa] - t_first
    # q, q' span and q'' span^2 / 2 at the first node (0), the middle (x1) and the last (1)
    f0 = acc[a + (first + S_Q) * sa]
    d0 = acc[a + (first + S_V) * sa] * span
    s0 = 0.5 * acc[a + (first + S_F) * sa] * span * span
    f2 = acc[a + (ACC_SAMPLES + S_Q) * sa]
    d2 = acc[a + (ACC_SAMPLES + S_V) * sa] * span
    s2 = 0.5 * acc[a + (ACC_SAMPLES + S_F) * sa] * span * span
    if three:
        x1 = (acc[a + (middle + S_T) * sa] - t_first) / span
        f1 = acc[a + (middle + S_Q) * sa]
        d1 = acc[a + (middle + S_V) * sa] * span
        s1 = 0.5 * acc[a + (middle + S_F) * sa] * span * span
        r = 1.0 / x1                 # the node gaps' reciprocals: x1, 1 - x1 (and 1)
        u = 1.0 / (1.0 - x1)
        g01 = (f1 - f0) * r          # level 1 between distinct nodes
        g12 = (f2 - f1) * u
        # level 2: [s0, (g01 - d0) r, (d1 - g01) r, s1, (g12 - d1) u, (d2 - g12) u, s2]
        b1 = (g01 - d0) * r
        b2 = (d1 - g01) * r
        b4 = (g12 - d1) * u
        b5 = (d2 - g12) * u
        # level 3 (gaps x1, x1, x1, 1-x1, 1-x1, 1-x1)
        c0 = (b1 - s0) * r
        c1 = (b2 - b1) * r
        c2 = (s1 - b2) * r
        c3 = (b4 - s1) * u
        c4 = (b5 - b4) * u
        c5 = (s2 - b5) * u
        # level 4 (gaps x1, x1, 1, 1-x1, 1-x1)
        e0 = (c1 - c0) * r
        e1 = (c2 - c1) * r
        e2 = c3 - c2
        e3 = (c4 - c3) * u
        e4 = (c5 - c4) * u
        # level 5 (gaps x1, 1, 1, 1-x1)
        k0 = (e1 - e0) * r
        k1 = e2 - e1
        k2 = e3 - e2
        k3 = (e4 - e3) * u
        # levels 6-8 (gaps 1)
        m0 = k1 - k0
        m1 = k2 - k1
        m2 = k3 - k2
        n0 = m1 - m0
        n1 = m2 - m1
        coefficients = (f0, d0, s0, c0, e0, k0, m0, n0, n1 - n0)
    else:
        x1 = 1.0
        g = f2 - f0                  # nodes 0, 0, 0, 1, 1, 1
        b1 = g - d0
        b2 = d2 - g
        c0 = b1 - s0
        c1 = b2 - b1
        c2 = s2 - b2
        e0 = c1 - c0
        e1 = c2 - c1
        coefficients = (f0, d0, s0, c0, e0, e1 - e0, 0.0, 0.0, 0.0)
    for j in range(9):
        acc[a + (INTERP + j) * sa] = coefficients[j]
    acc[a + INTERP_T * sa] = t_first
    acc[a + INTERP_SPAN * sa] = span
    acc[a + INTERP_X1 * sa] = x1


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def absolute_acceleration_at(acc, a, sa, p, o, s, t, base):
    """q'' + a_b (m/s^2) at time t (s) on the samples' interpolant (`samples_interpolant`'s
    INTERP slots), a_b(t) exact (oscillator.base_acceleration of the row at
    p[o + column * s])."""
    span = acc[a + INTERP_SPAN * sa]
    x = (t - acc[a + INTERP_T * sa]) / span
    # Horner's scheme with the first two derivatives, node group by node group (1, x1, 0)
    value = acc[a + (INTERP + 8) * sa]
    d1 = 0.0
    d2 = 0.0
    for j in range(7, -1, -1):
        d = x - (1.0 if j >= 6 else (acc[a + INTERP_X1 * sa] if j >= 3 else 0.0))
        d2 = d2 * d + 2.0 * d1
        d1 = d1 * d + value
        value = value * d + acc[a + (INTERP + j) * sa]
    return d2 / (span * span) + base_acceleration(t, p, o, s, None, base)


PEAK_ITERATIONS = 6     # successive parabolas at most, refining an acceleration extremum
PEAK_VALUE_TOL = 1e-12  # ... until one changes the extremum's value by less than this fraction
                        # (1e-8 stopped short: 6.5e-9 off at rtol 1e-10, measured)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def refine_acceleration_peak(acc, a, sa, p, o, s, base):
    """Where `observe_acceleration` set ACC_TURN: the extremum of q'' + a_b between the oldest
    and newest of the last three step-end samples (two consecutive steps), found by successive
    parabolic interpolation on `absolute_acceleration_at` (the samples' degree-8 interpolant,
    a_b exact) starting from the three samples, so the value is the interpolant's, never a
    parabola's extrapolation. Raises ACC_AMP to the extremum's |value| where it lies in the
    tail window (from acc[T_TAIL]); clears ACC_TURN. p[o + column * s]: the row whose
    excitation block gives a_b."""
    acc[a + ACC_TURN * sa] = 0.0
    t_tail = acc[a + T_TAIL * sa]
    samples_interpolant(acc, a, sa)
    span = acc[a + INTERP_SPAN * sa]
    xc = acc[a + (ACC_SAMPLES + S_T) * sa]
    yc = acc[a + (ACC_SAMPLES + S_A) * sa]
    xb = acc[a + (ACC_SAMPLES + SAMPLE_SIZE + S_T) * sa]
    yb = acc[a + (ACC_SAMPLES + SAMPLE_SIZE + S_A) * sa]
    xa = acc[a + (ACC_SAMPLES + 2 * SAMPLE_SIZE + S_T) * sa]
    ya = acc[a + (ACC_SAMPLES + 2 * SAMPLE_SIZE + S_A) * sa]
    sign = 1.0 if yb > ya else -1.0           # a maximum of q'' + a_b, or a minimum
    best = 0.0
    for _ in range(PEAK_ITERATIONS):
        d1 = (yb - ya) / (xb - xa)
        curvature = ((yc - yb) / (xc - xb) - d1) / (xc - xa)
        if not sign * curvature < 0.0:
            break
        tv = 0.5 * (xa + xb) - 0.5 * d1 / curvature
        if not (xa < tv < xc) or tv == xb:
            break
        yv = absolute_acceleration_at(acc, a, sa, p, o, s, tv, base)
        if tv >= t_tail:
            best = max(best, abs(yv))
        gain = sign * (yv - yb)
        if gain > 0.0:
            if tv < xb:
                xc, yc = xb, yb
            else:
                xa, ya = xb, yb
            xb, yb = tv, yv
        elif tv < xb:
            xa, ya = tv, yv
        else:
            xc, yc = tv, yv
        if abs(gain) <= PEAK_VALUE_TOL * abs(yb):
            break
    acc[a + ACC_AMP * sa] = max(acc[a + ACC_AMP * sa], best)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def refine_marked_lanes(W, L, p, p_first, n_run):
    """`refine_acceleration_peak` for each of the first n_run lanes of a lock-step driver that
    `observe_acceleration` marked (ACC_TURN), one by one, outside the vector loops: lane j's
    accumulator at W[j + slot * L], its row at p[p_first + j + column * L]."""
    for j in range(n_run):
        if W[j + ACC_TURN * L] != 0.0:
            refine_acceleration_peak(W, j, L, p, p_first + j, L, True)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def observe_tail_start(acc, p, o, s, t_tail, t, q, v, fv, base):
    """The absolute acceleration |q'' + a_b| (m/s^2) where the tail window starts, at t_tail
    (s) inside the step just sampled, from t (s) where the state was (q m, q' = v m/s,
    q'' = fv m/s^2): the step-end samples and their refinement see only what lies after it.
    Read on the samples' interpolant, into ACC_AMP. Where the middle sample is not that step's
    start (the lanes sample only near the tail: a step that grew tenfold can straddle its start
    unsampled before), the step's start becomes the middle sample, the oldest none. A
    trajectory's own accumulator acc (record_step's); p[o + column * s] its row."""
    middle = ACC_SAMPLES + SAMPLE_SIZE
    if acc[middle + S_T] != t or math.isnan(acc[middle + S_A]):
        acc[middle + S_T] = t
        acc[middle + S_Q] = q
        acc[middle + S_V] = v
        acc[middle + S_F] = fv
        acc[middle + S_A] = fv + base_acceleration(t, p, o, s, None, base)
        acc[middle + SAMPLE_SIZE + S_A] = math.nan
    samples_interpolant(acc, 0, 1)
    at_start = absolute_acceleration_at(acc, 0, 1, p, o, s, t_tail, base)
    acc[ACC_AMP] = max(acc[ACC_AMP], abs(at_start))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=False, _nrt=False,
         inline=InlineWhereTrue(18))
def observe_step_end(acc, a, sa, p, o, s, t, h, t_new, q_new, v_new, fv_new, t_tail, track,
                     centre, thr_fixed, thr_rel, take, fast, base):
    """The Observer: what every accepted step's end adds to the metrics, for both drivers
    (`record_step`, and `kernels.lanes._finish` for the lanes' ordinary steps).

    The accumulator is read at acc[a + slot * sa], the prepared parameter row at
    p[o + column * s] (a trajectory's own arrays: a = o = 0, sa = s = 1; a lane of the lock-step
    driver: its offsets and the number of lanes). The step of size h (s) from t ends at t_new
    (the attempt's end as next_attempt set it) with q_new (m), q' = v_new (m/s) and
    q'' = fv_new (m/s^2).
    Updates, only where `take` (straight-line selects, so the lanes' loop vectorises): the
    running peak |q|; the tail window's max |q| and range
    (from t_tail, s); with `track`, the last time |q - centre| was above the threshold
    thr_fixed + thr_rel * peak (m); with base excitation (`base` True),
    `observe_acceleration` (`fast`: oscillator's switch for a_b; where it sets ACC_TURN the
    driver calls `refine_acceleration_peak` next, outside any vector loop).
    Returns (threshold, whether q_new is above it): record_step finds a crossing inside the
    step itself. Inlined where `fast` is True (the lanes' loop, which it must not stop
    vectorising), compiled once and called elsewhere (record_step: inlining its selects cost
    compile time in every caller; stages.InlineWhereTrue).
    """
    peak = acc[a + PEAK * sa]
    peak_new = max(peak, abs(q_new))
    in_tail = take & (t_new >= t_tail)
    acc[a + PEAK * sa] = peak_new if take else peak
    tail_amp = acc[a + TAIL_AMP * sa]
    tail_qmin = acc[a + TAIL_QMIN * sa]
    tail_qmax = acc[a + TAIL_QMAX * sa]
    acc[a + TAIL_AMP * sa] = max(tail_amp, abs(q_new)) if in_tail else tail_amp
    acc[a + TAIL_QMIN * sa] = min(tail_qmin, q_new) if in_tail else tail_qmin
    acc[a + TAIL_QMAX * sa] = max(tail_qmax, q_new) if in_tail else tail_qmax
    thr = thr_fixed + thr_rel * peak_new
    above = abs(q_new - centre) > thr
    last_above = acc[a + LAST_ABOVE * sa]
    acc[a + LAST_ABOVE * sa] = t + h if take & track & above else last_above
    if base is not None:
        _observe_base(acc, a, sa, p, o, s, t, h, t_new, q_new, v_new, fv_new, t_tail, take,
                      fast, base)
    return thr, above


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         inline=InlineWhereTrue(15))
def _observe_base(acc, a, sa, p, o, s, t, h, t_new, q_new, v_new, fv_new, t_tail, take, fast,
                  base):
    """`observe_step_end`'s base-excitation part: `observe_acceleration` with a_b(t + h) (fast:
    oscillator's switch). A function of its own, inlined only where `base` is the constant
    True: where it is None (lanes._finish, whose lanes get the metric from
    lanes._observe_acceleration) its branch is dead, and Numba does not copy it in before it
    prunes the branch."""
    observe_acceleration(acc, a, sa, t_new, q_new, v_new, fv_new,
                         fv_new + base_acceleration(t + h, p, o, s, fast, base), t_tail, take)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def record_step(p, o, s, settings, acc, K, q_new, v_new, h, Qc, buf, series, track, centre,
                thr_fixed, thr_rel, xe_known, qe_known, parametric, base, eighth):
    """Reduce the metrics of an accepted step [acc[T], acc[T_NEW]] on its dense output and
    advance the trajectory to its end. p[o + column * s]: the point's prepared row (its
    divergence bound on |q|, m, and base excitation); `buf` must have room for one more
    extremum (`with_room`).

    eighth: the method's switch (None: RK45, True: DOP853), for `interpolant`. The early stop
    (settings[STOP_STEADY]: solver.stop_when_steady) is read here, at a maximum, not passed
    as a switch: a switch's every value is a compile of the whole driver, and this test costs
    nothing measurable on the extrema it runs on.

    If the driver has already located the step's extremum of q, xe_known in [0, 1] is its
    x = (t - t_old)/h and qe_known q there; xe_known < 0 means: locate it here. The interpolant
    (Qc, `interpolant`) is built only when something needs it. What the step's end adds is
    `observe_step_end`'s; here are the events inside the step (an extremum, the tail's start,
    a threshold crossing, time-series samples).
    """
    t = acc[T]
    t_new = acc[T_NEW]
    q_old = acc[Q]
    v_old = acc[V]
    fv_old = acc[FV]
    t_tail = acc[T_TAIL]
    bound = p[o + BOUND * s]

    if not (abs(q_new) <= bound and math.isfinite(v_new)):
        acc[STATUS] = mt.DIVERGED
        acc[T_STOP] = t_new
        if math.isfinite(q_new) and abs(q_new) > bound and abs(q_old) <= bound:
            interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base,
                        eighth)
            side = 1.0 if q_new > 0.0 else -1.0
            acc[T_STOP] = t + dense_root(q_old, h, Qc[0], side * bound, 0.0, 1.0) * h
        return

    n_samples = series.shape[0]
    k = int(acc[SAMPLE])
    dt_sample = settings[SAMPLE_DT]
    has_ext = (v_old > 0.0 and v_new <= 0.0) or (v_old < 0.0 and v_new >= 0.0)
    have_qc = False
    xe = 0.0
    qe = 0.0
    if has_ext:
        if xe_known >= 0.0:
            xe = xe_known
            qe = qe_known
        else:
            interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base,
                        eighth)
            have_qc = True
            xe = dense_extremum(v_old, v_new, h, Qc[1])
            qe = dense_value(q_old, h, Qc[0], xe)
        te = t + xe * h
        kind = mt.MAXIMUM if v_old > 0.0 else mt.MINIMUM
        n_ext = int(acc[N_EXT])
        buf[n_ext, mt.EXT_T] = te
        buf[n_ext, mt.EXT_Q] = qe
        buf[n_ext, mt.EXT_KIND] = kind
        acc[N_EXT] = n_ext + 1
        acc[PEAK] = max(acc[PEAK], abs(qe))
        if te >= t_tail:
            acc[TAIL_AMP] = max(acc[TAIL_AMP], abs(qe))
            acc[TAIL_QMIN] = min(acc[TAIL_QMIN], qe)
            acc[TAIL_QMAX] = max(acc[TAIL_QMAX], qe)
        if (settings[STOP_STEADY] != 0.0 and kind == mt.MAXIMUM
                and acc[T_FINAL] == settings[T_END]):
            t_tail = _stop_when_steady(settings, acc, buf, te, qe, t_tail,
                                       p[o + DAMPING * s])

    if t < t_tail <= t_new:
        if not have_qc:
            interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base,
                        eighth)
            have_qc = True
        qt = dense_value(q_old, h, Qc[0], (t_tail - t) / h)
        acc[PEAK] = max(acc[PEAK], abs(qt))
        acc[TAIL_AMP] = max(acc[TAIL_AMP], abs(qt))
        acc[TAIL_QMIN] = min(acc[TAIL_QMIN], qt)
        acc[TAIL_QMAX] = max(acc[TAIL_QMAX], qt)

    thr, above = observe_step_end(acc, 0, 1, p, o, s, t, h, t_new, q_new, v_new,
                                  K[fsal_row(K), 1], t_tail, track, centre, thr_fixed,
                                  thr_rel, True, None, base)
    if base is not None:
        if acc[ACC_TURN] != 0.0:
            _refine_sine_peak(acc, 0, 1, p, o, s, base)
        if t < t_tail <= t_new:
            observe_tail_start(acc, p, o, s, t_tail, t, q_old, v_old, fv_old, base)
        _observe_record_step(settings, acc, p, o, s, t, t_new, q_old, v_old, fv_old, q_new,
                             v_new, K[fsal_row(K), 1], has_ext, qe, base)

    if track and not above:
        xa, xb, side = _above_bracket(q_old, q_new, has_ext, xe, qe, centre, thr)
        if xa >= 0.0:
            if not have_qc:
                interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric,
                            base, eighth)
                have_qc = True
            x = dense_root(q_old, h, Qc[0], centre + side * thr, xa, xb)
            acc[LAST_ABOVE] = t + x * h

    if k < n_samples and k * dt_sample <= t_new:
        if not have_qc:
            interpolant(p, o, s, settings, acc, K, q_new, v_new, h, Qc, parametric, base,
                        eighth)
            have_qc = True
        take_samples(acc, series, t, t_new, h, q_old, Qc, dt_sample)

    acc[T] = t_new
    acc[Q] = q_new
    acc[V] = v_new
    last = fsal_row(K)
    acc[FQ] = K[last, 0]
    acc[FV] = K[last, 1]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def take_samples(acc, series, t, t_new, h, q_old, Qc, dt_sample):
    """The time series' samples k dt_sample (s) that fall in the accepted step (t, t_new] of
    size h (s) from q_old (m), on its dense output Qc (`interpolant`), into series[k] (m), the
    next sample's index into acc[SAMPLE]."""
    k = int(acc[SAMPLE])
    n_samples = series.shape[0]
    while k < n_samples and k * dt_sample <= t_new:
        series[k] = dense_value(q_old, h, Qc[0], (k * dt_sample - t) / h)
        k += 1
    acc[SAMPLE] = k


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def take_hermite_samples(acc, series, t, t_new, h, q_old, v_old, a_old, q_new, v_new, a_new,
                         Qc, dt_sample):
    """The time series' samples (for the spectra) in an accepted step (t, t_new] of size h
    (s) that the lanes drivers keep off the scalar path, on DOP853's quintic Hermite through
    both ends' deflection (m), velocity (m/s) and acceleration (m/s^2), as record_step takes
    them through `interpolant` (take_samples into series, acc[SAMPLE] advanced; Qc: scratch).
    Does nothing when no sample is due in the step."""
    k = acc[SAMPLE]
    if not (k < series.shape[0] and k * dt_sample <= t_new):
        return
    dop853.hermite_coefficients(q_old, v_old, a_old, q_new, v_new, a_new, h, Qc)
    take_samples(acc, series, t, t_new, h, q_old, Qc, dt_sample)


def _quintic_basis() -> np.ndarray:
    """The quintic Hermite basis H_i (the polynomials of degree 5 with H_i's value, slope and
    second derivative at 0 and 1 the unit vector e_i, in the order value, slope, second
    derivative at 0, then at 1) as monomial coefficients: column i is H_i's."""
    conditions = np.zeros((6, 6))
    for k in range(6):                     # value, slope, second derivative of s^k at 0 and 1
        conditions[0, k] = 1.0 if k == 0 else 0.0
        conditions[1, k] = 1.0 if k == 1 else 0.0
        conditions[2, k] = 2.0 if k == 2 else 0.0
        conditions[3, k] = 1.0
        conditions[4, k] = float(k)
        conditions[5, k] = float(k * (k - 1))
    return np.linalg.inv(conditions)


def _quintic_gram() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, D, E): the Gram matrices over [0, 1] of the quintic Hermite basis H_i
    (`_quintic_basis`) and of their first and second derivatives: M_ij = int H_i H_j, D_ij =
    int H_i' H_j', E_ij = int H_i'' H_j''. From the monomials' exact integrals; computed once,
    at import."""
    basis = _quintic_basis()
    powers = np.arange(6)
    plain = 1.0 / (powers[:, None] + powers[None, :] + 1.0)
    slope = np.zeros((6, 6))
    curve = np.zeros((6, 6))
    for a in range(1, 6):
        for b in range(1, 6):
            slope[a, b] = a * b / (a + b - 1.0)
            if a >= 2 and b >= 2:
                curve[a, b] = a * (a - 1) * b * (b - 1) / (a + b - 3.0)
    return (basis.T @ plain @ basis, basis.T @ slope @ basis, basis.T @ curve @ basis)


_GRAM, _SLOPE_GRAM, _CURVE_GRAM = _quintic_gram()


def _quintic_midpoint_row() -> tuple[float, ...]:
    """The second derivatives at s = 1/2 of the quintic Hermite basis (`_quintic_basis`):
    q''(t + h/2) = sum_i row_i c_i / h^2, c = (q0, h v0, h^2 a0, q1, h v1, h^2 a1)."""
    second = np.array([k * (k - 1) * 0.5 ** (k - 2) if k >= 2 else 0.0 for k in range(6)])
    return tuple(float(x) for x in second @ _quintic_basis())


_MID = _quintic_midpoint_row()


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def quintic_midpoint_curvature(h, q0, v0, a0, q1, v1, a1):
    """q'' (m/s^2) at the middle of a step of h (s) on the quintic Hermite through q, q' = v
    and q'' = a at both ends (`_MID`)."""
    return (_MID[0] * q0 + _MID[1] * h * v0 + _MID[2] * h * h * a0 + _MID[3] * q1
            + _MID[4] * h * v1 + _MID[5] * h * h * a1) / (h * h)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _form(M, c0, c1, c2, c3, c4, c5):
    """c^T M c for the 6 x 6 matrix M, written out: a loop over a tuple's items indexes it at
    run time, which Numba compiles to a slow switch (277 ns for `quintic_squares` against 28
    written out, benchmarks/RESULTS.md)."""
    return (c0 * (M[0, 0] * c0 + M[0, 1] * c1 + M[0, 2] * c2 + M[0, 3] * c3 + M[0, 4] * c4
                  + M[0, 5] * c5)
            + c1 * (M[1, 0] * c0 + M[1, 1] * c1 + M[1, 2] * c2 + M[1, 3] * c3 + M[1, 4] * c4
                    + M[1, 5] * c5)
            + c2 * (M[2, 0] * c0 + M[2, 1] * c1 + M[2, 2] * c2 + M[2, 3] * c3 + M[2, 4] * c4
                    + M[2, 5] * c5)
            + c3 * (M[3, 0] * c0 + M[3, 1] * c1 + M[3, 2] * c2 + M[3, 3] * c3 + M[3, 4] * c4
                    + M[3, 5] * c5)
            + c4 * (M[4, 0] * c0 + M[4, 1] * c1 + M[4, 2] * c2 + M[4, 3] * c3 + M[4, 4] * c4
                    + M[4, 5] * c5)
            + c5 * (M[5, 0] * c0 + M[5, 1] * c1 + M[5, 2] * c2 + M[5, 3] * c3 + M[5, 4] * c4
                    + M[5, 5] * c5))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def quintic_squares(h, q0, v0, a0, q1, v1, a1):
    """The integrals over a step of length h (s) of q^2, q'^2 and q''^2 on the quintic
    Hermite through q, q' = v and q'' = a at both ends: (h c^T M c, c^T D c / h,
    c^T E c / h^3), c = (q0, h v0, h^2 a0, q1, h v1, h^2 a1), M, D, E `_quintic_gram`'s."""
    c1 = h * v0
    c2 = h * h * a0
    c4 = h * v1
    c5 = h * h * a1
    return (h * _form(_GRAM, q0, c1, c2, q1, c4, c5),
            _form(_SLOPE_GRAM, q0, c1, c2, q1, c4, c5) / h,
            _form(_CURVE_GRAM, q0, c1, c2, q1, c4, c5) / (h * h * h))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _up_zero(a, b):
    """1.0 where a monotone piece of q from a to b (m) crosses zero upwards, else 0.0."""
    return 1.0 if (a < 0.0) & (0.0 <= b) else 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _up_level(a, b, u):
    """1.0 where a monotone piece of q from a to b (m) takes |q| up through the level u (m):
    q up through u, or down through -u; else 0.0."""
    return 1.0 if ((a < u) & (u <= b)) | ((a > -u) & (-u >= b)) else 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def record_statistics(settings, acc, p, o, s, t, t_new, q_old, v_old, fv_old, q_new,
                      v_new, fv_new, has_ext, qe, base):
    """`observe_random` and `observe_level_crossings` for record_step's accepted step
    [t, t_new] (s) of a record, with the absolute acceleration at both ends (the newest
    sample's at t_new, the step before's end at t, evaluated here where there is none) and at
    its middle, and a_b's integrals over the step (`step_integrals`; a_b at both ends and
    middle and its integral are kept in STEP_AB for the modes' curvature squares). Call it after
    `observe_acceleration` has taken the step's end as its newest sample. (The one-mode lanes
    call the two observers in their own vector loops: kernels.lanes `_record_sums`.)"""
    if t < acc[T_TAIL]:
        return
    a_new = acc[ACC_SAMPLES + S_A]
    a_old = acc[ACC_SAMPLES + SAMPLE_SIZE + S_A]     # at t: the step before's end
    if math.isnan(a_old):
        a_old = fv_old + base_acceleration(t, p, o, s, None, base)
    ab_mid = base_acceleration(0.5 * (t + t_new), p, o, s, None, base)
    b1, b2 = step_integrals(acc, 0, 1, t, t_new, p, o, s, base)
    acc[STEP_AB] = a_old - fv_old
    acc[STEP_AB + 1] = ab_mid
    acc[STEP_AB + 2] = a_new - fv_new
    acc[STEP_AB + 3] = b1
    window = observe_random(acc, 0, 1, t, t_new, q_old, v_old, fv_old, q_new, v_new, fv_new,
                            a_old, a_new, ab_mid, b1, b2, has_ext, qe, True)
    for k in range(int(settings[N_LEVELS])):
        observe_level_crossings(settings, acc, 0, 1, k, q_old, qe, q_new, has_ext, window)


# record_step's kind-specific parts, each compiled only for its own kind (excitation.by_kind):
# a sine's acceleration peak refined, a record's statistics.
_refine_sine_peak = ex.by_kind(refine_acceleration_peak, None)
_observe_record_step = ex.by_kind(None, record_statistics)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def step_integrals(acc, a, sa, t, t_new, p, o, s, base):
    """The integrals of a_b and of a_b^2 over the step [t, t_new] (s) of a record's row
    (m/s, m^2/s^3; excitation.record_integrals: exact on the record's interpolant), the
    accumulator at acc[a + slot * sa]: those from 0 to t_new are kept (AT_END), so that the
    next step, which starts there, reads its start's instead of evaluating them again."""
    if acc[a + AT_END * sa] == t:
        first0, square0 = acc[a + (AT_END + 1) * sa], acc[a + (AT_END + 2) * sa]
    else:
        first0, square0 = ex.record_integrals(t, p, o + EXCITATION * s, s, base)
    first1, square1 = ex.record_integrals(t_new, p, o + EXCITATION * s, s, base)
    acc[a + AT_END * sa] = t_new
    acc[a + (AT_END + 1) * sa] = first1
    acc[a + (AT_END + 2) * sa] = square1
    return first1 - first0, square1 - square0


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def observe_random(acc, a, sa, t, t_new, q_old, v_old, fv_old, q_new, v_new, fv_new, a_old,
                   a_new, ab_mid, b1, b2, has_ext, qe, take):
    """The record kind's statistics of the accepted step [t, t_new] (s) of the watched
    deflection q (m; q' = v, q'' = fv at both ends, a the absolute acceleration q'' + a_b,
    m/s^2, at both ends, ab_mid a_b at the middle, b1 and b2 the integrals of a_b and a_b^2
    over the step: `step_integrals`; qe its extremum inside the step where has_ext),
    accumulator at acc[a + slot * sa] as `observe_step_end`'s, where `take` and the step
    starts at or after the tail window's start (returned: whether it did): the window's start
    and end, the integrals of q^2, q'^2 and q''^2 on the quintic Hermite through q, q', q''
    at both ends (`quintic_squares`), the accelerations' other parts (`acceleration_squares`:
    the integrals of q'' a_b, r^2 and r a_b by Simpson's rule, of a_b^2 exact), and the
    up-crossings of zero on the step's monotone pieces, q_old to qe to q_new (the levels':
    `observe_level_crossings`). Straight-line selects, so that the lanes' loop vectorises;
    adding 0.0 where not taken leaves a sum's bits as they were."""
    window = take & (t >= acc[a + T_TAIL * sa])
    opened = acc[a + IN_WINDOW * sa]
    acc[a + W_START * sa] = t if window & (opened == 0.0) else acc[a + W_START * sa]
    acc[a + IN_WINDOW * sa] = 1.0 if window else opened
    acc[a + W_END * sa] = t_new if window else acc[a + W_END * sa]
    h = t_new - t
    square, slope, curve = quintic_squares(h, q_old, v_old, fv_old, q_new, v_new, fv_new)
    ab_old = a_old - fv_old
    ab_new = a_new - fv_new
    r2, rb = carrier_step(fv_old, fv_new, v_old, v_new, acc[a + SHARE * sa], ab_old, ab_mid,
                          ab_new, b1, h)
    f_mid = quintic_midpoint_curvature(h, q_old, v_old, fv_old, q_new, v_new, fv_new)
    fb = h / 6.0 * (fv_old * ab_old + 4.0 * f_mid * ab_mid + fv_new * ab_new)
    acc[a + SUM_Q2 * sa] += square if window else 0.0
    acc[a + SUM_V2 * sa] += slope if window else 0.0
    acc[a + SUM_F2 * sa] += curve if window else 0.0
    acc[a + SUM_FB * sa] += fb if window else 0.0
    acc[a + SUM_R2 * sa] += r2 if window else 0.0
    acc[a + SUM_RB * sa] += rb if window else 0.0
    acc[a + SUM_B2 * sa] += b2 if window else 0.0
    up = (_up_zero(q_old, qe) + _up_zero(qe, q_new)) if has_ext else _up_zero(q_old, q_new)
    acc[a + UP_ZERO * sa] += up if window else 0.0
    return window


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def acceleration_squares(acc):
    """The integrals over a record's statistics window of the absolute acceleration's square,
    (q'' + a_b)^2, and of the relative one's, q''^2 (m^2/s^3), from `observe_random`'s parts.
    Each is a smooth part plus a multiple of a_b, whose square is integrated exactly on the
    record's interpolant; of the two smooth parts, r = q'' + G a_b (the span's own forces, G
    its participation: SHARE; q'' + a_b = r + (1 - G) a_b, q'' = r - G a_b) and q'' itself on
    the step's quintic Hermite (q'' + a_b = q'' + a_b), the smaller carries it
    (`carried_square`): r for a span below the spectrum's band, which the base moves while
    its own forces stay small (Simpson's rule on the whole square with steps long beside the
    record's samples read such a span's RMS 1.8 % low), q'' for a span above it, which
    follows the base (r is then nearly G a_b)."""
    g = acc[SHARE]
    f2, fb, r2, rb, b2 = acc[SUM_F2], acc[SUM_FB], acc[SUM_R2], acc[SUM_RB], acc[SUM_B2]
    relative = carried_square(f2, r2, rb, b2, g)
    if r2 <= f2:
        return max(r2 + 2.0 * (1.0 - g) * rb + (1.0 - g) ** 2 * b2, 0.0), relative
    return max(f2 + 2.0 * fb + b2, 0.0), relative


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def carrier_step(x_old, x_new, rate_old, rate_new, g, ab_old, ab_mid, ab_new, b1, h):
    """One step's integrals of r^2 and r a_b (Simpson's rule), r = x + g a_b the smooth part
    of a record's response's second derivative x (x_old, x_new at the step's ends; rate_old,
    rate_new its first derivative there; g its participation: x = r - g a_b), a_b at the
    step's ends and middle and its integral b1 over the step of h (s): r's middle value is
    the one its exact integral, rate_new - rate_old + g b1, gives with its ends."""
    r_old = x_old + g * ab_old
    r_new = x_new + g * ab_new
    r_mid = (6.0 * (rate_new - rate_old + g * b1) / h - r_old - r_new) / 4.0
    return (h / 6.0 * (r_old * r_old + 4.0 * r_mid * r_mid + r_new * r_new),
            h / 6.0 * (r_old * ab_old + 4.0 * r_mid * ab_mid + r_new * ab_new))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def carried_square(f2, r2, rb, b2, g):
    """The integral of x^2 over a record's window, x = r - g a_b a second derivative of its
    response: through r (its integrals r2 of r^2 and rb of r a_b, `carrier_step`, and b2 of
    a_b^2, exact) where r is the smaller part, else f2, x^2's integral on the steps' quintic
    Hermite (`acceleration_squares`)."""
    if r2 <= f2:
        return max(r2 - 2.0 * g * rb + g * g * b2, 0.0)
    return f2


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def observe_level_crossings(settings, acc, a, sa, k, q_old, qe, q_new, has_ext, window):
    """Level k's up-crossings of |q| through settings[LEVEL_0 + k] (m) on the step's monotone
    pieces, q_old to qe (its extremum, where has_ext) to q_new (m), into acc[a + (UP_LEVEL +
    k) * sa], where `window` (`observe_random`'s; a level grazed inside a step counts)."""
    u = settings[LEVEL_0 + k]
    up = (_up_level(q_old, qe, u) + _up_level(qe, q_new, u)) if has_ext else _up_level(
        q_old, q_new, u)
    acc[a + (UP_LEVEL + k) * sa] += up if window else 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _stop_when_steady(settings, acc, buf, te, qe, t_tail, damping):
    """At a maximum of q at te (s, q = qe m), with settings[STOP_STEADY]: if the extrema say
    the response is steady or has decayed (`metrics.steady_period`), move the trajectory's
    tail window to start here and end M periods later (M = settings[STEADY_PERIODS]), where
    the trajectory then ends, when that is before its end time: the tail's metrics restart
    from this maximum. Returns the tail window's start (s).

    Not before the start-up transient can have decayed to eps = settings[STEADY_TOL] of its
    size: te >= ln(1/eps) / (zeta w1), from `damping` = -2 zeta w1 (1/s, the prepared row's
    DAMPING; the slowest mode's). A lightly damped span near resonance beats slowly as it
    settles, and where the beat's envelope turns its extrema repeat for many periods while
    still 0.6 % short of the steady level (a reviewer's zeta = 0.002 span at 0.995 f1); the
    extrema alone cannot tell that turn from a steady state. A floor, not a proof: near a
    parametric tongue's edge or a jump a response settles slower than zeta w1. Undamped:
    never (no transient decays)."""
    eps = settings[STEADY_TOL]
    if not te * (-0.5 * damping) >= math.log(1.0 / eps):
        return t_tail
    period = mt.steady_period(buf, int(acc[N_EXT]), int(settings[STEADY_PERIODS]),
                              eps, acc[PEAK])
    end = te + settings[STEADY_PERIODS] * period
    if not (period > 0.0 and end < acc[T_FINAL]):
        return t_tail
    acc[T_TAIL] = te
    acc[T_FINAL] = end
    acc[TAIL_AMP] = abs(qe)
    acc[TAIL_QMIN] = qe
    acc[TAIL_QMAX] = qe
    acc[ACC_AMP] = 0.0
    return te


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def end_series(acc, series):
    """NaN for the samples a trajectory that stopped early never reached."""
    for j in range(int(acc[SAMPLE]), series.shape[0]):
        series[j] = math.nan
