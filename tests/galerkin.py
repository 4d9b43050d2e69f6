"""An independent N-mode Galerkin reference for the transverse span (tests only).

Written from the equation of motion (the paper's Eq.17, membrane term generalised with alpha,
P > 0 compression, both clamps accelerating as a_b(t), w relative to the clamps):

    rho A (w_tt + a_b) + P w_xx + EI w_xxxx - 3 EI w_xx^3 - 11 EI w_xx w_xxx w_x
        - (2 P + 4 alpha EA) w_xx w_x^2 - 3 EI w_xxxx w_x^2 + (21/2) EI w_xx^3 w_x^2 = 0,

pinned at x = 0 and x = l, with w = sum_{n=1..N} q_n(t) sin(n k x), k = pi / l. Projected on
sin(m k x) and divided by rho A l / 2, with modal viscous damping 2 zeta w_m q_m':

    q_m'' + 2 zeta w_m q_m' + F_m(q, P) = -Gamma_m a_b(t),
    F_m = (2 / (rho A l)) int_0^l R(x) sin(m k x) dx,   R = everything above but rho A (w_tt + a_b),
    w_m = m^2 w1 (unloaded), w1^2 = (EI / rho A) k^4, Gamma_m = 4 / (m pi) (odd m), 0 (even m).

The projections F_m are computed at run time by quadrature of R, not from coefficient
tensors: the midpoint rule with M nodes x_j = (j + 1/2) l / M on [0, l]. That rule is exact
(to round-off) here, not merely accurate: every term of R is odd about x = 0 and 2l-periodic
(w, w_xx, w_xxxx are odd, w_x, w_xxx even, and each term has an odd number of odd factors), so
R sin(m k x) is even and 2l-periodic, and the midpoint rule on [0, l] is the 2M-point uniform
rule over the whole period [0, 2l], exact for trigonometric polynomials of degree < 2M. R
sin(m k x) has degree <= 6N (five factors of degree N, times sin(m k x)); M = 8N + 8 nodes
(default) leaves a wide margin. Checked in tests/test_modes.py against Gauss-Legendre.

Units: SI throughout; q_n in m, t in s, forces per unit modal mass in m s-2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.integrate import OdeSolution, solve_ivp
from scipy.optimize import brentq


@dataclass(frozen=True)
class Cable:
    """A span's data (SI): E (Pa), rho (kg m-3), A (m2), I (m4), l (m), alpha, zeta."""
    youngs_modulus: float = 1.1e11
    density: float = 8900.0
    area: float = 6e-6
    inertia: float = 2.865e-12
    length: float = 0.5
    membrane: float = 0.375
    damping_ratio: float = 0.0

    @property
    def k(self) -> float:
        """pi / l (m-1)."""
        return math.pi / self.length

    @property
    def w1(self) -> float:
        """First natural frequency of the unloaded span, sqrt(EI / rho A) k^2 (rad/s)."""
        return math.sqrt(self.youngs_modulus * self.inertia
                         / (self.density * self.area)) * self.k ** 2


def participation(n_modes: int) -> np.ndarray:
    """Gamma_n = (2 / l) int_0^l sin(n k x) dx = 4 / (n pi) for odd n, 0 for even n."""
    n = np.arange(1, n_modes + 1)
    return np.where(n % 2 == 1, 4.0 / (n * math.pi), 0.0)


