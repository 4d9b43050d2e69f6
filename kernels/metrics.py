"""Response metrics reduced inside the kernel, without storing the trajectory (docs/model.md sec. 3).

While it integrates, the driver records every extremum of q (located on the dense output), the
running peak |q|, the tail window's max |q| and range, and the last time |q - centre| exceeded
a threshold. `classify` (kernels/transverse.py) turns those, with this module's reductions,
into a state, a settling time and a response period.

States (integer flags, stored with CF flag_values / flag_meanings):
    INVALID_INPUT      the point's coefficients are not finite or its mass is not positive
    DECAYED            tail amplitude <= tol * peak amplitude
    STEADY             every envelope peak of the tail lies within +-tol*A of its final level
                       (or of its class's in a period-k orbit: `periodic_order`), or at rest
                       away from zero: q within +-tol*A over the tail and the final state
                       within that of a stable equilibrium (`transverse.at_rest`)
    MODULATED          envelope varies in the tail without one-way drift (beating, quasi-periodic)
    UNSETTLED          envelope still drifting one way across the tail (a transient still decaying
                       or growing at t_end), or the tail holds too few oscillations to judge
                       and is not at rest (a run shorter than one period): lengthen t_end
    DIVERGED           non-finite state or |q| beyond the divergence bound
    STEP_TOO_SMALL     the step size fell below SciPy's minimum (10 ulps of t)
    MAX_STEPS          the bound on accepted steps was reached
    COMPLETED          the run reached t_end with no settling to judge (a longitudinal span;
                       a transverse span under a sine sweep)
"""

import math

import numba as nb
import numpy as np

from . import excitation as ex

# The state table lives in kernels/states.py (no Numba: the sweep layer reads it); the kernels
# import it from here.
from .states import (COMPLETED, DECAYED, DIVERGED, HIDDEN_MODE, INVALID_INPUT,  # noqa: F401
                     LONGITUDINAL_STATES, MAX_STEPS, MODULATED, OFF_MIDSPAN, RUNNING,
                     SECOND_PASS, STATE_MEANINGS, STEADY, STEP_TOO_SMALL, TRANSVERSE_STATES,
                     UNSETTLED)

# Extremum kinds in the extrema buffer.
MAXIMUM = 1.0
MINIMUM = -1.0

# Columns of the extrema buffer.
EXT_T = 0      # time of the extremum (s)
EXT_Q = 1      # q at the extremum (m)
EXT_KIND = 2   # MAXIMUM or MINIMUM


@nb.njit(cache=True, nogil=True, error_model="numpy")
def tail_counts(buf, n, t_tail):
    """Number of maxima and minima at t >= t_tail, and the mean spacing (s) of those maxima."""
    n_max = 0
    n_min = 0
    first_max = math.nan
    last_max = math.nan
    for i in range(n):
        if buf[i, EXT_T] < t_tail:
            continue
        if buf[i, EXT_KIND] == MAXIMUM:
            if n_max == 0:
                first_max = buf[i, EXT_T]
            last_max = buf[i, EXT_T]
            n_max += 1
        else:
            n_min += 1
    period = (last_max - first_max) / (n_max - 1) if n_max >= 2 else math.nan
    return n_max, n_min, period


@nb.njit(cache=True, nogil=True, error_model="numpy")
def last_envelope_violation(buf, n, band, k=1):
    """Time (s) of the last extremum farther than `band` (m) from the final level of its class.

    The maxima are split into k classes by their position counted from the last maximum
    (position j belongs to class j mod k), and so are the minima; the final level of a class is
    its last extremum. k = 1: every maximum is compared with the last maximum, every minimum with
    the last minimum; k = 2 suits a period-2 orbit whose maxima alternate between two levels.
    Returns 0.0 when no extremum lies outside its band.
    """
    levels = np.empty((2, k))
    seen = np.zeros(2, np.int64)
    for i in range(n - 1, -1, -1):
        kind = 0 if buf[i, EXT_KIND] == MAXIMUM else 1
        j = seen[kind]
        seen[kind] = j + 1
        if j < k:
            levels[kind, j] = buf[i, EXT_Q]
        elif abs(buf[i, EXT_Q] - levels[kind, j % k]) > band:
            return buf[i, EXT_T]
    return 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy")
