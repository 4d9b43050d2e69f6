"""Length x frequency map: where the parametric resonance zones lie.

Span lengths 0.3-1.4 m against load frequencies W/w1 = 0.5-3 at P0 = 4 N and 2 % damping. The
amplitude and state maps show the principal zone near W = 2 w1, overlaid with its closed-form
boundaries W/w1 = 2 sqrt(1 +- mu), mu = P0 / (2 Pcr) (dotted where damping closes it), the narrow
zone near W = w1, and the buckling length where P0 = Pcr.

    python examples/length_frequency_map.py [--small] [--out DIR]
"""

import argparse
from pathlib import Path

import sweep
from sweep.plot import plot, save

SCENE = """
name = "length-frequency-map"
description = "Consistent model, Table 1 cable, 2 % damping, 4 N: length x W/w1 map"
[model]
coefficients = "consistent"
[cable]
damping_ratio = 0.02
[load]
type = "harmonic"
amplitude = 4.0            # N
[initial]
displacement = 1e-4        # m
[axes]
length = {{start = 0.3, stop = 1.4, num = {n_length}}}            # m
frequency_ratio = {{start = 0.5, stop = 3.0, num = {n_freq}}}     # W / w1
[solver]
t_end = {t_end}            # s
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--small", action="store_true", help="a reduced grid, as CI runs it")
    parser.add_argument("--out", default="out", help="output directory (default: ./out)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    grid = dict(n_length=4, n_freq=5, t_end=2.0) if args.small else \
        dict(n_length=45, n_freq=51, t_end=30.0)
    result = out / "length_frequency_map.nc"
    ds = sweep.run(sweep.load_scene_text(SCENE.format(**grid)), output=result, overwrite=True)
    print(result)
    for path in save(plot(ds), out, prefix="length_frequency_map-"):
        print(path)


if __name__ == "__main__":
    main()
