"""Random base acceleration (docs/model.md sec. 11): the record kind of the excitation and the
statistics the kernels accumulate, against independent references.

- One realisation of the nonlinear span (1 and 3 modes) against SciPy's DOP853 at rtol 1e-10
  on the same sampled signal (the Galerkin reference of tests/galerkin.py, forced by the
  record's cubic Hermite interpolant): the RMS deflection and velocity, the peak and the
  crossings over the same window.
- A linear oscillator: the RMS over the realisations against the exact integral of |H|^2 W,
  within the statistical error of the records (docs/model.md sec. 11.3).
- The hardening oscillator under white noise: the RMS deflection against the exact
  stationary (Fokker-Planck) density, the RMS velocity against the linear one, the
  up-crossing rates against Rice's formula with that density; equivalent linearisation is
  shown to be further off than the engine.
- The scene: rules refused in one line, the realisation dimension selectable, the same bits
  over threads and chunks.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import sweep
from sweep.errors import SceneError
from sweep.execute import transverse_chunk
from sweep.kernels import layout as tk
from sweep.kernels import oscillator as osc
from sweep.models import random as rnd
from sweep.models import random_scene
from sweep.models.random_outputs import RandomInputs
from sweep.schema import STANDARD_GRAVITY as G

from galerkin import Cable, Projection, participation

FLAT = [[10.0, 0.04], [500.0, 0.04]]        # g^2/Hz: flat over the span's response band


def scene(overrides: dict | None = None, axes: dict | None = None):
    """A random scene of a 0.3 m Table-1 span (f1 = 42.4 Hz; the inertia of tests/galerkin.py's
    Cable) under FLAT."""
    text = ["[cable]", "length = 0.3", "damping_ratio = 0.05", "inertia = 2.865e-12",
            "[base]", f"asd_g2 = {FLAT}", "duration = 1.0", "realisations = 2", "seed = 3"]
    if axes:
        text.append("[axes]")
        text += [f"{k} = {v}" for k, v in axes.items()]
    return sweep.load_scene_text("\n".join(text) + "\n", overrides=overrides or {})


# ------------------------------------------------ 1. one realisation against SciPy DOP853

def _window_statistics(sol, weights, t0, t1, n_modes, rhs, record, fs, gamma):
    """RMS of the midspan deflection and velocity, its largest |value| and its up-crossings of
    zero over [t0, t1] (s), from SciPy's dense output on a fine grid (Simpson's rule)."""
    t = np.linspace(t0, t1, 400_001)
    y = sol(t)
    q = weights @ y[:n_modes]
    v = weights @ y[n_modes:]
    h = t[1] - t[0]

    def simpson(values):
        return h / 3.0 * (values[0] + values[-1] + 4.0 * values[1:-1:2].sum()
                          + 2.0 * values[2:-1:2].sum())
    span = t1 - t0
    up = int(np.count_nonzero((q[:-1] < 0.0) & (q[1:] >= 0.0)))
    return (math.sqrt(simpson(q * q) / span), math.sqrt(simpson(v * v) / span),
            float(np.max(np.abs(q))), up)


@pytest.mark.parametrize("n_modes, drivers, ramp", [(1, ("scalar", "lanes"), 0.0),
                                                    (3, ("scalar", "lanes"), 0.0),
                                                    (1, ("lanes",), 0.25),
                                                    pytest.param(3, ("scalar",), 0.25,
                                                                 marks=pytest.mark.slow)])
def test_one_realisation_matches_scipy_on_the_same_record(n_modes, drivers, ramp):
    """A 0.3 m span with the paper's membrane stretching (strongly nonlinear at this level:
    the linear RMS is 1.27x the nonlinear one), 1 s of one record: RMS deflection and velocity
    to 1e-6, the peak to 1e-6 and the zero up-crossings to one, against SciPy DOP853 at rtol
    1e-10 on the Galerkin reference forced by the same Hermite interpolant; one mode and
    several by both drivers (the lanes take records too). With base.ramp the record's level
    rises over its first `ramp` s by (1 - cos(pi t / ramp)) / 2 (written here), and the
    statistics start that much later."""
    sc = scene({"model.modes": n_modes, "model.membrane": 0.375, "solver.rtol": 1e-10,
                "base.realisations": 1, "base.ramp": ramp})
    random = RandomInputs.of(sc.values)
    record = random.records()[0]
    fs = random.sample_rate
    cable = Cable(length=0.3, damping_ratio=0.05, membrane=0.375)
    proj = Projection(cable, n_modes, None)
    n = np.arange(1, n_modes + 1)
    damping = 2.0 * cable.damping_ratio * cable.w1 * n ** 2
    gamma = participation(n_modes)

    def f(t, y):
        q, v = y[:n_modes], y[n_modes:]
        a_b = float(rnd.hermite(record, fs, t))
        if t < ramp:
            a_b *= 0.5 - 0.5 * math.cos(math.pi * t / ramp)
        return np.concatenate((v, -damping * v - proj.force(q, 0.0) - gamma * a_b))
    scale = 1e-3
    atol = np.concatenate((np.full(n_modes, 1e-13 * scale),
                           np.full(n_modes, 1e-13 * scale * n_modes ** 2 * cable.w1)))
    sol = solve_ivp(f, (0.0, random.t_end), np.zeros(2 * n_modes), method="DOP853",
                    rtol=1e-10, atol=atol, dense_output=True, max_step=1.0 / fs).sol
    weights = np.sin(n * math.pi / 2.0)
    for driver in drivers:
        ds = sweep.run(scene({"model.modes": n_modes, "model.membrane": 0.375,
                              "solver.rtol": 1e-10, "base.realisations": 1,
                              "solver.driver": driver, "base.ramp": ramp}))
        assert int(ds.state.values.ravel()[0]) == 8           # completed
        window = float(ds.statistics_window.values.ravel()[0])
        transient = math.log(1.0 / float(sc.values["metrics.tolerance"])) / (
            cable.damping_ratio * cable.w1)
        assert window == pytest.approx(random.t_end - ramp - transient, rel=1e-3)
        samples = record[:int(math.floor(random.t_end * fs)) + 1, 0]
        t_k = np.arange(samples.size) / fs
        rise = 0.5 - 0.5 * np.cos(np.pi * t_k / max(ramp, 1e-300))
        shaken = samples * np.where(t_k < ramp, rise, 1.0)
        assert float(ds.base_grms.values.ravel()[0]) == pytest.approx(
            math.sqrt(np.mean(shaken ** 2)) / 9.80665, rel=1e-12)
        rms_q, rms_v, peak, up = _window_statistics(sol, weights, random.t_end - window,
                                                    random.t_end, n_modes, f, record, fs,
                                                    gamma)
        assert float(ds.rms_deflection.values.ravel()[0]) == pytest.approx(rms_q, rel=1e-6)
        assert float(ds.rms_velocity.values.ravel()[0]) == pytest.approx(rms_v, rel=1e-6)
        assert float(ds.amplitude.values.ravel()[0]) == pytest.approx(peak, rel=1e-6)
        crossings = float(ds.zero_upcrossing_rate.values.ravel()[0]) * window
        assert abs(crossings - up) <= 1
        assert float(ds.linear_rms.values.ravel()[0]) > 1.1 * rms_q    # hardening


# ------------------------------------------------- 2. kernel runs on hand-made rows

def _rows(omega: float, zeta: float, k3: float, realisations: int, fs: float) -> np.ndarray:
    """Oscillator rows q'' + 2 zeta w q' + w^2 q + k3 q^3 = -a_b(t) (participation 1), one per
    realisation (the record kind's columns: level factor 1, sample rate, record index)."""
    names = {name: i for i, name in enumerate(osc.PARAM_NAMES)}
    rows = np.zeros((realisations, osc.N_PARAMS))
    for r in range(realisations):
        row = rows[r]
        row[names["mass"]], row[names["damping"]] = 1.0, 2.0 * zeta * omega
        row[names["k0"]], row[names["g0"]] = omega * omega, k3
        row[names["bound"]], row[names["q_scale"]] = 1.0, 1e-3
        row[names["v_scale"]], row[names["participation"]] = 1e-3 * omega, 1.0
        row[names["base_accel"]], row[names["base_omega"]] = 1.0, fs
        row[names["base_phase"]] = r
    return rows


def _run(rows: np.ndarray, records: rnd.Records, t_end: float, t_tail: float,
         levels: tuple = (), driver: str = "scalar") -> dict[str, np.ndarray]:
    """The one-mode kernel (driver: "scalar" or "lanes") with DOP853 at rtol 1e-7 over
    [0, t_end], statistics from t_tail (s)."""
    s = np.zeros(tk.N_SETTINGS)
    s[tk.RTOL], s[tk.T_END], s[tk.MAX_STEPS] = 1e-7, t_end, 1e9
    s[tk.MAX_STEP], s[tk.TAIL], s[tk.TOL] = math.inf, (t_end - t_tail) / t_end, 0.02
    s[tk.ATOL_SCALE], s[tk.BASE], s[tk.CONSTANT_STIFFNESS], s[tk.METHOD] = 0.01, 1, 1, 1
    s[tk.N_LEVELS] = len(levels)
    s[tk.LEVEL_0:tk.LEVEL_0 + len(levels)] = levels
    return transverse_chunk(rows, s, 0, driver, -1, False, records.values)


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
def test_linear_oscillator_rms_matches_the_exact_integral(driver):
    """A linear 60 Hz oscillator (zeta = 0.05) under FLAT: the mean over 12 records of 10 s of
    the RMS deflection, velocity and absolute acceleration against the exact integrals of
    |H|^2 W, |w H|^2 W and |1 + w^2 H|^2 W, within 4 standard errors of the ensemble (about
    1 %); the zero up-crossing rate against Rice's sqrt(m2/m0) / 2 pi. Both one-mode drivers
    (the lanes keep a record's ordinary steps' statistics in their own loop)."""
    f, w = rnd.spectrum(FLAT)
    records = rnd.synthesise(f, w, 10.0, 5000.0, 12, 11)
    omega, zeta = 2 * math.pi * 60.0, 0.05
    out = _run(_rows(omega, zeta, 0.0, 12, 5000.0), records, 10.0, 1.0, driver=driver)
    assert np.all(out["states"] == 8)
    for column, what in ((tk.RMS_DEFLECTION, "deflection"), (tk.RMS_VELOCITY, "velocity"),
                         (tk.RMS_ACCELERATION, "absolute_acceleration")):
        exact = math.sqrt(float(rnd.linear_mean_square(
            f, w, np.array([omega]), np.array([2 * zeta * omega]), np.ones(1), what=what)))
        values = out["reals"][:, column]
        error = values.std(ddof=1) / math.sqrt(values.size)
        assert abs(values.mean() - exact) < 4.0 * error, (what, values.mean(), exact, error)
        assert error < 0.02 * exact
    m0 = rnd.linear_mean_square(f, w, np.array([omega]), np.array([2 * zeta * omega]),
                                np.ones(1))
    m2 = rnd.linear_mean_square(f, w, np.array([omega]), np.array([2 * zeta * omega]),
                                np.ones(1), what="velocity")
    rice = math.sqrt(m2 / m0) / (2 * math.pi)
    assert out["reals"][:, tk.ZERO_RATE].mean() == pytest.approx(rice, rel=0.01)


def _fokker_planck(s0: float, omega: float, k3: float) -> tuple[float, callable]:
    """The exact stationary variance of q'' + 2 zeta w q' + w^2 q + k3 q^3 = white noise and
    its density p(q) ~ exp(-(q^2/2 + k3 q^4 / (4 w^2)) / s0^2), normalised (quadrature)."""
    def weight(q):
        return math.exp(-(q * q / 2.0 + k3 * q ** 4 / (4.0 * omega ** 2)) / (s0 * s0))
    lim = 12.0 * s0
    norm = quad(weight, -lim, lim, epsabs=0, epsrel=1e-12, limit=200)[0]
    var = quad(lambda q: q * q * weight(q), -lim, lim, epsabs=0, epsrel=1e-12, limit=200)[0]
    return var / norm, lambda q: weight(q) / norm


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
def test_hardening_oscillator_matches_the_fokker_planck_density(driver):
    """A 100 Hz oscillator (zeta = 0.02) with k3 such that eps = k3 s0^2 / w^2 = 1 under a flat
    spectrum (white over its response): the RMS deflection over 16 records of 16 s against the
    exact stationary value (sigma^2 / s0^2 = 0.4679 at eps = 1, by quadrature here), the RMS
    velocity against the linear Gamma^2 W / (8 zeta w) (the density's q' is Gaussian and
    linear), and the up-crossing rates of |q| at 1 and 2 sigma against Rice's 2 sigma_v p(u) /
    sqrt(2 pi). Gaussian equivalent linearisation, (sqrt(1 + 12 eps) - 1) / (6 eps), is 3.7 %
    low on the RMS: outside the tolerance the engine meets. Both one-mode drivers."""
    flat = [[5.0, 0.02], [1000.0, 0.02]]
    f, w = rnd.spectrum(flat)
    omega, zeta = 2 * math.pi * 100.0, 0.02
    s0 = math.sqrt(w[0] / (8 * zeta * omega ** 3))
    k3 = omega ** 2 / s0 ** 2                           # eps = 1
    var, density = _fokker_planck(s0, omega, k3)
    assert var / s0 ** 2 == pytest.approx(0.4679, abs=1e-4)
    sigma = math.sqrt(var)
    sigma_v = math.sqrt(w[0] / (8 * zeta * omega))
    records = rnd.synthesise(f, w, 16.0, 10_000.0, 16, 5)
    out = _run(_rows(omega, zeta, k3, 16, 10_000.0), records, 16.0, 1.0,
               levels=(sigma, 2 * sigma), driver=driver)
    assert np.all(out["states"] == 8)
    ms = out["reals"][:, tk.RMS_DEFLECTION] ** 2
    error = ms.std(ddof=1) / math.sqrt(ms.size)
    rms = math.sqrt(ms.mean())
    assert rms == pytest.approx(sigma, rel=0.015)
    assert abs(ms.mean() - var) < 4.0 * error
    linearised = s0 * math.sqrt((math.sqrt(13.0) - 1.0) / 6.0)
    assert abs(linearised / sigma - 1.0) > 0.03
    v_rms = math.sqrt(np.mean(out["reals"][:, tk.RMS_VELOCITY] ** 2))
    assert v_rms == pytest.approx(sigma_v, rel=0.015)
    for k, u in enumerate((sigma, 2 * sigma)):
        rice = 2.0 * sigma_v * density(u) / math.sqrt(2 * math.pi)
        rate = out["reals"][:, tk.LEVEL_RATE + k].mean()
        assert rate == pytest.approx(rice, rel=0.05), (u, rate, rice)


# --------------------------------------------------------------------- 3. the scene

def test_the_dataset_has_a_realisation_dimension_and_means():
    """Two levels x 2 realisations: `realisation` and `base_asd_scale` select; the means and
    intervals are over realisations; -6 dB halves the linear RMS; the records' grms equals
    the spectrum's within the sampling of a record; the same bits on one thread in chunks of
    one point as on two threads."""
    sc = scene({"outputs.clearance": [1e-4, 2e-4]}, axes={"base_asd_scale": [-6.0, 0.0]})
    ds = sweep.run(sc, threads=2)
    again = sweep.run(scene({"outputs.clearance": [1e-4, 2e-4], "run.chunk_size": 1},
                            axes={"base_asd_scale": [-6.0, 0.0]}), threads=1)
    for name in ("rms_deflection", "amplitude", "clearance_upcrossing_rate"):
        np.testing.assert_array_equal(ds[name].values, again[name].values)
    assert ds.rms_deflection.dims == ("base_asd_scale", "realisation")
    one = ds.rms_deflection.sel(base_asd_scale=-6.0, realisation=1)
    assert np.isfinite(float(one))
    np.testing.assert_allclose(ds.rms_deflection_mean.sel(base_asd_scale=0.0),
                               ds.rms_deflection.sel(base_asd_scale=0.0).mean("realisation"))
    linear = ds.linear_rms
    assert float(linear.sel(base_asd_scale=-6.0) / linear.sel(base_asd_scale=0.0)) == \
        pytest.approx(10 ** (-6 / 20), rel=1e-12)
    f, w = rnd.spectrum(FLAT)
    assert float(ds.base_grms_spectrum.sel(base_asd_scale=0.0)) == pytest.approx(rnd.grms(f, w))
    assert ds.clearance.values.tolist() == [1e-4, 2e-4]
    assert ds.exceedance_probability.dims == ("base_asd_scale", "clearance")
    assert set(np.unique(ds.state.values)) == {8}
    assert float(ds.escape_probability.max()) == 0.0
    assert np.all(np.isnan(ds.escape_time_mean.values))


@pytest.mark.parametrize("overrides, words", [
    ({"base.duration": None}, "needs base.duration"),
    ({"base.frequency": 20.0}, "replaces the sine"),
    ({"solver.t_end": 2.0}, "longer than the record"),
    ({"base.sample_rate": 900.0}, "cannot carry the spectrum"),
    ({"base.sample_rate": 1200.0}, "give at least 1250 Hz"),
    ({"outputs.clearance": [1e-3] * 5}, "1 to 4 levels"),
    ({"outputs.clearance": [1e-3, 2e-3, 1e-3]}, "a level is given twice"),
    ({"base.asd": [[10.0, 1.0], [500.0, 1.0]], "base.asd_g2": [[10.0, 0.1], [500.0, 0.1]]},
     "give one, not both"),
    ({"solver.stop_when_steady": True}, "never steady"),
])
def test_bad_random_scenes_are_one_line(overrides, words):
    """Each mistake is one SceneError line naming the key."""
    given = {k: v for k, v in overrides.items() if v is not None}
    text = ["[cable]", "length = 0.3", "damping_ratio = 0.05", "[base]",
            f"asd_g2 = {FLAT}", "realisations = 2"]
    if "base.duration" not in overrides:
        text.append("duration = 1.0")
    with pytest.raises(SceneError) as caught:
        sweep.load_scene_text("\n".join(text) + "\n", overrides=given)
    message = str(caught.value)
    assert "\n" not in message and words in message, message


@pytest.mark.parametrize("n_modes", [1, 2])
def test_records_run_in_the_lanes_the_same_over_threads_and_chunks(n_modes):
    """One and two clamped modes on the lanes (named: with 4 records a basis the default of
    two modes would be the scalar driver, sweep/models/rules.py), two levels x 2 realisations:
    the same bits on two threads as on one in chunks of one point, and the scalar driver's
    statistics to the tolerance (the two differ in round-off, so their step sequences part)."""
    axes = {"base_asd_scale": [-6.0, 0.0]}
    common = {"model.modes": n_modes, "clamps.rotation": "clamped", "solver.rtol": 1e-9,
              "outputs.clearance": [1e-4], "solver.driver": "lanes"}
    sc = scene(common, axes=axes)
    ds = sweep.run(sc, threads=2, progress=False)
    again = sweep.run(scene({**common, "run.chunk_size": 1}, axes=axes), threads=1,
                      progress=False)
    scalar = sweep.run(scene({**common, "solver.driver": "scalar"}, axes=axes), threads=2,
                       progress=False)
    # each driver's window starts with its own first step in it (a step, ~1e-4 of the
    # window, apart); the acceleration's mean square is the trapezoidal rule on the step
    # ends: O(h^2) of each driver's own steps
    tolerance = {"rms_deflection": 5e-4, "rms_acceleration_g": 1e-3, "peak_deflection": 1e-4,
                 "deflection_m2": 5e-4, "rms_clamp_bending_strain": 5e-4,
                 "clamp_strain_m4": 5e-4}
    for name, rtol in tolerance.items():
        np.testing.assert_array_equal(ds[name].values, again[name].values)
        assert np.all(np.isfinite(ds[name].values)), name
        np.testing.assert_allclose(ds[name].values, scalar[name].values, rtol=rtol, atol=0.0,
                                   err_msg=name)
    for name in ("zero_upcrossing_rate", "clearance_upcrossing_rate"):   # each over its own
        counts = [np.rint(d[name] * d.statistics_window).values for d in (ds, scalar)]
        np.testing.assert_array_equal(*counts, err_msg=name)              # window: the counts
        assert counts[0].min() > 0, name
    assert set(np.unique(ds.state.values)) == {8}


def test_random_keys_need_a_spectrum():
    with pytest.raises(SceneError) as caught:
        sweep.load_scene_text("[base]\nduration = 2.0\n")
    assert "only for a random base acceleration" in str(caught.value)


def test_a_record_shorter_than_the_start_up_is_refused():
    """A lightly damped span whose transient outlasts the record: one line, before any run."""
    sc = scene({"cable.damping_ratio": 0.001})
    with pytest.raises(SceneError) as caught:
        sweep.run(sc)
    assert "start-up transient" in str(caught.value)
    # the duration it advises is the threshold, ln(1/tol) / (zeta w1) / 0.9 (it said 10 x the
    # start-up, which a record a ninth of that long already meets), worked out here by hand
    startup = (math.log(1.0 / float(sc.values["metrics.tolerance"]))
               / (0.001 * 2.0 * math.pi * 42.4))                     # f1 = 42.4 Hz, 3 digits
    advised = float(re.search(r"base\.duration of at least ([0-9.e+]+) s", str(caught.value)).group(1))
    assert advised == pytest.approx(startup / 0.9, rel=1e-2)
    for startup_s in (0.9031, 1.0481, 0.01):    # a reviewer's: 3 digits rounded down below it
        with pytest.raises(SceneError) as short:
            random_scene.check_duration(0.5 * startup_s, startup_s)
        given = float(re.search(r"at least ([0-9.e+]+) s", str(short.value)).group(1))
        random_scene.check_duration(given, startup_s)          # the advice runs


def test_a_span_whose_start_up_outlasts_the_record_is_flagged_the_others_run():
    """One setting of the grid too lightly damped for the record (its start-up longer than
    90 % of it) is flagged invalid_input with a one-line warning; the rest of the grid runs
    and keeps its statistics (a reviewer found one long span refusing the whole map)."""
    from sweep.errors import CableSweepWarning
    with pytest.warns(CableSweepWarning, match=r"1 of 2 span settings start up for longer "
                      r"than 90% of the 1 s run .* flagged invalid_input, the others run"):
        ds = sweep.run(scene({"base.realisations": 1, "outputs.clearance": [1e-5]},
                             axes={"damping_ratio": [0.001, 0.05]}), progress=False)
    states = ds.state.transpose("damping_ratio", ...).values.reshape(2, -1)
    assert np.all(states[0] == 0) and np.all(states[1] == 8)      # invalid_input, completed
    rms = ds.rms_deflection.transpose("damping_ratio", ...).values.reshape(2, -1)
    assert np.all(np.isnan(rms[0])) and np.all(rms[1] > 0.0)
    # what never ran has no verdict: not "no escape", not "no crossing" (a reviewer's filter
    # on escape_probability == 0 kept a span that was never simulated)
    for name in ("escape_probability", "clearance_upcrossings", "expected_exceedances",
                 "exceedance_probability", "exceedance_probability_upper"):
        if name in ds:
            values = ds[name].transpose("damping_ratio", ...).values.reshape(2, -1)
            assert np.all(np.isnan(values[0])) and np.all(np.isfinite(values[1])), name
    assert "clearance_upcrossings" in ds
    assert float(ds.escape_probability.sel(damping_ratio=0.05)) == 0.0


def test_a_softening_oscillator_escapes_and_has_no_rms():
    """q'' + 2 zeta w q' + w^2 q - k q^3 = -a_b with the barrier at q_b = w / sqrt(k) equal to
    1.5 linear RMS: every realisation leaves through it within 8 s (the divergence bound put
    just beyond it), reported diverged with its failure time inside the run and NaN
    statistics (an escape has no stationary RMS); at a barrier of 8 RMS none escapes."""
    f, w = rnd.spectrum(FLAT)
    omega, zeta = 2 * math.pi * 60.0, 0.05
    sigma = math.sqrt(float(rnd.linear_mean_square(
        f, w, np.array([omega]), np.array([2 * zeta * omega]), np.ones(1))))
    records = rnd.synthesise(f, w, 8.0, 5000.0, 4, 2)
    for barrier, escapes in ((1.5 * sigma, True), (8.0 * sigma, False)):
        rows = _rows(omega, zeta, -omega ** 2 / barrier ** 2, 4, 5000.0)
        rows[:, osc.BOUND] = 1.2 * barrier
        out = _run(rows, records, 8.0, 1.0)
        if escapes:
            assert np.all(out["states"] == 5)                       # diverged
            times = out["reals"][:, tk.FAILURE_TIME]
            assert np.all((times > 0.0) & (times < 8.0))
            assert np.all(np.isnan(out["reals"][:, tk.RMS_DEFLECTION]))
        else:
            assert np.all(out["states"] == 8)
            assert np.all(np.isfinite(out["reals"][:, tk.RMS_DEFLECTION]))


@pytest.mark.parametrize("rotation, n_modes, axes", [
    ("pinned", 1, None), ("clamped", 3, None),
    ("elastic", 2, {"clamp_rotational_stiffness": [0.01, 1.0]})])
def test_a_span_without_stretching_meets_its_linear_rms(rotation, n_modes, axes):
    """Clamps that let the cable slide (clamps.axial_stiffness = 0: no stretching): the mean
    RMS deflection over 16 records of 4 s is the exact linear_rms (the integral of |H|^2 W
    summed over the modes with their midspan values and participations) within twice its
    95 % half-width (about 4 standard errors); pinned with one mode, clamped with three, and
    elastic clamps of two stiffnesses (each point its own basis) with two."""
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "clamps.rotation": rotation,
                          "cable.diameter": 2.76e-3, "model.modes": n_modes,
                          "base.realisations": 16, "base.duration": 4.0}, axes=axes))
    mean = ds.rms_deflection_mean.values
    half = ds.rms_deflection_ci.values
    linear = ds.linear_rms.broadcast_like(ds.rms_deflection_mean).values
    assert np.all(half < 0.05 * mean)
    assert np.all(np.abs(mean - linear) < 2.0 * half), (mean, half, linear)


