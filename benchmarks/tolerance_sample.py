"""Worst-case accuracy per rtol over a broad random sample (the README's tolerance table).

What it measures
----------------
A seeded random sample (--points, --seed) of the consistent model (Table 1 cable, membrane
0.375) over the ranges the scenes and examples use: length U[0.3, 1.2] m, harmonic load
amplitude U[0.5, 6] N, W/w1 U[0.5, 3], damping ratio U[0, 0.05], q0 log-uniform in
[1e-9, 1e-2] m with a random sign, and on half the points also q'(0) = +-w1 x a log-uniform
[1e-9, 1e-2] m; t in [0, 5] s, the metrics defaults (tail 0.5, tolerance 0.02).

Reference: the kernel's DOP853 (scalar driver) at rtol 1e-13 with atol 1e-3 x rtol x each
point's own scales, and the same at rtol 1e-12 as the reference's own spread. A subset of
--scipy-check points is checked against SciPy's `solve_ivp(method="DOP853", rtol=1e-13)`
(atol 1e-16 x the point's scales; tail amplitude from its dense output, extrema by brentq on
q'), independent of the kernel.

For each rtol of --rtols, cable-sweep as a user runs it (lanes driver, RK45, 2 threads) with
the default atol (0.01 x rtol x the point's scales) and, for comparison, the old fixed
atol = rtol x 1e-4 (m, m/s). Reported: the max, 99th percentile and median relative amplitude
error |A - A_ref| / A_ref over the points whose reference is not `decayed` (a decayed point's
tail amplitude is set by the tolerances: the README says so), the points whose state differs
from the reference's, mean accepted steps, and the wall time; also the max over the points
whose reference is `steady` (a periodic response: no sensitive beat or growth phase).

Command (about 2-4 minutes on 2 shared cores):
    python benchmarks/tolerance_sample.py
Small check: python benchmarks/tolerance_sample.py --points 200 --rtols 1e-8 --scipy-check 5
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import markdown_table, solve_scipy, tail_amplitude  # noqa: E402
from sweep import grid, models  # noqa: E402
from sweep.kernels import metrics as mt  # noqa: E402
from sweep.kernels import oscillator as osc  # noqa: E402
from sweep.kernels import transverse as tk  # noqa: E402
from sweep.run import settings_vector, solve_points  # noqa: E402
from sweep.scene import load_scene_text  # noqa: E402

T_END = 5.0
SCENE = """
name = "tolerance-sample"
[model]
coefficients = "consistent"
membrane = 0.375
[solver]
t_end = 5.0
"""


def sample(n: int, seed: int) -> np.ndarray:
    """The kernel's parameter rows of n random points (see the module docstring)."""
    rng = np.random.default_rng(seed)
    scene = load_scene_text(SCENE, source="tolerance_sample.py")
    p = grid.parameters(scene, {})
    p["length"] = rng.uniform(0.3, 1.2, n)
    p["load_amplitude"] = rng.uniform(0.5, 6.0, n)
    p["frequency_ratio"] = rng.uniform(0.5, 3.0, n)
    p["damping_ratio"] = rng.uniform(0.0, 0.05, n)
    p["initial_displacement"] = rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-9, -2, n)
    w1 = models.consistent(p)["omega_1"]
    with_v = rng.random(n) < 0.5
    p["initial_velocity"] = np.where(with_v, rng.choice([-1.0, 1.0], n) * w1
                                     * 10.0 ** rng.uniform(-9, -2, n), 0.0)
    if p["inertia"] is None:
        p["inertia"] = scene.get("cable.inertia")
    return grid.rows(models.oscillator(p), osc.PARAM_NAMES, n)


def settings(rtol: float, atol: float | None, method: str = "rk45") -> np.ndarray:
    """The settings vector of the scene at rtol; atol None: the default (scaled) atol."""
    overrides = {"solver.rtol": rtol, "solver.method": method}
    if atol is not None:
        overrides["solver.atol"] = atol
    return settings_vector(load_scene_text(SCENE, source="tolerance_sample.py",
                                           overrides=overrides))


def run(table: np.ndarray, s: np.ndarray, driver: str = "lanes", threads: int = 2):
    """(states, amplitudes, peaks, mean steps, wall s) of cable-sweep on every row."""
    start = time.perf_counter()
    r = solve_points(table, s, 0, threads=threads, driver=driver)
    wall = time.perf_counter() - start
    return (r.states, r.reals[:, tk.AMPLITUDE], r.reals[:, tk.PEAK],
            float(r.counts[:, tk.STEPS].mean()), wall)


