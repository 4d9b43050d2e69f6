"""Tests for sweep.scene: loading, overrides, validation messages, TOML round trip."""

from __future__ import annotations

import math

import numpy as np
import pytest

import sweep
from sweep import schema
from sweep.errors import SceneError
from sweep.scene import (DEFAULT_T_END, DEFAULT_TRANSITS, PAPER_VELOCITY, Scene, builtin_scenes,
                         load_scene, load_scene_text, parse_override)

BASE = """
name = "t"
[cable]
length = 1.0
"""

LONG = '[model]\nkind = "longitudinal"\n'
LONG_5S = LONG + "[solver]\nt_end = 5.0\n"     # snapshot times up to 5 s are then valid


def scene_error(text: str, overrides=None) -> str:
    """The message of the SceneError that loading ``text`` raises (checked to be one line)."""
    with pytest.raises(SceneError) as info:
        load_scene_text(text, source="t.toml", overrides=overrides)
    message = str(info.value)
    assert "\n" not in message and message.strip() == message
    return message


def assert_round_trip(scene: Scene) -> None:
    again = load_scene_text(scene.to_toml())
    assert again == scene
    assert again.values == scene.values
    assert list(again.axes) == list(scene.axes)
    for name, values in scene.axes.items():
        np.testing.assert_array_equal(again.axes[name], values)


# --------------------------------------------------------------------------- built-ins


def test_builtin_scenes_listed_sorted_with_one_line_descriptions():
    scenes = builtin_scenes()
    assert list(scenes) == sorted(scenes)
    assert {"paper-fig5", "harness-parametric"} <= set(scenes)
    for description in scenes.values():
        assert description and "\n" not in description


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_builtins_load_and_round_trip(name):
    scene = load_scene(name)
    assert scene.name == name
    assert scene.source == name
    assert set(scene.values) == set(schema.BY_DOTTED)
    assert_round_trip(scene)


def test_paper_fig5_contents():
    scene = load_scene("paper-fig5")
    assert scene.get("model.coefficients") == "paper"
    assert scene.get("initial.velocity") == pytest.approx(0.0321)
    assert scene.get("load.frequency_ratio") == 1.0
    assert scene.get("outputs.time_series") is True
    assert list(scene.axes) == ["length"]
    np.testing.assert_array_equal(scene.axes["length"], [0.5, 0.7, 0.85, 1.0])
    assert scene.get("cable.length") is None  # swept


def test_harness_parametric_contents():
    scene = load_scene("harness-parametric")
    assert scene.get("model.coefficients") == "consistent"
    assert scene.get("cable.damping_ratio") == 0.02
    assert list(scene.axes) == ["length", "frequency_ratio"]
    assert scene.axes["length"].shape == (15,)
    assert scene.axes["frequency_ratio"][[0, -1]].tolist() == [0.5, 3.0]
    assert scene.axes["frequency_ratio"].dtype == np.float64


def test_load_from_path_uses_file_stem_as_default_name(tmp_path):
    path = tmp_path / "my-scene.toml"
    path.write_text("[solver]\nrtol = 1e-9\n", encoding="utf-8")
    scene = load_scene(path)
    assert scene.name == "my-scene"
    assert scene.source == str(path)
    assert scene.text == path.read_text(encoding="utf-8")
    assert scene.get("solver.rtol") == 1e-9
    assert load_scene(str(path)) == scene


def test_defaults_applied():
    scene = load_scene_text("")
    assert scene.name == "unnamed" and scene.description == ""
    for key in schema.KEYS:
        if key.dotted not in ("load.frequency_ratio", "solver.t_end", "cable.inertia"):
            assert scene.get(key.dotted) == key.default
    assert scene.get("cable.inertia") == scene.get("cable.area") ** 2 / (4 * np.pi)
    assert scene.get("load.frequency_ratio") == 1.0
    assert scene.get("solver.t_end") == DEFAULT_T_END == 5.0
    assert scene.get("solver.max_step") is None
    assert scene.axes == {}


# --------------------------------------------------------------------------- overrides


def test_parse_override():
    assert parse_override("solver.rtol=1e-9") == ("solver.rtol", 1e-9)
    assert parse_override("model.coefficients=paper") == ("model.coefficients", "paper")
    assert parse_override('model.coefficients="paper"') == ("model.coefficients", "paper")
    assert parse_override("axes.length=[0.5, 1.0]") == ("axes.length", [0.5, 1.0])
    assert parse_override("axes.frequency_ratio={start=0.5, stop=3, num=11}") == (
        "axes.frequency_ratio", {"start": 0.5, "stop": 3, "num": 11})
    assert parse_override(" outputs.time_series = true ") == ("outputs.time_series", True)


@pytest.mark.parametrize("item", ["solver.rtol", "=1e-9", "  = 3"])
def test_parse_override_bad_form(item):
    with pytest.raises(SceneError, match="KEY=VALUE"):
        parse_override(item)


def test_overrides_float_string_list_and_range():
    scene = load_scene("paper-fig5", overrides={
        "solver.rtol": 1e-9,
        "model.coefficients": "consistent",
        "initial.velocity": "0.01",
        "axes.load_amplitude": [1.0, 2.0, 4.0],
        "axes.frequency_ratio": "{start = 0.5, stop = 3, num = 11}",
    })
    assert scene.get("solver.rtol") == 1e-9
    assert scene.get("model.coefficients") == "consistent"
    assert scene.get("initial.velocity") == 0.01
    assert list(scene.axes) == ["length", "load_amplitude", "frequency_ratio"]
    np.testing.assert_allclose(scene.axes["frequency_ratio"], np.linspace(0.5, 3.0, 11))
    assert scene.get("load.frequency_ratio") is None
    assert scene.overrides["initial.velocity"] == 0.01
    assert_round_trip(scene)


def test_parsed_overrides_from_the_command_line():
    items = ["cable.damping_ratio=0.05", "axes.cable.length=[0.4, 0.6]", "name=run-2"]
    scene = load_scene("harness-parametric", overrides=dict(map(parse_override, items)))
    assert scene.get("cable.damping_ratio") == 0.05
    assert list(scene.axes) == ["length", "frequency_ratio"]  # replaced in place
    np.testing.assert_array_equal(scene.axes["length"], [0.4, 0.6])
    assert scene.name == "run-2"


def test_override_scalar_replaces_axis():
    scene = load_scene("paper-fig5", overrides={"cable.length": 0.8})
    assert scene.axes == {}
    assert scene.get("cable.length") == 0.8


def test_override_frequency_replaces_frequency_ratio():
    scene = load_scene("harness-parametric", overrides={"load.frequency": 10.0})
    assert list(scene.axes) == ["length"]
    assert scene.get("load.frequency") == 10.0
    assert scene.get("load.frequency_ratio") is None


@pytest.mark.parametrize("name, override, value, gone", [
    ("launch-sine-qualification", {"base.acceleration_g": 0.5}, 0.5, ("base.levels_g",)),
    ("launch-sine-qualification", {"axes.base_acceleration_g": [0.5, 1.0]}, None,
     ("base.levels_g",)),
    ("harness-base-sine", {"base.levels_g": [[5.0, 0.5], [100.0, 0.6]]},
     ((5.0, 0.5), (100.0, 0.6)), ("base.acceleration_g", "base.acceleration")),
    ("launch-random-gevs", {"base.asd": [[20.0, 1.0], [2000.0, 1.0]]},
     ((20.0, 1.0), (2000.0, 1.0)), ("base.asd_g2",))])
def test_override_replaces_another_way_to_give_the_same_quantity(name, override, value, gone):
    """A level as a table in g and a spectrum in g^2/Hz or (m/s^2)^2/Hz are other ways to give
    one quantity, beside the either-or pairs: --set of one replaces what the scene gave (a
    reviewer: refused "give one level, not both", while the README says --set can always
    replace what the scene file says)."""
    scene = load_scene(name, overrides=override)
    (key, given), = override.items()
    if value is not None:
        assert scene.get(key) == value
    else:
        assert list(scene.axes["base_acceleration_g"]) == given
    for other in gone:
        assert scene.get(other) is None, other


