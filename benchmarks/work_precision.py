"""Work-precision of cable-sweep against SciPy RK45/DOP853, numbalsoda dop853/lsoda and diffrax.

Wall time against the error of what a user reads (amplitude, settling time and state, final
state), on the same points, on the same machine, in the same run; it also picks the default
rtol.

What it measures
----------------
Reference points: the consistent model (Table 1 cable defaults, damping ratio 0.02, harmonic
end load 4 N) on lengths 0.3, 0.5, 0.7, 1.0 m x frequency ratios W/w1 0.8, 1.0, 1.9, 2.0, 2.5
(--lengths, --ratios), from q0 = 1e-3 m at rest, t in [0, 5] s. Tail window [2.5, 5] s and
tolerance 0.02: the scene defaults (metrics.tail, metrics.tolerance).

Reference solution: SciPy `solve_ivp(method="DOP853", rtol=1e-13, atol=1e-16,
dense_output=True)`, its metrics computed by `reference_metrics.response_metrics` on the dense
output: every extremum of q (sign changes of q' on a 20001-point grid, located with brentq),
tail amplitude (max |q| over the tail's extrema and the window ends), peak, state (decayed /
steady / modulated / unsettled) and settling time, with the kernel's definitions (README "What
the output holds"; `kernels/metrics.py`) written independently. Also q(5). A second DOP853 run
at 10x looser tolerances (rtol 1e-12, atol 1e-15) is compared with it and printed as the
reference's own uncertainty.

For each rtol of --rtols (default 1e-3, 1e-4, ..., 1e-12) with atol = rtol * 1e-4, floored at
1e-16 (--atol-factor; or one fixed atol for all with --atol). The factor 1e-4 keeps the scene
default pair (rtol 1e-8, atol 1e-12) on the curve; with q ~ 1e-3 m it makes the relative
tolerance govern until |q| falls ~10x below q0.
  - cable-sweep: `sweep.run.solve_points` on all points, on 1 thread and on 2 threads (wall time
    for the set: best of repeats filling >= 0.2 s, after a compile warm-up that is reported
    separately; the --pi and --dop853 kernels are warmed up too). Amplitude, state and settling
    time are the kernel's own outputs; q(5) comes from the `displacement` time series with
    sample_interval = t_end (samples at t = 0 and 5 s).
  - with --pi / --dop853, cable-sweep again with solver.controller = "pi" / solver.method =
    "dop853" (its own curve, timed the same way).
  - SciPy RK45 and DOP853 (`solve_ivp`, plain Python right-hand side), one point at a time,
    dense_output=True, one timed run per point, 1 thread. Their amplitude, state and settling
    time come from `reference_metrics` on their own dense output (not timed).
  - numbalsoda (optional extra: `pip install numbalsoda`; skipped with a message if it is not
    importable) `dop853` and `lsoda`: a Numba `cfunc` right-hand side with numbalsoda's
    signature that calls the System's own right-hand side (`kernels.oscillator.acceleration`,
    njit, libm's cos) on the point's parameter row prepared by `kernels.oscillator.prepare`,
    passed through the data pointer (one more slot of the padded row counts right-hand-side
    calls: no measurable cost), called from an `@njit(parallel=True)` prange loop over all
    points, in the same shuffled order as cable-sweep's (`sweep.run.point_order`, which spreads
    the costly points over the threads); each call returns q, q' on --ns-samples (20001) evenly
    spaced times on [0, 5] s (numbalsoda has no dense-output object; its 0.3.4 `dop853`
    integrates [0, 5] s once and fills the output times from DOP853's dense output, `lsoda`
    interpolates to each output time). Timed like cable-sweep (the prange loop, best of repeats,
    after a compile warm-up) on 1 and on 2 Numba threads. The timed loop includes filling the
    output times, which a user needs to read amplitude and settling time: about a quarter of
    dop853's time at rtol 1e-8 with 20001 samples (measured during development against 2001
    samples); --ns-samples 5001 costs less, with an interpolation floor of ~3e-11 on the
    amplitude. The metrics are then taken from the samples (not timed): q'' at each sample from
    the right-hand side (`kernels.oscillator.acceleration.py_func`), a piecewise quintic Hermite
    interpolant through (q, q', q'') (`reference_metrics.HermiteSamples`) and
    `reference_metrics` on it, with the sample times as the bracketing grid: the same
    definitions applied to the sampled signal. Its interpolation error is ~(w dt)^6/46080 of the
    amplitude: applied to the reference solution sampled the same way it changes the amplitudes
    by <= 1.1e-13 relative (non-decayed points), settling times by ~1e-13 t_end, and no state.
    The plain max of the samples would underestimate the amplitude by up to (w dt)^2/8 (2.5e-5
    measured at 20001 samples), far above the errors compared here. numbalsoda reports no step
    counts: "mean steps" is empty.
  - diffrax (optional extra: `pip install jax diffrax`; skipped with a message if it is not
    importable; --no-diffrax) Tsit5, Dopri5 and Dopri8: `jax.jit(jax.vmap(...))` of
    `diffeqsolve` over all points on one single-threaded CPU device (1 thread) and `jax.pmap`
    of it over two (2 threads), PIDController with the same rtol/atol, its dense output
    evaluated on the --ns-samples times afterwards (not timed); metrics as numbalsoda's. See
    the `Diffrax` class.
Reported per method and rtol: wall time for the set (1 thread; 2 threads for cable-sweep and
numbalsoda), mean accepted steps, mean right-hand-side evaluations, max relative amplitude
error |A - A_ref| / A_ref, the settling-time error max |Ts - Ts_ref| / t_end over the points
whose reference state has a settling time (decayed, steady) and whose result has one, the
number of points whose state differs from the reference's, and the max relative final-state
error |q(5) - q_ref(5)| / max|q_ref|.

Decayed points. With 2 % damping the short spans off resonance decay by ~1e-9 before the tail
window (l = 0.3 m: A_ref ~ 7e-12 m from q0 = 1e-3 m); there the amplitude is set by atol, not
rtol, and even the reference is only good to ~1e-6 relative. Points whose reference amplitude
is <= metrics.tolerance (0.02) x peak, the kernel's own "decayed" test, are therefore left out of
the amplitude-error column `amp err`, the recommendation and the equal-error ratios;
`amp err (all)` includes them. --include-decayed applies the recommendation to all points.

Recommendation: the largest rtol (cheapest) whose cable-sweep max relative amplitude error is
below --threshold (1e-6) on every (non-decayed) reference point, and stays below it for every
tighter rtol in the list too (so a loose rtol that passes by luck is not picked).

Equal-error ratios: the error target is the max amplitude error cable-sweep reaches at
--target-rtol (1e-8, the default rtol; the nearest rtol run otherwise). Each method's wall time
at that error is interpolated linearly in log(wall) against log(error) between the two rtols
that bracket it (the first crossing from the loose end); cable-sweep's speed ratio against each
peer at 1 thread (and at 2 threads against numbalsoda) is printed. Then, for each amplitude
error of --errors (1e-3 .. 1e-11), the fastest cable-sweep method and the fastest peer there,
on 1 and on 2 threads, and their ratio (`fastest_report`).

Command (full size; run on an otherwise idle machine with >= 2 cores; a few minutes, mostly
SciPy RK45 and the metrics extraction of the SciPy runs)
--------------------------------------------------------------------------------------------
    PYTHONPATH=. python benchmarks/work_precision.py --plot work_precision.png \
        --json work_precision.json

Small check: python benchmarks/work_precision.py --rtols 1e-4,1e-8 --lengths 0.5,1.0 \
    --ratios 1.0,2.0
Prints Markdown tables to stdout; --plot PATH saves wall time vs max amplitude error and vs
settling-time error (PNG, two panels).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common, reference_metrics

from bench_common import (best_time, markdown_table, parameter_table,  # noqa: E402
                          solve_scipy, write_json)
from sweep.kernels import oscillator as osc  # noqa: E402
from reference_metrics import (HAS_SETTLING, HermiteSamples, response_metrics,  # noqa: E402
                               self_check)
from sweep.run import (KernelResult, grid_order, point_order, sample_times,  # noqa: E402
                       settings_vector, solve_points)
from sweep.scene import Scene, load_scene_text  # noqa: E402

T_END = 5.0
DEFAULT_RTOLS = "1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12"
ATOL_FLOOR = 1e-16
CABLE = "cable-sweep"
CABLE_PI = "cable-sweep (PI)"      # solver.controller = "pi"
CABLE_DOP853 = "cable-sweep (DOP853)"   # solver.method = "dop853"
NS_MAX_STEPS = 2_000_000_000        # numbalsoda mxstep (a C int): no practical bound
NS_COUNTER = osc.N_PARAMS           # slot of the RHS-call counter in a numbalsoda data row,
                                    # after the prepared parameter row
NS_TERMS = (True, None)             # the oscillator's (parametric, base) in the numbalsoda rhs: the
                                    # cos(W t) load terms, no base excitation (this scene has none)
NS_ROW = (NS_COUNTER + 8) // 8 * 8  # data row length: whole 64-byte lines, so that one point's
                                    # counter never shares a cache line with another point's row
DX_MAX_STEPS = 100_000              # diffrax's step bound (its dense output is stored per step)
TIE = 1.01                          # equal-error: an error within 1 % of the target reaches it

SCENE = """
name = "work-precision"
description = "Benchmark: consistent model, Table 1 cable, 2 % damping, reference points"

