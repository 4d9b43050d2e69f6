"""The multi-mode transverse System: the span's first N Galerkin modes, coupled (SI units).

    w(x, t) = sum_{n=1..N} q_n(t) sin(n k x),  k = pi / l,

projected on every sin(m k x) and divided by rho A l / 2 (docs/model.md sec. 7):

    q_m'' = -2 zeta w_m q_m' - (w_m^2 - m^2 P(t) k^2 / rho A) q_m - N_m(q, t) - Gamma_m a_b(t)

with w_m = m^2 w1, Gamma_m = 4 / (m pi) for odd m and 0 for even m, and N_m the projection of
Eq.17's nonlinear terms. In the dimensionless fields of xi = k x in [0, pi]

    a = sum n q_n cos(n xi),    b = -sum n^2 q_n sin(n xi),
    c = -sum n^3 q_n cos(n xi), d = sum n^4 q_n sin(n xi)

(w_x = k a, w_xx = k^2 b, w_xxx = k^3 c, w_xxxx = k^4 d), Eq.17's nonlinear force per unit
rho A is

    F = beta_b (-3 b^3 - 11 a b c - 3 a^2 d) - beta_m(t) a^2 b + (21/2) beta_q a^2 b^3,
    beta_b = w1^2 k^2,  beta_q = w1^2 k^4,  beta_m(t) = (4 alpha EA + 2 P(t)) k^4 / rho A,

and N_m = (2 / pi) int_0^pi F sin(m xi) d xi. The integrand is odd in xi and 2 pi periodic, so
its integral over [0, pi] is half the integral over a period of an even trigonometric
polynomial of degree at most 6N (the quintic term: five fields of degree N times sin(m xi)).
The trapezoidal rule on M >= 3N + 1 equal intervals of [0, pi] (2M points a period) is exact
for it: N_m = (2 / M) sum_{j=1..M-1} F(xi_j) sin(m xi_j), xi_j = j pi / M (the end points add
nothing: b = d = 0 there). So the projection is evaluated at M - 1 nodes inside the right-hand
side, exact to round-off, at a cost that grows as N^2 (fields and projection), where
precomputed coupling tensors would grow as N^6 (the quintic's). With N = 1 and M = 4 it
reproduces the one-mode coefficients K3 and K5 of docs/model.md sec. 2 (tests/test_modes.py).

A point's raw row (columns below) holds mode 1's linear coefficients, the load, the membrane
and the base excitation, then the initial state of every mode; `prepare` expands it into the
per-mode coefficients the right-hand side reads. P > 0 is compression.
"""

import math

import numba as nb
import numpy as np

from . import excitation as ex
from .vecmath import fast_cos, fast_sin

# Columns of a raw multi-mode row.
W1_SQ = 0           # w1^2 = (EI / rho A) k^4, the first mode's linear stiffness  (1/s^2)
DAMPING = 1         # 2 zeta w1 (mode n: n^2 times this)                          (1/s)
LOAD_MEAN = 2       # P_mean k^2 / rho A (the constant part of P)                   (1/s^2)
LOAD_COS = 3        # P0 k^2 / rho A, the part times cos(W t)                       (1/s^2)
MEMBRANE = 4        # 4 alpha EA k^4 / rho A                                        (1/(s^2 m^2))
K_SQ = 5            # k^2 = (pi / l)^2                                              (1/m^2)
OMEGA = 6           # W, the load's angular frequency                               (rad/s)
BOUND = 7           # |q_n| (and |midspan deflection|) beyond which a point diverged  (m)
Q_SCALE = 8         # the point's displacement scale (sweep.models.modal.state_scale) (m)
V_SCALE = 9         # its velocity scale                                            (m/s)
PARTICIPATION = 10  # Gamma_1 = 4 / pi (0 without base excitation); mode n: Gamma_1 / n, odd n
LOAD_PHASE = 11     # phi_W: P(t) = P0 cos(W t + phi_W)                                    (rad)
EXCITATION = 12     # the base excitation block (kernels.excitation): a_b(t), fixed or swept
BASE_ACCEL = EXCITATION + ex.ACCEL   # A, base acceleration amplitude                     (m/s^2)
BASE_OMEGA = EXCITATION + ex.OMEGA   # w_b, base angular frequency (a sweep's start)      (rad/s)
BASE_PHASE = EXCITATION + ex.PHASE   # phi_b (a stepped sweep's carried phase)            (rad)
N_FIXED = EXCITATION + ex.SIZE       # then q_n(0) (m) for n = 1..N, then q_n'(0) (m/s)

