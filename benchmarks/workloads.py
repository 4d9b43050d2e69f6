"""The built-in scenes as shipped against the engine's other settings and its peers, each at the
scene's own accuracy: what the defaults buy, and how far ahead of a peer they are.

What it measures
----------------
For each built-in time-domain scene (or --scene NAME), on a sample of its grid (SAMPLES below:
a few points that keep the scene's regimes, below, at and above resonance; `--set` adds
overrides):

- the reference: the sample with solver.method = "dop853", rtol 1e-12 and the scalar driver,
  which is SciPy's DOP853 step for step (tests/test_kernel_vs_scipy.py checks it for one
  mode, tests/test_mode_convergence.py the modal driver's steps against it at N = 1), so an
  independent SciPy solution at rtol 1e-12;
- the scene as shipped and each of the engine's settings (method rk45 / dop853 x rtol 1e-6 ..
  1e-10, the shipped driver): its time per point (best of --repeats after a compile run, one
  thread: run.threads = 1) and its error: max |x - x_ref| / max |x_ref| of the scene's
  headline output x (a random scene's `rms_deflection`, else `amplitude`, else
  `peak_amplitude`) over the sample;
- the fastest setting whose error is at most the shipped run's ("best at equal error");
- peers at the same error: SciPy `solve_ivp` on the sample's points with the System's own
  right-hand side (several modes: the compiled `kernels.modes.derivative`; one mode:
  `kernels.oscillator.acceleration` in Python, bench_common.scipy_rhs, as fast as a
  hand-written closure),
  at the method and rtol of the scalar driver's setting that reaches the shipped error (SciPy
  then takes the same steps, so reaches the same error). A stepped sine or a sine sweep has
  no SciPy peer here (benchmarks/stepped_sweep.py, sine_sweep_cost.py);
- numbalsoda's dop853 and lsoda from a Numba prange loop on the same points with the System's
  own right-hand side compiled into their cfunc (benchmarks/scene_peers.py; a sine sweep
  too, each point to its own sweep end; not a stepped sine, whose dwells chain), each at
  the loosest rtol whose final-state error (max |q - q_ref| / max |q_ref| at the run's end)
  is at most the shipped run's, on 1 and 2 threads, against the shipped run's kernel call
  (its solve without the dataset: `scene_peers.engine_run`) on 1 and 2 threads. The peers
  integrate the trajectory only; the engine also tracks the scene's outputs (amplitudes,
  peaks, settling, clamp loads). Skipped, with its install line, where numbalsoda does not
  import. diffrax is listed, not run on the scenes (its peer would need the right-hand side
  rewritten in JAX; benchmarks/work_precision.py runs it on the one-mode reference sweep).
  A 4-12 point sample is too small to spread over two threads: --full runs the whole grids;
- a random scene of one mode (its sample: one span, one level): a hand-written fixed-step
  RK4 loop in Numba on the same records (benchmarks/random_cost.py `rk4_rms_over`, the
  coefficients the engine takes), its RMS over each point's window of the reference run, at
  the widest step 1 / (m fs), m = 0.25 .. 4, that reaches the shipped error; its time per
  point is the loop's alone (the engine's includes the records' synthesis and the dataset).
  SciPy on a record is in benchmarks/random_cost.py (110-160x the engine).

Command
-------
    PYTHONPATH=. python benchmarks/workloads.py [--scene NAME ...] [--check R] [--repeats 3]
        [--shipped-only] [--full]

Prints one or two Markdown tables per scene; with --check R it exits 1 when a scene's shipped
run is less than R times faster than its fastest peer (SciPy's, RK4's, or numbalsoda's on 1 or
2 threads, the lowest ratio). numbalsoda needs `pip install numbalsoda`, whose build needs
cmake, a C++ compiler and gfortran (`apt-get install cmake g++ gfortran`); the project's
`bench` extra lists it.
"""

from __future__ import annotations

import argparse
import math
from importlib import metadata
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the checkout's sweep/kernels
sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench_common

import scene_peers  # noqa: E402
from bench_common import machine, markdown_table  # noqa: E402

import sweep  # noqa: E402

