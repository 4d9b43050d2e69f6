"""Figures: each kind drawn from a real small result, the `sweep plot` command, the examples."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import sweep
from sweep import plot as splot

from conftest import fast_first, sweep_env

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

LINE = """
name = "plot-line"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
frequency_ratio = 2.0
[initial]
displacement = 1e-4
[axes]
length = [0.3, 0.6, 0.9, 1.4]
[solver]
t_end = 1.0
[outputs]
time_series = true
"""

MAP = """
name = "plot-map"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
inertia = 5.73e-12              # m^4, the paper's number (the overlay test computes with it)
[load]
amplitude = 4.0                 # N, the paper's end load
[initial]
displacement = 1e-4
[axes]
length = [0.4, 0.7, 1.0, 1.4]
frequency_ratio = [1.0, 1.8, 2.0, 2.2, 2.8]
[solver]
t_end = 1.0
"""

LONGITUDINAL = """
name = "plot-longitudinal"
[model]
kind = "longitudinal"
[load]
type = "constant"
amplitude = 4.0
[axes]
length = [0.5, 1.0]
[solver]
intervals = 40
transits = 4.0
[outputs]
histories = true
normalised = true
snapshot_times = [7.1111e-5, 2.13334e-4]
"""

LONGITUDINAL_ONE = LONGITUDINAL.replace("[axes]\nlength = [0.5, 1.0]", "[cable]\nlength = 1.0")


def _result(text: str, path: Path) -> xr.Dataset:
    return sweep.run(sweep.load_scene_text(text), output=path, progress=False)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Small real results, each also written as netCDF: name -> (Dataset, path)."""
    base = tmp_path_factory.mktemp("results")
    out = {}
    for name, text in (("line", LINE), ("map", MAP), ("longitudinal", LONGITUDINAL),
                       ("longitudinal-one", LONGITUDINAL_ONE)):
        path = base / f"{name}.nc"
        out[name] = (_result(text, path), path)
    return out


