"""The kernels against SciPy: the same steps as solve_ivp(RK45) and solve_ivp(DOP853) (solver.method
"dop853"), the same answer as DOP853 at tight tolerance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from sweep.kernels import dop853
from sweep.kernels import metrics as km
from sweep.kernels import transverse as tk
from sweep import models

from conftest import param_row, rhs, settings, solve


def consistent_row(length=0.7, ratio=2.0, zeta=0.02, q0=1e-3, load=4.0, load_type="harmonic"):
    """A kernel row of the consistent model for the Table 1 cable."""
    p = dict(youngs_modulus=1.1e11, density=8900.0, area=6e-6, inertia=5.73e-12,
             length=length, membrane=0.375, load_amplitude=load, damping_ratio=zeta,
             frequency_ratio=ratio, frequency=None, initial_displacement=q0,
             initial_velocity=0.0, coefficients="consistent", load_type=load_type,
             paper_parametric="printed", divergence_bound=None)
    c = models.oscillator(p)
    return param_row(*(c[name] for name in ("mass", "damping", "k0", "k1", "g0", "g1", "h",
                                            "omega", "q0", "v0", "bound")))


CASES = {
    "paper l=1": lambda paper: paper,
    "consistent resonance": lambda paper: consistent_row(),
    "consistent off-resonance": lambda paper: consistent_row(length=0.4, ratio=1.3, q0=2e-3),
    "constant load above buckling": lambda paper: consistent_row(length=1.0, load=8.0,
                                                                 load_type="constant"),
}


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("rtol", [1e-5, 1e-8])
def test_same_steps_as_scipy_rk45(case, rtol, paper_row):
    row = CASES[case](paper_row)
    t_end = 2.0
    sol = solve_ivp(rhs(row), (0.0, t_end), row[8:10], method="RK45", rtol=rtol, atol=1e-12)
    assert sol.status == 0
    states, reals, counts, _ = solve(row, settings(rtol=rtol, t_end=t_end))
    n_scipy = len(sol.t) - 1
    assert counts[0, tk.STEPS] == n_scipy
    assert counts[0, tk.RHS_EVALS] == sol.nfev
    # Stopping after k accepted steps exposes the kernel's k-th step end: it is SciPy's t[k].
    # Not bit for bit: NumPy sums the stages in BLAS order, and the controller's err^(-1/5)
    # carries that round-off into the step sizes (seen: <= 2.3e-8 relative).
    for k in sorted({1, 2, 7, n_scipy // 3, n_scipy // 2, n_scipy - 1}):
        _, reals, _, _ = solve(row, settings(rtol=rtol, t_end=t_end, max_steps=k))
        assert reals[0, tk.FAILURE_TIME] == pytest.approx(sol.t[k], rel=1e-7)


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("rtol", [1e-5, 1e-7])
@pytest.mark.parametrize("driver", ["lanes", "scalar"])
def test_same_steps_as_scipy_dop853(case, rtol, driver, paper_row):
    row = CASES[case](paper_row)
    t_end = 2.0
    sol = solve_ivp(rhs(row), (0.0, t_end), row[8:10], method="DOP853", rtol=rtol, atol=1e-12)
    assert sol.status == 0
    s = settings(rtol=rtol, t_end=t_end, method="dop853")
    _, reals, counts, _ = solve(row, s, driver=driver)
    n_scipy = len(sol.t) - 1
    assert counts[0, tk.STEPS] == n_scipy
    # SciPy's nfev, plus, below rtol 3e-6, three for each step whose seventh-order dense output
    # the metrics used (an extremum, the tail's start): SciPy pays those only with
    # dense_output=True, and then on every step
    extra = counts[0, tk.RHS_EVALS] - sol.nfev
    if rtol < dop853.SEVENTH_ORDER_BELOW_RTOL:
        assert extra % 3 == 0 and 3 <= extra <= 3 * n_scipy
    else:
        assert extra == 0
    # DOP853's error estimate K^T E5 cancels far more than RK45's: at rtol 1e-9 its round-off
    # (BLAS order in NumPy, libm cos against vecmath.fast_cos) is ~1e-4 of its value, and
    # err^(-1/8) carries 1/8 of that into each step size (seen: <= 6e-6 relative); over a
    # thousand steps that can move one accept/reject decision (1266 steps against SciPy's 1265
    # on the off-resonance case), so the step-for-step check runs at rtol 1e-5 and 1e-7.
    for k in sorted({1, 2, 7, n_scipy // 3, n_scipy // 2, n_scipy - 1}):
        _, reals, _, _ = solve(row, settings(rtol=rtol, t_end=t_end, max_steps=k,
                                             method="dop853"), driver=driver)
        assert reals[0, tk.FAILURE_TIME] == pytest.approx(sol.t[k], rel=3e-5)


def test_same_steps_with_first_and_max_step(paper_row):
    sol = solve_ivp(rhs(paper_row), (0.0, 1.0), paper_row[8:10], method="RK45", rtol=1e-7,
                    atol=1e-12, first_step=1e-4, max_step=2e-3)
    _, _, counts, _ = solve(paper_row, settings(rtol=1e-7, t_end=1.0, first_step=1e-4,
                                                max_step=2e-3))
    assert counts[0, tk.STEPS] == len(sol.t) - 1
    assert counts[0, tk.RHS_EVALS] == sol.nfev


def _reference(row, t_end):
    return solve_ivp(rhs(row), (0.0, t_end), row[8:10], method="DOP853", rtol=1e-13,
                     atol=1e-16, dense_output=True)


def reference_amplitude(sol, t0, t1):
    """max |q| over [t0, t1] from a DOP853 solution: fine grid, then q' = 0 refined by brentq."""
    t = np.linspace(t0, t1, 40001)
    q, v = sol.sol(t)
    best = max(abs(q[0]), abs(q[-1]))
    for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
        te = brentq(lambda s: sol.sol(s)[1], t[i], t[i + 1], xtol=1e-15)
        best = max(best, abs(sol.sol(te)[0]))
    return best


