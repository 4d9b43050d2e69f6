"""Two threads against one on a built-in scene: the kernels' time of the whole scene.

What it measures
----------------
`sweep.run` of the built-in scene NAME (with --set overrides, TOML values as `sweep run
--set`) at run.threads = 1 and 2, each after one run not counted (compile or load the cache),
best of --repeats: the dataset's run_seconds (the kernels' time, without loading the scene
and assembling the dataset) and the ratio. ROOT is the checkout to import (default: this
one), so two checkouts can be compared by running the script once for each, alternately.

Command
-------
    python benchmarks/thread_scaling.py NAME [--root ROOT] [--repeats 3] [--set KEY=VALUE ...]

e.g. `python benchmarks/thread_scaling.py launch-random-gevs --set outputs.response_asd=false`.
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--root", default=str(Path(__file__).resolve().parents[1]))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    sys.path.insert(0, args.root)
    import sweep
    overrides = {}
    for item in args.set:
        key, _, value = item.partition("=")
        overrides[key] = tomllib.loads(f"v = {value}")["v"]
    seconds = {}
    for threads in (1, 2):
        scene = sweep.load_scene(args.scene, {**overrides, "run.threads": threads})
        sweep.run(scene, progress=False)
        seconds[threads] = min(float(sweep.run(scene, progress=False).attrs["run_seconds"])
                               for _ in range(args.repeats))
    print(f"{args.scene} ({args.root}): 1 thread {seconds[1]:.3f} s, 2 threads "
          f"{seconds[2]:.3f} s, {seconds[1] / seconds[2]:.2f}x")


if __name__ == "__main__":
    main()
