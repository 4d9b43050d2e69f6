"""solver.stop_when_steady: a point ends once its response is steady (or has decayed), its
tail window moved to the periods after. Checked against the closed-form linear base response
(docs/model.md secs. 3 and 5), against the full run of the same points, and on responses that never
settle (beating), which must never stop."""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep.errors import SceneError

from conftest import fast_first

G = 9.80665
LINEAR = """
name = "linear-base"
[model]
membrane = 0.0
[cable]
length = 0.4
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.001
frequency = 20.0
[axes]
base_frequency = [10.0, 20.0, 30.0]
[solver]
t_end = 20.0
rtol = 1e-10
driver = "{driver}"
method = "{method}"
stop_when_steady = true
"""


def linear_amplitude(ds, f):
    """(4/pi) A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2), m."""
    w1 = 2 * math.pi * float(ds.natural_frequency)
    w = 2 * math.pi * f
    return (4 / math.pi) * 0.001 * G / math.sqrt((w1**2 - w**2)**2 + (2 * 0.02 * w1 * w)**2)


@pytest.mark.parametrize("driver, method", fast_first(
    [("lanes", "rk45"), ("scalar", "rk45"), ("lanes", "dop853")], ("lanes", "rk45")))
def test_linear_steady_amplitude_is_the_closed_form_and_the_run_ends_early(driver, method):
    ds = sweep.run(sweep.load_scene_text(LINEAR.format(driver=driver, method=method)))
    assert np.all(ds.state.values == 2)                       # steady
    stop = ds.stop_time.values
    assert np.all(np.isfinite(stop)) and np.all(stop < 20.0)
    for i, f in enumerate(ds.base_frequency.values):
        exact = linear_amplitude(ds, float(f))
        assert float(ds.amplitude[i]) == pytest.approx(exact, rel=2e-4)


@pytest.mark.parametrize("modes", fast_first([1, 3], 1))
def test_a_lightly_damped_span_near_resonance_stops_at_its_steady_level(modes):
    """zeta = 0.002 at 0.995 and 1.005 f1: the response beats slowly as it settles, and where
    the beat's envelope turns, its maxima repeat to 1e-4 for many periods while 0.6 % short of
    the steady level (a reviewer found the early stop there, -6.2e-3 against the closed form).
    Not before ln(1/eps) / (zeta w1): within 2e-4 of the closed form, each side."""
    text = LINEAR.format(driver="lanes", method="rk45").replace(
        "damping_ratio = 0.02", "damping_ratio = 0.002").replace(
        "base_frequency = [10.0, 20.0, 30.0]", "base_frequency_ratio = [0.995, 1.005]").replace(
        "frequency = 20.0", "frequency_ratio = 1.0").replace("t_end = 20.0", "t_end = 100.0")
    ds = sweep.run(sweep.load_scene_text(text, overrides={"model.modes": modes}),
                   progress=False)
    w1 = 2 * math.pi * float(ds.natural_frequency)
    floor = math.log(1e4) / (0.002 * w1)
    for i, r in enumerate(ds.base_frequency_ratio.values):
        w = r * w1
        exact = (4 / math.pi) * 0.001 * G / math.sqrt((w1**2 - w**2)**2
                                                      + (2 * 0.002 * w1 * w)**2)
        assert int(ds.state[i]) == 2
        assert float(ds.amplitude[i]) == pytest.approx(exact, rel=2e-4)
        assert floor <= float(ds.stop_time[i]) < 100.0


def test_points_that_do_not_stop_equal_the_full_run_and_stopped_ones_its_level():
    overrides = {"model.modes": 1, "axes.length": [0.3, 0.5, 0.8],
                 "axes.base_frequency": [8.0, 20.0, 40.0, 70.0], "solver.t_end": 8.0}
    full = sweep.run(sweep.load_scene("harness-base-sine", overrides=overrides))
    early = sweep.run(sweep.load_scene("harness-base-sine", overrides={
        **overrides, "solver.stop_when_steady": True}))
    final = sweep.run(sweep.load_scene("harness-base-sine", overrides={
        **overrides, "metrics.tail": 0.25}))                  # the full run's last 2 s
    stopped = np.isfinite(early.stop_time.values)
    assert stopped.sum() >= 6
    assert np.array_equal(early.amplitude.values[~stopped], full.amplitude.values[~stopped])
    steady = (full.state.values == 2) & stopped
    rel = np.abs(early.amplitude.values - final.amplitude.values) / final.amplitude.values
    assert rel[steady].max() < 1e-3
    assert int(early.n_rhs.sum()) < int(full.n_rhs.sum())
    assert np.array_equal(early.state.values, full.state.values)