@pytest.mark.parametrize("override, frequency, axis", [
    ({"base.frequency": 20.0}, 20.0, None),
    ({"base.frequency_ratio": 0.5}, None, None),
    ({"axes.base_frequency": [10.0, 20.0]}, None, "base_frequency")])
def test_a_fixed_base_frequency_override_replaces_the_scenes_sweep(override, frequency, axis):
    """--set base.frequency=20 on a sweep scene was refused "give one frequency, not both",
    while the README says --set can always replace what the scene says: a fixed frequency (key
    or axis) replaces the sweep table whole, and the envelope outputs only a sweep has (the
    scene file gives outputs.envelope = true; a fixed frequency stores none)."""
    scene = load_scene("launch-sine-qualification", overrides={**override, "solver.t_end": 3.0})
    assert scene.get("base.frequency") == frequency
    if "base.frequency_ratio" in override:
        assert scene.get("base.frequency_ratio") == 0.5
    for name in ("start", "stop", "rate", "ramp_cycles", "direction"):
        assert scene.get(f"base.sweep.{name}") is None, name
    assert scene.get("outputs.envelope") is False
    assert scene.get("solver.t_end") == 3.0
    assert list(scene.axes) == ["length"] + ([axis] if axis else [])
    if axis:
        assert list(scene.axes[axis]) == [10.0, 20.0]
    # the rest of the scene stays as its file says
    assert scene.get("base.levels_g") == ((5.0, 1.875), (45.0, 1.875), (50.0, 2.5), (100.0, 2.5))
    assert scene.get("cable.damping_ratio") == 0.02


def test_a_fixed_frequency_override_of_a_sweep_without_t_end_asks_for_one():
    """The launch scene's run ends with its sweep (it gives no solver.t_end): a fixed frequency
    in its place has no end time anyone chose, so one line asks for solver.t_end."""
    for override in ({"base.frequency": 20.0}, {"axes.base_frequency": [10.0, 20.0]}):
        with pytest.raises(SceneError) as info:
            load_scene("launch-sine-qualification", overrides=override)
        message = str(info.value)
        (key,) = override
        assert "\n" not in message and message.startswith(f"override '{key}': "), message
        assert "replaces the scene's sweep" in message and "solver.t_end=" in message


def test_a_sweep_override_replaces_the_scenes_fixed_frequency():
    """--set base.sweep={...} on a scene with a base_frequency axis ran into "give one
    frequency, not both": the sweep replaces the frequency (key or axis), and a stepped sweep's
    [continuation] (which a continuous sweep cannot have); the scene's other keys stay."""
    sweep_table = {"base.sweep": {"start": 5.0, "stop": 100.0, "rate": 2.0},
                   "solver.t_end": 200.0}
    scene = load_scene("harness-base-sine", overrides=sweep_table)
    assert list(scene.axes) == ["length"]
    assert (scene.get("base.sweep.start"), scene.get("base.sweep.stop"),
            scene.get("base.sweep.rate")) == (5.0, 100.0, 2.0)
    assert scene.get("base.frequency") is None and scene.get("base.acceleration_g") == 1.0
    scene = load_scene("harness-stepped-sine", overrides=sweep_table)
    assert list(scene.axes) == ["length"] and scene.get("continuation.axis") is None
    assert scene.get("base.frequency_ratio") is None and scene.get("base.sweep.rate") == 2.0


def test_a_sweep_override_drops_the_dwells_end_time_unless_one_is_given():
    """A reviewer: every built-in fixed-frequency scene gives its dwell a solver.t_end (20, 4,
    3 s), which refused any longer sweep ('remove solver.t_end', which --set cannot do): a
    sweep that replaces the fixed frequency takes its own duration, ln(f_e / f_s) / (r ln 2 /
    60) s, unless an override gives t_end."""
    sweep_table = {"base.sweep.start": 5.0, "base.sweep.stop": 100.0, "base.sweep.rate": 8.0}
    duration = math.log(100.0 / 5.0) / (8.0 * math.log(2.0) / 60.0)          # 32.41 s
    for name in ("harness-clamps", "harness-base-sine", "harness-stepped-sine"):
        scene = load_scene(name, overrides=sweep_table)
        assert scene.get("solver.t_end") is None, name      # the sweep's own end
        assert scene.get("base.sweep.rate") == 8.0 and scene.get("base.frequency") is None
        assert duration == pytest.approx(32.4145, abs=1e-4)
    scene = load_scene("harness-clamps", overrides={**sweep_table, "solver.t_end": 40.0})
    assert scene.get("solver.t_end") == 40.0
    scene = load_scene("harness-clamps", overrides={"base.acceleration_g": 2.0})
    assert scene.get("solver.t_end") == 3.0                  # no sweep: the dwell's end stays


def test_a_fixed_frequency_on_a_stepped_scene_drops_the_continuation_it_orphans():
    """A reviewer: --set base.frequency=30 on harness-stepped-sine left [continuation] naming
    the base_frequency_ratio axis the override removed (refused, and --set cannot remove a
    table): the continuation goes with its axis; one that still has its axis stays."""
    for override in ({"base.frequency": 30.0}, {"axes.base_frequency": [20.0, 30.0]},
                     {"base.frequency_ratio": 1.2}):
        scene = load_scene("harness-stepped-sine", overrides=override)
        assert scene.get("continuation.axis") is None, override
        assert "base_frequency_ratio" not in scene.axes
    scene = load_scene("harness-stepped-sine", overrides={"axes.length": [0.3, 0.4]})
    assert scene.get("continuation.axis") == "base_frequency_ratio"


@pytest.mark.parametrize("override", [
    {"continuation.axis": "base_frequncy_ratio"}, {"continuation.axis": "frequency_ratio"},
    {"continuation.axis": ""}, {"continuation": {"axis": "damping_ratio"}},
    {"continuation.axis": "base_frequency", "base.frequency": 30.0}])
def test_a_continuation_override_naming_no_axis_is_refused(override):
    """A tester: --set continuation.axis with a typo ran 26 independent dwells from rest with
    status 0, the stepped sweep dropped without a word (the orphaned continuation's removal
    took the override for a lost axis); the scene file's own refusal applies."""
    with pytest.raises(SceneError) as info:
        load_scene("harness-stepped-sine", overrides=override)
    assert "scene key 'continuation.axis'" in str(info.value), str(info.value)


@pytest.mark.parametrize("overrides, words", [
    ({"base.frequency": 20.0, "base.sweep.rate": 3.0},
     "overrides 'base.frequency' and 'base.sweep': give one, not both"),
    ({"axes.base_sweep_rate": [2.0, 4.0], "base.frequency_ratio": 1.0},
     "overrides 'base.frequency_ratio' and 'base.sweep': give one, not both"),
    ({"base.frequency": 20.0, "solver.t_end": 3.0, "outputs.envelope": True},
     "scene key 'outputs.envelope': needs a swept base frequency")])
def test_a_fixed_frequency_and_a_sweep_both_overridden_are_refused(overrides, words):
    """Two overrides that give the base frequency two ways are refused, as a pair's are; an
    override of a sweep-only output beside a fixed frequency stays, and is refused."""
    with pytest.raises(SceneError) as info:
        load_scene("launch-sine-qualification", overrides=overrides)
    assert words in str(info.value), str(info.value)


