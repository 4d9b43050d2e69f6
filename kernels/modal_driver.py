"""Scalar driver of the multi-mode System (kernels.modes): one trajectory after another.

The state is y = (q_1..q_N, q_1'..q_N') (m, m/s). Each step is SciPy's RK45 or DOP853 on the
whole state (the tableaux of kernels.dopri5 and kernels.dop853, looped over as SciPy's
`rk_step` does), with SciPy's RMS error norm over its 2N components and SciPy's controller, so
the attempts are those of solve_ivp on the same system.

The metrics are the one-mode trajectory's (kernels.trajectory, the same accumulator and the
same Observer) applied to the midspan deflection q_mid = sum q_n phi_n(1/2): every
Runge-Kutta stage, solution and dense output is linear in the state, so the step's stage
derivatives projected on q_mid (K_mid) are exactly the stages of q_mid, and its interpolants
(RK45's quartic, DOP853's quintic Hermite) are exactly those of q_mid. On top, each mode's
tail amplitude max |q_n| (step ends, the tail's start and every extremum of q_n located on its
own interpolant), the span's largest deflection max |w(x, t)| (every step of the tail window
that can hold a larger one searched in time and place: `observe_span`) and a divergence test
on every mode (a mode with no midspan deflection, an even one, can grow unseen at midspan).

Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import dop853
from . import excitation as ex
from . import dopri5
from . import metrics as mt
from . import modes as md
from . import oscillator as osc
from . import trajectory as tj
from .flags import CONTRACT
from .layout import (AMPLITUDE, CLAMP_BEND, CLAMP_SHEAR, CURVATURE_M0, FAILURE_TIME,
                     FIRST_STEP, MAX_STEP, LOADS, METHOD, MID_BEND, N_COUNTS, N_REALS, PEAK, PERIOD, RHS_EVALS, RTOL, SETTLING,
                     SPAN_MAX, SPAN_PLACE, STRETCH, SWEPT, TAIL, TOL, T_END, WANT_SETTLING)
from .transverse import classify_metrics, swept_outputs

NODE = 1e-9          # a mode whose |phi(1/2)| is below this (shapes of unit scale) has a node
                     # at midspan
HIDDEN_FLOOR = 1e-9  # such a mode is judged (`span_state`) above this x the largest mode's peak:
                     # growing, it would reach any level (an even mode seeded by round-off
                     # stays below)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def observer_row(row, n_modes, pp):
    """The oscillator-layout row (kernels.oscillator columns) the trajectory module's Observer
    reads for the midspan deflection: its divergence bound, scales and base excitation, and
    the first mode's damping from the prepared row pp (-2 zeta w_1, 1/s: the early stop's
    decay time)."""
    p = np.zeros(osc.N_PARAMS)
    p[osc.MASS] = 1.0
    p[osc.DAMPING] = pp[md.P_DAMPING * n_modes]
    p[osc.BOUND] = row[md.BOUND]
    p[osc.Q_SCALE] = row[md.Q_SCALE]
    p[osc.V_SCALE] = row[md.V_SCALE]
    for c in range(ex.SIZE):
        p[osc.EXCITATION + c] = row[md.EXCITATION + c]
    p[osc.PARTICIPATION] = row[md.PARTICIPATION]
    return p


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def valid(row, n_modes):
    """Whether a raw multi-mode row can be integrated: finite, w1^2 > 0 and bound > 0."""
    for j in range(md.n_columns(n_modes)):
        if not math.isfinite(row[j]):
            return False
    return row[md.W1_SQ] > 0.0 and row[md.BOUND] > 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")
def _project(v, weights, offset, n):
    """sum_i weights[i] v[offset + i]."""
    s = 0.0
    for i in range(n):
        s += weights[i] * v[offset + i]
    return s


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _project_stages(K, weights, n, n_stages, K_mid):
    """K_mid[j] = the midspan's (deflection, velocity) rates of stage j (K's rows projected on
    the weights by `_project`), j = 0..n_stages. Uncounted, so its rows K[j] cost no
    reference counts (the counted integrate loop paid two a stage)."""
    for j in range(n_stages + 1):
        K_mid[j, 0] = _project(K[j], weights, 0, n)
        K_mid[j, 1] = _project(K[j], weights, n, n)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _next_step(y, y_new, K, dim, n_stages):
    """The accepted step's end as the next step's start: y = y_new, K[0] = K[n_stages] (a
    loop: a slice assignment within one array may copy, which needs Numba's allocator)."""
    for i in range(dim):
        y[i] = y_new[i]
        K[0, i] = K[n_stages, i]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def rk_step(t, y, h, S, n_modes, T, K, y_new, stage, A, B, C, base):
    """One step of size h (s) of the explicit tableau (A, B, C) from (t, y), SciPy's
    `rk_step` on the 2N-component state; K[0] must hold f(t, y). Fills K[1..n_stages] (the
    last: f(t + h, y_new)) and y_new. S: the right-hand side's scratch (modes.scratch); stage:
    scratch of length 2N."""
    n_stages = B.shape[0]
    dim = 2 * n_modes
    for s in range(1, n_stages + 1):   # the stages, then f(t + h, y_new): one call site, as
        last = s == n_stages            # md.derivative is inlined (forceinline) where called
        X = y_new if last else stage
        for i in range(dim):
            d = 0.0
            if last:
                for j in range(n_stages):
                    d += K[j, i] * B[j]
            else:
                for j in range(s):
                    d += K[j, i] * A[s, j]
            X[i] = y[i] + d * h
        md.derivative(t + h if last else t + C[s] * h, X, K[s], S, n_modes, T, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def error_norm(K, h, y, y_new, rtol, atol_q, atol_v, n_modes, eighth):
    """SciPy's error norm of the attempt over all 2N components: RK45's RMS of h K^T E / scale,
    or DOP853's combination of its fifth- and third-order estimates; scale = atol +
    rtol max(|y|, |y_new|), atol_q (m) for displacements, atol_v (m/s) for velocities."""
    dim = 2 * n_modes
    e_a = 0.0
    e_b = 0.0
    for i in range(dim):
        atol = atol_q if i < n_modes else atol_v
        scale = atol + max(abs(y[i]), abs(y_new[i])) * rtol
        if eighth:
            s5 = 0.0
            s3 = 0.0
            for j in range(K.shape[0]):
                s5 += K[j, i] * dop853.E5[j]
                s3 += K[j, i] * dop853.E3[j]
            e_a += (s5 / scale) ** 2
            e_b += (s3 / scale) ** 2
        else:
            s = 0.0
            for j in range(K.shape[0]):
                s += K[j, i] * dopri5.E[j]
            e_a += (s * h / scale) ** 2
    if eighth:
        if e_a == 0.0 and e_b == 0.0:
            return 0.0
        return abs(h) * e_a / math.sqrt((e_a + dop853.ERR3_WEIGHT * e_b) * dim)
    return math.sqrt(e_a / dim)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def initial_step(y, f, t_end, max_step, rtol, atol_q, atol_v, order, S, n_modes, T, base):
    """SciPy's `select_initial_step` on the 2N-component state from t = 0 (f = f(0, y)).
    One evaluation."""
    dim = 2 * n_modes
    if t_end == 0.0:
        return 0.0
    d0 = 0.0
    d1 = 0.0
    for i in range(dim):
        scale = (atol_q if i < n_modes else atol_v) + abs(y[i]) * rtol
        d0 += (y[i] / scale) ** 2
        d1 += (f[i] / scale) ** 2
    d0 = math.sqrt(d0 / dim)
    d1 = math.sqrt(d1 / dim)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end)
    y1 = np.empty(dim)
    f1 = np.empty(dim)
    for i in range(dim):
        y1[i] = y[i] + h0 * f[i]
    md.derivative_call(h0, y1, f1, S, n_modes, T, base)
    d2 = 0.0
    for i in range(dim):
        scale = (atol_q if i < n_modes else atol_v) + abs(y[i]) * rtol
        d2 += ((f1[i] - f[i]) / scale) ** 2
    d2 = math.sqrt(d2 / dim) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100.0 * h0, h1, t_end, max_step)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _mode_interpolant(y, y_new, K, h, i, n_modes, eighth, Km, Qm):
    """Qm (2, 5): mode i's dense output over the accepted step (RK45's quartic from the stages,
    DOP853's quintic Hermite), in dopri5.dense_coefficients' layout; Km (n_stages + 1, 2) is
    scratch."""
    last = K.shape[0] - 1
    if eighth:
        dop853.hermite_coefficients(y[i], y[n_modes + i], K[0, n_modes + i], y_new[i],
                                    y_new[n_modes + i], K[last, n_modes + i], h, Qm)
    else:
        for j in range(K.shape[0]):
            Km[j, 0] = K[j, i]
            Km[j, 1] = K[j, n_modes + i]
        dopri5.dense_coefficients(Km, Qm)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def modal_size(n_modes):
    """Length of the modes' accumulator `modal` of both multi-mode drivers: each mode's tail
    amplitude max |q_n| over the tail window (slots 0..N-1, m), each mode's peak max |q_n| at
    the accepted steps' ends over the whole run (N..2N-1, m), the largest deflection over
    the span in the tail window (slot 2N, m; `observe_span`), N unused slots (2N + 1..3N,
    0; they held the mode shapes at the place of slot 2N's deflection), the
    largest |sum phi_n''(s) q_n| at each clamp s = 0, 1 and at midspan s = 1/2 in the tail
    window (clamp_slot(N) + 0, 1, 2, m: the curvature there times l^2; `_observe_bends`),
    the largest stretch E and clamp shears |F_0|, |F_1| there (load_slot(N) + 0, 1, 2;
    kernels.modes.span_loads; `_observe_loads`), the shear factor kappa of the point's
    prepared row (factor_slot(N), 1/m^2, kernels.modes.shear_factor) and whether the loads
    are observed at all (factor_slot(N) + 1: settings[LOADS], 1.0 or 0.0), both set by
    `start`; under a random base acceleration with the loads observed, the integrals over the
    statistics window of c_e^2, c_e'^2 and c_e''^2 for the clamp at s = 0 and midspan
    (square_slot(N) + 0..2, + 3..5; m^2 s, m^2/s, m^2/s^3; `_observe_bend_squares`); the end
    load's factors for the clamp's reaction (end_load_slot(N) + 0..3: kernels.modes
    `end_load_factors`); the base inertia's factor for it (inertia_slot(N), s^2:
    kernels.modes.inertia_factor; 0 without base excitation); the place of slot 2N's
    deflection, x* / l (place_slot(N); 1/2 until one is found); the other carrier of the
    curvatures' second derivatives under a random base acceleration (carrier_slot(N) + 0..5)."""
    return 3 * n_modes + 27


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def observer_scratch(n_modes):
    """Length of the observers' scratch qx: the modes' values at an instant (0..N-1, for
    `observe_span`; N..N+7: its `_span_spread`'s), then `_observe_loads`' (N..3N-1: q and
    its rate there; then three blocks of 6: kernels.modes.span_loads at the step's start,
    end and inside)."""
    return 3 * n_modes + 18


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def clamp_slot(n_modes):
    """The first of the three curvature slots of the modes' accumulator (`modal_size`): the
    clamps at s = 0 and 1, then midspan (kernels.modes BEND_0, BEND_1, BEND_MID)."""
    return 3 * n_modes + 1


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def load_slot(n_modes):
    """The first of the three load slots of the modes' accumulator (`modal_size`): the
    largest stretch E and clamp shears |F_0|, |F_1| in the tail window (kernels.modes.span_loads)."""
    return 3 * n_modes + 4


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def factor_slot(n_modes):
    """The slot of the shear factor kappa (kernels.modes.shear_factor) in the accumulator."""
    return 3 * n_modes + 7


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def end_load_slot(n_modes):
    """The first of the end load's four factors in the accumulator (kernels.modes
    `end_load_factors`: its P l^2 / EI mean and cosine amplitude, W, phi_W)."""
    return 3 * n_modes + 15


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def inertia_slot(n_modes):
    """The slot of the base inertia's factor (kernels.modes.inertia_factor) in the
    accumulator."""
    return 3 * n_modes + 19


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def place_slot(n_modes):
    """The slot of x* / l, the place of the span's largest deflection (slot 2N), in the
    accumulator."""
    return 3 * n_modes + 20


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def carrier_slot(n_modes):
    """The first of the six slots of the other carrier of the curvatures' second derivatives
    (`_observe_bend_squares`): for the clamp (k = 0) and midspan (k = 1) the integrals of
    r_k^2 and r_k a_b (carrier_slot + 2 k, + 2 k + 1; m^2/s^3), r_k = c_k'' + G_k a_b, and
    G_k (carrier_slot + 4 + k: sum_n phi_n''(s) Gamma_n times l^2, m; set by `start`)."""
    return 3 * n_modes + 21


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=False, _nrt=False)
def inertia_at(factor, t, p1, base):
    """(inertia, its rate) (m, m/s) for kernels.modes.span_loads at t (s): `factor` (the
    accumulator's, kernels.modes.inertia_factor, s^2) times a_b(t) and a_b'(t) of the
    Observer row p1 (`observer_row`: the base excitation block, any kind;
    kernels.excitation.signal_and_rate). (0, 0) without base excitation."""
    if base is None:
        return 0.0, 0.0
    if factor == 0.0:
        return 0.0, 0.0
    a, rate = ex.signal_and_rate(t, p1, osc.EXCITATION, 1, base)
    return factor * a, factor * rate


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def end_load_at(modal, n_modes, t):
    """(P l^2 / EI, its rate) of the end load at t (s), from the accumulator's factors."""
    s = end_load_slot(n_modes)
    return md.end_load(modal[s], modal[s + 1], modal[s + 2], modal[s + 3], t)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def state_loads(rows, coupling, q, v, n_modes, modal, t, p1, base, out):
    """kernels.modes.span_loads of the modes' state (q, v) at t (s), its shear factor, end load
    and base inertia read from the modes' accumulator `modal` (`modal_size`; a lane's column
    in the lanes driver) and the Observer row p1 (`inertia_at`): what every load observer of
    both multi-mode drivers calls. rows, coupling: the basis' CLAMPS and COUPLING."""
    load, rate = end_load_at(modal, n_modes, t)
    inertia, inertia_rate = inertia_at(modal[inertia_slot(n_modes)], t, p1, base)
    md.span_loads(rows, coupling, q, v, n_modes, modal[factor_slot(n_modes)], load, rate,
                  inertia, inertia_rate, out)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def square_slot(n_modes):
    """The first of the six curvature-square integrals of the modes' accumulator
    (`modal_size`)."""
    return 3 * n_modes + 9


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _observe_bend_squares(y, y_new, f, f_new, h, n, curvature, modal, acc):
    """The accepted step's integrals of c^2, c'^2 and c''^2 for the clamp's curvature at
    s = 0 and midspan's (kernels.modes BEND_0, BEND_MID; c = sum phi_n''(s) q_n, times l^2:
    m), on the quintic Hermite through c, c' and c'' at both ends (trajectory's, as the
    midspan's mean squares): f, f_new the right-hand side at the step's ends (q_n'' =
    f[N + n]); curvature: the basis' CLAMPS rows. And the other carrier of c'', r = c'' +
    G a_b (`carrier_slot`), as trajectory.observe_random's for the midspan: the integrals of
    r^2 and r a_b by Simpson's rule through the middle value of r that its exact integral
    gives, from the step's a_b that trajectory.record_statistics kept in acc (STEP_AB)."""
    slot = square_slot(n)
    other = carrier_slot(n)
    ab_old = acc[tj.STEP_AB]
    ab_mid = acc[tj.STEP_AB + 1]
    ab_new = acc[tj.STEP_AB + 2]
    b1 = acc[tj.STEP_AB + 3]
    for k in range(2):
        e = md.BEND_0 if k == 0 else md.BEND_MID
        c0 = 0.0
        c1 = 0.0
        r0 = 0.0
        r1 = 0.0
        a0 = 0.0
        a1 = 0.0
        for c in range(n):
            w = curvature[e, c]
            c0 += w * y[c]
            c1 += w * y_new[c]
            r0 += w * y[n + c]
            r1 += w * y_new[n + c]
            a0 += w * f[n + c]
            a1 += w * f_new[n + c]
        square, slope, curve = tj.quintic_squares(h, c0, r0, a0, c1, r1, a1)
        modal[slot + 3 * k] += square
        modal[slot + 3 * k + 1] += slope
        modal[slot + 3 * k + 2] += curve
        r2, rb = tj.carrier_step(a0, a1, r0, r1, modal[other + 4 + k], ab_old, ab_mid, ab_new,
                                 b1, h)
        modal[other + 2 * k] += r2
        modal[other + 2 * k + 1] += rb


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _observe_record_modes(t, t_tail, y, y_new, K, h, n, curvature, modal, acc, base):
    """The record kind's modal statistics of the accepted step [t, t + h] (K: its stages, the
    last f(t + h, y_new)), as trajectory.observe_random's for the midspan: the curvature
    squares at the clamp and midspan (`_observe_bend_squares`) once the step starts in the
    statistics window, where the scene observes the loads. curvature: the basis' CLAMPS rows;
    acc: the midspan's accumulator, after trajectory.record_statistics took the step."""
    if t >= t_tail and modal[factor_slot(n) + 1] != 0.0:
        _observe_bend_squares(y, y_new, K[0], K[K.shape[0] - 1], h, n, curvature, modal, acc)


