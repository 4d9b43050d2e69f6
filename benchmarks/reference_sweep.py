"""Reference sweep: cable-sweep throughput on 1 and 2 threads, side by side with SciPy RK45.

What it measures
----------------
The reference sweep is the paper preset (Eq.32 as printed, `model.coefficients = "paper"`,
harmonic load 4 N, undamped) over 100 span lengths in [0.3, 1.2] m x 100 frequency ratios
n = W/w0 in [0.5, 3] (10 000 points), starting at rest from q0 = 4e-3 m, t in [0, 5] s,
rtol 1e-8 and atol 1e-12 (the scene defaults) unless --rtol / --atol are given.

1. cable-sweep: `sweep.run.solve_points` (the kernel over every point, as `sweep.run` calls it,
   without building the xarray Dataset) on each thread count of --threads. It reports
   trajectories/s, accepted steps/s and the parallel efficiency rate(N) / (N * rate(1)).
   The first call (JIT compile, or loading numba's on-disk cache) is timed separately on two
   points; for a true cold compile run with an empty cache: NUMBA_CACHE_DIR=$(mktemp -d).
   Each thread count is timed --repeats times; the best (smallest) wall time is reported.
2. SciPy: `solve_ivp(method="RK45")` one point at a time on a random sample of the same grid
   (--scipy-sample points, fixed --seed), same rtol/atol, plain Python right-hand side with
   the coefficients of the same parameter rows. Timed without dense output (integration
   only, SciPy's most favourable case), once per point. The speed-up is
   cable-sweep(most threads) / SciPy, in trajectories per second.
3. Agreement on the sample (an untimed second SciPy run with dense_output=True):
   - the max relative difference between cable-sweep's `amplitude` (max |q| for t >= 2.5 s,
     extrema located on the dense output) and max |q| of SciPy's dense output on a grid of
     --grid points over [2.5, 5] s. The grid max slightly underestimates the true max (by up
     to about (omega dt)^2 / 8 relative, omega the response's angular frequency, dt the grid
     spacing), so this difference is not expected to be below that level; the `refined` row
     repeats it with each extremum located by root-finding q' = 0 on the dense output (what
     the kernel does), which should agree to near round-off;
   - whether the accepted step counts (cable-sweep `n_steps` vs len(sol.t) - 1) and the
     right-hand-side evaluation counts (`n_rhs` vs sol.nfev) are equal point by point.

Command (full size; run on an otherwise idle machine)
------------------------------------------------------
    PYTHONPATH=. python benchmarks/reference_sweep.py --json reference_sweep.json

Small check: python benchmarks/reference_sweep.py --points-per-axis 10 --scipy-sample 10
Prints Markdown tables to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

from bench_common import (markdown_table, parameter_table, solve_scipy, tail_amplitude,  # noqa: E402
                    write_json)
from sweep.run import KernelResult, settings_vector, solve_points  # noqa: E402
from sweep.scene import Scene, load_scene_text  # noqa: E402

T_END = 5.0
TAIL_START = 2.5       # the scene's default tail window: the last half of [0, t_end]

SCENE = """
name = "reference-sweep"
description = "Benchmark: paper preset, 100 lengths x 100 frequency ratios, q0 = 4 mm"

[model]
kind = "transverse"
coefficients = "paper"
paper_parametric = "printed"

[load]
type = "harmonic"
amplitude = 4.0

[initial]
displacement = 4e-3
velocity = 0.0

[axes]
length = {{start = 0.3, stop = 1.2, num = {n}}}
frequency_ratio = {{start = 0.5, stop = 3.0, num = {n}}}

[solver]
t_end = 5.0
rtol = {rtol!r}
atol = {atol!r}
"""


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--points-per-axis", type=int, default=100,
                   help="points per axis: the grid has N x N points (default 100)")
    p.add_argument("--threads", default="1,2",
                   help="comma-separated thread counts to time (default 1,2)")
    p.add_argument("--drivers", default="lanes,scalar",
                   help="kernel drivers to time, comma-separated (default lanes,scalar); the "
                        "first one's results are checked against SciPy")
    p.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance (default 1e-8)")
    p.add_argument("--atol", type=float, default=1e-12, help="absolute tolerance (default 1e-12)")
    p.add_argument("--scipy-sample", type=int, default=100,
                   help="points solved with SciPy RK45 (default 100)")
    p.add_argument("--seed", type=int, default=12345, help="seed of the SciPy sample")
    p.add_argument("--repeats", type=int, default=3,
                   help="timed runs per thread count; the best is reported (default 3)")
    p.add_argument("--grid", type=int, default=20001,
                   help="dense-output grid points on [2.5, 5] s for SciPy's amplitude")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def build_scene(points_per_axis: int, rtol: float, atol: float) -> Scene:
    """The reference sweep's scene."""
    text = SCENE.format(n=points_per_axis, rtol=rtol, atol=atol)
    return load_scene_text(text, source="reference_sweep.py")


