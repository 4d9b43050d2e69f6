"""The clamp-spacing question (docs/model.md sec. 9, sweep/design.py): the largest span meeting
a frequency and a deflection criterion, against closed forms computed here from the cable data,
not from the result's own derived values."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy.optimize import brentq

import sweep
from conftest import TABLE1_CABLE
from sweep.cli import main
from sweep.design import max_span, refine_span
from sweep.version import package_version

# Table 1 cable, bending moment of the solid round 6 mm^2 section.
E, RHO, AREA, INERTIA, ZETA = 1.1e11, 8900.0, 6e-6, 2.865e-12, 0.02
G = 9.80665
LEVEL_G = 0.001            # g: tiny, so the membrane-free span responds linearly
BASE_FREQUENCY = 30.0      # Hz

SCENE = """
name = "{name}"
description = "design test"
[model]
kind = "transverse"
coefficients = "consistent"
membrane = {membrane}
modes = 1
[cable]
{table1}
damping_ratio = 0.02
{cable}
[load]
amplitude = 0.0
[base]
{base}
[initial]
displacement = 0.0
velocity = 0.0
[axes]
{axes}
[solver]
{solver}
"""


def f1(length: float) -> float:
    """First natural frequency (Hz) of the unloaded span, docs/model.md sec. 9."""
    return math.pi * math.sqrt(E * INERTIA / (RHO * AREA)) / (2.0 * length ** 2)


def l_max_frequency(f_min: float) -> float:
    return math.sqrt(math.pi * math.sqrt(E * INERTIA / (RHO * AREA)) / (2.0 * f_min))


def linear_amplitude(length: float) -> float:
    """(4/pi) A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2), m."""
    w1, w = 2 * math.pi * f1(length), 2 * math.pi * BASE_FREQUENCY
    return (4 / math.pi) * LEVEL_G * G / math.sqrt((w1 ** 2 - w ** 2) ** 2
                                                   + (2 * ZETA * w1 * w) ** 2)


def _run(tmp: Path, name: str, *, membrane: float | None = 0.0, cable: str = "",
         base: str = f"acceleration_g = {LEVEL_G}\nfrequency = {BASE_FREQUENCY}",
         axes: str, solver: str = "t_end = 5.0", output: bool = True) -> tuple[xr.Dataset, Path]:
    path = tmp / f"{name}.toml"
    text = SCENE.format(table1=TABLE1_CABLE, name=name, membrane=membrane, cable=cable,
                        base=base, axes=axes, solver=solver)
    if membrane is None:                         # the uniform stretching tension
        text = text.replace("membrane = None\n", "")
    path.write_text(text)
    out = tmp / f"{name}.nc"
    ds = sweep.run(sweep.load_scene(str(path)), output=out if output else None, progress=False)
    return ds, out


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("design")
    coarse = _run(tmp, "coarse", axes="length = {start = 0.1, stop = 0.6, num = 11}",
                  solver="t_end = 0.5")
    # lengths from 0.1 m up to the 30 Hz resonance (0.357 m), every 5 mm; the uniform
    # stretching tension, negligible at this level (2e-6 of the stiffness at 1e-6 m)
    linear = _run(tmp, "linear", membrane=None,
                  axes="length = {start = 0.1, stop = 0.34, num = 49}")
    swept = _run(tmp, "swept", membrane=0.375,
                 base='acceleration_g = 0.5\n'
                      'sweep = {start = 20.0, stop = 60.0, rate = 16.0, direction = "both"}',
                 axes="length = {start = 0.2, stop = 0.35, num = 4}", solver="")
    no_length = _run(tmp, "nolength", cable="length = 0.3", base=f"acceleration_g = {LEVEL_G}",
                     axes="base_frequency = [20.0, 30.0]", solver="t_end = 0.5")
    return {"coarse": coarse, "linear": linear, "swept": swept, "no_length": no_length}


def test_frequency_criterion_alone_is_the_closed_form(results):
    ds, _ = results["coarse"]
    out = max_span(ds, min_frequency=100.0)
    exact = l_max_frequency(100.0)
    assert 0.1 < exact < 0.6
    got = float(out["max_span"])
    assert abs(got / exact - 1) < 1e-6, (got, exact)      # log f vs log l: exact for l^-2
    assert str(out["limited_by"].values) == "min_frequency"
    assert out["max_span"].attrs["units"] == "m"
    assert "natural_frequency >= 100 Hz" in out.attrs["criteria"]
    assert "coarse" in out.attrs["title"]
    # a limit below every grid frequency: every span passes, the grid binds
    grid = max_span(ds, min_frequency=1.0)
    assert float(grid["max_span"]) == pytest.approx(0.6)
    assert str(grid["limited_by"].values) == "grid"
    # above every grid frequency: the shortest span fails already
    none = max_span(ds, min_frequency=f1(0.1) * 1.01)
    assert np.isnan(float(none["max_span"]))
    assert str(none["limited_by"].values) == "min_frequency"


def _amplitude_reference(limit: float) -> float:
    l_res = math.sqrt(math.pi * math.sqrt(E * INERTIA / (RHO * AREA))
                      / (2 * BASE_FREQUENCY))
    return brentq(lambda length: linear_amplitude(length) - limit, 0.1, l_res, xtol=1e-12)


@pytest.mark.parametrize("limit", [2e-8, 1e-7, 5e-7])
def test_amplitude_criterion_on_a_linear_span_is_the_closed_form(results, limit):
    ds, _ = results["linear"]
    out = max_span(ds, max_amplitude=limit)
    exact = _amplitude_reference(limit)
    got = float(out["max_span"])
    assert abs(got / exact - 1) < 0.02, (got, exact)
    assert abs(got / exact - 1) < 2e-3, (got, exact)      # 5 mm grid: far better than 2 %
    assert str(out["limited_by"].values) == "max_amplitude"
    assert "amplitude <= " in out.attrs["criteria"]


def test_both_criteria_the_smaller_span_binds(results):
    ds, _ = results["linear"]
    f_span = l_max_frequency(100.0)
    a_small, a_large = _amplitude_reference(2e-8), _amplitude_reference(5e-7)
    assert a_small < f_span < a_large
    out = max_span(ds, min_frequency=100.0, max_amplitude=5e-7)
    assert float(out["max_span"]) == pytest.approx(f_span, rel=1e-6)
    assert str(out["limited_by"].values) == "min_frequency"
    out = max_span(ds, min_frequency=100.0, max_amplitude=2e-8)
    assert float(out["max_span"]) == pytest.approx(a_small, rel=2e-3)
    assert str(out["limited_by"].values) == "max_amplitude"


def _strain_reference(limit: float) -> float:
    """The span where the linear midspan bending strain (d / 2) pi^2 q / l^2 (d of the solid
    section, q `linear_amplitude`) reaches `limit` (the stretching's strain is ~ q^2: nil)."""
    d = math.sqrt(4.0 * AREA / math.pi)
    l_res = math.sqrt(math.pi * math.sqrt(E * INERTIA / (RHO * AREA))
                      / (2 * BASE_FREQUENCY))
    return brentq(lambda length: d / 2 * math.pi ** 2 * linear_amplitude(length) / length ** 2
                  - limit, 0.1, l_res, xtol=1e-12)


@pytest.mark.parametrize("limit", [1e-8, 1e-7])
def test_strain_and_deflection_criteria_on_a_linear_span_are_the_closed_forms(results, limit):
    """--max-strain on the pinned linear span: the midspan bending strain of the closed-form
    amplitude reaches the limit there; --max-deflection: one mode's largest deflection is
    its midspan amplitude (the amplitude criterion's span)."""
    ds, _ = results["linear"]
    out = max_span(ds, max_strain=limit)
    assert float(out["max_span"]) == pytest.approx(_strain_reference(limit), rel=2e-3)
    assert str(out["limited_by"].values) == "max_strain"
    criteria = out.attrs["criteria"]      # a pure number shows no unit (not "... 1")
    assert f"max_strain <= {limit:g}" in criteria and f"{limit:g} 1" not in criteria
    deflection = max_span(ds, max_deflection=limit * 10)
    assert float(deflection["max_span"]) == pytest.approx(_amplitude_reference(limit * 10),
                                                          rel=2e-3)
    assert str(deflection["limited_by"].values) == "max_deflection"


def test_a_swept_result_uses_peak_amplitude_over_its_worst_direction(results):
    ds, _ = results["swept"]
    assert "peak_frequency" in ds and "direction" in ds["peak_amplitude"].dims
    worst = ds["peak_amplitude"].max("direction").values
    lengths = ds["length"].values
    assert np.all(np.diff(worst) > 0), worst          # the response grows with the span here
    # a limit the 3rd length's better direction passes and its worse one fails: the worse binds
    best = ds["peak_amplitude"].min("direction").values
    assert best[2] < worst[2] and worst[1] < best[2], (best, worst)
    limit = 0.5 * (best[2] + worst[2])
    expected = lengths[1] + (limit - worst[1]) / (worst[2] - worst[1]) * (lengths[2] - lengths[1])
    out = max_span(ds, max_amplitude=limit)
    assert float(out["max_span"]) == pytest.approx(expected, rel=1e-9)
    assert float(out["max_span"]) < lengths[2]         # the better direction alone: beyond
    assert str(out["limited_by"].values) == "max_amplitude"
    assert "peak_amplitude <= " in out.attrs["criteria"]
    assert "direction" not in out.dims


def test_other_axes_are_kept(results):
    ds, _ = results["coarse"]
    two = xr.concat([ds, ds], dim=xr.DataArray([0.01, 0.02], dims="damping_ratio",
                                               attrs={"units": "1", "long_name": "damping"}))
    two["natural_frequency"] = ds["natural_frequency"]         # over length only: broadcast
    out = max_span(two, min_frequency=100.0)
    assert out["max_span"].dims == ("damping_ratio",)
    assert out["damping_ratio"].attrs["units"] == "1"
    np.testing.assert_allclose(out["max_span"].values, l_max_frequency(100.0), rtol=1e-6)


def test_a_failed_state_ends_the_walk(results):
    ds, _ = results["coarse"]
    bad = ds.copy(deep=True)
    state = bad["state"].values
    meanings = bad["state"].attrs["flag_meanings"].split()
    values = list(np.atleast_1d(bad["state"].attrs["flag_values"]))
    state[2] = values[meanings.index("diverged")]
    out = max_span(bad, min_frequency=100.0)
    assert float(out["max_span"]) == pytest.approx(float(ds["length"][1]))
    assert str(out["limited_by"].values) == "state"


@pytest.mark.parametrize("where", [0, 2])
def test_a_failed_solve_is_named_not_the_limit_its_nan_fails(results, where):
    """A point whose solve failed (max_steps_reached, amplitude NaN) fails the amplitude limit
    only through its NaN: the design names `state` (a reviewer's run named max_amplitude, the
    user then changing the design rather than the solver), at the shortest span and inside."""
    ds, _ = results["coarse"]
    bad = ds.copy(deep=True)
    meanings = bad["state"].attrs["flag_meanings"].split()
    values = list(np.atleast_1d(bad["state"].attrs["flag_values"]))
    bad["state"].values[where] = values[meanings.index("max_steps_reached")]
    bad["amplitude"].values[where] = np.nan
    out = max_span(bad, max_amplitude=1.0)
    assert str(out["limited_by"].values) == "state"
    expected = np.nan if where == 0 else float(ds["length"][where - 1])
    np.testing.assert_equal(float(out["max_span"]), expected)


@pytest.mark.parametrize("kwargs, fragment", [
    ({}, "no criterion"),
    ({"max_amplitude": 1e-3, "quantity": "nonesuch"}, "nonesuch"),
    ({"max_amplitude": 1e-3, "quantity": "natural_frequency"}, "units"),
    ({"min_frequency": -5.0}, "positive"),
    ({"quantity": "amplitude"}, "--max-amplitude"),
])
def test_bad_criteria_are_one_line(results, kwargs, fragment):
    ds, _ = results["coarse"]
    with pytest.raises(sweep.UserError, match=fragment) as info:
        max_span(ds, **kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["escape_barrier", "max_deflection_position"])
def test_quantity_is_a_response_not_a_position_or_a_threshold(results, name):
    """--quantity names a response to limit: a barrier (escape_barrier) or the place of the
    largest deflection (max_deflection_position) is in m over the length axis too, and was
    taken for one."""
    ds, _ = results["coarse"]
    if name not in ds:                             # several modes hold it: one added here
        ds = ds.assign({name: ds["amplitude"].assign_attrs(units="m")})
    with pytest.raises(sweep.UserError) as info:
        max_span(ds, max_amplitude=1e-3, quantity=name)
    message = str(info.value)
    assert f"--quantity {name}: not a response" in message and "\n" not in message
    assert "amplitude" in message.split("a response:")[-1]


def test_every_variable_in_m_is_classed_a_response_or_not(results):
    """Each variable in m over the length axis that a result holds is either a response
    --quantity may limit (RESPONSES) or no response (NON_RESPONSES): an output added in m
    must be classed before design reads it."""
    from sweep.design import NON_RESPONSES, RESPONSES
    seen = set()
    for ds, _ in results.values():
        seen |= {str(n) for n, v in ds.data_vars.items()
                 if v.attrs.get("units") == "m" and "length" in v.dims}
    assert seen and seen <= set(RESPONSES) | set(NON_RESPONSES), seen
    assert not set(RESPONSES) & set(NON_RESPONSES)


def test_a_result_without_length_is_refused(results):
    ds, _ = results["no_length"]
    with pytest.raises(sweep.UserError, match="length") as info:
        max_span(ds, min_frequency=100.0)
    assert "\n" not in str(info.value)


def test_cli_design_writes_a_cf_clean_file(results, tmp_path, capsys):
    from test_cf import cf_problems
    _, path = results["coarse"]
    out = tmp_path / "out.nc"
    assert main(["design", str(path), "--min-frequency", "100", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "max_span_mm" in text and "min_frequency" in text
    assert f"{l_max_frequency(100.0) * 1e3:.2f}" in text
    assert cf_problems(out) == []
    back = xr.open_dataset(out)
    assert back["max_span"].attrs["units"] == "m"
    assert float(back["max_span"]) == pytest.approx(l_max_frequency(100.0), rel=1e-6)
    assert str(back["limited_by"].values) == "min_frequency"
    back.close()


def test_cli_design_takes_result_files_after_its_options(results, capsys):
    """`sweep design A.nc --min-frequency 100 B.nc` as `sweep design A.nc B.nc --min-frequency
    100` (a user's natural order once a file is added; argparse alone refused it with its
    top-level usage); an unknown option is still argparse's one-line error."""
    _, first = results["coarse"]
    _, second = results["linear"]
    assert main(["design", str(first), str(second), "--min-frequency", "100"]) == 0
    expected = capsys.readouterr().out
    assert main(["design", str(first), "--min-frequency", "100", str(second)]) == 0
    assert capsys.readouterr().out == expected
    with pytest.raises(SystemExit) as info:
        main(["design", str(first), "--min-frequency", "100", "--no-such-option"])
    assert info.value.code == 2
    assert "unrecognized arguments: --no-such-option" in capsys.readouterr().err


@pytest.mark.parametrize("limit, unit", [("--max-deflection", "mm"), ("--min-frequency", "Hz"),
                                         ("--max-strain", "microstrain")])
def test_cli_design_an_unquoted_unit_is_named_as_one(results, capsys, limit, unit):
    """`--max-deflection 2 mm` unquoted leaves 'mm' as a result file: one line that says
    so and how to quote it (an auditor got "result 'mm': no such file" alone)."""
    _, path = results["coarse"]
    assert main(["design", str(path), limit, "2", unit]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"'{unit}'" in err and "quote" in err


def test_design_units_micro_as_the_greek_letter_and_a_tolerance_with_a_unit():
    """A strain limit takes micro as U+03BC as well as the micro sign (a length limit took
    both, a strain only the sign); --tolerance takes a unit as the limits do."""
    from sweep.cli import _parser
    from sweep.design import limit_value
    for text in ("180 \u03bc\u03b5", "180 \u03bcstrain", "180 \u00b5\u03b5", "180 microstrain"):
        assert limit_value(text, "1") == pytest.approx(180e-6, rel=1e-15), text
    args = _parser().parse_args(["design", "r.nc", "--refine", "--tolerance", "1 mm"])
    assert args.tolerance == pytest.approx(1e-3, rel=1e-15)
    assert _parser().parse_args(["design", "r.nc", "--tolerance", "0.002"]).tolerance == 0.002


def test_cli_design_says_when_its_span_is_interpolated(results, capsys):
    """A response criterion's span is interpolated between grid lengths (a resonance between
    them can make it unsafe): the command says so and points at --refine; a frequency
    criterion's log-log interpolation is exact for f1 ~ l^-2 and gets no such line."""
    ds, path = results["coarse"]
    binding = float(np.nanmedian(ds["amplitude"].values))      # fails part-way along the grid
    assert main(["design", str(path), "--max-amplitude", f"{binding:.6g}"]) == 0
    assert "--refine" in capsys.readouterr().out
    assert main(["design", str(path), "--max-amplitude", "1e3"]) == 0   # the whole grid passes
    assert "--refine" not in capsys.readouterr().out
    assert main(["design", str(path), "--min-frequency", "100"]) == 0
    assert "--refine" not in capsys.readouterr().out


def test_cli_design_says_nothing_of_a_span_that_is_a_grid_length(tmp_path, capsys):
    """A span limited by a failed state is the last passing grid length, not interpolated:
    no 'interpolated' line (it was printed for any row limited by a response-side name)."""
    from test_design_random import synthetic
    path = tmp_path / "diverged.nc"
    ds = synthetic(diverged=(2, 0)).drop_vars("exceedance_probability")   # fails 0.2 m
    ds.assign_attrs(cable_sweep_version=package_version()).to_netcdf(path)
    assert main(["design", str(path), "--max-rms", "0.0024"]) == 0    # rms crosses at 0.24 m
    out = capsys.readouterr().out
    assert "150.00  state" in out and "interpolated" not in out
    assert main(["design", str(path), "--max-rms", "0.0012"]) == 0    # crosses at 0.12 m
    assert "1 span(s) interpolated between the grid's lengths" in capsys.readouterr().out


def test_cli_design_says_an_elastic_frequency_span_is_interpolated(tmp_path, capsys):
    """With elastic clamps f1 is not ~ l^-2 (K = k_t l / EI grows with the span), so the
    frequency span interpolated log-log between grid lengths is not exact: the command says so
    and points at --refine (pinned ends get no such line: test above)."""
    text = SCENE.format(table1=TABLE1_CABLE, name="elastic", membrane=0.0, cable="",
                        base=f"acceleration_g = {LEVEL_G}\nfrequency = {BASE_FREQUENCY}",
                        axes="length = [0.2, 0.3, 0.4]", solver="t_end = 0.05")
    scene = sweep.load_scene_text(text, overrides={"clamps.rotation": "elastic",
                                                   "clamps.rotational_stiffness": 1.0})
    path = tmp_path / "elastic.nc"
    ds = sweep.run(scene, output=path, progress=False)
    f = ds["natural_frequency"].values
    limit = float(np.sqrt(f[0] * f[1]))                  # between the first two lengths
    assert main(["design", str(path), "--min-frequency", f"{limit:.9g}"]) == 0
    out = capsys.readouterr().out
    assert "1 min_frequency span(s) interpolated as log f against log l" in out
    assert "but not for elastic ones" in out and "--refine gives the exact span" in out


def test_design_labels_are_short_complete_and_match_how_the_span_was_found(results):
    """long_name is a plot's label (<= 100 characters) and must read as complete: limited_by's
    criteria were cut to a list that looked whole (ending at max_rms), so they are all in its
    comment and none in its label; a refined span's comment says bisection, not interpolation
    between grid lengths (its long_name said one, its comment the other); several results'
    span has a label within 100 characters too (it had 146)."""
    from sweep.design import LIMITED_BY
    from sweep.governing import governing_span
    coarse, _ = results["coarse"]
    grid = max_span(coarse, min_frequency=100.0)
    label, comment = grid["limited_by"].attrs["long_name"], grid["limited_by"].attrs["comment"]
    assert len(label) <= 100 and not any(name in label for name in LIMITED_BY)
    assert all(name in comment for name in LIMITED_BY)
    assert "interpolated" in grid["max_span"].attrs["comment"]
    refined = refine_span(coarse, min_frequency=100.0)         # the frequency alone: no run
    assert "refined by bisection" in refined["max_span"].attrs["long_name"]
    assert "interpolated" not in refined["max_span"].attrs["comment"]
    assert "bisected" in refined["max_span"].attrs["comment"]
    linear, _ = results["linear"]
    both = governing_span([("linear.nc", linear), ("coarse.nc", _frequency_only(results))],
                          min_frequency=40.0)
    for var in ("max_span", "limited_by", "limited_in"):
        assert len(both[var].attrs["long_name"]) <= 100, var


def test_cli_design_limits_take_units(results, tmp_path, capsys):
    """A limit may carry its unit, as a scene key does: '--max-amplitude "2 mm"' is 0.002 m (it
    was refused as an invalid float, and a bare 2 meant 2 m), '--min-frequency "0.1 kHz"' is
    100 Hz; a unit of the wrong kind is one line, exit 2."""
    _, path = results["coarse"]
    spans = []
    for flags in (["--max-amplitude", "0.002", "--min-frequency", "100"],
                  ["--max-amplitude", "2 mm", "--min-frequency", "0.1 kHz"]):
        out = tmp_path / f"span{len(spans)}.nc"
        assert main(["design", str(path), *flags, "-o", str(out)]) == 0
        with xr.open_dataset(out) as got:
            spans.append(got["max_span"].values.copy())
    capsys.readouterr()
    np.testing.assert_array_equal(spans[0], spans[1])
    with pytest.raises(SystemExit) as info:
        main(["design", str(path), "--max-amplitude", "2 Hz"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-amplitude" in err and "a frequency" in err


@pytest.mark.parametrize("text, strain", [("3e-4", 3e-4), ("300 microstrain", 3e-4),
                                          ("0.03 %", 3e-4), ("0.03%", 3e-4), ("300 ppm", 3e-4)])
def test_a_strain_limit_takes_the_units_strain_is_given_in(text, strain):
    """--max-strain as a data sheet or a fatigue curve gives it: plain (m/m), in microstrain or
    ppm, or in per cent."""
    from sweep.cli import _strain
    assert _strain(text) == pytest.approx(strain, rel=1e-12)


@pytest.mark.parametrize("text", ["abc", "3 mm", "0.03 % x", "1.2.3"])
def test_a_strain_limit_in_another_unit_is_one_line(text, capsys):
    with pytest.raises(SystemExit) as info:
        main(["design", "x.nc", "--max-strain", text])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-strain" in err and "microstrain" in err


def test_cli_design_over_an_axis_prints_a_line_per_value(results, tmp_path, capsys):
    from test_cf import cf_problems
    ds, _ = results["coarse"]
    two = xr.concat([ds, ds], dim=xr.DataArray([0.01, 0.02], dims="damping_ratio",
                                               attrs={"units": "1", "long_name": "damping"}))
    src = tmp_path / "two.nc"
    two.to_netcdf(src)
    out = tmp_path / "out2.nc"
    assert main(["design", str(src), "--min-frequency", "100", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert sum("min_frequency" in line for line in lines[1:]) == 2
    assert cf_problems(out) == []


@pytest.mark.parametrize("which, flags, fragment", [
    ("coarse", [], "no criterion"),
    ("no_length", ["--min-frequency", "100"], "length"),
    ("coarse", ["--max-amplitude", "1e-3", "--quantity", "nonesuch"], "nonesuch"),
    ("coarse", ["--min-frequency", "abc"], "does not start with a number"),
    ("coarse", ["--min-frequency", "100 hz_x"], "unknown unit"),
    ("coarse", ["--max-strain", "1e-3"], "max_strain"),
    ("swept", ["--max-strain", "-1"], "positive"),
])
def test_cli_design_bad_input_is_one_line_exit_2(results, which, flags, fragment, capsys):
    _, path = results[which]
    try:
        code = main(["design", str(path), *flags])
    except SystemExit as exc:                     # argparse's own errors
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and len(err.splitlines()) == 1, err


def test_an_unstable_span_ends_the_walk_at_the_growth_rate_zero():
    # principal parametric resonance (W = 2 w1) under a fixed 0.5 N end load: the load ratio
    # P0/Pcr grows as l^2, so long spans are unstable, short ones stable
    scene = sweep.load_scene("harness-stability", overrides={
        "axes.length": {"start": 0.2, "stop": 0.8, "num": 13},
        "axes.frequency_ratio": [2.0], "axes.load_amplitude": [0.5]})
    ds = sweep.run(scene, progress=False)
    g = ds["growth_rate"].squeeze().values
    lengths = ds["length"].values
    b = int(np.argmax(g > 0))
    assert b > 0 and np.all(g[:b] <= 0) and np.all(g[b:] > 0), g
    out = max_span(ds, min_frequency=1.0)
    got = float(out["max_span"].squeeze())
    assert lengths[b - 1] < got < lengths[b]
    assert got == pytest.approx(lengths[b - 1] - g[b - 1] * (lengths[b] - lengths[b - 1])
                                / (g[b] - g[b - 1]), rel=1e-9)
    assert str(out["limited_by"].squeeze().values) == "stability"
    assert out["max_span"].dims == ("frequency_ratio", "load_amplitude")


def _stability_result(growth: list[float], flags: list[int]) -> xr.Dataset:
    """A hand-made stability result over length 0.1..0.4 m (as a hand-edited or foreign file
    may be): its `stability` flags and `growth_rate` (1/s) as given, f1 far above any limit."""
    lengths = np.array([0.1, 0.2, 0.3, 0.4])
    stability = xr.DataArray(np.array(flags, np.int8), dims=("length",), attrs={
        "flag_values": np.array([-1, 0, 1], np.int8),
        "flag_meanings": "invalid_input stable unstable_period_1"})
    return xr.Dataset(
        {"stability": stability,
         "growth_rate": ("length", np.array(growth, float), {"units": "1/s"}),
         "natural_frequency": ("length", 1e3 * (0.1 / lengths) ** 2, {"units": "Hz"})},
        coords={"length": ("length", lengths, {"units": "m"})})


@pytest.mark.parametrize("flag", [1, -1])               # unstable_period_1, invalid_input
def test_a_failing_flag_without_a_positive_growth_rate_gives_the_last_passing_length(flag):
    """The flag fails 0.3 m while growth_rate is still negative there: the growth rate does
    not cross zero between 0.2 and 0.3 m, so nothing is interpolated: the span is the last
    passing grid length, 0.2 m (a clamped interpolation returned the failing 0.3 m)."""
    ds = _stability_result([-2.0, -1.0, -0.5, 1.0], [0, 0, flag, flag])
    out = max_span(ds, min_frequency=1.0)
    assert float(out["max_span"]) == 0.2
    assert str(out["limited_by"].values) == "stability"
    # where the growth rate does cross zero in the bracket, its zero is the span
    crossing = max_span(_stability_result([-2.0, -1.0, 3.0, 4.0], [0, 0, flag, flag]),
                        min_frequency=1.0)
    assert float(crossing["max_span"]) == pytest.approx(0.2 + 0.1 * 1.0 / 4.0, rel=1e-12)


# --refine: bisection on length with the engine, against the same closed forms


def _coarse_linear(results) -> xr.Dataset:
    """The linear span's result on a 40 mm grid (every 8th length): its grid answer is off by
    up to ~2.5 %, so the refinement has something to do."""
    ds, _ = results["linear"]
    return ds.isel(length=slice(0, None, 8))


@pytest.mark.parametrize("limit", [2e-8, 1e-7, 5e-7])
def test_refine_amplitude_is_the_closed_form_with_log2_runs(results, limit):
    ds = _coarse_linear(results)
    exact = _amplitude_reference(limit)
    grid = float(max_span(ds, max_amplitude=limit)["max_span"])
    tol = 1e-4
    out = refine_span(ds, max_amplitude=limit, tolerance=tol)
    got = float(out["max_span"])
    assert abs(got / exact - 1) < 2e-3, (got, exact)
    assert exact - tol - 1e-6 < got <= exact + 1e-6, (got, exact)   # the passing end
    assert abs(got / exact - 1) < abs(grid / exact - 1)
    assert str(out["limited_by"].values) == "max_amplitude"
    bracket = 0.04                                   # one grid step
    expected = math.ceil(math.log2(bracket / tol))
    assert abs(int(out.attrs["refine_runs"]) - expected) <= 1, out.attrs["refine_runs"]
    assert out.attrs["refine_tolerance"] == tol


def test_refine_frequency_alone_costs_no_run(results):
    ds = _coarse_linear(results)
    out = refine_span(ds, min_frequency=100.0)
    assert abs(float(out["max_span"]) / l_max_frequency(100.0) - 1) < 1e-3
    assert int(out.attrs["refine_runs"]) == 0
    assert str(out["limited_by"].values) == "min_frequency"


def test_refine_both_criteria_the_smaller_binds(results):
    ds = _coarse_linear(results)
    out = refine_span(ds, min_frequency=100.0, max_amplitude=2e-8, tolerance=1e-4)
    assert float(out["max_span"]) == pytest.approx(_amplitude_reference(2e-8), rel=2e-3)
    assert str(out["limited_by"].values) == "max_amplitude"
    out = refine_span(ds, min_frequency=100.0, max_amplitude=5e-7, tolerance=1e-4)
    assert float(out["max_span"]) == pytest.approx(l_max_frequency(100.0), rel=1e-6)
    assert str(out["limited_by"].values) == "min_frequency"


def test_refine_names_a_failed_solve_not_the_limit_its_nan_fails(results, monkeypatch):
    """A solve that fails beyond some length (its state max_steps_reached, its amplitude NaN)
    binds the refined span, and `limited_by` says `state` at the bracket's end and at every
    bisection run, as the grid answer does (an auditor's --refine named max_deflection where
    a sweep's solve had failed). The failure is made here, past 0.2 m, by marking the stored
    result and the engine's one-length runs the way a failed solve leaves them."""
    import importlib
    ds = _coarse_linear(results).copy(deep=True)
    limit = 5e-7
    failed_from = 0.2
    assert failed_from < _amplitude_reference(limit)   # the failure binds before the limit
    meanings = ds["state"].attrs["flag_meanings"].split()
    flag = list(np.atleast_1d(ds["state"].attrs["flag_values"]))[
        meanings.index("max_steps_reached")]

    def failed_beyond(result: xr.Dataset) -> xr.Dataset:
        result = result.copy(deep=True)
        beyond = result["length"] >= failed_from
        result["state"] = result["state"].where(~beyond, flag)
        result["amplitude"] = result["amplitude"].where(~beyond)
        return result

    ds = failed_beyond(ds)
    assert str(max_span(ds, max_amplitude=limit)["limited_by"].values) == "state"
    engine = importlib.import_module("sweep.run")
    real_run = engine.run
    monkeypatch.setattr(engine, "run", lambda *a, **k: failed_beyond(real_run(*a, **k)))
    tol = 1e-3
    out = refine_span(ds, max_amplitude=limit, tolerance=tol)
    assert str(out["limited_by"].values) == "state"
    assert failed_from - tol <= float(out["max_span"]) < failed_from


def test_refine_bad_tolerance_is_one_line(results):
    ds = _coarse_linear(results)
    with pytest.raises(sweep.UserError, match="positive") as info:
        refine_span(ds, max_amplitude=1e-7, tolerance=0.0)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("tolerance", [1e-300, 1e-17, 1e-11])
def test_refine_refuses_a_tolerance_no_bisection_reaches(results, tolerance):
    """Below 1e-9 of the longest span the bracket would be halved to round-off for ever: one
    line, before any run."""
    ds = _coarse_linear(results)
    with pytest.raises(sweep.UserError, match="--tolerance") as info:
        refine_span(ds, max_amplitude=1e-7, tolerance=tolerance)
    assert "\n" not in str(info.value) and "reach" in str(info.value)


def test_refine_runs_only_what_the_result_holds(results):
    """A stored scene with an axis the data lack (a crafted 2e6-point one), a length not in
    metres, or a dask cluster of its own is not run as the file says: the first two are
    refused in one line, the third runs on this machine's threads."""
    ds = _coarse_linear(results)
    assert "\n[axes]\n" in ds.attrs["scene"] and 'backend = "threads"' in ds.attrs["scene"]
    extra = ds.copy()
    extra.attrs["scene"] = ds.attrs["scene"].replace(
        "\n[axes]\n", "\n[axes]\ndamping_ratio = {start = 0.01, stop = 0.05, num = 2000000}\n",
        1)
    with pytest.raises(sweep.UserError, match="damping_ratio") as info:
        refine_span(extra, max_amplitude=1e-7, tolerance=1e-3)
    assert "\n" not in str(info.value)
    mm = ds.copy()
    mm["length"] = mm["length"] * 1e3
    mm["length"].attrs = dict(ds["length"].attrs, units="mm")
    with pytest.raises(sweep.UserError, match="metres"):
        refine_span(mm, max_amplitude=1e-7, tolerance=1e-3)
    dask = ds.copy()
    dask.attrs["scene"] = ds.attrs["scene"].replace(
        'backend = "threads"\nworkers = 0', 'backend = "dask"\nworkers = 6', 1)
    assert 'workers = 6' in dask.attrs["scene"]
    out = refine_span(dask, max_amplitude=1e-7, tolerance=1e-2)
    assert int(out.attrs["refine_runs"]) >= 1           # ran, in-process (no cluster started)


def test_cli_design_refine_prints_and_writes(results, tmp_path, capsys):
    from test_cf import cf_problems
    src = tmp_path / "coarse-linear.nc"
    _coarse_linear(results).to_netcdf(src)
    out = tmp_path / "refined.nc"
    assert main(["design", str(src), "--max-amplitude", "1e-7", "--refine",
                 "--tolerance", "1e-4", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "max_amplitude" in text and "engine runs" in text
    assert cf_problems(out) == []
    back = xr.open_dataset(out)
    assert float(back["max_span"]) == pytest.approx(_amplitude_reference(1e-7), rel=2e-3)
    assert int(back.attrs["refine_runs"]) > 0
    back.close()
    assert main(["design", str(src), "--max-amplitude", "1e-7", "--tolerance", "1e-4"]) == 2
    assert "--refine" in capsys.readouterr().err


# the design chart: sweep plot of a design result


def test_cli_plot_of_a_design_result_writes_the_chart(results, tmp_path, capsys):
    _, path = results["coarse"]
    design = tmp_path / "design.nc"
    assert main(["design", str(path), "--min-frequency", "100", "-o", str(design)]) == 0
    figs = tmp_path / "figs"
    assert main(["plot", str(design), "-o", str(figs)]) == 0
    out = capsys.readouterr().out
    png = figs / "design-max_span.png"
    assert png.exists() and png.stat().st_size > 0, out
    assert str(png) in out


def test_plot_design_over_one_axis_names_the_criteria(results, tmp_path):
    from sweep.plot import load_result, plot, plot_design
    ds, _ = results["coarse"]
    two = xr.concat([ds, ds], dim=xr.DataArray([0.01, 0.02], dims="damping_ratio",
                                               attrs={"units": "1", "long_name": "damping"}))
    design = max_span(two, min_frequency=100.0)
    design["limited_by"].values[1] = "state"       # two criteria: two legend entries
    path = tmp_path / "two-design.nc"
    design.to_netcdf(path)
    back = load_result(path)
    fig = plot_design(back)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("min_frequency" in t for t in texts) and any("state" in t for t in texts)
    assert "mm" in ax.get_ylabel()
    assert list(plot(back)) == ["max_span"]
    one = plot(back, {"damping_ratio": 0.02})
    assert list(one) == ["max_span"]
    with pytest.raises(sweep.UserError, match="not one of"):
        plot(back, {"damping_ratio": 0.5})


def test_a_design_result_with_a_bad_criterion_is_refused(results, tmp_path):
    from sweep.plot import load_result
    ds, _ = results["coarse"]
    design = max_span(ds, min_frequency=100.0)
    design["limited_by"] = design["limited_by"].copy(data=np.array("nonesuch", dtype=object))
    path = tmp_path / "bad-design.nc"
    design.to_netcdf(path)
    with pytest.raises(sweep.UserError, match="nonesuch") as info:
        load_result(path)
    assert "\n" not in str(info.value)


def test_refine_a_swept_result_tightens_the_grid_bracket(results):
    ds, _ = results["swept"]
    worst = ds["peak_amplitude"].max("direction").values
    lengths = ds["length"].values
    limit = 0.5 * (worst[1] + worst[2])
    out = refine_span(ds, max_amplitude=limit, tolerance=1e-3)
    got = float(out["max_span"])
    assert lengths[1] <= got < lengths[2]
    assert str(out["limited_by"].values) == "max_amplitude"
    assert int(out.attrs["refine_runs"]) == math.ceil(math.log2((lengths[2] - lengths[1])
                                                                / 1e-3))
    # the engine at the refined span passes and a tolerance beyond it fails
    again = sweep.load_scene_text(ds.attrs["scene"], overrides={"axes.length": [got]})
    assert float(sweep.run(again, progress=False)["peak_amplitude"].max()) <= limit
    again = sweep.load_scene_text(ds.attrs["scene"], overrides={"axes.length": [got + 1e-3]})
    assert float(sweep.run(again, progress=False)["peak_amplitude"].max()) > limit


def test_refine_a_stepped_result_keeps_its_stepped_axis_whole():
    scene = sweep.load_scene("harness-stepped-sine", overrides={
        "axes.base_frequency_ratio": {"start": 0.9, "stop": 1.1, "num": 3},
        "model.modes": 1, "solver.t_end": 1.0})
    ds = sweep.run(scene, progress=False)
    assert ds.attrs["continuation_axis"] == "base_frequency_ratio"
    worst = ds["amplitude"].max("direction")
    limit = float(worst.isel(length=1).max()) * 1.05
    grid = max_span(ds, max_amplitude=limit)
    out = refine_span(ds, max_amplitude=limit, tolerance=2e-3)
    assert out["max_span"].dims == ("base_frequency_ratio",)
    refined = out["limited_by"].values == "max_amplitude"
    assert refined.any() and int(out.attrs["refine_runs"]) > 0
    lengths = ds["length"].values
    for g, r in zip(grid["max_span"].values[refined], out["max_span"].values[refined]):
        below = lengths[lengths <= g].max()
        assert below <= r < lengths[lengths > below].min()
    np.testing.assert_array_equal(out["max_span"].values[~refined],
                                  grid["max_span"].values[~refined])


def test_refine_the_stability_criterion():
    scene = sweep.load_scene("harness-stability", overrides={
        "axes.length": {"start": 0.2, "stop": 0.8, "num": 13},
        "axes.frequency_ratio": [2.0], "axes.load_amplitude": [0.5]})
    ds = sweep.run(scene, progress=False)
    lengths = ds["length"].values
    out = refine_span(ds, min_frequency=1.0, tolerance=1e-3)
    got = float(out["max_span"].squeeze())
    b = int(np.argmax(ds["growth_rate"].squeeze().values > 0))
    assert lengths[b - 1] <= got < lengths[b]
    assert str(out["limited_by"].squeeze().values) == "stability"
    assert 0 < int(out.attrs["refine_runs"]) <= 6
    # the growth rate's zero, which max_span interpolates linearly, within the bracket
    assert got == pytest.approx(float(max_span(ds, min_frequency=1.0)["max_span"].squeeze()),
                                abs=5e-3)


# --- several results at once (sweep.governing) ------------------------------------------------

def _frequency_only(results) -> xr.Dataset:
    """The coarse result without its responses: only the frequency criterion applies to it."""
    ds, _ = results["coarse"]
    return ds.drop_vars([v for v in ("amplitude", "peak_amplitude") if v in ds])


@pytest.mark.parametrize("limit, f_min, binds, where", [
    (1e-7, 40.0, "max_amplitude", "linear.nc"),      # 0.2447 m against 0.3089 m
    (5e-7, 60.0, "min_frequency", None),             # 0.3123 m against 0.2522 m
])
def test_several_results_the_shortest_span_binds_and_says_where(results, limit, f_min,
                                                                binds, where):
    """A launch's tests as separate results: each answers the criteria it holds (here the
    amplitude only the linear span's, the frequency both), and the closed forms' smaller span
    binds, named with the result it binds in."""
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    out = governing_span([("linear.nc", linear), ("coarse.nc", _frequency_only(results))],
                         max_amplitude=limit, min_frequency=f_min)
    expected = min(_amplitude_reference(limit), l_max_frequency(f_min))
    assert float(out["max_span"]) == pytest.approx(expected, rel=2e-3)
    assert str(out["limited_by"].values) == binds
    if where is not None:
        assert str(out["limited_in"].values) == where
    assert "linear.nc" in out.attrs["criteria"] and "coarse.nc" in out.attrs["criteria"]


def test_several_results_refuse_what_none_or_no_criterion_answers(results):
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    pair = [("linear.nc", linear), ("coarse.nc", _frequency_only(results))]
    with pytest.raises(sweep.UserError, match="nor does any other result"):
        governing_span(pair, max_rms=1e-3)
    with pytest.raises(sweep.UserError, match="result 'coarse.nc': none of the criteria"):
        governing_span(pair, max_amplitude=1e-7)
    nolength, _ = results["no_length"]
    with pytest.raises(sweep.UserError, match="result 'n.nc' has no 'length' axis"):
        governing_span([("linear.nc", linear), ("n.nc", nolength)], min_frequency=40.0)
    a = linear.expand_dims(damping_ratio=[0.01])
    b = _frequency_only(results).expand_dims(damping_ratio=[0.02])
    with pytest.raises(sweep.UserError, match="shared axes \\(damping_ratio\\)"):
        governing_span([("a.nc", a), ("b.nc", b)], min_frequency=40.0)


def test_cli_design_of_two_results_prints_where_it_binds(results, tmp_path, capsys):
    _, linear_path = results["linear"]
    other = tmp_path / "coarse.nc"
    _frequency_only(results).to_netcdf(other)
    assert main(["design", str(linear_path), str(other), "--max-amplitude", "1e-7",
                 "--min-frequency", "40"]) == 0
    out = capsys.readouterr().out
    assert "limited_by" in out and "linear.nc" in out and "max_amplitude" in out
    assert main(["design", str(linear_path), str(other), "--min-frequency", "40",
                 "--refine"]) == 2
    assert "--refine takes one result" in capsys.readouterr().err


def test_several_results_refuse_points_whose_sets_differ(results):
    """Two [points] results with as many sets but other values: combined by index they would
    put one cable's span under another's name (a reviewer's case): refused."""
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    a = linear.expand_dims(point=[0, 1]).assign_coords(area=("point", [6e-6, 4e-6]))
    b = linear.expand_dims(point=[0, 1]).assign_coords(area=("point", [3e-6, 8e-6]))
    with pytest.raises(sweep.UserError, match="shared axes \\(point\\)"):
        governing_span([("a.nc", a), ("b.nc", b)], min_frequency=40.0)
    same = governing_span([("a.nc", a), ("c.nc", a.copy())], min_frequency=40.0)
    assert same["max_span"].dims == ("point",)


def test_a_sine_limit_binds_the_sine_result_not_the_random_one(results):
    """--max-amplitude given with a sine and a random result limits the sine one (the random
    result's `amplitude`, each record's tail peak, is not the sine test's response); a random
    result is refused it alone too, and together where no other criterion applies to it, in
    the same words, pointing at its own criteria."""
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    randomlike = linear.expand_dims(realisation=[0, 1])
    randomlike["amplitude"] = randomlike["amplitude"] * 0.0 + 1.0       # fails every length
    out = governing_span([("sine.nc", linear), ("random.nc", randomlike)],
                         max_amplitude=1e-7, min_frequency=40.0)
    assert float(out["max_span"]) == pytest.approx(_amplitude_reference(1e-7), rel=2e-3)
    assert str(out["limited_in"].values) == "sine.nc"
    said = "--max-amplitude limits a sine or dwell response, and this is a random result"
    with pytest.raises(sweep.UserError, match=said) as alone:
        max_span(randomlike, max_amplitude=1e-7)
    with pytest.raises(sweep.UserError, match=said) as together:
        governing_span([("sine.nc", linear), ("random.nc", randomlike)], max_amplitude=1e-7)
    for info in (alone, together):
        assert "--max-peak M" in str(info.value) and "\n" not in str(info.value)
    assert "result 'random.nc'" in str(together.value)


def test_several_results_name_every_one_that_fails_at_the_shortest(results):
    """Where the shortest length fails in several results, limited_in names them all (the
    first given alone made the answer depend on the files' order); a result given twice is
    refused."""
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    other = _frequency_only(results)
    out = governing_span([("a.nc", linear), ("b.nc", other)], min_frequency=1e4)
    assert np.isnan(float(out["max_span"]))
    assert str(out["limited_in"].values) == "a.nc, b.nc"
    with pytest.raises(sweep.UserError, match="given twice"):
        governing_span([("a.nc", linear), ("a.nc", other)], min_frequency=40.0)


def test_several_results_of_different_spans_are_warned_in_one_line(results):
    """Results whose stored scenes describe different spans (the cable's mass, rigidities or
    damping, the clamps) are warned of: the shortest of their spans gives one span another's
    limit (a reviewer's bundle bound a second cable of a [points] result). The same cable
    written from its data sheet is the same span: no warning."""
    import warnings

    from sweep.errors import CableSweepWarning
    from sweep.governing import governing_span
    linear, _ = results["linear"]
    stored = sweep.load_scene_text(linear.attrs["scene"])

    def with_scene(**overrides):
        ds = linear.copy()
        ds.attrs["scene"] = sweep.load_scene_text(stored.to_toml(), overrides=overrides).to_toml()
        return ds
    damped = with_scene(**{"cable.damping_ratio": 0.05})
    with pytest.warns(CableSweepWarning, match=r"results 'a.nc' and 'b.nc' describe different "
                      r"spans \(damping ratio"):
        governing_span([("a.nc", linear), ("b.nc", damped)], min_frequency=40.0)
    clamped = with_scene(**{"clamps.rotation": "clamped"})
    with pytest.warns(CableSweepWarning, match=r"clamps rotation pinned against clamped"):
        governing_span([("a.nc", linear), ("b.nc", clamped)], min_frequency=40.0)
    v = stored.values
    lines = [line for line in stored.to_toml().splitlines()
             if not line.startswith(("youngs_modulus", "density", "area", "inertia"))]
    at = lines.index("[cable]") + 1
    lines[at:at] = [f"linear_mass = {v['cable.density'] * v['cable.area']!r}",
                    f"bending_rigidity = {v['cable.youngs_modulus'] * v['cable.inertia']!r}",
                    f"axial_rigidity = {v['cable.youngs_modulus'] * v['cable.area']!r}"]
    sheet = linear.copy()
    sheet.attrs["scene"] = "\n".join(lines) + "\n"
    assert sweep.load_scene_text(sheet.attrs["scene"]).get("cable.linear_mass") is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        governing_span([("a.nc", linear), ("b.nc", sheet)], min_frequency=40.0)


def test_a_mode_with_a_node_at_midspan_that_moved_is_warned_in_one_line():
    """A midspan criterion (--max-amplitude) passing a length where mode 2 (a node at
    midspan) moved by more than 1 % of the midspan's amplitude warns in one line naming it (a
    reviewer's 3-mode sweep: the stretching excited mode 2, the largest deflection along the
    span 10.6 % above the midspan's); none where the even modes stayed at rest, and none for
    --max-deflection, which reads the whole span."""
    import warnings

    from sweep.errors import CableSweepWarning
    lengths = np.array([0.1, 0.2, 0.3])
    amplitude = np.array([1e-3, 2e-3, 5e-3])
    modal = np.array([[1e-3, 0.0, 1e-5], [2e-3, 4.5e-4, 2e-5], [5e-3, 1.4e-3, 5e-5]])
    ds = xr.Dataset(
        {"amplitude": ("length", amplitude, {"units": "m"}),
         "max_deflection": ("length", amplitude * 1.1, {"units": "m"}),
         "modal_amplitude": (("length", "mode"), modal, {"units": "m"}),
         "state": ("length", np.full(3, 2, np.int8),
                   {"flag_values": np.array([0, 1, 2], np.int8),
                    "flag_meanings": "invalid_input decayed steady"})},
        coords={"length": ("length", lengths, {"units": "m"}), "mode": [1, 2, 3]})
    with pytest.warns(CableSweepWarning, match=r"at 1 passing grid span\(s\) a mode with a "
                      r"node at midspan moved \(e\.g\. length 0\.2 m: 22\.5%"):
        max_span(ds, max_amplitude=3e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        max_span(ds, max_deflection=3e-3)
        still = ds.copy(deep=True)
        still["modal_amplitude"][:, 1] = 0.0
        max_span(still, max_amplitude=3e-3)


# ---- a constant end load: the loaded span's frequency (sweep.models.stability) --------------

LOAD = 40.0          # N, compression


def _beam_column_frequency(load: float, length: float, clamped: bool) -> float:
    """The first natural frequency (Hz) of the straight Table-1 span under a constant axial
    compression `load` (N, negative: tension), from the beam-column equation
    EI w'''' + P w'' + rho A w_tt = 0: pinned ends sin(pi x / l), so f1 sqrt(1 - P / Pcr);
    clamped ends (w = w' = 0 at both) the lowest root of the 4 x 4 determinant of
    w = A cosh(a x) + B sinh(a x) + C cos(b x) + D sin(b x), found by a scan and brentq."""
    ei, mass = E * INERTIA, RHO * AREA
    if not clamped:
        return f1(length) * math.sqrt(1.0 - load * length ** 2 / (math.pi ** 2 * ei))

    def det(f: float) -> float:
        p, k = load / ei, mass * (2 * math.pi * f) ** 2 / ei
        root = math.sqrt(p * p + 4.0 * k)
        a, b = math.sqrt((root - p) / 2.0) * length, math.sqrt((root + p) / 2.0) * length
        rows = [[1.0, 0.0, 1.0, 0.0], [0.0, a, 0.0, b],
                [math.cosh(a), math.sinh(a), math.cos(b), math.sin(b)],
                [a * math.sinh(a), a * math.cosh(a), -b * math.sin(b), b * math.cos(b)]]
        return float(np.linalg.det(np.array(rows)))
    grid = np.linspace(0.05, 3.0, 600) * f1(length)
    values = [det(f) for f in grid]
    k = next(i for i in range(len(grid) - 1) if values[i] * values[i + 1] < 0.0)
    return brentq(det, grid[k], grid[k + 1], xtol=1e-12, rtol=1e-14)


def _loaded_scene(rotation: str, modes: int, load: float, axes: str, t_end: float = 0.05):
    text = SCENE.format(table1=TABLE1_CABLE, name="loaded", membrane=0.0, cable="",
                        base=f"acceleration_g = {LEVEL_G}\nfrequency = {BASE_FREQUENCY}",
                        axes=axes, solver=f"t_end = {t_end}")
    return sweep.load_scene_text(text, overrides={"load.type": "constant", "load.amplitude": load,
                                                  "clamps.rotation": rotation,
                                                  "model.modes": modes})


@pytest.mark.parametrize("rotation, modes, rel", [("pinned", 1, 1e-12), ("pinned", 3, 1e-12),
                                                  ("clamped", 1, 3e-3), ("clamped", 3, 3e-4)])
def test_the_loaded_frequency_is_the_beam_columns(rotation, modes, rel):
    """loaded_frequency, the lowest frequency of the run's own linearised modes with the
    constant end load's stiffness in, against the continuous beam-column's (written here)
    under compression and tension: pinned sines exactly (the load does not couple them);
    clamped ends within the Galerkin error of one mode (its buckling load 40.69 against
    4 pi^2 EI / l^2) and of three, which the load couples (modes 1 and 3), an error that
    grows with the load (at 0.45 m, P / Pcr = 0.65: 1.6 % and 0.14 %, 0.035 % in tension;
    7 x the tolerance there); NaN where the compression buckles the straight span."""
    from sweep.grid import coordinates, parameters
    from sweep.models.modal import oscillator
    from sweep.models.stability import loaded_frequency
    lengths = [0.2, 0.3, 0.45]
    for load in (LOAD, -LOAD):
        scene = _loaded_scene(rotation, modes, load, f"length = {lengths}")
        coeffs = oscillator(parameters(scene, coordinates(scene)))
        got = np.asarray(loaded_frequency(coeffs, modes), float).ravel()
        for length, value in zip(lengths, got):
            buckled = load * length ** 2 > (4.0 if rotation == "clamped" else 1.0) * (
                math.pi ** 2 * E * INERTIA)
            if buckled:
                assert np.isnan(value), (length, value)
                continue
            exact = _beam_column_frequency(load, length, rotation == "clamped")
            far = length > 0.4                        # |P| / Pcr = 0.65
            assert value == pytest.approx(exact, rel=7.0 * rel if far else rel), (load, length)
    assert np.isnan(got).sum() == 0                     # tension never buckles


def test_a_constant_end_load_is_judged_by_the_loaded_frequency(tmp_path, capsys):
    """A span under a constant compression: --min-frequency judges its loaded frequency (the
    unloaded one, which a constant load leaves unchanged, would pass a span 4 % too long on
    a reviewer's clamped case), the interpolated span is said to be interpolated, and
    --refine gives the root of the pinned span's f1(l) sqrt(1 - P / Pcr(l)) = limit, solved
    here, with no engine run."""
    scene = _loaded_scene("pinned", 1, LOAD, "length = [0.15, 0.2, 0.25]")
    path = tmp_path / "loaded.nc"
    ds = sweep.run(scene, output=path, progress=False)
    assert ds["loaded_frequency"].attrs["units"] == "Hz"
    limit = 80.0
    exact = brentq(lambda length: _beam_column_frequency(LOAD, length, False) - limit, 0.15,
                   0.25, xtol=1e-14)
    assert exact < l_max_frequency(limit) - 0.01          # the unloaded answer is longer
    out = max_span(ds, min_frequency=limit)
    assert "loaded_frequency >= 80 Hz" in out.attrs["criteria"]
    assert float(out["max_span"]) == pytest.approx(exact, rel=0.02)
    refined = refine_span(ds, min_frequency=limit, tolerance=1e-6)
    assert float(refined["max_span"]) == pytest.approx(exact, abs=2e-6)
    assert int(refined.attrs["refine_runs"]) == 0
    assert main(["design", str(path), "--min-frequency", "80"]) == 0
    assert "nor under a constant end load" in capsys.readouterr().out