# `_observe_record_modes` for a random record, nothing for the sine kinds (not compiled there)
observe_random_modes = ex.by_kind(None, _observe_record_modes)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def curvature_moments(modal, n, acc, reals):
    """reals' CURVATURE_M0.. and MID_CURVATURE_M0.. (mean squares, `modal_size`) over the
    statistics window of a random trajectory (acc: its watched accumulator), where the loads
    were observed; left NaN otherwise."""
    span = acc[tj.W_END] - acc[tj.W_START]
    if modal[factor_slot(n) + 1] == 0.0 or acc[tj.IN_WINDOW] == 0.0 or not span > 0.0:
        return
    for k in range(6):
        reals[CURVATURE_M0 + k] = modal[square_slot(n) + k] / span
    other = carrier_slot(n)
    for k in range(2):          # the second derivative's, through its smaller carrier
        reals[CURVATURE_M0 + 3 * k + 2] = tj.carried_square(
            modal[square_slot(n) + 3 * k + 2], modal[other + 2 * k], modal[other + 2 * k + 1],
            acc[tj.SUM_B2], modal[other + 4 + k]) / span


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _turns(r0, r1):
    """Whether a rate going from r0 to r1 over a step changes sign (an extremum)."""
    return (r0 > 0.0 and r1 <= 0.0) or (r0 < 0.0 and r1 >= 0.0)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def shape_size(shapes, c):
    """An upper bound of max |phi_c| over the span: the basis' own (column 5 of its shapes,
    sweep.models.basis.shape_sizes), within a few tenths of a per cent of the maximum."""
    return shapes[c, 5]