def test_cli_runs_a_sweep_scene_at_a_fixed_frequency(tmp_path, monkeypatch):
    """`sweep run launch-sine-qualification --set base.frequency=20` runs (one span, 0.2 s):
    a fixed-frequency result at 20 Hz and the table's level there (1.875 g, flat from 5 to
    45 Hz), no sweep direction, no envelope."""
    import xarray as xr
    from sweep.cli import main
    monkeypatch.chdir(tmp_path)
    argv = ["run", "launch-sine-qualification", "--set", "base.frequency=20.0", "--set",
            "solver.t_end=0.2", "--set", "axes.length=[0.3]", "-o", "out.nc", "--quiet"]
    assert main(argv) == 0
    with xr.open_dataset(tmp_path / "out.nc") as ds:
        assert "direction" not in ds.dims and "band_frequency" not in ds.dims
        assert "envelope" not in ds and "amplitude" in ds     # a fixed frequency's tail amplitude
        assert ds["length"].values.tolist() == [0.3]
        assert float(ds["base_frequency"].squeeze()) == 20.0
        assert float(ds["base_acceleration_g"].squeeze()) == pytest.approx(1.875, rel=1e-12)
        assert np.all(np.isfinite(ds["peak_amplitude"].values))


def test_override_both_frequencies_refused():
    message = scene_error(BASE, {"load.frequency": 10.0, "axes.frequency_ratio": [1.0, 2.0]})
    assert "give one, not both" in message


def test_string_override_for_string_key_kept_as_text():
    scene = load_scene_text(BASE, overrides={"name": "2024", "description": "true"})
    assert scene.name == "2024" and scene.description == "true"


def test_numpy_override_values():
    scene = load_scene_text(BASE, overrides={"axes.length": np.array([0.5, 1.0]),
                                             "solver.max_steps": np.int64(1000)})
    np.testing.assert_array_equal(scene.axes["length"], [0.5, 1.0])
    assert scene.get("solver.max_steps") == 1000


def test_unknown_override_key_gets_did_you_mean():
    message = scene_error(BASE, {"cable.lenght": 2.0})
    assert "'cable.lenght'" in message and "did you mean 'cable.length'?" in message
    message = scene_error(BASE, {"cabel.length": 2.0})
    assert "'cabel.length'" in message and "did you mean 'cable.length'?" in message


# --------------------------------------------------------------------------- round trip


def test_round_trip_override_heavy_scene():
    scene = load_scene_text(BASE, overrides={
        "description": 'quotes " and \\ backslash\tand tab, unicode \u03c9',
        "solver.max_step": 0.01,
        "solver.first_step": 1e-7,
        "metrics.divergence_bound": 0.5,
        "load.frequency": 3.3,
        "axes.damping_ratio": {"start": 1e-3, "stop": 0.1, "num": 7, "spacing": "log"},
        "axes.length": {"start": 0.3, "stop": 1.0, "num": 15},
        "axes.initial_displacement": [-2e-4, 1e-4],
        "run.threads": 4,
    })
    assert list(scene.axes) == ["damping_ratio", "length", "initial_displacement"]
    assert scene.get("load.frequency_ratio") is None
    assert_round_trip(scene)


def test_axes_are_read_only_float64():
    scene = load_scene("paper-fig5")
    with pytest.raises(ValueError):
        scene.axes["length"][0] = 3.0


# --------------------------------------------------------------------------- axes


def test_axis_order_preserved():
    scene = load_scene_text("""
[axes]
frequency_ratio = [1.0, 2.0]
load_amplitude = [1.0]
length = [1.0, 0.5]
""")
    assert list(scene.axes) == ["frequency_ratio", "load_amplitude", "length"]
    np.testing.assert_array_equal(scene.axes["length"], [1.0, 0.5])  # decreasing is fine


def test_log_spacing():
    scene = load_scene_text('[axes]\nlength = {start = 0.1, stop = 10, num = 3, spacing = "log"}')
    np.testing.assert_allclose(scene.axes["length"], [0.1, 1.0, 10.0])


def test_range_of_one_point():
    scene = load_scene_text("[axes]\nlength = {start = 0.7, stop = 2, num = 1}")
    np.testing.assert_array_equal(scene.axes["length"], [0.7])


def test_axis_by_dotted_key_is_normalised():
    scene = load_scene_text('[axes]\n"load.amplitude" = [1, 2]\ncable.length = [0.5, 1]')
    assert list(scene.axes) == ["load_amplitude", "length"]
    assert scene.axes["load_amplitude"].dtype == np.float64


def test_axis_wins_over_scalar():
    scene = load_scene_text("[cable]\nlength = 2.0\n[axes]\nlength = [0.5, 1.0]")
    assert scene.get("cable.length") is None
    np.testing.assert_array_equal(scene.axes["length"], [0.5, 1.0])


@pytest.mark.parametrize("axes, expected", [
    ("length = []", ["axis 'length'", "empty list", "at least one value"]),
    ("length = [0.5, 0.5]", ["axis 'length'", "strictly"]),
    ("length = [0.5, 1.0, 0.7]", ["axis 'length'", "strictly"]),
    ("length = [0.5, true]", ["axis 'length'", "number"]),
    ("length = [0.5, nan]", ["axis 'length'", "finite"]),
    ("length = [-0.5, 1.0]", ["axis 'length'", "-0.5", "> 0 m"]),
    ("length = 1.0", ["axis 'length'", "list"]),
    ("length = {start = 0.5, stop = 1}", ["axis 'length'", "'num'"]),
    ("length = {start = 0.5, stop = 1, num = 0}", ["axis 'length'", "num"]),
    ("length = {start = 0.5, stop = 1, num = 2.5}", ["axis 'length'", "whole number"]),
    ("length = {start = 0.5, stop = 1, num = 3, step = 1}", ["axis 'length'", "'step'"]),
    ('length = {start = 0.5, stop = 1, num = 3, spacing = "cubic"}', ["axis 'length'", "spacing"]),
    ('length = {start = 0.0, stop = 1, num = 3, spacing = "log"}', ["axis 'length'", "log"]),
    ("length = {start = 0.5, stop = 0.5, num = 3}", ["axis 'length'", "strictly"]),
    ("lenght = [1.0]", ["axis 'lenght'", "did you mean 'length'?"]),
    ("amplitude = [1.0]", ["axis 'amplitude'", "did you mean 'load_amplitude'?"]),
    ("rtol = [1e-6, 1e-8]", ["axis 'rtol'", "solver.rtol", "cannot be swept", "sweepable: "]),
    ('"solver.rtol" = [1e-6]', ["axis 'solver.rtol'", "cannot be swept"]),
    ("length = [1.0]\n\"cable.length\" = [2.0]", ["'length'", "twice"]),
    ("qwertyuiop = [1.0]", ["axis 'qwertyuiop'", "sweepable: length"]),
])
def test_axis_errors(axes, expected):
    message = scene_error("[axes]\n" + axes)
    for part in expected:
        assert part in message


def test_axes_must_be_a_table():
    assert "scene key 'axes'" in scene_error("axes = [1, 2]")


# --------------------------------------------------------------------------- scalar keys


