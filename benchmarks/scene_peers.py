"""numbalsoda's dop853 and lsoda on a built-in scene's own points, from a Numba prange loop:
the peers of benchmarks/workloads.py, each at the error the scene's shipped run reaches.

The right-hand side is the System's own, compiled into a numbalsoda `cfunc` (signature
rhs(t, u, du, p)): one mode, `kernels.oscillator.acceleration` on the row as
`kernels.oscillator.prepare` leaves it (libm's cos and sin); several modes,
`kernels.modes.derivative` on the row as `kernels.modes.prepare` leaves it, the basis' tables
and polynomial frozen into the cfunc (a family of bases of one shape, harness-clamps', stacked,
each row's basis read from its data row). So a peer's time is its integrator's, over the same
arithmetic per evaluation. A sine sweep integrates each point to its own sweep end, as the
engine does; a stepped sine (its dwells chained) and random records have no peer here.

Accuracy is the final state: max |q - q_ref| / max |q_ref| over the sample's points and modes
(q in m at the run's end), q_ref from the engine's scalar DOP853 at rtol 1e-12 (SciPy's steps).
A peer at rtol r takes atol = ATOL + ATOL_SCALE r q_scale per point (the engine's displacement
tolerance, kernels/trajectory.py point_atol; numbalsoda takes one atol for every component);
its run is the loosest r in PEER_RTOLS whose error is at most the engine's.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

SOLVERS = ("dop853", "lsoda")
PEER_RTOLS = tuple(float(f"{m}e-{k}") for k in range(5, 13) for m in (3, 1))[1:]  # 1e-5..1e-12
MAX_STEPS = 2_000_000_000          # numbalsoda mxstep (a C int): no practical bound
INSTALL = ("pip install numbalsoda (its build needs cmake, a C++ compiler and gfortran: "
           "apt-get install cmake g++ gfortran)")


def available() -> bool:
    """Whether numbalsoda imports."""
    try:
        import numbalsoda  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass
class Group:
    """Points that share one compiled right-hand side: their places in the sample, data rows
    (what the cfunc reads at p) and start states."""
    rhs: Any
    points: np.ndarray
    data: np.ndarray
    u0: np.ndarray


@dataclass
class Problem:
    """A scene's sample for the peers: its groups, each point's end time (s) and displacement
    scale (m), the scene's ATOL and ATOL_SCALE, and the number of modes."""
    groups: list[Group]
    ends: np.ndarray
    q_scale: np.ndarray
    atol: float
    atol_scale: float
    n_modes: int

    def atols(self, rtol: float) -> np.ndarray:
        """Each point's absolute tolerance (m) at relative tolerance rtol."""
        return self.atol + self.atol_scale * rtol * self.q_scale


def _padded(width: int) -> int:
    """A data row's length: whole 64-byte lines, so that points on two threads share none."""
    return (width + 7) // 8 * 8


def _one_mode_rhs(parametric: bool, base: bool) -> Any:
    """The cfunc of the one-mode oscillator with its parametric and base terms as asked."""
    import numba as nb
    from numbalsoda import lsoda_sig

    from sweep.kernels import oscillator as osc
    acceleration = osc.acceleration
    par = True if parametric else None
    shaken = True if base else None

    @nb.cfunc(lsoda_sig)
    def rhs(t, u, du, p):
        du[0] = u[1]
        du[1] = acceleration(t, u[0], u[1], p, 0, 1, None, par, shaken)
    return rhs


def _modal_rhs(n: int, size: int, bases: list[tuple], base: bool) -> Any:
    """The cfunc of the N-mode model over `bases` (one shape; a data row's column `size` - 1
    its index among them): data row [prepared row | projections (n) | monomials | index]."""
    import numba as nb
    from numbalsoda import lsoda_sig

    from sweep.kernels import modes as md
    P = md.prepared_size(n)
    T_all = np.ascontiguousarray(np.stack([b[md.TABLES] for b in bases]))
    CP_all = np.ascontiguousarray(np.stack([b[md.COUPLING] for b in bases]))
    derivative = md.derivative
    shaken = True if base else None
    width = 2 * n
    last = size - 1
    PY = [np.ascontiguousarray(np.stack([b[md.POLYNOMIAL][k] for b in bases]))
          for k in range(5)]
    prog, starts, mono, coef, ends = PY
    last_group = int(bases[0][md.POLYNOMIAL][5])

    @nb.cfunc(lsoda_sig)
    def rhs(t, u, du, p):
        d = nb.carray(p, (size,))
        b = int(d[last])
        S = (d[:P], d[P:P + n], CP_all[b],
             (prog[b], starts[b], mono[b], coef[b], ends[b], last_group), d[P + n:last])
        derivative(t, nb.carray(u, (width,)), nb.carray(du, (width,)), S, n, T_all[b], shaken)
    return rhs


