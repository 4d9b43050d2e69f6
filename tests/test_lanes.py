"""The lock-step lanes driver gives the scalar driver's results (to round-off)."""

from __future__ import annotations

import platform
import re

import numpy as np
import pytest

from sweep.kernels import lanes, vecmath
from sweep.kernels import transverse as tk
from sweep.kernels.oscillator import Q0

from conftest import param_row, settings
from sweep.threads import solve_transverse
from sweep.specialise import call


def _solve(driver, rows, s, n_samples=0):
    n = rows.shape[0]
    out = (np.empty(n, np.int8), np.empty((n, tk.N_REALS)), np.empty((n, tk.N_COUNTS), np.int64),
           np.empty((n, n_samples)))
    solve_transverse(rows, s, *out, driver=driver)
    return out


def _assert_equal_to_round_off(rows, s, a, b, n_samples):
    """The lanes results b equal the scalar driver's a to round-off, as these trajectories
    amplify it: the scalar driver's own results with q0 moved by one ulp either way show by how
    much, element by element (~1e-9 relative on the mixed grid, ~1e-6 for the period of a
    died-out swing, whose extrema are flat). b may differ from a by 5 times that, plus 1e-9
    relative (lengths also 1e-12 of the point's peak |q|, the response's scale)."""
    moved = []
    for direction in (np.inf, -np.inf):
        nudged = rows.copy()
        nudged[:, Q0] = np.nextafter(nudged[:, Q0], direction)
        moved.append(_solve("scalar", nudged, s, n_samples))
    peak = np.abs(a[1][:, tk.PEAK])

    def check(got, want, up, down, atol, rtol=1e-9):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
        spread = np.maximum(np.abs(up - want), np.abs(down - want))
        excess = np.abs(got - want) - (atol + rtol * np.abs(want) + 5.0 * spread)
        assert not np.nanmax(excess, initial=-1.0) > 0.0, (
            f"differs beyond round-off at {np.unravel_index(np.nanargmax(excess), excess.shape)}")

    # The final state (where a stepped sweep's next point starts) is a value at a fixed time,
    # first-order sensitive to the phase a trajectory has gathered, where an amplitude, a
    # maximum, is stationary to it: 1e-8 relative (measured 1.2e-9 where amplitudes show 7e-10;
    # the one-ulp nudge does not reach vecmath's cosine), velocities on the table's own scale.
    speed = np.nanmax(np.abs(a[1][:, tk.V_END]), initial=0.0)
    for col in range(tk.N_REALS):
        final = col in (tk.Q_END, tk.V_END)
        length = col in (tk.AMPLITUDE, tk.PEAK, tk.Q_END)
        atol = 1e-12 * peak if length else (1e-12 * speed if col == tk.V_END else 1e-15)
        check(b[1][:, col], a[1][:, col], moved[0][1][:, col], moved[1][1][:, col], atol,
              1e-8 if final else 1e-9)
    check(b[3], a[3], moved[0][3], moved[1][3], 1e-12 * peak[:, None])


def test_fast_cos_matches_libm_to_round_off():
    x = np.concatenate([np.linspace(-2e4, 2e4, 400001), np.pi / 2 * np.arange(-50, 50)])
    W = np.zeros(1)
    got = np.array([vecmath.fast_cos(float(v)) for v in x[::97]])
    np.testing.assert_allclose(got, np.cos(x[::97]), rtol=0, atol=4.5e-16)
    del W


@pytest.mark.parametrize("rtol, controller, method", [(1e-5, "scipy", "rk45"), (1e-8, "scipy", "rk45"),
                                                      (1e-6, "pi", "rk45"), (1e-7, "scipy", "dop853")])
def test_lanes_equal_scalar_on_a_mixed_grid(rtol, controller, method):
    rng = np.random.default_rng(7)
    rows = [param_row(c=rng.uniform(0, 2), k0=rng.uniform(-5, 400), k1=rng.uniform(-100, 100),
                      g0=rng.uniform(-1e3, 1e5), g1=rng.uniform(0, 1e3), h=rng.uniform(-1e4, 1e4),
                      omega=rng.uniform(0, 60), q0=rng.uniform(-0.05, 0.05),
                      v0=rng.uniform(-0.5, 0.5), bound=1.0) for _ in range(150)]
    rows.append(param_row(m=0.0))                      # invalid
    rows.append(param_row(k0=-1.0, g0=-1.0, q0=1.0))   # diverges
    rows = np.stack(rows)
    s = settings(rtol=rtol, atol=rtol * 1e-4, t_end=2.0, sample_dt=0.05, max_steps=20000,
                 controller=controller, method=method)
    a = _solve("scalar", rows, s, 41)
    b = _solve("lanes", rows, s, 41)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[2], b[2])
    _assert_equal_to_round_off(rows, s, a, b, 41)