@pytest.mark.parametrize("text, expected", [
    ("[cable]\nlenght = 1.0", ["scene key 'cable.lenght'", "did you mean 'cable.length'?"]),
    ("[cable]\namplitude = 1.0", ["scene key 'cable.amplitude'", "did you mean 'load.amplitude'?"]),
    ("[cable]\nzzzzzz = 1.0", ["scene key 'cable.zzzzzz'", "valid keys in [cable]: "]),
    ("[cabel]\nlength = 1.0", ["scene key 'cabel.length'", "did you mean 'cable.length'?"]),
    ("lenght = 1.0", ["scene key 'lenght'", "did you mean 'cable.length'?"]),
    ("zzzzzz = 1.0", ["scene key 'zzzzzz'", "[cable]"]),
    ("cable = 1.0", ["scene key 'cable'", "table"]),
    ("[cable]\nlength = [0.5, 1.0]", ["scene key 'cable.length'", "[axes]"]),
    ("[cable.length]\nx = 1", ["scene key 'cable.length'", "single value"]),
    ("[cable]\nlength = -1.0", ["scene key 'cable.length'", "must be > 0 m, got -1.0",
                                "span length in metres"]),
    ("[cable]\nlength = \"1.0\"", ["scene key 'cable.length'", "must be a number"]),
    ("[cable]\nlength = true", ["scene key 'cable.length'", "must be a number"]),
    ("[cable]\nlength = inf", ["scene key 'cable.length'", "finite"]),
    ("[cable]\ndensity = 0", ["scene key 'cable.density'", "> 0", "kg/m^3"]),
    ("[cable]\narea = -6e-6", ["scene key 'cable.area'", "m^2"]),
    ("[cable]\ninertia = 0.0", ["scene key 'cable.inertia'", "m^4"]),
    ("[cable]\nyoungs_modulus = 0.0", ["scene key 'cable.youngs_modulus'", "Pa"]),
    ("[solver]\nt_end = 0", ["scene key 'solver.t_end'", "seconds"]),
    ("[solver]\nrtol = 1e-15", ["scene key 'solver.rtol'", ">= 1e-14 and <= 0.1"]),
    ("[solver]\nrtol = 0.5", ["scene key 'solver.rtol'", "<= 0.1"]),
    ("[solver]\natol = 0", ["scene key 'solver.atol'", "> 0"]),
    ("[solver]\nmax_steps = 2.5", ["scene key 'solver.max_steps'", "whole number"]),
    ("[solver]\nmax_steps = true", ["scene key 'solver.max_steps'", "whole number"]),
    ("[solver]\nmax_steps = 0", ["scene key 'solver.max_steps'", ">= 1"]),
    ("[outputs]\ntime_series = \"yes\"", ["scene key 'outputs.time_series'", "true or false"]),
    ("[outputs]\ntime_series = 1", ["scene key 'outputs.time_series'", "true or false"]),
    ('[model]\ncoefficients = "papr"', ["scene key 'model.coefficients'", "'consistent', 'paper'",
                                        "did you mean 'paper'?"]),
    ("[model]\ncoefficients = 1", ["scene key 'model.coefficients'", "string"]),
    ('[model]\nkind = "sideways"', ["scene key 'model.kind'", "'transverse', 'longitudinal'"]),
    ("name = 3", ["scene key 'name'", "non-empty string"]),
    ('name = ""', ["scene key 'name'", "non-empty string"]),
    ("description = 3", ["scene key 'description'", "string"]),
    ("[outputs]\nsample_interval = 10.0", ["scene key 'outputs.sample_interval'", "t_end"]),
    ("[solver]\nmax_step = 6.0", ["scene key 'solver.max_step'", "t_end"]),
    ("[solver]\nt_end = 1.0\nfirst_step = 2.0", ["scene key 'solver.first_step'", "t_end"]),
])
def test_key_errors(text, expected):
    message = scene_error(text)
    for part in expected:
        assert part in message, (part, message)


def test_integral_float_accepted_for_int_keys():
    assert load_scene_text("[solver]\nmax_steps = 1e6").get("solver.max_steps") == 1_000_000
    assert isinstance(load_scene_text("[solver]\nmax_steps = 1e6").get("solver.max_steps"), int)


def test_int_accepted_for_float_keys():
    value = load_scene_text("[cable]\nlength = 2").get("cable.length")
    assert value == 2.0 and isinstance(value, float)


# --------------------------------------------------------------------------- cross-key rules


@pytest.mark.parametrize("text", [
    "[load]\nfrequency = 10.0\nfrequency_ratio = 1.0",
    "[load]\nfrequency = 10.0\n[axes]\nfrequency_ratio = [1.0, 2.0]",
    "[load]\nfrequency_ratio = 1.0\n[axes]\nfrequency = [1.0, 2.0]",
    "[axes]\nfrequency = [1.0, 2.0]\nfrequency_ratio = [1.0, 2.0]",
])
def test_both_frequencies_refused(text):
    message = scene_error(text)
    assert "'load.frequency' and 'load.frequency_ratio'" in message
    assert "give one, not both" in message


def test_frequency_alone():
    scene = load_scene_text("[load]\nfrequency = 12.5")
    assert scene.get("load.frequency") == 12.5
    assert scene.get("load.frequency_ratio") is None


@pytest.mark.parametrize("axis", ["youngs_modulus", "density", "area", "inertia", "membrane"])
def test_paper_refuses_cable_axes(axis):
    message = scene_error(f'[model]\ncoefficients = "paper"\n[axes]\n{axis} = [1.0, 2.0]')
    assert f"axis '{axis}'" in message
    assert "model.coefficients = 'paper' has no such parameter" in message
    assert "'consistent'" in message


def test_paper_default_velocity():
    paper = '[model]\ncoefficients = "paper"\n'
    assert load_scene_text(paper).get("initial.velocity") == PAPER_VELOCITY
    assert load_scene_text(paper + "[initial]\ndisplacement = 1e-3").get("initial.velocity") == 0.0
    swept = load_scene_text(paper + "[axes]\ninitial_displacement = [1e-3, 2e-3]")
    assert swept.get("initial.velocity") == 0.0
    assert load_scene_text(paper + "[initial]\nvelocity = 0.1").get("initial.velocity") == 0.1
    assert load_scene_text("").get("initial.velocity") == 0.0


# --------------------------------------------------------------------------- files