def _shape_key(basis: tuple) -> tuple:
    """What must agree for bases to share one cfunc (their arrays are stacked, the count of
    the polynomial's symmetric monomials frozen in): the arrays' shapes and that count."""
    from sweep.kernels import modes as md
    py = basis[md.POLYNOMIAL]
    key = (basis[md.TABLES].shape, basis[md.COUPLING].shape)
    return key + tuple(a.shape for a in py[:5]) + (py[5],)


def problem(name: str, overrides: dict[str, Any]) -> Problem:
    """The peers' problem of scene `name` with `overrides` (its sample): every grid point."""
    import sweep
    from sweep.kernels import excitation as ex
    from sweep.kernels import layout as tk
    from sweep.kernels import modes as md
    from sweep.kernels import oscillator as osc
    from sweep.models import transverse as tm
    scene = sweep.load_scene(name, overrides=overrides)
    inputs = tm.resolve(scene)
    if inputs.continuation is not None or inputs.random is not None:
        raise ValueError(f"{name}: a stepped sine or a random scene has no numbalsoda peer here")
    settings = tm.settings_vector(scene)
    n = inputs.n_modes
    base = settings[tk.BASE] != 0.0                 # the engine's switches (sweep/threads.py)
    parametric = settings[tk.CONSTANT_STIFFNESS] == 0.0
    points = np.arange(int(np.prod(inputs.shape)))
    if n == 1:
        rows = tm._system(inputs, settings).rows_at(points)
        block, q_col = osc.EXCITATION, osc.Q_SCALE
        size = _padded(osc.N_PARAMS)
        data = np.zeros((rows.shape[0], size))
        for i, row in enumerate(rows):
            osc.prepare.py_func(row, data[i], 0, 1)
        rhs = _one_mode_rhs(parametric, base)
        groups = [Group(rhs, points, data, np.ascontiguousarray(rows[:, [osc.Q0, osc.V0]]))]
    else:
        rows = tm.modal_rows(inputs, points)
        block, q_col = md.EXCITATION, md.Q_SCALE
        arrays = inputs.basis.kernel_arrays()
        family = arrays if isinstance(arrays, list) else [arrays]
        index = (rows[:, -1].astype(np.int64) if isinstance(arrays, list)
                 else np.zeros(rows.shape[0], np.int64))
        keys: dict[tuple, list[int]] = {}
        for k in np.unique(index):
            keys.setdefault(_shape_key(family[k]), []).append(int(k))
        P = md.prepared_size(n)
        groups = []
        for members in keys.values():
            py = family[members[0]][md.POLYNOMIAL]
            M = py[0].shape[0]
            size = P + n + M + 1
            mine = np.flatnonzero(np.isin(index, members))
            data = np.zeros((mine.size, _padded(size)))
            for j, i in enumerate(mine):
                md.prepare(rows[i], n, data[j, :P], family[index[i]][md.RATIOS])
                data[j, size - 1] = members.index(int(index[i]))
            rhs = _modal_rhs(n, size, [family[k] for k in members], base)
            u0 = np.ascontiguousarray(rows[mine][:, md.N_FIXED:md.N_FIXED + 2 * n])
            groups.append(Group(rhs, mine, data, u0))
    ends = (rows[:, block + ex.END].copy() if inputs.swept and inputs.per_point_end
            else np.full(rows.shape[0], float(settings[tk.T_END])))
    return Problem(groups, ends, rows[:, q_col].copy(), float(settings[tk.ATOL]),
                   float(settings[tk.ATOL_SCALE]), n)


