"""Early stop (solver.stop_when_steady) on the built-in damped harness maps: speed-up and the
amplitude difference against the full run, over every point.

For each scene, three runs of the same grid on 2 threads (best of --repeats wall times for
the first two):
  full   the scene as it is (every point to t_end, the tail window its last metrics.tail);
  early  the same with solver.stop_when_steady = true;
  final  the full run again with its tail window cut to its last 2 s (metrics.tail = 2/t_end):
         the full run's steady level, what a steady amplitude converges to.
Reported: speed-up full/early (wall time and right-hand-side evaluations), how many points
stopped, and for the points steady in both runs the worst and median relative difference of
the early amplitude from the full run's tail maximum and from its final level (and, with several
modes, of each mode's tail amplitude from its final level, relative to the point's largest
mode); points that did not stop must equal the full run bit for bit.

Command (2-core machine, otherwise idle; scene labels as arguments run only those, e.g.
"harness-base-sine" for the five-mode map alone):
    python benchmarks/early_stop.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import sweep  # noqa: E402

# (scene, overrides, repeats): the five-mode map as shipped takes ~45 s a run, so it runs once
SCENES = [("harness-parametric", {}, 3), ("harness-base-sine", {"model.modes": 1}, 3),
          ("harness-base-sine", {}, 1)]


def best(scene, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        ds = sweep.run(scene, threads=2, progress=False)
        times.append(time.perf_counter() - t)
    return min(times), ds


def modal_worst(early, final, steady) -> str:
    """Worst difference of the early run's modal amplitudes from the final level's, over the
    steady points, relative to each point's largest mode ("" for one mode)."""
    if "modal_amplitude" not in early:
        return ""
    m_e = early.modal_amplitude.values[steady]
    m_n = final.modal_amplitude.values[steady]
    return f"{(np.abs(m_e - m_n) / m_n.max(axis=-1, keepdims=True)).max():.1e}"


def main() -> None:
    print("| scene | points | full (s) | early (s) | speed-up | RHS ratio | stopped | "
          "worst / median vs full tail max | worst / median vs full final level | "
          "stopped points: worst vs final level | "
          "stopped points: modal amplitudes, worst vs final level | not stopped equal |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    wanted = sys.argv[1:]          # scene labels to run (default: all)
    for name, extra, repeats in SCENES:
        label = name + (" (" + ", ".join(f"{k}={v}" for k, v in extra.items()) + ")"
                        if extra else "")
        if wanted and label not in wanted:
            continue
        full_scene = sweep.load_scene(name, overrides=extra)
        sweep.run(full_scene, threads=2, progress=False)              # compile / load
        t_full, full = best(full_scene, repeats)
        early_scene = sweep.load_scene(name, overrides={**extra, "solver.stop_when_steady": True})
        sweep.run(early_scene, threads=2, progress=False)
        t_early, early = best(early_scene, repeats)
        t_end = full_scene.get("solver.t_end")
        final = sweep.run(sweep.load_scene(name, overrides={**extra, "metrics.tail": 2.0 / t_end}),
                          threads=2, progress=False)
        a_f, a_e, a_n = (full.amplitude.values, early.amplitude.values, final.amplitude.values)
        steady = (full.state.values == 2) & (early.state.values == 2)
        stopped = np.isfinite(early.stop_time.values)
        r_full = np.abs(a_e - a_f)[steady] / a_f[steady]
        r_final = np.abs(a_e - a_n)[steady] / a_n[steady]
        same = bool(np.array_equal(a_e[~stopped], a_f[~stopped]))
        r_stopped = (np.abs(a_e - a_n) / a_n)[steady & stopped]
        print(f"| {label} | {a_f.size} | {t_full:.3f} | {t_early:.3f} | {t_full / t_early:.2f}x | "
              f"{float(full.n_rhs.sum() / early.n_rhs.sum()):.2f} | {int(stopped.sum())} | "
              f"{r_full.max():.1e} / {np.median(r_full):.1e} | {r_final.max():.1e} / "
              f"{np.median(r_final):.1e} | {r_stopped.max():.1e} | "
              f"{modal_worst(early, final, steady & stopped)} | {same} |")


if __name__ == "__main__":
    main()
