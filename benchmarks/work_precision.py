"""Work-precision curves of cable-sweep, SciPy RK45 and SciPy DOP853: picks the default rtol.

What it measures
----------------
Reference points: the consistent model (Table 1 cable defaults, damping ratio 0.02, harmonic
end load 4 N) on lengths 0.3, 0.5, 0.7, 1.0 m x frequency ratios W/w1 0.8, 1.0, 1.9, 2.0, 2.5
(--lengths, --ratios), from q0 = 1e-3 m at rest, t in [0, 5] s.

Reference solution: SciPy `solve_ivp(method="DOP853", rtol=1e-13, atol=1e-16,
dense_output=True)`. Reference amplitude = max |q| over [2.5, 5] s (the kernel's tail window):
the dense output on a 20001-point grid, then every sign change of the velocity component q'
located with brentq and |q| taken there. Also q(5) and the peak max |q| over [0, 5] s.
A second DOP853 run at 10x looser tolerances (rtol 1e-12, atol 1e-15) is compared with it and
printed as the reference's own uncertainty.

For each rtol of --rtols (default 1e-3, 1e-4, ..., 1e-12) with atol = rtol * 1e-4, floored at
1e-16 (--atol-factor; or one fixed atol for all with --atol). The factor 1e-4 keeps the scene
default pair (rtol 1e-8, atol 1e-12) on the curve; with q ~ 1e-3 m it makes the relative
tolerance govern until |q| falls ~10x below q0.
  - cable-sweep: `sweep.run.solve_points` on all points, 1 thread (wall time for the set:
    best of repeats filling >= 0.2 s, after a compile warm-up that is reported separately).
    q(5) comes from the `displacement` time series with sample_interval = t_end (samples at
    t = 0 and t = 5 s only), the amplitude from the `amplitude` output;
  - SciPy RK45 and DOP853, one point at a time, dense_output=True (the run that yields the
    amplitude; the amplitude extraction itself is not timed), one timed run per point.
Reported per rtol: wall time for the set, mean accepted steps, max relative amplitude error
|A - A_ref| / A_ref, max relative final-state error |q(5) - q_ref(5)| / max|q_ref|.

Decayed points. With 2 % damping the short spans off resonance decay by ~1e-9 before the tail
window (l = 0.3 m: A_ref ~ 7e-12 m from q0 = 1e-3 m); there the amplitude is set by atol, not
rtol, and even the reference is only good to ~1e-6 relative. Points whose reference amplitude
is <= metrics.tolerance (0.02) x peak, the kernel's own "decayed" test, are therefore left out of
the amplitude-error column `amp err` and the recommendation; `amp err (all)` includes them.
--include-decayed applies the recommendation to all points.

Recommendation: the largest rtol (cheapest) whose cable-sweep max relative amplitude error is
below --threshold (1e-6) on every (non-decayed) reference point, and stays below it for every
tighter rtol in the list too (so a loose rtol that passes by luck is not picked).

Command (full size; run on an otherwise idle machine, a few minutes, mostly SciPy RK45)
--------------------------------------------------------------------------------------
    PYTHONPATH=. python benchmarks/work_precision.py --plot work_precision.png \
        --json work_precision.json

Small check: python benchmarks/work_precision.py --rtols 1e-4,1e-8
Prints Markdown tables to stdout; --plot PATH saves wall time vs max amplitude error (PNG).
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

from bench_common import (best_time, markdown_table, parameter_table,  # noqa: E402
                          solve_scipy, tail_amplitude, write_json)
from sweep.run import KernelResult, sample_times, settings_vector, solve_points  # noqa: E402
from sweep.scene import Scene, load_scene_text  # noqa: E402

T_END = 5.0
TAIL_START = 2.5                 # the scene's default tail window: the last half of [0, t_end]
DEFAULT_RTOLS = "1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12"
ATOL_FLOOR = 1e-16

SCENE = """
name = "work-precision"
description = "Benchmark: consistent model, Table 1 cable, 2 % damping, reference points"

[model]
kind = "transverse"
coefficients = "consistent"

[cable]
damping_ratio = 0.02

[load]
type = "harmonic"
amplitude = 4.0

[initial]
displacement = 1e-3
velocity = 0.0

[axes]
length = {lengths}
frequency_ratio = {ratios}

[solver]
t_end = 5.0

