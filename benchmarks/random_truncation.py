"""What keeping N modes of a span costs a random answer (docs/model.md sec. 11, "Band
truncation"): the modes above the N kept lie inside a 20-2000 Hz spectrum for every harness
span, and their share of the response is what a truncated run leaves out.

1. Linear, exact: for the built-in scene launch-random-gevs's bundle (pinned, 2 % damping) at
   qualification, the RMS midspan deflection and the absolute midspan acceleration (grms) of
   the span made linear with N = 1, 3, 5 modes against N = 41 (converged), from the exact
   integral of |H|^2 W (sweep/models/random.py `linear_mean_square`; pinned sines: mode n at
   n^2 f1, weight sin(n pi / 2) 4 / (n pi)).
2. Nonlinear, by Monte Carlo: the engine's mean RMS deflection and grms over 8 records of 8 s
   (the same records: common random numbers) with 1 and 3 modes at one span, with their 95 %
   intervals, and what each costs.

    PYTHONPATH=. python benchmarks/random_truncation.py [--length 0.15] [--realisations 8]

Prints Markdown tables to stdout.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

LENGTHS = (0.10, 0.15, 0.20, 0.30)
KEPT = (1, 3, 5)
CONVERGED = 41


def linear_table() -> str:
    """Part 1: the linear span's RMS and grms with N modes against the converged sum."""
    import sweep
    from sweep.models import modal
    from sweep.models import transverse as tm
    from sweep.models.random import linear_mean_square
    from sweep.schema import STANDARD_GRAVITY as G
    scene = sweep.load_scene("launch-random-gevs", {"axes.length": list(LENGTHS),
                                                    "axes.base_asd_scale": [0.0]})
    inputs = tm.resolve(scene)
    coeffs = modal.oscillator(inputs.params)
    f1 = np.asarray(coeffs["natural_frequency"], float).ravel()
    zeta = float(np.asarray(inputs.params["damping_ratio"], float).ravel()[0])
    f, w = inputs.random.spectrum
    rows = []
    for length, fn in zip(LENGTHS, f1):
        def answer(n_modes: int, what: str) -> float:
            n = np.arange(1, n_modes + 1)
            omega = 2 * math.pi * fn * n ** 2.0
            weight = np.sin(n * math.pi / 2) * 4 / (n * math.pi)
            return math.sqrt(float(linear_mean_square(f, w, omega[None, :],
                                                      (2 * zeta * omega)[None, :],
                                                      weight[None, :], what=what)[0]))
        q_full = answer(CONVERGED, "deflection")
        a_full = answer(CONVERGED, "absolute_acceleration") / G
        cells = [f"{length * 1e3:.0f}", f"{fn:.1f}", f"{q_full * 1e3:.3f}", f"{a_full:.1f}"]
        for n in KEPT:
            cells.append(f"{answer(n, 'deflection') / q_full:.4f}")
        for n in KEPT:
            cells.append(f"{answer(n, 'absolute_acceleration') / G / a_full:.3f}")
        rows.append("| " + " | ".join(cells) + " |")
    head = ("| span (mm) | f1 (Hz) | RMS deflection, converged (mm) | grms, converged | "
            + " | ".join(f"RMS, {n} mode{'s' if n > 1 else ''} / converged" for n in KEPT)
            + " | " + " | ".join(f"grms, {n} mode{'s' if n > 1 else ''} / converged"
                                 for n in KEPT) + " |")
    return "\n".join([head, "|" + "---|" * (4 + 2 * len(KEPT))] + rows)


def nonlinear_table(length: float, realisations: int) -> str:
    """Part 2: the engine's means over the same records with 1 and 3 modes."""
    import sweep
    rows = []
    for modes in (1, 3):
        scene = sweep.load_scene("launch-random-gevs", {
            "axes.length": [length], "axes.base_asd_scale": [0.0], "model.modes": modes,
            "base.realisations": realisations, "outputs.response_asd": False})
        sweep.run(sweep.load_scene("launch-random-gevs", {
            "axes.length": [length], "axes.base_asd_scale": [0.0], "model.modes": modes,
            "base.realisations": 1, "outputs.response_asd": False}),
            progress=False)                                        # compile
        started = time.perf_counter()
        ds = sweep.run(scene, progress=False)
        wall = time.perf_counter() - started
        def one(name: str) -> float:
            return float(np.asarray(ds[name].values).item())
        rows.append(f"| {modes} | {one('rms_deflection_mean') * 1e3:.3f} +- "
                    f"{one('rms_deflection_ci') * 1e3:.3f} | "
                    f"{one('rms_acceleration_g_mean'):.1f} +- "
                    f"{one('rms_acceleration_g_ci'):.1f} | "
                    f"{one('linear_rms') * 1e3:.3f} | {wall:.1f} |")
    return "\n".join(["| modes | mean RMS deflection (mm) | mean grms at midspan | linear RMS "
                      "(mm) | wall time, all cores (s) |", "|---|---|---|---|---|"] + rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=0.15, help="m, part 2's span")
    parser.add_argument("--realisations", type=int, default=8)
    args = parser.parse_args()
    print("Linear, exact (GEVS qualification, 14.14 grms in):\n")
    print(linear_table())
    print(f"\nNonlinear, {args.realisations} records of 8 s at {args.length * 1e3:.0f} mm, "
          "qualification:\n")
    print(nonlinear_table(args.length, args.realisations))
    print(f"\n    PYTHONPATH=. python benchmarks/random_truncation.py {' '.join(sys.argv[1:])}")


if __name__ == "__main__":
    main()
