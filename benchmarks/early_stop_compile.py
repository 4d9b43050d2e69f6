"""What the early stop costs to compile: a scene's first run, then the same scene with
solver.stop_when_steady, in one fresh process on an empty Numba cache.

What it measures
----------------
The wall time of `sweep.run(paper-fig5)` on an empty cache (compiling, then running), and then
of the same scene with the early stop on. Where the early stop is a compile switch of the
drivers (before the thirty-fifth session) the second run compiles the driver again; where the
drivers read it from the settings (since), it compiles nothing. Run it on two checkouts, one
after the other, a few times: one cold start cannot be repeated.

Command
-------
    python benchmarks/early_stop_compile.py ROOT      # ROOT: a checkout (default: this one)

Prints one line.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).resolve().parents[1])
os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="early-stop-compile-")
sys.path.insert(0, ROOT)

import sweep  # noqa: E402

t0 = time.perf_counter()
sweep.run(sweep.load_scene("paper-fig5"), progress=False)
t1 = time.perf_counter()
sweep.run(sweep.load_scene("paper-fig5", {"solver.stop_when_steady": True}), progress=False)
t2 = time.perf_counter()
print(f"{ROOT}: paper-fig5's first run {t1 - t0:.1f} s; then with the early stop {t2 - t1:.1f} s")
