"""The multi-mode transverse System: the span's first N Galerkin modes, coupled (SI units).

    w(x, t) = sum_{n=1..N} q_n(t) phi_n(x / l),

the phi_n a basis of the span's own linear modes (sweep/models/basis.py; pinned sines
sin(n pi x / l) are the first), projected on every phi_m and divided by rho A int phi_m^2
(docs/model.md secs. 7, 10):

    q_m'' = -2 zeta w_m q_m' - w_m^2 q_m - N_m(q, t) - Gamma_m a_b(t)

N_m the projection of the axial-load and nonlinear terms: the bending terms either from the
span's energy (a row's BENDING 1, below) or Eq.17's as the paper prints them (0). In the
dimensionless fields of xi = pi x / l in [0, pi] (k = pi / l)

    a = sum q_n dphi_n/dxi,  b = sum q_n d2phi_n/dxi2,  c = ... d3,  d = ... d4

(w_x = k a, w_xx = k^2 b, w_xxx = k^3 c, w_xxxx = k^4 d; pinned sines: a = sum n q_n cos(n xi),
b = -sum n^2 q_n sin(n xi), ...), Eq.17's force per unit rho A is

    F = beta_b (-3 b^3 - 11 a b c - 3 a^2 d) - beta_m(t) a^2 b + (21/2) beta_q a^2 b^3
        + (P(t) k^2 / rho A) b,
    beta_b = w_p^2 k^2,  beta_q = w_p^2 k^4,  beta_m(t) = (4 alpha EA + 2 P(t)) k^4 / rho A,

(w_p^2 = (EI / rho A) k^4, the pinned span's first frequency squared) and N_m = int F phi_m /
int phi_m^2, evaluated by the basis' quadrature: the fields at its nodes (its tables), F there,
summed with its weights. The nodes and the modes are symmetric about midspan (equal clamps),
so the tables are folded there (sweep.models.basis.mirrored_quadrature): a node's fields and its
mirror node's come from one sum over the modes, the symmetric and antisymmetric ones apart,
and each mode projects the pair's forces at once, about half the work of a plain node loop.
For pinned sines the integrand is a trigonometric polynomial of degree at most 6N and the
trapezoidal rule on M = 3N + 1 equal intervals of [0, pi] is exact for it;
the axial load's term gives the diagonal n^2 P k^2 / rho A there, and couples the modes through
A_ij = int phi_i' phi_j' for other shapes with no code of its own. The cost grows as N^2
(fields and projection). The same force is also each mode's polynomial in q, of degree 5:
where the basis' Gauss-Legendre rule needs many nodes (clamped and elastic ends need 6 N + 12
to reach round-off, pinned sines 3 N) and the modes are few, evaluating that polynomial costs
less (a basis' POLYNOMIAL item, built from FORCE_TERMS by sweep.models.basis.force_polynomial:
the same terms, expanded once per basis; its monomials grow as N^5, so it is not built above
a few modes). With N = 1 it reproduces the one-mode coefficients K3 and K5 of docs/model.md
sec. 2 (tests/test_modes.py).

Eq.17's bending terms are not the gradient of an energy with several modes (their Jacobian
is not symmetric: an undamped span's energy wanders). The span's bending energy (EI / 2) int
kappa^2 dx, kappa = w_xx / (1 + w_x^2)^(3/2), is (EI / 2) int w_xx^2 (1 - 3 w_x^2 + 6 w_x^4)
dx to quintic order; its generalised force on mode m in the weak form (no integration by
parts, so right for every end condition, rotational springs included) has the nonlinear part,
per unit rho A, in the fields above,

    int [a^2 b (-3 beta_b + 6 beta_q a^2) phi_m'' + a b^2 (-3 beta_b + 12 beta_q a^2) phi_m'],

(phi_m', phi_m'' in xi), summed with the basis' weights on the shapes' slopes and curvatures
(T rows 5 and 6); the stretching and the axial load stay as above, without Eq.17's bending
terms (`_energy_forces`). A chunk with no such row runs Eq.17's loop alone, as before.

`basis` in the kernels is the tuple sweep.models.basis.Basis.kernel_arrays() gives:
(T, the shapes' derivatives at the nodes and the projection weights, folded about midspan
(above; PARITY); stations, the shapes at stations along the span; midspan, phi_n(1/2);
ratios, (2, N): w_n / w_p and Gamma_n / (4 / pi); shapes, (N, 6): each mode's beam-function
form, for `shape_at`, and a bound of max |phi_n|; coupling, (N, N): A_ij / pi^2, the
uniform stretching's; clamps, (10, N): the rows the load observers read, CLAMPS below;
polynomial: the force's polynomial, or an empty one (`no_polynomial`: no monomials) where
the quadrature is used; one type for both, so that a basis of either form runs on the same
compiled driver, which picks the form at run time, once an evaluation).
Nothing here knows the shapes' kind.

A point's raw row (columns below) holds the span's linear coefficients (w_p, its damping), the
load, the membrane and the base excitation, then the initial state of every mode; `prepare`
expands it, with the basis' ratios, into the per-mode coefficients the right-hand side reads.
P > 0 is compression.
"""

import math

import numba as nb
import numpy as np

from . import excitation as ex
from .flags import CONTRACT
from .vecmath import fast_cos, fast_sin

# Columns of a raw multi-mode row.
W1_SQ = 0           # w_p^2 = (EI / rho A) k^4: the pinned span's first mode's     (1/s^2)
DAMPING = 1         # 2 zeta w_p (mode n: w_n / w_p times this)                   (1/s)
LOAD_MEAN = 2       # P_mean k^2 / rho A (the constant part of P)                   (1/s^2)
LOAD_COS = 3        # P0 k^2 / rho A, the part times cos(W t)                       (1/s^2)
MEMBRANE = 4        # 4 alpha EA k^4 / rho A                                        (1/(s^2 m^2))
K_SQ = 5            # k^2 = (pi / l)^2                                              (1/m^2)
OMEGA = 6           # W, the load's angular frequency                               (rad/s)
BOUND = 7           # |q_n| (and |midspan deflection|) beyond which a point diverged  (m)
Q_SCALE = 8         # the point's displacement scale (sweep.models.modal.state_scale) (m)
V_SCALE = 9         # its velocity scale                                            (m/s)
PARTICIPATION = 10  # 4 / pi (0 without base excitation); mode n: times its basis ratio
LOAD_PHASE = 11     # phi_W: P(t) = P0 cos(W t + phi_W)                                    (rad)
TENSION = 12        # k_s k^4 l / (2 rho A): the uniform stretching tension's factor  (1/(s^2 m^2))
BENDING = 13        # the bending terms: 1 from the span's energy (weak form), 0 Eq.17's    (1)
EXCITATION = 14     # the base excitation block (kernels.excitation): a_b(t), fixed or swept
BASE_ACCEL = EXCITATION + ex.ACCEL   # A, base acceleration amplitude                     (m/s^2)
BASE_OMEGA = EXCITATION + ex.OMEGA   # w_b, base angular frequency (a sweep's start)      (rad/s)
BASE_PHASE = EXCITATION + ex.PHASE   # phi_b (a stepped sweep's carried phase)            (rad)
N_FIXED = EXCITATION + ex.SIZE       # then q_n(0) (m) for n = 1..N, then q_n'(0) (m/s)

FIXED_NAMES = ("w1_sq", "damping", "load_mean", "load_cos", "membrane", "k_sq", "omega",
               "bound", "q_scale", "v_scale", "participation", "load_phase",
               "tension", "bending") + ex.NAMES


# The items of the `basis` tuple every modal kernel takes (module docstring).
TABLES = 0          # (8, N, columns): the quadrature's tables, folded about midspan (PARITY)
STATIONS = 1        # (M + 1, N): the shapes at stations along the span
MIDSPAN = 2         # (N,): phi_n(1/2)
RATIOS = 3          # (2, N): w_n / w_p and Gamma_n / (4 / pi)
SHAPES = 4          # (N, 6): each mode's beam-function form (beta, A, B, C, D), for
                    # `shape_at`, and an upper bound of max |phi_n| over the span (column 5)
