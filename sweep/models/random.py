"""Random base excitation (launch random test, GEVS): the base acceleration's spectrum and
sampled stationary Gaussian records of it.

Spectrum. A one-sided acceleration spectral density (ASD) is a table of [Hz, level]
breakpoints (levels in g^2/Hz, scene key base.asd_g2, or (m/s^2)^2/Hz, base.asd),
interpolated log-log between breakpoints (a straight line in dB/octave) and zero outside them.
Its mean square is integrated in closed form segment by segment (`mean_square`, `grms`): the
GSFC-STD-7000 (GEVS) qualification spectrum [[20, 0.026], [50, 0.16], [800, 0.16],
[2000, 0.026]] integrates to 14.14 grms (published: 14.1), its acceptance level (-3 dB,
levels x 10^-0.3) to 10.01 grms (published: 10.0).

Records. `synthesise` builds each record by one inverse real FFT of N samples (N even,
period T = N / fs >= base.duration, bin spacing df = 1/T): bin k at f_k = k df carries a
cosine and a sine of independent Gaussian amplitudes a_k, b_k of variance W(f_k) df, so
that x(t) = sum_k a_k cos(2 pi f_k t) + b_k sin(2 pi f_k t). The classic "amplitude
sqrt(2 W df), random phase" recipe gives every record exactly the same mean square and a
Gaussian distribution only in the limit of many bins; Gaussian coefficients (Rayleigh
amplitudes, uniform phases) make each record a true sample of the Gaussian process, so the
spread of a response over realisations is the spread a real test would show. DC and the
Nyquist bin carry nothing. Each realisation r has its own random stream
(np.random.SeedSequence(seed, spawn_key=(r,))): a realisation is the same whatever the
number of realisations asked for, and everything is fixed by the seed.

The record is periodic with period T: a simulation must never run past T (it would replay
the same excitation). The sample rate defaults to 10 x the spectrum's top frequency
(`default_sample_rate`) and must exceed twice it. Between samples the excitation is the
cubic Hermite interpolant of the samples and of their exact (spectral) time derivatives
(`hermite`, what the kernel does too): the forcing is C1 in time, so an adaptive step sees
no kinks at the sample instants, and it is accurate to ~(2 pi f dt)^4 / 384 at frequency f.

Responses. `linear_mean_square` integrates |G(f)|^2 W(f) over the spectrum for a linear sum
of damped modes (deflection, velocity or absolute acceleration) by composite Gauss-Legendre
quadrature graded around each resonance; `miles_rms` and `miles_grms` are Miles' white-noise
single-mode formulas.

NumPy, no SciPy; the loop that completes the records (each piece's cubic and the running
integrals, kernels.excitation.fill_record_pieces) is compiled, and imported only when records
are made (the records' layout, kernels.layout.RECORD_ROWS, is a plain constant).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import UserError, one_line
from ..kernels.layout import RECORD_ROWS
from ..schema import STANDARD_GRAVITY

DEFAULT_RATE_FACTOR = 10.0
"""`default_sample_rate`: the sample rate is 10 x the spectrum's top frequency."""
MIN_RATE_FACTOR = 2.5
"""The lowest sample rate a record may have, times the spectrum's top frequency: at 2.5 x the
records' cubic Hermite interpolant, which the kernels integrate, already carries about 5 %
less of the spectrum near its top (an auditor's Welch of the interpolant; 11 % at 2.05 x)."""
MAX_RECORD_BYTES = 2 ** 32
"""Largest records `synthesise` builds: 4 GiB of float64 (R x RECORD_ROWS x N x 8 bytes, the
samples, their derivatives, their running integrals and each piece's cubic)."""

GRADING = 2.0 ** np.arange(-3, 11)
"""`linear_mean_square`: quadrature edges at f_n (1 +/- zeta_n x these) around each mode."""
BACKGROUND_PER_DECADE = 24
"""`linear_mean_square`: log-spaced quadrature edges per decade of the spectrum's band."""