class Projection:
    """F(q, P) of the module docstring, by the midpoint rule with `nodes` nodes (default
    8N + 8), or by Gauss-Legendre when `gauss` is True (for checking the rule's exactness)."""

    def __init__(self, cable: Cable, n_modes: int, nodes: int | None = None,
                 gauss: bool = False) -> None:
        self.cable = cable
        self.n_modes = n_modes
        l, k = cable.length, cable.k
        m = nodes if nodes is not None else 8 * n_modes + 8
        if gauss:
            s, weights = np.polynomial.legendre.leggauss(m)
            x = 0.5 * l * (s + 1.0)
            weights = 0.5 * l * weights
        else:
            x = (np.arange(m) + 0.5) * l / m
            weights = np.full(m, l / m)
        n = np.arange(1, n_modes + 1, dtype=float)[:, None]
        sin = np.sin(n * k * x[None, :])
        cos = np.cos(n * k * x[None, :])
        # derivative matrices: w_x = q @ d1 etc., shape (N, M)
        self.d1 = n * k * cos
        self.d2 = -(n * k) ** 2 * sin
        self.d3 = -(n * k) ** 3 * cos
        self.d4 = (n * k) ** 4 * sin
        rho_a = cable.density * cable.area
        # F_m = sum_j R_j (2 / (rho A l)) weight_j sin(m k x_j)
        self.project = (2.0 / (rho_a * l)) * (sin * weights[None, :]).T      # (M, N)
        self._m = m
        self._derivatives = np.concatenate((self.d1, self.d2, self.d3, self.d4), axis=1)

    def _at_nodes(self, q: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(linear, cubic, quintic) parts of R (N m-1) at the nodes, for modal coordinates q
        (m; (N,) or (..., N)) and end load p (N): the four derivatives w_x .. w_xxxx from one
        product with the stacked matrices."""
        c = self.cable
        ei = c.youngs_modulus * c.inertia
        ea = c.youngs_modulus * c.area
        m = self._m
        w = np.asarray(q, dtype=float) @ self._derivatives
        w1, w2, w3, w4 = w[..., :m], w[..., m:2 * m], w[..., 2 * m:3 * m], w[..., 3 * m:]
        linear = p * w2 + ei * w4
        cubic = (-3.0 * ei * w2 ** 3 - 11.0 * ei * w2 * w3 * w1
                 - (2.0 * p + 4.0 * c.membrane * ea) * w2 * w1 ** 2 - 3.0 * ei * w4 * w1 ** 2)
        quintic = 10.5 * ei * w2 ** 3 * w1 ** 2
        return linear, cubic, quintic

    def parts(self, q: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(linear, cubic, quintic) parts of F (m s-2) at modal coordinates q (m) and end load
        p (N, compression > 0); q may be (N,) or (..., N)."""
        return tuple(part @ self.project for part in self._at_nodes(q, p))

    def force(self, q: np.ndarray, p: float) -> np.ndarray:
        """F(q, P) (m s-2) at modal coordinates q (m; (N,) or (..., N)): the sum of `parts`,
        summed at the nodes before one projection (a reference's right-hand side)."""
        linear, cubic, quintic = self._at_nodes(q, p)
        return (linear + cubic + quintic) @ self.project


def load_function(amplitude: float, omega: float, kind: str = "harmonic") -> Callable:
    """P(t) (N): P0 cos(W t) (kind "harmonic", W in rad/s) or P0 (kind "constant")."""
    if kind == "constant":
        return lambda t: amplitude
    return lambda t: amplitude * math.cos(omega * t)


def galerkin_rhs(cable: Cable, n_modes: int, load_amplitude: float = 0.0,
                 load_omega: float = 0.0, load_type: str = "harmonic",
                 base_acceleration: float = 0.0, base_frequency: float = 0.0,
                 nodes: int | None = None) -> Callable[[float, np.ndarray], np.ndarray]:
    """SciPy right-hand side f(t, y), y = (q_1..q_N (m), q_1'..q_N' (m/s)), of the projected
    equations: load P0 (N) at W = load_omega (rad/s) or constant, base acceleration
    a_b = A sin(2 pi f t) (A in m s-2, f = base_frequency in Hz)."""
    proj = Projection(cable, n_modes, nodes)
    n = np.arange(1, n_modes + 1)
    damping = 2.0 * cable.damping_ratio * cable.w1 * n ** 2
    forcing = participation(n_modes) * base_acceleration
    base_omega = 2.0 * math.pi * base_frequency
    load = load_function(load_amplitude, load_omega, load_type)

    def f(t: float, y: np.ndarray) -> np.ndarray:
        out = np.empty(2 * n_modes)
        v = y[n_modes:]
        out[:n_modes] = v
        out[n_modes:] = -damping * v - proj.force(y[:n_modes], load(t)) \
            - forcing * math.sin(base_omega * t)
        return out
    return f


def integrate(cable: Cable, n_modes: int, y0, t_end: float, scale: float,
              rtol: float = 1e-11, **rhs_args) -> OdeSolution:
    """SciPy DOP853 from y0 = (q(0) (m), q'(0) (m/s)) over [0, t_end] (s) at rtol, atol
    1e-3 rtol x scale for q (scale: the response's size, m) and that x N^2 w1 for q'; returns
    the dense output (an OdeSolution). rhs_args go to galerkin_rhs."""
    f = galerkin_rhs(cable, n_modes, **rhs_args)
    atol_q = 1e-3 * rtol * scale
    atol = np.concatenate((np.full(n_modes, atol_q),
                           np.full(n_modes, atol_q * n_modes ** 2 * cable.w1)))
    sol = solve_ivp(f, (0.0, t_end), np.asarray(y0, dtype=float), method="DOP853",
                    rtol=rtol, atol=atol, dense_output=True)
    assert sol.success, sol.message
    return sol.sol


def _tail_max(values: Callable, rates: Callable, t: np.ndarray) -> float:
    """max |values(t)| over [t[0], t[-1]]: on the grid t, then at every sign change of rates
    whose grid value is within 1 % of the grid's largest, located by brentq."""
    x, r = values(t), rates(t)
    peak = float(np.max(np.abs(x)))
    near = np.maximum(np.abs(x[:-1]), np.abs(x[1:])) >= 0.99 * peak
    for i in np.nonzero(near & (np.signbit(r[:-1]) != np.signbit(r[1:])))[0]:
        root = brentq(lambda s: float(rates(s)), t[i], t[i + 1], xtol=1e-15, rtol=1e-15)
        peak = max(peak, abs(float(values(root))))
    return peak


def tail_maxima(sol: OdeSolution, n_modes: int, t_end: float, tail: float = 0.5,
                fastest_hz: float = 1.0,
                samples_per_period: int = 64) -> tuple[np.ndarray, float]:
    """(max |q_n| per mode (m), max |sum_n q_n sin(n pi / 2)| (m), the midspan deflection) over
    the tail window [t_end (1 - tail), t_end] (s) of a dense output: sampled at the step ends
    and samples_per_period points per period of the fastest motion (fastest_hz, Hz), each crest
    then located at the sign change of the dense output's velocity (brentq)."""
    t0 = t_end * (1.0 - tail)
    grid = np.linspace(t0, t_end, int(samples_per_period * fastest_hz * (t_end - t0)) + 2)
    ends = np.asarray(sol.ts)
    t = np.unique(np.concatenate((grid, ends[(ends > t0) & (ends < t_end)])))
    modal = np.empty(n_modes)
    for i in range(n_modes):
        modal[i] = _tail_max(lambda s, i=i: sol(s)[i], lambda s, i=i: sol(s)[n_modes + i], t)
    shape = np.sin(np.arange(1, n_modes + 1) * math.pi / 2.0)
    shape[np.abs(shape) < 0.5] = 0.0                       # exactly 0, +-1
    midspan = _tail_max(lambda s: shape @ sol(s)[:n_modes],
                        lambda s: shape @ sol(s)[n_modes:], t)
    return modal, midspan


def span_tail_maximum(sol: OdeSolution, n_modes: int, t_end: float, tail: float = 0.5,
                      fastest_hz: float = 1.0, samples_per_period: int = 64,
                      stations: int = 801) -> float:
    """max |w(x, t)| = |sum_n q_n(t) sin(n pi x / l)| (m) over the span and the tail window
    [t_end (1 - tail), t_end] (s) of a dense output: `span_tail_argmax`'s value."""
    return span_tail_argmax(sol, n_modes, t_end, tail, fastest_hz, samples_per_period,
                            stations)[0]


def span_tail_argmax(sol: OdeSolution, n_modes: int, t_end: float, tail: float = 0.5,
                     fastest_hz: float = 1.0, samples_per_period: int = 64,
                     stations: int = 801) -> tuple[float, float]:
    """(max |w(x, t)| (m), its place x / l) over the span and the tail window
    [t_end (1 - tail), t_end] (s) of a dense output, w = sum_n q_n(t) sin(n pi x / l), by brute
    force: on a grid of samples_per_period instants per period of the fastest motion
    (fastest_hz, Hz) plus the step ends, times `stations` equally spaced stations, then refined
    from the best few grid points by Nelder-Mead in (t, x), kept inside the window and the
    span."""
    from scipy.optimize import minimize
    t0 = t_end * (1.0 - tail)
    grid = np.linspace(t0, t_end, int(samples_per_period * fastest_hz * (t_end - t0)) + 2)
    ends = np.asarray(sol.ts)
    t = np.unique(np.concatenate((grid, ends[(ends > t0) & (ends < t_end)])))
    x = np.linspace(0.0, 1.0, stations)
    n = np.arange(1, n_modes + 1)
    shapes = np.sin(np.outer(n, x) * math.pi)                 # (N, stations)
    w = np.abs(sol(t)[:n_modes].T @ shapes)                   # (times, stations)

    def deflection(z: np.ndarray) -> float:
        s = min(max(z[0], t0), t_end)
        xi = min(max(z[1], 0.0), 1.0)
        return -abs(float(sol(s)[:n_modes] @ np.sin(n * math.pi * xi)))

    i, j = np.unravel_index(int(np.argmax(w)), w.shape)
    best, place = float(w[i, j]), float(x[j])
    for flat in np.argsort(w, axis=None)[-5:]:
        i, j = np.unravel_index(flat, w.shape)
        found = minimize(deflection, np.array([t[i], x[j]]), method="Nelder-Mead",
                         options={"xatol": 1e-13, "fatol": 1e-18, "maxiter": 4000})
        if -float(found.fun) > best:
            best, place = -float(found.fun), min(max(float(found.x[1]), 0.0), 1.0)
    return best, place


def absolute_tail_maximum(sol: OdeSolution, f: Callable, n_modes: int, base_acceleration: float,
                          base_frequency: float, t_end: float, tail: float = 0.5,
                          fastest_hz: float = 1.0, samples_per_period: int = 64) -> float:
    """max |w''(l/2, t) + a_b(t)| (m/s^2), the absolute midspan acceleration, over the tail
    window [t_end (1 - tail), t_end] (s) of a dense output: w'' = sum_n q_n'' sin(n pi / 2)
    with q'' = f(t, y(t)) (galerkin_rhs: the equations themselves on the dense state), a_b =
    A sin(2 pi f t); on a grid of samples_per_period points per period of the fastest motion,
    each grid point within 1 % of the largest refined by a bounded scalar search between its
    neighbours."""
    from scipy.optimize import minimize_scalar
    shape = np.sin(np.arange(1, n_modes + 1) * math.pi / 2.0)
    shape[np.abs(shape) < 0.5] = 0.0
    omega = 2.0 * math.pi * base_frequency

    def absolute(s: float) -> float:
        return abs(float(shape @ f(s, sol(s))[n_modes:]) + base_acceleration * math.sin(omega * s))

    t0 = t_end * (1.0 - tail)
    t = np.linspace(t0, t_end, int(samples_per_period * fastest_hz * (t_end - t0)) + 2)
    a = np.array([absolute(s) for s in t])
    peak = float(np.max(a))
    for i in np.nonzero(a >= 0.99 * peak)[0]:
        lo, hi = t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]
        found = minimize_scalar(lambda s: -absolute(s), bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-14})
        peak = max(peak, -float(found.fun))
    return peak


