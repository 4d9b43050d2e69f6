"""Run a scene: grid -> model coefficients -> kernel over every point -> Dataset (-> netCDF)."""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
import xarray as xr

from . import grid, models
from .dataset import assemble
from .errors import UserError
from .io import check_output_path, write_netcdf
from .scene import Scene

_PERMUTATION_SEED = 20261121   # fixed: the point order never changes any point's result


@dataclass
class KernelResult:
    """Flat per-point kernel outputs, in grid (C) order."""
    states: np.ndarray      # int8 state flags
    reals: np.ndarray       # (n, kernels.transverse.N_REALS)
    counts: np.ndarray      # (n, kernels.transverse.N_COUNTS) int64
    series: np.ndarray      # (n, n_samples) q samples (m); n_samples may be 0
    sample_times: np.ndarray


def sample_times(t_end: float, dt: float) -> np.ndarray:
    """k * dt for every k with k * dt <= t_end (s); computed as the kernel computes them."""
    n = int(math.floor(t_end / dt)) + 1
    k = np.arange(max(n - 2, 0), n + 2)
    return np.arange(int(k[k * dt <= t_end][-1]) + 1) * dt


def settings_vector(scene: Scene) -> np.ndarray:
    """The kernel's settings vector (kernels.transverse) from the scene's solver/metrics keys."""
    from kernels import transverse as tk
    s = np.zeros(tk.N_SETTINGS)
    s[tk.RTOL] = scene.get("solver.rtol")
    s[tk.ATOL] = scene.get("solver.atol")
    s[tk.T_END] = scene.get("solver.t_end")
    s[tk.MAX_STEPS] = scene.get("solver.max_steps")
    s[tk.MAX_STEP] = scene.get("solver.max_step") or math.inf
    s[tk.FIRST_STEP] = scene.get("solver.first_step") or 0.0
    s[tk.TAIL] = scene.get("metrics.tail")
    s[tk.TOL] = scene.get("metrics.tolerance")
    s[tk.SAMPLE_DT] = scene.get("outputs.sample_interval") or scene.get("solver.t_end") / 1000.0
    s[tk.WANT_SETTLING] = 1.0 if scene.get("outputs.settling_time") else 0.0
    s[tk.MIN_STEP] = scene.get("solver.min_step") or 0.0
    return s


def _progress_printer(total: int, enabled: bool) -> Callable[[int], None]:
    start = time.perf_counter()

    def report(done: int) -> None:
        if not enabled:
            return
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else 0.0
        left = (total - done) / rate if rate > 0 else math.inf
        width = 30
        bar = "#" * int(width * done / total) + "-" * (width - int(width * done / total))
        sys.stderr.write(f"\r[{bar}] {done}/{total} points  {rate:,.0f}/s  "
                         f"{left:5.1f} s left ")
        if done == total:
            sys.stderr.write("\n")
        sys.stderr.flush()
    return report


def check_memory(n_points: int, bytes_per_point: float, what: str) -> None:
    """Refuse, before allocating, a sweep whose arrays would not fit in this machine's memory.

    bytes_per_point counts every array a point needs, with its copies (solve order, grid
    order, Dataset). Raises UserError when the total passes 80 % of physical memory.
    """
    need = n_points * bytes_per_point
    try:
        have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return
    if need > 0.8 * have:
        raise UserError(f"scene: {n_points:,} points x {bytes_per_point / 1024:,.1f} KiB "
                        f"({what}) need about {need / 2**30:,.1f} GiB, more than this machine's "
                        f"{have / 2**30:,.0f} GiB allow (use fewer axis values, or store fewer "
                        "samples or snapshots)")


def point_order(n: int) -> np.ndarray:
    """The fixed pseudo-random order points are solved in: spreads costly points over threads.

    The order never changes a result: each point depends only on its own parameters.
    """
    return np.random.default_rng(_PERMUTATION_SEED).permutation(n)


def grid_order(order: np.ndarray) -> np.ndarray:
    """Indices that put results solved in `order` back in grid order."""
    back = np.empty(order.size, np.int64)
    back[order] = np.arange(order.size)
    return back