def reference(table: np.ndarray, rtol: float):
    """The kernel's DOP853 at rtol, atol 1e-3 x rtol x each point's scales (scalar driver)."""
    s = settings(rtol, None, "dop853")
    s[tk.ATOL_SCALE] = 1e-3
    return run(table, s, driver="scalar")


def errors(amp: np.ndarray, ref: np.ndarray) -> np.ndarray:
    err = np.abs(amp - ref) / ref
    return np.where(np.isfinite(err), err, np.inf)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--rtols", default="1e-6,1e-7,1e-8,1e-9,1e-10")
    ap.add_argument("--scipy-check", type=int, default=20,
                    help="points checked against SciPy DOP853 rtol 1e-13")
    args = ap.parse_args()
    t0 = time.perf_counter()
    table = sample(args.points, args.seed)
    run(table[:16], settings(1e-8, None))                       # compile / cache load
    ref_state, ref_amp, ref_peak, ref_steps, ref_wall = reference(table, 1e-13)
    chk_state, chk_amp, *_ = reference(table, 1e-12)
    judged = (ref_state != mt.DECAYED) & (ref_amp > 0.02 * ref_peak) & np.isfinite(ref_amp) \
        & (ref_state != mt.DIVERGED)
    names, counts = np.unique([mt.STATE_MEANINGS[s] for s in ref_state], return_counts=True)
    print(f"# Tolerance sample: {args.points} random points (seed {args.seed}), "
          f"{int(judged.sum())} not decayed\n")
    print("Reference states: " + ", ".join(f"{a} {b}" for a, b in zip(names, counts))
          + f". Reference: kernel DOP853 rtol 1e-13, {ref_steps:,.0f} mean steps, "
          f"{ref_wall:.1f} s. Against rtol 1e-12: max amplitude diff "
          f"{errors(chk_amp, ref_amp)[judged].max():.1e}, states differing "
          f"{int((chk_state != ref_state).sum())}.")
    picks = np.flatnonzero(judged)[:: max(1, int(judged.sum()) // max(args.scipy_check, 1))]
    picks = picks[:args.scipy_check]
    diffs = []
    for i in picks:
        row = table[i]
        atol = 1e-16 * row[[osc.Q_SCALE, osc.V_SCALE]]
        sol = solve_scipy(row, T_END, 1e-13, atol, method="DOP853", dense=True)
        diffs.append(abs(tail_amplitude(sol, 0.5 * T_END, T_END) - ref_amp[i]) / ref_amp[i])
    if diffs:
        print(f"SciPy DOP853 rtol 1e-13 on {len(diffs)} of the points: max amplitude diff "
              f"from the reference {max(diffs):.1e}.\n")
    rows = []
    for rtol in [float(x) for x in args.rtols.split(",")]:
        for label, atol in (("default: 0.01 x rtol x scales", None),
                            ("fixed rtol x 1e-4", rtol * 1e-4)):
            state, amp, _, steps, wall = run(table, settings(rtol, atol))
            err = errors(amp, ref_amp)[judged]
            err_steady = errors(amp, ref_amp)[judged & (ref_state == mt.STEADY)]
            rows.append([f"{rtol:.0e}", label, f"{err.max():.1e}",
                         f"{np.percentile(err, 99):.1e}", f"{np.median(err):.1e}",
                         f"{err_steady.max(initial=0.0):.1e}",
                         str(int((state != ref_state).sum())), f"{steps:,.0f}", f"{wall:.2f}"])
    print(markdown_table(["rtol", "atol", "max amp err", "99th pct", "median", "max, steady",
                          f"states != ref (of {args.points})", "mean steps", "wall 2 thr (s)"],
                         rows))
    worst = np.flatnonzero(judged)[np.argmax(errors(run(table, settings(1e-8, None))[1],
                                                    ref_amp)[judged])]
    print(f"\nWorst point at rtol 1e-8 (default atol): row {worst}, reference state "
          f"{mt.STATE_MEANINGS[ref_state[worst]]}, q0 {table[worst, osc.Q0]:.2e} m, "
          f"v0 {table[worst, osc.V0]:.2e} m/s. Total {time.perf_counter() - t0:.0f} s.")


if __name__ == "__main__":
    main()