def _clamped_beam(beta: float, s: float) -> tuple[float, float]:
    """phi(s) and phi''(s) (per unit s^2) of the clamped-clamped beam function with root
    beta (sigma its ratio), written here from the textbook form."""
    sigma = (math.cosh(beta) - math.cos(beta)) / (math.sinh(beta) - math.sin(beta))
    phi = (math.cosh(beta * s) - math.cos(beta * s)
           - sigma * (math.sinh(beta * s) - math.sin(beta * s)))
    curvature = beta ** 2 * (math.cosh(beta * s) + math.cos(beta * s)
                             - sigma * (math.sinh(beta * s) + math.sin(beta * s)))
    return phi, curvature


def test_clamp_strain_moments_of_several_modes_meet_the_exact_linear_ones():
    """Three clamped modes, stretching off: the kernels' mean squares of the clamp's and the
    midspan's curvature, as bending strain (d / 2 l^2 times it) and its rate's and second
    derivative's (m0, m2, m4), averaged over 16 records of 4 s, against the exact integrals
    of |sum_n phi_n''(s) Gamma_n / (w_n^2 - w^2 + 2 i zeta w_n w)|^2 w^(2k) W, the beam
    functions, participations and frequencies computed here (beta l = 4.7300, 7.8532,
    10.9956), within about four standard errors of the resonant mean square (2.4 % each)."""
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "clamps.rotation": "clamped",
                          "cable.diameter": 2.76e-3, "model.modes": 3,
                          "base.realisations": 16, "base.duration": 4.0}))
    betas = (4.730040745, 7.853204624, 10.99560784)
    rho_a, ei, length, zeta, d = 8900.0 * 6e-6, 110e9 * 2.865e-12, 0.3, 0.05, 2.76e-3
    f1 = betas[0] ** 2 / (2 * math.pi * length ** 2) * math.sqrt(ei / rho_a)
    assert float(ds.natural_frequency) == pytest.approx(f1, rel=1e-4)
    gammas = [quad(lambda s: _clamped_beam(b, s)[0], 0, 1)[0]
              / quad(lambda s: _clamped_beam(b, s)[0] ** 2, 0, 1)[0] for b in betas]
    w0 = 0.04 * G ** 2
    strain = 0.5 * d / length ** 2
    for place, s in (("clamp", 0.0), ("midspan", 0.5)):
        weights = [_clamped_beam(b, s)[1] * g for b, g in zip(betas, gammas)]

        def density(f, k):
            w = 2 * math.pi * f
            h = sum(c / ((2 * math.pi * f1 * (b / betas[0]) ** 2) ** 2 - w * w + 2j * zeta
                         * 2 * math.pi * f1 * (b / betas[0]) ** 2 * w)
                    for b, c in zip(betas, weights))
            return abs(h) ** 2 * w ** (2 * k) * w0 * strain ** 2

        for k, rel in ((0, 0.1), (1, 0.1), (2, 0.15)):
            exact = quad(density, 10.0, 500.0, args=(k,), limit=400, points=[f1])[0]
            got = float(ds[f"{place}_strain_m{2 * k}"].mean("realisation"))
            assert got == pytest.approx(exact, rel=rel), (place, k, got, exact)
        assert float((ds[f"rms_{place}_bending_strain"] ** 2).mean()) == pytest.approx(
            float(ds[f"{place}_strain_m0"].mean()), rel=1e-12)


