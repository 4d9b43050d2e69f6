"""The central-difference kernel against the exact d'Alembert solution (docs/model.md sec. 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep.kernels import longitudinal as lk

E, RHO, A = 1.1e11, 8900.0, 6e-6
WAVE = math.sqrt(E / RHO)
EA = E * A


def exact_u(x, t, length, load):
    """d'Alembert by images: fronts from the loaded end, reflected at both ends."""
    s = length - x
    e0 = load / EA
    ramp = lambda z: np.maximum(z, 0.0)   # noqa: E731
    u = np.zeros(np.broadcast(x, t).shape)
    n_max = int(WAVE * np.max(t) / (2 * length)) + 2
    for n in range(n_max):
        u += e0 * (-1) ** n * (-ramp(WAVE * t - 2 * n * length - s)
                               + ramp(WAVE * t - 2 * (n + 1) * length + s))
    return u


def run_span(courant, intervals=1000, transits=8.0, length=1.0, load=4.0, levels=(),
             n_hist=0, dt_sample=0.0):
    dx = length / intervals
    dt = courant * dx / WAVE
    p = np.array([[length, WAVE, EA, load, transits * length / WAVE, length]])
    s = np.array([intervals, courant, dt_sample, 1e12])
    times = np.asarray(levels, dtype=float) * dt
    out = dict(states=np.empty(1, np.int8), reals=np.empty((1, lk.N_REALS)),
               steps=np.empty(1, np.int64), hist_u=np.empty((1, n_hist)),
               hist_f=np.empty((1, n_hist)))
    snaps = [np.empty((1, len(times), intervals + 1)) for _ in range(3)]
    lk.solve_batch(p, s, times, out["states"], out["reals"], out["steps"], out["hist_u"],
                   out["hist_f"], *snaps)
    return out, snaps, dt


def test_courant_one_is_exact_at_the_nodes_over_eight_transits():
    levels = [1, 137, 500, 999, 1000, 1001, 2500, 4321, 7999]
    out, (u, f, v), dt = run_span(1.0, levels=levels)
    x = np.linspace(0.0, 1.0, 1001)
    peak = 2 * 4.0 * 1.0 / EA
    for i, n in enumerate(levels):
        np.testing.assert_allclose(u[0, i], exact_u(x, n * dt, 1.0, 4.0), rtol=0,
                                   atol=1e-12 * peak)
    assert out["states"][0] == lk.COMPLETED


def test_courant_one_metrics_equal_the_closed_forms():
    out, _, _ = run_span(1.0)
    r = out["reals"][0]
    assert r[lk.PEAK_END_DISPLACEMENT] == pytest.approx(2 * 4.0 / EA, rel=1e-12)
    assert r[lk.PEAK_FIXED_END_FORCE] == pytest.approx(2 * 4.0, rel=1e-12)
    assert r[lk.ARRIVAL_TIME] == pytest.approx(1.0 / WAVE, rel=1e-9)
    assert r[lk.PERIOD] == pytest.approx(4.0 / WAVE, rel=1e-9)


def test_fixed_end_force_is_a_square_wave_between_0_and_2p0():
    dt_sample = 0.01 / WAVE
    n_hist = 801
    out, _, _ = run_span(1.0, n_hist=n_hist, dt_sample=dt_sample)
    t = np.arange(n_hist) * dt_sample * WAVE           # in transits
    f = out["hist_f"][0] / 4.0
    phase = np.mod(t, 4.0)
    away = np.abs(np.mod(t - 1.0, 2.0)) > 0.02         # keep off the jumps at 1, 3, 5, 7
    expected = np.where((phase > 1.0) & (phase < 3.0), -2.0, 0.0)
    np.testing.assert_allclose(f[away], expected[away], atol=1e-9)
    end = out["hist_u"][0] / (4.0 / EA)               # triangle: 0 -> -2 at t = 2 -> 0 at 4
    tri = -np.where(phase <= 2.0, phase, 4.0 - phase)
    np.testing.assert_allclose(end, tri, atol=1e-9)


