"""`model.modes = N`: the N-mode Galerkin span against an independent reference.

With w = sum_{n=1..N} q_n(t) sin(n pi x / l), the engine projects Eq.17 on every mode. The
reference is tests/galerkin.py, written from Eq.17 alone (its docstring): the projections are
computed at run time by a quadrature of the residual that is exact for these trigonometric
polynomials, and the equations are integrated by SciPy's DOP853 at rtol 1e-11, its tail maxima
found on the dense output and refined at the velocity's sign changes (measured: they change by
< 1e-11 relative between rtol 1e-11 and 1e-12). Nothing here uses the engine's kernels or its
coefficients.

1. the reference itself: N = 1 gives the closed-form one-mode coefficients (w1, Pcr, K3, K5,
   Gamma), its linear part is diag(w_n^2 (1 - P / Pcr_n)), its quadrature equals Gauss-Legendre;
2. the engine's modal amplitudes and midspan amplitude (modes = 3, rk45 and dop853) against the
   reference to 1e-4: a strongly nonlinear base-excited point and an axially loaded one released
   from displacements in modes 1 and 3;
3. w_n = n^2 w1: `modal_frequency`, and the period of a small free vibration in mode 3 alone;
4. parity: from rest under base excitation the even modes stay at round-off;
5. the principal parametric tongue of mode 2 (W near 2 w_2 = 8 w1): a 1e-9 m seed grows by
   orders of magnitude inside it and stays small outside, in the engine and the reference;
6. the refusals of the new keys.
"""

from __future__ import annotations

import functools
import json
import math

import numpy as np
import pytest
from scipy.integrate import quad

import sweep
from sweep.errors import UserError
from sweep.models.basis import unfolded_tables

from conftest import fast_first
from galerkin import (Cable, Projection, absolute_tail_maximum, galerkin_rhs, integrate,
                      participation, span_tail_argmax, tail_maxima)

E = 1.1e11                     # Young's modulus, Pa
RHO = 8900.0                   # density, kg/m^3
AREA = 6e-6                    # m^2
INERTIA = 2.865e-12            # m^4, the solid round section's bending moment
G = 9.80665                    # standard gravity, m/s^2
LENGTH = 0.5                   # m: f1 = 15.26 Hz


def scene(values: dict, axes: dict | None = None) -> sweep.Scene:
    """A scene of the Table 1 cable from dotted keys (`values`, lists allowed) and axes, as
    TOML text."""
    values = {"cable.youngs_modulus": E, "cable.density": RHO, "cable.area": AREA,
              "cable.inertia": INERTIA, "cable.length": LENGTH, "model.membrane": 0.375,
              **values}
    sections: dict[str, list[str]] = {}
    for key, value in values.items():
        section, name = key.split(".")
        sections.setdefault(section, []).append(f"{name} = {json.dumps(value)}")
    sections["axes"] = [f"{name} = {json.dumps([float(v) for v in vs])}"
                        for name, vs in (axes or {}).items()]
    text = "\n".join(f"[{s}]\n" + "\n".join(lines) for s, lines in sections.items())
    return sweep.load_scene_text('name = "modes-test"\n' + text)


def state_name(ds, flag: int) -> str:
    """The meaning of a `state` flag value (from the dataset's own flag attributes)."""
    attrs = ds["state"].attrs
    return attrs["flag_meanings"].split()[list(attrs["flag_values"]).index(flag)]


def modal_row(ds, n_modes: int) -> np.ndarray:
    """`modal_amplitude` of a one-point grid as an array over mode 1..N (m)."""
    assert list(ds["mode"].values) == list(range(1, n_modes + 1))
    return ds["modal_amplitude"].transpose(..., "mode").values.reshape(-1, n_modes)[0]


# ----------------------------------------------------------------- 1. the reference itself

@pytest.mark.parametrize("length, membrane", [(0.3, 0.375), (0.5, 0.25), (1.0, 0.0)])
def test_reference_with_one_mode_is_the_closed_form_equation(length, membrane):
    """N = 1: the reference's projection is w1^2 (1 - P/Pcr) q + K3(P) q^3 + K5 q^5 with
    w1^2 = (EI/rhoA) k^4, Pcr = EI k^2, K3 = alpha (E/rho) k^4 + P k^4/(2 rhoA) - (5/4)(EI/rhoA)
    k^6, K5 = -(21/16)(EI/rhoA) k^8, to 1e-12 (measured <= 5e-16), in compression and tension,
    each part homogeneous of its degree in q; and Gamma_1 = 4/pi, the projection of a uniform
    acceleration, against quad."""
    cable = Cable(length=length, membrane=membrane)
    k = math.pi / length
    ei_rho_a = E * INERTIA / (RHO * AREA)
    w1_sq = ei_rho_a * k ** 4
    pcr = E * INERTIA * k * k
    proj = Projection(cable, 1)
    assert abs(cable.w1 ** 2 / w1_sq - 1.0) < 1e-12
    for p in (0.0, 0.3 * pcr, -2.0 * pcr):
        k3 = membrane * E / RHO * k ** 4 + p * k ** 4 / (2 * RHO * AREA) - 1.25 * ei_rho_a * k ** 6
        k5 = -21.0 / 16.0 * ei_rho_a * k ** 8
        k3_scale = membrane * E / RHO * k ** 4 + abs(p) * k ** 4 / (2 * RHO * AREA) \
            + 1.25 * ei_rho_a * k ** 6                      # no cancellation hides an error
        for q in (1.0, 1e-3):
            linear, cubic, quintic = proj.parts(np.array([q]), p)
            assert abs(linear[0] / q - w1_sq * (1.0 - p / pcr)) < 1e-12 * w1_sq * (1 + abs(p) / pcr)
            assert abs(cubic[0] / q ** 3 - k3) < 1e-12 * k3_scale
            assert abs(quintic[0] / q ** 5 / k5 - 1.0) < 1e-12
        # Pcr: the load that cancels the linear stiffness
        slope = (proj.parts(np.array([1.0]), 0.0)[0][0] - proj.parts(np.array([1.0]), 1.0)[0][0])
        assert abs(w1_sq / slope / pcr - 1.0) < 1e-12
    gamma = 2.0 / length * quad(lambda x: math.sin(k * x), 0.0, length, epsabs=0, epsrel=1e-13)[0]
    assert abs(participation(1)[0] / gamma - 1.0) < 1e-12
    assert abs(gamma - 4.0 / math.pi) < 1e-13


