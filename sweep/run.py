"""Run a scene: the scene's model (sweep/models/) over every grid point -> Dataset (-> netCDF).

`run` is the one entry point: it checks the output path and the caller's options, picks the
model of the scene's model.kind (`models.model_for`), which solves every point through the
generic runner (sweep/runner.py) and assembles its Dataset, and writes the file atomically.
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

from . import models
from .errors import UserError
from .io import check_output_path, remove_stale_temporaries, write_netcdf
from .scene import Scene

if TYPE_CHECKING:
    import xarray as xr

# Kept importable from here (benchmarks and scripts use them): the transverse model's kernel
# entry points and the runner's point order and resource checks. Imported on first use
# (PEP 562), so that `import sweep` (and `sweep --help`, `sweep scenes`) loads neither xarray
# nor numba.
_REEXPORTED = {name: "sweep.models.transverse" for name in
               ("ATOL_SCALE", "KernelResult", "sample_times", "settings_vector", "solve_points")}
_REEXPORTED.update({name: "sweep.runner" for name in
                    ("available_memory", "check_disk", "check_memory", "grid_order",
                     "point_order", "run_options")})


def __getattr__(name: str) -> Any:
    if name in _REEXPORTED:
        import importlib
        return getattr(importlib.import_module(_REEXPORTED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
    from .lazydask import defer
    defer()                                       # no dask import unless the run uses dask
    from .runner import run_options
    if output is not None:
        check_output_path(output, overwrite, scene if resume else None)
    # The bar only on a terminal; the lines that say a cold start is compiling (minutes on a
    # first run) wherever the caller has not asked for quiet: a CI log, nohup, a notebook.
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise UserError(f"sweep.run: progress = {progress!r:.40}: give True, False or None "
                        "(None: a bar only when stderr is a terminal)")
    announce = progress is not False
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
    from .dataset import short_long_names
    from .store import ChunkStore
    try:
        options = run_options(scene, threads=threads, progress=progress, announce=announce,
                              **persist)
        ds = short_long_names(models.model_for(scene.get("model.kind")).run(scene, options))
        if output is not None:
            _write_whole(ds, output, overwrite)
    finally:
        if output is not None:
            # a run that failed before finishing a chunk leaves no store to block the next one
            ChunkStore(output, "").release(discard_empty=True)
    return ds


def _write_whole(ds: Any, output: str | os.PathLike, overwrite: bool) -> None:
    """Write the finished run to `output` and drop its chunk store, with Ctrl-C, SIGTERM and
    SIGHUP held until both are done (the result is whole by then; a signal is reported as a
    warning, not lost work)."""
    import signal
    import warnings

    from .errors import CableSweepWarning
    from .execute import signals_held
    from .store import ChunkStore
    with signals_held() as held:
        write_netcdf(ds, output, overwrite)
        ChunkStore(output, "").remove()
    if held:
        warnings.warn(f"{signal.Signals(held[0]).name} received while writing "
                      f"'{os.fspath(output)}': the write was finished first, the result is "
                      "complete", CableSweepWarning, stacklevel=3)


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