[model]
kind = "transverse"
coefficients = "consistent"

[cable]
damping_ratio = 0.02

[load]
type = "harmonic"
amplitude = 4.0

[initial]
displacement = 1e-3
velocity = 0.0

[axes]
length = {lengths}
frequency_ratio = {ratios}

[solver]
t_end = 5.0

[outputs]
time_series = true
sample_interval = 5.0
"""


@dataclass
class Reference:
    """Reference quantities per point."""
    amplitude: np.ndarray      # max |q| over the tail window (m)
    peak: np.ndarray           # max |q| over [0, 5] s (m)
    q_end: np.ndarray          # q(5) (m)
    steps: np.ndarray          # accepted DOP853 steps
    state: np.ndarray          # state names (reference_metrics)
    settling: np.ndarray       # settling time (s) or NaN


@dataclass
class Measurement:
    """One method at one tolerance, over all points."""
    method: str
    rtol: float
    atol: float
    wall_s: float              # 1 thread
    steps: np.ndarray          # accepted steps per point (NaN: not reported by the solver)
    rhs_evals: np.ndarray      # right-hand-side evaluations per point
    amplitude: np.ndarray
    q_end: np.ndarray
    state: np.ndarray          # state names
    settling: np.ndarray       # settling time (s) or NaN
    wall2_s: float = math.nan  # 2 threads (cable-sweep and numbalsoda only)
    notes: list[str] = field(default_factory=list)


@dataclass
class Settings:
    """What every method needs to know about the metrics."""
    tail: float
    tol: float
    ns_samples: int


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rtols", default=DEFAULT_RTOLS, help="comma-separated rtols")
    p.add_argument("--atol-factor", type=float, default=1e-4,
                   help="atol = rtol * factor, floored at 1e-16 (default 1e-4)")
    p.add_argument("--atol", type=float, help="one fixed atol for every rtol instead")
    p.add_argument("--lengths", default="0.3,0.5,0.7,1.0", help="span lengths (m)")
    p.add_argument("--ratios", default="0.8,1.0,1.9,2.0,2.5", help="frequency ratios W/w1")
    p.add_argument("--ref-rtol", type=float, default=1e-13, help="reference DOP853 rtol")
    p.add_argument("--ref-atol", type=float, default=1e-16, help="reference DOP853 atol")
    p.add_argument("--threshold", type=float, default=1e-6,
                   help="max relative amplitude error of the recommended rtol (default 1e-6)")
    p.add_argument("--include-decayed", action="store_true",
                   help="judge the recommendation on decayed points too")
    p.add_argument("--target-rtol", type=float, default=1e-8,
                   help="equal-error target: cable-sweep's amplitude error at this rtol "
                        "(default 1e-8)")
    p.add_argument("--ns-samples", type=int, default=20001,
                   help="numbalsoda output times on [0, t_end] (default 20001)")
    p.add_argument("--pi", action="store_true",
                   help="also run cable-sweep with the PI controller (solver.controller = pi)")
    p.add_argument("--dop853", action="store_true",
                   help="also run cable-sweep with DOP853 (solver.method = dop853)")
    p.add_argument("--no-numbalsoda", action="store_true", help="skip the numbalsoda peers")
    p.add_argument("--no-diffrax", action="store_true", help="skip the diffrax (JAX) peers")
    p.add_argument("--errors", default="1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11",
                   help="amplitude errors of the fastest-method table (comma-separated)")
    p.add_argument("--no-scipy", action="store_true",
                   help="skip the SciPy peers (quick checks only)")
    p.add_argument("--plot", metavar="PATH", help="save the work-precision plot as PNG")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    return p.parse_args()


def floats(text: str) -> list[float]:
    return [float(s) for s in text.split(",") if s.strip()]


def atol_for(rtol: float, args: argparse.Namespace) -> float:
    """The atol paired with `rtol`: fixed --atol, else rtol * --atol-factor (floor 1e-16)."""
    if args.atol is not None:
        return args.atol
    return max(rtol * args.atol_factor, ATOL_FLOOR)


def build_scene(lengths: list[float], ratios: list[float]) -> Scene:
    """The reference points' scene (tolerances are overridden per run)."""
    text = SCENE.format(lengths=lengths, ratios=ratios)
    return load_scene_text(text, source="work_precision.py")


