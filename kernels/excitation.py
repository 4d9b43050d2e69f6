"""The base excitation signal a_b(t) (m/s^2), written once for every System (docs/model.md
sec. 5 and 6).

    a_b(t) = A(t) sin(phi(t))
    phi(t) = phi_b + w_b t                          fixed frequency (RATE = 0)
    phi(t) = phi_b + w_b (exp(lam t) - 1) / lam     logarithmic sweep from w_b at rate lam

A logarithmic sweep from f_s to f_e at r octaves per minute has lam = s r ln 2 / 60 (1/s),
s = +1 up, -1 down: its frequency is f(t) = f_s exp(lam t) and it lasts T = ln(f_e/f_s) / lam.

The level A(t) is the constant ACCEL, or (SEGMENTS > 0) a table of segments in the log of
the excitation frequency, u(t) = ln w(t) = LOG_OMEGA + lam t: on segment k, which starts at
u = EDGE[k], ln A = LOG_LEVEL[k] + SLOPE[k] (u - EDGE[k]) (A in m/s^2). That is a table of
(frequency, level) breakpoints interpolated log-log, read along the sweep whichever way it
runs. After END (s; the sweep's end) the clamps stop: a_b = 0. A sweep's level rises from 0
over its first RAMP seconds, as a shaker's does, by the factor (1 - cos(pi t / RAMP)) / 2
(RAMP = 0: full level from t = 0).

A random base acceleration is the excitation kind `record` (docs/model.md sec. 11): a_b(t)
sampled at fs on a grid, records[r, k, 0] = a_b(k / fs) and records[r, k, 1] its time
derivative (m/s^3, exact from the spectrum), interpolated between samples by the cubic
Hermite polynomial through both (so the forcing is continuous with its rate, as the adaptive
step wants), periodic with the record's period N / fs. Each sample also carries the piece
from it to the next as a cubic in the fraction u of the interval (its coefficients of u^2 and
u^3, CUBIC_C and CUBIC_D, `fill_record_pieces`), so that a read is four numbers side by side
and three multiply-adds, and the running integrals of a_b and a_b^2 (`record_integrals`;
kernels.layout.RECORD_ROWS). The records are shared by every grid
point (common random numbers): the kernels take them as the `base` switch itself, an array
where the sine kinds take True (`signal`), and a row's block names its record: RECORD (its
realisation r), RECORD_RATE (fs, Hz) and RECORD_SCALE (the level factor, 1: the spectrum as
given; in the ACCEL column).

The columns form one block, read as p[o + column * s] from its first column (the accessor of
kernels.oscillator: o the block's first slot, s the stride), so each System places the block
where it likes in its rows and calls `acceleration` on it. Units: t in s.
"""

import math

import numba as nb
import numpy as np
from numba.core import types
from numba.extending import overload

from .flags import CONTRACT
from .vecmath import fast_sin_cos

# Columns of the excitation block, relative to its first column.
ACCEL = 0           # A, the constant level (m/s^2 peak; read when SEGMENTS = 0)
OMEGA = 1           # w_b, the frequency, a sweep's start frequency (rad/s)
PHASE = 2           # phi_b, the phase at t = 0 (rad; a stepped sweep's carried phase)
RATE = 3            # lam, the sweep rate (1/s): w(t) = w_b exp(lam t); 0 for a fixed frequency
SEGMENTS = 4        # number of level segments (0: the constant ACCEL)
END = 5             # with SEGMENTS > 0: a_b = 0 after this time (s)
LOG_OMEGA = 6       # ln w_b (w_b in rad/s), with SEGMENTS > 0
MAX_SEGMENTS = 8    # room for this many segments (a level table of up to 9 breakpoints)
EDGE = 7                            # segment k starts at u = p[EDGE + k] (ln of rad/s)
LOG_LEVEL = EDGE + MAX_SEGMENTS     # ln A there (A in m/s^2)
SLOPE = LOG_LEVEL + MAX_SEGMENTS    # d ln A / d ln w on the segment (1)
RAMP = SLOPE + MAX_SEGMENTS         # with SEGMENTS > 0: the level's rise time from 0 (s)
SIZE = RAMP + 1
# The record kind's columns (the sine kinds' ACCEL, OMEGA and PHASE: a row is one kind or the
# other, as its scene's `base` switch is an array of records or True).
RECORD_SCALE = ACCEL   # the level factor on the record (1), 10^(dB / 20) of a level in dB
RECORD_RATE = OMEGA    # fs, the records' sample rate (Hz)
RECORD = PHASE         # r, which record (realisation) the row follows (an index, as a float)
# The records' columns (kernels.layout.RECORD_ROWS) beyond a sample's a_b (0), its derivative (1)
# and the running integrals (2, 3): the coefficients of u^2 and u^3 of the piece from it.
CUBIC_C = 4
CUBIC_D = 5
RECORD_START = END     # the row's statistics start no earlier than this (s): its start-up
                       # transient's end (kernels.trajectory.record_window)
                       # (RAMP, as the sweeps': the record's level rises from 0 over RAMP s)

