"""Floquet multipliers of the damped Mathieu equation, one load period per case (SI units).

The straight span linearised about q = 0 under a harmonic axial load (docs/model.md sec. 8):

    q'' + c q' + (k + kc cos(W t)) q = 0

c (1/s), k and kc (1/s^2), W (rad/s), period T = 2 pi / W (s). For one mode of the consistent
model c = 2 zeta w1, k = w1^2, kc = -w1^2 P0/Pcr; the caller supplies c, k, kc and W.

The monodromy matrix Phi(T) holds the states (q, q') at T from (1, 0) and (0, 1) at t = 0.
Liouville gives det Phi = exp(-c T) exactly, so only its trace is taken from the integration;
the multipliers are lambda = (tr +- sqrt(tr^2 - 4 det)) / 2 with the exact det
(`multipliers`). The case is unstable iff max |lambda| > 1; its growth rate is
sigma = ln(max |lambda|) / T (1/s): -c/2 for a complex pair, > 0 where unstable. The trace does
not depend on the load's phase (a shifted start conjugates Phi), so cos(W t) has none here; it
follows that kc and -kc (a half-period shift) give the same trace.

Method: a fixed-step explicit Runge-Kutta over exactly one period, `steps` equal steps
h = T / steps, both columns of Phi integrated side by side (four scalars), with the eighth-order
weights of the Dormand-Prince 8(5,3) tableau of kernels/dop853.py (12 stages, order 8; its
embedded estimators are not used: no step control, no rejections). Why this one: it is the
highest-order explicit tableau the project already carries (and tests against SciPy's DOP853);
at order 8 the error per period falls as (h Omega)^8 (measured: about 2^8 a halving of h), so
1e-11 takes only about 5 steps per radian of the fastest rate Omega (below), where by order
alone a fifth-order method (DOPRI5) would need several times as many; and being explicit
and fixed-step the cost of a case is known in advance and is the same for every case with the
same Omega T. The load's cos is evaluated at the stage phases 2 pi (i + C_s) / steps by angle
addition (one cos/sin pair a step; the stage offsets' cos/sin once per case), so the phase is
exact to round-off at every stage and needs no W t product.

Step rule (`steps_for`): steps = ceil(Omega T / H_OMEGA), at least MIN_STEPS, with
Omega = max(sqrt(|k| + |kc|), W, |c|) (1/s) the fastest rate of the equation and H_OMEGA = 0.2
the largest h Omega. The equation is scale free (t -> t sqrt(k)), so the error depends only on
the ratios W/sqrt(k), kc/k and zeta, not on k. Measured against SciPy DOP853 at rtol 1e-13
(tests/test_floquet_kernel.py::test_step_rule_convergence_study, the corners W/sqrt(k) = 0.2,
0.5, 1.2, 4, |kc|/k up to 1, zeta 0 to 0.1, k = 1 and 1e8; and 150 random cases over the range):
the trace's error relative to max(|tr|, 2 sqrt(det)) is at most 3.5e-12 (4.0e-12 random) at
h Omega = 0.2, against 8.7e-10 (1.0e-9) at 0.4 and 7e-13 at 0.16. Over the range that is 32
(W/sqrt(k) = 4) to 223 (W/sqrt(k) = 0.2, |kc| = k) steps a period. An error d in the trace
moves max |lambda| by about d / (2 sqrt(tr^2 - 4 det)) where the multipliers are real (not at
all where they are a complex pair: |lambda| = sqrt(det) exactly), so 1e-7 holds everywhere but
within tr^2 - 4 det < ~1e-9 of a zone boundary, where no double-precision trace does better.

Several modes: linearised about q = 0 the pinned span's modes (docs/model.md sec. 7) decouple
(each its own c_n, k_n, kc_n), so a caller runs `floquet_block` once per mode and takes the
largest multiplier and growth rate. Clamped and elastic ends (docs/model.md sec. 10) couple
them through the axial-load matrix (A_13 of a clamped span): the N modes obey

    q'' + D q' + (S + L cos W t) q = 0,    D = diag(2 zeta w_n), S = diag(w_n^2), L (N, N),

(D in 1/s, S and L in 1/s^2, q in m) and `coupled_monodromy` integrates all 2N columns of its
Phi(T) side by side with the same tableau, stage phases and step rule (`coupled_steps_for`:
Omega from the row-sum bound max_n (|S_n| + sum_m |L_nm|) on the system's largest eigenvalue,
which is `steps_for`'s |k| + |kc| for one mode). Its multipliers are Phi's eigenvalues, taken
by the caller (sweep/models/stability.py: numpy, outside the kernel, which stays free of
LAPACK); `coupled_block` fills the matrices of a block of points.

No I/O; `floquet_block` and `coupled_block` release the GIL and never raise; the coupled
functions compile only when a scene with coupled modes first calls them.
"""