# --- any end conditions: the span's own modes as callables ---------------------------------

def clamped_shapes(n_modes: int, length: float) -> list[Callable[[np.ndarray, int], np.ndarray]]:
    """The clamped-clamped span's modes phi_n(x) = cosh(b x) - cos(b x) - s_n (sinh(b x) -
    sin(b x)), s_n = (cosh b l - cos b l) / (sinh b l - sin b l), cos(b l) cosh(b l) = 1 (the
    textbook form, docs/model.md sec. 10.1), as functions phi(x, k) giving the k-th derivative
    (1/m^k) at x (m); b_n l by brentq near (2n + 1) pi / 2. Written from the textbook, not from
    sweep.models.basis."""
    shapes = []
    for n in range(1, n_modes + 1):
        guess = (2 * n + 1) * math.pi / 2.0
        bl = brentq(lambda z: math.cos(z) * math.cosh(z) - 1.0, guess - 0.3, guess + 0.3,
                    xtol=1e-15)
        b = bl / length
        s = (math.cosh(bl) - math.cos(bl)) / (math.sinh(bl) - math.sin(bl))

        def phi(x, k, b=b, s=s):
            z = b * np.asarray(x, dtype=float)
            hyper = [np.cosh(z), np.sinh(z)][k % 2] - s * [np.sinh(z), np.cosh(z)][k % 2]
            trig = [np.cos(z), -np.sin(z), -np.cos(z), np.sin(z)][k % 4] \
                - s * [np.sin(z), np.cos(z), -np.sin(z), -np.cos(z)][k % 4]
            return b ** k * (hyper - trig)
        shapes.append(phi)
    return shapes