NAMES = (("base_accel", "base_omega", "base_phase", "sweep_rate", "level_segments",
          "sweep_end", "log_base_omega")
         + tuple(f"level_edge_{k}" for k in range(MAX_SEGMENTS))
         + tuple(f"level_log_{k}" for k in range(MAX_SEGMENTS))
         + tuple(f"level_slope_{k}" for k in range(MAX_SEGMENTS)) + ("level_ramp",))
"""The block's column names, in order (sweep.models.modal.base_excitation gives them)."""


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def phase(t, p, o, s):
    """phi(t) (rad) of the excitation block at p[o + column * s], at time t (s)."""
    lam = p[o + RATE * s]
    if lam == 0.0:
        return p[o + OMEGA * s] * t + p[o + PHASE * s]
    return _swept_phase(math.expm1(lam * t), lam, p, o, s)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _swept_phase(grown, lam, p, o, s):
    """phi (rad) of a sweep at rate lam != 0 (1/s) at the time t whose expm1(lam t) is
    `grown`: w_b expm1(lam t) / lam + phi_b."""
    return p[o + OMEGA * s] * (grown / lam) + p[o + PHASE * s]


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def level(t, p, o, s):
    """A(t) (m/s^2 peak) of the excitation block at p[o + column * s], at time t (s)."""
    n = int(p[o + SEGMENTS * s])
    if n == 0:
        return p[o + ACCEL * s]
    if t > p[o + END * s]:
        return 0.0
    u = p[o + LOG_OMEGA * s] + p[o + RATE * s] * t
    k = _segment(u, p, o, s, n)
    a = math.exp(p[o + (LOG_LEVEL + k) * s] + p[o + (SLOPE + k) * s] * (u - p[o + (EDGE + k) * s]))
    return a * _rise(t, p[o + RAMP * s])


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _segment(u, p, o, s, n):
    """The level segment k (of n) that u = ln w holds: the last whose EDGE is <= u."""
    k = 0
    while k + 1 < n and u >= p[o + (EDGE + k + 1) * s]:
        k += 1
    return k


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _rise(t, ramp):
    """The ramp's rise at t (s): (1 - cos(pi t / ramp)) / 2 over its first `ramp` seconds
    (RAMP; base.ramp or a sweep's ramp_cycles), 1 after (and with no ramp)."""
    if t < ramp:
        return 0.5 - 0.5 * math.cos(math.pi * t / ramp)
    return 1.0


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _ramped(t, ramp, a, rate):
    """(a, rate) of a level a (m/s^2) and its rate (m/s^3) at t (s) under the ramp's
    `_rise`, unchanged after it."""
    if t < ramp:
        rise = _rise(t, ramp)
        return a * rise, rate * rise + a * 0.5 * math.pi / ramp * math.sin(math.pi * t / ramp)
    return a, rate


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def acceleration_and_rate(t, p, o, s):
    """(a_b(t), a_b'(t)) (m/s^2, m/s^3) of the sine kinds: A' sin(phi) + A w(t) cos(phi), A'
    = A SLOPE[k] lam on a level segment, plus the ramp's rise (for the loads' observers,
    which need the rate where a load peaks: kernels.modal_driver.inertia_at)."""
    phi = phase(t, p, o, s)
    w = p[o + OMEGA * s] * math.exp(p[o + RATE * s] * t)
    n = int(p[o + SEGMENTS * s])
    if n == 0:
        a = p[o + ACCEL * s]
        return a * math.sin(phi), a * w * math.cos(phi)
    if t > p[o + END * s]:
        return 0.0, 0.0
    u = p[o + LOG_OMEGA * s] + p[o + RATE * s] * t
    k = _segment(u, p, o, s, n)
    a = math.exp(p[o + (LOG_LEVEL + k) * s] + p[o + (SLOPE + k) * s] * (u - p[o + (EDGE + k) * s]))
    a, rate = _ramped(t, p[o + RAMP * s], a, a * p[o + (SLOPE + k) * s] * p[o + RATE * s])
    return a * math.sin(phi), rate * math.sin(phi) + a * w * math.cos(phi)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def acceleration(t, p, o, s):
    """a_b(t) = A(t) sin(phi(t)) (m/s^2) of the excitation block at p[o + column * s], with
    libm's sin (the scalar drivers; the lanes drivers take only fixed-frequency, fixed-level
    rows and evaluate A sin(w_b t + phi_b) in their vector loops)."""
    return level(t, p, o, s) * math.sin(phase(t, p, o, s))


