"""What one span's random response costs (docs/model.md sec. 11), the engine against SciPy and
a hand-written fixed-step RK4, at equal accuracy on the same record.

What it measures
----------------
Cost: CPU seconds of one thread per simulated second of one record (a "realisation-second"),
one span of the built-in scene launch-random-gevs (one mode unless said), side by side:

- the engine as shipped, through the public API: `sweep.run(sweep.load_scene(
  "launch-random-gevs", overrides))` with one length, one level, --realisations records of
  the scene's 8 s and run.threads = 1; one run first (compile or load the cache), then the
  best wall time of --repeats runs, everything in it (the records' synthesis, the dataset)
  counted and divided by realisations x 8 s. Also with model.modes = 3, and at the scene's
  150 mm span at qualification (0 dB);
- SciPy solve_ivp (DOP853, RK45) on the same one-mode equation and the same record, the
  coefficients as the engine takes them (`sweep.models.modal.oscillator` at the grid point):
  q'' = -(c q' + k0 q + g0 q^3 + h q^5) / m - G s a_b(t), a_b the cubic Hermite interpolant of
  the record's samples and derivatives (`sweep.models.random.hermite`, written out in scalar
  Python), s the level factor 10^(dB/20); a pure-Python right-hand side. Timed on the
  accuracy record (--accuracy-duration s, not 8 s: SciPy is slow) and extrapolated per second;
- a fixed-step classical RK4 loop compiled with Numba (`rk4_rms`, about 30 lines) on the same
  Hermite interpolant, step 1/(m fs) for m in --rk4-steps; best of --repeats on the cost
  records (the engine's).

Accuracy: the RMS midspan deflection over the statistics window of realisation 0 of a record
of --accuracy-duration s, each method over its own window (the engine's starts at its first
step end after the start-up transient, t_end - statistics_window; RK4's at the first step
on its grid after that), against a reference: SciPy DOP853 at rtol 1e-11 (and 1e-10, to show
it converged) on the same equation with z' = q^2 integrated beside it, so the reference's
integral of q^2 is at the solver's tolerance. The reference's atol (and the measured SciPy
runs') is rtol x 0.01 x the engine's own state scales (q_scale, v_scale; what the engine
takes by default), z kept out of the error norm in the measured runs. The case is mildly
nonlinear and its trajectory converges (100 mm span at -10 dB by default; the stretching
150-300 mm spans at qualification are chaotic: per-realisation trajectories, and their RMS,
move with the tolerance, only the statistics over realisations converge). Error =
|RMS - RMS_ref| / RMS_ref.

Also (--scene): the whole built-in scene, `sweep run launch-random-gevs` through the public
API on 2 threads, warm, median of 3; and the projection of a 20 spans x 20 realisations x 60 s
map on 2 cores from the measured per-realisation-second costs.

Command
-------
    PYTHONPATH=. python benchmarks/random_cost.py [--realisations 4] [--repeats 3]
        [--accuracy-duration 1.0] [--rk4-steps 1 2 4] [--no-scene]

Prints Markdown tables to stdout.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

import numba as nb  # noqa: E402
import numpy as np  # noqa: E402
from scipy.integrate import DOP853, solve_ivp  # noqa: E402

from bench_common import machine, markdown_table  # noqa: E402

import sweep  # noqa: E402
from sweep import grid  # noqa: E402
from sweep.models import modal  # noqa: E402
from sweep.models.random import hermite  # noqa: E402
from sweep.models.random_outputs import RandomInputs  # noqa: E402

SCENE = "launch-random-gevs"
_SHIPPED = sweep.load_scene(SCENE).values
DEFAULT = (_SHIPPED["solver.method"], float(_SHIPPED["solver.rtol"]))   # the scene as shipped
ATOL_SCALE = 0.01          # sweep/models/transverse.py: the engine's default atol fraction
MAP = (20, 20, 60.0)       # spans, realisations, seconds: the map


def overrides(length: float, level_db: float, realisations: int, duration: float | None = None,
              modes: int = 1, threads: int = 1) -> dict:
    """The scene's overrides for one span at one level."""
    out = {"axes.length": [length], "axes.base_asd_scale": [level_db],
           "base.realisations": realisations, "run.threads": threads, "model.modes": modes}
    if duration is not None:
        out["base.duration"] = duration
    return out


