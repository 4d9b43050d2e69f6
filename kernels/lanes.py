"""Lock-step SIMD driver: LANES trajectories advanced side by side in vector lanes.

Each lane is one trajectory with its own time, step size and accept/reject decision (the
trajectory module's state machine, SciPy RK45's sequence of attempts). Only the arithmetic of
an attempt (six right-hand sides, the stage sums, the error norm) runs across the lanes at
once; that loop has no calls and no branches, so LLVM vectorises it. The load's cos(W t) is
`fast_cos`, an inlined polynomial with Cody-Waite range reduction (fdlibm's kernels), because a
libm call would stop vectorisation. A lane whose trajectory ends takes the next point of its
block at once, so lanes stay busy.

Results equal the scalar driver's to round-off (the two cos differ by an ulp or so).
"""

import math

import numba as nb
import numpy as np

from . import metrics as mt
from . import trajectory as tj
from .dopri5 import A, B, C, E, MIN_RTOL, N_STAGES
from .layout import ATOL, RTOL, TOL, WANT_SETTLING
from .oscillator import DAMPING, G0, G1, H, K0, K1, MASS, OMEGA
from .transverse import classify, reject_point, valid

LANES = 16            # trajectories per lock-step group (a multiple of the SIMD width)
BLOCK = 64          # points per parallel work item

# Cody-Waite split of pi/2 and fdlibm's minimax kernels on [-pi/4, pi/4].
_TWO_OVER_PI = 0.63661977236758134308
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fast_cos(x):
    """cos(x) without a libm call, to about an ulp for |x| < 1e5 (vectorisable)."""
    k = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_2T
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    quadrant = k - 4.0 * math.floor(0.25 * k)     # 0, 1, 2, 3 as floats: vectorisable
    v = s if (quadrant == 1.0) | (quadrant == 3.0) else c
    return -v if (quadrant == 1.0) | (quadrant == 2.0) else v


# The lanes' working memory is one flat array W, row r of lane j at W[r * LANES + j]: one
# underlying object with constant offsets between rows, so LLVM proves the rows independent and
# vectorises across lanes with no run-time alias checks. Rows MASS .. OMEGA hold the
# oscillator's coefficients (as in oscillator), then:
W_T = OMEGA + 1       # time (s)
W_Q = OMEGA + 2       # q (m)
W_V = OMEGA + 3       # q' (m/s)
W_H = OMEGA + 4       # step to attempt (s); 0 for an idle lane
W_K = OMEGA + 5       # stage s, component c at row W_K + 2 s + c (K[0] = f(t, y) on entry)
W_QN = W_K + 2 * (N_STAGES + 1)   # fifth-order q (m)
W_VN = W_QN + 1                   # fifth-order q' (m/s)
W_ERR = W_QN + 2                  # SciPy's error norm
W_ROWS = W_QN + 3

