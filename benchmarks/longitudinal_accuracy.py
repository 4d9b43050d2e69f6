"""Longitudinal accuracy: max nodal error of the central difference against d'Alembert.

Table 1 cable, l = 1 m, P0 = 4 N, --intervals intervals, over --transits transits; the field
is compared with the exact solution (fronts from the loaded end reflected at both ends) at
every --every-th time level, for each Courant number in --courant. Errors are relative to the
peak end displacement 2 P0 l / EA.

Command:
    PYTHONPATH=. python benchmarks/longitudinal_accuracy.py
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

E, RHO, A, P0, LENGTH = 1.1e11, 8900.0, 6e-6, 4.0, 1.0
WAVE = math.sqrt(E / RHO)
EA = E * A


def exact_u(x: np.ndarray, t: float) -> np.ndarray:
    """d'Alembert's solution by images (docs/model.md sec. 4)."""
    s = LENGTH - x
    e0 = P0 / EA
    u = np.zeros_like(x)
    for n in range(int(WAVE * t / (2 * LENGTH)) + 2):
        u += e0 * (-1) ** n * (-np.maximum(WAVE * t - 2 * n * LENGTH - s, 0.0)
                               + np.maximum(WAVE * t - 2 * (n + 1) * LENGTH + s, 0.0))
    return u


def max_error(courant: float, intervals: int, transits: float, every: int) -> tuple[float, int]:
    """(max nodal error / peak, levels compared) for one Courant number."""
    from sweep.kernels import longitudinal as lk
    dt = courant * (LENGTH / intervals) / WAVE
    n_levels = int(math.ceil(transits * LENGTH / WAVE / dt - 1e-9))
    levels = np.arange(0, n_levels + 1, every)
    params = np.array([[LENGTH, WAVE, EA, P0, transits * LENGTH / WAVE, LENGTH]])
    snaps = [np.empty((1, levels.size, intervals + 1)) for _ in range(3)]
    lk.solve_batch(params, np.array([intervals, courant, 0.0, 1e12]), levels * dt,
                   np.empty(1, np.int8), np.empty((1, lk.N_REALS)), np.empty(1, np.int64),
                   np.empty((1, 0)), np.empty((1, 0)), *snaps)
    x = np.linspace(0.0, LENGTH, intervals + 1)
    worst = max(np.max(np.abs(snaps[0][0, i] - exact_u(x, n * dt)))
                for i, n in enumerate(levels))
    return worst / (2 * P0 * LENGTH / EA), levels.size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--intervals", type=int, default=1000)
    parser.add_argument("--transits", type=float, default=8.0)
    parser.add_argument("--courant", default="1.0,0.9")
    parser.add_argument("--every", type=int, default=10)
    args = parser.parse_args()
    print(f"# d'Alembert check: {args.intervals} intervals, {args.transits:g} transits\n")
    print("| Courant | levels compared | max nodal error / (2 P0 l / EA) |")
    print("|---|---|---|")
    for courant in (float(c) for c in args.courant.split(",")):
        err, n = max_error(courant, args.intervals, args.transits, args.every)
        print(f"| {courant:g} | {n} | {err:.2e} |")


if __name__ == "__main__":
    main()
