"""Whether a scene's results depend on what was compiled before it: every built-in scene (or
those named), reduced as `sweep compile` reduces it (sweep.warmup.reduced: two values an axis),
run three ways, each in a fresh process on an empty Numba cache of its own: all the scenes in
one process in order, all in reverse order, and each alone. Every numeric output variable
must have the same bits all three ways.

Why: Numba links a callee that a process compiled itself into its caller's code, where LLVM
may inline it and fuse its arithmetic with the caller's, but links one loaded from the cache
as it is; a shared callee that is called rather than inlined can then round differently by
the order in which a process met its callers (the twenty-fourth session found one, a record
read, and inlined it).

Command
-------
    PYTHONPATH=. python benchmarks/compile_order.py [SCENE ...]

Prints each scene's verdict and exits 1 when any output differs. About 6 minutes for every
built-in scene on the 2-core development VM (the compiling, three times over).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

RUN = """
import sys, numpy as np, sweep
from sweep.warmup import reduced
out = {}
for name in sys.argv[2:]:
    ds = sweep.run(reduced(sweep.load_scene(name, {"run.threads": 1})), progress=False)
    out.update({f"{name}/{v}": ds[v].values for v in ds.data_vars if ds[v].dtype.kind in "fiu"})
np.savez(sys.argv[1], **out)
"""


def outputs(folder: Path, label: str, scenes: list[str]) -> dict[str, np.ndarray]:
    """Run `scenes` in one fresh process on an empty cache; their outputs by 'scene/var'."""
    cache, out = folder / f"cache-{label}", folder / f"{label}.npz"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT))
    subprocess.run([sys.executable, "-c", RUN, str(out), *scenes], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    with np.load(out) as data:
        return {k: data[k] for k in data.files}


def main() -> int:
    sys.path.insert(0, str(ROOT))
    from sweep import builtin_scenes
    scenes = sys.argv[1:] or list(builtin_scenes())
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        forward = outputs(folder, "forward", scenes)
        backward = outputs(folder, "backward", scenes[::-1])
        differ = 0
        for name in scenes:
            alone = outputs(folder, f"alone-{name}", [name])
            bad = [k for k in alone if not (
                np.array_equal(alone[k], forward[k], equal_nan=True)
                and np.array_equal(alone[k], backward[k], equal_nan=True))]
            differ += len(bad)
            print(f"{name}: {len(alone)} outputs, "
                  + (f"{len(bad)} differ: {', '.join(bad)}" if bad else "the same bits"))
    print("\n    PYTHONPATH=. python benchmarks/compile_order.py " + " ".join(sys.argv[1:]))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
