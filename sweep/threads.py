"""The transverse kernel over a table of points on Python threads, one block of points at a time.

Each driver's kernel (`kernels.lanes.solve_block`, `kernels.transverse.solve_block`) solves a
contiguous block of rows and releases the GIL, so plain threads run blocks side by side. They
draw blocks from one queue, shrinking as the points run out (guided scheduling): a thread
whose points were cheap takes more, which balances the ~3x cost spread between short and long
spans better than a static schedule. There is no Numba parallel region to compile (that alone
took ~3 s on a cold cache), and a point's result never depends on the blocks or the number of
threads.

Points a driver leaves SECOND_PASS (at rest away from zero, settling wanted) are finished by
`kernels.transverse.settle_second_pass`, compiled only when a sweep has one.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

MIN_BLOCK = 128        # points per block, at least (smaller blocks leave lanes idle as they drain)
MAX_BLOCK = 1024       # at most
SHARE = 2              # a block is at most 1/SHARE of a thread's share of the points left
LANES_PER_THREAD = 16  # a thread for every 16 points (one lanes group), at most


def thread_count(threads: int = 0) -> int:
    """Threads a call runs on: `threads`, or 0 for Numba's default (NUMBA_NUM_THREADS, all
    cores unless set), capped at that default."""
    import numba
    limit = numba.config.NUMBA_NUM_THREADS
    return min(threads, limit) if threads > 0 else limit


def next_block(lo: int, n: int, n_threads: int) -> int:
    """End of the block that starts at row `lo` of n, on n_threads threads: guided scheduling,
    blocks shrinking with the points left, from MAX_BLOCK down to MIN_BLOCK (or to an equal
    share of a small grid), so the threads finish together while blocks stay long enough to
    keep the lanes full."""
    floor = min(MIN_BLOCK, -(-n // n_threads))
    size = (n - lo) // (SHARE * n_threads)
    return min(n, lo + max(floor, min(MAX_BLOCK, size)))


def solve_transverse(params: np.ndarray, settings: np.ndarray, states: np.ndarray,
                     reals: np.ndarray, counts: np.ndarray, series: np.ndarray, *,
                     driver: str = "lanes", threads: int = 0) -> None:
    """Solve every row of `params` (n, N_PARAMS) into the preallocated outputs (first axis n):
    states int8, reals (n, N_REALS), counts (n, N_COUNTS) int64, series (n, n_samples).

    driver: "lanes" (lock-step SIMD lanes, the default) or "scalar" (SciPy's arithmetic, one
    trajectory after another); threads: 0 for all (see thread_count).
    """
    from sweep.kernels import lanes
    from sweep.kernels import metrics as mt
    from sweep.kernels import transverse as tk
    if driver not in ("lanes", "scalar"):
        raise ValueError(f"driver {driver!r}: expected 'lanes' or 'scalar'")
    if driver == "scalar":
        def solve_block(lo: int, hi: int) -> None:
            tk.solve_block(params, settings, lo, hi, states, reals, counts, series)
    else:
        pi = True if settings[tk.CONTROLLER] != 0.0 else None   # see lanes.solve_block
        eighth = True if settings[tk.METHOD] != 0.0 else None

        def solve_block(lo: int, hi: int) -> None:
            lanes.solve_block(params, settings, lo, hi, states, reals, counts, series, pi,
                              eighth)
    n = params.shape[0]
    n_threads = min(thread_count(threads), -(-n // LANES_PER_THREAD))
    if n_threads <= 1:
        solve_block(0, n)
    else:
        start = 0
        lock = threading.Lock()
        stop = threading.Event()         # set on an interrupt: no new blocks are started

        def work() -> None:
            nonlocal start
            while not stop.is_set():
                with lock:
                    lo = start
                    hi = start = next_block(lo, n, n_threads)
                if lo >= n:
                    return
                solve_block(lo, hi)

        with ThreadPoolExecutor(n_threads, thread_name_prefix="cable-sweep") as pool:
            try:
                for future in [pool.submit(work) for _ in range(n_threads)]:
                    future.result()
            except BaseException:
                stop.set()
                raise
    if np.any(states == mt.SECOND_PASS):
        tk.settle_second_pass(params, settings, states, reals, counts)