def tail_trend(buf, n, t_tail, t_end):
    """True when the envelope drifts one way across the tail: the max |q| of the extrema in each
    quarter of the tail window strictly falls (or strictly rises) from quarter to quarter.

    A decaying or growing transient drifts; beating and quasi-periodic responses whose
    modulation is faster than a quarter of the tail do not. Fast wiggles of the envelope (for
    example at the load frequency) stay inside a quarter and do not hide the drift.
    """
    falling, rising = _quarter_trends(buf, n, t_tail, t_end)
    return falling or rising


@nb.njit(cache=True, nogil=True, error_model="numpy")
def tail_rises(buf, n, t_tail, t_end):
    """True when the envelope grows across the tail, quarter by quarter (`tail_trend`)."""
    return _quarter_trends(buf, n, t_tail, t_end)[1]


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _quarter_trends(buf, n, t_tail, t_end):
    """(falling, rising): whether the max |q| of the extrema in each quarter of the tail
    strictly falls, or strictly rises, from quarter to quarter."""
    quarter = np.zeros(4)
    width = (t_end - t_tail) / 4.0
    for i in range(n):
        if buf[i, EXT_T] < t_tail:
            continue
        j = min(3, int((buf[i, EXT_T] - t_tail) / width)) if width > 0.0 else 3
        quarter[j] = max(quarter[j], abs(buf[i, EXT_Q]))
    falling = True
    rising = True
    for j in range(3):
        falling = falling and quarter[j + 1] < quarter[j]
        rising = rising and quarter[j + 1] > quarter[j]
    return falling, rising


# Periodic orbits of higher order (period-k: k maxima per period whose levels differ).
MAX_ORDER = 8        # the largest k tried
MIN_PER_CLASS = 3    # extrema each class needs in the tail before k >= 2 is believed


@nb.njit(cache=True, nogil=True, error_model="numpy")
def level_spread(buf, n, k):
    """Largest range (m) of the last k maxima or of the last k minima: how far apart the final
    levels of the k classes of `last_envelope_violation` lie."""
    lo = np.full(2, math.inf)
    hi = np.full(2, -math.inf)
    seen = np.zeros(2, np.int64)
    for i in range(n - 1, -1, -1):
        kind = 0 if buf[i, EXT_KIND] == MAXIMUM else 1
        if seen[kind] < k:
            seen[kind] += 1
            lo[kind] = min(lo[kind], buf[i, EXT_Q])
            hi[kind] = max(hi[kind], buf[i, EXT_Q])
    spread = 0.0
    for kind in range(2):
        if seen[kind] > 0:
            spread = max(spread, hi[kind] - lo[kind])
    return spread


@nb.njit(cache=True, nogil=True, error_model="numpy")
def periodic_order(buf, n, t_tail, band, n_max, n_min):
    """The smallest k in 2..MAX_ORDER for which the tail is a period-k orbit, and its settling
    time (s); (0, nan) when there is none.

    Period-k: every extremum lies within +-band (m) of the final level of its class
    (`last_envelope_violation` with k classes) from before t_tail (s) on; the tail holds at least
    MIN_PER_CLASS maxima and minima per class (n_max, n_min: the tail's counts); and the final
    levels of the classes differ by more than the band (else k = 1 would have held). A transient
    whose extrema drift one way cannot pass: the range of a class then exceeds that of the last
    k levels.
    """
    for k in range(2, MAX_ORDER + 1):
        if n_max < MIN_PER_CLASS * k or n_min < MIN_PER_CLASS * k:
            break
        if level_spread(buf, n, k) <= band:
            continue
        t_settle = last_envelope_violation(buf, n, band, k)
        if t_settle < t_tail:
            return k, t_settle
    return 0, math.nan


@nb.njit(cache=True, nogil=True, error_model="numpy")
def orbit_period(buf, n, t_tail, k):
    """Period (s) of a period-k orbit: k times the mean spacing of the tail's maxima, measured
    over a whole number of periods ending at the last maximum."""
    n_max = 0
    last = math.nan
    for i in range(n - 1, -1, -1):
        if buf[i, EXT_T] < t_tail:
            break
        if buf[i, EXT_KIND] == MAXIMUM:
            if n_max == 0:
                last = buf[i, EXT_T]
            n_max += 1
    periods = (n_max - 1) // k
    if periods < 1:
        return math.nan
    seen = 0
    for i in range(n - 1, -1, -1):
        if buf[i, EXT_KIND] == MAXIMUM:
            if seen == periods * k:
                return (last - buf[i, EXT_T]) / periods
            seen += 1
    return math.nan


