"""In-kernel metrics on signals with known answers (closed forms, or SciPy at tight tolerance)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from sweep.kernels import metrics as km
from sweep.kernels import transverse as tk

from conftest import param_row, rhs, settings, solve


def test_decaying_sinusoid_settling_time_is_analytic():
    """q'' + 2 zeta w q' + w^2 q = 0, q(0) = 1: the last time |q| > tol, from the closed form."""
    w, zeta, tol = 2 * np.pi * 5.0, 0.05, 0.02
    sigma = zeta * w
    wd = w * np.sqrt(1 - zeta ** 2)

    def q(t):
        return np.exp(-sigma * t) * (np.cos(wd * t) + sigma / wd * np.sin(wd * t))

    # Extrema of q sit at n pi / wd with |q| = exp(-sigma n pi / wd); the peak is q(0) = 1.
    n_last = int(np.floor(np.log(1 / tol) * wd / (sigma * np.pi)))
    t_n = n_last * np.pi / wd
    t_zero = brentq(q, t_n, t_n + np.pi / wd) if q(t_n) > 0 else brentq(q, t_n, t_n + np.pi / wd)
    t_settle = brentq(lambda t: abs(q(t)) - tol, t_n, t_zero, xtol=1e-14)

    row = param_row(c=2 * zeta * w, k0=w * w, q0=1.0)
    states, reals, _, _ = solve(row, settings(t_end=10.0, tol=tol, rtol=1e-10))
    assert states[0] == km.DECAYED
    assert reals[0, tk.SETTLING] == pytest.approx(t_settle, rel=1e-7)
    assert reals[0, tk.PEAK] == pytest.approx(1.0, rel=1e-12)


def test_undamped_linear_oscillator_is_steady_with_exact_period_and_amplitude():
    w = 2 * np.pi * 3.0
    row = param_row(k0=w * w, q0=2e-3)
    states, reals, _, _ = solve(row, settings(t_end=4.0, rtol=1e-10))
    assert states[0] == km.STEADY
    assert reals[0, tk.SETTLING] == 0.0          # periodic from t = 0: no transient at all
    assert reals[0, tk.PERIOD] == pytest.approx(2 * np.pi / w, rel=1e-8)
    assert reals[0, tk.AMPLITUDE] == pytest.approx(2e-3, rel=1e-8)


def _envelope_peaks(sol, t0, t1):
    """(times, q) of the extrema of q on [t0, t1] of a dense SciPy solution."""
    t = np.linspace(t0, t1, 200001)
    v = sol.sol(t)[1]
    times = [brentq(lambda s: sol.sol(s)[1], t[i], t[i + 1], xtol=1e-14)
             for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]]
    return np.array(times), sol.sol(np.array(times))[0]


def test_post_buckled_settling_time_matches_scipy_envelope():
    """Damped oscillation onto q_s = 1 (k0 = -1, g0 = 1): the same definition on DOP853's peaks."""
    row = param_row(c=1.0, k0=-1.0, g0=1.0, q0=0.2)
    t_end, tol = 60.0, 0.02
    states, reals, _, _ = solve(row, settings(t_end=t_end, tol=tol, rtol=1e-10))
    assert states[0] == km.STEADY
    sol = solve_ivp(rhs(row), (0, t_end), row[8:10], method="DOP853", rtol=1e-13, atol=1e-15,
                    dense_output=True)
    times, peaks = _envelope_peaks(sol, 0.0, t_end)
    # A maximum where q'' = -(k0 q + g0 q^3) < 0 (v = 0 at an extremum).
    is_max = -(row[2] * peaks + row[4] * peaks ** 3) < 0
    tail_amp = reals[0, tk.AMPLITUDE]
    assert tail_amp == pytest.approx(1.0, rel=1e-4)
    level_max, level_min = peaks[is_max][-1], peaks[~is_max][-1]
    level = np.where(is_max, level_max, level_min)
    outside = np.abs(peaks - level) > tol * tail_amp
    expected = times[outside][-1]
    assert reals[0, tk.SETTLING] == pytest.approx(expected, rel=1e-7)


def test_overdamped_creep_settles_on_final_value():
    """No extrema at all (c = 5): settling is the last time |q - q_end| > tol * A."""
    row = param_row(c=5.0, k0=-1.0, g0=1.0, q0=0.1)
    t_end, tol = 40.0, 0.02
    states, reals, _, _ = solve(row, settings(t_end=t_end, tol=tol, rtol=1e-10))
    assert states[0] == km.STEADY
    sol = solve_ivp(rhs(row), (0, t_end), row[8:10], method="DOP853", rtol=1e-13, atol=1e-15,
                    dense_output=True)
    q_end = sol.y[0, -1]
    amp = reals[0, tk.AMPLITUDE]
    expected = brentq(lambda t: q_end - sol.sol(t)[0] - tol * amp, 0.0, t_end, xtol=1e-13)
    assert reals[0, tk.SETTLING] == pytest.approx(expected, rel=1e-6)