SAMPLES: dict[str, dict[str, Any]] = {
    "paper-fig5": {},
    "harness-parametric": {"axes.length": [0.3, 0.6, 1.0],
                           "axes.frequency_ratio": [0.8, 1.0, 1.9, 2.0, 2.5]},
    "harness-base-sine": {"axes.length": [0.3, 0.5, 0.7],
                          "axes.base_frequency": {"start": 10.0, "stop": 80.0, "num": 4,
                                                  "spacing": "log"}},
    "harness-clamps": {"axes.length": [0.15, 0.3, 0.45],
                       "axes.clamp_rotational_stiffness": [0.01, 1.0, 100.0]},
    "harness-stepped-sine": {"axes.length": [0.5],
                             "axes.base_frequency_ratio": {"start": 0.8, "stop": 2.0, "num": 13}},
    "launch-sine-qualification": {"axes.length": [0.15, 0.35]},
    # the one span and level of the scene where a record's response converges as a trajectory
    # (at 0 dB, and on the longer spans at -10 dB, it is chaotic: benchmarks/random_divergence.py)
    "launch-random-gevs": {"axes.length": [0.1], "axes.base_asd_scale": [-10.0],
                           "base.realisations": 2},
}
RTOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
HEADLINE = ("rms_deflection", "amplitude", "peak_amplitude")   # a random scene's: its RMS
RK4_STEPS = (0.25, 0.5, 1.0, 2.0, 4.0)   # the RK4 peer's steps 1 / (m fs), widest first
INSTALL = {"numbalsoda": scene_peers.INSTALL, "diffrax": "pip install diffrax jax"}


def headline(ds: Any) -> np.ndarray:
    """The scene's headline output, flattened (m)."""
    for name in HEADLINE:
        if name in ds:
            return np.asarray(ds[name].values, float).ravel()
    raise SystemExit(f"no headline output ({', '.join(HEADLINE)}) in the dataset")


def error(x: np.ndarray, ref: np.ndarray) -> float:
    """max |x - ref| / max |ref| over the points both have (NaN where a point has none)."""
    ok = np.isfinite(x) & np.isfinite(ref)
    if not ok.any():
        return math.nan
    return float(np.max(np.abs(x[ok] - ref[ok])) / np.max(np.abs(ref[ok])))


def timed(name: str, overrides: dict[str, Any],
          repeats: int) -> tuple[float, np.ndarray, Any]:
    """(best wall time per point (s) on one thread over `repeats` runs after a first one, inf
    with none; headline; the dataset) of scene `name`. With repeats 0 (a run that is not
    timed: a reference) on every core (the points are independent: the same results)."""
    threads = 1 if repeats > 0 else 0
    scene = sweep.load_scene(name, overrides={**overrides, "run.threads": threads})
    ds = sweep.run(scene, progress=False)                   # compile, or load the cache
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        ds = sweep.run(scene, progress=False)
        best = min(best, time.perf_counter() - start)
    x = headline(ds)
    return best / x.size, x, ds


def has_scipy_peer(name: str, overrides: dict[str, Any]) -> bool:
    """Whether `scipy_peer` can run the scene: not a sweep, a stepped sine or random records."""
    from sweep.models import transverse as tm
    inputs = tm.resolve(sweep.load_scene(name, overrides=overrides))
    return not inputs.swept and inputs.continuation is None and inputs.random is None


