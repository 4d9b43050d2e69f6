"""Execution backends and resumable runs: dask equals threads; a killed run resumes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import sweep

PACKAGE_ROOT = Path(sweep.__file__).resolve().parents[1]

SCENE = """
name = "execute-test"
[cable]
damping_ratio = 0.02
[initial]
displacement = 1e-3
[axes]
length = {start = 0.3, stop = 1.0, num = 9}
frequency_ratio = {start = 0.5, stop = 3.0, num = 7}
[solver]
t_end = 1.0
"""

VOLATILE = {"history", "run_seconds"}     # when it ran and how long it took


def assert_same_result(a: xr.Dataset, b: xr.Dataset, ignore: set = frozenset()) -> None:
    """Equal data and attributes, but for the volatile attributes and those in `ignore`."""
    skip = VOLATILE | set(ignore)
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert a[name].attrs.keys() == b[name].attrs.keys()
    assert {k: v for k, v in a.attrs.items() if k not in skip} == \
        {k: v for k, v in b.attrs.items() if k not in skip}


def test_dask_local_cluster_equals_threads_for_any_chunking():
    pytest.importorskip("dask.distributed")
    threads = sweep.run(sweep.load_scene_text(SCENE), progress=False)
    for chunk, workers in ((7, 2), (25, 1)):
        scene = sweep.load_scene_text(SCENE, overrides={"run.backend": "dask",
                                                        "run.workers": workers,
                                                        "run.chunk_size": chunk})
        # The scene text differs by its [run] section only.
        assert_same_result(sweep.run(scene, progress=False), threads, ignore={"scene"})


def test_longitudinal_on_dask_equals_threads():
    pytest.importorskip("dask.distributed")
    text = ("[model]\nkind = 'longitudinal'\n[solver]\nintervals = 50\n[axes]\n"
            "length = [0.3, 0.6, 0.9, 1.2, 1.5]\n")
    threads = sweep.run(sweep.load_scene_text(text), progress=False)
    dask = sweep.run(sweep.load_scene_text(text, overrides={
        "run.backend": "dask", "run.workers": 2, "run.chunk_size": 2}), progress=False)
    assert_same_result(dask, threads, ignore={"scene"})


def _cli(args, cwd, **kwargs):
    env = {**os.environ, "PYTHONPATH": str(PACKAGE_ROOT)}
    return subprocess.Popen([sys.executable, "-m", "sweep.cli", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


KILL_SCENE = """
name = "kill-and-resume"
[cable]
damping_ratio = 0.02
[initial]
displacement = 1e-3
[axes]
length = {start = 0.2, stop = 1.0, num = 40}
frequency_ratio = {start = 0.5, stop = 3.0, num = 40}
[solver]
t_end = 4.0
rtol = 1e-10
[run]
threads = 1
chunk_size = 40
"""


def test_a_killed_run_resumes_and_writes_the_same_file(tmp_path):
    (tmp_path / "s.toml").write_text(KILL_SCENE)
    store = tmp_path / "out.nc.chunks"
    proc = _cli(["run", "s.toml", "-o", "out.nc", "--quiet"], tmp_path)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and len(list(store.glob("chunk-*.npz"))) < 3:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done_at_kill = len(list(store.glob("chunk-*.npz")))
    assert 3 <= done_at_kill < 40
    assert not (tmp_path / "out.nc").exists()            # the file appears only when complete

    refused = _cli(["run", "s.toml", "-o", "out.nc"], tmp_path)
    _, err = refused.communicate(timeout=300)
    assert refused.returncode == 2 and "--resume" in err

    resumed = _cli(["run", "s.toml", "-o", "out.nc", "--resume", "--quiet"], tmp_path)
    _, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err
    computed = int(err.split(" computed")[0].split(", ")[-1])
    assert computed == 40 - done_at_kill                    # only the missing chunks
    assert not store.exists()                               # removed after success

    whole = _cli(["run", "s.toml", "-o", "whole.nc", "--quiet"], tmp_path)
    _, err = whole.communicate(timeout=600)
    assert whole.returncode == 0, err
    with xr.open_dataset(tmp_path / "out.nc") as a, xr.open_dataset(tmp_path / "whole.nc") as b:
        assert_same_result(a, b)


def _chunk_compiling_a_fresh_function(rows: np.ndarray, threads: int = 0) -> dict:
    """A chunk kernel whose first call compiles: a Numba function made anew (no cache)."""
    import numba

    @numba.njit
    def double(x):
        return 2.0 * x

    return {"value": np.array([double(float(r)) for r in rows])}


def test_progress_says_when_the_kernels_compile_and_only_then(capsys):
    """With progress on, a run whose kernels Numba compiles (a cold start: seconds with nothing
    on the screen) says so on stderr, and how long it took; one whose kernels are loaded or
    already compiled says nothing; with progress off, nothing either."""
    from sweep.execute import execute

    values = np.zeros(6)

    def place(lo, hi, arrays):
        values[lo:hi] = arrays["value"]

    for progress in (True, False):
        execute(_chunk_compiling_a_fresh_function, lambda lo, hi: np.arange(lo, hi), 6, (),
                place, chunk_size=3, progress=progress)
        err = capsys.readouterr().err
        np.testing.assert_array_equal(values, 2.0 * np.arange(6))
        if progress:
            assert "compiling the Numba kernels" in err and "compiled in" in err, err
            assert err.count("compiling") == 1        # once, though each chunk compiled anew
        else:
            assert "compil" not in err, err
    scene = sweep.load_scene_text(SCENE)
    sweep.run(scene, progress=False)                  # compiled (or loaded) here
    sweep.run(scene, progress=True)
    assert "compil" not in capsys.readouterr().err