def test_beating_is_modulated_without_settling_time():
    """Mathieu oscillator just outside its principal zone: bounded, strongly beating."""
    w, eps = 2 * np.pi, 0.2
    row = param_row(k0=w * w, k1=eps * w * w, omega=2 * w * 1.1, q0=1e-3)
    t_end = 40.0
    states, reals, _, _ = solve(row, settings(t_end=t_end))
    sol = solve_ivp(rhs(row), (0, t_end), row[8:10], method="DOP853", rtol=1e-12, atol=1e-15,
                    dense_output=True)
    _, peaks = _envelope_peaks(sol, t_end / 2, t_end)
    env = np.abs(peaks)
    assert env.max() > 1.2 * env.min()                 # the reference really beats
    assert states[0] == km.MODULATED
    assert math.isnan(reals[0, tk.SETTLING])


def test_growing_parametric_resonance_is_unsettled():
    """Inside the principal zone with no nonlinearity: exponential growth, bounded run."""
    w, eps = 2 * np.pi, 0.2
    row = param_row(k0=w * w, k1=eps * w * w, omega=2 * w, q0=1e-6)
    states, reals, _, _ = solve(row, settings(t_end=20.0))
    sol = solve_ivp(rhs(row), (0, 20.0), row[8:10], method="DOP853", rtol=1e-12, atol=1e-18)
    assert np.max(np.abs(sol.y[0])) > 100 * 1e-6       # the reference grows
    assert states[0] == km.UNSETTLED
    assert math.isnan(reals[0, tk.SETTLING])


def test_finite_time_blow_up_is_diverged_at_the_right_time():
    """q'' = q + q^3 from q = 1 blows up; stopped where |q| crosses the bound."""
    bound = 10.0
    row = param_row(k0=-1.0, g0=-1.0, q0=1.0, bound=bound)
    states, reals, _, _ = solve(row, settings(t_end=5.0))

    def cross(t, y):
        return y[0] - bound
    cross.terminal = True
    sol = solve_ivp(rhs(row), (0, 5.0), row[8:10], method="DOP853", rtol=1e-13, atol=1e-15,
                    events=cross)
    assert states[0] == km.DIVERGED
    assert reals[0, tk.FAILURE_TIME] == pytest.approx(sol.t_events[0][0], rel=1e-7)
    assert math.isnan(reals[0, tk.AMPLITUDE])


def test_at_rest_is_decayed_with_zero_settling():
    states, reals, _, _ = solve(param_row(k0=4.0), settings(t_end=1.0))
    assert states[0] == km.DECAYED
    assert reals[0, tk.AMPLITUDE] == 0.0 and reals[0, tk.SETTLING] == 0.0


@pytest.mark.parametrize("bad", [dict(m=0.0), dict(k0=math.nan), dict(g1=math.inf),
                                 dict(bound=-1.0)])
def test_invalid_point_gets_a_status_and_never_raises(bad):
    rows = np.stack([param_row(k0=1e4, q0=1e-3), param_row(**{"k0": 1e4, "q0": 1e-3, **bad})])
    states, reals, _, _ = solve(rows, settings(t_end=1.0))
    assert states[1] == km.INVALID_INPUT and np.isnan(reals[1]).all()
    assert states[0] == km.STEADY


def test_max_steps_bounds_the_work():
    states, reals, counts, _ = solve(param_row(k0=1e6, q0=1e-3), settings(t_end=10.0,
                                                                          max_steps=50))
    assert states[0] == km.MAX_STEPS and counts[0, tk.STEPS] == 50
    assert 0 < reals[0, tk.FAILURE_TIME] < 10.0


def test_settling_switched_off_is_not_computed():
    row = param_row(c=4.0, k0=100.0, q0=1.0)
    states, reals, counts, _ = solve(row, settings(t_end=10.0, settling=False))
    assert states[0] == km.DECAYED and math.isnan(reals[0, tk.SETTLING])


def test_response_period_of_principal_parametric_resonance_is_twice_the_load_period():
    """Saturated by a hardening cubic, the response locks at W/2."""
    w, eps = 2 * np.pi, 0.4
    W = 2 * w
    row = param_row(c=2 * 0.05 * w, k0=w * w, k1=eps * w * w, g0=w * w * 1e4, omega=W, q0=1e-4)
    states, reals, _, _ = solve(row, settings(t_end=60.0))
    assert states[0] == km.STEADY
    assert reals[0, tk.PERIOD] == pytest.approx(2 * (2 * np.pi / W), rel=1e-4)


def test_points_are_independent_of_their_neighbours_and_of_threads():
    import numba
    rng = np.random.default_rng(1)
    rows = np.stack([param_row(c=rng.uniform(0, 1), k0=rng.uniform(1, 100),
                               k1=rng.uniform(0, 50), g0=rng.uniform(0, 1e4),
                               omega=rng.uniform(1, 30), q0=rng.uniform(-0.1, 0.1))
                     for _ in range(40)])
    rows[7] = param_row(k0=-1.0, g0=-1.0, q0=1.0, bound=5.0)   # a diverging neighbour
    s = settings(t_end=3.0, sample_dt=0.05)
    alone = [solve(rows[i], s, 61) for i in (3, 8)]
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = solve(rows, s, 61)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = solve(rows, s, 61)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a, b)
    for j, i in enumerate((3, 8)):
        for a, b in zip(alone[j], one):
            np.testing.assert_array_equal(a[0], b[i])
    assert one[0][7] == km.DIVERGED
