"""Shared helpers of the benchmark scripts in this folder (not a benchmark itself).

- `parameter_table`: the kernel's parameter rows of a scene, built exactly as `sweep.run` does.
- `scipy_rhs` / `solve_scipy`: `kernels.oscillator.acceleration` itself (its pure-Python
  form) as the right-hand side for `scipy.integrate.solve_ivp`, coefficients read from a row.
- `tail_amplitude`: max |q| over a time window from a SciPy dense output.
- `markdown_table`, `write_json`, `best_time`: reporting and timing.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import OptimizeResult, brentq

from sweep.kernels import oscillator as osc
from sweep import grid, models
from sweep.scene import Scene


def parameter_table(scene: Scene) -> np.ndarray:
    """The (n, N_PARAMS) parameter rows of every grid point, in grid (C) order, as sweep.run."""
    coords = grid.coordinates(scene)
    coeffs = models.oscillator(grid.parameters(scene, coords))
    dims = tuple(coords)
    shape = tuple(coords[d].size for d in dims)
    return grid.flatten(coeffs, osc.PARAM_NAMES, dims, shape)


def scipy_rhs(row: np.ndarray) -> Callable[[float, np.ndarray], list[float]]:
    """f(t, y) for solve_ivp from a kernel parameter row: the System's own right-hand side
    (`kernels.oscillator.acceleration`, its pure-Python form `py_func`, with libm's cos and
    sin) on the row prepared as the kernels prepare it. The same arithmetic as the scalar
    driver; as fast as a hand-written closure (1.2 us a call either way)."""
    prepared = np.empty(osc.N_PARAMS)
    osc.prepare.py_func(row, prepared, 0, 1)
    p = [float(x) for x in prepared]                  # list indexing: Python floats
    terms = osc.terms_of(parametric=True, base=bool(row[osc.BASE_ACCEL] != 0.0))
    acceleration = osc.acceleration.py_func

    def rhs(t: float, y: np.ndarray) -> list[float]:
        q, v = y
        return [v, acceleration(t, q, v, p, 0, 1, None, *terms)]

    return rhs


def solve_scipy(row: np.ndarray, t_end: float, rtol: float, atol: float,
                method: str = "RK45", dense: bool = False) -> OptimizeResult:
    """solve_ivp on [0, t_end] from the row's (q0, v0); raises if the solver fails."""
    y0 = [float(row[osc.Q0]), float(row[osc.V0])]
    sol = solve_ivp(scipy_rhs(row), (0.0, t_end), y0, method=method, rtol=rtol, atol=atol,
                    dense_output=dense)
    if not sol.success:
        raise RuntimeError(f"solve_ivp({method}) failed: {sol.message}")
    return sol


def tail_amplitude(sol: OptimizeResult, t_start: float, t_end: float, n_grid: int = 20001,
                   refine: bool = True) -> float:
    """max |q| over [t_start, t_end] from `sol.sol` (needs dense_output=True).

    The dense output is evaluated on `n_grid` evenly spaced times. Without `refine` the grid
    max is returned (it slightly underestimates the true max). With `refine`, every sign change
    of the velocity component q' between grid points is located with brentq and |q| is taken
    there too, which is how the kernel finds its extrema.
    """
    t = np.linspace(t_start, t_end, n_grid)
    q, v = sol.sol(t)
    best = float(np.max(np.abs(q)))
    if not refine:
        return best
    crossings = np.nonzero(np.signbit(v[:-1]) != np.signbit(v[1:]))[0]
    for i in crossings:
        if v[i] == 0.0:
            continue                     # the grid point itself is the extremum
        root = brentq(lambda s: float(sol.sol(s)[1]), t[i], t[i + 1], xtol=1e-15)
        best = max(best, abs(float(sol.sol(root)[0])))
    return best


def best_time(fn: Callable[[], Any], min_total: float = 0.2, max_repeats: int = 20) -> float:
    """Smallest wall time (s) of `fn()` over repeats; repeats until `min_total` s are spent."""
    times: list[float] = []
    while len(times) < max_repeats:
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
        if sum(times) >= min_total:
            break
    return min(times)


def machine() -> str:
    """The CPU's model name (from /proc/cpuinfo where there is one) and the CPUs this process
    may use."""
    import os
    import platform
    name = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{name}, {len(os.sched_getaffinity(0))} CPUs"


def markdown_table(headers: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A GitHub Markdown table; cells are str()-ed (format numbers before)."""
    lines = ["| " + " | ".join(headers) + " |",
             "|" + "|".join("---" for _ in headers) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def write_json(path: str | Path, data: dict[str, Any]) -> None:
    """Write `data` as indented JSON (NaN written as null)."""
    def clean(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        if isinstance(x, (np.floating, float)):
            return None if not math.isfinite(float(x)) else float(x)
        if isinstance(x, np.integer):
            return int(x)
        return x
    Path(path).write_text(json.dumps(clean(data), indent=2) + "\n", encoding="utf-8")
