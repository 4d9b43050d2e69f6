"""Throughput: cable-sweep's trajectories/s and accepted steps/s against grid size and threads.

What it measures
----------------
The reference sweep's problem (reference_sweep.py: paper coefficients, Eq.32 as printed,
harmonic load 4 N, undamped, q0 = 4 mm at rest, t in [0, 5] s, rtol 1e-8, atol 1e-12) on grids
of span length in [0.3, 1.2] m x frequency ratio in [0.5, 3] of --sizes points each (default
1e2, 1e3, 1e4, 1e5, 1e6). A grid of N points is n_length x n_ratio with n_length the largest
divisor of N not above sqrt(N) (1e3 -> 25 x 40, 1e5 -> 250 x 400), or round(sqrt N) x
round(N / round(sqrt N)) when that divisor would make the grid more than 4:1; the table gives
the grid and its real point count.

For each size and each thread count of --threads (default 1,2), two timings:

1. kernel: `sweep.run.solve_points` on the grid's parameter rows (built as sweep.run builds
   them, by bench_common.parameter_table, outside the timing): the compiled kernel over every
   point, plus the point shuffle and the reorder that solve_points does.
2. sweep.run: `sweep.run(scene, threads=T, progress=False)` on the same grid, no output file:
   everything a Python caller pays, i.e. grid and coefficient arrays, the kernel, and the
   xarray Dataset assembly. "overhead" = the cost of the Python layer around the kernel,
   measured within the same call: sweep.run's wall time minus the solve_points time that
   sweep.run itself records (the Dataset's `run_seconds` attribute), so the noise between
   two separate timings does not enter it (the JSON also has sweep.run wall - kernel wall).

Each reports trajectories/s, accepted steps/s and the parallel efficiency
rate(T) / (T x rate(1)) (T is the thread count actually used: numba caps it at
NUMBA_NUM_THREADS). Small grids are repeated more: a size of N points gets
max(1, min(--max-repeats, ceil(--repeats x 1e4 / N))) timed runs of each measurement (with the
defaults: 50 runs at 1e2, 30 at 1e3, 3 at 1e4, 1 at 1e5 and 1e6); the best (smallest) wall time
is reported. Before any timing one untimed sweep.run on 2 x 2 points loads (or JIT-compiles) the
kernel and imports xarray.

Expected time with the defaults on the 2-core development machine (about 6 400 trajectories/s
per thread): one pass over the 1e6 grid takes about 2.6 minutes on 1 thread and 1.4 on 2, and
each is timed twice (kernel and sweep.run), so the whole script takes about 10 minutes;
--sizes 1e2,1e3,1e4,1e5 leaves the 1e6 grid out (about 1.5 minutes).

Command (full size; run on an otherwise idle machine)
------------------------------------------------------
    PYTHONPATH=. python benchmarks/throughput.py --json throughput.json

Small check: PYTHONPATH=. python benchmarks/throughput.py --sizes 100,1000 --repeats 1
Prints a Markdown table to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

from bench_common import markdown_table, parameter_table, write_json  # noqa: E402
from reference_sweep import SCENE  # noqa: E402
from sweep.run import run, settings_vector, solve_points  # noqa: E402
from sweep.scene import Scene, load_scene_text  # noqa: E402

RATIO_AXIS = {"start": 0.5, "stop": 3.0}


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", default="1e2,1e3,1e4,1e5,1e6",
                   help="comma-separated grid sizes in points (default 1e2,1e3,1e4,1e5,1e6)")
    p.add_argument("--threads", default="1,2",
                   help="comma-separated thread counts (default 1,2)")
    p.add_argument("--repeats", type=int, default=3,
                   help="timed runs at 1e4 points; ceil(R x 1e4 / N) at N points, at least 1 "
                        "(default 3)")
    p.add_argument("--max-repeats", type=int, default=50,
                   help="at most this many timed runs per measurement (default 50)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def grid_shape(n: int) -> tuple[int, int]:
    """(lengths, frequency ratios) of a grid of about n points, as near square as possible."""
    root = math.isqrt(n)
    rows = next(d for d in range(root, 0, -1) if n % d == 0)
    if n // rows > 4 * rows:                 # e.g. a prime n: take the nearest rectangle
        rows = max(1, round(math.sqrt(n)))
        return rows, max(1, round(n / rows))
    return rows, n // rows


def build_scene(n_length: int, n_ratio: int) -> Scene:
    """The reference sweep's scene on an n_length x n_ratio grid (default tolerances)."""
    text = SCENE.format(n=n_length, rtol=1e-8, atol=1e-12)
    return load_scene_text(text, source="throughput.py",
                           overrides={"axes.frequency_ratio": {**RATIO_AXIS, "num": n_ratio}})


def repeats_for(n: int, repeats: int, max_repeats: int) -> int:
    """Timed runs for a grid of n points: more for small grids."""
    return max(1, min(max_repeats, math.ceil(repeats * 1e4 / n)))


