"""Response metrics of one trajectory from a dense solution, in plain Python/NumPy/SciPy.

This module mirrors the metric definitions of `kernels/metrics.py` and `kernels/transverse.py`
(`solve_point`) and of the README's "What the output holds", but is written independently of
them: it shares no code with the kernel and works on any dense solution `dense(t) -> (q, q')`,
for example `sol.sol` of `scipy.integrate.solve_ivp(..., dense_output=True)`, or a piecewise
Hermite interpolant through sampled output (`HermiteSamples`). The benchmarks use it to measure
what a user reads (amplitude, settling time, state) from solvers that do not compute it.

Definitions (tail window [t_tail, t_end], t_tail = t_end (1 - tail); tolerance `tol`):
- extrema: every sign change of q' between consecutive grid times, located with brentq on the
  dense q'. A cell holds a maximum when q' > 0 at its left end and q' <= 0 at its right end, a
  minimum when q' < 0 then q' >= 0 (the kernel's rule on step ends: q'(0) = 0 at rest is not an
  extremum). Two extrema inside one grid cell are missed, so the grid must resolve the motion.
- tail amplitude A: max |q| over the extrema in the tail, q(t_tail) and q(t_end) (also the grid
  samples in the tail, which never exceed the true max).
- peak P: max |q| over the whole run: q(0), every extremum, q(t_end) (and the grid samples).
- state and settling time Ts:
    decayed    A <= tol * P;  Ts = the last time |q| > tol * P (brentq on the dense q).
    steady     >= 2 maxima and >= 2 minima in the tail, and the last extremum (whole run) farther
               than tol * A from the last extremum of its own kind (maxima vs minima) lies before
               t_tail;  Ts = the time of that extremum, 0 when there is none.
               Also steady: fewer extrema than that in the tail but the tail's range of q is
               <= tol * A (at rest away from zero); Ts = the last time |q - q(t_end)| > tol * A.
    unsettled  the envelope drifts one way: the max |q| of the tail extrema in each quarter of
               the tail strictly falls, or strictly rises, quarter to quarter; or too few
               extrema in the tail and a range > tol * A.  Ts = NaN.
    modulated  >= 2 maxima and minima in the tail, not steady, no one-way drift.  Ts = NaN.
- period: mean time between maxima in the tail (NaN with fewer than 2).

`self_check()` runs the definitions on closed-form signals (python benchmarks/reference_metrics.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.interpolate import PPoly
from scipy.optimize import brentq

Dense = Callable[[np.ndarray | float], np.ndarray]    # t -> array (2, ...) of q, q'

DECAYED = "decayed"
STEADY = "steady"
MODULATED = "modulated"
UNSETTLED = "unsettled"
HAS_SETTLING = (DECAYED, STEADY)


@dataclass
class Metrics:
    """What the kernel reports for one trajectory, from a dense solution."""
    state: str
    amplitude: float         # max |q| over the tail window
    peak: float              # max |q| over the whole run
    settling_time: float     # s; NaN unless decayed or steady
    period: float            # mean time between maxima in the tail; NaN with fewer than 2
    q_end: float             # q(t_end)
    ext_t: np.ndarray        # times of all extrema
    ext_q: np.ndarray        # q at the extrema
    ext_max: np.ndarray      # True for maxima, False for minima


class HermiteSamples:
    """Piecewise quintic Hermite interpolant of sampled q, q', q'' (a dense output from samples).

    Called as `h(t)`, it returns [q(t), q'(t)] like SciPy's `sol.sol`. On a sinusoid of angular
    frequency w sampled every dt its error is about (w dt)^6 / 46080 of the amplitude (the plain
    maximum of the samples underestimates a peak by up to (w dt)^2 / 8).
    """

    def __init__(self, t: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray):
        t, q, v, a = (np.asarray(x, dtype=float) for x in (t, q, v, a))
        h = np.diff(t)
        y0, y1 = q[:-1], q[1:]
        d0, d1 = h * v[:-1], h * v[1:]
        s0, s1 = h * h * a[:-1], h * h * a[1:]
        # coefficients of x^k, x = (t - t_i) / h in [0, 1]
        a0 = y0
        a1 = d0
        a2 = 0.5 * s0
        a3 = -10 * y0 - 6 * d0 - 1.5 * s0 + 10 * y1 - 4 * d1 + 0.5 * s1
        a4 = 15 * y0 + 8 * d0 + 1.5 * s0 - 15 * y1 + 7 * d1 - s1
        a5 = -6 * y0 - 3 * d0 - 0.5 * s0 + 6 * y1 - 3 * d1 + 0.5 * s1
        c = np.array([a5 / h**5, a4 / h**4, a3 / h**3, a2 / h**2, a1 / h, a0])
        self.q = PPoly(c, t, extrapolate=True)
        self.v = self.q.derivative()
        self.t = t

    def __call__(self, t):
        return np.array([self.q(t), self.v(t)])


def _crossing(f: Callable[[float], float], a: float, b: float) -> float:
    """Root of f in [a, b] (f(a), f(b) of opposite signs or zero at an end)."""
    fa, fb = f(a), f(b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    return brentq(f, a, b, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)


def extrema(dense: Dense, grid: np.ndarray, v_grid: np.ndarray):
    """All extrema of q: (times, values, is_max), from sign changes of q' on `grid`."""
    va, vb = v_grid[:-1], v_grid[1:]
    is_max = (va > 0.0) & (vb <= 0.0)
    is_min = (va < 0.0) & (vb >= 0.0)
    cells = np.nonzero(is_max | is_min)[0]
    ts = np.empty(cells.size)

    def v_at(s: float) -> float:
        return float(dense(s)[1])

    for j, i in enumerate(cells):
        ts[j] = _crossing(v_at, float(grid[i]), float(grid[i + 1]))
    qs = np.asarray(dense(ts)[0], dtype=float).reshape(-1) if ts.size else np.empty(0)
    return ts, qs, is_max[cells]


def last_time_above(dense: Dense, times: np.ndarray, values: np.ndarray, centre: float,
                    thr: float) -> float:
    """The last time |q - centre| > thr. `times` (sorted) must hold every extremum of q, so
    that q is monotone between consecutive entries; `values` = q there. 0.0 if never."""
    above = np.nonzero(np.abs(values - centre) > thr)[0]
    if above.size == 0:
        return 0.0
    i = int(above[-1])
    if i == times.size - 1:
        return float(times[-1])
    side = 1.0 if values[i] > centre else -1.0
    level = centre + side * thr
    return _crossing(lambda s: float(dense(s)[0]) - level, float(times[i]), float(times[i + 1]))


def envelope_violation(ext_q: np.ndarray, ext_t: np.ndarray, ext_max: np.ndarray,
                       band: float) -> float:
    """Time of the last extremum farther than `band` from the last extremum of its own kind
    (maxima against the last maximum, minima against the last minimum); 0.0 if none."""
    last_max = ext_q[ext_max][-1] if np.any(ext_max) else math.nan
    last_min = ext_q[~ext_max][-1] if np.any(~ext_max) else math.nan
    level = np.where(ext_max, last_max, last_min)
    out = np.nonzero(np.abs(ext_q - level) > band)[0]
    return float(ext_t[out[-1]]) if out.size else 0.0


def drifts(ext_q: np.ndarray, ext_t: np.ndarray, t_tail: float, t_end: float) -> bool:
    """True when the max |q| of the tail extrema per quarter of the tail window strictly falls or
    strictly rises from quarter to quarter (an empty quarter counts as 0)."""
    quarter = np.zeros(4)
    width = (t_end - t_tail) / 4.0
    for t, q in zip(ext_t, ext_q):
        if t < t_tail:
            continue
        j = min(3, int((t - t_tail) / width)) if width > 0 else 3
        quarter[j] = max(quarter[j], abs(q))
    d = np.diff(quarter)
    return bool(np.all(d < 0) or np.all(d > 0))


def response_metrics(dense: Dense, t_end: float, tail: float = 0.5, tol: float = 0.02,
                     grid: np.ndarray | None = None, n_grid: int = 20001) -> Metrics:
    """The kernel's metrics of the trajectory `dense` on [0, t_end] (see the module docstring).

    grid: the times whose q' sign changes bracket the extrema (default: n_grid evenly spaced
    on [0, t_end]); for sampled output, pass the sample times.
    """
    if grid is None:
        grid = np.linspace(0.0, t_end, n_grid)
    grid = np.asarray(grid, dtype=float)
    t_tail = t_end * (1.0 - tail)
    qg, vg = dense(grid)
    ext_t, ext_q, ext_max = extrema(dense, grid, vg)
    q_tail = float(dense(t_tail)[0])
    q_end = float(dense(t_end)[0])
    q_start = float(dense(0.0)[0])

    in_tail = ext_t >= t_tail
    tail_vals = np.concatenate([ext_q[in_tail], [q_tail, q_end], qg[grid >= t_tail]])
    amplitude = float(np.max(np.abs(tail_vals)))
    q_lo, q_hi = float(np.min(tail_vals)), float(np.max(tail_vals))
    peak = float(np.max(np.abs(np.concatenate([[q_start, q_end, q_tail], ext_q, qg]))))
    tail_max_t = ext_t[in_tail & ext_max]
    n_max = tail_max_t.size
    n_min = int(np.sum(in_tail & ~ext_max))
    period = float((tail_max_t[-1] - tail_max_t[0]) / (n_max - 1)) if n_max >= 2 else math.nan

    # every extremum, the grid and the tail start, in time order: q is monotone in between
    times = np.concatenate([grid, ext_t, [t_tail]])
    values = np.concatenate([qg, ext_q, [q_tail]])
    order = np.argsort(times, kind="stable")
    times, values = times[order], values[order]

    band = tol * amplitude
    settling = math.nan
    if amplitude <= tol * peak:
        state = DECAYED
        settling = last_time_above(dense, times, values, 0.0, tol * peak)
    elif n_max >= 2 and n_min >= 2:
        t_settle = envelope_violation(ext_q, ext_t, ext_max, band)
        if t_settle < t_tail:
            state, settling = STEADY, t_settle
        else:
            state = UNSETTLED if drifts(ext_q, ext_t, t_tail, t_end) else MODULATED
    elif q_hi - q_lo <= band:
        state = STEADY
        settling = last_time_above(dense, times, values, q_end, band)
    else:
        state = UNSETTLED
    return Metrics(state, amplitude, peak, settling, period, q_end, ext_t, ext_q, ext_max)


def self_check(verbose: bool = True) -> None:
    """Checks the definitions on closed-form signals; raises AssertionError on a failure."""
    t_end, w = 5.0, 2 * math.pi * 7.3

    def dense_of(q: Callable, v: Callable) -> Dense:
        return lambda t: np.array([q(t), v(t)])

    # a steady sinusoid with a decaying transient: cos(w t) (1 + e^(-t/0.2)); amplitude 1 + tiny
    tau = 0.2
    q = lambda t: np.cos(w * t) * (1 + np.exp(-t / tau))                          # noqa: E731
    v = lambda t: (-w * np.sin(w * t) * (1 + np.exp(-t / tau))                   # noqa: E731
                   - np.cos(w * t) * np.exp(-t / tau) / tau)
    m = response_metrics(dense_of(q, v), t_end)
    assert m.state == STEADY, m.state
    assert abs(m.peak - 2.0) < 1e-9, m.peak
    # the largest tail extremum is the first, at w t = 37 pi
    first = 2.5 + 0.5 * math.pi / w
    assert abs(m.amplitude - (1.0 + math.exp(-first / tau))) < 1e-9, m.amplitude
    assert abs(m.period - 2 * math.pi / w) < 1e-9, m.period
    # the last extremum more than 0.02 from +-1: e^(-t/tau) > 0.02 up to tau ln 50 = 0.782 s
    assert 0.782 - math.pi / w <= m.settling_time <= 0.783, m.settling_time
    # the extrema sit at multiples of pi/w (to the shift the transient makes): check the count
    assert abs(m.ext_t.size - round(t_end * w / math.pi)) <= 1, m.ext_t.size

    # a decaying oscillation e^(-t/tau) cos(w t): decayed, Ts where e^(-t/tau)|cos| = 0.02
    q = lambda t: np.exp(-t / tau) * np.cos(w * t)                                # noqa: E731
    v = lambda t: np.exp(-t / tau) * (-w * np.sin(w * t) - np.cos(w * t) / tau)  # noqa: E731
    m = response_metrics(dense_of(q, v), t_end)
    assert m.state == DECAYED, m.state
    assert abs(abs(q(m.settling_time)) - 0.02) < 1e-12, m.settling_time
    assert tau * math.log(50) - math.pi / w <= m.settling_time <= tau * math.log(50) + 1e-9

    # beating: cos(w t) + 0.5 cos(1.1 w t): modulated, no settling time
    q = lambda t: np.cos(w * t) + 0.5 * np.cos(1.1 * w * t)                      # noqa: E731
    v = lambda t: -w * np.sin(w * t) - 0.55 * w * np.sin(1.1 * w * t)            # noqa: E731
    m = response_metrics(dense_of(q, v), t_end)
    assert m.state == MODULATED and math.isnan(m.settling_time), m

    # a slowly growing oscillation: unsettled
    q = lambda t: np.exp(t / 3) * np.cos(w * t)                                  # noqa: E731
    v = lambda t: np.exp(t / 3) * (-w * np.sin(w * t) + np.cos(w * t) / 3)      # noqa: E731
    m = response_metrics(dense_of(q, v), t_end)
    assert m.state == UNSETTLED and math.isnan(m.settling_time), m

    # at rest away from zero: q = 1 + e^(-t/tau) (no extrema): steady, Ts where e^(-t/tau)=0.02
    q = lambda t: 1 + np.exp(-t / tau)                                           # noqa: E731
    v = lambda t: -np.exp(-t / tau) / tau                                        # noqa: E731
    m = response_metrics(dense_of(q, v), t_end)
    assert m.state == STEADY and abs(m.settling_time - tau * math.log(50)) < 1e-6, m

    # the sampled interpolant against the closed form of the steady case
    tau = 0.2
    q = lambda t: np.cos(w * t) * (1 + np.exp(-t / tau))                          # noqa: E731
    v = lambda t: (-w * np.sin(w * t) * (1 + np.exp(-t / tau))                   # noqa: E731
                   - np.cos(w * t) * np.exp(-t / tau) / tau)
    h = 1e-7
    ts = np.linspace(0.0, t_end, 5001)
    a = (v(ts + h) - v(ts - h)) / (2 * h)
    exact = response_metrics(dense_of(q, v), t_end)
    sampled = response_metrics(HermiteSamples(ts, q(ts), v(ts), a), t_end, grid=ts)
    assert sampled.state == exact.state
    assert abs(sampled.amplitude - exact.amplitude) < 1e-7, (sampled.amplitude, exact.amplitude)
    assert abs(sampled.settling_time - exact.settling_time) < 1e-6
    if verbose:
        print("reference_metrics self-check passed")


if __name__ == "__main__":
    self_check()
