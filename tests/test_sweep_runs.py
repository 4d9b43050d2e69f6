"""Stepped and continuous sine sweeps through the runner as any sweep goes: on a dask cluster
(a continuation line, or a swept point, a task), kept chunk by chunk in the store and resumed
after an interruption, with the same results to the bit as an uninterrupted in-process run."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import sweep
import sweep.execute as ex

STEPPED = """
name = "stepped-runs"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.05
[continuation]
axis = "base_frequency_ratio"
direction = "both"
[solver]
t_end = 0.6
[axes]
length = [0.4, 0.5, 0.6]
base_frequency_ratio = {start = 0.9, stop = 1.3, num = 6}
"""

SWEPT = """
name = "swept-runs"
[cable]
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 0.2
sweep = { start = 30.0, stop = 50.0, rate = 16.0, direction = "both" }
[outputs]
envelope = true
[axes]
length = [0.3, 0.32, 0.34]
"""


def _same(a: xr.Dataset, b: xr.Dataset) -> None:
    """Every variable equal to the bit (NaN where NaN), run_seconds aside."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.data_vars:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


@pytest.fixture(scope="module", params=[STEPPED, SWEPT], ids=["stepped", "swept"])
def case(request):
    scene = sweep.load_scene_text(request.param)
    return scene, sweep.run(scene)


@pytest.mark.slow
def test_a_dask_cluster_gives_the_in_process_result(case, tmp_path):
    pytest.importorskip("dask.distributed")
    scene, whole = case
    ds = sweep.run(sweep.load_scene_text(scene.text, overrides={
        "run.backend": "dask", "run.workers": 1, "run.chunk_size": 2}))
    _same(ds, whole)


def test_an_interrupted_run_keeps_its_chunks_and_resumes_to_the_same_result(case, tmp_path,
                                                                           monkeypatch, capsys):
    scene, whole = case
    scene = sweep.load_scene_text(scene.text, overrides={"run.chunk_size": 1, "run.threads": 1})
    stepped = scene.get("continuation.axis") is not None
    name = "stepped_chunk" if stepped else "transverse_chunk"
    real = getattr(ex, name)
    calls = []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(ex, name, interrupted)     # the models take it from ex at run time
    out = tmp_path / "out.nc"
    with pytest.raises((KeyboardInterrupt, sweep.UserError)):
        sweep.run(scene, output=out)
    assert not out.exists()                              # no half-written result
    store = tmp_path / "out.nc.chunks"
    assert store.is_dir() and any(store.iterdir())       # the finished chunks are kept
    monkeypatch.setattr(ex, name, real)
    calls.clear()
    capsys.readouterr()
    ds = sweep.run(scene, output=out, resume=True)
    _same(ds, whole)
    # a stepped sweep's unit of work is a line, and it says so
    unit = "lines" if stepped else "points"
    assert f"2 of 6 {unit} were already done" in capsys.readouterr().err   # 3 spans x 2 ways
    with xr.open_dataset(out) as written:
        _same(written, whole)