STAGE_SERIES_BELOW = 2.0 ** -6
"""|lam h| and |g h| (a step h, s) up to which a sweep's stage reads come from the step's start
(`sweep_anchor`, `anchored`): the series they take leaves less than 1e-22."""


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _expm1_over(x):
    """expm1(x) / x (1 at x = 0) for |x| <= STAGE_SERIES_BELOW: its Taylor series to x^8."""
    return 1.0 + x * (1.0 / 2.0 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x * (
        1.0 / 720.0 + x * (1.0 / 5040.0 + x * (1.0 / 40320.0 + x / 362880.0)))))))


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=False, _nrt=False)
def sweep_state(t, h, p, o, s):
    """`sweep_anchor` before its sine and cosine: (1, phi(t) (rad), w(t) (rad/s), A(t)
    (m/s^2), g (1/s)) at the start t (s) of a step of h (s), or all zeros where the anchor does
    not hold. One expm1 gives the phase and w(t) = w_b (1 + expm1(lam t))."""
    none = (0.0, 0.0, 0.0, 0.0, 0.0)
    lam = p[o + RATE * s]
    if lam == 0.0 or not abs(lam * h) <= STAGE_SERIES_BELOW:
        return none
    n = int(p[o + SEGMENTS * s])
    a = p[o + ACCEL * s]
    g = 0.0
    if n > 0:
        if t < p[o + RAMP * s] or t + h > p[o + END * s]:
            return none
        u = p[o + LOG_OMEGA * s] + lam * t
        k = _segment(u, p, o, s, n)
        if _segment(p[o + LOG_OMEGA * s] + lam * (t + h), p, o, s, n) != k:
            return none
        g = p[o + (SLOPE + k) * s] * lam
        if not abs(g * h) <= STAGE_SERIES_BELOW:
            return none
        a = math.exp(p[o + (LOG_LEVEL + k) * s]
                     + p[o + (SLOPE + k) * s] * (u - p[o + (EDGE + k) * s]))
    grown = math.expm1(lam * t)
    return (1.0, _swept_phase(grown, lam, p, o, s), p[o + OMEGA * s] * (1.0 + grown), a, g)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=False, _nrt=False)