def test_reference_linear_part_participations_and_quadrature():
    """N = 4: the linear part is diag(w_n^2 (1 - P/Pcr_n)), w_n = n^2 w1, Pcr_n = n^2 EI k^2
    (off-diagonal round-off only); each mode alone is the one-mode span with k -> n k (its K3,
    K5 to 1e-12: the derivatives' n^p factors); Gamma_n = (2/l) int sin(n k x) dx by quad (0
    for even n); and the midpoint rule is exact: its default nodes, the fewest that are exact
    (3N + 1) and 300 Gauss-Legendre nodes agree to 1e-13 on every part at an arbitrary state."""
    n_modes, p = 4, 7.0
    cable = Cable(length=0.7)
    k = cable.k
    proj = Projection(cable, n_modes)
    n = np.arange(1, n_modes + 1)
    matrix = proj.parts(np.eye(n_modes), p)[0]             # row i: the force of q = e_i
    expected = np.diag((n ** 2 * cable.w1) ** 2 * (1.0 - p / (n ** 2 * E * INERTIA * k * k)))
    np.testing.assert_allclose(matrix, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # mode n alone is the one-mode span with k -> n k (its cubic and quintic on itself)
    ei_rho_a = E * INERTIA / (RHO * AREA)
    for i in n:
        kn = i * k
        _, cubic, quintic = proj.parts(np.eye(n_modes)[i - 1], p)
        k3 = cable.membrane * E / RHO * kn ** 4 + p * kn ** 4 / (2 * RHO * AREA) \
            - 1.25 * ei_rho_a * kn ** 6
        assert abs(cubic[i - 1] / k3 - 1.0) < 1e-12
        assert abs(quintic[i - 1] / (-21.0 / 16.0 * ei_rho_a * kn ** 8) - 1.0) < 1e-12
    for i in n:
        integral = quad(lambda x: math.sin(i * k * x), 0.0, cable.length, epsabs=1e-14,
                        epsrel=1e-14, limit=200)[0]
        assert abs(participation(n_modes)[i - 1] - 2.0 / cable.length * integral) < 1e-12
    q = np.array([2e-3, -7e-4, 5e-4, 3e-4])
    fewest = Projection(cable, n_modes, nodes=3 * n_modes + 1)
    gauss = Projection(cable, n_modes, nodes=300, gauss=True)
    for part, few, gl in zip(proj.parts(q, p), fewest.parts(q, p), gauss.parts(q, p)):
        np.testing.assert_allclose(part, gl, rtol=0, atol=1e-13 * np.abs(gl).max())
        np.testing.assert_allclose(few, gl, rtol=0, atol=1e-13 * np.abs(gl).max())
    # force (the references' right-hand side) is the sum of the parts, one state or many
    total = sum(gauss.parts(q, p))
    np.testing.assert_allclose(proj.force(q, p), total, rtol=0, atol=1e-13 * np.abs(total).max())
    states = np.stack((q, -0.5 * q, q[::-1]))
    totals = sum(gauss.parts(states, p))
    np.testing.assert_allclose(proj.force(states, p), totals, rtol=0,
                               atol=1e-13 * np.abs(totals).max())


# ------------------------------------------------- 2. modal amplitudes against the reference

N3 = 3
T_END = 1.5                    # s
CASES = {
    # Table 1 span at 2 % damping, 1 g at 1.5 f1 on the stiffened (upper) branch, from rest
    "base-excited": dict(zeta=0.02, base=G, base_ratio=1.5, load=0.0, load_ratio=0.0,
                         q0=[0.0, 0.0, 0.0], membrane=0.375),
    # 1 % damping, harmonic end load 6 N (0.48 Pcr) at W = 1.5 w1, released from modes 1 and 3
    "axially-loaded": dict(zeta=0.01, base=0.0, base_ratio=0.0, load=6.0, load_ratio=1.5,
                           q0=[2e-3, 0.0, 3e-4], membrane=0.375),
    # the same without membrane stretching, released at slopes pi q / l up to 0.19: the bending
    # terms of Eq.17 (3, 11, 3, 21/2 EI and the 2 P) shape the response, not the membrane's
    "bending-nonlinear": dict(zeta=0.01, base=0.0, base_ratio=0.0, load=6.0, load_ratio=1.5,
                              q0=[0.03, 0.0, 5e-3], membrane=0.0),
}


@functools.lru_cache(maxsize=None)
def reference(name: str) -> tuple[np.ndarray, float]:
    """(tail max |q_n| (m), tail max |q1 - q3| (m)) of a CASES entry, from tests/galerkin.py."""
    c = CASES[name]
    cable = Cable(length=LENGTH, damping_ratio=c["zeta"], membrane=c["membrane"])
    f1 = cable.w1 / (2 * math.pi)
    scale = max(max(abs(x) for x in c["q0"]), 4 / math.pi * c["base"] / cable.w1 ** 2)
    sol = integrate(cable, N3, c["q0"] + [0.0] * N3, T_END, scale,
                    load_amplitude=c["load"], load_omega=c["load_ratio"] * cable.w1,
                    base_acceleration=c["base"], base_frequency=c["base_ratio"] * f1)
    return tail_maxima(sol, N3, T_END, 0.5, fastest_hz=2 * N3 ** 2 * f1)


def assert_modal_close(engine: np.ndarray, ref: np.ndarray, rtol: float) -> None:
    """Per mode: relative to rtol where the reference is > 1e-3 of its largest mode, else
    absolutely within 1e-7 of that largest mode (a mode at round-off in both)."""
    scale = float(np.max(ref))
    for n, (e, r) in enumerate(zip(engine, ref), start=1):
        if r > 1e-3 * scale:
            assert abs(e / r - 1.0) < rtol, (n, e, r)
        else:
            assert abs(e - r) < 1e-7 * scale, (n, e, r)


@pytest.mark.parametrize("driver", ["lanes", "scalar"])
@pytest.mark.parametrize("method", ["rk45", "dop853"])
@pytest.mark.parametrize("name", fast_first(CASES, "bending-nonlinear"))
def test_modal_amplitudes_match_the_reference(name, method, driver):
    """modal_amplitude (tail max |q_n|) and amplitude (tail max |q1 - q3|) of modes = 3 at
    rtol 1e-10 against the reference, to 1e-4 relative (the even mode, at round-off in both,
    absolutely). The base-excited point is strongly nonlinear: K3 a^2 / w1^2 = 3.5 (> 0.05
    asserted); mode 3 carries 2 % of the midspan amplitude there. The membrane dominates the
    cubic there, so the third case drops it (alpha = 0) and starts at large slopes: changing any
    one of Eq.17's bending coefficients (3, 11, 3, 21/2 EI, the 2 P) by 5 % moves its mode 1
    amplitude by 3.4e-4 to 2.5e-2 (measured with the reference). Measured: mode 1 and the
    midspan amplitude within 2e-9 relative, mode 3 within 1.1e-7, both methods."""
    c = CASES[name]
    values = {"model.modes": N3, "cable.damping_ratio": c["zeta"], "model.membrane": c["membrane"],
              "load.amplitude": c["load"], "solver.t_end": T_END, "solver.rtol": 1e-10,
              "solver.method": method, "solver.driver": driver, "metrics.tail": 0.5,
              "initial.modal_displacement": c["q0"]}
    if c["load"]:
        values["load.frequency_ratio"] = c["load_ratio"]
    if c["base"]:
        values["base.acceleration"] = c["base"]
        values["base.frequency_ratio"] = c["base_ratio"]
    ds = sweep.run(scene(values, {"damping_ratio": [c["zeta"]]}))
    ref_modal, ref_midspan = reference(name)
    cable = Cable(length=LENGTH)
    if c["base"]:
        k3 = Projection(cable, 1).parts(np.array([1.0]), 0.0)[1][0]
        assert k3 * ref_modal[0] ** 2 / cable.w1 ** 2 > 0.05
    assert state_name(ds, int(ds["state"].values[0])) not in (
        "invalid_input", "diverged", "step_size_too_small", "max_steps_reached")
    assert_modal_close(modal_row(ds, N3), ref_modal, 1e-4)
    assert abs(float(ds["amplitude"].values[0]) / ref_midspan - 1.0) < 1e-4


ACCELERATION_SOLVERS = [("dop853", 1e-8, "lanes"), ("dop853", 1e-8, "scalar"),
                        ("rk45", 1e-8, "lanes"), ("rk45", 1e-8, "scalar"),
                        ("dop853", 1e-10, "lanes")]


@pytest.mark.parametrize("method, rtol, driver",
                         fast_first(ACCELERATION_SOLVERS, ("dop853", 1e-8, "lanes")))
def test_absolute_acceleration_of_several_modes_matches_the_reference(method, rtol, driver):
    """absolute_acceleration, the tail's peak |w''(l/2) + a_b| (m/s^2) of the base-excited
    point with three modes, against the reference's dense output (q'' from the projected
    equations on it, a grid refined by a bounded search), each method and driver. DOP853 at
    rtol 1e-8 takes long steps (its step-end samples alone were 3e-5 off on one mode): the
    extremum is refined on the degree-8 polynomial through q, q', q'' at three step ends.
    Measured: within 1.2e-8 relative at rtol 1e-8 (both methods), 5.6e-11 at 1e-10."""
    c = CASES["base-excited"]
    cable = Cable(length=LENGTH, damping_ratio=c["zeta"], membrane=c["membrane"])
    f1 = cable.w1 / (2 * math.pi)
    rhs = dict(base_acceleration=c["base"], base_frequency=c["base_ratio"] * f1)
    sol = integrate(cable, N3, [0.0] * 2 * N3, T_END, 4 / math.pi * c["base"] / cable.w1 ** 2,
                    **rhs)
    ref = absolute_tail_maximum(sol, galerkin_rhs(cable, N3, **rhs), N3, c["base"],
                                c["base_ratio"] * f1, T_END, 0.5, fastest_hz=2 * N3 ** 2 * f1)
    ds = sweep.run(scene({"model.modes": N3, "cable.damping_ratio": c["zeta"],
                          "model.membrane": c["membrane"], "load.amplitude": 0.0,
                          "base.acceleration": c["base"], "base.frequency_ratio": c["base_ratio"],
                          "solver.t_end": T_END, "solver.rtol": rtol, "solver.method": method,
                          "solver.driver": driver, "metrics.tail": 0.5},
                         {"damping_ratio": [c["zeta"]]}))
    engine = float(ds["absolute_acceleration"].values[0])
    assert abs(engine / ref - 1.0) < (1e-6 if rtol >= 1e-8 else 1e-8), (engine, ref)


# ---------------------------------------------------------------------- 3. w_n = n^2 w1

def test_modal_frequency_is_n_squared_f1():
    """modal_frequency (Hz) on (mode, length): n^2 (pi / (2 l^2)) sqrt(EI / rhoA), to 1e-12."""
    lengths = [0.4, 0.6]
    ds = sweep.run(scene({"model.modes": 3, "load.amplitude": 0.0, "solver.t_end": 0.01,
                          "initial.modal_displacement": [1e-6, 0.0, 0.0]},
                         {"length": lengths}))
    freq = ds["modal_frequency"]
    assert set(freq.dims) == {"mode", "length"}
    assert freq.attrs["units"] == "Hz"
    f = freq.transpose("length", "mode").values
    for i, length in enumerate(lengths):
        f1 = math.pi / (2 * length ** 2) * math.sqrt(E * INERTIA / (RHO * AREA))
        np.testing.assert_allclose(f[i], f1 * np.arange(1, 4) ** 2, rtol=1e-12)


def test_free_vibration_in_mode_3_has_period_of_9_w1():
    """Released undamped from q = (0, 0, 1e-6) m, modes = 3: the midspan deflection is -q3 and
    its response_period is 2 pi / (9 w1) to 1e-6. The amplitude's own frequency shift, s =
    (3/8) K3_33 a^2 / w_3^2 with the reference's self-cubic K3_33 of mode 3, is 2.9e-7 (bounded
    below 3e-7); the period is also (1 - s) 2 pi / (9 w1) to 1e-10 (first-order Lindstedt, its
    next term O(s^2); a mode-3 motion drives mode 1 only through q3^3, far smaller still).
    Measured: -2.943373e-7 against -s = -2.943361e-7. The tail holds 20 periods. rtol 1e-12:
    DOP853 (the multi-mode default) at 1e-10 ends 4e-9 off in the period over the 40 periods
    (RK45 at 1e-10, with 4-5x the steps, within 1e-10)."""
    cable = Cable(length=LENGTH)
    a = 1e-6
    w3 = 9 * cable.w1
    k3_33 = Projection(cable, 3).parts(np.array([0.0, 0.0, 1.0]), 0.0)[1][2]
    assert 0 < 0.375 * k3_33 * a * a / w3 ** 2 < 3e-7
    period = 2 * math.pi / w3
    ds = sweep.run(scene({"model.modes": 3, "load.amplitude": 0.0, "cable.damping_ratio": 0.0,
                          "solver.t_end": 40 * period, "solver.rtol": 1e-12,
                          "initial.modal_displacement": [0.0, 0.0, a]},
                         {"damping_ratio": [0.0]}))
    shift = 0.375 * k3_33 * a * a / w3 ** 2
    assert abs(float(ds["response_period"].values[0]) / period - 1.0) < 1e-6
    assert abs(float(ds["response_period"].values[0]) / period - (1.0 - shift)) < 1e-10
    modal = modal_row(ds, 3)
    assert abs(modal[2] / a - 1.0) < 1e-6
    assert abs(float(ds["amplitude"].values[0]) / a - 1.0) < 1e-6
    assert modal[0] < 1e-9 * a and modal[1] < 1e-12 * a


# ------------------------------------------------------------------------------ 4. parity

def test_even_modes_stay_at_round_off_under_base_excitation():
    """modes = 4, from rest under the base-excited case's 1 g at 1.5 f1: the uniform base
    acceleration and the response it drives are symmetric about midspan, so modes 2 and 4
    are never forced: their modal_amplitude stays < 1e-12 x the odd modes' (measured 2e-17; the
    reference's: 1e-16, its quadrature's round-off)."""
    ds = sweep.run(scene({"model.modes": 4, "load.amplitude": 0.0, "cable.damping_ratio": 0.02,
                          "base.acceleration": G, "base.frequency_ratio": 1.5,
                          "solver.t_end": 0.5}, {"damping_ratio": [0.02]}))
    modal = modal_row(ds, 4)
    odd = max(modal[0], modal[2])
    assert modal[0] > 1e-4 and modal[2] > 1e-6            # the odd modes respond (m)
    assert modal[1] < 1e-12 * odd and modal[3] < 1e-12 * odd


# ------------------------------------------------------------- 5. the parametric tongue of mode 2

TONGUE_ZETA = 0.005
TONGUE_T_END = 1.0             # s
SEED = 1e-9                    # m


@functools.lru_cache(maxsize=None)
def tongue_reference(ratio: float) -> np.ndarray:
    """Tail max |q_n| (m) of the reference, modes = 2, seed q_2(0), load 0.6 Pcr_1 at W/w1."""
    cable = Cable(length=LENGTH, damping_ratio=TONGUE_ZETA)
    p0 = 0.6 * E * INERTIA * cable.k ** 2
    sol = integrate(cable, 2, [0.0, SEED, 0.0, 0.0], TONGUE_T_END, SEED,
                    load_amplitude=p0, load_omega=ratio * cable.w1)
    return tail_maxima(sol, 2, TONGUE_T_END, 0.5, fastest_hz=8 * cable.w1 / (2 * math.pi))[0]


@pytest.mark.parametrize("driver", ["lanes", "scalar"])
def test_mode_2_grows_in_its_principal_parametric_tongue_only(driver):
    """P0 = 0.6 Pcr_1 = 0.15 Pcr_2 (mu_2 = P0 / (2 Pcr_2) = 0.075): the first-order zone of mode 2
    is W = 8 w1 sqrt(1 +- mu_2) = 7.69-8.29 w1, its growth rate at the centre about
    mu_2 w_2 / 2 - zeta w_2 = 12.5 /s. At W = 8 w1 the 1e-9 m seed grows to > 1e-5 m (the
    reference: 1.7e-4 m, where the membrane's stiffening detunes it); at W = 6 w1, far outside
    every zone of modes 1 and 2, it stays below the seed. Engine (rk45, rtol 1e-10) and
    reference agree to 1e-4 at both (measured 7e-9); mode 1, never seeded, stays at
    round-off."""
    cable = Cable(length=LENGTH)
    mu = 0.6 * E * INERTIA * cable.k ** 2 / (2 * 4 * E * INERTIA * cable.k ** 2)
    assert 8 * math.sqrt(1 - mu) < 8.0 < 8 * math.sqrt(1 + mu) and 6.0 < 8 * math.sqrt(1 - mu)
    ratios = [6.0, 8.0]
    ds = sweep.run(scene({"model.modes": 2, "cable.damping_ratio": TONGUE_ZETA,
                          "load.amplitude": 0.6 * E * INERTIA * cable.k ** 2,
                          "solver.t_end": TONGUE_T_END, "solver.rtol": 1e-10,
                          "solver.driver": driver, "initial.modal_displacement": [0.0, SEED]},
                         {"frequency_ratio": ratios}))
    modal = ds["modal_amplitude"].transpose("frequency_ratio", "mode").values
    outside, inside = tongue_reference(6.0), tongue_reference(8.0)
    assert inside[1] > 1e4 * SEED and outside[1] < SEED
    assert modal[1, 1] > 1e4 * SEED
    assert modal[0, 1] < SEED
    assert abs(modal[1, 1] / inside[1] - 1.0) < 1e-4
    assert abs(modal[0, 1] / outside[1] - 1.0) < 1e-4
    assert np.all(modal[:, 0] < 1e-12 * modal[:, 1])
    # the midspan is a node of mode 2: it stays at round-off, yet neither point has decayed
    # (mode 2 grows at 8 w1; at 6 w1 it is still 38 % of its seed): each is judged on mode 2
    # (whatever state the midspan's round-off was given: it differed between the drivers),
    # and the largest deflection over the span is mode 2's amplitude (its crest at l/4, 3l/4)
    amplitude = ds["amplitude"].values
    assert np.all(amplitude < 1e-12 * modal[:, 1])
    states = [state_name(ds, int(f)) for f in ds["state"].values]
    assert "decayed" not in states, states
    assert states[1] == "unsettled"                    # still growing at t_end
    np.testing.assert_allclose(ds["max_deflection"].values, modal[:, 1], rtol=1e-12)


@pytest.mark.parametrize("rotation, n_modes", [("pinned", 4), ("clamped", 4), ("clamped", 5)])
def test_a_symmetric_span_shaken_by_its_clamps_stays_exactly_symmetric(rotation, n_modes):
    """Base excitation from rest, below, at and above the first resonance (0.6, 1.0, 1.5 f1,
    3 g): the symmetric modes move and the antisymmetric ones stay exactly 0 (the folded
    quadrature and the bases' exact zeros, docs/model.md sec. 7); seeded with 1e-9 m, mode
    2 moves (so exact symmetry is not an output that cannot change). Pinned sines and clamped
    ends, by quadrature (clamped 4 and 5 modes: their folded Gauss-Legendre rule)."""
    values = {"model.modes": n_modes, "clamps.rotation": rotation, "base.acceleration_g": 3.0,
              "load.amplitude": 0.0, "solver.t_end": 0.3, "metrics.tail": 0.5}
    ds = sweep.run(scene(values, {"base_frequency_ratio": [0.6, 1.0, 1.5]}), progress=False)
    modal = ds["modal_amplitude"].transpose("base_frequency_ratio", "mode").values
    assert np.all(modal[:, 0] > 1e-5)
    assert np.all(modal[:, 1::2] == 0.0), modal
    seed = [0.0] * n_modes
    seed[1] = 1e-9
    ds = sweep.run(scene({**values, "initial.modal_displacement": seed},
                         {"base_frequency_ratio": [1.0]}), progress=False)
    assert float(ds["modal_amplitude"].sel(mode=2).max()) > 1e-10


# ------------------------------------------------------- 6. the largest deflection over the span

@pytest.mark.parametrize("n_modes", [1, 2, 3, 6])
def test_span_maximum_is_the_dense_grids_maximum(n_modes):
    """kernels.modes.span_argmax (stations and Newton) against 200001 equally spaced stations
    for random modal coefficients: never above the grid's maximum by more than the grid's own
    miss (at most |w''| (dx / 2)^2 / 2, |w''| <= sum |q_n| (n pi)^2), never below it by more
    than 1e-12 relative; its place is where w has that value."""
    from sweep.kernels import modes as md
    rng = np.random.default_rng(n_modes)
    x = np.linspace(0.0, 1.0, 200001)
    shapes = np.sin(np.outer(np.arange(1, n_modes + 1), x) * math.pi)
    from sweep.models.basis import pinned_sines
    basis = pinned_sines(n_modes).kernel_arrays()
    for _ in range(200):
        q = rng.normal(size=n_modes) * rng.choice([1e-6, 1e-3, 1.0], size=n_modes)
        grid = float(np.max(np.abs(q @ shapes)))
        value, place = md.span_argmax(q, n_modes, basis)
        miss = np.sum(np.abs(q) * (np.arange(1, n_modes + 1) * math.pi) ** 2) \
            * (0.5 * (x[1] - x[0])) ** 2 / 2
        assert grid * (1 - 1e-12) <= value <= grid + miss, (q, value, grid)
        at_place = abs(q @ np.sin(np.arange(1, n_modes + 1) * math.pi * place))
        assert at_place == pytest.approx(value, rel=1e-12, abs=1e-300), (q, place)


SPAN_CASES = {
    # released from three modes at once (undamped-ish free vibration at 1, 4, 9 f1): the
    # largest deflection lies off midspan, between the modes' extrema in time
    "three-modes-free": dict(q0=[1e-3, 6e-4, 2e-4], zeta=0.01, load=0.0, ratio=0.0),
    # the same under a harmonic end load (0.48 Pcr at W = 1.5 w1)
    "three-modes-loaded": dict(q0=[2e-3, 1e-3, 3e-4], zeta=0.01, load=6.0, ratio=1.5),
    # modes 1 and 2 undamped: the midspan sees 68 % of the largest deflection
    "two-modes-undamped": dict(q0=[1e-3, -8e-4], zeta=0.0, load=0.0, ratio=0.0),
}
SPAN_T_END = 0.4               # s


@pytest.mark.parametrize("method", ["rk45", "dop853"])
@pytest.mark.parametrize("name", list(SPAN_CASES))
def test_max_deflection_is_the_largest_over_span_and_tail(name, method):
    """max_deflection (m) against tests/galerkin.py's dense output searched by brute force
    over the span and the tail window (a grid of instants and 801 stations, then Nelder-Mead
    in (t, x)), rtol 1e-10: within 1e-7 relative (measured: 2.4e-9 at worst), and 4.6-32 %
    above the midspan amplitude in every case (so the midspan could not pass for it); its
    place (max_deflection_position, m from the nearer clamp) within 1e-3 l of the search's."""
    c = SPAN_CASES[name]
    n = len(c["q0"])
    cable = Cable(length=LENGTH, damping_ratio=c["zeta"])
    sol = integrate(cable, n, c["q0"] + [0.0] * n, SPAN_T_END, max(c["q0"]),
                    load_amplitude=c["load"], load_omega=c["ratio"] * cable.w1)
    ref, place = span_tail_argmax(sol, n, SPAN_T_END, 0.5,
                                  fastest_hz=n ** 2 * cable.w1 / (2 * math.pi))
    values = {"model.modes": n, "cable.damping_ratio": c["zeta"], "load.amplitude": c["load"],
              "solver.t_end": SPAN_T_END, "solver.rtol": 1e-10, "solver.method": method,
              "metrics.tail": 0.5, "initial.modal_displacement": c["q0"]}
    if c["load"]:
        values["load.frequency_ratio"] = c["ratio"]
    ds = sweep.run(scene(values, {"damping_ratio": [c["zeta"]]}))
    assert ds["max_deflection"].attrs["units"] == "m"
    largest = float(ds["max_deflection"].values[0])
    assert abs(largest / ref - 1.0) < 1e-7, (largest, ref)
    assert largest > 1.04 * float(ds["amplitude"].values[0])
    position = ds["max_deflection_position"]
    assert position.attrs["units"] == "m"
    assert abs(float(position.values[0]) - min(place, 1.0 - place) * LENGTH) < 1e-3 * LENGTH


SWEPT_T = dict(start=100.0, stop=180.0, rate=60.0, ramp_cycles=10.0)   # Hz, Hz, oct/min, 1


def swept_scene(zeta: float, level: str, direction: str = "", rtol: float = 1e-10
                ) -> sweep.Scene:
    """A log sweep (SWEPT_T) of three modes of the Table 1 span at damping ratio zeta, the
    [base] level line `level`, `direction` ('direction = "both", ' or nothing)."""
    s = SWEPT_T
    return sweep.load_scene_text(f"""name = "swept-span"
[model]
modes = 3
membrane = 0.375
[cable]
youngs_modulus = {E!r}
density = {RHO!r}
area = {AREA!r}
inertia = {INERTIA!r}
length = {LENGTH!r}
damping_ratio = {zeta!r}
[load]
amplitude = 0.0
[base]
{level}
sweep = {{ start = {s['start']!r}, stop = {s['stop']!r}, rate = {s['rate']!r}, {direction}ramp_cycles = {s['ramp_cycles']!r} }}
[solver]
rtol = {rtol!r}
""")


def test_a_sine_sweeps_largest_deflection_over_the_span():
    """A log sweep of three modes through mode 3's resonance (9 f1 = 137 Hz, the clamps at
    2 g): max_deflection over the whole sweep and its place against tests/galerkin.py's
    equations under the same swept base (docs/model.md sec. 6: f_s 2^(r t / 60), the level's
    (1 - cos)/2 rise over ramp_cycles / f_s) integrated by SciPy DOP853 and searched by brute
    force over the sweep and the span: within 1e-6 relative, and well above the midspan's
    peak_amplitude (8.6 % above it: mode 3 moves the crest off midspan)."""
    s = SWEPT_T
    zeta, accel = 0.01, 2.0 * G
    cable = Cable(length=LENGTH, damping_ratio=zeta)
    lam = s["rate"] * math.log(2.0) / 60.0
    duration = math.log(s["stop"] / s["start"]) / lam
    rise = s["ramp_cycles"] / s["start"]
    proj = Projection(cable, 3)
    damping = 2.0 * zeta * cable.w1 * np.arange(1, 4) ** 2
    gamma = participation(3)

    def rhs(t, y):
        ramp = 0.5 - 0.5 * math.cos(math.pi * t / rise) if t < rise else 1.0
        a_b = accel * ramp * math.sin(2.0 * math.pi * s["start"] * math.expm1(lam * t) / lam)
        return np.concatenate((y[3:], -damping * y[3:] - proj.force(y[:3], 0.0) - gamma * a_b))

    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (0.0, duration), np.zeros(6), method="DOP853", rtol=1e-11,
                    atol=np.r_[np.full(3, 1e-15), np.full(3, 1e-12)], dense_output=True)
    assert sol.success
    ref, place = span_tail_argmax(sol.sol, 3, duration, 1.0, fastest_hz=s["stop"])
    ds = sweep.run(swept_scene(zeta, f"acceleration = {accel!r}"), progress=False)
    largest = float(ds["max_deflection"])
    assert "whole sweep" in ds["max_deflection"].attrs["long_name"]
    assert abs(largest / ref - 1.0) < 1e-6, (largest, ref)
    assert largest > 1.05 * float(ds["peak_amplitude"])     # measured 1.086
    nearer = min(place, 1.0 - place) * LENGTH
    assert abs(float(ds["max_deflection_position"]) - nearer) < 1e-3 * LENGTH
    assert nearer < 0.45 * LENGTH                     # off midspan


