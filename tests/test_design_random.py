"""The clamp-spacing question on a random-vibration result (sweep/design.py, docs/model.md
sec. 9 and 11): the `realisation` dimension counts at its worst, never as a design axis, and
the criteria --max-rms, --max-peak and --clearance. Synthetic Datasets built here (dims length
x realisation x clearance) with closed-form crossings; one reduced real run of
launch-random-gevs for the CLI end to end."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.cli import main
from sweep.design import CRITERIA, LIMITED_BY, max_span, refine_span
from sweep.version import package_version

LENGTHS = np.array([0.10, 0.15, 0.20, 0.25, 0.30])        # m
LEVELS = np.array([0.001, 0.002, 0.005])                   # m, clearance levels
FLAGS = dict(flag_values=np.array([0, 8, 5, 6, 7], np.int8),
             flag_meanings="invalid_input completed diverged step_size_too_small "
                           "max_steps_reached")
COMPLETED, DIVERGED = 8, 5


def rms_of(length: np.ndarray) -> np.ndarray:
    """The synthetic mean RMS midspan deflection (m), linear in length: 0.01 * length."""
    return 0.01 * np.asarray(length, float)


def synthetic(*, realisations: int = 3, scales: tuple[float, ...] | None = None,
              diverged: tuple[int, int] | None = None) -> xr.Dataset:
    """A random result over length (x base_asd_scale) x realisation (x clearance): state
    completed (or diverged at (length index, realisation)), rms_deflection_mean = rms_of(l)
    (x 2 per dB of scale), peak_deflection_mean = 4 rms, exceedance_probability growing
    linearly in length and the same in every realisation but the last (which adds 0.02)."""
    axes = {"length": LENGTHS}
    if scales is not None:
        axes["base_asd_scale"] = np.array(scales, float)
    dims = tuple(axes)
    shape = tuple(len(v) for v in axes.values())
    gain = np.ones(shape)
    if scales is not None:
        gain = gain * (2.0 ** np.asarray(scales))[None, :]
    rms = rms_of(LENGTHS).reshape((-1,) + (1,) * (len(shape) - 1)) * gain
    state = np.full(shape + (realisations,), COMPLETED, np.int8)
    per_real = np.repeat(rms[..., None], realisations, axis=-1)
    per_real = per_real * (1.0 + 0.1 * np.arange(realisations))     # the last the largest
    if diverged is not None:
        state[(diverged[0],) + (0,) * (len(shape) - 1) + (diverged[1],)] = DIVERGED
        per_real[(diverged[0],) + (0,) * (len(shape) - 1) + (diverged[1],)] = np.nan
    # P(l, c) = (l - 0.1) / 0.2 * 0.02 / (c / 0.001): 0 at 0.1 m, 0.02 at 0.3 m for 1 mm
    prob = ((LENGTHS - 0.10) / 0.20 * 0.02)[:, None] / (LEVELS / 0.001)[None, :]
    prob = prob.reshape((len(LENGTHS),) + (1,) * (len(shape) - 1) + (1, len(LEVELS)))
    prob = np.broadcast_to(prob, shape + (realisations, len(LEVELS))).copy()
    prob[..., -1, :] += 0.02 * np.broadcast_to(
        (LENGTHS - 0.10)[:, None] / 0.20, (len(LENGTHS), len(LEVELS))).reshape(
        (len(LENGTHS),) + (1,) * (len(shape) - 1) + (len(LEVELS),))
    rdims = dims + ("realisation",)
    return xr.Dataset(
        {"state": xr.DataArray(state, dims=rdims, attrs=dict(FLAGS, units="1")),
         "rms_deflection": xr.DataArray(per_real, dims=rdims, attrs={"units": "m"}),
         "amplitude": xr.DataArray(4.0 * per_real, dims=rdims, attrs={"units": "m"}),
         "rms_deflection_mean": xr.DataArray(rms, dims=dims, attrs={"units": "m"}),
         "peak_deflection_mean": xr.DataArray(4.0 * rms, dims=dims, attrs={"units": "m"}),
         "exceedance_probability": xr.DataArray(prob, dims=rdims + ("clearance",),
                                                attrs={"units": "1"}),
         "natural_frequency": xr.DataArray(52.6 * (0.15 / LENGTHS) ** 2, dims=("length",),
                                           attrs={"units": "Hz"})},
        coords={**{k: (k, v, {"units": "m"} if k == "length" else {"units": "dB"})
                   for k, v in axes.items()},
                "realisation": np.arange(realisations, dtype=np.int32),
                "clearance": ("clearance", LEVELS, {"units": "m"})},
        attrs={"title": "synthetic-random"})


def test_the_new_criteria_are_named():
    assert {"max_rms", "max_peak", "clearance"} <= set(CRITERIA)
    from sweep.plot.result import _DESIGN_LIMITS
    assert set(_DESIGN_LIMITS) == set(LIMITED_BY)        # sweep plot reads every one


@pytest.mark.parametrize("limit", [0.0012, 0.0017, 0.0024])
def test_max_rms_is_the_linear_crossing(limit):
    out = max_span(synthetic(), max_rms=limit)
    # rms = 0.01 l crosses the limit at l = 100 limit, inside the grid
    assert float(out["max_span"]) == pytest.approx(100.0 * limit, rel=1e-12)
    assert str(out["limited_by"].values) == "max_rms"


def _length_in(ds: xr.Dataset, units: str | None, per_metre: float) -> xr.Dataset:
    """`ds` with its length coordinate written in `units` (`per_metre` of them to a metre;
    None: no units attribute), as a hand-edited or foreign file may hold it."""
    attrs = {} if units is None else {"units": units}
    return ds.assign_coords(length=("length", ds["length"].values * per_metre, attrs))


@pytest.mark.parametrize("units, per_metre", [("mm", 1e3), ("cm", 1e2), ("km", 1e-3), ("metre", 1.0),
                                              ("millimeters", 1e3)])
def test_a_length_in_another_length_unit_is_read_in_metres(units, per_metre, capsys, tmp_path):
    """rms = 0.01 l (l in m) crosses 0.0017 m at 0.17 m whatever unit the file's length is
    written in (a length in mm was read as metres: a 170 m span, labelled m)."""
    ds = _length_in(synthetic(), units, per_metre)
    out = max_span(ds, max_rms=0.0017)
    assert float(out["max_span"]) == pytest.approx(0.17, rel=1e-12)
    assert out["max_span"].attrs["units"] == "m"
    assert out.attrs["length_grid"] == "5 lengths, 0.1 to 0.3 m"
    path = tmp_path / "r.nc"
    ds.drop_vars("exceedance_probability").assign_attrs(
        cable_sweep_version=package_version()).to_netcdf(path)
    assert main(["design", str(path), "--max-rms", "0.0017"]) == 0
    assert "170.00" in capsys.readouterr().out


@pytest.mark.parametrize("units, said", [("inch", "units 'inch'"), ("1", "units '1'"),
                                         (None, "no units")])
def test_a_length_in_no_length_unit_is_refused_in_one_line(units, said):
    with pytest.raises(sweep.UserError) as info:
        max_span(_length_in(synthetic(), units, 1.0), max_rms=0.0017)
    message = str(info.value)
    assert f"'length' axis has {said}" in message and "m, mm, cm, km" in message
    assert "\n" not in message


def test_limits_from_python_take_units_as_the_command_does():
    """max_span(ds, min_frequency="0.03 kHz") is 30 Hz, as 'sweep design --min-frequency
    "0.03 kHz"' (it was refused with the command's words); f1 = 52.6 (0.15 / l)^2 Hz crosses
    30 Hz at l = 0.15 sqrt(52.6 / 30), rms = 0.01 l crosses 1.7 mm at 0.17 m."""
    ds = synthetic()
    frequency = max_span(ds, min_frequency="0.03 kHz")
    assert float(frequency["max_span"]) == pytest.approx(0.15 * np.sqrt(52.6 / 30.0), rel=1e-12)
    assert float(max_span(ds, max_rms="1.7 mm")["max_span"]) == pytest.approx(0.17, rel=1e-12)
    assert str(max_span(ds, max_peak=" 8 mm ")["limited_by"].values) == "max_peak"


def test_max_peak_reads_the_mean_peak():
    out = max_span(synthetic(), max_peak=0.008)          # 4 * 0.01 l = 0.008 at l = 0.2
    assert float(out["max_span"]) == pytest.approx(0.2, rel=1e-12)
    assert str(out["limited_by"].values) == "max_peak"


def test_realisation_is_no_design_axis_and_counts_at_its_worst():
    ds = synthetic(realisations=3, scales=(-3.0, 0.0))
    out = max_span(ds, max_rms=0.0015)
    assert out["max_span"].dims == ("base_asd_scale",)
    assert "realisation" not in out.dims
    # rms = 0.01 l 2^(dB): crossing at l = 0.15 * 2^3 (beyond the grid) and 0.15
    assert str(out["limited_by"].values[0]) == "grid"
    assert float(out["max_span"].values[0]) == pytest.approx(0.30)
    assert float(out["max_span"].values[1]) == pytest.approx(0.15, rel=1e-12)
    # (a per-realisation quantity, amplitude, is a sine limit's and refused for a random
    # result: test_a_sine_response_limit_of_a_random_result_is_refused_in_one_line)


def test_a_diverged_realisation_fails_its_length():
    # realisation 1 escapes at 0.25 m: the rms criterion alone would pass up to 0.30 m
    out = max_span(synthetic(diverged=(3, 1)), max_rms=1.0)
    assert float(out["max_span"]) == pytest.approx(0.20)
    assert str(out["limited_by"].values) == "state"
    shortest = max_span(synthetic(diverged=(0, 0)), max_rms=1.0)
    assert np.isnan(float(shortest["max_span"]))
    assert str(shortest["limited_by"].values) == "state"


@pytest.mark.parametrize("level, p, expected", [
    # mean over 3 realisations of P = k (l - 0.1) / 0.2 with k = 0.02 / (c / 1 mm) + 0.02 / 3
    (0.001, 0.01, 0.10 + 0.2 * 0.01 / (0.02 + 0.02 / 3)),
    (0.002, 0.01, 0.10 + 0.2 * 0.01 / (0.01 + 0.02 / 3)),
    (0.001, 0.02, 0.10 + 0.2 * 0.02 / (0.02 + 0.02 / 3)),
])
def test_clearance_is_the_mean_exceedance_probability_crossing(level, p, expected):
    out = max_span(synthetic(), clearance=level, max_probability=p)
    assert float(out["max_span"]) == pytest.approx(expected, rel=1e-12)
    assert str(out["limited_by"].values) == "clearance"
    assert f"clearance {level:g} m" in out.attrs["criteria"]


def test_clearance_default_probability_is_one_percent():
    a = max_span(synthetic(), clearance=0.001)
    b = max_span(synthetic(), clearance=0.001, max_probability=0.01)
    assert float(a["max_span"]) == float(b["max_span"])


def test_the_smallest_span_binds_among_the_random_criteria():
    out = max_span(synthetic(), max_rms=0.0025, max_peak=0.008, clearance=0.001)
    spans = {"max_rms": 0.25, "max_peak": 0.20, "clearance": 0.10 + 0.2 * 0.01 / (0.02 + 0.02 / 3)}
    assert float(out["max_span"]) == pytest.approx(min(spans.values()), rel=1e-12)
    assert str(out["limited_by"].values) == "clearance"


def _sine_result() -> xr.Dataset:
    ds = synthetic()
    keep = ["state", "amplitude", "natural_frequency"]
    return ds[keep].isel(realisation=0, drop=True)


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(max_rms=0.001), "'rms_deflection_mean'"),
    (dict(max_peak=0.004), "'peak_deflection_mean'"),
    (dict(clearance=0.002), "'exceedance_probability'"),
])
def test_a_non_random_result_is_refused_in_one_line(kwargs, fragment):
    with pytest.raises(sweep.UserError, match=fragment) as info:
        max_span(_sine_result(), **kwargs)
    assert "asd_g2" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("flag, kwargs", [
    ("--max-amplitude", dict(max_amplitude=0.002)),
    ("--max-deflection", dict(max_deflection=0.002)),
    ("--max-strain", dict(max_strain=1e-3)),
    ("--max-amplitude", dict(max_amplitude=0.002, max_rms=0.002)),
])
def test_a_sine_response_limit_of_a_random_result_is_refused_in_one_line(flag, kwargs):
    """A random result holds `amplitude` (each record's tail peak), but the README gives it
    --max-rms, --max-peak and --clearance only: a sine response's limit is refused, pointing at
    those (it read the records' largest peak alone, and was refused beside a sine result)."""
    with pytest.raises(sweep.UserError) as info:
        max_span(synthetic(), **kwargs)
    message = str(info.value)
    assert message.startswith(f"design: {flag} limits a sine or dwell response")
    assert "--max-peak M" in message and "--max-rms M" in message and "\n" not in message


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(clearance=0.003), "not one of the result's clearance levels (0.001, 0.002, 0.005 m)"),
    (dict(max_rms=0.001, max_probability=0.05), "give --clearance M too"),
    (dict(clearance=0.001, max_probability=1.0), "below 1"),
    (dict(max_rms=-1.0), "--max-rms -1"),
    (dict(max_peak="x"), "max_peak='x' (--max-peak): 'x' does not start with a number"),
    (dict(min_frequency="3 mm"), "min_frequency='3 mm' (--min-frequency): '3 mm' is a length"),
])
def test_bad_random_criteria_are_one_line(kwargs, fragment):
    with pytest.raises(sweep.UserError) as info:
        max_span(synthetic(), **kwargs)
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_refine_refuses_a_random_result_in_one_line():
    with pytest.raises(sweep.UserError, match="refine the length axis in the scene") as info:
        refine_span(synthetic(), max_rms=0.0015)
    assert "\n" not in str(info.value)