def test_toml_syntax_error_names_file_line_and_column(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('name = "x"\n[cable]\nlength = = 1\n', encoding="utf-8")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert "\n" not in message
    assert "s.toml" in message and "TOML syntax error at line 3, column" in message
    assert "fix the line" in message


def test_toml_syntax_error_at_end_of_text():
    assert "end of the file" in scene_error("a = [1,")


def test_unknown_scene_name():
    with pytest.raises(SceneError) as info:
        load_scene("qwerty")
    assert str(info.value) == ("scene 'qwerty': no built-in scene of that name and no such "
                               "file (run 'sweep scenes' for the built-in names)")
    with pytest.raises(SceneError) as info:
        load_scene("launch-random-gev")
    assert str(info.value).endswith("no such file (did you mean 'launch-random-gevs'? run "
                                    "'sweep scenes' for the built-in names)")


def test_directory_refused(tmp_path):
    with pytest.raises(SceneError, match="is a directory"):
        load_scene(tmp_path)


def test_non_utf8_refused(tmp_path):
    path = tmp_path / "latin.toml"
    path.write_bytes(b'name = "caf\xe9"\n')
    with pytest.raises(SceneError, match="latin.toml.*UTF-8"):
        load_scene(path)


# --------------------------------------------------------------------------- kind "floats"


def test_floats_key_valid_list():
    scene = load_scene_text(LONG_5S + "[outputs]\nsnapshot_times = [0, 1e-4, 2]")
    times = scene.get("outputs.snapshot_times")
    assert times == (0.0, 1e-4, 2.0)
    assert isinstance(times, tuple) and all(type(t) is float for t in times)


def test_floats_key_default_none_and_empty_list():
    assert load_scene_text(LONG).get("outputs.snapshot_times") is None
    assert load_scene_text(LONG + "[outputs]\nsnapshot_times = []").get(
        "outputs.snapshot_times") == ()


@pytest.mark.parametrize("value, expected", [
    ("[1e-4, -1e-4]", ["item 2", "-0.0001", ">= 0 s"]),
    ("[1e-4, nan]", ["item 2", "finite", "nan"]),
    ("[inf]", ["item 1", "finite", "inf"]),
    ("[1e-4, true]", ["item 2", "must be a number", "True"]),
    ('["1e-4"]', ["item 1", "must be a number", "'1e-4'"]),
    ("[[1e-4]]", ["item 1", "must be a number"]),
    ("1e-4", ["must be a list of numbers", "0.0001", "snapshot_times = ["]),
    ('"1e-4"', ["must be a list of numbers"]),
    ("{a = 1}", ["must be a list of numbers"]),
])
def test_floats_key_errors(value, expected):
    message = scene_error(LONG + f"[outputs]\nsnapshot_times = {value}")
    assert "scene key 'outputs.snapshot_times'" in message
    for part in expected:
        assert part in message, (part, message)


def test_floats_key_override():
    item = parse_override("outputs.snapshot_times=[1e-4, 2e-4]")
    scene = load_scene_text(LONG, overrides=dict([item]))
    assert scene.get("outputs.snapshot_times") == (1e-4, 2e-4)
    scene = load_scene_text(LONG, overrides={"outputs.snapshot_times": "[3e-4]"})
    assert scene.get("outputs.snapshot_times") == (3e-4,)
    scene = load_scene_text(LONG, overrides={"outputs.snapshot_times": np.array([1e-4, 5e-4])})
    assert scene.get("outputs.snapshot_times") == (1e-4, 5e-4)
    assert "item 1" in scene_error(LONG, {"outputs.snapshot_times": "[nan]"})


@pytest.mark.parametrize("times", ["[]", "[0.1, 1e-07, 0.30000000000000004]"])
def test_floats_key_round_trip(times):
    scene = load_scene_text(LONG_5S + f"[outputs]\nsnapshot_times = {times}")
    assert f"snapshot_times = {times}" in scene.to_toml()
    assert_round_trip(scene)
    other = load_scene_text(LONG_5S + "[outputs]\nsnapshot_times = [0.5]")
    assert other != scene


# --------------------------------------------------------------------------- longitudinal


def test_longitudinal_defaults():
    scene = load_scene_text(LONG)
    assert scene.get("model.kind") == "longitudinal"
    assert scene.get("load.type") == "constant"
    assert scene.get("solver.transits") == DEFAULT_TRANSITS == 8.0
    assert scene.get("solver.t_end") is None
    assert scene.get("solver.intervals") == 1000
    assert scene.get("solver.courant") == 1.0
    assert scene.get("outputs.histories") is False
    assert scene.get("outputs.normalised") is False


def test_longitudinal_one_end_time():
    scene = load_scene_text(LONG + "[solver]\nt_end = 0.01")
    assert scene.get("solver.t_end") == 0.01 and scene.get("solver.transits") is None
    scene = load_scene_text(LONG + "[solver]\ntransits = 3")
    assert scene.get("solver.transits") == 3.0 and scene.get("solver.t_end") is None


def test_longitudinal_allowed_axes_and_constant_load():
    scene = load_scene_text(LONG + """
[load]
type = "constant"
[axes]
length = [0.5, 1.0]
load_amplitude = [1, 2]
youngs_modulus = [1e11, 2e11]
density = [2700, 8900]
area = [1e-6, 6e-6]
""")
    assert list(scene.axes) == ["length", "load_amplitude", "youngs_modulus", "density", "area"]
    assert scene.get("load.type") == "constant"


def test_longitudinal_refuses_transverse_only_keys_and_keeps_its_own():
    """A transverse run's keys were accepted here and ignored (tests/test_silent_answers.py has
    each); the wave's own sample interval is not compared with a transverse end time."""
    for text in ('coefficients = "paper"', "[load]\nfrequency = 10.0",
                 "[initial]\nvelocity = 0.1", "[solver]\nrtol = 1e-6", "[metrics]\ntail = 0.25",
                 "[outputs]\ntime_series = true"):
        assert "would ignore it" in scene_error(LONG + text)
    scene = load_scene_text(LONG + "[outputs]\nhistories = true\nsample_interval = 1e-6")
    assert scene.get("outputs.sample_interval") == 1e-6


def test_longitudinal_sweeps_the_density_without_the_paper_rules():
    scene = load_scene_text('[model]\nkind = "longitudinal"\n[axes]\ndensity = [2700, 8900]')
    assert scene.get("initial.velocity") == 0.0
    assert list(scene.axes) == ["density"]


def test_longitudinal_refuses_harmonic_load():
    message = scene_error(LONG + '[load]\ntype = "harmonic"')
    assert message == ("scene key 'load.type': model.kind = 'longitudinal' takes only 'constant' "
                       "(use load.type = 'constant', a suddenly applied end load (docs/model.md sec. 4), "
                       "or model.kind = 'transverse' for a harmonic load)")
    assert message == scene_error(LONG, {"load.type": "harmonic"})


@pytest.mark.parametrize("axis", ["damping_ratio", "frequency_ratio", "frequency", "inertia",
                                  "membrane", "initial_displacement"])
def test_longitudinal_refuses_other_axes(axis):
    message = scene_error(LONG + f"[axes]\n{axis} = [0.1, 0.2]")
    assert message == (f"axis '{axis}': model.kind = 'longitudinal' has no such parameter "
                       "(remove the axis; it sweeps length, load_amplitude, youngs_modulus, "
                       "density, area)")


def test_longitudinal_refuses_both_end_times():
    message = scene_error(LONG + "[solver]\nt_end = 0.01\ntransits = 4")
    assert "'solver.t_end'" in message and "'solver.transits'" in message
    assert "give one, not both" in message
    assert "give one, not both" in scene_error(LONG, {"solver.t_end": 0.01,
                                                      "solver.transits": 4.0})


def test_end_time_override_replaces_the_other():
    scene = load_scene_text(LONG + "[solver]\ntransits = 4", overrides={"solver.t_end": 0.01})
    assert scene.get("solver.t_end") == 0.01 and scene.get("solver.transits") is None
    scene = load_scene_text(LONG + "[solver]\nt_end = 0.01", overrides={"solver.transits": 2})
    assert scene.get("solver.transits") == 2.0 and scene.get("solver.t_end") is None


def test_courant_above_one_refused():
    message = scene_error(LONG + "[solver]\ncourant = 1.01")
    assert message == (
        "scene key 'solver.courant': must be <= 1, got 1.01 (the explicit central difference is "
        "unstable above 1: its grid-scale mode grows about 1.33x per step at C = 1.01; use 1.0, "
        "which is exact at the nodes)")
    assert "unstable" in scene_error(LONG, {"solver.courant": 2})
    assert "unstable" in scene_error(LONG + "[solver]\ncourant = 1.0000001")
    assert "unstable" in scene_error(LONG + "[solver]\ncourant = 1e300")
    assert "unstable" in scene_error("[solver]\ncourant = 1.5")  # transverse too


@pytest.mark.parametrize("value", ["0", "-0.5"])
def test_courant_not_positive_refused(value):
    message = scene_error(LONG + f"[solver]\ncourant = {value}")
    assert "scene key 'solver.courant'" in message and "must be > 0 and <= 1" in message
    assert "unstable" not in message


def test_courant_below_one_accepted():
    assert load_scene_text(LONG + "[solver]\ncourant = 0.5").get("solver.courant") == 0.5


@pytest.mark.parametrize("text, expected", [
    ("[solver]\ntransits = 0", ["scene key 'solver.transits'", "> 0", "transits"]),
    ("[solver]\nintervals = 1", ["scene key 'solver.intervals'", ">= 2"]),
    ("[solver]\nintervals = 10.5", ["scene key 'solver.intervals'", "whole number"]),
    ("[outputs]\nhistories = 1", ["scene key 'outputs.histories'", "true or false"]),
    ("[outputs]\nnormalised = \"yes\"", ["scene key 'outputs.normalised'", "true or false"]),
])
def test_longitudinal_key_errors(text, expected):
    message = scene_error(LONG + text)
    for part in expected:
        assert part in message, (part, message)


def test_snapshot_time_after_t_end_refused():
    message = scene_error(LONG + "[solver]\nt_end = 0.01\n[outputs]\n"
                                 "snapshot_times = [0.005, 0.01, 0.02]")
    assert "scene key 'outputs.snapshot_times'" in message
    assert "item 3" in message and "0.02" in message and "solver.t_end" in message
    ok = load_scene_text(LONG + "[solver]\nt_end = 0.01\n[outputs]\nsnapshot_times = [0.01]")
    assert ok.get("outputs.snapshot_times") == (0.01,)
    # With transits the end time depends on the point: checked against the longest one (below).
    assert "solver.transits" in scene_error(LONG + "[outputs]\nsnapshot_times = [100.0]")


def test_resolved_longitudinal_scene_round_trip():
    scene = load_scene_text(LONG + """
[solver]
intervals = 400
courant = 0.75
[outputs]
histories = true
normalised = true
snapshot_times = [1e-5, 2.5e-5]
[axes]
length = [0.5, 1.0]
load_amplitude = {start = 1, stop = 4, num = 4}
""", overrides={"name": "bar"})
    text = scene.to_toml()
    assert 'kind = "longitudinal"' in text and 'type = "constant"' in text
    assert "transits = 8.0" in text and "t_end" not in text
    assert_round_trip(scene)
    with_t_end = load_scene_text(LONG + "[solver]\nt_end = 0.002")
    assert "transits" not in with_t_end.to_toml()
    assert_round_trip(with_t_end)


# --------------------------------------------------------------------------- transverse end time


def test_transverse_t_end_default():
    assert load_scene_text("").get("solver.t_end") == 5.0
    assert load_scene_text('[model]\nkind = "transverse"').get("solver.t_end") == 5.0
    assert load_scene_text("[solver]\nt_end = 2").get("solver.t_end") == 2.0
    assert load_scene_text("").get("solver.transits") is None
    assert_round_trip(load_scene_text(""))


def test_transverse_refuses_transits():
    expected = ("scene key 'solver.transits': only for model.kind = 'longitudinal' "
                "(use solver.t_end in seconds)")
    assert scene_error("[solver]\ntransits = 8") == expected
    assert scene_error(BASE, {"solver.transits": 8}) == expected


def test_transverse_time_checks_use_default_t_end():
    assert "t_end" in scene_error("[outputs]\nsample_interval = 5.5")
    assert load_scene_text("[outputs]\nsample_interval = 5.0").get("outputs.sample_interval") == 5.0


def test_kind_override_switches_rules():
    scene = load_scene_text(BASE, overrides={"model.kind": "longitudinal"})
    assert scene.get("load.type") == "constant" and scene.get("solver.transits") == 8.0
    back = load_scene_text(scene.to_toml(), overrides={"model.kind": "transverse",
                                                       "solver.t_end": 3.0})
    assert back.get("solver.t_end") == 3.0 and back.get("solver.transits") is None


# --------------------------------------------------------------------------- range values as written


def _decimal(units: int, places: int) -> str:
    """units x 10^-places as a plain decimal string, e.g. (4, 1) -> '0.4'."""
    from decimal import Decimal
    return format(Decimal(units).scaleb(-places), "f")


@pytest.mark.parametrize("start, stop, num, sel", [
    ("0.3", "1.2", 10, "0.4"), ("0.3", "1.2", 10, "0.8"), ("0.1", "1.0", 10, "0.7"),
    ("0.5", "3", 26, "2.3"), ("2", "0.2", 10, "0.6"), ("1e-3", "2e-3", 11, "0.0017"),
])
def test_linear_range_gives_the_values_as_written(start, stop, num, sel):
    """Each value is the float of the decimal it is (0.4, not linspace's 0.39999999999999997),
    so xarray's exact .sel with the written number finds it."""
    import xarray as xr
    scene = load_scene_text(f"[axes]\nlength = {{start = {start}, stop = {stop}, num = {num}}}")
    axis = xr.DataArray(scene.axes["length"], dims="length", coords={"length": scene.axes["length"]})
    assert float(axis.sel(length=float(sel))) == float(sel)
    assert scene.axes["length"][0] == float(start) and scene.axes["length"][-1] == float(stop)
    by_set = load_scene_text("", overrides=dict([parse_override(
        f"axes.length={{start={start}, stop={stop}, num={num}}}")]))
    np.testing.assert_array_equal(by_set.axes["length"], scene.axes["length"])


def test_linear_range_of_written_decimals_matches_the_decimals():
    """Hypothesis: start = a 10^-d, step = k 10^-d; value i must be float('<a + i k> e-d'),
    the float Python reads from the decimal a user would type."""
    from hypothesis import given, settings as hsettings, strategies as st

    @hsettings(max_examples=300, deadline=None)
    @given(st.integers(1, 10**6), st.integers(-10**4, 10**4).filter(bool),
           st.integers(0, 12), st.integers(2, 60))
    def check(a: int, k: int, places: int, num: int) -> None:
        units = [a + i * k for i in range(num)]
        if min(units) <= 0:
            return                                    # lengths must stay positive
        text = (f"[axes]\nlength = {{start = {_decimal(units[0], places)}, "
                f"stop = {_decimal(units[-1], places)}, num = {num}}}")
        values = load_scene_text(text).axes["length"]
        expected = [float(_decimal(u, places)) for u in units]
        assert values.tolist() == expected, text

    check()


def test_range_that_is_not_a_short_decimal_is_correctly_rounded():
    from fractions import Fraction
    values = load_scene_text("[axes]\nlength = {start = 0.1, stop = 1.0, num = 4}").axes["length"]
    exact = [Fraction(1, 10) + i * Fraction(3, 10) for i in range(4)]
    assert values.tolist() == [float(x) for x in exact]       # 0.4, 0.7 exactly
    thirds = load_scene_text("[axes]\nload_amplitude = {start = 0, stop = 1, num = 4}")
    assert thirds.axes["load_amplitude"].tolist() == [0.0, 1 / 3, 2 / 3, 1.0]


@pytest.mark.parametrize("mantissa", [1, 2, 5, 7])
@pytest.mark.parametrize("first, decades", [(0, 3), (-6, 4), (-3, 6), (2, 2)])
def test_log_range_of_whole_decades_is_exact(mantissa, first, decades):
    text = (f'[axes]\nlength = {{start = {mantissa}e{first}, stop = {mantissa}e{first + decades}, '
            f'num = {decades + 1}, spacing = "log"}}')
    values = load_scene_text(text).axes["length"]
    assert values.tolist() == [float(f"{mantissa}e{first + i}") for i in range(decades + 1)]


def test_log_range_close_to_the_geometric_values():
    """Hypothesis: every log value within 1e-14 relative of start (stop/start)^(i/(num-1))
    (computed in 40-digit decimal; rounding to 15 digits moves a value by up to 5e-15),
    endpoints exact, strictly monotonic."""
    from decimal import Decimal, localcontext
    from hypothesis import given, settings as hsettings, strategies as st

    @hsettings(max_examples=200, deadline=None)
    @given(st.floats(1e-6, 1e6), st.floats(1e-6, 1e6), st.integers(2, 50))
    def check(start: float, stop: float, num: int) -> None:
        if abs(stop / start - 1) < 1e-6:
            return
        text = f'[axes]\nlength = {{start = {start!r}, stop = {stop!r}, num = {num}, spacing = "log"}}'
        values = load_scene_text(text).axes["length"]
        assert values[0] == start and values[-1] == stop
        with localcontext() as ctx:
            ctx.prec = 40
            ratio = Decimal(stop) / Decimal(start)
            exact = [Decimal(start) * ratio ** (Decimal(i) / (num - 1)) for i in range(num)]
        np.testing.assert_allclose(values, [float(x) for x in exact], rtol=1e-14, atol=0)
        assert np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0)

    check()


