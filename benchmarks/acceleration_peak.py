"""The tail's peak absolute acceleration |q'' + a_b| against SciPy, per method, driver and rtol.

One mode (the Table 1 cable, 0.3 m span, f1 = 42.4 Hz, 3 % damping, stretching alpha = 3/8),
base excitation from rest, four cases: below resonance (10 m/s^2, f/f1 = 0.9, 5 s, the last
half as the tail window), the upper branch above it (10 m/s^2, 1.2), a start-up transient
still decaying through the window (1 m/s^2, 0.7, 0.4 s: the window's first instant is the
peak), and resonance (10 m/s^2, 1.0, 0.6 s, the last 30 %). The reference is SciPy's DOP853 at
rtol 1e-12 (tests/test_base_excitation.py's `dense_reference`: q'' from the equation on its
dense output, refined by a bounded search). Prints the relative errors of `amplitude` and
`absolute_acceleration` for every case, method (rk45, dop853), rtol (1e-6 to 1e-10) and driver.

Command (from the repository root; about two minutes with a warm cache):

    PYTHONPATH=. python benchmarks/acceleration_peak.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import numpy as np  # noqa: E402

import sweep  # noqa: E402
from test_base_excitation import GAMMA, dense_reference, modal_rhs, scene, span  # noqa: E402

LENGTH = 0.3        # m
ZETA = 0.03
CASES = {"below resonance": (10.0, 0.9, 5.0, 0.5), "upper branch": (10.0, 1.2, 5.0, 0.5),
         "decaying through the tail": (1.0, 0.7, 0.4, 0.5), "at resonance": (10.0, 1.0, 0.6, 0.3)}
SOLVERS = [("rk45", 1e-6), ("rk45", 1e-8), ("dop853", 1e-8), ("dop853", 1e-10)]


def main() -> None:
    w1 = span(LENGTH, 0.375)["w1"]
    refs = {}
    for name, (accel, ratio, t_end, tail) in CASES.items():
        wb = ratio * w1
        f = modal_rhs(LENGTH, 0.375, ZETA, accel, wb)
        refs[name] = dense_reference(f, lambda t, a=accel, w=wb: a * np.sin(w * t), t_end, tail,
                                     (0.0, 0.0), GAMMA * accel / w1 ** 2,
                                     3 * max(ratio, 1.0) * w1 / (2 * math.pi))
    print("| method | rtol | driver | case | amplitude error | acceleration error |")
    print("|---|---|---|---|---|---|")
    for method, rtol in SOLVERS:
        for driver in ("lanes", "scalar"):
            for name, (accel, ratio, t_end, tail) in CASES.items():
                ds = sweep.run(scene({"cable.length": LENGTH, "cable.damping_ratio": ZETA,
                                      "load.amplitude": 0.0, "base.acceleration": accel,
                                      "base.frequency_ratio": ratio, "solver.t_end": t_end,
                                      "metrics.tail": tail, "solver.method": method,
                                      "solver.rtol": rtol, "solver.driver": driver},
                                     {"base_acceleration": [accel]}), progress=False)
                amplitude, absolute = refs[name]
                print(f"| {method} | {rtol:.0e} | {driver} | {name} | "
                      f"{float(ds['amplitude'].values[0]) / amplitude - 1:+.1e} | "
                      f"{float(ds['absolute_acceleration'].values[0]) / absolute - 1:+.1e} |",
                      flush=True)


if __name__ == "__main__":
    main()
