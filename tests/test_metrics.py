"""In-kernel metrics on signals with known answers (closed forms, or SciPy at tight tolerance)."""

from __future__ import annotations

import functools
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


def _period2_row() -> np.ndarray:
    """Consistent model, l = 0.943 m, zeta = 0.0378, P0 = 11.81 N at W/w1 = 0.9467, q0 = 3e-4 m
    (the paper's inertia 5.73e-12 m^4 written out): a period-2 orbit, maxima at two levels."""
    from sweep import models
    from sweep.kernels import oscillator as osc
    c = models.oscillator(dict(
        youngs_modulus=1.1e11, density=8900.0, area=6e-6, inertia=5.73e-12, length=0.943,
        membrane=0.375, load_amplitude=11.81, damping_ratio=0.0378, frequency_ratio=0.9467,
        initial_displacement=3e-4, initial_velocity=0.0, coefficients="consistent",
        load_type="harmonic", paper_parametric="printed"))
    return np.array([float(c[name]) for name in osc.PARAM_NAMES])


@functools.lru_cache(maxsize=1)
def _period2_reference() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(times, q, is_maximum) of the extrema of _period2_row over 60 s, DOP853 at rtol 1e-12."""
    row = _period2_row()
    sol = solve_ivp(rhs(row), (0, 60.0), row[8:10], method="DOP853", rtol=1e-12, atol=1e-16,
                    dense_output=True)
    times, peaks = _envelope_peaks(sol, 0.0, 60.0)
    # q'' < 0 at a maximum (q' = 0 there).
    is_max = -(row[2] * peaks + row[4] * peaks ** 3 + row[6] * peaks ** 5
               + (row[3] * peaks + row[5] * peaks ** 3) * np.cos(row[7] * times)) < 0
    return times, peaks, is_max


@pytest.mark.slow
@pytest.mark.parametrize("driver", ["scalar", "lanes"])
def test_period_two_orbit_is_steady_with_its_true_period(driver):
    """Maxima alternating between two levels: steady, period two maxima long, settling time the
    last extremum off its own level; checked against DOP853 at rtol 1e-12 over 60 s."""
    row = _period2_row()
    t_end, tol = 13.0, 0.02
    states, reals, _, _ = solve(row, settings(t_end=t_end, tol=tol, rtol=1e-10), driver=driver)
    times, peaks, is_max = _period2_reference()
    t_max, q_max = times[is_max], peaks[is_max]
    # The reference: after 40 s, maxima 2 apart repeat to 1e-9 m (a period-2 orbit: the
    # Poincare return of every second maximum), neighbours differ by far more than the band.
    late = t_max > 40.0
    assert np.ptp(q_max[late][::2]) < 1e-9 and np.ptp(q_max[late][1::2]) < 1e-9
    assert abs(q_max[late][0] - q_max[late][1]) > 5 * tol * q_max.max()
    period = np.mean(t_max[late][2::2] - t_max[late][:-2:2])
    assert period == pytest.approx(2 * (2 * np.pi / row[7]), rel=1e-9)   # locked at W / 2
    assert states[0] == km.STEADY
    # response_period: two maxima spacings, over a whole number of periods of the tail.
    tail = t_max[(t_max >= t_end / 2) & (t_max < t_end)]
    whole = (tail.size - 1) // 2
    assert reals[0, tk.PERIOD] == pytest.approx((tail[-1] - tail[-1 - 2 * whole]) / whole,
                                                rel=1e-8)
    assert reals[0, tk.PERIOD] == pytest.approx(period, rel=1e-6)   # the transient is gone
    # Settling: the last extremum before t_end farther than tol * A from the final level of its
    # own class (kind, and position from the end modulo 2).
    amp = reals[0, tk.AMPLITUDE]
    expected = 0.0
    for kind in (True, False):
        mine = (is_max == kind) & (times < t_end)
        t_k, q_k = times[mine], peaks[mine]
        level = np.where(np.arange(q_k.size)[::-1] % 2 == 0, q_k[-1], q_k[-2])
        off = np.abs(q_k - level) > tol * amp
        expected = max(expected, t_k[off][-1])
    assert 0.5 < expected < t_end / 2
    assert reals[0, tk.SETTLING] == pytest.approx(expected, rel=1e-6)


def _buffer(times, values, kinds) -> tuple[np.ndarray, int]:
    buf = np.column_stack([times, values, kinds]).astype(float)
    return buf, buf.shape[0]


def _extrema(levels_max, levels_min, n_periods, spacing=0.1):
    """Alternating maxima and minima, the maxima cycling through levels_max, the minima through
    levels_min; one extremum every spacing/2 s."""
    values = []
    for i in range(n_periods * len(levels_max)):
        values += [levels_max[i % len(levels_max)], levels_min[i % len(levels_min)]]
    times = 0.5 * spacing * np.arange(len(values))
    kinds = np.tile([km.MAXIMUM, km.MINIMUM], len(values) // 2)
    return times, np.array(values), kinds


def test_three_level_orbit_is_period_three_and_settles_after_its_transient():
    times, values, kinds = _extrema([1.0, 1.3, 1.15], [-1.1, -0.9, -1.2], 12)
    values[:7] *= 1.5                      # a transient in the first 7 extrema
    buf, n = _buffer(times, values, kinds)
    t_end = times[-1] + 0.05
    t_tail = t_end / 2
    n_max, n_min, _ = km.tail_counts(buf, n, t_tail)
    band = 0.02 * 1.3
    assert km.last_envelope_violation(buf, n, band) >= t_tail      # k = 1 does not hold
    k, t_settle = km.periodic_order(buf, n, t_tail, band, n_max, n_min)
    assert k == 3                                                   # not 6: the smallest k
    assert t_settle == times[6]
    assert km.orbit_period(buf, n, t_tail, k) == pytest.approx(3 * 0.1, rel=1e-12)


def test_quasi_periodic_and_drifting_extrema_are_not_periodic_orbits():
    j = np.arange(96)
    golden = (np.sqrt(5) - 1) / 2
    t = 0.05 * np.arange(2 * j.size)
    kinds = np.tile([km.MAXIMUM, km.MINIMUM], j.size)
    band = 0.02
    cases = {
        "quasi-periodic": 1 + 0.2 * np.cos(2 * np.pi * golden * j),
        # Decaying by 1.1 bands over the tail's 47 spacings: a class k = 8 apart spans only
        # 39 of them (0.91 bands); the last 8 levels differ by far less than the band.
        "drifting": 1.0 + 1.1 * band / 47 * (j[-1] - j),
    }
    for name, maxima in cases.items():
        values = np.empty(2 * j.size)
        values[0::2], values[1::2] = maxima, -maxima
        buf, n = _buffer(t, values, kinds)
        t_tail = t[-1] / 2
        n_max, n_min, _ = km.tail_counts(buf, n, t_tail)
        assert n_max >= km.MIN_PER_CLASS * km.MAX_ORDER               # enough extrema for every k
        assert km.last_envelope_violation(buf, n, band) >= t_tail, name
        assert km.periodic_order(buf, n, t_tail, band, n_max, n_min)[0] == 0, name


def _unsettled_share(scene) -> float:
    import sweep
    states = sweep.run(scene).state.values
    return np.mean(states == km.UNSETTLED)


def test_builtin_harness_scene_gives_answers():
    """At most 1 % of its 390 points unsettled (the scene's comment names the 2 left: on a
    zone's edge, where decay rates go to zero); 43 were with t_end = 10 s."""
    import sweep
    assert _unsettled_share(sweep.load_scene("harness-parametric")) <= 0.01


def test_readme_example_scene_gives_answers():
    """The toml block under "Scene files" in README.md (4 lengths x 251 frequency ratios): at
    most 1 % unsettled (694 of 1 004 were with t_end = 5 s)."""
    import pathlib
    import sweep
    text = (pathlib.Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    block = text[text.index("```toml", text.index("## Scene files")) + len("```toml"):]
    scene = sweep.load_scene_text(block[:block.index("```")])
    assert len(scene.axes["frequency_ratio"]) * len(scene.axes["length"]) == 1004
    assert _unsettled_share(scene) <= 0.01
