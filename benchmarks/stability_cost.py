"""The cost of a stability chart (outputs.stability, Floquet multipliers from one load period a
point) against the time-domain map of the same grid.

What it measures
----------------
1. harness-stability (17 703 points: W/w1 x P0 over a 1 m Table 1 span, 2 % damping, one
   mode): the Floquet kernel over every point (`sweep.models.stability.stability_outputs`, the
   kernel call alone) and the whole `sweep.run`, on 1 and 2 threads: chart points per second.
2. harness-parametric's own grid (15 lengths x 26 W/w1, P0 = 2 N, t_end = 30 s), run two
   ways in one process: its time-domain map (the built-in scene as it is, lanes driver, RK45
   at rtol 1e-8), and the same grid with only outputs.stability: wall time of `sweep.run` and
   kernel time (the time-domain solve: `solve_points` on its rows; the chart: the Floquet
   kernel), and their ratio; and how many points the two call unstable (the time-domain map's
   diverged, modulated, unsettled or growing points against growth_rate > 0).

Warm Numba cache (everything run once first); best of --repeats.

Command
-------
    PYTHONPATH=. python benchmarks/stability_cost.py
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

import numpy as np  # noqa: E402

import sweep  # noqa: E402
from bench_common import markdown_table, parameter_table  # noqa: E402
from sweep.models import modal  # noqa: E402
from sweep.models.stability import stability_outputs  # noqa: E402
from sweep.models.transverse import resolve, settings_vector  # noqa: E402
from sweep.run import solve_points  # noqa: E402

ONLY_STABILITY = {"outputs.stability": True, "outputs.amplitude": False,
                  "outputs.peak_amplitude": False, "outputs.settling_time": False,
                  "outputs.response_period": False, "outputs.solver_stats": False}


def best(fn, repeats: int) -> float:
    """The smallest wall time (s) of fn() over `repeats` calls."""
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        fn()
        times.append(time.perf_counter() - began)
    return min(times)


def floquet_kernel(scene, threads: int) -> float:
    """The Floquet kernel over every point of `scene` (s): coefficients built outside."""
    inputs = resolve(scene)
    coeffs = modal.oscillator(inputs.params)
    return lambda: stability_outputs(coeffs, inputs.dims, inputs.shape, inputs.n_modes, threads)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    chart = sweep.load_scene("harness-stability")
    n = int(np.prod([a.size for a in chart.axes.values()]))
    sweep.run(chart)
    rows = []
    for threads in (1, 2):
        kernel = best(floquet_kernel(chart, threads), args.repeats)
        whole = best(lambda: sweep.run(chart, threads=threads), args.repeats)
        rows.append(("harness-stability", n, threads, f"{kernel:.3f}", f"{n / kernel:,.0f}",
                     f"{whole:.3f}", f"{n / whole:,.0f}"))
    print(f"## Stability chart ({time.strftime('%Y-%m-%d')})\n")
    print(markdown_table(("scene", "points", "threads", "kernel s", "kernel points/s",
                          "sweep.run s", "points/s"), rows))

    timedomain = sweep.load_scene("harness-parametric")
    stable_only = sweep.load_scene("harness-parametric", overrides=ONLY_STABILITY)
    table = parameter_table(timedomain)
    settings = settings_vector(timedomain)
    m = table.shape[0]
    solve_points(table[:16], settings, 0, threads=1)
    sweep.run(stable_only)
    compare = []
    for threads in (1, 2):
        t_kernel = best(lambda: solve_points(table, settings, 0, threads=threads), args.repeats)
        t_run = best(lambda: sweep.run(timedomain, threads=threads), args.repeats)
        f_kernel = best(floquet_kernel(stable_only, threads), args.repeats)
        f_run = best(lambda: sweep.run(stable_only, threads=threads), args.repeats)
        compare.append((threads, m, f"{t_kernel:.3f}", f"{f_kernel:.4f}",
                        f"{t_kernel / f_kernel:,.0f}x", f"{t_run:.3f}", f"{f_run:.3f}",
                        f"{t_run / f_run:,.0f}x"))
    print("\n## harness-parametric's grid: time-domain map (t_end = 30 s) against the chart\n")
    print(markdown_table(("threads", "points", "time-domain kernel s", "Floquet kernel s",
                          "kernel ratio", "time-domain sweep.run s", "chart sweep.run s",
                          "run ratio"), compare))
    both = sweep.run(sweep.load_scene("harness-parametric",
                                      overrides={"outputs.stability": True}))
    unstable = both["growth_rate"] > 0
    meanings = dict(zip(both["state"].attrs["flag_values"].tolist(),
                        both["state"].attrs["flag_meanings"].split()))
    grew = both["amplitude"] > 1e-4        # above the seed q0 = 1e-4 m at the end
    print(f"\nFloquet unstable: {int(unstable.sum())} of {m} points; time-domain tail amplitude "
          f"above the seed: {int(grew.sum())}; both: {int((unstable & grew).sum())}; states of "
          f"the Floquet-unstable points: "
          + ", ".join(f"{meanings[v]} {int(((both['state'] == v) & unstable).sum())}"
                      for v in meanings if int(((both['state'] == v) & unstable).sum())))
    print("\nCommand: PYTHONPATH=. python " + " ".join(sys.argv))


if __name__ == "__main__":
    main()
