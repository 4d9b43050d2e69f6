"""The cold start of a checkout: the first kernel call of paper-fig5, and where its compile time goes.

What it measures
----------------
In this process (run it with an empty NUMBA_CACHE_DIR for a cold start), the wall time of the
first `solve_points` call on one point of `paper-fig5` (after the imports), and Numba's compile
events during it: each compiled function's inclusive compile time, the longest first.

Command
-------
    NUMBA_CACHE_DIR=$(mktemp -d) python benchmarks/cold_start.py [CHECKOUT]

CHECKOUT (default: this one) is the root of a cable-sweep checkout, so that two versions are
compared side by side, one per core (as RESULTS.md does):

    NUMBA_CACHE_DIR=$(mktemp -d) taskset -c 0 python benchmarks/cold_start.py /path/before &
    NUMBA_CACHE_DIR=$(mktemp -d) taskset -c 1 python benchmarks/cold_start.py /path/after
"""

from __future__ import annotations

import sys
import time
from pathlib import Path


def main() -> int:
    root = Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root))
    sys.path.insert(0, str(root / "benchmarks"))
    from numba.core import event

    import sweep
    from bench_common import parameter_table
    from sweep.run import settings_vector, solve_points
    scene = sweep.load_scene("paper-fig5")
    table = parameter_table(scene)
    settings = settings_vector(scene)
    with event.install_recorder("numba:compile") as recorder:
        began = time.perf_counter()
        solve_points(table[:1], settings, 0, threads=1)
        total = time.perf_counter() - began
    starts: dict = {}
    spans = []
    for stamp, ev in recorder.buffer:
        key = (ev.data["dispatcher"].py_func.__qualname__, str(ev.data["args"]))
        if ev.is_start:
            starts[key] = stamp
        else:
            spans.append((stamp - starts.pop(key), key[0]))
    print(f"{root}: first call {total:.2f} s")
    for seconds, name in sorted(spans, reverse=True)[:20]:
        print(f"{seconds:7.2f} s  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
