"""Tests for sweep.scene: loading, overrides, validation messages, TOML round trip."""

from __future__ import annotations

import numpy as np
import pytest

from sweep import schema
from sweep.errors import SceneError
from sweep.scene import (PAPER_VELOCITY, Scene, builtin_scenes, load_scene, load_scene_text,
                         parse_override)

BASE = """
name = "t"
[cable]
length = 1.0
"""


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
        if key.dotted not in ("load.frequency_ratio",):
            assert scene.get(key.dotted) == key.default
    assert scene.get("load.frequency_ratio") == 1.0
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
    ('[model]\nkind = "longitudinal"', ["scene key 'model.kind'", "not available", "'transverse'"]),
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
        load_scene("paper-fig6")
    assert str(info.value) == ("scene 'paper-fig6': no built-in scene of that name and no such "
                               "file (run 'sweep scenes' for the built-in names)")


def test_directory_refused(tmp_path):
    with pytest.raises(SceneError, match="is a directory"):
        load_scene(tmp_path)


def test_non_utf8_refused(tmp_path):
    path = tmp_path / "latin.toml"
    path.write_bytes(b'name = "caf\xe9"\n')
    with pytest.raises(SceneError, match="latin.toml.*UTF-8"):
        load_scene(path)