@pytest.mark.parametrize("case", ["paper l=1", "consistent resonance", "consistent off-resonance"])
@pytest.mark.parametrize("method, driver", [("rk45", "scalar"), ("dop853", "lanes")])
def test_series_and_amplitude_match_dop853(case, method, driver, paper_row):
    """At the scene defaults (rtol 1e-8, atol 1e-12) samples, amplitude and peak on the dense
    output (RK45's quartic; DOP853: its seventh-order interpolant) to 1e-6."""
    row = CASES[case](paper_row)
    t_end = 5.0
    ref = _reference(row, t_end)
    s = settings(t_end=t_end, sample_dt=0.01, method=method)
    n_samples = 501
    _, reals, _, series = solve(row, s, n_samples, driver=driver)
    times = np.arange(n_samples) * 0.01
    q_ref = ref.sol(times)[0]
    scale = np.max(np.abs(q_ref))
    assert np.max(np.abs(series[0] - q_ref)) < 1e-6 * scale
    amp_ref = reference_amplitude(ref, 2.5, 5.0)
    assert reals[0, tk.AMPLITUDE] == pytest.approx(amp_ref, rel=1e-6)
    peak_ref = reference_amplitude(ref, 0.0, 5.0)
    assert reals[0, tk.PEAK] == pytest.approx(peak_ref, rel=1e-6)


@pytest.mark.parametrize("case", ["paper l=1", "consistent resonance"])
@pytest.mark.parametrize("driver", ["lanes", "scalar"])
def test_dop853_amplitude_is_scipys_dense_output(case, driver, paper_row):
    """DOP853's amplitude and peak come from its own seventh-order interpolant: on the same
    steps as SciPy's DOP853 (rtol 1e-7, checked step for step above) they equal what SciPy's
    dense output gives, to round-off: far below the error of the quintic Hermite interpolant
    used before (about 1e-6 relative at this tolerance on the work-precision points)."""
    row = CASES[case](paper_row)
    t_end = 2.0
    rtol = 1e-7
    sol = solve_ivp(rhs(row), (0.0, t_end), row[8:10], method="DOP853", rtol=rtol, atol=1e-12,
                    dense_output=True)
    s = settings(rtol=rtol, t_end=t_end, method="dop853")    # tail: the last half, [1, 2] s
    _, reals, counts, _ = solve(row, s, driver=driver)
    assert counts[0, tk.STEPS] == len(sol.t) - 1
    assert reals[0, tk.AMPLITUDE] == pytest.approx(reference_amplitude(sol, 1.0, t_end),
                                                   rel=1e-11)
    assert reals[0, tk.PEAK] == pytest.approx(reference_amplitude(sol, 0.0, t_end), rel=1e-11)


def test_post_buckled_equilibrium_matches_closed_form():
    """Constant load above Pcr with alpha > 0: the span settles on q_s = sqrt(-k0/g0)."""
    row = consistent_row(length=1.0, load=8.0, load_type="constant", zeta=0.05, q0=1e-4)
    k0, g0 = row[2], row[4]
    assert k0 < 0 < g0
    q_s = np.sqrt(-k0 / g0)
    states, reals, _, _ = solve(row, settings(t_end=10.0))
    assert states[0] == km.STEADY
    assert reals[0, tk.AMPLITUDE] == pytest.approx(q_s, rel=1e-3)