def compile_time(table: np.ndarray, settings: np.ndarray) -> float:
    """Wall time (s) of the first kernel call (two points): JIT compile or cache load."""
    start = time.perf_counter()
    solve_points(table[:2], settings, 0, threads=1)
    return time.perf_counter() - start


def time_sweep(table: np.ndarray, settings: np.ndarray, threads: int,
               repeats: int, driver: str = "lanes") -> tuple[float, KernelResult]:
    """Best wall time (s) of solve_points over `repeats` runs on `threads`, and its result."""
    best = np.inf
    result = None
    solve_points(table[:2], settings, 0, threads=1, driver=driver)      # compile or load
    for _ in range(repeats):
        start = time.perf_counter()
        result = solve_points(table, settings, 0, threads=threads, driver=driver)
        best = min(best, time.perf_counter() - start)
    return best, result


def threads_used(requested: int) -> int:
    """The thread count solve_points actually runs with (capped at numba's pool size)."""
    import numba
    return min(requested, numba.config.NUMBA_NUM_THREADS)


def time_scipy(rows: np.ndarray, rtol: float, atol: float) -> tuple[float, np.ndarray]:
    """Total wall time (s) of solve_ivp(RK45) over `rows`, one at a time, and the step counts."""
    steps = np.empty(len(rows), np.int64)
    start = time.perf_counter()
    for i, row in enumerate(rows):
        steps[i] = len(solve_scipy(row, T_END, rtol, atol).t) - 1
    return time.perf_counter() - start, steps


def scipy_agreement(rows: np.ndarray, kernel: KernelResult, rtol: float, atol: float,
                    n_grid: int) -> dict[str, object]:
    """Compare SciPy RK45 with cable-sweep's amplitude, step and evaluation counts on `rows`.

    `kernel` holds cable-sweep's results for the same rows, in the same order.
    """
    from kernels import transverse as tk
    grid_diff = np.empty(len(rows))
    refined_diff = np.empty(len(rows))
    step_diff = np.empty(len(rows), np.int64)
    rhs_equal = np.empty(len(rows), bool)
    for i, row in enumerate(rows):
        sol = solve_scipy(row, T_END, rtol, atol, dense=True)
        amp = kernel.reals[i, tk.AMPLITUDE]
        amp_grid = tail_amplitude(sol, TAIL_START, T_END, n_grid, refine=False)
        amp_refined = tail_amplitude(sol, TAIL_START, T_END, n_grid, refine=True)
        grid_diff[i] = abs(amp - amp_grid) / amp_grid
        refined_diff[i] = abs(amp - amp_refined) / amp_refined
        step_diff[i] = abs(kernel.counts[i, tk.STEPS] - (len(sol.t) - 1))
        rhs_equal[i] = kernel.counts[i, tk.RHS_EVALS] == sol.nfev
    return {
        "max_rel_amplitude_diff_grid": float(np.nanmax(grid_diff)),
        "max_rel_amplitude_diff_refined": float(np.nanmax(refined_diff)),
        "steps_equal": int(np.sum(step_diff == 0)),
        "max_step_count_diff": int(step_diff.max()),
        "rhs_evals_equal": int(rhs_equal.sum()),
        "points": len(rows),
    }


def state_counts(states: np.ndarray) -> dict[str, int]:
    """Number of points in each response state that occurs."""
    from kernels.metrics import STATE_MEANINGS
    values, counts = np.unique(states, return_counts=True)
    return {STATE_MEANINGS[v]: int(c) for v, c in zip(values, counts)}