def test_one_mode_stores_no_max_deflection():
    """One mode: the largest deflection is the midspan's (amplitude), so no second copy."""
    ds = sweep.run(scene({"model.modes": 1, "solver.t_end": 0.05,
                          "initial.modal_displacement": [1e-4]}))
    assert "max_deflection" not in ds and "max_deflection_position" not in ds


# ------------------------------------------------------------------------------ 7. refusals

@pytest.mark.parametrize("values, key", [
    ({"model.modes": 2, "model.coefficients": "paper"}, "modes"),
    ({"model.modes": 2, "initial.modal_displacement": [1e-3]}, "modal_displacement"),
    ({"model.modes": 2, "initial.modal_velocity": [0.0, 0.0, 0.0]}, "modal_velocity"),
    ({"model.modes": 2, "initial.modal_displacement": [1e-3, 0.0],
      "initial.displacement": 1e-3}, "displacement"),
    ({"model.modes": 0}, "modes"),
])
def test_bad_modes_input_is_refused_with_one_line(values, key):
    """modes > 1 with the paper preset, a modal list of the wrong length, both spellings of the
    initial displacement, modes < 1: one UserError line naming the key."""
    with pytest.raises(UserError) as err:
        sweep.run(scene({"load.amplitude": 0.0, "solver.t_end": 0.01, **values}))
    message = str(err.value)
    assert "\n" not in message and key in message


