"""The cost of a launch sine qualification sweep: 5-100 Hz at 2 octaves/min, per span.

What it measures
----------------
The built-in scene launch-sine-qualification swept up only (base.sweep.direction = "up"): 17
clamp spacings 0.15-0.55 m of the Table 1 cable, 2 % damping, tabled levels (1.875-2.5 g),
130 s of simulated time per span, one mode, rtol 1e-8. For RK45 and DOP853, each on the lanes
(the default: 16 sweeps side by side in SIMD lanes) and on the scalar driver (SciPy's
arithmetic, one sweep after another), on 1 and 2 threads: the wall time of `sweep.run` over the
17 spans (warm Numba cache: one run first), best of --repeats, and the seconds per span.

The peer, in the same run: SciPy's `solve_ivp` (same method, same rtol, the per-point atol the
engine uses) on the same chirp, its right-hand side a plain Python closure written here from
the span's kernel row (math.sin, math.exp: docs/model.md sec. 6), on --peer-spans spans
(solve_ivp costs about a minute a span). The table gives SciPy's seconds per span, the
engine's on one thread, their ratio, and how far apart the two peak amplitudes are (both
integrate the same equation at the same tolerances, so they agree to about rtol x the number
of cycles).

Command
-------
    PYTHONPATH=. python benchmarks/sine_sweep_cost.py
    PYTHONPATH=. python benchmarks/sine_sweep_cost.py --repeats 1 --peer-spans 1

Prints Markdown tables and the command line to stdout.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import sweep  # noqa: E402
from bench_common import markdown_table, parameter_table  # noqa: E402
from sweep.kernels import excitation as ex  # noqa: E402
from sweep.kernels import oscillator as osc  # noqa: E402
from sweep.models.transverse import ATOL_SCALE  # noqa: E402

SCENE = "launch-sine-qualification"


def chirp_rhs(row: np.ndarray):
    """f(t, y) of the one-mode System with the row's swept, tabled base excitation, written
    out in Python (the kernel's columns read once): q'' = -(c q' + k0 q + g0 q^3 + h q^5)/m
    - G a_b(t), a_b = A(u) R(t) sin(phi(t)), u = ln w_b + lam t, phi = w_b (exp(lam t) - 1)/lam,
    R the level's rise (1 - cos(pi t / T_r)) / 2 over the first T_r s."""
    m, c, k0, g0, h = (float(row[i]) for i in (osc.MASS, osc.DAMPING, osc.K0, osc.G0, osc.H))
    gamma = float(row[osc.PARTICIPATION])
    b = osc.EXCITATION
    w_b, lam = float(row[b + ex.OMEGA]), float(row[b + ex.RATE])
    log_w, end = float(row[b + ex.LOG_OMEGA]), float(row[b + ex.END])
    n = int(row[b + ex.SEGMENTS])
    edges = [float(row[b + ex.EDGE + k]) for k in range(n)]
    logs = [float(row[b + ex.LOG_LEVEL + k]) for k in range(n)]
    slopes = [float(row[b + ex.SLOPE + k]) for k in range(n)]
    rise = float(row[b + ex.RAMP])

    def rhs(t: float, y: np.ndarray) -> list[float]:
        q, v = y
        a_b = 0.0
        if t <= end:
            u = log_w + lam * t
            k = 0
            while k + 1 < n and u >= edges[k + 1]:
                k += 1
            level = math.exp(logs[k] + slopes[k] * (u - edges[k]))
            if t < rise:                  # the level's rise over the sweep's first cycles
                level *= 0.5 - 0.5 * math.cos(math.pi * t / rise)
            a_b = level * math.sin(w_b * math.expm1(lam * t) / lam)
        return [v, -(c * v + k0 * q + g0 * q ** 3 + h * q ** 5) / m - gamma * a_b]

    return rhs


def scipy_peak(row: np.ndarray, method: str, rtol: float) -> tuple[float, float]:
    """(peak |q| over the sweep (m), wall time (s)) of solve_ivp on the row's chirp, with the
    engine's per-point absolute tolerances (ATOL_SCALE x rtol x the row's scales)."""
    atol = [ATOL_SCALE * rtol * row[osc.Q_SCALE], ATOL_SCALE * rtol * row[osc.V_SCALE]]
    end = float(row[osc.EXCITATION + ex.END])
    began = time.perf_counter()
    sol = solve_ivp(chirp_rhs(row), (0.0, end), [0.0, 0.0], method=method, rtol=rtol,
                    atol=atol)
    took = time.perf_counter() - began
    return float(np.max(np.abs(sol.y[0]))), took


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--peer-spans", type=int, default=2,
                        help="spans solved by SciPy as the peer (about a minute each)")
    args = parser.parse_args()

    cost = []
    runs = {}
    for method in ("rk45", "dop853"):
        for driver in ("lanes", "scalar"):
            scene = sweep.load_scene(SCENE, overrides={"base.sweep.direction": "up",
                                                       "solver.method": method,
                                                       "solver.driver": driver})
            sweep.run(scene, threads=1)                           # compile, warm the cache
            n = scene.axes["length"].size
            for threads in (1, 2):
                best = math.inf
                for _ in range(args.repeats):
                    began = time.perf_counter()
                    ds = sweep.run(scene, threads=threads)
                    best = min(best, time.perf_counter() - began)
                runs[method, driver, threads] = ds
                simulated = float(ds["sweep_duration"]) * n
                cost.append((method.upper(), driver, threads, n, f"{best:.2f}",
                             f"{best / n:.3f}", f"{simulated / best:,.0f}",
                             f"{int(ds['n_steps'].sum()):,}"))
    print(f"## {SCENE}, up sweep, 17 spans ({time.strftime('%Y-%m-%d')})\n")
    print(markdown_table(("method", "driver", "threads", "spans", "wall s", "s per span",
                          "simulated s per wall s", "steps"), cost))

    scene = sweep.load_scene(SCENE, overrides={"base.sweep.direction": "up"})
    oriented = sweep.models.transverse.oriented(sweep.models.transverse.resolve(scene), "up")
    rows = sweep.models.transverse._system(
        oriented, sweep.models.transverse.settings_vector(scene)).rows_at(
        np.arange(scene.axes["length"].size))
    lengths = scene.axes["length"]
    pick = np.linspace(0, lengths.size - 1, args.peer_spans).round().astype(int) \
        if args.peer_spans > 1 else np.array([lengths.size // 2])
    peer = []
    for method in ("rk45", "dop853"):
        ds = runs[method, "lanes", 1]
        per_span = float(ds.attrs["run_seconds"]) / lengths.size
        for i in pick:
            peak, took = scipy_peak(rows[i], method.upper(), float(scene.get("solver.rtol")))
            ours = float(ds["peak_amplitude"].isel(length=i))
            peer.append((method.upper(), f"{lengths[i]:.3f}", f"{took:.1f}", f"{per_span:.3f}",
                         f"{took / per_span:,.0f}x", f"{abs(ours / peak - 1):.1e}"))
    print("\n## Peer: scipy.integrate.solve_ivp on the same chirp, same tolerances\n")
    print(markdown_table(("method", "length (m)", "SciPy s per span",
                          "cable-sweep s per span (lanes, 1 thread, mean)", "ratio",
                          "peak |q| relative difference"), peer))
    print("\nCommand: PYTHONPATH=. python " + " ".join(sys.argv))


if __name__ == "__main__":
    main()
