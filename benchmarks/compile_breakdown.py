"""Where a scene's first-run compile time goes, function by function.

What it measures
----------------
In this process (run it with an empty NUMBA_CACHE_DIR: a cold start), `sweep compile`'s
warm-up of the scene (sweep/warmup.py: the scene on a few of its points, one thread) under
Numba's compile-event recorder: the wall time, and each compiled function's inclusive compile
time (its own plus its callees' compiled for it) and its own (without them), the longest
first, with how many specialisations of it were compiled.

Command
-------
    NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=. python benchmarks/compile_breakdown.py harness-base-sine
    NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=. python benchmarks/compile_breakdown.py paper-fig5 --top 10

Prints a Markdown table and the command line to stdout.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_common import markdown_table  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", help="a built-in scene name or a .toml file")
    parser.add_argument("--top", type=int, default=25, help="functions listed (default 25)")
    args = parser.parse_args()
    from numba.core import event

    import sweep
    from sweep.warmup import warm_up
    scene = sweep.load_scene(args.scene)
    with event.install_recorder("numba:compile") as recorder:
        began = time.perf_counter()
        warm_up(scene, threads=1)
        total = time.perf_counter() - began
    inclusive: dict[str, float] = collections.defaultdict(float)
    own: dict[str, float] = collections.defaultdict(float)
    count: collections.Counter = collections.Counter()
    stack: list[list] = []      # [name, start, callees' seconds]
    for stamp, ev in recorder.buffer:
        func = ev.data["dispatcher"].py_func
        name = f"{func.__module__.rsplit('.', 1)[-1]}.{func.__qualname__}"
        if ev.is_start:
            stack.append([name, stamp, 0.0])
        else:
            started_name, started, callees = stack.pop()
            spent = stamp - started
            inclusive[started_name] += spent
            own[started_name] += spent - callees
            count[started_name] += 1
            if stack:
                stack[-1][2] += spent
    rows = [[name, f"{seconds:.1f}", f"{own[name]:.1f}", count[name]]
            for name, seconds in sorted(inclusive.items(), key=lambda kv: -kv[1])[:args.top]]
    print(f"{args.scene}: the warm-up took {total:.1f} s on a cold cache")
    print()
    print(markdown_table(["function (module.name)", "inclusive compile (s)",
                          "own compile (s)", "specialisations"], rows))
    print()
    print("command: NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=. python "
          f"benchmarks/compile_breakdown.py {args.scene} --top {args.top}")


if __name__ == "__main__":
    main()