FIXED_NAMES = ("w1_sq", "damping", "load_mean", "load_cos", "membrane", "k_sq", "omega",
               "bound", "q_scale", "v_scale", "participation", "load_phase") + ex.NAMES


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def n_columns(n_modes):
    """Columns of a raw row for n_modes modes (callable from Python and from the kernels)."""
    return N_FIXED + 2 * n_modes


# The prepared row `prepare` writes (length prepared_size(N)): four blocks of N per-mode
# coefficients, then the scalars.
P_DAMPING = 0       # block 0: -n^2 (2 zeta w1)                                     (1/s)
P_STIFF = 1         # block 1: -(n^4 w1^2 - n^2 P_mean k^2 / rho A)                 (1/s^2)
P_STIFF_COS = 2     # block 2: n^2 P0 k^2 / rho A (times cos W t)                   (1/s^2)
P_FORCE = 3         # block 3: -Gamma_n                                              (1)
S_BETA_B = 0        # scalars after the blocks: beta_b = w1^2 k^2                   (1/(s^2 m^2))
S_BETA_Q = 1        # beta_q = w1^2 k^4                                              (1/(s^2 m^4))
S_BETA_M0 = 2       # beta_m's constant part: 4 alpha EA k^4/rho A + 2 k^2 P_mean k^2/rho A
S_BETA_M1 = 3       # beta_m's cos(W t) part: 2 k^2 P0 k^2 / rho A
S_OMEGA = 4
S_LOAD_PHASE = 5
S_EXCITATION = 6    # the excitation block, copied from the raw row
S_BASE_ACCEL = S_EXCITATION + ex.ACCEL
S_BASE_OMEGA = S_EXCITATION + ex.OMEGA
S_BASE_PHASE = S_EXCITATION + ex.PHASE
N_SCALARS = S_EXCITATION + ex.SIZE


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def prepared_size(n_modes):
    """Length of a prepared row for n_modes modes."""
    return 4 * n_modes + N_SCALARS


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def intervals(n_modes):
    """M, the trapezoidal rule's intervals on [0, pi] that make the projection exact: 3N + 1."""
    return 3 * n_modes + 1


@nb.njit(cache=True, nogil=True, error_model="numpy")
def tables(n_modes):
    """The mode shapes at the quadrature nodes xi_j = j pi / M, j = 1..M - 1, M = 3N + 1:
    T[0, n - 1, j - 1] = n cos(n xi_j) (a), T[1] = -n^2 sin (b), T[2] = -n^3 cos (c),
    T[3] = n^4 sin (d), T[4] = (2 / M) sin(n xi_j) (the projection's weights)."""
    m = intervals(n_modes)
    t = np.empty((5, n_modes, m - 1))
    for i in range(n_modes):
        n = i + 1.0
        for j in range(m - 1):
            xi = (j + 1.0) * math.pi / m
            sn = math.sin(n * xi)
            cn = math.cos(n * xi)
            t[0, i, j] = n * cn
            t[1, i, j] = -n * n * sn
            t[2, i, j] = -n * n * n * cn
            t[3, i, j] = n * n * n * n * sn
            t[4, i, j] = 2.0 / m * sn
    return t