[outputs]
time_series = true
sample_interval = 5.0
"""


@dataclass
class Reference:
    """Reference quantities per point."""
    amplitude: np.ndarray      # max |q| over [2.5, 5] s (m)
    peak: np.ndarray           # max |q| over [0, 5] s (m)
    q_end: np.ndarray          # q(5) (m)
    steps: np.ndarray          # accepted DOP853 steps


@dataclass
class Measurement:
    """One method at one tolerance, over all points."""
    method: str
    rtol: float
    atol: float
    wall_s: float
    steps: np.ndarray          # accepted steps per point
    amplitude: np.ndarray
    q_end: np.ndarray


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rtols", default=DEFAULT_RTOLS, help="comma-separated rtols")
    p.add_argument("--atol-factor", type=float, default=1e-4,
                   help="atol = rtol * factor, floored at 1e-16 (default 1e-4)")
    p.add_argument("--atol", type=float, help="one fixed atol for every rtol instead")
    p.add_argument("--lengths", default="0.3,0.5,0.7,1.0", help="span lengths (m)")
    p.add_argument("--ratios", default="0.8,1.0,1.9,2.0,2.5", help="frequency ratios W/w1")
    p.add_argument("--ref-rtol", type=float, default=1e-13, help="reference DOP853 rtol")
    p.add_argument("--ref-atol", type=float, default=1e-16, help="reference DOP853 atol")
    p.add_argument("--threshold", type=float, default=1e-6,
                   help="max relative amplitude error of the recommended rtol (default 1e-6)")
    p.add_argument("--include-decayed", action="store_true",
                   help="judge the recommendation on decayed points too")
    p.add_argument("--plot", metavar="PATH", help="save wall time vs amplitude error as PNG")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def floats(text: str) -> list[float]:
    return [float(s) for s in text.split(",") if s.strip()]


def atol_for(rtol: float, args: argparse.Namespace) -> float:
    """The atol paired with `rtol`: fixed --atol, else rtol * --atol-factor (floor 1e-16)."""
    if args.atol is not None:
        return args.atol
    return max(rtol * args.atol_factor, ATOL_FLOOR)


def build_scene(lengths: list[float], ratios: list[float]) -> Scene:
    """The reference points' scene (tolerances are overridden per run)."""
    text = SCENE.format(lengths=lengths, ratios=ratios)
    return load_scene_text(text, source="work_precision.py")


def reference_solution(table: np.ndarray, rtol: float, atol: float) -> Reference:
    """DOP853 at tight tolerances: amplitude (extrema refined), peak, q(5), steps per point."""
    amp, peak, q_end, steps = (np.empty(len(table)) for _ in range(4))
    for i, row in enumerate(table):
        sol = solve_scipy(row, T_END, rtol, atol, method="DOP853", dense=True)
        amp[i] = tail_amplitude(sol, TAIL_START, T_END)
        peak[i] = max(tail_amplitude(sol, 0.0, T_END), float(np.max(np.abs(sol.y[0]))))
        q_end[i] = sol.y[0, -1]
        steps[i] = len(sol.t) - 1
    return Reference(amp, peak, q_end, steps)


def run_cable_sweep(table: np.ndarray, scene: Scene, rtol: float, atol: float) -> Measurement:
    """cable-sweep on all points, 1 thread: best wall time, amplitude and q(t_end)."""
    from kernels import transverse as tk
    tuned = load_scene_text(scene.to_toml(), source="work_precision.py",
                            overrides={"solver.rtol": rtol, "solver.atol": atol})
    settings = settings_vector(tuned)
    times = sample_times(settings[tk.T_END], settings[tk.SAMPLE_DT])
    assert times[-1] == T_END, times
    result: list[KernelResult] = []

    def once() -> None:
        result.append(solve_points(table, settings, times.size, threads=1))

    wall = best_time(once)
    last = result[-1]
    return Measurement("cable-sweep", rtol, atol, wall, last.counts[:, tk.STEPS].copy(),
                       last.reals[:, tk.AMPLITUDE].copy(), last.series[:, -1].copy())