def scipy_peer(name: str, overrides: dict[str, Any], method: str, rtol: float) -> float:
    """SciPy solve_ivp's time per point (s) on the sample with the System's right-hand side
    (module docstring), at (method, rtol) and the scene's own atol (`has_scipy_peer`)."""
    from scipy.integrate import solve_ivp

    from sweep.kernels import layout as tk
    from sweep.kernels import modes as md
    from sweep.kernels import oscillator as osc
    from sweep.models import transverse as tm
    scene = sweep.load_scene(name, overrides={**overrides, "solver.method": method,
                                              "solver.rtol": rtol, "solver.driver": "scalar"})
    inputs = tm.resolve(scene)
    settings = tm.settings_vector(scene)
    t_end = float(settings[tk.T_END])
    rtol_s = float(settings[tk.RTOL])
    c = float(settings[tk.ATOL_SCALE]) * rtol_s        # kernels/trajectory.py point_atol

    def tolerances(q_scale: float, v_scale: float, n: int) -> np.ndarray:
        return np.concatenate((np.full(n, settings[tk.ATOL] + c * q_scale),
                               np.full(n, settings[tk.ATOL] + c * v_scale)))

    points = np.arange(int(np.prod(inputs.shape)))
    elapsed = 0.0
    if inputs.n_modes == 1:
        from bench_common import parameter_table, scipy_rhs
        rows = parameter_table(scene)
        for row in rows:
            start = time.perf_counter()
            solve_ivp(scipy_rhs(row), (0.0, t_end), [row[osc.Q0], row[osc.V0]],
                      method=method.upper(), rtol=rtol_s,
                      atol=tolerances(row[osc.Q_SCALE], row[osc.V_SCALE], 1))
            elapsed += time.perf_counter() - start
        return elapsed / len(rows)
    rows = tm.modal_rows(inputs, points)
    bases = inputs.basis.kernel_arrays()
    n = inputs.n_modes
    for row in rows:
        arrays = bases if isinstance(bases, tuple) else bases[int(row[-1])]
        S = md.row_scratch(row, arrays)
        T = arrays[md.TABLES]
        base = True if row[md.BASE_ACCEL] != 0.0 else None

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            dy = np.empty(2 * n)
            md.derivative(t, y, dy, S, n, T, base)
            return dy

        y0 = row[md.N_FIXED:md.N_FIXED + 2 * n]
        atol = tolerances(row[md.Q_SCALE], row[md.V_SCALE], n)
        rhs(0.0, y0)                                          # compile
        start = time.perf_counter()
        solve_ivp(rhs, (0.0, t_end), y0, method=method.upper(), rtol=rtol_s, atol=atol)
        elapsed += time.perf_counter() - start
    return elapsed / len(rows)


def has_numbalsoda_peer(name: str, overrides: dict[str, Any]) -> bool:
    """Whether benchmarks/scene_peers.py runs the scene: not a stepped sine (its dwells chain)
    nor random records."""
    from sweep.models import transverse as tm
    inputs = tm.resolve(sweep.load_scene(name, overrides=overrides))
    return inputs.continuation is None and inputs.random is None


def is_random(name: str, overrides: dict[str, Any]) -> bool:
    """Whether the scene is a random one of one mode (`rk4_peer` runs it)."""
    from sweep.models import transverse as tm
    inputs = tm.resolve(sweep.load_scene(name, overrides=overrides))
    return inputs.random is not None and inputs.n_modes == 1


def rk4_peer(name: str, sample: dict[str, Any], ref: np.ndarray, ref_ds: Any, e_ship: float,
             t_ship: float, repeats: int) -> tuple[list[str], float | None]:
    """The random scene's peer: a hand-written fixed-step RK4 loop in Numba
    (benchmarks/random_cost.py `rk4_rms_over`) on the sample's own records and coefficients,
    its RMS deflection over each point's window of the reference run, at the widest step
    1 / (m fs), m in RK4_STEPS, whose error is at most the shipped run's: (its table row, the
    shipped run's speed against it)."""
    import random_cost
    scene = sweep.load_scene(name, overrides=sample)
    if len(scene.axes["length"]) != 1 or len(scene.axes["base_asd_scale"]) != 1:
        raise SystemExit(f"{name}: the RK4 peer takes a sample of one span at one level")
    case = random_cost.Case(float(scene.axes["length"][0]),
                            float(scene.axes["base_asd_scale"][0]),
                            int(scene.values["base.realisations"]))
    t_end = case.t_end
    starts = t_end - np.asarray(ref_ds["statistics_window"].values, float).ravel()
    if starts.size != case.records.shape[0] or ref.size != starts.size:
        raise SystemExit(f"{name}: expected one point per record in the sample")

    def run(m: float) -> np.ndarray:
        return np.array([random_cost.rk4_rms_over(case.records[r, :, 0], case.records[r, :, 1],
                                                  case.fs, case.coef, t_end, starts[r], m)
                         for r in range(starts.size)])
    for m in RK4_STEPS:
        rms = run(m)                                     # (compiles on the first)
        e = error(rms, ref)
        if e <= e_ship:
            t = random_cost.best(lambda: run(m), max(repeats, 1)) / starts.size
            return (["RK4 (Numba, 30 lines)", "rk4", f"h = 1/({m:g} fs)", "-",
                     f"{t * 1e3:.3g}", f"{e:.2g}", f"{t / t_ship:.2f}"], t / t_ship)
    return (["RK4 (Numba, 30 lines)", "rk4", f"h >= 1/({RK4_STEPS[-1]:g} fs)", "-", "-",
             f"> {e_ship:.2g}", "-"], None)