def test_a_rare_clearance_is_judged_from_every_record_at_once():
    """A linear span (clamps.axial_stiffness = 0: no stretching; Gaussian response) under FLAT,
    16 records of 2 s (windows of about 1.7 s) and a 120 s test. At u = 3.17 sigma each
    record's window expects about one up-crossing by |q| (Rice: 2 nu0 exp(-u^2 / 2 sigma^2),
    sigma and nu0 = sqrt(m2 / m0) / 2 pi from the quadrature of |H|^2 W written here), so
    some windows count none, while the test expects about 70 exceedances: the probability of
    at least one must be 1, not the mean over the records of each one's 1 - exp(-nu_r T)
    (about 0.6: a window with no crossing says 0). At u = 2 sigma (about 320 crossings
    counted) the pooled expected number meets Rice's with the records' own sigma and nu0
    within 20 % (3 standard errors of the count: 17 %)."""
    cable = Cable(length=0.3, damping_ratio=0.05)
    w1, zeta = cable.w1, cable.damping_ratio
    level = 0.04 * G * G                                   # FLAT, (m/s^2)^2/Hz

    def moment(k: int) -> float:
        def integrand(f: float) -> float:
            w = 2.0 * math.pi * f
            return w ** k * (4.0 / math.pi) ** 2 * level / abs(w1 * w1 - w * w
                                                                + 2j * zeta * w1 * w) ** 2
        f1 = w1 / (2.0 * math.pi)
        return sum(quad(integrand, a, b, limit=200)[0]
                   for a, b in ((10.0, 0.8 * f1), (0.8 * f1, 1.25 * f1), (1.25 * f1, 500.0)))

    sigma = math.sqrt(moment(0))
    nu0 = math.sqrt(moment(2) / moment(0)) / (2.0 * math.pi)
    low, rare = 2.0 * sigma, 3.17 * sigma
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "base.realisations": 16,
                          "base.duration": 2.0, "base.test_duration": 120.0,
                          "outputs.clearance": [low, rare]}), progress=False)
    assert ds.exceedance_probability.dims == ("clearance",)
    window = ds.statistics_window.values.ravel()
    per_record = ds.clearance_upcrossing_rate.values.reshape(16, 2)
    expected_rice = 2.0 * nu0 * math.exp(-rare ** 2 / (2.0 * sigma ** 2)) * 120.0
    assert 0.5 < 2.0 * nu0 * math.exp(-rare ** 2 / (2.0 * sigma ** 2)) * window.mean() < 2.0
    assert expected_rice > 50.0
    assert np.any(per_record[:, 1] == 0.0)                 # windows that saw none
    assert float(ds.exceedance_probability.sel(clearance=rare)) > 0.999
    # at 2 sigma: Rice with the records' own mean square and zero-crossing rate
    rms = ds.rms_deflection.values.ravel()
    own_sigma = math.sqrt(np.sum(rms ** 2 * window) / np.sum(window))
    own_nu0 = np.sum(ds.zero_upcrossing_rate.values.ravel() * window) / np.sum(window)
    rice_low = 2.0 * own_nu0 * math.exp(-low ** 2 / (2.0 * own_sigma ** 2)) * 120.0
    got = float(ds.expected_exceedances.sel(clearance=low))
    assert float(ds.clearance_upcrossings.sel(clearance=low)) > 250.0
    assert got == pytest.approx(rice_low, rel=0.2)
    assert float(ds.exceedance_probability.sel(clearance=low)) == pytest.approx(
        1.0 - math.exp(-got))
    # the upper bound: chi2(0.95, 2 n + 2) / 2 crossings over the windows' total (SciPy here)
    from scipy.stats import chi2
    for level in (low, rare):
        n = float(ds.clearance_upcrossings.sel(clearance=level))
        bound = chi2.ppf(0.95, 2.0 * n + 2.0) / 2.0 / window.sum() * 120.0
        upper = float(ds.exceedance_probability_upper.sel(clearance=level))
        assert upper == pytest.approx(1.0 - math.exp(-bound), rel=1e-9)
        assert upper >= float(ds.exceedance_probability.sel(clearance=level))


