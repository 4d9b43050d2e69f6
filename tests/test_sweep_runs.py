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


class _Dwells:
    """Counts the stepped chunks' kernel calls (one dwell of the lines in hand each: `calls`
    holds their line counts) and, while `stop_at` is set, raises SIGINT as Ctrl-C does after
    that call (the dwell in hand finishes)."""

    def __init__(self, monkeypatch, stop_at: int | None) -> None:
        import signal
        self.calls: list[int] = []
        self.stop_at = stop_at
        real = ex.transverse_chunk

        def counted(*args, **kwargs):
            self.calls.append(args[0].shape[0])
            out = real(*args, **kwargs)
            if self.stop_at is not None and len(self.calls) == self.stop_at:
                signal.raise_signal(signal.SIGINT)
            return out
        monkeypatch.setattr(ex, "transverse_chunk", counted)


def test_a_stepped_resume_counts_the_lines_the_interrupt_kept_whole(tmp_path, monkeypatch,
                                                                     capsys, ctrl_c_raises):
    """Stopped after the up lines finished and the down lines began (one chunk of 6 lines:
    3 whole, 3 part-way), the interrupt's count and the resume's agree: 3 of 6 lines were
    already done (it said 0 of 6 done and 6 computed, the whole ones among those 'from where
    they stopped'), and the result is the same to the bit as a run never stopped."""
    scene = sweep.load_scene_text(STEPPED, overrides={"run.threads": 1})
    whole = sweep.run(scene)
    dwells = _Dwells(monkeypatch, stop_at=8)
    out = tmp_path / "out.nc"
    with pytest.raises(KeyboardInterrupt) as stopped:
        sweep.run(scene, output=out)
    assert "3 of 6 lines are kept whole and 3 part-way" in str(stopped.value)
    dwells.stop_at = None
    capsys.readouterr()
    ds = sweep.run(scene, output=out, resume=True)
    assert ("3 of 6 lines were already done, 3 computed (3 of them from where they stopped)"
            in capsys.readouterr().err)
    _same(ds, whole)


def test_a_stepped_run_stopped_mid_line_resumes_each_line_from_its_last_dwell(tmp_path,
                                                                             monkeypatch,
                                                                             capsys,
                                                                             ctrl_c_raises):
    """An interrupt part-way along the lines keeps every finished dwell (the chunk's progress:
    outputs, dwells done, the carried state and phases), and --resume goes on from there: it
    solves only the dwells left, and the result is the same to the bit as a run never
    stopped."""
    scene = sweep.load_scene_text(STEPPED, overrides={"run.threads": 1})
    whole = sweep.run(scene)
    dwells = _Dwells(monkeypatch, stop_at=4)
    calls = dwells.calls
    out = tmp_path / "out.nc"
    with pytest.raises(KeyboardInterrupt) as stopped:
        sweep.run(scene, output=out)
    assert not out.exists()
    # one thread: the up lines (3 spans) ran 4 of their 6 dwells, the down lines none
    assert calls == [3, 3, 3, 3]
    assert "0 of 6 lines are kept whole and 3 part-way" in str(stopped.value)
    assert [p.name.startswith("progress-") for p in (tmp_path / "out.nc.chunks").glob("*.npz")] \
        == [True]
    import shutil
    shutil.copytree(tmp_path / "out.nc.chunks", tmp_path / "kept")
    calls.clear()
    dwells.stop_at = None
    ds = sweep.run(scene, output=out, resume=True)
    assert calls == [3, 3] + [3] * 6           # the up lines' last 2 dwells, then the down lines
    _same(ds, whole)
    assert not (tmp_path / "out.nc.chunks").exists()
    # a damaged progress file is not trusted: said in one line, its lines solved again
    out.unlink()
    shutil.copytree(tmp_path / "kept", tmp_path / "out.nc.chunks")
    progress = next((tmp_path / "out.nc.chunks").glob("progress-*.npz"))
    progress.write_bytes(progress.read_bytes()[:-100])
    calls.clear()
    capsys.readouterr()
    ds = sweep.run(scene, output=out, resume=True)
    assert calls == [3] * 12
    _same(ds, whole)
    warned = [line for line in capsys.readouterr().err.splitlines() if "not used" in line]
    assert len(warned) == 1 and progress.name in warned[0]


def test_stored_times_are_found_as_typed():
    """The time-series coordinate holds the sample times k dt as the decimals they are
    (7 x 0.05 s is 0.35, not 0.35000000000000003): `.sel(elapsed_time=0.35)` finds the sample,
    as an axis value is found as typed (a reviewer found 282 of 2001 times unreachable)."""
    ds = sweep.run(sweep.load_scene("paper-fig5", {
        "axes.length": [0.5], "solver.t_end": 15.0, "outputs.sample_interval": 0.05}),
        progress=False)
    times = ds["elapsed_time"].values
    np.testing.assert_array_equal(times, np.arange(times.size) / 20.0)
    for t in (0.35, 0.7, 14.95, 15.0):
        assert float(ds["elapsed_time"].sel(elapsed_time=t)) == t
