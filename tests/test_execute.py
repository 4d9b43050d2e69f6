"""Execution backends and resumable runs: dask equals threads; a killed run resumes."""

from __future__ import annotations

import contextlib
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.cli import main as sweep_main

from conftest import TABLE1_CABLE, fast_first, stderr_lines, sweep_env
from sweep.kernels.states import NOT_SOLVED


SCENE = """
name = "execute-test"
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
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


@pytest.mark.slow
def test_dask_local_cluster_equals_threads_for_any_chunking():
    pytest.importorskip("dask.distributed")
    threads = sweep.run(sweep.load_scene_text(SCENE), progress=False)
    for chunk, workers in ((7, 2), (25, 1)):
        scene = sweep.load_scene_text(SCENE, overrides={"run.backend": "dask",
                                                        "run.workers": workers,
                                                        "run.chunk_size": chunk})
        # The scene text differs by its [run] section only.
        assert_same_result(sweep.run(scene, progress=False), threads, ignore={"scene"})


@pytest.mark.slow
def test_longitudinal_on_dask_equals_threads():
    pytest.importorskip("dask.distributed")
    text = ("[model]\nkind = 'longitudinal'\n[solver]\nintervals = 50\n[axes]\n"
            "length = [0.3, 0.6, 0.9, 1.2, 1.5]\n")
    threads = sweep.run(sweep.load_scene_text(text), progress=False)
    dask = sweep.run(sweep.load_scene_text(text, overrides={
        "run.backend": "dask", "run.workers": 2, "run.chunk_size": 2}), progress=False)
    assert_same_result(dask, threads, ignore={"scene"})


@pytest.mark.slow
def test_random_spectra_on_dask_equal_threads():
    """A dask worker's chunk computes the response's spectra after its solve (in parts on the
    chunk's threads), the threads backend block by block as the rows turn final: the same
    values either way."""
    pytest.importorskip("dask.distributed")
    small = {"axes.length": [0.1, 0.15], "axes.base_asd_scale": [0.0], "base.realisations": 3,
             "base.duration": 1.0, "outputs.response_asd": True, "run.threads": 2}
    threads = sweep.run(sweep.load_scene("launch-random-gevs", small), progress=False)
    dask = sweep.run(sweep.load_scene("launch-random-gevs", {
        **small, "run.backend": "dask", "run.workers": 2, "run.chunk_size": 4}), progress=False)
    assert np.isfinite(threads["deflection_asd"].values).all()
    assert_same_result(dask, threads, ignore={"scene"})


def _cli(args, cwd, **kwargs):
    env = sweep_env()
    return subprocess.Popen([sys.executable, "-m", "sweep.cli", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


# A few hundred long runs in one default chunk (about 1.5 s of work on one thread of the 2-core
# development machine): finished blocks reach the store part-way only if they go by time. The
# child process times its blocks to 0.2 s (BLOCK_SECONDS, FLUSH_SECONDS) so that the test is
# short and there are blocks left after the first one saved on any machine.
LONG_SCENE = """
name = "kill-and-resume"
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
[initial]
displacement = 1e-3
[axes]
length = {start = 0.2, stop = 1.0, num = 20}
frequency_ratio = {start = 0.5, stop = 3.0, num = 20}
[solver]
t_end = 80.0
rtol = 1e-10
[run]
threads = 1
"""
LONG_POINTS = 400
SHORT_BLOCKS = ("import sys, sweep.execute as e, sweep.threads as t; "
                "t.BLOCK_SECONDS = e.FLUSH_SECONDS = 0.2; "
                "from sweep.cli import main; sys.exit(main(sys.argv[1:]))")


@pytest.fixture(scope="module")
def long_whole(tmp_path_factory):
    """The long sweep run without interruption, as a file."""
    here = tmp_path_factory.mktemp("whole")
    (here / "s.toml").write_text(LONG_SCENE)
    with contextlib.chdir(here):          # the file names its scene file as the CLI runs do
        sweep.run(sweep.load_scene("s.toml"), output="whole.nc", progress=False)
    return here / "whole.nc"


def _stored_points(store: Path) -> int:
    """Points in a chunk store's finished chunk files (their names give each range)."""
    ranges = [tuple(int(x) for x in p.stem.split("-")[1:3]) for p in store.glob("chunk-*.npz")]
    return sum(hi - lo for lo, hi in ranges)


def _start_and_wait_for_a_chunk(tmp_path, args, scene=LONG_SCENE, script=SHORT_BLOCKS):
    """Start `sweep run` on `scene` (the long one) in a process that runs `script`; return it
    once the store holds a finished chunk."""
    (tmp_path / "s.toml").write_text(scene)
    store = tmp_path / "out.nc.chunks"
    # SIGINT as a terminal's Ctrl-C gives it (a test runner may have it ignored for children)
    env = sweep_env()
    proc = subprocess.Popen([sys.executable, "-c", script, "run", "s.toml", "-o", "out.nc",
                             *args], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300
    while not list(store.glob("chunk-*.npz")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.02)
    return proc, store


@pytest.mark.slow
def test_a_killed_run_keeps_finished_blocks_and_resumes_to_the_same_file(tmp_path, long_whole,
                                                                        capsys):
    """Killed (SIGKILL) part-way through one default chunk, a run has its finished blocks in
    the store; --resume computes only the rest and writes the uninterrupted run's file."""
    proc, store = _start_and_wait_for_a_chunk(tmp_path, ["--quiet"])
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    kept = _stored_points(store)
    assert 0 < kept < LONG_POINTS                         # saved part-way, by time
    assert not (tmp_path / "out.nc").exists()            # the file appears only when complete

    with contextlib.chdir(tmp_path):
        scene = sweep.load_scene("s.toml")
        with pytest.raises(sweep.UserError, match="--resume"):
            sweep.run(scene, output="out.nc", progress=False)
        sweep.run(scene, output="out.nc", resume=True, progress=False)
    err = capsys.readouterr().err
    assert f"{kept:,} of {LONG_POINTS:,} points were already done, " \
           f"{LONG_POINTS - kept:,} computed" in err     # only the missing points
    assert not store.exists()                               # removed after success
    with xr.open_dataset(tmp_path / "out.nc") as a, xr.open_dataset(long_whole) as b:
        assert_same_result(a, b)


@pytest.mark.slow
def test_ctrl_c_keeps_finished_blocks_says_how_to_resume_and_exits_130(tmp_path, long_whole,
                                                                        capsys):
    """SIGINT part-way: exit status 130, one line on stderr (no traceback, no progress bar:
    stderr is not a terminal) naming what was kept and the command that finishes the run;
    that command computes only the rest and writes the uninterrupted run's file."""
    proc, store = _start_and_wait_for_a_chunk(tmp_path, ["--threads", "1"])
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    lines = stderr_lines(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    kept = _stored_points(store)
    assert 0 < kept < LONG_POINTS
    assert f"{kept:,} of {LONG_POINTS:,} points are kept in {store.name}" in lines[0], err
    command = lines[0].split("finish the run with: ")[1]
    assert command == "sweep run s.toml -o out.nc --threads 1 --resume"
    with contextlib.chdir(tmp_path):
        assert sweep_main(shlex.split(command)[1:] + ["--quiet"]) == 0
    assert f"{LONG_POINTS - kept:,} computed" in capsys.readouterr().err
    with xr.open_dataset(tmp_path / "out.nc") as a, xr.open_dataset(long_whole) as b:
        assert_same_result(a, b)


# Its points 8 x 8, ten times as long: one block of the lanes on one thread (about 3 s here).
ONE_BLOCK_SCENE = LONG_SCENE.replace("num = 20", "num = 8").replace("t_end = 80.0",
                                                                    "t_end = 800.0")
FLUSH_OFTEN = ("import sys, sweep.execute as e; e.FLUSH_SECONDS = 0.2; "
               "from sweep.cli import main; sys.exit(main(sys.argv[1:]))")


def test_ctrl_c_on_one_thread_stops_the_kernel_inside_its_block(tmp_path):
    """A tester: on one thread Ctrl-C waited for the whole block (a one-mode sine sweep, 24 s),
    as the thread that solved was the main one, where Python runs a signal's handler only
    between kernel calls. One 64-point block of the lanes (about 3 s here), its finished rows
    saved every 0.2 s: SIGINT once the first are saved stops the kernel inside the block, so
    some of its rows are left to --resume."""
    proc, store = _start_and_wait_for_a_chunk(tmp_path, ["--threads", "1"], ONE_BLOCK_SCENE,
                                              FLUSH_OFTEN)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert 0 < _stored_points(store) < 64, err          # before: the whole block, 64


def test_ctrl_c_without_an_output_file_says_nothing_was_kept(capsys):
    """Without -o nothing is kept: the line says so, and how to make a run resumable."""
    from sweep.cli import _interrupted, _parser
    from sweep.execute import RunInterrupted
    args = _parser().parse_args(["run", "x.toml"])
    line = _interrupted(RunInterrupted(0, 10, None), args, ["run", "x.toml"])
    assert "not kept" in line and "-o OUT.nc" in line and "--resume" in line


def test_a_signal_before_anything_finished_says_so_whatever_the_scene(tmp_path):
    """With -o but nothing finished yet (a first run still compiling): nothing kept, said
    once, the signal named; not the old line blaming a stepped sweep."""
    import signal as sig

    from sweep.cli import _interrupted, _parser
    from sweep.execute import RunInterrupted
    out = str(tmp_path / "out.nc")
    args = _parser().parse_args(["run", "harness-base-sine", "-o", out])
    line = _interrupted(RunInterrupted(0, 533, None, sig.SIGTERM), args,
                        ["run", "harness-base-sine", "-o", out])
    assert line.startswith("SIGTERM received before any point was finished: nothing kept")
    assert "stepped" not in line and "\n" not in line


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


def test_a_cold_start_is_announced_off_a_terminal_too(capsys):
    """No bar (stderr is not a terminal: CI, nohup, a notebook's !sweep run), but the two
    compile lines all the same: a first run that compiles for minutes is never silent."""
    from sweep.execute import execute

    values = np.zeros(4)

    def place(lo, hi, arrays):
        values[lo:hi] = arrays["value"]

    execute(_chunk_compiling_a_fresh_function, lambda lo, hi: np.arange(lo, hi), 4, (),
            place, chunk_size=2, progress=False, announce=True)
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert lines[0].startswith("compiling the Numba kernels") and \
        lines[-1].startswith("compiled in "), err
    assert "\r" not in err and "%|" not in err                  # no bar


# --- blocks, checkpoints by time, resumable ranges -----------------------------------------

def _rows(n: int, seed: int = 3) -> np.ndarray:
    """Kernel rows of n random points of the execute-test scene, and the scene."""
    from sweep import grid, models
    from sweep.kernels.oscillator import PARAM_NAMES
    scene = sweep.load_scene_text(SCENE)
    coords = grid.coordinates(scene)
    params = grid.parameters(scene, coords)
    shape = tuple(c.size for c in coords.values())
    points = np.random.default_rng(seed).integers(0, int(np.prod(shape)), n)
    at = grid.point_values(params, tuple(coords), shape, points)
    return grid.rows(models.oscillator(at), PARAM_NAMES, n), scene


@pytest.mark.parametrize("threads", [1, 2])
def test_blocks_are_reported_once_each_and_stop_ends_the_solve(threads):
    """on_block hears of every row once, as results equal to a call without it; with `stop`
    set from the first report, the call returns with exactly the reported rows solved."""
    import threading

    from sweep.run import settings_vector
    from sweep.threads import MAX_BLOCK, solve_transverse
    from sweep.execute import transverse_outputs
    rows, scene = _rows(600)
    s = settings_vector(scene)
    whole = transverse_outputs(600, 0)
    solve_transverse(rows, s, *whole.values(), threads=threads)
    seen = []
    got = transverse_outputs(600, 0)
    solve_transverse(rows, s, *got.values(), threads=threads,
                     on_block=lambda lo, hi: seen.append((lo, hi)))
    assert sorted(seen)[0][0] == 0 and sorted(seen)[-1][1] == 600
    assert sum(hi - lo for lo, hi in seen) == 600 and all(hi - lo <= MAX_BLOCK for lo, hi in seen)
    for name in whole:
        np.testing.assert_array_equal(got[name], whole[name], err_msg=name)

    stop = threading.Event()
    seen = []
    part = transverse_outputs(600, 0)
    part["states"][:] = -1
    solve_transverse(rows, s, *part.values(), threads=threads, stop=stop,
                     on_block=lambda lo, hi: (seen.append((lo, hi)), stop.set()))
    solved = np.zeros(600, bool)
    for lo, hi in seen:
        solved[lo:hi] = True
    assert 0 < solved.sum() < 600
    np.testing.assert_array_equal(part["states"][solved], whole["states"][solved])
    # rows never reached: untouched, or marked not solved where their block had begun
    assert np.all(np.isin(part["states"][~solved], (-1, NOT_SOLVED)))


def test_a_long_report_holds_up_neither_other_blocks_nor_its_own_solver():
    """threads.Watch calls on_block outside the lock on its table of blocks: while one thread
    reports rows of a block (a random scene's spectra are computed there), the block's solving
    thread reports the rows that turned final since, ends the block, and begins and ends
    another; every row is reported once."""
    import threading

    from sweep.threads import Watch
    states = np.full(20, NOT_SOLVED, np.int8)
    inside, release, solver_done = threading.Event(), threading.Event(), threading.Event()
    seen = []

    def on_block(lo, hi):
        seen.append((lo, hi))
        if lo == 0:
            inside.set()
            release.wait(10)

    watch = Watch(states, on_block, None)
    watch.begin(0, 10)
    states[:4] = 0                             # rows 0..3 final
    reporter = threading.Thread(target=watch.tick)

    def solve():
        states[4:10] = 0
        watch.end(0)
        watch.begin(10, 20)
        states[10:20] = 0
        watch.end(10)
        solver_done.set()

    solver = threading.Thread(target=solve)
    try:
        reporter.start()
        assert inside.wait(10)                 # the reporter is inside on_block(0, 4)
        solver.start()
        assert solver_done.wait(5), "the solving thread waited for another thread's report"
        assert seen == [(0, 4), (4, 10), (10, 20)]
    finally:
        release.set()
        reporter.join(10)
        solver.join(10)
    assert not watch.blocks


SLOW_MODES = """
name = "slow-blocks"
[model]
modes = 5
[cable]
{cable}
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 1.0
[solver]
t_end = 12.0
rtol = 1e-9
[axes]
length = {{start = 0.4, stop = 0.8, num = 8}}
base_frequency_ratio = {{start = 0.8, stop = 3.0, num = {n}}}
"""


@pytest.mark.parametrize("driver", fast_first(["lanes", "scalar"], "lanes"))
def test_slow_blocks_report_rows_as_they_finish_and_an_interrupt_stops_inside_a_block(driver):
    """Five modes on one thread: the lanes' first block is 64 slow points (MIN_TIMED_BLOCK; a
    block of these took 17 s on harness-base-sine; here about 2 s, long beside the watcher's
    0.25 s: with t_end 4 s the block, 0.7 s, ended before the interrupt was heard once the
    lanes got faster; the scalar driver's are shorter,
    SCALAR_BLOCK, then timed), so before, nothing was reported (stored) and an
    interrupt was not heard until the block ended. The watcher reports rows within the block,
    each once and in order, results equal to a run without it; with `stop` set at the first
    report, the kernel returns within the block (the lanes: at once, their rows in flight
    unsolved; the scalar driver before its next row), part of the block unsolved and what was
    reported equal to the whole run's."""
    import threading

    from sweep.execute import modes_outputs
    from sweep.models import transverse as tm
    from sweep.threads import MIN_TIMED_BLOCK, solve_modes
    n = MIN_TIMED_BLOCK // 8
    inputs = tm.resolve(sweep.load_scene_text(SLOW_MODES.format(n=n, cable=TABLE1_CABLE)))
    rows = tm.modal_rows(inputs, np.arange(8 * n))
    s = inputs.settings

    untouched = 99                      # a state no kernel writes: a row never begun

    def run(**kwargs) -> dict:
        out = modes_outputs(8 * n, 0, 5)
        out["states"][:] = untouched
        solve_modes(rows, inputs.basis.kernel_arrays(), s, out["states"], out["reals"], out["counts"], out["series"],
                    out["modal"], out["final"], driver=driver, threads=1, **kwargs)
        return out

    whole = run()
    seen = []
    got = run(on_block=lambda lo, hi: seen.append((lo, hi)))
    assert len(seen) > 1, seen                         # within the one block
    assert all(type(lo) is int and type(hi) is int for lo, hi in seen)   # the store's JSON
    assert [lo for lo, _ in seen] == [0] + [hi for _, hi in seen[:-1]] and seen[-1][1] == 8 * n
    for name in whole:
        np.testing.assert_array_equal(got[name], whole[name], err_msg=name)

    stop = threading.Event()
    seen = []
    part = run(stop=stop, on_block=lambda lo, hi: (seen.append((lo, hi)), stop.set()))
    solved = seen[-1][1]
    assert [lo for lo, _ in seen] == [0] + [hi for _, hi in seen[:-1]]
    assert 0 < solved < 8 * n
    for name in whole:
        np.testing.assert_array_equal(part[name][:solved], whole[name][:solved], err_msg=name)
    # past the reported rows: some left in flight (NOT_SOLVED) or never begun (the scalar
    # driver's blocks are short: SCALAR_BLOCK); any that did finish out of order are left
    # unreported (a resume computes them again), their results still the same
    rest = part["states"][solved:]
    assert np.any((rest == NOT_SOLVED) | (rest == untouched))
    done = np.flatnonzero((rest != NOT_SOLVED) & (rest != untouched)) + solved
    np.testing.assert_array_equal(part["states"][done], whole["states"][done])


def test_finished_blocks_reach_the_store_by_time_and_the_rest_is_computed_on_resume(tmp_path,
                                                                                 monkeypatch):
    """A chunk whose blocks come back one by one: with FLUSH_SECONDS = 0 every block is its
    own file as soon as it is done; a store holding some ranges gets only the others computed,
    and the whole equals one uninterrupted pass."""
    from sweep import execute as ex
    calls = []

    def blocks(rows, threads=0, on_block=None, stop=None):
        out = {"value": np.full(rows.size, np.nan)}
        for lo in range(0, rows.size, 4):
            hi = min(rows.size, lo + 4)
            out["value"][lo:hi] = 2.0 * rows[lo:hi]
            on_block(lo, hi, out)
            calls.append(len(list(store.directory.glob("chunk-*.npz"))))
        return out

    monkeypatch.setattr(ex, "FLUSH_SECONDS", 0.0)
    store = ex.ChunkStore(tmp_path / "o.nc", "fp")
    done, _ = store.open(resume=False, overwrite=False, chunk_size=10)
    values = np.zeros(30)
    rows_for = lambda lo, hi: np.arange(lo, hi, dtype=float)           # noqa: E731
    assert ex.execute(blocks, rows_for, 30, (), _place(values), chunk_size=10, store=store,
                      done=done) == 30
    np.testing.assert_array_equal(values, 2.0 * np.arange(30))
    assert calls == list(range(1, 10))      # a file per block, written as the block ended
    for path in sorted(store.directory.glob("chunk-*.npz"))[1::2]:      # lose every other one
        path.unlink()
    done, _ = store.open(resume=True, overwrite=False, chunk_size=10)
    values[:] = 0.0
    computed = ex.execute(blocks, rows_for, 30, (), _place(values), chunk_size=10,
                          store=store, done=done)
    assert computed == 30 - sum(hi - lo for lo, hi in done)
    np.testing.assert_array_equal(values, 2.0 * np.arange(30))

    monkeypatch.setattr(ex, "FLUSH_SECONDS", 1e9)     # never by time: one file per chunk end
    store.remove()
    done, _ = store.open(resume=False, overwrite=False, chunk_size=10)
    ex.execute(blocks, rows_for, 30, (), _place(values), chunk_size=10, store=store, done=done)
    assert len(list(store.directory.glob("chunk-*.npz"))) == 3


def _place(values):
    def place(lo, hi, arrays):
        values[lo:hi] = arrays["value"]
    return place


def test_overlapping_or_foreign_chunks_are_refused():
    from sweep.execute import missing_ranges
    a = {"v": np.zeros(3)}
    assert missing_ranges(10, {(2, 5): a}) == [(0, 2), (5, 10)]
    assert missing_ranges(3, {(0, 3): a}) == []
    for done in ({(2, 5): a, (4, 7): {"v": np.zeros(3)}}, {(8, 11): a}, {(0, 4): a}):
        with pytest.raises(sweep.UserError, match="chunk store"):
            missing_ranges(10, done)


def test_a_kernel_without_blocks_gets_chunks_sized_by_its_speed():
    """The first call is short (it times the kernel), the next ones grow at most fourfold, up
    to chunk_size, and together they cover every point once."""
    from sweep.execute import FIRST_CHUNK, execute
    sizes = []

    def fast(rows, threads=0):
        sizes.append(rows.size)
        return {"value": 2.0 * rows}

    values = np.zeros(3000)
    execute(fast, lambda lo, hi: np.arange(lo, hi, dtype=float), 3000, (), _place(values),
            chunk_size=500, threads=1)
    np.testing.assert_array_equal(values, 2.0 * np.arange(3000))
    assert sizes[:4] == [FIRST_CHUNK, 4 * FIRST_CHUNK, 16 * FIRST_CHUNK, 64 * FIRST_CHUNK]
    assert max(sizes) == 500 and sum(sizes) == 3000


# --- the memory guard -----------------------------------------------------------------------

def _fake_system(root: Path, meminfo_kib: int | None = None, v2: tuple | None = None,
                 v1: tuple | None = None) -> str:
    if meminfo_kib is not None:
        (root / "proc").mkdir(parents=True, exist_ok=True)
        (root / "proc/meminfo").write_text(f"MemTotal:  99999999 kB\nMemFree: 1 kB\n"
                                           f"MemAvailable:   {meminfo_kib} kB\n")
    if v2 is not None:
        (root / "sys/fs/cgroup").mkdir(parents=True, exist_ok=True)
        (root / "sys/fs/cgroup/memory.max").write_text(f"{v2[0]}\n")
        (root / "sys/fs/cgroup/memory.current").write_text(f"{v2[1]}\n")
    if v1 is not None:
        (root / "sys/fs/cgroup/memory").mkdir(parents=True, exist_ok=True)
        (root / "sys/fs/cgroup/memory/memory.limit_in_bytes").write_text(f"{v1[0]}\n")
        (root / "sys/fs/cgroup/memory/memory.usage_in_bytes").write_text(f"{v1[1]}\n")
    return str(root)


def test_the_memory_guard_counts_available_memory_and_the_cgroup_limit(tmp_path, monkeypatch):
    """A sweep that fits in physical memory but not in what is available, or not in what a
    cgroup limit leaves, is refused with the figure and where it comes from."""
    from sweep.run import available_memory, check_memory
    gib = 2**30
    monkeypatch.setattr(os, "sysconf", lambda name: {"SC_PAGE_SIZE": 4096,
                                                     "SC_PHYS_PAGES": 64 * gib // 4096}[name])
    nothing = _fake_system(tmp_path / "none")
    assert available_memory(nothing) == (64 * gib, "physical memory")
    check_memory(10**6, 40 * 1024, "test", root=nothing)          # 38 GiB of 64: fine

    low = _fake_system(tmp_path / "avail", meminfo_kib=8 * 2**20)  # 8 GiB available
    assert available_memory(low) == (8 * gib, "available memory")
    with pytest.raises(sweep.UserError, match=r"8\.0 GiB of available memory"):
        check_memory(10**6, 40 * 1024, "test", root=low)
    check_memory(10**5, 40 * 1024, "test", root=low)               # 3.8 GiB of 8: fine

    v2 = _fake_system(tmp_path / "v2", meminfo_kib=32 * 2**20, v2=(6 * gib, 2 * gib))
    assert available_memory(v2) == (4 * gib, "memory the cgroup limit leaves")
    with pytest.raises(sweep.UserError, match=r"4\.0 GiB of memory the cgroup limit leaves"):
        check_memory(10**5, 40 * 1024, "test", root=v2)
    unlimited = _fake_system(tmp_path / "v2max", meminfo_kib=32 * 2**20, v2=("max", gib))
    assert available_memory(unlimited) == (32 * gib, "available memory")

    v1 = _fake_system(tmp_path / "v1", v1=(3 * gib, gib))
    assert available_memory(v1) == (2 * gib, "memory the cgroup limit leaves")
    with pytest.raises(sweep.UserError, match="cgroup"):
        check_memory(10**5, 40 * 1024, "test", root=v1)


@pytest.mark.parametrize("n, workers", [(180, 2), (1000, 1), (50, 4), (200_000, 2)])
def test_dask_tasks_are_several_per_worker_so_an_interrupt_keeps_some(n, workers):
    """A dask task is saved when it ends: a 180-point, 5-mode sweep (0.26 s a point) ran as one
    task and an interrupt lost it all. Now: about 8 tasks a worker, at least
    DASK_LEAST_TASK_POINTS points each (so a small grid still fills the lanes)."""
    from sweep.execute import DASK_LEAST_TASK_POINTS, chunk_ranges, default_chunk_size
    size = default_chunk_size(n, "dask", workers)
    tasks = chunk_ranges(n, size)
    assert sum(hi - lo for lo, hi in tasks) == n
    assert size >= DASK_LEAST_TASK_POINTS
    assert min(8 * workers, n // DASK_LEAST_TASK_POINTS) <= len(tasks) <= 8 * workers
