"""Whether a scene's results depend on what was compiled before it: every built-in scene (or
those named), reduced as `sweep compile` reduces it (sweep.warmup.reduced: two values an axis),
run four ways, each in a fresh process on an empty Numba cache of its own: all the scenes in
one process in order, all in reverse order, in order after the small kernels that tests call
from Python were first compiled from Python, and each alone. Every numeric output variable
must have the same bits all four ways. `--set KEY=VALUE` (TOML values, as `sweep run --set`)
applies to every scene named: `--set model.modes=3` runs the multi-mode drivers.

Why: Numba links a callee that a process compiled itself into its caller's code, where LLVM
may inline it and fuse its arithmetic with the caller's, but links one loaded from the cache
as it is; a shared callee that is called rather than inlined can then round differently by
the order in which a process met its callers (the twenty-fourth session found one, a record
read, and inlined it). And Numba compiles a callee that states no `fastmath` with the flags
of its first caller: called from Python first (as the tests do), a read that the multi-mode
kernels compile with contraction lost it, and 38 of the 54 outputs of launch-random-gevs with
3 modes moved (the thirty-eighth session, benchmarks/RESULTS.md; kernels/flags.py has the
rule that prevents it).

Command
-------
    PYTHONPATH=. python benchmarks/compile_order.py [SCENE ...] [--set KEY=VALUE ...]

Prints each scene's verdict and exits 1 when any output differs. About 8 minutes for every
built-in scene on the 2-core development VM (the compiling, four times over).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

RUN = """
import json, sys, numpy as np, sweep
from sweep.warmup import reduced
from sweep.scene.overrides import parse_override
overrides = dict(parse_override(item) for item in json.loads(sys.argv[3]))
if sys.argv[2] == "python-first":
    # what the test suite does before some scenes: call the small reads from Python
    import sweep.kernels.excitation as ex, sweep.kernels.modes as md
    p, records = np.ones(1000), np.ones((1, 16, 4))
    ex.record_acceleration(0.1, p, 0, 1, records)
    md.base_acceleration(0.1, p, 3, records)
out = {}
for name in sys.argv[4:]:
    scene = sweep.load_scene(name, {"run.threads": 1, **overrides})
    ds = sweep.run(reduced(scene), progress=False)
    out.update({f"{name}/{v}": ds[v].values for v in ds.data_vars if ds[v].dtype.kind in "fiu"})
np.savez(sys.argv[1], **out)
"""


def outputs(folder: Path, label: str, scenes: list[str], overrides: list[str],
            first: str = "-") -> dict[str, np.ndarray]:
    """Run `scenes` in one fresh process on an empty cache, after the Python calls `first`
    names ("python-first", or "-": none); their outputs by 'scene/var'."""
    cache, out = folder / f"cache-{label}", folder / f"{label}.npz"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT))
    subprocess.run([sys.executable, "-c", RUN, str(out), first, json.dumps(overrides),
                    *scenes], env=env, check=True, stdout=subprocess.DEVNULL)
    with np.load(out) as data:
        return {k: data[k] for k in data.files}


def main() -> int:
    sys.path.insert(0, str(ROOT))
    from sweep import builtin_scenes
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="*", metavar="SCENE")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="an override for every scene, as `sweep run --set`")
    args = p.parse_args()
    scenes = args.scenes or list(builtin_scenes())
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        ways = [outputs(folder, "forward", scenes, args.set),
                outputs(folder, "backward", scenes[::-1], args.set),
                outputs(folder, "python-first", scenes, args.set, "python-first")]
        differ = 0
        for name in scenes:
            alone = outputs(folder, f"alone-{name}", [name], args.set)
            bad = [k for k in alone if not all(
                np.array_equal(alone[k], way[k], equal_nan=True) for way in ways)]
            differ += len(bad)
            print(f"{name}: {len(alone)} outputs, "
                  + (f"{len(bad)} differ: {', '.join(bad)}" if bad else "the same bits"))
    print("\n    PYTHONPATH=. python benchmarks/compile_order.py " + " ".join(sys.argv[1:]))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