def test_range_values_sel_through_the_netcdf_file(tmp_path):
    """sweep.run(scene, output=...) then xr.open_dataset(...).sel(length=0.4)."""
    import xarray as xr
    import sweep
    scene = load_scene_text("[axes]\nlength = {start = 0.3, stop = 1.2, num = 10}\n"
                            "[solver]\nt_end = 0.02\n[initial]\ndisplacement = 1e-4")
    sweep.run(scene, output=tmp_path / "r.nc", progress=False)
    with xr.open_dataset(tmp_path / "r.nc") as ds:
        for written in (0.4, 0.8, 0.9, 1.1):
            assert float(ds["length"].sel(length=written)) == written
        assert ds["state"].sel(length=0.4).size == 1


# --------------------------------------------------------------------------- default inertia


def test_default_inertia_is_the_bending_moment_of_the_solid_section():
    """Not given: A^2/(4 pi) = pi d^4/64 of the round section of area A (2.865e-12 m^4 for
    6 mm^2), not the paper's polar moment 5.73e-12 (twice it)."""
    import math
    assert load_scene_text("").get("cable.inertia") == pytest.approx(2.8648e-12, rel=1e-4)
    for area in (6e-6, 1e-6, 3.3e-5):
        d = math.sqrt(4 * area / math.pi)
        inertia = load_scene_text(f"[cable]\narea = {area!r}").get("cable.inertia")
        assert inertia == pytest.approx(math.pi * d ** 4 / 64, rel=1e-14)
    assert load_scene_text("[cable]\ninertia = 1e-12").get("cable.inertia") == 1e-12
    assert load_scene_text("", overrides={"cable.area": 1e-6}).get("cable.inertia") == \
        pytest.approx(1e-12 / (4 * math.pi), rel=1e-14)
    assert_round_trip(load_scene_text("[axes]\narea = [1e-6, 6e-6]"))


