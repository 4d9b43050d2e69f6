"""Model coefficients against independent references: quadrature of the paper's Galerkin
integrals (Eq.17 projected on sin(pi x / l), as Eq.22 defines them) and Eq.32 as printed."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import quad

import sweep
from sweep import models
from sweep.kernels import metrics as km


def galerkin_by_quadrature(E, rho, A, I, l, P):
    """Project Eq.17 (divided by rho A) on phi = sin(pi x/l) numerically; divide by int phi^2.

    Eq.17: rho A w_tt + P w_xx + EI w_xxxx - 3 EI w_xx^3 - 11 EI w_xx w_xxx w_x
           - (2P + 3/2 EA) w_xx w_x^2 - 3 EI w_xxxx w_x^2 + 21/2 EI w_xx^3 w_x^2 = 0.
    Returns the coefficients of q, q^3 and q^5 of q'' + ... = 0.
    """
    k = np.pi / l
    d = [lambda x, n=n: (k ** n) * [np.sin, np.cos, lambda s: -np.sin(s), lambda s: -np.cos(s)]
         [n % 4](k * x) for n in range(5)]                      # phi and its derivatives
    lam2, lam1, beta = E * I / (rho * A), E / rho, P / (rho * A)

    def proj(f):
        return quad(lambda x: f(x) * d[0](x), 0, l, epsabs=0, epsrel=1e-13, limit=200)[0]

    c1 = proj(d[0])
    lin = proj(lambda x: beta * d[2](x) + lam2 * d[4](x))
    cub = proj(lambda x: -3 * lam2 * d[2](x) ** 3 - 11 * lam2 * d[2](x) * d[3](x) * d[1](x)
               - (2 * beta + 1.5 * lam1) * d[2](x) * d[1](x) ** 2
               - 3 * lam2 * d[4](x) * d[1](x) ** 2)
    quint = proj(lambda x: 10.5 * lam2 * d[2](x) ** 3 * d[1](x) ** 2)
    return lin / c1, cub / c1, quint / c1


CABLES = [
    dict(E=1.1e11, rho=8900.0, A=6e-6, I=5.73e-12, l=1.0, P=4.0),
    dict(E=1.1e11, rho=8900.0, A=6e-6, I=2.865e-12, l=0.35, P=-12.0),
    dict(E=7.0e10, rho=2700.0, A=2e-5, I=3.2e-11, l=2.3, P=150.0),
]


@pytest.mark.parametrize("cable", CABLES)
def test_consistent_coefficients_equal_the_projection_of_eq17(cable):
    lin, cub, quint = galerkin_by_quadrature(**cable)
    c = models.consistent(dict(youngs_modulus=cable["E"], density=cable["rho"],
                               area=cable["A"], inertia=cable["I"], length=cable["l"],
                               membrane=0.375, load_amplitude=cable["P"]))
    assert c["mass"] == 1.0
    assert c["k"] + c["k_load"] == pytest.approx(lin, rel=1e-10)
    assert c["g"] + c["g_load"] == pytest.approx(cub, rel=1e-10)
    assert c["h"] == pytest.approx(quint, rel=1e-10)


def test_paper_c4_is_wrong_and_ours_is_the_projection():
    """Eq.30 prints c4 = +357/16 lam2 k^8 l; the projection gives -21/32 lam2 k^8 l."""
    cable = CABLES[0]
    _, _, quint = galerkin_by_quadrature(**cable)
    lam2 = cable["E"] * cable["I"] / (cable["rho"] * cable["A"])
    k, l = np.pi / cable["l"], cable["l"]
    assert quint * l / 2 == pytest.approx(-21 / 32 * lam2 * k ** 8 * l, rel=1e-10)
    assert quint * l / 2 != pytest.approx(357 / 16 * lam2 * k ** 8 * l, rel=0.5)


def test_closed_forms_of_table1_cable():
    p = dict(youngs_modulus=1.1e11, density=8900.0, area=6e-6, inertia=5.73e-12, length=1.0,
             membrane=0.375, load_amplitude=4.0)
    c = models.consistent(p)
    EI, rhoA = 1.1e11 * 5.73e-12, 8900.0 * 6e-6
    assert EI == pytest.approx(0.630, rel=1e-3) and rhoA == pytest.approx(0.0534, rel=1e-3)
    assert c["buckling_load"] == pytest.approx(EI * np.pi ** 2, rel=1e-14)
    assert c["omega_1"] == pytest.approx(np.pi ** 2 * np.sqrt(EI / rhoA), rel=1e-14)


def _paper(l, corrected=False, load=4.0):
    return models.paper(dict(length=l, load_amplitude=load,
                             paper_parametric="corrected" if corrected else "printed"))


@pytest.mark.parametrize("l", [0.5, 0.7, 0.85, 1.0])
def test_paper_preset_is_eq32_as_printed(l):
    c = _paper(l)
    pi = np.pi
    assert c["mass"] == 0.5 * l
    assert c["k"] == pytest.approx(1.73 * pi ** 2 * l)
    assert c["k_load"] == pytest.approx(-1.08 * l ** 5)
    assert c["g"] == pytest.approx(6.6e5 * pi ** 2 * l ** 3 - 2.1 * pi ** 4 / l)
    assert c["g_load"] == pytest.approx(0.54 * pi ** 2 * l ** 3)
    assert c["h"] == pytest.approx(76 * pi ** 6 / l ** 3)
    assert c["omega_ref"] == pytest.approx(1.86 * pi)


def test_paper_corrected_parametric_terms_come_from_eq31():
    """Eq.31's 37.5 and 18.7 over w0^2 = (1.86 pi)^2 l^-8: 10.84 l^5 and 5.41 pi^2 l^3."""
    c = _paper(1.0, corrected=True)
    assert -c["k_load"] == pytest.approx(10.84, abs=0.005)
    assert c["g_load"] / np.pi ** 2 == pytest.approx(5.41, abs=0.005)
    # Corrected, the load ratio is close to the consistent model's P0/Pcr = 4 / (0.63 pi^2).
    ratio = 4.0 / c["buckling_load"]
    assert ratio == pytest.approx(4.0 / (1.1e11 * 5.73e-12 * np.pi ** 2), rel=0.02)