CHORD = np.array([0.0, 0.25, 0.385, 0.4725, 0.535, 0.5824, 0.6198])
"""CHORD[k] >= max (s - s^(k+1)) over s in [0, 1] (k s / (k + 1) at s = (k+1)^(-1/k): 0,
1/4, 0.3849, 0.4725, 0.5350, 0.5824, 0.6197): how far the term s^(k+1) of an interpolant
can fall below its chord s (dopri5.DENSE_TERMS of them)."""
CHORD_MARGIN = 1e-12
"""`mode_reach`'s chord bound's margin, times the coefficients' sum: q_c(1) computed here may
round a few ulps away from the interpolant's own value at the step's end."""


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def chord_bound(q0, q1, reach, spread):
    """An upper bound (m) of |q| over a step on an interpolant from q0 to q1 (m): the tighter
    of `reach` (|q0| plus its coefficients' sizes) and the chord's, max(|q0|, |q1|) plus
    `spread` (how far the interpolant can leave its chord: sum_k |coefficient k| CHORD[k])
    plus CHORD_MARGIN reach. Near a crest, where |q'| h is most of `reach`, the chord's is
    the tighter: the linear term lies on the chord."""
    return min(reach, max(abs(q0), abs(q1)) + spread + CHORD_MARGIN * reach)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def mode_reach(y, h, QA, c):
    """An upper bound (m) of |q_c| over the accepted step, on mode c's interpolant
    q_c = y_c + h sum_k QA[c, 0, k] s^(k+1), s in [0, 1]: `chord_bound` of |y_c| +
    |h| sum_k |QA[c, 0, k]| and the chord from y_c to q_c(1)."""
    reach = 0.0
    total = 0.0
    spread = 0.0
    for k in range(QA.shape[2]):
        a = QA[c, 0, k]
        total += a
        reach += abs(a)
        spread += abs(a) * CHORD[k]
    return chord_bound(y[c], y[c] + h * total, abs(y[c]) + abs(h) * reach, abs(h) * spread)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _span_bound(y, h, QA, n_modes, shapes):
    """An upper bound (m) of |w(x, t)| over the span and over the accepted step (every mode's
    interpolant in QA, q_c = y_c + h sum_k QA[c, 0, k] x^(k+1), x in [0, 1]):
    sum_c max |q_c| max |phi_c|, with max |q_c| from `mode_reach` and
    max |phi_c| from `shape_size`."""
    bound = 0.0
    for c in range(n_modes):
        bound += mode_reach(y, h, QA, c) * shape_size(shapes, c)
    return bound


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def illinois_next(lo, hi, g_lo, g_hi, bisect):
    """The next point at which the Illinois method evaluates a rate g that falls through zero
    in [lo, hi] (g_lo >= 0 > g_hi, ends already weighted by `illinois_keep`): the regula
    falsi's root of the chord, or the middle where `bisect` (the bracket failed to halve), where
    the chord is flat or where its root is not inside."""
    if bisect or not g_lo > g_hi:
        return 0.5 * (lo + hi)
    x = lo + (hi - lo) * g_lo / (g_lo - g_hi)
    return x if lo < x < hi else 0.5 * (lo + hi)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def illinois_keep(lo, hi, g_lo, g_hi, kept, x, g):
    """The Illinois method's bracket (lo, hi, g_lo, g_hi, kept) after the rate g at x: x
    replaces the end whose rate has g's side (g > 0: lo), and the other end's rate is halved
    where that end was kept the step before too (kept: the end kept last, -1 lo, +1 hi, 0
    none), so the chord does not stall on one side."""
    if g > 0.0:
        return x, hi, g, g_hi * 0.5 if kept == 1 else g_hi, 1
    return lo, x, g_lo * 0.5 if kept == -1 else g_lo, g, -1


SPAN_SAMPLES = 4
"""Intervals of an accepted step at whose ends `observe_span` takes the span's maximum: a
crest in time of the largest deflection shows as its rate turning from rising to falling
between two of them, and is then located (`_span_crest`)."""
SPAN_ITERATIONS = 60
"""Most evaluations that locate a crest inside an interval (`_span_crest`)."""
SPAN_WIDTH = 2.0 ** -30
"""The bracket (a fraction of the step) at which `_span_crest` stops: the crest's height is
then exact to about (1e-9)^2 of the step's curvature in time, far below round-off."""


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _span_sample(y, h, QA, s, n, qx, basis):
    """(max over the span of |w| (m), its place x* / l, the rate of |w(x*)| (m per unit s))
    at the fraction s of the accepted step, on every mode's interpolant (QA): the maximum by
    kernels.modes.span_argmax; the rate is that of the interpolants themselves (their
    polynomials' derivatives), so by the envelope theorem it is the rate of the span's
    maximum, which rises where it is > 0 and falls where it is < 0. qx (N): scratch."""
    for c in range(n):
        qx[c] = dopri5.dense_value(y[c], h, QA[c, 0], s)
    value, place = md.span_argmax(qx, n, basis)
    w = 0.0
    rate = 0.0
    for c in range(n):
        phi = md.shape_at(basis[md.SHAPES], c, place)[0]
        slope = 0.0
        for k in range(QA.shape[2] - 1, -1, -1):
            slope = slope * s + (k + 1) * QA[c, 0, k]
        w += phi * qx[c]
        rate += phi * slope
    return value, place, (rate if w >= 0.0 else -rate)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _interpolant_terms(y_c, h, c, s):
    """(q, dq/ds, d2q/ds^2) (m) of one mode's interpolant q = y_c + h sum_k c[k] s^(k+1) at
    the fraction s of the step (Horner's scheme with its derivatives)."""
    p = 0.0
    d1 = 0.0
    d2 = 0.0
    for k in range(c.shape[0] - 1, -1, -1):
        d2 = d2 * s + d1
        d1 = d1 * s + p
        p = p * s + c[k]
    return y_c + h * s * p, h * (p + s * d1), h * (2.0 * d1 + 2.0 * s * d2)


