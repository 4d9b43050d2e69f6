"""What a span's end condition costs to compile: pinned, then clamped spans of three modes, on
each multi-mode driver, in one fresh process on an empty Numba cache.

What it measures
----------------
The wall time of four `sweep.run` calls of harness-base-sine (three modes, short runs), one
after the other in one process: pinned spans on the lanes, the same spans clamped on the
lanes, pinned spans on the scalar driver, then harness-clamps' elastic spans on the scalar
driver. A run's time is almost all compiling. Where a basis' force form (its polynomial, or
the quadrature) is part of the kernels' types (before the thirty-seventh session) a clamped or
elastic span after a pinned one compiles its driver again; where both forms are one type
(since), it compiles nothing. Run it on two checkouts, one after the other, a few times: one
cold start cannot be repeated.

Command
-------
    python benchmarks/basis_compile.py ROOT      # ROOT: a checkout (default: this one)

Prints one line a run.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).resolve().parents[1])
os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="basis-compile-")
sys.path.insert(0, ROOT)

import sweep  # noqa: E402

SHORT = {"model.modes": 3, "solver.t_end": 1.0}
RUNS = [
    ("pinned, lanes", "harness-base-sine",
     {**SHORT, "axes.length": [0.3, 0.4], "solver.driver": "lanes"}),
    ("clamped, lanes", "harness-base-sine",
     {**SHORT, "axes.length": [0.3, 0.4], "solver.driver": "lanes",
      "clamps.rotation": "clamped"}),
    ("pinned, scalar", "harness-base-sine",
     {**SHORT, "axes.length": [0.3], "solver.driver": "scalar"}),
    ("elastic (harness-clamps), scalar", "harness-clamps",
     {"solver.t_end": 1.0, "axes.length": [0.3], "axes.clamp_rotational_stiffness": [1.0]}),
]

print(f"{ROOT} (empty cache):")
for label, name, overrides in RUNS:
    began = time.perf_counter()
    sweep.run(sweep.load_scene(name, overrides), threads=1, progress=False)
    print(f"  {label}: {time.perf_counter() - began:.1f} s", flush=True)
