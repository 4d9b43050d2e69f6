"""Run a scene: grid -> model coefficients -> kernel over every point -> Dataset (-> netCDF)."""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import xarray as xr

from . import grid, models
from .dataset import assemble, package_version
from .errors import UserError
from .io import check_output_path, remove_stale_temporaries, write_netcdf
from .scene import Scene

_PERMUTATION_SEED = 20261121   # fixed: the point order never changes any point's result
ATOL_SCALE = 0.01              # default atol: this x rtol x each point's own scales (m, m/s)


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
    """The kernel's settings vector (kernels.transverse) from the scene's solver/metrics keys.

    solver.atol given: that absolute tolerance for q (m) and q' (m/s), as SciPy's scalar atol.
    Not given: each point's own, ATOL_SCALE x rtol x its displacement and velocity scales
    (sweep.models.state_scale), so results do not depend on the response's size.
    BASE is 1.0 for a scene with base excitation ([base]): the kernel then adds the forcing
    term and computes the absolute acceleration.
    """
    from sweep.kernels import transverse as tk
    s = np.zeros(tk.N_SETTINGS)
    s[tk.RTOL] = scene.get("solver.rtol")
    atol = scene.get("solver.atol")
    s[tk.ATOL] = 0.0 if atol is None else atol
    s[tk.ATOL_SCALE] = ATOL_SCALE if atol is None else 0.0
    s[tk.T_END] = scene.get("solver.t_end")
    s[tk.MAX_STEPS] = scene.get("solver.max_steps")
    s[tk.MAX_STEP] = scene.get("solver.max_step") or math.inf
    s[tk.FIRST_STEP] = scene.get("solver.first_step") or 0.0
    s[tk.TAIL] = scene.get("metrics.tail")
    s[tk.TOL] = scene.get("metrics.tolerance")
    s[tk.SAMPLE_DT] = scene.get("outputs.sample_interval") or scene.get("solver.t_end") / 1000.0
    s[tk.WANT_SETTLING] = 1.0 if scene.get("outputs.settling_time") else 0.0
    s[tk.MIN_STEP] = scene.get("solver.min_step") or 0.0
    s[tk.CONTROLLER] = 1.0 if scene.get("solver.controller") == "pi" else 0.0
    s[tk.METHOD] = 1.0 if scene.get("solver.method") == "dop853" else 0.0
    if scene.has_base:                  # else 0.0: no forcing term compiled
        s[tk.BASE] = 1.0
    return s


