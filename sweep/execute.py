"""Execution: the flattened grid in chunks, on threads in-process or on dask, resumable.

A chunk is a contiguous range of the grid's points in solve order (a fixed permutation, see
run.point_order); one chunk is one kernel call, or one dask task. With a chunk store (next to
the output file) every finished chunk is written to disk as soon as it is done, so a run that is
killed can be resumed and computes only the chunks that are missing. Results never depend on
the backend, the chunking or the number of workers: each point depends on its own row only.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from .errors import UserError

STORE_SUFFIX = ".chunks"
IN_FLIGHT = 2          # dask tasks submitted ahead per worker thread


# --- chunk kernels (top-level functions: dask pickles them by name) -------------------------

def _set_threads(threads: int) -> None:
    """Numba's thread count for a parallel kernel (the longitudinal one), by the same rule as
    the transverse kernel's Python threads (threads.thread_count)."""
    import numba

    from .threads import thread_count
    numba.set_num_threads(thread_count(threads))


def transverse_outputs(n: int, n_samples: int) -> dict[str, np.ndarray]:
    """Empty transverse outputs of n points, by name (the kernel's output arrays)."""
    from sweep.kernels import transverse as tk
    return {"states": np.empty(n, np.int8), "reals": np.empty((n, tk.N_REALS)),
            "counts": np.empty((n, tk.N_COUNTS), np.int64), "series": np.empty((n, n_samples))}


def longitudinal_outputs(n: int, n_hist: int, n_snap: int,
                         n_nodes: int) -> dict[str, np.ndarray]:
    """Empty longitudinal outputs of n spans, by name (the kernel's output arrays)."""
    from sweep.kernels import longitudinal as lk
    return {"states": np.empty(n, np.int8), "reals": np.empty((n, lk.N_REALS)),
            "steps": np.empty(n, np.int64), "hist_u": np.empty((n, n_hist)),
            "hist_f": np.empty((n, n_hist)), "snap_u": np.empty((n, n_snap, n_nodes)),
            "snap_f": np.empty((n, n_snap, n_nodes)), "snap_v": np.empty((n, n_snap, n_nodes))}


def transverse_chunk(params: np.ndarray, settings: np.ndarray, n_samples: int, driver: str,
                     threads: int = 0) -> dict[str, np.ndarray]:
    """Transverse kernel over `params` rows; outputs by name (states, reals, counts, series)."""
    from .threads import solve_transverse
    out = transverse_outputs(params.shape[0], n_samples)
    solve_transverse(params, settings, out["states"], out["reals"], out["counts"], out["series"],
                     driver=driver, threads=threads)
    return out


def longitudinal_chunk(params: np.ndarray, settings: np.ndarray, snapshot_times: np.ndarray,
                       n_hist: int, n_nodes: int, threads: int = 0) -> dict[str, np.ndarray]:
    """Central-difference kernel over `params` rows; outputs by name."""
    from sweep.kernels import longitudinal as lk
    _set_threads(threads)
    out = longitudinal_outputs(params.shape[0], n_hist, snapshot_times.size, n_nodes)
    lk.solve_batch(params, settings, snapshot_times, out["states"], out["reals"], out["steps"],
                   out["hist_u"], out["hist_f"], out["snap_u"], out["snap_f"], out["snap_v"])
    return out


# --- the chunk store ---------------------------------------------------------------------------