def cli(*args, cwd=None, env=None):
    env = sweep_env(env)
    return subprocess.run([sys.executable, "-m", "sweep.cli", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=600)


def _check_png(path: Path, fig: Figure, dpi: float = 100) -> np.ndarray:
    """The PNG exists, is not empty, has the figure's size in pixels and is not blank."""
    assert path.is_file() and path.stat().st_size > 1000, path
    image = mpimg.imread(path)
    width, height = fig.get_size_inches() * dpi
    assert abs(image.shape[0] - height) <= 1 and abs(image.shape[1] - width) <= 1, \
        (path, image.shape, width, height)
    assert float(image[..., :3].std()) > 0.01, f"{path} is blank"
    return image


@pytest.mark.parametrize("name, keys", [
    ("line", {"amplitude", "settling_time", "time_series"}),
    ("map", {"amplitude", "settling_time", "state"}),
    ("longitudinal", {"peak_end_displacement", "dynamic_amplification", "snapshots",
                      "histories"}),
    ("longitudinal-one", {"snapshots", "histories"}),
])
def test_each_figure_is_drawn_and_saved_at_its_size(results, tmp_path, name, keys):
    ds, _ = results[name]
    figures = splot.plot(ds)
    # A variable with one value everywhere (or none) has no figure, and says why.
    silent = {k for k in keys if k in ds and splot.why_not_drawn(ds[k]) is not None}
    assert set(figures) == keys - silent and set(figures.skipped) == silent
    keys = keys - silent
    paths = splot.save(figures, tmp_path, prefix=f"{name}-")
    assert sorted(p.name for p in paths) == sorted(f"{name}-{k}.png" for k in keys)
    for key, fig in figures.items():
        assert isinstance(fig, Figure)
        _check_png(tmp_path / f"{name}-{key}.png", fig)


def test_map_axes_labels_markers_and_closed_form_overlays(results):
    ds, _ = results["map"]
    ax = splot.plot_map(ds, "amplitude")
    assert ax.get_xlabel() == "load frequency over the span's first natural frequency, W/w1"
    assert ax.get_ylabel() == "span length between constraints [m]"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    # The principal zone boundaries W/w1 = 2 sqrt(1 +- mu), mu = P0 / (2 Pcr), per length.
    assert any(text.startswith("W/w1 = 2 sqrt(1") for text in labels), labels
    mu = 0.5 * ds["load_ratio"].sel(length=1.4).item()
    upper = [line for line in ax.lines if line.get_ls() == "-"]
    assert upper, "no zone boundary drawn"
    xs = np.concatenate([line.get_xdata() for line in upper])
    ys = np.concatenate([line.get_ydata() for line in upper])
    at_1m = np.isclose(ys, 1.4, rtol=1e-12)
    assert at_1m.any()
    np.testing.assert_allclose(sorted(xs[at_1m]), [2 * np.sqrt(1 - mu), 2 * np.sqrt(1 + mu)],
                               rtol=1e-9)
    # The buckling length l = pi sqrt(EI / P0) lies in [0.4, 1.4] m for the Table 1 cable.
    l_cr = np.pi * np.sqrt(1.1e11 * 5.73e-12 / 4.0)
    assert any(text == f"P0 = Pcr: l = {l_cr:.3g} m" for text in labels), labels
    # Colour scale: amplitudes span many decades, so it is logarithmic.
    assert ax.collections[0].norm.__class__.__name__ == "LogNorm"


def test_state_colours_come_from_the_flag_attributes(results):
    ds, _ = results["map"]
    styles = splot.state_styles(ds["state"])
    assert [s[1] for s in styles] == ds["state"].attrs["flag_meanings"].split()
    assert dict((s[1], s[2]) for s in styles)["diverged"] == splot.STATE_STYLES["diverged"][0]
    odd = ds["state"].copy()
    odd.attrs["flag_values"] = np.arange(10, dtype=np.int8)
    odd.attrs["flag_meanings"] = odd.attrs["flag_meanings"] + " wobbly sleepy"
    styles = splot.state_styles(odd)
    assert len(styles) == 10 and styles[-1][3] == "*" and styles[-1][2] != styles[-2][2]


def test_functions_take_an_axes_like_xarray(results):
    ds, _ = results["map"]
    fig = Figure(figsize=(10, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    assert splot.plot_map(ds, "settling_time", ax=left) is left
    assert splot.plot_state_map(ds, ax=right) is right
    line_ds, _ = results["line"]
    ax = fig.add_subplot(3, 3, 9)
    assert splot.plot_line(line_ds, "amplitude", ax=ax, add_legend=False) is ax
    assert splot.plot_line(ds, "amplitude", select={"frequency_ratio": 2.0}).get_xlabel() == \
        "span length between constraints [m]"


def test_span_lengths_stay_in_metres_where_the_overlays_are_placed(results):
    """Span lengths below 1 m are drawn in metres (not mm, as a displacement would be): the
    closed-form overlays (the buckling length, the paper's points) are placed in metres."""
    ds, _ = results["map"]
    short = ds.sel(length=ds["length"] < 1.0)
    assert short.sizes["length"] >= 2
    ax = splot.plot_line(short, "amplitude", select={"frequency_ratio": 2.0})
    assert ax.get_xlabel() == "span length between constraints [m]"
    xs = np.concatenate([np.asarray(line.get_xdata(), float) for line in ax.lines])
    assert np.isin(short["length"].values, xs).all() and np.all(xs <= 1.0)


def test_select_picks_values_and_names_what_is_wrong(results):
    ds, _ = results["map"]
    three = xr.concat([ds, ds], dim=xr.DataArray([0.01, 0.02], dims="damping_ratio",
                                                 name="damping_ratio"))
    three["state"] = three["state"].transpose("length", "frequency_ratio", "damping_ratio")
    with pytest.raises(sweep.UserError, match="3 swept axes .*--select damping_ratio=0.01"):
        splot.plot(three)
    def names(figures):          # drawn, or left out with a reason
        return set(figures) | set(figures.skipped)
    assert names(splot.plot(three, select={"damping_ratio": 0.02})) == \
        {"amplitude", "settling_time", "state"}
    assert names(splot.plot(three, select={"damping_ratio": 0.02, "length": 0.7})) == \
        {"amplitude", "settling_time"}
    with pytest.raises(sweep.UserError, match="'depth' is not a swept axis"):
        splot.plot(ds, select={"depth": 1.0})
    with pytest.raises(sweep.UserError, match="not a value of axis 'length'.*0.4, 0.7, 1, 1.4"):
        splot.plot(ds, select={"length": 0.5})


@pytest.mark.slow
def test_cli_plot_writes_png_and_svg(results, tmp_path):
    _, path = results["map"]
    done = cli("plot", str(path), "-o", str(tmp_path / "figs"), "--format", "png,svg",
               "--select", "length=1.0")
    assert done.returncode == 0, done.stderr
    written = done.stdout.split()
    assert sorted(Path(p).name for p in written) == sorted(
        f"map-length=1-{k}.{f}" for k in ("amplitude",) for f in ("png", "svg"))
    assert "settling_time: no figure" in done.stderr     # all NaN at t_end = 1 s
    image = mpimg.imread(tmp_path / "figs" / "map-length=1-amplitude.png")
    assert image.shape[:2] == (480, 640)
    assert (tmp_path / "figs" / "map-length=1-amplitude.svg").read_text().lstrip().startswith(
        "<?xml")


@pytest.mark.slow
def test_cli_plot_defaults_to_the_current_directory_without_a_display(results, tmp_path):
    _, path = results["longitudinal-one"]
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "MPLBACKEND",
                                                            "WAYLAND_DISPLAY")}
    done = cli("plot", str(path), cwd=tmp_path, env=env)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "longitudinal-one-histories.png", "longitudinal-one-snapshots.png"]