class Case:
    """One span at one level, one mode: the engine's coefficients of its grid point 0 and its
    records (the same as sweep.run synthesises)."""

    def __init__(self, length: float, level_db: float, realisations: int,
                 duration: float | None = None) -> None:
        self.overrides = overrides(length, level_db, realisations, duration)
        self.scene = sweep.load_scene(SCENE, self.overrides)
        coords = grid.coordinates(self.scene)
        params = grid.parameters(self.scene, coords)
        dims = grid.dimensions(coords)
        shape = tuple(coords[d].size for d in dims)
        c = {k: float(np.ravel(v)[0]) for k, v in
             modal.oscillator(grid.point_values(params, dims, shape, np.array([0]))).items()
             if np.size(v) == 1 and np.isrealobj(v)}
        m = c["mass"]
        # q'' = C v + K q + G3 q^3 + H5 q^5 - B a_b(t)   (kernels/oscillator.py `prepare`)
        self.coef = (-c["damping"] / m, -c["k0"] / m, -c["g0"] / m, -c["h"] / m,
                     c["participation"] * c["base_accel"])
        self.scales = (c["q_scale"], c["v_scale"])
        self.f1 = c["natural_frequency"]
        random = RandomInputs.of(self.scene.values)
        self.records = random.records()
        self.fs = random.sample_rate
        self.t_end = random.t_end

    def rhs(self, r: int):
        """f(t, [q, v, z]) for solve_ivp, z' = q^2: scalar Python, the record as lists."""
        C, K, G3, H5, B = self.coef
        x, dx = self.records[r, :, 0].tolist(), self.records[r, :, 1].tolist()
        n, fs, dt = len(x), self.fs, 1.0 / self.fs

        def f(t, y):
            q, v = y[0], y[1]
            s = t * fs
            kf = math.floor(s)
            u = s - kf
            k = int(kf) % n
            k1 = k + 1 if k + 1 < n else 0
            u2 = u * u
            u3 = u2 * u
            ab = ((2.0 * u3 - 3.0 * u2 + 1.0) * x[k] + (u3 - 2.0 * u2 + u) * dt * dx[k]
                  + (3.0 * u2 - 2.0 * u3) * x[k1] + (u3 - u2) * dt * dx[k1])
            q2 = q * q
            return [v, K * q + G3 * q * q2 + H5 * q * q2 * q2 + C * v - B * ab, q2]

        return f

    def scipy_rms(self, r: int, method: str, rtol: float, starts: list[float],
                  z_in_norm: bool) -> tuple[dict[float, float], float]:
        """({window start: RMS over [start, t_end]}, wall s) of solve_ivp on the record."""
        qs, vs = self.scales
        zs = qs * qs * self.t_end if z_in_norm else 1e300
        atol = [ATOL_SCALE * rtol * qs, ATOL_SCALE * rtol * vs, ATOL_SCALE * rtol * zs]
        times = sorted(set(starts)) + [self.t_end]
        begin = time.perf_counter()
        sol = solve_ivp(self.rhs(r), (0.0, self.t_end), [0.0, 0.0, 0.0], method=method,
                        rtol=rtol, atol=atol, t_eval=times)
        wall = time.perf_counter() - begin
        if not sol.success:
            raise RuntimeError(f"solve_ivp({method}) failed: {sol.message}")
        z = dict(zip(times, sol.y[2]))
        return {t0: math.sqrt((z[self.t_end] - z[t0]) / (self.t_end - t0))
                for t0 in times[:-1]}, wall

    def reference_rms(self, r: int, rtol: float, starts: list[float]) -> dict[float, float]:
        """{window start: RMS over [start, t_end]} of SciPy's DOP853 restarted at every sample
        instant (and window start): the forcing is a polynomial within each interval (the
        Hermite cubic), so each piece is smooth and DOP853 keeps its order. Integrated across
        the samples, its step straddles the cubic's jumps in a_b'' and its error estimate does
        not follow them (the measured DOP853 row: 100 x its rtol)."""
        qs, vs = self.scales
        atol = np.array([ATOL_SCALE * rtol * qs, ATOL_SCALE * rtol * vs,
                         ATOL_SCALE * rtol * qs * qs * self.t_end])
        n = int(round(self.t_end * self.fs))
        cuts = np.union1d(np.arange(n + 1) / self.fs, starts)
        f = self.rhs(r)
        y = np.zeros(3)
        z = {}
        for a, b in zip(cuts[:-1], cuts[1:]):
            if a in starts:
                z[a] = y[2]
            s = DOP853(f, a, y, b, rtol=rtol, atol=atol, first_step=b - a)
            while s.status == "running":
                s.step()
            if s.status != "finished":
                raise RuntimeError("DOP853 failed on a sample interval")
            y = s.y
        return {t0: math.sqrt((y[2] - z[t0]) / (self.t_end - t0)) for t0 in starts}


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def hermite_weights(fs, t, n):
    """The cubic Hermite's samples k, k1 (of n, periodic) and its weights on x[k], dx[k],
    x[k1], dx[k1] at time t (s) of a record sampled at fs (Hz)."""
    s = t * fs
    kf = math.floor(s)
    u = s - kf
    k = int(kf) % n
    k1 = k + 1 if k + 1 < n else 0
    u2 = u * u
    u3 = u2 * u
    return (k, k1, 2.0 * u3 - 3.0 * u2 + 1.0, (u3 - 2.0 * u2 + u) / fs, 3.0 * u2 - 2.0 * u3,
            (u3 - u2) / fs)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _hermite(x, dx, fs, t):
    k, k1, w0, w1, w2, w3 = hermite_weights(fs, t, x.size)
    return w0 * x[k] + w1 * dx[k] + w2 * x[k1] + w3 * dx[k1]


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _force(C, K, G3, H5, q, v):
    q2 = q * q
    return C * v + q * (K + q2 * (G3 + H5 * q2))