class ChunkStore:
    """Finished chunks of one run, as .npz files in `<output>.chunks/`, written atomically.

    `fingerprint` identifies the run (resolved scene, kernel, chunking); a store made by another
    run is refused rather than mixed in.
    """

    def __init__(self, output: str | os.PathLike, fingerprint: str) -> None:
        out = Path(output)
        self.directory = out.with_name(out.name + STORE_SUFFIX)
        self.fingerprint = fingerprint

    def exists(self) -> bool:
        return self.directory.exists()

    def open(self, resume: bool, overwrite: bool,
             chunk_size: int) -> tuple[dict[tuple[int, int], dict], int]:
        """Prepare the store; return the chunks already finished (only when resuming) and the
        chunk size to use (a resumed run keeps the interrupted run's)."""
        if self.directory.exists() and not resume:
            if not overwrite:
                raise UserError(f"chunk store '{self.directory}': left by an interrupted run "
                                "(use --resume to finish it, or --overwrite to start again)")
            shutil.rmtree(self.directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        meta = self.directory / "run.json"
        if meta.exists():
            stored = json.loads(meta.read_text())
            if stored.get("fingerprint") != self.fingerprint:
                raise UserError(f"chunk store '{self.directory}': made by a different scene "
                                "(remove it, or use --overwrite to start again)")
            chunk_size = int(stored["chunk_size"])
        else:
            tmp = meta.with_suffix(".tmp")
            tmp.write_text(json.dumps({"fingerprint": self.fingerprint, "chunk_size": chunk_size}))
            os.replace(tmp, meta)
        done = {}
        for path in sorted(self.directory.glob("chunk-*.npz")):
            lo, hi = (int(x) for x in path.stem.split("-")[1:3])
            try:
                with np.load(path) as data:
                    done[(lo, hi)] = {k: data[k] for k in data.files}
            except (OSError, ValueError):
                path.unlink(missing_ok=True)         # torn by a kill: compute it again
        for path in self.directory.glob(".chunk-*.tmp.npz"):
            path.unlink(missing_ok=True)
        return done, chunk_size

    def save(self, lo: int, hi: int, arrays: dict[str, np.ndarray]) -> None:
        path = self.directory / f"chunk-{lo:012d}-{hi:012d}.npz"
        tmp = self.directory / f".chunk-{lo:012d}-{hi:012d}.tmp.npz"
        np.savez(tmp, **arrays)
        os.replace(tmp, path)

    def remove(self) -> None:
        shutil.rmtree(self.directory, ignore_errors=True)


def fingerprint(*parts: Any) -> str:
    """A hash of everything that decides a run's chunks and their contents."""
    text = json.dumps([str(p) for p in parts])
    return hashlib.sha256(text.encode()).hexdigest()


# --- progress ---------------------------------------------------------------------------------

def progress_printer(total: int, enabled: bool) -> Callable[[int], None]:
    """report(done) draws a one-line bar on stderr: points done, rate, time left."""
    start = time.perf_counter()
    first = [None]

    def report(done: int) -> None:
        if not enabled:
            return
        if first[0] is None:
            first[0] = done
        elapsed = time.perf_counter() - start
        rate = (done - first[0]) / elapsed if elapsed > 0 else 0.0
        left = (total - done) / rate if rate > 0 else math.inf
        width = 30
        filled = int(width * done / total) if total else width
        sys.stderr.write(f"\r[{'#' * filled}{'-' * (width - filled)}] {done:,}/{total:,} points"
                         f"  {rate:,.0f}/s  {left:6.1f} s left ")
        if done >= total:
            sys.stderr.write("\n")
        sys.stderr.flush()
    return report


@contextlib.contextmanager
def announce_compilation(enabled: bool) -> Iterator[None]:
    """Within the block, say on stderr when Numba compiles a kernel (a cold start: seconds with
    nothing else on the screen; not when it loads one from its cache) and, at the end, how long
    compiling took. Only in-process compiles are seen (not a dask worker's)."""
    if not enabled:
        yield
        return
    from numba.core import event

    class Notice(event.Listener):
        depth = 0
        seconds = 0.0
        started = 0.0

        def on_start(self, ev: event.Event) -> None:
            if self.depth == 0:
                if self.seconds == 0.0:
                    sys.stderr.write("compiling the Numba kernels this sweep needs (once: later "
                                     "runs load them from Numba's cache) ...\n")
                    sys.stderr.flush()
                self.started = time.perf_counter()
            self.depth += 1

        def on_end(self, ev: event.Event) -> None:
            self.depth -= 1
            if self.depth == 0:
                self.seconds += time.perf_counter() - self.started

    notice = Notice()
    with event.install_listener("numba:compile", notice):
        yield
    if notice.seconds > 0.0:
        sys.stderr.write(f"compiled in {notice.seconds:.1f} s\n")
        sys.stderr.flush()


# --- execution ------------------------------------------------------------------------------

def chunk_ranges(n: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(lo, min(n, lo + chunk_size)) for lo in range(0, n, chunk_size)]


def default_chunk_size(n: int, backend: str, workers: int) -> int:
    """Points per chunk: for threads, enough for every thread's lanes and at most 100 chunks;
    for dask, about 8 tasks per worker of at least 2 000 points (a task then runs long enough
    to hide the scheduler's per-task overhead of a few ms)."""
    import numba
    if backend == "dask":
        return max(2000, -(-n // (8 * max(workers, 1))))
    return max(4096 * numba.get_num_threads(), -(-n // 100))


def execute(chunk_fn: Callable[..., dict], rows_for: Callable[[int, int], np.ndarray], n: int,
            args: tuple, place: Callable[[int, int, dict], None], *, chunk_size: int,
            backend: str = "threads", threads: int = 0, scheduler: str | None = None,
            workers: int = 0, progress: bool = False, store: ChunkStore | None = None,
            done: dict | None = None) -> int:
    """Solve points 0..n-1 (solve order) chunk by chunk; returns the number of chunks computed.

    rows_for(lo, hi) builds the kernel's parameter rows of a chunk just before it runs, so the
    whole table never sits in memory; chunk_fn(rows, *args, threads=...) returns the chunk's
    output arrays by name, and place(lo, hi, arrays) stores them. Chunks in `done` (from a
    store) are placed, not computed; every computed chunk is also written to `store`.
    """
    report = progress_printer(n, progress and n > chunk_size)
    finished = 0
    for (lo, hi), arrays in (done or {}).items():
        place(lo, hi, arrays)
        finished += hi - lo
    todo = [r for r in chunk_ranges(n, chunk_size) if r not in (done or {})]
    if finished:
        report(finished)

    def collect(lo: int, hi: int, arrays: dict) -> None:
        nonlocal finished
        place(lo, hi, arrays)
        if store is not None:
            store.save(lo, hi, arrays)
        finished += hi - lo
        report(finished)

    if backend == "dask":
        _execute_dask(chunk_fn, rows_for, args, todo, collect, scheduler, workers)
    else:
        with announce_compilation(progress):
            for lo, hi in todo:
                collect(lo, hi, chunk_fn(rows_for(lo, hi), *args, threads=threads))
    return len(todo)


def _execute_dask(chunk_fn, rows_for, args, todo, collect, scheduler, workers) -> None:
    """Each chunk a task on a dask.distributed cluster: the one at `scheduler` (an address), or
    a LocalCluster of `workers` single-threaded worker processes started for this run. At most
    IN_FLIGHT tasks per worker thread are submitted at a time, so memory stays bounded."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as exc:
        raise UserError("run.backend = 'dask': dask.distributed is not installed "
                        "(pip install distributed)") from exc
    cluster = None
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, TimeoutError) as exc:
                raise UserError(f"run.scheduler '{scheduler}': no dask scheduler answers there "
                                "(check the address, e.g. tcp://HOST:8786)") from exc
        else:
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                                   threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1")
            client = Client(cluster)
        with client:
            slots = IN_FLIGHT * max(1, sum(client.nthreads().values()))
            pending = iter(todo)
            futures = {}

            def submit_next(queue) -> None:
                for lo, hi in pending:
                    # one kernel thread per task: one per dask worker thread, no oversubscription
                    fut = client.submit(chunk_fn, rows_for(lo, hi), *args, threads=1, pure=False)
                    futures[fut] = (lo, hi)
                    if queue is not None:
                        queue.add(fut)
                    return

            for _ in range(slots):
                submit_next(None)
            queue = as_completed(list(futures))
            for fut in queue:
                lo, hi = futures.pop(fut)
                collect(lo, hi, fut.result())
                submit_next(queue)
    finally:
        if cluster is not None:
            cluster.close()
