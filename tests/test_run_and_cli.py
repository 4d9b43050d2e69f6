"""End to end: scenes -> Dataset -> netCDF, and the `sweep` command as a user runs it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.kernels import metrics as km

from conftest import sweep_env


SMALL = """
name = "small"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
[initial]
displacement = 1e-3
[axes]
length = [0.4, 0.6]
frequency_ratio = [1.0, 2.0, 2.5]
[solver]
t_end = 2.0
"""


def cli(*args, cwd=None):
    env = sweep_env()
    return subprocess.run([sys.executable, "-m", "sweep.cli", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=600)


def test_python_dash_m_sweep_is_the_console_script(tmp_path):
    """`python -m sweep` for an environment whose scripts are not on PATH: the same commands
    and exit codes as `sweep` (a bad scene key: one line, exit 2)."""
    env = sweep_env()
    ok = subprocess.run([sys.executable, "-m", "sweep", "--version"], capture_output=True,
                        text=True, env=env, timeout=600)
    assert ok.returncode == 0 and ok.stdout.startswith("sweep (cable-sweep) ")
    bad = subprocess.run([sys.executable, "-m", "sweep", "run", "paper-fig5", "-o", "x.nc",
                          "--set", "cable.lenght=1"], capture_output=True, text=True, env=env,
                         timeout=600, cwd=tmp_path)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "x.nc").exists()


def test_paper_fig5_amplitudes():
    """Within 10 % of the paper's 4.1, 3.8, 3.4, 3.0 mm; and docs/model.md's re-run of Eq.32."""
    ds = sweep.run(sweep.load_scene("paper-fig5"), progress=False)
    amp_mm = ds["amplitude"].values * 1e3
    np.testing.assert_allclose(amp_mm, [4.1, 3.8, 3.4, 3.0], rtol=0.10)
    np.testing.assert_allclose(amp_mm, [4.10, 3.67, 3.42, 3.22], atol=0.006)
    assert ds["displacement"].dims == ("length", "elapsed_time")
    assert ds["elapsed_time"].values[-1] == pytest.approx(5.0)


def test_an_undamped_span_has_no_settling_time():
    """docs/model.md sec. 3: never a settling time for an undamped response. paper-fig5
    (Eq.32, undamped) is steady from t = 0, which the envelope test reads as 0 s: NaN instead;
    with damping the same span decays to its static state and has one (the last time
    |q| > tol * peak, found by the kernels: positive and before t_end)."""
    scene = sweep.load_scene("paper-fig5", overrides={"axes.length": [0.5],
                                                      "axes.damping_ratio": [0.0, 0.3]})
    ds = sweep.run(scene, progress=False).squeeze()
    undamped, damped = ds["settling_time"].values
    assert np.isnan(undamped) and ds["state"].values[0] == km.STEADY
    assert 0.0 < damped < 5.0 and ds["state"].values[1] == km.DECAYED


def test_dataset_layout_units_and_netcdf_round_trip(tmp_path):
    scene = sweep.load_scene_text(SMALL)
    out = tmp_path / "small.nc"
    ds = sweep.run(scene, output=out, progress=False)
    assert ds["state"].dims == ("length", "frequency_ratio")
    assert ds["natural_frequency"].dims == ("length",)          # depends on length only
    for name in list(ds.data_vars) + list(ds.coords):
        assert ds[name].attrs.get("units") is not None, name
        assert ds[name].attrs.get("long_name"), name
    back = xr.open_dataset(out)
    try:
        assert back.attrs["Conventions"].startswith("CF-")
        assert back.attrs["cable_sweep_version"]
        again = sweep.load_scene_text(back.attrs["scene"])
        assert again == scene
        flags = back["state"].attrs
        assert list(flags["flag_values"]) == list(km.TRANSVERSE_STATES)
        assert flags["flag_meanings"].split() == [km.STATE_MEANINGS[f]
                                                  for f in km.TRANSVERSE_STATES]
        for name in ds.variables:
            np.testing.assert_array_equal(back[name].values, ds[name].values)
            assert back[name].attrs["units"] == ds[name].attrs["units"]
    finally:
        back.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.nc"]


def test_only_what_is_asked_is_stored():
    scene = sweep.load_scene_text(SMALL, overrides={"outputs.settling_time": False,
                                                    "outputs.solver_stats": False,
                                                    "outputs.amplitude": False})
    ds = sweep.run(scene, progress=False)
    assert "settling_time" not in ds and "n_steps" not in ds and "amplitude" not in ds
    assert "displacement" not in ds and "elapsed_time" not in ds.coords
    assert "state" in ds and "peak_amplitude" in ds


def test_axis_order_follows_the_scene_and_results_do_not_depend_on_it():
    a = sweep.run(sweep.load_scene_text(SMALL), progress=False)
    swapped = SMALL.replace("length = [0.4, 0.6]\nfrequency_ratio = [1.0, 2.0, 2.5]",
                            "frequency_ratio = [1.0, 2.0, 2.5]\nlength = [0.4, 0.6]")
    b = sweep.run(sweep.load_scene_text(swapped), progress=False)
    assert b["state"].dims == ("frequency_ratio", "length")
    for name in ("state", "amplitude", "settling_time", "n_steps"):
        np.testing.assert_array_equal(a[name].values, b[name].transpose(*a[name].dims).values)


def test_existing_output_is_refused_before_any_work(tmp_path):
    out = tmp_path / "x.nc"
    out.write_text("keep me")
    with pytest.raises(sweep.UserError, match="exists"):
        sweep.run(sweep.load_scene_text(SMALL), output=out)
    assert out.read_text() == "keep me"
    sweep.run(sweep.load_scene_text(SMALL), output=out, overwrite=True, progress=False)
    xr.open_dataset(out).close()


def test_failed_write_leaves_no_partial_file_and_keeps_the_results(tmp_path, monkeypatch):
    original = xr.Dataset.to_netcdf

    def boom(self, *args, **kwargs):
        raise RuntimeError("disk on fire")
    monkeypatch.setattr(xr.Dataset, "to_netcdf", boom)
    # netCDF4 reports its library's failures as RuntimeError: one UserError naming the file,
    # the kept chunks and --resume.
    with pytest.raises(sweep.UserError, match=r"could not be written \(disk on fire\).*--resume"):
        sweep.run(sweep.load_scene_text(SMALL), output=tmp_path / "y.nc", progress=False)
    # No partial netCDF, no temporary file: only the finished chunks, kept for a resume.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["y.nc.chunks"]
    monkeypatch.setattr(xr.Dataset, "to_netcdf", original)
    ds = sweep.run(sweep.load_scene_text(SMALL), output=tmp_path / "y.nc", resume=True,
                   progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["y.nc"]
    fresh = sweep.run(sweep.load_scene_text(SMALL), progress=False)
    for name in fresh.data_vars:
        np.testing.assert_array_equal(ds[name].values, fresh[name].values)


def test_cli_run_writes_netcdf_and_summarises(tmp_path):
    r = cli("run", "paper-fig5", "-o", "fig5.nc", "--set", "axes.length=[0.5, 1.0]",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "2 points" in r.stdout and "fig5.nc" in r.stdout
    with xr.open_dataset(tmp_path / "fig5.nc") as ds:
        assert list(ds["length"].values) == [0.5, 1.0]


def test_cli_lists_scenes():
    r = cli("scenes")
    assert r.returncode == 0
    names = [line.split()[0] for line in r.stdout.splitlines()]
    assert "paper-fig5" in names and "harness-parametric" in names


@pytest.mark.parametrize("args, needle", [
    (["run", "paper-fig6"], "paper-fig6"),
    (["run", "paper-fig5", "--set", "cable.lenght=1"], "did you mean"),
    (["run", "paper-fig5", "--set", "solver.t_end=-1"], "solver.t_end"),
    (["run", "paper-fig5", "--set", "solver.rtol"], "KEY=VALUE"),
    (["run", "paper-fig5", "-o", "no/such/dir/x.nc"], "does not exist"),
    (["run", "paper-fig5", "-o", "out.txt"], ".nc"),
    (["run", "paper-fig5", "--threads", "0"], "--threads"),
    (["run"], "SCENE".lower()),
    (["fly"], "fly"),
])
def test_cli_user_errors_exit_2_with_one_line(args, needle, tmp_path):
    r = cli(*args, cwd=tmp_path)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert needle.lower() in lines[0].lower()
    assert "Traceback" not in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_cli_refuses_existing_output(tmp_path):
    (tmp_path / "o.nc").write_text("x")
    r = cli("run", "paper-fig5", "-o", "o.nc", cwd=tmp_path)
    assert r.returncode == 2 and "--overwrite" in r.stderr
    assert (tmp_path / "o.nc").read_text() == "x"


def test_summary_counts_states_by_their_flag_values():
    """The one-line summary reads flag_values: longitudinal flags are not 0..n-1."""
    from sweep.cli import _summary
    ds = sweep.run(sweep.load_scene("paper-fig7", overrides={"solver.intervals": 50}),
                   progress=False)
    assert _summary(ds, 1.0).endswith("(1 completed)")


def test_summary_counts_both_a_time_domain_runs_and_its_charts_states():
    """A stability chart run beside a time-domain run (base excitation on a stability scene):
    the line counts both (a reviewer saw only the time domain's)."""
    import xarray as xr
    from sweep.cli import _summary
    flags = {"flag_values": np.array([0, 2], np.int8), "flag_meanings": "decayed steady"}
    stab = {"flag_values": np.array([0, 1], np.int8), "flag_meanings": "stable unstable"}
    ds = xr.Dataset({"state": ("x", np.array([0, 2, 2], np.int8), flags),
                     "stability": ("x", np.array([1, 0, 1], np.int8), stab)},
                    attrs={"title": "t", "n_points": 3})
    assert _summary(ds, 1.0).endswith("(state: 1 decayed, 2 steady; stability: 1 stable, "
                                      "2 unstable)")
    assert _summary(ds.drop_vars("state"), 1.0).endswith("(1 stable, 2 unstable)")



def test_the_umask_is_read_without_setting_it(monkeypatch):
    """Setting the umask to read it would change it for every thread for an instant: where the
    kernel reports it (/proc/self/status), the mode comes from there, os.umask untouched."""
    from sweep.files import new_file_mode
    try:
        with open("/proc/self/status") as status:
            if not any(line.startswith("Umask:") for line in status):
                pytest.skip("this kernel does not report the umask")
    except OSError:
        pytest.skip("no /proc/self/status")
    old = os.umask(0o027)
    try:
        def refuse(mask):
            raise AssertionError("os.umask called")
        monkeypatch.setattr(os, "umask", refuse)
        assert new_file_mode() == 0o640
        monkeypatch.undo()
    finally:
        os.umask(old)


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_output_file_follows_the_umask(tmp_path, umask, mode):
    """The netCDF file gets the mode any tool's new file gets (0666 less the umask), not the
    temporary file's 0600."""
    from sweep.io import write_netcdf
    ds = xr.Dataset({"x": ("n", np.arange(3.0))}, coords={"n": np.arange(3)})
    old = os.umask(umask)
    try:
        out = write_netcdf(ds, tmp_path / "out.nc")
    finally:
        os.umask(old)
    assert os.stat(out).st_mode & 0o777 == mode


def test_a_closed_pipe_on_stdout_is_no_traceback():
    """`sweep keys | head -1`: the reader has gone when the command writes: exit 141 as a
    shell reports SIGPIPE, no traceback."""
    read, write = os.pipe()
    os.close(read)
    proc = subprocess.Popen([sys.executable, "-m", "sweep.cli", "keys"], stdout=write,
                            stderr=subprocess.PIPE)
    os.close(write)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141, err
    assert "Traceback" not in err and "BrokenPipe" not in err


def test_a_signal_after_the_run_is_complete_exits_0(tmp_path, monkeypatch, capsys):
    """SIGTERM between the file's write and the summary line (a reviewer's run exited 143
    though the file was whole): exit 0, saying the result is whole."""
    import sweep.cli as cli
    scene = tmp_path / "small.toml"
    scene.write_text(SMALL)
    out = tmp_path / "small.nc"

    def terminated(*args, **kwargs):
        exc = KeyboardInterrupt()
        exc.signum = signal.SIGTERM
        raise exc

    monkeypatch.setattr(cli, "_summary", terminated)
    assert cli.main(["run", str(scene), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "SIGTERM received after the run was complete" in err and str(out) in err
    assert xr.open_dataset(out)["state"].size > 0