COUPLING = 5        # (N, N): A_ij / pi^2 = int dphi_i/dxi dphi_j/dxi ds, the span's stretch
CLAMPS = 6          # (10, N): what the load observers watch per mode (rows below; s = x / l)
POLYNOMIAL = 7      # the same force as a polynomial in q, or empty (`no_polynomial`, below)

# Rows of basis[CLAMPS]: what the load observers of the modal drivers read (per unit q_n).
BEND_0 = 0          # phi_n''(0): the curvature at the clamp x = 0 (times 1 / l^2)
BEND_1 = 1          # phi_n''(1): at the clamp x = l
BEND_MID = 2        # phi_n''(1/2): at midspan
SHEAR_0 = 3         # phi_n'''(0): the shear's shape at x = 0 (times 1 / l^3)
SHEAR_1 = 4         # phi_n'''(1)
SLOPE_0 = 5         # phi_n'(0): the slope at x = 0 (times 1 / l; the reaction reads AXIAL_0)
SLOPE_1 = 6         # phi_n'(1)
INERTIA = 7         # Gamma_n int (1 - s) phi_n ds: mode n's share of a uniform load's reaction
                    # at a clamp (1/2 of the load times l for all the modes: `inertia_factor`)
AXIAL_0 = 8         # the axial load's reaction at x = 0 per unit q_n and (N - P) / l, the part
AXIAL_1 = 9         # the modes leave out carried statically (phi_n'(e) for pinned sines)
N_BENDS = 3         # rows 0..2: the curvatures, linear in q, watched alike
N_OBSERVED = 10

# Rows of basis[TABLES] (sweep.models.basis): 0..3 the fields' shapes (a, b, c, d per unit
# q_n), 4..6 the projection weights on phi_m, phi_m' and phi_m'', then
PARITY = 7          # each mode's parity about midspan along every column where the tables are
                    # folded (every column a node and its mirror): +1, -1, +1, ... (mode n is
                    # symmetric for odd n, antisymmetric for even n); 0 where not folded


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def folded_pairs(T):
    """How many columns of tables T stand for a node and its mirror: all where they are
    folded about midspan (T[PARITY] not 0), none where they are read node by node. Where they
    are, the modes of even index i (n = i + 1 odd) are the symmetric ones."""
    return T.shape[2] if T[PARITY, 0, 0] != 0.0 else 0


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def span_loads(rows, coupling, q, v, n_modes, kappa, load, load_rate, inertia, inertia_rate,
               out):
    """The stretching and the clamps' shear as the load observers watch them, for the modes'
    q (m) and rates v (m/s): out = (E, E', F_0, F_0', F_1, F_1') with E = q^T C q (m^2; C =
    `coupling`, A_ij / pi^2: the span's elongation is (pi^2 / 2 l) E, its uniform tension
    N = k_s pi^2 E / (2 l)) and F_e = s3_e . q - (kappa E - load) s1_e . q +- inertia (m;
    s3_e, s1_e: `rows`' SHEAR_e and AXIAL_e; + at e = 0, - at e = 1): the transverse
    reaction at clamp e, V = -EI w''' + (N - P) w', is -(EI / l^3) F_e there, with the loads'
    parts that the modes kept do not carry going to the clamps as they would statically (the
    mode-acceleration correction, without which the reaction converges like 1/N): the axial
    load's through AXIAL_e (phi_n'(e) for sines; not 0 at a clamped end) and the base
    inertia's, r (rho A l^4 / EI) a_b(t) (`inertia_factor`; inertia and inertia_rate, m and
    m/s). kappa = k_s pi^2 l / (2 EI), 1/m^2; load = P l^2 / EI of the end load P at that
    instant, compression positive (`end_load`), load_rate its rate, 1/s; E' and F_e' their
    rates (/s)."""
    e = 0.0
    de = 0.0
    for i in range(n_modes):
        ci = 0.0
        di = 0.0
        for j in range(n_modes):
            c = coupling[i, j]
            ci += c * q[j]
            di += c * v[j]
        e += q[i] * ci
        de += q[i] * di + v[i] * ci
    out[0] = e
    out[1] = de
    axial = kappa * e - load                  # (N - P) l^2 / EI
    axial_rate = kappa * de - load_rate
    for end in range(2):
        s3 = 0.0
        d3 = 0.0
        s1 = 0.0
        d1 = 0.0
        for i in range(n_modes):
            a = rows[SHEAR_0 + end, i]
            b = rows[AXIAL_0 + end, i]
            s3 += a * q[i]
            d3 += a * v[i]
            s1 += b * q[i]
            d1 += b * v[i]
        sign = 1.0 - 2.0 * end
        out[2 + 2 * end] = s3 - axial * s1 + sign * inertia
        out[3 + 2 * end] = d3 - (axial_rate * s1 + axial * d1) + sign * inertia_rate


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def span_load_bound(rows, coupling, q_max, n_modes, kappa, load_max, inertia_max, k):
    """An upper bound of |L_k| (`span_loads`' load k: 0 the stretch E, 1 and 2 the shears F_0
    and F_1, m^2 and m) over states whose modes are within |q_n| <= q_max[n] (m), with the end
    load's |P l^2 / EI| <= load_max and the inertia's |r a_b| <= inertia_max (m): |E| <=
    sum |C_ij| q_max_i q_max_j, |F_e| <= sum |s3_e,i| q_max_i + (|kappa| |E|max + load_max)
    sum |s1_e,i| q_max_i + inertia_max, term by term from span_loads' sums."""
    e = 0.0
    for i in range(n_modes):
        for j in range(n_modes):
            e += abs(coupling[i, j]) * q_max[i] * q_max[j]
    if k == 0:
        return e
    end = k - 1
    s3 = 0.0
    s1 = 0.0
    for i in range(n_modes):
        s3 += abs(rows[SHEAR_0 + end, i]) * q_max[i]
        s1 += abs(rows[AXIAL_0 + end, i]) * q_max[i]
    return s3 + (abs(kappa) * e + load_max) * s1 + inertia_max


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def inertia_factor(row, n_modes, rows):
    """r (rho A l^4 / EI) (s^2) of a raw row, times a_b(t) (m/s^2) the `span_loads` inertia
    (m): r = 1/2 - sum_n rows[INERTIA, n], the share of a uniform load's reaction at a clamp
    that the N modes leave out (0.095 for one pinned mode, 0.155 for one clamped, about
    0.25 / N pinned), and rho A l^4 / EI = pi^4 / w_p^2."""
    r = 0.5
    for i in range(n_modes):
        r -= rows[INERTIA, i]
    return r * math.pi ** 4 / row[W1_SQ]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def end_load_factors(pp, n_modes):
    """The end load P(t) = P_mean + P_cos cos(W t + phi_W) of a prepared row as
    (P_mean l^2 / EI, P_cos l^2 / EI, W (rad/s), phi_W (rad)) for `end_load`: pi^2 times the
    row's linear load terms (P k^2 / rho A, 1/s^2) over w_p^2 = (EI / rho A) k^4."""
    s = 3 * n_modes
    w_p2 = pp[s + S_BETA_B] * pp[s + S_BETA_B] / pp[s + S_BETA_Q]
    scale = math.pi * math.pi / w_p2
    return (scale * pp[s + S_LOAD_MEAN], scale * pp[s + S_LOAD_COS], pp[s + S_OMEGA],
            pp[s + S_LOAD_PHASE])


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def end_load(mean, amplitude, omega, phase, t):
    """(P l^2 / EI, its rate, 1/s) at t (s) of the end load `end_load_factors` gives; no
    cosine or sine where the load is constant or absent (every load observation of a span
    without a harmonic end load would pay them)."""
    if amplitude == 0.0:
        return mean, 0.0
    x = omega * t + phase
    return mean + amplitude * math.cos(x), -amplitude * omega * math.sin(x)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def shear_factor(pp, n_modes):
    """kappa = k_s pi^2 l / (2 EI) (1/m^2) of a prepared row (`span_loads`): pi^2 S_TENSION /
    w_p^2, w_p^2 = S_BETA_B^2 / S_BETA_Q; 0 without the uniform tension."""
    s = 3 * n_modes
    tension = pp[s + S_TENSION]
    if tension == 0.0:
        return 0.0
    return math.pi * math.pi * tension * pp[s + S_BETA_Q] / (pp[s + S_BETA_B] * pp[s + S_BETA_B])


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def basis_modes(basis):
    """N, the number of modes of a basis tuple (callable from Python and from the kernels)."""
    return basis[RATIOS].shape[1]