import math

import numba as nb
import numpy as np

from .dop853 import A, B, C

N_STAGES = 12
H_OMEGA = 0.2           # the step rule's largest h Omega (dimensionless); see `steps_for`
MIN_STEPS = 8           # the fewest steps a period
MAX_STEPS = 1 << 20     # more steps than this a period (W/Omega below about 4e-5): NaN, kind -1

# Kinds of a case (`multipliers`).
KIND_BAD = -1           # W <= 0, non-finite input, or more than MAX_STEPS steps needed
KIND_STABLE = 0         # max |lambda| <= 1
KIND_POSITIVE = 1       # unstable, positive real multiplier > 1: period-T response (even zones)
KIND_NEGATIVE = 2       # unstable, negative real multiplier < -1: period-2T response (odd zones)
KIND_COMPLEX = 3        # unstable complex pair: c < 0, or coupled modes near W = w_i + w_j


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _stage_phases(dphi):
    """cos and sin of each stage's load phase offset C_s dphi (rad), once per case."""
    cs = np.empty(N_STAGES)
    sn = np.empty(N_STAGES)
    for s in range(N_STAGES):
        cs[s] = math.cos(C[s] * dphi)
        sn[s] = math.sin(C[s] * dphi)
    return cs, sn


@nb.njit(cache=True, nogil=True, error_model="numpy")
def monodromy(c, k, kc, W, steps):
    """The monodromy matrix Phi(T), T = 2 pi / W (s), of q'' + c q' + (k + kc cos W t) q = 0
    (c in 1/s, k, kc in 1/s^2, W in rad/s) by `steps` equal steps of the DOP853 eighth-order
    tableau; returns (Phi11, Phi12, Phi21, Phi22): columns the states (q, q') at T from (1, 0)
    and (0, 1) (Phi11, Phi22 dimensionless, Phi12 in s, Phi21 in 1/s). NaN for steps < 1 or
    W <= 0."""
    if not (steps >= 1) or not (W > 0.0):
        return np.nan, np.nan, np.nan, np.nan
    n = int(steps)
    dphi = 2.0 * math.pi / n                      # load phase advance a step (rad)
    h = dphi / W                                  # step (s)
    cs, sn = _stage_phases(dphi)
    K = np.empty((N_STAGES, 4))
    q1 = 1.0
    v1 = 0.0
    q2 = 0.0
    v2 = 1.0
    for i in range(n):
        th = i * dphi
        ci = math.cos(th)
        si = math.sin(th)
        # stage 0
        stiff = k + kc * ci
        K[0, 0] = v1
        K[0, 1] = -c * v1 - stiff * q1
        K[0, 2] = v2
        K[0, 3] = -c * v2 - stiff * q2
        for s in range(1, N_STAGES):
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            for j in range(s):
                w = A[s, j]
                a0 += w * K[j, 0]
                a1 += w * K[j, 1]
                a2 += w * K[j, 2]
                a3 += w * K[j, 3]
            Q1 = q1 + h * a0
            V1 = v1 + h * a1
            Q2 = q2 + h * a2
            V2 = v2 + h * a3
            stiff = k + kc * (ci * cs[s] - si * sn[s])      # cos(th + C_s dphi)
            K[s, 0] = V1
            K[s, 1] = -c * V1 - stiff * Q1
            K[s, 2] = V2
            K[s, 3] = -c * V2 - stiff * Q2
        b0 = 0.0
        b1 = 0.0
        b2 = 0.0
        b3 = 0.0
        for j in range(N_STAGES):
            w = B[j]
            b0 += w * K[j, 0]
            b1 += w * K[j, 1]
            b2 += w * K[j, 2]
            b3 += w * K[j, 3]
        q1 += h * b0
        v1 += h * b1
        q2 += h * b2
        v2 += h * b3
    return q1, q2, v1, v2


