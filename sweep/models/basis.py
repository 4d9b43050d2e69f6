"""Mode shapes of a span: the Galerkin basis of the multi-mode System (docs/model.md secs. 7, 10).

A Basis holds N mode shapes phi_n(s) of the span, s = x / l in [0, 1], each in beam-function
form

    phi_n(s) = A cos(beta s) + B sin(beta s) + C exp(-beta s) + D exp(-beta (1 - s)),

(beta = b_n l; pinned sines: beta = n pi, B = 1, the rest 0; clamped and elastic ends add the
two decaying exponentials, the numerically stable form of the cosh/sinh beam functions), with
what the System's right-hand side and its Observer need of them, all dimensionless:

- the linear natural frequencies w_n / w_p and base participations Gamma_n / (4 / pi), both
  against the pinned span's first mode (w_p = (pi / l)^2 sqrt(EI / rho A), Gamma = 4 / pi), so
  a point's row holds the cable's data and the basis its shapes' ratios (the modes are the
  span's own linear modes: the mass and bending stiffness are diagonal; for beam functions
  w_n / w_p = (beta_n / pi)^2);
- a quadrature rule on (0, 1) exact (to round-off) for the projections of the nonlinear and
  axial-load terms, and the shapes' derivatives at its nodes: the kernel evaluates the
  deflection's fields there and projects on each mode (kernels/modes.py), so an axial load or a
  stretching term that couples the modes (a non-diagonal A_ij = int phi_i' phi_j') needs no
  code of its own;
- each mode's value at midspan (the watched deflection) and at stations along the span (the
  largest deflection over the span, refined on the shapes themselves).

`Basis.kernel_arrays()` is the tuple the kernels take (kernels/modes.py: T, stations, midspan,
ratios, shapes). The kernels know nothing of sines: a new end condition is a new Basis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

SPAN_STATIONS_PER_MODE = 8
"""Stations along the span per mode (8 per half-wave of the highest pinned mode) at which the
largest deflection is first looked for, before Newton's method refines it on the shapes."""


@dataclass(frozen=True, eq=False)
class Basis:
    """N mode shapes of a span and what the multi-mode kernels read of them (module docstring).

    shapes: (N, 5) rows (beta, A, B, C, D) of the beam-function form; frequency_ratio (N,):
    w_n / w_p; participation_ratio (N,): Gamma_n / (4 / pi) (Gamma_n = int phi_n /
    int phi_n^2, uniform base motion); tables (5, N, J): at the J quadrature nodes s_j, phi_n' / pi,
    phi_n'' / pi^2, phi_n''' / pi^3, phi_n'''' / pi^4 (derivatives in s, so these are the
    derivatives in xi = pi s, the kernel's fields' units) and the projection weights
    w_j phi_n(s_j) / int phi_n^2; midspan (N,): phi_n(1/2); stations ((M + 1), N): phi_n at
    s_k = k / M, M = SPAN_STATIONS_PER_MODE N. name: what the modes are; mode_text and
    frequency_text: mode n and its frequency in words, for the dataset's long names."""

    name: str
    shapes: np.ndarray
    frequency_ratio: np.ndarray
    participation_ratio: np.ndarray
    tables: np.ndarray
    midspan: np.ndarray
    stations: np.ndarray
    mode_text: str = "mode shape n"
    frequency_text: str = "(beta_n l / pi)^2 f1 of the pinned span"
    _arrays: tuple = field(default=(), repr=False)

    @property
    def n_modes(self) -> int:
        return int(self.shapes.shape[0])

    def kernel_arrays(self) -> tuple[np.ndarray, ...]:
        """(T, stations, midspan, ratios, shapes): the basis as kernels/modes.py reads it;
        ratios is (2, N): w_n / w_p and Gamma_n / (4 / pi)."""
        if not self._arrays:
            ratios = np.ascontiguousarray(np.stack([self.frequency_ratio,
                                                    self.participation_ratio]), np.float64)
            arrays = tuple(np.ascontiguousarray(a, np.float64) for a in (
                self.tables, self.stations, self.midspan)) + (
                ratios, np.ascontiguousarray(self.shapes, np.float64))
            object.__setattr__(self, "_arrays", arrays)
        return self._arrays


