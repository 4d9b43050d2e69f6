"""The first run of every built-in scene, as a new user meets it: an empty Numba cache.

What it measures
----------------
For each built-in scene (or those named), `sweep run SCENE -o OUT.nc` in a fresh process with
NUMBA_CACHE_DIR set to a new empty folder, so nothing is loaded from a cache: the wall time of
the whole process, the compile time the command line reports ("compiled in X s": from the first
kernel call until every kernel the scene needs is compiled) and, with --warm, the same command
run again on the cache the first run left (warm): the difference cold - warm is what compiling
costs that scene. One run each: a cold start cannot be repeated on the same cache.

Command
-------
    PYTHONPATH=. python benchmarks/first_run.py                 # every built-in scene
    PYTHONPATH=. python benchmarks/first_run.py --warm paper-fig5 harness-base-sine

Prints a Markdown table and the command line to stdout.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_common import markdown_table  # noqa: E402

COMPILED = re.compile(r"compiled in ([0-9.]+) s")


def run_once(scene: str, cache: str, out: Path) -> tuple[float, float | None]:
    """(wall time in s, reported compile time in s or None) of one `sweep run`."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    began = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "sweep.cli", "run", scene, "-o", str(out),
                           "--overwrite"], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - began
    if done.returncode != 0:
        raise SystemExit(f"{scene}: exit {done.returncode}: {done.stderr.strip()[-400:]}")
    found = COMPILED.search(done.stderr)
    return wall, float(found.group(1)) if found else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scenes", nargs="*", help="built-in scene names (default: all)")
    parser.add_argument("--warm", action="store_true",
                        help="run each scene again on its warm cache (doubles the time)")
    args = parser.parse_args()
    import sweep
    scenes = args.scenes or list(sweep.builtin_scenes())
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            cache = tempfile.mkdtemp(dir=tmp)
            out = Path(tmp) / f"{scene}.nc"
            cold, compiled = run_once(scene, cache, out)
            row = [scene, f"{cold:.1f}", "-" if compiled is None else f"{compiled:.1f}"]
            if args.warm:
                warm, _ = run_once(scene, cache, out)
                row += [f"{warm:.1f}", f"{cold - warm:.1f}"]
            rows.append(row)
            print(f"{scene}: " + ", ".join(row[1:]), file=sys.stderr)
    headers = ["scene", "cold run (s)", "reported compile (s)"]
    if args.warm:
        headers += ["warm run (s)", "cold - warm (s)"]
    print(markdown_table(headers, rows))
    print()
    print("command: PYTHONPATH=. python benchmarks/first_run.py "
          + " ".join((["--warm"] if args.warm else []) + args.scenes))


if __name__ == "__main__":
    main()
