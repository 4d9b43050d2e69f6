"""dask backend against threads: wall time of the same sweep on both, results compared.

The reference sweep's problem (paper coefficients, q0 = 4 mm, t in [0, 5] s, default
tolerances) on grids of --sizes points. `threads`: sweep.run in-process on all cores. `dask`:
sweep.run with run.backend = "dask" on a LocalCluster of --workers single-threaded worker
processes started by the run (its start-up is included, as a user pays it), default chunking.
The results must be equal bit for bit.

Command:
    PYTHONPATH=. python benchmarks/dask_overhead.py
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import sweep  # noqa: E402

SCENE = """
name = "dask-overhead"
[model]
coefficients = "paper"
[initial]
displacement = 4e-3
velocity = 0.0
[axes]
length = {{start = 0.3, stop = 1.2, num = {nl}}}
frequency_ratio = {{start = 0.5, stop = 3.0, num = {nf}}}
"""


def timed(scene: sweep.Scene) -> tuple[float, object]:
    start = time.perf_counter()
    ds = sweep.run(scene, progress=False)
    return time.perf_counter() - start, ds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1e5,1e6")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    sweep.run(sweep.load_scene_text(SCENE.format(nl=2, nf=2)), progress=False)   # compile
    print("| points | threads backend (s) | dask backend, LocalCluster of "
          f"{args.workers} (s) | dask / threads | equal |")
    print("|---|---|---|---|---|")
    for size in (int(float(s)) for s in args.sizes.split(",")):
        nl = int(round(size ** 0.5))
        text = SCENE.format(nl=nl, nf=size // nl)
        t_threads, a = timed(sweep.load_scene_text(text))
        t_dask, b = timed(sweep.load_scene_text(text, overrides={
            "run.backend": "dask", "run.workers": args.workers}))
        equal = all(np.array_equal(a[v].values, b[v].values, equal_nan=True)
                    for v in a.data_vars)
        print(f"| {nl * (size // nl):,} | {t_threads:.2f} | {t_dask:.2f} | "
              f"{t_dask / t_threads:.2f} | {equal} |", flush=True)


if __name__ == "__main__":
    main()