@pytest.mark.parametrize("courant", [0.9, 0.5])
def test_below_one_the_error_falls_with_refinement(courant):
    errors = []
    for intervals in (100, 200, 400):
        dt = courant * (1.0 / intervals) / WAVE
        level = int(round(1.5 / WAVE / dt))
        _, (u, _, _), dt = run_span(courant, intervals=intervals, transits=2.0, levels=[level])
        x = np.linspace(0.0, 1.0, intervals + 1)
        errors.append(np.max(np.abs(u[0, 0] - exact_u(x, level * dt, 1.0, 4.0))))
    assert errors[1] < errors[0] and errors[2] < errors[1]
    assert errors[2] < 0.7 * errors[0]


def test_just_below_one_stays_bounded_over_a_million_steps():
    out, _, _ = run_span(0.999, intervals=50, transits=1e6 / 50 * 0.999)
    assert out["states"][0] == lk.COMPLETED and out["steps"][0] >= 1_000_000
    assert out["reals"][0, lk.PEAK_END_DISPLACEMENT] < 2.2 * 4.0 / EA


def test_naive_start_would_be_wrong_taylor_start_is_exact():
    """The first level: the loaded end has moved by C^2 dx P0/EA, the rest not at all."""
    _, (u, _, _), dt = run_span(1.0, intervals=10, transits=1.0, levels=[1])
    assert u[0, 0, -1] == pytest.approx(-0.1 * 4.0 / EA, rel=1e-14)
    assert np.all(u[0, 0, :-1] == 0.0)


def test_invalid_span_gets_a_state():
    p = np.array([[1.0, WAVE, EA, 4.0, 1e-3, 1.0], [-1.0, WAVE, EA, 4.0, 1e-3, 1.0]])
    states = np.empty(2, np.int8)
    reals = np.empty((2, lk.N_REALS))
    lk.solve_batch(p, np.array([20, 1.0, 0.0, 1e12]), np.empty(0), states, reals,
                   np.empty(2, np.int64), np.empty((2, 0)), np.empty((2, 0)),
                   *[np.empty((2, 0, 21)) for _ in range(3)])
    assert list(states) == [lk.COMPLETED, lk.INVALID_INPUT]


def test_paper_fig7_scene_end_to_end(tmp_path):
    ds = sweep.run(sweep.load_scene("paper-fig7"), output=tmp_path / "fig7.nc", progress=False)
    assert float(ds["dynamic_amplification"]) == pytest.approx(2.0, rel=1e-9)
    assert float(ds["force_amplification"]) == pytest.approx(2.0, rel=1e-9)
    assert float(ds["period"]) == pytest.approx(4 * float(ds["transit_time"]), rel=1e-9)
    ratio = ds["snapshot_force_ratio"]
    assert ratio.dims == ("snapshot_time", "position")
    # At 0.25 l/a: -1 behind the front (x/l > 0.75), 0 ahead of it.
    first = ratio.isel(snapshot_time=0)
    assert float(first.sel(position=0.9, method="nearest")) == pytest.approx(-1.0, abs=1e-6)
    assert float(first.sel(position=0.5, method="nearest")) == pytest.approx(0.0, abs=1e-6)
    vel = ds["snapshot_velocity_ratio"].isel(snapshot_time=0)
    assert float(vel.sel(position=0.9, method="nearest")) == pytest.approx(-1.0, abs=1e-6)
    assert ds["fixed_end_force"].attrs["units"] == "N"


def test_longitudinal_sweep_over_length_and_load():
    scene = sweep.load_scene_text("""
[model]
kind = "longitudinal"
[solver]
intervals = 200
[axes]
length = [0.3, 0.6, 1.2]
load_amplitude = [1.0, 10.0]
""")
    ds = sweep.run(scene, progress=False)
    assert ds["peak_end_displacement"].dims == ("length", "load_amplitude")
    exact = 2 * ds["load_amplitude"] * ds["length"] / EA
    np.testing.assert_allclose(ds["peak_end_displacement"], exact.transpose(*ds["state"].dims),
                               rtol=1e-10)
    np.testing.assert_allclose(ds["period"], (4 * ds["length"] / WAVE).broadcast_like(ds["period"]),
                               rtol=1e-9)