def _both_right_hand_sides(row, basis, y, t, base):
    """(derivative's dy, lanes_derivative's with one lane) of a raw row on kernel arrays
    `basis` at state y, time t; the lanes' with the basis' coefficients and with the lane's
    own copy of them (a family's lanes, kernels.modes.write_lane_basis), the same bits."""
    dy, shared, own = _both_kernel()(row, basis, y, t, base)
    np.testing.assert_array_equal(own, shared)
    return dy, shared


@functools.cache
def _both_kernel():
    """The compiled pair of right-hand sides `_both_right_hand_sides` calls (compiled once)."""
    import numba as nb
    from sweep.kernels import modes as md

    @nb.njit
    def both(row, basis, y, t, base):
        n = md.basis_modes(basis)
        T = basis[md.TABLES]
        S = md.row_scratch(row, basis)
        dy = np.empty(2 * n)
        md.derivative(t, y, dy, S, n, T, base)
        pp = S[0]
        PP = np.empty((pp.shape[0], 1))         # one lane of the lanes driver's arrays
        PP[:, 0] = pp
        X = np.empty((2 * n, 1))
        X[:, 0] = y
        K = np.empty((1, 2 * n, 1))
        tt = np.full(1, t)
        FLD = np.empty((4, md.field_rows(basis), 1))
        LB = md.lane_basis(basis, 1)
        md.lanes_derivative(tt, X, K, 0, PP, n, T, FLD, np.empty((4, 1)), 1, None, base,
                            basis[md.COUPLING], basis[md.POLYNOMIAL], LB, False)
        shared = K[0, :, 0].copy()
        # the lane's own copy of the basis (a family's lanes): the same bits
        md.lanes_derivative(tt, X, K, 0, PP, n, T, FLD, np.empty((4, 1)), 1, None, base,
                            basis[md.COUPLING], basis[md.POLYNOMIAL], LB, True)
        return dy, shared, K[0, :, 0].copy()
    return both


