"""What a record-synchronous lock-step path over realisations would buy (issues 36 and 38): the
30-line fixed-step RK4 loop that is the random scenes' peer (benchmarks/random_cost.py
`rk4_rms_over`, one record after another) against the same classical RK4 advancing 16
realisations side by side, all at the same time and step, so that the record's interpolation
weights are shared and each stage is one loop across the realisations that LLVM vectorises.

Both integrate one mode, q'' = -(c q' + k q + g q^3 + h q^5) - B a_b(t), from rest over
`--duration` s of the engine's own records (sweep.models.random.synthesise, GEVS, 20 kHz) at
h = 1 / (m fs), and return the RMS of q over the whole run (the same bits: the test below).
Neither keeps the engine's other statistics (peaks, crossings, accelerations, spectra), so the
ratio is an upper bound on what such a path gains, not a feature:

    PYTHONPATH=. python benchmarks/lockstep_rk4.py [--realisations 16] [--duration 8]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numba as nb
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from random_cost import _force, best, hermite_weights, rk4_rms_over  # noqa: E402

GEVS = [[20.0, 0.026], [50.0, 0.16], [800.0, 0.16], [2000.0, 0.026]]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def rk4_lanes(X, DX, fs, coef, t_end, m):
    """The integral of q^2 (m^2 s) over [0, t_end] (s) of each lane, lanes = columns of the
    records X, DX ([sample, lane]: a_b and its derivative), by the classical RK4 at
    h = 1 / (m fs), every lane at the same time: the cubic Hermite's weights at t + h/2 and
    t + h once a step, then each stage a loop across the lanes."""
    C, K, G3, H5, B = coef
    h = 1.0 / (m * fs)
    steps = int(round(t_end * fs * m))
    L = X.shape[1]
    n = X.shape[0]
    q = np.zeros(L)
    v = np.zeros(L)
    z = np.zeros(L)
    a0 = np.empty(L)
    ah = np.empty(L)
    a1 = np.empty(L)
    for j in range(L):
        a0[j] = X[0, j]
    for i in range(steps):
        t = i * h
        for which in range(2):
            k, k1, w0, w1, w2, w3 = hermite_weights(fs, t + 0.5 * h * (which + 1), n)
            out = ah if which == 0 else a1
            for j in range(L):
                out[j] = w0 * X[k, j] + w1 * DX[k, j] + w2 * X[k1, j] + w3 * DX[k1, j]
        for j in range(L):
            q1 = q[j]
            v1 = v[j]
            f1 = _force(C, K, G3, H5, q1, v1) - B * a0[j]
            q2, v2 = q1 + 0.5 * h * v1, v1 + 0.5 * h * f1
            f2 = _force(C, K, G3, H5, q2, v2) - B * ah[j]
            q3, v3 = q1 + 0.5 * h * v2, v1 + 0.5 * h * f2
            f3 = _force(C, K, G3, H5, q3, v3) - B * ah[j]
            q4, v4 = q1 + h * v3, v1 + h * f3
            f4 = _force(C, K, G3, H5, q4, v4) - B * a1[j]
            z[j] += h / 6.0 * (q1 * q1 + 2.0 * q2 * q2 + 2.0 * q3 * q3 + q4 * q4)
            q[j] = q1 + h / 6.0 * (v1 + 2.0 * v2 + 2.0 * v3 + v4)
            v[j] = v1 + h / 6.0 * (f1 + 2.0 * f2 + 2.0 * f3 + f4)
            a0[j] = a1[j]
    return z


def main() -> None:
    from sweep.models import random as rnd
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--realisations", type=int, default=16)
    parser.add_argument("--duration", type=float, default=8.0, help="s, each record")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    fs = 20000.0
    f, w = rnd.spectrum(GEVS)
    records = rnd.synthesise(f, w, args.duration, fs, args.realisations, 1).values
    X = np.ascontiguousarray(records[:, :, 0].T)
    DX = np.ascontiguousarray(records[:, :, 1].T)
    w1, zeta = 2 * math.pi * 300.0, 0.02                        # a 300 Hz span, 2 % damping
    coef = np.array([-2 * zeta * w1, -w1 * w1, -1e12, 0.0, 4.0 / math.pi])
    t_end = args.duration - 1.0 / fs
    seconds = args.realisations * t_end
    print(f"{args.realisations} records of {args.duration:g} s at {fs:g} Hz, one thread\n")
    print("| RK4 step | scalar loop, ms a realisation-second | 16 lanes in lock-step | ratio |")
    print("|---|---|---|---|")
    for m in (0.5, 1.0):
        lanes = rk4_lanes(X, DX, fs, coef, t_end, m)
        scalar = np.array([rk4_rms_over(records[r, :, 0].copy(), records[r, :, 1].copy(), fs,
                                        coef, t_end, 0.0, m) for r in range(args.realisations)])
        assert np.array_equal(np.sqrt(lanes / t_end), scalar), "the two RK4s differ"
        a = best(lambda: rk4_lanes(X, DX, fs, coef, t_end, m), args.repeats)
        b = best(lambda: [rk4_rms_over(records[r, :, 0].copy(), records[r, :, 1].copy(), fs,
                                       coef, t_end, 0.0, m)
                          for r in range(args.realisations)], args.repeats)
        print(f"| h = 1/({m:g} fs) | {b / seconds * 1e3:.3f} | {a / seconds * 1e3:.3f} | "
              f"{b / a:.2f} |")


if __name__ == "__main__":
    main()
