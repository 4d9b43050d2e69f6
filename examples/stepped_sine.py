"""Stepped sine up and down on the clamps: the two branches of a hardening span, and its jumps.

A shaker's stepped sine dwells at each frequency and steps on without stopping, so each dwell
starts where the last one left the span ([continuation], docs/model.md sec. 6). Stepping up, a
span stiffened by membrane stretching rides its resonant branch past f1 and falls off it;
stepping down it stays low and jumps up at the lower fold. This script steps one span both
ways with three modes, prints where each sweep jumped and how far apart the branches are, and
draws the branches.

    python examples/stepped_sine.py [--small] [--out DIR] [--length M] [--level G]
"""

import argparse
from pathlib import Path

import numpy as np

import sweep
from sweep.plot import plot, save

SCENE = """
name = "stepped-sine"
description = "Stepped sine up and down, {level} g, a {length} m span of the Table 1 cable, 3 modes"
[model]
coefficients = "consistent"
modes = 3
[cable]
inertia = 2.865e-12        # m^4
damping_ratio = 0.02
length = {length}          # m
[load]
amplitude = 0.0            # N: the clamps' motion alone
[base]
acceleration_g = {level}   # g, peak
[axes]
base_frequency_ratio = {{start = 0.8, stop = 2.0, num = {num}}}   # f / f1
[continuation]
axis = "base_frequency_ratio"
direction = "both"
[solver]
t_end = {t_end}            # s per dwell
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="a reduced grid, as CI runs it")
    parser.add_argument("--out", default="out", help="output directory (default: ./out)")
    parser.add_argument("--length", type=float, default=0.5, help="span length, m (0.5)")
    parser.add_argument("--level", type=float, default=0.05, help="base level, g peak (0.05)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    text = SCENE.format(level=args.level, length=args.length, num=13 if args.small else 49,
                        t_end=1.0 if args.small else 4.0)
    ds = sweep.run(sweep.load_scene_text(text), output=out / "stepped_sine.nc", overwrite=True)
    print(out / "stepped_sine.nc")
    ratio = ds["base_frequency_ratio"].values
    for direction, flag, what in (("up", 2, "falls off the resonant branch"),
                                  ("down", 1, "jumps onto it")):
        jumps = ratio[ds["jump"].sel(direction=direction).values == flag]
        where = ", ".join(f"{r:.3g}" for r in jumps) or "nowhere (no jump at this level)"
        print(f"stepping {direction}, the span {what} at f/f1 = {where}")
    up = ds["amplitude"].sel(direction="up").values
    down = ds["amplitude"].sel(direction="down").values
    print(f"largest ratio of the two branches: {np.nanmax(up / down):.3g}; worst deflection "
          f"{np.nanmax(up) * 1e3:.3g} mm, worst acceleration "
          f"{float(ds['absolute_acceleration_g'].max()):.3g} g")
    for path in save(plot(ds), out, prefix="stepped_sine-"):
        print(path)


if __name__ == "__main__":
    main()