@pytest.fixture(scope="module")
def random_file(tmp_path_factory):
    """A reduced launch-random-gevs (3 lengths, 2 records of 2 s, 0 dB, one clearance level),
    written as 'sweep run -o' writes it."""
    scene = sweep.load_scene("launch-random-gevs", {
        "axes.length": [0.1, 0.14, 0.18], "base.realisations": 2, "base.duration": 2.0,
        "axes.base_asd_scale": [0.0], "outputs.clearance": [0.001]})
    path = tmp_path_factory.mktemp("random") / "gevs.nc"
    ds = sweep.run(scene, output=path, progress=False)
    return ds, path


def test_cli_design_of_a_random_result_end_to_end(random_file, tmp_path, capsys):
    ds, path = random_file
    rms = ds["rms_deflection_mean"].isel(base_asd_scale=0).values
    assert np.all(np.diff(rms) > 0)                      # grows with length
    limit = float(0.5 * (rms[1] + rms[2]))               # crossing between 0.14 and 0.18 m
    out = tmp_path / "span.nc"
    assert main(["design", str(path), "--max-rms", f"{limit!r}", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "max_rms" in printed
    assert "interpolated" in printed and "--refine" not in printed   # refused for random
    got = xr.open_dataset(out)
    assert got["max_span"].dims == ("base_asd_scale",)
    expected = 0.14 + 0.04 * (limit - rms[1]) / (rms[2] - rms[1])
    assert float(got["max_span"].values[0]) == pytest.approx(expected, rel=1e-9)
    got.close()
    # a clearance level the result lacks: exit 2, one line on stderr naming its levels
    assert main(["design", str(path), "--clearance", "0.002"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "(0.001 m)" in err and "outputs.clearance" in err
    assert main(["design", str(path), "--max-rms", "0.001", "--refine"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--refine" in err
    with pytest.raises(SystemExit) as info:               # argparse: not a number
        main(["design", str(path), "--max-peak", "big"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-peak" in err


def test_a_clearance_pass_the_records_cannot_vouch_for_is_warned_in_one_line():
    """A span that passes --clearance on an estimate whose upper confidence bound
    (exceedance_probability_upper: few or no crossings counted) is above the limit is named
    in one warning; none where every passing span's bound is below it."""
    from sweep.errors import CableSweepWarning
    ds = synthetic()
    estimate = ds["exceedance_probability"].mean("realisation")
    weak = ds.assign(exceedance_probability_upper=(estimate + 0.5).clip(max=1.0))
    with pytest.warns(CableSweepWarning,
                      match=r"--clearance 0.001: 1 span\(s\) rest on a grid length"):
        out = max_span(weak, clearance=0.001)
    assert float(out["max_span"]) == float(max_span(ds, clearance=0.001)["max_span"])
    sure = ds.assign(exceedance_probability_upper=estimate * 1.0001)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        max_span(sure, clearance=0.001)


def test_a_passing_span_whose_response_is_unsettled_is_warned_in_one_line():
    """A response criterion that passes a grid length whose state is unsettled (its response
    still changing at t_end: a parametric growth) warns in one line naming it; the span is
    unchanged, and a result with every passing length settled says nothing."""
    from sweep.errors import CableSweepWarning
    ds = synthetic()
    state = ds["state"].copy()
    state[1, 0] = 4
    flags = dict(flag_values=np.array([0, 8, 5, 6, 7, 4], np.int8),
                 flag_meanings="invalid_input completed diverged step_size_too_small "
                               "max_steps_reached unsettled", units="1")
    unsettled = ds.assign(state=state.assign_attrs(flags))
    with pytest.warns(CableSweepWarning, match=r"1 passing grid span\(s\) are unsettled "
                      r"\(e\.g\. length 0\.15 m\)"):
        out = max_span(unsettled, max_rms=0.0025)
    assert float(out["max_span"]) == float(max_span(ds, max_rms=0.0025)["max_span"])
    with warnings.catch_warnings():
        warnings.simplefilter("error", CableSweepWarning)
        max_span(ds.assign(state=ds["state"].assign_attrs(flags)), max_rms=0.0025)
        max_span(unsettled, min_frequency=10.0)    # the frequency reads no response


def test_design_refuses_to_write_over_its_input_in_one_line(random_file, tmp_path, capsys):
    """-o naming the input result (even by another path), with --overwrite: refused in one
    line before any work, the result left as it was."""
    import os
    import shutil
    _, path = random_file
    mine = tmp_path / "mine.nc"
    shutil.copy(path, mine)
    before = mine.read_bytes()
    link = tmp_path / "again.nc"
    os.symlink(mine, link)
    for output in (mine, link):
        assert main(["design", str(mine), "--max-rms", "0.001", "-o", str(output),
                     "--overwrite"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "is the input result" in err[0]
    assert mine.read_bytes() == before


def test_a_quiet_run_without_an_output_is_refused_before_any_work(capsys):
    """`sweep run SCENE -q` without -o would compute a result and neither write nor show it:
    one line, exit 2."""
    assert main(["run", "paper-fig5", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--quiet without -o" in err[0]


SINE_BESIDE = """
name = "sine-beside-gevs"
[model]
kind = "transverse"
coefficients = "consistent"
modes = 1
[base]
acceleration_g = 1.0
sweep = { start = 20.0, stop = 40.0, rate = 8.0, direction = "both" }
[initial]
displacement = 0.0
velocity = 0.0
"""


def test_the_readme_merge_of_a_sine_and_a_random_result_keeps_both(random_file, tmp_path,
                                                                     monkeypatch):
    """A sine sweep and a random result of the same cable and spans name their run outputs
    alike over other dimensions: a plain xr.merge stops on one of them. The README's lines (run
    as printed, on qual.nc and gevs.nc) give one Dataset with the span's natural_frequency
    once and each run's state and peak_amplitude as that run wrote them."""
    import re
    from pathlib import Path

    gevs, gevs_path = random_file
    cable = sweep.load_scene_text(gevs.attrs["scene"])
    keys = ("linear_mass", "bending_rigidity", "axial_rigidity", "damping_ratio")
    scene = sweep.load_scene_text(SINE_BESIDE, overrides={
        **{f"cable.{k}": cable.get(f"cable.{k}") for k in keys},
        "axes.length": [float(v) for v in gevs["length"].values]})
    monkeypatch.chdir(tmp_path)
    sine = sweep.run(scene, output="qual.nc", progress=False)
    Path("gevs.nc").symlink_to(gevs_path)
    with xr.open_dataset("qual.nc") as a, xr.open_dataset("gevs.nc") as b:
        with pytest.raises(xr.MergeError, match="conflicting values for variable"):
            xr.merge([a, b], compat="no_conflicts", join="outer")
    readme = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    start = readme.index("**A sine and a random result in one Dataset.**")
    block = re.search(r"```python\n(.*?)```", readme[start:], re.S).group(1)
    names: dict = {}
    exec(block, names)
    both = names["both"]
    assert "random_natural_frequency" not in both
    np.testing.assert_array_equal(both["natural_frequency"], sine["natural_frequency"])
    np.testing.assert_array_equal(both["natural_frequency"], gevs["natural_frequency"])
    for name in ("state", "peak_amplitude"):
        assert both[name].dims == sine[name].dims == ("direction", "length")
        np.testing.assert_array_equal(both[name], sine[name])
        assert both[f"random_{name}"].dims == gevs[name].dims
        np.testing.assert_array_equal(both[f"random_{name}"], gevs[name])
        assert both[f"random_{name}"].attrs["long_name"] == gevs[name].attrs["long_name"]
    assert both["rms_deflection_mean"].attrs["units"] == "m"
    assert "scene" not in both.attrs and both.attrs["Conventions"] == sine.attrs["Conventions"]
    for ds in (names["sine"], names["gevs"]):
        ds.close()
