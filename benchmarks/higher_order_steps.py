"""Steps and right-hand sides per point that SciPy's RK45 and DOP853 need for a final-state error.

Why: the reference sweep's throughput at equal error is set by how many attempts a point needs.
This asks SciPy (not cable-sweep) how many accepted steps and right-hand-side evaluations its
5th-order RK45 and 8th-order DOP853 take on a sample of the reference sweep's points, and the
max and median final-state error |q(5) - q_ref(5)| / max_t |q_ref| each reaches, against DOP853
at rtol 1e-13 (as `reference_sweep.py --equal-error`). atol = rtol x 1e-4.

Command (about a minute):
    PYTHONPATH=. python benchmarks/higher_order_steps.py [--sample 40] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_common import markdown_table, parameter_table, solve_scipy  # noqa: E402
from reference_sweep import T_END, build_scene, final_state_reference  # noqa: E402

LADDERS = {"RK45": [1e-6, 3e-7, 1e-7], "DOP853": [1e-6, 3e-7, 1e-7, 3e-8]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sample", type=int, default=40, help="points of the reference sweep")
    p.add_argument("--seed", type=int, default=0, help="seed of the sample")
    args = p.parse_args()
    table = parameter_table(build_scene(100, 1e-5, 1e-9))
    pick = np.sort(np.random.default_rng(args.seed).choice(len(table), args.sample,
                                                           replace=False))
    rows = table[pick]
    q_ref, q_max = final_state_reference(rows)
    out = []
    for method, rtols in LADDERS.items():
        for rtol in rtols:
            errors, steps, nfev = [], 0, 0
            for row, qr, qm in zip(rows, q_ref, q_max):
                sol = solve_scipy(row, T_END, rtol, rtol * 1e-4, method=method)
                errors.append(abs(sol.y[0, -1] - qr) / qm)
                steps += len(sol.t) - 1
                nfev += sol.nfev
            out.append([method, f"{rtol:g}", f"{max(errors):.2e}", f"{np.median(errors):.2e}",
                        f"{steps / len(rows):.0f}", f"{nfev / len(rows):.0f}"])
    print(f"{args.sample} points of the reference sweep (seed {args.seed}), SciPy solve_ivp\n")
    print(markdown_table(["method", "rtol", "max final-state error", "median", "steps/point",
                          "RHS evals/point"], out))


if __name__ == "__main__":
    main()