# The tableau as compile-time constants (tuples are frozen into the code).
_A = tuple(tuple(float(x) for x in row) for row in A)
_B = tuple(float(x) for x in B)
_C = tuple(float(x) for x in C)
_E = tuple(float(x) for x in E)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _accel(W, j, t, q, v):
    """q'' of lane j's oscillator at (t, q, v)."""
    cw = fast_cos(W[OMEGA * LANES + j] * t)
    q2 = q * q
    force = (W[DAMPING * LANES + j] * v
             + (W[K0 * LANES + j] + W[K1 * LANES + j] * cw) * q
             + (W[G0 * LANES + j] + W[G1 * LANES + j] * cw) * q * q2
             + W[H * LANES + j] * q * q2 * q2)
    return -force / W[MASS * LANES + j]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _attempt(W, rtol, atol):
    """One Dormand-Prince attempt in every lane of W.

    The stages are written out with scalar locals and the tableau's entries (dopri5.A, B, C,
    E), summed in the scalar step's order; one loop with a run-time trip count runs across the
    lanes with straight-line arithmetic, so LLVM vectorises it rather than unrolling it.
    """
    L = LANES
    for j in range(W.shape[0] // W_ROWS):
        t = W[W_T * L + j]
        q = W[W_Q * L + j]
        v = W[W_V * L + j]
        h = W[W_H * L + j]
        k1q = W[W_K * L + j]
        k1v = W[(W_K + 1) * L + j]
        k2q = v + (k1v * _A[1][0]) * h
        k2v = _accel(W, j, t + _C[1] * h, q + (k1q * _A[1][0]) * h, k2q)
        q3 = q + (k1q * _A[2][0] + k2q * _A[2][1]) * h
        k3q = v + (k1v * _A[2][0] + k2v * _A[2][1]) * h
        k3v = _accel(W, j, t + _C[2] * h, q3, k3q)
        q4 = q + (k1q * _A[3][0] + k2q * _A[3][1] + k3q * _A[3][2]) * h
        k4q = v + (k1v * _A[3][0] + k2v * _A[3][1] + k3v * _A[3][2]) * h
        k4v = _accel(W, j, t + _C[3] * h, q4, k4q)
        q5 = q + (k1q * _A[4][0] + k2q * _A[4][1] + k3q * _A[4][2] + k4q * _A[4][3]) * h
        k5q = v + (k1v * _A[4][0] + k2v * _A[4][1] + k3v * _A[4][2] + k4v * _A[4][3]) * h
        k5v = _accel(W, j, t + _C[4] * h, q5, k5q)
        q6 = q + (k1q * _A[5][0] + k2q * _A[5][1] + k3q * _A[5][2] + k4q * _A[5][3]
                  + k5q * _A[5][4]) * h
        k6q = v + (k1v * _A[5][0] + k2v * _A[5][1] + k3v * _A[5][2] + k4v * _A[5][3]
                   + k5v * _A[5][4]) * h
        k6v = _accel(W, j, t + _C[5] * h, q6, k6q)
        qn = q + h * (k1q * _B[0] + k2q * _B[1] + k3q * _B[2] + k4q * _B[3] + k5q * _B[4]
                      + k6q * _B[5])
        vn = v + h * (k1v * _B[0] + k2v * _B[1] + k3v * _B[2] + k4v * _B[3] + k5v * _B[4]
                      + k6v * _B[5])
        k7q = vn
        k7v = _accel(W, j, t + h, qn, vn)
        eq = (k1q * _E[0] + k2q * _E[1] + k3q * _E[2] + k4q * _E[3] + k5q * _E[4]
              + k6q * _E[5] + k7q * _E[6]) * h
        ev = (k1v * _E[0] + k2v * _E[1] + k3v * _E[2] + k4v * _E[3] + k5v * _E[4]
              + k6v * _E[5] + k7v * _E[6]) * h
        rq = eq / (atol + max(abs(q), abs(qn)) * rtol)
        rv = ev / (atol + max(abs(v), abs(vn)) * rtol)
        W[(W_K + 2) * L + j] = k2q
        W[(W_K + 3) * L + j] = k2v
        W[(W_K + 4) * L + j] = k3q
        W[(W_K + 5) * L + j] = k3v
        W[(W_K + 6) * L + j] = k4q
        W[(W_K + 7) * L + j] = k4v
        W[(W_K + 8) * L + j] = k5q
        W[(W_K + 9) * L + j] = k5v
        W[(W_K + 10) * L + j] = k6q
        W[(W_K + 11) * L + j] = k6v
        W[(W_K + 12) * L + j] = k7q
        W[(W_K + 13) * L + j] = k7v
        W[W_QN * L + j] = qn
        W[W_VN * L + j] = vn
        W[W_ERR * L + j] = math.sqrt(rq * rq + rv * rv) / math.sqrt(2.0)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _load_lane(params, settings, point, lane, W, acc, states, reals, counts, series):
    """Give `lane` the trajectory of row `point`; an invalid row is answered at once.
    Returns False when the row needs no integration."""
    p = params[point]
    if not valid(p):
        reject_point(reals[point], counts[point], series[point])
        states[point] = mt.INVALID_INPUT
        return False
    for c in range(OMEGA + 1):
        W[c * LANES + lane] = p[c]
    tj.start(p, settings, acc[lane], series[point])
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy")
def solve_block(params, settings, lo, hi, states, reals, counts, series):
    """Solve rows lo..hi-1 of `params` through LANES lock-step lanes."""
    rtol = max(settings[RTOL], MIN_RTOL)
    atol = settings[ATOL]
    track = settings[WANT_SETTLING] != 0.0
    thr_rel = settings[TOL]
    W = np.zeros(W_ROWS * LANES)
    W[MASS * LANES:(MASS + 1) * LANES] = 1.0
    acc = np.zeros((LANES, tj.N_SLOTS))
    bufs = [tj.new_buffer() for _ in range(LANES)]
    point = np.full(LANES, -1, np.int64)
    K = np.empty((N_STAGES + 1, 2))
    Qc = np.empty((2, 4))
    next_point = lo
    while True:
        busy = 0
        for j in range(LANES):
            step = 0.0
            while True:
                if point[j] >= 0:
                    step = tj.next_attempt(settings, acc[j])
                    if step > 0.0:
                        break
                    i = point[j]
                    tj.end_series(acc[j], series[i])
                    states[i] = classify(params[i], settings, acc[j], bufs[j], reals[i],
                                         counts[i])
                    point[j] = -1
                if next_point >= hi:
                    break
                if _load_lane(params, settings, next_point, j, W, acc, states, reals,
                              counts, series):
                    point[j] = next_point
                    bufs[j] = tj.new_buffer()
                next_point += 1
            W[W_H * LANES + j] = step
            if step > 0.0:
                busy += 1
                W[W_T * LANES + j] = acc[j, tj.T]
                W[W_Q * LANES + j] = acc[j, tj.Q]
                W[W_V * LANES + j] = acc[j, tj.V]
                W[W_K * LANES + j] = acc[j, tj.FQ]
                W[(W_K + 1) * LANES + j] = acc[j, tj.FV]
        if busy == 0:
            return
        _attempt(W, rtol, atol)
        for j in range(LANES):
            if W[W_H * LANES + j] > 0.0:
                i = point[j]
                for s in range(N_STAGES + 1):
                    K[s, 0] = W[(W_K + 2 * s) * LANES + j]
                    K[s, 1] = W[(W_K + 2 * s + 1) * LANES + j]
                bufs[j] = tj.finish_attempt(params[i], settings, acc[j], K,
                                            W[W_QN * LANES + j], W[W_VN * LANES + j],
                                            W[W_ERR * LANES + j], W[W_H * LANES + j], Qc,
                                            bufs[j], series[i], track, 0.0, 0.0, thr_rel)


@nb.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def solve_batch(params, settings, states, reals, counts, series):
    """Same interface and results (to round-off) as transverse.solve_batch_scalar, several
    times faster per core: blocks of BLOCK points in parallel, LANES lanes per block."""
    n = params.shape[0]
    n_blocks = (n + BLOCK - 1) // BLOCK
    for b in nb.prange(n_blocks):
        solve_block(params, settings, b * BLOCK, min(n, (b + 1) * BLOCK), states, reals,
                    counts, series)
