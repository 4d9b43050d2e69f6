"""Base excitation (issue 18): right-hand-side evaluations per second with and without [base].

What it measures
----------------
One grid, --points-per-axis span lengths in [0.3, 1.0] m x as many frequency ratios in
[0.5, 3] (40 x 40 = 1600 points by default), in three forms of the same scene: the consistent
model, Table 1 cable with inertia 2.865e-12 m^4, damping ratio 0.02, from q0 = 1e-3 m at rest,
t in [0, 5] s, the scene's default tolerances (rtol 1e-8, each point's own atol):
  (a) load:  the axial harmonic end load alone, P0 = 2 N; the axis is load.frequency_ratio
             (W/w1). The kernel compiles the cos(W t) terms in and the base term out.
  (b) base:  base excitation alone: load.amplitude = 0, base.acceleration_g = 1; the axis is
             base.frequency_ratio (f/f1). No row has a time-varying stiffness, so the cos(W t)
             terms are compiled out (settings CONSTANT_STIFFNESS, as `sweep run` sets it) and
             the base term -G A sin(w_b t) in, with the absolute acceleration metric.
  (c) both:  (b) plus (a)'s end load at a fixed W/w1 = 2 (the principal parametric
             resonance); the axis is base.frequency_ratio. Both terms are compiled in.
The kernel is `sweep.run.solve_points` (the lanes driver by default, as `sweep run` calls it,
without building the Dataset and without a time series), for each solver.method of --methods
and each thread count of --threads. Every (form, method) kernel is compiled (or loaded from
Numba's cache) on two points before anything is timed. Each configuration is timed --repeats
times, the forms one after another inside each repeat (so a burst of load elsewhere on the
machine hits all three alike), and the best (smallest) wall time is kept.

RHS evals/s = the kernel's own count of right-hand-side evaluations (counts[:, RHS_EVALS],
summed over the points) / that wall time: the throughput per unit of integration work, which
does not depend on how many steps each form's responses need. "ratio to (a)" is that rate over
form (a)'s, same method and threads. The issue's acceptance: ratio >= 0.8 for (b) and (c).

Command (full size; on an otherwise idle machine, about a minute warm)
---------------------------------------------------------------------
    PYTHONPATH=. python benchmarks/base_excitation.py --json base_excitation.json

Small check: python benchmarks/base_excitation.py --points-per-axis 8 --repeats 2
Prints a Markdown table to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import machine, markdown_table, parameter_table, write_json  # noqa: E402
from sweep.kernels import oscillator as osc  # noqa: E402
from sweep.models.transverse import set_constant_stiffness  # noqa: E402
from sweep.kernels import transverse as tk  # noqa: E402
from sweep.run import settings_vector, solve_points  # noqa: E402
from sweep.scene import Scene, load_scene_text  # noqa: E402

SCENE = """
name = "base-excitation-bench"
description = "Benchmark: RHS evaluations per second, form {form}"

[model]
kind = "transverse"
coefficients = "consistent"
membrane = 0.375

[cable]
inertia = 2.865e-12
damping_ratio = 0.02

[load]
type = "harmonic"
{load}
{base}
[initial]
displacement = 1e-3
velocity = 0.0

[axes]
length = {{start = 0.3, stop = 1.0, num = {n}}}
{axis} = {{start = 0.5, stop = 3.0, num = {n}}}

