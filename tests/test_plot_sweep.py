"""Figures of a continuous sine sweep ([base] sweep = {start, stop, rate}): the response envelope
against the excitation frequency (`plot_envelope`), its map, the peak lines, `sweep plot`."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import sweep  # noqa: E402
from sweep import plot as splot  # noqa: E402
from sweep.cli import main  # noqa: E402
from sweep.errors import UserError  # noqa: E402
from sweep.plot.envelope import plot_envelope  # noqa: E402

SWEPT = """
name = "plot-sweep"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
levels_g = [[10.0, 0.2], [40.0, 0.2], [50.0, 0.4], [100.0, 0.4]]
sweep = {start = 20.0, stop = 60.0, rate = 8.0}
[outputs]
envelope = true
[axes]
length = [0.4, 0.5]
"""


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    """One tiny real swept result, written and read back as `sweep plot` reads it."""
    path = tmp_path_factory.mktemp("sweep") / "swept.nc"
    sweep.run(sweep.load_scene_text(SWEPT), output=path, progress=False)
    return splot.load_result(path), path


def _envelope_lines(fig: Figure) -> list:
    return [line for line in fig.axes[0].get_lines() if line.get_gid() == "envelope"]


def _legend_texts(fig: Figure) -> list[str]:
    legend = fig.axes[0].get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend is not None else []


def _hand_made(n_points: int = 2, level: bool = True) -> xr.Dataset:
    """A swept result built by hand with the variables and attributes `sweep run` writes."""
    n = 3
    centres = 1000.0 * 2.0 ** (np.arange(-13, -13 + 6) / n)          # 50 ... 160 Hz
    bounds = np.column_stack([centres * 2 ** (-1 / (2 * n)), centres * 2 ** (1 / (2 * n))])
    lengths = np.linspace(0.4, 0.6, n_points)
    env = np.full((n_points, centres.size), np.nan)
    env[:, 1:5] = 1e-3 * np.array([[0.5, 2.0, 1.0, 0.3]]) * (1 + np.arange(n_points))[:, None]
    ds = xr.Dataset(
        {"state": ("length", np.full(n_points, 8, np.int8),
                   {"long_name": "response state of the point", "units": "1",
                    "flag_values": np.array([0, 8, 5, 6, 7], np.int8),
                    "flag_meanings": "invalid_input completed diverged step_size_too_small "
                                     "max_steps_reached"}),
         "envelope": (("length", "band_frequency"), env,
                      {"units": "m", "long_name": "response envelope"}),
         "peak_amplitude": ("length", np.nanmax(env, axis=1), {"units": "m"}),
         "peak_frequency": ("length", np.full(n_points, centres[2]), {"units": "Hz"}),
         "natural_frequency": ("length", np.linspace(70.0, 90.0, n_points), {"units": "Hz"}),
         "band_frequency_bounds": (("band_frequency", "nv"), bounds)},
        coords={"length": ("length", lengths, {"units": "m", "long_name": "span length"}),
                "band_frequency": ("band_frequency", centres,
                                   {"units": "Hz", "bounds": "band_frequency_bounds"})},
        attrs={"title": "hand-made", "model_kind": "transverse"})
    if level:
        ds["base_level_g"] = ("band_frequency", np.full(centres.size, 0.5),
                              {"units": "9.80665 m s-2"})
    return ds


def test_the_envelope_is_drawn_log_log_with_units(result, tmp_path):
    ds, _ = result
    fig = plot_envelope(ds)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert "Hz" in ax.get_xlabel() and "mm" in ax.get_ylabel()
    assert len(fig.axes) == 2                                   # the base level on the right
    twin = fig.axes[1]
    assert twin.get_yscale() == "log" and "g" in twin.get_ylabel().split("[")[-1]
    lines = _envelope_lines(fig)
    assert len(lines) == ds.sizes["length"]
    assert [line.get_label() for line in lines] == ["length = 0.4 m", "length = 0.5 m"]
    # The envelope is drawn in mm at the band centres.
    np.testing.assert_allclose(lines[0].get_xdata(), ds["band_frequency"].values)
    np.testing.assert_allclose(lines[0].get_ydata(),
                               ds["envelope"].isel(length=0).values * 1e3)
    fig.savefig(tmp_path / "envelope.png")
    assert (tmp_path / "envelope.png").stat().st_size > 1000


def test_bands_the_sweep_did_not_reach_are_gaps_not_zeros(result):
    ds, _ = result
    ds = ds.copy(deep=True)
    ds["envelope"][0, :2] = np.nan
    lines = _envelope_lines(plot_envelope(ds))
    y = np.asarray(lines[0].get_ydata(), float)
    assert np.isnan(y[:2]).all() and np.isfinite(y[2:]).all()
    assert not np.any(y == 0.0)
    # A whole hand-made result with NaN at both ends draws no zeros either.
    fig = plot_envelope(_hand_made())
    for line in _envelope_lines(fig):
        y = np.asarray(line.get_ydata(), float)
        assert np.isnan(y[[0, 5]]).all() and (y[1:5] > 0).all()
    assert fig.axes[0].get_ylim()[0] > 0


def test_peaks_and_natural_frequencies_are_marked(result):
    ds, _ = result
    fig = plot_envelope(ds)
    ax = fig.axes[0]
    stars = [c for c in ax.collections if len(c.get_offsets())]
    peaks = np.concatenate([np.asarray(c.get_offsets()) for c in stars])
    expected = np.column_stack([ds["peak_frequency"].values, ds["peak_amplitude"].values * 1e3])
    np.testing.assert_allclose(sorted(map(tuple, peaks)), sorted(map(tuple, expected)))
    assert any(t.startswith("natural frequency f1") for t in _legend_texts(fig))


def test_failed_points_are_left_out_and_counted():
    ds = _hand_made(3)
    ds["state"][1] = 5                                          # diverged
    ds["envelope"][1] = np.nan
    fig = plot_envelope(ds)
    assert len(_envelope_lines(fig)) == 2
    assert any("left out: 1 of 3" in t and "diverged 1" in t for t in _legend_texts(fig))


def test_without_base_level_there_is_no_twin_axis():
    ds = _hand_made(level=False)
    splot.check_result(ds)
    fig = plot_envelope(ds)
    assert len(fig.axes) == 1 and len(_envelope_lines(fig)) == 2
    figures = splot.plot(ds)
    assert {"envelope", "envelope_map"} <= set(figures)


def test_one_point_and_selections():
    ds = _hand_made(3)
    fig = plot_envelope(ds, select={"length": 0.5})
    assert len(_envelope_lines(fig)) == 1
    assert "envelope" in splot.plot(ds, {"length": 0.5})
    two = xr.concat([ds, ds], dim=xr.DataArray([1.0, 2.0], dims="base_sweep_rate",
                                               attrs={"units": "min-1"}))
    two["band_frequency"] = ds["band_frequency"]
    two["band_frequency_bounds"] = ds["band_frequency_bounds"]
    two["base_level_g"] = ds["base_level_g"]
    two = two.transpose("length", "base_sweep_rate", ...)
    with pytest.raises(UserError, match="select"):
        plot_envelope(two)
    figures = splot.plot(two)
    assert "envelope" not in figures and "select" in figures.skipped["envelope"]
    assert len(_envelope_lines(plot_envelope(two, select={"base_sweep_rate": 2.0}))) == 3


def test_the_envelope_map_has_a_log_frequency_axis(result):
    ds, _ = result
    figures = splot.plot(ds)
    ax = figures["envelope_map"].axes[0]
    assert ax.get_xscale() == "log" and "Hz" in ax.get_xlabel()
    assert "length" in ax.get_ylabel() or "span" in ax.get_ylabel()


def test_a_misplaced_envelope_is_refused():
    ds = _hand_made()
    ds["envelope"] = ds["envelope"].isel(length=0, drop=True)
    with pytest.raises(UserError, match="envelope"):
        splot.check_result(ds)


def test_swept_results_get_peak_lines_with_or_without_the_envelope(result):
    ds, _ = result
    figures = splot.plot(ds)
    assert {"peak_amplitude", "peak_frequency", "envelope", "envelope_map"} <= set(figures)
    bare = ds.drop_vars(["envelope", "base_level_g", "band_frequency_bounds", "band_frequency"])
    splot.check_result(bare)
    figures = splot.plot(bare)
    assert {"peak_amplitude", "peak_frequency"} <= set(figures)
    assert not {"envelope", "envelope_map"} & set(figures)
    ax = figures["peak_frequency"].axes[0]
    assert "Hz" in ax.get_ylabel()


def test_sweep_plot_writes_the_envelope_png(result, tmp_path, capsys):
    _, path = result
    out = tmp_path / "figs"
    assert main(["plot", str(path), "-o", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    for key in ("envelope", "envelope_map", "peak_amplitude", "peak_frequency"):
        assert f"swept-{key}.png" in names, names
    assert (out / "swept-envelope.png").stat().st_size > 1000
    assert "swept-envelope.png" in capsys.readouterr().out