def _force_scene(n_modes, rotation, membrane):
    """(raw row, kernel arrays) of a 0.4 m span of n_modes modes with an end load and base
    excitation; rotation: clamps.rotation ("elastic": 20 N m/rad); membrane: model.membrane
    (None: the uniform tension and the energy's bending terms)."""
    from sweep.models.transverse import modal_rows, resolve
    text = (f'[model]\nmodes = {n_modes}\ncoefficients = "consistent"\n'
            + (f"membrane = {membrane}\n" if membrane is not None else "")
            + f'[clamps]\nrotation = "{rotation}"\n'
            + ('rotational_stiffness = "20 N m"\n' if rotation == "elastic" else "")
            + '[cable]\nlinear_mass = "53.4 g/m"\nbending_rigidity = "0.31515 N m^2"\n'
            'axial_rigidity = "660 kN"\ndiameter = "2.76 mm"\ndamping_ratio = 0.02\n'
            'length = 0.4\n[load]\namplitude = 3.0\nfrequency_ratio = 1.3\n'
            '[base]\nacceleration_g = 2.0\nfrequency = 40.0\n')
    inputs = resolve(sweep.load_scene_text(text))
    return modal_rows(inputs, np.arange(1))[0].copy(), inputs.basis.kernel_arrays()


@pytest.mark.parametrize("polynomial", [False, True])
@pytest.mark.parametrize("rotation, membrane", [("pinned", 0.375), ("pinned", None),
                                                ("clamped", None)])