def test_paper_scenes_keep_the_papers_inertia():
    for name in ("paper-fig5", "paper-fig7"):
        assert load_scene(name).get("cable.inertia") == 5.73e-12


def _natural_frequency(scene: Scene):
    from sweep import grid, models
    coords = grid.coordinates(scene)
    return models.oscillator(grid.parameters(scene, coords))["natural_frequency"]


def test_natural_frequency_with_the_default_inertia_is_the_closed_form():
    """f1 = pi sqrt(EI/(rho A)) / (2 l^2) with I = A^2/(4 pi), also when area is an axis (the
    inertia then follows the area point by point)."""
    import math
    E, rho, length = 1.1e11, 8900.0, 0.7

    def f1(area: float) -> float:
        return math.pi * math.sqrt(E * area ** 2 / (4 * math.pi) / (rho * area)) / (2 * length ** 2)

    base = f"[cable]\nyoungs_modulus = {E!r}\ndensity = {rho!r}\nlength = {length!r}\n"
    assert float(_natural_frequency(load_scene_text(base))) == pytest.approx(f1(6e-6), rel=1e-13)
    swept = load_scene_text(base + "[axes]\narea = [1e-6, 6e-6, 2e-5]")
    assert swept.get("cable.inertia") is None
    freq = _natural_frequency(swept)
    assert freq.dims == ("area",)
    np.testing.assert_allclose(freq.values, [f1(a) for a in (1e-6, 6e-6, 2e-5)], rtol=1e-13)
    given = load_scene_text(base + "inertia = 5.73e-12\n[axes]\narea = [1e-6, 6e-6]")
    np.testing.assert_allclose(
        _natural_frequency(given).values,
        [math.pi * math.sqrt(E * 5.73e-12 / (rho * a)) / (2 * length ** 2) for a in (1e-6, 6e-6)],
        rtol=1e-13)


# --------------------------------------------------------------------------- refused at load time


@pytest.mark.parametrize("axis", ["frequency_ratio", "frequency"])
def test_constant_load_with_a_frequency_axis_refused_by_load_scene(axis):
    message = scene_error(f'[load]\ntype = "constant"\n[axes]\n{axis} = [1.0, 2.0]')
    assert message == (f"axis '{axis}': load.type = 'constant' has no load frequency to sweep "
                       f"(remove the {axis} axis, or use load.type = 'harmonic')")
    with pytest.raises(SceneError, match="load.type = 'constant'"):
        load_scene("harness-parametric", overrides={"load.type": "constant"})


def test_longitudinal_snapshot_after_every_spans_end_refused_by_load_scene():
    """With solver.transits the end time is transits x l/a per span: a snapshot after the
    longest span's end would be NaN at every point, so load_scene refuses it."""
    import math
    longest = 2.0 * (1.0 / math.sqrt(1.1e11 / 8900.0))           # 2 transits of the 1 m span
    text = LONG + "[solver]\ntransits = 2.0\n[axes]\nlength = [0.5, 1.0]\n[outputs]\n"
    message = scene_error(text + f"snapshot_times = [1e-4, {longest * 1.001!r}]")
    assert message.startswith("scene key 'outputs.snapshot_times': item 2 of the list")
    assert "solver.transits" in message and f"{longest:.6g} s" in message
    # Between the short span's end and the long one's: NaN for the short span only, accepted.
    scene = load_scene_text(text + f"snapshot_times = [{0.75 * longest!r}, {longest!r}]")
    assert scene.get("outputs.snapshot_times") == (0.75 * longest, longest)
    # A denser cable on a density axis is slower: its spans end later, and the time is kept.
    denser = LONG + "[solver]\ntransits = 2.0\n[axes]\ndensity = [8900.0, 20000.0]\n[outputs]\n"
    assert load_scene_text(denser + f"snapshot_times = [{longest * 1.001!r}]")


# --------------------------------------------------------------------------- the default driver

ELASTIC = '[model]\nmodes = 3\n[clamps]\nrotation = "elastic"\nrotational_stiffness = 1.0\n'


@pytest.mark.parametrize("text, overrides, expected", [
    # several modes: the lanes where at least 4 points share a basis, else the scalar driver
    ("[model]\nmodes = 3", {}, "scalar"),                                   # one span
    ("[model]\nmodes = 3", {"axes.length": [0.3, 0.4, 0.5]}, "scalar"),
    ("[model]\nmodes = 3", {"axes.length": [0.3, 0.4, 0.5, 0.6]}, "lanes"),
    # elastic clamps: K = k_t l / EI, a basis per length and per stiffness, all of them in
    # one lanes call up to 4 modes (kernels.modes.stacked); 5 modes do not stack, nor
    # does k_t = 0 (the pinned span's basis)
    (ELASTIC, {"axes.length": [0.2, 0.3, 0.4, 0.5, 0.6]}, "lanes"),
    (ELASTIC, {"axes.length": [0.2, 0.3, 0.4]}, "scalar"),
    (ELASTIC.replace("modes = 3", "modes = 5"), {"axes.length": [0.2, 0.3, 0.4, 0.5, 0.6]},
     "scalar"),
    (ELASTIC.replace("rotational_stiffness = 1.0\n", ""),
     {"axes.clamp_rotational_stiffness": [0.0, 1.0, 10.0, 100.0]}, "scalar"),
    (ELASTIC, {"axes.length": [0.2, 0.3], "axes.load_amplitude": [0.0, 1.0, 2.0, 3.0]},
     "lanes"),
    (ELASTIC, {"axes.length": [0.2, 0.3], "axes.load_amplitude": [1.0, 2.0],
               "axes.damping_ratio": [0.01, 0.02]}, "lanes"),
    (ELASTIC.replace("modes = 3", "modes = 5"), {"axes.length": [0.2, 0.3],
     "axes.youngs_modulus": [1e11, 2e11], "axes.load_amplitude": [1.0, 2.0]}, "scalar"),
    (ELASTIC.replace("modes = 3", "modes = 5"), {"axes.length": [0.2, 0.3],
     "axes.load_amplitude": [1.0, 2.0, 3.0, 4.0]}, "lanes"),
    (ELASTIC.replace("rotational_stiffness = 1.0\n", ""),
     {"axes.clamp_rotational_stiffness": [0.1, 1.0, 10.0, 100.0]}, "lanes"),
    ('[model]\nmodes = 3\n[clamps]\nrotation = "clamped"', {"axes.length": [0.2, 0.3, 0.4, 0.5]},
     "lanes"),
    # one mode: always the lanes (their cost barely depends on how many run)
    ("", {}, "lanes"),
    # what a scene gives is kept
    ('[model]\nmodes = 3\n[solver]\ndriver = "lanes"', {}, "lanes"),
    (ELASTIC + '[solver]\ndriver = "lanes"', {"axes.length": [0.2, 0.3]}, "lanes"),
])
def test_default_driver_follows_the_points_that_share_a_basis(text, overrides, expected):
    assert load_scene_text(text, overrides=overrides).get("solver.driver") == expected


def test_default_driver_with_points_that_vary_together():
    text = ELASTIC + "[points]\nlength = [0.2, 0.3, 0.4, 0.5]\nload_amplitude = [1.0, 2.0, 3.0, 4.0]\n"
    assert load_scene_text(text).get("solver.driver") == "lanes"       # four K, one call
    five = ELASTIC.replace("modes = 3", "modes = 5")
    assert load_scene_text(five + text[len(ELASTIC):]).get("solver.driver") == "scalar"
    text = ELASTIC + "[points]\nload_amplitude = [1.0, 2.0, 3.0, 4.0]\ndamping_ratio = [0.01, 0.02, 0.03, 0.04]\n"
    assert load_scene_text(text).get("solver.driver") == "lanes"       # one K for all four


