"""The transverse kernel over a table of points on Python threads, one block of points at a time.

Each driver's kernel (`kernels.lanes.solve_block`, `kernels.transverse.solve_block`) solves a
contiguous block of rows and releases the GIL, so plain threads run blocks side by side. They
draw blocks from one queue, shrinking as the points run out (guided scheduling): a thread
whose points were cheap takes more, which balances the ~3x cost spread between short and long
spans better than a static schedule. There is no Numba parallel region to compile (that alone
took ~3 s on a cold cache), and a point's result never depends on the blocks or the number of
threads.

Blocks are also sized by time: once a thread has timed a block (a grid of at most two
MIN_TIMED_BLOCK blocks a thread is split into equal shares instead), its next one takes about
BLOCK_SECONDS (never fewer than MIN_TIMED_BLOCK points on the lanes, whose lanes drain at a
block's end; SCALAR_BLOCK on a scalar driver, which has none). A block of slow points
(several modes: 64 of them took 17 s) is not waited for: a watcher thread looks every
WATCH_SECONDS at the rows of the blocks in progress, and a caller's `on_block(lo, hi)` hears
of rows as soon as they are final (a checkpoint, a progress bar), every WATCH_SECONDS or so,
whatever the block. A `stop` event (an interrupt) reaches the kernels through their `halt`
flag, which the watcher sets: they return at once (the lanes drivers) or before their next row
(the scalar ones), the rows not finished left unsolved for a resume to compute.

Points a driver leaves SECOND_PASS (at rest away from zero, settling wanted) are finished by
`kernels.transverse.settle_second_pass` block by block, compiled only when a sweep has one (or
ahead of a run: COMPILE_AHEAD), never for random records (their state is final).
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable

import numpy as np

from .specialise import call, entry_point

MIN_BLOCK = 128        # points per block, at least (smaller blocks leave lanes idle as they drain)
MAX_BLOCK = 1024       # at most
SHARE = 2              # a block is at most 1/SHARE of a thread's share of the points left
LANES_PER_THREAD = 16  # a thread for every 16 points (one lanes group), at most
BLOCK_SECONDS = 2.0    # a timed block takes about this long on one thread (s)
MIN_TIMED_BLOCK = 64   # points per timed block, at least (4 per lane: a block's lanes drain at
                       # its end, which costs more the fewer points each lane gets)
SOLO_BLOCK = 8192      # at most, on one thread (nothing to balance: fewer drains)
TAIL_SHARE = 4         # on one thread, a block takes the points after it too when they are
                       # fewer than 1/TAIL_SHARE of it: a block of a few points costs the lanes
                       # a drain of their own at a fraction of their speed (harness-base-sine's
                       # 130 points were blocks of 64, 64 and 2)
SCALAR_BLOCK = 4       # points per block, at least, on a scalar driver: it has no lanes to
                       # drain, so its blocks shrink further and the threads end together
                       # (benchmarks/RESULTS.md: a 144-point random scene, about 5 % less)
COMPILE_AHEAD = threading.Event()
"""Set by sweep.warmup (`sweep compile`): the follow-up passes a block needs only when some
point ends in a particular way (a second pass, a mode judged off midspan) are compiled even
where no point needs them, so that a later run compiles nothing."""

WATCH_SECONDS = 0.25   # the watcher reports final rows and passes on an interrupt this often (s)


def _follow_up(kernel: Any, needed: bool, *args: Any) -> None:
    """kernel(*args) through `call` where needed; otherwise, with COMPILE_AHEAD set, only its
    entry point compiled (or loaded from the cache)."""
    if needed:
        call(kernel, *args)
    elif COMPILE_AHEAD.is_set():
        entry_point(kernel, *args)


def thread_count(threads: int = 0) -> int:
    """Threads a call runs on: `threads`, or 0 for Numba's default (NUMBA_NUM_THREADS, all
    cores unless set), capped at that default."""
    import numba
    limit = numba.config.NUMBA_NUM_THREADS
    return min(threads, limit) if threads > 0 else limit


def next_block(lo: int, n: int, n_threads: int, cap: int = MAX_BLOCK,
               least: int = MIN_BLOCK) -> int:
    """End of the block that starts at row `lo` of n, on n_threads threads: guided scheduling,
    blocks shrinking with the points left, from `cap` (at most MAX_BLOCK) down to `least`
    (MIN_BLOCK for the lanes, SCALAR_BLOCK for a scalar driver; or to an equal share of a
    small grid, or to `cap`), so the threads finish together while blocks stay long enough to
    keep the lanes full. One thread takes blocks of `cap` (at most SOLO_BLOCK)."""
    if n_threads == 1:                              # nothing to balance: fewer lane drains
        hi = min(n, lo + min(cap, SOLO_BLOCK))
        return n if n - hi < (hi - lo) // TAIL_SHARE else hi
    cap = min(cap, MAX_BLOCK)
    floor = min(least, cap, -(-n // n_threads))
    size = (n - lo) // (SHARE * n_threads)
    return min(n, lo + max(floor, min(cap, size)))


def timed_cap(points: int, seconds: float, most: int = MAX_BLOCK,
              least: int = MIN_TIMED_BLOCK) -> int:
    """Points the next block of a thread gets so it takes about BLOCK_SECONDS, from the last
    block's `points` in `seconds` (s): between `least` (MIN_TIMED_BLOCK for the lanes) and
    `most`."""
    if seconds <= 0.0:
        return most
    return max(least, min(most, int(points * BLOCK_SECONDS / seconds)))


def solve_transverse(params: np.ndarray, settings: np.ndarray, states: np.ndarray,
                     reals: np.ndarray, counts: np.ndarray, series: np.ndarray, *,
                     driver: str = "lanes", threads: int = 0,
                     on_block: Callable[[int, int], None] | None = None,
                     stop: threading.Event | None = None,
                     envelope: np.ndarray | None = None,
                     durations: np.ndarray | None = None,
                     records: np.ndarray | None = None) -> None:
    """Solve every row of `params` (n, N_PARAMS) into the preallocated outputs (first axis n):
    states int8, reals (n, N_REALS), counts (n, N_COUNTS) int64, series (n, n_samples).
    A swept base frequency (settings[SWEPT] = 1) takes envelope (n, n_bands) for its response
    envelope and durations (n,), each point's end time (s; `swept_settings`), on either
    driver (the lanes: kernels.lanes.solve_swept_block).
    records: a random base acceleration's (R, N, 4) records (sweep.models.random.Records'
    values), which the kernels take as their `base` switch (kernels.excitation's record kind),
    on either driver.

    driver: "lanes" (lock-step SIMD lanes, the default) or "scalar" (SciPy's arithmetic, one
    trajectory after another); threads: 0 for all (see thread_count). on_block(lo, hi) is
    called once rows lo..hi-1 are final, every row once, in order within a block (from the
    solving thread or the watcher: `Watch`), within about WATCH_SECONDS of their turning so;
    with `stop` set, no new block starts, the kernels stop within about WATCH_SECONDS (the
    lanes drivers) or before their next row (the scalar ones), and the call returns with the
    rows it did not finish unsolved (on_block says which are solved).
    """
    from sweep.kernels import lanes
    from sweep.kernels import metrics as mt
    from sweep.kernels import transverse as tk
    if driver not in ("lanes", "scalar"):
        raise ValueError(f"driver {driver!r}: expected 'lanes' or 'scalar'")
    from sweep.kernels import oscillator as osc
    # Compile-time switches (None or True: one specialisation each, see lanes.solve_block)
    constant = settings[tk.CONSTANT_STIFFNESS] != 0.0
    if constant and (np.any(params[:, osc.K1] != 0.0) or np.any(params[:, osc.G1] != 0.0)):
        raise ValueError("settings say CONSTANT_STIFFNESS but a row has k1 or g1 != 0")
    parametric, base = osc.terms_of(parametric=not constant, base=settings[tk.BASE] != 0.0)
    base = _random_base(records, base)
    eighth = method_switch(settings)
    swept = settings[tk.SWEPT] != 0.0
    pi = True if settings[tk.CONTROLLER] != 0.0 else None
    if swept and driver == "lanes":
        ends = np.full(params.shape[0], settings[tk.T_END]) if durations is None else durations
        if envelope is None:
            envelope = np.empty((params.shape[0], 0))

        def kernel(lo: int, hi: int) -> None:
            call(lanes.solve_swept_block, params, settings, lo, hi, states, reals, counts,
                 series, envelope, ends, pi, eighth, parametric, base, watch.halt)
    elif swept:
        def kernel(lo: int, hi: int) -> None:
            for i in range(lo, hi):
                call(tk.solve_swept_block, params, swept_settings(settings, durations, i), i,
                     i + 1, states, reals, counts, series, envelope, parametric, base, eighth)
    elif driver == "scalar":
        def kernel(lo: int, hi: int) -> None:
            call(tk.solve_block, params, settings, lo, hi, states, reals, counts, series,
                 parametric, base, eighth, watch.halt)
    else:
        def kernel(lo: int, hi: int) -> None:
            call(lanes.solve_block, params, settings, lo, hi, states, reals, counts, series,
                 pi, eighth, parametric, base, watch.halt)

    def solve_block(lo: int, hi: int) -> None:
        watch.begin(lo, hi)
        kernel(lo, hi)
        if watch.halted():
            watch.end(lo)                # the follow-up pass is left to a resume
            return
        if records is None:              # a record's state is final (COMPLETED or failed)
            _follow_up(tk.settle_second_pass, bool(np.any(states[lo:hi] == mt.SECOND_PASS)),
                       params[lo:hi], settings, states[lo:hi], reals[lo:hi], counts[lo:hi],
                       parametric, base, eighth)
        watch.end(lo)

    watch = Watch(states, on_block, stop)
    run_blocks(solve_block, params.shape[0], threads, watch.stop, one_at_a_time=swept,
               tick=watch.ticker(), lanes=driver == "lanes")


def solve_modes(params: np.ndarray, basis: tuple[np.ndarray, ...] | list, settings: np.ndarray,
                states: np.ndarray,
                reals: np.ndarray, counts: np.ndarray, series: np.ndarray, modal: np.ndarray,
                final: np.ndarray, *, driver: str = "lanes", threads: int = 0,
                on_block: Callable[[int, int], None] | None = None,
                stop: threading.Event | None = None, envelope: np.ndarray | None = None,
                durations: np.ndarray | None = None,
                records: np.ndarray | None = None, which: np.ndarray | None = None,
                family: tuple | None = None) -> None:
    """`solve_transverse` for the multi-mode System: rows of kernels.modes columns for the N
    modes of `basis` in (the mode shapes as the kernels take them:
    sweep.models.basis.Basis.kernel_arrays()), the same outputs plus modal (n, N), each mode's
    tail amplitude (m), and final (n, 2 N), the final state (m, m/s). On the lanes `basis` may
    be a list of such bases that kernels.modes.stacked can stack (a BasisFamily's), row
    i's basis[which[i]]: every row in one call, whatever its basis (`family`: the list
    stacked, where the caller has it).
    driver: "lanes" (kernels.modal_lanes, lock-step SIMD lanes) or "scalar"
    (kernels.modal_driver, SciPy's arithmetic); the two agree to round-off. A swept base
    frequency takes the scalar driver, with envelope and durations as `solve_transverse`'s;
    records (a random base acceleration's) run on either driver."""
    from sweep.kernels import layout as tk
    from sweep.kernels import metrics as mt
    from sweep.kernels import modal_driver
    if driver not in ("lanes", "scalar"):
        raise ValueError(f"driver {driver!r}: expected 'lanes' or 'scalar'")
    from sweep.kernels.modes import stacked
    bases = basis if isinstance(basis, list) else [basis]
    which = (np.zeros(params.shape[0], np.int64) if which is None
             else np.ascontiguousarray(which, np.int64))
    if driver == "lanes":
        from sweep.kernels import modal_lanes as kernel
        family = stacked(bases) if family is None else family
        if family is None:
            raise ValueError("these bases cannot share one lanes call "
                             "(kernels.modes.stacked)")
        first: tuple = (family, which)
    else:
        kernel = modal_driver
        if len(bases) != 1:
            raise ValueError("the scalar driver takes one basis a call")
        first = (bases[0],)
    base = _random_base(records, True if settings[tk.BASE] != 0.0 else None)
    eighth = method_switch(settings)
    swept = settings[tk.SWEPT] != 0.0
    if swept and driver != "scalar":
        raise ValueError("a swept base frequency takes driver 'scalar'")

    def solve_block(lo: int, hi: int) -> None:
        watch.begin(lo, hi)
        if swept:
            for i in range(lo, hi):
                call(modal_driver.solve_swept_block, params, bases[0],
                     swept_settings(settings, durations, i), i, i + 1, states, reals, counts,
                     series, modal, final, envelope, base, eighth)
        else:
            call(kernel.solve_block, params, *first, settings, lo, hi, states, reals,
                 counts, series, modal, final, base, eighth, watch.halt)
        if watch.halted():
            watch.end(lo)                # the follow-up passes are left to a resume
            return
        if records is not None:          # a record's state is final (COMPLETED or failed)
            watch.end(lo)
            return
        for b in np.unique(which[lo:hi]):      # each basis' rows (all of them: one basis)
            at = lo + np.flatnonzero(which[lo:hi] == b)
            rows = slice(lo, hi) if at.size == hi - lo else at
            row, state, real, count, mode = (params[rows], states[rows], reals[rows],
                                              counts[rows], modal[rows])
            off = bool(np.any((state == mt.OFF_MIDSPAN) | (state == mt.HIDDEN_MODE)))
            _follow_up(modal_driver.judge_off_midspan, off, row, bases[b], settings, state,
                       real, count, mode, base, eighth)
            second = bool(np.any(state == mt.SECOND_PASS))
            _follow_up(modal_driver.settle_second_pass, second, row, bases[b], settings, state,
                       real, count, base, eighth)
            if not isinstance(rows, slice):     # copies of the rows: their results back
                states[rows], reals[rows], counts[rows], modal[rows] = state, real, count, mode
        watch.end(lo)

    watch = Watch(states, on_block, stop)
    run_blocks(solve_block, params.shape[0], threads, watch.stop, one_at_a_time=swept,
               tick=watch.ticker(), lanes=driver == "lanes")


def _random_base(records: np.ndarray | None, base: bool | None) -> Any:
    """The kernels' `base` switch: the records of a random base acceleration (every driver
    takes them), else `base` as it is (None or True: a sine kind)."""
    if records is None:
        return base
    from sweep.kernels.layout import RECORD_ROWS
    if records.ndim != 3 or records.shape[2] != RECORD_ROWS:
        raise ValueError(f"records of shape {records.shape}: expected (R, N, {RECORD_ROWS}), "
                         "the samples with their integrals and pieces (sweep.models.random: "
                         "synthesise makes them, with_pieces completes given samples)")
    return np.ascontiguousarray(records, dtype=np.float64)


def method_switch(settings: np.ndarray) -> bool | None:
    """The kernels' method switch (`eighth`): True for DOP853 (settings[METHOD] is 1), None
    for RK45 (each compiles only its own method's code)."""
    from sweep.kernels import layout as tk
    return True if settings[tk.METHOD] != 0.0 else None


def swept_settings(settings: np.ndarray, durations: np.ndarray | None, i: int) -> np.ndarray:
    """The settings row i of a swept scene runs with: T_END its own end time durations[i]
    (s), or settings as they are (durations None: every row ends at settings' T_END)."""
    from sweep.kernels import layout as tk
    if durations is None:
        return settings
    own = settings.copy()
    own[tk.T_END] = durations[i]
    return own


def run_blocks(solve_block: Callable[[int, int], None], n: int, threads: int,
               stop: threading.Event | None, one_at_a_time: bool = False,
               tick: Callable[[], None] | None = None, lanes: bool = True) -> None:
    """Run solve_block(lo, hi) over blocks covering rows 0..n-1 on `threads` threads (0: all),
    guided scheduling and timed blocks (module docstring); with `stop` set no new block starts.
    one_at_a_time: points that each take long (a sine sweep's): a thread for every row, and on a
    scalar driver every block one row (the lanes take equal shares). tick(): called every
    WATCH_SECONDS from a thread of its own while the blocks run (`Watch.tick`). lanes: whether
    solve_block runs lanes, which drain at a block's end (blocks of at least MIN_BLOCK points, a
    thread per LANES_PER_THREAD); False: a scalar driver (SCALAR_BLOCK)."""
    if tick is None:
        _run_blocks(solve_block, n, threads, stop, one_at_a_time, lanes)
        return
    done = threading.Event()

    def watcher() -> None:
        while not done.wait(WATCH_SECONDS):
            tick()

    watching = threading.Thread(target=watcher, name="cable-sweep-watch", daemon=True)
    watching.start()
    try:
        _run_blocks(solve_block, n, threads, stop, one_at_a_time, lanes)
    finally:
        done.set()
        watching.join()


def _run_blocks(solve_block: Callable[[int, int], None], n: int, threads: int,
                stop: threading.Event | None, one_at_a_time: bool, lanes: bool) -> None:
    """`run_blocks` without the watcher."""
    per_thread = LANES_PER_THREAD if lanes and not one_at_a_time else 1
    least, least_timed = (MIN_BLOCK, MIN_TIMED_BLOCK) if lanes else (SCALAR_BLOCK, SCALAR_BLOCK)
    n_threads = max(1, min(thread_count(threads), -(-n // per_thread)))
    stop = stop or threading.Event()     # set on an interrupt: no new blocks are started
    most = SOLO_BLOCK if n_threads == 1 else MAX_BLOCK
    share = -(-n // n_threads)
    # The first block is short: it times the points, which sizes the next ones. A grid of at
    # most two such blocks a thread has no next ones to size: each thread takes an equal share
    # (144 random points on 2 threads were blocks of 64, 64 and 16, the last on one thread).
    first = share if 1 < n_threads and share <= 2 * least_timed else least_timed
    start = 0
    lock = threading.Lock()

    def work() -> None:
        nonlocal start
        cap = first
        while not stop.is_set():
            with lock:
                lo = start
                hi = start = lo + 1 if one_at_a_time and not lanes else next_block(
                    lo, n, n_threads, cap, least)
            if lo >= n:
                return
            began = time.perf_counter()
            solve_block(lo, hi)
            cap = timed_cap(hi - lo, time.perf_counter() - began, most, least_timed)

    # Even one thread works off the calling thread: a signal's Python handler (an interrupt
    # setting `stop`) runs only once the main thread is back in Python, never inside a kernel
    # call, which may last a whole block (a one-thread sine sweep ignored Ctrl-C for 24 s).
    with ThreadPoolExecutor(n_threads, thread_name_prefix="cable-sweep") as pool:
        try:
            for future in [pool.submit(work) for _ in range(n_threads)]:
                future.result()
        except BaseException:
            stop.set()
            raise


class Watch:
    """The rows of the blocks in progress, for a watcher thread: which are final (their state
    written, >= 0: the kernels write a row's state after every other output of it, and rows
    still NOT_SOLVED, SECOND_PASS, OFF_MIDSPAN or HIDDEN_MODE are not), reported to
    on_block(lo, hi) each row once, whichever thread gets there first; and an interrupt
    (`stop`) passed to the kernels through `halt`.

    A thread claims the rows it reports under the lock that guards the table of blocks and
    calls on_block outside it: a caller's on_block may take long (a random scene's spectra are
    computed there, about 40 % of its work), and under that lock it kept the other threads
    from ending or beginning blocks. Two threads may so report disjoint rows of one block at
    the same time, in either order."""

    def __init__(self, states: np.ndarray, on_block: Callable[[int, int], None] | None,
                 stop: threading.Event | None) -> None:
        from sweep.kernels import states as st
        self.states, self.on_block = states, on_block
        self.caller_stop = stop is not None
        self.stop = stop or threading.Event()
        self.halt = np.zeros(1, np.int8)     # read by the lanes drivers every attempt, the
                                             # scalar ones between rows
        self.lock = threading.Lock()
        self.blocks: dict[int, list[int]] = {}   # a block's first row -> [its end, claimed to]
        self.not_solved = st.NOT_SOLVED

    def begin(self, lo: int, hi: int) -> None:
        """Rows lo..hi-1 start (from the solving thread)."""
        self.states[lo:hi] = self.not_solved
        with self.lock:
            self.blocks[lo] = [hi, lo]

    def end(self, lo: int) -> None:
        """The block that starts at `lo` is done (its follow-up passes too): its final rows not
        yet claimed are reported, and it is forgotten (from the solving thread)."""
        self._report(lo)
        with self.lock:
            self.blocks.pop(lo, None)

    def ticker(self) -> Callable[[], None] | None:
        """`tick`, for run_blocks, where there is anyone to tell or anything to stop (a caller's
        on_block or stop); None otherwise (a stepped sweep's dwells: no watcher thread)."""
        return self.tick if self.on_block is not None or self.caller_stop else None

    def halted(self) -> bool:
        """Whether an interrupt has reached the kernels."""
        return bool(self.halt[0])

    def tick(self) -> None:
        """Pass an interrupt on to the kernels; report the rows that have turned final."""
        if self.stop.is_set():
            self.halt[0] = 1
        with self.lock:
            firsts = list(self.blocks)
        for lo in firsts:
            self._report(lo)

    def _report(self, lo: int) -> None:
        """Claim the block's rows that have turned final since its last claim, and report
        them."""
        with self.lock:
            block = self.blocks.get(lo)
            if block is None:
                return                   # ended since the caller looked
            hi, reported = block
            pending = np.flatnonzero(self.states[reported:hi] < 0)
            final = reported + int(pending[0] if pending.size else hi - reported)
            block[1] = final
        if final > reported and self.on_block is not None:
            self.on_block(reported, final)
