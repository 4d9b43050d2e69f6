"""Base excitation of the clamps, the sweep layer (docs/model.md sec. 5): the [base] keys and
axes, their rules (one line each, the key named), the kernel columns the model gives, the
settings flag, and the dataset's outputs (units, long names, CF, netCDF round trip).

The kernel's numbers (forcing, absolute acceleration) are checked against closed forms and
SciPy in tests/test_base_excitation.py; here only what the sweep layer builds around them.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep import grid, models
from sweep.cli import main
from sweep.errors import CableSweepWarning, UserError
from sweep.kernels import oscillator as osc
from sweep.kernels import transverse as tk
from sweep.run import settings_vector
from sweep.scene import load_scene, load_scene_text

G = 9.80665                      # standard gravity, m/s^2 (written here, not imported)
GAMMA = 4.0 / math.pi            # int sin(pi x/l) dx / int sin^2(pi x/l) dx over the span

BASE = """
name = "base-test"
[cable]
damping_ratio = 0.02
inertia = 2.865e-12
[load]
amplitude = 0.0
[base]
acceleration_g = 0.5
frequency = 20.0
[axes]
length = [0.3, 0.5]
"""
NO_BASE = """
name = "no-base"
[initial]
displacement = 1e-4
"""
FIX = ("add a [base] table with acceleration, acceleration_g or levels_g and frequency, "
       "frequency_ratio or sweep")


def refused(text: str, overrides: dict | None = None) -> str:
    """The one-line message a scene is refused with."""
    with pytest.raises(UserError) as info:
        load_scene_text(text, overrides=overrides)
    message = str(info.value)
    assert "\n" not in message and message.endswith(")"), message
    return message


# --------------------------------------------------------------------------- scene rules


@pytest.mark.parametrize("text, overrides, words", [
    (BASE.replace("frequency = 20.0", "frequency = 20.0\nfrequency_ratio = 1.0"), None,
     ["'base.frequency' and 'base.frequency_ratio'", "give one, not both"]),
    (BASE.replace("acceleration_g = 0.5", "acceleration_g = 0.5\nacceleration = 4.9"), None,
     ["'base.acceleration' and 'base.acceleration_g'", "give one, not both", "m/s^2"]),
    (BASE + "base_acceleration = [1.0, 2.0]\n", None,          # a key and the other's axis
     ["'base.acceleration' and 'base.acceleration_g'", "give one, not both"]),
    (BASE + "base_frequency_ratio = [0.5, 1.0]\n", None,
     ["'base.frequency' and 'base.frequency_ratio'"]),
    (BASE, {"base.acceleration": 4.9, "base.acceleration_g": 0.5},
     ["overrides 'base.acceleration' and 'base.acceleration_g'", "give one, not both"]),
    (BASE, {"base.frequency": 5.0, "axes.base_frequency_ratio": [1.0, 2.0]},
     ["overrides 'base.frequency' and 'base.frequency_ratio'"]),
])
def test_both_spellings_of_level_or_frequency_are_refused(text, overrides, words):
    message = refused(text, overrides)
    for word in words:
        assert word in message, message


def test_a_base_table_without_frequency_or_level_names_the_key_and_the_fix():
    message = refused(BASE.replace("frequency = 20.0", ""))
    assert message.startswith("scene key 'base.acceleration_g': base excitation needs a "
                              "frequency"), message
    assert "none of base.frequency, base.frequency_ratio, base.sweep" in message
    assert "add frequency = 20.0 (Hz), frequency_ratio = 1.0 (f/f1) or sweep = { start = 5.0, stop = 100.0, rate = 2.0 } to the [base]" in message
    message = refused(BASE.replace("acceleration_g = 0.5", ""))
    assert message.startswith("scene key 'base.frequency': base excitation needs a level")
    assert "none of base.acceleration, base.acceleration_g, base.levels_g" in message
    message = refused("[base]\n")
    assert message.startswith("scene section '[base]': base excitation needs a level"), message


@pytest.mark.parametrize("key, value, words", [
    ("base.acceleration_g", -0.5, "must be >= 0 g, got -0.5"),
    ("base.acceleration", -1.0, "must be >= 0 m s-2, got -1.0"),
    ("base.frequency", 0.0, "must be > 0 Hz, got 0.0"),
    ("base.frequency_ratio", -2.0, "must be > 0, got -2.0"),
])
def test_out_of_range_base_values_say_the_bound_and_the_unit(key, value, words):
    text = BASE.replace("acceleration_g = 0.5\nfrequency = 20.0\n",
                        f"{key.split('.')[1]} = {value}\n"
                        + ("frequency = 20.0\n" if "acceleration" in key else
                           "acceleration_g = 0.5\n"))
    message = refused(text)
    assert message.startswith(f"scene key '{key}': {words} ("), message


def test_a_base_axis_alone_is_refused_with_the_table_to_add():
    message = refused("[axes]\nbase_frequency = [10.0, 20.0]\n")
    assert message.startswith("axis 'base_frequency': base excitation needs a level")
    assert message.endswith(f"({FIX})"), message
    message = refused("[axes]\nbase_acceleration_g = [0.5, 1.0]\n")
    assert message.startswith("axis 'base_acceleration_g': base excitation needs a frequency")
    assert message.endswith(f"({FIX})"), message


def test_base_axes_count_as_the_base_table():
    """Like the load axes: the level and the frequency as axes need no [base] table."""
    scene = load_scene_text("[axes]\nbase_acceleration_g = [0.5, 1.0]\n"
                            "base_frequency_ratio = [0.8, 1.0, 1.2]\n")
    assert scene.has_base and list(scene.axes) == ["base_acceleration_g",
                                                   "base_frequency_ratio"]
    assert scene.get("base.acceleration_g") is None and scene.get("base.frequency") is None


def test_an_override_of_one_base_key_without_a_base_table_says_add_the_table():
    message = refused(NO_BASE, {"base.acceleration_g": 0.5})
    assert message.startswith("scene key 'base.acceleration_g': base excitation needs a "
                              "frequency"), message
    assert message.endswith(f"({FIX})")
    # the whole excitation from the command line is a base scene
    scene = load_scene_text(NO_BASE, overrides={"base.acceleration_g": 0.5,
                                                "base.frequency": 20.0})
    assert scene.has_base


@pytest.mark.parametrize("model, words", [
    ('kind = "longitudinal"', "model.kind = 'longitudinal' has no base excitation"),
    ('coefficients = "paper"', "model.coefficients = 'paper' has no base excitation"),
])
def test_base_is_refused_where_the_model_has_no_forcing_term(model, words):
    message = refused(BASE.replace("[cable]", f"[model]\n{model}\n[cable]"))
    assert message.startswith(f"scene key 'base.acceleration_g': {words}"), message
    assert ("use model.kind = 'transverse'" in message
            or "use model.coefficients = 'consistent'" in message)
    # an axis in a longitudinal scene: the base rule speaks first, not the generic axis one
    message = refused('[model]\nkind = "longitudinal"\n[axes]\nbase_frequency = [5.0, 10.0]\n')
    assert message.startswith("axis 'base_frequency': model.kind = 'longitudinal' has no base")


@pytest.mark.parametrize("argv, words", [
    (["run", "harness-parametric", "--set", "base.acceleration_g=0.5"], FIX),
    (["run", "harness-base-sine", "--set", "base.acceleration_g=-1"], "must be >= 0 g"),
    (["run", "harness-base-sine", "--set", "base.acceleration=4.9", "--set",
      "base.acceleration_g=0.5"], "give one, not both"),
    (["run", "harness-base-sine", "--set", "model.kind=longitudinal"], "has no base excitation"),
])
def test_cli_prints_one_line_and_exits_2(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "-o", "out.nc", "--quiet"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == "" and len(lines) == 1, captured.err
    assert lines[0].startswith("sweep: error: ") and words in lines[0], lines[0]
    assert "base" in lines[0] and lines[0].endswith(")")
    assert list(tmp_path.iterdir()) == []


def test_set_overrides_the_level_and_drops_the_other_spelling():
    scene = load_scene("harness-base-sine", overrides={"base.acceleration_g": 0.5})
    assert scene.get("base.acceleration_g") == 0.5
    scene = load_scene("harness-base-sine", overrides={"base.acceleration": 4.9})
    assert scene.get("base.acceleration") == 4.9 and scene.get("base.acceleration_g") is None
    scene = load_scene("harness-base-sine",
                       overrides={"axes.base_acceleration": [2.0, 4.0]})
    assert scene.get("base.acceleration_g") is None
    assert list(scene.axes["base_acceleration"]) == [2.0, 4.0]
    # the frequency: an axis in the scene file, replaced by the ratio
    scene = load_scene("harness-base-sine", overrides={"axes.base_frequency_ratio": [0.9, 1.1]})
    assert "base_frequency" not in scene.axes and scene.get("base.frequency") is None
    assert list(scene.axes) == ["length", "base_frequency_ratio"]
    scene = load_scene("harness-base-sine", overrides={"base.frequency_ratio": 1.0})
    assert list(scene.axes) == ["length"] and scene.get("base.frequency_ratio") == 1.0


def test_base_scene_writes_back_and_loads_equal():
    for text in (BASE, "[axes]\nbase_acceleration = [1.0, 2.0]\nbase_frequency = [5.0]\n"):
        scene = load_scene_text(text)
        assert load_scene_text(scene.to_toml()) == scene
    assert "[base]" not in load_scene_text(NO_BASE).to_toml()


def test_zero_solution_warning_only_without_a_driving_base():
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        load_scene_text(BASE)                           # at rest, driven: no warning
    with pytest.warns(CableSweepWarning, match="stays at q = 0|stay|q = 0"):
        load_scene_text(BASE.replace("acceleration_g = 0.5", "acceleration_g = 0.0"))


# --------------------------------------------------------------------------- model columns


def _columns(text: str, overrides: dict | None = None) -> tuple[dict, dict]:
    scene = load_scene_text(text, overrides=overrides)
    coords = grid.coordinates(scene)
    params = grid.parameters(scene, coords)
    return models.oscillator(params), params


def _omega_1(length: float, inertia: float = 2.865e-12) -> float:
    """w1 = (pi/l)^2 sqrt(EI/(rho A)) of the Table 1 cable (rad/s)."""
    return (math.pi / length) ** 2 * math.sqrt(1.1e11 * inertia / (8900.0 * 6e-6))


def test_kernel_columns_of_a_level_in_g_at_a_frequency_in_hz():
    out, _ = _columns(BASE)
    assert set(osc.PARAM_NAMES) <= set(out)
    assert out["base_accel"] == pytest.approx(0.5 * G, rel=1e-15)
    assert out["base_omega"] == pytest.approx(2 * math.pi * 20.0, rel=1e-15)
    assert out["participation"] == pytest.approx(GAMMA, rel=1e-15)
    assert out["participation"] == pytest.approx(1.2732395447351628, rel=1e-15)


def test_kernel_columns_of_a_level_in_m_s2_at_a_frequency_ratio():
    text = BASE.replace("acceleration_g = 0.5", "acceleration = 3.0").replace(
        "frequency = 20.0", "frequency_ratio = 1.5")
    out, _ = _columns(text)
    assert out["base_accel"] == 3.0
    np.testing.assert_allclose(out["base_omega"].values,
                               [1.5 * _omega_1(0.3), 1.5 * _omega_1(0.5)], rtol=1e-13)
    assert out["base_omega"].dims == ("length",)
    np.testing.assert_allclose(out["base_frequency"].values,
                               [1.5 * _omega_1(l) / (2 * math.pi) for l in (0.3, 0.5)],
                               rtol=1e-13)
    assert float(out["base_acceleration_g"]) == pytest.approx(3.0 / G, rel=1e-15)


def test_kernel_columns_follow_swept_base_axes():
    out, _ = _columns(BASE, {"axes.base_acceleration_g": [0.25, 1.0],
                             "axes.base_frequency": [10.0, 40.0, 80.0]})
    np.testing.assert_allclose(out["base_accel"].values, [0.25 * G, 1.0 * G], rtol=1e-15)
    np.testing.assert_allclose(out["base_omega"].values, 2 * math.pi * np.array([10, 40, 80.0]),
                               rtol=1e-15)


def test_no_base_gives_zero_columns_and_no_base_quantities():
    out, _ = _columns(NO_BASE)
    assert out["base_accel"] == out["base_omega"] == out["participation"] == 0.0
    assert "linear_amplitude" not in out and "base_frequency" not in out


def test_linear_closed_form_and_resonance_amplification():
    """One mode's linear_amplitude (sweep/models/linear.py, which gives every mode count's) is
    Gamma A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2)."""
    from sweep.models import linear
    from sweep.models import transverse as tm
    scene = load_scene_text(BASE, overrides={"axes.base_frequency": [5.0, 20.0, 100.0]})
    inputs = tm.resolve(scene)
    out = models.oscillator(inputs.params)
    amplitude = linear.linear_amplitude(out, inputs.params, inputs.basis, 1, inputs.coords)
    assert list(amplitude.dims) == ["length", "base_frequency"]
    a = 0.5 * G
    for i, length in enumerate((0.3, 0.5)):
        w1 = _omega_1(length)
        for j, f in enumerate((5.0, 20.0, 100.0)):
            w = 2 * math.pi * f
            expected = GAMMA * a / math.sqrt((w1 ** 2 - w ** 2) ** 2 + (0.04 * w1 * w) ** 2)
            assert float(amplitude[i, j]) == pytest.approx(expected, rel=1e-12)
    assert float(out["resonance_amplification"]) == pytest.approx(25.0)
    undamped, _ = _columns(BASE.replace("damping_ratio = 0.02", "damping_ratio = 0.0"))
    assert np.isnan(float(undamped["resonance_amplification"]))


@pytest.mark.parametrize("modes", [2, 3, 5])
def test_the_linear_amplitude_of_several_pinned_modes_is_their_sum(modes):
    """A verifier: linear_amplitude was the first mode's alone with several modes, 1-2 % off
    the linear response the run's modes give (so off `amplitude` in the linear limit). It is
    A |sum_n Gamma_n phi_n(l/2) / (w_n^2 - w^2 + i 2 zeta w_n w)| over the scene's modes:
    pinned sines written here (Gamma_n phi_n(l/2) = 4 / (n pi) sin(n pi / 2), w_n = n^2 w_1),
    below, at and above resonance, over a frequency axis and two spans."""
    from sweep.models import linear, modal
    from sweep.models import transverse as tm
    text = (f"[model]\nmodes = {modes}\n[cable]\ndamping_ratio = 0.02\n[base]\n"
            "acceleration_g = 0.5\n[axes]\nlength = [0.3, 0.5]\n"
            "base_frequency = [10.0, 23.0, 40.0, 61.0, 250.0]\n")
    inputs = tm.resolve(sweep.load_scene_text(text))
    coeffs = modal.oscillator(inputs.params)
    got = linear.linear_amplitude(coeffs, inputs.params, inputs.basis, modes, inputs.coords)
    assert got.attrs["units"] == "m" and f"its {modes} modes" in got.attrs["long_name"]
    f1 = np.asarray(coeffs["natural_frequency"]).reshape(-1, 1)
    w1, w = 2 * np.pi * f1, 2 * np.pi * np.array([[10.0, 23.0, 40.0, 61.0, 250.0]])
    g_sum = sum(4 / (n * np.pi) * np.sin(n * np.pi / 2)
                / ((n * n * w1) ** 2 - w ** 2 + 2j * 0.02 * n * n * w1 * w)
                for n in range(1, modes + 1))
    np.testing.assert_allclose(got.transpose("length", "base_frequency").values,
                               0.5 * 9.80665 * np.abs(g_sum), rtol=1e-12)
    one = linear.linear_amplitude(coeffs, inputs.params, inputs.basis, 1, inputs.coords)
    change = np.max(np.abs(got.values / one.values - 1.0))
    assert change > 1e-3 if modes >= 3 else change < 1e-15   # mode 2 does not move midspan


def test_state_scale_includes_the_driven_response():
    """max(|q0|, |v0|/w1, Gamma A / max(w1^2, w_b^2)): quasi-static below resonance, the mass
    line above; a point at rest at q = 0 is driven, so its scale is not the bound."""
    out, _ = _columns(BASE, {"axes.base_frequency": [1.0, 500.0]})
    for i, length in enumerate((0.3, 0.5)):
        w1 = _omega_1(length)
        for j, f in enumerate((1.0, 500.0)):
            wb = 2 * math.pi * f
            expected = GAMMA * 0.5 * G / max(w1 ** 2, wb ** 2)
            assert float(out["q_scale"][i, j]) == pytest.approx(expected, rel=1e-12)
            assert float(out["v_scale"][i, j]) == pytest.approx(w1 * expected, rel=1e-12)
    q, v = models.state_scale(2e-3, 0.0, 10.0, 1.0, forcing=1.0, base_omega=5.0)
    assert (q, v) == (pytest.approx(1e-2), pytest.approx(1e-1))        # 1/max(100, 25)
    q, _ = models.state_scale(0.0, 0.0, 10.0, 0.7, forcing=0.0, base_omega=5.0)
    assert q == 0.7                                                    # nothing: the bound


def test_settings_flag():
    assert settings_vector(load_scene_text(BASE))[tk.BASE] == 1.0
    assert settings_vector(load_scene_text(NO_BASE))[tk.BASE] == 0.0


# --------------------------------------------------------------------------- dataset


SMALL = {"solver.t_end": 0.3, "axes.length": [0.3, 0.5], "axes.base_frequency": [20.0, 40.0]}


@pytest.fixture(scope="module")
def base_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("base") / "base.nc"
    ds = sweep.run(load_scene("harness-base-sine", overrides=SMALL), output=out,
                   progress=False)
    return ds, out


def test_outputs_carry_units_and_long_names(base_run):
    ds, _ = base_run
    expected = {"absolute_acceleration": "m s-2", "absolute_acceleration_g": "9.80665 m s-2",
                "transmissibility": "1", "base_acceleration": "m s-2",
                "base_acceleration_g": "9.80665 m s-2", "base_frequency": "Hz",
                "base_frequency_ratio": "1", "linear_amplitude": "m",
                "resonance_amplification": "1"}
    for name, units in expected.items():
        assert ds[name].attrs["units"] == units, name
        assert len(ds[name].attrs["long_name"]) > 10, name
    for name in ("absolute_acceleration", "absolute_acceleration_g", "transmissibility"):
        assert ds[name].dims == ("length", "base_frequency"), name
    # the swept frequency is the coordinate; the level (a scalar key) is a 0-d variable
    assert "base_frequency" in ds.coords and "base_frequency" not in ds.data_vars
    assert float(ds["base_acceleration_g"]) == 1.0
    assert float(ds["base_acceleration"]) == pytest.approx(G)
    assert ds["base_frequency_ratio"].dims == ("length", "base_frequency")


def test_outputs_are_the_kernel_column_in_both_units_and_over_the_level(base_run):
    ds, _ = base_run
    acc = ds["absolute_acceleration"].values
    assert np.all(np.isfinite(acc)) and np.all(acc > 0)
    np.testing.assert_allclose(ds["absolute_acceleration_g"].values, acc / G, rtol=1e-15)
    np.testing.assert_allclose(ds["transmissibility"].values, acc / G, rtol=1e-15)   # A = 1 g


def test_base_axes_select_after_a_netcdf_round_trip(base_run):
    ds, out = base_run
    with xr.open_dataset(out) as back:
        point = back.sel(length=0.5, base_frequency=40.0)
        assert float(point["absolute_acceleration"]) == float(
            ds["absolute_acceleration"].sel(length=0.5, base_frequency=40.0))
        assert back["base_frequency"].attrs["units"] == "Hz"
        assert back["absolute_acceleration_g"].attrs["units"] == "9.80665 m s-2"
    scene = load_scene("harness-base-sine", overrides={
        "solver.t_end": 0.2, "axes.length": [0.4], "base.frequency": 30.0,
        "axes.base_acceleration_g": [0.5, 1.25]})
    path = out.with_name("levels.nc")
    sweep.run(scene, output=path, progress=False)
    with xr.open_dataset(path) as back:
        assert list(back["base_acceleration_g"].values) == [0.5, 1.25]
        assert back["base_acceleration_g"].attrs["units"] == "9.80665 m s-2"
        level = back.sel(base_acceleration_g=1.25, length=0.4)
        assert float(level["base_acceleration"]) == pytest.approx(1.25 * G)
        assert float(level["transmissibility"]) == pytest.approx(
            float(level["absolute_acceleration"]) / (1.25 * G), rel=1e-15)


def test_small_base_scene_passes_the_cf_checker(base_run):
    from test_cf import cf_problems
    _, out = base_run
    assert cf_problems(out) == []


def test_no_base_outputs_without_base_or_when_switched_off():
    ds = sweep.run(load_scene_text(NO_BASE, overrides={"solver.t_end": 0.2}), progress=False)
    names = set(ds.variables)
    for name in ("absolute_acceleration", "absolute_acceleration_g", "transmissibility",
                 "base_frequency", "base_acceleration", "linear_amplitude"):
        assert name not in names, name
    ds = sweep.run(load_scene_text(BASE, overrides={"solver.t_end": 0.2,
                                                    "outputs.absolute_acceleration": False}),
                   progress=False)
    assert "absolute_acceleration" not in ds and "transmissibility" not in ds
    assert "linear_amplitude" in ds and "amplitude" in ds