def acceleration(row: np.ndarray, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """q'' (m/s^2) of the oscillator at samples (t (s), q (m), q' (m/s)) of one point, from its
    raw parameter row `row`: the System's own right-hand side (`kernels.oscillator.acceleration`,
    its pure-Python form, libm's cos and sin) on the row prepared as the kernels prepare it,
    looped over the samples."""
    prepared = np.empty(osc.N_PARAMS)
    osc.prepare.py_func(row, prepared, 0, 1)
    p = [float(x) for x in prepared]                  # list indexing: Python floats
    terms = osc.terms_of(parametric=True, base=bool(row[osc.BASE_ACCEL] != 0.0))
    rhs = osc.acceleration.py_func
    return np.array([rhs(ti, qi, vi, p, 0, 1, None, *terms)
                     for ti, qi, vi in zip(t.tolist(), q.tolist(), v.tolist())])


def reference_solution(table: np.ndarray, rtol: float, atol: float, cfg: Settings) -> Reference:
    """DOP853 at tight tolerances and reference_metrics on its dense output, per point."""
    n = len(table)
    amp, peak, q_end, steps, settling = (np.empty(n) for _ in range(5))
    state = np.empty(n, dtype=object)
    for i, row in enumerate(table):
        sol = solve_scipy(row, T_END, rtol, atol, method="DOP853", dense=True)
        m = response_metrics(sol.sol, T_END, cfg.tail, cfg.tol)
        amp[i], peak[i], settling[i], state[i] = m.amplitude, m.peak, m.settling_time, m.state
        q_end[i] = sol.y[0, -1]
        steps[i] = len(sol.t) - 1
    return Reference(amp, peak, q_end, steps, state, settling)


def variant(scene: Scene, overrides: dict[str, object]) -> Scene:
    """The scene with some keys overridden (solver.rtol, solver.method, ...)."""
    return load_scene_text(scene.to_toml(), source="work_precision.py", overrides=overrides)


def run_cable_sweep(table: np.ndarray, scene: Scene, rtol: float, atol: float,
                    controller: str = "scipy", method: str = "rk45") -> Measurement:
    """cable-sweep on all points: best wall time on 1 and on 2 threads, and its outputs."""
    from sweep.kernels import metrics as mt
    from sweep.kernels import transverse as tk
    tuned = variant(scene, {"solver.rtol": rtol, "solver.atol": atol,
                            "solver.controller": controller, "solver.method": method})
    settings = settings_vector(tuned)
    times = sample_times(settings[tk.T_END], settings[tk.SAMPLE_DT])
    assert times[-1] == T_END, times
    result: list[KernelResult] = []

    def once(threads: int) -> None:
        result.append(solve_points(table, settings, times.size, threads=threads))

    wall = best_time(lambda: once(1))
    last = result[-1]
    wall2 = best_time(lambda: once(2)) if max_threads() >= 2 else math.nan
    name = CABLE_DOP853 if method == "dop853" else CABLE if controller == "scipy" else CABLE_PI
    m = Measurement(name, rtol, atol, wall, last.counts[:, tk.STEPS].astype(float),
                    last.counts[:, tk.RHS_EVALS].astype(float),
                    last.reals[:, tk.AMPLITUDE].copy(), last.series[:, -1].copy(),
                    np.array([mt.STATE_MEANINGS[s] for s in last.states], dtype=object),
                    last.reals[:, tk.SETTLING].copy(), wall2)
    if not np.array_equal(result[-1].reals, last.reals, equal_nan=True):
        m.notes.append("2-thread outputs differ from 1-thread outputs")
    return m


def run_scipy(table: np.ndarray, method: str, rtol: float, atol: float,
              cfg: Settings) -> Measurement:
    """SciPy `method` one point at a time (dense output on); the solves alone are timed."""
    n = len(table)
    wall = 0.0
    steps, evals, amp, q_end, settling = (np.empty(n) for _ in range(5))
    state = np.empty(n, dtype=object)
    for i, row in enumerate(table):
        start = time.perf_counter()
        sol = solve_scipy(row, T_END, rtol, atol, method=method, dense=True)
        wall += time.perf_counter() - start
        steps[i] = len(sol.t) - 1
        evals[i] = sol.nfev
        m = response_metrics(sol.sol, T_END, cfg.tail, cfg.tol)
        amp[i], settling[i], state[i] = m.amplitude, m.settling_time, m.state
        q_end[i] = sol.y[0, -1]
    return Measurement(f"SciPy {method}", rtol, atol, wall, steps, evals, amp, q_end, state,
                       settling)


def max_threads() -> int:
    import numba
    return int(numba.config.NUMBA_NUM_THREADS)


# --- numbalsoda ------------------------------------------------------------------------------

class Numbalsoda:
    """numbalsoda's dop853 and lsoda over all points from a Numba prange loop.

    The right-hand side is a `cfunc` with numbalsoda's signature rhs(t, u, du, p) that calls the
    System's own `kernels.oscillator.acceleration` (njit, inlined; libm's cos: fast=None;
    terms NS_TERMS). p points to one row of `data`: the point's parameter row prepared by
    `kernels.oscillator.prepare` (columns 0 .. N_PARAMS - 1), and at NS_COUNTER a counter of
    calls (rows padded to NS_ROW doubles: no false sharing between threads).
    """

    SOLVERS = ("dop853", "lsoda")

    def __init__(self) -> None:
        import numba as nb
        from numbalsoda import dop853, lsoda, lsoda_sig

        assert NS_COUNTER < NS_ROW
        acceleration = osc.acceleration

        @nb.cfunc(lsoda_sig)
        def rhs(t, u, du, p):
            q = u[0]
            v = u[1]
            du[0] = v
            du[1] = acceleration(t, q, v, p, 0, 1, None, True, None)  # NS_TERMS
            p[NS_COUNTER] += 1.0

        def make_loop(solver):
            @nb.njit(parallel=True)
            def loop(funcptr, data, u0, t_eval, rtol, atol, out, ok):
                for i in nb.prange(data.shape[0]):
                    data[i, NS_COUNTER] = 0.0
                    usol, success = solver(funcptr, u0[i], t_eval, data=data[i], rtol=rtol,
                                           atol=atol, mxstep=NS_MAX_STEPS)
                    out[i] = usol
                    ok[i] = success
            return loop

        self.rhs = rhs
        self.funcptr = rhs.address
        self.loops = {"dop853": make_loop(dop853), "lsoda": make_loop(lsoda)}

    def warm_up(self, table: np.ndarray, t_eval: np.ndarray) -> float:
        """Compile both loops; returns the wall time of that."""
        start = time.perf_counter()
        for name in self.SOLVERS:
            self.solve(name, table[:1], t_eval, 1e-3, 1e-7, threads=1)
        return time.perf_counter() - start

    def solve(self, name: str, table: np.ndarray, t_eval: np.ndarray, rtol: float, atol: float,
              threads: int, timed: bool = False):
        """(samples (n, nt, 2), success (n,), rhs calls (n,), best wall time or NaN), in the
        order of `table`; solved in cable-sweep's shuffled point order."""
        import numba
        n = len(table)
        order = point_order(n)
        if np.any(table[:, osc.BASE_ACCEL] != 0.0):
            raise ValueError("Numbalsoda: the rhs is compiled without base excitation "
                             "(NS_TERMS) but a row has base_accel != 0")
        data = np.zeros((n, NS_ROW))
        for i, row in enumerate(table[order]):
            osc.prepare.py_func(row, data[i], 0, 1)
        u0 = np.ascontiguousarray(table[order][:, [osc.Q0, osc.V0]])
        out = np.empty((n, t_eval.size, 2))
        ok = np.zeros(n, dtype=np.bool_)
        loop = self.loops[name]
        numba.set_num_threads(threads)

        def once() -> None:
            loop(self.funcptr, data, u0, t_eval, rtol, atol, out, ok)

        wall = best_time(once) if timed else math.nan
        if not timed:
            once()
        back = grid_order(order)
        return out[back], ok[back], data[back, NS_COUNTER], wall


def run_numbalsoda(ns: Numbalsoda, name: str, table: np.ndarray, rtol: float, atol: float,
                   cfg: Settings) -> Measurement:
    """numbalsoda `name` on all points, timed on 1 and 2 threads; metrics from the samples."""
    t_eval = np.linspace(0.0, T_END, cfg.ns_samples)
    out, ok, evals, wall = ns.solve(name, table, t_eval, rtol, atol, threads=1, timed=True)
    wall2 = math.nan
    notes = []
    if max_threads() >= 2:
        out2, ok2, _, wall2 = ns.solve(name, table, t_eval, rtol, atol, threads=2, timed=True)
        if not (np.array_equal(out, out2, equal_nan=True) and np.array_equal(ok, ok2)):
            notes.append("2-thread outputs differ from 1-thread outputs")
    return sampled_measurement(f"numbalsoda {name}", rtol, atol, table, t_eval, out, ok, evals,
                               np.full(len(table), math.nan), wall, wall2, notes, cfg)


def sampled_measurement(method: str, rtol: float, atol: float, table: np.ndarray,
                        t_eval: np.ndarray, out: np.ndarray, ok: np.ndarray, evals: np.ndarray,
                        steps: np.ndarray, wall: float, wall2: float, notes: list[str],
                        cfg: Settings) -> Measurement:
    """A peer's Measurement from its samples out (n, nt, 2) of q, q' at t_eval: the metrics of
    `reference_metrics` on a quintic Hermite interpolant through (q, q', q'') (not timed)."""
    n = len(table)
    amp, q_end, settling = (np.full(n, math.nan) for _ in range(3))
    state = np.full(n, "solver_failed", dtype=object)
    for i, row in enumerate(table):
        if not ok[i]:
            continue
        q, v = out[i, :, 0], out[i, :, 1]
        dense = HermiteSamples(t_eval, q, v, acceleration(row, t_eval, q, v))
        m = response_metrics(dense, T_END, cfg.tail, cfg.tol, grid=t_eval)
        amp[i], settling[i], state[i] = m.amplitude, m.settling_time, m.state
        q_end[i] = q[-1]
    if not ok.all():
        notes.append(f"{int((~ok).sum())} points failed")
    return Measurement(method, rtol, atol, wall, steps, evals, amp, q_end, state, settling,
                       wall2, notes)


# --- diffrax ---------------------------------------------------------------------------------

class Diffrax:
    """diffrax (JAX) Tsit5, Dopri5 and Dopri8 over all points: `jax.jit(jax.vmap(solve))` on one
    CPU device for 1 thread, `jax.pmap` of that over two devices (the points split in halves)
    for 2 threads. JAX is told, before it is imported, to make two host devices of one thread
    each (XLA_FLAGS). The right-hand side is the oscillator's (kernels.oscillator.acceleration
    with the cos(W t) load terms) written in jax.numpy on the point's prepared row. PIDController
    with SciPy's rtol/atol (an RMS norm, as SciPy's), SaveAt(dense=True): the timed call is the
    solve with its dense output, as cable-sweep's reads its metrics off its own; the samples on
    the --ns-samples times are evaluated from it afterwards (not timed; SaveAt(ts=...) on 20 001
    times made the solve itself several times slower), the metrics from those samples.
    Steps: diffrax's num_accepted_steps; RHS evaluations: its num_steps (accepted and rejected) x the stages a step costs (FSAL counted
    once: Tsit5 and Dopri5 6, Dopri8 13)."""

    SOLVERS = ("Tsit5", "Dopri5", "Dopri8")
    RHS_PER_STEP = {"Tsit5": 6, "Dopri5": 6, "Dopri8": 13}

    def __init__(self) -> None:
        import os
        if "jax" not in sys.modules:
            os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "")
                                       + " --xla_force_host_platform_device_count=2"
                                       " --xla_cpu_multi_thread_eigen=false"
                                       " intra_op_parallelism_threads=1")
        import jax
        jax.config.update("jax_enable_x64", True)
        import diffrax
        import jax.numpy as jnp
        self.jax, self.jnp, self.diffrax = jax, jnp, diffrax
        self.fns: dict = {}

    def _compiled(self, name: str, n_eval: int):
        key = (name, n_eval)
        if key in self.fns:
            return self.fns[key]
        jax, jnp, dfx = self.jax, self.jnp, self.diffrax

        def rhs(t, y, P):
            q, v = y[0], y[1]
            cw = jnp.cos(P[osc.OMEGA] * t + P[osc.LOAD_PHASE])
            q2 = q * q
            a = ((P[osc.K0] + P[osc.K1] * cw) * q + (P[osc.G0] + P[osc.G1] * cw) * q * q2
                 + P[osc.H] * q * q2 * q2 + P[osc.DAMPING] * v)
            return jnp.stack([v, a])

        solver = getattr(dfx, name)()

        def one(P, y0, rtol, atol):
            sol = dfx.diffeqsolve(dfx.ODETerm(rhs), solver, 0.0, T_END, None, y0, args=P,
                                  saveat=dfx.SaveAt(dense=True),
                                  stepsize_controller=dfx.PIDController(rtol=rtol, atol=atol),
                                  max_steps=DX_MAX_STEPS, throw=False)
            return sol

        def samples(sol, ts):
            return (jax.vmap(sol.evaluate)(ts), sol.result == dfx.RESULTS.successful,
                    sol.stats["num_accepted_steps"], sol.stats["num_steps"])

        batched = jax.vmap(one, in_axes=(0, 0, None, None))
        sampled = jax.vmap(samples, in_axes=(0, None))
        fns = (jax.jit(batched), jax.pmap(batched, in_axes=(0, 0, None, None)),
               jax.jit(sampled), jax.pmap(sampled, in_axes=(0, None)))
        self.fns[key] = fns
        return fns

    def warm_up(self, table: np.ndarray, t_eval: np.ndarray) -> float:
        """Compile every solver on 1 and 2 devices; returns the wall time of that."""
        start = time.perf_counter()
        for name in self.SOLVERS:
            for threads in (1, 2):
                self.solve(name, table, t_eval, 1e-3, 1e-7, threads)
        return time.perf_counter() - start

    def solve(self, name: str, table: np.ndarray, t_eval: np.ndarray, rtol: float, atol: float,
              threads: int, timed: bool = False):
        """(samples (n, nt, 2), success (n,), accepted steps (n,), steps (n,), best wall
        time or NaN)."""
        jnp = self.jnp
        n = len(table)
        if np.any(table[:, osc.BASE_ACCEL] != 0.0):
            raise ValueError("Diffrax: the rhs has no base excitation but a row has one")
        P = np.zeros((n, osc.N_PARAMS))
        for i, row in enumerate(table):
            osc.prepare.py_func(row, P[i], 0, 1)
        y0 = np.ascontiguousarray(table[:, [osc.Q0, osc.V0]])
        single, parallel, sample_single, sample_parallel = self._compiled(name, t_eval.size)
        ts = jnp.asarray(t_eval)
        if threads == 1:
            args = (jnp.asarray(P), jnp.asarray(y0))
            fn, sample = single, sample_single
        else:
            half = (n + 1) // 2
            pad = 2 * half - n
            P2 = np.concatenate([P, P[:pad]]).reshape(2, half, -1)
            y2 = np.concatenate([y0, y0[:pad]]).reshape(2, half, 2)
            args = (jnp.asarray(P2), jnp.asarray(y2))
            fn, sample = parallel, sample_parallel

        def once():
            result = fn(*args, rtol, atol)
            self.jax.block_until_ready(result)
            return result

        wall = best_time(once) if timed else math.nan
        ys, ok, accepted, steps = (np.asarray(x) for x in sample(once(), ts))
        if threads != 1:
            ys, ok, accepted, steps = (x.reshape((-1,) + x.shape[2:])[:n]
                                       for x in (ys, ok, accepted, steps))
        return ys, ok, accepted.astype(float), steps.astype(float), wall


