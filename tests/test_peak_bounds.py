"""The bounds that let the load observers skip a peak search (kernels.excitation.peak_bound,
kernels.modes.span_load_bound): each at least the largest value it bounds, found by dense
sampling of the functions the kernels evaluate, and not much more (a bound that is always
huge would skip nothing)."""

import math

import numba as nb
import numpy as np
import pytest

from sweep.kernels import excitation as ex
from sweep.kernels import modes as md
from sweep.models.random import with_pieces


@nb.njit(cache=True)
def _peak_bound(t0, t1, p, base):
    return ex.peak_bound(t0, t1, p, 0, 1, base)


def _sine_block(segments: bool) -> np.ndarray:
    """A log sweep 10 -> 200 Hz over 4 s; a level of 5 m/s^2, or a table 5 m/s^2 at 20 Hz
    rising to 10 at 50 Hz and falling as 1/f after (log-log), with a 0.3 s ramp."""
    p = np.zeros(ex.SIZE)
    w0 = 2.0 * math.pi * 10.0
    lam = math.log(20.0) / 4.0
    p[ex.OMEGA] = w0
    p[ex.RATE] = lam
    if not segments:
        p[ex.ACCEL] = 5.0
        return p
    u20, u50 = math.log(2.0 * math.pi * 20.0), math.log(2.0 * math.pi * 50.0)
    p[ex.SEGMENTS] = 2
    p[ex.END] = 4.0
    p[ex.LOG_OMEGA] = math.log(w0)
    p[ex.EDGE] = u20
    p[ex.EDGE + 1] = u50
    p[ex.LOG_LEVEL] = math.log(5.0)
    p[ex.LOG_LEVEL + 1] = math.log(10.0)
    p[ex.SLOPE] = (math.log(10.0) - math.log(5.0)) / (u50 - u20)
    p[ex.SLOPE + 1] = -1.0
    p[ex.RAMP] = 0.3
    return p


@pytest.mark.parametrize("segments", [False, True])
def test_a_sine_levels_bound_is_its_largest_level_over_the_interval(segments):
    """Intervals below, across and above the table's breakpoints (20 Hz at t = 1.16 s, 50 Hz at
    2.12 s): the bound is at least |a_b| everywhere on the interval and equals the largest
    level A(t) there (before the ramp's rise), sampled densely."""
    p = _sine_block(segments)
    base = True
    rng = np.random.default_rng(3)
    for t0, t1 in [(0.0, 0.5), (1.0, 1.3), (2.0, 2.3), (1.5, 1.5001), (3.0, 3.9),
                   *rng.uniform(0.0, 3.9, (20, 2))]:
        lo, hi = min(t0, t1), max(t0, t1)
        lam = p[ex.RATE]
        corners = [t for t in (math.log(2.0) / lam, math.log(5.0) / lam) if lo <= t <= hi]
        ts = np.append(np.linspace(max(lo, 1e-3), hi, 2001), corners)   # (rise(0) is 0)
        signal = np.abs([ex.acceleration(t, p, 0, 1) for t in ts])
        levels = np.array([ex.level(t, p, 0, 1) / ex._rise(t, p[ex.RAMP]) for t in ts])
        bound = _peak_bound(t0, t1, p, base)
        assert bound >= signal.max()
        assert bound == pytest.approx(levels.max(), rel=1e-6)


def test_a_records_bound_holds_on_every_interval_and_is_within_a_third_of_its_peak():
    """The record kind: a band-limited signal sampled at 10x its top frequency with its exact
    derivative (as the spectrum synthesis gives it: 24 random tones up to fs / 10), intervals
    from a fraction of a sample to many, across the period's wrap; the bound is at least
    |a_b(t)| on the cubic Hermite interpolant the kernels evaluate, sampled densely, and over
    intervals of three samples or more typically within 15 % of the sampled peak (at most
    2.5x, where the signal is small beside its rate)."""
    fs, n = 100.0, 400
    rng = np.random.default_rng(7)
    tk = np.arange(n) / fs
    records = np.empty((2, n, 2))
    for r in range(2):
        w = 2.0 * math.pi * rng.integers(1, n // 10, 24) * fs / n    # periodic in n / fs
        a, phase = rng.normal(0.0, 1.0, 24), rng.uniform(0.0, 2.0 * math.pi, 24)
        records[r, :, 0] = (a * np.sin(np.outer(tk, w) + phase)).sum(axis=1)
        records[r, :, 1] = (a * w * np.cos(np.outer(tk, w) + phase)).sum(axis=1)
    records = with_pieces(records, fs)             # what the kernels read beside the samples
    p = np.zeros(ex.SIZE)
    p[ex.RECORD] = 1
    p[ex.RECORD_RATE] = fs
    p[ex.RECORD_SCALE] = -0.7                       # a negative factor is still a size
    ratios = []
    for _ in range(60):
        t0 = rng.uniform(0.0, 2.0 * n / fs - 0.2)
        t1 = t0 + rng.uniform(0.001, 0.1)
        ts = np.linspace(t0, t1, 4001)
        peak = max(abs(ex.record_acceleration(t, p, 0, 1, records)) for t in ts)
        bound = _peak_bound(t0, t1, p, records)
        assert bound >= peak
        if t1 - t0 >= 3.0 / fs:
            ratios.append(bound / peak)
    assert ratios and np.median(ratios) < 1.15 and max(ratios) < 2.5


@pytest.mark.parametrize("n_modes", [1, 3, 5])
def test_the_span_load_bound_holds_over_its_box_of_states_and_is_reached_at_a_corner(n_modes):
    """span_loads on random rows and a random symmetric coupling (as a clamped basis has,
    with off-diagonal terms), states q with |q_i| <= q_max_i, any end load within +-load_max
    and inertia within +-inertia_max: every load's size is within the bound, and some corner
    of the box comes within 1e-12 of it where all terms' signs line up (k = 0: a non-negative
    coupling)."""
    rng = np.random.default_rng(n_modes)
    rows = rng.normal(size=(md.N_OBSERVED, n_modes))
    c = rng.normal(size=(n_modes, n_modes))
    coupling = c @ c.T
    q_max = rng.uniform(1e-4, 1e-3, n_modes)
    kappa, load_max, inertia_max = 3e4, 2.0, 5e-5
    bounds = [md.span_load_bound(rows, coupling, q_max, n_modes, kappa, load_max, inertia_max,
                                 k) for k in range(3)]
    out = np.empty(6)
    v = np.zeros(n_modes)
    for _ in range(3000):
        q = q_max * rng.choice([-1.0, 1.0], n_modes) * rng.uniform(0.0, 1.0, n_modes) ** 0.2
        md.span_loads(rows, coupling, q, v, n_modes, kappa, rng.uniform(-load_max, load_max),
                      0.0, rng.uniform(-inertia_max, inertia_max), 0.0, out)
        for k in range(3):
            assert abs(out[2 * k]) <= bounds[k] * (1.0 + 1e-12)
    positive = np.abs(coupling)
    md.span_loads(rows, positive, q_max, v, n_modes, kappa, 0.0, 0.0, 0.0, 0.0, out)
    assert out[0] == pytest.approx(md.span_load_bound(rows, positive, q_max, n_modes, kappa,
                                                      0.0, 0.0, 0), rel=1e-12)
