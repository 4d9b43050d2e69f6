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

PACKAGE_ROOT = Path(sweep.__file__).resolve().parents[1]
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

LINE = """
name = "plot-line"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
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
    env = {**(env if env is not None else os.environ), "PYTHONPATH": str(PACKAGE_ROOT)}
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
    assert set(figures) == keys
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


def test_select_picks_values_and_names_what_is_wrong(results):
    ds, _ = results["map"]
    three = xr.concat([ds, ds], dim=xr.DataArray([0.01, 0.02], dims="damping_ratio",
                                                 name="damping_ratio"))
    three["state"] = three["state"].transpose("length", "frequency_ratio", "damping_ratio")
    with pytest.raises(sweep.UserError, match="3 swept axes .*--select damping_ratio=0.01"):
        splot.plot(three)
    assert set(splot.plot(three, select={"damping_ratio": 0.02})) == \
        {"amplitude", "settling_time", "state"}
    assert set(splot.plot(three, select={"damping_ratio": 0.02, "length": 0.7})) == \
        {"amplitude", "settling_time"}
    with pytest.raises(sweep.UserError, match="'depth' is not a swept axis"):
        splot.plot(ds, select={"depth": 1.0})
    with pytest.raises(sweep.UserError, match="not a value of axis 'length'.*0.4, 0.7, 1, 1.4"):
        splot.plot(ds, select={"length": 0.5})


def test_cli_plot_writes_png_and_svg(results, tmp_path):
    _, path = results["map"]
    done = cli("plot", str(path), "-o", str(tmp_path / "figs"), "--format", "png,svg",
               "--select", "length=1.0")
    assert done.returncode == 0, done.stderr
    written = done.stdout.split()
    assert sorted(Path(p).name for p in written) == sorted(
        f"map-{k}.{f}" for k in ("amplitude", "settling_time") for f in ("png", "svg"))
    image = mpimg.imread(tmp_path / "figs" / "map-amplitude.png")
    assert image.shape[:2] == (480, 640)
    assert (tmp_path / "figs" / "map-amplitude.svg").read_text().lstrip().startswith("<?xml")


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
                          env={**os.environ, "PYTHONPATH": str(PACKAGE_ROOT)}, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


@pytest.mark.parametrize("make, message", [
    (lambda p: p.write_text("this is not netCDF\n"), "not a readable netCDF file"),
    (lambda p: xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(p), "not a cable-sweep result"),
    (lambda p: None, "no such file"),
    (lambda p: p.mkdir(), "is a directory"),
])
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


@pytest.mark.parametrize("args, message", [
    (["--select", "depth=1"], "'depth' is not a swept axis"),
    (["--select", "length=0.55"], "not a value of axis 'length'"),
    (["--select", "length"], "expected DIM=VALUE"),
    (["--select", "length=long"], "is not a number"),
    (["--format", "png,bogus"], "format 'bogus'"),
])
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
])
def test_examples_run_on_a_reduced_grid(tmp_path, script, stem, keys):
    env = {**os.environ, "PYTHONPATH": str(PACKAGE_ROOT)}
    done = subprocess.run([sys.executable, str(EXAMPLES / script), "--small", "--out",
                           str(tmp_path)], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    ds = xr.open_dataset(tmp_path / f"{stem}.nc")
    assert ds.attrs["cable_sweep_version"] and "state" in ds
    for key in keys:
        png = tmp_path / f"{stem}-{key}.png"
        assert png.is_file() and png.stat().st_size > 1000, png