# What of its basis a lane of the lock-step driver reads across the lanes (kernels.modal_lanes:
# the lanes of one call may each carry their own basis of a family, `member`): one column of LB
# (lane_basis_size(basis), lanes), written by `write_lane_basis`. Rows, for N modes:
#   0 ..                basis[COUPLING], N x N, row by row (the uniform tension's A_ij / pi^2)
#   lb_midspan(N) ..    basis[MIDSPAN], N (phi_n(1/2): the midspan deflection's weights)
#   lb_bends(N) ..      basis[CLAMPS] rows 0..N_BENDS-1, N each (the curvatures watched)
#   lb_sizes(N) ..      basis[SHAPES][:, 5], N (each mode's bound of max |phi_n|)
#   lb_coefficients(N) .. the polynomial's coefficients (basis[POLYNOMIAL][3]; none without)
@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lb_midspan(n_modes):
    return n_modes * n_modes


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lb_bends(n_modes):
    return n_modes * n_modes + n_modes


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lb_sizes(n_modes):
    return n_modes * n_modes + (1 + N_BENDS) * n_modes


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def lb_coefficients(n_modes):
    return n_modes * n_modes + (2 + N_BENDS) * n_modes


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def lane_basis_size(basis):
    """Rows of a lane's column of LB for `basis` (the layout above)."""
    n = basis_modes(basis)
    return lb_coefficients(n) + _coefficients_size(basis[POLYNOMIAL])


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _coefficients_size(PY):
    """The coefficients of polynomial PY (none for an empty one)."""
    return PY[3].shape[0]


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def write_lane_basis(basis, LB, j):
    """Column j of LB: what of `basis` the lanes read across the lanes (the layout above)."""
    n = basis_modes(basis)
    CP = basis[COUPLING]
    for i in range(n):
        for k in range(n):
            LB[i * n + k, j] = CP[i, k]
        LB[lb_midspan(n) + i, j] = basis[MIDSPAN][i]
        for e in range(N_BENDS):
            LB[lb_bends(n) + e * n + i, j] = basis[CLAMPS][e, i]
        LB[lb_sizes(n) + i, j] = basis[SHAPES][i, 5]
    _write_coefficients(basis[POLYNOMIAL], LB, lb_coefficients(n), j)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _write_coefficients(PY, LB, row, j):
    """LB[row.., j] = polynomial PY's coefficients (none for an empty one)."""
    coef = PY[3]
    for t in range(coef.shape[0]):
        LB[row + t, j] = coef[t]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def lane_basis(basis, lanes):
    """LB (lane_basis_size(basis), lanes) with every lane's column `basis`' (tests and
    benchmarks that call `lanes_derivative` on one basis)."""
    LB = np.zeros((lane_basis_size(basis), lanes))
    for j in range(lanes):
        write_lane_basis(basis, LB, j)
    return LB


def stacked(bases):
    """The kernel arrays of `bases` (sweep.models.basis.Basis.kernel_arrays() each, N modes)
    stacked item by item along a new first axis: a family as kernels.modal_lanes takes it,
    all of whose points run in one call whatever their basis (`member` picks one out; plain
    NumPy, called from Python). None where the lanes cannot: items of different shapes, a
    polynomial in some bases and not in others (the quadrature's tables, read alike by every
    lane, would differ) or of a different structure (its program, starts, monomials,
    symmetric ends and pure count: only its coefficients may differ), or different zeros in
    the coupling or the midspan weights (the lanes skip a family's zeros). Elastic ends of up
    to 4 modes with K > 0 stack (sweep.models.basis.elastic_bases_stack)."""
    first = bases[0]
    for other in bases[1:]:
        if any(a.shape != b.shape for a, b in zip(first[:POLYNOMIAL], other[:POLYNOMIAL])):
            return None
        if not uses_polynomial(first) or not uses_polynomial(other) or not all(
                np.array_equal(first[POLYNOMIAL][k], other[POLYNOMIAL][k])
                for k in (0, 1, 2, 4, 5)):
            return None
        if not all(np.array_equal(first[k] == 0, other[k] == 0) for k in (COUPLING, MIDSPAN)):
            return None
    arrays = tuple(np.ascontiguousarray(np.stack([b[k] for b in bases]))
                   for k in range(POLYNOMIAL))
    polynomial = tuple(np.ascontiguousarray(np.stack([b[POLYNOMIAL][k] for b in bases]))
                       for k in range(5)) + (
        np.array([b[POLYNOMIAL][5] for b in bases], np.int64),)
    return arrays + (polynomial,)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def member(family, b):
    """Basis b of a family stacked item by item along a first axis (`stacked`: every item of
    every basis the same shape, the polynomials' structure the same):
    the basis tuple the kernels take, its arrays views of the family's."""
    PY = family[POLYNOMIAL]
    return (family[TABLES][b], family[STATIONS][b], family[MIDSPAN][b], family[RATIOS][b],
            family[SHAPES][b], family[COUPLING][b], family[CLAMPS][b],
            (PY[0][b], PY[1][b], PY[2][b], PY[3][b], PY[4][b], PY[5][b]))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def n_columns(n_modes):
    """Columns of a raw row for n_modes modes (callable from Python and from the kernels)."""
    return N_FIXED + 2 * n_modes


