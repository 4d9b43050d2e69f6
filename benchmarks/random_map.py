"""The random-vibration map issue 36 sizes: 20 clamp spacings x 20 realisations x 60 s records of
GEVS qualification, one mode, on every core, through the public API; its wall time with and
without the response's spectral densities (outputs.response_asd).

The built-in scene launch-random-gevs with its lengths (0.10..0.30 m) at 20 values, the level at
qualification (0 dB) alone, 20 records of 60 s: 24 000 realisation-seconds. One run each after a
compile run of a small grid (Numba's cache warm).

    PYTHONPATH=. python benchmarks/random_map.py [--spans 20] [--realisations 20]
        [--duration 60] [--threads 0]

Prints one Markdown table to stdout.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels


def main() -> None:
    import sweep
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spans", type=int, default=20)
    parser.add_argument("--realisations", type=int, default=20)
    parser.add_argument("--duration", type=float, default=60.0, help="s, each record")
    parser.add_argument("--threads", type=int, default=0, help="0: every core")
    args = parser.parse_args()

    def scene(asd: bool, spans: int, realisations: int, duration: float):
        return sweep.load_scene("launch-random-gevs", {
            "axes.length": {"start": 0.1, "stop": 0.3, "num": spans},
            "axes.base_asd_scale": [0.0], "base.realisations": realisations,
            "base.duration": duration, "outputs.response_asd": asd})

    print(f"| {args.spans} spans x {args.realisations} records x {args.duration:g} s | "
          "wall time (s) | kernels' time (run_seconds, s) | realisation-seconds per s |")
    print("|---|---|---|---|")
    for asd in (False, True):
        sweep.run(scene(asd, 2, 2, 30.0), threads=args.threads, progress=False)   # compile
        started = time.perf_counter()
        ds = sweep.run(scene(asd, args.spans, args.realisations, args.duration),
                       threads=args.threads, progress=False)
        wall = time.perf_counter() - started
        work = args.spans * args.realisations * args.duration
        print(f"| {'with' if asd else 'without'} outputs.response_asd | {wall:.1f} | "
              f"{float(ds.attrs['run_seconds']):.1f} | {work / wall:.0f} |")


if __name__ == "__main__":
    main()
