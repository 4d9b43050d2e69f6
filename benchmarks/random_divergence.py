"""Whether one realisation of a random scene converges as a trajectory, or only in its
statistics: two solutions of the same record that differ only in their steps, and how far they
part over time.

What it measures
----------------
One span of launch-random-gevs (--length, m; --db, dB on the GEVS spectrum), one record, its
one-mode equation written out here from the engine's parameter row (q'' + c q' + k0 q + g0 q^3
+ h q^5 = -Gamma a_b(t), the record's cubic Hermite by sweep.models.random.hermite), solved by
SciPy's DOP853 four times with rtol 1e-9 .. 1e-12 and max_step 1/fs .. 1/(8 fs) (different
steps, each far below the response's own error). Prints, per second of the record, the largest
|q| difference from the tightest solution, and each solution's RMS over the last 2/3 of the
record: a difference that stays at the integration error means the trajectory converges; one
that grows to the response's size means the response is chaotic (sensitive to its initial
state), so only statistics over realisations converge.

Command
-------
    PYTHONPATH=. python benchmarks/random_divergence.py [--length 0.3] [--db 0.0]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import parameter_table  # noqa: E402

import sweep  # noqa: E402
from sweep.kernels import oscillator as osc  # noqa: E402
from sweep.models import random as rnd  # noqa: E402
from sweep.models.random_outputs import RandomInputs  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--length", type=float, default=0.3)
    parser.add_argument("--db", type=float, default=0.0)
    args = parser.parse_args()
    scene = sweep.load_scene("launch-random-gevs", overrides={
        "axes.length": [args.length], "axes.base_asd_scale": [args.db],
        "base.realisations": 1})
    row = parameter_table(scene)[0]
    col = {name: row[i] for i, name in enumerate(osc.PARAM_NAMES)}
    random = RandomInputs.of(scene.values)
    record, fs = random.records()[0], random.sample_rate
    level = col["base_accel"]                  # the row's level factor (of the amplitude)

    def f(t: float, y: np.ndarray) -> list[float]:
        q, v = y
        a_b = level * float(rnd.hermite(record, fs, t))
        return [v, -(col["damping"] * v + col["k0"] * q + col["g0"] * q ** 3
                     + col["h"] * q ** 5 + col["participation"] * a_b) / col["mass"]]

    t = np.linspace(0.0, random.t_end, 8001)
    runs = ((1e-9, 1.0), (1e-10, 0.5), (1e-11, 0.25), (1e-12, 0.125))
    q = {}
    for rtol, per_sample in runs:
        sol = solve_ivp(f, (0.0, random.t_end), [0.0, 0.0], method="DOP853", rtol=rtol,
                        atol=1e-16, dense_output=True, max_step=per_sample / fs)
        q[rtol] = sol.sol(t)[0]
    tail = t > random.t_end / 3.0
    print(f"span {args.length:g} m at {args.db:g} dB, f1 = {math.sqrt(col['k0']) / (2 * math.pi):.1f}"
          f" Hz, record {random.t_end:g} s at {fs:g} Hz")
    ref = q[runs[-1][0]]
    for rtol, per_sample in runs:
        rms = math.sqrt(float(np.mean(q[rtol][tail] ** 2)))
        d = np.abs(q[rtol] - ref)
        seconds = [f"{d[(t >= k) & (t < k + 1)].max():.1e}" for k in range(int(random.t_end))]
        print(f"rtol {rtol:g}, max_step {per_sample:g}/fs: RMS {rms * 1e3:.4f} mm; max |dq| (m) "
              f"by second: {' '.join(seconds)}")


if __name__ == "__main__":
    main()
