"""The cost of model.modes = N: the multi-mode drivers (scalar and lanes) per N, and N = 1.

What it measures
----------------
One small grid of a built-in-like base-excited scene: the Table 1 cable (E 1.1e11 Pa, rho
8900 kg/m^3, A 6e-6 m^2, inertia 2.865e-12 m^4), damping ratio 0.02, 1 g base excitation, no
end load, from rest, --points-per-axis lengths in [0.3, 0.8] m x as many base frequency
ratios in [0.5, 2], t in [0, 5] s, rtol 1e-8 (each point's own atol), RK45 (--method).

- "one-mode lanes": N = 1 through sweep.run with model.modes = 1 (kernels.lanes, the
  one-mode oscillator), Dataset building included;
- "scalar" and "lanes" for N in --modes: the multi-mode System (kernels.modes) on rows built
  as sweep.run builds them (sweep.models.transverse.modal_rows), solved by
  kernels.modal_driver.solve_block and by kernels.modal_lanes.solve_block, both through
  sweep.threads.solve_modes as sweep.run calls them, in the same run.

For each: mean accepted steps and right-hand-side evaluations per point (the kernels' own
counts), wall time per point on one thread, trajectories/s on 1 and 2 threads (--threads),
and the lanes driver's speed-up over the scalar one. Every kernel is compiled (or loaded from
Numba's cache) on two points before anything is timed; each configuration is timed --repeats
times and the best wall time kept.

Command
-------
    PYTHONPATH=. python benchmarks/modes_cost.py
    PYTHONPATH=. python benchmarks/modes_cost.py --points-per-axis 4 --modes 1 2 --repeats 1

Prints a Markdown table and the command line to stdout.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import markdown_table  # noqa: E402

import sweep  # noqa: E402
from sweep.kernels import layout as tk  # noqa: E402
from sweep.models.basis import pinned_sines  # noqa: E402
from sweep.models import transverse as tm  # noqa: E402
from sweep.threads import solve_modes  # noqa: E402

SCENE = """
name = "modes-cost"
[model]
modes = {n}
membrane = 0.375
[cable]
youngs_modulus = 1.1e11
density = 8900.0
area = 6e-6
inertia = 2.865e-12
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 1.0
[solver]
t_end = 5.0
rtol = 1e-8
method = "{method}"
[run]
threads = {threads}
[axes]
length = {lengths}
base_frequency_ratio = {ratios}
"""


def scene_text(n: int, method: str, points: int, threads: int = 1) -> str:
    lengths = [float(x) for x in np.linspace(0.3, 0.8, points)]
    ratios = [float(x) for x in np.linspace(0.5, 2.0, points)]
    return SCENE.format(n=n, method=method, threads=threads, lengths=lengths, ratios=ratios)


def modes_rows(text: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows in kernels.modes columns, settings) of the scene's grid, as sweep.run builds them."""
    inputs = tm.resolve(sweep.load_scene_text(text))
    assert inputs.n_modes == n
    rows = tm.modal_rows(inputs, np.arange(int(np.prod(inputs.shape))))
    return rows, inputs.settings.copy()


def solve(driver: str, rows: np.ndarray, n: int, s: np.ndarray, threads: int) -> tuple:
    """(wall time in s, counts) of one driver over every row on `threads` threads, through
    sweep.threads.solve_modes as sweep.run calls it."""
    m = rows.shape[0]
    states = np.empty(m, np.int8)
    reals = np.empty((m, tk.N_REALS))
    counts = np.empty((m, tk.N_COUNTS), np.int64)
    series = np.empty((m, 0))
    modal_amp = np.empty((m, n))
    final = np.empty((m, 2 * n))
    began = time.perf_counter()
    solve_modes(rows, pinned_sines(n).kernel_arrays(), s, states, reals, counts, series,
                modal_amp, final, driver=driver,
                threads=threads)
    return time.perf_counter() - began, counts


def best(fn, repeats: int) -> tuple:
    results = [fn() for _ in range(repeats)]
    return min(results, key=lambda r: r[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points-per-axis", type=int, default=8)
    ap.add_argument("--modes", type=int, nargs="+", default=[1, 2, 3, 5, 7])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--method", default="rk45", choices=("rk45", "dop853"))
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    points = args.points_per_axis
    n_points = points * points
    headers = ["driver", "N", "steps/point", "RHS/point", "ms/point (1 thread)"]
    headers += [f"traj/s ({t} thr)" for t in args.threads]
    headers += [f"lanes speed-up ({t} thr)" for t in args.threads]
    table = []

    # N = 1: the one-mode lanes driver through sweep.run
    def one_mode(threads: int) -> tuple:
        scene = sweep.load_scene_text(scene_text(1, args.method, points, threads))
        began = time.perf_counter()
        ds = sweep.run(scene, progress=False)
        return time.perf_counter() - began, ds
    sweep.run(sweep.load_scene_text(scene_text(1, args.method, 2)), progress=False)
    walls = {t: best(lambda: one_mode(t), args.repeats) for t in args.threads}
    ds = walls[args.threads[0]][1]
    table.append(["one-mode lanes (sweep.run)", 1, f"{float(ds['n_steps'].mean()):.0f}",
                  f"{float(ds['n_rhs'].mean()):.0f}",
                  f"{1e3 * walls[args.threads[0]][0] / n_points:.2f}"]
                 + [f"{n_points / walls[t][0]:.1f}" for t in args.threads]
                 + ["" for _ in args.threads])

    for n in args.modes:
        rows, s = modes_rows(scene_text(n, args.method, points), n)
        for driver in ("scalar", "lanes"):
            solve(driver, rows[:2], n, s, 1)                      # compile or load
        timed = {(d, t): best(lambda: solve(d, rows, n, s, t), args.repeats)
                 for t in args.threads for d in ("scalar", "lanes")}
        for driver in ("scalar", "lanes"):
            wall1, counts = timed[(driver, args.threads[0])]
            speed = [f"{timed[('scalar', t)][0] / timed[('lanes', t)][0]:.2f}"
                     if driver == "lanes" else "" for t in args.threads]
            table.append([f"modal {driver}", n, f"{counts[:, tk.STEPS].mean():.0f}",
                          f"{counts[:, tk.RHS_EVALS].mean():.0f}",
                          f"{1e3 * wall1 / n_points:.2f}"]
                         + [f"{n_points / timed[(driver, t)][0]:.1f}" for t in args.threads]
                         + speed)
        print(f"N = {n} done", file=sys.stderr, flush=True)
    print(f"{n_points} points ({points} lengths x {points} base frequency ratios), "
          f"{args.method}, rtol 1e-8, t_end 5 s, best of {args.repeats}\n")
    print(markdown_table(headers, table))
    print("\ncommand: PYTHONPATH=. python " + " ".join(sys.argv))


if __name__ == "__main__":
    main()