def _fail(key: str, what: str) -> UserError:
    return UserError(one_line(f"scene key '{key}': {what}"))


def _is_number(value: Any) -> bool:
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and math.isfinite(float(value)))


def _is_integer(value: Any) -> bool:
    return _is_number(value) and float(value).is_integer()


def spectrum(breakpoints: Sequence[Sequence[float]], key: str = "base.asd_g2",
             per_g2: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(f (Hz), W ((m/s^2)^2/Hz)) of a one-sided ASD given as [Hz, level] breakpoints: levels
    in g^2/Hz (per_g2, scene key base.asd_g2) or in (m/s^2)^2/Hz (key base.asd). At least two
    breakpoints, frequencies > 0 and increasing, levels > 0."""
    unit = "g^2/Hz" if per_g2 else "(m/s^2)^2/Hz"
    form = f"a list of [Hz, {unit}] pairs"
    if isinstance(breakpoints, (str, bytes, Mapping)) or not hasattr(breakpoints, "__len__"):
        raise _fail(key, f"give {form}; got {breakpoints!r}")
    if len(breakpoints) < 2:
        raise _fail(key, f"give at least 2 breakpoints ({form}); got {len(breakpoints)}")
    f, w = [], []
    for i, pair in enumerate(breakpoints):
        if (isinstance(pair, (str, bytes, Mapping)) or not hasattr(pair, "__len__")
                or len(pair) != 2 or not all(_is_number(v) for v in pair)):
            raise _fail(key, f"breakpoint {i + 1} must be a pair [Hz, {unit}] of finite "
                             f"numbers; got {_show(pair)}")
        f.append(float(pair[0]))
        w.append(float(pair[1]))
        if f[-1] <= 0.0:
            raise _fail(key, f"frequencies must be > 0 Hz; got {f[-1]:g} Hz (breakpoint "
                             f"{i + 1})")
        if i and f[-1] <= f[-2]:
            raise _fail(key, f"frequencies must increase; got {f[-1]:g} Hz after {f[-2]:g} Hz")
        if w[-1] <= 0.0:
            raise _fail(key, f"levels must be > 0 {unit}; got {w[-1]:g} at {f[-1]:g} Hz "
                             "(leave a band out of the table instead)")
    scale = STANDARD_GRAVITY ** 2 if per_g2 else 1.0
    return np.array(f, float), np.array(w, float) * scale


def _show(value: Any) -> str:
    """A breakpoint as the user wrote it (lists and tuples of NumPy numbers as plain lists)."""
    if isinstance(value, np.ndarray):
        return repr(value.tolist())
    return repr(value)


def asd_at(frequency: Any, f: np.ndarray, W: np.ndarray) -> np.ndarray:
    """The one-sided ASD ((m/s^2)^2/Hz) at `frequency` (Hz, any shape): interpolated log-log
    between the breakpoints (f Hz, W (m/s^2)^2/Hz), 0 outside [f[0], f[-1]]."""
    x = np.asarray(frequency, float)
    inside = (x >= f[0]) & (x <= f[-1])
    level = np.exp(np.interp(np.log(np.clip(x, f[0], f[-1])), np.log(f), np.log(W)))
    return np.where(inside, level, 0.0)


def mean_square(f: np.ndarray, W: np.ndarray) -> float:
    """The mean square ((m/s^2)^2) of the ASD (f Hz, W (m/s^2)^2/Hz): its exact integral over
    [f[0], f[-1]]. On a segment W = W_k (x / f_k)^b, b = ln(W_k+1 / W_k) / ln(f_k+1 / f_k),
    whose integral is W_k f_k ((f_k+1 / f_k)^(b+1) - 1) / (b + 1) (W_k f_k ln(f_k+1 / f_k)
    when b = -1), written with expm1 so that b near -1 loses no digits."""
    f = np.asarray(f, float)
    W = np.asarray(W, float)
    log_r = np.log(f[1:] / f[:-1])
    c = (np.log(W[1:] / W[:-1]) / log_r + 1.0) * log_r       # (b + 1) ln(f_k+1 / f_k)
    safe = np.where(c == 0.0, 1.0, c)
    factor = np.where(c == 0.0, 1.0, np.expm1(safe) / safe)
    return float(np.sum(W[:-1] * f[:-1] * log_r * factor))


def grms(f: np.ndarray, W: np.ndarray) -> float:
    """The RMS acceleration (g, 9.80665 m/s^2) of the ASD (f Hz, W (m/s^2)^2/Hz)."""
    return math.sqrt(mean_square(f, W)) / STANDARD_GRAVITY


def default_sample_rate(f: np.ndarray) -> float:
    """The default sample rate (Hz) of records of a spectrum whose breakpoints are f (Hz):
    10 x its top frequency (the usual rule fs >= 10 f_max)."""
    return DEFAULT_RATE_FACTOR * float(f[-1])


@dataclass(frozen=True, eq=False)
class Records:
    """Sampled base accelerations: values (R, N, RECORD_ROWS) float64, C-contiguous,
    values[r, k, 0] the acceleration a_b (m/s^2) of realisation r at t = k / sample_rate,
    values[r, k, 1] its exact time derivative (m/s^3), values[r, k, 2] and values[r, k, 3]
    the integrals of the record's cubic Hermite interpolant (the kernels' a_b) and of its
    square from 0 to that sample (m/s, m^2/s^3), values[r, k, 4:6] the coefficients of u^2
    and u^3 of the interpolant's piece from that sample (m/s^2;
    kernels.excitation.fill_record_pieces); sample_rate (Hz). Each record is periodic with
    `period`. eq=False: records compare by identity (compare `values` with np.array_equal)."""
    values: np.ndarray
    sample_rate: float

    @property
    def period(self) -> float:
        """The records' period N / sample_rate (s): no simulation may run past it."""
        return self.samples / self.sample_rate

    @property
    def realisations(self) -> int:
        """R, the number of records."""
        return int(self.values.shape[0])

    @property
    def samples(self) -> int:
        """N, the samples of a record (even)."""
        return int(self.values.shape[1])