@nb.njit(cache=True, nogil=True, error_model="numpy")
def sweep_metrics(p, o, s, buf, n, bands_per_octave, first_band, envelope):
    """A swept point's outputs from its n extrema of q (buf) and its excitation block at
    p[o + column * s] (kernels.excitation): returns the peak frequency (Hz), the excitation
    frequency f(t) at the extremum of largest |q| (NaN with no extremum during the sweep), and
    writes envelope[b] (m), the largest |q| at an extremum of q while f(t) lay in band
    first_band + b of the base-2 1/N-octave bands, centres 1000 x 2^(k/N) Hz (N =
    bands_per_octave), edges a factor 2^(1/2N) either side; NaN for a band with no extremum.
    Extrema after the sweep's end (a run longer than the sweep) belong to no band."""
    for b in range(envelope.shape[0]):
        envelope[b] = math.nan
    end = p[o + ex.END * s]
    best = -1.0
    t_best = math.nan
    for i in range(n):
        t = buf[i, EXT_T]
        if t > end:
            break
        q = abs(buf[i, EXT_Q])
        if q > best:
            best = q
            t_best = t
        if envelope.shape[0] == 0:
            continue
        f = ex.frequency(t, p, o, s)
        b = int(math.floor(bands_per_octave * math.log2(f / 1000.0) + 0.5) - first_band)
        if 0 <= b < envelope.shape[0] and not envelope[b] >= q:
            envelope[b] = q
    return ex.frequency(t_best, p, o, s) if best >= 0.0 else math.nan


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _lag_holds(buf, n, m, k, bound):
    """Whether the last 2 (m + 1) k extrema buf[n - 2 (m + 1) k : n] repeat with a lag of k
    maxima (2k entries: maxima and minima alternate): every one within `bound` (m) of the
    latest of its class (its position mod 2k), and each class's drift still to come, if its
    approach to that level is geometric, within `bound` too: d r / (1 - r), d its newest
    difference, r the mean ratio of its successive differences over the window (classes
    whose differences change sign wander within round-off: no drift)."""
    lag = 2 * k
    last = n - 1
    for c in range(lag):
        level = buf[last - c, EXT_Q]
        newest = 0.0
        oldest = 0.0
        one_way = True
        for r in range(1, m + 1):
            q = buf[last - c - lag * r, EXT_Q]
            if abs(q - level) > bound:
                return False
            d = buf[last - c - lag * (r - 1), EXT_Q] - q
            if r == 1:
                newest = d
            elif (d > 0.0) != (newest > 0.0) or d == 0.0:
                one_way = False
            oldest = d
        if one_way and newest != 0.0 and m > 1:
            ratio = abs(newest / oldest) ** (1.0 / (m - 1))
            if not ratio < 1.0:
                return False
            if abs(newest) * ratio / (1.0 - ratio) > bound:
                return False
    return True


@nb.njit(cache=True, nogil=True, error_model="numpy")
def steady_period(buf, n, m, eps, peak):
    """The early stop's test (solver.stop_when_steady), at a maximum of q (buf[n - 1]): the
    response period (s) when the response is steady or has decayed, else 0.0.

    Over the last m + 1 periods, of k maxima each (k = 1 .. MAX_ORDER: a response with
    several maxima a period, superharmonic or period-k): A is the largest |q| of their
    extrema (m). Decayed: A <= eps x peak (the run's max |q| so far). Steady: the extrema
    repeat with a lag of k maxima to within eps x A, the drift still to come included
    (`_lag_holds`). The smallest k that holds gives the period, over the window's m periods.
    A beating or quasi-periodic response keeps its extrema apart at every lag and never
    passes; a transient passes only once the rest of its approach is below eps x A."""
    if n < 1 or buf[n - 1, EXT_KIND] != MAXIMUM:
        return 0.0
    amp = 0.0
    scanned = 0
    for k in range(1, MAX_ORDER + 1):
        need = 2 * (m + 1) * k
        if n < need:
            return 0.0
        for j in range(scanned, need):        # the window grows with k: scan the new part
            kind = buf[n - 1 - j, EXT_KIND]
            if (kind == MAXIMUM) != (j % 2 == 0):
                return 0.0                    # maxima and minima do not alternate here
            amp = max(amp, abs(buf[n - 1 - j, EXT_Q]))
        scanned = need
        period = (buf[n - 1, EXT_T] - buf[n - 1 - 2 * k * m, EXT_T]) / m
        if amp <= eps * peak:
            return period                     # decayed
        if _lag_holds(buf, n, m, k, eps * amp):
            return period
    return 0.0