def test_harness_clamps_runs_on_the_lanes():
    """35 points, each its own K = k_t l / EI, in one lanes call (the bases stack)."""
    from sweep import load_scene
    assert load_scene("harness-clamps").get("solver.driver") == "lanes"


@pytest.mark.parametrize("overrides, expected", [
    ({"model.modes": 3}, "lanes"),                       # 9 spans x 2 levels x 8 records a basis
    ({"model.modes": 1}, "lanes"),                       # one mode: 9 x 2 x 8 in one call
    ({"model.modes": 1, "base.realisations": 1, "axes.length": [0.1],
      "axes.base_asd_scale": [0.0]}, "scalar"),          # one trajectory
    ({"model.modes": 1, "base.realisations": 2, "axes.length": [0.1],
      "axes.base_asd_scale": [0.0]}, "lanes"),           # two
    ({"model.modes": 1, "base.realisations": 1, "axes.length": [0.1],
      "axes.base_asd_scale": [0.0], "clamps.rotation": "elastic", "cable.diameter": "3 mm",
      "axes.clamp_rotational_stiffness": [1.0, 2.0]}, "lanes"),  # elastic: still one call
    ({"model.modes": 3, "base.realisations": 1, "axes.length": [0.1]}, "scalar"),   # 2 records
    ({"model.modes": 3, "base.realisations": 4}, "lanes"),                          # 9 x 2 x 4
    ({"model.modes": 3, "base.realisations": 1, "clamps.rotation": "elastic",
      "clamps.rotational_stiffness": 1.0, "cable.diameter": "3 mm"}, "lanes"),      # one call
    ({"model.modes": 5, "base.realisations": 1, "clamps.rotation": "elastic",
      "clamps.rotational_stiffness": 1.0, "cable.diameter": "3 mm"}, "scalar"),     # 2 a basis
    ({"model.modes": 3, "base.realisations": 2, "clamps.rotation": "elastic",
      "clamps.rotational_stiffness": 1.0, "cable.diameter": "3 mm"}, "lanes"),      # 4 a basis
    ({"model.modes": 3, "clamps.rotation": "elastic", "clamps.rotational_stiffness": 1.0,
      "cable.diameter": "3 mm"}, "lanes"),                                          # 16 a basis
    ({"model.modes": 3, "base.realisations": 1, "solver.driver": "lanes"}, "lanes"),
])
def test_a_random_scene_counts_its_records_for_the_default_driver(overrides, expected):
    from sweep import load_scene
    assert load_scene("launch-random-gevs", overrides).get("solver.driver") == expected


@pytest.mark.parametrize("overrides, expected", [
    ({}, "scalar"),                                       # 3 lines a direction
    ({"axes.length": [0.3, 0.4, 0.5, 0.6]}, "lanes"),     # 4 lines
    ({"axes.length": [0.5]}, "scalar"),
])
def test_a_stepped_sweep_counts_its_lines_for_the_default_driver(overrides, expected):
    """A stepped sweep's kernel call takes one dwell of every line: the dwells along the
    continuation axis do not fill the lanes."""
    from sweep import load_scene
    assert load_scene("harness-stepped-sine", overrides).get("solver.driver") == expected


def test_a_validated_scene_is_read_only_and_still_pickles():
    """An edited value would run unchecked (a reviewer's negative damping ran as a divergence,
    a string one failed deep in the model): refused in one line; dask still pickles it."""
    import pickle
    scene = sweep.load_scene("paper-fig5")
    with pytest.raises(TypeError, match="read-only once validated"):
        scene.values["cable.damping_ratio"] = -1.0
    with pytest.raises(TypeError, match="read-only"):
        scene.axes.update(length=[0.3])
    again = pickle.loads(pickle.dumps(scene))
    assert again == scene


@pytest.mark.parametrize("call, fragment", [
    (lambda: sweep.load_scene(5), "not a scene name or a path"),
    (lambda: sweep.load_scene("paper-fig5", "model.modes=3"), "not a mapping of dotted keys"),
    (lambda: sweep.load_scene_text(5), "not TOML text"),
    (lambda: sweep.load_scene_text("[model]\nmodes = 1\n", {"model.modes": 2}),
     "give overrides by keyword"),
    (lambda: sweep.run(sweep.load_scene("paper-fig5"), output=5, progress=False),
     "not a file name"),
    (lambda: sweep.run(sweep.load_scene("paper-fig5"), progress="no"), "give True, False"),
])
def test_api_arguments_of_the_wrong_kind_are_one_line(call, fragment):
    """A script's mistake (load_scene_text's second argument is the source's name, not the
    overrides: they were silently dropped) gets one UserError, not a deep traceback."""
    with pytest.raises(sweep.UserError, match=fragment):
        call()


def test_a_table_override_of_a_section_merges_key_by_key():
    """--set 'cable={length=0.3}' (or overrides={'cable': {...}}) sets the keys it names and
    keeps the section's others (a reviewer found it replaced [cable] whole: the damping fell
    to 0 unsaid); the command line's parsed form does the same."""
    from sweep.scene import parse_override
    text = "[cable]\nlength = 0.5\ndamping_ratio = 0.02\n[solver]\nt_end = 0.5\n"
    for overrides in ({"cable": {"length": 0.3}}, dict([parse_override("cable={length=0.3}")])):
        scene = sweep.load_scene_text(text, overrides=overrides)
        assert scene.get("cable.length") == 0.3
        assert scene.get("cable.damping_ratio") == 0.02


def test_a_nested_table_override_merges_as_its_section_form_does():
    """--set 'base.sweep={start=80.0, stop=20.0}' on a sweep of 20 to 80 Hz at 60 oct/min
    sets start and stop and keeps the rate, as 'base={sweep={...}}' did (it replaced the
    table and was refused: 'missing rate'); a key the table does not have is still one line
    naming it."""
    from sweep.scene import parse_override
    text = ('name = "down"\n[cable]\nlength = 0.4\n[base]\nacceleration_g = 0.5\n'
            "sweep = {start = 20.0, stop = 80.0, rate = 60.0}\n")
    for item in ("base.sweep={start=80.0, stop=20.0}", "base={sweep={start=80.0, stop=20.0}}"):
        scene = sweep.load_scene_text(text, overrides=dict([parse_override(item)]))
        assert (scene.get("base.sweep.start"), scene.get("base.sweep.stop"),
                scene.get("base.sweep.rate")) == (80.0, 20.0, 60.0), item
    with pytest.raises(SceneError, match="'base.sweep.rat'.*did you mean 'base.sweep.rate'"):
        sweep.load_scene_text(text, overrides=dict([parse_override("base.sweep={rat=1}")]))


def test_a_section_table_override_flattens_nested_tables_and_keeps_the_pair_rules():
    """base={sweep={rate=1}} sets base.sweep.rate alone (it replaced the sweep's table,
    dropping start and stop); points={length=[...]} replaces the length axis as
    points.length does; both keys of an either-or pair in one table are refused as two
    overrides are."""
    from sweep.scene import parse_override
    scene = sweep.load_scene("launch-sine-qualification",
                             overrides=dict([parse_override("base={sweep={rate=1}}")]))
    assert scene.get("base.sweep.rate") == 1.0 and scene.get("base.sweep.start") == 5.0
    scene = sweep.load_scene("harness-base-sine",
                             overrides=dict([parse_override("points={length=[0.2,0.25]}")]))
    assert "length" in scene.points and "length" not in scene.axes
    with pytest.raises(SceneError, match="give one, not both"):
        sweep.load_scene("harness-base-sine", overrides=dict(
            [parse_override("base={acceleration_g=1, acceleration=3}")]))
