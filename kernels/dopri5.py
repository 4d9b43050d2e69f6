"""Dormand-Prince 5(4) for the modal oscillator, step for step as SciPy's RK45.

The tableau, the error estimate, the RMS error norm, the initial-step selection and the
step-size controller are those of `scipy.integrate._ivp.rk.RK45` (SciPy 1.17), so that on the
same problem the kernel accepts and rejects the same steps as
``solve_ivp(method="RK45")`` up to round-off. The state is y = (q, q') in (m, m/s).

Solver (the tableau and `rk_step`), controller (`step_factor`) and dense output
(`dense_coefficients`, `dense_value`) are separate pieces.
"""

import math

import numba as nb
import numpy as np

from .oscillator import acceleration, stage_acceleration, step_anchor
from .vecmath import exp2_fast, log2_fast

# --- the tableau (Dormand & Prince 1980; dense output with Shampine's optimal c6) -------------
N_STAGES = 6
ERROR_ESTIMATOR_ORDER = 4
RHS_PER_ATTEMPT = N_STAGES       # stages 2..6 and f(t + h, y_new)
C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0])
A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
])
B = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84])
E = np.array([-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
P = np.array([
    [1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
    [0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0.0, 127303824393 / 49829197408, -318862633887 / 49829197408,
     701980252875 / 199316789632],
    [0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
])

# --- the controller (SciPy's constants) -------------------------------------------------------
SAFETY = 0.9          # multiply asymptotic step estimates by this
MIN_FACTOR = 0.2      # smallest allowed step decrease
MAX_FACTOR = 10.0     # largest allowed step increase
ERROR_EXPONENT = -1.0 / (ERROR_ESTIMATOR_ORDER + 1)

# --- an optional PI controller (Gustafsson 1991, in Hairer & Wanner's DOPRI5 form) -------------
PI_BETA = 0.08                        # weight of the previous accepted step's error
PI_ALPHA = 0.2 - 0.75 * PI_BETA       # weight of this attempt's error (0.14)
PI_MIN_ERR_PREV = 1e-4                # floor on the previous error (Hairer's facold)
MIN_RTOL = 100 * np.finfo(float).eps   # SciPy raises smaller rtol to this


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def explicit_rk_step(t, y, h, p, K, y_new, A, B, C, parametric, base):
    """One step of size h (s) from (t, y) of the explicit Runge-Kutta method with tableau
    (A, B, C), as SciPy's `rk_step`; K[0] must hold f(t, y). p: a prepared parameter row
    (oscillator.prepare); base: oscillator's base-excitation switch (None or True).

    Fills K[1..n_stages - 1] with the stage derivatives, K[n_stages] with f(t + h, y_new), and
    y_new with the solution (weights B). n_stages right-hand-side evaluations.
    """
    n_stages = B.shape[0]
    anchor = step_anchor(t, h, p, 0, 1, base)
    for s in range(1, n_stages):
        dq = 0.0
        dv = 0.0
        for j in range(s):
            dq += K[j, 0] * A[s, j]
            dv += K[j, 1] * A[s, j]
        q = y[0] + dq * h
        v = y[1] + dv * h
        K[s, 0] = v
        K[s, 1] = stage_acceleration(t, C[s] * h, q, v, p, 0, 1, anchor, parametric, base)
    sq = 0.0
    sv = 0.0
    for j in range(n_stages):
        sq += K[j, 0] * B[j]
        sv += K[j, 1] * B[j]
    y_new[0] = y[0] + h * sq
    y_new[1] = y[1] + h * sv
    K[n_stages, 0] = y_new[1]
    K[n_stages, 1] = stage_acceleration(t, h, y_new[0], y_new[1], p, 0, 1, anchor, parametric,
                                        base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def rk_step(t, y, h, p, K, y_new, parametric, base):
    """One Dormand-Prince step of size h (s) from (t, y); K[0] must hold f(t, y).

    Fills K[1..6] with the stage derivatives (K[6] = f(t + h, y_new)) and y_new with the
    fifth-order solution. Six right-hand-side evaluations.
    """
    explicit_rk_step(t, y, h, p, K, y_new, A, B, C, parametric, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def error_norm(K, h, y, y_new, rtol, atol_q, atol_v):
    """SciPy's RMS norm of the embedded error estimate, scaled by atol + rtol max(|y|, |y_new|)
    per component: atol_q (m) for q, atol_v (m/s) for q' (SciPy's atol as a 2-vector)."""
    eq = 0.0
    ev = 0.0
    for j in range(N_STAGES + 1):
        eq += K[j, 0] * E[j]
        ev += K[j, 1] * E[j]
    eq *= h
    ev *= h
    sq = atol_q + max(abs(y[0]), abs(y_new[0])) * rtol
    sv = atol_v + max(abs(y[1]), abs(y_new[1])) * rtol
    rq = eq / sq
    rv = ev / sv
    return math.sqrt(rq * rq + rv * rv) / math.sqrt(2.0)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def step_factor(err, rejected_before, exponent):
    """SciPy's step-size factor for an error norm `err`; `exponent` is -1/(order + 1) of the
    method's error estimator (ERROR_EXPONENT: -1/5 for RK45, dop853.ERROR_EXPONENT: -1/8).

    Accepted (err < 1): min(MAX_FACTOR, SAFETY err^exponent), capped at 1 after a rejection.
    Rejected: max(MIN_FACTOR, SAFETY err^exponent); a non-finite error gives MIN_FACTOR.
    """
    if err < 1.0:
        if err == 0.0:
            factor = MAX_FACTOR
        else:
            factor = min(MAX_FACTOR, SAFETY * err ** exponent)
        if rejected_before:
            factor = min(1.0, factor)
        return factor
    factor = SAFETY * err ** exponent
    if not factor > MIN_FACTOR:          # also catches NaN
        factor = MIN_FACTOR
    return factor


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def pi_step_factor(err, log2_err_prev, rejected_before):
    """Step-size factor of the PI controller (vectorisable; both drivers use this function).

    Accepted (err < 1): SAFETY err^-PI_ALPHA err_prev^PI_BETA within [MIN_FACTOR, MAX_FACTOR],
    capped at 1 right after a rejection; err_prev is the previous accepted step's error, at
    least PI_MIN_ERR_PREV, given as its log2 (`pi_log2_err`). Rejected:
    max(MIN_FACTOR, SAFETY err^-PI_ALPHA); a non-finite error gives MIN_FACTOR.
    Powers to ~1e-9 (vecmath.exp2_fast / log2_fast): ample for a step-size factor.
    """
    log_err = log2_fast(min(max(err, 1e-18), 1e18))
    accepted = err < 1.0
    y = -PI_ALPHA * log_err + (PI_BETA * log2_err_prev if accepted else 0.0)
    factor = SAFETY * exp2_fast(min(max(y, -30.0), 30.0))
    accept = min(MAX_FACTOR, max(MIN_FACTOR, factor))
    accept = min(1.0, accept) if rejected_before else accept
    reject = max(MIN_FACTOR, factor)
    reject = MIN_FACTOR if err != err else reject
    return accept if accepted else reject


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def pi_log2_err(err):
    """log2 of an accepted step's error for the PI controller's memory (floored at
    PI_MIN_ERR_PREV)."""
    return log2_fast(max(err, PI_MIN_ERR_PREV))


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _rms2(a, b):
    return math.sqrt(a * a + b * b) / math.sqrt(2.0)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def initial_step(t0, y, f, t_bound, max_step, rtol, atol_q, atol_v, p, o, s, order, parametric,
                 base):
    """SciPy's `select_initial_step` (Hairer, Norsett & Wanner, Sec. II.4) for a method whose
    error estimator has order `order` (ERROR_ESTIMATOR_ORDER for RK45); absolute tolerances
    atol_q (m) and atol_v (m/s); the prepared row at p[o + column * s]
    (oscillator.acceleration). One evaluation."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    sq = atol_q + abs(y[0]) * rtol
    sv = atol_v + abs(y[1]) * rtol
    d0 = _rms2(y[0] / sq, y[1] / sv)
    d1 = _rms2(f[0] / sq, f[1] / sv)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, interval)
    q1 = y[0] + h0 * f[0]
    v1 = y[1] + h0 * f[1]
    fq1 = v1
    fv1 = acceleration(t0 + h0, q1, v1, p, o, s, None, parametric, base)
    d2 = _rms2((fq1 - f[0]) / sq, (fv1 - f[1]) / sv) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100.0 * h0, h1, interval, max_step)


DENSE_TERMS = 7     # columns of an interpolant's coefficient array: up to degree 7 in x
QUARTIC_TERMS = 4   # columns of RK45's own: its quartic (its drivers allocate no more)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def dense_coefficients(K, Q):
    """Q[:, :4] = K^T P: the quartic interpolant of the last step. Q has shape (2,
    QUARTIC_TERMS), or (2, DENSE_TERMS), the layout of DOP853's seventh-order interpolant
    (dop853.dense_output), with Q[:, 4:] = 0."""
    for i in range(2):
        for k in range(4):
            s = 0.0
            for j in range(N_STAGES + 1):
                s += K[j, i] * P[j, k]
            Q[i, k] = s
        for k in range(4, Q.shape[1]):
            Q[i, k] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def dense_value(y_old_i, h, c, x):
    """One component of the interpolant at x = (t - t_old)/h in [0, 1]: y_old_i its value at
    the step's start, c its row of dense_coefficients or dop853's (Q[i]): a quartic when c
    has QUARTIC_TERMS entries (the same value as the degree-7 sum with zeros above x^4)."""
    if c.shape[0] == QUARTIC_TERMS:
        return y_old_i + h * (x * (c[0] + x * (c[1] + x * (c[2] + x * c[3]))))
    return y_old_i + h * (x * (c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * (
        c[4] + x * (c[5] + x * c[6])))))))


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def dense_root(y_old_i, h, c, target, xa, xb):
    """x in [xa, xb] where one component of the interpolant (row c = Q[i] of
    dense_coefficients) equals `target`.

    Requires a bracket: the values at xa and xb lie on opposite sides of `target` (or the one
    at xb equals it). Illinois false position with bisection as a guard; converges to a few
    ulps of x.
    """
    fa = dense_value(y_old_i, h, c, xa) - target
    fb = dense_value(y_old_i, h, c, xb) - target
    if fb == 0.0:
        return xb
    if fa == 0.0:
        return xa
    side = 0
    for _ in range(100):
        if xb - xa <= 4e-16 * max(1.0, abs(xb)):
            break
        x = xb - fb * (xb - xa) / (fb - fa)
        if not (xa < x < xb):
            x = 0.5 * (xa + xb)
        fx = dense_value(y_old_i, h, c, x) - target
        if fx == 0.0:
            return x
        if (fx > 0.0) == (fb > 0.0):
            xb = x
            fb = fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            xa = x
            fa = fx
            if side == 1:
                fb *= 0.5
            side = 1
    return 0.5 * (xa + xb)


EXTREMUM_NEWTON_STEPS = 4     # Newton steps `dense_extremum` takes before it falls back to
EXTREMUM_RESIDUAL = 1e-14     # dense_root; |q'(x)| / (|q'_old| + |q'_new|) that ends them


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def dense_extremum(v_old, v_new, h, c):
    """x in [0, 1] where the interpolated q' (row c = Q[1] of an interpolant; v_old, v_new: q'
    at the step's ends, of opposite signs or v_new = 0) vanishes: Newton's method from the
    linear guess, kept inside the sign bracket, until the residual is at round-off
    (EXTREMUM_RESIDUAL); where EXTREMUM_NEWTON_STEPS do not get there, `dense_root` on the
    bracket left. A few evaluations of the interpolant where the bracketed root finder alone
    takes ten or more."""
    positive = v_old > 0.0
    xa = 0.0
    xb = 1.0
    x = v_old / (v_old - v_new) if v_old != v_new else 0.5
    x = x if 0.0 <= x <= 1.0 else 0.5
    small = EXTREMUM_RESIDUAL * (abs(v_old) + abs(v_new))
    for _ in range(EXTREMUM_NEWTON_STEPS):
        g = dense_value(v_old, h, c, x)
        if abs(g) <= small:
            return x
        if c.shape[0] == QUARTIC_TERMS:
            dg = h * (c[0] + x * (2.0 * c[1] + x * (3.0 * c[2] + x * (4.0 * c[3]))))
        else:
            dg = h * (c[0] + x * (2.0 * c[1] + x * (3.0 * c[2] + x * (4.0 * c[3] + x * (
                5.0 * c[4] + x * (6.0 * c[5] + x * 7.0 * c[6]))))))
        if (g > 0.0) == positive:
            xa = x
        else:
            xb = x
        x_new = x - g / dg if dg != 0.0 else 0.5 * (xa + xb)
        x = x_new if xa < x_new < xb else 0.5 * (xa + xb)
    return dense_root(v_old, h, c, 0.0, xa, xb)
