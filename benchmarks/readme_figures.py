"""The results README.md quotes from the built-in scenes, regenerated from fresh runs.

Each figure below is a phrase of README.md with its numbers, written by a function of the
scene's result at the README's own precision (its stated tolerance: 0.04 mm means 0.035 to
0.045 mm). This script runs the scenes and prints every phrase, marking those README.md no
longer holds; tests/test_readme_figures.py runs the same table and fails on any such phrase,
so a change that moves a quoted result cannot leave the README behind.

Command (from the repository root; about a minute on a 2-core machine with a warm cache):

    PYTHONPATH=. python benchmarks/readme_figures.py            # every figure
    PYTHONPATH=. python benchmarks/readme_figures.py paper-fig5 # the figures of one scene
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[1]
if __name__ == "__main__":      # run as a script: the checkout's sweep/kernels (imported by the
    sys.path.insert(0, str(ROOT))   # tests: theirs, the path left alone for what they spawn)

import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402


@dataclass(frozen=True)
class Figure:
    """A README phrase: `phrase(ds)` writes it from the result of `scene` (with `overrides`)."""
    scene: str
    what: str
    phrase: Callable[[xr.Dataset], str]
    overrides: dict[str, Any] = field(default_factory=dict)


def two_figures(x: float) -> str:
    """x to two significant figures, as plain digits: 29.6 -> '30', 588.1 -> '590'."""
    digits = 1 - int(math.floor(math.log10(abs(x))))
    value = round(x, digits)
    return f"{value:.{max(digits, 0)}f}"


def _fig5(ds: xr.Dataset) -> str:
    return "**" + ", ".join(f"{a * 1e3:.2f}" for a in ds["amplitude"].values) + " mm**"


def _up(ds: xr.Dataset) -> xr.Dataset:
    return ds.sel(direction="up")


def _long(ds: xr.Dataset) -> xr.Dataset:
    """The qualification's spans of 0.2 m and longer (resonant inside the band)."""
    return ds.where(ds["length"] >= 0.2 - 1e-9, drop=True)


def _qual_up(ds: xr.Dataset) -> str:
    peak = _long(_up(ds))["peak_amplitude"].values * 1e3
    acc = _long(_up(ds))["absolute_acceleration_g"].values
    return (f"{peak.min():.1f} to {peak.max():.1f} mm and {two_figures(acc.min())} to "
            f"{two_figures(acc.max())} g")


def _qual_down(ds: xr.Dataset) -> str:
    peak = _long(ds.sel(direction="down"))["peak_amplitude"].values * 1e3
    return f"peaks at {peak.min():.1f} to {peak.max():.1f} mm"


def _qual_short(ds: xr.Dataset) -> str:
    worst = float(ds["peak_amplitude"].sel(length=0.15).max()) * 1e3    # either direction
    return f"driven quasi-statically ({worst:.2f} mm)"


def _design(**criteria: float) -> Callable[[xr.Dataset], str]:
    def phrase(ds: xr.Dataset) -> str:
        from sweep.design import max_span
        return f"{float(max_span(ds, **criteria)['max_span']) * 1e3:.2f}"
    return phrase


def _stepped_over(ds: xr.Dataset) -> str:
    """`sweep design --max-amplitude "1 mm" --over base_frequency_ratio direction`: its row."""
    from sweep.design import max_span
    out = max_span(ds, max_amplitude=1e-3, over=("base_frequency_ratio", "direction"))
    return (f"{float(out['max_span']) * 1e3:.2f} {out['limited_by'].values} "
            f"{float(out['binding_base_frequency_ratio']):g} {out['binding_direction'].values}")


def _stepped(ds: xr.Dataset) -> str:
    def jumps(direction: str, flag: int) -> list[str]:
        out = []
        for length in (0.4, 0.5, 0.6):
            line = ds.sel(direction=direction, length=length)
            ratio = line["base_frequency_ratio"].values[line["jump"].values == flag]
            out.append(f"{ratio[0] if direction == 'up' else ratio[-1]:g}")
        return out
    up, down = jumps("up", 2), jumps("down", 1)
    return (f"f/f1 = {up[0]}, {up[1]} and {up[2]} (0.4, 0.5, 0.6 m), the "
            f"down sweeps jump onto it at {down[0]}, {down[1]} and {down[2]}")


def _base_sine(ds: xr.Dataset) -> str:
    acc = ds["absolute_acceleration_g"].max("base_frequency")
    amp = ds["amplitude"].max("base_frequency") * 1e3
    others = acc.where(ds["length"] > 0.2 + 1e-9, drop=True)
    return (f"the worst midspan acceleration is {float(acc.sel(length=0.2)):.1f} g on the "
            f"0.2 m span (f1 = {float(ds['natural_frequency'].sel(length=0.2)):.0f} Hz, at the "
            f"top of the band) and {float(others.min()):.1f}-{float(others.max()):.1f} g on the "
            f"others; the worst deflection is {float(amp.sel(length=0.2)):.1f} mm at 0.2 m and "
            f"{float(amp.sel(length=0.8)):.1f} mm at 0.8 m")


FIGURES: tuple[Figure, ...] = (
    Figure("paper-fig5", "tail amplitudes of the paper's four spans", _fig5),
    Figure("launch-sine-qualification", "up sweep: peaks and accelerations, spans >= 0.2 m",
           _qual_up),
    Figure("launch-sine-qualification", "down sweep: peaks, spans >= 0.2 m", _qual_down),
    Figure("launch-sine-qualification", "the 0.15 m span, worst of up and down", _qual_short),
    Figure("launch-sine-qualification", "sweep design --min-frequency 100 (mm)",
           _design(min_frequency=100.0)),
    Figure("launch-sine-qualification", "sweep design --max-amplitude 0.002 --min-frequency 40",
           _design(max_amplitude=0.002, min_frequency=40.0)),
    Figure("harness-stepped-sine", "where the up and down sweeps jump", _stepped),
    Figure("harness-stepped-sine", "sweep design --max-amplitude '1 mm' --over "
           "base_frequency_ratio direction", _stepped_over),
    Figure("harness-base-sine", "worst accelerations and deflections", _base_sine),
)
"""Every quoted figure, in README order within each scene."""


def results(scenes: set[str]) -> dict[str, xr.Dataset]:
    """Each scene's fresh result (one run a scene)."""
    import sweep
    return {name: sweep.run(sweep.load_scene(name), progress=False) for name in sorted(scenes)}


def flat(text: str) -> str:
    """Text with every run of white space one space: a phrase is found however the README
    wraps its lines."""
    return " ".join(text.split())


def readme() -> str:
    """README.md, flattened (`flat`)."""
    return flat((ROOT / "README.md").read_text(encoding="utf-8"))


def main(argv: list[str]) -> int:
    wanted = [f for f in FIGURES if not argv or f.scene in argv]
    runs = results({f.scene for f in wanted})
    text = readme()
    stale = 0
    for figure in wanted:
        phrase = figure.phrase(runs[figure.scene])
        ok = flat(phrase) in text
        stale += not ok
        print(f"{'ok   ' if ok else 'STALE'} {figure.scene}: {figure.what}\n      "
              + phrase)
    print(f"{len(wanted) - stale} of {len(wanted)} figures as README.md quotes them")
    return 1 if stale else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
