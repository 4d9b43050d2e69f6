"""The base acceleration's rate a_b'(t), which the clamp reaction's observers read where a
load peaks (kernels.excitation.signal_and_rate; docs/model.md sec. 10.5): against a central
difference of a_b(t) itself (kernels.excitation.acceleration, record_acceleration), for a
fixed sine, a logarithmic sweep up and down with its level ramp and a level table, and a
random record's cubic Hermite interpolant, across segment edges, sample edges and the ramp's
end."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sweep.kernels import excitation as ex
from sweep.models.excitation import EXCITATION_NAMES, block, ramp_time, sweep_duration, sweep_rate
from sweep.models.random import with_pieces


def _row(values: dict) -> np.ndarray:
    return np.array([float(values[name]) for name in EXCITATION_NAMES])


def _check(value, rate, times, h, scale):
    """rate(t) = (value(t), its derivative) at `times` (s), against a central difference of
    step h (s); scale: the rate's typical size (its round-off there)."""
    for t in times:
        a, da = rate(t)
        assert a == pytest.approx(value(t), rel=1e-12, abs=1e-12)
        numeric = (value(t + h) - value(t - h)) / (2.0 * h)
        assert da == pytest.approx(numeric, rel=1e-6, abs=1e-7 * scale), t


@pytest.mark.parametrize("start, stop", [(20.0, 200.0), (200.0, 20.0)])
@pytest.mark.parametrize("table", [None, [[20.0, 0.5], [60.0, 2.0], [100.0, 2.0], [200.0, 0.3]]])
def test_the_sine_kinds_rate_is_the_derivative_of_the_signal(start, stop, table):
    rate_oct = 60.0
    p = _row(block(9.80665, 2.0 * math.pi * start, sweep_rate(start, stop, rate_oct),
                   sweep_duration(start, stop, rate_oct), table, ramp_time(start, 10.0)))
    end = sweep_duration(start, stop, rate_oct)
    times = np.concatenate((np.linspace(0.001, 0.49, 37), np.linspace(0.5, end - 0.01, 211)))
    _check(lambda t: ex.acceleration(t, p, 0, 1),
           lambda t: ex.acceleration_and_rate(t, p, 0, 1), times, 1e-7,
           2.0 * 9.80665 * 2.0 * math.pi * 200.0)
    assert ex.acceleration_and_rate(end + 0.1, p, 0, 1) == (0.0, 0.0)


def test_a_fixed_sine_rate():
    p = _row(block(3.0, 2.0 * math.pi * 37.0))
    p[ex.PHASE] = 0.4
    _check(lambda t: ex.acceleration(t, p, 0, 1),
           lambda t: ex.acceleration_and_rate(t, p, 0, 1), np.linspace(0.0, 0.1, 101), 1e-8,
           3.0 * 2.0 * math.pi * 37.0)
    a, da = ex.acceleration_and_rate(0.01, p, 0, 1)
    w = 2.0 * math.pi * 37.0
    assert da == pytest.approx(3.0 * w * math.cos(w * 0.01 + 0.4), rel=1e-12)


def test_a_records_rate_is_the_derivative_of_its_hermite_interpolant():
    rng = np.random.default_rng(7)
    fs = 400.0
    records = with_pieces(rng.standard_normal((2, 2, 64)).transpose(0, 2, 1), fs)
    p = np.zeros(ex.SIZE)
    p[ex.RECORD_SCALE] = 1.7
    p[ex.RECORD_RATE] = fs
    p[ex.RECORD] = 1.0
    # (off the samples by more than the difference's step: the interpolant is C1, its second
    # derivative jumps there)
    times = np.concatenate((np.linspace(0.0, 64 / fs * 1.5, 401) + 0.37e-3 / fs,
                            np.arange(1, 30) / fs + 1e-6))
    _check(lambda t: ex.record_acceleration(t, p, 0, 1, records),
           lambda t: ex.record_and_rate(t, p, 0, 1, records), times, 1e-9, 1.7 * 3.0 * fs)
    # at a sample the rate is the sample's own derivative, times the level factor
    a, da = ex.record_and_rate(5.0 / fs, p, 0, 1, records)
    assert a == pytest.approx(1.7 * records[1, 5, 0], rel=1e-12)
    assert da == pytest.approx(1.7 * records[1, 5, 1], rel=1e-9)
