"""The cost of a stepped sweep ([continuation]) against the same grid of independent points.

What it measures
----------------
The built-in scene harness-stepped-sine with one mode (model.modes = 1: the cost of the stepping,
not of the modes; Table 1 cable, 0.05 g base excitation, 2 % damping, 4 s dwells, RK45 at rtol
1e-8, the lanes driver) on a map of --lengths span lengths in
[0.3, 0.8] m x --steps base frequency ratios in [0.8, 2.0], in three forms, each on 1 and 2
threads (--threads):

- "stepped both": continuation along base_frequency_ratio, up and down (2 x lengths x steps
  dwells, in `steps` kernel calls per direction, each over the `lengths` spans of one step);
- "stepped up": one direction;
- "independent": the same grid with no [continuation] (every point from rest, in chunks).

Wall time of sweep.run (warm Numba cache: everything is run once on a small grid first), best of
--repeats; points/s counts grid points x directions (dwells). The stepped forms make one
kernel call per step: with few spans a call has fewer points than the lanes and threads can
fill, which is what the comparison shows.

Command
-------
    PYTHONPATH=. python benchmarks/stepped_sweep.py
    PYTHONPATH=. python benchmarks/stepped_sweep.py --lengths 40 --steps 100 --repeats 1

Prints a Markdown table and the command line to stdout.
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


def _scene(lengths: int, steps: int, direction: str | None) -> sweep.Scene:
    overrides = {"model.modes": 1,
                 "axes.length": f"{{start = 0.3, stop = 0.8, num = {lengths}}}",
                 "axes.base_frequency_ratio": f"{{start = 0.8, stop = 2.0, num = {steps}}}"}
    if direction is None:
        text = (Path(sweep.__file__).parent / "scenes" / "harness-stepped-sine.toml").read_text()
        head, rest = text.split("\n[continuation]\n")
        text = head + "\n[solver]\n" + rest.split("\n[solver]\n")[1]     # no [continuation]
        return sweep.load_scene_text(text, overrides=overrides)
    return sweep.load_scene("harness-stepped-sine",
                            overrides={**overrides, "continuation.direction": direction})


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--lengths", type=int, default=20)
    parser.add_argument("--steps", type=int, default=49)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    forms = (("stepped both", "both", 2), ("stepped up", "up", 1), ("independent", None, 1))
    for _, direction, _ in forms:                          # compile / load the caches
        sweep.run(_scene(2, 3, direction), progress=False)
    rows = []
    for name, direction, ways in forms:
        scene = _scene(args.lengths, args.steps, direction)
        for threads in args.threads:
            best = min(_timed(scene, threads) for _ in range(args.repeats))
            dwells = args.lengths * args.steps * ways
            rows.append([name, threads, dwells, f"{best:.2f}", f"{dwells / best:,.0f}"])
    print(markdown_table(["form", "threads", "points x directions", "wall s (best)",
                          "points/s"], rows))
    print(f"\n    PYTHONPATH=. python benchmarks/stepped_sweep.py {' '.join(sys.argv[1:])}")
    return 0


def _timed(scene: sweep.Scene, threads: int) -> float:
    began = time.perf_counter()
    sweep.run(scene, threads=threads, progress=False)
    return time.perf_counter() - began


if __name__ == "__main__":
    sys.exit(main())
