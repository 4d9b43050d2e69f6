"""The multi-mode driver at N = 1 against the one-mode kernel, a divergence and a growth only
an even mode shows, and the `sweep modes` convergence check (docs/model.md sec. 7).

The one-mode kernel (kernels.transverse, from sweep/models/modal.py's closed-form K3 and K5)
and the multi-mode driver (kernels.modal_driver, whose nonlinear terms are Eq.17 projected by
quadrature at run time) share no coefficient code: at N = 1 they must agree to round-off and
take the same steps. The convergence check's figures are checked against the two results it
compares, recomputed here from two plain sweep.run calls.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep.cli import main
from sweep.convergence import compare
from sweep.kernels import layout as tk
from sweep.kernels import modes as md
from sweep.kernels import oscillator as osc
from sweep.models import modal
from sweep.specialise import call
from sweep.threads import method_switch

from conftest import settings, solve

TABLE1 = {"youngs_modulus": 1.1e11, "density": 8900.0, "area": 6e-6, "inertia": 2.865e-12,
          "membrane": 0.375, "coefficients": "consistent", "paper_parametric": "printed",
          "divergence_bound": None}


def _params(**changes):
    """The parameters by axis name that sweep.models.modal takes, for one point."""
    p = dict(TABLE1, length=0.5, damping_ratio=0.02, load_amplitude=1.0, load_type="harmonic",
             frequency=None, frequency_ratio=2.0, initial_displacement=1e-3,
             initial_velocity=0.0, base_acceleration=None, base_acceleration_g=1.0,
             base_frequency=None, base_frequency_ratio=1.3)
    p.update(changes)
    return p


def _solve_modes(rows, n_modes, s):
    from sweep.kernels import modal_driver
    rows = np.atleast_2d(rows)
    n = rows.shape[0]
    states = np.empty(n, np.int8)
    reals = np.empty((n, tk.N_REALS))
    counts = np.empty((n, tk.N_COUNTS), np.int64)
    modal_amp = np.empty((n, n_modes))
    from sweep.models.basis import pinned_sines
    call(modal_driver.solve_block, rows, pinned_sines(n_modes).kernel_arrays(), s, 0, n,
         states, reals, counts,
         np.empty((n, 0)), modal_amp, np.empty((n, 2 * n_modes)), True if s[tk.BASE] else None,
         method_switch(s), np.zeros(1, np.int8))
    return states, reals, counts, modal_amp


def _mode_row(p, q0, v0):
    one = modal.oscillator(p)
    columns = modal.modes_columns(p, one, len(q0), q0, v0)
    names = md.FIXED_NAMES + tuple(f"q0_{i + 1}" for i in range(len(q0))) + tuple(
        f"v0_{i + 1}" for i in range(len(q0)))
    return np.array([columns[name] for name in names], dtype=float), one


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_one_mode_of_the_modal_driver_is_the_one_mode_kernel(method):
    """The same steps and metrics. DOP853 at an rtol above dop853.SEVENTH_ORDER_BELOW_RTOL,
    where both drivers read the metrics off the quintic Hermite interpolant (below it the
    one-mode kernel takes DOP853's own seventh-order one: `..._within_the_hermite_error`)."""
    p = _params()
    row, one = _mode_row(p, [1e-3], [0.0])
    s = settings(rtol=1e-9 if method == "rk45" else 1e-5, atol=0.0, t_end=3.0, method=method)
    s[tk.ATOL_SCALE] = 0.01
    s[tk.BASE] = 1.0
    st_m, re_m, co_m, amp_m = _solve_modes(row, 1, s)
    one_row = np.array([one[name] for name in osc.PARAM_NAMES], dtype=float)
    st_1, re_1, co_1, _ = solve(one_row, s)
    assert st_m[0] == st_1[0]
    assert np.array_equal(co_m, co_1)                     # the same steps, rejections, RHS
    for col in (tk.AMPLITUDE, tk.PEAK, tk.SETTLING, tk.PERIOD):
        assert re_m[0, col] == pytest.approx(re_1[0, col], rel=1e-10, nan_ok=True)
    # The acceleration peak is refined on a polynomial through three step ends, from divided
    # differences of nearly equal numbers, so round-off in the samples reaches it amplified.
    assert re_m[0, tk.ACCELERATION] == pytest.approx(re_1[0, tk.ACCELERATION], rel=1e-8)
    assert amp_m[0, 0] == pytest.approx(re_1[0, tk.AMPLITUDE], rel=1e-10)


def test_one_mode_of_the_modal_driver_is_the_one_mode_dop853_within_the_hermite_error():
    """At rtol 1e-9 the one-mode kernel's DOP853 amplitude comes off its seventh-order dense
    output, the modal driver's off the quintic Hermite interpolant, on the same steps: they
    differ by that interpolant's error, below 1e-6 relative here."""
    p = _params()
    row, one = _mode_row(p, [1e-3], [0.0])
    s = settings(rtol=1e-9, atol=0.0, t_end=3.0, method="dop853")
    s[tk.ATOL_SCALE] = 0.01
    s[tk.BASE] = 1.0
    _, re_m, co_m, amp_m = _solve_modes(row, 1, s)
    one_row = np.array([one[name] for name in osc.PARAM_NAMES], dtype=float)
    _, re_1, co_1, _ = solve(one_row, s)
    assert co_m[0, tk.STEPS] == co_1[0, tk.STEPS]
    assert co_1[0, tk.RHS_EVALS] > co_m[0, tk.RHS_EVALS]     # the dense output's stages
    for col in (tk.AMPLITUDE, tk.PEAK):
        assert re_m[0, col] == pytest.approx(re_1[0, col], rel=1e-6)


def test_a_growing_even_mode_diverges_though_the_midspan_stays_at_rest():
    """Mode 2 has a node at midspan: its parametric resonance (W = 2 w_2) grows unseen there,
    and the point must still be flagged diverged when q_2 passes the bound."""
    p = _params(load_amplitude=40.0, damping_ratio=0.0, base_acceleration_g=None,
                base_frequency_ratio=None, frequency_ratio=8.0, divergence_bound=1e-4)
    row, _ = _mode_row(p, [0.0, 1e-7], [0.0, 0.0])
    s = settings(rtol=1e-8, atol=1e-14, t_end=5.0)
    states, reals, _, modal_amp = _solve_modes(row, 2, s)
    assert states[0] == 5                                  # diverged
    assert 0.0 < reals[0, tk.FAILURE_TIME] < 5.0
    assert np.all(np.isnan(modal_amp[0]))


HIDDEN = """
name = "hidden-mode"
[model]
modes = 2
membrane = 0.375
[cable]
damping_ratio = 0.005
[load]
type = "harmonic"
frequency_ratio = 8.0           # W = 2 w_2: mode 2's principal parametric zone
[base]
acceleration_g = 0.2
frequency_ratio = 0.5
[initial]
modal_displacement = [0.0, 1e-9]
[solver]
t_end = 20.0
[axes]
length = [0.5]
load_amplitude = [2.2, 2.5, 2.9]
"""


def _quarters(amplitude: float) -> list[float]:
    """max |q_2| (m) in each quarter of the tail window [10, 20] s, by SciPy on the independent
    Galerkin reference (tests/galerkin.py), the scene HIDDEN at load amplitude P0 (N)."""
    import galerkin as g
    cable = g.Cable(length=0.5, damping_ratio=0.005)
    sol = g.integrate(cable, 2, [0.0, 1e-9, 0.0, 0.0], 20.0, 3e-4, rtol=1e-8,
                      load_amplitude=amplitude, load_omega=8.0 * cable.w1,
                      base_acceleration=0.2 * 9.80665,
                      base_frequency=0.5 * cable.w1 / (2.0 * math.pi))
    q2 = np.abs(sol(np.linspace(10.0, 20.0, 40001))[1])
    return [float(q2[i * 10000:(i + 1) * 10000].max()) for i in range(4)]


@pytest.mark.slow
def test_an_even_mode_growing_under_a_steady_midspan_makes_the_point_unsettled():
    """Mode 2 has a node at midspan. Inside its parametric zone it grows from a seed while the
    midspan (mode 1, driven below resonance) is steady: at 2.5 N the point was called steady
    with q_2 still growing 44-fold over the tail. The point must be unsettled there, and stay
    steady below the zone (2.2 N: q_2 decays) and where q_2 has settled on its own orbit
    (2.9 N). Whether q_2 grows, decays or has settled is taken from SciPy on the independent
    Galerkin reference, and the tail amplitudes are compared with it."""
    ds = sweep.run(sweep.load_scene_text(HIDDEN), progress=False)
    states = [str(s) for s in np.asarray(ds["state"].attrs["flag_meanings"].split())[
        ds["state"].values.ravel()]]
    assert states == ["steady", "unsettled", "steady"]
    q2 = ds["modal_amplitude"].sel(mode=2).values.ravel()
    for i, amplitude in enumerate((2.2, 2.5, 2.9)):
        quarters = _quarters(amplitude)
        growing = all(b > 1.5 * a for a, b in zip(quarters, quarters[1:]))
        decaying = all(b < a / 1.5 for a, b in zip(quarters, quarters[1:]))
        settled = max(quarters) < 1.001 * min(quarters)
        assert (growing, decaying, settled) == [(False, True, False), (True, False, False),
                                                (False, False, True)][i], quarters
        assert q2[i] == pytest.approx(max(quarters), rel=0.05)
    assert np.isnan(ds["settling_time"].values.ravel()[1])


def _scene(modes, lengths=(0.4, 0.7), frequencies=(12.0, 40.0)):
    text = f"""
name = "modes-check"
[model]
modes = {modes}
membrane = 0.375
[cable]
inertia = 2.865e-12
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.5
[solver]
t_end = 3.0
[axes]
length = {list(lengths)}
base_frequency = {list(frequencies)}
"""
    return text


def test_sweep_modes_reports_the_changes_of_the_two_runs(tmp_path, capsys):
    path = tmp_path / "modes-check.toml"
    path.write_text(_scene(1))
    assert main(["modes", str(path), "-q", "--tolerance", "0.001"]) == 0
    out = capsys.readouterr().out
    coarse = sweep.run(sweep.load_scene(str(path)), progress=False)
    fine = sweep.run(sweep.load_scene(str(path), overrides={"model.modes": 3}), progress=False)
    assert "modes 1 against 3, 4 points" in out
    rel = np.abs(fine["amplitude"] - coarse["amplitude"]) / np.abs(fine["amplitude"])
    largest = float(rel.max())
    line = next(l for l in out.splitlines() if l.strip().startswith("amplitude "))
    assert float(line.split()[1]) == pytest.approx(largest, rel=1e-2)
    assert f"{int((rel > 0.001).sum())}/4" in line
    report = compare(coarse, fine, tolerance=10.0)
    assert report.enough() == (report.state_changes == 0)
    # The 0.7 m span's third mode (9 f1 = 54 Hz unloaded) is driven hard at 40 Hz with its
    # stretching: one mode is far off there, and the verdict says so.
    assert "NOT enough" in out


def test_sweep_modes_refuses_what_it_cannot_compare(tmp_path, capsys):
    path = tmp_path / "modes-check.toml"
    path.write_text(_scene(1))
    assert main(["modes", str(path), "--tolerance", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--tolerance" in err
    assert main(["modes", "paper-fig5"]) == 2          # refused before anything runs
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "model.coefficients" in err and "paper" in err
    assert "model.modes" not in err              # a key the user never set
    assert main(["modes", str(path), "--modes", "11"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--modes 11" in err and "1 to 10" in err


SWEPT_SCENE = """
name = "modes-sweep"
[model]
membrane = 0.375
[load]
amplitude = 0.0
[cable]
inertia = 2.865e-12
damping_ratio = 0.02
[base]
acceleration_g = 1.0
sweep = { start = 20.0, stop = 40.0, rate = 60.0 }
[outputs]
envelope = true
[axes]
length = [0.4]
"""


def test_sweep_modes_compares_a_sine_sweep_and_says_when_one_mode_is_not_enough(tmp_path,
                                                                                  capsys):
    """A 1 s sweep over 20-40 Hz of a 0.4 m span (f1 = 23.9 Hz, f3 = 215 Hz): its points end
    'completed', and the check compares what a sweep has (peak amplitude, peak frequency,
    envelope), each change the one recomputed here from two plain runs; the third mode's
    quasi-static share moves the peak by about 4 % (measured 4.3 %), so one mode is not
    enough for 1 %."""
    path = tmp_path / "modes-sweep.toml"
    path.write_text(SWEPT_SCENE)
    assert main(["modes", str(path), "-q", "--tolerance", "0.01"]) == 0
    out = capsys.readouterr().out
    coarse = sweep.run(sweep.load_scene(str(path)), progress=False)
    fine = sweep.run(sweep.load_scene(str(path), overrides={"model.modes": 3}), progress=False)
    for name in ("peak_amplitude", "peak_frequency", "envelope"):
        rel = np.abs(fine[name] - coarse[name]) / np.abs(fine[name])
        line = next(l for l in out.splitlines() if l.strip().startswith(name + " "))
        assert float(line.split()[1]) == pytest.approx(float(rel.max()), rel=1e-2), line
    peak = float((abs(fine["peak_amplitude"] - coarse["peak_amplitude"])
                  / fine["peak_amplitude"]).max())
    assert 0.02 < peak < 0.1
    assert "1 mode: NOT enough for 0.01" in out


def test_a_comparison_of_nothing_gives_no_verdict():
    """Every point failed in both runs: nothing is compared, and the report says so instead
    of 'enough'."""
    path_text = _scene(1, lengths=(0.4,), frequencies=(12.0,))
    coarse = sweep.run(sweep.load_scene_text(path_text), progress=False)
    attrs = coarse["state"].attrs
    diverged = int(attrs["flag_values"][attrs["flag_meanings"].split().index("diverged")])
    failed = coarse.copy(deep=True)
    failed["state"][...] = diverged
    report = compare(failed, failed, tolerance=0.01)
    assert not report.compared() and not report.enough()
    assert "no verdict" in report.text() and "enough for" not in report.text()


def test_sweep_modes_compares_a_random_results_means_once_a_point():
    """A random result's means over its records (what `sweep design --max-rms` reads) are
    compared, once per point where every record succeeded (the state has a realisation
    dimension, the mean does not)."""
    import xarray as xr
    from sweep.convergence import compare
    state = xr.DataArray(np.full((2, 3), 8, np.int8), dims=("length", "realisation"),
                         coords={"length": [0.1, 0.2], "realisation": [0, 1, 2]},
                         attrs={"flag_values": np.arange(9, dtype=np.int8),
                                "flag_meanings": " ".join(["invalid_input", "decayed", "steady",
                                                           "modulated", "unsettled",
                                                           "diverged", "step_size_too_small",
                                                           "max_steps_reached",
                                                           "completed"])})
    coarse = xr.Dataset({"state": state,
                         "rms_deflection_mean": ("length", [1.0e-3, 2.0e-3])})
    fine = coarse.copy(deep=True)
    fine["rms_deflection_mean"] = ("length", [1.0e-3, 2.2e-3])
    fine["state"].values[0, 1] = 5                       # a record that diverged: not compared
    report = compare(coarse, fine, 0.01)
    change = next(c for c in report.changes if c.metric == "rms_deflection_mean")
    assert change.compared == 1 and change.over == 1
    assert change.relative == pytest.approx(0.2 / 2.2)