def available_memory(root: str = "/") -> tuple[float, str] | None:
    """The memory a new allocation can count on (bytes), and where that figure comes from: the
    least of physical memory, the kernel's MemAvailable (/proc/meminfo) and what this process's
    cgroup limit leaves (v2: memory.max - memory.current; v1: memory.limit_in_bytes -
    memory.usage_in_bytes, under /sys/fs/cgroup). None when none of them can be read.
    `root` is where /proc and /sys are looked for (a test's fake files)."""
    base = Path(root)
    found: list[tuple[float, str]] = []
    with contextlib.suppress(ValueError, OSError, AttributeError):
        found.append((os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"),
                      "physical memory"))
    with contextlib.suppress(OSError, ValueError):
        for line in (base / "proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                found.append((float(line.split()[1]) * 1024, "available memory"))
    for limit, usage in (("sys/fs/cgroup/memory.max", "sys/fs/cgroup/memory.current"),
                         ("sys/fs/cgroup/memory/memory.limit_in_bytes",
                          "sys/fs/cgroup/memory/memory.usage_in_bytes")):
        with contextlib.suppress(OSError, ValueError):
            text = (base / limit).read_text().strip()
            if text != "max":
                left = float(text) - float((base / usage).read_text())
                found.append((max(left, 0.0), "memory the cgroup limit leaves"))
    return min(found) if found else None


def check_memory(n_points: int, bytes_per_point: float, what: str, root: str = "/") -> None:
    """Refuse, before allocating, a sweep whose arrays would not fit in the memory this process
    can count on (available_memory: the least of physical memory, MemAvailable and the cgroup
    limit's room; `root` as there).

    bytes_per_point counts every array a point needs, with its copies (solve order, grid
    order, Dataset). Raises UserError when the total passes 80 % of that memory.
    """
    need = n_points * bytes_per_point
    have = available_memory(root)
    if have is not None and need > 0.8 * have[0]:
        raise UserError(f"scene: {n_points:,} points x {bytes_per_point / 1024:,.1f} KiB "
                        f"({what}) need about {need / 2**30:,.1f} GiB, more than the "
                        f"{have[0] / 2**30:,.1f} GiB of {have[1]} here allow (use fewer axis "
                        "values, or store fewer samples or snapshots)")


def check_disk(store, bytes_per_point: float) -> None:
    """Refuse, before solving, a run whose chunks do not fit on the chunk store's disk; warn
    when the netCDF file (at most its arrays' size, `bytes_per_point` bytes a point) may not
    fit beside them. `store`: an open store.ChunkStore."""
    from .errors import CableSweepWarning
    from .files import free_bytes, mib
    import warnings
    store.bytes_per_point = max(store.bytes_per_point, bytes_per_point)
    chunks = store.space_needed()
    free = free_bytes(store.directory)
    if free is None:
        return
    if chunks > free:
        raise UserError(f"chunk store '{store.directory}': not enough space on the device (the "
                        f"run needs about {mib(chunks)} there, {mib(free)} free; free space, or "
                        "choose another -o path)")
    if chunks + bytes_per_point * store.points > free:
        warnings.warn(f"'{store.directory.parent}': {mib(free)} free may not hold the chunks "
                      f"({mib(chunks)}) and the output file (up to "
                      f"{mib(bytes_per_point * store.points)}) together", CableSweepWarning,
                      stacklevel=2)


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


def solve_points(params: np.ndarray, settings: np.ndarray, n_samples: int,
                 threads: int = 0, progress: bool = False,
                 chunk_size: int | None = None, driver: str = "lanes") -> KernelResult:
    """Run the transverse kernel over the rows of `params` in-process (grid order in, grid
    order out). driver: "lanes" (kernels.lanes, lock-step SIMD) or "scalar"
    (kernels.transverse, one trajectory per iteration); the two agree to round-off."""
    from .execute import default_chunk_size, execute, transverse_chunk, transverse_outputs
    n = params.shape[0]
    order = point_order(n)
    outputs = transverse_outputs(n, n_samples)
    execute(transverse_chunk, lambda lo, hi: np.ascontiguousarray(params[order[lo:hi]]), n,
            (settings, n_samples, driver), placer(outputs, order),
            chunk_size=chunk_size or default_chunk_size(n, "threads", 0),
            threads=threads, progress=progress)
    return KernelResult(outputs["states"], outputs["reals"], outputs["counts"],
                        outputs["series"], np.empty(0))


def placer(outputs: dict[str, np.ndarray], order: np.ndarray) -> Callable[[int, int, dict], None]:
    """place(lo, hi, arrays): put a chunk's results (points order[lo:hi]) into grid order."""
    def place(lo: int, hi: int, arrays: dict) -> None:
        points = order[lo:hi]
        for name, values in arrays.items():
            outputs[name][points] = values
    return place


def run_fingerprint(scene: Scene) -> str:
    """What decides a run's results: every scene value but the run.* keys, and the axes."""
    from .execute import fingerprint
    values = {k: v for k, v in scene.values.items() if not k.startswith("run.")}
    axes = {k: [float(x) for x in v] for k, v in scene.axes.items()}
    return fingerprint(sorted(values.items()), sorted(axes.items()), package_version())


def solve_chunked(scene: Scene, chunk_fn: Callable[..., dict],
                  rows_at: Callable[[np.ndarray], np.ndarray], args: tuple,
                  outputs: dict[str, np.ndarray], *, output: str | os.PathLike | None = None,
                  resume: bool = False, overwrite: bool = False, threads: int = 0,
                  progress: bool = False,
                  scheduler: str | None = None) -> dict[str, np.ndarray]:
    """Solve every grid point in chunks on the scene's backend (on the dask cluster at
    `scheduler` when the caller gives one), filling `outputs` (grid order, first axis =
    points). rows_at(flat indices) gives the kernel's parameter rows of those points. With
    `output`, every finished chunk is persisted next to it and, when resuming, only the missing
    chunks are computed."""
    from .execute import default_chunk_size, execute
    from .store import ChunkStore
    n = next(iter(outputs.values())).shape[0]
    order = point_order(n)
    backend = "dask" if scheduler else scene.get("run.backend")
    workers = scene.get("run.workers")
    chunk = scene.get("run.chunk_size") or default_chunk_size(n, backend, workers or
                                                              (os.cpu_count() or 1))
    store = None
    done: dict = {}
    if output is not None:
        store = ChunkStore(output, run_fingerprint(scene))
        done, chunk = store.open(resume, overwrite, chunk, points=n)
        check_disk(store, sum(v.nbytes for v in outputs.values()) / max(n, 1))
    computed = execute(chunk_fn, lambda lo, hi: rows_at(order[lo:hi]), n, args,
                       placer(outputs, order),
                       chunk_size=chunk, backend=backend, threads=threads,
                       scheduler=scheduler, workers=workers,
                       progress=progress, store=store, done=done)
    if resume:
        sys.stderr.write(f"resumed: {n - computed:,} of {n:,} points were already done, "
                         f"{computed:,} computed\n")
    return outputs


def run(scene: Scene, output: str | os.PathLike | None = None, *, overwrite: bool = False,
        resume: bool = False, threads: int | None = None,
        progress: bool | None = None, scheduler: str | None = None) -> xr.Dataset:
    """Run every point of `scene` and return the result Dataset; with `output`, also write it
    as netCDF atomically (checked before any work: an existing file needs `overwrite=True`).

    With `output`, every finished chunk is kept in `<output>.chunks/` until the file is written:
    a run that was killed is finished with `resume=True`, which computes only the missing chunks.
    threads: worker threads (default: the scene's run.threads, 0 = all cores).
    progress: a progress bar on stderr (default: only when stderr is a terminal).
    scheduler: the address of a running dask scheduler (tcp://HOST:PORT) to run the chunks on,
    whatever the scene's run.backend; only from the caller, never from a scene, because the
    cluster runs code in this process (the client unpickles what it sends back): give only a
    cluster you control. Default: the scene's run.backend (dask: a LocalCluster of run.workers).
    """
    if not isinstance(scene, Scene):
        raise UserError(f"sweep.run: expected a Scene from sweep.load_scene, got {type(scene).__name__}")
    if output is not None:
        check_output_path(output, overwrite)
    if progress is None:
        progress = sys.stderr.isatty()
    if threads is None:
        threads = scene.get("run.threads")
    if not isinstance(threads, (int, np.integer)) or isinstance(threads, bool) or threads < 0:
        raise UserError(f"sweep.run: threads = {threads!r} is not a thread count (give an integer "
                        ">= 1, or 0 or None for every core)")
    if scheduler is not None:
        _check_scheduler(scene, scheduler)
    persist = dict(output=output, resume=resume, overwrite=overwrite, scheduler=scheduler)
    if output is not None:
        remove_stale_temporaries(output)            # of a write that was killed
    from .store import ChunkStore
    try:
        if scene.get("model.kind") == "longitudinal":
            from .longitudinal import run_longitudinal
            ds = run_longitudinal(scene, threads=threads, progress=progress, **persist)
        else:
            ds = run_transverse(scene, threads=threads, progress=progress, **persist)
        if output is not None:
            write_netcdf(ds, output, overwrite)
            ChunkStore(output, "").remove()
    finally:
        if output is not None:
            # a run that failed before finishing a chunk leaves no store to block the next one
            ChunkStore(output, "").release(discard_empty=True)
    return ds


def _check_scheduler(scene: Scene, scheduler: str) -> None:
    """Refuse a malformed scheduler address before any work; warn that the scene's run.workers
    (a LocalCluster's size) is not used on an existing cluster."""
    import warnings

    from .errors import CableSweepWarning
    from .execute import check_scheduler
    check_scheduler(scheduler, "sweep.run: scheduler")
    if scene.get("run.workers"):
        warnings.warn(f"run.workers = {scene.get('run.workers')} (a LocalCluster's size) is not "
                      f"used: the chunks run on the cluster at {scheduler}, on its own workers",
                      CableSweepWarning, stacklevel=3)


def run_transverse(scene: Scene, threads: int = 0, progress: bool = False,
                   output: str | os.PathLike | None = None, resume: bool = False,
                   overwrite: bool = False, scheduler: str | None = None) -> xr.Dataset:
    """The transverse (RK45) sweep of `scene` as a Dataset."""
    from sweep.kernels import transverse as tk
    from sweep.kernels.oscillator import PARAM_NAMES

    coords = grid.coordinates(scene)
    dims = tuple(coords)
    shape = tuple(coords[d].size for d in dims)
    settings = settings_vector(scene)
    times = (sample_times(settings[tk.T_END], settings[tk.SAMPLE_DT])
             if scene.get("outputs.time_series") else np.empty(0))
    n_points = int(np.prod(shape, dtype=np.int64))
    # Outputs (and their Dataset copies), the solve order and a few derived quantities: the
    # parameter rows are built chunk by chunk and never held for the whole grid.
    check_memory(n_points, 2.0 * (1 + 8 * (tk.N_REALS + tk.N_COUNTS + times.size)) + 40,
                 "metrics and time series")
    params = grid.parameters(scene, coords)
    coeffs = models.oscillator(params)          # derived quantities, on the axes they need
    # No time-varying stiffness anywhere (a constant or zero end load): the kernels leave the
    # cos(W t) terms out (the same results, bit for bit, and a cheaper right-hand side).
    varying = any(bool(np.any(np.asarray(coeffs[c]) != 0.0)) for c in ("k1", "g1"))
    settings[tk.CONSTANT_STIFFNESS] = 0.0 if varying else 1.0

    def rows_at(points: np.ndarray) -> np.ndarray:
        at = grid.point_values(params, dims, shape, points)
        return grid.rows(models.oscillator(at), PARAM_NAMES, points.size)

    started = time.perf_counter()
    from .execute import transverse_chunk, transverse_outputs
    out = solve_chunked(scene, transverse_chunk, rows_at,
                        (settings, times.size, scene.get("solver.driver")),
                        transverse_outputs(n_points, times.size),
                        output=output, resume=resume, overwrite=overwrite, threads=threads,
                        progress=progress, scheduler=scheduler)
    result = KernelResult(out["states"], out["reals"], out["counts"], out["series"], times)
    return assemble(scene, coords, shape, coeffs, result, time.perf_counter() - started)