def test_importing_the_plot_module_picks_no_backend():
    code = ("import sys, sweep.plot; import matplotlib; "
            "print('matplotlib.pyplot' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=sweep_env(), timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


NOT_RESULTS = [
    (lambda p: p.write_text("this is not netCDF\n"), "not a readable netCDF file"),
    (lambda p: xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(p), "not a cable-sweep result"),
    (lambda p: None, "no such file"),
    (lambda p: p.mkdir(), "is a directory"),
]


@pytest.mark.parametrize("make, message", fast_first(NOT_RESULTS, NOT_RESULTS[0]))
def test_cli_plot_refuses_a_file_that_is_not_a_result(tmp_path, make, message):
    target = tmp_path / "thing.nc"
    make(target)
    done = cli("plot", str(target), "-o", str(tmp_path / "figs"))
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("sweep: error: ") and message in lines[0], \
        done.stderr
    assert not (tmp_path / "figs").exists()


BAD_PLOT_OPTIONS = [
    (["--select", "depth=1"], "'depth' is not a swept axis"),
    (["--select", "length=0.55"], "not a value of axis 'length'"),
    (["--select", "length"], "expected DIM=VALUE"),
    (["--select", "length=long"], "is not a number"),
    (["--format", "png,bogus"], "format 'bogus'"),
]


@pytest.mark.parametrize("args, message", fast_first(BAD_PLOT_OPTIONS, BAD_PLOT_OPTIONS[0]))
def test_cli_plot_bad_options_are_one_line(results, tmp_path, args, message):
    _, path = results["map"]
    done = cli("plot", str(path), "-o", str(tmp_path), *args)
    assert done.returncode == 2
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and message in lines[0], done.stderr


@pytest.mark.skipif(not EXAMPLES.is_dir(), reason="examples/ is not next to the tests")
@pytest.mark.parametrize("script, stem, keys", [
    ("length_sweep.py", "length_sweep", ("amplitude", "settling_time")),
    ("load_amplitude_sweep.py", "load_amplitude_sweep",
     ("amplitude", "settling_time", "time_series")),
    ("length_frequency_map.py", "length_frequency_map", ("amplitude", "settling_time", "state")),
    ("stepped_sine.py", "stepped_sine", ("amplitude", "absolute_acceleration_g")),
    ("qualification_sweep.py", "qualification_sweep", ("envelope", "peak_amplitude")),
])
@pytest.mark.slow
def test_examples_run_on_a_reduced_grid(tmp_path, script, stem, keys):
    env = sweep_env()
    done = subprocess.run([sys.executable, str(EXAMPLES / script), "--small", "--out",
                           str(tmp_path)], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    ds = xr.open_dataset(tmp_path / f"{stem}.nc")
    assert ds.attrs["cable_sweep_version"] and "state" in ds
    for key in keys:
        png = tmp_path / f"{stem}-{key}.png"
        if key in ds and splot.why_not_drawn(ds[key]) is not None:
            assert not png.exists() and f"{key}: no figure" in done.stderr, done.stderr
            continue
        assert png.is_file() and png.stat().st_size > 1000, png


# ------------------------------------------------------------- pictures that say something

def _draw(fig: Figure) -> Figure:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    FigureCanvasAgg(fig).draw()
    return fig


def _map_ds(template: xr.Dataset, amplitude: np.ndarray, state: np.ndarray) -> xr.Dataset:
    """A synthetic length x frequency_ratio result with the real state table and scene."""
    ny, nx = amplitude.shape
    dims = ("length", "frequency_ratio")
    return xr.Dataset(
        {"state": (dims, state.astype(np.int8), dict(template["state"].attrs)),
         "amplitude": (dims, amplitude, dict(template["amplitude"].attrs))},
        coords={"length": ("length", np.linspace(0.4, 1.4, ny), dict(template["length"].attrs)),
                "frequency_ratio": ("frequency_ratio", np.linspace(0.5, 3.0, nx),
                                    dict(template["frequency_ratio"].attrs))},
        attrs={k: template.attrs[k] for k in ("title", "scene", "model_kind", "coefficients",
                                              "cable_sweep_version")})


def _flag(ds: xr.Dataset, meaning: str) -> int:
    meanings = ds["state"].attrs["flag_meanings"].split()
    return int(np.atleast_1d(ds["state"].attrs["flag_values"])[meanings.index(meaning)])


def test_constant_or_all_nan_quantities_get_no_figure_and_say_why(results, caplog, tmp_path):
    ds, _ = results["line"]
    zero = ds.assign(settling_time=ds["settling_time"].copy(data=np.zeros(ds.sizes["length"])))
    figures = splot.plot(zero)
    assert "settling_time" not in figures and "amplitude" in figures
    assert figures.skipped["settling_time"] == "every point has the same value, 0 s"
    nan = ds.assign(amplitude=ds["amplitude"] * np.nan)
    assert splot.plot(nan).skipped["amplitude"] == "no point has a value (all NaN)"
    varying = ds.assign(settling_time=ds["settling_time"].copy(data=[0.1, 0.2, 0.3, 0.4]))
    assert "settling_time" in splot.plot(varying)
    # save() says it, one line per figure left out.
    with caplog.at_level("WARNING", logger="sweep.plot"):
        splot.save(figures, tmp_path, formats=())
    assert any("settling_time: no figure (every point has the same value, 0 s)" in r.message
               for r in caplog.records)
    # A map where every point has one state: no state map.
    mds, _ = results["map"]
    one = mds.assign(state=mds["state"].copy(data=np.full(mds["state"].shape,
                                                          _flag(mds, "decayed"))))
    figures = splot.plot(one)
    assert "state" not in figures and figures.skipped["state"] == "every point is decayed"


def test_no_tick_label_has_an_offset_and_near_constant_data_get_a_sensible_range(results):
    ds, _ = results["line"]
    # A dynamic amplification of 2 up to round-off, as the longitudinal runs give it.
    flat = ds.assign(amplitude=ds["amplitude"].copy(data=2e-3 + 1e-15 * np.arange(4)))
    figures = splot.plot(flat)
    for name, fig in figures.items():
        _draw(fig)
        for ax in fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                assert axis.get_offset_text().get_text() == "", (name, ax.get_ylabel())
    ax = figures["amplitude"].axes[0]
    low, high = ax.get_ylim()
    assert low == pytest.approx(1.9) and high == pytest.approx(2.1)      # 2 mm +- 5 %
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert any(text and float(text) == 2.0 for text in labels), labels


def test_dense_maps_mark_states_by_hatched_regions_outlined_on_cell_edges(results):
    from matplotlib.collections import PathCollection
    from matplotlib.contour import ContourSet
    template, _ = results["map"]
    ny, nx = 15, 20
    state = np.full((ny, nx), _flag(template, "decayed"))
    state[3:9, 4:12] = _flag(template, "unsettled")
    state[10:, 15:] = _flag(template, "modulated")
    amplitude = np.geomspace(1e-6, 1e-3, ny * nx).reshape(ny, nx)
    ds = _map_ds(template, amplitude, state)
    ax = splot.plot_map(ds, "amplitude")
    assert not [c for c in ax.collections if isinstance(c, PathCollection)], "markers drawn"
    contours = [c for c in ax.collections if isinstance(c, ContourSet)]
    hatched = [c for c in contours if c.hatches[0]]
    assert sorted(c.hatches[0] for c in hatched) == sorted(
        [splot._HATCHES["unsettled"], splot._HATCHES["modulated"]])
    handles = {t.get_text(): h for t, h in zip(ax.get_legend().get_texts(),
                                               ax.get_legend().legend_handles)}
    assert handles["unsettled (48)"].get_hatch() == splot._HATCHES["unsettled"]
    # The outlines run along cell edges (midway between the centres), not through centres.
    xe = splot._edges(ds["frequency_ratio"].values)
    ye = splot._edges(ds["length"].values)
    dx, dy = np.diff(xe).min(), np.diff(ye).min()
    outlines = [c for c in contours if not c.hatches[0]]
    assert len(outlines) == 2
    for c in outlines:
        for path in c.get_paths():
            for vx, vy in path.vertices:
                near_x = np.abs(xe - vx).min() < 0.01 * dx
                near_y = np.abs(ye - vy).min() < 0.01 * dy
                assert near_x or near_y, (vx, vy)
    # A small grid keeps one marker per marked cell.
    small = _map_ds(template, amplitude[:5, :5], state[3:8, 8:13])
    ax = splot.plot_map(small, "amplitude")
    marks = [c for c in ax.collections if isinstance(c, PathCollection)]
    assert sum(len(c.get_offsets()) for c in marks) == int((state[3:8, 8:13] != state[0, 0]).sum())


def test_a_noise_floor_is_one_no_response_colour_and_the_scale_spans_what_is_above(results):
    template, _ = results["map"]
    amplitude = np.geomspace(1e-12, 2e-3, 6 * 7).reshape(6, 7)        # m: nine decades
    ds = _map_ds(template, amplitude, np.full((6, 7), _flag(template, "decayed")))
    ax = splot.plot_map(ds, "amplitude")
    mesh = ax.collections[0]
    top_mm = 2.0
    assert mesh.norm.vmax == pytest.approx(top_mm)
    assert mesh.norm.vmin == pytest.approx(splot.FLOOR * top_mm)         # three decades
    below = amplitude * 1e3 < splot.FLOOR * top_mm
    colours = mesh.cmap(mesh.norm(amplitude.ravel() * 1e3))
    white = np.array([1.0, 1.0, 1.0, 1.0])
    assert np.all(colours[below.ravel()] == white)
    assert not np.any(np.all(colours[~below.ravel()] == white, axis=1))
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"no response, < {splot.FLOOR * top_mm:.2g} mm ({int(below.sum())})" in labels


def test_displacements_are_in_mm_everywhere(results):
    line, _ = results["line"]
    assert splot.plot_line(line, "amplitude").get_ylabel().endswith("[mm]")
    mds, _ = results["map"]
    fig = splot.plot_map(mds, "amplitude").figure
    assert fig.axes[-1].get_ylabel().endswith("[mm]")                     # the colour bar
    fig = splot.plot_time_series(line)
    assert fig.get_supylabel().endswith("[mm]")
    one, _ = results["longitudinal-one"]
    fig = splot.plot_histories(one)
    assert fig.axes[0].get_ylabel().replace("\n", " ").endswith("[mm]")
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(t.startswith("exact peak 2 P0 l/EA = ") and t.endswith(" mm") for t in texts)
    fig = splot.plot_snapshots(one)
    assert fig.axes[0].get_title().endswith("[mm]")


def test_every_figure_has_the_load_case_in_a_footer(results):
    for name in ("line", "map", "longitudinal-one"):
        ds, _ = results[name]
        for key, fig in splot.plot(ds).items():
            texts = " ".join(t.get_text() for t in fig.texts).replace("\n", " ")
            assert "Load case:" in texts, (name, key)
            assert "P0 = 4 N" in texts, texts
            if name == "longitudinal-one":
                assert "4 transits" in texts and "40 intervals" in texts, texts
            else:
                assert "damping ratio 0.02" in texts and "t_end = 1 s" in texts, texts
                assert "q(0) = 0.1 mm" in texts, texts
    # A selected axis value is the value in the footer; a swept one is left out.
    mds, _ = results["map"]
    text = splot.footer(splot.select_points(mds, {"frequency_ratio": 2.2}))
    assert "W/w1 = 2.2" in text and "l = " not in text


def test_the_paper_fig5_case_marks_the_papers_amplitudes(results):
    ds, _ = results["line"]
    paper = ds.assign_coords(length=[0.5, 0.7, 0.85, 1.0]).assign_attrs(
        coefficients="paper", scene=ds.attrs["scene"].replace("frequency_ratio = 2.0",
                                                              "frequency_ratio = 1.0"))
    assert "frequency_ratio = 1.0" in paper.attrs["scene"]
    ax = splot.plot_line(paper, "amplitude")
    diamonds = [c for c in ax.collections if c.get_paths() and
                len(c.get_offsets()) == 4 and not c.get_facecolor().size]
    assert len(diamonds) == 1
    np.testing.assert_allclose(diamonds[0].get_offsets(),
                               [[0.5, 4.1], [0.7, 3.8], [0.85, 3.4], [1.0, 3.0]])
    fig = splot.plot_time_series(paper)
    assert [float(line.get_ydata()[0]) for line in fig.axes[0].lines[1:]] == \
        pytest.approx([4.1, -4.1])
    # Not the paper's case: no paper points.
    for other in (ds.assign_coords(length=[0.5, 0.7, 0.85, 1.0]),        # consistent model
                  paper.assign_attrs(scene=ds.attrs["scene"])):             # W/w1 = 2
        ax = splot.plot_line(other, "amplitude")
        assert not any("paper" in t.get_text() for t in ax.get_legend().get_texts())


def test_a_selection_is_in_the_file_names(results, tmp_path):
    mds, _ = results["map"]
    first = splot.save(splot.plot(mds, select={"length": 0.7}), tmp_path, prefix="map-")
    second = splot.save(splot.plot(mds, select={"length": 1.0}), tmp_path, prefix="map-")
    assert {p.name for p in first} & {p.name for p in second} == set()
    assert all(p.name.startswith("map-length=0.7-") for p in first)
    assert splot._select_tag({"load_amplitude": 4.0, "weird key/x": -1.5}) == \
        "load_amplitude=4-weird_key_x=-1.5"
    assert [p.name for p in splot.save(splot.plot(mds), tmp_path, prefix="map-")][0] == \
        "map-amplitude.png"


def test_state_map_of_a_longitudinal_two_axis_result_with_mixed_states(tmp_path):
    """Longitudinal flags are 0, 8, 5, 7 (one state table for every kind): the state map's
    colour boundaries must still increase (the map raised 'bins must be monotonically
    increasing' before the styles were sorted)."""
    ds = _result("""
name = "long-mixed"
[model]
kind = "longitudinal"
[load]
type = "constant"
[solver]
intervals = 20
t_end = 0.0023          # s: 323 levels at 0.5 m, 162 at 1 m
max_steps = 200         # the 0.5 m spans stop at max_steps_reached
[axes]
length = [0.5, 1.0]
load_amplitude = [1.0, 2.0]
""", tmp_path / "mixed.nc")
    assert set(np.unique(ds["state"].values)) == {7, 8}
    figures = splot.plot(ds)
    state = figures["state"]
    _draw(state)
    labels = [t.get_text() for t in state.legends[0].get_texts()] if state.legends else [
        t.get_text() for ax in state.axes for lg in [ax.get_legend()] if lg for t in lg.get_texts()]
    assert any("max_steps_reached" in t for t in labels) and any("completed" in t for t in labels)


def test_a_level_in_db_is_labelled_db_though_its_cf_units_are_one():
    """UDUNITS (so CF) has no decibel: base_asd_scale's units are '1' and its long name says
    dB; the axis label shows [dB], and a plain ratio stays without brackets."""
    from sweep import schema
    from sweep.plot.labels import label
    key = schema.BY_DOTTED["base.asd_scale"]
    level = xr.DataArray([0.0], dims="base_asd_scale", name="base_asd_scale",
                         attrs={"units": key.units, "long_name": key.long_name})
    assert key.units == "1" and label(level).endswith("[dB]")
    ratio = xr.DataArray([1.0], dims="x", name="x", attrs={"units": "1", "long_name": "ratio"})
    assert label(ratio) == "ratio"


@pytest.mark.parametrize("values, log", [([0.5, 7.88, 100.0], True), ([1.0, 50.0, 99.0], False),
                                         ([1.0, 2.0, 4.0, 8.0], True), ([1.0, 2.0, 3.0], False),
                                         ([0.01, 100.0], True), ([1.0, 5.0], False)])
def test_an_axis_over_decades_is_drawn_log(values, log):
    """A coordinate is drawn on a log axis when geometric, or, not arithmetic, spanning two
    decades (a reviewer's clamp stiffnesses 0.5, 7.88, 100 N m/rad: the first two cells were
    slivers on a linear axis), or two values a decade apart; else linear."""
    from sweep.plot.style import _is_log_spaced
    assert _is_log_spaced(np.array(values)) is log


def test_an_axis_from_zero_over_decades_is_drawn_symlog_with_cells_around_each_value():
    """A tester: clamp_axial_stiffness = [0, 1e4, 1e6] N/m (0: the cable slides) was drawn on
    a linear axis, two of its three cells slivers. With one 0 and positive values drawn log,
    the axis is symlog, linear up to the smallest positive value; each cell holds its value,
    the cells meet, and matplotlib's symlog transform spaces 0, 1e4 and 1e6 as the edges
    assume (0 -> 1e4 as long as one decade)."""
    from sweep.plot.style import symlog_threshold
    values = np.array([0.0, 1e4, 1e6])
    assert symlog_threshold(values) == 1e4
    assert symlog_threshold(np.array([1e6, 1e4, 0.0])) == 1e4
    for linear in ([0.0, 1.0, 2.0], [0.0, 5.0, 9.0], [1.0, 1e2, 1e4], [0.0, 1e4]):
        assert symlog_threshold(np.array(linear)) is None, linear
    edges = splot._edges(values)
    assert np.all(edges[:-1] < values) and np.all(values < edges[1:])
    np.testing.assert_allclose(edges, [-5e3, 5e3, 1e5, 1e7], rtol=1e-12)
    ds = xr.Dataset({"amplitude": (("clamp_axial_stiffness", "length"), np.ones((3, 2)))},
                    coords={"clamp_axial_stiffness": values, "length": [0.2, 0.3]})
    ax = Figure().add_subplot()
    splot.maps._mesh(ax, ds, "length", "clamp_axial_stiffness", ds.amplitude.values)
    assert ax.get_yscale() == "symlog"
    shown = ax.transData.transform(np.column_stack([[0.25] * 3, values]))[:, 1]
    assert 2.0 * (shown[1] - shown[0]) == pytest.approx(shown[2] - shown[1], rel=1e-9)
    assert [t.get_text() for t in ax.get_yticklabels()] == ["0", "10000", "1e+06"]


def test_the_span_loads_get_a_strain_figure_and_two_stiffnesses_decades_apart_a_log_axis():
    """A span that reports its loads gets 'max_strain' (the quantity `sweep design
    --max-strain` limits; harness-clamps had no strain figure), and an axis of two clamp
    stiffnesses four decades apart is drawn on a log scale (a linear one put the cells' edges
    below zero: negative stiffness labels)."""
    text = ('[cable]\ndiameter = "2.76 mm"\ndamping_ratio = 0.02\n'
            '[clamps]\nrotation = "elastic"\n[base]\nacceleration_g = 1.0\n'
            'frequency_ratio = 0.8\n[solver]\nt_end = 1.0\n[axes]\nlength = [0.2, 0.3, 0.4]\n'
            'clamp_rotational_stiffness = [0.01, 100.0]\n')
    ds = sweep.run(sweep.load_scene_text(text), progress=False)
    figures = splot.plot(ds)
    assert "max_strain" in figures
    ax = figures["max_strain"].axes[0]
    scales = {ax.get_xscale(), ax.get_yscale()}
    labels = ax.get_xlabel() + ax.get_ylabel()
    assert "log" in scales and "rotational stiffness" in labels
    for fig in figures.values():
        fig.clf()


@pytest.mark.parametrize("clamps, says", [
    ("", "pinned ends"),
    ('rotation = "clamped"\naxial_stiffness = 0.0', "clamped ends, sliding axially"),
    ('rotation = "elastic"\nrotational_stiffness = 0.5', "elastic ends (k_t = 0.5 N m/rad)"),
])
def test_the_footer_says_what_the_clamps_hold(clamps, says):
    """A clamped map and an elastic one differ by up to 2.3x in f1 and amplitude: the load
    case says which ends they are (a reviewer found the same footer on both)."""
    text = f"[model]\nmodes = 1\n[clamps]\n{clamps}\n[base]\nacceleration_g = 1.0\n" \
           "frequency = 20.0\n[axes]\nlength = [0.3, 0.4]\n"
    ds = xr.Dataset({"state": ("length", [2, 2])}, coords={"length": [0.3, 0.4]},
                    attrs={"scene": text})
    assert says in splot.footer(ds)


def test_a_shortened_axis_label_keeps_its_ratio_symbol():
    """A long name too long for an axis falls back to the variable's name; a ratio keeps its
    symbol (a stepped sweep's axis read 'base frequency ratio', not of what)."""
    from sweep.plot.labels import label
    da = xr.DataArray([1.0], dims="x", name="base_frequency_ratio", attrs={
        "units": "1", "long_name": "base excitation frequency over the unloaded span's first "
                                   "natural frequency, f/f1"})
    assert label(da) == "base frequency ratio, f/f1"


def test_a_stepped_sweeps_hint_never_asks_to_fix_its_stepped_axis():
    """A result with one axis too many for a figure names values to select; a stepped sweep's
    hint must not name its continuation axis (fixing it leaves no branch to draw), which it
    did where that axis came last (a reviewer's length x clamp stiffness x frequency)."""
    dims = ("length", "clamp_rotational_stiffness", "base_frequency_ratio")
    ds = xr.Dataset({"amplitude": (dims, np.ones((2, 2, 3))),
                     "state": (dims, np.zeros((2, 2, 3), dtype="i1"),
                               {"flag_values": np.array([0], dtype="i1"),
                                "flag_meanings": "steady"})},
                    coords={"length": [0.3, 0.4], "clamp_rotational_stiffness": [1.0, 100.0],
                            "base_frequency_ratio": [0.8, 1.0, 1.2]},
                    attrs={"continuation_axis": "base_frequency_ratio"})
    with pytest.raises(sweep.errors.UserError) as info:
        splot.select_points(ds)
    assert "--select clamp_rotational_stiffness=1" in str(info.value)
    assert "--select base_frequency_ratio" not in str(info.value)