# The prepared row `prepare` writes (length prepared_size(N)): three blocks of N per-mode
# coefficients, then the scalars. r_n = w_n / w_p and g_n = Gamma_n / (4 / pi) are the basis'
# ratios (w_p the pinned span's first frequency, W1_SQ's root; pinned sines: n^2 and 1/n, odd n).
P_DAMPING = 0       # block 0: -r_n (2 zeta w_p) = -2 zeta w_n                      (1/s)
P_STIFF = 1         # block 1: -r_n^2 w_p^2 = -w_n^2                                  (1/s^2)
P_FORCE = 2         # block 2: -g_n (4 / pi), the mode's base participation          (1)
S_BETA_B = 0        # scalars after the blocks: beta_b = w_p^2 k^2                  (1/(s^2 m^2))
S_BETA_Q = 1        # beta_q = w_p^2 k^4                                             (1/(s^2 m^4))
S_BETA_M0 = 2       # beta_m's constant part: 4 alpha EA k^4/rho A + 2 k^2 P_mean k^2/rho A
S_BETA_M1 = 3       # beta_m's cos(W t) part: 2 k^2 P0 k^2 / rho A
S_OMEGA = 4
S_LOAD_PHASE = 5
S_LOAD_MEAN = 6     # the axial load's linear term P(t) k^2 / rho A: constant part    (1/s^2)
S_LOAD_COS = 7      # and the part times cos(W t + phi_W)                             (1/s^2)
S_TENSION = 8       # the uniform tension's factor (TENSION)                          (1/(s^2 m^2))
S_ENERGY = 9        # 1: the bending terms from the span's energy, 0: Eq.17's (BENDING)     (1)
S_EXCITATION = 10   # the excitation block, copied from the raw row
S_BASE_ACCEL = S_EXCITATION + ex.ACCEL
S_BASE_OMEGA = S_EXCITATION + ex.OMEGA
S_BASE_PHASE = S_EXCITATION + ex.PHASE
N_SCALARS = S_EXCITATION + ex.SIZE


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def prepared_size(n_modes):
    """Length of a prepared row for n_modes modes."""
    return 3 * n_modes + N_SCALARS


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def shape_at(shapes, i, x):
    """Mode i's shape and its first two derivatives in s = x / l at s = x, (phi, phi', phi''),
    from its beam-function row shapes[i] = (beta, A, B, C, D) (module docstring); the
    exponentials only where their coefficients are not zero (pinned sines: sin(beta x) alone,
    to the bit)."""
    beta = shapes[i, 0]
    a = shapes[i, 1]
    b = shapes[i, 2]
    c = shapes[i, 3]
    d = shapes[i, 4]
    bx = beta * x
    cb = math.cos(bx)
    sb = math.sin(bx)
    v = a * cb + b * sb
    d1 = -a * sb + b * cb
    d2 = -v
    if c != 0.0:
        e = c * math.exp(-bx)
        v += e
        d1 -= e
        d2 += e
    if d != 0.0:
        e = d * math.exp(-beta * (1.0 - x))
        v += e
        d1 += e
        d2 += e
    return v, beta * d1, beta * beta * d2


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def span_argmax(q, n_modes, basis):
    """(max over the span of |w(x)| (m), its x / l) for the modal coefficients q[0..N-1]
    (m), w = sum_n q_n phi_n(x / l): the values at the basis' stations (8 per half-wave of
    mode N for pinned sines), each local maximum within 10 % of the best refined by Newton's
    method on w'(x) = 0 on the shapes themselves (`shape_at`), never leaving its station's
    interval. A value found, so never above the true maximum; the refinement makes it exact to
    round-off when the stations bracket the maximum's hump (tests/test_modes.py checks it
    against a dense grid)."""
    stations = basis[STATIONS]
    shapes = basis[SHAPES]
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
    w = 0.0                       # w_prev, w, w_next: w at stations k - 1, k, k + 1
    w_next = 0.0
    for i in range(n_modes):
        w += q[i] * stations[0, i]
        w_next += q[i] * stations[1, i]
    for k in range(1, m):
        w_prev = w
        w = w_next
        w_next = 0.0
        for i in range(n_modes):
            w_next += q[i] * stations[k + 1, i]
        if not (abs(w) >= abs(w_prev) and abs(w) >= abs(w_next) and abs(w) >= 0.9 * best):
            continue
        x = k / m                               # in units of l
        for _ in range(8):
            d1 = 0.0
            d2 = 0.0
            for i in range(n_modes):
                _, p1, p2 = shape_at(shapes, i, x)
                d1 += q[i] * p1
                d2 += q[i] * p2
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
            v += q[i] * shape_at(shapes, i, x)[0]
        if abs(v) > top:
            top = abs(v)
            where = x
    return top, where


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def prepare(row, n_modes, pp, ratios):
    """Write the prepared row pp (prepared_size(N)) of raw row `row` (columns above) for a
    basis whose ratios are `ratios` (2, N): w_n / w_p and Gamma_n / (4 / pi)
    (sweep.models.basis)."""
    n_b = n_modes
    k2 = row[K_SQ]
    for i in range(n_modes):
        r = ratios[0, i]
        pp[P_DAMPING * n_b + i] = -r * row[DAMPING]
        pp[P_STIFF * n_b + i] = -(r * r) * row[W1_SQ]
        pp[P_FORCE * n_b + i] = -row[PARTICIPATION] * ratios[1, i]
    s = 3 * n_b
    pp[s + S_BETA_B] = row[W1_SQ] * k2
    pp[s + S_BETA_Q] = row[W1_SQ] * k2 * k2
    pp[s + S_BETA_M0] = row[MEMBRANE] + 2.0 * k2 * row[LOAD_MEAN]
    pp[s + S_BETA_M1] = 2.0 * k2 * row[LOAD_COS]
    pp[s + S_OMEGA] = row[OMEGA]
    pp[s + S_LOAD_PHASE] = row[LOAD_PHASE]
    pp[s + S_LOAD_MEAN] = row[LOAD_MEAN]
    pp[s + S_LOAD_COS] = row[LOAD_COS]
    pp[s + S_TENSION] = row[TENSION]
    pp[s + S_ENERGY] = 1.0 if row[BENDING] != 0.0 else 0.0
    for c in range(ex.SIZE):
        pp[s + S_EXCITATION + c] = row[EXCITATION + c]


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def base_acceleration(t, pp, n_modes, base):
    """a_b(t) (m/s^2) of a prepared row (kernels.excitation.signal: `base` True for the sine
    kinds, the records for the record kind)."""
    return ex.signal(t, pp, 3 * n_modes + S_EXCITATION, 1, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, inline="always")
def _eq17_bending(a, b, c, d, beta_b, beta_q):
    """Eq.17's nonlinear bending terms at a node, from the fields (a, b, c, d) there (module
    docstring): beta_b (-3 b^3 - 11 a b c - 3 a^2 d) + 10.5 beta_q a^2 b^3 (per unit rho A);
    both forms of the right-hand side take them from here."""
    a2 = a * a
    b2 = b * b
    return beta_b * (-3.0 * b2 * b - 11.0 * a * b * c - 3.0 * a2 * d) + 10.5 * beta_q * a2 * b2 * b


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, inline="always")
def _energy_bending(a, b, beta_b, beta_q):
    """The nonlinear bending force from the span's energy at a node, from the fields (a, b)
    there (module docstring), as its two parts: (the part projected on dphi_m/dxi, the part
    projected on d2phi_m/dxi2) = (a b^2 (12 beta_q a^2 - 3 beta_b), a^2 b (6 beta_q a^2 -
    3 beta_b)) (per unit rho A); every form of the right-hand side takes them from here."""
    a2 = a * a
    return (a * (b * b) * (12.0 * beta_q * a2 - 3.0 * beta_b),
            a2 * b * (6.0 * beta_q * a2 - 3.0 * beta_b))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, inline="always")
def _axial(a, b, linear, membrane):
    """The axial terms at a node, projected on phi_m: (linear - membrane a^2) b, linear = P(t)
    k^2 / rho A less the uniform tension's N k^2 / rho A, membrane = beta_m(t) (the paper's local
    membrane term; module docstring)."""
    return (linear - membrane * (a * a)) * b


# The nonlinear and axial-load force as data, term by term: (group, projection row of the
# tables, coefficient, fields), the fields 0..3 = a, b, c, d; the force on mode m is the sum of
# group scale x coefficient x int (product of the fields) x (the projection row's shape), the
# same terms the node functions above evaluate (tests/test_modes.py checks the two against each
# other). sweep.models.basis expands them into each mode's polynomial in q (`POLYNOMIAL`), which
# the right-hand side evaluates instead of the quadrature where that costs less.
G_LINEAR = 0        # P(t) k^2 / rho A less the uniform tension's N k^2 / rho A: SC[0]
G_MEMBRANE = 1      # beta_m(t), the paper's local membrane term: SC[1]
G_ENERGY_CUBIC = 2  # beta_b, lanes whose bending terms come from the span's energy
G_ENERGY_QUINTIC = 3    # beta_q, the same lanes
G_EQ17_CUBIC = 4    # beta_b, lanes with Eq.17's bending terms
G_EQ17_QUINTIC = 5  # beta_q, the same lanes
N_GROUPS = 6
FORCE_TERMS = (
    (G_LINEAR, 4, 1.0, (1,)),                      # _axial: linear b, on phi_m
    (G_MEMBRANE, 4, -1.0, (0, 0, 1)),              # - membrane a^2 b, on phi_m
    (G_ENERGY_CUBIC, 5, -3.0, (0, 1, 1)),          # _energy_bending: -3 beta_b a b^2, on phi_m'
    (G_ENERGY_CUBIC, 6, -3.0, (0, 0, 1)),          # -3 beta_b a^2 b, on phi_m''
    (G_ENERGY_QUINTIC, 5, 12.0, (0, 0, 0, 1, 1)),  # 12 beta_q a^3 b^2, on phi_m'
    (G_ENERGY_QUINTIC, 6, 6.0, (0, 0, 0, 0, 1)),   # 6 beta_q a^4 b, on phi_m''
    (G_EQ17_CUBIC, 4, -3.0, (1, 1, 1)),            # _eq17_bending: beta_b (-3 b^3
    (G_EQ17_CUBIC, 4, -11.0, (0, 1, 2)),           # - 11 a b c
    (G_EQ17_CUBIC, 4, -3.0, (0, 0, 3)),            # - 3 a^2 d)
    (G_EQ17_QUINTIC, 4, 10.5, (0, 0, 1, 1, 1)),    # + 10.5 beta_q a^2 b^3, on phi_m
)