def in_chunks(n: int, solve_chunk: Callable[[int, int], None], threads: int = 0,
              progress: bool = False, chunk_size: int | None = None) -> None:
    """Call solve_chunk(lo, hi) over [0, n) in chunks of `chunk_size` points (default: enough
    for every thread, at most 100 chunks), on `threads` Numba threads (0 = all), with a
    progress bar on stderr when `progress` and the run has more than one chunk."""
    import numba
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS) if threads
                          else numba.config.NUMBA_NUM_THREADS)
    chunk = chunk_size or max(4096 * numba.get_num_threads(), -(-n // 100))
    report = _progress_printer(n, progress and n > chunk)
    for lo in range(0, n, chunk):
        hi = min(n, lo + chunk)
        solve_chunk(lo, hi)
        report(hi)


def solve_points(params: np.ndarray, settings: np.ndarray, n_samples: int,
                 threads: int = 0, progress: bool = False,
                 chunk_size: int | None = None, driver: str = "lanes") -> KernelResult:
    """Run the transverse kernel over the rows of `params` (grid order in, grid order out).

    driver: "lanes" (kernels.lanes, lock-step SIMD) or "scalar" (kernels.transverse, one
    trajectory per iteration); the two agree to round-off.
    """
    from kernels import lanes
    from kernels import transverse as tk
    solve_batch = lanes.solve_batch if driver == "lanes" else tk.solve_batch_scalar

    n = params.shape[0]
    order = point_order(n)
    shuffled = np.ascontiguousarray(params[order])
    states = np.empty(n, np.int8)
    reals = np.empty((n, tk.N_REALS))
    counts = np.empty((n, tk.N_COUNTS), np.int64)
    series = np.empty((n, n_samples))

    def solve_chunk(lo: int, hi: int) -> None:
        solve_batch(shuffled[lo:hi], settings, states[lo:hi], reals[lo:hi], counts[lo:hi],
                    series[lo:hi])

    in_chunks(n, solve_chunk, threads, progress, chunk_size)
    back = grid_order(order)
    return KernelResult(states[back], reals[back], counts[back], series[back], np.empty(0))


def run(scene: Scene, output: str | os.PathLike | None = None, *, overwrite: bool = False,
        threads: int | None = None, progress: bool | None = None) -> xr.Dataset:
    """Run every point of `scene` and return the result Dataset; with `output`, also write it
    as netCDF atomically (checked before any work: an existing file needs `overwrite=True`).

    threads: worker threads (default: the scene's run.threads, 0 = all cores).
    progress: a progress bar on stderr (default: only when stderr is a terminal).
    """
    if not isinstance(scene, Scene):
        raise UserError(f"sweep.run: expected a Scene from sweep.load_scene, got {type(scene).__name__}")
    if output is not None:
        check_output_path(output, overwrite)
    if progress is None:
        progress = sys.stderr.isatty()
    if threads is None:
        threads = scene.get("run.threads")
    if scene.get("model.kind") == "longitudinal":
        from .longitudinal import run_longitudinal
        ds = run_longitudinal(scene, threads=threads, progress=progress)
    else:
        ds = run_transverse(scene, threads=threads, progress=progress)
    if output is not None:
        write_netcdf(ds, output, overwrite)
    return ds


def run_transverse(scene: Scene, threads: int = 0, progress: bool = False) -> xr.Dataset:
    """The transverse (RK45) sweep of `scene` as a Dataset."""
    from kernels import transverse as tk
    from kernels.oscillator import PARAM_NAMES

    coords = grid.coordinates(scene)
    dims = tuple(coords)
    shape = tuple(coords[d].size for d in dims)
    settings = settings_vector(scene)
    times = (sample_times(settings[tk.T_END], settings[tk.SAMPLE_DT])
             if scene.get("outputs.time_series") else np.empty(0))
    n_points = int(np.prod(shape, dtype=np.int64))
    check_memory(n_points, 3.0 * (8 * (len(PARAM_NAMES) + tk.N_REALS + tk.N_COUNTS + times.size)
                                  + 1), "parameters, metrics and time series")
    params = grid.parameters(scene, coords)
    coeffs = models.oscillator(params)
    table = grid.flatten(coeffs, PARAM_NAMES, dims, shape)
    started = time.perf_counter()
    result = solve_points(table, settings, times.size, threads=threads, progress=progress,
                          chunk_size=scene.get("run.chunk_size"),
                          driver=scene.get("solver.driver"))
    result.sample_times = times
    return assemble(scene, coords, shape, coeffs, result, time.perf_counter() - started)