@pytest.mark.parametrize("count", [0, 1, 3, 17, 150, 200, 201, 5000, 2e6])
def test_the_poisson_upper_bound_is_the_chi_square_quantile(count):
    """The one-sided 95 % upper bound of a Poisson mean behind exceedance_probability_upper
    (no SciPy at run time) against SciPy's chi-square quantile: 3.0 for no event (the rule
    of three)."""
    from scipy.stats import chi2

    from sweep.models.random_outputs import poisson_upper
    assert poisson_upper(count) == pytest.approx(chi2.ppf(0.95, 2 * count + 2) / 2, rel=3e-6)
    assert math.isnan(poisson_upper(math.nan)) and math.isnan(poisson_upper(-1.0))


def _spectra(level_db: float):
    """`scene`'s two records of 8 s at level_db as their FFTs X_r, the bins' angular
    frequencies (rad/s), a grid four times as fine as the samples (s) and `fine(Z)`, a
    spectrum's signal on that grid (the trigonometric interpolant, within about 1e-5 of the
    kernels' cubic Hermite one): the records repeat with their period, so a linear span's
    steady response to one is the inverse FFT of its transfer function times X_r."""
    f, w = rnd.spectrum(FLAT)
    fs = 10.0 * FLAT[-1][0]
    records = rnd.synthesise(f, w, 8.0, fs, 2, 3)
    n, up = records.samples, 4
    X = [np.fft.rfft(records.values[r, :, 0]) * 10 ** (level_db / 20) for r in range(2)]
    return (X, 2 * np.pi * np.fft.rfftfreq(n, 1.0 / fs), np.arange(n * up) / (fs * up),
            lambda Z: np.fft.irfft(Z, n=n * up) * up)