@nb.njit(cache=True, nogil=True, error_model="numpy")
def monodromy_trace(c, k, kc, W, steps):
    """tr Phi(T) (dimensionless) of q'' + c q' + (k + kc cos W t) q = 0 over one period
    T = 2 pi / W, `steps` equal steps of the DOP853 eighth-order tableau (see `monodromy`;
    c in 1/s, k, kc in 1/s^2, W in rad/s). NaN for steps < 1 or W <= 0."""
    p11, p12, p21, p22 = monodromy(c, k, kc, W, steps)
    return p11 + p22


@nb.njit(cache=True, nogil=True, error_model="numpy")
def liouville_deviation(c, k, kc, W, steps):
    """The integrated det Phi(T) relative to Liouville's exp(-c T): det / exp(-c T) - 1
    (dimensionless), a check on the integration (the multipliers use the exact det)."""
    p11, p12, p21, p22 = monodromy(c, k, kc, W, steps)
    T = 2.0 * math.pi / W
    return (p11 * p22 - p12 * p21) * math.exp(c * T) - 1.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def steps_for(c, k, kc, W, h_omega=H_OMEGA):
    """Equal steps a period for the accuracy target: ceil(Omega T / h_omega), at least MIN_STEPS,
    Omega = max(sqrt(|k| + |kc|), W, |c|) (1/s), T = 2 pi / W (s); c in 1/s, k, kc in 1/s^2,
    W in rad/s, h_omega the largest h Omega (dimensionless; H_OMEGA from the convergence study
    of the module docstring). Returns -1 for W <= 0, non-finite input, or more than MAX_STEPS."""
    if not (W > 0.0) or not (math.isfinite(c) and math.isfinite(k) and math.isfinite(kc)
                             and math.isfinite(W)) or not (h_omega > 0.0):
        return -1
    omega = max(math.sqrt(abs(k) + abs(kc)), W, abs(c))
    x = math.ceil(2.0 * math.pi * omega / (W * h_omega))
    if not (x <= MAX_STEPS):
        return -1
    return max(MIN_STEPS, int(x))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def multipliers(tr, det, T):
    """(max |lambda| (dimensionless), growth rate sigma = ln(max |lambda|) / T (1/s), kind) of a
    2x2 monodromy with trace tr and determinant det (pass Liouville's exact exp(-c T)), period T
    (s). kind: KIND_STABLE (0, max |lambda| <= 1), KIND_POSITIVE (1, unstable, real lambda > 1:
    period-T response, zones near W = 2 w1 / m, m even, and below the first), KIND_NEGATIVE (2,
    unstable, real lambda < -1: period-2T response, m odd, the principal zone near W = 2 w1),
    KIND_COMPLEX (3, unstable complex pair: only if det > 1, i.e. c < 0), KIND_BAD (-1, with NaN,
    for non-finite input, det <= 0 or T <= 0)."""
    if not (math.isfinite(tr) and math.isfinite(det) and det > 0.0 and T > 0.0
            and math.isfinite(T)):
        return np.nan, np.nan, KIND_BAD
    disc = tr * tr - 4.0 * det
    if disc < 0.0:                       # complex pair, |lambda| = sqrt(det)
        mag = math.sqrt(det)
        sigma = 0.5 * math.log(det) / T
        kind = KIND_COMPLEX if mag > 1.0 else KIND_STABLE
        return mag, sigma, kind
    mag = 0.5 * (abs(tr) + math.sqrt(disc))          # the larger real multiplier's size
    sigma = math.log(mag) / T
    if mag > 1.0:
        kind = KIND_POSITIVE if tr > 0.0 else KIND_NEGATIVE
    else:
        kind = KIND_STABLE
    return mag, sigma, kind


