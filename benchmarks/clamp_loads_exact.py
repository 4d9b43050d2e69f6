"""The clamp's loads of the Galerkin model against the exact continuous beam, mode by mode.

What it measures
----------------
A linear span (clamps.axial_stiffness = 0: no stretching; the Table 1 bundle's data as the
built-in harness scenes give them, 0.3 m, damping ratio 0.005 and t_end = 15 / (zeta w1), the
tail window its last 20 %, so that the start's free vibration has decayed by e^-12 there)
shaken at 0.1 g below, near and above its first natural frequency, with pinned, clamped and
elastic clamps (rotational stiffness --stiffness N m/rad), each with
model.modes = 1, 3, 5 and 7 through the public API (`sweep.run`, the scene's own modal
drivers). Each output is its peak over the tail window; the reference is the exact
steady-state of the Euler-Bernoulli beam under a uniform base acceleration, undamped
(w = particular + cosh, sinh, cos, sin terms, the four end conditions solved as a
4 x 4 system in tests/exact_beam.py, which the tests share): midspan deflection |w(l/2)|,
clamp moment |EI w''(0)| and transverse reaction |EI w'''(0)| (no stretching, no end load:
V = -EI w'''). The Galerkin answer converges to it with the modes; this table shows how
fast, so that a user can choose model.modes (or run `sweep modes`). The damping (0.5 % of
critical) moves the exact values by about 1e-4 at these ratios, which stay clear of each
excited mode's resonance.

Command
-------
    PYTHONPATH=. python benchmarks/clamp_loads_exact.py [--length 0.3] [--stiffness 0.1]
        [--ratios 0.3 0.7 1.4 2.0] [--modes 1 3 5 7]

Prints a Markdown table: the relative error of each output (tool / exact - 1).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import exact_beam  # noqa: E402

from bench_common import machine, markdown_table  # noqa: E402

import sweep  # noqa: E402

LINEAR_MASS = 0.0534        # kg/m, rho A (the harness scenes' "53.4 g/m")
BENDING = 0.31515           # N m^2, EI
G_LEVEL = 0.1               # g, base acceleration amplitude
G0 = 9.80665                # m/s^2
DAMPING = 0.005             # damping ratio (SCENE's)


def _cases(stiffness: float) -> list[tuple[str, dict]]:
    return [("pinned", {"clamps.rotation": "pinned"}),
            ("clamped", {"clamps.rotation": "clamped"}),
            (f"elastic {stiffness:g} N m/rad", {"clamps.rotation": "elastic",
                                               "clamps.rotational_stiffness": stiffness})]


def exact(omega: float, l: float, k_end: float | None) -> tuple[float, float, float]:
    """(|w(l/2)|, |EI w''(0)|, |EI w'''(0)|) of the undamped beam's steady state under a base
    acceleration of amplitude G_LEVEL g at omega (rad/s) (tests/exact_beam.py: the closed
    form, written independently of the tool)."""
    return exact_beam.steady_loads(omega, G_LEVEL * G0, l, LINEAR_MASS, BENDING, k_end)


def first_frequency(l: float, k_end: float | None) -> float:
    """The exact first natural frequency (rad/s) (tests/exact_beam.py)."""
    return exact_beam.first_frequency(l, LINEAR_MASS, BENDING, k_end)


SCENE = exact_beam.BUNDLE_SCENE
"""The linear bundle span (tests/exact_beam.py), its axes set per run."""


def tool(l: float, over: dict, modes: int, ratios: list[float], t_end: float):
    """The tool's dataset of the linear span (SCENE) at `ratios` x its own f1."""
    scene = sweep.load_scene_text(SCENE, overrides={
        **over, "axes.length": [l], "axes.base_frequency_ratio": ratios,
        "model.modes": modes, "solver.t_end": t_end, "run.threads": 1})
    return sweep.run(scene, progress=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--length", type=float, default=0.3, help="m")
    parser.add_argument("--stiffness", type=float, default=0.1, help="N m/rad, elastic ends")
    parser.add_argument("--ratios", type=float, nargs="+", default=[0.3, 0.7, 1.4, 2.0])
    parser.add_argument("--modes", type=int, nargs="+", default=[1, 3, 5, 7])
    args = parser.parse_args()
    print(f"Machine: {machine()}\n")
    rows = []
    for name, over in _cases(args.stiffness):
        k_end = {"pinned": 0.0, "clamped": None}.get(name, args.stiffness)
        w1 = first_frequency(args.length, k_end)
        t_end = 15.0 / (DAMPING * w1)
        for modes in args.modes:
            ds = tool(args.length, over, modes, args.ratios, t_end)
            for r in args.ratios:
                point = ds.sel(base_frequency_ratio=r).squeeze()
                ref = exact(r * w1, args.length, k_end)
                got = [float(point["amplitude"])]
                got += [float(point[v]) if v in point else 0.0
                        for v in ("clamp_moment", "clamp_force")]
                errors = [f"{g / e - 1.0:+.2%}" if e > 0 else "-" for g, e in zip(got, ref)]
                if k_end == 0.0:
                    errors[1] = "(0)"
                rows.append([name, modes, r, *errors])
    print(f"Linear {args.length} m span, {G_LEVEL} g base sine, damping 0.5 %: tool / exact "
          "beam - 1\n")
    print(markdown_table(["clamps", "modes", "f / f1", "midspan deflection", "clamp moment",
                          "clamp force"], rows))


if __name__ == "__main__":
    main()