@nb.njit(cache=True, nogil=True, error_model="numpy")
def rk4_rms_over(x, dx, fs, coef, t_end, t0, m):
    """RMS of q (m) over [t0, t_end] (s) by the classical RK4 at step h = 1 / (m fs) from rest,
    z' = q^2 integrated beside q, q', z(t0) read on the cubic Hermite through
    z and z' = q^2 at the ends of the step that holds t0: the window of another solver's run,
    not one of RK4's grid points."""
    C, K, G3, H5, B = coef
    h = 1.0 / (m * fs)
    steps = int(round(t_end * fs * m))
    q = v = z = 0.0
    z0 = 0.0 if t0 <= 0.0 else math.nan
    a0 = _hermite(x, dx, fs, 0.0)
    for i in range(steps):
        t = i * h
        a_half = _hermite(x, dx, fs, t + 0.5 * h)
        a1 = _hermite(x, dx, fs, t + h)
        q1, v1 = q, v
        f1 = _force(C, K, G3, H5, q1, v1) - B * a0
        q2, v2 = q + 0.5 * h * v1, v + 0.5 * h * f1
        f2 = _force(C, K, G3, H5, q2, v2) - B * a_half
        q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * f2
        f3 = _force(C, K, G3, H5, q3, v3) - B * a_half
        q4, v4 = q + h * v3, v + h * f3
        f4 = _force(C, K, G3, H5, q4, v4) - B * a1
        z_new = z + h / 6.0 * (q1 * q1 + 2.0 * q2 * q2 + 2.0 * q3 * q3 + q4 * q4)
        q_new = q + h / 6.0 * (v1 + 2.0 * v2 + 2.0 * v3 + v4)
        v += h / 6.0 * (f1 + 2.0 * f2 + 2.0 * f3 + f4)
        if math.isnan(z0) and t0 <= t + h:           # the step that holds t0
            u = max(0.0, min(1.0, (t0 - t) / h))
            u2 = u * u
            u3 = u2 * u
            z0 = ((2.0 * u3 - 3.0 * u2 + 1.0) * z + (u3 - 2.0 * u2 + u) * h * q * q
                  + (3.0 * u2 - 2.0 * u3) * z_new + (u3 - u2) * h * q_new * q_new)
        z = z_new
        q = q_new
        a0 = a1
    return math.sqrt((z - z0) / (t_end - t0))