def optional_peers() -> list[str]:
    """One line per optional peer: run, or skipped (not importable, with its install line)."""
    lines = []
    for module, line in INSTALL.items():
        try:
            mod = __import__(module)
        except ImportError:
            lines.append(f"{module}: skipped (not importable; {line})")
            continue
        version = getattr(mod, "__version__", None) or metadata.version(module)
        if module == "numbalsoda":
            lines.append(f"numbalsoda {version}: dop853 and lsoda on each scene's points "
                         "(benchmarks/scene_peers.py)")
        else:
            lines.append(f"{module} {version}: importable; not run on the scenes (its peer "
                         "needs the right-hand side rewritten in JAX; its one-mode "
                         "work-precision curve is benchmarks/work_precision.py's)")
    return lines


def numbalsoda_table(name: str, sample: dict[str, Any], shipped_rtol: float,
                     repeats: int) -> tuple[str, float | None]:
    """The numbalsoda peers of scene `name` on its sample, at the shipped run's final-state
    error (benchmarks/scene_peers.py), their rtol scan starting at the shipped rtol: (a
    Markdown table, the shipped kernel's speed-up over the fastest peer, the lower of 1 and 2
    threads; None where no peer ran)."""
    reference = {**sample, "solver.method": "dop853", "solver.rtol": 1e-12,
                 "solver.driver": "scalar"}
    pr = scene_peers.problem(name, sample)
    ref, _ = scene_peers.engine_run(name, reference)
    final, t_ship = scene_peers.engine_run(name, sample, max(repeats, 1))
    e_ship = scene_peers.final_error(final, ref, pr.n_modes)
    rows = [["as shipped (its kernel)", "", "", f"{e_ship:.2g}", f"{t_ship[1] * 1e3:.3g}",
             f"{t_ship[2] * 1e3:.3g}", "1.00 / 1.00"]]
    ratio = None
    for solver in scene_peers.SOLVERS:
        run = scene_peers.matched(pr, solver, ref, e_ship, max(repeats, 1),
                                  start=shipped_rtol)
        if run.rtol is None:
            rows.append([f"numbalsoda {solver}", solver, "none",
                         f"{run.error:.2g} (its floor, above)", "-", "-", "-"])
            continue
        r1, r2 = run.per_point[1] / t_ship[1], run.per_point[2] / t_ship[2]
        ratio = min(r1, r2) if ratio is None else min(ratio, r1, r2)
        rows.append([f"numbalsoda {solver}", solver, f"{run.rtol:g}", f"{run.error:.2g}",
                     f"{run.per_point[1] * 1e3:.3g}", f"{run.per_point[2] * 1e3:.3g}",
                     f"{r1:.2f} / {r2:.2f}"])
    table = markdown_table(["run", "method", "rtol", "final-state error",
                            "ms per point (1 thread)", "(2 threads)",
                            "shipped speed-up (1 / 2 threads)"], rows)
    return (f"Against numbalsoda at the shipped run's final-state error (max |q - q_ref| / "
            f"max |q_ref| at the run's end); times are the solve alone, the engine's without "
            f"its dataset, the peers' without the scene's outputs:\n\n{table}\n"), ratio