def test_courant_below_one_warns_once():
    scene = sweep.load_scene_text("[model]\nkind = 'longitudinal'\n[solver]\ncourant = 0.8\n"
                                  "intervals = 50\n[axes]\nlength = [0.5, 1.0]")
    with pytest.warns(sweep.CableSweepWarning, match="ring") as record:
        sweep.run(scene, progress=False)
    assert len([w for w in record if issubclass(w.category, sweep.CableSweepWarning)]) == 1


def test_transverse_constant_load_above_buckling_settles_or_diverges():
    """Eq.28-29 through RK45: post-buckled equilibrium with alpha > 0, divergence with 0."""
    scene = sweep.load_scene_text("""
[model]
membrane = 0.375
[cable]
damping_ratio = 0.05
inertia = 5.73e-12              # m^4, the paper's value (EI below), whatever the default
[load]
type = "constant"
amplitude = 8.0
[initial]
displacement = 1e-4
[axes]
membrane = [0.375, 0.0]
[solver]
t_end = 10.0
""")
    ds = sweep.run(scene, progress=False)
    assert float(ds["load_ratio"]) > 1.0                      # above Pcr = EI pi^2 = 6.2 N
    from sweep.kernels import metrics as km
    steady, gone = ds["state"].values
    assert steady == km.STEADY and gone == km.DIVERGED
    EI, rhoA, k = 1.1e11 * 5.73e-12, 8900 * 6e-6, np.pi
    k1 = EI / rhoA * k ** 4 * (1 - 8.0 / (EI * k ** 2))
    K3 = 0.375 * 1.1e11 / 8900 * k ** 4 + 8.0 * k ** 4 / (2 * rhoA) - 1.25 * EI / rhoA * k ** 6
    q_s = np.sqrt(-k1 / K3)                                   # docs/model.md: sqrt(-k1/K3)
    assert float(ds["amplitude"][0]) == pytest.approx(q_s, rel=1e-3)
    assert 0 < float(ds["failure_time"][1]) < 10.0


def test_last_history_sample_at_t_end_is_the_exact_value():
    """8 transits of 0.3 m in 1000 intervals: 8000 dt rounds just below t_end = 1000 samples;
    the sample at t_end must still hold d'Alembert's value, not NaN."""
    scene = sweep.load_scene("paper-fig7", overrides={
        "cable.length": 0.3, "outputs.snapshot_times": [], "outputs.normalised": False})
    ds = sweep.run(scene, progress=False)
    t = ds["elapsed_time"].values
    assert t[-1] == pytest.approx(8 * 0.3 / WAVE, rel=1e-12)
    u = ds["end_displacement"].values
    assert np.isfinite(u).all()
    np.testing.assert_allclose(u, exact_u(0.3, t, 0.3, 4.0), rtol=0, atol=1e-9 * 0.3 * 4.0 / EA)
    f = ds["fixed_end_force"].values
    assert np.isfinite(f).all() and f[-1] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("t_end", [1.5e-4, 2.3e-4, 1e-12])
def test_peaks_end_at_t_end_when_it_falls_between_levels(t_end):
    """t_end not a whole number of steps: the last level lies past it. The peak end
    displacement is d'Alembert's largest |u(l, t)| over [0, t_end] (a ramp rising to t_end
    there, so its largest is at t_end), not the level's after it (14 % more at 1.5e-4 s in a
    reviewer's 10 intervals)."""
    scene = sweep.load_scene("paper-fig7", overrides={
        "solver.intervals": 10, "solver.t_end": t_end, "outputs.snapshot_times": []})
    ds = sweep.run(scene, progress=False)
    times = np.linspace(0.0, t_end, 20001)
    exact = np.max(np.abs(exact_u(1.0, times, 1.0, 4.0)))
    assert float(ds["peak_end_displacement"]) == pytest.approx(exact, rel=1e-9, abs=1e-25)


def test_more_intervals_than_memory_is_refused_in_one_line():
    """The scheme's three time levels count: 2e9 intervals would need ~48 GiB a span."""
    scene = sweep.load_scene("paper-fig7", overrides={
        "solver.intervals": 2_000_000_000, "outputs.snapshot_times": []})
    with pytest.raises(sweep.UserError, match="solver.intervals") as caught:
        sweep.run(scene, progress=False)
    assert "time levels" in str(caught.value) and "\n" not in str(caught.value)
