"""Few points a basis: the multi-mode lanes against the scalar driver, and the default it chose.

What it measures
----------------
The lock-step lanes (kernels/modal_lanes.py) run every point of one kernel call side by side,
and a call takes the points of one set of mode shapes. Where few points share a basis (a single
span; elastic clamps, whose K = k_t l / EI and so whose modes differ at every length and
stiffness), most lanes idle while the vector loops and the per-step bookkeeping cost nearly
what they cost for sixteen. This script times, on one thread (each configuration once to
compile or load the cache, then best of --repeats, `sweep.run` wall time):

- harness-clamps' three modes at t_end = 1 s on two spans (0.2, 0.3 m) and one clamp
  stiffness (1 N m/rad), so two bases, with M = 1, 4, 8, 16 points a basis (an axis of M
  base frequency ratios 0.8-1.2): solver.driver = "lanes" against "scalar";
- the built-in harness-clamps as shipped (35 points, a basis each) on the driver its rules
  choose (sweep.models.rules.LANES_LEAST_POINTS) and on the lanes.

Command
-------
    PYTHONPATH=. python benchmarks/lanes_occupancy.py [--repeats 2] [--no-scene]

Prints a Markdown table and the command line.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import markdown_table  # noqa: E402

import sweep  # noqa: E402


def best_wall(name: str, overrides: dict, repeats: int) -> tuple[float, str]:
    """(best wall time of sweep.run (s), the driver the scene ran on)."""
    scene = sweep.load_scene(name, overrides)
    sweep.run(scene, progress=False)                     # compile, or load the cache
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        sweep.run(scene, progress=False)
        best = min(best, time.perf_counter() - start)
    return best, scene.get("solver.driver")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--no-scene", action="store_true",
                        help="skip harness-clamps as shipped (about 20 s)")
    args = parser.parse_args()
    rows = []
    for m in (1, 4, 8, 16):
        base = {"run.threads": 1, "solver.t_end": 1.0, "axes.length": [0.2, 0.3],
                "axes.clamp_rotational_stiffness": [1.0]}
        if m > 1:
            base["axes.base_frequency_ratio"] = list(np.linspace(0.8, 1.2, m))
        lanes, _ = best_wall("harness-clamps", {**base, "solver.driver": "lanes"}, args.repeats)
        scalar, _ = best_wall("harness-clamps", {**base, "solver.driver": "scalar"},
                              args.repeats)
        _, default = best_wall("harness-clamps", base, 0)
        rows.append([f"{m}", f"{2 * m}", f"{lanes:.3f}", f"{scalar:.3f}",
                     f"{lanes / scalar:.2f}", default])
    print(markdown_table(["points a basis", "points", "lanes (s)", "scalar (s)",
                          "lanes / scalar", "default driver"], rows))
    if not args.no_scene:
        shipped, default = best_wall("harness-clamps", {"run.threads": 1}, args.repeats)
        lanes, _ = best_wall("harness-clamps", {"run.threads": 1, "solver.driver": "lanes"},
                             args.repeats)
        print(f"\nharness-clamps as shipped, one thread: {shipped:.2f} s on its default "
              f"driver ({default}), {lanes:.2f} s on the lanes ({lanes / shipped:.2f}x)")
    print("\n    PYTHONPATH=. python benchmarks/lanes_occupancy.py " + " ".join(sys.argv[1:]))


if __name__ == "__main__":
    main()