def test_oscillator_frequency_and_constant_load():
    base = dict(youngs_modulus=1.1e11, density=8900.0, area=6e-6, inertia=5.73e-12,
                length=0.5, membrane=0.375, load_amplitude=4.0, damping_ratio=0.02,
                frequency_ratio=2.0, frequency=None, initial_displacement=0.0,
                initial_velocity=0.0, coefficients="consistent", load_type="harmonic",
                paper_parametric="printed", divergence_bound=None)
    h = models.oscillator(base)
    w1 = 2 * np.pi * h["natural_frequency"]
    assert h["omega"] == pytest.approx(2.0 * w1)
    assert h["damping"] == pytest.approx(2 * 0.02 * w1)
    assert h["bound"] == 0.5
    f = models.oscillator({**base, "frequency": 50.0, "frequency_ratio": None})
    assert f["omega"] == pytest.approx(2 * np.pi * 50.0)
    c = models.oscillator({**base, "load_type": "constant"})
    assert c["k1"] == 0.0 and c["g1"] == 0.0 and c["omega"] == 0.0
    assert c["k0"] == pytest.approx(h["k0"] + h["k1"])
    assert c["g0"] == pytest.approx(h["g0"] + h["g1"])


TABLE1 = dict(youngs_modulus=1.1e11, density=8900.0, area=6e-6, inertia=5.73e-12, length=1.0,
              membrane=0.375, load_amplitude=0.0, damping_ratio=0.0, frequency_ratio=None,
              frequency=None, initial_displacement=0.0, initial_velocity=0.0,
              coefficients="consistent", load_type="constant", paper_parametric="printed",
              divergence_bound=None)


def barrier_by_roots(p):
    """q_b from the modal equation's stiffness w1^2 (1 - P/Pcr) + K3 q^2 + K5 q^4 written out
    (docs/model.md sec. 2), its smallest positive root in s = q^2 by numpy's polynomial roots."""
    k = np.pi / p["length"]
    ei_ra = p["youngs_modulus"] * p["inertia"] / (p["density"] * p["area"])
    pcr = p["youngs_modulus"] * p["inertia"] * k ** 2
    k1 = ei_ra * k ** 4 * (1 - p["load_amplitude"] / pcr)
    k3 = (p["membrane"] * p["youngs_modulus"] / p["density"] * k ** 4
          + p["load_amplitude"] * k ** 4 / (2 * p["density"] * p["area"]) - 1.25 * ei_ra * k ** 6)
    k5 = -21 / 16 * ei_ra * k ** 8
    s = np.polynomial.polynomial.polyroots([k1, k3, k5])
    s = s.real[(abs(s.imag) < 1e-12 * abs(s)) & (s.real > 0)]
    return float(np.sqrt(s.min()))


@pytest.mark.parametrize("length, load", [(1.0, 0.0), (0.3, 0.0), (2.0, 0.0), (1.0, 3.0)])
def test_escape_barrier_without_membrane_is_the_closed_form(length, load):
    """membrane = 0: the barrier lies at slope pi q_b / l < 1, inside the model's range
    (unloaded: (pi q_b / l)^2 = (-5/4 + sqrt(25/16 + 21/4)) / (21/8), whatever the cable)."""
    p = {**TABLE1, "membrane": 0.0, "length": length, "load_amplitude": load}
    qb = float(models.oscillator(p)["escape_barrier"])
    assert qb == pytest.approx(barrier_by_roots(p), rel=1e-12)
    if load == 0.0:
        slope = np.sqrt((-1.25 + np.sqrt(25 / 16 + 21 / 4)) / (21 / 8))
        assert qb == pytest.approx(slope * length / np.pi, rel=1e-12)