def run_diffrax(dx: Diffrax, name: str, table: np.ndarray, rtol: float, atol: float,
                cfg: Settings) -> Measurement:
    """diffrax `name` on all points, timed on 1 and 2 devices; metrics from the samples."""
    t_eval = np.linspace(0.0, T_END, cfg.ns_samples)
    out, ok, accepted, steps, wall = dx.solve(name, table, t_eval, rtol, atol, 1, timed=True)
    notes = []
    out2, ok2, _, _, wall2 = dx.solve(name, table, t_eval, rtol, atol, 2, timed=True)
    if not np.allclose(out, out2, rtol=1e-12, atol=0.0, equal_nan=True):
        notes.append("2-device outputs differ from 1-device outputs beyond 1e-12")
    evals = steps * Diffrax.RHS_PER_STEP[name]
    return sampled_measurement(f"diffrax {name}", rtol, atol, table, t_eval, out, ok, evals,
                               accepted, wall, wall2, notes, cfg)


# --- errors and reporting --------------------------------------------------------------------

def amplitude_errors(amplitude: np.ndarray, ref: Reference) -> np.ndarray:
    """|A - A_ref| / A_ref per point (inf where the method gave no finite amplitude)."""
    err = np.abs(amplitude - ref.amplitude) / ref.amplitude
    return np.where(np.isfinite(err), err, np.inf)