def scene_table(name: str, repeats: int, shipped_only: bool = False,
                full: bool = False) -> tuple[str, float | None]:
    """The scene's Markdown table and its shipped run's ratio to its fastest peer; with
    shipped_only, only the shipped run and its peers; with full, on the scene's whole grid
    rather than its sample."""
    sample = {} if full else SAMPLES[name]
    shipped = sweep.load_scene(name, overrides=sample).values
    _, ref, ref_ds = timed(name, {**sample, "solver.method": "dop853", "solver.rtol": 1e-12,
                                  "solver.driver": "scalar"}, 0)
    t_ship, x, _ = timed(name, sample, repeats)
    e_ship = error(x, ref)
    rows = [["as shipped", shipped["solver.method"], f"{shipped['solver.rtol']:g}",
             shipped["solver.driver"], f"{t_ship * 1e3:.3g}", f"{e_ship:.2g}", "1.00"]]
    best = (t_ship, "as shipped")
    for method in () if shipped_only else ("rk45", "dop853"):
        for rtol in RTOLS:
            t, y, _ = timed(name, {**sample, "solver.method": method, "solver.rtol": rtol},
                            repeats)
            e = error(y, ref)
            rows.append(["", method, f"{rtol:g}", shipped["solver.driver"], f"{t * 1e3:.3g}",
                         f"{e:.2g}", f"{t_ship / t:.2f}"])
            if e <= e_ship and t < best[0]:
                best = (t, f"{method} rtol {rtol:g}")
    # the SciPy peer: the scalar setting (shipped method) that reaches the shipped error
    ratio = None
    peer_rtol = None if not has_scipy_peer(name, sample) else next(
        (r for r in sorted(RTOLS, reverse=True)
         if error(timed(name, {**sample, "solver.driver": "scalar", "solver.rtol": r}, 0)[1],
                  ref) <= e_ship), None)
    if is_random(name, sample):
        row, ratio = rk4_peer(name, sample, ref, ref_ds, e_ship, t_ship, repeats)
        rows.append(row)
    if peer_rtol is not None:
        t_peer = scipy_peer(name, sample, shipped["solver.method"], peer_rtol)
        ratio = t_peer / t_ship
        rows.append(["SciPy solve_ivp", shipped["solver.method"], f"{peer_rtol:g}", "-",
                     f"{t_peer * 1e3:.3g}", f"<= {e_ship:.2g}", f"{ratio:.1f}"])
    table = markdown_table(["run", "method", "rtol", "driver", "ms per point (1 thread)",
                            "error", "shipped speed-up"], rows)
    which = "the whole grid" if full else "the sample"
    text = (f"### {name}\n\n{len(x)} points ({which}); error against DOP853 at rtol 1e-12 "
            f"(SciPy's steps). Fastest at the shipped error or better: {best[1]} "
            f"({t_ship / best[0]:.2f}x the shipped run).\n\n{table}\n")
    if scene_peers.available() and has_numbalsoda_peer(name, sample):
        more, r = numbalsoda_table(name, sample, float(shipped["solver.rtol"]), repeats)
        text += "\n" + more
        if r is not None:
            ratio = r if ratio is None else min(ratio, r)
    return text, ratio


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", nargs="+", default=list(SAMPLES))
    parser.add_argument("--check", type=float, default=None)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--shipped-only", action="store_true",
                        help="only the shipped run and its peers")
    parser.add_argument("--full", action="store_true",
                        help="the scenes' whole grids rather than their samples")
    args = parser.parse_args()
    print(f"Machine: {machine()}\n")
    for line in optional_peers():
        print(f"- {line}")
    print()
    failed = []
    for name in args.scene:
        if name not in SAMPLES:
            raise SystemExit(f"--scene {name}: not a built-in time-domain scene "
                             f"({', '.join(SAMPLES)})")
        text, ratio = scene_table(name, args.repeats, args.shipped_only, args.full)
        print(text, flush=True)
        if args.check is not None and ratio is not None and ratio < args.check:
            failed.append(f"{name}: {ratio:.2f}x its fastest peer, below {args.check:g}")
    print(f"    PYTHONPATH=. python benchmarks/workloads.py {' '.join(sys.argv[1:])}")
    if failed:
        print("\n".join(failed), file=sys.stderr)
        raise SystemExit(1)


if __name__ == "__main__":
    main()
