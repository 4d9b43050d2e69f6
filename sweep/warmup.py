"""Compile a scene's kernels ahead of its first run (`sweep compile`).

A scene's first run with an empty Numba cache spends most of its time compiling (7-71 s for the
built-in scenes on the 2-core development VM: benchmarks/RESULTS.md). What is compiled depends
on the scene's choices (its model, method, driver, modes, excitation, outputs), not on its
values, so the scene's own run on a few of its points compiles and caches everything its full
run needs: run it after installing, in a container image or before a batch of jobs, and the
first real run starts at once.

The follow-up passes a run needs only when some point ends in a particular way (the second
pass of a point at rest away from zero, a mode judged off midspan) are compiled too, needed or
not (sweep.threads.COMPILE_AHEAD).
"""

from __future__ import annotations

import dataclasses

from .scene import Scene

POINTS_PER_AXIS = 2
"""Values of each axis the warm-up runs: two, so that a stepped sweep's continuation axis still
has a step to carry its state across."""


def reduced(scene: Scene) -> Scene:
    """`scene` on the first POINTS_PER_AXIS values of each axis and its first [points] set, on
    the threads backend (in this process, whose compiles land in the cache every backend
    reads): the same kernels, a few points."""
    values = dict(scene.values)
    values["run.backend"] = "threads"
    return dataclasses.replace(
        scene, values=values,
        axes={name: axis[:POINTS_PER_AXIS] for name, axis in scene.axes.items()},
        points={name: column[:1] for name, column in scene.points.items()})


def warm_up(scene: Scene, threads: int | None = None) -> float:
    """Run `reduced(scene)` once and discard its result, so that Numba compiles (or loads)
    every kernel the scene's run needs, its follow-up passes included, and keeps them in its
    cache. Returns the seconds spent compiling (0 when everything came from the cache)."""
    from .execute import announce_compilation
    from .run import run
    from .threads import COMPILE_AHEAD
    COMPILE_AHEAD.set()
    try:
        with announce_compilation(False) as clock:
            run(reduced(scene), threads=threads, progress=False)
    finally:
        COMPILE_AHEAD.clear()
    return clock.seconds
