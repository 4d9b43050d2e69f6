"""Where a lanes run spends its time: each phase of the lanes driver's loop
(kernels/modal_lanes.py's for several modes, kernels/lanes.py's for one).

What it measures
----------------
A copy of the driver's module compiled with a time-stamp-counter read (rdtsc, from a
five-line C helper built here with the system's C compiler) before each phase of
`solve_block`'s main loop, run on the largest block of a built-in scene as `sweep.run` gives it
to the kernel (one thread). Several modes (kernels/modal_lanes.py): the share of the cycles in
loading and ending lanes with the next attempt's set-up, the attempt (the stages' right-hand
sides and sums, the error), the controller and midspan projection, the modes' event test,
`_finish`, the modes' step-end update, the steps handed to the scalar path (`_flagged_lane`:
extrema, crests, samples) and the lanes' advance. One mode (kernels/lanes.py): the next
attempts, loading and ending lanes, a random record's stage reads, the attempt (the stage
chain and the error), the PI factors, `_finish`, the ordinary steps' base-excitation metric or
record statistics, and the steps handed to the scalar path (counted with the loop's top). The
copy is compiled once untimed, then timed once. A diagnostic: the shares say where to look,
the kernels' own timings are benchmarks/modes_cost.py's and workloads.py's.

Command
-------
    PYTHONPATH=. python benchmarks/lanes_phases.py [NAME] [--set KEY=VALUE ...]

e.g. `PYTHONPATH=. python benchmarks/lanes_phases.py harness-base-sine --set
"axes.base_frequency={start=5.0,stop=100.0,num=16,spacing=\\"log\\"}" --set
"axes.length=[0.2,0.35,0.5,0.65,0.8]" --set solver.t_end=2.0`, or one mode's random records:
`PYTHONPATH=. python benchmarks/lanes_phases.py launch-random-gevs --set "axes.length=[0.15]"
--set "axes.base_asd_scale=[0.0]" --set base.realisations=16 --set
outputs.response_asd=false`. Needs a C compiler (cc); says so and stops without one.
"""

from __future__ import annotations

import argparse
import ctypes
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
import types
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

HELPER = "#include <stdint.h>\n#include <x86intrin.h>\nuint64_t rdtsc(void) { return __rdtsc(); }\n"
# each phase ends where the next begins; the first is the loop's own top (the interrupt test)
PHASES = [("        tj.next_attempts(W, L, H, FLAG, settings, n_run)\n", "loop top"),
          ("        _attempt(W, Y, YN, K, ST, TT, H, ERR,", "next attempt, lanes loaded and ended"),
          ("        _control(W, H, ERR, SC, settings, n_run)\n", "attempt (stages, error)"),
          ("        _mode_events(", "controller, midspan projection, reaches"),
          ("        _keep_record_start(", "modes' event test"),
          ("        n_flagged = _finish(", "a record's start kept"),
          ("        _record_statistics(", "_finish"),
          ("        _tail_modes(", "a record's statistics"),
          ("        _span_events(", "modes' step-end update"),
          ("        if base is not None:\n            _sine_refine_marked(",
           "span events (the load observers)"),
          ("        if n_flagged > 0:\n", "ordinary steps' extrema refined"),
          ("        _advance(Y, YN, K, MOVE, dim, n_stages, n_run)\n",
           "steps handed to the scalar path")]