def main() -> None:
    args = parse_args()
    thread_counts = [int(s) for s in args.threads.split(",") if s.strip()]
    scene = build_scene(args.points_per_axis, args.rtol, args.atol)
    table = parameter_table(scene)
    settings = settings_vector(scene)
    n = len(table)

    compile_s = compile_time(table, settings)
    runs = []
    results = {}
    for driver in args.drivers.split(","):
        for threads in thread_counts:
            wall, results[driver] = time_sweep(table, settings, threads, args.repeats, driver)
            steps = int(results[driver].counts[:, 0].sum())
            runs.append({"driver": driver, "threads": threads,
                         "threads_used": threads_used(threads), "wall_s": wall,
                         "trajectories_per_s": n / wall, "steps_per_s": steps / wall,
                         "total_steps": steps})
    for r in runs:
        rate1 = next((o["trajectories_per_s"] for o in runs
                      if o["threads_used"] == 1 and o["driver"] == r["driver"]), None)
        r["parallel_efficiency"] = (r["trajectories_per_s"] / (r["threads_used"] * rate1)
                                    if rate1 else float("nan"))
    result = next(iter(results.values()))

    sample = np.sort(np.random.default_rng(args.seed).choice(
        n, size=min(args.scipy_sample, n), replace=False))
    rows = table[sample]
    scipy_wall, scipy_steps = time_scipy(rows, args.rtol, args.atol)
    scipy_rate = len(rows) / scipy_wall
    fastest = max(runs, key=lambda r: r["trajectories_per_s"])
    kernel_sample = KernelResult(result.states[sample], result.reals[sample],
                                 result.counts[sample], result.series[sample], np.empty(0))
    agreement = scipy_agreement(rows, kernel_sample, args.rtol, args.atol, args.grid)

    print(f"# Reference sweep: paper preset, {args.points_per_axis} lengths x "
          f"{args.points_per_axis} frequency ratios = {n} points, q0 = 4e-3 m, t_end = 5 s, "
          f"rtol = {args.rtol:g}, atol = {args.atol:g}\n")
    print(f"Machine: {platform.processor() or platform.machine()}, Python "
          f"{platform.python_version()}; first kernel call (compile or cache load): "
          f"{compile_s:.2f} s; best of {args.repeats} runs per thread count.\n")
    headers = ["solver", "threads", "points", "wall (s)", "trajectories/s", "accepted steps/s",
               "mean steps/point", "parallel eff."]
    rows_out = [[f"cable-sweep ({r['driver']})", r["threads_used"], n, f"{r['wall_s']:.3f}",
                 f"{r['trajectories_per_s']:,.0f}", f"{r['steps_per_s']:,.3g}",
                 f"{r['total_steps'] / n:,.0f}", f"{r['parallel_efficiency']:.2f}"]
                for r in runs]
    rows_out.append(["SciPy RK45 (Python RHS)", 1, len(rows), f"{scipy_wall:.3f}",
                     f"{scipy_rate:,.1f}", f"{scipy_steps.sum() / scipy_wall:,.3g}",
                     f"{scipy_steps.mean():,.0f}", ""])
    print(markdown_table(headers, rows_out))
    speedup = fastest["trajectories_per_s"] / scipy_rate
    step_speedup = fastest["steps_per_s"] / (scipy_steps.sum() / scipy_wall)
    print(f"\ncable-sweep ({fastest['driver']}, {fastest['threads_used']} threads) / SciPy RK45: "
          f"{speedup:,.0f}x trajectories per second ({step_speedup:,.0f}x accepted steps "
          "per second)\n")
    print(markdown_table(
        ["check on the SciPy sample", "value"],
        [["points", agreement["points"]],
         ["max rel. amplitude diff, SciPy grid max "
          f"({args.grid} pts on [2.5, 5] s, underestimates)",
          f"{agreement['max_rel_amplitude_diff_grid']:.2e}"],
         ["max rel. amplitude diff, SciPy extrema refined (q' = 0)",
          f"{agreement['max_rel_amplitude_diff_refined']:.2e}"],
         ["accepted step counts equal", f"{agreement['steps_equal']}/{agreement['points']}"],
         ["max accepted step count difference", agreement["max_step_count_diff"]],
         ["RHS evaluation counts equal", f"{agreement['rhs_evals_equal']}/{agreement['points']}"]]))
    states = state_counts(result.states)
    print("\nStates of the sweep: " + ", ".join(f"{k} {v}" for k, v in states.items()))

    if args.json:
        write_json(args.json, {
            "grid_points": n, "points_per_axis": args.points_per_axis, "rtol": args.rtol,
            "atol": args.atol, "compile_s": compile_s, "repeats": args.repeats,
            "cable_sweep": runs,
            "scipy": {"points": len(rows), "seed": args.seed, "wall_s": scipy_wall,
                      "trajectories_per_s": scipy_rate,
                      "steps_per_s": float(scipy_steps.sum() / scipy_wall)},
            "speedup_vs_scipy": speedup, "step_speedup_vs_scipy": step_speedup, "agreement": agreement, "states": states,
            "python": platform.python_version(), "machine": platform.machine()})


if __name__ == "__main__":
    main()
