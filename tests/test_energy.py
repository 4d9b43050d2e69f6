"""An undamped, unforced N-mode span keeps its energy (docs/model.md sec. 7, issue 35).

The span slides in its clamps (clamps.axial_stiffness = 0: no stretching), so the bending
nonlinearity is the only one and, at 5-8 % of the span, large enough to show. Its total energy

    E = (rho A / 2) int w_t^2 dx + (EI / 2) int w_xx^2 (1 - 3 w_x^2 + 6 w_x^4) dx
        + (k_t / 2) (w_x(0)^2 + w_x(l)^2)

(the bending term the exact curvature's energy to quintic order, tests/galerkin.py's
`bending_energy`; the rotational springs' energy for elastic ends) is computed here by
Gauss-Legendre quadrature of the textbook shapes (tests/galerkin.py, test_floquet_coupled.py's
elastic ones), scaled as the engine's (max |phi| = 1, phi > 0 near x = 0), not from
sweep.models.basis. Pinned, clamped and elastic (K = 10) ends, three modes:

1. SciPy DOP853 (rtol 1e-11) on tests/galerkin.py's weak-form right-hand side keeps E to
   1e-9 along its trajectory, and the paper's Eq.17 forms do not (the test can fail);
2. the engine (kernels/modes.py, RK45 at rtol 1e-10) ends where SciPy ends and keeps E at
   the integration tolerance; with model.membrane (Eq.17's bending terms) it does not.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from sweep.execute import modes_chunk
from sweep.kernels import layout as tk
from sweep.kernels import modes as md
from sweep.models import basis, modal

import galerkin as g
from conftest import settings
from test_floquet_coupled import LENGTH, elastic_shapes

STIFFNESS = 10.0                  # K = k_t l / EI of the elastic ends
Q0 = (0.06, 0.02, -0.015)         # initial modal deflections (m) on the 0.8 m span
T_END = 0.3                       # s: about 2 periods of the pinned mode 1, 40 of clamped mode 3
CABLE = g.Cable(length=LENGTH, membrane=0.0)
EI = CABLE.youngs_modulus * CABLE.inertia
RHO_A = CABLE.density * CABLE.area


def _engine_scaled(shapes: list) -> list:
    """The shapes phi(x, k) scaled as the engine's: max |phi| = 1 over the span (on a fine
    grid), phi > 0 just inside x = 0."""
    x = np.linspace(0.0, LENGTH, 40001)
    out = []
    for phi in shapes:
        size = float(np.max(np.abs(phi(x, 0)))) * math.copysign(1.0, float(phi(1e-4, 0)))
        out.append(lambda z, k, phi=phi, size=size: phi(z, k) / size)
    return out


def _elastic(stiffness: float) -> tuple[list, np.ndarray]:
    """test_floquet_coupled's elastic shapes (their b_n l from its scan) with derivatives up to
    the fourth: symmetric cos(b u) + c cosh(b u), c = -cos(b/2) / cosh(b/2), antisymmetric
    sin(b u) + c sinh(b u), c = -sin(b/2) / sinh(b/2), u = x / l - 1/2."""
    _, bl = elastic_shapes(stiffness)
    shapes = []
    for b, odd in zip(bl, (False, True, False)):
        c = -(math.sin(b / 2) / math.sinh(b / 2) if odd else math.cos(b / 2) / math.cosh(b / 2))

        def phi(x, k, b=b, odd=odd, c=c):
            u = b * (np.asarray(x, float) / LENGTH - 0.5)
            trig = [np.sin, np.cos, lambda z: -np.sin(z), lambda z: -np.cos(z)][(k + (0 if odd
                                                                                   else 1)) % 4]
            hyper = [np.sinh, np.cosh][(k + (0 if odd else 1)) % 2]
            return (b / LENGTH) ** k * (trig(u) + c * hyper(u))
        shapes.append(phi)
    return shapes, bl


def _span(ends: str) -> tuple[list, np.ndarray, float]:
    """(the shapes, their w_n (rad/s), K) of the span with `ends`."""
    if ends == "elastic":
        shapes, bl = _elastic(STIFFNESS)
        k = STIFFNESS
    else:
        shapes = (g.sine_shapes if ends == "pinned" else g.clamped_shapes)(3, LENGTH)
        bl = (np.arange(1, 4) * math.pi if ends == "pinned"
              else np.array([4.730040745, 7.853204624, 10.99560784]))
        k = 0.0
    return _engine_scaled(shapes), (np.asarray(bl) / LENGTH) ** 2 * math.sqrt(EI / RHO_A), k


def _energy(shapes: list, stiffness: float):
    """E(y) (J) of a state y = (q (m), q' (m/s)) or states (2N, times), module docstring."""
    x, w = np.polynomial.legendre.leggauss(96)
    x, w = 0.5 * LENGTH * (x + 1.0), 0.5 * LENGTH * w
    d = [np.array([phi(x, k) for phi in shapes]) for k in range(3)]
    mass = (d[0] * w) @ d[0].T
    ends = np.array([phi(np.array([0.0, LENGTH]), 1) for phi in shapes])     # (N, 2)
    k_t = stiffness * EI / LENGTH

    def energy(y: np.ndarray) -> np.ndarray:
        q, v = y[:3], y[3:]
        kinetic = 0.5 * RHO_A * np.einsum("i...,ij,j...->...", v, mass, v)
        slope, curvature = (np.einsum("i...,ij->...j", q, d[k]) for k in (1, 2))
        springs = 0.5 * k_t * (np.einsum("i...,ie->...e", q, ends) ** 2).sum(axis=-1)
        return kinetic + g.bending_energy(EI, slope, curvature, w) + springs
    return energy


def _scipy(f, y0: np.ndarray):
    """SciPy DOP853's dense output from y0 over [0, T_END] at rtol 1e-11."""
    sol = solve_ivp(f, (0.0, T_END), y0, method="DOP853", rtol=1e-11, atol=1e-15,
                    dense_output=True)
    assert sol.success
    return sol


def _engine(ends: str, membrane: float | None) -> np.ndarray:
    """The engine's final state (q, q') after T_END from Q0 at rest, undamped, unforced, the
    clamps sliding; membrane: model.membrane (None: the energy's bending terms)."""
    p = {"youngs_modulus": CABLE.youngs_modulus, "density": CABLE.density,
         "area": CABLE.area, "inertia": CABLE.inertia, "length": LENGTH,
         "damping_ratio": 0.0, "load_amplitude": 0.0, "load_type": "harmonic",
         "frequency": None, "frequency_ratio": 1.0, "coefficients": "consistent",
         "paper_parametric": "printed", "initial_displacement": Q0[0],
         "initial_velocity": 0.0, "divergence_bound": None, "membrane": membrane,
         "clamps_rotation": ends, "clamp_rotational_stiffness": STIFFNESS * EI / LENGTH,
         "clamp_axial_stiffness": None if membrane is not None else 0.0}
    columns = modal.modes_columns(p, modal.oscillator(p), 3, Q0, (0.0,) * 3)
    names = md.FIXED_NAMES + tuple(f"q0_{i}" for i in (1, 2, 3)) + tuple(
        f"v0_{i}" for i in (1, 2, 3))
    row = np.array([[float(columns[n]) for n in names]])
    span = basis.span_basis(basis.end_stiffness(ends, None if ends != "elastic" else
                                                STIFFNESS, 1.0, 1.0), 3)
    s = settings(rtol=1e-10, atol=0.0, t_end=T_END, settling=False)
    s[tk.ATOL_SCALE] = 1e-3
    s[tk.BASE] = 1.0          # the kernel base-excited scenes compile (tests/test_clamps.py),
    out = modes_chunk(row, s, 0, span.kernel_arrays())      # its level 0 here: unforced
    return out["final"][0]


@pytest.mark.parametrize("ends", ["pinned", "clamped", "elastic"])
def test_an_undamped_unforced_span_keeps_its_energy(ends):
    """SciPy on the weak form and the engine keep E (drift below 1e-9 and 1e-8 of E, their
    tolerances); SciPy on the paper's Eq.17 and the engine under model.membrane (Eq.17's
    bending terms, no stretching with alpha = 0) drift by more than 1e-4 of E."""
    shapes, omegas, stiffness = _span(ends)
    energy = _energy(shapes, stiffness)
    y0 = np.concatenate((Q0, np.zeros(3)))
    e0 = float(energy(y0))
    t = np.linspace(0.0, T_END, 601)
    weak = _scipy(g.shapes_rhs(CABLE, shapes, omegas, tension_stiffness=0.0), y0)
    drift = float(np.max(np.abs(energy(weak.sol(t)) - e0))) / e0
    eq17 = _scipy(g.shapes_rhs(CABLE, shapes, omegas), y0)
    drift_eq17 = float(np.max(np.abs(energy(eq17.sol(t)) - e0))) / e0
    assert drift < 1e-9
    assert drift_eq17 > 1e-4

    final = _engine(ends, None)
    np.testing.assert_allclose(final[:3], weak.y[:3, -1], rtol=0, atol=1e-7 * max(Q0))
    assert abs(float(energy(final)) - e0) / e0 < 1e-8
    final_eq17 = _engine(ends, 0.0)
    np.testing.assert_allclose(final_eq17[:3], eq17.y[:3, -1], rtol=0, atol=1e-7 * max(Q0))
    assert abs(float(energy(final_eq17)) - e0) / e0 > 1e-4
