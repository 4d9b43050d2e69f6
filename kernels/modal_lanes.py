"""Lock-step driver of the multi-mode System (kernels.modes): LANES trajectories side by side.

The interface and results (to round-off) of kernels.modal_driver.solve_block, for any number
of modes N. Each lane is one trajectory with its own time, step size and accept/reject
decision: SciPy's RK45 or DOP853 on the 2N state, SciPy's error norm over its 2N components,
SciPy's controller (or the PI controller), in SciPy's order of attempts.

The lanes' state lives in arrays whose LAST axis is the lane (contiguous): Y[c, l] (the state,
component c of lane l), K[s, c, l] (stage s; K[0] = f(t, y)), PP[c, l] (the prepared rows of
kernels.modes.prepare), FLD[f, j, l] (the fields a, b, c, d at quadrature node j). Every loop
over stages, modes, components or nodes sits OUTSIDE the innermost loop, which runs across the
lanes with straight-line arithmetic, so LLVM vectorises it (measured: the right-hand side and `_attempt`
compile to packed AVX-512 FMAs on zmm registers):

- the System's one right-hand side, kernels.modes.lanes_derivative, for every lane, cos(W t)
  and sin(w_b t) by vecmath.fast_cos / fast_sin (the scalar driver runs it with one lane and
  libm's);
- `_attempt`: one attempt of the tableau (A, B, C) (stage sums, the right-hand sides, the
  solution, f(t + h, y_new)) and SciPy's error norm;
- `_control`: accept/reject and the step-size update, err^(-1/5) by vecmath.inv_fifth_root
  (kernels.lanes._step_factor);
- trajectory.next_attempts: trajectory.next_attempt for the lanes whose step needs no special care;
- `_midspan`, `_mode_events`, `_finish`, `_tail_modes`, `_span_events`, `_advance`: the
  accepted step's stages projected on the midspan deflection (K_mid), the test for anything
  unusual, the Observer's step-end metrics of an ordinary step (trajectory.observe_step_end),
  each mode's tail amplitude at the step's end, the test for room above the span's largest
  deflection so far, and the move to the step's end.

An accepted step with anything to locate on a dense output (an extremum of the midspan
deflection; an extremum of a mode, a crest of a curvature or a clamp load where its bound over
the step (`_reaches`) could beat the largest so far; the tail's start, a time-series sample,
a threshold crossing) or a divergence goes to the scalar path for that lane alone (`_flagged_lane`): the scalar driver's
own functions on copies of the lane's columns (the divergence test on every mode,
modal_driver._observe_modes, trajectory.record_step on the lane's accumulator W[j::LANES]
and its Observer row, with the scalar driver's types, so that they compile once for both).
So do a lane's unusual steps to try (trajectory.next_attempt). An ordinary step whose bound
leaves room above the span's largest deflection so far has just that searched, by the scalar
driver's modal_driver.observe_span on copies of the lane's columns (`_span_lane`). A lane whose
trajectory ends is classified as modal_driver.solve_point does and takes the next point of the
block. Set-up (f(0), SciPy's initial step) is the scalar driver's arithmetic.

A random base acceleration (the record kind, kernels.excitation) runs here too: the right-hand
side reads each lane's record; a step with an event goes to the scalar path as above, whose
`record_step` and `modal_driver.observe_random_modes` accumulate the statistics (the lanes'
accumulator then has the record's slots, trajectory.SCALAR_SLOTS), and an ordinary step gets
the same two from `_record_steps`, lane by lane (the midspan's statistics,
trajectory.record_statistics, and the curvature squares), and with DOP853 its time-series
samples too (trajectory.take_hermite_samples).

Not bit for bit the scalar driver's (fast_cos, fast_sin, inv_fifth_root to an ulp or two; the
loops fuse multiply-adds), so results equal its results to what a trajectory makes of
round-off (tests/test_modal_lanes.py measures that spread with a one-ulp change of q_1(0)).
Units: t in s, q in m, q' in m/s.
"""

import math

import numba as nb
import numpy as np

from . import dop853
from . import dopri5
from . import excitation as ex
from . import metrics as mt
from . import modal_driver as drv
from . import modes as md
from . import trajectory as tj
from .flags import CONTRACT
from .lanes import _step_factor
from .layout import (CONTROLLER, LOADS, METHOD, N_COUNTS,
                     N_REALS, RTOL, SAMPLE_DT, TOL, WANT_SETTLING)
from .oscillator import BOUND, N_PARAMS
from .transverse import classify_metrics

LANES = 32      # trajectories per lock-step group: the lane loops' trip count; 32 lets LLVM's
                # interleaved vector loops (4 x 8 doubles) run whole (16: 2.3x slower a lane)