@nb.njit(cache=True, nogil=True, error_model="numpy")
def floquet_case(c, k, kc, W):
    """(max |lambda|, sigma (1/s), kind) of one case (see `multipliers`), steps by `steps_for`;
    NaN, NaN, KIND_BAD for W <= 0, non-finite input or too many steps."""
    n = steps_for(c, k, kc, W, H_OMEGA)
    if n < 1:
        return np.nan, np.nan, KIND_BAD
    T = 2.0 * math.pi / W
    tr = monodromy_trace(c, k, kc, W, n)
    return multipliers(tr, math.exp(-c * T), T)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def floquet_block(c, k, kc, W, lo, hi, multiplier, growth, kind):
    """Fill rows lo..hi-1 of multiplier (max |lambda|, dimensionless), growth (sigma, 1/s) and
    kind (integer array, see `multipliers`) for the cases c (1/s), k, kc (1/s^2), W (rad/s)
    (float64 arrays (n,)). Releases the GIL; never raises: a case with W <= 0, non-finite input
    or more than MAX_STEPS steps gets NaN and kind -1. One mode a call (module docstring)."""
    for i in range(lo, hi):
        m, g, kd = floquet_case(c[i], k[i], kc[i], W[i])
        multiplier[i] = m
        growth[i] = g
        kind[i] = kd


# --- several coupled modes: the N-mode linear system (docs/model.md secs. 8, 10) -------------

