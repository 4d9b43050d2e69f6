"""Files other tools accept: the IOOS compliance checker finds no CF errors or warnings in the
output of any built-in scene, and the file says truthfully what made it."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.dataset import CONVENTIONS, counter
from sweep.kernels import metrics as km

# Smaller grids and shorter runs than the scenes' own, with the same outputs and variables.
REDUCED = {
    "paper-fig5": {"solver.t_end": 0.5},
    "harness-parametric": {"axes.length": [0.5, 1.0], "axes.frequency_ratio": [1.0, 2.0],
                           "solver.t_end": 1.0},
    "paper-fig7": {"solver.intervals": 50},
    "harness-base-sine": {"axes.length": [0.3, 0.8], "axes.base_frequency": [10.0, 50.0],
                          "solver.t_end": 1.0},
    "harness-stepped-sine": {"axes.length": [0.5], "axes.base_frequency_ratio": [1.0, 1.2, 1.4],
                             "solver.t_end": 1.0},
    "launch-sine-qualification": {"axes.length": [0.2, 0.4], "base.sweep.rate": 64.0},
    "harness-clamps": {"axes.length": [0.2, 0.4], "axes.clamp_rotational_stiffness": [0.1, 10.0],
                       "solver.t_end": 0.3},
    "launch-random-gevs": {"axes.length": [0.1, 0.15], "base.realisations": 2,
                           "base.duration": 2.0, "outputs.response_asd": True},
}
# The checker's priorities: high are its "errors", medium its "warnings", low its
# "suggestions". A file fails on either of the first two.
FAILING = ("high_priorities", "medium_priorities")


def checker() -> str:
    """The compliance-checker command of this environment (installed by the test extras)."""
    beside = Path(sys.executable).with_name("compliance-checker")
    found = str(beside) if beside.exists() else shutil.which("compliance-checker")
    assert found, "compliance-checker is missing: pip install '.[test]'"
    return found


def cf_problems(path: Path) -> list[str]:
    """Every failed error- or warning-level check of the CF version the file declares."""
    test = "cf:" + CONVENTIONS.removeprefix("CF-")
    done = subprocess.run([checker(), f"--test={test}", "-f", "json", "-o", "-", str(path)],
                          capture_output=True, text=True, timeout=300)
    report = json.loads(done.stdout)[test]
    problems = [f"{priority} {check['name']}: {msg}"
                for priority in FAILING for check in report[priority] for msg in check["msgs"]]
    assert problems or report["high_count"] == report["medium_count"] == 0, report
    # A check that crashed (e.g. on a string coordinate variable) is reported on stderr and
    # in the exit status, not in the lists: the checker must have run every check.
    crashed = [line for line in (done.stderr + done.stdout).splitlines()
               if "exceptions occurred" in line or line.startswith(test + ".check_")]
    assert not crashed, crashed
    if not problems:
        assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    return problems


def scene_output(name: str, tmp_path: Path, **more) -> tuple[xr.Dataset, Path]:
    scene = sweep.load_scene(name, overrides={**REDUCED.get(name, {}), **more})
    out = tmp_path / f"{name}.nc"
    return sweep.run(scene, output=out, progress=False), out


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(sweep.builtin_scenes()))
def test_builtin_scene_output_passes_the_cf_checker_and_round_trips(name, tmp_path):
    ds, out = scene_output(name, tmp_path)
    assert cf_problems(out) == []
    back = xr.open_dataset(out)
    bounds = {ds[v].attrs.get("bounds") for v in ds.variables} - {None}
    try:
        for var in ds.variables:
            np.testing.assert_array_equal(back[var].values, ds[var].values)
            if var in bounds:                  # CF 7.1: a bounds variable takes its parent's
                assert "units" not in back[var].attrs, var
                continue
            if ds[var].dtype.kind in "OUS":          # a label (a stepped sweep's direction)
                assert "units" not in ds[var].attrs and ds[var].attrs["long_name"], var
                continue
            assert back[var].attrs["units"] == ds[var].attrs["units"], var
            assert len(back[var].attrs.get("long_name", "")) <= 100, var   # a plot's label
            assert not back[var].attrs.get("long_name", "").endswith("..."), var  # a whole one
        for coord in back.coords:
            assert "_FillValue" not in back[coord].encoding or \
                back[coord].encoding["_FillValue"] is None, coord
    finally:
        back.close()


@pytest.mark.parametrize("text, label", [
    ("transverse reaction at the clamp: max |V| at either clamp over the tail window, V = -EI "
     "w_xxx + (N - P) w_x (the shear, the stretching tension's transverse part and the end "
     "load's, P compression positive)",
     "transverse reaction at the clamp: max |V| at either clamp over the tail window"),
    ("bending strain of the outer fibre at the clamp: (d / 2) max |w_xx| at either clamp over "
     "the tail window (d the cable's diameter)", "bending strain of the outer fibre at the clamp"),
    ("largest outer-fibre strain reported: max(clamp_bending_strain, midspan_bending_strain) + "
     "axial_strain (their peaks added)", "largest outer-fibre strain reported"),
    ("up-crossings of the clearance level by the midspan deflection counted over the statistics "
     "windows of the realisations that did not escape",
     "up-crossings of the clearance level by the midspan deflection counted over the "
     "statistics..."),
    ("short enough", "short enough"),
])
def test_long_names_are_labels_and_the_explanation_a_comment(text, label):
    """xarray's plots label an axis with long_name: one over 100 characters is cut to its
    longest closed clause (or its words and '...'), the whole text kept in `comment`, before a
    comment it had."""
    from sweep.dataset import short_long_names
    ds = xr.Dataset({"v": ("x", [1.0], {"long_name": text, "comment": "old"})})
    short_long_names(ds)
    assert ds["v"].attrs["long_name"] == label
    assert ds["v"].attrs["comment"] == ("old" if text == label else f"{text}. old")


def test_the_checker_sees_what_was_wrong_before(tmp_path):
    """The test above can fail: a coordinate with a _FillValue, a `time` coordinate without a
    reference date and an int64 counter are what the files had before."""
    ds, _ = scene_output("paper-fig5", tmp_path)
    bad = ds.rename({"elapsed_time": "time"})
    bad["time"].attrs["standard_name"] = "time"
    path = tmp_path / "bad.nc"
    bad.to_netcdf(path, engine="netcdf4")           # xarray's default: _FillValue on coords
    problems = " ".join(cf_problems(path))
    assert "_FillValue" in problems and "since" in problems


@pytest.mark.slow
@pytest.mark.parametrize("method, other", [("dop853", "RK45"), ("rk45", "DOP853")])
def test_provenance_names_the_integrator_that_ran(method, other, tmp_path):
    ds, out = scene_output("harness-parametric", tmp_path, **{"solver.method": method})
    back = xr.open_dataset(out)
    try:
        name = method.upper()
        assert name in back.attrs["source"] and other not in back.attrs["source"]
        assert name in back["n_steps"].attrs["long_name"]
        assert name in back["n_rejected"].attrs["long_name"]
        assert back["n_steps"].dtype == np.int32 and back["n_rhs"].dtype == np.int32
    finally:
        back.close()


def test_counters_are_int32_only_where_they_fit():
    assert counter(np.array([0, 2**31 - 1])).dtype == np.int32
    big = counter(np.array([1, 2**31]))
    assert big.dtype == np.int64 and big[1] == 2**31     # kept exactly, never wrapped
    assert counter(np.array([-2**31 - 1])).dtype == np.int64


def test_one_state_table_across_kinds(tmp_path):
    """The same integer never means two things: every dataset's flags are the shared table's."""
    seen: dict[int, str] = {}
    for name in ("harness-parametric", "paper-fig7"):
        ds, out = scene_output(name, tmp_path)
        back = xr.open_dataset(out)
        try:
            attrs = back["state"].attrs
            values = [int(v) for v in np.atleast_1d(attrs["flag_values"])]
            meanings = attrs["flag_meanings"].split()
            assert len(values) == len(meanings) == len(set(values))
            assert set(np.unique(back["state"].values)) <= set(values)
        finally:
            back.close()
        for value, meaning in zip(values, meanings):
            assert seen.setdefault(value, meaning) == meaning, (name, value)
            assert km.STATE_MEANINGS[value] == meaning
    assert len(set(seen.values())) == len(seen)            # no meaning under two integers
    assert {"completed", "steady", "diverged"} <= set(seen.values())


def _readme_unitless() -> set[str]:
    """The names the README's "What the output holds" lists as labels without units (its
    parenthesis after "but for labels"), in backticks."""
    import re
    text = (Path(__file__).parents[1] / "README.md").read_text()
    section = text[text.index("## What the output holds"):]
    labels = section[section.index("but for labels"):section.index("global attributes")]
    return set(re.findall(r"`([A-Za-z_]+)`", labels))


def test_the_readme_names_every_design_variable_without_units():
    """A design result's string variables (`limited_by`, and `limited_in` of several results)
    carry no units, as CF allows a label; the README's list of what has none named only the
    `direction` coordinate and band bounds (a reviewer's finding)."""
    from sweep.design import max_span
    from sweep.governing import governing_span
    text = ('name = "spans"\n[cable]\ndamping_ratio = 0.02\n[base]\nacceleration_g = 0.1\n'
            "frequency_ratio = 0.5\n[solver]\nt_end = 0.05\n[axes]\nlength = [0.2, 0.3, 0.4]\n")
    ds = sweep.run(sweep.load_scene_text(text), progress=False)
    outputs = [max_span(ds, min_frequency=60.0),
               governing_span([("a", ds), ("b", ds)], min_frequency=60.0)]
    unitless = {name for out in outputs for name in out.variables
                if "units" not in out[name].attrs}
    assert {"limited_by", "limited_in"} <= unitless
    assert unitless <= _readme_unitless(), unitless - _readme_unitless()


def test_the_jump_flag_has_a_whole_label_and_its_explanation_a_comment():
    """`jump`'s long_name was over 100 characters and cut to its words and '...': it is now a
    whole label on any axis, the ratio and what a flag means in its comment."""
    from sweep import schema
    from sweep.models.continuation import jump_attrs
    longest = max(schema.BY_AXIS, key=len)
    for both, words in ((True, "different branches"), (False, "run both ways")):
        attrs = jump_attrs(longest, 1.5, both)
        assert len(attrs["long_name"]) <= 100 and not attrs["long_name"].endswith("...")
        assert longest in attrs["long_name"]
        assert "factor 1.5" in attrs["comment"] and words in attrs["comment"]