@pytest.mark.slow
@pytest.mark.parametrize("driver", ["lanes", "scalar"])
def test_several_modes_stop_and_their_modal_amplitudes_are_the_full_runs(driver):
    """Three modes: the early stop watches the midspan deflection; each mode's tail amplitude
    restarts with the midspan's window, so it is the full run's final level too."""
    overrides = {"model.modes": 3, "axes.length": [0.4, 0.7],
                 "axes.base_frequency": [20.0, 60.0], "solver.t_end": 8.0,
                 "solver.driver": driver}
    early = sweep.run(sweep.load_scene("harness-base-sine", overrides={
        **overrides, "solver.stop_when_steady": True}))
    final = sweep.run(sweep.load_scene("harness-base-sine", overrides={
        **overrides, "metrics.tail": 0.25}))                  # the full run's last 2 s
    stopped = np.isfinite(early.stop_time.values) & (final.state.values == 2)
    assert stopped.sum() >= 2
    rel = np.abs(early.amplitude.values - final.amplitude.values) / final.amplitude.values
    assert rel[stopped].max() < 1e-3
    modal_early = early.modal_amplitude.values[stopped]        # (point, mode)
    modal_final = final.modal_amplitude.values[stopped]
    scale = modal_final.max(axis=-1, keepdims=True)          # the point's largest mode
    assert (np.abs(modal_early - modal_final) / scale).max() < 1e-3
    assert np.all(early.state.values[stopped] == 2)
    # a stopped point ends there: fewer right-hand sides than the full run
    assert np.all(early.n_rhs.values[stopped] < final.n_rhs.values[stopped])


def test_a_beating_response_never_stops():
    """Undamped, started away from the forced motion: free vibration at f1 and the forced one
    at 0.7 f1 beat for ever; the extrema never repeat."""
    text = LINEAR.format(driver="lanes", method="rk45").replace(
        "damping_ratio = 0.02", "damping_ratio = 0.0").replace(
        "[axes]\nbase_frequency = [10.0, 20.0, 30.0]\n", "").replace(
        "frequency = 20.0", "frequency_ratio = 0.7\n[initial]\ndisplacement = 1e-5")
    ds = sweep.run(sweep.load_scene_text(text))
    assert not np.isfinite(float(ds.stop_time))
    assert int(ds.state) in (3, 4)                    # modulated or unsettled, not steady


def test_lanes_and_scalar_stop_alike():
    a = sweep.run(sweep.load_scene_text(LINEAR.format(driver="lanes", method="rk45")))
    b = sweep.run(sweep.load_scene_text(LINEAR.format(driver="scalar", method="rk45")))
    np.testing.assert_allclose(a.stop_time.values, b.stop_time.values, rtol=1e-9)
    np.testing.assert_allclose(a.amplitude.values, b.amplitude.values, rtol=1e-9)


@pytest.mark.parametrize("more, fragment", [
    ({"solver.stop_when_steady": False, "solver.steady_periods": 5}, "needs solver.stop_when"),
    ({"solver.steady_tolerance": 0.5}, "solver.steady_tolerance"),
    ({"solver.steady_periods": 1}, "solver.steady_periods"),
])
def test_bad_early_stop_settings_are_one_line(more, fragment):
    with pytest.raises(SceneError) as error:
        sweep.load_scene_text(LINEAR.format(driver="lanes", method="rk45"), overrides=more)
    assert fragment in str(error.value) and "\n" not in str(error.value)


def test_a_swept_scene_refuses_the_early_stop():
    with pytest.raises(SceneError, match="never steady"):
        sweep.load_scene("launch-sine-qualification",
                         overrides={"solver.stop_when_steady": True})