def final_state_errors(q_end: np.ndarray, ref: Reference) -> np.ndarray:
    """|q(5) - q_ref(5)| / max|q_ref| per point."""
    err = np.abs(q_end - ref.q_end) / ref.peak
    return np.where(np.isfinite(err), err, np.inf)


def settling_errors(m: Measurement, ref: Reference) -> np.ndarray:
    """|Ts - Ts_ref| / t_end on points where both the reference and `m` have a settling time
    (NaN elsewhere)."""
    has = np.isin(ref.state, HAS_SETTLING) & np.isfinite(m.settling)
    return np.where(has, np.abs(m.settling - ref.settling) / T_END, math.nan)


def state_mismatches(m: Measurement, ref: Reference) -> int:
    return int(np.sum(m.state != ref.state))


def max_amp_err(m: Measurement, ref: Reference, judged: np.ndarray) -> float:
    return float(np.max(amplitude_errors(m.amplitude, ref)[judged], initial=0.0))


def max_ts_err(m: Measurement, ref: Reference) -> float:
    err = settling_errors(m, ref)
    return float(np.nanmax(err)) if np.any(np.isfinite(err)) else math.nan


def recommend(runs: list[Measurement], ref: Reference, judged: np.ndarray,
              threshold: float) -> float | None:
    """Largest cable-sweep rtol whose amplitude error (on `judged` points) is below `threshold`
    for it and for every tighter rtol; None if even the tightest fails."""
    best = None
    for m in sorted((m for m in runs if m.method == CABLE), key=lambda m: m.rtol):
        if max_amp_err(m, ref, judged) < threshold:
            best = m.rtol
        else:
            break
    return best


def step_agreement(runs: list[Measurement], n: int) -> str:
    """A line: on how many points cable-sweep and SciPy RK45 took the same accepted steps."""
    parts = []
    for m in runs:
        if m.method != CABLE:
            continue
        rk = next((r for r in runs if r.method == "SciPy RK45" and r.rtol == m.rtol), None)
        if rk is None:
            continue
        diff = np.abs(m.steps - rk.steps)
        parts.append(f"rtol {m.rtol:.0e}: {int(np.sum(diff == 0))}/{n}"
                     + (f" (max diff {int(diff.max())})" if diff.max() > 0 else ""))
    return "Accepted steps equal, cable-sweep vs SciPy RK45: " + "; ".join(parts) + "."