def test_the_one_state_right_hand_side_is_the_lanes_one(rotation, membrane, polynomial):
    """kernels.modes.derivative (the scalar driver's loop order) against lanes_derivative with
    one lane (the lanes driver's, libm's cos): the same physics to round-off (1e-14 of the
    largest component) at random states and times, with the base excitation and without, for
    Eq.17's terms with the local membrane and the energy's with the uniform tension (clamped
    modes too), the force by quadrature and as its polynomial; both drivers are checked against
    independent references elsewhere."""
    from sweep.models.basis import with_force_form
    row, arrays = _force_scene(4, rotation, membrane)
    basis = with_force_form(arrays, polynomial)
    rng = np.random.default_rng(5)
    for base in (True, None):
        for _ in range(10):
            y = rng.normal(size=8) * np.r_[np.full(4, 5e-3), np.full(4, 2.0)]
            got, want = _both_right_hand_sides(row, basis, y, rng.uniform(0.0, 2.0), base)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-14 * np.abs(want).max())


@pytest.mark.parametrize("n_modes", [1, 2, 3, 5])
@pytest.mark.parametrize("rotation, membrane", [("pinned", 0.375), ("pinned", None),
                                                ("clamped", None), ("elastic", None)])
def test_the_force_s_polynomial_is_its_quadrature(rotation, membrane, n_modes):
    """The force expanded into each mode's polynomial in q (sweep.models.basis.force_polynomial,
    from kernels.modes.FORCE_TERMS: the terms as data) against the same force summed at the
    quadrature nodes by the node functions the right-hand side has always used (_axial,
    _energy_bending, _eq17_bending): equal to round-off (1e-14 of the largest component) at
    random states of every size up to the buckled span's, with and without base excitation,
    through both the one-state and the lanes' right-hand side, for Eq.17's terms, the energy's,
    and clamped and elastic ends (their non-diagonal coupling)."""
    from sweep.models.basis import with_force_form
    row, arrays = _force_scene(n_modes, rotation, membrane)
    _assert_the_same_force(row, with_force_form(arrays, False), with_force_form(arrays, True),
                           n_modes, seed=11)