@nb.njit(cache=True, nogil=True, error_model="numpy")
def midspan_weights(n_modes):
    """sin(n pi / 2) for n = 1..N: 1, 0, -1, 0, 1, ... (the midspan deflection is the sum of
    q_n times these)."""
    s = np.zeros(n_modes)
    for i in range(0, n_modes, 2):
        s[i] = 1.0 if (i // 2) % 2 == 0 else -1.0
    return s


SPAN_STATIONS_PER_MODE = 8   # stations of `span_stations` per mode: 8 per half-wave of mode N


@nb.njit(cache=True, nogil=True, error_model="numpy")
def span_stations(n_modes):
    """The mode shapes at the M + 1 equally spaced stations x_k = k l / M, k = 0..M, of
    `span_maximum` (M = 8N): S[k, n - 1] = sin(n pi x_k / l)."""
    m = SPAN_STATIONS_PER_MODE * n_modes
    s = np.empty((m + 1, n_modes))
    for k in range(m + 1):
        for i in range(n_modes):
            s[k, i] = math.sin((i + 1.0) * math.pi * k / m)
    return s


@nb.njit(cache=True, nogil=True, error_model="numpy")
def span_maximum(q, n_modes, stations):
    """max over the span 0 <= x <= l of |w(x)|, w = sum_n q_n sin(n pi x / l) (m), for the
    modal coefficients q[0..N-1] (m), and where it lies (x / l): `span_argmax`'s."""
    return span_argmax(q, n_modes, stations)[0]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def span_argmax(q, n_modes, stations):
    """(max over the span of |w(x)| (m), its x / l) for the modal coefficients q[0..N-1]
    (m), w = sum_n q_n sin(n pi x / l): the stations' values (`span_stations`: 8 per
    half-wave of mode N), each local maximum within 10 % of the best refined by Newton's
    method on w'(x) = 0, never leaving its station's interval. A value found, so never above
    the true maximum; the refinement makes it exact to round-off when the stations bracket
    the maximum's hump (tests/test_modes.py checks it against a dense grid)."""
    m = stations.shape[0] - 1
    best = 0.0
    where = 0.5
    for k in range(m + 1):
        w = 0.0
        for i in range(n_modes):
            w += q[i] * stations[k, i]
        if abs(w) > best:
            best = abs(w)
            where = k / m
    top = best
    for k in range(1, m):
        w_prev = 0.0
        w = 0.0
        w_next = 0.0
        for i in range(n_modes):
            w_prev += q[i] * stations[k - 1, i]
            w += q[i] * stations[k, i]
            w_next += q[i] * stations[k + 1, i]
        if not (abs(w) >= abs(w_prev) and abs(w) >= abs(w_next) and abs(w) >= 0.9 * best):
            continue
        x = k / m                               # in units of l
        for _ in range(8):
            d1 = 0.0
            d2 = 0.0
            for i in range(n_modes):
                a = (i + 1.0) * math.pi
                d1 += q[i] * a * math.cos(a * x)
                d2 -= q[i] * a * a * math.sin(a * x)
            if d2 == 0.0:
                break
            x_new = x - d1 / d2
            if not abs(x_new - k / m) <= 1.0 / m:
                break
            done = abs(x_new - x) <= 1e-15
            x = x_new
            if done:
                break
        v = 0.0
        for i in range(n_modes):
            v += q[i] * math.sin((i + 1.0) * math.pi * x)
        if abs(v) > top:
            top = abs(v)
            where = x
    return top, where


@nb.njit(cache=True, nogil=True, error_model="numpy")
def prepare(row, n_modes, pp):
    """Write the prepared row pp (prepared_size(N)) of raw row `row` (columns above)."""
    n_b = n_modes
    k2 = row[K_SQ]
    for i in range(n_modes):
        n2 = (i + 1.0) * (i + 1.0)
        pp[P_DAMPING * n_b + i] = -n2 * row[DAMPING]
        pp[P_STIFF * n_b + i] = -(n2 * n2 * row[W1_SQ] - n2 * row[LOAD_MEAN])
        pp[P_STIFF_COS * n_b + i] = n2 * row[LOAD_COS]
        pp[P_FORCE * n_b + i] = -row[PARTICIPATION] / (i + 1.0) if i % 2 == 0 else 0.0
    s = 4 * n_b
    pp[s + S_BETA_B] = row[W1_SQ] * k2
    pp[s + S_BETA_Q] = row[W1_SQ] * k2 * k2
    pp[s + S_BETA_M0] = row[MEMBRANE] + 2.0 * k2 * row[LOAD_MEAN]
    pp[s + S_BETA_M1] = 2.0 * k2 * row[LOAD_COS]
    pp[s + S_OMEGA] = row[OMEGA]
    pp[s + S_LOAD_PHASE] = row[LOAD_PHASE]
    for c in range(ex.SIZE):
        pp[s + S_EXCITATION + c] = row[EXCITATION + c]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def base_acceleration(t, pp, n_modes):
    """a_b(t) (m/s^2) of a prepared row (kernels.excitation)."""
    return ex.acceleration(t, pp, 4 * n_modes + S_EXCITATION, 1)


# The right-hand side may fuse a * b + c into one fused multiply-add (no reordering): the lanes
# driver's vector loops gain most of it; both drivers run this one function.
_CONTRACT = {"contract"}


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=_CONTRACT)
def lanes_derivative(tt, X, K, s, PP, n_modes, T, FLD, SC, n_run, fast, base):
    """The System's right-hand side for n_run states side by side (lanes l < n_run):
    K[s, :, l] = f(tt[l], X[:, l]), X[:, l] = (q_1..q_N, q_1'..q_N') (m, m/s), K[s, :, l] =
    (q', q'') (m/s, m/s^2). PP[:, l]: lane l's prepared row (`prepare`); T: `tables`(N); FLD
    (4, M - 1, lanes) and SC (4, lanes): scratch. fast: None (libm's cos and sin) or True
    (vecmath's vectorisable ones); base: None (no base excitation term) or True.

    The lane is every array's last, contiguous axis and every loop over modes and quadrature
    nodes sits outside the loop across the lanes, which is straight-line arithmetic, so LLVM
    vectorises it. The one-state `derivative` is this with one lane."""
    n = n_modes
    sc = 4 * n
    nodes = T.shape[2]
    for l in range(n_run):
        x = PP[sc + S_OMEGA, l] * tt[l] + PP[sc + S_LOAD_PHASE, l]
        cw = math.cos(x) if fast is None else fast_cos(x)
        SC[0, l] = cw
        SC[1, l] = PP[sc + S_BETA_M0, l] + PP[sc + S_BETA_M1, l] * cw
    if base is not None:
        if fast is None:                # libm, and any excitation (kernels.excitation)
            flat = PP.reshape(PP.size)
            lanes = PP.shape[1]
            for l in range(n_run):
                SC[2, l] = ex.acceleration(tt[l], flat, (sc + S_EXCITATION) * lanes + l, lanes)
        else:                           # the lanes: fixed frequency and level, vectorised
            for l in range(n_run):
                x = PP[sc + S_BASE_OMEGA, l] * tt[l] + PP[sc + S_BASE_PHASE, l]
                SC[2, l] = PP[sc + S_BASE_ACCEL, l] * fast_sin(x)
    for j in range(nodes):
        t0 = T[0, 0, j]
        t1 = T[1, 0, j]
        t2 = T[2, 0, j]
        t3 = T[3, 0, j]
        for l in range(n_run):
            q = X[0, l]
            FLD[0, j, l] = t0 * q
            FLD[1, j, l] = t1 * q
            FLD[2, j, l] = t2 * q
            FLD[3, j, l] = t3 * q
    for i in range(1, n):
        for j in range(nodes):
            t0 = T[0, i, j]
            t1 = T[1, i, j]
            t2 = T[2, i, j]
            t3 = T[3, i, j]
            for l in range(n_run):
                q = X[i, l]
                FLD[0, j, l] += t0 * q
                FLD[1, j, l] += t1 * q
                FLD[2, j, l] += t2 * q
                FLD[3, j, l] += t3 * q
    for j in range(nodes):
        for l in range(n_run):
            a = FLD[0, j, l]
            b = FLD[1, j, l]
            c = FLD[2, j, l]
            d = FLD[3, j, l]
            a2 = a * a
            b2 = b * b
            FLD[0, j, l] = (PP[sc + S_BETA_B, l] * (-3.0 * b2 * b - 11.0 * a * b * c
                                                     - 3.0 * a2 * d)
                            - SC[1, l] * a2 * b + 10.5 * PP[sc + S_BETA_Q, l] * a2 * b2 * b)
    for i in range(n):
        w = T[4, i, 0]
        for l in range(n_run):
            SC[3, l] = w * FLD[0, 0, l]
        for j in range(1, nodes):
            w = T[4, i, j]
            for l in range(n_run):
                SC[3, l] += w * FLD[0, j, l]
        for l in range(n_run):
            acc = ((PP[P_STIFF * n + i, l] + PP[P_STIFF_COS * n + i, l] * SC[0, l])
                   * X[i, l] + PP[P_DAMPING * n + i, l] * X[n + i, l] - SC[3, l])
            if base is not None:
                acc += PP[P_FORCE * n + i, l] * SC[2, l]
            K[s, i, l] = X[n + i, l]
            K[s, n + i, l] = acc


@nb.njit(cache=True, nogil=True, error_model="numpy")
def scratch(pp, n_modes, T):
    """The one-state right-hand side's working arrays for prepared row pp (`derivative`)."""
    PP = np.empty((pp.shape[0], 1))
    for c in range(pp.shape[0]):
        PP[c, 0] = pp[c]
    return (PP, np.empty((2 * n_modes, 1)), np.empty((1, 2 * n_modes, 1)), np.empty(1),
            np.empty((4, T.shape[2], 1)), np.empty((4, 1)))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def derivative(t, y, dy, S, n_modes, T, base):
    """dy = f(t, y) for one state y = (q_1..q_N, q_1'..q_N') (m, m/s): `lanes_derivative` with
    one lane and libm's cos and sin. S: `scratch`(prepared row, N, T); T: `tables`(N)."""
    PP, X, K, tt, FLD, SC = S
    for c in range(2 * n_modes):
        X[c, 0] = y[c]
    tt[0] = t
    lanes_derivative(tt, X, K, 0, PP, n_modes, T, FLD, SC, 1, None, base)
    for c in range(2 * n_modes):
        dy[c] = K[0, c, 0]
