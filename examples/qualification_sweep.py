"""A launch sine qualification sweep over a range of clamp spacings: which spans stay within a
deflection limit, up and down the sweep.

The built-in scene launch-sine-qualification sweeps both clamps of each span logarithmically
from 5 to 100 Hz at 2 octaves per minute and back, at a launcher's lateral sine levels x 1.25
(docs/model.md sec. 6). This script runs it, prints for each span its first natural frequency,
the peak midspan deflection of the up and of the down sweep and where it came, marks the spans
whose worst deflection exceeds --limit, answers the harness question with `sweep.design`: the
longest clamp spacing whose every shorter span keeps f1 >= --min-frequency and the worst
deflection of both sweeps within --limit (interpolated, then refined with the engine to 1 mm),
and draws the response envelopes.

    python examples/qualification_sweep.py [--small] [--out DIR] [--limit MM] [--min-frequency HZ]
"""

import argparse
from pathlib import Path

import sweep
import sweep.design
from sweep.plot import plot, save


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="a reduced sweep, as CI runs it")
    parser.add_argument("--out", default="out", help="output directory (default: ./out)")
    parser.add_argument("--limit", type=float, default=2.0,
                        help="allowed midspan deflection, mm (2.0)")
    parser.add_argument("--min-frequency", type=float, default=40.0,
                        help="required first natural frequency, Hz (40.0)")
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
    criteria = dict(min_frequency=args.min_frequency, max_amplitude=args.limit * 1e-3)
    design = sweep.design.max_span(ds, **criteria)
    refined = sweep.design.refine_span(ds, **criteria)
    print(f"longest clamp spacing with f1 >= {args.min_frequency:g} Hz and <= {args.limit:g} mm: "
          f"{float(design['max_span']) * 1e3:.1f} mm on the grid, "
          f"{float(refined['max_span']) * 1e3:.1f} mm refined "
          f"({refined.attrs.get('refine_runs', 0)} runs), limited by "
          f"{refined['limited_by'].item()}")
    for figure in save(plot(ds), out, prefix="qualification_sweep-"):
        print(figure)


if __name__ == "__main__":
    main()