def sweep_anchor(t, h, p, o, s):
    """A logarithmic sweep's state at the start t (s) of a step of h (s), from which `anchored`
    gives a_b at every stage time t + tau of the step (0 <= tau <= h) with no libm call:
    (1, sin phi(t), cos phi(t), w(t) (rad/s), A(t) (m/s^2), g = d ln A / dt (1/s)). Where the
    step is not one stretch of a single level segment after the ramp and before the sweep's
    END, where |lam h| or |g h| exceed STAGE_SERIES_BELOW, and for a fixed frequency: all
    zeros, each stage reads `acceleration` (a fixed sine keeps its bits). (`sweep_state`, then
    libm's sine and cosine of the phase.)"""
    held, x, w, a, g = sweep_state(t, h, p, o, s)
    if held == 0.0:
        return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return 1.0, math.sin(x), math.cos(x), w, a, g


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def anchored(anchor, tau, lam):
    """a_b (m/s^2) at t + tau (s) of a sweep at rate lam (1/s) from its `sweep_anchor` at t:
    A(t) exp(g tau) sin(phi(t) + d), d = w(t) tau expm1(lam tau) / (lam tau) the phase the
    sweep adds in tau, by the angle sum (vecmath's sine and cosine of d); the same value as
    `acceleration` at t + tau to round-off."""
    sin0 = anchor[1]
    cos0 = anchor[2]
    d = anchor[3] * tau * _expm1_over(lam * tau)
    sd, cd = fast_sin_cos(d)
    gt = anchor[5] * tau
    return anchor[4] * (1.0 + gt * _expm1_over(gt)) * (sin0 * cd + cos0 * sd)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def stage_signal(t, tau, anchor, p, o, s):
    """A sine block's a_b (m/s^2) at the stage time t + tau (s) of a step from t whose
    `sweep_anchor` is `anchor`: `anchored` where the anchor holds, else `acceleration` at
    t + tau. The one rule of a stage's read, for the one-mode scalar step
    (kernels.oscillator.stage_acceleration) and the lanes' (`sine_at_nodes`)."""
    if anchor[0] != 0.0:
        return anchored(anchor, tau, p[o + RATE * s])
    return acceleration(t + tau, p, o, s)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def sine_at_nodes(t, h, nodes, p, o, s, out, out_o, out_s):
    """A sine block's a_b (m/s^2) at a step's stage times t + nodes[i] h (s), i = 1 ..
    len(nodes) - 1, into out[out_o + (i - 1) * out_s], and at t + h into the slot after them:
    `stage_signal` from the step's `sweep_anchor`, the values the one-mode scalar step reads.
    The lanes' stage reads of a sweep (kernels.lanes), as `record_at_nodes` is a record's."""
    anchor = sweep_anchor(t, h, p, o, s)
    m = len(nodes)
    for i in range(1, m + 1):
        tau = nodes[i] * h if i < m else h
        out[out_o + (i - 1) * out_s] = stage_signal(t, tau, anchor, p, o, s)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def frequency(t, p, o, s):
    """The excitation frequency f(t) (Hz) of the block at p[o + column * s] at time t (s)."""
    return p[o + OMEGA * s] / (2.0 * math.pi) * math.exp(p[o + RATE * s] * t)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _sample_index(t, fs, n):
    """Where time t (s) falls among a record's n samples at fs (Hz): the sample k that starts
    its interval (and its piece), the fraction u of the interval, and whether t is past one
    period."""
    x = t * fs
    kf = math.floor(x)
    u = x - kf
    k = int(kf)
    lap = k >= n
    k = k - n if lap else k         # t in [0, 2 N / fs): a run never passes the period N / fs
    return k, u, lap                # (not `% n`: an integer division per stage and lane, which
                                    # took half a one-mode record's run on the lanes)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _record_piece(t, p, o, s, records):
    """The record kind's row at time t (s): its piece there as the cubic
    y + b u + c u^2 + d u^3 in the fraction u of the sample interval (y, b, c, d in m/s^2:
    the sample, dt times its derivative and the two coefficients the record carries,
    `cubic`), u, the interval dt = 1 / fs (s) and the level factor."""
    r = int(p[o + RECORD * s])
    fs = p[o + RECORD_RATE * s]
    dt = 1.0 / fs
    k, u, _ = _sample_index(t, fs, records.shape[1])
    return (records[r, k, 0], dt * records[r, k, 1], records[r, k, CUBIC_C],
            records[r, k, CUBIC_D], u, dt, p[o + RECORD_SCALE * s])


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def cubic(y0, d0, y1, d1, dt):
    """The coefficients c, d (m/s^2) of u^2 and u^3 of the cubic Hermite interpolant
    y0 + dt d0 u + c u^2 + d u^3 through the samples (y0, d0) at u = 0 and (y1, d1) at u = 1
    (m/s^2, m/s^3) of an interval dt (s) long."""
    b = dt * d0
    return 3.0 * (y1 - y0) - 2.0 * b - dt * d1, 2.0 * (y0 - y1) + b + dt * d1


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _piece_integrals(y0, b, c, d, u, dt):
    """The integrals of the piece y0 + b u + c u^2 + d u^3 (m/s^2) over the first fraction u of
    its interval dt (s), and of its square (m/s, m^2/s^3)."""
    first = u * (y0 + u * (b / 2.0 + u * (c / 3.0 + u * d / 4.0)))
    square = u * (y0 * y0 + u * (y0 * b + u * ((b * b + 2.0 * y0 * c) / 3.0 + u * (
        (y0 * d + b * c) / 2.0 + u * ((c * c + 2.0 * b * d) / 5.0 + u * (
            c * d / 3.0 + u * d * d / 7.0))))))
    return dt * first, dt * square


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def fill_record_pieces(record, dt):
    """Columns 2 to 5 of one record (N, RECORD_ROWS), in place, from its samples and their
    derivatives in columns 0 and 1 (m/s^2, m/s^3; dt the sample interval, s): in CUBIC_C and
    CUBIC_D the coefficients of the piece that starts at each sample (`cubic`; the last piece
    runs from sample N - 1 round to sample 0, the record being periodic), and in columns 2 and
    3 the running integrals of the interpolant and of its square from t = 0 to each sample (m/s,
    m^2/s^3), summed piece by piece in order (`_piece_integrals` over whole pieces; the last
    piece is left out: `record_integrals` adds it for a time past a whole period)."""
    n = record.shape[0]
    first = 0.0
    square = 0.0
    for k in range(n):
        k1 = k + 1 if k + 1 < n else 0
        c, d = cubic(record[k, 0], record[k, 1], record[k1, 0], record[k1, 1], dt)
        record[k, CUBIC_C] = c
        record[k, CUBIC_D] = d
        record[k, 2] = first
        record[k, 3] = square
        a, b = _piece_integrals(record[k, 0], dt * record[k, 1], c, d, 1.0, dt)
        first += a
        square += b


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, forceinline=True)
def record_integrals(t, p, o, s, records):
    """(integral of a_b, integral of a_b^2) from 0 to t (s) (m/s, m^2/s^3) of the record kind's
    row, on its cubic Hermite interpolant times the level factor, the ramp left out (exact
    once t is past it: a record's statistics start after it): the running integrals the
    records carry to each sample (columns 2 and 3, `fill_record_pieces`) and the partial
    interval in closed form. The difference of two such calls is the integral over the
    stretch between them."""
    n = records.shape[1]
    r = int(p[o + RECORD * s])
    fs = p[o + RECORD_RATE * s]
    scale = p[o + RECORD_SCALE * s]
    dt = 1.0 / fs
    k, u, lap = _sample_index(t, fs, n)
    first, square = _piece_integrals(records[r, k, 0], dt * records[r, k, 1],
                                     records[r, k, CUBIC_C], records[r, k, CUBIC_D], u, dt)
    first += records[r, k, 2]
    square += records[r, k, 3]
    if lap:                         # a whole period before it
        whole, whole_sq = _piece_integrals(records[r, n - 1, 0], dt * records[r, n - 1, 1],
                                           records[r, n - 1, CUBIC_C],
                                           records[r, n - 1, CUBIC_D], 1.0, dt)
        first += whole + records[r, n - 1, 2]
        square += whole_sq + records[r, n - 1, 3]
    return scale * first, scale * scale * square


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _horner(y, b, c, d, u):
    """The piece y + b u + c u^2 + d u^3 at the fraction u of its interval."""
    return y + u * (b + u * (c + u * d))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def record_value(t, p, o, s, records):
    """a_b(t) (m/s^2) of the record kind: record r = p[o + RECORD * s] of `records`
    (R, N, RECORD_ROWS) at time t (s), the cubic Hermite interpolant of the samples and their
    derivatives at fs = p[o + RECORD_RATE * s] (each piece as the cubic the record carries,
    `cubic`), periodic with period N / fs, times the level factor p[o + RECORD_SCALE * s], and
    over the first RAMP seconds (base.ramp; 0: none) by the ramp's (1 - cos(pi t / RAMP)) / 2,
    as a shaker brings its level up. Inlined where it is called (`inlined_signal`);
    `record_acceleration` is the same as a call."""
    y, b, c, d, u, dt, scale = _record_piece(t, p, o, s, records)
    return scale * _horner(y, b, c, d, u) * _rise(t, p[o + RAMP * s])


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, forceinline=True)
def record_at_nodes(t, h, nodes, p, o, s, records, out, out_o, out_s):
    """`record_value` at the times t + nodes[i] h (s), i = 1 .. len(nodes) - 1, into
    out[out_o + (i - 1) * out_s], and at t + h into the slot after them (a copy of the last
    where nodes[-1] is 1): a step's stage reads of one row, the row's columns read once for
    them all (the lanes' `_stage_reads`: 11 reads a DOP853 step, most of a one-mode record's
    run)."""
    r = int(p[o + RECORD * s])
    fs = p[o + RECORD_RATE * s]
    scale = p[o + RECORD_SCALE * s]
    ramp = p[o + RAMP * s]
    dt = 1.0 / fs
    n = records.shape[1]
    m = len(nodes)
    for i in range(1, m + 1):
        if i == m and nodes[m - 1] == 1.0:
            out[out_o + (m - 1) * out_s] = out[out_o + (m - 2) * out_s]
            break
        at = t + nodes[i] * h if i < m else t + h
        k, u, _ = _sample_index(at, fs, n)
        out[out_o + (i - 1) * out_s] = scale * _horner(
            records[r, k, 0], dt * records[r, k, 1], records[r, k, CUBIC_C],
            records[r, k, CUBIC_D], u) * _rise(at, ramp)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def record_acceleration(t, p, o, s, records):
    """`record_value` as a call of its own (`signal`: the several-mode System's reads)."""
    return record_value(t, p, o, s, records)


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def record_and_rate(t, p, o, s, records):
    """(a_b(t), a_b'(t)) (m/s^2, m/s^3) of the record kind: `record_acceleration` and the
    time derivative of its piece (and of the ramp's rise)."""
    y, b, c, d, u, dt, scale = _record_piece(t, p, o, s, records)
    slope = (b + u * (2.0 * c + 3.0 * u * d)) / dt
    return _ramped(t, p[o + RAMP * s], scale * _horner(y, b, c, d, u), scale * slope)


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def level_bound(t0, t1, p, o, s, base):
    """An upper bound (m/s^2) of |a_b(t)| over [t0, t1] (s) for the sine kinds: the constant
    level |ACCEL|, or the level table's largest A over the stretch of ln w that [t0, t1]
    sweeps (ln A is linear on each segment, so its largest value lies at an end of the stretch
    a segment covers; the ramp's rise is at most 1). `base` is the kind switch (`by_kind`)."""
    n = int(p[o + SEGMENTS * s])
    if n == 0:
        return abs(p[o + ACCEL * s])
    u0 = p[o + LOG_OMEGA * s] + p[o + RATE * s] * t0
    u1 = p[o + LOG_OMEGA * s] + p[o + RATE * s] * t1
    lo = min(u0, u1)
    hi = max(u0, u1)
    top = 0.0
    for k in range(n):
        edge = p[o + (EDGE + k) * s]
        a = lo if k == 0 else max(lo, edge)                           # segment 0 reaches down
        b = hi if k + 1 == n else min(hi, p[o + (EDGE + k + 1) * s])  # and the last one up
        if a > b:
            continue
        log_level = p[o + (LOG_LEVEL + k) * s]
        slope = p[o + (SLOPE + k) * s]
        top = max(top, math.exp(log_level + slope * (a - edge)),
                  math.exp(log_level + slope * (b - edge)))
    return top