def _steady_state(ds, l: float, level_db: float, n_modes: int):
    """The exact periodic steady state at midspan of a linear pinned span (length l m) under
    each of `scene`'s records at level_db (`_spectra`): the response to record r is the
    inverse FFT of -sum_n phi_n(1/2) Gamma_n H_n X_r, with Gamma_n = 4 / (n pi),
    w_n = n^2 w_1 and the scene's damping ratio on every mode. Returns t (s) and, per record,
    the deflection, the relative acceleration q'' and the absolute one q'' + a_b."""
    spectra, omega, t, fine = _spectra(level_db)
    w1 = 2 * np.pi * float(ds.natural_frequency.sel(length=l))
    out = []
    for X in spectra:
        Q = np.zeros_like(X)
        for m in range(1, n_modes + 1, 2):                   # even modes: a node at midspan
            wn = w1 * m * m
            H = 1.0 / (wn ** 2 - omega ** 2 + 2j * 0.05 * wn * omega)
            Q -= math.sin(m * math.pi / 2) * 4.0 / (m * math.pi) * H * X
        q, relative, base = (fine(Z) for Z in (Q, -omega ** 2 * Q, X))
        out.append((q, relative, relative + base))
    return t, out


@pytest.mark.parametrize("n_modes, driver", [
    (1, "lanes"), pytest.param(1, "scalar", marks=pytest.mark.slow),
    pytest.param(3, "lanes", marks=pytest.mark.slow),
    pytest.param(3, "scalar", marks=pytest.mark.slow)])
