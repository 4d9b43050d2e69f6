"""The Galerkin basis (sweep/models/basis.py): the mode shapes the multi-mode kernels read.

1. pinned sines: the closed-form basis against the shapes and integrals written out here;
2. the general basis (beam-function shapes, Gauss-Legendre quadrature) against the textbook
   clamped-clamped values (docs/model.md sec. 10: Thomson App. D, Rao Table 8.1);
3. the kernels take any basis: the pinned span built through the general path (its tables by
   quadrature, not closed forms) gives the closed-form basis' results, through the same
   compiled driver (nothing in the kernels knows which basis they run).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep.kernels import layout as tk
from sweep.models import transverse as tm
from sweep.models.basis import from_shapes, pinned_sines, shape_values
from sweep.specialise import call
from sweep.threads import method_switch


def test_pinned_sines_are_the_closed_forms():
    """Tables, participations, frequencies, midspan and stations of N = 4 pinned sines against
    sin(n pi s) and its derivatives written out here (numpy, not the basis' own loops)."""
    n = 4
    b = pinned_sines(n)
    m = 3 * n + 1
    xi = np.arange(1, m) * math.pi / m
    k = np.arange(1, n + 1)[:, None]
    expected = [k * np.cos(k * xi), -k ** 2 * np.sin(k * xi), -k ** 3 * np.cos(k * xi),
                k ** 4 * np.sin(k * xi), 2.0 / m * np.sin(k * xi),
                2.0 / m * k * np.cos(k * xi), -2.0 / m * k ** 2 * np.sin(k * xi)]
    assert b.tables.shape[0] == len(expected)
    for got, want in zip(b.tables, expected):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    np.testing.assert_array_equal(b.midspan, [1.0, 0.0, -1.0, 0.0])      # exact zeros
    np.testing.assert_array_equal(b.frequency_ratio, [1.0, 4.0, 9.0, 16.0])
    np.testing.assert_allclose(b.participation_ratio, [1.0, 0.0, 1.0 / 3.0, 0.0], rtol=1e-15)
    s = np.arange(b.stations.shape[0]) / (b.stations.shape[0] - 1)
    np.testing.assert_allclose(b.stations, np.sin(np.outer(s, k[:, 0]) * math.pi), atol=1e-15)


def test_beam_function_derivatives_are_the_shapes_slopes():
    """shape_values' derivatives 1..4 against central differences of the order below, for a
    shape using all four terms of the beam-function form."""
    shapes = np.array([[7.2, 0.3, -1.1, 0.8, -0.6]])
    s = np.linspace(0.05, 0.95, 19)
    h = 1e-5
    for order in range(1, 5):
        fd = (shape_values(shapes, s + h, order - 1) - shape_values(shapes, s - h, order - 1)) / (2 * h)
        exact = shape_values(shapes, s, order)
        np.testing.assert_allclose(exact, fd, rtol=1e-7, atol=1e-7 * np.abs(exact).max())


def test_the_kernels_shapes_are_the_bases_shapes():
    """The beam-function form is written twice, in NumPy for building a basis
    (basis.shape_values) and in the kernels for the span's Newton step (modes.shape_at, no
    NumPy import there): both agree on shapes using every term, to round-off, and shape_at's
    are checked against central differences through shape_values above."""
    from sweep.kernels import modes as md
    shapes = np.array([[7.2, 0.3, -1.1, 0.8, -0.6], [3.0 * math.pi, 0.0, 1.0, 0.0, 0.0]])
    for x in (0.0, 0.13, 0.5, 0.91, 1.0):
        for i in range(2):
            got = md.shape_at(shapes, i, x)
            want = [shape_values(shapes, np.array([x]), k)[i, 0] for k in range(3)]
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13 * max(map(abs, want)))


