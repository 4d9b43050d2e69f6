"""Random records on the lock-step lanes against the scalar driver, one mode and several.

What it measures
----------------
The built-in scene launch-random-gevs, one span at one level (--length, --level), --records
records of the scene's 8 s, model.modes = N for each N in --modes, run.threads = 1, through
the public API (`sweep.run`), once with solver.driver = "scalar" and once with "lanes" (the
default where enough points and records fill them, sweep/models/rules.py), side by side in
one run: the solve's own time (the dataset's
run_seconds: the kernels, after the records are made) per realisation-second, best of
--repeats after a first run (compile or cache), and the ratio. Beside it, how far each
driver's RMS deflection and acceleration lie from the scalar driver's at rtol 1e-9 on the
same records, relative: the largest over the records, and that of their mean over the
records. The lanes must be as accurate as the scalar driver at the scene's tolerance, not
equal to it (they differ in round-off, so the step sequences part). On a strongly
nonlinear span (the scene's 150 mm at qualification) each record's trajectory is chaotic and
moves with the tolerance by ~10 %; only the statistics over records converge, so the mean's
error is the one to read there; on a mildly nonlinear one (--length 0.1 --level -10) each
record's converges.

With --occupancy: how many trajectories the lanes need to beat the scalar driver (the rules'
RANDOM_LANES_LEAST_POINTS and RANDOM_ONE_MODE_LANES_LEAST_POINTS): one span at --length and
--level, 1, 2, 4, 8 and 16 records of --duration s, each N of --modes, both drivers, the
solve's time (run_seconds, best of --repeats after a first run) and the lanes' share of the
scalar driver's.

Then the whole built-in scene (9 spans x 2 levels x 8 records of 8 s, its spectra on) on 2
threads, warm, best of --repeats wall times of `sweep.run`: one mode (the scene as shipped)
and --scene-modes modes, each on both drivers.

Command
-------
    PYTHONPATH=. python benchmarks/random_lanes.py [--modes 1 2 3 5] [--records 32]
        [--repeats 2] [--length 0.15] [--level 0.0] [--scene-modes 3] [--no-scene]
    PYTHONPATH=. python benchmarks/random_lanes.py --occupancy --modes 1 3 --length 0.1
        --level -10 [--duration 2.0] [--repeats 3]

Prints a Markdown table to stdout.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from bench_common import machine, markdown_table  # noqa: E402

import sweep  # noqa: E402

SCENE = "launch-random-gevs"
WATCHED = ("rms_deflection", "rms_acceleration_g")


def scene(length: float, level: float, records: int, modes: int, driver: str,
          rtol: float | None = None, duration: float | None = None) -> sweep.Scene:
    """The built-in scene at one span and level, `records` records (of `duration` s, the
    scene's 8 s by default), N modes, one thread."""
    over = {"axes.length": [length], "axes.base_asd_scale": [level],
            "base.realisations": records, "run.threads": 1, "model.modes": modes,
            "solver.driver": driver, "outputs.response_asd": False}
    if duration is not None:
        over["base.duration"] = duration
    if rtol is not None:
        over["solver.rtol"] = rtol
    return sweep.load_scene(SCENE, over)


def solve(sc: sweep.Scene, repeats: int) -> tuple[float, dict]:
    """(best run_seconds over `repeats` after a first run, the last dataset's watched values)."""
    ds = sweep.run(sc, progress=False)
    best = np.inf
    for _ in range(repeats):
        ds = sweep.run(sc, progress=False)
        best = min(best, float(ds.attrs["run_seconds"]))
    return best, {k: ds[k].values.ravel() for k in WATCHED}


def occupancy(args: argparse.Namespace) -> None:
    """The lanes' time over the scalar driver's against the number of records (one span)."""
    rows = []
    for n in args.modes:
        for records in (1, 2, 4, 8, 16):
            t = {driver: solve(scene(args.length, args.level, records, n, driver,
                                     duration=args.duration), args.repeats)[0]
                 for driver in ("scalar", "lanes")}
            rows.append([f"{n}", f"{records}", f"{t['scalar'] * 1e3:.1f}",
                         f"{t['lanes'] * 1e3:.1f}", f"{t['lanes'] / t['scalar']:.2f}"])
    print(f"machine: {machine()}\n")
    print(f"{SCENE}, {args.length * 1e3:g} mm at {args.level:g} dB, records of "
          f"{args.duration:g} s, one thread, DOP853 at the scene's rtol; the solve's time "
          f"(run_seconds, best of {args.repeats} after a first run):\n")
    print(markdown_table(["modes", "records", "scalar ms", "lanes ms", "lanes / scalar"],
                         rows))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--modes", type=int, nargs="+", default=[1, 2, 3, 5])
    parser.add_argument("--records", type=int, default=32)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--length", type=float, default=0.15, help="m")
    parser.add_argument("--level", type=float, default=0.0, help="dB")
    parser.add_argument("--scene-modes", type=int, default=3)
    parser.add_argument("--no-scene", action="store_true", help="skip the whole scene's runs")
    parser.add_argument("--occupancy", action="store_true",
                        help="the lanes against the scalar driver over 1-16 records, only")
    parser.add_argument("--duration", type=float, default=2.0,
                        help="s, each record, with --occupancy")
    args = parser.parse_args()
    if args.occupancy:
        occupancy(args)
        return
    rows = []
    for n in args.modes:
        ref = sweep.run(scene(args.length, args.level, args.records, n, "scalar", 1e-9),
                        progress=False)
        ref = {k: ref[k].values.ravel() for k in WATCHED}
        seconds = args.records * 8.0
        wall = {}
        for driver in ("scalar", "lanes"):
            t, got = solve(scene(args.length, args.level, args.records, n, driver),
                           args.repeats)
            wall[driver] = t
            err = {k: float(np.max(np.abs(got[k] - ref[k]) / np.abs(ref[k]))) for k in WATCHED}
            mean = {k: abs(got[k].mean() / ref[k].mean() - 1.0) for k in WATCHED}
            rows.append([f"{n}", driver, f"{t / seconds * 1e3:.2f}",
                         f"{err['rms_deflection']:.1e} / {mean['rms_deflection']:.1e}",
                         f"{err['rms_acceleration_g']:.1e} / {mean['rms_acceleration_g']:.1e}",
                         f"{wall['scalar'] / t:.2f}" if driver == "lanes" else "1.00"])
    print(f"machine: {machine()}\n")
    print(f"{SCENE}, {args.length * 1e3:g} mm at {args.level:g} dB, {args.records} records of "
          f"8 s, one thread, DOP853 at the scene's rtol; solve ms per realisation-second "
          f"(run_seconds, best of {args.repeats} after a first run); error against the "
          "scalar driver at rtol 1e-9 on the same records (the largest over the records / "
          "that of their mean):\n")
    print(markdown_table(["modes", "driver", "solve ms / realisation-s",
                          "RMS deflection error (largest / mean's)",
                          "RMS acceleration error (largest / mean's)", "speed-up"], rows))
    if args.no_scene:
        return
    rows = []
    for n, driver in ((1, "scalar"), (1, "lanes"), (args.scene_modes, "scalar"),
                      (args.scene_modes, "lanes")):
        sc = sweep.load_scene(SCENE, {"model.modes": n, "solver.driver": driver,
                                      "run.threads": 2})
        sweep.run(sc, progress=False)
        best = np.inf
        for _ in range(args.repeats):
            start = time.perf_counter()
            sweep.run(sc, progress=False)
            best = min(best, time.perf_counter() - start)
        rows.append([f"{n}", driver, f"{best:.2f}"])
    print(f"\nThe whole scene {SCENE} (2 threads, warm, best of {args.repeats} wall times):\n")
    print(markdown_table(["modes", "driver", "wall s"], rows))


if __name__ == "__main__":
    main()