CREST_NEWTON = 12
"""Most Newton iterations of `_crest_newton`."""


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _crest_newton(y, h, QA, n, qx, basis, lo, hi, s, x):
    """(max |w| (m), its place x* / l, whether found) at the crest of the span's maximum in
    (time, place) between the fractions lo and hi of the step, by Newton's method on
    grad w = 0 in (s, x) from (s, x), w = sum_c phi_c(x) q_c(s) on the interpolants (QA);
    not found where an iterate leaves the bracket or the span, where w is not curved as at a
    crest of |w| (the Hessian definite, negative where w > 0), where it has not converged,
    or where the span holds a larger deflection elsewhere at that instant
    (kernels.modes.span_argmax: the crest is then another hump's). qx (N): scratch."""
    shapes = basis[md.SHAPES]
    done = False
    for _ in range(CREST_NEWTON):
        w = 0.0
        w_x = 0.0
        w_s = 0.0
        w_xx = 0.0
        w_xs = 0.0
        w_ss = 0.0
        for c in range(n):
            q, q_s, q_ss = _interpolant_terms(y[c], h, QA[c, 0], s)
            phi, p1, p2 = md.shape_at(shapes, c, x)
            w += phi * q
            w_x += p1 * q
            w_s += phi * q_s
            w_xx += p2 * q
            w_xs += p1 * q_s
            w_ss += phi * q_ss
        det = w_xx * w_ss - w_xs * w_xs
        if not (det > 0.0 and w * w_xx < 0.0):        # a crest of |w|: w's extremum, w's way
            return 0.0, x, False
        dx = (w_xs * w_s - w_ss * w_x) / det
        ds = (w_xs * w_x - w_xx * w_s) / det
        x += dx
        s += ds
        if not (lo <= s <= hi and 0.0 <= x <= 1.0):
            return 0.0, x, False
        if abs(dx) <= 1e-13 and abs(ds) <= 1e-13:
            done = True
            break
    if not done:
        return 0.0, x, False
    w = 0.0
    for c in range(n):
        qx[c] = dopri5.dense_value(y[c], h, QA[c, 0], s)
        w += md.shape_at(shapes, c, x)[0] * qx[c]
    top, place = md.span_argmax(qx, n, basis)
    if top > abs(w) * (1.0 + 1e-12):
        return top, place, False
    return abs(w), x, True


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _span_crest(y, h, QA, n, qx, basis, lo, hi, g_lo, g_hi, x_lo, x_hi):
    """(the largest span maximum found (m), its place x* / l) at the crest in time of the
    span's maximum between the fractions lo < hi of the step, where its rate
    (`_span_sample`) is g_lo >= 0 at lo and g_hi < 0 at hi, and its place x_lo at lo, x_hi
    at hi: Newton's method in time and place (`_crest_newton`) from the regula falsi's
    instant at x_lo, and at x_hi too where that is another hump (more than a station apart:
    the first hump's crest and, after the second took over, the second's may both lie in
    the interval); where neither finds a crest, the Illinois method on the rate (regula falsi
    that halves the end kept twice), a bisection wherever the bracket failed to halve, until
    it is SPAN_WIDTH of the step wide. The rate jumps where the maximum moves to another hump
    of w, but only upwards (where two humps' heights cross, the one taking over rises the
    faster): the bracket closes on a smooth crest."""
    s = lo + (hi - lo) * g_lo / (g_lo - g_hi)
    top, where, found = _crest_newton(y, h, QA, n, qx, basis, lo, hi, s, x_lo)
    if abs(x_hi - x_lo) * (basis[md.STATIONS].shape[0] - 1) > 1.0:
        other, place, also = _crest_newton(y, h, QA, n, qx, basis, lo, hi, s, x_hi)
        if other > top:
            top = other
            where = place
        found = found or also
    if found:
        return top, where
    kept = 0                       # the end kept last: -1 lo, +1 hi, 0 none
    width = hi - lo
    bisect = False
    for _ in range(SPAN_ITERATIONS):
        s = illinois_next(lo, hi, g_lo, g_hi, bisect)
        value, place, g = _span_sample(y, h, QA, s, n, qx, basis)
        if value > top:
            top = value
            where = place
        lo, hi, g_lo, g_hi, kept = illinois_keep(lo, hi, g_lo, g_hi, kept, s, g)
        if hi - lo <= SPAN_WIDTH or g == 0.0:
            break
        bisect = hi - lo > 0.5 * width
        width = hi - lo
    return top, where


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _span_spread(h, QA, n, shapes, s_m, r, a):
    """An upper bound (m) of |w(x, s) - w(x, s_m)| over the span and |s - s_m| <= r (fractions
    of the step): sum_c max |phi_c| sum_k |a_k| r^k, a_k the Taylor coefficients at s_m of
    mode c's interpolant q_c(s) - y_c = h sum_j QA[c, 0, j] s^(j+1) (its coefficients
    shifted to s_m by Horner's scheme). a (terms + 1): scratch."""
    terms = QA.shape[2]
    total = 0.0
    for c in range(n):
        a[0] = 0.0
        for j in range(terms):
            a[j + 1] = h * QA[c, 0, j]
        for i in range(terms):
            for j in range(terms - 1, i - 1, -1):
                a[j] += s_m * a[j + 1]
        spread = 0.0
        power = 1.0
        for k in range(1, terms + 1):
            power *= r
            spread += abs(a[k]) * power
        total += spread * shape_size(shapes, c)
    return total


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def observe_span(y, h, QA, s_lo, n_modes, qx, modal, basis):
    """The largest deflection over the span and over the fractions s_lo..1 of the accepted
    step (every mode's interpolant in QA) into modal[2N] (m) and its place x* / l into
    modal[place_slot(N)], where it exceeds the largest so far. Nothing where `_span_bound`
    leaves no room above the largest so far, nor where the span's maximum
    (kernels.modes.span_argmax) at the middle of s_lo..1 plus `_span_spread` over the rest
    leaves none; else the span's maximum at the ends of SPAN_SAMPLES equal intervals, and in
    each interval where it rises (or is level) at the start and falls at the end, at its
    crest (`_span_crest`). qx (observer_scratch(N)): scratch. Both multi-mode drivers call
    it: `_observe_modes`, and kernels.modal_lanes for a lane's ordinary step."""
    n = n_modes
    top = modal[2 * n]
    if _span_bound(y, h, QA, n, basis[md.SHAPES]) <= top:
        return
    half = SPAN_SAMPLES // 2
    s_mid = s_lo + (1.0 - s_lo) * half / SPAN_SAMPLES
    v_mid, x_mid, g_mid = _span_sample(y, h, QA, s_mid, n, qx, basis)
    place = modal[place_slot(n)]
    if v_mid > top:
        top = v_mid
        place = x_mid
    spread = _span_spread(h, QA, n, basis[md.SHAPES], s_mid, 1.0 - s_mid, qx[n:])
    if v_mid + spread > top:
        s_prev = s_lo
        g_prev = 0.0
        x_prev = 0.5
        for j in range(SPAN_SAMPLES + 1):
            s = 1.0 if j == SPAN_SAMPLES else s_lo + (1.0 - s_lo) * j / SPAN_SAMPLES
            if j == half:
                value, where, g = v_mid, x_mid, g_mid
            else:
                value, where, g = _span_sample(y, h, QA, s, n, qx, basis)
            if value > top:
                top = value
                place = where
            if j > 0 and g_prev >= 0.0 and g < 0.0:    # (g = 0: the crest is this sample)
                crest, at = _span_crest(y, h, QA, n, qx, basis, s_prev, s, g_prev, g, x_prev,
                                        where)
                if crest > top:
                    top = crest
                    place = at
            s_prev = s
            g_prev = g
            x_prev = where
    modal[2 * n] = top
    modal[place_slot(n)] = place


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def negligible(peak, largest):
    """Whether a mode whose peak so far is `peak` (m) is round-off beside the largest mode's
    peak `largest` (m): at most HIDDEN_FLOOR times it. Such a mode's extrema are not located
    inside a step (its tail amplitude is the largest at the steps' ends): an even mode seeded
    by round-off under symmetric excitation (1e-25 to 1e-11 m on harness-base-sine) turns at
    its own frequency, and each turn sent a step to the scalar path. A mode that grows above
    the floor (a parametric resonance) is watched as any other from then on."""
    return not (peak > HIDDEN_FLOOR * largest)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _observe_modes(t, t_new, t_tail, y, y_new, K, h, n_modes, eighth, modal, Km, QA, qx,
                   basis, Qp, p1, base):
    """The modes' accumulator `modal` (`modal_size`) over the accepted step [t, t_new]: each mode's
    peak at the step's end; in the tail window each mode's tail amplitude max |q_i| (the step's
    end, the tail's start inside the step, and an extremum of q_i inside the step, on its own
    interpolant, unless the mode is `negligible`) and the span's largest deflection over the
    step's part in the window (`observe_span`). QA (N, 2, terms): every mode's interpolant,
    scratch; qx (`observer_scratch`), Qp (2, terms): scratch; basis: the span's
    (kernels.modes). The loads (`_observe_bends`, `_observe_loads`) over the tail window, or
    over the whole run where `start` marked it so (a sine sweep: their peak over the whole
    sweep). p1, base: the Observer row and the excitation switch, for the base inertia's part
    of the clamp shear (`inertia_at`)."""
    n = n_modes
    largest = 0.0
    for i in range(n):
        modal[n + i] = max(modal[n + i], abs(y_new[i]))
        largest = max(largest, modal[n + i])
        if t_new >= t_tail:
            modal[i] = max(modal[i], abs(y_new[i]))
    # a run-time bool, not the literal False: the observers below compile once for both calls
    located = bool(False)
    if modal[factor_slot(n) + 1] == WHOLE_RUN:
        located = _observe_bends(t, t_new, 0.0, y, y_new, K, h, n, eighth, modal, Km, QA, basis,
                                 Qp, located)
        located = _observe_loads(t, t_new, 0.0, y, y_new, K, h, n, eighth, modal, Km, QA,
                                 basis, located, qx, p1, base)
    if t_new < t_tail:
        return
    if not located:
        for c in range(n):
            _mode_interpolant(y, y_new, K, h, c, n, eighth, Km, QA[c])
    located = bool(True)                # (run-time, as above: one compile of each observer)
    s_lo = 0.0
    if t < t_tail:                                   # the tail starts inside the step
        s_lo = (t_tail - t) / h
        for c in range(n):
            modal[c] = max(modal[c], abs(dopri5.dense_value(y[c], h, QA[c, 0], s_lo)))
    observe_span(y, h, QA, s_lo, n, qx, modal, basis)
    for i in range(n):
        if not _turns(y[n + i], y_new[n + i]) or negligible(modal[n + i], largest):
            continue
        x = dopri5.dense_root(y[n + i], h, QA[i, 1], 0.0, 0.0, 1.0)   # q_i' = 0
        if t + x * h >= t_tail:
            modal[i] = max(modal[i], abs(dopri5.dense_value(y[i], h, QA[i, 0], x)))
    if modal[factor_slot(n) + 1] != TAIL_WINDOW:    # none, or over the whole run (above)
        return
    located = _observe_bends(t, t_new, t_tail, y, y_new, K, h, n, eighth, modal, Km, QA, basis,
                             Qp, located)
    _observe_loads(t, t_new, t_tail, y, y_new, K, h, n, eighth, modal, Km, QA, basis, located,
                   qx, p1, base)


