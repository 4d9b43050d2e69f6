"""Load-amplitude sweep: the damping threshold of the principal parametric resonance.

One 0.8 m span, loaded at W = 2 w1 with amplitudes from 0.1 to 10 N (log spaced). Below
mu = P0 / (2 Pcr) = 2 zeta (P0 of about 0.4 N with 2 % damping and the default
bending inertia A^2/(4 pi): Pcr = 4.9 N) the start decays; above it the
response grows to a steady nonlinear amplitude. The time series are stored to show both.

    python examples/load_amplitude_sweep.py [--small] [--out DIR]
"""

import argparse
from pathlib import Path

import sweep
from sweep.plot import plot, save

SCENE = """
name = "load-amplitude-sweep"
description = "Consistent model, 0.8 m span, 2 % damping, W = 2 w1, P0 from 0.1 to 10 N"
[model]
coefficients = "consistent"
[cable]
length = 0.8               # m
damping_ratio = 0.02
[load]
type = "harmonic"
frequency_ratio = 2.0      # W / w1
[initial]
displacement = 1e-4        # m
[axes]
load_amplitude = {{start = 0.1, stop = 10.0, num = {num}, spacing = "log"}}    # N
[solver]
t_end = {t_end}            # s
[outputs]
time_series = true         # q(t), t_end / 1000 apart
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="a reduced grid, as CI runs it")
    parser.add_argument("--out", default="out", help="output directory (default: ./out)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    text = SCENE.format(num=4 if args.small else 41, t_end=2.0 if args.small else 10.0)
    result = out / "load_amplitude_sweep.nc"
    ds = sweep.run(sweep.load_scene_text(text), output=result, overwrite=True)
    print(result)
    for path in save(plot(ds), out, prefix="load_amplitude_sweep-"):
        print(path)


if __name__ == "__main__":
    main()