def run_scipy(table: np.ndarray, method: str, rtol: float, atol: float) -> Measurement:
    """SciPy `method` one point at a time (dense output on); the solves alone are timed."""
    wall = 0.0
    steps, amp, q_end = (np.empty(len(table)) for _ in range(3))
    for i, row in enumerate(table):
        start = time.perf_counter()
        sol = solve_scipy(row, T_END, rtol, atol, method=method, dense=True)
        wall += time.perf_counter() - start
        steps[i] = len(sol.t) - 1
        amp[i] = tail_amplitude(sol, TAIL_START, T_END)
        q_end[i] = sol.y[0, -1]
    return Measurement(f"SciPy {method}", rtol, atol, wall, steps, amp, q_end)


def amplitude_errors(amplitude: np.ndarray, ref: Reference) -> np.ndarray:
    """|A - A_ref| / A_ref per point (inf where the method gave no finite amplitude)."""
    err = np.abs(amplitude - ref.amplitude) / ref.amplitude
    return np.where(np.isfinite(err), err, np.inf)


def final_state_errors(q_end: np.ndarray, ref: Reference) -> np.ndarray:
    """|q(5) - q_ref(5)| / max|q_ref| per point."""
    err = np.abs(q_end - ref.q_end) / ref.peak
    return np.where(np.isfinite(err), err, np.inf)


def recommend(runs: list[Measurement], ref: Reference, judged: np.ndarray,
              threshold: float) -> float | None:
    """Largest cable-sweep rtol whose amplitude error (on `judged` points) is below `threshold`
    for it and for every tighter rtol; None if even the tightest fails."""
    best = None
    for m in sorted((m for m in runs if m.method == "cable-sweep"), key=lambda m: m.rtol):
        if np.max(amplitude_errors(m.amplitude, ref)[judged], initial=0.0) < threshold:
            best = m.rtol
        else:
            break
    return best


def step_agreement(runs: list[Measurement], n: int) -> str:
    """A line: on how many points cable-sweep and SciPy RK45 took the same accepted steps."""
    parts = []
    for m in runs:
        if m.method != "cable-sweep":
            continue
        rk = next(r for r in runs if r.method == "SciPy RK45" and r.rtol == m.rtol)
        diff = np.abs(m.steps - rk.steps)
        parts.append(f"rtol {m.rtol:.0e}: {int(np.sum(diff == 0))}/{n}"
                     + (f" (max diff {int(diff.max())})" if diff.max() > 0 else ""))
    return "Accepted steps equal, cable-sweep vs SciPy RK45: " + "; ".join(parts) + "."


def warm_up(table: np.ndarray, scene: Scene) -> float:
    """Compile (or load from cache) the kernel; returns the wall time of that first call."""
    start = time.perf_counter()
    solve_points(table[:1], settings_vector(scene), 2, threads=1)
    return time.perf_counter() - start


def point_labels(scene: Scene) -> list[tuple[float, float]]:
    """(length, frequency ratio) of every point, in the parameter table's (grid C) order."""
    lengths, ratios = np.meshgrid(scene.axes["length"], scene.axes["frequency_ratio"],
                                  indexing="ij")
    return list(zip(lengths.ravel().tolist(), ratios.ravel().tolist()))


