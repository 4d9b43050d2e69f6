"""sweep/models/random.py, the random base excitation's input side: the ASD table, its mean
square, the sampled Gaussian records, their Hermite interpolation and the exact linear
responses, each checked against something independent (a quadrature, the published GEVS and
Miles figures, a Welch estimate, an explicit sum of cosines, scipy.integrate.quad)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, signal

from sweep.errors import UserError
from sweep.models import random as rnd

G = 9.80665
GEVS = [[20, 0.026], [50, 0.16], [800, 0.16], [2000, 0.026]]


@pytest.fixture(scope="module")
def gevs():
    return rnd.spectrum(GEVS)


# ---- spectrum, asd_at, mean_square ----------------------------------------------------------

def test_spectrum_converts_g2_and_keeps_si_levels():
    f, W = rnd.spectrum(GEVS)
    assert f.dtype == W.dtype == np.float64
    np.testing.assert_array_equal(f, [20.0, 50.0, 800.0, 2000.0])
    np.testing.assert_allclose(W, np.array([0.026, 0.16, 0.16, 0.026]) * G ** 2, rtol=1e-15)
    f2, W2 = rnd.spectrum([[10, 3.0], [100, 3.0]], key="base.asd", per_g2=False)
    np.testing.assert_array_equal(W2, [3.0, 3.0])
    f3, _ = rnd.spectrum(np.array(GEVS, float))                  # an array of rows works too
    np.testing.assert_array_equal(f3, f)


def test_asd_at_interpolates_log_log_and_is_zero_outside(gevs):
    f, W = gevs
    np.testing.assert_allclose(rnd.asd_at(f, f, W), W, rtol=1e-14)
    # a log-log straight line: at the geometric mean of a segment, the geometric mean level
    mid = math.sqrt(20.0 * 50.0)
    assert rnd.asd_at(mid, f, W) == pytest.approx(math.sqrt(0.026 * 0.16) * G ** 2, rel=1e-13)
    # the rising slope is +6 dB/octave-ish: 0.026 -> 0.16 over log2(2.5) octaves
    slope_db = 10 * math.log10(0.16 / 0.026) / math.log2(50 / 20)
    level = rnd.asd_at([25.0, 30.0], f, W)
    assert 10 * math.log10(level[1] / level[0]) / math.log2(30 / 25) == pytest.approx(slope_db)
    np.testing.assert_array_equal(rnd.asd_at([0.0, 19.999, 2000.001, 1e6, -5.0], f, W), 0.0)
    assert rnd.asd_at(np.ones((2, 3)) * 100, f, W).shape == (2, 3)


def test_gevs_mean_square_against_a_fine_trapezoid_and_the_published_grms(gevs):
    f, W = gevs
    # trapezoid of W(f) f d(ln f) on a dense log grid that holds the breakpoints
    total = 0.0
    for lo, hi in zip(f[:-1], f[1:]):
        x = np.geomspace(lo, hi, 20001)
        y = rnd.asd_at(x, f, W) * x
        lx = np.log(x)
        total += float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(lx)))
    assert rnd.mean_square(f, W) == pytest.approx(total, rel=1e-6)
    # GSFC-STD-7000 (GEVS): qualification 14.1 grms, acceptance (-3 dB) 10.0 grms
    assert rnd.grms(f, W) == pytest.approx(14.1, rel=0.005)
    assert round(rnd.grms(f, W), 2) == 14.14
    assert rnd.grms(f, W * 10 ** -0.3) == pytest.approx(10.0, rel=0.005)


def test_mean_square_flat_and_minus_one_slopes_in_closed_form():
    f, W = rnd.spectrum([[10, 2.0], [110, 2.0]], key="base.asd", per_g2=False)
    assert rnd.mean_square(f, W) == pytest.approx(200.0, rel=1e-14)
    # W = 1/f (slope b = -1, -3 dB/octave): integral ln(f1/f0)
    f, W = rnd.spectrum([[10, 0.1], [1000, 0.001]], key="base.asd", per_g2=False)
    assert rnd.mean_square(f, W) == pytest.approx(math.log(100.0), rel=1e-13)
    # b close to -1 loses no digits: W = x^(-1 + 1e-9) between 1 and e
    f, W = np.array([1.0, math.e]), np.array([1.0, math.e ** (-1 + 1e-9)])
    expected = math.expm1(1e-9) / 1e-9
    assert rnd.mean_square(f, W) == pytest.approx(expected, rel=1e-12)
    assert rnd.default_sample_rate(np.array([20.0, 2000.0])) == 20000.0


# ---- synthesise -----------------------------------------------------------------------------

def test_ensemble_mean_square_matches_the_spectrum_within_three_standard_errors(gevs):
    f, W = gevs
    rec = rnd.synthesise(f, W, 1.0, 20000.0, 64, 11)
    assert rec.values.shape == (64, 20000, rnd.RECORD_ROWS)
    assert rec.values.dtype == np.float64
    assert rec.values.flags.c_contiguous
    assert (rec.realisations, rec.samples, rec.period, rec.sample_rate) == (64, 20000, 1.0,
                                                                          20000.0)
    per_record = np.mean(rec.values[:, :, 0] ** 2, axis=1)
    standard_error = per_record.std(ddof=1) / math.sqrt(per_record.size)
    assert abs(per_record.mean() - rnd.mean_square(f, W)) < 3 * standard_error
    # and the spread is a Gaussian record's (Rayleigh amplitudes), not zero (random phases)
    assert per_record.std() > 0.005 * per_record.mean()
    # zero mean: DC carries nothing
    assert np.max(np.abs(rec.values[:, :, 0].mean(axis=1))) < 1e-12 * math.sqrt(per_record.max())


def test_welch_estimate_matches_the_asd_in_the_flat_band(gevs):
    f, W = gevs
    rec = rnd.synthesise(f, W, 2.0, 20000.0, 16, 3)
    freq, psd = signal.welch(rec.values[:, :, 0], fs=20000.0, window="hann", nperseg=2048,
                             detrend=False, axis=-1)
    band = (freq >= 60.0) & (freq <= 780.0)
    mean = psd[:, band].mean(axis=0)
    se = psd[:, band].std(axis=0, ddof=1) / math.sqrt(psd.shape[0])
    target = rnd.asd_at(freq[band], f, W)
    assert np.all(np.abs(mean - target) < 5 * se)
    assert mean.mean() / target.mean() == pytest.approx(1.0, abs=0.02)
    # and outside the spectrum there is (almost) nothing: only the window's leakage
    high = freq >= 3000.0
    assert psd[:, high].max() < 1e-6 * target.mean()


def test_coefficients_dc_nyquist_and_out_of_band_are_zero():
    f, W = rnd.spectrum([[100, 0.1], [400, 0.1]])
    rec = rnd.synthesise(f, W, 0.25, 2000.0, 2, 5)
    X = np.fft.rfft(rec.values[0, :, 0])
    fk = np.fft.rfftfreq(rec.samples, 1 / rec.sample_rate)
    big = np.max(np.abs(X))
    assert abs(X[0]) < 1e-12 * big and abs(X[-1]) < 1e-12 * big
    assert np.all(np.abs(X[(fk < 100) | (fk > 400)]) < 1e-12 * big)
    assert np.all(np.abs(X[(fk >= 100) & (fk <= 400)]) > 0)


def _cosine_sum(x: np.ndarray, fs: float, t: np.ndarray, derivative: bool) -> np.ndarray:
    """The periodic signal of samples x as an explicit sum of cosines (from its rfft, summed
    term by term, no inverse FFT), or its analytic time derivative, at times t."""
    n = x.size
    X = np.fft.rfft(x)
    k = np.arange(1, n // 2)                              # no DC, no Nyquist (both zero here)
    w = 2 * np.pi * k * fs / n
    amp, phase = 2 * np.abs(X[k]) / n, np.angle(X[k])
    arg = np.outer(t, w) + phase
    if derivative:
        return -(np.sin(arg) * (amp * w)).sum(axis=1)
    return (np.cos(arg) * amp).sum(axis=1)


def test_derivative_record_is_the_analytic_derivative():
    f, W = rnd.spectrum([[100, 0.1], [400, 0.1]])
    rec = rnd.synthesise(f, W, 0.25, 2000.0, 2, 8)
    fs, n = rec.sample_rate, rec.samples
    t = np.arange(n) / fs
    for r in range(2):
        x, dx = rec.values[r, :, :2].T
        np.testing.assert_allclose(_cosine_sum(x, fs, t, False), x, atol=1e-10 * np.abs(x).max())
        np.testing.assert_allclose(_cosine_sum(x, fs, t, True), dx,
                                   atol=1e-10 * np.abs(dx).max())
        # a centred difference of a finer evaluation, h = 1e-6 s
        h = 1e-6
        fd = (_cosine_sum(x, fs, t + h, False) - _cosine_sum(x, fs, t - h, False)) / (2 * h)
        np.testing.assert_allclose(fd, dx, atol=1e-6 * np.abs(dx).max())


@pytest.mark.parametrize("threads", [1, 2, 5])
def test_records_follow_the_documented_draws(threads):
    """Another engineer may rebuild a record from docs/model.md sec. 11:
    a_k, b_k = sqrt(W df) x rng.standard_normal((2, N//2 + 1)),
    x(t) = sum a_k cos(2 pi f_k t) + b_k sin(2 pi f_k t);
    made on one thread or several (more threads than records included), the same records."""
    f, W = rnd.spectrum([[100, 0.1], [300, 0.3], [400, 0.05]])
    seed, fs = 21, 1500.0
    rec = rnd.synthesise(f, W, 0.2, fs, 3, seed, threads=threads)
    n = rec.samples
    assert n == 300
    df = fs / n
    fk = np.arange(n // 2 + 1) * df
    sd = np.sqrt(rnd.asd_at(fk, f, W) * df)
    sd[0] = sd[-1] = 0.0
    t = np.arange(n) / fs
    for r in range(3):
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r,)))
        a, b = rng.standard_normal((2, n // 2 + 1)) * sd
        arg = 2 * np.pi * np.outer(t, fk)
        x = np.cos(arg) @ a + np.sin(arg) @ b
        dx = 2 * np.pi * ((-np.sin(arg) * fk) @ a + (np.cos(arg) * fk) @ b)
        np.testing.assert_allclose(rec.values[r, :, 0], x, atol=1e-11 * np.abs(x).max())
        np.testing.assert_allclose(rec.values[r, :, 1], dx, atol=1e-11 * np.abs(dx).max())


def test_records_are_deterministic_and_realisations_are_stable(gevs):
    f, W = gevs
    a = rnd.synthesise(f, W, 0.1, 20000.0, 3, 42)
    b = rnd.synthesise(f, W, 0.1, 20000.0, 3, 42)
    c = rnd.synthesise(f, W, 0.1, 20000.0, 5, 42)
    d = rnd.synthesise(f, W, 0.1, 20000.0, 3, 43)
    e = rnd.synthesise(f, W, 0.1, 20000.0, 3, 42, threads=2)
    assert np.array_equal(a.values, b.values)
    assert np.array_equal(a.values, e.values)                 # the same bits on 2 threads
    assert np.array_equal(a.values, c.values[:3])
    assert not np.any(a.values[:, :, 0] == d.values[:, :, 0])
    assert not np.allclose(a.values[0], a.values[1])          # realisations differ


def test_record_length_is_even_and_covers_the_duration(gevs):
    f, W = gevs
    assert rnd.synthesise(f, W, 0.10001, 5000.0, 1, 0).samples == 502   # 500.05 -> 502
    assert rnd.synthesise(f, W, 0.1003, 5000.0, 1, 0).samples == 502    # 501.5 -> 502
    assert rnd.synthesise(f, W, 0.1, 3000.0 * 2, 1, 0).samples == 600   # float product exact
    rec = rnd.synthesise(f, W, 0.0999, 5003.0, 1, 0)                    # 499.8 -> 500
    assert rec.samples % 2 == 0 and rec.period >= 0.0999


def test_records_are_periodic_under_hermite(gevs):
    f, W = gevs
    rec = rnd.synthesise(f, W, 0.05, 20000.0, 2, 1)
    t = np.random.default_rng(0).uniform(0, rec.period, 500)
    for r in range(2):
        here = rnd.hermite(rec.values[r], rec.sample_rate, t)
        scale = np.abs(rec.values[r, :, 0]).max()
        for shift in (rec.period, 3 * rec.period, -rec.period):
            np.testing.assert_allclose(rnd.hermite(rec.values[r], rec.sample_rate, t + shift),
                                       here, atol=1e-9 * scale)
    # the last interval joins the last sample to the first
    x = rec.values[0]
    end = rnd.hermite(x, rec.sample_rate, np.array([rec.period - 1e-12, rec.period]))
    np.testing.assert_allclose(end, x[0, 0], atol=1e-6 * np.abs(x[:, 0]).max())


def test_the_kernels_read_the_records_hermite_interpolant(gevs):
    """Each piece of a record as the kernels read it (the cubic the record carries from its
    sample, kernels.excitation.record_value through record_acceleration, and a step's stage
    reads, record_at_nodes) is the cubic Hermite interpolant of the samples and their
    derivatives (`rnd.hermite`, written with the Hermite basis), over two periods and across
    the records' wrap, times the level factor and under the ramp's rise; and its rate
    (record_and_rate) is the interpolant's derivative (a central difference of `rnd.hermite`)."""
    from sweep.kernels import excitation as ex
    f, W = gevs
    fs = 20000.0
    rec = rnd.synthesise(f, W, 0.01, fs, 2, 9)
    rng = np.random.default_rng(4)
    t = np.concatenate([rng.uniform(0.0, 2.0 * rec.period, 400),
                        rec.period - np.array([1e-9, 0.3 / fs]), np.arange(0, 3) / fs])
    nodes = np.array([0.0, 0.2, 0.5, 1.0])
    for r, ramp in ((0, 0.0), (1, 0.004)):
        p = np.zeros(ex.SIZE)
        p[ex.RECORD], p[ex.RECORD_RATE], p[ex.RECORD_SCALE], p[ex.RAMP] = r, fs, -0.7, ramp
        rise = np.where(t < ramp, 0.5 - 0.5 * np.cos(np.pi * t / max(ramp, 1e-300)), 1.0)
        exact = -0.7 * rnd.hermite(rec.values[r], fs, t) * rise
        got = np.array([ex.record_acceleration(x, p, 0, 1, rec.values) for x in t])
        size = np.abs(rec.values[r, :, 0]).max()
        np.testing.assert_allclose(got, exact, rtol=0, atol=1e-13 * size)
        h = 1e-7
        slope = -0.7 * (rnd.hermite(rec.values[r], fs, t + h)
                        - rnd.hermite(rec.values[r], fs, t - h)) / (2 * h)
        away = (np.abs(t * fs - np.round(t * fs)) > 0.01) & (t > ramp + h)
        rates = np.array([ex.record_and_rate(x, p, 0, 1, rec.values)[1] for x in t])
        np.testing.assert_allclose(rates[away], slope[away], rtol=0,
                                   atol=1e-6 * np.abs(slope).max())
        out = np.zeros(len(nodes))
        for x in t[:50]:
            ex.record_at_nodes(x, 0.3 / fs, nodes, p, 0, 1, rec.values, out, 0, 1)
            # record_value compiled for this call, without contraction as record_at_nodes
            # is; record_acceleration lets a * b + c fuse (kernels/flags.py)
            want = [ex.record_value(x + c * 0.3 / fs, p, 0, 1, rec.values)
                    for c in nodes[1:]]
            assert list(out[:3]) == want and out[3] == out[2]


def test_record_integrals_are_the_interpolants_integrals(gevs):
    """The running integrals a record carries (rows 2 and 3: of its cubic Hermite interpolant
    and of its square, from 0 to each sample) and the kernels' integrals between any two
    times (kernels.excitation.record_integrals: those rows and the partial intervals in closed
    form, times the level factor and its square) against adaptive quadrature of the
    interpolant (`rnd.hermite`), over stretches from a fraction of a sample to most of the
    period, across its end (t below two periods: a run never passes one) and with a negative
    level factor."""
    from sweep.kernels import excitation as ex
    f, W = gevs
    fs = 20000.0
    rec = rnd.synthesise(f, W, 0.01, fs, 2, 5)
    values = rec.values
    rng = np.random.default_rng(3)
    for r in range(2):
        a = lambda t: float(rnd.hermite(values[r], fs, np.array([t]))[0])   # noqa: E731
        for k in rng.integers(1, rec.samples, 4):
            edges = np.arange(k + 1) / fs
            first = sum(integrate.quad(a, x0, x1, epsabs=0, epsrel=1e-12)[0]
                        for x0, x1 in zip(edges[:-1], edges[1:]))
            square = sum(integrate.quad(lambda t: a(t) ** 2, x0, x1, epsabs=0,
                                        epsrel=1e-12)[0] for x0, x1 in zip(edges[:-1], edges[1:]))
            scale1 = np.abs(values[r, :, 2]).max() + abs(first)
            assert values[r, k, 2] == pytest.approx(first, abs=1e-11 * scale1)
            assert values[r, k, 3] == pytest.approx(square, rel=1e-11)
        p = np.zeros(ex.SIZE)
        p[ex.RECORD], p[ex.RECORD_RATE], p[ex.RECORD_SCALE] = r, fs, -0.7
        for _ in range(12):
            t0 = rng.uniform(0.0, 2.0 * rec.period - 1e-4)
            t1 = min(t0 + rng.choice([0.3, 3.0, 30.0, 150.0]) / fs, 2.0 * rec.period - 1e-9)
            edges = np.unique(np.concatenate([[t0, t1], np.arange(np.ceil(t0 * fs),
                                                                   t1 * fs) / fs]))
            first = sum(integrate.quad(a, x0, x1, epsabs=0, epsrel=1e-12)[0]
                        for x0, x1 in zip(edges[:-1], edges[1:]))
            square = sum(integrate.quad(lambda t: a(t) ** 2, x0, x1, epsabs=0,
                                        epsrel=1e-12)[0] for x0, x1 in zip(edges[:-1], edges[1:]))
            v0, e0 = ex.record_integrals(t0, p, 0, 1, values)
            v1, e1 = ex.record_integrals(t1, p, 0, 1, values)
            size = (t1 - t0) * np.abs(values[r, :, 0]).max()
            assert v1 - v0 == pytest.approx(-0.7 * first, abs=1e-9 * size)
            assert e1 - e0 == pytest.approx(0.49 * square, rel=1e-9, abs=1e-12 * size ** 2)


# ---- hermite --------------------------------------------------------------------------------

def test_hermite_on_a_tone_is_accurate_to_the_fourth_order():
    fs, f0 = 20000.0, 100.0
    t = np.arange(20000) / fs                          # 1 s: 100 whole cycles, periodic
    w = 2 * np.pi * f0
    values = np.stack([np.cos(w * t), -w * np.sin(w * t)], axis=1)
    tq = np.random.default_rng(4).uniform(0, 1.0, 2000)
    err = np.max(np.abs(rnd.hermite(values, fs, tq) - np.cos(w * tq)))
    assert err < 1e-6
    assert err < 2 * (w / fs) ** 4 / 384                # the cubic Hermite bound


def test_hermite_is_exact_for_a_cubic_and_c1_at_the_nodes():
    fs = 50.0
    n = 40
    t = np.arange(n) / fs
    p = np.polynomial.Polynomial([0.3, -1.2, 2.5, -4.0])
    values = np.stack([p(t), p.deriv()(t)], axis=1)
    tq = np.linspace(t[1], t[-2], 777)                 # inside: no wrap
    np.testing.assert_allclose(rnd.hermite(values, fs, tq), p(tq), atol=1e-13)
    # at the nodes: the samples; either side of a node: the same value and slope
    np.testing.assert_allclose(rnd.hermite(values, fs, t), values[:, 0], atol=1e-14)
    rng = np.random.default_rng(5)
    rough = rng.normal(size=(2, n)).T                  # any samples and derivatives, at 2 Hz
    k = np.arange(1, n)
    tk = k / 2.0
    h = 1e-7
    for side in (-h, h):
        np.testing.assert_allclose(rnd.hermite(rough, 2.0, tk + side), rough[k, 0], atol=1e-5)
    # the one-sided slopes either side of each node agree with the given derivative (C1)
    for side in (-1.0, 1.0):
        slope = side * (rnd.hermite(rough, 2.0, tk + side * h) - rough[k, 0]) / h
        np.testing.assert_allclose(slope, rough[k, 1], atol=1e-5)


# ---- linear_mean_square and Miles -----------------------------------------------------------

def test_single_mode_on_gevs_against_miles(gevs):
    """docs: GEVS, f1 = 100 Hz, Q = 25, Gamma = 1: absolute acceleration 24.96 g exact vs
    25.07 g Miles; deflection 0.6196 mm exact vs 0.6227 mm Miles."""
    f, W = gevs
    w = 2 * np.pi * 100.0
    zeta = 1 / 50
    acc = math.sqrt(rnd.linear_mean_square(f, W, [w], [2 * zeta * w], [1.0],
                                           what="absolute_acceleration")) / G
    disp = math.sqrt(rnd.linear_mean_square(f, W, [w], [2 * zeta * w], [1.0])) * 1e3
    assert f"{acc:.4g}" == "24.96" and f"{rnd.miles_grms(100.0, 25.0, 0.16):.4g}" == "25.07"
    assert f"{disp:.4g}" == "0.6196"
    assert f"{rnd.miles_rms(100.0, 25.0, 0.16 * G ** 2) * 1e3:.4g}" == "0.6227"
    assert rnd.miles_rms(100.0, 25.0, 0.16 * G ** 2, gamma=2.0) == pytest.approx(
        2 * rnd.miles_rms(100.0, 25.0, 0.16 * G ** 2))


def test_flat_wide_spectrum_and_light_damping_tends_to_miles():
    f, W = rnd.spectrum([[1.0, 0.1], [1e5, 0.1]])
    w = 2 * np.pi * 100.0
    zeta = 1 / 200
    disp = math.sqrt(rnd.linear_mean_square(f, W, [w], [2 * zeta * w], [1.0]))
    assert disp == pytest.approx(rnd.miles_rms(100.0, 100.0, 0.1 * G ** 2), rel=1e-4)
    vel = math.sqrt(rnd.linear_mean_square(f, W, [w], [2 * zeta * w], [1.0], what="velocity"))
    assert vel == pytest.approx(w * disp, rel=1e-4)          # white noise: sigma_v = w sigma_q
    acc = math.sqrt(rnd.linear_mean_square(f, W, [w], [2 * zeta * w], [1.0],
                                           what="absolute_acceleration")) / G
    assert acc == pytest.approx(rnd.miles_grms(100.0, 100.0, 0.1), rel=0.01)


def _quad(f, W, omega, c, g, what):
    def integrand(x):
        w = 2 * np.pi * x
        G_ = -sum(gn / (on ** 2 - w ** 2 + 1j * cn * w) for on, cn, gn in zip(omega, c, g))
        T = {"deflection": G_, "velocity": 1j * w * G_,
             "absolute_acceleration": 1 - w ** 2 * G_}[what]
        return abs(T) ** 2 * float(rnd.asd_at(x, f, W))
    points = sorted(set(list(f[1:-1]) + [on / (2 * np.pi) for on in omega]))
    value, _ = integrate.quad(integrand, f[0], f[-1], points=points, limit=2000,
                              epsabs=0.0, epsrel=1e-11)
    return value


@pytest.mark.parametrize("what", rnd.RESPONSES)
def test_two_modes_against_scipy_quad(gevs, what):
    f, W = gevs
    # leading shape (2, 3): two weightings x three mode pairs, zeta down to 0.005
    fn = np.array([[90.0, 230.0], [700.0, 760.0], [45.0, 1990.0]])
    zeta = np.array([[0.005, 0.02], [0.01, 0.005], [0.05, 0.005]])
    omega = 2 * np.pi * fn
    c = 2 * zeta * omega
    weights = np.array([[[1.0, 0.4]], [[0.7, -1.3]]]) * 1e-3          # (2, 1, 2)
    got = rnd.linear_mean_square(f, W, omega, c, weights, what=what)
    assert got.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            expected = _quad(f, W, omega[j], c[j], weights[i, 0], what)
            assert got[i, j] == pytest.approx(expected, rel=1e-6), (i, j)


def test_linear_mean_square_is_vectorised_over_many_points(gevs):
    f, W = gevs
    rng = np.random.default_rng(2)
    omega = 2 * np.pi * rng.uniform(10, 3000, (1000, 5))
    c = 2 * rng.uniform(0.005, 0.1, (1000, 5)) * omega
    weights = rng.normal(size=(1000, 5))
    got = rnd.linear_mean_square(f, W, omega, c, weights)
    assert got.shape == (1000,) and np.all(got > 0)
    one = [rnd.linear_mean_square(f, W, omega[i], c[i], weights[i]) for i in (0, 517, 999)]
    np.testing.assert_allclose(got[[0, 517, 999]], one, rtol=1e-13)
    assert rnd.linear_mean_square(f, W, omega[0], c[0], weights[0]).shape == ()


# ---- errors ---------------------------------------------------------------------------------

def _user_error(name, call, *args, **kwargs):
    with pytest.raises(UserError) as info:
        call(*args, **kwargs)
    text = str(info.value)
    assert "\n" not in text and f"'{name}'" in text, text
    return text


@pytest.mark.parametrize("table, words", [
    (None, "pairs"), ("20 0.1", "pairs"), (5.0, "pairs"), ({20: 0.1}, "pairs"),
    ([[20, 0.1]], "at least 2"), ([], "at least 2"),
    ([[20, 0.1], [50]], "breakpoint 2"), ([[20, 0.1], [50, 0.1, 3]], "breakpoint 2"),
    ([[20, 0.1], [50, float("nan")]], "finite"), ([[20, 0.1], [float("inf"), 0.1]], "finite"),
    ([[20, 0.1], ["50", 0.1]], "breakpoint 2"), ([[20, 0.1], [50, True]], "breakpoint 2"),
    ([[20, 0.1], "ab"], "breakpoint 2"),
    ([[0, 0.1], [50, 0.1]], "> 0 Hz; got 0 Hz"), ([[-5, 0.1], [50, 0.1]], "got -5 Hz"),
    ([[20, 0.1], [80, 0.1], [50, 0.1]], "got 50 Hz after 80 Hz"),
    ([[20, 0.1], [20, 0.1]], "must increase"),
    ([[20, 0.1], [50, 0.0]], "got 0 at 50 Hz"), ([[20, -1], [50, 0.1]], "got -1 at 20 Hz"),
])
def test_spectrum_errors_are_one_line_and_name_the_key(table, words):
    assert words in _user_error("base.asd_g2", rnd.spectrum, table)
    assert "'base.asd'" in _user_error("base.asd", rnd.spectrum, table, key="base.asd",
                                       per_g2=False)


def test_a_hostile_breakpoint_is_quoted_on_one_line():
    text = _user_error("base.asd_g2", rnd.spectrum, [[20, 0.1], ["5\n0\x1b", 0.1]])
    assert "\x1b" not in text


@pytest.mark.parametrize("kwargs, key, words", [
    ({"duration": 0.0}, "base.duration", "> 0"),
    ({"duration": -1.0}, "base.duration", "> 0"),
    ({"duration": float("nan")}, "base.duration", "> 0"),
    ({"duration": "1"}, "base.duration", "> 0"),
    ({"realisations": 0}, "base.realisations", ">= 1"),
    ({"realisations": 1.5}, "base.realisations", ">= 1"),
    ({"realisations": True}, "base.realisations", ">= 1"),
    ({"seed": -1}, "base.seed", ">= 0"),
    ({"seed": 2.5}, "base.seed", ">= 0"),
    ({"seed": None}, "base.seed", ">= 0"),
    ({"sample_rate": 4000.0}, "base.sample_rate",
     "4000 Hz cannot carry the spectrum up to 2000 Hz; give at least 2.5 x"),
    ({"sample_rate": 3000.0}, "base.sample_rate", "the default is 10 x"),
    ({"sample_rate": 4900.0}, "base.sample_rate", "give at least 2.5 x"),   # over 2 x: lossy
    ({"sample_rate": float("inf")}, "base.sample_rate", "up to 2000 Hz"),
    ({"duration": 1e4, "sample_rate": 1e5}, "base.sample_rate", "GiB"),
    ({"duration": 1.0, "realisations": 10 ** 5}, "base.realisations", "GiB"),
    ({"duration": 1e-4}, "base.duration", "no frequency bin"),
])
def test_synthesise_errors_are_one_line_and_name_the_key(gevs, kwargs, key, words):
    f, W = gevs
    args = {"duration": 1.0, "sample_rate": 20000.0, "realisations": 2, "seed": 0} | kwargs
    text = _user_error(key, rnd.synthesise, f, W, **args)
    assert words in text, text


def test_integral_floats_are_accepted_as_counts(gevs):
    f, W = gevs
    a = rnd.synthesise(f, W, 0.01, 20000.0, 2.0, 7.0)
    b = rnd.synthesise(f, W, 0.01, 20000.0, np.int64(2), np.int64(7))
    assert np.array_equal(a.values, b.values)


def test_wide_band_light_damping_against_scipy_quad_with_margin():
    """Four decades of flat spectrum, zeta = 0.005: the graded edges keep the quadrature far
    inside its 1e-6 promise (1e-9 here) where the log-spaced background alone is sparse."""
    f, W = rnd.spectrum([[1, 0.01], [1e4, 0.01]])
    for fn in ([37.3, 3313.0], [5.5, 9000.0]):
        omega = 2 * np.pi * np.array(fn)
        c = 2 * 0.005 * omega
        weights = np.array([1.0, -0.5])
        for what in rnd.RESPONSES:
            expected = _quad(f, W, omega, c, weights, what)
            got = rnd.linear_mean_square(f, W, omega, c, weights, what=what)
            assert got == pytest.approx(expected, rel=1e-9), (fn, what)


def test_an_undamped_random_span_is_refused_by_its_damping():
    """Without damping the start-up never decays: one line naming cable.damping_ratio (it
    used to ask for a duration of 'at least inf s')."""
    import sweep
    scene = sweep.load_scene("launch-random-gevs", overrides={"cable.damping_ratio": 0.0})
    text = _user_error("cable.damping_ratio", sweep.run, scene, progress=False)
    assert "inf" not in text