def rk4_rms(x, dx, fs, coef, t_end, t_tail, m):
    """(RMS of q over [t0, t_end], t0) by `rk4_rms_over`, t0 the first step start of RK4's own
    grid (step 1 / (m fs)) at or after t_tail."""
    h = 1.0 / (m * fs)
    t0 = math.ceil(t_tail / h - 1e-9) * h
    return rk4_rms_over(x, dx, fs, coef, t_end, t0, m), t0


def best(fn, repeats: int) -> float:
    """Best wall time (s) of fn() over `repeats` runs, after one run not counted."""
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def engine_cost(length: float, level_db: float, realisations: int, modes: int,
                repeats: int, rtol: float | None = None,
                method: str | None = None) -> tuple[float, float]:
    """(wall s per realisation-second, the solve's own share: the dataset's run_seconds, the
    kernels' time after the records are made, per realisation-second) of sweep.run on one
    span, one thread, the scene's records (8 s); solver.rtol and solver.method the scene's
    unless given."""
    more = {} if rtol is None else {"solver.rtol": rtol}
    if method is not None:
        more["solver.method"] = method
    scene = sweep.load_scene(SCENE, {**overrides(length, level_db, realisations, modes=modes),
                                     **more})
    seconds = realisations * float(scene.values["base.duration"])
    solve = []

    def go():
        solve.append(sweep.run(scene, progress=False).attrs["run_seconds"])

    wall = best(go, repeats)
    return wall / seconds, min(solve[1:]) / seconds


def engine_rms(case: Case, method: str, rtol: float) -> tuple[float, float, int]:
    """(RMS deflection, window start, steps) of realisation 0 by sweep.run with solver.method
    and solver.rtol."""
    ds = sweep.run(sweep.load_scene(SCENE, {**case.overrides, "solver.rtol": rtol,
                                            "solver.method": method}), progress=False)
    first = {k: ds[k].values.ravel()[0] for k in ("rms_deflection", "statistics_window",
                                                    "n_steps")}
    return (float(first["rms_deflection"]), case.t_end - float(first["statistics_window"]),
            int(first["n_steps"]))


