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
2. SciPy: `solve_ivp(method="RK45")` (with --method dop853: "DOP853", and cable-sweep runs
   solver.method = "dop853") one point at a time on a random sample of the same grid
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

4. At equal error (--equal-error): every solver over a ladder of rtols (--ladder; atol = rtol x
   1e-4), its max final-state error max_i |q_i(5) - q_ref,i(5)| / max_t |q_ref,i| on the SciPy
   sample against DOP853 at rtol 1e-13 / atol 1e-16 (independent of every solver timed), and its
   throughput: cable-sweep (lanes: RK45 with SciPy's controller and with the PI controller,
   and DOP853 with SciPy's controller, `solver.method = "dop853"`) and numbalsoda
   dop853 (a Numba prange loop over all points, output at t = 0 and 5 s only, its cheapest
   case; the optional `bench` extra) over the whole grid on the most threads, SciPy RK45 on the
   sample. Throughput at the --target error is interpolated in log-log between the two rungs
   that bracket it; the ratios compare solvers at that same error.

Command (full size; run on an otherwise idle machine)
------------------------------------------------------
    PYTHONPATH=. python benchmarks/reference_sweep.py --json reference_sweep.json

Small check: python benchmarks/reference_sweep.py --points-per-axis 10 --scipy-sample 10
Prints Markdown tables to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import math
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
    p.add_argument("--equal-error", action="store_true",
                   help="also compare every solver at equal final-state error (item 4)")
    p.add_argument("--ladder", default="1e-4,3e-5,1e-5,3e-6,1e-6,3e-7,1e-7,3e-8",
                   help="rtols of the equal-error comparison")
    p.add_argument("--target", type=float, default=1e-5,
                   help="final-state error at which solvers are compared (default 1e-5)")
    p.add_argument("--method", choices=("rk45", "dop853"), default="rk45",
                   help="cable-sweep's solver.method for items 1-3; SciPy runs the same method "
                        "(default rk45)")
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


def time_scipy(rows: np.ndarray, rtol: float, atol: float,
               method: str = "RK45") -> tuple[float, np.ndarray]:
    """Total wall time (s) of solve_ivp(method) over `rows`, one at a time, and the step
    counts."""
    steps = np.empty(len(rows), np.int64)
    start = time.perf_counter()
    for i, row in enumerate(rows):
        steps[i] = len(solve_scipy(row, T_END, rtol, atol, method=method).t) - 1
    return time.perf_counter() - start, steps


def scipy_agreement(rows: np.ndarray, kernel: KernelResult, rtol: float, atol: float,
                    n_grid: int, method: str = "RK45") -> dict[str, object]:
    """Compare SciPy (`method`) with cable-sweep's amplitude, step and evaluation counts on
    `rows`.

    `kernel` holds cable-sweep's results for the same rows, in the same order.
    """
    from sweep.kernels import transverse as tk
    grid_diff = np.empty(len(rows))
    refined_diff = np.empty(len(rows))
    step_diff = np.empty(len(rows), np.int64)
    rhs_equal = np.empty(len(rows), bool)
    for i, row in enumerate(rows):
        sol = solve_scipy(row, T_END, rtol, atol, dense=True, method=method)
        amp = kernel.reals[i, tk.AMPLITUDE]
        amp_grid = tail_amplitude(sol, TAIL_START, T_END, n_grid, refine=False)
        amp_refined = tail_amplitude(sol, TAIL_START, T_END, n_grid, refine=True)
        grid_diff[i] = abs(amp - amp_grid) / amp_grid
        refined_diff[i] = abs(amp - amp_refined) / amp_refined
        step_diff[i] = abs(kernel.counts[i, tk.STEPS] - (len(sol.t) - 1))
        # DOP853's dense output costs SciPy three more evaluations per step (not the kernel's)
        dense_evals = 3 * (len(sol.t) - 1) if method == "DOP853" else 0
        rhs_equal[i] = kernel.counts[i, tk.RHS_EVALS] == sol.nfev - dense_evals
    return {
        "max_rel_amplitude_diff_grid": float(np.nanmax(grid_diff)),
        "max_rel_amplitude_diff_refined": float(np.nanmax(refined_diff)),
        "steps_equal": int(np.sum(step_diff == 0)),
        "max_step_count_diff": int(step_diff.max()),
        "rhs_evals_equal": int(rhs_equal.sum()),
        "points": len(rows),
    }


def final_state_reference(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """q(5) and max_t |q| of each row by SciPy DOP853 at rtol 1e-13, atol 1e-16."""
    q_end = np.empty(len(rows))
    q_max = np.empty(len(rows))
    for i, row in enumerate(rows):
        sol = solve_scipy(row, T_END, 1e-13, 1e-16, method="DOP853", dense=True)
        q_end[i] = sol.y[0, -1]
        q_max[i] = np.abs(sol.sol(np.linspace(0.0, T_END, 20001))[0]).max()
    return q_end, q_max


def at_target(rungs: list[dict[str, float]], target: float) -> float:
    """Trajectories/s at final-state error `target`, log-log interpolated between the cheapest
    rung at or below the target and the rung just looser; NaN when no rung reaches it."""
    rungs = sorted(rungs, key=lambda r: -r["rtol"])
    for k, r in enumerate(rungs):
        if r["error"] <= target:
            if k == 0 or not rungs[k - 1]["error"] > target:
                return r["rate"]
            a, b = rungs[k - 1], r
            w = (math.log(target) - math.log(a["error"])) / (math.log(b["error"]) - math.log(a["error"]))
            return math.exp(math.log(a["rate"]) + w * (math.log(b["rate"]) - math.log(a["rate"])))
    return math.nan


def equal_error(table: np.ndarray, sample: np.ndarray, rtols: list[float], threads: int,
                repeats: int, target: float) -> tuple[str, dict[str, object]]:
    """Item 4: every solver over the rtol ladder; Markdown and a JSON-able dict."""
    from sweep.kernels import transverse as tk
    rows = table[sample]
    q_ref, q_max = final_state_reference(rows)

    def error(q_end: np.ndarray) -> float:
        return float(np.max(np.abs(q_end - q_ref) / q_max))

    rungs: dict[str, list[dict[str, float]]] = {}
    for rtol in rtols:
        atol = rtol * 1e-4
        for name, controller, method in (("cable-sweep (lanes)", 0.0, 0.0),
                                         ("cable-sweep (lanes, PI)", 1.0, 0.0),
                                         ("cable-sweep (lanes, DOP853)", 0.0, 1.0)):
            scene = build_scene(2, rtol, atol)
            settings = settings_vector(scene)
            settings[tk.CONTROLLER] = controller
            settings[tk.METHOD] = method
            settings[tk.SAMPLE_DT] = T_END
            solve_points(table[:2], settings, 2, threads=1)
            best = np.inf
            for _ in range(repeats):
                start = time.perf_counter()
                res = solve_points(table, settings, 2, threads=threads)
                best = min(best, time.perf_counter() - start)
            rungs.setdefault(name, []).append({"rtol": rtol, "rate": len(table) / best,
                                               "error": error(res.series[sample, -1])})
        if NUMBALSODA is not None:
            t_eval = np.array([0.0, T_END])
            out, ok, _, wall = NUMBALSODA.solve("dop853", table, t_eval, rtol, atol,
                                                threads=threads, timed=True)
            err = error(out[sample, -1, 0]) if ok[sample].all() else math.nan
            rungs.setdefault("numbalsoda dop853", []).append(
                {"rtol": rtol, "rate": len(table) / wall, "error": err})
        start = time.perf_counter()
        q_end = np.array([solve_scipy(row, T_END, rtol, atol).y[0, -1] for row in rows])
        rungs.setdefault("SciPy RK45 (Python RHS)", []).append(
            {"rtol": rtol, "rate": len(rows) / (time.perf_counter() - start),
             "error": error(q_end)})
    lines = [f"Max final-state error on the {len(rows)}-point sample (vs DOP853 at rtol 1e-13) "
             f"and trajectories/s; cable-sweep and numbalsoda on {threads} threads over all "
             f"{len(table)} points, SciPy on 1 thread over the sample.\n"]
    names = list(rungs)
    header = ["rtol"] + [f"{n}: error" for n in names] + [f"{n}: traj/s" for n in names]
    body = []
    for k, rtol in enumerate(rtols):
        body.append([f"{rtol:g}"] + [f"{rungs[n][k]['error']:.1e}" for n in names]
                    + [f"{rungs[n][k]['rate']:,.0f}" for n in names])
    lines.append(markdown_table(header, body))
    rates = {n: at_target(rungs[n], target) for n in names}
    mine = rates["cable-sweep (lanes)"]
    lines.append(f"\nAt max final-state error {target:g} (log-log interpolation):\n")
    lines.append(markdown_table(
        ["solver", "trajectories/s", "cable-sweep (lanes) / solver", "cable-sweep (PI) / solver",
         "cable-sweep (DOP853) / solver"],
        [[n, f"{rates[n]:,.0f}", f"{mine / rates[n]:,.1f}x",
          f"{rates['cable-sweep (lanes, PI)'] / rates[n]:,.1f}x",
          f"{rates['cable-sweep (lanes, DOP853)'] / rates[n]:,.1f}x"] for n in names]))
    return "\n".join(lines), {"target": target, "rungs": rungs, "at_target": rates}


NUMBALSODA = None


def state_counts(states: np.ndarray) -> dict[str, int]:
    """Number of points in each response state that occurs."""
    from sweep.kernels.metrics import STATE_MEANINGS
    values, counts = np.unique(states, return_counts=True)
    return {STATE_MEANINGS[v]: int(c) for v, c in zip(values, counts)}


def main() -> None:
    from sweep.kernels import transverse as tk
    args = parse_args()
    thread_counts = [int(s) for s in args.threads.split(",") if s.strip()]
    scene = build_scene(args.points_per_axis, args.rtol, args.atol)
    table = parameter_table(scene)
    settings = settings_vector(scene)
    settings[tk.METHOD] = 1.0 if args.method == "dop853" else 0.0
    peer = args.method.upper()
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
    scipy_wall, scipy_steps = time_scipy(rows, args.rtol, args.atol, peer)
    scipy_rate = len(rows) / scipy_wall
    fastest = max(runs, key=lambda r: r["trajectories_per_s"])
    kernel_sample = KernelResult(result.states[sample], result.reals[sample],
                                 result.counts[sample], result.series[sample], np.empty(0))
    agreement = scipy_agreement(rows, kernel_sample, args.rtol, args.atol, args.grid, peer)

    print(f"# Reference sweep: paper preset, {args.points_per_axis} lengths x "
          f"{args.points_per_axis} frequency ratios = {n} points, q0 = 4e-3 m, t_end = 5 s, "
          f"rtol = {args.rtol:g}, atol = {args.atol:g}, solver.method = {args.method}\n")
    print(f"Machine: {platform.processor() or platform.machine()}, Python "
          f"{platform.python_version()}; first kernel call (compile or cache load): "
          f"{compile_s:.2f} s; best of {args.repeats} runs per thread count.\n")
    headers = ["solver", "threads", "points", "wall (s)", "trajectories/s", "accepted steps/s",
               "mean steps/point", "parallel eff."]
    rows_out = [[f"cable-sweep ({r['driver']})", r["threads_used"], n, f"{r['wall_s']:.3f}",
                 f"{r['trajectories_per_s']:,.0f}", f"{r['steps_per_s']:,.3g}",
                 f"{r['total_steps'] / n:,.0f}", f"{r['parallel_efficiency']:.2f}"]
                for r in runs]
    rows_out.append([f"SciPy {peer} (Python RHS)", 1, len(rows), f"{scipy_wall:.3f}",
                     f"{scipy_rate:,.1f}", f"{scipy_steps.sum() / scipy_wall:,.3g}",
                     f"{scipy_steps.mean():,.0f}", ""])
    print(markdown_table(headers, rows_out))
    speedup = fastest["trajectories_per_s"] / scipy_rate
    step_speedup = fastest["steps_per_s"] / (scipy_steps.sum() / scipy_wall)
    print(f"\ncable-sweep ({fastest['driver']}, {fastest['threads_used']} threads) / SciPy {peer}: "
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

    equal = None
    if args.equal_error:
        global NUMBALSODA
        try:
            from work_precision import Numbalsoda
            NUMBALSODA = Numbalsoda()
            NUMBALSODA.solve("dop853", table[:2], np.array([0.0, T_END]), 1e-5, 1e-9, threads=1)
        except ImportError as exc:
            print(f"numbalsoda not available ({exc}); pip install '.[bench]' to include it",
                  file=sys.stderr)
        text, equal = equal_error(table, sample, [float(r) for r in args.ladder.split(",")],
                                  max(r["threads_used"] for r in runs), args.repeats, args.target)
        print("\n## At equal final-state error\n")
        print(text)

    if args.json:
        write_json(args.json, {"equal_error": equal,
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
