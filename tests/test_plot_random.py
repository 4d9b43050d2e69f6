"""Figures of a random result ([base] asd_g2, docs/model.md sec. 11): `realisation` is not a
swept axis; 'rms', 'peak', 'exceedance' and 'peaks' (sweep/plot/random.py) and the means over
the realisations in place of the per-realisation quantities; `sweep plot` on the file."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import sweep  # noqa: E402
from sweep import plot as splot  # noqa: E402
from sweep.cli import main  # noqa: E402
from sweep.errors import UserError  # noqa: E402
from sweep.plot.random import MAX_LEVELS, plot_rms  # noqa: E402
from sweep.plot.result import over_points  # noqa: E402

REDUCED = {"axes.length": [0.1, 0.15, 0.2], "base.realisations": 2, "base.duration": 2.0}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    """The built-in GEVS scene on a reduced grid (3 spans x 2 levels x 2 records of 2 s, with
    its clearance levels), written and read back as `sweep plot` reads it; and its path."""
    path = tmp_path_factory.mktemp("random") / "gevs.nc"
    sweep.run(sweep.load_scene("launch-random-gevs", REDUCED), output=path, progress=False)
    return splot.load_result(path), path


def _lines(fig: Figure, gid: str) -> list:
    return [line for ax in fig.axes for line in ax.get_lines() if line.get_gid() == gid]


def _legend_texts(fig: Figure) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend()
            for t in ax.get_legend().get_texts()]


def test_realisation_is_not_a_swept_axis(result):
    ds, _ = result
    assert "realisation" in ds["state"].dims
    assert splot.swept_axes(ds) == ["length", "base_asd_scale"]
    shown = over_points(ds)
    assert "realisation" not in shown.dims and shown["state"].dims == ("length",
                                                                       "base_asd_scale")


def test_a_random_result_plots_without_select(result):
    ds, _ = result
    figures = splot.plot(ds)
    assert {"rms", "peak", "exceedance", "peaks", "asd"} <= set(figures)
    # Per-point figures draw the means; nothing is drawn over the realisations.
    assert "amplitude" not in figures and "state" not in figures
    assert {"rms_deflection_mean", "rms_acceleration_g_mean"} <= set(figures) | set(
        figures.skipped)
    for fig in figures.values():
        assert isinstance(fig, Figure)
        assert "base random" in fig.texts[-1].get_text()      # the footer names the input


def test_rms_has_units_a_band_per_level_and_the_linear_line(result):
    ds, _ = result
    fig = splot.plot(ds)["rms"]
    ax = fig.axes[0]
    assert ax.get_xlabel().endswith("[m]")                  # span lengths stay in m
    assert ax.get_ylabel() == "RMS midspan deflection [mm]"
    assert ax.get_title().startswith("launch-random-gevs: RMS midspan deflection")
    means, linear = _lines(fig, "rms_deflection_mean"), _lines(fig, "linear_rms")
    assert len(means) == len(linear) == ds.sizes["base_asd_scale"]
    for mean, lin in zip(means, linear):
        assert lin.get_linestyle() == "--" and lin.get_color() == mean.get_color()
    expected = ds["linear_rms"].isel(base_asd_scale=0).values * 1e3   # mm
    np.testing.assert_allclose(linear[0].get_ydata(), expected)
    np.testing.assert_allclose(means[0].get_ydata(),
                               ds["rms_deflection_mean"].isel(base_asd_scale=0).values * 1e3)
    assert len(ax.collections) == len(means)                 # one 95 % band per level
    texts = _legend_texts(fig)
    assert "linear (Miles-like, exact)" in texts
    assert any("95 % interval" in t for t in texts)


def test_peak_draws_the_clearance_levels(result):
    ds, _ = result
    fig = splot.plot(ds)["peak"]
    ax = fig.axes[0]
    assert ax.get_ylabel() == "peak midspan deflection [mm]"
    levels = sorted(line.get_ydata()[0] for line in _lines(fig, "clearance"))
    np.testing.assert_allclose(levels, np.sort(ds["clearance"].values) * 1e3)
    assert {f"clearance {v * 1e3:g} mm" for v in ds["clearance"].values} <= {
        t.get_text() for t in ax.texts}


def test_exceedance_is_a_probability_per_clearance_level(result):
    ds, _ = result
    fig = splot.plot(ds)["exceedance"]
    ax = fig.axes[0]
    assert ax.get_ylabel() == "probability of exceeding the clearance in the test"
    lines = _lines(fig, "exceedance")
    assert len(lines) == ds.sizes["clearance"] * ds.sizes["base_asd_scale"]
    assert all(0.0 <= y <= 1.0 for line in lines for y in line.get_ydata())
    assert {f"clearance {v * 1e3:g} mm" for v in ds["clearance"].values} <= set(
        _legend_texts(fig))


def test_peaks_is_the_distribution_of_peak_over_rms(result):
    ds, _ = result
    fig = splot.plot(ds)["peaks"]
    ax = fig.axes[0]
    assert ax.get_xlabel() == "peak factor, peak / RMS midspan deflection"     # units 1
    curves = _lines(fig, "peak_factors")
    assert len(curves) == ds.sizes["base_asd_scale"]
    ratio = (ds["peak_deflection"] / ds["rms_deflection"]).isel(base_asd_scale=0).values
    np.testing.assert_allclose(curves[0].get_xdata(), np.sort(ratio.ravel()))
    assert curves[0].get_ydata()[-1] == 1.0


def test_a_random_result_over_length_alone_plots(result):
    ds, _ = result
    one = ds.isel(base_asd_scale=[1])                         # the level a single value
    figures = splot.plot(one)
    assert {"rms", "peak", "exceedance", "peaks", "asd"} <= set(figures)
    assert len(_lines(figures["rms"], "linear_rms")) == 1
    assert "rms_acceleration_g_mean" in figures               # a line over length
    assert figures["rms_acceleration_g_mean"].axes[0].get_ylabel().endswith("[g]")


def test_all_nan_figures_are_left_out_with_a_reason(result):
    ds, _ = result
    escaped = ds.copy()
    for name in ("rms_deflection_mean", "peak_deflection_mean", "peak_deflection",
                 "exceedance_probability"):
        escaped[name] = ds[name] * np.nan
    figures = splot.plot(escaped)
    for name in ("rms", "peak", "exceedance", "peaks"):
        assert name not in figures and "all NaN" in figures.skipped[name]


def test_too_many_levels_need_a_selection(result):
    ds, _ = result
    many = ds.reindex(base_asd_scale=np.linspace(-6.0, 0.0, MAX_LEVELS + 1), method="nearest")
    figures = splot.plot(many)
    assert "rms" not in figures and "--select base_asd_scale=-6" in figures.skipped["rms"]
    with pytest.raises(UserError, match="--select"):
        plot_rms(many)
    assert "rms" in splot.plot(many, {"base_asd_scale": 0.0})


def test_realisation_cannot_be_selected(result):
    ds, _ = result
    with pytest.raises(UserError, match="'realisation' is not a swept axis .*random records"):
        splot.plot(ds, {"realisation": 0})


def test_cli_plot_writes_the_random_figures(result, tmp_path, capsys):
    _, path = result
    assert main(["plot", str(path), "-o", str(tmp_path)]) == 0
    written = {p.name for p in tmp_path.glob("*.png")}
    assert {f"gevs-{k}.png" for k in ("rms", "peak", "exceedance", "peaks")} <= written
    assert all(p.stat().st_size > 1000 for p in tmp_path.glob("*.png"))


def test_asd_draws_the_response_over_the_input_spectrum(result):
    """'asd': each span's absolute acceleration ASD (g^2/Hz) as stored, at the highest level,
    and the input spectrum at that level dashed over it, log-log, over the spectrum's band."""
    ds, _ = result
    fig = splot.plot(ds)["asd"]
    lines = _lines(fig, "acceleration_asd")
    assert len(lines) == 3                                  # the three spans
    top = ds.sel(base_asd_scale=0.0)
    for line, length in zip(lines, top.length.values):
        x, y = line.get_data()
        stored = top.acceleration_asd.sel(length=length)
        np.testing.assert_array_equal(y, stored.sel(asd_frequency=x).values)
    linear = _lines(fig, "linear_acceleration_asd")
    for line, length in zip(linear, top.length.values):
        x, y = line.get_data()
        np.testing.assert_array_equal(
            y, top.linear_acceleration_asd.sel(length=length, asd_frequency=x).values)
    assert len(linear) == 3
    base, = _lines(fig, "base_asd_g2")
    x, y = base.get_data()
    assert x[0] >= 20.0 and x[-1] <= 2000.0
    np.testing.assert_array_equal(y, top.base_asd_g2.sel(asd_frequency=x).values)
    assert max(y) == pytest.approx(0.16, rel=1e-9)          # GEVS's plateau at 0 dB
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert "g$^2$/Hz" in ax.get_ylabel() and "Hz" in ax.get_xlabel()
    # a level chosen: its own spectrum, 3 dB down
    quiet = splot.plot_asd(ds, select={"base_asd_scale": -3.0})
    x, y = _lines(quiet, "base_asd_g2")[0].get_data()
    assert max(y) == pytest.approx(0.16 * 10 ** -0.3, rel=1e-9)


def test_parameter_sets_are_points_not_a_curve():
    """A random result over [points] (separate cables, not an ordered axis): markers with
    error bars and no line between the sets, the x ticks naming each set's values."""
    scene = sweep.load_scene("launch-random-gevs", {
        "points.length": [0.1, 0.15, 0.2], "base.realisations": 2,
        "base.duration": 2.0, "axes.base_asd_scale": [0.0]})
    ds = sweep.run(scene, progress=False)
    assert "point" in ds.dims
    fig = splot.plot(ds)["rms"]
    ax = fig.axes[0]
    for line in _lines(fig, "rms_deflection_mean") + _lines(fig, "linear_rms"):
        assert line.get_linestyle() == "None" and line.get_marker() not in (None, "None")
    assert [t.get_text().split("\n")[0] for t in ax.get_xticklabels()] == ["0", "1", "2"]
    assert "length" in ax.get_xlabel() and "parameter set" in ax.get_xlabel()
