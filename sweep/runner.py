"""The generic runner: every grid point of a scene solved in chunks, whatever the model.

A model (sweep/models/) gives the kernel call for a chunk (`chunk_fn`), the parameter rows of
any set of points (`rows_at`) and the empty outputs; this module orders the points (a fixed
pseudo-random permutation that spreads costly regions over the threads), checks memory and
disk before any work, keeps finished chunks in the chunk store when there is an output file
(resume) and puts every chunk's results back in grid order. It knows no physics.
"""

from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .errors import UserError
from .scene import Scene
from .version import package_version

_PERMUTATION_SEED = 20261121   # fixed: the point order never changes any point's result


@dataclass(frozen=True)
class RunOptions:
    """How a run executes, resolved once (`run_options`) from the scene's run.* keys and the
    caller's arguments: nothing here changes a result.

    backend "threads" | "dask"; workers: dask LocalCluster processes (0: one per core);
    chunk_size: points per kernel call or task (None: chosen from the grid); threads: worker
    threads (0: all cores); progress: a bar on stderr; announce: a line on stderr when Numba
    starts compiling and one when it is done, terminal or not; scheduler: an existing dask scheduler's
    address (the caller's, never a scene's); output: the netCDF path whose chunk store keeps
    finished chunks (None: no store); resume, overwrite: as sweep.run's; fingerprint: what
    decides the results (`run_fingerprint`), which a chunk store must match.
    """
    backend: str = "threads"
    workers: int = 0
    chunk_size: int | None = None
    threads: int = 0
    progress: bool = False
    announce: bool = False
    scheduler: str | None = None
    output: str | os.PathLike | None = None
    resume: bool = False
    overwrite: bool = False
    fingerprint: str = ""


def run_options(scene: Scene, *, threads: int = 0, progress: bool = False,
                announce: bool = False, output: str | os.PathLike | None = None, resume: bool = False,
                overwrite: bool = False, scheduler: str | None = None) -> RunOptions:
    """The RunOptions of running `scene` with sweep.run's arguments (a scheduler forces the
    dask backend)."""
    return RunOptions(backend="dask" if scheduler else scene.get("run.backend"),
                      workers=scene.get("run.workers"), chunk_size=scene.get("run.chunk_size"),
                      threads=threads, progress=progress, announce=announce,
                      scheduler=scheduler, output=output,
                      resume=resume, overwrite=overwrite, fingerprint=run_fingerprint(scene))


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


def check_memory(n_points: int, bytes_per_point: float, what: str, root: str = "/",
                 working: float = 0.0, working_what: str = "", fix: str = "") -> None:
    """Refuse, before allocating, a sweep whose arrays would not fit in the memory this process
    can count on (available_memory: the least of physical memory, MemAvailable and the cgroup
    limit's room; `root` as there).

    bytes_per_point counts every array a point needs, with its copies (solve order, grid
    order, Dataset); `working` the bytes the kernels' working arrays take besides
    (`working_what` says what they are, `fix` how to shrink them). Raises UserError when the
    total passes 80 % of that memory.
    """
    need = n_points * bytes_per_point + working
    have = available_memory(root)
    if have is not None and need > 0.8 * have[0]:
        besides = (f" and {working / 2**30:,.1f} GiB of {working_what}" if working > 0.0
                   else "")
        raise UserError(f"scene: {n_points:,} points x {bytes_per_point / 1024:,.1f} KiB "
                        f"({what}){besides} need about {need / 2**30:,.1f} GiB, more than the "
                        f"{have[0] / 2**30:,.1f} GiB of {have[1]} here allow ("
                        + (fix or "use fewer axis values, or store fewer samples or "
                           "snapshots") + ")")


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


def placer(outputs: dict[str, np.ndarray], order: np.ndarray) -> Callable[[int, int, dict], None]:
    """place(lo, hi, arrays): put a chunk's results (points order[lo:hi]) into grid order."""
    def place(lo: int, hi: int, arrays: dict) -> None:
        points = order[lo:hi]
        for name, values in arrays.items():
            outputs[name][points] = values
    return place


def run_fingerprint(scene: Scene) -> str:
    """What decides a run's results: every scene value but the run.* keys, the axes and the
    [points] (in order: their order is the point dimension's), the package version and the
    kernels' sources (a chunk stored by other kernels, whose outputs may differ in values or
    layout, is never resumed from)."""
    from .execute import fingerprint
    from .jitcache import package_sources_digest
    values = {k: v for k, v in scene.values.items() if not k.startswith("run.")}
    axes = {k: [float(x) for x in v] for k, v in scene.axes.items()}
    code = (package_version(), package_sources_digest())
    if not scene.points:
        return fingerprint(sorted(values.items()), sorted(axes.items()), *code)
    points = {k: [float(x) for x in v] for k, v in scene.points.items()}
    return fingerprint(sorted(values.items()), sorted(axes.items()), *code,
                       list(points.items()))


def solve_chunked(options: RunOptions, chunk_fn: Callable[..., dict],
                  rows_at: Callable[[np.ndarray], np.ndarray], args: tuple,
                  outputs: dict[str, np.ndarray], unit: str = "points") -> dict[str, np.ndarray]:
    """Solve every grid point in chunks as `options` say (backend, threads, chunk store),
    filling `outputs` (grid order, first axis = points): chunk_fn(rows, *args) is the model's
    kernel call, rows_at(flat indices) the model's parameter rows of those points. With an
    output path every finished chunk is persisted next to it and, when resuming, only the
    missing chunks are computed. unit: what a row is ("points"; a stepped sweep's "lines"),
    for the bar and the lines it prints."""
    from .execute import default_chunk_size, execute
    from .store import ChunkStore
    n = next(iter(outputs.values())).shape[0]
    order = point_order(n)
    chunk = options.chunk_size or default_chunk_size(n, options.backend, options.workers or
                                                     (os.cpu_count() or 1))
    store = None
    done: dict = {}
    partial: dict = {}
    if options.output is not None:
        store = ChunkStore(options.output, options.fingerprint)
        done, chunk = store.open(options.resume, options.overwrite, chunk, points=n)
        partial = store.progress(done)
        check_disk(store, sum(v.nbytes for v in outputs.values()) / max(n, 1))
    computed = execute(chunk_fn, lambda lo, hi: rows_at(order[lo:hi]), n, args,
                       placer(outputs, order),
                       chunk_size=chunk, backend=options.backend, threads=options.threads,
                       scheduler=options.scheduler, workers=options.workers,
                       progress=options.progress, announce=options.announce, store=store,
                       done=done, partial=partial, unit=unit)
    if options.resume:
        from .execute import DWELLS_DONE
        # a stepped chunk left unfinished kept its lines' progress: whole lines (every dwell
        # done, as the interrupt's message counted them) and part-way ones
        whole = partway = 0
        for a in partial.values():
            finished = a[DWELLS_DONE] == a["states"].shape[1]      # (lines, dwells)
            whole += int(np.count_nonzero(finished))
            partway += int(np.count_nonzero((a[DWELLS_DONE] > 0) & ~finished))
        kept = n - computed + whole
        sys.stderr.write(f"resumed: {kept:,} of {n:,} {unit} were already done, "
                         f"{n - kept:,} computed"
                         + (f" ({partway:,} of them from where they stopped)" if partway
                            else "") + "\n")
    return outputs