def warm_up(table: np.ndarray, scene: Scene) -> float:
    """Compile (or load from cache) the kernel; returns the wall time of that first call."""
    start = time.perf_counter()
    solve_points(table[:1], settings_vector(scene), 2, threads=1)
    return time.perf_counter() - start


def point_labels(scene: Scene) -> list[tuple[float, float]]:
    """(length, frequency ratio) of every point, in the parameter table's (grid C) order."""
    lengths, ratios = np.meshgrid(scene.axes["length"], scene.axes["frequency_ratio"],
                                  indexing="ij")
    return list(zip(lengths.ravel().tolist(), ratios.ravel().tolist()))


def methods_of(runs: list[Measurement]) -> list[str]:
    seen: list[str] = []
    for m in runs:
        if m.method not in seen:
            seen.append(m.method)
    return seen


def curve(runs: list[Measurement], method: str) -> list[Measurement]:
    """The runs of `method`, loosest rtol first."""
    return sorted((m for m in runs if m.method == method), key=lambda m: -m.rtol)


def wall_at_error(ms: list[Measurement], errs: list[float], target: float,
                  two_threads: bool = False) -> tuple[float, str]:
    """Wall time at error `target` on the log-log curve (errs per run, loosest rtol first):
    interpolated between the first pair of rtols whose errors bracket it.
    An error within TIE (1 %) of the target counts as reaching it (cable-sweep and SciPy RK45
    take the same steps: their errors differ only by round-off).
    Returns (wall, how): how is "", "<=" (the loosest rtol is already as accurate: an upper
    bound) or "not reached" (wall NaN)."""
    walls = [m.wall2_s if two_threads else m.wall_s for m in ms]
    if not ms or not all(math.isfinite(w) for w in walls):
        return math.nan, "not measured"
    if errs[0] <= target * TIE:
        return walls[0], "<=" if errs[0] < target / TIE else ""
    for (e_a, w_a), (e_b, w_b) in zip(zip(errs, walls), zip(errs[1:], walls[1:])):
        if e_a >= target and e_b <= target * TIE:
            la, lb = math.log(max(e_a, 1e-300)), math.log(max(e_b, 1e-300))
            x = 1.0 if la == lb else min(1.0, (math.log(target) - la) / (lb - la))
            return math.exp(math.log(w_a) + x * (math.log(w_b) - math.log(w_a))), ""
    return math.nan, "not reached"


def equal_error_report(runs: list[Measurement], ref: Reference, judged: np.ndarray,
                       target_rtol: float) -> tuple[list[str], dict]:
    """Lines of the equal-error comparison and its JSON record."""
    cable = curve(runs, CABLE)
    at = min(cable, key=lambda m: abs(math.log(m.rtol / target_rtol)))
    target = max_amp_err(at, ref, judged)
    lines = [f"## Equal-error speed (max amplitude error {target:.2e}: cable-sweep's at rtol "
             f"{at.rtol:.0e})\n"]
    if target <= 0 or not math.isfinite(target):
        return lines + ["No usable target error."], {}
    walls: dict[str, dict] = {}
    for method in methods_of(runs):
        ms = curve(runs, method)
        errs = [max_amp_err(m, ref, judged) for m in ms]
        w1, how1 = wall_at_error(ms, errs, target)
        w2, how2 = wall_at_error(ms, errs, target, two_threads=True)
        walls[method] = {"wall_1_thread_s": w1, "how_1": how1, "wall_2_threads_s": w2,
                         "how_2": how2, "best_error": min(errs)}
    c1 = walls[CABLE]["wall_1_thread_s"]
    c2 = walls[CABLE]["wall_2_threads_s"]
    rows = []
    for method, w in walls.items():
        def ratio(mine: float, how: str, base: float) -> str:
            if how == "not measured" or not math.isfinite(base):
                return ""
            if how == "not reached":
                return f"not reached (best {w['best_error']:.1e})"
            return f"{'<= ' if how == '<=' else ''}{mine / base:.1f}x" if method != CABLE \
                else "1x"
        rows.append([method,
                     (f"{w['how_1'] + ' ' if w['how_1'] == '<=' else ''}"
                      f"{w['wall_1_thread_s']:.4g}" if math.isfinite(w["wall_1_thread_s"])
                      else ""),
                     ratio(w["wall_1_thread_s"], w["how_1"], c1),
                     (f"{w['how_2'] + ' ' if w['how_2'] == '<=' else ''}"
                      f"{w['wall_2_threads_s']:.4g}" if math.isfinite(w["wall_2_threads_s"])
                      else ""),
                     ratio(w["wall_2_threads_s"], w["how_2"], c2)
                     if math.isfinite(w["wall_2_threads_s"]) else ""])
    lines.append(markdown_table(["method", "wall at target, 1 thread (s)",
                                 "cable-sweep speed ratio, 1 thread", "2 threads (s)",
                                 "ratio, 2 threads"], rows))
    lines.append("\nWall time interpolated in log-log between the rtols that bracket the target "
                 "error; ratio = the peer's wall time / cable-sweep's at the same error, same "
                 "points, same thread count. '<=': the peer's loosest rtol is already more "
                 "accurate than the target (its time there is an upper bound).")
    return lines, {"target_error": target, "target_rtol": at.rtol, "methods": walls}


def fastest_report(runs: list[Measurement], ref: Reference, judged: np.ndarray,
                   targets: list[float]) -> tuple[list[str], list[dict]]:
    """Lines of the fastest-method table: at each target amplitude error, every method's wall
    time there (log-log interpolation, `wall_at_error`) on 1 and on 2 threads, the fastest
    cable-sweep method against the fastest peer, and its JSON record."""
    curves = {method: curve(runs, method) for method in methods_of(runs)}
    errors = {method: [max_amp_err(m, ref, judged) for m in ms] for method, ms in curves.items()}
    record = []
    rows = []
    for target in targets:
        entry = {"target_error": target}
        cells = [f"{target:.0e}"]
        for two in (False, True):
            walls = {}
            for method, ms in curves.items():
                wall, how = wall_at_error(ms, errors[method], target, two_threads=two)
                if math.isfinite(wall):
                    walls[method] = wall
            ours = {m: w for m, w in walls.items() if m.startswith(CABLE)}
            peers = {m: w for m, w in walls.items() if not m.startswith(CABLE)}
            best = min(ours, key=ours.get) if ours else None
            peer = min(peers, key=peers.get) if peers else None
            key = "2_threads" if two else "1_thread"
            entry[key] = {"fastest_cable_sweep": best, "wall_s": ours.get(best),
                          "fastest_peer": peer, "peer_wall_s": peers.get(peer),
                          "all": walls}
            cells += [f"{best} {ours[best]:.4g}" if best else "not reached",
                      f"{peer} {peers[peer]:.4g}" if peer else "not reached",
                      (f"**{peers[peer] / ours[best]:.1f}x**" if best and peer else
                       ("cable-sweep only" if best else "peer only" if peer else ""))]
        record.append(entry)
        rows.append(cells)
    lines = ["## Fastest method at each amplitude error\n",
             markdown_table(["amp err", "fastest cable-sweep, 1 thread (s)",
                             "fastest peer, 1 thread (s)", "peer / cable-sweep, 1 thread",
                             "fastest cable-sweep, 2 threads (s)", "fastest peer, 2 threads (s)",
                             "peer / cable-sweep, 2 threads"], rows),
             "\nWall time for all points at that max amplitude error (non-decayed points), "
             "interpolated in log-log between the bracketing rtols of each method; a method "
             "that never reaches the error is left out; SciPy has no 2-thread row. Ratio > 1: "
             "the fastest cable-sweep method is that many times faster than the fastest peer."]
    return lines, record