TAIL_WINDOW = 1.0
"""settings[LOADS] (and the accumulator's flag): the loads' peaks over the tail window."""
WHOLE_RUN = 2.0
"""settings[LOADS]: over the whole run (a sine sweep's peak over the sweep)."""


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _observe_bends(t, t_new, t_tail, y, y_new, K, h, n, eighth, modal, Km, QA, basis, Qp,
                   located):
    """The curvature at each clamp and at midspan, c_e(t) = sum phi_n''(s_e) q_n(t) (s_e = 0,
    1, 1/2: kernels.modes BEND_0, BEND_1, BEND_MID; times l^2, m), over the accepted step
    [t, t_new] ending in the tail window: its largest |c_e| into modal[clamp_slot(N) + e] at
    the step's end, at the tail's start inside the step and at an extremum inside the step
    (the root of its interpolated rate), on every mode's interpolant (QA; `located`: already
    computed). Returns whether the interpolants are now computed."""
    curvature = basis[md.CLAMPS]
    slot = clamp_slot(n)
    for e in range(md.N_BENDS):
        c1 = 0.0
        r0 = 0.0
        r1 = 0.0
        for c in range(n):
            c1 += curvature[e, c] * y_new[c]
            r0 += curvature[e, c] * y[n + c]
            r1 += curvature[e, c] * y_new[n + c]
        modal[slot + e] = max(modal[slot + e], abs(c1))
        inside = t < t_tail
        turns = _turns(r0, r1)
        if not (inside or turns):
            continue
        if not located:
            for c in range(n):
                _mode_interpolant(y, y_new, K, h, c, n, eighth, Km, QA[c])
            located = True
        if inside:
            modal[slot + e] = max(modal[slot + e],
                                  abs(_combined(curvature[e], y, h, QA, (t_tail - t) / h, n)))
        if turns:
            for j in range(Qp.shape[1]):
                Qp[1, j] = 0.0
            for c in range(n):
                for j in range(Qp.shape[1]):
                    Qp[1, j] += curvature[e, c] * QA[c, 1, j]
            x = dopri5.dense_root(r0, h, Qp[1], 0.0, 0.0, 1.0)
            if t + x * h >= t_tail:
                modal[slot + e] = max(modal[slot + e],
                                      abs(_combined(curvature[e], y, h, QA, x, n)))
    return located