def sine_shapes(n_modes: int, length: float) -> list[Callable[[np.ndarray, int], np.ndarray]]:
    """The pinned span's modes sin(n pi x / l) as clamped_shapes gives its own: phi(x, k), the
    k-th derivative (1/m^k) at x (m)."""
    def make(n: int):
        b = n * math.pi / length

        def phi(x, k):
            z = b * np.asarray(x, dtype=float)
            return b ** k * [np.sin(z), np.cos(z), -np.sin(z), -np.cos(z)][k % 4]
        return phi
    return [make(n) for n in range(1, n_modes + 1)]


def bending_energy(ei: float, w1: np.ndarray, w2: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """U_b = (EI / 2) int w_xx^2 (1 - 3 w_x^2 + 6 w_x^4) dx (J) from the slope w1 and curvature
    w2 (1/m) at quadrature nodes with `weights` (m), the last axis: the bending energy of the
    exact curvature kappa = w_xx / (1 + w_x^2)^(3/2), kappa^2 = w_xx^2 (1 + w_x^2)^-3, to the
    quintic order of its forces (the series' next term, -10 w_x^6, is left out)."""
    return 0.5 * ei * (w2 ** 2 * (1.0 - 3.0 * w1 ** 2 + 6.0 * w1 ** 4)) @ weights


def reaction_left_out(shapes: list, length: float, nodes: int = 96) -> float:
    """r = 1/2 - sum_n Gamma_n int (l - x) phi_n dx / l^2 (Gamma_n = int phi_n / int
    phi_n^2, Gauss-Legendre on `nodes` nodes): the share of a uniform load's reaction at the
    clamp x = 0 (statically 1/2 of the load) that the modes `shapes` do not carry. The
    mode-acceleration correction carries it there: V(0) gains -rho A l r a_b(t), V(l) the
    opposite."""
    g, weights = np.polynomial.legendre.leggauss(nodes)
    x, weights = 0.5 * length * (g + 1.0), 0.5 * length * weights
    phi = np.array([s(x, 0) for s in shapes])
    gamma = (phi @ weights) / ((phi ** 2) @ weights)
    return 0.5 - float(gamma @ ((phi * (length - x)) @ weights)) / length ** 2


def axial_reaction(shapes: list, length: float, nodes: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """(e_0, e_1) (1/m, per unit q_n): the reaction of the axial load (N - P) w_xx at x = 0
    and x = l per unit (N - P) and q_n, as the span's equilibrium gives it with the part of
    the load the modes leave out carried statically: e_0 = (1/l) sum_m A_nm int (l - x) phi_m
    / int phi_m^2, e_1 = -(1/l) sum_m A_nm int x phi_m / int phi_m^2, A_nm = int phi_n'
    phi_m' dx (Gauss-Legendre on `nodes` nodes). For sines these are phi_n'(0) and
    phi_n'(l); at a clamped end, where phi_n' = 0, they are not."""
    g, weights = np.polynomial.legendre.leggauss(nodes)
    x, weights = 0.5 * length * (g + 1.0), 0.5 * length * weights
    phi = np.array([s(x, 0) for s in shapes])
    slope = np.array([s(x, 1) for s in shapes])
    mass = (phi ** 2) @ weights
    axial = (slope * weights) @ slope.T
    left = (phi * (length - x)) @ weights / mass
    right = (phi * x) @ weights / mass
    return axial @ left / length, -(axial @ right) / length


def shapes_rhs(cable: Cable, shapes: list, omegas: np.ndarray, base_acceleration: float = 0.0,
               base_frequency: float = 0.0, nodes: int = 96,
               tension_stiffness: float | None = None) -> Callable:
    """SciPy right-hand side of the Galerkin equations on the span's own linear modes `shapes`
    (clamped_shapes' or sine_shapes' callables; omegas: their natural angular frequencies,
    rad/s), projected on each mode by Gauss-Legendre and divided by rho A int phi_n^2; modal
    damping 2 zeta w_n; base participation int phi_n / int phi_n^2; a_b = A sin(2 pi f t).

    tension_stiffness None: Eq.17's residual R (module docstring, no end load), the paper's
    local membrane term and bending terms, projected on phi_m. tension_stiffness k_s (N/m): the
    stretching is the uniform tension N = k_s e, e = (1/2) int w_x^2 dx (R gains - N w_xx, on
    phi_m), and the bending nonlinearity is the weak form of `bending_energy`'s U_b, the
    engine's rule for a span without model.membrane: Q_m = EI int [w_xx (-3 w_x^2 + 6 w_x^4)
    phi_m'' + w_xx^2 (-3 w_x + 12 w_x^3) phi_m'] dx (its linear part EI w_xxxx stays on
    phi_m: for the span's own modes that is the stiffness, springs at the ends included)."""
    n_modes = len(shapes)
    l = cable.length
    g, weights = np.polynomial.legendre.leggauss(nodes)
    x, weights = 0.5 * l * (g + 1.0), 0.5 * l * weights
    d = [np.array([phi(x, k) for phi in shapes]) for k in range(5)]     # (N, M) each
    mass = (d[0] ** 2) @ weights
    gamma = (d[0] @ weights) / mass
    project = [(d[k] * weights).T / (cable.density * cable.area * mass) for k in range(3)]
    ei, ea = cable.youngs_modulus * cable.inertia, cable.youngs_modulus * cable.area
    damping = 2.0 * cable.damping_ratio * np.asarray(omegas)
    omega_b = 2.0 * math.pi * base_frequency

    def f(t: float, y: np.ndarray) -> np.ndarray:
        q, v = y[:n_modes], y[n_modes:]
        w1, w2, w3, w4 = (q @ d[k] for k in range(1, 5))
        if tension_stiffness is None:
            r = (ei * w4 - 3.0 * ei * w2 ** 3 - 11.0 * ei * w2 * w3 * w1
                 - 4.0 * cable.membrane * ea * w2 * w1 ** 2
                 - 3.0 * ei * w4 * w1 ** 2 + 10.5 * ei * w2 ** 3 * w1 ** 2)
            force = r @ project[0]
        else:
            r = ei * w4 - tension_stiffness * 0.5 * (w1 ** 2 @ weights) * w2
            force = (r @ project[0] + ei * w2 ** 2 * (-3.0 * w1 + 12.0 * w1 ** 3) @ project[1]
                     + ei * w2 * (-3.0 * w1 ** 2 + 6.0 * w1 ** 4) @ project[2])
        a = -damping * v - force - gamma * base_acceleration * math.sin(omega_b * t)
        return np.concatenate((v, a))
    return f