def clamped_mode_1() -> np.ndarray:
    """The clamped-clamped first mode cosh(b s) - cos(b s) - sigma (sinh(b s) - sin(b s)),
    written in the beam-function form (cosh and sinh as decaying exponentials), normalised to
    1 at midspan; b l = 4.730040745, sigma = (cosh b - cos b) / (sinh b - sin b)."""
    beta = 4.730040745
    sigma = (math.cosh(beta) - math.cos(beta)) / (math.sinh(beta) - math.sin(beta))
    # cosh x - sigma sinh x = (1 - sigma)/2 e^x + (1 + sigma)/2 e^-x, e^(b s) = e^b e^-(b(1-s))
    row = np.array([[beta, -1.0, sigma, (1.0 + sigma) / 2.0,
                     (1.0 - sigma) / 2.0 * math.exp(beta)]])
    mid = shape_values(row, np.array([0.5]))[0, 0]
    row[0, 1:] /= mid
    return row


def test_a_clamped_mode_by_quadrature_matches_the_textbook_values():
    """docs/model.md sec. 10's table for the clamped-clamped first mode on l = 1 (normalised to
    max |phi| = 1, at midspan): int phi^2 = 0.39648, int phi'^2 = 4.8777, G / int phi^2 =
    1.3195, phi''(0) = 28.18, phi''(1/2) = -17.13, f1 / f1 pinned = 2.267; the clamped ends
    hold phi = phi' = 0. Through from_shapes (Gauss-Legendre) and shape_values."""
    row = clamped_mode_1()
    ends = np.array([0.0, 1.0])
    np.testing.assert_allclose(shape_values(row, ends), 0.0, atol=1e-9)
    np.testing.assert_allclose(shape_values(row, ends, 1), 0.0, atol=1e-8)
    b = from_shapes("clamped-clamped", row, 40)
    x, w = np.polynomial.legendre.leggauss(40)
    s, w = (x + 1) / 2, w / 2
    phi = shape_values(row, s)[0]
    slope = shape_values(row, s, 1)[0]
    assert abs(phi ** 2 @ w - 0.39648) < 1e-5
    assert abs(slope ** 2 @ w - 4.8777) < 1e-4
    assert abs(b.participation_ratio[0] * 4 / math.pi - 1.3195) < 1e-4
    assert abs(b.frequency_ratio[0] - 2.267) < 1e-3
    curvature = shape_values(row, np.array([0.0, 0.5]), 2)[0]
    assert abs(curvature[0] - 28.18) < 0.01 and abs(curvature[1] + 17.13) < 0.01
    assert b.midspan[0] == pytest.approx(1.0, abs=1e-14)
    # the kernel's fields are derivatives in xi = pi s
    np.testing.assert_allclose(b.tables[1, 0], shape_values(row, s, 2)[0] / math.pi ** 2)


MODES_SCENE = """
name = "basis-check"
[model]
modes = 3
membrane = 0.25
[cable]
damping_ratio = 0.02
length = 0.3
[load]
amplitude = 0.0
[base]
acceleration_g = {level}
frequency_ratio = {ratio}
[solver]
t_end = 0.4
rtol = 1e-10
"""


@pytest.mark.parametrize("level, ratio", [(2.0, 0.7), (8.0, 1.05), (4.0, 2.8)])
def test_the_driver_runs_a_quadrature_basis_as_it_runs_the_closed_form_one(level, ratio):
    """Three modes of a base-excited, nonlinear span below, near and above its first resonance:
    the pinned sines' closed-form basis against the same shapes given to the general path
    (from_shapes: 24 Gauss-Legendre nodes, its own masses, participations and frequencies),
    both through modal_driver.solve_block as compiled once. Modal amplitudes agree to 1e-9
    relative (what round-off in a different quadrature makes of a trajectory at rtol 1e-10),
    so a new basis needs no kernel code."""
    from sweep.kernels import modal_driver
    inputs = tm.resolve(sweep.load_scene_text(MODES_SCENE.format(level=level, ratio=ratio)))
    rows = tm.modal_rows(inputs, np.arange(1))
    s = inputs.settings
    closed = pinned_sines(3)
    general = from_shapes("pinned, by quadrature", closed.shapes, 24)
    results = []
    for basis in (closed, general):
        states = np.empty(1, np.int8)
        reals = np.empty((1, tk.N_REALS))
        counts = np.empty((1, tk.N_COUNTS), np.int64)
        modal = np.empty((1, 3))
        call(modal_driver.solve_block, rows, basis.kernel_arrays(), s, 0, 1, states, reals,
             counts, np.empty((1, 0)), modal, np.empty((1, 6)), True, method_switch(s),
             np.zeros(1, np.int8))
        results.append((states[0], reals[0, tk.AMPLITUDE], modal[0]))
    (s0, a0, m0), (s1, a1, m1) = results
    assert s0 == s1
    assert abs(a1 / a0 - 1) < 1e-9, (a0, a1)
    assert abs(m1[0] / m0[0] - 1) < 1e-9 and abs(m1[2] / m0[2] - 1) < 1e-8, (m0, m1)
    assert m1[1] < 1e-12 * m1[0] and m0[1] < 1e-12 * m0[0]        # the even mode stays at rest