def no_polynomial(n_modes):
    """The POLYNOMIAL item of a basis whose force is evaluated by quadrature: the layout of
    sweep.models.basis.force_polynomial's (program, starts, monomials, coefficients,
    symmetric, pure) with no monomial and no term, so that both forms are one Numba type
    (plain NumPy, called from Python)."""
    return (np.zeros((0, 2), np.int64), np.zeros((n_modes, N_GROUPS + 1), np.int64),
            np.zeros(0, np.int64), np.zeros(0), np.zeros((n_modes, N_GROUPS), np.int64), 0)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def has_polynomial(PY):
    """Whether polynomial PY has monomials (a basis that uses it: every real one holds the
    N modes' own), not `no_polynomial`'s empty one."""
    return PY[0].shape[0] > 0


def uses_polynomial(basis):
    """Whether the right-hand side evaluates the basis' force as its polynomial (POLYNOMIAL)
    rather than by quadrature (an empty POLYNOMIAL, `no_polynomial`)."""
    return has_polynomial.py_func(basis[POLYNOMIAL])


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _field_rows(T, PY):
    """`field_rows` of tables T and polynomial PY."""
    nodes = T.shape[2] + folded_pairs(T)
    if not has_polynomial(PY):
        return nodes
    return max(nodes, (PY[0].shape[0] + N_GROUPS + 1 + 3) // 4)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def field_rows(basis):
    """The middle axis of the lanes' scratch FLD (4, rows, lanes) for `basis`: its quadrature
    nodes (each pair's two: `_lanes_fields`), or room for the polynomial's monomials and
    group scales (`_polynomial_lanes`) (callable from Python and from the kernels)."""
    return _field_rows(basis[TABLES], basis[POLYNOMIAL])


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _group_scale(g, linear, membrane, beta_b, beta_q, energy):
    """Group g's scale (FORCE_TERMS) for one state: energy 1 where the bending terms come
    from the span's energy, 0 where from Eq.17."""
    if g == G_LINEAR:
        return linear
    if g == G_MEMBRANE:
        return membrane
    if g == G_ENERGY_CUBIC:
        return energy * beta_b
    if g == G_ENERGY_QUINTIC:
        return energy * beta_q
    if g == G_EQ17_CUBIC:
        return (1.0 - energy) * beta_b
    return (1.0 - energy) * beta_q


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _polynomial_lanes(X, PP, sc, SC, PY, R, n, n_run, symmetric):
    """The polynomial form of the force (POLYNOMIAL: program (K, 2), starts (N, N_GROUPS + 1),
    monomials (T,), coefficients (T,), symmetric (N, N_GROUPS), pure; sweep.models.basis.
    force_polynomial) for every lane: R[0..K-1] the monomials (R[k] = R[program[k, 0]]
    R[program[k, 1]] for k >= N, the q_n below), R[K + g] group g's scale;
    returns the bit mask of the groups some lane has a non-zero scale in. Each mode's sum is
    `_polynomial_mode`'s. symmetric (`_symmetric_lanes`): the monomials of the symmetric modes
    alone, the first PY[5] (the others are 0 and unread)."""
    program = PY[0]
    n_mono = program.shape[0]
    for k in range(n):
        for l in range(n_run):
            R[k, l] = X[k, l]
    for k in range(n, PY[5] if symmetric else n_mono):
        i = program[k, 0]
        j = program[k, 1]
        for l in range(n_run):
            R[k, l] = R[i, l] * R[j, l]
    active = 0
    for g in range(N_GROUPS):
        for l in range(n_run):
            R[n_mono + g, l] = _group_scale(g, SC[0, l], SC[1, l], PP[sc + S_BETA_B, l],
                                            PP[sc + S_BETA_Q, l], PP[sc + S_ENERGY, l])
        for l in range(n_run):
            if R[n_mono + g, l] != 0.0:
                active |= 1 << g
                break
    return active


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _polynomial_mode(i, PY, R, active, out, n_run, symmetric, LB, own):
    """out[l] = the force on mode i in lane l (per unit rho A, as the quadrature's projection):
    the sum over the groups in `active` of the group's scale R[K + g] times its terms'
    coefficients x monomials (`_polynomial_lanes` filled R): PY's coefficients, or with `own`
    each lane's (LB, `write_lane_basis`; the structure, PY's, is every lane's);
    symmetric (`_symmetric_lanes`): the terms of symmetric modes alone, the others being 0
    (sweep.models.basis.force_polynomial), and none for an antisymmetric mode."""
    starts = PY[1]
    mono = PY[2]
    coef = PY[3]
    n_mono = PY[0].shape[0]
    cf = lb_coefficients(starts.shape[0])      # LB's row of the first coefficient
    for l in range(n_run):
        out[l] = 0.0
    for g in range(N_GROUPS):
        lo = starts[i, g]
        hi = PY[4][i, g] if symmetric else starts[i, g + 1]
        if lo == hi or not (active >> g) & 1:
            continue
        k = mono[lo]
        if not own:                     # (the shared coefficient stays in a register)
            c = coef[lo]
            for l in range(n_run):
                R[n_mono + N_GROUPS, l] = c * R[k, l]
            for t in range(lo + 1, hi):
                c = coef[t]
                k = mono[t]
                for l in range(n_run):
                    R[n_mono + N_GROUPS, l] += c * R[k, l]
        else:
            for l in range(n_run):
                R[n_mono + N_GROUPS, l] = LB[cf + lo, l] * R[k, l]
            for t in range(lo + 1, hi):
                k = mono[t]
                for l in range(n_run):
                    R[n_mono + N_GROUPS, l] += LB[cf + t, l] * R[k, l]
        for l in range(n_run):
            out[l] += R[n_mono + g, l] * R[n_mono + N_GROUPS, l]


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _energy_forces(PP, sc, FLD, SC, nodes, n_run):
    """The nonlinear forces at the nodes (per unit rho A, in the fields' units) of lanes
    whose bending terms may come from the span's energy (S_ENERGY 1) or Eq.17 (0), from the
    fields FLD[0..3] = (a, b, c, d) at each node: FLD[0] = what is projected on phi_m (the
    stretching, the axial load and, for Eq.17's lanes, Eq.17's bending terms), FLD[1] and
    FLD[2] = the energy's bending force's parts projected on dphi_m/dxi and d2phi_m/dxi2
    (module docstring: a b^2 (-3 beta_b + 12 beta_q a^2) and a^2 b (-3 beta_b + 6 beta_q
    a^2); 0 for Eq.17's lanes). SC[0], SC[1]: the linear and membrane factors of b."""
    for j in range(nodes):
        for l in range(n_run):
            a = FLD[0, j, l]
            b = FLD[1, j, l]
            c = FLD[2, j, l]
            d = FLD[3, j, l]
            e = PP[sc + S_ENERGY, l]
            beta_b = PP[sc + S_BETA_B, l]
            beta_q = PP[sc + S_BETA_Q, l]
            g1, g2 = _energy_bending(a, b, beta_b, beta_q)
            FLD[0, j, l] = ((1.0 - e) * _eq17_bending(a, b, c, d, beta_b, beta_q)
                            + _axial(a, b, SC[0, l], SC[1, l]))
            FLD[1, j, l] = e * g1
            FLD[2, j, l] = e * g2


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _eq17_forces(PP, sc, FLD, SC, nodes, n_run):
    """`_energy_forces` where every lane's bending terms come from Eq.17: FLD[0, j] = Eq.17's
    bending terms and the stretching and axial load at each node, from the fields FLD[0..3] =
    (a, b, c, d) there."""
    for j in range(nodes):
        for l in range(n_run):
            a = FLD[0, j, l]
            b = FLD[1, j, l]
            c = FLD[2, j, l]
            d = FLD[3, j, l]
            FLD[0, j, l] = (_eq17_bending(a, b, c, d, PP[sc + S_BETA_B, l],
                                          PP[sc + S_BETA_Q, l])
                            + _axial(a, b, SC[0, l], SC[1, l]))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _energy_only_forces(PP, sc, FLD, SC, nodes, n_run):
    """`_energy_forces` where every lane's bending terms come from the span's energy: from
    the fields FLD[0..1] = (a, b) alone (c and d are not computed then), the same three
    parts, the same arithmetic (so the same bits) without Eq.17's terms."""
    for j in range(nodes):
        for l in range(n_run):
            a = FLD[0, j, l]
            b = FLD[1, j, l]
            g1, g2 = _energy_bending(a, b, PP[sc + S_BETA_B, l], PP[sc + S_BETA_Q, l])
            FLD[0, j, l] = _axial(a, b, SC[0, l], SC[1, l])
            FLD[1, j, l] = g1
            FLD[2, j, l] = g2


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _lanes_signal(tt, PP, sc, SC, n_run, base):
    """SC[2, l] = a_b(tt[l]) (m/s^2) of each lane's excitation block (rows sc + S_EXCITATION..
    of PP), any kind (kernels.excitation: libm's sine, or a record read lane by lane)."""
    flat = PP.reshape(PP.size)
    lanes = PP.shape[1]
    for l in range(n_run):
        SC[2, l] = ex.signal(tt[l], flat, (sc + S_EXCITATION) * lanes + l, lanes, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _lanes_sine(tt, PP, sc, SC, n_run, base):
    """`_lanes_signal` for the lanes' fixed-frequency, fixed-level sine, vectorised
    (vecmath.fast_sin)."""
    for l in range(n_run):
        x = PP[sc + S_BASE_OMEGA, l] * tt[l] + PP[sc + S_BASE_PHASE, l]
        SC[2, l] = PP[sc + S_BASE_ACCEL, l] * fast_sin(x)


# fast True: the vectorised sine, or a record (which has no fast form) lane by lane
_lanes_fast_signal = ex.by_kind(_lanes_sine, _lanes_signal)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _lanes_fields(T, f, X, FLD, n, n_run, symmetric):
    """Fields f and f + 1 (0: a and b, 2: c and d) of every lane at every node of the basis'
    folded tables T (sweep.models.basis.mirrored_quadrature): FLD[f, j] and FLD[f + 1, j] at
    the nodes of T's columns j < half, and at the mirror of each paired node j < paired
    (`folded_pairs`: all or none) in row half + j. A paired node's symmetric modes (even i)
    and its antisymmetric ones (odd i) are summed apart, e and o, over half the nodes; at the
    mirror node the field is (-1)^order (e - o), order 1 for a and 3 for c, 2 for b and 4 for
    d. symmetric (`_symmetric_lanes`): the antisymmetric modes are at rest, o = 0, and the
    mirror rows are not written (the forces there are the nodes' own, mirrored)."""
    half = T.shape[2]
    folded = folded_pairs(T) > 0
    mirrors = 0 if symmetric else folded_pairs(T)
    for j in range(mirrors):            # the rows mode 1 (symmetric) does not write
        for l in range(n_run):
            FLD[f, half + j, l] = 0.0
            FLD[f + 1, half + j, l] = 0.0
    for i in range(n):
        odd = folded and i % 2 == 1
        if symmetric and odd:
            continue
        for j in range(half):
            r = half + j if odd and j < mirrors else j
            t0 = T[f, i, j]
            t1 = T[f + 1, i, j]
            if i == 0:
                for l in range(n_run):
                    q = X[0, l]
                    FLD[f, r, l] = t0 * q
                    FLD[f + 1, r, l] = t1 * q
            else:
                for l in range(n_run):
                    q = X[i, l]
                    FLD[f, r, l] += t0 * q
                    FLD[f + 1, r, l] += t1 * q
    for j in range(mirrors):
        for l in range(n_run):
            e = FLD[f, j, l]
            o = FLD[f, half + j, l]
            FLD[f, j, l] = e + o
            FLD[f, half + j, l] = o - e
            e = FLD[f + 1, j, l]
            o = FLD[f + 1, half + j, l]
            FLD[f + 1, j, l] = e + o
            FLD[f + 1, half + j, l] = e - o


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _pair_forces(FLD, half, paired, parts, n_run, symmetric):
    """The forces FLD[0..parts-1] at each paired node j (row j) and its mirror (row half + j)
    replaced by their sum (row j) and difference (row half + j): what a mode of either parity
    projects there (`lanes_derivative`). symmetric: the mirror's forces are the node's own
    mirrored (an even function of the antisymmetric fields on phi_m and phi_m'', odd on
    phi_m'), so what a symmetric mode projects is twice the node's own, in row j, the same
    bits as the sum or difference."""
    for c in range(parts):
        for j in range(paired):
            if symmetric:
                for l in range(n_run):
                    FLD[c, j, l] = 2.0 * FLD[c, j, l]
                continue
            for l in range(n_run):
                g = FLD[c, j, l]
                h = FLD[c, half + j, l]
                FLD[c, j, l] = g + h
                FLD[c, half + j, l] = g - h


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _symmetric_lanes(T, X, n, n_run):
    """Whether every lane's antisymmetric modes (even n, in folded tables T) are exactly at
    rest, q = 0: then the span's shape is symmetric about midspan, the forces on the
    antisymmetric modes are exactly 0 and the mirror nodes' exactly the nodes' own, so the
    right-hand side skips them (a symmetric span under a symmetric load from rest stays so:
    the base excitation's usual case)."""
    if folded_pairs(T) == 0:
        return False
    for i in range(1, n, 2):
        for l in range(n_run):
            if X[i, l] != 0.0:
                return False
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def lanes_derivative(tt, X, K, s, PP, n_modes, T, FLD, SC, n_run, fast, base, CP, PY, LB,
                     own):
    """The System's right-hand side for n_run states side by side (lanes l < n_run):
    K[s, :, l] = f(tt[l], X[:, l]), X[:, l] = (q_1..q_N, q_1'..q_N') (m, m/s), K[s, :, l] =
    (q', q'') (m/s, m/s^2). PP[:, l]: lane l's prepared row (`prepare`); T: the basis'
    tables (basis[TABLES]: the shapes' derivatives at the quadrature nodes and the
    projection weights, folded about midspan: `_lanes_fields`); FLD (4, `field_rows`, lanes)
    and SC (4, lanes): scratch. fast: None (libm's cos and
    sin) or True (vecmath's vectorisable ones); base: None (no base excitation term), True
    (a sine kind) or the records of a random base acceleration (kernels.excitation: read lane
    by lane, fast or not);
    CP: the basis' coupling A_ij / pi^2 (basis[COUPLING]). own: whether the lanes carry bases
    of their own (a family's, whose zeros and polynomial structure are the same): then each
    lane's coupling and polynomial coefficients are LB's (`lane_basis_size`, lanes;
    `write_lane_basis`) and CP is read for its zeros only; else every lane's are CP's and PY's
    (one basis: no per-lane loads). The uniform stretching tension N = k_s e, e = (k^2 l / 2)
    sum CP_ij q_i q_j, adds -N k^2 b / rho A to F (a lane whose TENSION is 0 has none; when no
    lane has one it is not computed). A lane whose S_ENERGY is
    1 takes its bending terms from the span's energy (module docstring), projected on the
    shapes' slopes and curvatures too (`_energy_forces`). PY: the basis' POLYNOMIAL, or None
    (a switch: the quadrature's code alone, as kernels.modal_lanes passes it for a basis
    without one); where it has monomials (`has_polynomial`), the same force is evaluated as
    each mode's polynomial in q (`_polynomial_lanes`, FLD its scratch: `field_rows`) instead
    of at the nodes.

    Everything that couples the modes is evaluated at the nodes and projected on each mode
    there: the nonlinear terms and the axial load's linear term P(t) w_xx (for pinned sines a
    diagonal n^2 P k^2 / rho A, for other shapes the matrix A_ij = int phi_i' phi_j'), so the
    per-mode coefficients are the diagonal mass, damping, stiffness and participation only.

    The lane is every array's last, contiguous axis and every loop over modes and quadrature
    nodes sits outside the loop across the lanes, which is straight-line arithmetic, so LLVM
    vectorises it. It and its callees are compiled `forceinline` (LLVM inlines them into
    modal_lanes._attempt's one call site; Numba's IR is not copied, so the first compile is
    unchanged): a call passes every array as its 7-11 words, about 100 here, which cost
    ~50 ns of a 3-mode clamped evaluation's 360 and 8 % of harness-clamps' run."""
    n = n_modes
    sc = 3 * n
    half = T.shape[2]
    paired = folded_pairs(T)
    symmetric = _symmetric_lanes(T, X, n, n_run)
    mirrors = 0 if symmetric else paired    # the mirror nodes' rows the fields fill
    nodes = half + mirrors
    for l in range(n_run):
        x = PP[sc + S_OMEGA, l] * tt[l] + PP[sc + S_LOAD_PHASE, l]
        cw = math.cos(x) if fast is None else fast_cos(x)
        SC[0, l] = PP[sc + S_LOAD_MEAN, l] + PP[sc + S_LOAD_COS, l] * cw
        SC[1, l] = PP[sc + S_BETA_M0, l] + PP[sc + S_BETA_M1, l] * cw
    tension = False
    for l in range(n_run):
        tension = tension or PP[sc + S_TENSION, l] != 0.0
    if tension:                         # the uniform tension N = k_s e, e = int w_x^2 / 2
        for l in range(n_run):
            SC[3, l] = 0.0
        for i in range(n):
            for k in range(n):
                a_ik = CP[i, k]
                if a_ik == 0.0:
                    continue
                if own:
                    r = i * n + k
                    for l in range(n_run):
                        SC[3, l] += LB[r, l] * X[i, l] * X[k, l]
                else:
                    for l in range(n_run):
                        SC[3, l] += a_ik * X[i, l] * X[k, l]
        for l in range(n_run):
            SC[0, l] -= PP[sc + S_TENSION, l] * SC[3, l]
    if base is not None:
        if fast is None:
            _lanes_signal(tt, PP, sc, SC, n_run, base)
        else:
            _lanes_fast_signal(tt, PP, sc, SC, n_run, base)
    if PY is not None and has_polynomial(PY):    # (None: the quadrature alone is compiled)
        R = FLD.reshape((FLD.shape[0] * FLD.shape[1], FLD.shape[2]))
        active = _polynomial_lanes(X, PP, sc, SC, PY, R, n, n_run, symmetric)
        for i in range(n):
            _polynomial_mode(i, PY, R, active, SC[3], n_run, symmetric, LB, own)
            _mode_acceleration(K, s, i, X, PP, SC, n, n_run, base)
        return
    energy = False                      # some lane's bending terms from the span's energy
    eq17 = False                        # some lane's Eq.17's (which alone read c and d)
    for l in range(n_run):
        energy = energy or PP[sc + S_ENERGY, l] != 0.0
        eq17 = eq17 or PP[sc + S_ENERGY, l] == 0.0
    for f in range(0, 4 if eq17 else 2, 2):     # (a, b), then (c, d) for Eq.17's lanes
        _lanes_fields(T, f, X, FLD, n, n_run, symmetric)
    if energy and not eq17:
        _energy_only_forces(PP, sc, FLD, SC, nodes, n_run)
    elif energy:
        _energy_forces(PP, sc, FLD, SC, nodes, n_run)
    else:
        _eq17_forces(PP, sc, FLD, SC, nodes, n_run)
    _pair_forces(FLD, half, paired, 3 if energy else 1, n_run, symmetric)
    for i in range(n):
        if symmetric and i % 2 == 1:
            for l in range(n_run):
                SC[3, l] = 0.0
        else:
            # a paired node's row j holds the pair's sum, row half + j its difference: a
            # symmetric mode takes the sum on phi_m and phi_m'' and the difference on phi_m'
            even = i % 2 == 0
            r0 = 0 if even else half
            r1 = half if even else 0
            w = T[4, i, 0]
            j0 = r0 if mirrors > 0 else 0
            for l in range(n_run):
                SC[3, l] = w * FLD[0, j0, l]
            for j in range(1, half):
                w = T[4, i, j]
                r = r0 + j if j < mirrors else j
                for l in range(n_run):
                    SC[3, l] += w * FLD[0, r, l]
            if energy:                  # the weak form's parts, on phi_m' and phi_m''
                for j in range(half):
                    w1 = T[5, i, j]
                    w2 = T[6, i, j]
                    p1 = r1 + j if j < mirrors else j
                    p2 = r0 + j if j < mirrors else j
                    for l in range(n_run):
                        SC[3, l] += w1 * FLD[1, p1, l] + w2 * FLD[2, p2, l]
        _mode_acceleration(K, s, i, X, PP, SC, n, n_run, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def _mode_acceleration(K, s, i, X, PP, SC, n, n_run, base):
    """K[s, i] = q_i' and K[s, n + i] = q_i'' of every lane from mode i's projected force
    SC[3] (per unit rho A) and, with a base, the base acceleration SC[2]."""
    for l in range(n_run):
        acc = (PP[P_STIFF * n + i, l] * X[i, l] + PP[P_DAMPING * n + i, l] * X[n + i, l]
               - SC[3, l])
        if base is not None:
            acc += PP[P_FORCE * n + i, l] * SC[2, l]
        K[s, i, l] = X[n + i, l]
        K[s, n + i, l] = acc


@nb.njit(cache=True, nogil=True, error_model="numpy")
def scratch(pp, n_modes, basis):
    """What the one-state right-hand side (`derivative`) reads and writes besides its state:
    a copy of the prepared row pp, its projections' accumulator (N), the basis' coupling
    (basis[COUPLING]) and polynomial (basis[POLYNOMIAL]), and the polynomial's monomials'
    scratch."""
    return (pp.copy(), np.empty(n_modes), basis[COUPLING], basis[POLYNOMIAL],
            _monomials_scratch(basis[POLYNOMIAL]))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _monomials_scratch(PY):
    """Room for polynomial PY's monomials (none for an empty one)."""
    return np.empty(PY[0].shape[0])


@nb.njit(cache=True, nogil=True, error_model="numpy")
def row_scratch(row, basis):
    """`scratch` for raw row `row` (columns above) of a span of `basis` (the tuple the kernels
    take): the row prepared (`prepare`), ready for `derivative(t, y, dy, S, N, basis[TABLES],
    base)`."""
    n = basis_modes(basis)
    pp = np.empty(prepared_size(n))
    prepare(row, n, pp, basis[RATIOS])
    return scratch(pp, n, basis)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def _polynomial_state(y, PY, MB, n, linear, membrane, beta_b, beta_q, energy, symmetric, F):
    """F[i] = the force on mode i of one state y (per unit rho A) from the basis' polynomial
    (POLYNOMIAL; `_polynomial_lanes` with one lane, the same sums in the same order): MB its
    monomials' scratch; energy 1 (the span's energy's bending terms) or 0 (Eq.17's);
    symmetric: the antisymmetric modes at rest, their monomials 0 and unread
    (`_polynomial_mode`)."""
    program = PY[0]
    starts = PY[1]
    mono = PY[2]
    coef = PY[3]
    for k in range(n):
        MB[k] = y[k]
    for k in range(n, PY[5] if symmetric else program.shape[0]):
        MB[k] = MB[program[k, 0]] * MB[program[k, 1]]
    for i in range(n):
        f = 0.0
        if symmetric and i % 2 == 1:
            F[i] = f
            continue
        for g in range(N_GROUPS):
            lo = starts[i, g]
            hi = PY[4][i, g] if symmetric else starts[i, g + 1]
            if lo == hi:
                continue
            scale = _group_scale(g, linear, membrane, beta_b, beta_q, energy)
            if scale == 0.0:
                continue
            acc = coef[lo] * MB[mono[lo]]
            for t in range(lo + 1, hi):
                acc += coef[t] * MB[mono[t]]
            f += scale * acc
        F[i] = f


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, inline="always")
def _node_forces(a, b, c, d, linear, membrane, beta_b, beta_q, energy):
    """One node's forces from its fields (a, b, c, d): (on phi_m, on phi_m', on phi_m''), the
    bending terms from the span's energy (energy True: c and d unread) or Eq.17's."""
    g0 = _axial(a, b, linear, membrane)
    if energy:
        g1, g2 = _energy_bending(a, b, beta_b, beta_q)
        return g0, g1, g2
    return g0 + _eq17_bending(a, b, c, d, beta_b, beta_q), 0.0, 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, inline="always")
def _state_fields(T, f, j, y, n, split, symmetric):
    """Fields f and f + 1 (0: a and b, 2: c and d) of one state at column j of the folded
    tables T, as (e_f, o_f, e_f+1, o_f+1): split (folded), the antisymmetric modes' share
    (odd i, o) apart from the symmetric ones' (even i, e), else all in e; symmetric, the
    antisymmetric modes skipped (at rest)."""
    e0 = 0.0
    o0 = 0.0
    e1 = 0.0
    o1 = 0.0
    if not split:
        for i in range(n):
            e0 += T[f, i, j] * y[i]
            e1 += T[f + 1, i, j] * y[i]
        return e0, o0, e1, o1
    for i in range(0, n, 2):
        e0 += T[f, i, j] * y[i]
        e1 += T[f + 1, i, j] * y[i]
    if not symmetric:
        for i in range(1, n, 2):
            o0 += T[f, i, j] * y[i]
            o1 += T[f + 1, i, j] * y[i]
    return e0, o0, e1, o1


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False,
         forceinline=True)