def _assert_the_same_force(row, reference, other, n, seed):
    """Both right-hand sides on kernel arrays `other` against the one-state right-hand side on
    `reference`, at random states of every size up to the buckled span's (and the same states
    with their antisymmetric modes at rest), times and with and without base excitation: equal
    to 1e-14 of the largest component."""
    rng = np.random.default_rng(seed)
    for base in (True, None):
        for size in (1e-4, 5e-3, 2e-2):
            y = rng.normal(size=2 * n) * np.r_[np.full(n, size), np.full(n, 2.0)]
            symmetric = y.copy()
            symmetric[1:n:2] = 0.0
            symmetric[n + 1::2] = 0.0
            t = rng.uniform(0.0, 2.0)
            for state in (y, symmetric):
                want, _ = _both_right_hand_sides(row, reference, state, t, base)
                for got in _both_right_hand_sides(row, other, state, t, base):
                    np.testing.assert_allclose(got, want, rtol=0,
                                               atol=1e-14 * np.abs(want).max())


@pytest.mark.parametrize("n_modes", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("rotation, membrane", [("pinned", 0.375), ("pinned", None),
                                                ("clamped", None), ("elastic", None)])
def test_the_folded_quadrature_is_the_node_by_node_one(rotation, membrane, n_modes):
    """The quadrature folded about midspan (sweep.models.basis.mirrored_quadrature: half the
    nodes, each standing for its mirror node too; the forces projected a pair at a time)
    against the same tables read node by node: equal to round-off (1e-14 of the largest
    component) at random states, symmetric modes and antisymmetric ones together and the
    antisymmetric ones at rest (the skipped half), through both right-hand sides, for odd and
    even node counts (pinned sines: 3N; clamped and elastic:
    6N + 12). The node-by-node sum is checked against independent references elsewhere."""
    from sweep.models.basis import with_force_form
    row, arrays = _force_scene(n_modes, rotation, membrane)
    folded = with_force_form(arrays, False)
    by_nodes = with_force_form(arrays, False, mirrored=False)
    assert np.all(folded[0][7] != 0.0) and not np.any(by_nodes[0][7])
    assert folded[0].shape[2] == (by_nodes[0].shape[2] + 1) // 2
    _assert_the_same_force(row, by_nodes, folded, n_modes, seed=13)


def test_tables_fold_only_where_they_mirror():
    """mirrored_quadrature unfolds back to the tables it folded (every built-in end
    condition, odd and even node counts: pinned 3 and 4 modes have 9 and 12 nodes), finds the
    modes' parities (+1, -1, +1, ...), and leaves whole, parity row 0, tables that do not
    mirror about midspan: one mode's curvature perturbed at one node by 1e-9, or nodes placed
    off symmetry."""
    from sweep.models.basis import (clamped, elastic_ends, from_shapes, mirrored_quadrature,
                                    pinned_sines)
    for basis in (pinned_sines(3), pinned_sines(4), clamped(3), elastic_ends(4, 5.0)):
        folded = mirrored_quadrature(basis.tables)
        assert folded.shape[2] == (basis.tables.shape[2] + 1) // 2
        assert list(folded[7, :, 0]) == [1.0 if i % 2 == 0 else -1.0
                                         for i in range(basis.n_modes)]
        np.testing.assert_allclose(unfolded_tables(folded), basis.tables,
                                   rtol=0, atol=1e-14 * np.abs(basis.tables).max())
    tables = clamped(3).tables.copy()
    tables[1, 2, 0] *= 1.0 + 1e-9
    assert not np.any(mirrored_quadrature(tables)[7])
    shifted = from_shapes("shifted", clamped(2).shapes, 20).tables[:, :, 1:]   # 19 of 20 nodes
    assert not np.any(mirrored_quadrature(shifted)[7])
    np.testing.assert_array_equal(unfolded_tables(mirrored_quadrature(shifted)), shifted)


def test_the_polynomial_is_chosen_where_it_costs_less():
    """sweep.models.basis.polynomial_pays (the rule measured by benchmarks/rhs_cost.py): the
    polynomial for clamped and elastic ends of up to 4 modes, whose Gauss-Legendre rule needs
    6 N + 12 nodes (3 N + 6 folded); never for pinned sines, whose 3 N (folded: half) cost as
    little; never above POLYNOMIAL_MAX_MODES."""
    from sweep.kernels import modes as md
    from sweep.models.basis import POLYNOMIAL_MAX_MODES, clamped, elastic_ends, pinned_sines
    for n in range(1, 8):
        assert not md.uses_polynomial(pinned_sines(n).kernel_arrays())
        assert md.uses_polynomial(clamped(n).kernel_arrays()) == (n <= 4)
        assert md.uses_polynomial(elastic_ends(n, 3.0).kernel_arrays()) == (n <= 4)
    assert POLYNOMIAL_MAX_MODES < 8


def test_either_force_form_is_one_type_to_the_kernels():
    """A basis whose force is its polynomial and one read by quadrature are the same Numba
    type (the quadrature's an empty polynomial, kernels.modes.no_polynomial), alone and as a
    lanes call's family: pinned, clamped and elastic spans of N modes run on one compiled
    driver, which picks the form at run time (before, a clamped scene after a pinned one
    compiled every modal driver again)."""
    import numba as nb

    from sweep.kernels import modes as md
    from sweep.models.basis import clamped, elastic_ends, pinned_sines
    for n in (2, 3, 5):
        bases = [pinned_sines(n).kernel_arrays(), clamped(n).kernel_arrays(),
                 elastic_ends(n, 3.0).kernel_arrays()]
        assert [md.uses_polynomial(b) for b in bases] == [False, n <= 4, n <= 4]
        assert len({nb.typeof(b) for b in bases}) == 1
        assert len({nb.typeof(md.stacked([b])) for b in bases}) == 1     # a lanes call's
        assert md.stacked(bases[:1] * 2) is None      # (bases by quadrature do not stack)
        assert not md.has_polynomial.py_func(md.no_polynomial(n))


def test_one_modes_modal_lists_are_its_initial_state():
    """model.modes = 1 with initial.modal_displacement / modal_velocity (one entry each): the
    same run as initial.displacement / velocity (a reviewer found the lists accepted and then
    ignored: the span started at rest and read 'decayed', amplitude 0)."""
    text = ("[model]\nmodes = 1\n[cable]\nlength = 0.5\ndamping_ratio = 0.02\n[load]\n"
            "amplitude = 0.0\n[initial]\n{init}\n[solver]\nt_end = 0.1\n")
    listed = sweep.run(sweep.load_scene_text(text.format(
        init="modal_displacement = [1e-3]\nmodal_velocity = [0.05]")), progress=False)
    single = sweep.run(sweep.load_scene_text(text.format(
        init="displacement = 1e-3\nvelocity = 0.05")), progress=False)
    assert float(listed.peak_amplitude) > 1e-3
    for name in ("peak_amplitude", "amplitude", "state"):
        assert float(listed[name]) == float(single[name])


def test_a_sweep_up_and_down_keeps_each_directions_largest_deflection():
    """direction = "both": max_deflection and its place are each direction's (a reviewer found
    the place of the up sweep stored for both)."""
    ds = sweep.run(swept_scene(0.01, "acceleration_g = 2.0", 'direction = "both", ',
                               rtol=1e-8), progress=False)
    for name in ("max_deflection", "max_deflection_position"):
        assert ds[name].dims[0] == "direction", name
    up, down = (float(ds["max_deflection"].sel(direction=d)) for d in ("up", "down"))
    assert up != down
