"""[points]: zipped parameter sets on a `point` dimension. Each entry's results must equal
running that parameter set alone (its values given as scalars), bit for bit, in every model
the scene can use; bad [points] is refused in one line."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.cli import main
from sweep.errors import SceneError

BASE = """
name = "segments"
description = "a harness's segments, each with its own section"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.5
frequency_ratio = 1.0
[points]
length = [0.30, 0.50, 0.30]
area = [6e-6, 4e-6, 3e-6]
inertia = [2.865e-12, 1.3e-12, 0.7e-12]
[axes]
base_frequency_ratio = [0.9, 1.0, 1.1]
[solver]
t_end = 0.5
"""

AXIAL = """
name = "axial-points"
[load]
amplitude = 4.0
[initial]
displacement = 1e-3
[points]
length = [0.5, 0.8]
load_amplitude = [2.0, 6.0]
[axes]
frequency_ratio = [1.0, 2.0]
[solver]
t_end = 0.5
driver = "{driver}"
"""

SWEPT = """
name = "sweeps-up-and-down"
[cable]
damping_ratio = 0.02
length = 0.31
[load]
amplitude = 0.0
[base]
acceleration_g = 0.2
sweep = {{ start = 30.0, stop = 50.0, rate = 120.0 }}
[points]
base_sweep_start = [30.0, 50.0]
base_sweep_stop = [50.0, 30.0]
[outputs]
envelope = true
"""

LONGITUDINAL = """
name = "wave-points"
[model]
kind = "longitudinal"
[load]
amplitude = 4.0
[points]
length = [0.5, 1.0, 0.7]
area = [6e-6, 3e-6, 6e-6]
[solver]
intervals = 50
"""


def _alone(scene: sweep.Scene, i: int) -> sweep.Scene:
    """Point i of `scene` as a scene of its own: every [points] value given as a scalar (an
    override of a key drops its [points] entry)."""
    from sweep.schema import BY_AXIS
    overrides = {BY_AXIS[name].dotted: float(values[i]) for name, values in scene.points.items()}
    return sweep.load_scene_text(scene.text, overrides=overrides)


def _assert_point_equals_alone(ds: xr.Dataset, i: int, alone: xr.Dataset) -> None:
    point = ds.isel(point=i)
    for name, variable in alone.data_vars.items():
        mine = point[name]
        assert mine.dims == variable.dims, name
        assert np.array_equal(mine.values, variable.values, equal_nan=True), name
        assert mine.attrs.keys() == variable.attrs.keys(), name
        assert all(np.array_equal(mine.attrs[k], variable.attrs[k]) for k in mine.attrs), name
    assert set(point.data_vars) == set(alone.data_vars)


def _check_every_point(text: str, tmp_path=None) -> xr.Dataset:
    scene = sweep.load_scene_text(text)
    ds = sweep.run(scene, threads=1)
    count = len(next(iter(scene.points.values())))
    assert ds.sizes["point"] == count
    for i in range(count):
        _assert_point_equals_alone(ds, i, sweep.run(_alone(scene, i), threads=1))
    return ds


def test_base_excited_segments_each_equal_running_alone():
    ds = _check_every_point(BASE)
    assert ds.amplitude.dims == ("point", "base_frequency_ratio")
    # the [points] values ride on the point dimension, with units
    assert list(ds.length.values) == [0.30, 0.50, 0.30]
    assert ds.length.dims == ("point",) and ds.length.attrs["units"] == "m"
    assert ds.inertia.attrs["units"] == "m4" or ds.inertia.attrs["units"] == "m^4"
    # two points with one length and different sections answer differently
    assert ds.natural_frequency.values[0] != ds.natural_frequency.values[2]


@pytest.mark.parametrize("driver", ["scalar", "lanes"])
def test_axial_load_points_equal_running_alone(driver):
    _check_every_point(AXIAL.format(driver=driver))


def test_swept_points_up_and_down_equal_running_alone():
    ds = _check_every_point(SWEPT.format())
    up, down = ds.isel(point=0), ds.isel(point=1)
    assert float(up.sweep_duration) == pytest.approx(float(down.sweep_duration))
    assert float(up.peak_amplitude) != float(down.peak_amplitude)


def test_longitudinal_points_equal_running_alone():
    _check_every_point(LONGITUDINAL)


def test_stability_points_equal_running_alone():
    text = AXIAL.format(driver="scalar") + "[outputs]\nstability = true\namplitude = false\n" \
        "peak_amplitude = false\nsettling_time = false\nresponse_period = false\n"
    ds = _check_every_point(text)
    assert "growth_rate" in ds and "amplitude" not in ds


def test_points_combine_with_axes_as_a_product_and_keep_order():
    scene = sweep.load_scene_text(BASE)
    ds = sweep.run(scene, threads=2)
    assert ds.state.shape == (3, 3)
    again = sweep.run(scene, threads=1)
    for name in ds.data_vars:
        assert np.array_equal(ds[name].values, again[name].values, equal_nan=True), name
    # point 1 at the middle ratio is the product's (1, 1) entry: its own natural frequency
    f1 = ds.natural_frequency.values[1]
    assert float(ds.base_frequency.isel(point=1, base_frequency_ratio=1)) == pytest.approx(f1)


def test_to_toml_round_trip_and_netcdf_are_clean(tmp_path):
    scene = sweep.load_scene_text(BASE)
    assert sweep.load_scene_text(scene.to_toml()) == scene
    out = tmp_path / "points.nc"
    ds = sweep.run(scene, output=out)
    back = xr.open_dataset(out)
    assert list(back.point.values) == [0, 1, 2]
    np.testing.assert_array_equal(back.length.values, [0.30, 0.50, 0.30])
    assert back.length.attrs["long_name"]
    np.testing.assert_array_equal(back.amplitude.values, ds.amplitude.values)
    # a point is found by the values written in the scene
    picked = back.amplitude.where(back.length == 0.5, drop=True)
    assert picked.sizes["point"] == 1
    back.close()


def test_cf_checker_finds_nothing(tmp_path):
    from test_cf import cf_problems
    out = tmp_path / "points.nc"
    sweep.run(sweep.load_scene_text(BASE), output=out)
    assert cf_problems(out) == []


def test_reordered_points_are_another_run():
    from sweep.runner import run_fingerprint
    a = sweep.load_scene_text(BASE)
    b = sweep.load_scene_text(BASE.replace("[0.30, 0.50, 0.30]", "[0.50, 0.30, 0.30]"))
    c = sweep.load_scene_text(BASE)
    assert run_fingerprint(a) != run_fingerprint(b)
    assert run_fingerprint(a) == run_fingerprint(c)


def test_overrides_replace_points_entries():
    scene = sweep.load_scene_text(BASE, overrides={"points.length": [0.2, 0.4, 0.6]})
    np.testing.assert_array_equal(scene.points["length"], [0.2, 0.4, 0.6])
    scalar = sweep.load_scene_text(BASE, overrides={"cable.length": 0.4})
    assert "length" not in scalar.points and scalar.get("cable.length") == 0.4
    axis = sweep.load_scene_text(BASE, overrides={"axes.length": [0.3, 0.4]})
    assert "length" not in axis.points and list(axis.axes) == ["base_frequency_ratio", "length"]
    moved = sweep.load_scene_text(BASE, overrides={"points.base_frequency_ratio": [1, 1, 2]})
    assert "base_frequency_ratio" not in moved.axes
    # the other spelling of the base frequency goes too
    hz = sweep.load_scene_text(BASE, overrides={"points.base_frequency": [20, 30, 40]})
    assert "base_frequency_ratio" not in hz.axes and hz.get("base.frequency_ratio") is None


@pytest.mark.parametrize("table, fragment", [
    ("length = [0.3, 0.5]\narea = [6e-6]", "every list needs one value per point, but length "
                                           "has 2, area has 1"),
    ("lenght = [0.3, 0.5]", "[points] entry 'lenght': unknown axis"),
    ("rtol = [1e-8, 1e-9]", "[points] entry 'rtol': 'solver.rtol' cannot be swept"),
    ("base_frequency_ratio = [1.0, 2.0]", "'base_frequency_ratio' is also an axis"),
    ("length = 0.3", "[points] entry 'length': must be a list"),
    ("length = {start = 0.3, stop = 0.5, num = 3}", "must be a list"),
    ("length = []", "[points] entry 'length': empty list"),
    ("length = [0.3, -0.5]", "[points] entry 'length'"),
    ("length = [0.3, 'a']", "[points] entry 'length'"),
    ("length = [0.3, 0.5]\ncable.length = [0.3, 0.5]", "given twice"),
])
def test_bad_points_are_one_line(table, fragment):
    text = BASE.replace("length = [0.30, 0.50, 0.30]\narea = [6e-6, 4e-6, 3e-6]\n"
                        "inertia = [2.865e-12, 1.3e-12, 0.7e-12]", table)
    with pytest.raises(SceneError) as error:
        sweep.load_scene_text(text)
    message = str(error.value)
    assert fragment in message and "\n" not in message


def test_a_stepped_sweep_along_a_points_entry_is_refused():
    text = BASE + "[continuation]\naxis = \"length\"\n"
    with pytest.raises(SceneError, match="'length' is a \\[points\\] entry"):
        sweep.load_scene_text(text)


def test_a_pair_spelt_both_ways_is_refused():
    text = BASE.replace("inertia = [2.865e-12, 1.3e-12, 0.7e-12]",
                        "base_frequency = [20.0, 30.0, 40.0]")
    with pytest.raises(SceneError, match="base.frequency"):
        sweep.load_scene_text(text)


def test_cli_bad_points_exit_2_one_line(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(BASE.replace("area = [6e-6, 4e-6, 3e-6]", "area = [6e-6]"))
    assert main(["run", str(path), "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "[points]" in err
    assert not (tmp_path / "x.nc").exists()


def test_zipped_sweeps_are_not_refused_by_their_product():
    """start = stop never happens on the zipped points (30 -> 50, 50 -> 30); the product of
    the two lists would have 30 -> 30."""
    scene = sweep.load_scene_text(SWEPT.format())
    assert scene.points["base_sweep_start"].tolist() == [30.0, 50.0]


def test_coefficients_checked_at_every_point_not_the_product():
    """A point set whose product would hold a non-finite coefficient but whose entries do not
    is taken; one whose entry does is refused naming the [points] entry."""
    good = BASE.replace("inertia = [2.865e-12, 1.3e-12, 0.7e-12]",
                        "inertia = [2.865e-12, 1.3e-12, 0.7e-12]\n"
                        "density = [1e-200, 8900.0, 8900.0]").replace(
        "area = [6e-6, 4e-6, 3e-6]", "area = [6e-6, 4e-6, 1e-200]")
    scene = sweep.load_scene_text(good)
    # the product's corner density 1e-200 x area 1e-200 would give rho A = 0
    assert (scene.points["density"] * scene.points["area"]).min() > 0
    with pytest.raises(SceneError, match="axis 'density' at 1e-200"):
        sweep.load_scene_text(good.replace("[axes]\n", "[axes]\ndensity = [1e-200, 8900.0]\n")
                              .replace("density = [1e-200, 8900.0, 8900.0]\n", ""))
    bad = BASE.replace("inertia = [2.865e-12, 1.3e-12, 0.7e-12]",
                       "inertia = [2.865e-12, 1.3e-12, 0.7e-12]\ndensity = [8900.0, 5e-324, 8900.0]")
    with pytest.raises(SceneError, match="\\[points\\]"):
        sweep.load_scene_text(bad)


CABLES = """
name = "cables"
description = "three cables over clamp spacings"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 1.0
frequency = 60.0
[points]
area = [6e-6, 4e-6, 3e-6]
inertia = [2.865e-12, 1.3e-12, 0.7e-12]
[axes]
length = {start = 0.1, stop = 0.6, num = 11}
[solver]
t_end = 0.5
"""


def test_design_gives_each_cable_its_own_span():
    """The frequency criterion per point against sec. 9's closed form for that point's own
    section: l_max = sqrt(pi sqrt(EI/(rho A)) / (2 f_min)); refined with the engine, each
    point's span equals refining that cable's own run."""
    import math

    from sweep.design import max_span, refine_span
    ds = sweep.run(sweep.load_scene_text(CABLES), progress=False)
    spans = max_span(ds, min_frequency=100.0)
    assert spans.max_span.dims == ("point",)
    for i, (area, inertia) in enumerate([(6e-6, 2.865e-12), (4e-6, 1.3e-12), (3e-6, 0.7e-12)]):
        exact = math.sqrt(math.pi * math.sqrt(1.1e11 * inertia / (8900.0 * area)) / 200.0)
        assert float(spans.max_span[i]) == pytest.approx(exact, rel=1e-2)
    refined = refine_span(ds, max_amplitude=2e-4, tolerance=2e-3)
    scene = sweep.load_scene_text(CABLES)
    alone = refine_span(sweep.run(_alone(scene, 1), progress=False), max_amplitude=2e-4,
                        tolerance=2e-3)
    assert float(refined.max_span[1]) == float(alone.max_span)
    assert str(refined.limited_by.values[1]) == "max_amplitude"


@pytest.mark.slow
def test_plots_label_each_parameter_set_with_its_values(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    from sweep import plot as splot
    ds = sweep.run(sweep.load_scene_text(CABLES), progress=False)
    figures = splot.plot(ds)
    ax = figures["amplitude"].axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert labels == ["0: 6e-06, 2.87e-12", "1: 4e-06, 1.3e-12", "2: 3e-06, 7e-13"]
    assert "area [m2]" in ax.get_ylabel() or "area [m^2]" in ax.get_ylabel()
    line = splot.plot(ds.isel(length=4))["amplitude"].axes[0]
    assert [t.get_text() for t in line.get_xticklabels()][1] == "1\n4e-06, 1.3e-12"
    assert main(["plot", str(_written(ds, tmp_path)), "-o", str(tmp_path / "figs")]) == 0
    assert (tmp_path / "figs" / "cables-amplitude.png").exists()


def _written(ds: xr.Dataset, tmp_path) -> object:
    path = tmp_path / "cables.nc"
    ds.to_netcdf(path)
    return path