def derivative(t, y, dy, S, n_modes, T, base):
    """dy = f(t, y) for one state y = (q_1..q_N, q_1'..q_N') (m, m/s), dy = (q', q'') (m/s,
    m/s^2): `lanes_derivative`'s right-hand side for the scalar driver, libm's cos and sin,
    from the same node-level pieces (`_axial`, `_energy_bending`, `_eq17_bending`) in one
    state's loop order: each node's fields summed over the modes in registers and its forces
    projected on every mode at once (with one lane, the lanes' loops cost more in overhead
    than in arithmetic: 2-3x this), or, where the basis has one, its polynomial
    (`_polynomial_state`). It agrees with `lanes_derivative` to round-off. S: `scratch`
    (prepared row, N, the basis) or `row_scratch`; T: the basis' tables (basis[TABLES],
    folded about midspan: the fields of a paired node and its mirror from one pass over the
    modes, each mode projecting both nodes' forces at once); y and dy distinct."""
    pp, F, CP, PY, MB = S               # F: the projections, mode by mode
    n = n_modes
    sc = 3 * n
    x = pp[sc + S_OMEGA] * t + pp[sc + S_LOAD_PHASE]
    cw = math.cos(x)
    linear = pp[sc + S_LOAD_MEAN] + pp[sc + S_LOAD_COS] * cw
    membrane = pp[sc + S_BETA_M0] + pp[sc + S_BETA_M1] * cw
    tension = pp[sc + S_TENSION]
    if tension != 0.0:                  # the uniform tension N = k_s e, e = int w_x^2 / 2
        e = 0.0
        for i in range(n):
            for k in range(n):
                a_ik = CP[i, k]
                if a_ik != 0.0:
                    e += a_ik * y[i] * y[k]
        linear -= tension * e
    beta_b = pp[sc + S_BETA_B]
    beta_q = pp[sc + S_BETA_Q]
    energy = pp[sc + S_ENERGY] != 0.0
    # every antisymmetric mode at rest (`_symmetric_lanes`, one lane): skipped, the same bits
    paired = folded_pairs(T)
    symmetric = paired > 0
    for i in range(1, n, 2):
        symmetric = symmetric and y[i] == 0.0
    # the polynomial's force (the nodes' loop then runs over none), or F zeroed for the nodes
    # (no call where there is no polynomial: a call per evaluation cost a pinned span 1.28x)
    if has_polynomial(PY):
        _polynomial_state(y, PY, MB, n, linear, membrane, beta_b, beta_q, pp[sc + S_ENERGY],
                          symmetric, F)
        nodes = 0
    else:
        for i in range(n):
            F[i] = 0.0
        nodes = T.shape[2]
    # A paired node sums its symmetric modes (e) and antisymmetric ones (o) apart: the mirror
    # node's fields are (-1)^order (e - o), and each mode projects both nodes' forces at once,
    # their sum or difference. Where every antisymmetric mode is at rest the mirror nodes'
    # forces are the nodes' own, mirrored, and the antisymmetric modes' are 0.
    for j in range(nodes):
        pair = j < paired
        ae, ao, be, bo = _state_fields(T, 0, j, y, n, pair, symmetric)
        ce = 0.0
        co = 0.0
        de = 0.0
        do = 0.0
        if not energy:
            ce, co, de, do = _state_fields(T, 2, j, y, n, pair, symmetric)
        g0, g1, g2 = _node_forces(ae + ao, be + bo, ce + co, de + do, linear, membrane,
                                  beta_b, beta_q, energy)
        h0 = h1 = h2 = 0.0              # an antisymmetric mode's share of a pair
        if pair and symmetric:          # the mirror's forces: the node's own, mirrored
            g0 += g0
            g1 += g1
            g2 += g2
        elif pair:                      # the pair's sums and differences
            h0, h1, h2 = _node_forces(ao - ae, be - bo, co - ce, de - do, linear, membrane,
                                      beta_b, beta_q, energy)
            g0, h0 = g0 + h0, g0 - h0
            g1, h1 = g1 - h1, g1 + h1
            g2, h2 = g2 + h2, g2 - h2
        # the symmetric modes (every mode where the tables are not folded), then the others
        for i in range(0, n, 2 if pair else 1):
            if energy:
                F[i] += T[4, i, j] * g0 + T[5, i, j] * g1 + T[6, i, j] * g2
            else:
                F[i] += T[4, i, j] * g0
        if pair and not symmetric:
            for i in range(1, n, 2):
                if energy:
                    F[i] += T[4, i, j] * h0 + T[5, i, j] * h1 + T[6, i, j] * h2
                else:
                    F[i] += T[4, i, j] * h0
    ab = base_acceleration(t, pp, n, base) if base is not None else 0.0
    for i in range(n):
        acc = pp[P_STIFF * n + i] * y[i] + pp[P_DAMPING * n + i] * y[n + i] - F[i]
        if base is not None:
            acc += pp[P_FORCE * n + i] * ab
        dy[i] = y[n + i]
        dy[n + i] = acc


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def derivative_call(t, y, dy, S, n_modes, T, base):
    """`derivative` as a function call of its own, for the callers that evaluate it a few times
    a point (the first step's guess, the start, the rest test): `derivative` is inlined where
    it is called (forceinline: a call passes about 100 words of arrays an evaluation; inlined
    into the scalar driver's step, a pinned 3-mode span runs 1.1x faster), and one copy here
    serves all of these, so that a driver compiles two copies, not six."""
    derivative(t, y, dy, S, n_modes, T, base)