def test_the_accelerations_rms_meet_the_exact_steady_state_record_by_record(n_modes, driver):
    """A span that does not stretch (linear), pinned, two records of 8 s at -20 dB, below the
    spectrum's band (1.0 m, f1 = 3.8 Hz: the span isolates, its absolute acceleration is
    mostly the clamps' own), inside it (0.3 m, 42 Hz) and above it (0.08 m, 600 Hz): each
    record's RMS deflection and RMS relative and absolute acceleration over its own window
    against the exact periodic steady state (`_steady_state`) over that window, to 1e-3. A
    step long beside the record's samples integrates a_b^2 exactly and the span's own forces
    by Simpson's rule (trajectory.acceleration_squares); Simpson's rule on the whole
    square read the isolating span's absolute acceleration about 2 % low."""
    lengths = [1.0, 0.3, 0.08]
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "model.modes": n_modes,
                          "solver.driver": driver, "base.duration": 8.0},
                         axes={"length": lengths, "base_asd_scale": [-20.0]}),
                   progress=False)
    assert float(ds.natural_frequency.sel(length=1.0)) < FLAT[0][0] < float(
        ds.natural_frequency.sel(length=0.3)) < FLAT[-1][0] < float(
        ds.natural_frequency.sel(length=0.08))
    for l in lengths:
        t, exact = _steady_state(ds, l, -20.0, n_modes)
        point = ds.sel(length=l, base_asd_scale=-20.0)
        for r, (q, relative, absolute) in enumerate(exact):
            window = t >= t[-1] + t[1] - float(point.statistics_window[r])
            for name, x in (("rms_deflection", q), ("rms_relative_acceleration", relative),
                            ("rms_acceleration", absolute)):
                got = float(point[name][r])
                assert got == pytest.approx(math.sqrt(np.mean(x[window] ** 2)), rel=1e-3), (
                    l, r, name)


