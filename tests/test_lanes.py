"""The lock-step lanes driver gives the scalar driver's results (to round-off)."""

from __future__ import annotations

import numpy as np
import pytest

from kernels import lanes
from kernels import transverse as tk

from conftest import param_row, settings


def _solve(fn, rows, s, n_samples=0):
    n = rows.shape[0]
    out = (np.empty(n, np.int8), np.empty((n, tk.N_REALS)), np.empty((n, tk.N_COUNTS), np.int64),
           np.empty((n, n_samples)))
    fn(rows, s, *out)
    return out


def test_fast_cos_matches_libm_to_round_off():
    x = np.concatenate([np.linspace(-2e4, 2e4, 400001), np.pi / 2 * np.arange(-50, 50)])
    W = np.zeros(1)
    got = np.array([lanes.fast_cos(float(v)) for v in x[::97]])
    np.testing.assert_allclose(got, np.cos(x[::97]), rtol=0, atol=4.5e-16)
    del W


@pytest.mark.parametrize("rtol", [1e-5, 1e-8])
def test_lanes_equal_scalar_on_a_mixed_grid(rtol):
    rng = np.random.default_rng(7)
    rows = [param_row(c=rng.uniform(0, 2), k0=rng.uniform(-5, 400), k1=rng.uniform(-100, 100),
                      g0=rng.uniform(-1e3, 1e5), g1=rng.uniform(0, 1e3), h=rng.uniform(-1e4, 1e4),
                      omega=rng.uniform(0, 60), q0=rng.uniform(-0.05, 0.05),
                      v0=rng.uniform(-0.5, 0.5), bound=1.0) for _ in range(150)]
    rows.append(param_row(m=0.0))                      # invalid
    rows.append(param_row(k0=-1.0, g0=-1.0, q0=1.0))   # diverges
    rows = np.stack(rows)
    s = settings(rtol=rtol, atol=rtol * 1e-4, t_end=2.0, sample_dt=0.05, max_steps=20000)
    a = _solve(tk.solve_batch_scalar, rows, s, 41)
    b = _solve(lanes.solve_batch, rows, s, 41)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[2], b[2])
    np.testing.assert_allclose(b[1], a[1], rtol=1e-9, atol=1e-15, equal_nan=True)
    np.testing.assert_allclose(b[3], a[3], rtol=1e-9, atol=1e-15, equal_nan=True)


def test_sweep_drivers_agree_and_lanes_is_the_default():
    import sweep
    text = """
[cable]
damping_ratio = 0.01
[initial]
displacement = 1e-3
[axes]
length = [0.3, 0.5, 0.9]
frequency_ratio = [0.8, 1.9, 2.1, 2.6]
[outputs]
time_series = true
sample_interval = 0.05
[solver]
t_end = 1.0
"""
    scene = sweep.load_scene_text(text)
    assert scene.get("solver.driver") == "lanes"
    a = sweep.run(scene, progress=False)
    b = sweep.run(sweep.load_scene_text(text, overrides={"solver.driver": "scalar"}),
                  progress=False)
    for name in ("state", "n_steps", "n_rejected", "n_rhs"):
        np.testing.assert_array_equal(a[name].values, b[name].values)
    for name in ("amplitude", "peak_amplitude", "settling_time", "displacement"):
        np.testing.assert_allclose(a[name].values, b[name].values, rtol=1e-9, atol=1e-15)


def test_vectorisable_controller_matches_scipy_controller():
    from kernels.dopri5 import step_factor
    errs = np.concatenate([np.geomspace(1e-12, 1e12, 4001), [0.0, 1.0, 5.9049e-6, np.inf, np.nan]])
    for rejected_before in (False, True):
        ours = np.array([lanes._step_factor(e, rejected_before) for e in errs])
        ref = np.array([step_factor(e, rejected_before) for e in errs])
        np.testing.assert_allclose(ours, ref, rtol=2e-15, atol=0)
    x = np.geomspace(1e-9, 1e9, 10001)
    roots = np.array([lanes._inv_fifth_root(v) for v in x])
    np.testing.assert_allclose(roots, x ** -0.2, rtol=1e-15)