[solver]
t_end = 5.0
method = "{method}"
"""

LOAD_ONLY = "amplitude = 2.0"
LOAD_FIXED = "amplitude = 2.0\nfrequency_ratio = 2.0"
NO_LOAD = "amplitude = 0.0"
BASE = "\n[base]\nacceleration_g = 1.0\n"

# form: (label, [load] lines, [base] section, axis name)
FORMS = {
    "a": ("(a) load", LOAD_ONLY, "", "frequency_ratio"),
    "b": ("(b) base", NO_LOAD, BASE, "base_frequency_ratio"),
    "c": ("(c) load + base", LOAD_FIXED, BASE, "base_frequency_ratio"),
}


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--points-per-axis", type=int, default=40,
                   help="lengths and frequency ratios each (default 40: 1600 points)")
    p.add_argument("--methods", default="rk45,dop853", help="solver.method values")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts")
    p.add_argument("--repeats", type=int, default=10,
                   help="timed runs per configuration (default 10)")
    p.add_argument("--driver", choices=("lanes", "scalar"), default="lanes",
                   help="transverse driver (default lanes, the scene default)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def build_scene(form: str, n: int, method: str) -> Scene:
    """Form `form` ("a", "b" or "c") of the benchmark scene on an n x n grid."""
    _, load, base, axis = FORMS[form]
    text = SCENE.format(form=form, load=load, base=base, axis=axis, n=n, method=method)
    return load_scene_text(text, source="base_excitation.py")


def kernel_inputs(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """(parameter rows, settings vector) of `scene`, as `sweep.run` builds them: with no
    time-varying stiffness in any row, CONSTANT_STIFFNESS compiles the cos(W t) terms out."""
    table = parameter_table(scene)
    settings = settings_vector(scene)
    set_constant_stiffness(settings, {c: table[:, osc.PARAM_NAMES.index(c)] for c in ("k1", "g1")})
    return table, settings


def main() -> None:
    import numba
    args = parse_args()
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    thread_counts = [int(s) for s in args.threads.split(",") if s.strip()]
    n_axis = args.points_per_axis

    inputs = {}
    compile_s = {}
    for method in methods:
        for form in FORMS:
            table, settings = kernel_inputs(build_scene(form, n_axis, method))
            start = time.perf_counter()
            solve_points(table[:2], settings, 0, threads=1, driver=args.driver)
            compile_s[(form, method)] = time.perf_counter() - start
            inputs[(form, method)] = (table, settings)
    for (form, method), (table, settings) in inputs.items():
        if settings[tk.BASE] != (0.0 if form == "a" else 1.0):
            raise RuntimeError(f"form {form}: settings BASE = {settings[tk.BASE]}")
        if (settings[tk.CONSTANT_STIFFNESS] != 0.0) != (form == "b"):
            raise RuntimeError(f"form {form}: CONSTANT_STIFFNESS = "
                               f"{settings[tk.CONSTANT_STIFFNESS]}")

    best: dict[tuple[str, str, int], float] = {}
    counts: dict[tuple[str, str], np.ndarray] = {}
    states: dict[tuple[str, str], np.ndarray] = {}
    for _ in range(args.repeats):
        for method in methods:
            for threads in thread_counts:
                for form in FORMS:
                    table, settings = inputs[(form, method)]
                    start = time.perf_counter()
                    res = solve_points(table, settings, 0, threads=threads, driver=args.driver)
                    wall = time.perf_counter() - start
                    key = (form, method, threads)
                    best[key] = min(best.get(key, np.inf), wall)
                    if (form, method) in counts and not np.array_equal(
                            counts[(form, method)], res.counts):
                        raise RuntimeError(f"form {form}, {method}, {threads} threads: "
                                           "counts differ between runs")
                    counts[(form, method)] = res.counts
                    states[(form, method)] = res.states

    runs = []
    for method in methods:
        for threads in thread_counts:
            rate_a = None
            for form in FORMS:
                c = counts[(form, method)]
                n = len(c)
                wall = best[(form, method, threads)]
                rate = float(c[:, tk.RHS_EVALS].sum()) / wall
                rate_a = rate if form == "a" else rate_a
                runs.append({"form": form, "label": FORMS[form][0], "method": method,
                             "threads": threads,
                             "threads_used": min(threads, numba.config.NUMBA_NUM_THREADS),
                             "points": n, "wall_s": wall, "rhs_evals_per_s": rate,
                             "ratio_to_a": rate / rate_a if rate_a else float("nan"),
                             "mean_steps": float(c[:, tk.STEPS].mean()),
                             "mean_rhs_evals": float(c[:, tk.RHS_EVALS].mean()),
                             "compile_s": compile_s[(form, method)]})

    from sweep.kernels.metrics import STATE_MEANINGS
    n_points = n_axis * n_axis
    print(f"# Base excitation: RHS evaluations per second, {n_axis} lengths x {n_axis} frequency "
          f"ratios = {n_points} points, consistent model, Table 1 cable, inertia 2.865e-12 m^4, "
          f"damping 0.02, q0 = 1e-3 m, t_end = 5 s, rtol 1e-8, {args.driver} driver\n")
    print(f"Machine: {machine()}; Python {platform.python_version()}, numba {numba.__version__}; "
          f"{datetime.date.today().isoformat()}; best of {args.repeats} runs per row; first "
          f"kernel calls (compile or cache load): "
          f"{sum(compile_s.values()):.2f} s in all.\n")
    print(markdown_table(
        ["form", "method", "threads", "points", "wall (s)", "RHS evals/s", "ratio to (a)",
         "mean steps/point"],
        [[r["label"], r["method"], r["threads_used"], r["points"], f"{r['wall_s']:.3f}",
          f"{r['rhs_evals_per_s']:,.3g}", f"{r['ratio_to_a']:.2f}", f"{r['mean_steps']:,.0f}"]
         for r in runs]))
    print()
    for (form, method), s in states.items():
        values, n = np.unique(s, return_counts=True)
        print(f"States, {FORMS[form][0]}, {method}: "
              + ", ".join(f"{STATE_MEANINGS[v]} {int(k)}" for v, k in zip(values, n)))
    lowest = {form: min(r["ratio_to_a"] for r in runs if r["form"] == form) for form in "bc"}
    worst = min(lowest.values())
    print("\nAcceptance (RHS evals/s with [base] >= 0.8 x without, every method and thread "
          "count): " + "; ".join(f"{FORMS[f][0]}: lowest ratio {x:.2f}, "
                                 f"{'met' if x >= 0.8 else 'NOT met'}"
                                 for f, x in lowest.items()) + ".")
    print("\nCommand: python benchmarks/base_excitation.py " + " ".join(sys.argv[1:]))

    if args.json:
        write_json(args.json, {
            "points_per_axis": n_axis, "points": n_points, "driver": args.driver,
            "repeats": args.repeats, "runs": runs, "lowest_ratio": lowest,
            "acceptance_met": worst >= 0.8, "machine": machine(),
            "python": platform.python_version(), "numba": numba.__version__,
            "date": datetime.date.today().isoformat()})


if __name__ == "__main__":
    main()