@pytest.mark.parametrize("driver", ["lanes", pytest.param("scalar", marks=pytest.mark.slow)])
def test_the_clamp_strain_moments_meet_the_exact_steady_state_record_by_record(driver):
    """Three clamped modes that do not stretch, two records of 8 s at -20 dB, below the
    spectrum's band (1.2 m, f1 = 6 Hz), inside it (0.3 m, 96 Hz) and above it (0.12 m, 600
    Hz): each record's mean squares of the bending strain at the clamp and at midspan, of its
    rate and of its second derivative (m0, m2, m4) against the exact periodic steady state of
    the curvature sum_n phi_n''(s) q_n (the beam functions, participations and frequencies
    computed here, as `_steady_state` does for the deflection), to 1e-3 (the largest
    difference 4.4e-4, m4 at 0.3 m). m4 below the band is mostly the clamps' own acceleration
    times the curvature's participation (modal_driver.carrier_slot); on the steps' quintic
    alone it read 0.2 % low at the clamp."""
    lengths = [1.2, 0.3, 0.12]
    ds = sweep.run(scene({"clamps.axial_stiffness": 0.0, "clamps.rotation": "clamped",
                          "cable.diameter": 2.76e-3, "model.modes": 3, "solver.driver": driver,
                          "base.duration": 8.0},
                         axes={"length": lengths, "base_asd_scale": [-20.0]}), progress=False)
    betas = (4.730040745, 7.853204624, 10.99560784)
    gammas = [quad(lambda s: _clamped_beam(b, s)[0], 0, 1)[0]
              / quad(lambda s: _clamped_beam(b, s)[0] ** 2, 0, 1)[0] for b in betas]
    spectra, omega, t, fine = _spectra(-20.0)
    for l in lengths:
        point = ds.sel(length=l, base_asd_scale=-20.0)
        w1 = 2 * np.pi * float(point.natural_frequency)
        strain = 0.5 * 2.76e-3 / l ** 2
        for place, s in (("clamp", 0.0), ("midspan", 0.5)):
            for r, X in enumerate(spectra):
                C = sum(_clamped_beam(b, s)[1] * g * X
                        / ((w1 * (b / betas[0]) ** 2) ** 2 - omega ** 2
                           + 2j * 0.05 * w1 * (b / betas[0]) ** 2 * omega)
                        for b, g in zip(betas, gammas))
                window = t >= t[-1] + t[1] - float(point.statistics_window[r])
                for k in range(3):
                    c = fine((1j * omega) ** k * C)
                    exact = strain ** 2 * np.mean(c[window] ** 2)
                    got = float(point[f"{place}_strain_m{2 * k}"][r])
                    assert got == pytest.approx(exact, rel=1e-3), (l, place, r, k, got, exact)