def pinned_sines(n_modes: int) -> Basis:
    """phi_n = sin(n pi s), n = 1..N: the pinned-pinned span (docs/model.md sec. 7), closed
    forms throughout. w_n = n^2 w_p; Gamma_n / (4 / pi) = 1 / n for odd n and 0 for even n;
    the quadrature is the trapezoidal rule on M = 3N + 1 equal intervals (interior nodes
    only: the integrands vanish at the ends), exact for the trigonometric polynomials of
    degree <= 6N the cubic and quintic terms make; phi_n(1/2) = 1, 0, -1, 0, ... exactly."""
    if n_modes < 1:
        raise ValueError(f"n_modes = {n_modes}: at least one mode")
    n = n_modes
    m = 3 * n + 1
    tables = np.empty((5, n, m - 1))
    for i in range(n):
        k = i + 1.0
        for j in range(m - 1):
            xi = (j + 1.0) * math.pi / m
            sn = math.sin(k * xi)
            cn = math.cos(k * xi)
            tables[0, i, j] = k * cn
            tables[1, i, j] = -k * k * sn
            tables[2, i, j] = -k * k * k * cn
            tables[3, i, j] = k * k * k * k * sn
            tables[4, i, j] = 2.0 / m * sn
    orders = np.arange(1, n + 1)
    midspan = np.zeros(n)
    midspan[0::2] = [1.0 if (i // 2) % 2 == 0 else -1.0 for i in range(0, n, 2)]
    stations_m = SPAN_STATIONS_PER_MODE * n
    stations = np.empty((stations_m + 1, n))
    for k in range(stations_m + 1):
        for i in range(n):
            stations[k, i] = math.sin((i + 1.0) * math.pi * k / stations_m)
    shapes = np.zeros((n, 5))
    shapes[:, 0] = orders * math.pi
    shapes[:, 2] = 1.0
    return Basis(name=f"pinned-pinned: sin(n pi x / l), n = 1..{n}", shapes=shapes,
                 frequency_ratio=(orders * orders).astype(float),
                 participation_ratio=np.where(orders % 2 == 1, 1.0 / orders, 0.0),
                 tables=tables, midspan=midspan, stations=stations,
                 mode_text="sin(n pi x/l)", frequency_text="n^2 f1")


def shape_values(shapes: np.ndarray, s: np.ndarray, derivative: int = 0) -> np.ndarray:
    """The mode shapes' derivative of order `derivative` (0..4, in s) at the points s, as an
    array (N, len(s)), from their beam-function rows (beta, A, B, C, D) (module docstring)."""
    s = np.asarray(s, float)
    beta, a, b, c, d = (shapes[:, k][:, None] for k in range(5))
    x = beta * s[None, :]
    cos, sin = np.cos(x), np.sin(x)
    e_left, e_right = np.exp(-x), np.exp(-beta * (1.0 - s[None, :]))
    # d/ds of (cos, sin, e^-bs, e^-b(1-s)) = beta (-sin, cos, -e^-bs, e^-b(1-s))
    trig = [(a * cos + b * sin), (-a * sin + b * cos), -(a * cos + b * sin),
            (a * sin - b * cos)][derivative % 4]
    sign = -1.0 if derivative % 2 else 1.0
    return beta ** derivative * (trig + sign * c * e_left + d * e_right)


def from_shapes(name: str, shapes: np.ndarray, nodes: int,
                mode_text: str = "mode shape n") -> Basis:
    """A Basis of any beam-function shapes (rows (beta, A, B, C, D), each a linear mode of the
    span, w_n / w_p = (beta / pi)^2), its projections by Gauss-Legendre quadrature on `nodes`
    nodes of (0, 1), its participations and masses from the shapes (the same quadrature): the
    general case, for shapes whose integrals the kernel has no closed form of (clamped and
    elastic ends). The nodes must make the projections exact to round-off for the shapes and
    number of modes in use (products of six shapes): the caller checks that, e.g. by doubling
    them."""
    shapes = np.asarray(shapes, float)
    n = shapes.shape[0]
    x, w = np.polynomial.legendre.leggauss(nodes)
    s, w = (x + 1.0) / 2.0, w / 2.0
    phi = shape_values(shapes, s)
    mass = phi ** 2 @ w                                   # int phi_n^2 ds
    gamma = (phi @ w) / mass                              # int phi_n / int phi_n^2
    tables = np.empty((5, n, nodes))
    for order in range(1, 5):
        tables[order - 1] = shape_values(shapes, s, order) / math.pi ** order
    tables[4] = w[None, :] * phi / mass[:, None]
    stations_m = SPAN_STATIONS_PER_MODE * n
    stations = shape_values(shapes, np.arange(stations_m + 1) / stations_m).T
    midspan = shape_values(shapes, np.array([0.5]))[:, 0]
    return Basis(name=name, shapes=shapes, frequency_ratio=(shapes[:, 0] / math.pi) ** 2,
                 participation_ratio=gamma / (4.0 / math.pi),
                 tables=tables, midspan=midspan, stations=np.ascontiguousarray(stations),
                 mode_text=mode_text)


CLAMPED = math.inf
"""The rotational stiffness K = k_t l / EI of a clamped end (no rotation)."""


def _end_conditions(beta: float, stiffness: float) -> np.ndarray:
    """The 4 x 4 matrix whose null vector is (A, B, C, D) of a mode with eigenvalue beta of a
    span with w = 0 and a rotational spring K = `stiffness` (k_t l / EI) at both ends:
    phi(0) = 0, phi''(0) = K phi'(0), phi(1) = 0, phi''(1) = -K phi'(1) (derivatives in s).
    Rows scaled to stay bounded for any beta and K (CLAMPED: phi' = 0 at both ends)."""
    e = math.exp(-beta)
    c, s = math.cos(beta), math.sin(beta)
    spring, slope = ((0.0, 1.0) if stiffness == CLAMPED
                     else (beta / (beta + stiffness), stiffness / (beta + stiffness)))
    return np.array([
        [1.0, 0.0, 1.0, e],                                               # phi(0)
        [-spring, -slope, spring + slope, (spring - slope) * e],          # phi'' - K phi' at 0
        [c, s, e, 1.0],                                                   # phi(1)
        [-spring * c - slope * s, -spring * s + slope * c,                # phi'' + K phi' at 1
         (spring - slope) * e, spring + slope],
    ])


def _eigenvalues(n_modes: int, stiffness: float) -> np.ndarray:
    """The first n_modes roots beta = b_n l of the end conditions' determinant: the n-th lies
    in [n pi, the clamped span's] (pinned at K = 0, clamped as K -> inf), found by a scan of
    that interval and bisection to round-off."""
    def det(beta: float) -> float:
        return float(np.linalg.det(_end_conditions(beta, stiffness)))

    roots = []
    for n in range(1, n_modes + 1):
        if stiffness == 0.0:
            roots.append(n * math.pi)
            continue
        lo, hi = n * math.pi, (n + 0.5) * math.pi + 0.02
        grid = np.linspace(lo, hi, 401)
        values = [det(b) for b in grid]
        found = None
        for k in range(len(grid) - 1):
            if values[k] == 0.0:
                found = grid[k]
                break
            if values[k] * values[k + 1] < 0.0:
                a, b, fa = grid[k], grid[k + 1], values[k]
                for _ in range(200):
                    mid = 0.5 * (a + b)
                    fm = det(mid)
                    if mid in (a, b) or fm == 0.0:
                        break
                    if fa * fm < 0.0:
                        b = mid
                    else:
                        a, fa = mid, fm
                found = 0.5 * (a + b)
                break
        if found is None:
            raise ValueError(f"no eigenvalue of mode {n} found for K = {stiffness}")
        roots.append(found)
    return np.array(roots)


def _normalised(beta: float, stiffness: float) -> np.ndarray:
    """The beam-function row (beta, A, B, C, D) of the mode with eigenvalue beta, scaled to
    max |phi| = 1 over the span, signed so that phi'(0) + phi''(0) / beta > 0 (a sine's
    sign)."""
    _, _, vt = np.linalg.svd(_end_conditions(beta, stiffness))
    row = np.concatenate([[beta], vt[-1]])
    s = np.linspace(0.0, 1.0, 4097)
    phi = shape_values(row[None, :], s)[0]
    k = int(np.argmax(np.abs(phi)))
    x = s[k]
    for _ in range(8):                           # Newton on phi' = 0 at the largest value
        d1 = shape_values(row[None, :], np.array([x]), 1)[0, 0]
        d2 = shape_values(row[None, :], np.array([x]), 2)[0, 0]
        if d2 == 0.0:
            break
        x = min(1.0, max(0.0, x - d1 / d2))
    largest = abs(shape_values(row[None, :], np.array([x]))[0, 0])
    start = shape_values(row[None, :], np.array([0.0]), 1)[0, 0] + \
        shape_values(row[None, :], np.array([0.0]), 2)[0, 0] / beta
    row[1:] *= math.copysign(1.0 / largest, start)
    return row


def quadrature_nodes(n_modes: int) -> int:
    """Gauss-Legendre nodes for a beam-function basis of n_modes modes: its projections (a
    product of six shapes, degree about 6 beta_N / pi in the trigonometric part) exact to
    round-off with a wide margin (tests/test_basis.py doubles them)."""
    return 8 * n_modes + 24


def elastic_ends(n_modes: int, stiffness: float) -> Basis:
    """The span's N lowest modes with a rotational spring of stiffness K = k_t l / EI
    (dimensionless) at both ends and no deflection there (docs/model.md sec. 10): K = 0 is the
    pinned span (use pinned_sines: its closed forms), CLAMPED the clamped one; each mode
    scaled to max |phi| = 1, its projections by Gauss-Legendre quadrature."""
    if n_modes < 1:
        raise ValueError(f"n_modes = {n_modes}: at least one mode")
    if not (stiffness >= 0.0):
        raise ValueError(f"rotational stiffness K = {stiffness}: must be >= 0")
    betas = _eigenvalues(n_modes, stiffness)
    shapes = np.array([_normalised(b, stiffness) for b in betas])
    if stiffness == CLAMPED:
        return from_shapes(f"clamped-clamped beam functions, n = 1..{n_modes}", shapes,
                           quadrature_nodes(n_modes), mode_text="clamped-clamped mode n")
    return from_shapes(f"elastic ends K = k_t l / EI = {stiffness:g}, n = 1..{n_modes}",
                       shapes, quadrature_nodes(n_modes),
                       mode_text=f"mode n of the span with rotational springs K = {stiffness:g}")


def clamped(n_modes: int) -> Basis:
    """The clamped-clamped span's N lowest modes (elastic_ends with K -> inf)."""
    return elastic_ends(n_modes, CLAMPED)
