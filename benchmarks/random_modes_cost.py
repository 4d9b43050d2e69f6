"""What a random run of several modes costs, pinned and clamped ends (the solve's own time).

What it measures
----------------
The built-in scene launch-random-gevs with model.modes = --modes on --lengths spans, --records
records of --duration s, one thread, spectra off, through the public API (`sweep.run`): the
best `run_seconds` (the kernels' time, after the records are made) of --repeats runs after a
first one (compile or cache), for pinned ends and for clamped ends (`clamps.rotation =
"clamped"`, `cable.diameter = "10 mm"`). Run it in two `git worktree`s, each with its own
fresh NUMBA_CACHE_DIR, alternately, to compare two versions of the kernels.

Command
-------
    NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=. python benchmarks/random_modes_cost.py
        [--modes 3] [--lengths 0.1 0.15 0.2] [--records 4] [--duration 2] [--repeats 3]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels

import sweep  # noqa: E402

ENDS = {"pinned": {}, "clamped": {"clamps.rotation": "clamped", "cable.diameter": "10 mm"}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--modes", type=int, default=3)
    parser.add_argument("--lengths", type=float, nargs="+", default=[0.1, 0.15, 0.2])
    parser.add_argument("--records", type=int, default=4)
    parser.add_argument("--duration", type=float, default=2.0, help="s, each record")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    base = {"run.threads": 1, "outputs.response_asd": False, "model.modes": args.modes,
            "axes.length": args.lengths, "base.realisations": args.records,
            "base.duration": args.duration}
    for ends, more in ENDS.items():
        scene = sweep.load_scene("launch-random-gevs", {**base, **more})
        sweep.run(scene, progress=False)
        seconds = [sweep.run(scene, progress=False).attrs["run_seconds"]
                   for _ in range(args.repeats)]
        print(f"{args.modes} {ends} modes, {len(args.lengths)} spans x {args.records} records x "
              f"{args.duration:g} s: best run_seconds {min(seconds):.3f} s of "
              f"{[round(x, 3) for x in seconds]}", flush=True)


if __name__ == "__main__":
    main()