def timer() -> ctypes._CFuncPtr:
    """rdtsc() from a helper compiled now (exits with a message without a C compiler)."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        sys.exit("lanes_phases: no C compiler (cc) to build the time-stamp-counter helper")
    work = Path(tempfile.mkdtemp())
    (work / "rdtsc.c").write_text(HELPER)
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(work / "rdtsc.so"),
                    str(work / "rdtsc.c")], check=True)
    lib = ctypes.CDLL(str(work / "rdtsc.so"))
    lib.rdtsc.restype = ctypes.c_uint64
    lib.rdtsc.argtypes = []
    return lib.rdtsc


# one mode (kernels/lanes.py): the steps handed to the scalar path end the loop, and count
# with its top (the loop has no marker after them: a step with none `continue`s past it)
ONE_MODE_PHASES = [
    ("        tj.next_attempts(W, L, W[W_H * L:(W_H + 1) * L]",
     "loop top, and the steps handed to the scalar path"),
    ("        top = 0\n", "next attempts"),
    ("        n_run = min(L, (top + SIMD - 1) // SIMD * SIMD)\n", "lanes loaded and ended"),
    ("        if record is not None:\n            _stage_reads(", "lanes to run"),
    ("        if eighth is None:\n            _attempt(W, rtol", "a record's stage reads"),
    ("        if pi is not None:\n            _pi_factors", "attempt (stage chain, error)"),
    ("        _keep_record_start(W, n_run, base)\n", "PI factors"),
    ("        n_flagged, n_extrema, n_near = _finish(", "a record's start kept"),
    ("        _ordinary_acceleration(W, settings", "_finish"),
    ("        if n_flagged == 0:\n            continue\n",
     "ordinary steps' acceleration peak or record statistics")]


def instrumented(rdtsc: ctypes._CFuncPtr, name: str = "modal_lanes",
                 phases: list | None = None) -> types.ModuleType:
    """kernels/NAME.py with a cycle count per phase (`solve_block(..., halt, cycles)`), the
    phases' markers `phases` (PHASES, or ONE_MODE_PHASES for kernels/lanes.py, whose last
    phase has no marker after it). Written to a file and imported: the one-mode lanes make
    their stage chains from the source of their functions."""
    phases = PHASES if phases is None else phases
    src = (ROOT / "kernels" / f"{name}.py").read_text()
    src = src.replace("from . import", "from sweep.kernels import").replace(
        "from .", "from sweep.kernels.").replace("cache=True", "cache=False")
    if src.count(" base, swept, halt):\n") == 1:     # kernels/lanes.py: the entries call _drive
        src = src.replace(" base, swept, halt):\n", " base, swept, halt, cycles):\n")
        src = src.replace(" base, halt):\n", " base, halt, cycles):\n")
        src = src.replace(" base, None, halt)\n", " base, None, halt, cycles)\n")
        src = src.replace(" base, True, halt)\n", " base, True, halt, cycles)\n")
    elif src.count(" eighth, halt):\n") == 1:
        src = src.replace(" eighth, halt):\n", " eighth, halt, cycles):\n", 1)
    else:
        sys.exit(f"lanes_phases: kernels/{name}.py changed: solve_block's signature")
    head, loop = src.split("    while True:\n        if halt[0] != 0:", 1)
    loop = "    while True:\n        if halt[0] != 0:" + loop
    for k, (text, _) in enumerate(phases):
        if loop.count(text) != 1:
            sys.exit(f"lanes_phases: kernels/{name}.py changed: no {text.strip()!r}")
        loop = loop.replace(text, f"        _c = rdtsc(); cycles[{k}] += _c - _t0; _t0 = _c\n"
                            + text)
    if phases is PHASES:
        last = phases[-1][0]
        loop = loop.replace(last, last + f"        _c = rdtsc(); cycles[{len(phases)}] += "
                            "_c - _t0; _t0 = _c\n")
    import importlib.util
    path = Path(tempfile.mkdtemp()) / f"{name}_phases.py"
    path.write_text(head + "    _t0 = rdtsc()\n" + loop)
    spec = importlib.util.spec_from_file_location(f"{name}_phases", path)
    module = importlib.util.module_from_spec(spec)
    module.__dict__["rdtsc"] = rdtsc
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", nargs="?", default="harness-base-sine")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    import sweep
    import sweep.threads as threads
    overrides = {"run.threads": 1, "solver.driver": "lanes"}
    for item in args.set:
        key, _, value = item.partition("=")
        overrides[key] = tomllib.loads(f"v = {value}")["v"]
    calls = []
    original = threads.call

    def spy(fn, *call_args):
        if (getattr(fn, "__name__", "") in ("solve_block", "solve_swept_block")
                and fn.__module__.endswith("lanes")):
            calls.append((fn.__module__.rsplit(".", 1)[-1], fn.__name__, call_args))
        return original(fn, *call_args)

    threads.call = spy
    sweep.run(sweep.load_scene(args.scene, overrides), progress=False)
    threads.call = original
    if not calls:
        sys.exit(f"lanes_phases: {args.scene} ran on no lanes driver")
    import importlib
    import inspect

    name = "modal_lanes" if any(n == "modal_lanes" for n, _, _ in calls) else "lanes"
    entry = next(f for n, f, _ in calls if n == name)    # solve_block or solve_swept_block
    driver = importlib.import_module(f"sweep.kernels.{name}")
    names = list(inspect.signature(getattr(driver, entry).py_func).parameters)
    lo, hi = names.index("lo"), names.index("hi")
    block = max((a for n, _, a in calls if n == name), key=lambda a: a[hi] - a[lo])
    phases = PHASES if name == "modal_lanes" else ONE_MODE_PHASES
    module = instrumented(timer(), name, phases)
    cycles = np.zeros(len(phases) + 1, np.uint64)
    for timed in (False, True):
        cycles[:] = 0
        fresh = [a.copy() if isinstance(a, np.ndarray) and a.flags.writeable else a
                 for a in block]
        start = time.perf_counter()
        getattr(module, entry)(*fresh, cycles)
        wall = time.perf_counter() - start
    labels = [label for _, label in phases] + (["lanes' advance"] if phases is PHASES else [])
    total = float(cycles.sum())
    print(f"{args.scene} ({name}): block of rows {block[lo]}..{block[hi]}, "
          f"{wall * 1e3:.0f} ms")
    for label, value in zip(labels, cycles):
        print(f"  {label:56s} {100.0 * float(value) / total:5.1f} %")
    print("\n    PYTHONPATH=. python benchmarks/lanes_phases.py " + " ".join(sys.argv[1:]))


if __name__ == "__main__":
    main()
