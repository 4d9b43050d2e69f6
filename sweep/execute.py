"""Execution: the flattened grid in chunks, on threads in-process or on dask, resumable.

A chunk is a contiguous range of the grid's points in solve order (a fixed permutation, see
run.point_order); one chunk is one kernel call, or one dask task. With a chunk store (next to
the output file) finished work is written to disk as it is done, by time rather than by point
count: the transverse kernel reports each block of points it finishes (sweep.threads: blocks of
about 2 s on a thread), and the finished blocks are saved at the first block end FLUSH_SECONDS
after the last save; a kernel that cannot report blocks (the longitudinal one) gets chunks
sized from its measured speed to take about CHUNK_SECONDS each.
A run that is killed can then be resumed and computes only the points that are missing, and
Ctrl-C stops it after the blocks in hand, with every finished one kept. Results never depend on
the backend, the chunking or the number of workers: each point depends on its own row only.
"""

from __future__ import annotations

import contextlib
import inspect
import os
import signal
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from .errors import UserError
from .store import STORE_SUFFIX, ChunkStore, fingerprint  # noqa: F401  (re-exported)

IN_FLIGHT = 2          # dask tasks submitted ahead per worker thread
FLUSH_SECONDS = 1.0    # finished blocks are saved at a block end this long after the last save (s)
CHUNK_SECONDS = 2.0    # a kernel call that cannot report its blocks takes about this long (s)
FIRST_CHUNK = 4        # points per thread in such a kernel's first, timing call


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM, SIGHUP: `signum`) stopped a run: `kept` of `total` points are in the
    chunk store `store` (None when the run had no output file, so nothing was kept)."""

    def __init__(self, kept: int, total: int, store: Path | None,
                 signum: int = signal.SIGINT, unit: str = "points", partway: int = 0) -> None:
        self.kept, self.total, self.store, self.signum = kept, total, store, signum
        self.unit, self.partway = unit, partway
        if store is None:
            text = ("interrupted: results were not kept (a run with an output file keeps "
                    "every finished chunk, and resume=True finishes it)")
        else:
            text = (f"interrupted: {self.kept_text()} in '{store}' "
                    "(run again with resume=True to compute only the rest)")
        super().__init__(text)

    def kept_text(self) -> str:
        """'K of N points are kept' (and the lines kept part-way, their finished dwells)."""
        if not self.partway:
            return f"{self.kept:,} of {self.total:,} {self.unit} are kept"
        return (f"{self.kept:,} of {self.total:,} {self.unit} are kept whole and "
                f"{self.partway:,} part-way (a resumed line goes on from its last finished "
                "dwell)")


# --- chunk kernels (top-level functions: dask pickles them by name) -------------------------

def _set_threads(threads: int) -> None:
    """Numba's thread count for a parallel kernel (the longitudinal one), by the same rule as
    the transverse kernel's Python threads (threads.thread_count)."""
    import numba

    from .threads import thread_count
    numba.set_num_threads(thread_count(threads))


def transverse_outputs(n: int, n_samples: int, n_bands: int = -1) -> dict[str, np.ndarray]:
    """Empty transverse outputs of n points, by name (the kernel's output arrays); with
    n_bands >= 0 (a swept base frequency) also envelope (n, n_bands), the response envelope
    (m, kernels.metrics.sweep_metrics)."""
    from sweep.kernels import layout as tk
    out = {"states": np.empty(n, np.int8), "reals": np.empty((n, tk.N_REALS)),
           "counts": np.empty((n, tk.N_COUNTS), np.int64), "series": np.empty((n, n_samples))}
    if n_bands >= 0:
        out["envelope"] = np.empty((n, n_bands))
    return out


def longitudinal_outputs(n: int, n_hist: int, n_snap: int,
                         n_nodes: int) -> dict[str, np.ndarray]:
    """Empty longitudinal outputs of n spans, by name (the kernel's output arrays)."""
    from sweep.kernels import wave_layout as lk
    return {"states": np.empty(n, np.int8), "reals": np.empty((n, lk.N_REALS)),
            "steps": np.empty(n, np.int64), "hist_u": np.empty((n, n_hist)),
            "hist_f": np.empty((n, n_hist)), "snap_u": np.empty((n, n_snap, n_nodes)),
            "snap_f": np.empty((n, n_snap, n_nodes)), "snap_v": np.empty((n, n_snap, n_nodes))}


def transverse_chunk(params: np.ndarray, settings: np.ndarray, n_samples: int, driver: str,
                     n_bands: int = -1, per_point_end: bool = False,
                     records: np.ndarray | None = None, threads: int = 0,
                     on_block: Callable[[int, int, dict], None] | None = None,
                     stop: threading.Event | None = None) -> dict[str, np.ndarray]:
    """Transverse kernel over `params` rows; outputs by name (states, reals, counts, series;
    `transverse_outputs`). A swept base frequency (settings[SWEPT] = 1): n_bands the envelope's
    bands, and per_point_end: each point ends with its own sweep (the rows' sweep_end column,
    kernels.excitation.END) rather than at settings' T_END. records: a random base
    acceleration's records (sweep/models/random_outputs.py), shared by every row.

    on_block(lo, hi, outputs) hears of each block of rows as soon as it is final; with `stop`
    set the call returns early, with only the rows on_block reported solved."""
    from sweep.kernels import oscillator as osc

    from .threads import solve_transverse
    out = transverse_outputs(params.shape[0], n_samples, n_bands)
    report = None if on_block is None else (lambda lo, hi: on_block(lo, hi, out))
    solve_transverse(params, settings, out["states"], out["reals"], out["counts"], out["series"],
                     driver=driver, threads=threads, on_block=report, stop=stop,
                     envelope=out.get("envelope"),
                     durations=_ends(params, osc.EXCITATION) if per_point_end else None,
                     records=records)
    return out


