"""The multi-mode lanes driver (kernels.modal_lanes) gives the scalar modal driver's results.

Against kernels.modal_driver.solve_block on mixed rows (N = 2, 3, 5; base-excited, harmonic
and constant axial loads, RK45 and DOP853, with and without time series and settling times,
more rows than lanes so that lanes take new points as theirs end), plus a row that diverges
and an invalid one (NaN): the same states, step counts within a few, the metrics and modal
amplitudes equal to round-off. Round-off here is what these trajectories make of it,
measured as test_lanes.py does for one mode: the scalar driver's own results with q_1(0)
moved by one ulp either way. The rows are built from cable data as sweep.run builds them
(sweep.models.transverse.modal_rows).
"""

from __future__ import annotations

import numpy as np
import pytest

import sweep
from conftest import TABLE1_CABLE
from sweep.kernels import layout as tk
from sweep.kernels import metrics as km
from sweep.kernels import modal_driver, modal_lanes
from sweep.kernels import modes as md
from sweep.models import transverse as tm
from sweep.models.basis import clamped, pinned_sines
from sweep.specialise import call
from sweep.threads import method_switch


def scene_rows(text: str, n_modes: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(rows in kernels.modes columns, settings, samples per series) of a scene's grid."""
    inputs = tm.resolve(sweep.load_scene_text(text))
    assert inputs.n_modes == n_modes
    rows = tm.modal_rows(inputs, np.arange(int(np.prod(inputs.shape))))
    return rows, inputs.settings.copy(), inputs.sample_times.size


def one_basis(basis, rows: np.ndarray) -> tuple:
    """The lanes' (family, which) of `rows` all on one Basis: a family of one."""
    return md.stacked([basis.kernel_arrays()]), np.zeros(rows.shape[0], np.int64)


def solve(driver, rows: np.ndarray, n_modes: int, s: np.ndarray, n_samples: int) -> tuple:
    """(states, reals, counts, series, modal, final) of driver.solve_block over every row."""
    n = rows.shape[0]
    out = (np.full(n, 99, np.int8), np.full((n, tk.N_REALS), -1.0),
           np.full((n, tk.N_COUNTS), -1, np.int64), np.full((n, n_samples), -1.0),
           np.full((n, n_modes), -1.0), np.full((n, 2 * n_modes), -1.0))
    basis = pinned_sines(n_modes)
    first = (one_basis(basis, rows) if driver is modal_lanes
             else (basis.kernel_arrays(),))
    call(driver.solve_block, rows, *first, s, 0, n, *out,
         True if s[tk.BASE] != 0.0 else None, method_switch(s), np.zeros(1, np.int8))
    return out


CABLE = """
name = "modal-lanes"
[model]
modes = {n}
[cable]
{table1}
damping_ratio = 0.02
[solver]
t_end = {t_end}
rtol = {rtol}
method = "{method}"
[outputs]
time_series = {series}
sample_interval = 0.01
[initial]
modal_displacement = {q0}
"""

CASES = {
    # N = 2, harmonic end load (compression up to 1.2 Pcr at 0.5 m) near the principal
    # parametric resonances, RK45 with a time series and settling times
    "n2-harmonic-load": (2, "rk45", True, True, 1e-7, 0.4, """
[load]
type = "harmonic"
amplitude = 3.0
[axes]
length = [0.3, 0.45, 0.6, 0.8]
frequency_ratio = [0.9, 1.5, 1.9, 2.05, 2.3, 3.0, 3.9, 4.2, 6.0]
"""),
    # N = 3, base-excited at 1 g on both sides of resonance, DOP853, no series, no settling
    "n3-base-dop853": (3, "dop853", False, False, 1e-8, 0.5, """
[load]
amplitude = 0.0
[base]
acceleration_g = 1.0
[axes]
length = [0.3, 0.5, 0.7, 0.8]
base_frequency_ratio = [0.5, 0.8, 0.95, 1.1, 1.3, 1.6, 2.0, 2.5, 3.1]
"""),
    # N = 5, constant compressive end load with base excitation, RK45, settling, no series
    "n5-constant-load-base": (5, "rk45", False, True, 1e-6, 0.3, """
[load]
type = "constant"
amplitude = 1.5
[base]
acceleration_g = 0.5
[axes]
length = [0.3, 0.5, 0.8]
base_frequency_ratio = [0.6, 0.9, 1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 7.0, 9.0]
"""),
    # N = 3, RK45, the same base-excited grid with a time series and settling times
    "n3-base-rk45-series": (3, "rk45", True, True, 1e-7, 0.3, """
[load]
amplitude = 2.0
[base]
acceleration_g = 1.0
frequency_ratio = 1.2
[axes]
length = [0.35, 0.55, 0.75]
frequency_ratio = [0.7, 1.3, 1.9, 2.1, 2.8, 3.5, 4.1, 5.0, 6.0, 7.9, 8.1, 9.0]
"""),
}


def case_rows(name: str) -> tuple[np.ndarray, int, np.ndarray, int]:
    """A CASES entry's rows, then a row that diverges (compressed to 3 Pcr_1: mode 1 grows
    away from q = 0, past a divergence bound 5 |q_1(0)|) and an invalid one (NaN stiffness),
    in the middle of the block."""
    n, method, series, settling, rtol, t_end, axes = CASES[name]
    q0 = [1e-4 * (-0.5) ** i for i in range(n)]
    text = CABLE.format(table1=TABLE1_CABLE, n=n, t_end=t_end, rtol=rtol, method=method,
                        series="true" if series else "false", q0=q0) + axes
    rows, s, n_samples = scene_rows(text, n)
    s[tk.WANT_SETTLING] = 1.0 if settling else 0.0
    diverging = rows[1].copy()
    diverging[md.LOAD_MEAN] = 3.0 * diverging[md.W1_SQ]
    diverging[md.BOUND] = 5.0 * abs(diverging[md.N_FIXED])
    invalid = rows[2].copy()
    invalid[md.W1_SQ] = np.nan
    half = rows.shape[0] // 2
    rows = np.concatenate([rows[:half], diverging[None], invalid[None], rows[half:]])
    return rows, n, s, n_samples


def assert_within_round_off(got, want, moved, atol, rel=1e-9):
    """got equals want to 5 times the spread of the nudged runs `moved`, plus `rel` relative
    and atol (same NaNs)."""
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    spread = np.maximum(np.abs(moved[0] - want), np.abs(moved[1] - want))
    with np.errstate(invalid="ignore"):
        excess = np.abs(got - want) - (atol + rel * np.abs(want) + 5.0 * spread)
    worst = np.nanmax(excess, initial=-1.0)
    assert not worst > 0.0, (
        f"differs beyond round-off at {np.unravel_index(np.nanargmax(excess), excess.shape)}")


@pytest.mark.parametrize("name", list(CASES))
def test_lanes_equal_the_scalar_modal_driver(name):
    rows, n, s, n_samples = case_rows(name)
    assert rows.shape[0] > modal_lanes.LANES          # lanes take new points as theirs end
    a = solve(modal_driver, rows, n, s, n_samples)
    b = solve(modal_lanes, rows, n, s, n_samples)
    states = a[0]
    assert set(states) >= {km.INVALID_INPUT, km.DIVERGED}
    assert np.sum((states != km.INVALID_INPUT) & (states != km.DIVERGED)) >= rows.shape[0] - 2
    np.testing.assert_array_equal(b[0], a[0])
    moved = []
    for direction in (np.inf, -np.inf):
        nudged = rows.copy()
        nudged[:, md.N_FIXED] = np.nextafter(nudged[:, md.N_FIXED], direction)
        moved.append(solve(modal_driver, nudged, n, s, n_samples))
    # step counts: equal, or within a few where the attempts part at round-off
    steps = a[2][:, tk.STEPS]
    assert np.all(np.abs(b[2] - a[2]) <= 3 + 1e-3 * steps[:, None]), np.abs(b[2] - a[2]).max(0)
    assert np.mean(np.all(b[2] == a[2], axis=1)) > 0.5
    # Two metrics are read at steps' ends, so they move with the step sizes, whose relative
    # round-off is the error norm's, about eps / rtol (its sums cancel down to rtol x the
    # state), which a one-ulp nudge need not show: a mode's divergence stops the run at a
    # step's end (modal_driver: T_STOP = t_new; measured 2.7 eps / rtol), and the absolute
    # acceleration's extremum is refined on a polynomial through three step ends.
    step_end = 20.0 * np.finfo(float).eps / s[tk.RTOL]
    peak = np.abs(a[1][:, tk.PEAK])
    for col in range(tk.N_REALS):
        length = col in (tk.AMPLITUDE, tk.PEAK, tk.Q_END)
        assert_within_round_off(b[1][:, col], a[1][:, col], [m[1][:, col] for m in moved],
                                1e-12 * peak if length else 1e-15,
                                step_end if col in (tk.FAILURE_TIME, tk.ACCELERATION) else 1e-9)
    assert_within_round_off(b[3], a[3], [m[3] for m in moved], 1e-12 * peak[:, None])
    assert_within_round_off(b[4], a[4], [m[4] for m in moved], 1e-12 * peak[:, None])
    speed = np.nanmax(np.abs(a[5]), axis=1, initial=0.0)[:, None]   # the final state's scale
    assert_within_round_off(b[5], a[5], [m[5] for m in moved], 1e-12 * speed)
    if n_samples:
        assert np.isfinite(b[3][states == km.STEADY]).all()


def test_a_block_inside_a_table_and_idle_lanes():
    """A block lo..hi inside the table (fewer points than lanes) writes only its rows, and its
    results are those of the whole table's solve."""
    rows, n, s, n_samples = case_rows("n3-base-dop853")
    whole = solve(modal_lanes, rows, n, s, n_samples)
    part = tuple(np.full_like(x, 7) for x in whole)
    call(modal_lanes.solve_block, rows, *one_basis(pinned_sines(n), rows), s, 5, 12, *part,
         True, method_switch(s), np.zeros(1, np.int8))
    for x, y in zip(whole, part):
        np.testing.assert_array_equal(y[5:12], x[5:12])
        assert np.all(y[:5] == 7) and np.all(y[12:] == 7)


@pytest.mark.parametrize("name", ["n3-base-dop853", "n2-harmonic-load"])
def test_packed_lanes_give_each_point_its_own_results(name):
    """Once a block has no more points to load, its running lanes are packed into the lowest
    ones as others end (modal_lanes._move_lane), so a trajectory changes lane mid-run: each
    point's results, bit for bit, are those of the point solved alone in a block of its own.
    The points' step counts differ several-fold, so lanes end out of their order and the
    packing moves many of them."""
    rows, n, s, n_samples = case_rows(name)
    whole = solve(modal_lanes, rows, n, s, n_samples)
    steps = whole[2][:, tk.STEPS]
    assert steps.max() > 3 * steps[steps > 0].min()
    arrays = one_basis(pinned_sines(n), rows)
    for i in range(rows.shape[0]):
        alone = tuple(np.full_like(x, 7) for x in whole)
        call(modal_lanes.solve_block, rows, *arrays, s, i, i + 1, *alone,
             True if s[tk.BASE] != 0.0 else None, method_switch(s), np.zeros(1, np.int8))
        for x, y in zip(whole, alone):
            np.testing.assert_array_equal(y[i], x[i], err_msg=f"row {i}")


@pytest.mark.slow
@pytest.mark.skipif(__import__("platform").machine().lower() not in ("x86_64", "amd64"),
                    reason="reads x86 assembly")
@pytest.mark.parametrize("base", [None, True])
@pytest.mark.parametrize("ends", ["pinned", "clamped"])
def test_the_lanes_right_hand_side_is_vectorised(base, ends):
    """The multi-mode lanes are fast only while LLVM vectorises the right-hand side across
    the lanes (kernels.modes.lanes_derivative: 19-72 ns a lane for 2-5 modes, against 150-400
    ns for one state): compiled afresh as the lanes call it (fast True; no base term, or the
    sine's), it must run largely on packed-double instructions, as tests/test_lanes.py asks of
    the one-mode lanes' loops (left scalar, a loop has ~0.15 packed per scalar one). Its many
    short loops each keep a scalar remainder: measured 243 packed to 611 scalar (0.40) without
    the base term, so the bar is 0.25 here. Both forms of the force: the quadrature (pinned
    sines) and the polynomial (3 clamped modes, sweep.models.basis.polynomial_pays)."""
    import re

    import numba
    kernel = md.lanes_derivative
    options = {k: v for k, v in kernel.targetoptions.items() if k not in ("cache", "nopython")}
    fresh = numba.njit(**options)(kernel.py_func)
    arrays = (pinned_sines(3) if ends == "pinned" else clamped(3)).kernel_arrays()
    assert md.uses_polynomial(arrays) == (ends == "clamped")
    n, lanes = 3, modal_lanes.LANES
    T, CP = arrays[md.TABLES], arrays[md.COUPLING]
    fresh(np.zeros(lanes), np.zeros((2 * n, lanes)), np.zeros((2, 2 * n, lanes)), 1,
          np.zeros((md.prepared_size(n), lanes)), n, T,
          np.zeros((4, md.field_rows(arrays), lanes)), np.zeros((4, lanes)), lanes, True, base,
          CP, arrays[md.POLYNOMIAL], md.lane_basis(arrays, lanes), False)
    mnemonics = [line.split()[0] for text in fresh.inspect_asm().values()
                 for line in text.splitlines() if line.startswith("\t") and line.split()]
    packed = sum(1 for m in mnemonics if re.fullmatch(r"v?[a-z0-9]+pd", m))
    scalar = sum(1 for m in mnemonics if re.fullmatch(r"v?[a-z0-9]+sd", m))
    assert packed >= 20 and packed >= 0.25 * scalar, (packed, scalar)


def _elastic_family_rows(**overrides):
    """(rows with each row's basis index last, the family's kernel arrays, settings, samples)
    of harness-clamps on a small grid: six spans, each its own K = k_t l / EI, at and off
    their resonance, clamp loads observed."""
    scene = sweep.load_scene("harness-clamps", {
        "axes.length": [0.15, 0.3, 0.45], "axes.clamp_rotational_stiffness": [0.1, 10.0],
        "axes.base_frequency_ratio": [0.6, 1.0], "solver.t_end": 0.6, **overrides})
    inputs = tm.resolve(scene)
    rows = tm.modal_rows(inputs, np.arange(int(np.prod(inputs.shape))))
    return rows, inputs.basis.kernel_arrays(), inputs.settings.copy(), inputs.sample_times.size


@pytest.mark.parametrize("method", ["dop853", "rk45"])
def test_a_family_of_bases_shares_one_lanes_call(method):
    """Elastic clamps give every span its own basis (harness-clamps: 35 spans, 35 bases); the
    lanes run them in one call, each lane reading its own basis (kernels.modes.member,
    write_lane_basis). Each point's results are bit for bit those of its basis' points solved
    on the lanes alone (a lane's arithmetic does not depend on its neighbours: a lane reading
    another's coupling, coefficients, midspan weights, curvature rows or shapes would change
    them), and equal the scalar driver's to round-off."""
    from sweep.execute import _family_chunk, modes_chunk
    rows, family, s, n_samples = _elastic_family_rows(**{"solver.method": method})
    assert len(family) == 6 and md.stacked(family) is not None
    args = (s, n_samples, family)
    together = modes_chunk(rows, *args, driver="lanes", threads=1)
    alone = _family_chunk(rows, *args, "lanes", -1, False, None, 1, None, None)
    scalar = _family_chunk(rows, *args, "scalar", -1, False, None, 1, None, None)
    assert set(together["states"]) <= {km.STEADY, km.MODULATED, km.UNSETTLED}
    for name in together:
        np.testing.assert_array_equal(together[name], alone[name], err_msg=name)
    np.testing.assert_array_equal(together["states"], scalar["states"])
    for name in ("reals", "modal", "final"):
        got, want = together[name], scalar[name]
        np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-12 * np.nanmax(np.abs(want)),
                                   err_msg=name)