@nb.njit(cache=True, nogil=True, error_model="numpy", fastmath=CONTRACT, _nrt=False)
def record_bound(t0, t1, p, o, s, records):
    """An upper bound (m/s^2) of |a_b(t)| over [t0, t1] (s) for the record kind: on each
    sample interval the span touches, the cubic Hermite through (y0, d0) and (y1, d1) is at
    most max(|y0|, |y1|) + 4/27 dt (|d0| + |d1|) (its value weights are >= 0 and sum to 1, its
    slope weights u (1 - u)^2 and u^2 (1 - u) are at most 4/27), times the level factor (the
    ramp's rise is at most 1)."""
    n = records.shape[1]
    r = int(p[o + RECORD * s])
    fs = p[o + RECORD_RATE * s]
    dt = 1.0 / fs
    first = int(math.floor(min(t0, t1) * fs))
    last = int(math.floor(max(t0, t1) * fs))
    top = 0.0
    for k in range(first, last + 1):
        k0 = k - n if k >= n else k          # t < 2 N / fs, as `_sample_index`
        k1 = k0 + 1 if k0 + 1 < n else 0
        top = max(top, max(abs(records[r, k0, 0]), abs(records[r, k1, 0]))
                  + 4.0 / 27.0 * dt * (abs(records[r, k0, 1]) + abs(records[r, k1, 1])))
    return abs(p[o + RECORD_SCALE * s]) * top


