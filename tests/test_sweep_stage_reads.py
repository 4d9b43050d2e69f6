"""A logarithmic sweep's stage reads from the step's start (kernels.excitation.sweep_anchor and
`anchored`, which the one-mode scalar driver's steps use instead of evaluating a_b at every
stage): against the closed form a_b(t) = A(t) sin(phi(t)) evaluated in extended precision
(numpy's longdouble), written here from docs/model.md sec. 6, at every stage time of DOP853
and RK45 steps along sweeps up and down, with a constant level and with a level table whose
slopes differ (before, between and after its edges), and the anchor refused where a step
crosses a segment edge, the ramp's end or the sweep's end, or where the series it takes would
not hold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sweep.kernels import dop853, dopri5
from sweep.kernels import excitation as ex
from sweep.models.excitation import EXCITATION_NAMES, block, ramp_time, sweep_duration, sweep_rate

G = 9.80665
TABLE = [[20.0, 0.5], [60.0, 2.0], [100.0, 2.0], [200.0, 0.3]]


def _row(start: float, stop: float, rate_oct: float, table) -> tuple[np.ndarray, dict]:
    values = block(2.0 * G, 2.0 * math.pi * start, sweep_rate(start, stop, rate_oct),
                   sweep_duration(start, stop, rate_oct), table, ramp_time(start, 10.0))
    return np.array([float(values[name]) for name in EXCITATION_NAMES]), values


def _exact(t: float, start: float, stop: float, rate_oct: float, table) -> float:
    """a_b(t) (m/s^2) in extended precision: f(t) = start 2^(+-rate t / 60), phi = 2 pi int f,
    the level the table's log-log interpolation at f(t) (or 2 g), full level (t past the
    ramp)."""
    x = np.longdouble
    sign = 1 if stop > start else -1
    lam = sign * x(rate_oct) * np.log(x(2)) / x(60)
    t = x(t)
    f = x(start) * np.exp(lam * t)
    phi = 2 * x(np.pi) * x(start) * np.expm1(lam * t) / lam
    if table is None:
        level = 2 * x(G)
    else:
        fs = [x(b[0]) for b in table]
        k = min(max([0] + [i for i in range(len(fs) - 1) if f >= fs[i]]), len(fs) - 2)
        slope = np.log(x(table[k + 1][1]) / x(table[k][1])) / np.log(fs[k + 1] / fs[k])
        level = x(table[k][1]) * x(G) * (f / fs[k]) ** slope
    return float(level * np.sin(phi))


@pytest.mark.parametrize("start, stop", [(20.0, 200.0), (200.0, 20.0)])
@pytest.mark.parametrize("table", [None, TABLE])
@pytest.mark.parametrize("nodes", [dop853.C, dopri5.C], ids=["dop853", "rk45"])
def test_stage_reads_from_the_step_start_are_the_sweeps_signal(start, stop, table, nodes):
    rate_oct = 60.0
    p, values = _row(start, stop, rate_oct, table)
    end = values["sweep_end"]
    rng = np.random.default_rng(3)
    used = 0
    for t in np.concatenate((rng.uniform(values["level_ramp"], end - 0.01, 60),
                             [values["level_ramp"], end - 2e-3])):
        h = 1e-3 * rng.uniform(0.05, 1.0)
        anchor = ex.sweep_anchor(t, h, p, 0, 1)
        if anchor[0] == 0.0:
            continue
        used += 1
        for c in list(nodes) + [1.0]:
            tau = c * h
            got = ex.anchored(anchor, tau, p[ex.RATE])
            want = _exact(t + tau, start, stop, rate_oct, table)
            # the phase's own rounding, |phi| ulp, is the floor both ways of reading a_b
            phase = abs(ex.phase(t + tau, p, 0, 1))
            tol = 2.0 * G * 2.0 * (4e-16 + 2.0 * np.spacing(phase))
            assert got == pytest.approx(want, abs=tol), (t, tau)
            assert got == pytest.approx(ex.acceleration(t + tau, p, 0, 1), abs=tol), (t, tau)
    assert used >= 50                        # the anchor holds for most steps


def test_the_anchor_is_refused_where_a_step_crosses_an_edge_the_ramp_or_the_end():
    p, values = _row(20.0, 200.0, 60.0, TABLE)
    lam = values["sweep_rate"]
    edge = (math.log(2.0 * math.pi * 60.0) - values["log_base_omega"]) / lam   # f = 60 Hz
    ramp = values["level_ramp"]
    end = values["sweep_end"]
    h = 1e-3
    assert ex.sweep_anchor(edge - 0.5 * h, h, p, 0, 1)[0] == 0.0          # an edge inside
    assert ex.sweep_anchor(edge + 0.5 * h, h, p, 0, 1)[0] == 1.0
    assert ex.sweep_anchor(ramp - 0.5 * h, h, p, 0, 1)[0] == 0.0          # the ramp's end
    assert ex.sweep_anchor(end - 0.5 * h, h, p, 0, 1)[0] == 0.0           # the sweep's end
    assert ex.sweep_anchor(end - 1.5 * h, h, p, 0, 1)[0] == 1.0
    long_step = 1.01 * ex.STAGE_SERIES_BELOW / abs(lam)                  # the series' limit
    assert ex.sweep_anchor(ramp + 0.1, long_step, p, 0, 1)[0] == 0.0
    fixed, _ = _row(20.0, 200.0, 60.0, None)
    fixed[ex.RATE] = 0.0                                                   # a fixed frequency
    assert ex.sweep_anchor(1.0, h, fixed, 0, 1)[0] == 0.0