def with_pieces(values: np.ndarray, sample_rate: float) -> np.ndarray:
    """(R, N, RECORD_ROWS): records given as their samples and derivatives, values (R, N, 2)
    or more columns (m/s^2, m/s^3; sample_rate Hz), with what the kernels read beside them
    (`Records`: the running integrals of the interpolant and of its square, and each piece's
    cubic; kernels.excitation.fill_record_pieces). A record is periodic: its last piece runs
    from sample N - 1 to sample 0."""
    from ..kernels.excitation import fill_record_pieces
    out = np.empty((values.shape[0], values.shape[1], RECORD_ROWS))
    out[:, :, :2] = values[:, :, :2]
    for r in range(values.shape[0]):
        fill_record_pieces(out[r], 1.0 / float(sample_rate))
    return out


def record_length(duration: float, sample_rate: float) -> int:
    """N: the smallest even integer >= duration x sample_rate (a product within 1e-9 of an
    integer counts as that integer, so 0.1 s at 3000 Hz is 300 samples, not 302)."""
    x = duration * sample_rate
    n = round(x) if abs(x - round(x)) <= 1e-9 * x else math.ceil(x)
    return max(2, n + n % 2)


def synthesise(f: np.ndarray, W: np.ndarray, duration: float, sample_rate: float,
               realisations: int, seed: int, threads: int = 1) -> Records:
    """`realisations` stationary Gaussian records of the ASD (f Hz, W (m/s^2)^2/Hz), each of
    N = `record_length`(duration (s), sample_rate (Hz)) samples and period N / sample_rate
    >= duration, with their exact time derivatives (module docstring).

    Bin k (f_k = k df, df = sample_rate / N, k = 0 .. N/2) has the complex coefficient
    X_k = (N/2) (a_k - i b_k), a_k and b_k independent N(0, W(f_k) df) (`asd_at`; zero at DC
    and at the Nyquist bin), drawn as rng.standard_normal((2, N//2 + 1)) (a then b) from
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r,))) for realisation
    r; the record is np.fft.irfft(X, n=N) and its derivative np.fft.irfft(i 2 pi f_k X_k).
    With threads > 1 the records are made that many at a time (NumPy's generators and FFTs
    release the GIL; each record has its own generator, so they are the same bits on any
    number of threads): 2 threads halve the time, which on one span is about a third of a
    run's (16 records of 8 s at 20 kHz: 0.29 -> 0.14 s)."""
    if not _is_number(duration) or duration <= 0.0:
        raise _fail("base.duration", f"the record's duration must be a number > 0 s; got "
                                     f"{duration!r}")
    if not _is_integer(realisations) or realisations < 1:
        raise _fail("base.realisations", f"give a whole number >= 1 of records; got "
                                         f"{realisations!r}")
    if not _is_integer(seed) or seed < 0:
        raise _fail("base.seed", f"the random seed must be a whole number >= 0; got {seed!r}")
    top = float(f[-1])
    if not _is_number(sample_rate) or not sample_rate >= MIN_RATE_FACTOR * top:
        shown = f"{sample_rate:g} Hz" if _is_number(sample_rate) else repr(sample_rate)
        raise _fail("base.sample_rate", f"{shown} cannot carry the spectrum up to {top:g} Hz; "
                                        f"give at least {MIN_RATE_FACTOR:g} x its top frequency "
                                        f"({MIN_RATE_FACTOR * top:g} Hz; the default is 10 x)")
    duration, sample_rate = float(duration), float(sample_rate)
    realisations, seed = int(realisations), int(seed)
    n = record_length(duration, sample_rate)
    size = realisations * RECORD_ROWS * n * 8
    if size > MAX_RECORD_BYTES:
        raise UserError(one_line(
                    "scene keys 'base.duration', 'base.sample_rate', 'base.realisations': "
                    f"{realisations} records of {n:,} samples, their derivatives and "
                    f"integrals take "
                    f"{size / 2 ** 30:.3g} GiB, over the {MAX_RECORD_BYTES / 2 ** 30:g} GiB "
                    "limit; shorten the duration, lower the sample rate or take fewer "
                    "realisations"))
    df = sample_rate / n
    fk = np.arange(n // 2 + 1) * df
    variance = asd_at(fk, f, W) * df
    variance[0] = variance[-1] = 0.0
    if not np.any(variance > 0.0):
        raise _fail("base.duration", f"a record of {n / sample_rate:g} s has no frequency "
                                     f"bin (spacing {df:g} Hz) within the spectrum's "
                                     f"{f[0]:g}..{top:g} Hz; give at least "
                                     f"{1.0 / (top - f[0]):.3g} s")
    scale = 0.5 * n * np.sqrt(variance)
    derivative = 2j * np.pi * fk
    values = np.empty((realisations, n, RECORD_ROWS))
    from ..kernels.excitation import fill_record_pieces

    def make(r: int) -> None:
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(r,)))
        a, b = rng.standard_normal((2, n // 2 + 1))
        X = scale * (a - 1j * b)
        values[r, :, 0] = np.fft.irfft(X, n=n)
        values[r, :, 1] = np.fft.irfft(derivative * X, n=n)
        fill_record_pieces(values[r], 1.0 / sample_rate)

    workers = min(int(threads), realisations)
    if workers > 1:
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(workers) as pool:
            list(pool.map(make, range(realisations)))
    else:
        for r in range(realisations):
            make(r)
    return Records(values=values, sample_rate=sample_rate)


def hermite(values_r: np.ndarray, sample_rate: float, t: Any) -> np.ndarray:
    """The record values_r ((N, 2) or more columns: samples (m/s^2) and their time derivatives
    (m/s^3) at k / sample_rate (Hz)) at times t (s, any shape; modulo the period
    N / sample_rate): the cubic Hermite interpolant on each interval, with k = floor(t fs)
    mod N, u = t fs - floor(t fs), dt = 1 / fs and sample k + 1 wrapping to 0,

        a = h00(u) x_k + h10(u) dt x'_k + h01(u) x_k+1 + h11(u) dt x'_k+1,

    h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = 3u^2 - 2u^3, h11 = u^3 - u^2. This is
    the reference of what the kernel evaluates."""
    x, dx = values_r[:, 0], values_r[:, 1]
    n = x.shape[0]
    s = np.asarray(t, float) * sample_rate
    whole = np.floor(s)
    u = s - whole
    k = np.mod(whole, n).astype(np.int64)
    k1 = np.where(k + 1 == n, 0, k + 1)
    dt = 1.0 / sample_rate
    u2 = u * u
    u3 = u2 * u
    return ((2.0 * u3 - 3.0 * u2 + 1.0) * x[k] + (u3 - 2.0 * u2 + u) * dt * dx[k]
            + (3.0 * u2 - 2.0 * u3) * x[k1] + (u3 - u2) * dt * dx[k1])


RESPONSES = ("deflection", "velocity", "absolute_acceleration")
"""What `linear_mean_square` integrates: y, y' or y'' + a_b."""


def linear_mean_square(f: np.ndarray, W: np.ndarray, omega: Any, two_zeta_omega: Any,
                       weights: Any, n_points: int = 8,
                       what: str = "deflection") -> np.ndarray:
    """The exact mean square of a linear response to the base acceleration a_b of ASD
    (f Hz, W (m/s^2)^2/Hz): y(t) = sum_n weights_n q_n(t), q_n'' + two_zeta_omega_n q_n' +
    omega_n^2 q_n = -a_b(t), so that y's transfer from a_b is

        G(f) = -sum_n weights_n / (omega_n^2 - w^2 + i two_zeta_omega_n w),  w = 2 pi f,

    and what = "deflection": integral of |G|^2 W df over [f[0], f[-1]] (m^2 for weights in
    m per unit modal response, participation included); "velocity" (y'): |G|^2 w^2
    ((m/s)^2); "absolute_acceleration" (y'' + a_b): |1 - w^2 G|^2 ((m/s^2)^2).

    omega (rad/s), two_zeta_omega (1/s, > 0) and weights: arrays whose last axis is the mode;
    their leading axes broadcast (grid points) and give the result's shape. Composite
    Gauss-Legendre quadrature, n_points nodes a subinterval; the subintervals' edges are the
    breakpoints, f_n (1 +/- zeta_n 2^j) for j = -3 .. 10 and f_n around each mode
    (f_n = omega_n / 2 pi, zeta_n = two_zeta_omega_n / (2 omega_n)) and 24 log-spaced points
    a decade: 1e-6 relative or better for damping ratios down to 0.005."""
    if what not in RESPONSES:
        raise ValueError(f"what must be one of {RESPONSES}; got {what!r}")
    f = np.asarray(f, float)
    W = np.asarray(W, float)
    omega, c, g = np.broadcast_arrays(np.asarray(omega, float),
                                      np.asarray(two_zeta_omega, float),
                                      np.asarray(weights, float))
    if omega.ndim == 0:
        raise ValueError("omega, two_zeta_omega and weights need a last (mode) axis")
    if not (np.all(omega > 0.0) and np.all(c > 0.0)):
        raise ValueError("linear_mean_square needs omega > 0 and two_zeta_omega > 0")
    shape, modes = omega.shape[:-1], omega.shape[-1]
    omega, c, g = (a.reshape(-1, modes) for a in (omega, c, g))
    decades = math.log10(f[-1] / f[0])
    background = np.geomspace(f[0], f[-1], max(8, math.ceil(BACKGROUND_PER_DECADE * decades)))
    fixed = np.concatenate([f, background])
    x_gl, w_gl = np.polynomial.legendre.leggauss(n_points)
    edges_per_point = fixed.size + modes * (2 * GRADING.size + 1)
    chunk = max(1, 2 ** 18 // (edges_per_point * n_points))
    out = np.empty(omega.shape[0])
    for start in range(0, omega.shape[0], chunk):
        part = slice(start, start + chunk)
        out[part] = _chunk(f, W, fixed, x_gl, w_gl, omega[part], c[part], g[part], what)
    return out.reshape(shape)


def _chunk(f: np.ndarray, W: np.ndarray, fixed: np.ndarray, x_gl: np.ndarray,
           w_gl: np.ndarray, omega: np.ndarray, c: np.ndarray, g: np.ndarray,
           what: str) -> np.ndarray:
    """`linear_mean_square` of a chunk of points ((p, modes) arrays)."""
    p = omega.shape[0]
    fn = omega / (2.0 * np.pi)
    zeta = c / (2.0 * omega)
    spread = zeta[..., None] * GRADING
    around = np.concatenate([fn[..., None] * (1.0 - spread), fn[..., None] * (1.0 + spread),
                             fn[..., None]], axis=-1).reshape(p, -1)
    edges = np.concatenate([np.broadcast_to(fixed, (p, fixed.size)), around], axis=1)
    edges = np.sort(np.clip(edges, f[0], f[-1]), axis=1)
    half = 0.5 * (edges[:, 1:] - edges[:, :-1])
    mid = 0.5 * (edges[:, 1:] + edges[:, :-1])
    nodes = (mid[..., None] + half[..., None] * x_gl).reshape(p, -1)
    quad_w = (half[..., None] * w_gl).reshape(p, -1)
    w = 2.0 * np.pi * nodes
    w2 = w * w
    re = np.zeros_like(w)                 # G = re + i im, summed mode by mode in real numbers
    im = np.zeros_like(w)
    for n in range(omega.shape[1]):
        real = omega[:, n, None] ** 2 - w2
        imag = c[:, n, None] * w
        scale = g[:, n, None] / (real * real + imag * imag)
        re -= scale * real
        im += scale * imag
    if what == "deflection":
        power = re * re + im * im
    elif what == "velocity":
        power = w2 * (re * re + im * im)
    else:
        power = (1.0 - w2 * re) ** 2 + (w2 * im) ** 2
    return np.sum(quad_w * power * asd_at(nodes, f, W), axis=1)


def miles_rms(f1: Any, q_factor: Any, W_at_f1: Any, gamma: Any = 1.0) -> Any:
    """Miles' RMS deflection (m) of a single mode of natural frequency f1 (Hz) and amplification
    Q (zeta = 1 / 2Q) under white base acceleration of ASD W_at_f1 ((m/s^2)^2/Hz),
    participation gamma: sqrt(gamma^2 W / (8 zeta w^3)), w = 2 pi f1."""
    zeta = 0.5 / np.asarray(q_factor, float)
    w = 2.0 * np.pi * np.asarray(f1, float)
    return np.sqrt(np.asarray(gamma, float) ** 2 * np.asarray(W_at_f1, float)
                   / (8.0 * zeta * w ** 3))[()]


def miles_grms(f1: Any, q_factor: Any, W_g: Any) -> Any:
    """Miles' RMS absolute acceleration (g) of a single mode of natural frequency f1 (Hz) and
    amplification Q under white base acceleration of ASD W_g (g^2/Hz): sqrt(pi/2 f1 Q W_g)."""
    return np.sqrt(0.5 * np.pi * np.asarray(f1, float) * np.asarray(q_factor, float)
                   * np.asarray(W_g, float))[()]