def signal_and_rate(t, p, o, s, base):
    """(a_b(t), a_b'(t)) (m/s^2, m/s^3) of the excitation block for the scene's `base` switch,
    as `signal` chooses."""
    if isinstance(base, np.ndarray):
        return record_and_rate(t, p, o, s, base)
    return acceleration_and_rate(t, p, o, s)


@overload(signal_and_rate)
def _signal_and_rate(t, p, o, s, base):
    if isinstance(base, types.Array):
        return lambda t, p, o, s, base: record_and_rate(t, p, o, s, base)
    return lambda t, p, o, s, base: acceleration_and_rate(t, p, o, s)


def signal(t, p, o, s, base):
    """a_b(t) (m/s^2) of the excitation block at p[o + column * s] for the scene's `base`
    switch: True (or any non-array): the sine kinds (`acceleration`); an array of records:
    the record kind (`record_acceleration`). Compiled, the choice is made from base's type."""
    if isinstance(base, np.ndarray):
        return record_acceleration(t, p, o, s, base)
    return acceleration(t, p, o, s)


@overload(signal, inline="always")
def _signal(t, p, o, s, base):
    if isinstance(base, types.Array):
        return lambda t, p, o, s, base: record_acceleration(t, p, o, s, base)
    return lambda t, p, o, s, base: acceleration(t, p, o, s)