def scene_wall(repeats: int) -> float:
    """Median wall time (s) of the whole built-in scene on 2 threads, after one run."""
    scene = sweep.load_scene(SCENE, {"run.threads": 2})
    sweep.run(scene, progress=False)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        sweep.run(scene, progress=False)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--length", type=float, default=0.10, help="m (the accuracy case)")
    parser.add_argument("--level", type=float, default=-10.0, help="dB (the accuracy case)")
    parser.add_argument("--realisations", type=int, default=4, help="records timed (8 s each)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--accuracy-duration", type=float, default=1.0,
                        help="s: the accuracy record, also SciPy's timed record")
    parser.add_argument("--engine-rtol", type=float, nargs="+", default=[1e-6, 1e-7, 1e-8],
                        help="rtols of the engine's DOP853 rows")
    parser.add_argument("--rk45-rtol", type=float, nargs="*", default=[1e-5, 1e-6],
                        help="rtols of the engine's RK45 rows")
    parser.add_argument("--rk4-steps", type=float, nargs="+", default=[0.25, 0.5, 1.0, 2.0],
                        help="m: RK4 steps of 1 / (m fs)")
    parser.add_argument("--no-scene", action="store_true", help="skip the whole scene's run")
    args = parser.parse_args()

    # accuracy, realisation 0 of the short record
    acc = Case(args.length, args.level, 1, args.accuracy_duration)
    x, dx = acc.records[0, :, 0], acc.records[0, :, 1]
    probe = np.random.default_rng(0).uniform(0.0, acc.t_end, 1000)
    mine = np.array([_hermite(x, dx, acc.fs, t) for t in probe])
    f = acc.rhs(0)
    python = np.array([f(t, [0.0, 0.0, 0.0])[1] for t in probe]) / -acc.coef[4]
    for what, got in (("the RK4 loop's", mine), ("the SciPy right-hand side's", python)):
        if not np.allclose(got, hermite(acc.records[0], acc.fs, probe), rtol=1e-12,
                           atol=1e-12):
            raise RuntimeError(f"{what} a_b is not sweep.models.random.hermite's")
    runs = ([("dop853", rtol) for rtol in args.engine_rtol]
            + [("rk45", rtol) for rtol in args.rk45_rtol])
    engine = {run: engine_rms(acc, *run) for run in runs}
    t_tail = engine[runs[0]][1]
    rk4 = {m: rk4_rms(x, dx, acc.fs, acc.coef, acc.t_end, t_tail, m)
           for m in args.rk4_steps + [16.0]}
    starts = sorted({e[1] for e in engine.values()} | {r[1] for r in rk4.values()} | {t_tail})
    scipy_runs = {(method, rtol): acc.scipy_rms(0, method, rtol, starts, False)
                  for method, rtol in (("DOP853", 1e-6), ("RK45", 1e-6), ("RK45", 1e-7))}
    ref = acc.reference_rms(0, 1e-11, starts)
    ref_10 = acc.reference_rms(0, 1e-10, starts)

    def error(rms: float, t0: float) -> float:
        return abs(rms - ref[t0]) / ref[t0]

    # cost per realisation-second, one thread
    cost = Case(args.length, args.level, args.realisations)
    seconds = args.realisations * cost.t_end

    def rk4_all(m: float) -> None:
        for r in range(args.realisations):
            rk4_rms(cost.records[r, :, 0], cost.records[r, :, 1], cost.fs, cost.coef, cost.t_end,
                    t_tail, m)

    rows = []
    label = f"{args.length * 1e3:g} mm, {args.level:g} dB"
    engine_rows = {}
    for (method, rtol), (rms, t0, steps) in engine.items():
        wall, solve = engine_cost(args.length, args.level, args.realisations, 1, args.repeats,
                                  rtol, method)
        engine_rows[method, rtol] = (wall, error(rms, t0))
        rows.append([f"engine, {method.upper()} rtol {rtol:g}"
                     + (" (default)" if (method, rtol) == DEFAULT else ""),
                     label, f"{wall * 1e3:.2f}", f"{solve * 1e3:.2f}",
                     f"{steps / acc.t_end:.0f}", f"{error(rms, t0):.1e}"])
    rk4_rows = {}
    for m in args.rk4_steps:
        per_s = best(lambda: rk4_all(m), args.repeats) / seconds
        rk4_rows[m] = (per_s, error(*rk4[m]))
        rows.append([f"RK4 (Numba), h = 1/({m:g} fs)", label, f"{per_s * 1e3:.2f}", "",
                     f"{m * acc.fs:.0f}", f"{error(*rk4[m]):.1e}"])
    for (method, rtol), (rms, wall) in scipy_runs.items():
        rows.append([f"SciPy solve_ivp {method} rtol {rtol:g} ({acc.t_end:g} s record)",
                     label, f"{wall / acc.t_end * 1e3:.0f}", "", "",
                     f"{error(rms[t_tail], t_tail):.1e}"])
    for length, level in ((args.length, args.level), (0.15, 0.0)):
        for modes in ((1, 3) if (length, level) != (args.length, args.level) else (3,)):
            per_s = engine_cost(length, level, args.realisations, modes, args.repeats)
            rows.append([f"engine, {DEFAULT[0].upper()} rtol {DEFAULT[1]:g} (default), {modes} mode"
                         + ("s" if modes > 1 else ""), f"{length * 1e3:g} mm, {level:g} dB",
                         f"{per_s[0] * 1e3:.2f}", f"{per_s[1] * 1e3:.2f}", "", ""])
    print(f"machine: {machine()}\n")
    print(f"Cost per realisation-second (ms of one thread per simulated second of one record; "
          f"best of {args.repeats} after a first run, {args.realisations} records of "
          f"{cost.t_end:g} s; SciPy once on {acc.t_end:g} s) and error of the RMS deflection "
          f"of realisation 0 of a {acc.t_end:g} s record ({label}, window from "
          f"{t_tail:.4f} s) against SciPy DOP853 at rtol 1e-11 restarted at every sample:\n")
    print(markdown_table(["method", "span", "wall ms / realisation-s", "solve ms / "
                          "realisation-s (run_seconds)", "steps / s", "RMS error"], rows))
    print(f"\nreference check: rtol 1e-10 against 1e-11 "
          f"{max(abs(ref_10[t] / ref[t] - 1.0) for t in starts):.1e}; RK4 at h = 1/(16 fs) "
          f"against it {error(*rk4[16.0]):.1e}; RMS_ref = {ref[t_tail]:.6e} m\n")

    # equal accuracy: the widest RK4 step at least as accurate as each engine run
    equal = None
    for (method, rtol), (wall, e_engine) in engine_rows.items():
        fine = [m for m in args.rk4_steps if rk4_rows[m][1] <= e_engine]
        if not fine:
            print(f"equal accuracy, engine {method} rtol {rtol:g} (error {e_engine:.1e}): no RK4 step "
                  "measured is as accurate")
            continue
        m = min(fine)
        per_s, e = rk4_rows[m]
        if (method, rtol) == runs[0]:
            equal = m
        line = (f"equal accuracy, engine {method} rtol {rtol:g} (error {e_engine:.1e}) / RK4 at h = "
                f"1/({m:g} fs) (error {e:.1e}, the widest step at least as accurate): "
                f"{wall / per_s:.1f}x the cost")
        coarser = [k for k in args.rk4_steps if k < m]
        if coarser:                    # on the h^4 line from m, the step of equal error
            m_eq = m * (e / e_engine) ** 0.25
            line += (f"; on the h^4 line the equal-error step is 1/({m_eq:.2g} fs), "
                     f"about {wall / (per_s * m_eq / m):.0f}x")
        print(line)
    if not args.no_scene:
        wall = scene_wall(3)
        whole = sweep.load_scene(SCENE, {})
        n = (len(whole.axes["length"]) * len(whole.axes["base_asd_scale"])
             * int(whole.values["base.realisations"]))
        rs = n * float(whole.values["base.duration"])
        spans, reals, duration = MAP
        mapped = spans * reals * duration
        print(f"\nwhole scene ({n} trajectories x {whole.values['base.duration']:g} s = "
              f"{rs:g} realisation-s) on 2 threads, warm, median of 3: {wall:.2f} s "
              f"({2.0 * wall / rs * 1e3:.2f} ms of a thread per realisation-second)")
        print(f"{spans} spans x {reals} realisations x {duration:g} s = {mapped:g} "
              f"realisation-s on 2 cores: {mapped * wall / rs:.0f} s at the scene's rate; "
              f"{mapped * engine_rows[runs[0]][0] / 2.0:.0f} s at the one-span "
              f"rate above (engine, {runs[0][0]} rtol {runs[0][1]:g}); "
              + (f"{mapped * rk4_rows[equal][0] / 2.0:.1f} s for the RK4 loop at "
                 f"h = 1/({equal:g} fs), as accurate" if equal is not None else ""))
    print("\n    PYTHONPATH=. python benchmarks/random_cost.py " + " ".join(sys.argv[1:]))


if __name__ == "__main__":
    main()