SIMD = 4        # the vector loops cover the active lanes rounded up to this


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _combine(K, s, w, Y, H, OUT, dim, n_run, skip_zeros):
    """OUT[c, l] = Y[c, l] + (K[0, c, l] w[0] + ... + K[s - 1, c, l] w[s - 1]) H[l] (SciPy's
    stage sums, in order; with skip_zeros the zero weights are left out)."""
    for c in range(dim):
        first = True
        for k in range(s):
            wk = w[k]
            if skip_zeros and wk == 0.0:
                continue
            if first:
                for l in range(n_run):
                    OUT[c, l] = K[k, c, l] * wk
                first = False
            else:
                for l in range(n_run):
                    OUT[c, l] += K[k, c, l] * wk
        if first:
            for l in range(n_run):
                OUT[c, l] = Y[c, l]
        else:
            for l in range(n_run):
                OUT[c, l] = Y[c, l] + OUT[c, l] * H[l]


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _attempt(W, Y, YN, K, ST, TT, H, ERR, PP, n, T, FLD, SC, A, B, C, rtol, eighth, n_run,
             base, CP, PY, LB, own):
    """One attempt of the tableau (A, B, C) from every lane's (t, Y) with step H (SciPy's
    rk_step: K[1..n_stages] and YN = y_new, K[n_stages] = f(t + h, y_new); K[0] = f(t, y)
    given) and SciPy's error norm over the 2N components (ERR): RK45's RMS, or DOP853's
    combination of its fifth- and third-order estimates (`eighth`). The absolute tolerances are
    each lane's accumulator's (ATOL_Q for q_n, ATOL_V for q_n'). CP, PY, LB, own: the basis'
    coupling and polynomial, or each lane's own (kernels.modes.lanes_derivative)."""
    L = LANES
    dim = 2 * n
    n_stages = B.shape[0]
    for s in range(1, n_stages + 1):   # the stages, then f(t + h, y_new) (one call site:
        last = s == n_stages            # md.lanes_derivative is inlined, once)
        X = YN if last else ST
        _combine(K, s, B if last else A[s], Y, H, X, dim, n_run, eighth)
        c = 1.0 if last else C[s]
        for l in range(n_run):
            TT[l] = W[tj.T * L + l] + c * H[l]
        md.lanes_derivative(TT, X, K, s, PP, n, T, FLD, SC, n_run, True, base, CP, PY, LB,
                            own)
    # the error norm: ST[0], ST[1] accumulate the sums of squares, SC[0], SC[1] the estimates
    for l in range(n_run):
        ST[0, l] = 0.0
        ST[1, l] = 0.0
    for c in range(dim):
        r = (tj.ATOL_Q if c < n else tj.ATOL_V) * L
        if eighth:
            for k in range(n_stages + 1):
                e5 = dop853.E5[k]
                e3 = dop853.E3[k]
                if k == 0:
                    for l in range(n_run):
                        SC[0, l] = K[0, c, l] * e5
                        SC[1, l] = K[0, c, l] * e3
                elif e5 != 0.0 or e3 != 0.0:
                    for l in range(n_run):
                        SC[0, l] += K[k, c, l] * e5
                        SC[1, l] += K[k, c, l] * e3
            for l in range(n_run):
                scale = W[r + l] + max(abs(Y[c, l]), abs(YN[c, l])) * rtol
                x5 = SC[0, l] / scale
                x3 = SC[1, l] / scale
                ST[0, l] += x5 * x5
                ST[1, l] += x3 * x3
        else:
            for l in range(n_run):
                SC[0, l] = K[0, c, l] * dopri5.E[0]
            for k in range(1, n_stages + 1):
                e = dopri5.E[k]
                if e != 0.0:
                    for l in range(n_run):
                        SC[0, l] += K[k, c, l] * e
            for l in range(n_run):
                scale = W[r + l] + max(abs(Y[c, l]), abs(YN[c, l])) * rtol
                x = SC[0, l] * H[l] / scale
                ST[0, l] += x * x
    if eighth:
        for l in range(n_run):
            e_a = ST[0, l]
            e_b = ST[1, l]
            err = abs(H[l]) * e_a / math.sqrt((e_a + dop853.ERR3_WEIGHT * e_b) * dim)
            ERR[l] = 0.0 if (e_a == 0.0) & (e_b == 0.0) else err
    else:
        for l in range(n_run):
            ERR[l] = math.sqrt(ST[0, l] / dim)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _control(W, H, ERR, SC, settings, n_run):
    """trajectory.control across the lanes with an attempt (H > 0): the counts, the step-size
    update (SciPy's controller for the method, or the PI controller) and accept/reject. SC[0]:
    scratch for the step-size factors."""
    L = LANES
    eighth = settings[METHOD] != 0.0
    per_attempt = float(dop853.RHS_PER_ATTEMPT if eighth else dopri5.RHS_PER_ATTEMPT)
    pi = settings[CONTROLLER] != 0.0
    FAC = SC[0]
    if pi:
        for l in range(n_run):
            err = ERR[l]
            memory = W[tj.LOG2_ERR_PREV * L + l]
            FAC[l] = dopri5.pi_step_factor(err, memory, W[tj.REJECTED_NOW * L + l] != 0.0)
            take = (H[l] > 0.0) & (err < 1.0)
            W[tj.LOG2_ERR_PREV * L + l] = dopri5.pi_log2_err(err) if take else memory
    elif eighth:
        for l in range(n_run):
            FAC[l] = _step_factor(ERR[l], W[tj.REJECTED_NOW * L + l] != 0.0, True)
    else:
        for l in range(n_run):
            FAC[l] = _step_factor(ERR[l], W[tj.REJECTED_NOW * L + l] != 0.0, None)
    for l in range(n_run):
        active = H[l] > 0.0
        accepted = ERR[l] < 1.0
        rejected_before = W[tj.REJECTED_NOW * L + l] != 0.0
        W[tj.RHS_EVALS * L + l] += per_attempt if active else 0.0
        W[tj.H_ABS * L + l] *= FAC[l] if active else 1.0
        W[tj.REJECTED_NOW * L + l] = (0.0 if accepted else 1.0) if active else (
            1.0 if rejected_before else 0.0)
        W[tj.REJECTED * L + l] += 1.0 if active & (not accepted) else 0.0
        W[tj.STEPS * L + l] += 1.0 if active & accepted else 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _midspan(K, YN, KM, QV, weights, LB, own, n, n_stages, eighth, n_run):
    """KM[s, 0, l], KM[s, 1, l]: the stages of lane l projected on the midspan deflection and
    its rate (modal_driver._project's sums, in order), for the stages record_step reads: all
    for RK45, the last (f(t + h, y_new), at KM[1]) for DOP853; QV[0, l], QV[1, l]: y_new's.
    The weights phi_n(1/2) are `weights`, or each lane's (own: LB, kernels.modes.
    write_lane_basis), whose zeros are `weights`' (the same for all)."""
    mid = md.lb_midspan(n)
    for s in range(n_stages + 2):
        if eighth and s < n_stages:
            continue
        r = 1 if eighth else s
        for part in range(2):
            for l in range(n_run):
                if s <= n_stages:
                    KM[r, part, l] = 0.0
                else:
                    QV[part, l] = 0.0
            for i in range(n):
                w = weights[i]
                if w == 0.0:
                    continue
                if s <= n_stages and own:
                    for l in range(n_run):
                        KM[r, part, l] += LB[mid + i, l] * K[s, part * n + i, l]
                elif s <= n_stages:
                    for l in range(n_run):
                        KM[r, part, l] += w * K[s, part * n + i, l]
                elif own:
                    for l in range(n_run):
                        QV[part, l] += LB[mid + i, l] * YN[part * n + i, l]
                else:
                    for l in range(n_run):
                        QV[part, l] += w * YN[part * n + i, l]


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _reaches(Y, YN, K, H, REACH, QB, n, n_run, eighth):
    """REACH[c, l]: an upper bound (m) of |q_c(t) - q_c(t_0)| over lane l's attempt, on mode
    c's interpolant as the scalar path builds it (modal_driver._mode_interpolant: DOP853's
    quintic Hermite through the state and its rates at both ends, RK45's quartic from the
    stages): the sum of its coefficients' sizes (a value located inside the step on the
    scalar path can never exceed |q_c(t_0)| + REACH[c, l]); QB[c, l]: an upper bound (m) of
    |q_c(t)| over it, as modal_driver.mode_reach (modal_driver.chord_bound: the tighter of
    |q_c(t_0)| + REACH and the chord's). K: the stages; eighth: the method switch. The one
    rule behind the lanes' tests of whether a step could hold a new largest deflection, mode
    amplitude, curvature or load (`_mode_events`, `_span_events`)."""
    last = K.shape[0] - 1                   # f(t + h, y_new)
    for c in range(n):
        for l in range(n_run):
            h = H[l]
            if eighth:
                c3, c4, c5 = dop853.hermite_terms(Y[c, l], Y[n + c, l], K[0, n + c, l],
                                                  YN[c, l], YN[n + c, l], K[last, n + c, l], h)
                a2 = 0.5 * h * h * K[0, n + c, l]
                reach = abs(h * Y[n + c, l]) + abs(a2) + abs(c3) + abs(c4) + abs(c5)
                total = h * Y[n + c, l] + a2 + c3 + c4 + c5
                spread = (drv.CHORD[1] * abs(a2) + drv.CHORD[2] * abs(c3)
                          + drv.CHORD[3] * abs(c4) + drv.CHORD[4] * abs(c5))
            else:
                reach = 0.0
                total = 0.0
                spread = 0.0
                for k in range(dopri5.QUARTIC_TERMS):
                    term = 0.0
                    for j in range(dopri5.N_STAGES + 1):
                        term += K[j, c, l] * dopri5.P[j, k]
                    reach += abs(term)
                    total += term
                    spread += drv.CHORD[k] * abs(term)
                reach *= abs(h)
                total *= h
                spread *= abs(h)
            REACH[c, l] = reach * BOUND_MARGIN
            QB[c, l] = drv.chord_bound(Y[c, l], Y[c, l] + total,
                                       (abs(Y[c, l]) + reach) * BOUND_MARGIN,
                                       spread * BOUND_MARGIN)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _basis_of(family, basis, own, b):
    """Basis b of the stacked `family` (kernels.modes.member) where the lanes carry bases of
    their own (own), else `basis`, every lane's (nothing to build at each step)."""
    return md.member(family, b) if own else basis


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always", _nrt=False)
def _load_rows(family, basis, own, b):
    """(CLAMPS, COUPLING) of basis b of `family`, or of `basis` (`_basis_of`)."""
    if own:
        return family[md.CLAMPS][b], family[md.COUPLING][b]
    return basis[md.CLAMPS], basis[md.COUPLING]