def inlined_signal(t, p, o, s, base):
    """`signal` with the record kind's read inlined into the caller (`record_value`): the
    one-mode System's reads (kernels.oscillator). Shared as a call with the several-mode
    System, whose process could compile it first (or another process, into the Numba cache),
    it made the one-mode results depend on which scenes had been compiled before."""
    return signal(t, p, o, s, base)


@overload(inlined_signal, inline="always")
def _inlined_signal(t, p, o, s, base):
    if isinstance(base, types.Array):
        return lambda t, p, o, s, base: record_value(t, p, o, s, base)
    return lambda t, p, o, s, base: acceleration(t, p, o, s)


def by_kind(sine, record):
    """One function for compiled code over the excitation kinds: it calls `sine` where the
    `base` switch (its LAST argument) is True, or None, and `record` where it is an array of
    records (both with the same arguments), chosen from base's type as the caller compiles.
    Either may be None: that kind does nothing (the call returns None). So a scene compiles
    its own kind's code only; a branch on `is_record(base)` would compile both, as Numba types
    a dead branch's body before it drops it."""
    def by_kind_call(*args):
        raise TypeError("kernels.excitation.by_kind functions run only in compiled code")

    # prefer_literal: the arguments keep their literal types (the switches' True, o, s = 0,
    # 1), so the call compiles the same specialisation a direct call would
    @overload(by_kind_call, prefer_literal=True)
    def _choose(*args):
        chosen = record if isinstance(args[-1], types.Array) else sine
        if chosen is None:
            return lambda *args: None
        return lambda *args: chosen(*args)

    by_kind_call.__doc__ = (f"{getattr(sine, '__name__', None)} for the sine kinds, "
                            f"{getattr(record, '__name__', None)} for records (by_kind)")
    return by_kind_call


def is_record(base):
    """Whether the scene's `base` switch is an array of records (the record kind)."""
    return isinstance(base, np.ndarray)


@overload(is_record, inline="always")
def _is_record(base):
    if isinstance(base, types.Array):
        return lambda base: True
    return lambda base: False


peak_bound = by_kind(level_bound, record_bound)
peak_bound.__doc__ = """peak_bound(t0, t1, p, o, s, base): an upper bound (m/s^2) of |a_b(t)|
over [t0, t1] (s) for the scene's kind (`level_bound`, `record_bound`): what lets an observer
skip a search for a peak that cannot exceed the largest so far."""
