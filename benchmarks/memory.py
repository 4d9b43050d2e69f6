"""Memory: peak resident memory of a sweep against the size of what it produces.

What it measures
----------------
The reference sweep's problem (reference_sweep.py: paper coefficients, q0 = 4 mm, lengths in
[0.3, 1.2] m x frequency ratios in [0.5, 3], default tolerances, no time series stored) on a
grid of --points points (default 1e6; the grid shape is throughput.py's, 1000 x 1000 for 1e6),
with t_end = --t-end (default 0.5 s, so that 1e6 points take seconds, not minutes: the arrays a
sweep allocates do not depend on t_end, only on the number of points). Every measurement runs
in a fresh subprocess of this interpreter, one after another:

1. baseline: a child that imports sweep and kernels and runs the kernel on 2 points (loading
   it from numba's cache, or compiling it), and nothing else.
2. API: a child that calls `sweep.run(scene, threads=T, progress=False)` (no output file) and
   sums the nbytes of the returned Dataset's variables (data and coordinates).
3. CLI: `python -m sweep.cli run SCENE.toml -o TMP/out.nc --quiet` on the same scene written as
   TOML, i.e. the sweep plus the netCDF write; the file's size is reported. Its baseline is
   the same CLI command on the 2-point scene of 1 (the CLI also imports netCDF4 and writes a
   file, a fixed cost that is not the grid's).

Peak resident memory is the child's ru_maxrss, read by this process with os.wait4 for that
child alone (the high-water mark of its resident set, KiB); children 1 and 2 also report their
own VmHWM from /proc/self/status (the same quantity, as a cross-check). "above baseline" is
peak - baseline peak (API rows over child 1, CLI rows over the 2-point CLI run): what the grid
itself costs. It is compared with the outputs and with the estimate sweep.run uses to refuse a
grid too large for memory (check_memory: 3 copies of 8 x (N_PARAMS + N_REALS + N_COUNTS) + 1
bytes per point, printed above the table). An untimed baseline child runs first, so that every
measured child finds the kernels in numba's cache (the same cache the project uses:
NUMBA_CACHE_DIR as set, or kernels/__pycache__).

Command (run on an otherwise idle machine)
------------------------------------------
    PYTHONPATH=. python benchmarks/memory.py --json memory.json

Other sizes: --points 1e4,1e5,1e6 (one API and one CLI child per size).
Small check: PYTHONPATH=. python benchmarks/memory.py --points 1e4
Prints a Markdown table to stdout; --json PATH also writes every number as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))   # the checkout's sweep/kernels
# Nothing else at module level: the children import only what they measure (the benchmark
# helpers pull in SciPy, which a sweep never loads).

MIB = 2.0**20


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--points", default="1e6",
                   help="grid size(s) in points, comma-separated (default 1e6)")
    p.add_argument("--t-end", type=float, default=0.5,
                   help="end time of every trajectory, s (default 0.5)")
    p.add_argument("--threads", type=int, default=0,
                   help="worker threads of the sweep (default 0: all)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    p.add_argument("--child", choices=["baseline", "api"], help=argparse.SUPPRESS)
    p.add_argument("--scene-file", help=argparse.SUPPRESS)
    return p.parse_args()


# ---------------------------------------------------------------------------- the children


def vm_hwm_kib() -> int:
    """This process's peak resident set (VmHWM, KiB) from /proc/self/status; -1 if unknown."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    except OSError:
        pass
    return -1


def child_baseline(scene_file: str) -> dict:
    """Import sweep and kernels, run the kernel on the 2 points of `scene_file`."""
    import sweep
    from sweep.kernels import oscillator as osc
    from sweep import grid, models
    from sweep.run import settings_vector, solve_points
    scene = sweep.load_scene(scene_file)
    coords = grid.coordinates(scene)          # the parameter rows, as sweep.run builds them
    coeffs = models.oscillator(grid.parameters(scene, coords))
    shape = tuple(coords[d].size for d in coords)
    table = grid.flatten(coeffs, osc.PARAM_NAMES, tuple(coords), shape)
    solve_points(table, settings_vector(scene), 0, threads=1)
    return {"vm_hwm_kib": vm_hwm_kib(), "points": len(table)}