def test_escapes_in_the_start_up_transient_are_warned_in_one_line():
    """A realisation that escaped before its point's start-up ended (its level ramp and
    transient: the row's own, not the survivors' window, so a point where every record
    escaped counts too) escaped in the start-up kick: one warning line names how many and
    when, and what to do with or without a ramp; none for later escapes. A span loaded at or
    past its buckling load escapes whatever the ramp: the line says so instead."""
    import warnings

    import xarray as xr

    from sweep.errors import CableSweepWarning
    from sweep.models.random_outputs import _warn_startup_escapes
    dims = ("length", "realisation")
    escaped = xr.DataArray([[True, True], [False, True]], dims=dims)
    startup = xr.DataArray([0.5, 1.0], dims="length")
    early = xr.DataArray([[0.05, 0.1], [np.nan, 1.5]], dims=dims)
    with pytest.warns(CableSweepWarning, match=r"2 of 3 escaped realisations escaped in the "
                      r"start-up \(0\.05-0\.1 s.*e\.g\. base\.ramp = 1\.0"):
        _warn_startup_escapes(escaped, early, startup, 0.0, xr.DataArray(False))
    with pytest.warns(CableSweepWarning, match=r"rise over base\.ramp = 0\.3 s"):
        _warn_startup_escapes(escaped, early, startup, 0.3, xr.DataArray(False))
    buckled = xr.DataArray([True, False], dims="length")
    with pytest.warns(CableSweepWarning, match=r"at or past the buckling load.*whatever the ramp"):
        _warn_startup_escapes(escaped, early, startup, 0.3, buckled)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        _warn_startup_escapes(escaped, early.where(~escaped, 2.5), startup, 0.0,
                              xr.DataArray(False))


@pytest.mark.slow
def test_a_ramped_record_does_not_kick_a_span_below_the_band_over_its_barrier():
    """A reviewer's case: a 0.15 m span of the GEVS bundle without stretching, loaded to 0.98
    of its buckling load (its first mode far below the spectrum's 20 Hz) at +12 dB. Switched
    on at full level, records kick it over its barrier in the start-up transient (escapes
    before the statistics window: warned); brought up over 1 s (base.ramp), none escape."""
    from sweep.errors import CableSweepWarning
    over = {"model.membrane": 0.0, "load.type": "constant", "axes.length": [0.15],
            "axes.load_amplitude": [0.98 * 43.86], "axes.base_asd_scale": [12.0],
            "base.realisations": 8, "base.duration": 4.0, "outputs.response_asd": False}
    with pytest.warns(CableSweepWarning, match="escaped in the start-up "):
        kicked = sweep.run(sweep.load_scene("launch-random-gevs", overrides=over),
                           progress=False)
    assert float(kicked.escape_probability.max()) > 0.0
    ramped = sweep.run(sweep.load_scene("launch-random-gevs",
                                        overrides={**over, "base.ramp": 1.0}), progress=False)
    assert float(ramped.escape_probability.max()) == 0.0
    assert np.all(np.isfinite(ramped.rms_deflection.values))
