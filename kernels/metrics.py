"""Response metrics reduced inside the kernel, without storing the trajectory (docs/model.md sec. 3).

While it integrates, the driver records every extremum of q (located on the dense output), the
running peak |q|, the tail window's max |q| and range, and the last time |q - centre| exceeded
a threshold. `classify` turns those into a state, a settling time and a response period.

States (integer flags, stored with CF flag_values / flag_meanings):
    INVALID_INPUT      the point's coefficients are not finite or its mass is not positive
    DECAYED            tail amplitude <= tol * peak amplitude
    STEADY             every envelope peak of the tail lies within +-tol*A of its final level
    MODULATED          envelope varies in the tail without one-way drift (beating, quasi-periodic)
    UNSETTLED          envelope still drifting one way across the tail (a transient still decaying
                       or growing at t_end), or the tail holds too few oscillations to judge:
                       lengthen t_end
    DIVERGED           non-finite state or |q| beyond the divergence bound
    STEP_TOO_SMALL     the step size fell below SciPy's minimum (10 ulps of t)
    MAX_STEPS          the bound on accepted steps was reached
"""

import math

import numba as nb
import numpy as np

INVALID_INPUT = 0
DECAYED = 1
STEADY = 2
MODULATED = 3
UNSETTLED = 4
DIVERGED = 5
STEP_TOO_SMALL = 6
MAX_STEPS = 7
RUNNING = -1
SECOND_PASS = -2      # internal: STEADY at rest away from zero, its settling time still to be found
                      # by transverse.settle_second_pass; never left in a result

STATE_MEANINGS = ("invalid_input", "decayed", "steady", "modulated", "unsettled", "diverged",
                  "step_size_too_small", "max_steps_reached")

# Extremum kinds in the extrema buffer.
MAXIMUM = 1.0
MINIMUM = -1.0

# Columns of the extrema buffer.
EXT_T = 0      # time of the extremum (s)
EXT_Q = 1      # q at the extremum (m)
EXT_KIND = 2   # MAXIMUM or MINIMUM


@nb.njit(cache=True, nogil=True, error_model="numpy")
def tail_counts(buf, n, t_tail):
    """Number of maxima and minima at t >= t_tail, and the response period from the maxima."""
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
def last_envelope_violation(buf, n, band):
    """Time of the last extremum farther than `band` (m) from the final level of its kind.

    The final level of the maxima is the last maximum, that of the minima the last minimum.
    Returns 0.0 when no extremum lies outside its band.
    """
    level_max = math.nan
    level_min = math.nan
    for i in range(n - 1, -1, -1):
        if buf[i, EXT_KIND] == MAXIMUM and math.isnan(level_max):
            level_max = buf[i, EXT_Q]
        if buf[i, EXT_KIND] == MINIMUM and math.isnan(level_min):
            level_min = buf[i, EXT_Q]
    for i in range(n - 1, -1, -1):
        level = level_max if buf[i, EXT_KIND] == MAXIMUM else level_min
        if abs(buf[i, EXT_Q] - level) > band:
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
    return falling or rising