@nb.njit(cache=True, nogil=True, error_model="numpy")
def coupled_steps_for(damping, stiffness, load, W, h_omega=H_OMEGA):
    """`steps_for` of q'' + D q' + (S + L cos W t) q = 0 (damping (N,): D's diagonal, 1/s;
    stiffness (N,): S's, 1/s^2; load (N, N): L, 1/s^2; W in rad/s): Omega = max(sqrt(rho), W,
    max |D_n|) with rho = max_n (|S_n| + sum_m |L_nm|) (1/s^2), the row-sum bound on the
    spectral radius of S + |P| L over the load cycle (the largest eigenvalue's size itself
    where the system is diagonal: one mode gives `steps_for`'s sqrt(|k| + |kc|)). Returns -1
    for W <= 0, non-finite input or more than MAX_STEPS."""
    if not (W > 0.0) or not math.isfinite(W) or not (h_omega > 0.0):
        return -1
    n = damping.shape[0]
    rho = 0.0
    fast = 0.0
    for i in range(n):
        row = abs(stiffness[i])
        for j in range(n):
            row += abs(load[i, j])
        if not (math.isfinite(row) and math.isfinite(damping[i])):
            return -1
        rho = max(rho, row)
        fast = max(fast, abs(damping[i]))
    omega = max(math.sqrt(rho), W, fast)
    x = math.ceil(2.0 * math.pi * omega / (W * h_omega))
    if not (x <= MAX_STEPS):
        return -1
    return max(MIN_STEPS, int(x))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _coupled_rhs(damping, stiffness, load, cos_wt, y, out):
    """out = f(y) for the columns of y (2N, 2N): rows 0..N-1 the modal deflections q, N..2N-1
    their rates q'; q'' = -D q' - S q - cos(W t) L q (`coupled_monodromy`). Inner loops run
    along the rows (contiguous)."""
    n = damping.shape[0]
    cols = y.shape[1]
    for i in range(n):
        d = -damping[i]
        s = -stiffness[i]
        for c in range(cols):
            out[i, c] = y[n + i, c]
            out[n + i, c] = d * y[n + i, c] + s * y[i, c]
        for j in range(n):
            w = -cos_wt * load[i, j]
            if w != 0.0:
                for c in range(cols):
                    out[n + i, c] += w * y[j, c]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def coupled_monodromy(damping, stiffness, load, W, steps, phi):
    """Phi(T), T = 2 pi / W (s), of the N coupled modes q'' + D q' + (S + L cos W t) q = 0
    (D = diag(damping), 1/s; S = diag(stiffness), 1/s^2; L = load (N, N), 1/s^2, any matrix;
    W in rad/s), written into phi (2N, 2N): column j is the state (q_1..q_N, q_1'..q_N') at T
    from the j-th unit state at t = 0 (q in m, q' in m/s). The same fixed-step eighth-order
    DOP853 weights and stage phases as `monodromy`, all 2N columns side by side; one mode with
    load = [[kc]] gives `monodromy`'s matrix. NaN for steps < 1 or W <= 0; never raises."""
    n2 = phi.shape[0]
    if not (steps >= 1) or not (W > 0.0):
        for i in range(n2):
            for j in range(n2):
                phi[i, j] = np.nan
        return
    m = int(steps)
    dphi = 2.0 * math.pi / m                      # load phase advance a step (rad)
    h = dphi / W                                  # step (s)
    cs, sn = _stage_phases(dphi)
    K = np.empty((N_STAGES, n2, n2))
    y = np.empty((n2, n2))
    for i in range(n2):
        for j in range(n2):
            phi[i, j] = 1.0 if i == j else 0.0
    for i in range(m):
        th = i * dphi
        ci = math.cos(th)
        si = math.sin(th)
        _coupled_rhs(damping, stiffness, load, ci, phi, K[0])
        for s in range(1, N_STAGES):
            y[:, :] = phi
            for j in range(s):
                w = h * A[s, j]
                if w != 0.0:                      # (the tableau has many zeros)
                    for r in range(n2):
                        for c in range(n2):
                            y[r, c] += w * K[j, r, c]
            _coupled_rhs(damping, stiffness, load, ci * cs[s] - si * sn[s], y, K[s])
        for j in range(N_STAGES):
            w = h * B[j]
            if w != 0.0:
                for r in range(n2):
                    for c in range(n2):
                        phi[r, c] += w * K[j, r, c]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def coupled_block(damping, stiffness, load, W, index, rate_ratio, load_shape, lo, hi, phi):
    """Phi(T) (`coupled_monodromy`) of rows lo..hi-1 into phi (rows, 2N, 2N): row i's system
    from its mode-1 coefficients and its basis b = index[i]: D_n = damping[i] rate_ratio[b, n]
    (1/s), S_n = stiffness[i] rate_ratio[b, n]^2 (1/s^2), L = load[i] load_shape[b] (1/s^2),
    W[i] (rad/s); damping, stiffness, load, W float64 (rows,), index int64 (rows,), rate_ratio
    (bases, N): w_n / w_1, load_shape (bases, N, N): the axial-load matrix over its (1, 1)
    entry. Steps by `coupled_steps_for`; a row it refuses (W <= 0, non-finite input, too many
    steps) gets NaN. Releases the GIL; never raises."""
    n = rate_ratio.shape[1]
    d = np.empty(n)
    s = np.empty(n)
    ld = np.empty((n, n))
    for i in range(lo, hi):
        b = index[i]
        for p in range(n):
            r = rate_ratio[b, p]
            d[p] = damping[i] * r
            s[p] = stiffness[i] * r * r
            for q in range(n):
                ld[p, q] = load[i] * load_shape[b, p, q]
        steps = coupled_steps_for(d, s, ld, W[i], H_OMEGA)
        coupled_monodromy(d, s, ld, W[i], steps if steps >= 1 else 0, phi[i])
