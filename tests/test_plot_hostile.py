"""`sweep plot` on hostile files: each is refused in one line (exit 2, no traceback) with no
figure written, or plotted correctly; figures are written all or none."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import sweep
import sweep.files
from sweep import cli
from sweep import plot as splot

from conftest import sweep_env


LINE = """
name = "hostile-line"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
frequency_ratio = 2.0
[initial]
displacement = 1e-4
[axes]
length = [0.3, 0.6, 0.9]
[solver]
t_end = 0.1
[outputs]
time_series = true
"""


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    """A tiny real result (3 points with time series): its path and the Dataset read back."""
    path = tmp_path_factory.mktemp("result") / "line.nc"
    sweep.run(sweep.load_scene_text(LINE), output=path, progress=False)
    with xr.open_dataset(path) as ds:
        return path, ds.load()


def _main(args, capsys):
    rc = cli.main(["plot", *map(str, args)])
    captured = capsys.readouterr()
    return rc, captured.out, captured.err


def _refused(args, out_dir: Path, capsys, message: str) -> str:
    rc, out, err = _main([*args, "-o", out_dir], capsys)
    lines = err.splitlines()
    assert rc == 2 and out == "", (rc, out, err)
    assert len(lines) == 1 and lines[0].startswith("sweep: error: ") and message in lines[0], err
    assert not out_dir.exists() or not any(out_dir.iterdir())
    return lines[0]


def _subprocess(*args, timeout=120):
    env = sweep_env()
    return subprocess.run([sys.executable, "-m", "sweep.cli", "plot", *map(str, args)],
                          capture_output=True, text=True, env=env, timeout=timeout)


def _with_scene(ds: xr.Dataset, text: str) -> xr.Dataset:
    return ds.assign_attrs(scene=text)


def _state(ds: xr.Dataset, values=None, **attrs) -> xr.Dataset:
    state = ds["state"].copy(data=ds["state"].values if values is None else values)
    state.attrs.update(attrs)
    return ds.assign(state=state)


def _kind_swapped(ds):
    return _with_scene(ds, ds.attrs["scene"].replace('kind = "transverse"',
                                                     'kind = "longitudinal"'))


# Each: (what, make a hostile Dataset from the real one, words of the one line).
CASES = [
    ("missing coordinate", lambda ds: ds.drop_vars("length"), "no coordinate variable"),
    ("float state", lambda ds: ds.assign(state=ds["state"].astype(float)),
     "not integer state flags"),
    ("text state", lambda ds: ds.assign(state=ds["state"].astype(str)),
     "not integer state flags"),
    ("flags of different lengths",
     lambda ds: _state(ds, flag_meanings=" ".join(ds["state"].attrs["flag_meanings"].split()[:-1])),
     "must pair up"),
    ("float flag values",
     lambda ds: _state(ds, flag_values=ds["state"].attrs["flag_values"].astype(float)),
     "not 1 to 64 integers"),
    ("flag values repeated",
     lambda ds: _state(ds, flag_values=np.r_[0, ds["state"].attrs["flag_values"][:-1]]),
     "repeat a value"),
    ("state outside its flags", lambda ds: _state(ds, np.full(3, 99, np.int8)),
     "not among its flag_values"),
    ("NaN coordinate", lambda ds: ds.assign_coords(length=[0.3, np.nan, 0.9]),
     "NaN, infinite"),
    ("infinite coordinate", lambda ds: ds.assign_coords(length=[0.3, np.inf, 0.9]),
     "NaN, infinite"),
    ("text coordinate", lambda ds: ds.assign_coords(length=["a", "b", "c"]), "not numbers"),
    ("repeated axis values", lambda ds: ds.assign_coords(length=[0.3, 0.6, 0.3]),
     "repeated values"),
    ("zero-length axis", lambda ds: ds.isel(length=slice(0, 0)), "axis 'length' has no values"),
    ("zero-length time", lambda ds: ds.isel(elapsed_time=slice(0, 0)),
     "axis 'elapsed_time' has no values"),
    ("scene not TOML", lambda ds: _with_scene(ds, "[model\nkind = "), "not valid TOML"),
    ("scene of another kind", _kind_swapped, "longitudinal scene"),
    ("scene section not a table", lambda ds: _with_scene(ds, "load = 5\n"), "not a table"),
    ("scene value of the wrong type",
     lambda ds: _with_scene(ds, ds.attrs["scene"].replace("t_end = 0.1", 't_end = "soon"')),
     "solver.t_end"),
    ("scene too deep", lambda ds: _with_scene(ds, "x = " + "[" * 5000 + "]" * 5000),
     "not valid TOML"),
    ("scene not text", lambda ds: ds.assign_attrs(scene=np.arange(3)), "not text"),
    ("title not text", lambda ds: ds.assign_attrs(title=np.arange(3)), "not text"),
    ("amplitude of text", lambda ds: ds.assign(amplitude=ds["amplitude"].astype(str)),
     "variable 'amplitude' holds"),
    ("amplitude over another dimension",
     lambda ds: ds.assign(amplitude=("other", [1.0, 2.0])), "lies over (other)"),
    ("history without the swept axis",
     lambda ds: ds.assign(displacement=ds["displacement"].isel(length=0, drop=True)),
     "'displacement' lies over (elapsed_time)"),
    ("mathtext units",
     lambda ds: ds.assign(amplitude=ds["amplitude"].assign_attrs(units="$\\frac{$")),
     "holds '$'"),
    ("control characters in long_name",
     lambda ds: ds.assign(amplitude=ds["amplitude"].assign_attrs(long_name="a\x1b[2Jb")),
     "control characters"),
    ("1 MB units", lambda ds: ds.assign(amplitude=ds["amplitude"].assign_attrs(units="m" * 2**20)),
     "attribute 'units' of variable 'amplitude' is 1,048,576 characters"),
    ("huge long_name",
     lambda ds: ds.assign(amplitude=ds["amplitude"].assign_attrs(long_name="x" * 100_000)),
     "attribute 'long_name' of variable 'amplitude'"),
    ("huge flag_meanings", lambda ds: _state(ds, flag_meanings="a " * 50_000),
     "attribute 'flag_meanings' of variable 'state'"),
]


@pytest.mark.parametrize("what, make, message", CASES, ids=[c[0] for c in CASES])
def test_a_malformed_result_is_one_line_and_writes_nothing(result, tmp_path, capsys, what,
                                                           make, message):
    _, ds = result
    hostile = make(ds.copy())
    for var in hostile.variables.values():
        var.encoding = {}                      # as built, not as first stored
    path = tmp_path / "hostile.nc"
    hostile.to_netcdf(path, engine="netcdf4")
    _refused([path], tmp_path / "figs", capsys, message)
    # The same from Python: plot() checks the Dataset before drawing.
    with pytest.raises(sweep.UserError, match="the result: "):
        splot.plot(hostile)


def test_a_non_monotonic_axis_is_plotted_in_order(result, tmp_path, capsys):
    _, ds = result
    shuffled = ds.isel(length=[2, 0, 1])
    path = tmp_path / "shuffled.nc"
    shuffled.to_netcdf(path, engine="netcdf4")
    rc, out, err = _main([path, "-o", tmp_path / "figs"], capsys)
    assert rc == 0, err
    assert sorted(Path(p).name for p in out.split()) == [
        "shuffled-amplitude.png", "shuffled-time_series.png"]
    ax = splot.plot(shuffled)["amplitude"].axes[0]
    x, y = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    np.testing.assert_allclose(x / x[0], [1.0, 2.0, 3.0])               # 0.3, 0.6, 0.9 m
    np.testing.assert_allclose(y, ds["amplitude"].values * 1e3)          # in mm, in order


def _truncated(src: Path, dst: Path) -> None:
    data = src.read_bytes()
    dst.write_bytes(data[: len(data) // 2])


def _header_flipped(src: Path, dst: Path) -> None:
    data = bytearray(src.read_bytes())
    for i in range(8, 2048, 7):
        data[i] ^= 0xFF
    dst.write_bytes(bytes(data))


@pytest.mark.parametrize("make, message", [
    (lambda src, dst: dst.write_bytes(b""), "is an empty file"),
    (lambda src, dst: dst.write_text("x,y\n1,2\n"), "no netCDF or HDF5 signature"),
    (lambda src, dst: dst.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 8),
     "not a readable netCDF file"),
    (_truncated, "not a readable netCDF file"),
    (_header_flipped, "not a readable netCDF file"),
    (lambda src, dst: dst.mkdir(), "is a directory"),
    (lambda src, dst: dst.symlink_to(dst.parent / "nowhere.nc"), "no such file"),
], ids=["empty", "text", "HDF5 not netCDF", "truncated", "corrupted header", "directory",
        "dangling link"])
def test_a_file_that_is_not_a_readable_result_is_one_line(result, tmp_path, capsys, make,
                                                          message):
    path = tmp_path / "thing.nc"
    make(result[0], path)
    _refused([path], tmp_path / "figs", capsys, message)


def test_huge_declared_dimensions_are_refused_before_reading(tmp_path, capsys):
    import netCDF4
    path = tmp_path / "huge.nc"
    with netCDF4.Dataset(path, "w") as nc:
        nc.cable_sweep_version = "0.1.0"
        nc.createDimension("length", 2**22)
        nc.createDimension("elapsed_time", 2**22)
        nc.createVariable("length", "f8", ("length",))
        state = nc.createVariable("state", "i1", ("length",))
        state.flag_values = np.arange(2, dtype=np.int8)
        state.flag_meanings = "decayed steady"
        nc.createVariable("displacement", "f8", ("length", "elapsed_time"), zlib=True,
                          chunksizes=(1024, 1024))
    assert path.stat().st_size < 100_000          # 128 TiB declared, nothing stored
    _refused([path], tmp_path / "figs", capsys, "GiB of data")


@pytest.mark.slow
def test_a_small_file_declaring_gigabytes_of_zeros_is_refused_before_inflating(tmp_path,
                                                                              capsys):
    """A file of a few MiB whose compressed variable inflates to 1 GiB of zeros (within the
    machine's memory, so the memory check alone lets it through): refused from its declared
    size against the file's, for plot and design alike, without reading the variable."""
    import netCDF4
    path = tmp_path / "bomb.nc"
    n = 2**14
    with netCDF4.Dataset(path, "w") as nc:
        nc.cable_sweep_version = "0.1.0"
        nc.createDimension("length", n)
        nc.createDimension("elapsed_time", 2**13)
        length = nc.createVariable("length", "f8", ("length",))
        length[:] = np.linspace(0.1, 1.0, n)
        length.units = "m"
        state = nc.createVariable("state", "i1", ("length",))
        state.flag_values = np.arange(2, dtype=np.int8)
        state.flag_meanings = "decayed steady"
        zeros = nc.createVariable("displacement", "f8", ("length", "elapsed_time"), zlib=True,
                                  complevel=9, chunksizes=(256, 2**13))
        for i in range(0, n, 256):
            zeros[i:i + 256, :] = 0.0
    assert path.stat().st_size < 8 * 2**20                   # 1 GiB declared
    _refused([path], tmp_path / "figs", capsys, "times it")
    assert cli.main(["design", str(path), "--min-frequency", "10"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "times it" in err, err


# ------------------------------------------------------------- as real processes

def _assert_refused(done: subprocess.CompletedProcess, fragment: str, figs: Path) -> None:
    """`sweep plot` exited 2 with one line on stderr holding `fragment`, and wrote no figures."""
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and fragment in lines[0], done.stderr
    assert not figs.exists()


def test_a_fifo_is_refused_without_opening_it(tmp_path):
    fifo = tmp_path / "result.nc"
    os.mkfifo(fifo)
    _assert_refused(_subprocess(fifo, "-o", tmp_path / "figs", timeout=120),
                    "is a FIFO, not a regular file", tmp_path / "figs")


def test_a_10_mb_attribute_is_refused_in_one_line(result, tmp_path):
    _, ds = result
    path = tmp_path / "big.nc"
    ds.assign_attrs(scene=ds.attrs["scene"] + "#" * 10 * 2**20).to_netcdf(path, engine="netcdf4")
    _assert_refused(_subprocess(path, "-o", tmp_path / "figs"), "attribute 'scene' is 10,4",
                    tmp_path / "figs")


def test_a_truncated_file_is_refused_in_one_line(result, tmp_path):
    path = tmp_path / "cut.nc"
    _truncated(result[0], path)
    _assert_refused(_subprocess(path, "-o", tmp_path / "figs"), "not a readable netCDF file",
                    tmp_path / "figs")


# ------------------------------------------------------------- all figures or none

def test_a_figure_that_fails_to_draw_leaves_no_file(result, tmp_path):
    _, ds = result
    figures = splot.plot(ds)
    bad = Figure()
    bad.text(0.5, 0.5, r"$\frac{$")                 # mathtext that does not parse
    figures["zzz_bad"] = bad
    with pytest.raises(ValueError):
        splot.save(figures, tmp_path / "figs", formats=("png", "svg"))
    assert not (tmp_path / "figs").exists()


@pytest.mark.parametrize("stage", ["temporary", "rename"])
def test_a_failure_while_writing_removes_what_the_call_wrote(result, tmp_path, monkeypatch,
                                                             stage):
    _, ds = result
    figures = splot.plot(ds)
    out = tmp_path / "figs"
    out.mkdir()
    (out / "keep.txt").write_text("not ours")
    calls = {"n": 0}
    target = ((sweep.files.tempfile, "mkstemp") if stage == "temporary"
              else (splot.figures.os, "replace"))
    real = getattr(*target)

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(*args, **kwargs)

    monkeypatch.setattr(*target, failing)
    with pytest.raises(sweep.UserError, match="could not be written .*No space left"):
        splot.save(figures, out, formats=("png", "svg"))
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]


def test_figures_are_written_with_ordinary_permissions_and_no_temporaries(result, tmp_path):
    _, ds = result
    paths = splot.save(splot.plot(ds), tmp_path, formats=("png",))
    mask = os.umask(0)
    os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths)
    for p in paths:
        assert p.stat().st_mode & 0o777 == 0o666 & ~mask


def test_a_result_too_large_for_memory_is_one_plot_line(monkeypatch, capsys, tmp_path):
    """MemoryError while plotting says the result does not fit (not the sweep's advice)."""
    from sweep import cli

    def no_memory(*args, **kwargs):
        raise MemoryError
    monkeypatch.setattr(cli, "_plot", no_memory, raising=True)
    assert cli.main(["plot", str(tmp_path / "big.nc"), "-o", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the result does not fit in memory" in err[0]
