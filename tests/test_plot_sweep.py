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


# ------------------------------------------------------------------ a sweep run up and down

BOTH_WAYS = """
name = "plot-both-ways"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.5
sweep = {start = 20.0, stop = 60.0, rate = 8.0, direction = "both"}
[outputs]
envelope = true
[axes]
length = [0.4, 0.5]
"""


@pytest.fixture(scope="module")
def both_ways(tmp_path_factory):
    """One tiny real sweep run both ways (a `direction` dimension), written and read back."""
    path = tmp_path_factory.mktemp("both") / "both.nc"
    sweep.run(sweep.load_scene_text(BOTH_WAYS), output=path, progress=False)
    ds = splot.load_result(path)
    assert list(ds["direction"].values) == ["up", "down"]
    assert ds["peak_amplitude"].dims == ("direction", "length")
    return ds, path


def _with_directions(ds: xr.Dataset, down_factor: float = 0.5) -> xr.Dataset:
    """A hand-made result with a `direction` dimension: the down values `down_factor` x up."""
    solved = ["state", "envelope", "peak_amplitude", "peak_frequency"]
    up, down = ds[solved], ds[solved].copy(deep=True)
    down["envelope"] = down["envelope"] * down_factor
    down["peak_amplitude"] = down["peak_amplitude"] * down_factor
    both = xr.concat([up, down], dim=xr.DataArray(["up", "down"], dims="direction"))
    out = ds.drop_vars(solved).assign(**{v: both[v] for v in solved})
    for v in solved:
        out[v].attrs = ds[v].attrs
    return out


@pytest.mark.slow
def test_sweep_plot_draws_every_figure_of_a_sweep_run_both_ways(both_ways, tmp_path, capsys):
    _, path = both_ways
    out = tmp_path / "figs"
    assert main(["plot", str(path), "-o", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    expected = {"peak_amplitude", "peak_frequency", "absolute_acceleration_g",
                "envelope", "envelope_map-up", "envelope_map-down"}
    assert {f"both-{key}.png" for key in expected} <= names, names
    assert "both-amplitude.png" not in names      # a sweep stores no tail amplitude
    assert "envelope_map" not in {n[len("both-"):-len(".png")] for n in names}
    assert all((out / n).stat().st_size > 1000 for n in names)
    assert "Traceback" not in capsys.readouterr().err


def test_the_envelope_of_a_sweep_run_both_ways_has_an_up_and_a_down_line_per_point(both_ways):
    ds, _ = both_ways
    fig = plot_envelope(ds)
    lines = _envelope_lines(fig)
    assert len(lines) == 2 * ds.sizes["length"]
    for i, length in enumerate(ds["length"].values):
        mine = [line for line in lines if line.get_label().startswith(f"length = {length:g} m")]
        assert sorted(line.get_linestyle() for line in mine) == ["-", "--"]
        assert len({line.get_color() for line in mine}) == 1       # one colour per point
        for line in mine:
            way = "up" if line.get_linestyle() == "-" else "down"
            np.testing.assert_allclose(
                line.get_ydata(), ds["envelope"].sel(direction=way).isel(length=i).values * 1e3)
    texts = _legend_texts(fig)
    # The legend names each point once and the line styles once, not every line.
    assert texts.count("swept up") == 1 and texts.count("swept down") == 1
    assert [t for t in texts if t.startswith("length")] == ["length = 0.4 m", "length = 0.5 m"]
    assert any("peak of the up sweep" in t for t in texts)
    assert any("peak of the down sweep" in t for t in texts)
    stars = np.concatenate([np.asarray(c.get_offsets()) for c in fig.axes[0].collections
                            if len(c.get_offsets())])
    expected = np.column_stack([ds["peak_frequency"].values.ravel(),
                                ds["peak_amplitude"].values.ravel() * 1e3])
    np.testing.assert_allclose(sorted(map(tuple, stars)), sorted(map(tuple, expected)))
    assert "up and down" in fig.axes[0].get_title()


def test_the_peak_lines_of_a_sweep_run_both_ways_overlay_up_and_down(both_ways):
    ds, _ = both_ways
    figures = splot.plot(ds)
    assert "amplitude" not in figures          # a sweep stores no tail amplitude
    for var in ("peak_amplitude", "peak_frequency"):
        ax = figures[var].axes[0]
        by_way = {line.get_gid(): line for line in ax.get_lines()
                  if str(line.get_gid()).startswith("direction-")}
        assert set(by_way) == {"direction-up", "direction-down"}, var
        assert by_way["direction-up"].get_linestyle() == "-"
        assert by_way["direction-down"].get_linestyle() == "--"
        factor = 1e3 if var != "peak_frequency" else 1.0
        for way in ("up", "down"):
            np.testing.assert_allclose(by_way[f"direction-{way}"].get_ydata(),
                                       ds[var].sel(direction=way).values * factor)
        texts = _legend_texts(figures[var])
        assert "swept up" in texts and "swept down" in texts
    assert "Hz" in figures["peak_frequency"].axes[0].get_ylabel()
    assert "mm" in figures["peak_amplitude"].axes[0].get_ylabel()
    assert any("swept up and down" in " ".join(t.get_text().split())   # the footer, wrapped
               for t in figures["peak_amplitude"].texts)


def test_maps_of_a_sweep_run_both_ways_are_drawn_per_direction_on_one_scale():
    ds = _with_directions(_hand_made(3), down_factor=0.25)
    splot.check_result(ds)
    figures = splot.plot(ds)
    assert {"envelope", "envelope_map-up", "envelope_map-down"} <= set(figures)
    assert "envelope_map" not in figures
    up, down = (figures[f"envelope_map-{w}"].axes[0] for w in ("up", "down"))
    assert up.collections[0].get_clim() == down.collections[0].get_clim()
    assert "swept up" in up.get_title() and "swept down" in down.get_title()
    with pytest.raises(UserError, match="direction"):
        splot.plot_map(ds, "envelope", x="band_frequency", y="length")
    # Two swept axes: every map (amplitude-like and state) once per direction.
    two = xr.concat([ds, ds], dim=xr.DataArray([1.0, 2.0], dims="base_sweep_rate",
                                               attrs={"units": "min-1"}))
    for name in ("band_frequency", "band_frequency_bounds", "base_level_g",
                 "natural_frequency"):
        two[name] = ds[name]
    two = two.transpose("direction", "length", "base_sweep_rate", ...)
    two["state"][1, 0, 1] = 5                                      # one down sweep diverged
    splot.check_result(two)
    figures = splot.plot(two)
    for name in ("peak_amplitude", "state"):      # (peak_frequency: one value, no figure)
        assert {f"{name}-up", f"{name}-down"} <= set(figures), (name, set(figures))
    assert "envelope" not in figures and "select" in figures.skipped["envelope"]


def test_failed_sweeps_of_one_direction_are_left_out_and_counted():
    ds = _with_directions(_hand_made(2))
    ds["state"].loc[{"direction": "down"}] = np.array([8, 5], np.int8)   # 0.6 m down diverged
    fig = plot_envelope(ds)
    assert len(_envelope_lines(fig)) == 3
    assert any("left out: 1 of 4 sweeps" in t and "diverged 1" in t for t in _legend_texts(fig))
    line = splot.plot_line(ds, "peak_amplitude")
    assert any(t.startswith("diverged (1)") for t in
               [t.get_text() for t in line.get_legend().get_texts()])