@contextlib.contextmanager
def _quiet_fortran():
    """The process' standard output (file descriptor 1) sent to /dev/null: lsoda's Fortran
    writes a line to it each time it switches to its stiff method."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


_LOOPS: dict[str, Any] = {}


def _loop(solver: str) -> Any:
    """The prange loop of numbalsoda's `solver` over a group's points (compiled once)."""
    if solver not in _LOOPS:
        import numba as nb
        import numbalsoda
        integrate = getattr(numbalsoda, solver)

        @nb.njit(parallel=True)
        def loop(funcptr, data, u0, ends, rtol, atol, out, ok):
            for i in nb.prange(data.shape[0]):
                t_eval = np.array([0.0, ends[i]])
                usol, success = integrate(funcptr, u0[i], t_eval, data=data[i], rtol=rtol,
                                          atol=atol[i], mxstep=MAX_STEPS)
                out[i] = usol[1]
                ok[i] = success
        _LOOPS[solver] = loop
    return _LOOPS[solver]


def solve(pr: Problem, solver: str, rtol: float, threads: int) -> tuple[np.ndarray, float]:
    """(final states (n, 2N), NaN where the solver failed; wall time (s)) of `solver` at
    rtol on `threads` threads."""
    import numba
    numba.set_num_threads(threads)
    n = pr.ends.size
    final = np.full((n, 2 * pr.n_modes), math.nan)
    atols = pr.atols(rtol)
    wall = 0.0
    loop = _loop(solver)
    for g in pr.groups:
        out = np.empty((g.points.size, 2 * pr.n_modes))
        ok = np.zeros(g.points.size, dtype=np.bool_)
        ends, atol = pr.ends[g.points], atols[g.points]
        with _quiet_fortran():
            start = time.perf_counter()
            loop(g.rhs.address, g.data, g.u0, ends, rtol, atol, out, ok)
            wall += time.perf_counter() - start
        out[~ok] = math.nan
        final[g.points] = out
    return final, wall


def final_error(final: np.ndarray, ref: np.ndarray, n_modes: int) -> float:
    """max |q - q_ref| / max |q_ref| over points and modes (the displacements of the final
    states; inf where a point has none)."""
    q, q_ref = final[:, :n_modes], ref[:, :n_modes]
    if not np.all(np.isfinite(q)):
        return math.inf
    return float(np.max(np.abs(q - q_ref)) / np.max(np.abs(q_ref)))


def engine_run(name: str, overrides: dict[str, Any], repeats: int = 0,
               threads: tuple[int, ...] = (1, 2)) -> tuple[np.ndarray, dict[int, float]]:
    """(the engine's final states (n, 2N) (m, m/s) of the sample, as the scene's run solves it:
    its own method, tolerance and driver; the kernel call's time per point (s) on each of
    `threads`, best of `repeats` after a first run on every core, none with repeats 0). The
    kernel call is the run's solve without its dataset (sweep.execute's chunk function on
    every point)."""
    import sweep
    from sweep.kernels import layout as tk
    from sweep.models import transverse as tm
    scene = sweep.load_scene(name, overrides=overrides)
    inputs = tm.resolve(scene)
    system = tm._system(inputs, tm.settings_vector(scene))
    rows = system.rows_at(np.arange(int(np.prod(inputs.shape))))
    out = system.chunk_fn(rows, *system.args, threads=0)   # (untimed: every core; compiles)
    times = {}
    for k in threads if repeats else ():
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            system.chunk_fn(rows, *system.args, threads=k)
            best = min(best, time.perf_counter() - start)
        times[k] = best / rows.shape[0]
    if inputs.n_modes == 1:
        final = np.stack([out["reals"][:, tk.Q_END], out["reals"][:, tk.V_END]], axis=1)
    else:
        final = np.asarray(out["final"])
    return final, times


@dataclass
class PeerRun:
    """A peer's run at the scene's error: solver, rtol, error, time per point (s) on 1 and 2
    threads; rtol None where no rtol in PEER_RTOLS reaches the error."""
    solver: str
    rtol: float | None
    error: float
    per_point: dict[int, float]


def matched(pr: Problem, solver: str, ref: np.ndarray, target: float, repeats: int,
            start: float = 1e-8, threads: tuple[int, ...] = (1, 2)) -> PeerRun:
    """`solver`'s loosest rtol in PEER_RTOLS whose final-state error is at most `target`,
    timed (best of `repeats` after its first run) on each of `threads`: the scan starts at
    `start` (the shipped rtol), loosens while the error stays within the target and tightens
    until it comes within (errors fall as rtol does), or until two steps tighter have not
    cut it by a fifth (the solver's floor: none reaches the target)."""
    n = pr.ends.size
    errors: dict[float, float] = {}

    def error_at(k: int) -> float:
        if PEER_RTOLS[k] not in errors:
            final, _ = solve(pr, solver, PEER_RTOLS[k], 1)   # (the first compiles)
            errors[PEER_RTOLS[k]] = final_error(final, ref, pr.n_modes)
        return errors[PEER_RTOLS[k]]

    k = int(np.argmin(np.abs(np.log(np.array(PEER_RTOLS) / start))))
    if error_at(k) <= target:
        while k > 0 and error_at(k - 1) <= target:
            k -= 1
    else:
        first = k
        while k + 1 < len(PEER_RTOLS) and error_at(k) > target:
            k += 1
            if k - first >= 2 and error_at(k) > 0.8 * error_at(k - 2):
                break                # a floor: tightening no longer lowers the error
        if error_at(k) > target:
            return PeerRun(solver, None, error_at(k), {})
    rtol = PEER_RTOLS[k]
    times = {t: min(solve(pr, solver, rtol, t)[1] for _ in range(max(repeats, 1))) / n
             for t in threads}
    return PeerRun(solver, rtol, error_at(k), times)
