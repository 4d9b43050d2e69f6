"""Inputs that used to give a plausible but wrong answer, now refused, flagged or warned.

- longitudinal spans whose time-level count overflows int64 (load_scene refuses; the kernel
  flags them itself);
- transverse runs shorter than one oscillation, which moved little and were called steady;
- settings that were silently ignored: cable data under coefficients = 'paper', a min_step
  above t_end or max_step, snapshot times after t_end, a scene whose every point starts at rest
  at q = 0 (the model has no forcing, so it computes q = 0).
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

import sweep
from sweep.errors import CableSweepWarning, SceneError
from sweep.kernels import longitudinal as lk
from sweep.kernels import metrics as km
from sweep.kernels import transverse as tk
from sweep.scene import load_scene, load_scene_text

from conftest import param_row, settings, solve, sweep_env

LONG = '[model]\nkind = "longitudinal"\n'
E, RHO, A = 1.1e11, 8900.0, 6e-6
WAVE = math.sqrt(E / RHO)


def scene_error(text: str, overrides=None) -> str:
    with pytest.raises(SceneError) as info:
        load_scene_text(text, source="t.toml", overrides=overrides)
    message = str(info.value)
    assert "\n" not in message
    return message


# --------------------------------------------------------------------------- longitudinal


@pytest.mark.parametrize("solver, keys", [
    ("transits = 1e19", "solver.transits"),           # 1e22 levels at 1000 intervals
    ("courant = 1e-308", "solver.courant"),          # dt underflows: t_end / dt = inf
    ("t_end = 1e300", "solver.t_end"),
])
def test_time_levels_beyond_int64_are_refused_at_load(solver, keys):
    message = scene_error(LONG + f"[solver]\n{solver}\n")
    assert keys in message and "time levels" in message and "solver.intervals" in message


def test_time_levels_within_the_limit_still_load():
    # t_end / dt = transits x intervals / courant = 8 x 1000 / 1e-12 = 8e15 < 2^62: the run
    # would take max_steps levels and say max_steps_reached (test_stress checks that state).
    load_scene_text(LONG + "[solver]\ncourant = 1e-12\n")


def _one_span(t_end: float, courant: float = 1.0, max_levels: float = 1e6,
              snapshot_times=(1e-4,)):
    """solve_batch on one 1 m Table 1 span with 100 intervals: (state, steps, reals, snap_u)."""
    p = np.array([[1.0, WAVE, E * A, 4.0, t_end, 1.0]])
    s = np.zeros(lk.N_SETTINGS)
    s[lk.INTERVALS], s[lk.COURANT], s[lk.SAMPLE_DT], s[lk.MAX_LEVELS] = 100, courant, 1e-5, \
        max_levels
    snaps = np.asarray(snapshot_times, dtype=float)
    states, reals, steps = np.empty(1, np.int8), np.empty((1, lk.N_REALS)), np.empty(1, np.int64)
    hist_u, hist_f = np.empty((1, 3)), np.empty((1, 3))
    snap_u, snap_f, snap_v = (np.empty((1, snaps.size, 101)) for _ in range(3))
    lk.solve_batch(p, s, snaps, states, reals, steps, hist_u, hist_f, snap_u, snap_f, snap_v)
    return int(states[0]), int(steps[0]), reals[0], snap_u[0]


def test_kernel_flags_a_level_count_beyond_int64_as_max_steps():
    """t_end = 1e19 transits (1e21 levels): the span runs its budget and says so (it used to
    wrap round to -2^63 levels: completed, zero steps, zero response)."""
    dt = 0.01 / WAVE                         # C dx / a
    state, steps, reals, _ = _one_span(1e19 / WAVE, max_levels=5000)
    assert state == lk.MAX_STEPS and steps == 5000
    assert reals[lk.TIME_STEP] == pytest.approx(dt, rel=1e-15)
    assert reals[lk.FAILURE_TIME] == pytest.approx(5000 * dt, rel=1e-12)
    # 5000 levels are 50 transits: the end moved (d'Alembert: peak 2 P0 l / EA).
    assert reals[lk.PEAK_END_DISPLACEMENT] == pytest.approx(2 * 4.0 / (E * A), rel=1e-9)


def test_kernel_budget_beyond_int64_is_capped():
    state, steps, _, _ = _one_span(8.0 / WAVE, max_levels=1e19)
    assert state == lk.COMPLETED and steps == 800


def test_kernel_refuses_a_time_step_that_underflows():
    # dt = 1e-308 x 0.01 / a is below the smallest double: t_end / dt is not a number of levels.
    state, steps, reals, snap = _one_span(8.0 / WAVE, courant=1e-308)
    assert state == lk.INVALID_INPUT and steps == 0
    assert np.isnan(reals).all() and np.isnan(snap).all()


def test_kernel_snapshot_beyond_int64_levels_is_nan_not_wrapped():
    # courant 1e-300: dt ~ 2.8e-306 s, so a 1e-4 s snapshot is ~3.5e301 levels away.
    state, steps, _, snap = _one_span(8.0 / WAVE, courant=1e-300, max_levels=100)
    assert state == lk.MAX_STEPS and steps == 100 and np.isnan(snap).all()


# --------------------------------------------------------------------------- transverse


PERIOD = 0.185                                  # s, the issue's natural period
W = 2.0 * math.pi / PERIOD


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
@pytest.mark.parametrize("t_end, tol", [(0.005, 0.02), (0.01, 0.05)])
def test_run_shorter_than_one_period_is_unsettled(driver, t_end, tol):
    """q = q0 cos(W t) run for a few % of its period: the tail [t_end/2, t_end] moves less than
    the band tol x A (closed form below), so 'moved little' called it steady; it is unsettled
    (too few oscillations to judge)."""
    q0 = 1e-4
    tail = q0 * (math.cos(W * t_end / 2) - math.cos(W * t_end))
    assert tail < tol * q0 * math.cos(W * t_end / 2)   # the old rule's case
    states, reals, _, _ = solve(param_row(k0=W * W, q0=q0), settings(t_end=t_end, tol=tol),
                                driver=driver)
    assert states[0] == km.UNSETTLED
    assert math.isnan(reals[0, tk.SETTLING])
    assert reals[0, tk.AMPLITUDE] == pytest.approx(q0 * math.cos(W * t_end / 2), rel=1e-6)


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
def test_slow_swing_about_a_buckled_equilibrium_is_unsettled(driver):
    """k0 = -1, g0 = 1: equilibrium q = 1, linearised w = sqrt(2) (period 4.4 s). Started
    0.05 away and run 0.5 s, q moves 0.05 (cos(0.35) - cos(0.71)) = 0.009 in the tail, under
    the band 0.02, but swings 0.05 about its equilibrium: unsettled."""
    w = math.sqrt(2.0)
    assert 0.05 * (math.cos(w * 0.25) - math.cos(w * 0.5)) < 0.02 * 1.0
    states, _, _, _ = solve(param_row(k0=-1.0, g0=1.0, q0=1.05), settings(t_end=0.5),
                            driver=driver)
    assert states[0] == km.UNSETTLED


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
@pytest.mark.parametrize("q0", [1.0, 1.0 + 1e-3])
def test_short_run_on_a_buckled_equilibrium_is_steady(driver, q0):
    """A span started on (or within the band of) its post-buckled equilibrium q = 1 is at rest
    there however short the run: steady, as before."""
    states, reals, _, _ = solve(param_row(k0=-1.0, g0=1.0, q0=q0), settings(t_end=0.5),
                                driver=driver)
    assert states[0] == km.STEADY
    assert reals[0, tk.AMPLITUDE] == pytest.approx(q0, abs=2e-3)


def test_issue_scene_shorter_than_the_period_is_unsettled():
    """The harness span (1 m, W = 0.5 w1) run for 0.01 s, far less than its natural period
    1/f1 with f1 = (pi/l)^2 sqrt(EI/(rho A)) / (2 pi): unsettled, no settling time (it used to
    be steady with a settling time)."""
    scene = load_scene("harness-parametric", overrides={
        "axes.length": [1.0], "axes.frequency_ratio": [0.5], "solver.t_end": 0.01})
    ds = sweep.run(scene, progress=False)
    ei_rho_a = E * 2.865e-12 / (RHO * A)
    f1 = (math.pi / 1.0) ** 2 * math.sqrt(ei_rho_a) / (2 * math.pi)
    assert ds["natural_frequency"].values.item() == pytest.approx(f1, rel=1e-12)
    assert 0.01 < 0.1 / f1
    assert ds["state"].values.item() == km.UNSETTLED
    assert np.isnan(ds["settling_time"].values).all()


# --------------------------------------------------------------------------- ignored settings


@pytest.mark.parametrize("key, value", [
    ("cable.youngs_modulus", 2e11), ("cable.density", 7800.0), ("cable.area", 1e-5),
    ("cable.inertia", 1e-11), ("model.membrane", 0.25)])
def test_paper_coefficients_refuse_other_cable_data(key, value):
    message = scene_error('[model]\ncoefficients = "paper"\n', overrides={key: value})
    assert f"'{key}'" in message and "ignores it" in message and "consistent" in message
    # the consistent model uses the same key
    load_scene_text("[initial]\ndisplacement = 1e-4\n", overrides={key: value})


def test_paper_coefficients_accept_table_1_values_and_resolved_scenes():
    load_scene_text('[model]\ncoefficients = "paper"\nmembrane = 0.375\n[cable]\n'
                    'youngs_modulus = 1.1e11\ndensity = 8900\narea = 6e-6\ninertia = 5.73e-12\n')
    for name in ("paper-fig5", "harness-parametric", "paper-fig7"):
        scene = load_scene(name)
        assert load_scene_text(scene.to_toml()) == scene
    bare = load_scene_text('[model]\ncoefficients = "paper"\n')      # inertia defaulted
    assert load_scene_text(bare.to_toml()) == bare


@pytest.mark.parametrize("solver, fragment", [
    ("t_end = 1.0\nmin_step = 2.0", "solver.t_end"),
    ("min_step = 0.1\nmax_step = 0.01", "solver.max_step"),
])
def test_min_step_above_t_end_or_max_step_is_refused(solver, fragment):
    message = scene_error(f"[solver]\n{solver}\n")
    assert "'solver.min_step'" in message and fragment in message


def test_min_step_within_both_loads():
    scene = load_scene_text("[solver]\nt_end = 1.0\nmin_step = 1e-3\nmax_step = 1e-2\n"
                            "[initial]\ndisplacement = 1e-4\n")
    assert scene.get("solver.min_step") == 1e-3


def test_snapshot_after_an_explicit_t_end_is_refused():
    message = scene_error(LONG + "[solver]\nt_end = 1e-3\n[outputs]\nsnapshot_times = [5e-4, 2e-3]\n")
    assert "item 2" in message and "solver.t_end" in message
    # an override of t_end replaces the scene's transits and is checked the same way
    message = scene_error(LONG + "[outputs]\nsnapshot_times = [2e-3]\n",
                          overrides={"solver.t_end": 1e-3})
    assert "solver.t_end" in message


def test_a_scene_of_the_zero_solution_warns():
    with pytest.warns(CableSweepWarning, match="no keys.*stays at q = 0"):
        load_scene_text("")
    with pytest.warns(CableSweepWarning, match="stays at q = 0"):
        load_scene_text("[axes]\ninitial_displacement = [0.0]\n")
    # it says why: with no end load, not that the end load changes the stiffness
    with pytest.warns(CableSweepWarning, match="nothing drives the span"):
        load_scene_text("[cable]\nlength = 0.5\n")
    with pytest.warns(CableSweepWarning, match="end load only changes the stiffness"):
        load_scene_text("[load]\namplitude = 2.0\nfrequency_ratio = 2.0\n")


@pytest.mark.parametrize("text", ["[initial]\ndisplacement = 1e-4\n",
                                  "[axes]\ninitial_velocity = [0.0, 1e-3]\n",
                                  '[model]\ncoefficients = "paper"\n',   # v0 = 0.0321 m/s
                                  LONG + "[load]\namplitude = 4.0\n"])    # the wave's cause
def test_a_scene_with_a_start_does_not_warn(text):
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        load_scene_text(text)


@pytest.mark.slow
def test_cli_says_in_one_line_what_an_empty_scene_ran(tmp_path):
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    done = subprocess.run([sys.executable, "-m", "sweep.cli", "run", str(empty), "-q", "-o",
                           str(tmp_path / "empty.nc")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600,
                          env=sweep_env())
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stderr.splitlines() if "warning" in line]
    assert len(lines) == 1 and lines[0].startswith("sweep: warning: the scene sets no keys")
    assert "1 m span" in lines[0] and "stays at q = 0" in lines[0]
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("text, key", [
    ("[outputs]\nsnapshot_times = [0.1]", "outputs.snapshot_times"),
    ("[outputs]\nhistories = true", "outputs.histories"),
    ("[outputs]\nnormalised = true", "outputs.normalised"),
    ("[run]\nworkers = 2", "run.workers"),
    ('[run]\nbackend = "threads"\nworkers = 2', "run.workers"),
])
def test_keys_a_transverse_threads_run_would_ignore_are_refused(text, key):
    with pytest.raises(sweep.UserError, match=f"scene key '{key}'.*would ignore it"):
        sweep.load_scene_text(text + "\n[initial]\ndisplacement = 1e-4")


@pytest.mark.parametrize("text, key", [
    ("[solver]\nintervals = 500", "solver.intervals"),
    ("[solver]\ncourant = 0.9", "solver.courant"),
    ('[load]\ntype = "constant"\namplitude = 1.0\nfrequency_ratio = 2.0',
     "load.frequency_ratio"),
])
def test_keys_a_transverse_run_would_ignore_are_refused(text, key):
    """The longitudinal grid's keys, and a load frequency with a constant load, were taken and
    stored in the result's scene without effect (a reviewer's finding)."""
    with pytest.raises(sweep.UserError, match=f"scene key '{key}'.*would.* ignore"):
        sweep.load_scene_text(text + "\n[initial]\ndisplacement = 1e-4")


@pytest.mark.parametrize("overrides", [
    {"cable.damping_ratio": 0.3}, {"initial.displacement": 1e-3}, {"load.frequency_ratio": 2.0},
    {"load.frequency": 50.0},
    {"model.membrane": 0.375}, {"model.coefficients": "paper"}, {"solver.rtol": 1e-3},
    {"solver.method": "dop853"}, {"solver.max_step": 1e-5}, {"metrics.tail": 0.25},
    {"outputs.settling_time": False}, {"outputs.time_series": True},
    {"outputs.amplitude": False}])
def test_keys_a_longitudinal_run_would_ignore_are_refused(overrides):
    """Each was accepted in a longitudinal scene, stored in its result and ignored: a damping
    ratio of 0.3 gave the undamped wave (a reviewer's finding). A resolved scene (every key
    written out at its default) still loads back."""
    with pytest.raises(sweep.UserError, match="would ignore it"):
        sweep.load_scene("paper-fig7", overrides)
    scene = sweep.load_scene("paper-fig7")
    assert sweep.load_scene_text(scene.to_toml()) == scene


def test_workers_with_the_dask_backend_and_resolved_scenes_still_load():
    scene = sweep.load_scene_text('[run]\nbackend = "dask"\nworkers = 2\n'
                                  "[initial]\ndisplacement = 1e-4")
    assert scene.get("run.workers") == 2
    for name in sweep.builtin_scenes():          # resolved scenes write every key out
        sweep.load_scene_text(sweep.load_scene(name).to_toml())


def test_a_longitudinal_scene_without_an_end_load_warns():
    """The end load is the longitudinal case's only cause (no end load by default since the
    4 N default went): a scene without one would give a span at rest everywhere, so it warns;
    with a load, or a load axis with a load somewhere, it does not."""
    text = 'name = "wave"\n[model]\nkind = "longitudinal"\n[solver]\nintervals = 50\n'
    with pytest.warns(CableSweepWarning, match="longitudinal scene is the wave"):
        sweep.load_scene_text(text)
    for loaded in ("[load]\namplitude = 4.0\n", "[axes]\nload_amplitude = [0.0, 2.0]\n"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", CableSweepWarning)
            sweep.load_scene_text(text + loaded)


@pytest.mark.parametrize("level_g, warned", [(2.0, False), (6.0, True)])
def test_a_span_deflected_beyond_moderate_slopes_is_warned_of(level_g, warned):
    """A 0.5 m span whose clamps let it slide (no stretching to hold it) at resonance: 39 mm at
    2 g (slope pi w / l about 0.25) runs quietly; at 6 g it passes a slope of 0.5, where the
    model's series in the squared slope is no longer accurate: one warning, with the count and
    the slope (a reviewer's spans at slopes of 0.4-0.7 were reported steady without a word)."""
    import warnings
    text = ("[cable]\nlength = 0.5\ndamping_ratio = 0.02\n[clamps]\naxial_stiffness = 0.0\n"
            f"[base]\nacceleration_g = {level_g}\nfrequency_ratio = 1.0\n[solver]\nt_end = 3.0\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = sweep.run(sweep.load_scene_text(text), progress=False)
    said = [str(w.message) for w in caught if "moderate slopes" in str(w.message)]
    steepest = max(float(ds[n].max()) for n in ("amplitude", "peak_amplitude") if n in ds)
    assert (math.pi * steepest / 0.5 > 0.5) == warned
    assert len(said) == (1 if warned else 0)
    if warned:
        assert said[0].startswith("1 of 1 points")