def test_sweep_drivers_agree_and_lanes_is_the_default():
    import sweep
    text = """
[cable]
damping_ratio = 0.01
[load]
amplitude = 4.0
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
    assert scene.get("solver.controller") == "scipy"
    c = sweep.run(sweep.load_scene_text(text, overrides={"solver.controller": "pi"}),
                  progress=False)
    assert int(c["n_rejected"].sum()) < int(a["n_rejected"].sum())
    np.testing.assert_allclose(c["amplitude"].values, a["amplitude"].values, rtol=1e-3)
    with pytest.raises(sweep.SceneError, match="solver.controller"):
        sweep.load_scene_text(text, overrides={"solver.controller": "pid"})
    assert scene.get("solver.method") == "rk45"
    d = sweep.run(sweep.load_scene_text(text, overrides={"solver.method": "dop853"}),
                  progress=False)
    assert int(d["n_steps"].sum()) < int(a["n_steps"].sum()) / 2
    np.testing.assert_array_equal(d["state"].values, a["state"].values)
    for name in ("amplitude", "peak_amplitude", "displacement"):
        np.testing.assert_allclose(d[name].values, a[name].values, rtol=1e-5, atol=1e-9)
    with pytest.raises(sweep.SceneError, match="solver.method.*rk45"):
        sweep.load_scene_text(text, overrides={"solver.method": "dop853",
                                               "solver.controller": "pi"})


@pytest.mark.parametrize("eighth, exponent", [(None, -1 / 5), (True, -1 / 8)])
def test_vectorisable_controller_matches_scipy_controller(eighth, exponent):
    from sweep.kernels.dopri5 import step_factor
    errs = np.concatenate([np.geomspace(1e-12, 1e12, 4001),
                           [0.0, 1.0, 5.9049e-6, 0.09 ** 8, np.inf, np.nan]])
    for rejected_before in (False, True):
        ours = np.array([lanes._step_factor(e, rejected_before, eighth) for e in errs])
        ref = np.array([step_factor(e, rejected_before, exponent) for e in errs])
        np.testing.assert_allclose(ours, ref, rtol=2e-15, atol=0)
        # SciPy's rule (rk.py, RungeKutta._step_impl), written out independently
        with np.errstate(divide="ignore", invalid="ignore"):
            scipy_rule = np.where(errs < 1, np.minimum(10.0, 0.9 * errs ** exponent),
                                  np.maximum(0.2, np.nan_to_num(0.9 * errs ** exponent, nan=0.2)))
        if rejected_before:
            scipy_rule = np.where(errs < 1, np.minimum(1.0, scipy_rule), scipy_rule)
        np.testing.assert_allclose(ours, scipy_rule, rtol=2e-15, atol=0)
    x = np.geomspace(1e-9, 1e9, 10001)
    roots = np.array([vecmath.inv_fifth_root(v) for v in x])
    np.testing.assert_allclose(roots, x ** -0.2, rtol=1e-15)


def test_controller_powers_are_accurate():
    x = np.geomspace(2.0 ** -62, 2.0 ** 63, 20001)
    logs = np.array([vecmath.log2_fast(v) for v in x])
    np.testing.assert_allclose(logs, np.log2(x), rtol=0, atol=1e-8)
    y = np.linspace(-31.0, 31.0, 20001)
    np.testing.assert_allclose([vecmath.exp2_fast(v) for v in y], 2.0 ** y, rtol=1e-8)


def test_pi_controller_factor_follows_its_formula():
    from sweep.kernels.dopri5 import (MAX_FACTOR, MIN_FACTOR, PI_ALPHA, PI_BETA, SAFETY, pi_log2_err,
                                pi_step_factor)
    prev = 3e-3
    memory = pi_log2_err(prev)
    for err in (1e-9, 1e-3, 0.5, 0.99, 1.5, 40.0, 1e6):
        raw = SAFETY * err ** -PI_ALPHA * (prev ** PI_BETA if err < 1 else 1.0)
        want = min(MAX_FACTOR, max(MIN_FACTOR, raw)) if err < 1 else max(MIN_FACTOR, raw)
        assert pi_step_factor(err, memory, False) == pytest.approx(want, rel=1e-8)
    assert pi_step_factor(0.5, memory, True) <= 1.0
    assert pi_step_factor(np.nan, memory, False) == MIN_FACTOR
    assert pi_log2_err(1e-12) == pytest.approx(np.log2(1e-4), abs=1e-8)   # floored


def test_pi_controller_is_accurate_and_rejects_less():
    """Against SciPy DOP853 at rtol 1e-13 (independent): the PI controller's final state is as
    accurate as SciPy's controller's at the same tolerance, with fewer rejected steps."""
    from scipy.integrate import solve_ivp
    row = param_row(c=0.3, k0=900.0, k1=200.0, g0=4e5, omega=58.0, q0=4e-3)
    s_end = 3.0
    ref = solve_ivp(lambda t, y: [y[1], -(0.3 * y[1] + (900 + 200 * np.cos(58 * t)) * y[0]
                                         + 4e5 * y[0] ** 3)],
                    (0, s_end), [4e-3, 0.0], method="DOP853", rtol=1e-13, atol=1e-16).y[0, -1]
    out = {}
    for controller in ("scipy", "pi"):
        s = settings(rtol=1e-6, atol=1e-10, t_end=s_end, sample_dt=s_end, controller=controller)
        states, reals, counts, series = _solve("lanes", row[None, :], s, 2)
        out[controller] = (abs(series[0, -1] - ref), counts[0, tk.REJECTED])
    assert out["pi"][0] < 1e-6 * 4e-3 * 100
    assert out["pi"][0] <= 3 * out["scipy"][0]
    assert out["pi"][1] < out["scipy"][1]


@pytest.mark.slow
@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_second_pass_points_in_a_threaded_lanes_batch(method):
    """Points at rest away from zero (overdamped creep, a damped post-buckled swing) get their
    settling time from the second pass whichever driver and thread count ran them; results do
    not depend on the thread count."""
    from sweep.kernels import metrics as km
    creep = [param_row(c=5.0, k0=-1.0, g0=1.0, q0=q0) for q0 in (0.1, 0.3, 2.0)]
    swing = [param_row(c=1.0, k0=-1.0, g0=1.0, q0=q0) for q0 in (0.2, -0.5)]
    rng = np.random.default_rng(3)
    others = [param_row(c=rng.uniform(0, 1), k0=rng.uniform(50, 400), omega=rng.uniform(5, 30),
                        q0=rng.uniform(-0.01, 0.01)) for _ in range(300)]
    rows = np.stack(others[:150] + creep + others[150:] + swing)
    s = settings(rtol=1e-8, t_end=40.0, tol=0.02, method=method)
    a = _solve("scalar", rows, s)
    b = _solve("lanes", rows, s)
    assert not np.any(a[0] == km.SECOND_PASS) and not np.any(b[0] == km.SECOND_PASS)
    second = [150, 151, 152, 303, 304]
    assert np.all(b[0][second] == km.STEADY)
    assert np.all(np.isfinite(b[1][second, tk.SETTLING]))
    np.testing.assert_array_equal(a[0], b[0])
    # At rest away from zero the error estimate is mostly round-off (the state barely moves), so
    # whether a late attempt passes can turn on it: on the q0 = 2 creep SciPy's own DOP853 takes
    # 74 steps, the scalar driver 74 and the lanes 76 (their sums round differently). There two
    # steps either way; everywhere else the same steps.
    same = np.setdiff1d(np.arange(rows.shape[0]), second)
    np.testing.assert_array_equal(a[2][same], b[2][same])
    assert np.all(np.abs(a[2][second, tk.STEPS] - b[2][second, tk.STEPS]) <= 2)
    # (The period of a swing that has died out comes from nearly flat extrema, whose position on
    # the dense output is ill-conditioned: there round-off moves it ~1e-6.)
    _assert_equal_to_round_off(rows, s, a, b, 0)
    for driver, ref in (("lanes", b), ("scalar", a)):
        n = rows.shape[0]
        out = (np.empty(n, np.int8), np.empty((n, tk.N_REALS)),
               np.empty((n, tk.N_COUNTS), np.int64), np.empty((n, 0)))
        solve_transverse(rows, s, *out, driver=driver, threads=1)
        for got, want in zip(out, ref):
            np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("least", ["lanes", "scalar"])
def test_guided_blocks_cover_every_row_once(least):
    """Blocks of at least MIN_BLOCK rows for the lanes, SCALAR_BLOCK for a scalar driver (or
    the grid's share, or what is left): every row once, every thread a block; a scalar
    driver's small grid ends in blocks of a few rows, so its threads end together."""
    from sweep.threads import MIN_BLOCK, SCALAR_BLOCK, next_block
    floor = MIN_BLOCK if least == "lanes" else SCALAR_BLOCK
    for n, threads in ((1, 2), (100, 2), (129, 2), (144, 2), (10_000, 2), (77_777, 3)):
        lo, seen = 0, []
        while lo < n:
            hi = next_block(lo, n, threads, least=floor)
            assert hi > lo and (hi - lo >= min(floor, -(-n // threads)) or hi == n)
            seen.append((lo, hi))
            lo = hi
        assert seen[0][0] == 0 and seen[-1][1] == n
        assert len(seen) >= min(threads, n)       # every thread gets a block, small grids too
        assert all(a[1] == b[0] for a, b in zip(seen, seen[1:]))
        if least == "scalar" and n >= 100:
            assert seen[-1][1] - seen[-1][0] <= 2 * SCALAR_BLOCK, seen[-3:]


def test_a_small_grid_is_split_evenly_between_the_threads():
    """A grid of at most two timed blocks a thread (MIN_TIMED_BLOCK) runs as one equal share a
    thread (there is no later block for the timing to size); a larger one starts with timed
    blocks."""
    import threading

    from sweep.threads import MIN_TIMED_BLOCK, run_blocks, thread_count
    if thread_count(2) < 2:
        pytest.skip("needs 2 threads")
    seen, lock = [], threading.Lock()

    def solve(lo, hi):
        with lock:
            seen.append((lo, hi))

    for n in (144, 4 * MIN_TIMED_BLOCK - 1, 4 * MIN_TIMED_BLOCK):
        seen.clear()
        run_blocks(solve, n, 2, None)
        half = -(-n // 2)
        assert sorted(seen) == [(0, half), (half, n)], n
    seen.clear()
    run_blocks(solve, 4 * MIN_TIMED_BLOCK + 2, 2, None)
    assert sorted(seen)[0] == (0, MIN_TIMED_BLOCK)


def test_sweep_run_refuses_a_negative_thread_count():
    import sweep
    scene = sweep.load_scene("paper-fig5")
    with pytest.raises(sweep.UserError, match="threads = -1"):
        sweep.run(scene, threads=-1)


_VECTOR_LOOPS = [("trajectory.next_attempts",
                  lambda W, s: (W, lanes.LANES, np.zeros(lanes.LANES), np.zeros(lanes.LANES), s,
                                lanes.LANES)),
                 ("_attempt", lambda W, s: (W, 1e-7, lanes.LANES, True, None, None)),
                 ("_attempt", lambda W, s: (W, 1e-7, lanes.LANES, None, True, None)),
                 ("_attempt", lambda W, s: (W, 1e-7, lanes.LANES, True, True, None)),
                 ("_attempt8", lambda W, s: (W, 1e-7, lanes.LANES, True, None, None)),
                 # a random record's chains: its reads are made before (_stage_reads)
                 ("_attempt", lambda W, s: (W, 1e-7, lanes.LANES, None, np.zeros((1, 2, 8)),
                                            True)),
                 ("_attempt8", lambda W, s: (W, 1e-7, lanes.LANES, None, np.zeros((1, 2, 8)),
                                             True)),
                 # a sweep's reads: the stages from each lane's anchor (the anchor is scalar)
                 ("_read_sweeps", lambda W, s: (W, lanes.LANES, True, True, True)),
                 ("_read_sweeps", lambda W, s: (W, lanes.LANES, None, True, True)),
                 ("_pi_factors", lambda W, s: (W, lanes.LANES)),
                 ("_finish", lambda W, s: (W, s, 0, lanes.LANES, None, None, True, None)),
                 ("_finish", lambda W, s: (W, s, 0, lanes.LANES, None, True, True, None)),
                 ("_finish", lambda W, s: (W, s, 0, lanes.LANES, None, None, True, True)),
                 ("_observe_acceleration", lambda W, s: (W, s, lanes.LANES)),
                 ("_locate_extrema", lambda W, s: (W, lanes.LANES))]


@pytest.mark.slow
@pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"),
                    reason="reads x86 assembly")
@pytest.mark.parametrize("name, args", _VECTOR_LOOPS,
                         ids=[f"{n}-{k}" for k, (n, _) in enumerate(_VECTOR_LOOPS)])
def test_lanes_loops_are_vectorised(name, args):
    """The lanes driver is fast only while LLVM vectorises its loops across the lanes, and an
    innocent edit can stop it (a branch, a libm call, too many memory streams): each loop,
    compiled afresh with its own options (cached code cannot be inspected), must run mostly on
    packed-double instructions. Vectorised, these loops have 0.5-1 packed per scalar one (the
    scalar remainder loop keeps the rest); a loop LLVM left scalar has ~0.15."""
    import numba
    from sweep.kernels import trajectory
    module, _, attribute = name.rpartition(".")
    kernel = getattr(trajectory if module == "trajectory" else lanes, attribute)
    options = {k: v for k, v in kernel.targetoptions.items() if k not in ("cache", "nopython")}
    fresh = numba.njit(**options)(kernel.py_func)
    W = np.zeros(lanes.W_ROWS * lanes.LANES)
    arguments = args(W, settings())
    if any(a is True for a in arguments):
        call(fresh, *arguments)               # the switches typed as the run types them
    else:
        fresh(*arguments)                     # (next_attempts: its lane count a literal)
    mnemonics = [line.split()[0] for text in fresh.inspect_asm().values()
                 for line in text.splitlines() if line.startswith("\t") and line.split()]
    packed = sum(1 for m in mnemonics if re.fullmatch(r"v?[a-z0-9]+pd", m))
    scalar = sum(1 for m in mnemonics if re.fullmatch(r"v?[a-z0-9]+sd", m))
    assert packed >= 20 and packed >= 0.4 * scalar, (name, packed, scalar)


_BOUNDS_CHECKED_RUN = """
import sys
import numpy as np
sys.path[:0] = [{tests!r}, {root!r}]
from conftest import param_row, settings
from sweep.kernels import lanes
from sweep.kernels import transverse as tk
rows = np.load({rows!r})
s = settings(rtol=1e-6, t_end=5.0, sample_dt=0.05)
n = rows.shape[0]
out = (np.empty(n, np.int8), np.empty((n, tk.N_REALS)), np.empty((n, tk.N_COUNTS), np.int64),
       np.empty((n, 101)))
from sweep.specialise import call
call(lanes.solve_block, rows, s, 0, n, *out, None, None, True, None, np.zeros(1, np.int8))
np.savez({result!r}, *out)
"""


@pytest.mark.slow
def test_lanes_stay_in_bounds_as_lanes_reload_and_buffers_grow(tmp_path):
    """Every array access of the lanes driver stays in bounds. Numba does not check indices,
    and the flagged lanes' bookkeeping (`_record_lane`) runs without reference counting, so a
    wrong index or buffer capacity would corrupt memory silently: here the driver is compiled
    afresh with NUMBA_BOUNDSCHECK=1 (an out-of-range index raises IndexError) on 40 points for
    16 lanes (lanes reload), ~200-300 extrema per point against 64 buffer rows (each lane's
    buffer grows, and is replaced for the next point) and a 101-sample time series. Its results
    must also equal the scalar driver's to round-off."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    rng = np.random.default_rng(5)
    rows = np.stack([param_row(c=rng.uniform(0.0, 0.5), k0=rng.uniform(2e4, 4e4),
                               g0=rng.uniform(0.0, 1e6), q0=rng.uniform(-0.01, 0.01),
                               v0=rng.uniform(-1.0, 1.0)) for _ in range(40)])
    np.save(tmp_path / "rows.npy", rows)
    tests = Path(__file__).resolve().parent
    script = _BOUNDS_CHECKED_RUN.format(tests=str(tests), root=str(tests.parent),
                                        rows=str(tmp_path / "rows.npy"),
                                        result=str(tmp_path / "result.npz"))
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    run = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    with np.load(tmp_path / "result.npz") as f:
        b = tuple(f[f"arr_{k}"] for k in range(4))

    s = settings(rtol=1e-6, t_end=5.0, sample_dt=0.05)
    a = _solve("scalar", rows, s, 101)
    extrema = 2.0 * s[tk.T_END] / a[1][:, tk.PERIOD]        # maxima and minima over [0, t_end]
    assert np.nanmin(extrema) > 128.0                         # two doublings of 64 rows
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[2], b[2])
    _assert_equal_to_round_off(rows, s, a, b, 101)


def test_one_thread_takes_a_small_remainder_into_its_block():
    """On one thread a block takes the few points after it (fewer than 1/TAIL_SHARE of it)
    rather than leaving them a block, and a drain, of their own."""
    from sweep.threads import TAIL_SHARE, next_block
    assert next_block(0, 130, 1, cap=64) == 64
    assert next_block(64, 130, 1, cap=64) == 130            # 2 left: taken
    assert next_block(0, 64 + 64 // TAIL_SHARE, 1, cap=64) == 64   # a quarter left: its own
    assert next_block(0, 64 + 64 // TAIL_SHARE - 1, 1, cap=64) == 64 + 64 // TAIL_SHARE - 1