def child_api(scene_file: str, threads: int) -> dict:
    """sweep.run on the scene file, no output; the Dataset's size."""
    import sweep
    scene = sweep.load_scene(scene_file)
    start = time.perf_counter()
    ds = sweep.run(scene, threads=threads, progress=False)
    wall = time.perf_counter() - start
    return {"vm_hwm_kib": vm_hwm_kib(), "wall_s": wall,
            "dataset_nbytes": int(sum(v.nbytes for v in ds.variables.values())),
            "data_vars_nbytes": int(sum(v.nbytes for v in ds.data_vars.values())),
            "points": int(ds.attrs["n_points"])}


# ---------------------------------------------------------------------------- the parent


def run_child(cmd: list[str], cwd: str) -> tuple[int, str, float]:
    """Run `cmd`; (its own ru_maxrss in KiB, its stdout, wall s). Raises if it fails."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + ([env["PYTHONPATH"]]
                                                       if env.get("PYTHONPATH") else []))
    with tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=err,
                                text=True)
        stdout = proc.stdout.read()
        proc.stdout.close()
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(cmd)} exited with {proc.returncode}:\n{err.read()}")
    return int(usage.ru_maxrss), stdout, wall   # ru_maxrss is in KiB on Linux


def last_json(stdout: str) -> dict:
    return json.loads(stdout.strip().splitlines()[-1])


def estimate_bytes_per_point() -> float:
    """check_memory's estimate in sweep.run_transverse (no time series)."""
    from sweep.kernels import transverse as tk
    from sweep.kernels.oscillator import PARAM_NAMES
    return 3.0 * (8 * (len(PARAM_NAMES) + tk.N_REALS + tk.N_COUNTS) + 1)


def write_scene(n_length: int, n_ratio: int, t_end: float, threads: int, path: Path) -> None:
    """The reference problem on an n_length x n_ratio grid, written as a TOML scene file."""
    from reference_sweep import SCENE
    from sweep.scene import load_scene_text
    from throughput import RATIO_AXIS
    scene = load_scene_text(SCENE.format(n=n_length, rtol=1e-8, atol=1e-12), source="memory.py",
                            overrides={"axes.frequency_ratio": {**RATIO_AXIS, "num": n_ratio},
                                       "solver.t_end": t_end, "run.threads": threads})
    path.write_text(scene.to_toml(), encoding="utf-8")


def measure(points: int, t_end: float, threads: int, tmp: str, base_kib: int,
            cli_base_kib: int) -> dict:
    """API and CLI children on a grid of about `points` points."""
    from throughput import grid_shape
    n_length, n_ratio = grid_shape(points)
    scene_file = Path(tmp) / f"scene-{points}.toml"
    write_scene(n_length, n_ratio, t_end, threads, scene_file)
    me = str(Path(__file__).resolve())
    api_kib, stdout, api_wall = run_child(
        [sys.executable, me, "--child", "api", "--scene-file", str(scene_file),
         "--threads", str(threads)], tmp)
    api = last_json(stdout)
    out = Path(tmp) / f"out-{points}.nc"
    cli_kib, _, cli_wall = run_child(
        [sys.executable, "-m", "sweep.cli", "run", str(scene_file), "-o", str(out), "--quiet"],
        tmp)
    file_bytes = out.stat().st_size
    out.unlink()
    n = api["points"]
    return {"points": n, "grid": [n_length, n_ratio], "t_end": t_end,
            "api_peak_kib": api_kib, "api_vm_hwm_kib": api["vm_hwm_kib"],
            "api_wall_s": api_wall, "api_sweep_s": api["wall_s"],
            "cli_peak_kib": cli_kib, "cli_wall_s": cli_wall,
            "dataset_nbytes": api["dataset_nbytes"], "data_vars_nbytes": api["data_vars_nbytes"],
            "netcdf_bytes": file_bytes,
            "api_above_baseline_bytes": (api_kib - base_kib) * 1024.0,
            "cli_above_baseline_bytes": (cli_kib - cli_base_kib) * 1024.0}