BOUND_MARGIN = 1.0 + 1e-12
"""REACH's margin over the coefficients' sum: the lanes' arithmetic (fused multiply-adds)
may round the sum an ulp or two below the scalar path's."""


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _span_events(W, QB, MOD, SPAN, MOVE, FLAG, n, n_run, LB):
    """SPAN[l] = 1 where lane l's ordinary accepted step (MOVE 1, FLAG 0: `_finish`) ends in
    the tail window and modal_driver._span_bound over the step (from QB, `_reaches`)
    exceeds the span's largest deflection so far (MOD's slot 2N), else 0: the step may hold
    a larger one, which `_span_lane` searches for (a step on the scalar path searches in
    modal_driver._observe_modes). LB: each lane's basis (its shapes' sizes,
    modal_driver.shape_size)."""
    L = LANES
    for l in range(n_run):
        SPAN[l] = 0.0                       # the bound, until the test below
    sizes = md.lb_sizes(n)
    for c in range(n):
        for l in range(n_run):
            SPAN[l] += QB[c, l] * LB[sizes + c, l]
    for l in range(n_run):
        ordinary = (MOVE[l] != 0.0) & (FLAG[l] == 0.0)
        tail = W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]
        SPAN[l] = 1.0 if ordinary & tail & (SPAN[l] > MOD[2 * n, l]) else 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _span_lane(j, n, Y, YN, K, H, MOD, eighth, Kl, yl, ynl, ml, Km, QA, qx, basis):
    """Lane j's ordinary step that `_span_events` marked: the span's largest deflection over
    it by the scalar driver's modal_driver.observe_span, on copies of the lane's state columns
    and every mode's interpolant built from them as the scalar path builds it
    (modal_driver._mode_interpolant), with the scalar driver's types (Kl, yl, ynl, ml, Km,
    QA, qx: `_flagged_lane`'s scratch)."""
    for s in range(K.shape[0]):
        for c in range(2 * n):
            Kl[s, c] = K[s, c, j]
    for c in range(2 * n):
        yl[c] = Y[c, j]
        ynl[c] = YN[c, j]
    h = H[j]
    for c in range(n):
        drv._mode_interpolant(yl, ynl, Kl, h, c, n, eighth, Km, QA[c])
    place = drv.place_slot(n)
    ml[2 * n] = MOD[2 * n, j]
    ml[place] = MOD[place, j]
    drv.observe_span(yl, h, QA, 0.0, n, qx, ml, basis)
    MOD[2 * n, j] = ml[2 * n]
    MOD[place, j] = ml[place]


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _mode_events(W, Y, YN, H, ERR, BOUNDS, MOD, EV, BIG, n, n_run, LB, family, basis, own,
                 BI, LD, P1L, REACH, QB, QMAX, base):
    """EV[l] = 1 where lane l's accepted attempt has, in some mode, a divergence (|q_n| > bound, or
    q_n' not finite), or, ending in the tail window, something the scalar path would locate
    inside it that could beat its largest so far (REACH and QB, `_reaches`: each mode's
    bounds over the step): an extremum of q_n in a mode not negligible beside the largest
    (modal_driver.negligible; BIG: scratch, the largest mode's peak) whose bound exceeds the
    mode's tail amplitude, a crest of the curvature at a clamp or at midspan (the
    kernels.modes.CLAMPS rows of `basis`, every lane's, or with `own` of each lane's, in LB; a
    pinned clamp's are all 0: never a crest) whose bound exceeds its largest so far, or a
    maximum of the stretch or of a clamp's shear (kernels.modes.span_loads with lane l's
    basis, `_load_rows`: its CLAMPS and COUPLING; MOD's shear factor; LD (2, 6): scratch;
    P1L: the lanes' Observer rows, for the base inertia's part of the shear,
    modal_driver.inertia_at) whose bound (modal_driver.load_bound_within; QMAX (N): scratch)
    exceeds its largest so far, where the scene observes the loads (settings[LOADS], in
    MOD): the scalar path's turn; else 0. A step whose events could not beat the largest
    values so far changes none of them on the scalar path (on a random record most of them:
    the extrema of the modes, curvatures and shears come at nearly every step). base: the
    excitation switch."""
    L = LANES
    for l in range(n_run):
        EV[l] = 0.0
        BIG[l] = 0.0
    observe = MOD[drv.factor_slot(n) + 1, 0] != 0.0     # settings[LOADS], every lane's
    for i in range(n):
        for l in range(n_run):
            BIG[l] = max(BIG[l], max(MOD[n + i, l], abs(YN[i, l])))
    for i in range(n):
        for l in range(n_run):
            v0 = Y[n + i, l]
            v1 = YN[n + i, l]
            turns = ((((v0 > 0.0) & (v1 <= 0.0)) | ((v0 < 0.0) & (v1 >= 0.0)))
                     & (not drv.negligible(max(MOD[n + i, l], abs(YN[i, l])), BIG[l]))
                     & (QB[i, l] > MOD[i, l]))
            tail = W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]
            bad = (not (abs(YN[i, l]) <= BOUNDS[l])) | (not (abs(v1) <= 1e308))
            EV[l] = 1.0 if (turns & tail) | bad else EV[l]
    if not observe:
        return
    slot = drv.clamp_slot(n)
    CVs = basis[md.CLAMPS]
    for e in range(md.N_BENDS):
        bend = md.lb_bends(n) + e * n
        for l in range(n_run):
            r0 = 0.0
            r1 = 0.0
            c0 = 0.0
            reach = 0.0
            for i in range(n):
                cv = LB[bend + i, l] if own else CVs[e, i]
                r0 += cv * Y[n + i, l]
                r1 += cv * YN[n + i, l]
                c0 += cv * Y[i, l]
                reach += abs(cv) * REACH[i, l]
            crest = ((r0 > 0.0) & (r1 <= 0.0)) | ((r0 < 0.0) & (r1 >= 0.0))
            tail = W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]
            beats = abs(c0) + reach > MOD[slot + e, l]
            EV[l] = 1.0 if crest & tail & beats else EV[l]
    a = LD[0]
    b = LD[1]
    loads = drv.load_slot(n)
    for l in range(n_run):
        if not (W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]) or EV[l] != 0.0:
            continue
        CV, CP = _load_rows(family, basis, own, BI[l])
        drv.state_loads(CV, CP, Y[:n, l], Y[n:, l], n, MOD[:, l], W[tj.T * L + l],
                        P1L[l], base, a)
        drv.state_loads(CV, CP, YN[:n, l], YN[n:, l], n, MOD[:, l], W[tj.T_NEW * L + l],
                        P1L[l], base, b)
        for c in range(n):
            QMAX[c] = QB[c, l]
        for k in range(3):
            if not (drv._load_rises(a, k) > 0.0 and drv._load_rises(b, k) <= 0.0):
                continue
            if drv.load_bound_within(W[tj.T * L + l], W[tj.T_NEW * L + l], QMAX, n, CV, CP,
                                     MOD[:, l], P1L[l], base, k) > MOD[loads + k, l]:
                EV[l] = 1.0
                break


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _finish(W, H, ERR, QV, KM, EV, FLAG, MOVE, P1, settings, n_samples, last, n_run,
            sampled_here, base):
    """For every lane's accepted attempt: an ordinary step (nothing to locate on the dense
    output: no extremum of the midspan deflection or of any mode (EV), no divergence, not the
    tail's start, no time-series sample, no threshold crossing) gets the Observer's step-end
    metrics (trajectory.observe_step_end, as in record_step) and moves to its end (MOVE 1);
    any other is left to the scalar path (FLAG 2). A random record's ordinary steps get their
    statistics from `_record_steps`, and with DOP853 (sampled_here) their time-series samples
    too. Returns how many lanes it flagged."""
    L = LANES
    track = settings[WANT_SETTLING] != 0.0
    thr_rel = settings[TOL]
    dt_sample = settings[SAMPLE_DT]
    n_flagged = 0
    for l in range(n_run):
        t_tail = W[tj.T_TAIL * L + l]          # the lane's own tail window start
        active = H[l] > 0.0
        accepted = ERR[l] < 1.0
        t = W[tj.T * L + l]
        t_new = W[tj.T_NEW * L + l]
        q_old = W[tj.Q * L + l]
        v_old = W[tj.V * L + l]
        qn = QV[0, l]
        vn = QV[1, l]
        fv_new = KM[last, 1, l]
        peak_new = max(W[tj.PEAK * L + l], abs(qn))
        thr = thr_rel * peak_new
        extremum = ((v_old > 0.0) & (vn <= 0.0)) | ((v_old < 0.0) & (vn >= 0.0))
        bounded = (abs(qn) <= P1[BOUND * L + l]) & (abs(vn) <= 1e308)
        straddles = (t < t_tail) & (t_tail <= t_new)
        sample = W[tj.SAMPLE * L + l]
        due = (sample < n_samples) & (sample * dt_sample <= t_new)
        crosses = track & (abs(qn) <= thr) & (thr < abs(q_old))
        event = active & accepted & ((EV[l] != 0.0) | extremum | (not bounded) | straddles
                                     | (due & (not sampled_here)) | crosses)
        done = active & accepted & (not event)
        FLAG[l] = 2.0 if event else 0.0
        MOVE[l] = 1.0 if done else 0.0
        n_flagged += 1 if event else 0
        tj.observe_step_end(W, l, L, P1, l, L, t, H[l], t_new, qn, vn, fv_new, t_tail, track,
                            0.0, 0.0, thr_rel, done, True, base)
        W[tj.T * L + l] = t_new if done else t
        W[tj.Q * L + l] = qn if done else q_old
        W[tj.V * L + l] = vn if done else v_old
        W[tj.FQ * L + l] = vn if done else W[tj.FQ * L + l]
        W[tj.FV * L + l] = fv_new if done else W[tj.FV * L + l]
    return n_flagged


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _tail_modes(W, YN, MOD, MOVE, FLAG, n, n_run, LB, family, basis, own, BI, LD, P1L,
                base):
    """The modes' accumulator (modal_driver.modal_size rows) at the end of an ordinary
    accepted step (MOVE 1, FLAG 0), as modal_driver._observe_modes there: each mode's peak
    MOD[N + i, l] = max(MOD[N + i, l], |q_i(t_new)|), and its tail amplitude MOD[i, l] the
    same once t_new >= the lane's tail start; so the curvatures (as `_mode_events`) in their
    slots (modal_driver.clamp_slot) and the stretch and shears (lane l's basis, `_load_rows`)
    in theirs (modal_driver.load_slot), where the scene observes the loads (LD: scratch; P1L:
    the Observer rows, modal_driver.inertia_at's). base: the excitation switch."""
    L = LANES
    for i in range(n):
        for l in range(n_run):
            ordinary = (MOVE[l] != 0.0) & (FLAG[l] == 0.0)
            take = ordinary & (W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l])
            q = abs(YN[i, l])
            MOD[i, l] = max(MOD[i, l], q) if take else MOD[i, l]
            MOD[n + i, l] = max(MOD[n + i, l], q) if ordinary else MOD[n + i, l]
    if MOD[drv.factor_slot(n) + 1, 0] == 0.0:          # settings[LOADS]: none observed
        return
    slot = drv.clamp_slot(n)
    CVs = basis[md.CLAMPS]
    for e in range(md.N_BENDS):
        bend = md.lb_bends(n) + e * n
        for l in range(n_run):
            c = 0.0
            for i in range(n):
                c += (LB[bend + i, l] if own else CVs[e, i]) * YN[i, l]
            take = ((MOVE[l] != 0.0) & (FLAG[l] == 0.0)
                    & (W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]))
            MOD[slot + e, l] = max(MOD[slot + e, l], abs(c)) if take else MOD[slot + e, l]
    b = LD[0]
    loads = drv.load_slot(n)
    for l in range(n_run):
        take = ((MOVE[l] != 0.0) & (FLAG[l] == 0.0)
                & (W[tj.T_NEW * L + l] >= W[tj.T_TAIL * L + l]))
        if not take:
            continue
        CV, CP = _load_rows(family, basis, own, BI[l])
        drv.state_loads(CV, CP, YN[:n, l], YN[n:, l], n, MOD[:, l], W[tj.T_NEW * L + l],
                        P1L[l], base, b)
        for k in range(3):
            MOD[loads + k, l] = max(MOD[loads + k, l], abs(b[2 * k]))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _advance(Y, YN, K, MOVE, dim, n_stages, n_run):
    """The lanes with MOVE[l] != 0 (an accepted step that goes on) move to the step's end:
    Y = y_new and K[0] = f(t + h, y_new)."""
    for c in range(dim):
        for l in range(n_run):
            move = MOVE[l] != 0.0
            Y[c, l] = YN[c, l] if move else Y[c, l]
            K[0, c, l] = K[n_stages, c, l] if move else K[0, c, l]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _load_lane(params, n, settings, point, j, W, Y, K, PP, P1, P1L, MOD, states, reals,
               counts, series, modal, final, pp, yl, fl, basis, LB, base):
    """Give lane j the trajectory of row `point` on `basis` (its column of LB too), set up by
    the scalar driver's own
    modal_driver.start (f(0), SciPy's initial step, the midspan accumulator, each mode's tail
    amplitude and divergence at t = 0). An invalid row is answered at once
    (modal_driver.solve_point): returns False."""
    L = LANES
    row = params[point]
    dim = 2 * n
    if not drv.valid(row, n):
        for c in range(N_REALS):
            reals[point, c] = math.nan
        for c in range(N_COUNTS):
            counts[point, c] = 0
        for c in range(series.shape[1]):
            series[point, c] = math.nan
        for c in range(n):
            modal[point, c] = math.nan
        for c in range(2 * n):
            final[point, c] = math.nan
        states[point] = mt.INVALID_INPUT
        return False
    md.prepare(row, n, pp, basis[md.RATIOS])
    S = md.scratch(pp, n, basis)
    for c in range(pp.shape[0]):
        PP[c, j] = pp[c]
    md.write_lane_basis(basis, LB, j)
    p1 = drv.observer_row(row, n, pp)
    for c in range(N_PARAMS):
        P1[c * L + j] = p1[c]
        P1L[j, c] = p1[c]
    mod = np.empty(MOD.shape[0])
    drv.start(row, n, settings, yl, fl, pp, S, basis[md.TABLES], p1, W[j::L], series[point],
              mod, basis[md.MIDSPAN], basis, base)
    for c in range(dim):
        Y[c, j] = yl[c]
        K[0, c, j] = fl[c]
    for c in range(MOD.shape[0]):
        MOD[c, j] = mod[c]
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _move_lane(k, i, W, Y, K, MOD, PP, P1, P1L, BOUNDS, H, LB, BI):
    """Lane k's trajectory into the idle lane i: every array that carries a lane's state from
    one attempt to the next (its accumulator, state, stages (K[0] = f(t, y)), modes'
    accumulator, prepared and Observer rows, bound, step, basis); lane k is left idle. A lane's
    arithmetic does not depend on its place, so neither do its results."""
    L = LANES
    for c in range(W.shape[0] // L):
        W[c * L + i] = W[c * L + k]
    for c in range(Y.shape[0]):
        Y[c, i] = Y[c, k]
    for s in range(K.shape[0]):
        for c in range(K.shape[1]):
            K[s, c, i] = K[s, c, k]
    for c in range(MOD.shape[0]):
        MOD[c, i] = MOD[c, k]
    for c in range(PP.shape[0]):
        PP[c, i] = PP[c, k]
    for c in range(LB.shape[0]):
        LB[c, i] = LB[c, k]
    BI[i] = BI[k]
    for c in range(P1.shape[0] // L):
        P1[c * L + i] = P1[c * L + k]
        P1L[i, c] = P1L[k, c]
    BOUNDS[i] = BOUNDS[k]
    H[i] = H[k]
    H[k] = 0.0
    W[tj.STATUS * L + k] = mt.DIVERGED           # idle, as before its first load


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _end_lane(params, n, settings, point, j, W, Y, MOD, states, reals, counts, series, modal,
              final, buf, yl, ml, basis, base):
    """Classify lane j's finished trajectory (row `point`) as modal_driver.solve_point does."""
    acc = W[j::LANES]
    tj.end_series(acc, series[point])
    for c in range(2 * n):
        yl[c] = Y[c, j]
    resting = drv.at_rest(params[point], basis, acc[tj.T], yl,
                          settings[TOL] * acc[tj.TAIL_AMP], base)
    state = classify_metrics(settings, acc, buf, reals[point], counts[point], base, resting)
    for c in range(MOD.shape[0]):
        ml[c] = MOD[c, j]
    state = drv.span_state(state, ml, yl, n, settings, reals[point], basis)
    if ex.is_record(base) and state == mt.COMPLETED:
        drv.curvature_moments(ml, n, acc, reals[point])
    failed = state == mt.DIVERGED or state == mt.STEP_TOO_SMALL or state == mt.MAX_STEPS
    for c in range(n):
        modal[point, c] = math.nan if failed else MOD[c, j]
    for c in range(2 * n):
        final[point, c] = math.nan if failed else yl[c]
    states[point] = state


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _flagged_lane(W, j, n, settings, Y, YN, K, KM, H, P1L, MOD, bound, weights, buf, series,
                  i, track, thr_rel, eighth, n_stages, Kl, yl, ynl, ml, Km, QA, qx, basis,
                  Kmid, Qc, base):
    """An accepted step of lane j (point i) that `_finish` left to the scalar path: reduced as
    modal_driver.integrate does (the divergence test on every mode, each mode's tail amplitude
    by modal_driver._observe_modes, the midspan Observer trajectory.record_step) on copies of
    the lane's state columns, its accumulator W[j::LANES] and its Observer row P1L[j] (the
    scalar driver's types, trajectory.new_accumulator: these compile once for both drivers).
    Returns whether the lane moves on to the step's end (False: a mode diverged)."""
    acc = W[j::LANES]
    t = acc[tj.T]
    t_new = acc[tj.T_NEW]
    h = H[j]
    for c in range(n):
        if not (abs(YN[c, j]) <= bound and math.isfinite(YN[n + c, j])):
            acc[tj.STATUS] = mt.DIVERGED
            acc[tj.T_STOP] = t_new
    if acc[tj.STATUS] != mt.RUNNING:
        return False
    for s in range(n_stages + 1):
        for c in range(2 * n):
            Kl[s, c] = K[s, c, j]
    for c in range(2 * n):
        yl[c] = Y[c, j]
        ynl[c] = YN[c, j]
    for c in range(MOD.shape[0]):
        ml[c] = MOD[c, j]
    t_tail = acc[tj.T_TAIL]
    drv._observe_modes(t, t_new, t_tail, yl, ynl, Kl, h, n, eighth, ml, Km, QA, qx, basis,
                       Qc, P1L[j], base)
    for r in range(Kmid.shape[0]):
        Kmid[r, 0] = KM[r, 0, j]
        Kmid[r, 1] = KM[r, 1, j]
    q_new = drv._project(ynl, weights, 0, n)
    v_new = drv._project(ynl, weights, n, n)
    tj.record_step(P1L[j], 0, 1, settings, acc, Kmid, q_new, v_new, h, Qc, buf, series[i],
                   track, 0.0, 0.0, thr_rel, -1.0, 0.0, True, base, eighth)
    drv.observe_random_modes(t, t_tail, yl, ynl, Kl, h, n, basis[md.CLAMPS], ml, acc, base)
    drv.restart_modes(acc, t_tail, t, t_new, yl, ynl, Kl, h, n, eighth, ml, Km, QA, qx,
                      basis, Qc, P1L[j], base)
    for c in range(MOD.shape[0]):
        MOD[c, j] = ml[c]
    return True                  # (a midspan divergence moves on, as in the scalar driver)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _refine_marked(W, P1L, n_run, base):
    """trajectory.refine_marked_lanes on the scalar path's types (a lane's accumulator
    W[j::LANES], its Observer row P1L[j]), so that the refinement compiles once for both
    drivers: `refine_acceleration_peak` for each lane that `observe_acceleration` marked."""
    for j in range(n_run):
        if W[tj.ACC_TURN * LANES + j] != 0.0:
            tj.refine_acceleration_peak(W[j::LANES], 0, 1, P1L[j], 0, 1, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _keep_start(W, START, n_run, base):
    """Each lane's midspan state at its attempt's start (t, q, q', q'': rows 0-3 of START),
    before `_finish` moves an ordinary step to its end: a record's statistics need both ends
    (`_record_steps`). base: the excitation switch (excitation.by_kind)."""
    L = LANES
    for j in range(n_run):
        START[0, j] = W[tj.T * L + j]
        START[1, j] = W[tj.Q * L + j]
        START[2, j] = W[tj.V * L + j]
        START[3, j] = W[tj.FV * L + j]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _record_steps(W, START, Y, YN, K, H, MOVE, FLAG, MOD, P1L, settings, n, n_run, family,
                  BI, yl, ynl, Kl, ml, series, point, Qc, sampled_here, base):
    """A random record's ordinary accepted steps (MOVE 1, FLAG 0: `_finish` moved them to
    their ends, with the step-end sample of the absolute acceleration; the others are the
    scalar path's, `_flagged_lane`): what the scalar path adds for such a step, on the
    scalar path's types, lane by lane: the midspan's statistics over the step
    (trajectory.record_statistics, as record_step calls it; START: the step's start,
    `_keep_start`) and, where the scene observes the loads, the curvature squares
    (modal_driver.observe_random_modes on copies of the lane's columns and its basis' curvature
    rows, basis BI[j] of the stacked `family`; yl, ynl, Kl, ml: scratch); with DOP853, the
    time series' samples in the step (for the spectra) on the midspan's quintic Hermite
    through both ends, as record_step takes them
    (trajectory.take_hermite_samples into series[point[j]]; Qc: scratch; RK45's samples are its
    quartic's, from the stages: `_finish` leaves those steps to the scalar path, and
    sampled_here is False). Before
    `_advance` (Y is the steps' start)."""
    L = LANES
    last = K.shape[0] - 1                      # f(t + h, y_new)
    bends = MOD[drv.factor_slot(n) + 1, 0] != 0.0      # settings[LOADS]
    dt_sample = settings[SAMPLE_DT]
    for j in range(n_run):
        if not ((MOVE[j] != 0.0) & (FLAG[j] == 0.0)):
            continue
        acc = W[j::L]
        t = START[0, j]
        if sampled_here:
            tj.take_hermite_samples(acc, series[point[j]], t, acc[tj.T], H[j], START[1, j],
                                    START[2, j], START[3, j], acc[tj.Q], acc[tj.V],
                                    acc[tj.FV], Qc, dt_sample)
        t_tail = acc[tj.T_TAIL]
        if t < t_tail:
            continue                           # the statistics start in the window
        tj.record_statistics(settings, acc, P1L[j], 0, 1, t, acc[tj.T], START[1, j],
                             START[2, j], START[3, j], acc[tj.Q], acc[tj.V], acc[tj.FV],
                             False, 0.0, base)
        if not bends:
            continue
        for c in range(2 * n):
            yl[c] = Y[c, j]
            ynl[c] = YN[c, j]
            Kl[0, c] = K[0, c, j]
            Kl[last, c] = K[last, c, j]
        for c in range(MOD.shape[0]):
            ml[c] = MOD[c, j]
        drv.observe_random_modes(t, t_tail, yl, ynl, Kl, H[j], n, family[md.CLAMPS][BI[j]],
                                 ml, acc, base)
        for c in range(MOD.shape[0]):
            MOD[c, j] = ml[c]


# A sine's acceleration peaks refined (ordinary steps'), a record's statistics (its ordinary
# steps'): each compiled for its own kind only (excitation.by_kind)
_sine_refine_marked = ex.by_kind(_refine_marked, None)
_keep_record_start = ex.by_kind(None, _keep_start)
_record_statistics = ex.by_kind(None, _record_steps)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_block(params, family, which, settings, lo, hi, states, reals, counts, series, modal,
                final, base, eighth, halt):
    """Solve rows lo..hi-1 of `params` (n, modes.n_columns(N)) through LANES lock-step lanes:
    the interface and results (to round-off) of modal_driver.solve_block (its outputs plus
    modal (n, N), each mode's tail amplitude max |q_n|, m, and final (n, 2N), the final
    state). family: the spans' mode shapes, bases of N modes stacked item by item
    (kernels.modes.stacked and member), row i's basis which[i]: the lanes of
    one call may each run their own (elastic clamps whose K differs from point to point), as
    far as the right-hand side and the observers read them lane by lane (their polynomials'
    structure and the zeros of their coupling and midspan weights are the same). base:
    None, or True when settings[BASE] is 1; eighth: None, or True when settings[METHOD] is 1
    (DOP853). halt: as kernels.lanes.solve_block's (an interrupt returns at once, the rows in
    flight unsolved). Releases the GIL (sweep.threads runs blocks on threads)."""
    L = LANES
    basis = md.member(family, 0)     # the family's structure: every basis' the same
    n = md.basis_modes(basis)
    dim = 2 * n
    rtol = max(settings[RTOL], dopri5.MIN_RTOL)
    track = settings[WANT_SETTLING] != 0.0
    thr_rel = settings[TOL]
    n_samples = series.shape[1]
    n_stages = dop853.N_STAGES if eighth else dopri5.N_STAGES
    last = 1 if eighth else n_stages          # f(t + h, y_new)'s row of KM
    A = dop853.A if eighth else dopri5.A
    B = dop853.B if eighth else dopri5.B
    C = dop853.C if eighth else dopri5.C
    T = basis[md.TABLES]
    rows = md.field_rows(basis)
    weights = basis[md.MIDSPAN]      # (the basis' arrays taken once: a tuple's item taken in
    CP = basis[md.COUPLING]          # the loop costs a reference count update a call)
    PY = basis[md.POLYNOMIAL]
    polynomial = md.has_polynomial(PY)
    own = family[md.RATIOS].shape[0] > 1          # the lanes carry bases of their own
    record = ex.is_record(base)      # a random record: the accumulator has its
    slots = tj.SCALAR_SLOTS if record else tj.N_SLOTS   # statistics' slots
    # a record's samples (the spectra's) on DOP853's quintic Hermite: `_record_steps`' in an
    # ordinary step (RK45's are its quartic from the stages: the scalar path's)
    sampled_here = record and eighth is not None
    W = np.zeros(slots * L)
    for j in range(L):
        W[tj.STATUS * L + j] = mt.DIVERGED         # idle until loaded
    Y = np.zeros((dim, L))
    YN = np.zeros((dim, L))
    ST = np.zeros((dim, L))
    K = np.zeros((n_stages + 1, dim, L))
    KM = np.zeros((n_stages + 1, 2, L))
    QV = np.zeros((2, L))
    START = np.zeros((4, L))
    MOD = np.zeros((drv.modal_size(n), L))
    for l in range(L):
        MOD[drv.factor_slot(n) + 1, l] = settings[LOADS]     # as modal_driver.start sets it
    PP = np.zeros((md.prepared_size(n), L))
    LB = np.zeros((md.lane_basis_size(basis), L))   # each lane's basis, read across the lanes
    BI = np.zeros(L, np.int64)                      # and its index into the family
    P1 = np.zeros(N_PARAMS * L)
    P1L = np.zeros((L, N_PARAMS))       # the same rows, a lane's contiguous (the scalar path)
    FLD = np.zeros((4, rows, L))
    SC = np.zeros((4, L))
    TT = np.zeros(L)
    H = np.zeros(L)
    ERR = np.zeros(L)
    EV = np.zeros(L)
    SPAN = np.zeros(L)
    FLAG = np.zeros(L)
    MOVE = np.zeros(L)
    BOUNDS = np.zeros(L)
    BIG = np.zeros(L)
    REACH = np.zeros((n, L))
    QB = np.zeros((n, L))
    QMAX = np.empty(n)
    pp = np.empty(md.prepared_size(n))
    yl = np.empty(dim)
    ynl = np.empty(dim)
    fl = np.empty(dim)
    ml = np.empty(drv.modal_size(n))
    qx = np.empty(drv.observer_scratch(n))
    LD = np.empty((2, 6))
    Kl = np.empty((n_stages + 1, dim))
    Km = np.empty((n_stages + 1, 2))
    terms = dopri5.DENSE_TERMS if eighth else dopri5.QUARTIC_TERMS   # RK45: its quartic
    QA = np.empty((n, 2, terms))
    Kmid = np.empty((2 if eighth else n_stages + 1, 2))
    Qc = np.empty((2, terms))
    bufs = [tj.new_buffer() for _ in range(L)]
    capacity = np.full(L, bufs[0].shape[0], np.int64)
    point = np.full(L, -1, np.int64)
    MOVES = np.empty((L, 2), np.int64)
    next_point = lo
    n_run = min(L, hi - lo)
    while True:
        if halt[0] != 0:
            return                # an interrupt: the rows in flight are left unsolved
        tj.next_attempts(W, L, H, FLAG, settings, n_run)
        top = 0
        for j in range(L):
            if j < n_run and FLAG[j] == 0.0:
                top = j + 1
                continue
            if j >= n_run and point[j] < 0 and next_point >= hi:
                H[j] = 0.0
                continue
            acc = W[j::L]
            step = 0.0
            while True:
                if point[j] >= 0:
                    step = tj.next_attempt(settings, acc)
                    if step > 0.0:
                        break
                    _end_lane(params, n, settings, point[j], j, W, Y, MOD, states, reals,
                              counts, series, modal, final, bufs[j], yl, ml,
                              _basis_of(family, basis, own, BI[j]), base)
                    point[j] = -1
                if next_point >= hi:
                    break
                if _load_lane(params, n, settings, next_point, j, W, Y, K, PP, P1, P1L,
                              MOD, states, reals, counts, series, modal, final, pp, yl, fl,
                              _basis_of(family, basis, own, which[next_point]), LB, base):
                    BI[j] = which[next_point]
                    point[j] = next_point
                    bufs[j] = tj.new_buffer()
                    capacity[j] = bufs[j].shape[0]
                    BOUNDS[j] = params[next_point, md.BOUND]
                next_point += 1
            H[j] = step
            if step > 0.0:
                top = j + 1
        if top == 0:
            return
        if next_point >= hi:              # draining: pack the running lanes
            n_moves, top = tj.lane_moves(H, top, MOVES)
            for m in range(n_moves):
                _move_lane(MOVES[m, 0], MOVES[m, 1], W, Y, K, MOD, PP, P1, P1L, BOUNDS,
                           H, LB, BI)
                tj.move_books(MOVES[m, 0], MOVES[m, 1], bufs, capacity, point)
        n_run = min(L, (top + SIMD - 1) // SIMD * SIMD)
        if polynomial:                    # (two specialisations of the attempt, each
            _attempt(W, Y, YN, K, ST, TT, H, ERR, PP, n, T, FLD, SC, A, B, C, rtol, eighth,
                     n_run, base, CP, PY, LB, own)
        else:                             # compiled with its own form alone)
            _attempt(W, Y, YN, K, ST, TT, H, ERR, PP, n, T, FLD, SC, A, B, C, rtol, eighth,
                     n_run, base, CP, None, LB, own)
        _control(W, H, ERR, SC, settings, n_run)
        _midspan(K, YN, KM, QV, weights, LB, own, n, n_stages, eighth, n_run)
        _reaches(Y, YN, K, H, REACH, QB, n, n_run, eighth)
        _mode_events(W, Y, YN, H, ERR, BOUNDS, MOD, EV, BIG, n, n_run, LB, family, basis, own,
                     BI, LD, P1L, REACH, QB, QMAX, base)
        _keep_record_start(W, START, n_run, base)
        n_flagged = _finish(W, H, ERR, QV, KM, EV, FLAG, MOVE, P1, settings, n_samples, last,
                            n_run, sampled_here, base)
        _record_statistics(W, START, Y, YN, K, H, MOVE, FLAG, MOD, P1L, settings, n, n_run,
                           family, BI, yl, ynl, Kl, ml, series, point, Qc, sampled_here,
                           base)
        _tail_modes(W, YN, MOD, MOVE, FLAG, n, n_run, LB, family, basis, own, BI, LD, P1L,
                    base)
        _span_events(W, QB, MOD, SPAN, MOVE, FLAG, n, n_run, LB)
        for j in range(n_run):
            if SPAN[j] != 0.0:
                _span_lane(j, n, Y, YN, K, H, MOD, eighth, Kl, yl, ynl, ml, Km, QA, qx,
                           _basis_of(family, basis, own, BI[j]))
        if base is not None:
            _sine_refine_marked(W, P1L, n_run, base)     # ordinary steps' extrema
        if n_flagged > 0:
            for j in range(n_run):
                if FLAG[j] != 2.0:
                    continue
                if W[tj.N_EXT * L + j] >= capacity[j]:
                    bufs[j] = tj.with_room(bufs[j], W[j::L])
                    capacity[j] = bufs[j].shape[0]
                mine = _basis_of(family, basis, own, BI[j])
                if _flagged_lane(W, j, n, settings, Y, YN, K, KM, H, P1L, MOD, BOUNDS[j],
                                 mine[md.MIDSPAN], bufs[j], series, point[j], track, thr_rel,
                                 eighth, n_stages, Kl, yl, ynl, ml, Km, QA, qx, mine, Kmid,
                                 Qc, base):
                    MOVE[j] = 1.0
        _advance(Y, YN, K, MOVE, dim, n_stages, n_run)
