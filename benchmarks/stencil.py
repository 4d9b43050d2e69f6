"""Central-difference stencil: point-updates per second, cable-sweep's kernel against NumPy.

What it measures
----------------
The longitudinal problem of docs/model.md sec. 4 (Table 1 cable, P0 = 4 N, C = 1) on --spans spans
of lengths evenly spread over [0.5, 1.5] m, --intervals intervals each, --transits wave
transits l/a. One point-update is one node advanced one time level.

1. cable-sweep: `kernels.longitudinal.solve_batch` (one span per parallel iteration, each span
   advanced through all its levels while its nodes sit in cache) on 1 and 2 threads; the
   first call (compile or cache load) is timed apart; best of --repeats.
2. NumPy: the same scheme vectorised over all spans at once (arrays spans x nodes, one
   array update per time level), run for --numpy-transits transits (it is slow) and reported
   per point-update. Its end displacements are checked against the kernel's at that time.

Command (idle machine):
    PYTHONPATH=. python benchmarks/stencil.py
Small check: python benchmarks/stencil.py --spans 50 --intervals 200
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

E, RHO, A, P0 = 1.1e11, 8900.0, 6e-6, 4.0
WAVE = math.sqrt(E / RHO)
EA = E * A


def kernel_run(lengths: np.ndarray, intervals: int, transits: float,
               threads: int) -> tuple[float, int, np.ndarray]:
    """(wall seconds, point-updates, peak end displacement per span) for the Numba kernel."""
    import numba
    from sweep.kernels import longitudinal as lk
    numba.set_num_threads(threads)
    n = lengths.size
    params = np.column_stack([lengths, np.full(n, WAVE), np.full(n, EA), np.full(n, P0),
                              transits * lengths / WAVE, lengths])
    settings = np.array([intervals, 1.0, 0.0, 1e12])
    states = np.empty(n, np.int8)
    reals = np.empty((n, lk.N_REALS))
    steps = np.empty(n, np.int64)
    empty2 = np.empty((n, 0))
    empty3 = [np.empty((n, 0, intervals + 1)) for _ in range(3)]
    start = time.perf_counter()
    lk.solve_batch(params, settings, np.empty(0), states, reals, steps, empty2, empty2, *empty3)
    wall = time.perf_counter() - start
    return wall, int(steps.sum()) * (intervals + 1), reals[:, lk.PEAK_END_DISPLACEMENT]


def numpy_run(lengths: np.ndarray, intervals: int, levels: int) -> tuple[float, int, np.ndarray]:
    """The same scheme vectorised over spans with NumPy; (wall s, point-updates, u(l) at the end).

    Every span takes the same number of levels (C = 1 and the same intervals give the same
    number of levels per transit).
    """
    n = lengths.size
    dx = (lengths / intervals)[:, None]
    ghost = 2.0 * dx[:, 0] * P0 / EA
    c2 = 1.0
    u_prev = np.zeros((n, intervals + 1))
    u_cur = np.zeros_like(u_prev)
    u_next = np.zeros_like(u_prev)
    start = time.perf_counter()
    u_next[:, 1:-1] = u_cur[:, 1:-1] + 0.5 * c2 * (u_cur[:, 2:] - 2 * u_cur[:, 1:-1] + u_cur[:, :-2])
    u_next[:, -1] = u_cur[:, -1] + c2 * (u_cur[:, -2] - u_cur[:, -1] - 0.5 * ghost)
    u_prev, u_cur, u_next = u_cur, u_next, u_prev
    for _ in range(levels - 1):
        u_next[:, 1:-1] = (2 * u_cur[:, 1:-1] - u_prev[:, 1:-1]
                           + c2 * (u_cur[:, 2:] - 2 * u_cur[:, 1:-1] + u_cur[:, :-2]))
        u_next[:, -1] = 2 * u_cur[:, -1] - u_prev[:, -1] + c2 * (2 * u_cur[:, -2] - ghost
                                                                  - 2 * u_cur[:, -1])
        u_prev, u_cur, u_next = u_cur, u_next, u_prev
    wall = time.perf_counter() - start
    return wall, levels * n * (intervals + 1), u_cur[:, -1].copy()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spans", type=int, default=1000)
    parser.add_argument("--intervals", type=int, default=1000)
    parser.add_argument("--transits", type=float, default=4.0)
    parser.add_argument("--numpy-transits", type=float, default=0.5)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    lengths = np.linspace(0.5, 1.5, args.spans)

    start = time.perf_counter()
    kernel_run(lengths[:2], 10, 1.0, 1)
    first = time.perf_counter() - start
    rows = []
    for threads in (1, 2):
        best = min(kernel_run(lengths, args.intervals, args.transits, threads)[0:2]
                   for _ in range(args.repeats))
        rows.append((f"cable-sweep kernel, {threads} thread{'s' if threads > 1 else ''}",
                     best[0], best[1]))
    levels = int(round(args.numpy_transits * args.intervals))
    np_wall, np_updates, np_end = numpy_run(lengths, args.intervals, levels)
    rows.append(("NumPy, vectorised over spans, 1 thread", np_wall, np_updates))
    # Check: at C = 1 the scheme is exact, so NumPy's end displacement must be d'Alembert's.
    exact_end = -P0 / EA * WAVE * np.minimum(levels * (lengths / args.intervals) / WAVE,
                                             2 * lengths / WAVE)
    err = float(np.max(np.abs(np_end - exact_end)) / np.max(np.abs(exact_end)))

    print(f"# Stencil: {args.spans} spans x {args.intervals} intervals, C = 1; kernel over "
          f"{args.transits:g} transits, NumPy over {args.numpy_transits:g}\n")
    print(f"First kernel call (compile or cache load): {first:.2f} s\n")
    print("| implementation | wall (s) | point-updates | point-updates/s | ratio to NumPy |")
    print("|---|---|---|---|---|")
    np_rate = np_updates / np_wall
    for name, wall, updates in rows:
        rate = updates / wall
        print(f"| {name} | {wall:.3f} | {updates:.3e} | {rate:.3e} | {rate / np_rate:.1f}x |")
    print(f"\nNumPy end displacement vs exact (d'Alembert) after {levels} levels: "
          f"max rel. error {err:.1e}")


if __name__ == "__main__":
    main()