def cpu_model() -> str:
    """The CPU model string from /proc/cpuinfo, else platform's processor or machine."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.split(":")[0].strip() in ("model name", "Model"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def threads_used(requested: int) -> int:
    """The thread count solve_points actually runs with (capped at numba's pool size)."""
    import numba
    return min(requested, numba.config.NUMBA_NUM_THREADS)


def best_of(fn, runs: int) -> tuple[float, object]:
    """Smallest wall time (s) of fn() over `runs` calls, and the result of that call."""
    best, best_result = math.inf, None
    for _ in range(runs):
        start = time.perf_counter()
        result = fn()
        wall = time.perf_counter() - start
        if wall < best:
            best, best_result = wall, result
    return best, best_result


def measure(n_target: int, thread_counts: list[int], repeats: int,
            max_repeats: int) -> list[dict[str, object]]:
    """Kernel and sweep.run timings of one grid size on each thread count."""
    from sweep.kernels import transverse as tk
    n_length, n_ratio = grid_shape(n_target)
    scene = build_scene(n_length, n_ratio)
    table = parameter_table(scene)
    settings = settings_vector(scene)
    n = len(table)
    runs = repeats_for(n, repeats, max_repeats)
    out = []
    for threads in thread_counts:
        k_wall, result = best_of(lambda: solve_points(table, settings, 0, threads=threads), runs)
        steps = int(result.counts[:, tk.STEPS].sum())
        r_wall, ds = best_of(lambda: run(scene, threads=threads, progress=False), runs)
        r_steps = int(ds["n_steps"].values.sum())
        inner = float(ds.attrs["run_seconds"])      # solve_points inside that same call
        if r_steps != steps:
            raise RuntimeError(f"sweep.run took {r_steps} steps, solve_points {steps}")
        out.append({
            "points": n, "grid": [n_length, n_ratio], "threads": threads,
            "threads_used": threads_used(threads), "runs": runs,
            "kernel_wall_s": k_wall, "kernel_trajectories_per_s": n / k_wall,
            "kernel_steps_per_s": steps / k_wall,
            "run_wall_s": r_wall, "run_trajectories_per_s": n / r_wall,
            "run_steps_per_s": steps / r_wall,
            "run_kernel_s": inner, "overhead_s": r_wall - inner,
            "overhead_fraction": (r_wall - inner) / r_wall,
            "run_minus_kernel_s": r_wall - k_wall,
            "total_steps": steps, "mean_steps_per_point": steps / n,
        })
        print(f"  {n} points, {threads} thread(s): kernel {k_wall:.3f} s, sweep.run "
              f"{r_wall:.3f} s (best of {runs})", file=sys.stderr, flush=True)
    one = next((r for r in out if r["threads_used"] == 1), None)
    for r in out:
        for key in ("kernel", "run"):
            rate1 = one[f"{key}_trajectories_per_s"] if one else math.nan
            r[f"{key}_parallel_efficiency"] = (r[f"{key}_trajectories_per_s"]
                                               / (r["threads_used"] * rate1))
    return out


def main() -> None:
    args = parse_args()
    sizes = [int(float(s)) for s in args.sizes.split(",") if s.strip()]
    thread_counts = [int(s) for s in args.threads.split(",") if s.strip()]

    start = time.perf_counter()
    run(build_scene(2, 2), threads=1, progress=False)      # load or compile; import xarray
    first_s = time.perf_counter() - start

    rows = []
    for n in sizes:
        rows += measure(n, thread_counts, args.repeats, args.max_repeats)

    print("# Throughput: reference sweep problem (paper coefficients, q0 = 4 mm, t in [0, 5] s, "
          "rtol 1e-8, atol 1e-12), lengths [0.3, 1.2] m x frequency ratios [0.5, 3]\n")
    print(f"Machine: {cpu_model()}, Python "
          f"{platform.python_version()}; first sweep.run (compile or cache load, imports): "
          f"{first_s:.2f} s. Best of `runs` timed runs. kernel = sweep.run.solve_points; "
          "sweep.run = the whole call (grid, coefficients, kernel, Dataset); "
          "overhead = sweep.run wall - the solve_points time inside that call "
          "(its run_seconds attribute).\n")
    headers = ["points", "grid", "threads", "runs", "kernel wall (s)", "trajectories/s",
               "accepted steps/s", "par. eff.", "sweep.run wall (s)", "sweep.run traj./s",
               "sweep.run par. eff.", "overhead (s)", "overhead (%)"]
    table = [[r["points"], f"{r['grid'][0]} x {r['grid'][1]}", r["threads_used"], r["runs"],
              f"{r['kernel_wall_s']:.4f}", f"{r['kernel_trajectories_per_s']:,.0f}",
              f"{r['kernel_steps_per_s']:.3g}", f"{r['kernel_parallel_efficiency']:.2f}",
              f"{r['run_wall_s']:.4f}", f"{r['run_trajectories_per_s']:,.0f}",
              f"{r['run_parallel_efficiency']:.2f}", f"{r['overhead_s']:.4f}",
              f"{100 * r['overhead_fraction']:.1f}"] for r in rows]
    print(markdown_table(headers, table))
    mean_steps = {r["points"]: r["mean_steps_per_point"] for r in rows}
    print("\nMean accepted steps per point: "
          + ", ".join(f"{n}: {s:,.0f}" for n, s in mean_steps.items()))

    if args.json:
        write_json(args.json, {
            "problem": "reference sweep: paper coefficients, q0 = 4e-3 m, t_end = 5 s, "
                       "rtol 1e-8, atol 1e-12, length [0.3, 1.2] m x frequency_ratio [0.5, 3]",
            "first_call_s": first_s, "repeats": args.repeats, "max_repeats": args.max_repeats,
            "results": rows, "python": platform.python_version(),
            "machine": platform.machine(), "cpu_model": cpu_model()})


if __name__ == "__main__":
    main()
