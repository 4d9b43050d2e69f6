"""Start-up: wall time of a CLI run of the built-in `paper-fig5`, cold and warm Numba cache.

What it measures
----------------
Wall time, seen from this process, of each command below run in a fresh subprocess with this
interpreter (sys.executable), stdout and stderr captured:

1. `python -c pass`: the bare interpreter, for reference.
2. `python -c "import sweep"`: the package import (NumPy, xarray, the scene schema).
3. `python -c "import sweep, sweep.kernels.transverse"`: the same plus numba and the kernel modules
   (the kernels are compiled or loaded from the cache at their first call, not at import).
3b. `python -m sweep.cli --help` and `python -m sweep.cli scenes`: commands that need neither
   NumPy, xarray nor Numba.
4. cold: `python -m sweep.cli run paper-fig5 -o TMP/out.nc --overwrite` with NUMBA_CACHE_DIR
   set to a fresh, empty temporary directory, so every kernel is JIT-compiled (--cold-repeats
   times, default 1, each with its own empty directory).
5. warm: the same command with the same NUMBA_CACHE_DIR as the (last) cold run, the kernels
   then load from that cache; --repeats runs (default 3).
6. kernel start, cold and warm: in a fresh process, after the imports and the scene, the wall
   time of the first kernel call (`sweep.run.solve_points` on one point of the scene): the
   compile latency itself (cold: empty cache, everything the scene needs is compiled; warm:
   loaded from the cache, including Numba's own one-time set-up of its compiler context).

Python's own bytecode caches (__pycache__/*.pyc) are left as they are: "cold" means an empty
Numba cache, the state right after `pip install`. The subprocesses get PYTHONPATH set to the
repository root (the checkout's `sweep` and `kernels`); with --installed PYTHONPATH is left
alone and the installed package is used. Each command is run once untimed first (except the
cold run), so the operating system's file cache is warm; rows 1 to 3 are repeated --repeats
times too. The table gives the minimum, median and maximum, and for the CLI runs the time the
CLI itself reports for the run (`... in X s`: the sweep and the Dataset, without the imports,
the scene loading and the netCDF write).

Command (run on an otherwise idle machine)
------------------------------------------
    python benchmarks/startup.py --json startup.json

Small check: python benchmarks/startup.py --repeats 1
Prints a Markdown table to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_common import markdown_table, write_json  # noqa: E402

SUMMARY = re.compile(r"points? in ([0-9.]+) s")

KERNEL_START = """
import sys, time
sys.path.insert(0, {bench!r})
from bench_common import parameter_table
from sweep import load_scene
from sweep.run import settings_vector, solve_points
scene = load_scene({scene!r})
table, settings = parameter_table(scene), settings_vector(scene)
start = time.perf_counter()
solve_points(table[:1], settings, 0, threads=1)
print(time.perf_counter() - start)
"""


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--repeats", type=int, default=3,
                   help="warm CLI runs, and runs of each reference command (default 3)")
    p.add_argument("--cold-repeats", type=int, default=1,
                   help="cold CLI runs, each with a fresh empty NUMBA_CACHE_DIR (default 1)")
    p.add_argument("--scene", default="paper-fig5",
                   help="built-in scene to run (default paper-fig5)")
    p.add_argument("--installed", action="store_true",
                   help="use the installed package (do not set PYTHONPATH to the checkout)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def base_env(installed: bool) -> dict[str, str]:
    env = dict(os.environ)
    if not installed:
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + ([env["PYTHONPATH"]]
                                                           if env.get("PYTHONPATH") else []))
    return env


def timed(cmd: list[str], env: dict[str, str], cwd: str) -> tuple[float, str]:
    """Wall time (s) of `cmd` in a subprocess, and its stdout; raises if it fails."""
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited with {proc.returncode}:\n{proc.stderr}")
    return wall, proc.stdout


def reported_run_time(stdout: str) -> float:
    """The run time the CLI prints in its summary line (`... N points in X s ...`)."""
    match = SUMMARY.search(stdout)
    return float(match.group(1)) if match else float("nan")


def summary(name: str, command: str, walls: list[float], runs_s: list[float]) -> dict:
    return {"name": name, "command": command, "walls_s": walls, "min_s": min(walls),
            "median_s": statistics.median(walls), "max_s": max(walls),
            "cli_reported_run_s": runs_s}


def main() -> None:
    args = parse_args()
    env = base_env(args.installed)
    py = sys.executable
    results = []
    with tempfile.TemporaryDirectory(prefix="cable-sweep-startup-") as tmp:
        out = str(Path(tmp) / "out.nc")
        refs = [("bare interpreter", [py, "-c", "pass"]),
                ("import sweep", [py, "-c", "import sweep"]),
                ("import sweep + kernels (numba)", [py, "-c", "import sweep, sweep.kernels.transverse"]),
                ("sweep --help", [py, "-m", "sweep.cli", "--help"]),
                ("sweep scenes", [py, "-m", "sweep.cli", "scenes"])]
        for name, cmd in refs:
            timed(cmd, env, tmp)                                 # untimed: warm the file cache
            walls = [timed(cmd, env, tmp)[0] for _ in range(args.repeats)]
            shown = "python " + " ".join(f'"{c}"' if " " in c else c for c in cmd[1:])
            results.append(summary(name, shown, walls, []))

        cli = [py, "-m", "sweep.cli", "run", args.scene, "-o", out, "--overwrite"]
        cold_walls, cold_runs, cache = [], [], ""
        for i in range(args.cold_repeats):
            cache = tempfile.mkdtemp(prefix=f"numba-cache-{i}-", dir=tmp)
            wall, stdout = timed(cli, {**env, "NUMBA_CACHE_DIR": cache}, tmp)
            cold_walls.append(wall)
            cold_runs.append(reported_run_time(stdout))
        results.append(summary("CLI, cold (empty Numba cache)",
                               "NUMBA_CACHE_DIR=<empty> python -m sweep.cli run " + args.scene
                               + " -o TMP/out.nc --overwrite", cold_walls, cold_runs))
        warm_walls, warm_runs = [], []
        for _ in range(args.repeats):
            wall, stdout = timed(cli, {**env, "NUMBA_CACHE_DIR": cache}, tmp)
            warm_walls.append(wall)
            warm_runs.append(reported_run_time(stdout))
        results.append(summary("CLI, warm (cache from the cold run)",
                               "NUMBA_CACHE_DIR=<same> python -m sweep.cli run " + args.scene
                               + " -o TMP/out.nc --overwrite", warm_walls, warm_runs))
        out_bytes = Path(out).stat().st_size

        snippet = KERNEL_START.format(bench=str(ROOT / "benchmarks"), scene=args.scene)
        kernel = [py, "-c", snippet]
        cold_k = []
        for i in range(args.cold_repeats):
            cache_k = tempfile.mkdtemp(prefix=f"numba-cache-k{i}-", dir=tmp)
            cold_k.append(float(timed(kernel, {**env, "NUMBA_CACHE_DIR": cache_k}, tmp)[1]))
        warm_k = [float(timed(kernel, {**env, "NUMBA_CACHE_DIR": cache_k}, tmp)[1])
                  for _ in range(args.repeats)]
        for name, values in (("kernel start, cold (first call, empty cache)", cold_k),
                             ("kernel start, warm (first call, cache from the cold run)", warm_k)):
            results.append(summary(name, "first solve_points call on one point of "
                                   + args.scene + " (after the imports)", values, []))

    print(f"# Start-up: `sweep run {args.scene}` from the command line, cold and warm Numba "
          "cache\n")
    print(f"Python {platform.python_version()} ({py}); package from "
          f"{'the installed package' if args.installed else f'PYTHONPATH={ROOT}'}; "
          f"{args.repeats} run(s) per row, {args.cold_repeats} cold; output {out_bytes:,} bytes. "
          "Wall time of the whole subprocess, seconds (kernel-start rows: the first kernel call "
          "alone); 'run (CLI)' is the time the CLI reports "
          "for the sweep itself.\n")
    rows = []
    for r in results:
        runs = r["cli_reported_run_s"]
        rows.append([r["name"], f"`{r['command']}`", len(r["walls_s"]), f"{r['min_s']:.3f}",
                     f"{r['median_s']:.3f}", f"{r['max_s']:.3f}",
                     f"{min(runs):.3f}" if runs else ""])
    print(markdown_table(["what", "command", "runs", "min (s)", "median (s)",
                          "max (s)", "run (CLI, s)"], rows))
    by = {r["name"]: r for r in results}
    cold = by["CLI, cold (empty Numba cache)"]["min_s"]
    warm = by["CLI, warm (cache from the cold run)"]["median_s"]
    imp = by["import sweep"]["median_s"]
    bare = by["bare interpreter"]["median_s"]
    k_cold = by["kernel start, cold (first call, empty cache)"]["min_s"]
    k_warm = by["kernel start, warm (first call, cache from the cold run)"]["median_s"]
    print(f"\nJIT compilation costs about {cold - warm:.2f} s once (cold {cold:.2f} s - warm "
          f"{warm:.2f} s); a warm run is {warm - imp:.2f} s beyond `import sweep` "
          f"({imp:.2f} s, of which {bare:.2f} s is the bare interpreter). The kernel's own "
          f"start (first call): {k_cold:.2f} s cold, {k_warm:.3f} s warm.")

    if args.json:
        write_json(args.json, {"scene": args.scene, "repeats": args.repeats,
                               "cold_repeats": args.cold_repeats, "installed": args.installed,
                               "results": results, "output_bytes": out_bytes,
                               "python": platform.python_version(),
                               "machine": platform.machine()})


if __name__ == "__main__":
    main()