def reduced_chunk(params: np.ndarray, inner: Callable[..., dict], inner_args: tuple,
                  reduction: Any, records: np.ndarray, threads: int = 0,
                  on_block: Callable[[int, int, dict], None] | None = None,
                  stop: threading.Event | None = None) -> dict[str, np.ndarray]:
    """inner(params, *inner_args) (`transverse_chunk` or `modes_chunk`) with its time series
    reduced row block by row block as soon as each is final: `reduction` (a model's, e.g.
    sweep/models/response_asd.py's Reduction) gives empty(n), the arrays that
    replace or join inner's (an empty series in place of the long one, unless the series is
    kept), and fill(params, records, solved, out, lo, hi), their rows lo..hi-1 from inner's
    outputs. A long series not kept lives only for the call. on_block and stop as
    `transverse_chunk`'s."""
    reduced: dict[str, np.ndarray] = {}
    making = threading.Lock()           # blocks are reported from several threads at once

    def outputs_of(solved: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        with making:
            if not reduced:
                reduced.update(solved)
                reduced.update(reduction.empty(params.shape[0]))
        return reduced

    def report(lo: int, hi: int, solved: dict[str, np.ndarray]) -> None:
        out = outputs_of(solved)
        reduction.fill(params, records, solved, out, lo, hi)
        on_block(lo, hi, out)

    solved = inner(params, *inner_args, threads=threads,
                   on_block=None if on_block is None else report, stop=stop)
    if on_block is None:                 # (a dask worker's chunk) every row at once, in parts
        out = outputs_of(solved)         # on the chunk's threads
        from concurrent.futures import ThreadPoolExecutor

        from .threads import thread_count
        n = params.shape[0]
        parts = chunk_ranges(n, max(1, -(-n // thread_count(threads))))
        with ThreadPoolExecutor(max(1, len(parts))) as pool:
            list(pool.map(lambda part: reduction.fill(params, records, solved, out, *part),
                          parts))
    return outputs_of(solved)


def _ends(params: np.ndarray, block: int) -> np.ndarray:
    """Each row's sweep end (s): column kernels.excitation.END of the excitation block that
    starts at column `block`."""
    from sweep.kernels import excitation as ex
    return np.ascontiguousarray(params[:, block + ex.END])


def modes_outputs(n: int, n_samples: int, n_modes: int, n_bands: int = -1) -> dict[str, np.ndarray]:
    """Empty multi-mode outputs of n points: `transverse_outputs` plus modal (n, n_modes), each
    mode's tail amplitude (m), and final (n, 2 n_modes), the final state (m, m/s)."""
    return {**transverse_outputs(n, n_samples, n_bands), "modal": np.empty((n, n_modes)),
            "final": np.empty((n, 2 * n_modes))}


def modes_of(basis: tuple[np.ndarray, ...] | list) -> int:
    """The number of modes of a basis as the kernels take it (sweep.models.basis
    Basis.kernel_arrays(), or a list of them: a BasisFamily's), read as
    kernels.modes.basis_modes reads it."""
    from sweep.kernels import modes as md
    return int((basis[0] if isinstance(basis, list) else basis)[md.RATIOS].shape[1])


def modes_chunk(params: np.ndarray, settings: np.ndarray, n_samples: int,
                basis: tuple[np.ndarray, ...],
                driver: str = "lanes", n_bands: int = -1, per_point_end: bool = False,
                records: np.ndarray | None = None, threads: int = 0,
                on_block: Callable[[int, int, dict], None] | None = None,
                stop: threading.Event | None = None) -> dict[str, np.ndarray]:
    """The multi-mode kernel (kernels.modal_driver) over `params` rows (kernels.modes columns
    for the N modes of `basis`, the mode shapes as the kernels take them:
    sweep.models.basis.Basis.kernel_arrays()); outputs by name (`modes_outputs`); driver
    "lanes" or "scalar" (threads.solve_modes); n_bands, per_point_end, on_block and stop as
    `transverse_chunk`'s. `basis` a list (a BasisFamily's): each row's last column is its
    basis' index; on the lanes every row goes to one call where the bases stack
    (kernels.modes.stacked), else the rows of each basis go to the kernel together."""
    from sweep.kernels import modes as md
    which = family = None
    if isinstance(basis, list):
        family = md.stacked(basis) if driver == "lanes" else None
        if family is None:
            return _family_chunk(params, settings, n_samples, basis, driver, n_bands,
                                 per_point_end, records, threads, on_block, stop)
        which = params[:, -1].astype(np.int64)
        params = np.ascontiguousarray(params[:, :-1])

    from .threads import solve_modes
    out = modes_outputs(params.shape[0], n_samples, modes_of(basis), n_bands)
    report = None if on_block is None else (lambda lo, hi: on_block(lo, hi, out))
    solve_modes(params, basis, settings, out["states"], out["reals"], out["counts"],
                out["series"], out["modal"], out["final"], driver=driver, threads=threads,
                on_block=report, stop=stop, envelope=out.get("envelope"),
                durations=_ends(params, md.EXCITATION) if per_point_end else None,
                records=records, which=which, family=family)
    return out


def _family_chunk(params: np.ndarray, settings: np.ndarray, n_samples: int, family: list,
                  driver: str, n_bands: int, per_point_end: bool,
                  records: np.ndarray | None, threads: int,
                  on_block: Callable[[int, int, dict], None] | None,
                  stop: threading.Event | None) -> dict[str, np.ndarray]:
    """`modes_chunk` of rows whose basis varies (the last column: an index into `family`):
    one kernel call per basis on its rows, whose finished rows are reported under their
    places in `params`. The bases' calls run side by side, one thread each, when there are
    threads for more than one (a basis' rows are often too few to spread over threads
    themselves: harness-clamps' 7 spans per clamp stiffness ran on one of two threads)."""
    from concurrent.futures import ThreadPoolExecutor

    from .threads import thread_count
    index = params[:, -1].astype(np.int64)
    rows = np.ascontiguousarray(params[:, :-1])
    out = modes_outputs(params.shape[0], n_samples, modes_of(family), n_bands)
    lock = threading.Lock()
    bases = np.unique(index)
    workers = min(thread_count(threads), bases.size)
    failed = threading.Event()           # a basis' call raised: the others not yet begun skip

    def solve(b: int) -> None:
        if failed.is_set() or (stop is not None and stop.is_set()):
            return
        at = np.flatnonzero(index == b)

        def report(lo: int, hi: int, part: dict, at: np.ndarray = at) -> None:
            with lock:
                for name, values in part.items():
                    out[name][at[lo:hi]] = values[lo:hi]
                for a, z in _runs(at[lo:hi]):
                    on_block(a, z, out)

        part = modes_chunk(rows[at], settings, n_samples, family[b], driver, n_bands,
                           per_point_end, records, 1 if workers > 1 else threads,
                           report if on_block is not None else None, stop)
        with lock:
            for name, values in part.items():
                out[name][at] = values

    if workers <= 1:
        for b in bases:
            solve(int(b))
        return out
    with ThreadPoolExecutor(workers, thread_name_prefix="cable-sweep-basis") as pool:
        futures = [pool.submit(solve, int(b)) for b in bases]
        try:
            for future in futures:
                future.result()
        except BaseException:
            failed.set()
            if stop is not None:
                stop.set()
            raise
    return out


def _runs(indices: np.ndarray) -> list[tuple[int, int]]:
    """Increasing `indices` as ranges (lo, hi) of consecutive values."""
    if indices.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(indices) != 1) + 1
    return [(int(part[0]), int(part[-1]) + 1) for part in np.split(indices, breaks)]


DWELLS_DONE, CARRIED = "dwells_done", "carried"    # a stepped chunk's progress, by line


def _fits(resume: dict[str, np.ndarray], flat: dict[str, np.ndarray], m: int, width: int,
          dwells: int) -> bool:
    """Whether a stored progress holds exactly the arrays of this chunk of m lines (else its
    lines start again)."""
    want = {k: ((m, dwells) + v.shape[1:], v.dtype) for k, v in flat.items()}
    want[DWELLS_DONE], want[CARRIED] = ((m,), np.dtype(np.int64)), ((m, width), np.dtype(float))
    return (set(resume) == set(want)
            and all(resume[k].shape == s and resume[k].dtype == t for k, (s, t) in want.items())
            and bool(np.all((resume[DWELLS_DONE] >= 0) & (resume[DWELLS_DONE] <= dwells))))


def stepped_chunk(lines: np.ndarray, kernel: Callable[..., dict], kernel_args: tuple,
                  dwells: int, orders: tuple, carry: Any, dwell: float, threads: int = 0,
                  on_block: Callable[[int, int, dict], None] | None = None,
                  stop: threading.Event | None = None,
                  on_progress: Callable[[Callable[[], tuple[dict, int, int]]], None] | None
                  = None, resume: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """Stepped sweeps ([continuation], sweep/models/continuation.py) of whole lines: each row
    of `lines` is one line of `dwells` dwells in one direction, its direction's index into
    `orders` (the visiting orders of the dwells, continuation.dwell_order) in column 0, then
    the dwells' kernel rows one after another. Each line is swept through its dwells by
    `kernel` (transverse_chunk or modes_chunk, with kernel_args), the state and phases carried
    as `carry` says, dwell: the dwell time (s); the lines share `threads`. Returns the kernel's
    outputs with a dwell axis after the first: (lines, dwells, ...). A line is the unit of a
    chunk (a dask task, a stored chunk): its dwells depend on each other.

    Progress within a chunk: after every dwell, on_progress(snapshot) hears that the lines
    moved on; snapshot() returns a consistent copy of the outputs so far with each line's
    finished dwells (DWELLS_DONE) and what its next dwell starts from (CARRIED: state, base
    and load phase), and the numbers of lines whole and part-way. `resume`, such a copy from
    an interrupted run, starts each line where it stopped: the line's results are the same to
    the bit. With `stop` set (an interrupt) no new dwell starts; on_block(0, m, outputs) is
    called only when every line is whole."""
    from .models import continuation as ct
    from .threads import thread_count
    m = lines.shape[0]
    rows = lines[:, 1:].reshape(m * dwells, -1)
    flat = {k: np.empty((m * dwells,) + v.shape[1:], v.dtype)
            for k, v in chunk_template(kernel, kernel_args).items()}
    done = np.zeros(m, np.int64)
    carried = np.zeros((m, len(carry.state) + 2))
    resumed = resume is not None and _fits(resume, flat, m, carried.shape[1], dwells)
    if resumed:
        done[:] = resume[DWELLS_DONE]
        carried[:] = resume[CARRIED]
        for k, v in flat.items():
            v[:] = resume[k].reshape(v.shape)
    direction = lines[:, 0].astype(int)
    line_points = np.arange(m * dwells).reshape(m, dwells)
    groups = []
    for d, order in enumerate(orders):
        which = (direction == d) & (done < dwells)
        if np.any(which):
            groups.append(ct.Lines(line_points[which], np.asarray(order), flat, done[which],
                                   carried[which] if resumed else None))
    lock = threading.Lock()

    def snapshot() -> tuple[dict, int, int]:
        with lock:
            arrays = {k: v.reshape((m, dwells) + v.shape[1:]).copy() for k, v in flat.items()}
            arrays[DWELLS_DONE], arrays[CARRIED] = done.copy(), carried.copy()
        whole = int(np.count_nonzero(arrays[DWELLS_DONE] == dwells))
        return arrays, whole, int(np.count_nonzero(arrays[DWELLS_DONE] > 0)) - whole

    def record(group: ct.Lines, points: np.ndarray, out: dict, count: np.ndarray,
               carried_now: np.ndarray) -> None:
        with lock:
            ct.write_outputs(group, points, out, count, carried_now)
            at = points // dwells
            done[at], carried[at] = count, carried_now
        if on_progress is not None:
            on_progress(snapshot)

    whole = ct.solve_lines(rows, groups, carry, dwell,
                           lambda batch: kernel(batch, *kernel_args, threads=1),
                           workers=thread_count(threads), stop=stop, record=record)
    out = {k: v.reshape((m, dwells) + v.shape[1:]) for k, v in flat.items()}
    if on_block is not None and whole:
        on_block(0, m, out)          # interrupted part-way: the progress holds what was done
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


# --- progress ---------------------------------------------------------------------------------

class Progress:
    """A one-line tqdm bar on stderr of points done, their rate and the time left; does nothing
    when not `enabled`. Safe to advance from several threads. The time Numba spends compiling
    is taken off the bar's clock (`exclude`), so the rate and the time left are the kernel's."""

    def __init__(self, total: int, done: int, enabled: bool, unit: str = "points") -> None:
        self.lock = threading.Lock()
        self.bar = None
        if enabled:
            from tqdm import tqdm
            # smoothing=0: the rate is the average since the start (compiling excluded), the
            # honest one for points solved in a random order
            self.bar = tqdm(total=total, initial=done, unit=f" {unit}",
                            dynamic_ncols=True, smoothing=0.0, mininterval=0.5,
                            file=sys.stderr, leave=True)

    def advance(self, points: int) -> None:
        if self.bar is not None:
            with self.lock:
                self.bar.update(points)

    def exclude(self, seconds: float) -> None:
        """Take `seconds` (s) spent compiling off the bar's clock."""
        if self.bar is not None:
            with self.lock:
                self.bar.start_t += seconds

    def write(self, text: str) -> None:
        """A line of text on stderr, above the bar when there is one."""
        if self.bar is not None:
            from tqdm import tqdm
            tqdm.write(text, file=sys.stderr)
        else:
            sys.stderr.write(text + "\n")
            sys.stderr.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class CompileClock:
    """Seconds Numba has spent compiling so far (s), and whether it has started once."""
    seconds = 0.0


@contextlib.contextmanager
def announce_compilation(enabled: bool,
                         progress: Progress | None = None) -> Iterator[CompileClock]:
    """Within the block, say on stderr when Numba compiles a kernel (a cold start: seconds with
    nothing else on the screen; not when it loads one from its cache) and, at the end, how long
    compiling took; the time is counted (the CompileClock yielded) and taken off `progress`'s
    clock either way. Only in-process compiles are seen (not a dask worker's)."""
    from numba.core import event
    out = progress or Progress(0, 0, False)
    clock = CompileClock()

    class Notice(event.Listener):
        depth = 0
        started = 0.0
        announced = False

        def on_start(self, ev: event.Event) -> None:
            if self.depth == 0:
                if enabled and not self.announced:
                    out.write("compiling the Numba kernels this sweep needs (once: later runs "
                              "load them from Numba's cache) ...")
                    self.announced = True
                self.started = time.perf_counter()
            self.depth += 1

        def on_end(self, ev: event.Event) -> None:
            self.depth -= 1
            if self.depth == 0:
                seconds = time.perf_counter() - self.started
                clock.seconds += seconds
                out.exclude(seconds)

    with event.install_listener("numba:compile", Notice()):
        yield clock
    if enabled and clock.seconds > 0.0:
        out.write(f"compiled in {clock.seconds:.1f} s")


# --- execution ------------------------------------------------------------------------------

def chunk_ranges(n: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(lo, min(n, lo + chunk_size)) for lo in range(0, n, chunk_size)]


DASK_LEAST_TASK_POINTS = 64
"""A dask task's fewest points: four lock-step groups of lanes; its scheduling costs a few ms,
a point 0.02-300 ms."""


def default_chunk_size(n: int, backend: str, workers: int) -> int:
    """Points per chunk, at most: for threads, enough for every thread's lanes and at most 100
    chunks (checkpoints and progress come from the blocks inside a chunk, by time); for dask,
    about 8 tasks per worker, of at least DASK_LEAST_TASK_POINTS: a task is saved only when it
    ends, so every worker gets several and an interrupt keeps the finished ones (a minimum of
    2 000 points made any sweep below 2 000 x 8 x workers one task, all lost on Ctrl-C)."""
    import numba
    if backend == "dask":
        return max(DASK_LEAST_TASK_POINTS, -(-n // (8 * max(workers, 1))))
    return max(4096 * numba.get_num_threads(), -(-n // 100))


def missing_ranges(n: int, done: dict[tuple[int, int], dict],
                   where: str = "chunk store") -> list[tuple[int, int]]:
    """The ranges of points 0..n-1 that no chunk in `done` covers, in order. Chunks that
    overlap, lie outside the grid or hold arrays of the wrong length are refused (UserError)."""
    gaps = []
    at = 0
    for lo, hi in sorted(done):
        lengths = {len(v) for v in done[(lo, hi)].values()}
        if not at <= lo < hi <= n or lengths - {hi - lo}:
            raise UserError(f"{where}: chunk {lo}-{hi} overlaps another, lies outside the "
                            f"{n:,} points or holds the wrong number of them (remove the store, "
                            "or use --overwrite to start again)")
        if lo > at:
            gaps.append((at, lo))
        at = hi
    if at < n:
        gaps.append((at, n))
    return gaps


class _Keeper:
    """The finished, not yet saved blocks of the chunk in hand: saved to the store at the first
    block end FLUSH_SECONDS after the last save, and whatever is left when the chunk ends or the
    run stops. A chunk of lines (a stepped sweep) reports its progress instead, as a snapshot
    of its part-way lines, saved the same way as the chunk's progress file."""

    def __init__(self, store: ChunkStore | None, progress: Progress) -> None:
        self.store, self.progress = store, progress
        self.lock = threading.Lock()
        self.base = 0
        self.arrays: dict = {}
        self.pending: list[tuple[int, int]] = []
        self.snapshot: Callable[[], tuple[dict, int, int]] | None = None
        self.size = 0
        self.saved = 0                   # points saved to the store by this run
        self.whole = self.partway = 0    # lines whole or part-way in the last progress saved
        self.flushed = time.perf_counter()

    def begin(self, base: int, size: int = 0) -> None:
        self.base, self.arrays, self.pending, self.size = base, {}, [], size
        self.snapshot, self.whole, self.partway = None, 0, 0

    def finished(self, lo: int, hi: int, arrays: dict) -> None:
        """Rows lo..hi-1 of the chunk in hand are final (called from the solving thread)."""
        with self.lock:
            self.arrays = arrays
            self.pending.append((lo, hi))
            self.snapshot = None             # the chunk file supersedes its progress
            self.progress.advance(hi - lo)
            if time.perf_counter() - self.flushed >= FLUSH_SECONDS:
                self._flush()

    def progressed(self, snapshot: Callable[[], tuple[dict, int, int]]) -> None:
        """The chunk in hand moved on; snapshot() gives its progress (stepped_chunk)."""
        with self.lock:
            self.snapshot = snapshot
            if time.perf_counter() - self.flushed >= FLUSH_SECONDS:
                self._flush()

    def flush(self) -> None:
        with self.lock:
            self._flush()

    def _flush(self) -> None:
        if self.store is not None:
            for lo, hi in _merged(self.pending):
                self.store.save(self.base + lo, self.base + hi,
                                {k: v[lo:hi] for k, v in self.arrays.items()})
                self.saved += hi - lo
            if self.snapshot is not None:
                arrays, self.whole, self.partway = self.snapshot()
                self.store.save_progress(self.base, self.base + self.size, arrays)
                self.snapshot = None
        self.pending = []
        self.flushed = time.perf_counter()


def _merged(ranges: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Adjacent ranges joined: [(0, 5), (9, 12), (5, 9)] -> [(0, 12)]."""
    out: list[list[int]] = []
    for lo, hi in sorted(ranges):
        if out and out[-1][1] == lo:
            out[-1][1] = hi
        else:
            out.append([lo, hi])
    return [(lo, hi) for lo, hi in out]


TERMINATING = (signal.SIGTERM, signal.SIGHUP)   # handled as Ctrl-C is (exit status 128 + signum)


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP (`signum`) arrived outside a chunked solve (see terminate_raises)."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(f"terminated by {signal.Signals(signum).name}")


def _raise_terminated(signum: int, frame: Any) -> None:
    raise Terminated(signum)


@contextlib.contextmanager
def terminate_raises() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise Terminated (a KeyboardInterrupt) as Ctrl-C
    raises KeyboardInterrupt, instead of ending the process at once: temporary files are
    removed and one line is printed. Only in the main thread, over the default handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.getsignal(s) for s in TERMINATING}
    for s, handler in previous.items():
        if handler is signal.SIG_DFL:
            signal.signal(s, _raise_terminated)
    try:
        yield
    finally:
        for s, handler in previous.items():
            if handler is signal.SIG_DFL:
                signal.signal(s, handler)


@contextlib.contextmanager
def _stopping_signals(handler: Callable[[int, Any], None]) -> Iterator[None]:
    """Within the block, `handler` answers Ctrl-C (SIGINT), SIGTERM and SIGHUP. Only in the main
    thread, and only over Python's own SIGINT handler and the default (or terminate_raises's)
    SIGTERM and SIGHUP handlers (not over one a caller installed, nor where one is ignored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    ours = {signal.SIGINT: (signal.default_int_handler,)}
    ours.update({s: (signal.SIG_DFL, _raise_terminated) for s in TERMINATING})
    taken = [s for s, defaults in ours.items() if signal.getsignal(s) in defaults]
    previous = {s: signal.signal(s, handler) for s in taken}
    try:
        yield
    finally:
        for s, before in previous.items():
            signal.signal(s, before)


@contextlib.contextmanager
def signals_held() -> Iterator[list[int]]:
    """Within the block, Ctrl-C, SIGTERM and SIGHUP are recorded (their numbers appended to the
    list yielded) instead of raising (`_stopping_signals`): for the final write of a finished
    run, which an exception inside netCDF4 or xarray would leave half done (xarray's file lock,
    taken when the exception struck, is then awaited for ever in its close)."""
    received: list[int] = []
    with _stopping_signals(lambda signum, frame: received.append(signum)):
        yield received


@contextlib.contextmanager
def _interrupt_sets(stop: threading.Event) -> Iterator[list[int]]:
    """Within the block, Ctrl-C, SIGTERM and SIGHUP set `stop` instead of ending the run at
    once (`_stopping_signals`), so it ends after the blocks in hand and keeps them; the
    signal's number is appended to the list yielded. A second one raises KeyboardInterrupt."""
    received: list[int] = []

    def handler(signum: int, frame: Any) -> None:
        if stop.is_set():
            raise KeyboardInterrupt
        received.append(signum)
        stop.set()

    with _stopping_signals(handler):
        yield received


def execute(chunk_fn: Callable[..., dict], rows_for: Callable[[int, int], np.ndarray], n: int,
            args: tuple, place: Callable[[int, int, dict], None], *, chunk_size: int,
            backend: str = "threads", threads: int = 0, scheduler: str | None = None,
            workers: int = 0, progress: bool = False, announce: bool | None = None,
            store: ChunkStore | None = None, done: dict | None = None,
            partial: dict | None = None, unit: str = "points") -> int:
    """Solve points 0..n-1 (solve order) chunk by chunk; returns the number of points computed.

    rows_for(lo, hi) builds the kernel's parameter rows of a chunk just before it runs, so the
    whole table never sits in memory; chunk_fn(rows, *args, threads=...) returns the chunk's
    output arrays by name, and place(lo, hi, arrays) stores them. A chunk_fn that takes
    `on_block` and `stop` (transverse_chunk) reports its finished blocks and stops early when
    asked. Chunks in `done` (from a store) are placed, not computed; finished work is also
    written to `store` (see FLUSH_SECONDS). Chunks have at most chunk_size points. `partial`
    (from a store: (lo, hi) -> arrays) holds chunks of lines left part-way, which a chunk_fn
    taking `resume` (stepped_chunk) continues on the threads backend.
    On Ctrl-C the run stops after the work in hand, saves it and raises RunInterrupted.
    When the dask cluster fails (a worker that keeps dying, a lost scheduler, a malformed
    result) the run stops with the finished chunks kept and raises one UserError line.
    progress: the bar (a terminal); announce: the compile lines (default: as progress);
    unit: what a row is, for the bar and the interrupt line ("points"; a stepped sweep's
    "lines").
    """
    done = done or {}
    where = f"chunk store '{store.directory}'" if store is not None else "chunk store"
    gaps = missing_ranges(n, done, where)
    todo = sum(hi - lo for lo, hi in gaps)
    for (lo, hi), arrays in done.items():
        place(lo, hi, arrays)
    bar = Progress(n, n - todo, progress, unit)
    keeper = _Keeper(store, bar)
    stop = threading.Event()
    failure = None
    try:
        with _interrupt_sets(stop) as received, \
                announce_compilation(progress if announce is None else announce,
                                     bar) as clock:
            if backend == "dask":
                try:
                    _execute_dask(chunk_fn, rows_for, args, _split(gaps, chunk_size), keeper,
                                  place, scheduler, workers, stop)
                except ClusterFailed as exc:
                    failure = exc
            else:
                _execute_threads(chunk_fn, rows_for, args, gaps, chunk_size, threads, keeper,
                                 place, stop, clock, partial or {})
    finally:
        keeper.flush()                   # what was finished when something went wrong
        bar.close()
    if failure is not None:
        raise UserError(_stopped_line(failure, n - todo + keeper.saved, n, store)) from None
    if stop.is_set():
        raise RunInterrupted(n - todo + keeper.saved + keeper.whole, n,
                             store.directory if store is not None else None,
                             received[0] if received else signal.SIGINT, unit, keeper.partway)
    return todo


def _split(gaps: list[tuple[int, int]], size: int) -> list[tuple[int, int]]:
    return [(a + lo, a + hi) for a, b in gaps for lo, hi in chunk_ranges(b - a, size)]


def _execute_threads(chunk_fn, rows_for, args, gaps, chunk_size, threads, keeper, place, stop,
                     clock, partial) -> None:
    """Chunks one after another in this process. A chunk_fn that reports blocks gets chunks of
    chunk_size; another gets chunks sized from its measured speed (compiling excluded) to take
    about CHUNK_SECONDS, growing at most fourfold from one chunk to the next. A chunk_fn that
    takes `resume` (stepped_chunk) reports its progress and resumes a chunk from the progress
    in `partial` ((lo, hi) -> arrays, from the store) that an interrupted run left."""
    from .threads import thread_count
    streams = "on_block" in inspect.signature(chunk_fn).parameters
    resumes = "resume" in inspect.signature(chunk_fn).parameters
    size = chunk_size if streams else min(chunk_size, FIRST_CHUNK * thread_count(threads))
    for a, b in gaps:
        lo = a
        while lo < b and not stop.is_set():
            hi = min(b, lo + size)
            rows = rows_for(lo, hi)
            keeper.begin(lo, hi - lo)
            if streams:
                more = {}
                if resumes:
                    more = {"on_progress": keeper.progressed, "resume": partial.get((lo, hi))}
                arrays = chunk_fn(rows, *args, threads=threads, on_block=keeper.finished,
                                  stop=stop, **more)
                if stop.is_set():
                    return                   # partly solved: the keeper has the finished rows
                keeper.flush()
                place(lo, hi, arrays)
            else:
                began, compiling = time.perf_counter(), clock.seconds
                arrays = chunk_fn(rows, *args, threads=threads)
                keeper.finished(0, hi - lo, arrays)
                keeper.flush()
                place(lo, hi, arrays)
                seconds = time.perf_counter() - began - (clock.seconds - compiling)
                grown = 4 * (hi - lo)
                if seconds > 0.0:
                    grown = min(grown, int((hi - lo) * CHUNK_SECONDS / seconds))
                size = max(1, min(chunk_size, grown))
            lo = hi


# --- dask -------------------------------------------------------------------------------------
# Connecting to a cluster trusts it: the client unpickles what the cluster sends back, and
# unpickling can run code in this process. So the address comes only from the operator (the
# --scheduler option or sweep.run's scheduler argument, never a scene file), and every result
# is checked to be exactly the arrays its chunk makes before it is placed or stored.

SCHEMES = ("tcp", "tls")   # dask scheduler address protocols accepted
ALLOWED_FAILURES = 1       # a task whose worker dies is run once more, then the run stops
CONNECT_SECONDS = 10.0     # to reach a scheduler (s)
NO_WORKER_SECONDS = 60.0   # a cluster without any worker thread this long stops the run (s)
POLL_SECONDS = 0.5         # the client looks at Ctrl-C and the cluster this often (s)


class ClusterFailed(Exception):
    """The dask cluster failed the run; the message says what happened, in one line."""


def _shown(value: Any, limit: int = 60) -> str:
    """A value for a one-line message: repr'd (control characters escaped) and shortened."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def check_scheduler(address: Any, where: str = "--scheduler") -> str:
    """`address` when it is a dask scheduler address, PROTOCOL://HOST:PORT with PROTOCOL tcp or
    tls and PORT 1..65535; otherwise a one-line UserError naming `where`. Contacts nothing."""
    from urllib.parse import urlsplit
    fix = "give the scheduler's address as tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786"
    if not isinstance(address, str):
        raise UserError(f"{where} {_shown(address)}: not an address ({fix})")
    shown = _shown(address)
    try:
        parts = urlsplit(address)
        port = parts.port
    except ValueError:
        raise UserError(f"{where} {shown}: the port must be a number from 1 to 65535 "
                        f"({fix})") from None
    if parts.scheme not in SCHEMES:
        raise UserError(f"{where} {shown}: not a dask scheduler address ({fix}; the "
                        f"protocol is one of {', '.join(s + '://' for s in SCHEMES)})")
    if not parts.hostname or not port:
        raise UserError(f"{where} {shown}: needs a host and a port from 1 to 65535 ({fix})")
    if parts.path not in ("", "/") or parts.query or parts.fragment or "@" in parts.netloc:
        raise UserError(f"{where} {shown}: has more than PROTOCOL://HOST:PORT ({fix})")
    return address


def chunk_template(chunk_fn: Callable[..., dict], args: tuple) -> dict[str, np.ndarray]:
    """The arrays chunk_fn(rows, *args) makes for no rows: their names, dtypes and trailing
    shapes. A chunk of points lo..hi-1 must return exactly these with hi - lo rows."""
    if chunk_fn is transverse_chunk:
        n_samples, n_bands = args[1], (args[3] if len(args) > 3 else -1)
        return transverse_outputs(0, n_samples, n_bands)
    if chunk_fn is modes_chunk:
        n_samples, basis, n_bands = args[1], args[2], (args[4] if len(args) > 4 else -1)
        return modes_outputs(0, n_samples, modes_of(basis), n_bands)
    if chunk_fn is reduced_chunk:
        inner, inner_args, reduction = args[0], args[1], args[2]
        return {**chunk_template(inner, inner_args), **reduction.empty(0)}
    if chunk_fn is stepped_chunk:
        kernel, kernel_args, dwells = args[0], args[1], args[2]
        return {k: np.empty((0, dwells) + v.shape[1:], v.dtype)
                for k, v in chunk_template(kernel, kernel_args).items()}
    if chunk_fn is longitudinal_chunk:
        _, snapshot_times, n_hist, n_nodes = args
        return longitudinal_outputs(0, n_hist, np.asarray(snapshot_times).size, n_nodes)
    raise TypeError(f"{_shown(chunk_fn)}: not a chunk function of sweep.execute")


def check_chunk(arrays: Any, lo: int, hi: int,
                template: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """`arrays` when it is exactly what the chunk of points lo..hi-1 makes: a dict with the
    names of `template`, each a numpy array of its dtype and of shape (hi - lo, *its trailing
    shape). Otherwise ClusterFailed, saying what is wrong. Values are not judged."""
    what = f"the result of chunk {lo}-{hi} from the cluster"
    if type(arrays) is not dict:
        raise ClusterFailed(f"{what} is a {_shown(type(arrays).__name__)}, not the kernel's "
                            "arrays by name; refused")
    missing = [k for k in template if k not in arrays]
    extra = [k for k in arrays if k not in template]
    if missing or extra:
        raise ClusterFailed(f"{what} has the wrong arrays (missing {_shown(missing)}, "
                            f"unexpected {_shown(extra)}); refused")
    for name, want in template.items():
        got = arrays[name]
        shape = (hi - lo,) + want.shape[1:]
        if type(got) is not np.ndarray:
            raise ClusterFailed(f"{what}: '{name}' is a {_shown(type(got).__name__)}, not a "
                                "numpy array; refused")
        if got.dtype != want.dtype or got.shape != shape:
            raise ClusterFailed(f"{what}: '{name}' is {got.dtype} {got.shape}, not "
                                f"{want.dtype} {shape}; refused")
    return arrays


def _stopped_line(failure: Exception, kept: int, total: int, store: ChunkStore | None) -> str:
    """The one line a failed dask run ends with: what happened, what is kept, how to go on."""
    if store is None:
        return (f"dask: {failure}; the run stopped and nothing was kept (a run with -o OUT.nc "
                "keeps its finished chunks, and --resume then computes only the rest)")
    if kept == 0:
        return (f"dask: {failure}; the run stopped before any point was finished: nothing is "
                "kept (run the same command again once the cluster is fixed)")
    return (f"dask: {failure}; the run stopped: {kept:,} of {total:,} points are kept in "
            f"'{store.directory}' (run the same command with --resume, or sweep.run with "
            "resume=True, to compute only the rest)")


@contextlib.contextmanager
def _quiet_dask() -> Iterator[None]:
    """Within the block: dask's retries and waits bounded (ALLOWED_FAILURES, CONNECT_SECONDS)
    and its loggers in this process silenced, so that a failure is the run's one line and not
    pages of dask's tracebacks. Restored afterwards."""
    import logging

    import dask
    names = ["distributed", "tornado", "bokeh"] + [
        name for name in list(logging.root.manager.loggerDict)
        if name.startswith(("distributed.", "tornado.", "bokeh."))]
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    settings = {"distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
                "distributed.comm.timeouts.connect": f"{CONNECT_SECONDS}s"}
    # A LocalCluster's worker processes set up their logging from the environment they start
    # with (one that dies is restarted during the run)
    quiet = {"DASK_LOGGING__DISTRIBUTED": "critical", "DASK_LOGGING__TORNADO": "critical"}
    saved = {name: os.environ.get(name) for name in quiet}
    with dask.config.set(settings):
        for logger in loggers:
            logger.setLevel(logging.CRITICAL + 1)
        os.environ.update(quiet)
        try:
            yield
        finally:
            for logger, level in zip(loggers, levels):
                logger.setLevel(level)
            for name, value in saved.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value


def _connect(scheduler: str | None, workers: int) -> tuple[Any, Any]:
    """A dask Client of the scheduler at `scheduler`, or of a LocalCluster of `workers`
    single-threaded worker processes on this machine (0: one per core); and that cluster."""
    import asyncio                                   # the dask path only
    import logging

    from dask.distributed import Client, LocalCluster
    if scheduler:
        try:
            _handshake(scheduler)
            return Client(scheduler, timeout=CONNECT_SECONDS), None
        except (Exception, asyncio.CancelledError) as exc:
            raise UserError(f"dask scheduler {_shown(scheduler)}: none answers there within "
                            f"{CONNECT_SECONDS:.0f} s ({type(exc).__name__}; check the address "
                            "and that the scheduler runs, e.g. tcp://HOST:8786)") from None
    import dask
    cluster = None
    try:
        # No dashboard; the scheduler's HTTP server (health and metrics routes, which it
        # always starts) on a free loopback port: on its default, 8787, it warns "Port 8787 is
        # already in use" to the user whenever another cluster or process holds that port.
        with dask.config.set({"distributed.worker.preload": ["sweep.dask_worker"]}):
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                                   threads_per_worker=1,
                                   processes=True, dashboard_address=None, host="127.0.0.1",
                                   scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                                   silence_logs=logging.CRITICAL + 1)
        return Client(cluster, timeout=CONNECT_SECONDS), cluster
    except (Exception, asyncio.CancelledError) as exc:
        _close(None, cluster)
        raise ClusterFailed(f"the LocalCluster did not start ({type(exc).__name__}: "
                            f"{_shown(str(exc), 120)})") from None


def _handshake(address: str) -> None:
    """Raise TimeoutError unless a dask server at `address` completes dask's handshake within
    CONNECT_SECONDS: dask's own connect waits for the handshake without bound, so a listener
    that accepts and never answers would hang the Client forever. On a thread of its own, with
    its own event loop (the caller may be running one, as in Jupyter)."""
    import asyncio                                   # the dask path only
    from distributed.comm import connect
    from distributed.security import Security
    outcome: list = []

    async def probe() -> None:
        comm = await asyncio.wait_for(
            connect(address, timeout=CONNECT_SECONDS,
                    **Security().get_connection_args("client")), CONNECT_SECONDS)
        await comm.close()

    def run() -> None:
        try:
            asyncio.run(probe())
            outcome.append(None)
        except (Exception, asyncio.CancelledError) as exc:
            outcome.append(exc)

    thread = threading.Thread(target=run, name="sweep-dask-handshake", daemon=True)
    thread.start()
    thread.join(CONNECT_SECONDS + 2.0)
    if not outcome:
        raise TimeoutError(f"no dask handshake from {address}")
    if outcome[0] is not None:
        raise outcome[0]


def _close(client: Any, cluster: Any) -> None:
    """Close what _connect opened, whatever state the cluster is in, quietly."""
    import asyncio                                   # the dask path only
    for thing in (client, cluster):
        if thing is not None:
            with contextlib.suppress(Exception, asyncio.CancelledError):
                thing.close(timeout=CONNECT_SECONDS)


def _execute_dask(chunk_fn, rows_for, args, todo, keeper, place, scheduler, workers,
                  stop) -> None:
    """Each chunk a task on a dask.distributed cluster: the one at `scheduler` (an address), or
    a LocalCluster of `workers` single-threaded worker processes started for this run. At most
    IN_FLIGHT tasks per worker thread are submitted at a time, so memory stays bounded. Every
    result is checked (check_chunk) before it is placed or stored. A cluster that fails (a
    worker that keeps dying, a lost scheduler, a failed task, no workers) raises
    ClusterFailed; the chunks finished before are kept."""
    try:
        import distributed  # noqa: F401
    except ImportError as exc:
        raise UserError("run.backend = 'dask': dask.distributed is not installed "
                        "(pip install distributed)") from exc
    template = chunk_template(chunk_fn, args)
    with _quiet_dask():
        client, cluster = _connect(scheduler, workers)
        try:
            _run_tasks(client, chunk_fn, rows_for, args, todo, keeper, place, stop, template,
                       f"the scheduler at {scheduler}" if scheduler else "the LocalCluster")
        finally:
            _close(client, cluster)


def _run_tasks(client, chunk_fn, rows_for, args, todo, keeper, place, stop, template,
               where: str) -> None:
    """Submit the chunks `todo` to `client`'s cluster, and place and keep their checked
    results as they come, watching for Ctrl-C (`stop`) and a failing cluster."""
    import asyncio                                   # the dask path only
    from dask.distributed import wait
    pending = iter(todo)
    futures: dict = {}

    def submit_next() -> None:
        for lo, hi in pending:
            # one kernel thread per task: one per dask worker thread, no oversubscription
            futures[client.submit(chunk_fn, rows_for(lo, hi), *args, threads=1,
                                  pure=False)] = (lo, hi)
            return

    for _ in range(IN_FLIGHT * max(1, _threads(client, where))):
        submit_next()
    idle_since = None
    while futures:
        try:
            finished = wait(list(futures), timeout=POLL_SECONDS,
                            return_when="FIRST_COMPLETED").done
        except TimeoutError:
            finished = set()
        except (Exception, asyncio.CancelledError) as exc:
            # e.g. FuturesCancelledError: the scheduler was lost (killed, network down)
            raise ClusterFailed(f"lost the connection to {where} while waiting for results "
                                f"({type(exc).__name__})") from None
        if stop.is_set():
            return
        if not finished:
            if _threads(client, where) > 0:
                idle_since = None
            elif idle_since is None:
                idle_since = time.perf_counter()
            elif time.perf_counter() - idle_since > NO_WORKER_SECONDS:
                raise ClusterFailed(f"{where} has had no worker for {NO_WORKER_SECONDS:.0f} s")
            continue
        for fut in sorted(finished, key=futures.get):      # in point order
            lo, hi = futures.pop(fut)
            arrays = _result(fut, lo, hi, where, stop)
            if stop.is_set():
                return
            check_chunk(arrays, lo, hi, template)
            keeper.begin(lo)
            keeper.finished(0, hi - lo, arrays)
            keeper.flush()
            place(lo, hi, arrays)
            submit_next()


def _threads(client: Any, where: str) -> int:
    """The number of worker threads `client`'s cluster has now."""
    import asyncio                                   # the dask path only
    try:
        return sum(client.nthreads().values())
    except (Exception, asyncio.CancelledError) as exc:
        raise ClusterFailed(f"lost the connection to {where} ({type(exc).__name__})") from None


def _result(fut: Any, lo: int, hi: int, where: str, stop: threading.Event) -> Any:
    """A finished task's result, or ClusterFailed saying why there is none."""
    import asyncio                                   # the dask path only
    from dask.distributed import KilledWorker
    try:
        return fut.result()
    except KilledWorker as exc:
        raise ClusterFailed(f"chunk {lo}-{hi}: the worker running it died "
                            f"{exc.allowed_failures + 1} times on {where} (out of memory, "
                            "killed, or crashed)") from None
    except asyncio.CancelledError:
        if stop.is_set():
            return None
        raise ClusterFailed(f"lost the connection to {where}") from None
    except Exception as exc:
        if stop.is_set():        # Ctrl-C reached the workers too
            return None
        text = str(exc).splitlines()[0] if str(exc) else ""
        raise ClusterFailed(f"chunk {lo}-{hi} failed on a worker of {where} "
                            f"({type(exc).__name__}: {_shown(text, 120)})") from None
