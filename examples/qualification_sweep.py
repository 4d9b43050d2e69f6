"""A launch sine qualification sweep over a range of clamp spacings: which spans stay within a
deflection limit, up and down the sweep.

The built-in scene launch-sine-qualification sweeps both clamps of each span logarithmically
from 5 to 100 Hz at 2 octaves per minute and back, at a launcher's lateral sine levels x 1.25
(docs/model.md sec. 6). This script runs it, prints for each span its first natural frequency,
the peak midspan deflection of the up and of the down sweep and where it came, marks the spans
whose worst deflection exceeds --limit, names the longest span that passes with every shorter
one, and draws the response envelopes.

    python examples/qualification_sweep.py [--small] [--out DIR] [--limit MM]
"""

import argparse
from pathlib import Path

import numpy as np

import sweep
from sweep.plot import plot, save


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="a reduced sweep, as CI runs it")
    parser.add_argument("--out", default="out", help="output directory (default: ./out)")
    parser.add_argument("--limit", type=float, default=2.0,
                        help="allowed midspan deflection, mm (2.0)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    overrides = {}
    if args.small:          # 5 spans, 16 octaves/min: 16 s of sweep a span and direction
        overrides = {"axes.length": [0.15, 0.2, 0.25, 0.3, 0.35], "base.sweep.rate": 16.0}
    scene = sweep.load_scene("launch-sine-qualification", overrides=overrides)
    path = out / "qualification_sweep.nc"
    ds = sweep.run(scene, output=path, overwrite=True)
    print(path)

    worst = ds["peak_amplitude"].max("direction") * 1e3          # mm
    print(f"{'length m':>9} {'f1 Hz':>7} {'up mm':>8} {'at Hz':>7} {'down mm':>8} {'at Hz':>7}")
    for length in ds["length"].values:
        up, down = (ds.sel(length=length, direction=d) for d in ("up", "down"))
        flag = "  over the limit" if worst.sel(length=length) > args.limit else ""
        print(f"{length:9.3f} {float(up['natural_frequency']):7.1f} "
              f"{float(up['peak_amplitude']) * 1e3:8.3f} {float(up['peak_frequency']):7.1f} "
              f"{float(down['peak_amplitude']) * 1e3:8.3f} {float(down['peak_frequency']):7.1f}"
              f"{flag}")
    passing = (worst <= args.limit).values
    first_fail = int(np.argmin(passing)) if not passing.all() else passing.size
    if first_fail == 0:
        print(f"no span of the grid stays within {args.limit} mm")
    else:
        print(f"longest span within {args.limit} mm with every shorter one: "
              f"{float(ds['length'][first_fail - 1]):.3f} m (on this grid)")
    for figure in save(plot(ds), out, prefix="qualification_sweep-"):
        print(figure)


if __name__ == "__main__":
    main()