def test_escape_barrier_beyond_the_model_range_is_nan():
    """Table 1 with membrane 3/8: the quintic's root lies at 55 m for a 1 m span (slope 174), far
    beyond slope 1, where the truncated slope series of the model diverge: NaN, not 55 m."""
    assert barrier_by_roots(TABLE1) == pytest.approx(55.4, rel=0.01)
    assert np.isnan(models.oscillator(TABLE1)["escape_barrier"])
    # The cut is at slope 1: membrane alpha* = (25/16) I k^2 / A puts the root exactly there.
    k = np.pi / TABLE1["length"]
    alpha = 25 / 16 * TABLE1["inertia"] * k ** 2 / TABLE1["area"]
    inside = {**TABLE1, "membrane": 0.999 * alpha}
    qb = float(models.oscillator(inside)["escape_barrier"])
    assert qb == pytest.approx(barrier_by_roots(inside), rel=1e-12) and qb * k < 1.0
    beyond = {**TABLE1, "membrane": 1.001 * alpha}
    assert barrier_by_roots(beyond) * k > 1.0
    assert np.isnan(models.oscillator(beyond)["escape_barrier"])
    lengths = xr.DataArray([0.3, 1.0], dims="length")
    both = models.oscillator({**TABLE1, "membrane": 0.0, "length": lengths})["escape_barrier"]
    assert both.dims == ("length",) and np.isfinite(both).all()


def test_in_range_barrier_separates_bounded_from_escaping_motion():
    """Started at rest 2 % inside the barrier the undamped span stays bounded at |q| = q0;
    2 % outside it escapes (diverges) well before t_end."""
    p = {**TABLE1, "membrane": 0.0}
    qb = float(models.oscillator(p)["escape_barrier"])
    ds = sweep.run(sweep.load_scene_text(f"""
[model]
membrane = 0.0
[cable]
length = 1.0
[load]
type = "constant"
amplitude = 0.0
[metrics]
divergence_bound = 10.0
[axes]
initial_displacement = [{0.98 * qb!r}, {1.02 * qb!r}]
[solver]
t_end = 2.0
"""), progress=False)
    assert float(ds["escape_barrier"]) == pytest.approx(qb, rel=1e-12)
    inside, outside = ds["state"].values
    assert inside not in (km.DIVERGED, km.STEP_TOO_SMALL, km.MAX_STEPS)
    assert float(ds["peak_amplitude"][0]) == pytest.approx(0.98 * qb, rel=1e-6)
    assert outside == km.DIVERGED and 0 < float(ds["failure_time"][1]) < 2.0


@pytest.mark.parametrize("rotation", ["pinned", "clamped", 10.0])
def test_one_mode_bending_terms_are_the_gradient_of_the_bending_energy(rotation):
    """One mode, no model.membrane (the bending terms from the span's energy, issue 35), the
    clamps sliding (no stretching): the cubic and quintic coefficients g, h of q'' + w1^2 q +
    g q^3 + h q^5 are those of the bending energy U_b(q) = (EI/2) int w''^2 (1 - 3 w'^2 +
    6 w'^4) dx of w = q phi, phi the span's first mode scaled to max |phi| = 1 (SciPy's own
    quadrature on sweep.models.basis' shape: U_b is a polynomial a2 q^2 + a4 q^4 + a6 q^6, its
    a4 and a6 solved from three amplitudes; then g = 4 a4 / m, h = 6 a6 / m, m = rho A
    int phi^2 dx). Pinned ends: -(3/2) and +(9/4) (EI/rho A) k^6, k^8, not Eq.17's -5/4 and
    -21/16."""
    from sweep.models import basis
    E, rho, A, I, l = 1.1e11, 8900.0, 6e-6, 2.865e-12, 0.6
    k_t = None if isinstance(rotation, str) else rotation * E * I / l
    p = dict(youngs_modulus=E, density=rho, area=A, inertia=I, length=l, load_amplitude=0.0,
             clamps_rotation=rotation if k_t is None else "elastic",
             clamp_rotational_stiffness=k_t, clamp_axial_stiffness=0.0)
    c = models.consistent(p)
    shape = basis.span_basis(basis.end_stiffness(p["clamps_rotation"], k_t, l, E * I), 1).shapes

    def d(x, n):
        return basis.shape_values(shape, np.array([x / l]), n)[0, 0] / l ** n

    def energy(q):
        return quad(lambda x: 0.5 * E * I * (q * d(x, 2)) ** 2 * (
            1.0 - 3.0 * (q * d(x, 1)) ** 2 + 6.0 * (q * d(x, 1)) ** 4), 0, l,
            epsabs=0, epsrel=1e-13, limit=200)[0]

    q = np.array([0.01, 0.02, 0.03])
    a2, a4, a6 = np.linalg.solve(np.stack([q ** 2, q ** 4, q ** 6], axis=1),
                                 [energy(x) for x in q])
    m = rho * A * quad(lambda x: d(x, 0) ** 2, 0, l, epsabs=0, epsrel=1e-13)[0]
    assert c["g"] == pytest.approx(4.0 * a4 / m, rel=1e-7)
    assert c["h"] == pytest.approx(6.0 * a6 / m, rel=1e-6)
    if rotation == "pinned":
        k = np.pi / l
        assert c["g"] == pytest.approx(-1.5 * E * I / (rho * A) * k ** 6, rel=1e-12)
        assert c["h"] == pytest.approx(2.25 * E * I / (rho * A) * k ** 8, rel=1e-12)