def _integrals(b, nodes=400):
    """int phi_n^2, int phi_n'^2, int phi_n (N each) and A_ij = int phi_i' phi_j' of basis b,
    by a Gauss-Legendre rule far finer than the basis' own."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    s, w = (x + 1.0) / 2.0, w / 2.0
    phi, slope = shape_values(b.shapes, s), shape_values(b.shapes, s, 1)
    return phi ** 2 @ w, slope ** 2 @ w, phi @ w, (slope * w) @ slope.T


def test_the_clamped_basis_is_the_textbook_clamped_span():
    """basis.clamped against the reference values of docs/model.md sec. 10 (Thomson App. D,
    Rao Table 8.1): the eigenvalues b_n l of cos(b l) cosh(b l) = 1, mode 1 scaled to max
    |phi| = 1 (its integrals, participation, curvature at the clamp and at midspan), the
    non-diagonal axial-load matrix A_ij of the unit-normalised modes 1-3 (the coupling of modes
    1 and 3), the clamped ends themselves, and the basis' own quadrature against one twice as
    fine (its projections exact)."""
    from sweep.models.basis import clamped, from_shapes, quadrature_nodes
    b = clamped(4)
    beta = b.shapes[:, 0]
    np.testing.assert_allclose(beta[:3], [4.730040745, 7.853204624, 10.99560784], rtol=1e-9)
    np.testing.assert_allclose(np.cos(beta), 1.0 / np.cosh(beta), rtol=0, atol=1e-13)
    np.testing.assert_allclose(b.frequency_ratio[0], 22.3733 / math.pi ** 2, rtol=1e-5)
    mass, stiff, area, a = _integrals(b)
    assert mass[0] == pytest.approx(0.39648, abs=1e-5)
    assert stiff[0] == pytest.approx(4.8777, abs=1e-4)
    assert area[0] == pytest.approx(0.5232, abs=1e-4)
    assert area[0] / mass[0] == pytest.approx(1.3195, abs=1e-4)
    assert b.participation_ratio[0] == pytest.approx(1.3195 / (4.0 / math.pi), abs=1e-4)
    assert b.participation_ratio[1] == pytest.approx(0.0, abs=1e-12)    # antisymmetric
    curvature = shape_values(b.shapes, np.array([0.0, 0.5, 1.0]), 2)[0]
    np.testing.assert_allclose(curvature, [28.18, -17.13, 28.18], atol=6e-3)
    unit = a[:3, :3] / np.sqrt(np.outer(mass[:3], mass[:3]))
    np.testing.assert_allclose(unit, [[12.303, 0.0, -9.731], [0.0, 46.050, 0.0],
                                      [-9.731, 0.0, 98.905]], atol=6e-4)
    ends = np.array([0.0, 1.0])
    assert np.abs(shape_values(b.shapes, ends)).max() < 1e-12
    assert np.abs(shape_values(b.shapes, ends, 1)).max() < 1e-9 * beta.max()
    assert b.midspan[0] == pytest.approx(1.0, abs=1e-12)    # mode 1 peaks at midspan
    assert np.abs(b.midspan[[1, 3]]).max() < 1e-12                    # antisymmetric: a node
    fine = from_shapes("fine", b.shapes, 2 * quadrature_nodes(4))
    phi_w = b.tables[4]                                   # weights w_j phi(s_j) / int phi^2
    for order in range(4):
        # the projections of every product of six shapes' derivatives the kernel forms
        field = (b.tables[order] * phi_w).sum(axis=1)
        np.testing.assert_allclose(field, (fine.tables[order] * fine.tables[4]).sum(axis=1),
                                   rtol=1e-11, atol=1e-11)


@pytest.mark.parametrize("stiffness, beta, end, mid, ratio", [
    (1.0, 3.3988, 2.83, 10.55, 9.888), (3.0, 3.7097, 7.11, 11.59, 9.991),
    (10.0, 4.1557, 14.98, 13.58, 10.458), (30.0, 4.4714, 21.82, 15.38, 11.223),
    (100.0, 4.6413, 25.93, 16.50, 11.875)])
def test_elastic_ends_are_the_rotational_spring_table(stiffness, beta, end, mid, ratio):
    """basis.elastic_ends against the rotational-spring table (docs/model.md sec. 10, springs
    K = k_t l / EI at both ends): mode 1's b_1 l, f1 / f1 pinned = (b_1 l / pi)^2, the
    curvatures at the end and at midspan per unit midspan amplitude, int phi'^2 / int phi^2;
    and the end conditions phi = 0, phi'' = K phi' (s = 0), phi'' = -K phi' (s = 1)."""
    from sweep.models.basis import elastic_ends
    b = elastic_ends(3, stiffness)
    assert b.shapes[0, 0] == pytest.approx(beta, abs=6e-5)
    assert b.frequency_ratio[0] == pytest.approx((beta / math.pi) ** 2, rel=1e-4)
    curvature = shape_values(b.shapes, np.array([0.0, 0.5]), 2)[0] / b.midspan[0]
    assert curvature[0] == pytest.approx(end, abs=6e-3)
    assert -curvature[1] == pytest.approx(mid, abs=6e-3)
    mass, stiff, _, _ = _integrals(b)
    assert stiff[0] / mass[0] == pytest.approx(ratio, abs=6e-4)
    s = np.array([0.0, 1.0])
    phi, d1, d2 = (shape_values(b.shapes, s, k) for k in range(3))
    scale = np.abs(d2).max()
    assert np.abs(phi).max() < 1e-12
    np.testing.assert_allclose(d2[:, 0], stiffness * d1[:, 0], atol=1e-9 * scale)
    np.testing.assert_allclose(d2[:, 1], -stiffness * d1[:, 1], atol=1e-9 * scale)
    # between pinned (n pi) and clamped, mode by mode
    assert np.all(b.shapes[:, 0] > np.arange(1, 4) * math.pi)
    assert np.all(b.shapes[:, 0] < [4.7301, 7.8533, 10.9957])


@pytest.mark.parametrize("stiffness", [0.0, 0.3, 3.0, 30.0, 300.0, math.inf])
def test_the_observed_rows_are_the_shapes_derivatives_and_mode_1_pushes_one_way(stiffness):
    """Basis.clamps holds phi'' at s = 0, 1, 1/2, phi''' and phi' at s = 0, 1 (pinned: the
    closed forms), equal to finite differences of the shapes themselves; and the first mode's
    reaction terms have one sign, -phi'''(0) > 0, phi'(0) >= 0 and its axial row (the axial
    load's reaction by the span's equilibrium, `reaction_rows`) > 0, whatever the ends (the
    one-mode clamp_force adds |q| |phi'''(0)| and (kappa E - P l^2 / EI) |q| a_1(0) only
    because of that)."""
    from sweep.models.basis import span_basis
    basis = span_basis(stiffness, 3)
    h = 1e-4
    for row, (k, s) in enumerate(((2, 0.0), (2, 1.0), (2, 0.5), (3, 0.0), (3, 1.0), (1, 0.0),
                                  (1, 1.0))):
        lower = shape_values(basis.shapes, np.array([s - h, s + h]), k - 1)
        numeric = (lower[:, 1] - lower[:, 0]) / (2 * h)
        scale = basis.shapes[:, 0] ** k
        assert np.allclose(basis.clamps[row], numeric, atol=1e-6 * scale.max()), row
    assert -basis.clamps[3, 0] > 0.0 and basis.clamps[5, 0] >= -1e-12
    assert basis.clamps[8, 0] > 0.0


@pytest.mark.parametrize("stiffness", [0.0, 3.0, math.inf])
def test_the_modes_share_of_a_uniform_loads_reaction_tends_to_one_half(stiffness):
    """Basis.clamps' last row, Gamma_n int (1 - s) phi_n ds, is each mode's share of the
    reaction at a clamp to a uniform load (statically 1/2 of it, any ends): against a
    trapezoidal quadrature of the shapes written here, summing to less than 1/2 and to
    1/2 as the modes grow, the rest shrinking like 1/N (what the clamp observers add back)."""
    from sweep.models.basis import span_basis
    s = np.linspace(0.0, 1.0, 20001)
    w = np.full(s.size, s[1])
    w[[0, -1]] = s[1] / 2.0                         # the trapezoidal rule's weights
    rest = []
    for n in (1, 5, 21):
        basis = span_basis(stiffness, n)
        phi = shape_values(basis.shapes, s)
        gamma = (phi @ w) / (phi ** 2 @ w)
        share = gamma * ((phi * (1.0 - s)) @ w)
        assert np.allclose(basis.clamps[7], share, atol=1e-8)
        rest.append(0.5 - basis.clamps[7].sum())
    assert 0.0 < rest[2] < rest[1] < rest[0] < 0.2
    assert rest[2] < 0.03 and rest[1] / rest[2] > 3.0


@pytest.mark.parametrize("n_modes", [1, 2, 3, 4])
def test_elastic_bases_of_every_k_stack_into_one_lanes_call(n_modes):
    """Elastic clamps give each span its own K = k_t l / EI and basis; up to 4 modes each
    carries the force's polynomial, whose structure (program, starts, monomials, symmetric
    ends) and the zeros of whose coupling and midspan weights do not depend on K, so a grid's
    bases stack (kernels.modes.stacked) and the lanes run them in one call; each stacked
    item is the basis' own array."""
    from sweep.kernels.modes import stacked
    from sweep.models.basis import elastic_bases_stack, span_basis
    ks = np.geomspace(1e-3, 1e4, 9)
    bases = [span_basis(k, n_modes).kernel_arrays() for k in ks]
    family = stacked(bases)
    assert family is not None and elastic_bases_stack(n_modes)
    for b, arrays in enumerate(bases):
        for item in range(7):
            np.testing.assert_array_equal(family[item][b], arrays[item])
        for k in range(5):
            np.testing.assert_array_equal(family[7][k][b], arrays[7][k])
        assert family[7][5][b] == arrays[7][5]


def test_bases_that_cannot_share_a_lanes_call_do_not_stack():
    """Pinned sines (the quadrature, no polynomial) beside elastic ends, different numbers of
    modes, and 5 elastic modes (no polynomial: each basis' tables would differ lane by lane)."""
    from sweep.kernels.modes import stacked
    from sweep.models.basis import elastic_bases_stack, span_basis
    assert stacked([span_basis(0.0, 3).kernel_arrays(), span_basis(1.0, 3).kernel_arrays()]) is None
    assert stacked([span_basis(1.0, 2).kernel_arrays(), span_basis(1.0, 3).kernel_arrays()]) is None
    assert stacked([span_basis(1.0, 5).kernel_arrays(), span_basis(2.0, 5).kernel_arrays()]) is None
    assert not elastic_bases_stack(5)
    assert stacked([span_basis(0.0, 5).kernel_arrays()]) is not None     # one basis: always