ROOT_ITERATIONS = 96
"""Most evaluations that locate a load's maximum inside a step (`_load_peak`: the bracket at
least halves every two, so this reaches 2^-48 of the step at worst)."""
ROOT_WIDTH = 2.0 ** -48
"""The bracket (a fraction of the step) at which `_load_peak` stops."""


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _loads_at(t, y, h, QA, x, n, basis, modal, qv, out, p1, base):
    """kernels.modes.span_loads at the fraction x of the step from t (s), on every mode's
    interpolant (QA); qv (2N): scratch for q and its rate there; p1, base: `inertia_at`'s."""
    for c in range(n):
        qv[c] = dopri5.dense_value(y[c], h, QA[c, 0], x)
        qv[n + c] = dopri5.dense_value(y[n + c], h, QA[c, 1], x)
    state_loads(basis[md.CLAMPS], basis[md.COUPLING], qv[:n], qv[n:], n, modal, t + x * h, p1,
                base, out)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _load_rises(out, k):
    """d|L_k|/dt's sign as a number for load k of kernels.modes.span_loads' out (k = 0: the
    stretch E >= 0, its rate; 1, 2: a shear F, F F')."""
    return out[1] if k == 0 else out[2 * k] * out[2 * k + 1]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _observe_loads(t, t_new, t_tail, y, y_new, K, h, n, eighth, modal, Km, QA, basis,
                   located, qx, p1, base):
    """The largest stretch E and clamp shears |F_0|, |F_1| (kernels.modes.span_loads) over
    the accepted step [t, t_new] ending in the tail window, into modal[load_slot(N) + k]: at
    the step's end, at the tail's start inside the step and, where |L_k| rises at the step's
    start and falls at its end, at its maximum inside the step (`_load_peak`, a root of its
    rate on every mode's interpolant: the loads are not linear in q, so no root of one
    polynomial gives it). qx: scratch (`observer_scratch`). Returns whether the interpolants are now
    computed. p1, base: `inertia_at`'s."""
    slot = load_slot(n)
    rows = basis[md.CLAMPS]
    qv = qx[n:3 * n]
    a = qx[3 * n:3 * n + 6]
    b = qx[3 * n + 6:3 * n + 12]
    m = qx[3 * n + 12:3 * n + 18]
    state_loads(rows, basis[md.COUPLING], y[:n], y[n:], n, modal, t, p1, base, a)
    state_loads(rows, basis[md.COUPLING], y_new[:n], y_new[n:], n, modal, t_new, p1, base, b)
    inside = t < t_tail
    need = inside
    for k in range(3):
        modal[slot + k] = max(modal[slot + k], abs(b[2 * k]))
        need = need or (_load_rises(a, k) > 0.0 and _load_rises(b, k) <= 0.0)
    if not need:
        return located
    if not located:
        for c in range(n):
            _mode_interpolant(y, y_new, K, h, c, n, eighth, Km, QA[c])
        located = True
    if inside:
        _loads_at(t, y, h, QA, (t_tail - t) / h, n, basis, modal, qv, m, p1, base)
        for k in range(3):
            modal[slot + k] = max(modal[slot + k], abs(m[2 * k]))
    for k in range(3):
        g_lo = _load_rises(a, k)
        g_hi = _load_rises(b, k)
        if g_lo > 0.0 and g_hi <= 0.0:
            if _load_bound(t, t_new, y, h, QA, n, basis, modal, qv, p1, base, k) <= modal[slot + k]:
                continue          # no instant of the step can beat the largest so far
            peak = _load_peak(t, y, h, QA, n, basis, modal, qv, m, p1, base, k, g_lo, g_hi,
                              (t_tail - t) / h)
            modal[slot + k] = max(modal[slot + k], peak)
    return located


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _load_bound(t, t_new, y, h, QA, n, basis, modal, q_max, p1, base, k):
    """An upper bound of |L_k| (kernels.modes.span_loads' load k) over the accepted step
    [t, t_new] (s), on every mode's interpolant (QA, `mode_reach`), the end load's largest
    size (its mean and amplitude) and the base inertia's (kernels.excitation.peak_bound over
    the step): where it is no larger than the largest |L_k| so far, `_observe_loads` skips the
    search for the step's peak (on a random record the shears turn at nearly every step, and
    that search took two thirds of a three-mode run). q_max (N): scratch."""
    for c in range(n):
        q_max[c] = mode_reach(y, h, QA, c)
    return load_bound_within(t, t_new, q_max, n, basis[md.CLAMPS], basis[md.COUPLING], modal,
                             p1, base, k)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def load_bound_within(t, t_new, q_max, n, rows, coupling, modal, p1, base, k):
    """`_load_bound` over the step [t, t_new] (s) from bounds q_max (N, m) of each mode's
    |q_n| over it (the multi-mode lanes' own, modal_lanes._mode_events); rows, coupling: the
    basis' CLAMPS and COUPLING."""
    s = end_load_slot(n)
    inertia = 0.0
    if base is not None and k > 0:
        factor = modal[inertia_slot(n)]
        if factor != 0.0:
            inertia = abs(factor) * ex.peak_bound(t, t_new, p1, osc.EXCITATION, 1, base)
    return md.span_load_bound(rows, coupling, q_max, n,
                              modal[factor_slot(n)], abs(modal[s]) + abs(modal[s + 1]),
                              inertia, k)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _load_peak(t, y, h, QA, n, basis, modal, qv, m, p1, base, k, g_lo, g_hi, x_tail):
    """The largest |L_k| (kernels.modes.span_loads' load k) found while locating its maximum
    inside the step, where its rise g = `_load_rises` is g_lo > 0 at the step's start and
    g_hi <= 0 at its end: the Illinois method (regula falsi that halves the end kept twice),
    a bisection wherever the bracket failed to halve, until it is ROOT_WIDTH of the step wide
    (a few evaluations for a smooth rate where bisection took 48). Only points at or after
    the fraction x_tail of the step count (the tail window's)."""
    lo = 0.0
    hi = 1.0
    kept = 0                       # the end kept last: -1 lo, +1 hi, 0 none
    width = 1.0
    bisect = False
    peak = 0.0
    for _ in range(ROOT_ITERATIONS):
        x = illinois_next(lo, hi, g_lo, g_hi, bisect)
        _loads_at(t, y, h, QA, x, n, basis, modal, qv, m, p1, base)
        if x >= x_tail:
            peak = max(peak, abs(m[2 * k]))
        g = _load_rises(m, k)
        lo, hi, g_lo, g_hi, kept = illinois_keep(lo, hi, g_lo, g_hi, kept, x, g)
        if hi - lo <= ROOT_WIDTH or g == 0.0:
            break
        bisect = hi - lo > 0.5 * width
        width = hi - lo
    return peak


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _combined(weights, y, h, QA, x, n):
    """sum weights[c] q_c at the fraction x of the step, on every mode's interpolant."""
    v = 0.0
    for c in range(n):
        v += weights[c] * dopri5.dense_value(y[c], h, QA[c, 0], x)
    return v


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def restart_modes(acc, t_tail, t, t_new, y, y_new, K, h, n_modes, eighth, modal, Km, QA, qx,
                  basis, Qp, p1, base):
    """After trajectory.record_step on the step [t, t_new]: where the early stop
    (solver.stop_when_steady) moved the tail window to start inside it (acc[T_TAIL] is no
    longer t_tail), each mode's tail amplitude and the span's restart there, as the midspan's
    does: the values at the new start, the extrema after it and the step's end."""
    if acc[tj.T_TAIL] == t_tail:
        return
    for i in range(n_modes):
        modal[i] = 0.0
    modal[2 * n_modes] = 0.0
    modal[place_slot(n_modes)] = 0.5
    for k in range(6):
        modal[clamp_slot(n_modes) + k] = 0.0
    _observe_modes(t, t_new, acc[tj.T_TAIL], y, y_new, K, h, n_modes, eighth, modal, Km, QA,
                   qx, basis, Qp, p1, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def span_state(state, modal, y, n_modes, settings, reals, basis):
    """The state judged from the whole response, and reals[SPAN_MAX]: a point whose midspan
    deflection decayed (DECAYED), or moved by less than HIDDEN_FLOOR x the largest mode's peak
    over the whole run (the modes' round-off at a node of every moving mode: whatever state
    that noise was given), while some mode's tail amplitude exceeds settings[TOL] x the
    largest mode's peak has not decayed: a mode with a node at midspan (an even one) kept
    moving; it is left OFF_MIDSPAN for `judge_off_midspan`. A point whose midspan is STEADY
    while a mode with a node at midspan has a tail amplitude above HIDDEN_FLOOR x that peak is
    left HIDDEN_MODE for the same judge: that mode may be growing (an even mode inside its
    parametric zone), unseen at midspan. reals[SPAN_MAX] = the largest
    deflection over the span in the tail window (m): modal[2N] (`_observe_modes`), the span
    at the final state y (a growing response peaks there) and at least the midspan
    amplitude; NaN where the point failed. basis: the span's (kernels.modes)."""
    n = n_modes
    if state == mt.DIVERGED or state == mt.STEP_TOO_SMALL or state == mt.MAX_STEPS:
        return state
    span_columns(modal, y, n, reals, basis)
    peak = 0.0
    for i in range(n):
        peak = max(peak, modal[n + i])
    if ((state == mt.STEADY or state == mt.MODULATED or state == mt.UNSETTLED)
            and reals[PEAK] < HIDDEN_FLOOR * peak):
        state = mt.DECAYED      # the midspan moved by the modes' round-off alone (a node of
                                # every moving mode): its own state says nothing
    if state != mt.DECAYED and state != mt.STEADY:
        return state
    for i in range(n):
        if state == mt.DECAYED and modal[i] > settings[TOL] * peak:
            return mt.OFF_MIDSPAN
        if state == mt.STEADY and _hidden(basis, i) and modal[i] > HIDDEN_FLOOR * peak:
            return mt.HIDDEN_MODE
    return state


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def span_columns(modal, y, n_modes, reals, basis):
    """reals[SPAN_MAX], the largest deflection over the span in the tail window (m; a sine
    sweep's: over the whole sweep), and reals[SPAN_PLACE], its place x* / l: modal[2N] at
    its place (`_observe_modes`), the span at the final state y (a growing response peaks
    there) and at least the midspan amplitude (reals[AMPLITUDE], at 1/2); then the loads'
    columns (`load_columns`). basis: the span's (kernels.modes)."""
    n = n_modes
    top = modal[2 * n]
    place = modal[place_slot(n)]
    final, where = md.span_argmax(y, n, basis)
    if final > top:
        top = final
        place = where
    if reals[AMPLITUDE] > top:
        top = reals[AMPLITUDE]
        place = 0.5
    reals[SPAN_MAX] = top
    reals[SPAN_PLACE] = place
    load_columns(modal, n, reals)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def load_columns(modal, n, reals):
    """reals' CLAMP_BEND, MID_BEND, STRETCH and CLAMP_SHEAR from the modes' accumulator
    (`modal_size`): the loads' peaks, the larger of the two clamps'."""
    reals[CLAMP_BEND] = max(modal[clamp_slot(n)], modal[clamp_slot(n) + 1])
    reals[MID_BEND] = modal[clamp_slot(n) + 2]
    reals[STRETCH] = modal[load_slot(n)]
    reals[CLAMP_SHEAR] = max(modal[load_slot(n) + 1], modal[load_slot(n) + 2])


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _hidden(basis, i):
    """Whether mode i has a node at midspan (an even mode of a symmetric span): the midspan
    deflection does not see it."""
    return abs(basis[md.MIDSPAN][i]) < NODE


@nb.njit(cache=True, nogil=True, error_model="numpy")
def start(row, n_modes, settings, y, f, pp, S, T, p1, acc, series, modal, weights, basis,
          base):
    """Set up a trajectory at t = 0 from raw row `row` for both multi-mode drivers: the initial
    state y and f = f(0, y) (length 2N each, written here), SciPy's initial step, the watched
    deflection's accumulator acc (trajectory.begin; p1: `observer_row`; weights: the
    deflection's mode weights, the basis' midspan values for the midspan), the modes'
    accumulator modal (`modal_size`) and the divergence test of every mode at t = 0. pp, S, T:
    the prepared row, the right-hand side's scratch and the basis' tables (modes.prepare,
    scratch); basis: the span's (kernels.modes)."""
    n = n_modes
    rtol = max(settings[RTOL], dopri5.MIN_RTOL)
    t_end = settings[T_END]
    t_tail = t_end * (1.0 - settings[TAIL])
    for i in range(2 * n):
        y[i] = row[md.N_FIXED + i]
    md.derivative_call(0.0, y, f, S, n, T, base)
    atol_q, atol_v = tj.point_atol(p1, 0, 1, settings, rtol)
    evals = 1.0
    if settings[FIRST_STEP] > 0.0:
        h_abs = min(settings[FIRST_STEP], t_end)
    else:
        eighth = settings[METHOD] != 0.0
        order = dop853.ERROR_ESTIMATOR_ORDER if eighth else dopri5.ERROR_ESTIMATOR_ORDER
        h_abs = initial_step(y, f, t_end, settings[MAX_STEP], rtol, atol_q, atol_v, order,
                             S, n, T, base)
        evals += 1.0
    fv = _project(f, weights, n, n)
    a0 = fv + (md.base_acceleration(0.0, pp, n, base) if base is not None else 0.0)
    tj.begin(settings, acc, series, _project(y, weights, 0, n), _project(y, weights, n, n),
             fv, a0, atol_q, atol_v, h_abs, evals, row[md.BOUND])
    if ex.is_record(base):
        share = 0.0                         # the watched deflection's participation
        for i in range(n):
            share -= weights[i] * pp[md.P_FORCE * n + i]
        tj.record_window(acc, row[md.EXCITATION + ex.RECORD_START],
                         row[md.EXCITATION + ex.RAMP], share)
        t_tail = acc[tj.T_TAIL]
    for i in range(n):
        modal[i] = abs(y[i]) if t_tail <= 0.0 else 0.0
        modal[n + i] = abs(y[i])
    modal[2 * n] = 0.0
    modal[place_slot(n)] = 0.5
    if t_tail <= 0.0:
        modal[2 * n], modal[place_slot(n)] = md.span_argmax(y, n, basis)
    curvature = basis[md.CLAMPS]
    t_loads = 0.0 if settings[LOADS] == WHOLE_RUN else t_tail
    for e in range(md.N_BENDS):
        c0 = 0.0
        for i in range(n):
            c0 += curvature[e, i] * y[i]
        modal[clamp_slot(n) + e] = abs(c0) if t_loads <= 0.0 else 0.0
    modal[factor_slot(n)] = md.shear_factor(pp, n)
    modal[factor_slot(n) + 1] = settings[LOADS]
    mean, amplitude, omega, phase = md.end_load_factors(pp, n)
    modal[end_load_slot(n)] = mean
    modal[end_load_slot(n) + 1] = amplitude
    modal[end_load_slot(n) + 2] = omega
    modal[end_load_slot(n) + 3] = phase
    modal[inertia_slot(n)] = md.inertia_factor(row, n, curvature) if base is not None else 0.0
    loads = np.empty(6)
    state_loads(curvature, basis[md.COUPLING], y[:n], y[n:], n, modal, 0.0, p1, base, loads)
    for k in range(3):
        modal[load_slot(n) + k] = abs(loads[2 * k]) if t_loads <= 0.0 else 0.0
    for k in range(6):
        modal[square_slot(n) + k] = 0.0
        modal[carrier_slot(n) + k] = 0.0
    for k in range(2):                  # the curvature's share G_k of a_b (c'' = r - G_k a_b)
        e = md.BEND_0 if k == 0 else md.BEND_MID
        for i in range(n):
            modal[carrier_slot(n) + 4 + k] -= curvature[e, i] * pp[md.P_FORCE * n + i]
    for i in range(n):
        modal[2 * n + 1 + i] = 0.0
    for i in range(n):
        if not abs(y[i]) <= row[md.BOUND]:
            acc[tj.STATUS] = mt.DIVERGED
            acc[tj.T_STOP] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def integrate(row, n_modes, settings, track, centre, thr_fixed, thr_rel, series, modal, base,
              eighth, weights, basis):
    """Integrate one point (raw row `row`, kernels.modes columns) from t = 0 to t_end with
    SciPy's RK45 or DOP853 (settings[METHOD]), reducing the watched deflection's metrics
    (kernels.trajectory's accumulator; weights: its mode weights, the basis' midspan values
    for the midspan) and the modes' accumulator (modal, `modal_size`, m; basis: the span's,
    kernels.modes) on the fly; `track`, centre, thr_fixed, thr_rel and the switches base,
    eighth (the method, as settings[METHOD]): as transverse.integrate.
    Returns (accumulator, extrema buffer, final state y)."""
    n = n_modes
    dim = 2 * n
    rtol = max(settings[RTOL], dopri5.MIN_RTOL)
    n_stages = dop853.N_STAGES if eighth else dopri5.N_STAGES
    A = dop853.A if eighth else dopri5.A
    B = dop853.B if eighth else dopri5.B
    C = dop853.C if eighth else dopri5.C
    T = basis[md.TABLES]
    pp = np.empty(md.prepared_size(n))
    md.prepare(row, n, pp, basis[md.RATIOS])
    S = md.scratch(pp, n, basis)
    p1 = observer_row(row, n, pp)
    K = np.empty((n_stages + 1, dim))
    K_mid = np.empty((n_stages + 1, 2))
    Km = np.empty((n_stages + 1, 2))
    terms = dopri5.DENSE_TERMS if eighth else dopri5.QUARTIC_TERMS   # RK45: its quartic
    Qc = np.empty((2, terms))
    QA = np.empty((n, 2, terms))
    qx = np.empty(observer_scratch(n))
    y = np.empty(dim)
    y_new = np.empty(dim)
    stage = np.empty(dim)
    acc = tj.new_accumulator(tj.SCALAR_SLOTS)
    buf = tj.new_buffer()

    start(row, n, settings, y, K[0], pp, S, T, p1, acc, series, modal, weights, basis, base)
    atol_q = acc[tj.ATOL_Q]
    atol_v = acc[tj.ATOL_V]

    while True:
        h = tj.next_attempt(settings, acc)
        if h == 0.0:
            break
        t = acc[tj.T]
        rk_step(t, y, h, S, n, T, K, y_new, stage, A, B, C, base)
        err = error_norm(K, h, y, y_new, rtol, atol_q, atol_v, n, eighth)
        if not tj.control(settings, acc, err):
            continue
        t_new = acc[tj.T_NEW]
        for i in range(n):
            if not (abs(y_new[i]) <= row[md.BOUND] and math.isfinite(y_new[n + i])):
                acc[tj.STATUS] = mt.DIVERGED
                acc[tj.T_STOP] = t_new
        if acc[tj.STATUS] != mt.RUNNING:
            break
        t_tail = acc[tj.T_TAIL]            # the trajectory's own (solver.stop_when_steady)
        _observe_modes(t, t_new, t_tail, y, y_new, K, h, n, eighth, modal, Km, QA, qx,
                       basis, Qc, p1, base)
        _project_stages(K, weights, n, n_stages, K_mid)
        if acc[tj.N_EXT] >= buf.shape[0]:
            buf = tj.with_room(buf, acc)
        q_mid = _project(y_new, weights, 0, n)
        v_mid = _project(y_new, weights, n, n)
        tj.record_step(p1, 0, 1, settings, acc, K_mid, q_mid, v_mid, h, Qc, buf, series, track,
                       centre, thr_fixed, thr_rel, -1.0, 0.0, True, base, eighth)
        observe_random_modes(t, t_tail, y, y_new, K, h, n, basis[md.CLAMPS], modal, acc, base)
        restart_modes(acc, t_tail, t, t_new, y, y_new, K, h, n, eighth, modal, Km, QA, qx,
                      basis, Qc, p1, base)
        _next_step(y, y_new, K, dim, n_stages)
    tj.end_series(acc, series)
    return acc, buf, y


@nb.njit(cache=True, nogil=True, error_model="numpy")
def at_rest(row, basis, t, y, band, base):
    """Whether the final state y at time t lies within `band` (m) of a stable equilibrium:
    per mode, linearised about the final q (stiffness k_i = -d q_i''/d q_i by a central
    difference), the equilibrium lies d_i = (restoring force_i) / k_i away and the motion about
    it has amplitude sqrt(d_i^2 + (q_i'/sqrt(k_i))^2); at rest when the root sum of squares of
    these over the modes is <= band. Any k_i <= 0: not at rest (kernels.transverse.at_rest
    for one mode). basis: the span's (kernels.modes)."""
    n = md.basis_modes(basis)
    T = basis[md.TABLES]
    S = md.row_scratch(row, basis)
    z = np.empty(2 * n)
    f = np.empty(2 * n)
    for i in range(n):
        z[i] = y[i]
        z[n + i] = 0.0
    md.derivative_call(t, z, f, S, n, T, base)
    up = np.empty(2 * n)
    down = np.empty(2 * n)
    total = 0.0
    for i in range(n):
        step = 1e-6 * max(abs(y[i]), 1e-9 * row[md.BOUND])
        z[i] = y[i] + step
        md.derivative_call(t, z, up, S, n, T, base)
        z[i] = y[i] - step
        md.derivative_call(t, z, down, S, n, T, base)
        z[i] = y[i]
        k = -(up[n + i] - down[n + i]) / (2.0 * step)
        if not k > 0.0:
            return False
        offset = -f[n + i] / k
        speed = y[n + i] / math.sqrt(k)
        total += offset * offset + speed * speed
    return math.sqrt(total) <= band


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_point(row, basis, settings, reals, counts, series, modal, final, envelope, base,
                eighth):
    """Integrate and classify one point (kernels.transverse.solve_point's outputs, plus each
    mode's tail amplitude in modal, m, and the final state y in final, m and m/s). Bad
    parameters give INVALID_INPUT, NaN metrics. basis: the span's (kernels.modes)."""
    n_modes = md.basis_modes(basis)
    if not valid(row, n_modes):
        for j in range(N_REALS):
            reals[j] = math.nan
        for j in range(N_COUNTS):
            counts[j] = 0
        for j in range(series.shape[0]):
            series[j] = math.nan
        for j in range(n_modes):
            modal[j] = math.nan
        for j in range(2 * n_modes):
            final[j] = math.nan
        for j in range(envelope.shape[0]):
            envelope[j] = math.nan
        return mt.INVALID_INPUT
    ext = np.empty(modal_size(n_modes))
    acc, buf, y = integrate(row, n_modes, settings, settings[WANT_SETTLING] != 0.0, 0.0, 0.0,
                            settings[TOL], series, ext, base, eighth,
                            basis[md.MIDSPAN], basis)
    resting = at_rest(row, basis, acc[tj.T], y, settings[TOL] * acc[tj.TAIL_AMP], base)
    state = classify_metrics(settings, acc, buf, reals, counts, base, resting)
    if settings[SWEPT] != 0.0:
        state = swept_outputs(row, md.EXCITATION, 1, settings, acc, buf, state, reals, envelope)
        if not (state == mt.DIVERGED or state == mt.STEP_TOO_SMALL or state == mt.MAX_STEPS):
            span_columns(ext, y, n_modes, reals, basis)
    else:
        state = span_state(state, ext, y, n_modes, settings, reals, basis)
    if ex.is_record(base) and state == mt.COMPLETED:
        curvature_moments(ext, n_modes, acc, reals)
    failed = state == mt.DIVERGED or state == mt.STEP_TOO_SMALL or state == mt.MAX_STEPS
    for j in range(n_modes):
        modal[j] = math.nan if failed else ext[j]
    for j in range(2 * n_modes):
        final[j] = math.nan if failed else y[j]
    return state


@nb.njit(cache=True, nogil=True, error_model="numpy")
def settle_second_pass(params, basis, settings, states, reals, counts, base, eighth):
    """Finish the points left SECOND_PASS (at rest away from zero), as
    kernels.transverse.settle_second_pass does for one mode: integrate again to find the
    final midspan value, then track |q_mid - final| against the band."""
    n_modes = md.basis_modes(basis)
    done = 0
    modal = np.empty(modal_size(n_modes))
    weights = basis[md.MIDSPAN]
    for i in range(params.shape[0]):
        if states[i] != mt.SECOND_PASS:
            continue
        track = bool(True)    # a run-time bool, as solve_point's: integrate compiles once
        first, _, _ = integrate(params[i], n_modes, settings, track, 0.0, 0.0, settings[TOL],
                                np.empty(0), modal, base, eighth, weights, basis)
        band = settings[TOL] * first[tj.TAIL_AMP]
        second, _, _ = integrate(params[i], n_modes, settings, track, first[tj.Q], band, 0.0,
                                 np.empty(0), modal, base, eighth, weights, basis)
        states[i] = tj.settle(second, reals[i], counts[i])
        done += 1
    return done


@nb.njit(cache=True, nogil=True, error_model="numpy")
def judge_off_midspan(params, basis, settings, states, reals, counts, modal, base, eighth):
    """Finish the points a driver left OFF_MIDSPAN (`span_state`: the midspan deflection
    decayed while a mode with a node at midspan kept moving): integrate again watching the
    mode with the largest tail amplitude (modal, (n, N), m) instead of the midspan, and take
    its state, response period and settling time; the midspan's amplitude, peak and
    acceleration stay. A mode found at rest away from zero is STEADY (no settling time).
    And the points left HIDDEN_MODE (the midspan steady, a mode with a node there moving):
    watch the largest such mode; its envelope rising across the tail (`metrics.tail_rises`),
    the point is UNSETTLED (no settling time) whatever that mode's level; above the settling
    band of the midspan amplitude, a steady mode makes the point settle once both have and a
    modulated one makes it MODULATED; otherwise the point stays STEADY. Its amplitude, period
    and the rest stay the midspan's.
    Returns how many points it judged."""
    n = md.basis_modes(basis)
    done = 0
    ext = np.empty(modal_size(n))
    own_reals = np.empty(N_REALS)
    own_counts = np.empty(N_COUNTS, np.int64)
    for i in range(params.shape[0]):
        hidden = states[i] == mt.HIDDEN_MODE
        if states[i] != mt.OFF_MIDSPAN and not hidden:
            continue
        k = -1
        for c in range(n):
            if (not hidden or _hidden(basis, c)) and (k < 0 or modal[i, c] > modal[i, k]):
                k = c
        weights = np.zeros(n)
        weights[k] = 1.0
        acc, buf, y = integrate(params[i], n, settings, settings[WANT_SETTLING] != 0.0, 0.0,
                                0.0, settings[TOL], np.empty(0), ext, base, eighth,
                                weights, basis)
        resting = at_rest(params[i], basis, acc[tj.T], y, settings[TOL] * acc[tj.TAIL_AMP], base)
        state = classify_metrics(settings, acc, buf, own_reals, own_counts, base, resting)
        state = mt.STEADY if state == mt.SECOND_PASS else state
        counts[i, RHS_EVALS] += own_counts[RHS_EVALS]
        done += 1
        if hidden:
            states[i] = mt.STEADY
            if mt.tail_rises(buf, int(acc[tj.N_EXT]), acc[tj.T_TAIL], acc[tj.T_FINAL]):
                states[i] = mt.UNSETTLED             # growing: at any level, for now
                reals[i, SETTLING] = math.nan
            elif modal[i, k] > settings[TOL] * reals[i, AMPLITUDE]:
                if state == mt.STEADY:               # settled once both are
                    reals[i, SETTLING] = max(reals[i, SETTLING], own_reals[SETTLING])
                elif state == mt.MODULATED:
                    states[i] = mt.MODULATED
            continue
        reals[i, PERIOD] = own_reals[PERIOD]
        reals[i, SETTLING] = own_reals[SETTLING]
        reals[i, FAILURE_TIME] = own_reals[FAILURE_TIME]
        states[i] = state
    return done


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_block(params, basis, settings, lo, hi, states, reals, counts, series, modal,
                final, base, eighth, halt):
    """Solve rows lo..hi-1 of `params` (n, modes.n_columns(N)), one trajectory after another:
    kernels.transverse.solve_block's outputs plus modal (n, N), each mode's tail amplitude
    max |q_n| (m), and final (n, 2N), the state y at the end (m, m/s; NaN where the point
    failed: where a stepped sweep's next point starts). basis: the span's mode shapes
    (kernels.modes; N = its number of modes). halt: as kernels.lanes.solve_block's
    (an interrupt starts no further row). Releases the GIL (sweep.threads runs blocks on
    threads)."""
    none = np.empty(0)
    for i in range(lo, hi):
        if halt[0] != 0:
            return
        states[i] = solve_point(params[i], basis, settings, reals[i], counts[i], series[i],
                                modal[i], final[i], none, base, eighth)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_swept_block(params, basis, settings, lo, hi, states, reals, counts, series, modal,
                      final, envelope, base, eighth):
    """`solve_block` for a swept base frequency (settings[SWEPT] = 1), with the response
    envelope of the midspan deflection: envelope (n, n_bands) (m; n_bands may be 0)."""
    for i in range(lo, hi):
        states[i] = solve_point(params[i], basis, settings, reals[i], counts[i], series[i],
                                modal[i], final[i], envelope[i], base, eighth)