STYLE = {CABLE: ("o", "C0"), CABLE_PI: ("P", "C5"), CABLE_DOP853: ("X", "C6"),
         "SciPy RK45": ("s", "C1"),
         "SciPy DOP853": ("^", "C2"),
         "numbalsoda dop853": ("D", "C3"), "numbalsoda lsoda": ("v", "C4"),
         "diffrax Tsit5": ("<", "C7"), "diffrax Dopri5": (">", "C8"),
         "diffrax Dopri8": ("*", "C9")}


def plot(runs: list[Measurement], ref: Reference, judged: np.ndarray, path: str,
         target: float | None) -> None:
    """Two panels: wall time vs max amplitude error and vs settling-time error, one line per
    method (markers: the rtols), dashed: 2 threads."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5), sharey=True)
    for method in methods_of(runs):
        ms = curve(runs, method)
        marker, colour = STYLE.get(method, ("x", None))
        amp = [max(max_amp_err(m, ref, judged), 1e-17) for m in ms]
        ts = [max(max_ts_err(m, ref), 1e-17) for m in ms]
        for ax, err in zip(axes, (amp, ts)):
            ax.loglog(err, [m.wall_s for m in ms], marker=marker, color=colour,
                      label=f"{method}, 1 thread")
            if any(math.isfinite(m.wall2_s) for m in ms):
                ax.loglog(err, [m.wall2_s for m in ms], marker=marker, color=colour,
                          linestyle="--", markerfacecolor="none", label=f"{method}, 2 threads")
            if method == CABLE:
                for e, m in zip(err, ms):
                    ax.annotate(f"{m.rtol:.0e}", (e, m.wall_s), textcoords="offset points",
                                xytext=(4, 4), fontsize=7)
    if target:
        axes[0].axvline(target, color="grey", linestyle=":", linewidth=1)
    axes[0].set_xlabel("max relative amplitude error (non-decayed points)")
    axes[1].set_xlabel("max settling-time error / t_end (points with a reference settling time)")
    axes[0].set_ylabel(f"wall time for {len(ref.amplitude)} points (s)")
    axes[0].set_title("amplitude")
    axes[1].set_title("settling time")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    rtols = sorted({m.rtol for m in runs}, reverse=True)
    fig.suptitle(f"Work-precision, consistent model, {len(ref.amplitude)} points, t in [0, 5] s, "
                 f"rtol {rtols[0]:.0e} ... {rtols[-1]:.0e}; markers: rtols")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def fmt(x: float, spec: str) -> str:
    return "" if not math.isfinite(x) else format(x, spec)


def optional_peer(cls, packages: str, skip: bool):
    """(an instance of the peer class cls, "") or (None, why not) where it is skipped or its
    packages (`packages`, as pip names them) are not installed."""
    if skip:
        return None, ""
    try:
        return cls(), ""
    except ImportError as exc:
        message = (f"{packages} not installed ({exc}): its rows are skipped "
                   f"(pip install {packages}).")
        print(message, file=sys.stderr)
        return None, message


def main() -> None:
    args = parse_args()
    self_check(verbose=False)            # reference_metrics on closed forms (< 1 s)
    rtols = floats(args.rtols)
    scene = build_scene(floats(args.lengths), floats(args.ratios))
    table = parameter_table(scene)
    cfg = Settings(tail=scene.get("metrics.tail"), tol=scene.get("metrics.tolerance"),
                   ns_samples=args.ns_samples)

    ns, ns_message = optional_peer(Numbalsoda, "numbalsoda", args.no_numbalsoda)
    dx, dx_message = optional_peer(Diffrax, "jax diffrax", args.no_diffrax)
    ns_compile_s = dx_compile_s = math.nan

    start = time.perf_counter()
    ref = reference_solution(table, args.ref_rtol, args.ref_atol, cfg)
    ref_s = time.perf_counter() - start
    check = reference_solution(table, args.ref_rtol * 10, args.ref_atol * 10, cfg)
    decayed = ref.amplitude <= cfg.tol * ref.peak
    judged = np.ones_like(decayed) if args.include_decayed else ~decayed
    compile_s = warm_up(table, scene)
    for wanted, key, value in ((args.pi, "solver.controller", "pi"),
                               (args.dop853, "solver.method", "dop853")):
        if wanted:      # each variant is its own kernel: compile it before anything is timed
            warm_up(table, variant(scene, {key: value}))
    if ns is not None:
        ns_compile_s = ns.warm_up(table, np.linspace(0.0, T_END, args.ns_samples))
    if dx is not None:
        dx_compile_s = dx.warm_up(table, np.linspace(0.0, T_END, args.ns_samples))

    runs: list[Measurement] = []
    for rtol in rtols:
        atol = atol_for(rtol, args)
        runs.append(run_cable_sweep(table, scene, rtol, atol))
        if args.pi:
            runs.append(run_cable_sweep(table, scene, rtol, atol, controller="pi"))
        if args.dop853:
            runs.append(run_cable_sweep(table, scene, rtol, atol, method="dop853"))
        if not args.no_scipy:
            runs.append(run_scipy(table, "RK45", rtol, atol, cfg))
            runs.append(run_scipy(table, "DOP853", rtol, atol, cfg))
        if ns is not None:
            for name in Numbalsoda.SOLVERS:
                runs.append(run_numbalsoda(ns, name, table, rtol, atol, cfg))
        if dx is not None:
            for name in Diffrax.SOLVERS:
                runs.append(run_diffrax(dx, name, table, rtol, atol, cfg))
        print(f"rtol {rtol:g} done", file=sys.stderr, flush=True)
    order = methods_of(runs)
    runs.sort(key=lambda m: (order.index(m.method), -m.rtol))

    n_settle = int(np.isin(ref.state, HAS_SETTLING).sum())
    states = ", ".join(f"{s} {int(np.sum(ref.state == s))}" for s in sorted(set(ref.state)))
    print(f"# Work-precision: consistent model, {len(table)} reference points "
          f"({int(decayed.sum())} decayed: A_ref <= {cfg.tol:g} x peak), t_end = 5 s\n")
    check_err = amplitude_errors(check.amplitude, ref)
    check_ts = np.abs(check.settling - ref.settling) / T_END
    print(f"Reference: DOP853 rtol {args.ref_rtol:g} atol {args.ref_atol:g}, "
          f"{ref.steps.mean():,.0f} mean steps, {ref_s:.1f} s (with the metrics). Reference "
          f"states: {states} ({n_settle} with a settling time). Against DOP853 at 10x looser: "
          f"max rel. amplitude diff {np.max(check_err[~decayed], initial=0):.1e} "
          f"(non-decayed), {np.max(check_err):.1e} (all); max settling-time diff / t_end "
          f"{np.nanmax(check_ts, initial=0):.1e}; states differing "
          f"{int(np.sum(check.state != ref.state))}; max rel. q(5) diff "
          f"{np.max(final_state_errors(check.q_end, ref)):.1e}. cable-sweep first call "
          f"(compile or cache load): {compile_s:.2f} s"
          + (f"; numbalsoda loops compile: {ns_compile_s:.2f} s" if ns is not None else "")
          + (f"; diffrax compile: {dx_compile_s:.2f} s" if dx is not None else "")
          + ".\n")
    for message in (ns_message, dx_message):
        if message:
            print(message + "\n")
    rows = []
    for m in runs:
        amp_err = amplitude_errors(m.amplitude, ref)
        rows.append([m.method, f"{m.rtol:.0e}", f"{m.atol:.0e}", f"{m.wall_s:.4f}",
                     fmt(m.wall2_s, ".4f"),
                     fmt(float(np.mean(m.steps)), ",.1f"),
                     fmt(float(np.mean(m.rhs_evals)), ",.0f"),
                     f"{np.max(amp_err[~decayed], initial=0):.1e}",
                     f"{np.max(amp_err):.1e}",
                     fmt(max_ts_err(m, ref), ".1e"),
                     str(state_mismatches(m, ref)),
                     f"{np.max(final_state_errors(m.q_end, ref)):.1e}"])
    print(markdown_table(["method", "rtol", "atol", "wall 1 thr (s)", "wall 2 thr (s)",
                          "mean steps", "mean RHS evals", "amp err", "amp err (all)", "Ts err",
                          "states != ref", "q(5) err"], rows))
    print(f"\nwall: for all {len(table)} points (cable-sweep and numbalsoda: best of repeats; "
          "SciPy: one run per point, summed). amp err: max |A - A_ref| / A_ref over "
          "non-decayed points; amp err (all): over all points; Ts err: max |Ts - Ts_ref| / "
          "t_end over points where the reference and the method both have a settling time; "
          f"states != ref: points (of {len(table)}) whose state differs from the reference's; "
          "q(5) err: max |q(5) - q_ref(5)| / max|q_ref|. SciPy and numbalsoda metrics: "
          "reference_metrics on their dense output (SciPy) or on a quintic Hermite interpolant "
          f"of {args.ns_samples} samples (numbalsoda); not timed.\n")
    for m in runs:
        for note in m.notes:
            print(f"Note: {m.method} rtol {m.rtol:.0e}: {note}")

    if any(m.method == "SciPy RK45" for m in runs):
        print(step_agreement(runs, len(table)) + "\n")
    chosen = recommend(runs, ref, judged, args.threshold)
    which = "all" if args.include_decayed else "non-decayed"
    if chosen is None:
        print(f"Recommended default: none of the rtols keeps the amplitude error below "
              f"{args.threshold:g} on all {which} reference points.\n")
    else:
        print(f"Recommended default: rtol = {chosen:g}, atol = {atol_for(chosen, args):g} "
              f"(largest rtol with max relative amplitude error < {args.threshold:g} on all "
              f"{which} reference points, and for every tighter rtol).\n")

    lines, equal = equal_error_report(runs, ref, ~decayed, args.target_rtol)
    print("\n".join(lines))
    lines, fastest = fastest_report(runs, ref, ~decayed, floats(args.errors))
    print("\n" + "\n".join(lines))

    if args.plot:
        plot(runs, ref, ~decayed, args.plot, equal.get("target_error"))
        print(f"\nPlot written to {args.plot}")
    if args.json:
        write_json(args.json, {
            "points": [{"length": l, "frequency_ratio": r, "decayed": bool(d),
                        "ref_amplitude": a, "ref_peak": pk, "ref_q_end": qe, "ref_state": s,
                        "ref_settling_time": ts}
                       for (l, r), d, a, pk, qe, s, ts in zip(
                           point_labels(scene), decayed, ref.amplitude, ref.peak, ref.q_end,
                           ref.state, ref.settling)],
            "reference": {"rtol": args.ref_rtol, "atol": args.ref_atol,
                          "mean_steps": float(ref.steps.mean()), "seconds": ref_s},
            "compile_s": compile_s, "numbalsoda_compile_s": ns_compile_s,
            "numbalsoda": ns_message or f"{args.ns_samples} samples",
            "threshold": args.threshold, "recommended_rtol": chosen,
            "recommended_atol": None if chosen is None else atol_for(chosen, args),
            "equal_error": equal, "fastest": fastest,
            "diffrax_compile_s": dx_compile_s,
            "runs": [{"method": m.method, "rtol": m.rtol, "atol": m.atol, "wall_s": m.wall_s,
                      "wall_2_threads_s": m.wall2_s,
                      "mean_steps": float(np.mean(m.steps)),
                      "mean_rhs_evals": float(np.mean(m.rhs_evals)),
                      "max_rel_amplitude_error": float(np.max(
                          amplitude_errors(m.amplitude, ref)[~decayed], initial=0)),
                      "max_rel_amplitude_error_all": float(np.max(
                          amplitude_errors(m.amplitude, ref))),
                      "max_settling_time_error_over_t_end": max_ts_err(m, ref),
                      "states_differing": state_mismatches(m, ref),
                      "max_rel_final_state_error": float(np.max(
                          final_state_errors(m.q_end, ref))),
                      "notes": m.notes} for m in runs]})


if __name__ == "__main__":
    main()
