"""What the clamps cost: a span's run with clamped ends against the same span pinned, same
number of modes, and what the span's loads (sweep/models/loads.py) add.

What it measures
----------------
The Table 1 cable between immovable clamps (the uniform stretching tension), 2 % damping,
1 g base excitation at the span's own f1, from rest, t in [0, 1] s, six lengths 0.30-0.55 m,
one thread, each configuration run once to compile and then --repeats times (best kept):

- per configuration (pinned / clamped, N modes): wall time, right-hand-side evaluations (the
  kernels' own counts, `n_rhs`) and wall time per evaluation, with the basis' quadrature nodes
  (pinned sines: the trapezoidal rule on 3 N intervals; clamped: Gauss-Legendre,
  sweep.models.basis.quadrature_nodes);
- the loads' observation: the clamped run with `outputs.amplitude = false` (the kernels then
  observe no loads: kernels/layout.py LOADS) against the run as shipped.

Command
-------
    PYTHONPATH=. python benchmarks/clamps_cost.py [--modes 3 5] [--repeats 3]

Prints a Markdown table to stdout.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

from bench_common import markdown_table  # noqa: E402

import sweep  # noqa: E402
from sweep.models.basis import clamped, pinned_sines  # noqa: E402

SCENE = """
name = "clamps-cost"
[model]
modes = {n}
[clamps]
rotation = "{rotation}"
[cable]
linear_mass = "53.4 g/m"
bending_rigidity = "0.31515 N m^2"
axial_rigidity = "660 kN"
diameter = "2.76395 mm"
damping_ratio = 0.02
[load]
amplitude = 0.0
[base]
acceleration_g = 1.0
frequency_ratio = 1.0
[solver]
t_end = 1.0
[run]
threads = 1
[axes]
length = [0.30, 0.35, 0.40, 0.45, 0.50, 0.55]
"""


def best_run(text: str, repeats: int, **overrides: object) -> tuple[float, float]:
    """(best wall time (s), total right-hand-side evaluations) of the scene `text`."""
    scene = sweep.load_scene_text(text, overrides=overrides)
    ds = sweep.run(scene, progress=False)                    # compile, or load the cache
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        ds = sweep.run(scene, progress=False)
        best = min(best, time.perf_counter() - start)
    return best, float(ds["n_rhs"].sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--modes", type=int, nargs="+", default=[3, 5])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = []
    for n in args.modes:
        cost = {}
        for rotation, basis in (("pinned", pinned_sines(n)), ("clamped", clamped(n))):
            wall, evals = best_run(SCENE.format(n=n, rotation=rotation), args.repeats)
            cost[rotation] = wall / evals
            rows.append([f"{n}", rotation, f"{basis.tables.shape[2]}", f"{wall:.2f}",
                         f"{evals:.0f}", f"{wall / evals * 1e9:.0f}"])
        rows[-1].append(f"{cost['clamped'] / cost['pinned']:.2f}")
        rows[-2].append("")
        wall_off, _ = best_run(SCENE.format(n=n, rotation="clamped"), args.repeats,
                               **{"outputs.amplitude": False})
        wall_on = float(rows[-1][3])
        rows.append([f"{n}", "clamped, no loads observed", "", f"{wall_off:.2f}", "", "",
                     f"loads cost {wall_on / wall_off:.3f}x"])
    print(markdown_table(["modes", "ends", "quadrature nodes", "wall (s)", "RHS evaluations",
                          "ns per evaluation", "clamped / pinned per evaluation"], rows))
    print("\n    PYTHONPATH=. python benchmarks/clamps_cost.py " + " ".join(sys.argv[1:]))


if __name__ == "__main__":
    main()
