"""Two versions of cable-sweep side by side: the paired runs of RESULTS.md.

Each pair runs both checkouts at the same time, one pinned to each core (`taskset`), then
swapped, so that both see the same machine at the same moment (a VM's timings wander by several
per cent from one minute to the next). Each run is a fresh process that solves the 10 000-point
reference sweep (benchmarks/reference_sweep.py's scene, `sweep.run.solve_points`) on one thread
`--repeats` times after one warm-up call and prints its best wall time (s).

    python benchmarks/before_after.py BEFORE_ROOT AFTER_ROOT [--method rk45|dop853]
        [--driver lanes|scalar] [--repeats 40] [--pairs 2]
        [--scene NAME --set KEY=VALUE ... [--threads N]]

With --scene, each run is instead `sweep.run` of that built-in scene (its own method and
driver unless --set says otherwise) on one thread, with the --set overrides (TOML values, as
`sweep run --set`), after one warm-up run: the whole run as a user makes it. With --threads N
(N > 1, --scene only) the scene runs on N threads, so the two checkouts cannot share the
machine: each pair runs them one after the other, unpinned, in alternating order.

BEFORE_ROOT and AFTER_ROOT are repository checkouts (e.g. `git clone . /tmp/before && git -C
/tmp/before checkout REV`); each is imported from its own directory. Needs 2 cores and taskset.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

ONE_RUN = """
import sys, time
root, method, driver, repeats = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
sys.path[:0] = [root, root + "/benchmarks"]
import reference_sweep as rs
from bench_common import parameter_table
from sweep.run import settings_vector, solve_points
from sweep.scene import load_scene_text
scene = load_scene_text(rs.SCENE.format(n=100, rtol=1e-8, atol=1e-12),
                        overrides={"solver.method": method})
table, settings = parameter_table(scene), settings_vector(scene)
solve_points(table[:32], settings, 0, threads=1, driver=driver)
best = float("inf")
for _ in range(repeats):
    start = time.perf_counter()
    solve_points(table, settings, 0, threads=1, driver=driver)
    best = min(best, time.perf_counter() - start)
print(best)
"""


SCENE_RUN = """
import sys, time
root, name, repeats = sys.argv[1], sys.argv[2], int(sys.argv[3])
sys.path[:0] = [root]
import sweep
from sweep.scene.overrides import parse_override
overrides = {"run.threads": int(sys.argv[4]),
             **dict(parse_override(item) for item in sys.argv[5:])}
scene = sweep.load_scene(name, overrides=overrides)
sweep.run(scene)
best = float("inf")
for _ in range(repeats):
    start = time.perf_counter()
    sweep.run(scene)
    best = min(best, time.perf_counter() - start)
print(best)
"""


def pair(roots: tuple[str, str], cores: tuple[int, int], args: argparse.Namespace) -> list[float]:
    """Best times (s) of both roots, run at once on the given cores."""
    if args.scene:
        command = ["-c", SCENE_RUN, "ROOT", args.scene, str(args.repeats), str(args.threads),
                   *args.set]
    else:
        command = ["-c", ONE_RUN, "ROOT", args.method, args.driver, str(args.repeats)]

    def start(root: str, core: int) -> subprocess.Popen:
        pin = ["taskset", "-c", str(core)] if args.threads == 1 else []
        return subprocess.Popen([*pin, sys.executable,
                                 *[root if c == "ROOT" else c for c in command]],
                                cwd=root, stdout=subprocess.PIPE, text=True)

    def best(proc: subprocess.Popen) -> float:
        return float(proc.communicate()[0].split()[-1])

    if args.threads == 1:
        procs = [start(root, core) for root, core in zip(roots, cores)]
        return [best(proc) for proc in procs]
    first = 0 if cores == (0, 1) else 1     # several threads: one at a time, alternating
    times = {first: best(start(roots[first], 0))}
    times[1 - first] = best(start(roots[1 - first], 0))
    return [times[0], times[1]]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--method", choices=("rk45", "dop853"), default="rk45")
    p.add_argument("--driver", choices=("lanes", "scalar"), default="lanes")
    p.add_argument("--repeats", type=int, default=40)
    p.add_argument("--pairs", type=int, default=2)
    p.add_argument("--scene", help="time `sweep.run` of this built-in scene instead")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a scene override (with --scene), as `sweep run --set`")
    p.add_argument("--threads", type=int, default=1,
                   help="run.threads of each --scene run (> 1: the checkouts one at a time)")
    args = p.parse_args()
    if args.threads != 1 and not args.scene:
        p.error("--threads: with --scene only")
    roots = (str(Path(args.before).resolve()), str(Path(args.after).resolve()))
    before, after = [], []
    for _ in range(args.pairs):
        for cores in ((0, 1), (1, 0)):
            b, a = pair(roots, cores, args)
            before.append(b)
            after.append(a)
    ratios = ", ".join(f"{a / b:.3f}" for a, b in zip(after, before))
    what = (f"{args.scene} {' '.join(args.set)}" if args.scene
            else f"{args.driver} {args.method}")
    threads = "1 thread" if args.threads == 1 else f"{args.threads} threads, one at a time"
    print(f"{what}, {threads}, best of {args.repeats} each run")
    print(f"before: best {min(before):.4f} s  runs {', '.join(f'{b:.4f}' for b in before)}")
    print(f"after:  best {min(after):.4f} s  runs {', '.join(f'{a:.4f}' for a in after)}")
    print(f"after / before: best {min(after) / min(before):.3f}; per pair {ratios}")


if __name__ == "__main__":
    main()