def plot(runs: list[Measurement], ref: Reference, judged: np.ndarray, path: str) -> None:
    """Wall time vs max relative amplitude error, one line per method, rtols annotated."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for method, marker in (("cable-sweep", "o"), ("SciPy RK45", "s"), ("SciPy DOP853", "^")):
        ms = [m for m in runs if m.method == method]
        err = [max(np.max(amplitude_errors(m.amplitude, ref)[judged], initial=0.0), 1e-17)
               for m in ms]
        ax.loglog(err, [m.wall_s for m in ms], marker=marker, label=method)
        if method == "cable-sweep":
            for e, m in zip(err, ms):
                ax.annotate(f"{m.rtol:.0e}", (e, m.wall_s), textcoords="offset points",
                            xytext=(4, 4), fontsize=7)
    ax.set_xlabel("max relative amplitude error (non-decayed points)")
    ax.set_ylabel(f"wall time for {len(ref.amplitude)} points, 1 thread (s)")
    ax.set_title("Work-precision, consistent model, t in [0, 5] s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    args = parse_args()
    rtols = floats(args.rtols)
    scene = build_scene(floats(args.lengths), floats(args.ratios))
    table = parameter_table(scene)
    tol = scene.get("metrics.tolerance")

    start = time.perf_counter()
    ref = reference_solution(table, args.ref_rtol, args.ref_atol)
    ref_s = time.perf_counter() - start
    check = reference_solution(table, args.ref_rtol * 10, args.ref_atol * 10)
    decayed = ref.amplitude <= tol * ref.peak
    judged = np.ones_like(decayed) if args.include_decayed else ~decayed
    compile_s = warm_up(table, scene)

    runs: list[Measurement] = []
    for rtol in rtols:
        atol = atol_for(rtol, args)
        runs.append(run_cable_sweep(table, scene, rtol, atol))
        runs.append(run_scipy(table, "RK45", rtol, atol))
        runs.append(run_scipy(table, "DOP853", rtol, atol))
        print(f"rtol {rtol:g} done", file=sys.stderr, flush=True)
    runs.sort(key=lambda m: (m.method != "cable-sweep", m.method, -m.rtol))

    print(f"# Work-precision: consistent model, {len(table)} reference points "
          f"({int(decayed.sum())} decayed: A_ref <= {tol:g} x peak), t_end = 5 s, 1 thread\n")
    check_err = amplitude_errors(check.amplitude, ref)
    print(f"Reference: DOP853 rtol {args.ref_rtol:g} atol {args.ref_atol:g}, "
          f"{ref.steps.mean():,.0f} mean steps, {ref_s:.1f} s. Against DOP853 at 10x looser: "
          f"max rel. amplitude diff {np.max(check_err[~decayed], initial=0):.1e} "
          f"(non-decayed), {np.max(check_err):.1e} (all); max rel. q(5) diff "
          f"{np.max(final_state_errors(check.q_end, ref)):.1e}. cable-sweep first call "
          f"(compile or cache load): {compile_s:.2f} s.\n")
    rows = []
    for m in runs:
        amp_err = amplitude_errors(m.amplitude, ref)
        rows.append([m.method, f"{m.rtol:.0e}", f"{m.atol:.0e}", f"{m.wall_s:.4f}",
                     f"{m.steps.mean():,.1f}", f"{np.max(amp_err[~decayed], initial=0):.1e}",
                     f"{np.max(amp_err):.1e}",
                     f"{np.max(final_state_errors(m.q_end, ref)):.1e}"])
    print(markdown_table(["method", "rtol", "atol", "wall (s)", "mean steps", "amp err",
                          "amp err (all)", "q(5) err"], rows))
    print("\namp err: max |A - A_ref| / A_ref over non-decayed points; amp err (all): over all "
          "points; q(5) err: max |q(5) - q_ref(5)| / max|q_ref|.\n")

    print(step_agreement(runs, len(table)) + "\n")
    chosen = recommend(runs, ref, judged, args.threshold)
    which = "all" if args.include_decayed else "non-decayed"
    if chosen is None:
        print(f"Recommended default: none of the rtols keeps the amplitude error below "
              f"{args.threshold:g} on all {which} reference points.")
    else:
        print(f"Recommended default: rtol = {chosen:g}, atol = {atol_for(chosen, args):g} "
              f"(largest rtol with max relative amplitude error < {args.threshold:g} on all "
              f"{which} reference points, and for every tighter rtol).")

    if args.plot:
        plot(runs, ref, judged, args.plot)
        print(f"Plot written to {args.plot}")
    if args.json:
        write_json(args.json, {
            "points": [{"length": l, "frequency_ratio": r, "decayed": bool(d),
                        "ref_amplitude": a, "ref_peak": pk, "ref_q_end": qe}
                       for (l, r), d, a, pk, qe in zip(point_labels(scene), decayed,
                                                        ref.amplitude, ref.peak, ref.q_end)],
            "reference": {"rtol": args.ref_rtol, "atol": args.ref_atol,
                          "mean_steps": float(ref.steps.mean()), "seconds": ref_s},
            "compile_s": compile_s, "threshold": args.threshold,
            "recommended_rtol": chosen,
            "recommended_atol": None if chosen is None else atol_for(chosen, args),
            "runs": [{"method": m.method, "rtol": m.rtol, "atol": m.atol, "wall_s": m.wall_s,
                      "mean_steps": float(m.steps.mean()),
                      "max_rel_amplitude_error": float(np.max(
                          amplitude_errors(m.amplitude, ref)[~decayed], initial=0)),
                      "max_rel_amplitude_error_all": float(np.max(
                          amplitude_errors(m.amplitude, ref))),
                      "max_rel_final_state_error": float(np.max(
                          final_state_errors(m.q_end, ref)))} for m in runs]})


if __name__ == "__main__":
    main()