def main() -> None:
    args = parse_args()
    if args.child == "baseline":
        print(json.dumps(child_baseline(args.scene_file)))
        return
    if args.child == "api":
        print(json.dumps(child_api(args.scene_file, args.threads)))
        return

    from bench_common import markdown_table, write_json
    sizes = [int(float(s)) for s in args.points.split(",") if s.strip()]
    me = str(Path(__file__).resolve())
    per_point_estimate = estimate_bytes_per_point()
    with tempfile.TemporaryDirectory(prefix="cable-sweep-memory-") as tmp:
        base_scene = Path(tmp) / "scene-baseline.toml"
        write_scene(2, 1, args.t_end, 1, base_scene)
        base_cmd = [sys.executable, me, "--child", "baseline", "--scene-file", str(base_scene)]
        run_child(base_cmd, tmp)                                     # fill numba's cache
        base_kib, stdout, base_wall = run_child(base_cmd, tmp)
        base_out = Path(tmp) / "out-baseline.nc"
        cli_base_kib, _, cli_base_wall = run_child(
            [sys.executable, "-m", "sweep.cli", "run", str(base_scene), "-o", str(base_out),
             "--quiet"], tmp)
        base_hwm = last_json(stdout)["vm_hwm_kib"]
        rows = []
        for n in sizes:
            rows.append(measure(n, args.t_end, args.threads, tmp, base_kib, cli_base_kib))
            print(f"  {n} points done", file=sys.stderr, flush=True)

    print(f"# Memory: peak resident set of a sweep (reference problem, t_end = {args.t_end:g} s, "
          "no time series) against its outputs\n")
    print(f"Python {platform.python_version()}; each row a fresh subprocess; peak = the child's "
          "ru_maxrss (os.wait4), MiB = 2^20 bytes. 'above baseline': sweep.run rows over the "
          "baseline child (import sweep and kernels, kernel on 2 points), CLI rows over the CLI "
          "on the same 2 points (which also imports netCDF4 and writes a file). "
          f"sweep.run's own estimate (check_memory): {per_point_estimate:.0f} B/point.\n")
    headers = ["points", "what", "peak RSS (MiB)", "above baseline (MiB)",
               "above baseline (B/point)", "output (MiB)", "output (B/point)",
               "above baseline / output", "wall (s)"]
    table = [["2", "baseline: import sweep + kernels, kernel on 2 points",
              f"{base_kib / 1024:.1f}", "0", "", "", "", "", f"{base_wall:.2f}"],
             ["2", "CLI baseline: the CLI on 2 points -o out.nc", f"{cli_base_kib / 1024:.1f}",
              "0", "", "", "", "", f"{cli_base_wall:.2f}"]]
    for r in rows:
        n = r["points"]
        for what, peak, above, size, wall in (
                ("sweep.run -> Dataset (nbytes of its variables)", r["api_peak_kib"],
                 r["api_above_baseline_bytes"], r["dataset_nbytes"], r["api_wall_s"]),
                ("CLI -o out.nc (file size)", r["cli_peak_kib"], r["cli_above_baseline_bytes"],
                 r["netcdf_bytes"], r["cli_wall_s"])):
            table.append([f"{n:,} ({r['grid'][0]} x {r['grid'][1]})", what,
                          f"{peak / 1024:.1f}", f"{above / MIB:.1f}", f"{above / n:.0f}",
                          f"{size / MIB:.2f}", f"{size / n:.1f}", f"{above / size:.2f}",
                          f"{wall:.2f}"])
    print(markdown_table(headers, table))
    print(f"\nVmHWM reported by the children (cross-check of ru_maxrss): baseline "
          f"{base_hwm / 1024:.1f} MiB, "
          + ", ".join(f"{r['points']:,} points {r['api_vm_hwm_kib'] / 1024:.1f} MiB"
                      for r in rows))

    if args.json:
        write_json(args.json, {"t_end": args.t_end, "threads": args.threads,
                               "baseline_peak_kib": base_kib, "baseline_vm_hwm_kib": base_hwm,
                               "baseline_wall_s": base_wall,
                               "cli_baseline_peak_kib": cli_base_kib,
                               "cli_baseline_wall_s": cli_base_wall,
                               "check_memory_estimate_bytes_per_point": per_point_estimate,
                               "results": rows, "python": platform.python_version(),
                               "machine": platform.machine()})


if __name__ == "__main__":
    main()
