"""Elementary functions written so that LLVM can vectorise the loops that call them.

A libm call inside a loop stops LLVM vectorising it; these are straight-line arithmetic
(selects, polynomials, Newton steps) accurate to an ulp or two over the ranges stated. They
round with `np.floor`, which stays a float (`math.floor` returns an integer: two vector
conversions per call, with no single instruction for them before AVX-512):

- `fast_cos(x)`, `fast_sin(x)`, `fast_sin_cos(x)`: cos x and sin x for |x| < 1e5 (Cody-Waite
  reduction, fdlibm's kernels);
- `inv_fifth_root(x)`: x^(-1/5) for 2^-31 <= x < 2^32 (power-of-two reduction, Newton);
- `log2_fast(x)`, `exp2_fast(y)`: to about 1e-9, for the step-size controller.
"""

import numba as nb
import numpy as np

FAST_TRIG_BELOW = 1e5
"""|x| below which `fast_cos`, `fast_sin` and `fast_sin_cos` hold to about an ulp."""

# Cody-Waite split of pi/2 and fdlibm's minimax kernels on [-pi/4, pi/4].
_TWO_OVER_PI = 0.63661977236758134308
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _reduced(x):
    """(sin r, cos r, quadrant k mod 4 as a float) with x = k pi/2 + r, |r| <= pi/4 (Cody-Waite
    reduction, fdlibm's kernels); accurate to about an ulp for |x| < 1e5."""
    k = np.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_2T
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    return s, c, k - 4.0 * np.floor(0.25 * k)       # 0, 1, 2, 3 as floats: vectorisable


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fast_cos(x):
    """cos(x) without a libm call, to about an ulp for |x| < 1e5 (vectorisable)."""
    s, c, quadrant = _reduced(x)
    v = s if (quadrant == 1.0) | (quadrant == 3.0) else c
    return -v if (quadrant == 1.0) | (quadrant == 2.0) else v


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fast_sin(x):
    """sin(x) without a libm call, to about an ulp for |x| < 1e5 (vectorisable)."""
    s, c, quadrant = _reduced(x)
    v = c if (quadrant == 1.0) | (quadrant == 3.0) else s
    return -v if (quadrant == 2.0) | (quadrant == 3.0) else v


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def fast_sin_cos(x):
    """(sin x, cos x) from one reduction, to about an ulp for |x| < 1e5 (vectorisable)."""
    s, c, quadrant = _reduced(x)
    odd = (quadrant == 1.0) | (quadrant == 3.0)
    sv = c if odd else s
    cv = s if odd else c
    return (-sv if (quadrant == 2.0) | (quadrant == 3.0) else sv,
            -cv if (quadrant == 1.0) | (quadrant == 2.0) else cv)


# Newton's start for m^(-1/5) on [1, 2) (least squares, |error| < 2e-5).
_R4, _R3, _R2, _R1, _R0 = (0.014560562999503732, -0.11387695821308534, 0.36488873237721625,
                           -0.6453524859268162, 1.3797612706449516)
_F16, _F8, _F4, _F2, _F1 = (2.0 ** (16 / 5), 2.0 ** (8 / 5), 2.0 ** (4 / 5), 2.0 ** (2 / 5),
                            2.0 ** (1 / 5))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def inv_fifth_root(x):
    """x^(-1/5) for 2^-31 <= x < 2^32, to about an ulp, without a libm call (vectorisable)."""
    r = 1.0
    if x >= 65536.0:
        x *= 1.0 / 65536.0
        r /= _F16
    if x >= 256.0:
        x *= 1.0 / 256.0
        r /= _F8
    if x >= 16.0:
        x *= 1.0 / 16.0
        r /= _F4
    if x >= 4.0:
        x *= 0.25
        r /= _F2
    if x >= 2.0:
        x *= 0.5
        r /= _F1
    if x < 1.0 / 65536.0:
        x *= 65536.0
        r *= _F16
    if x < 1.0 / 256.0:
        x *= 256.0
        r *= _F8
    if x < 1.0 / 16.0:
        x *= 16.0
        r *= _F4
    if x < 0.25:
        x *= 4.0
        r *= _F2
    if x < 0.5:
        x *= 2.0
        r *= _F1
    if x < 1.0:
        x *= 2.0
        r *= _F1
    y = (((_R4 * x + _R3) * x + _R2) * x + _R1) * x + _R0
    for _ in range(2):
        y2 = y * y
        y = y * (6.0 - x * y2 * y2 * y) * 0.2
    return r * y



# log2 and exp2 for the step-size controller, where ~1e-8 relative accuracy is ample.
_LN2 = 0.69314718055994530942
_INV_LN2 = 1.44269504088896340736
_SQRT2 = 1.41421356237309504880


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def log2_fast(x):
    """log2 x for 2^-63 < x < 2^64, to about 1e-9 absolute (vectorisable)."""
    e = 0.0
    if x >= 4294967296.0:
        x *= 1.0 / 4294967296.0
        e += 32.0
    if x >= 65536.0:
        x *= 1.0 / 65536.0
        e += 16.0
    if x >= 256.0:
        x *= 1.0 / 256.0
        e += 8.0
    if x >= 16.0:
        x *= 1.0 / 16.0
        e += 4.0
    if x >= 4.0:
        x *= 0.25
        e += 2.0
    if x >= 2.0:
        x *= 0.5
        e += 1.0
    if x < 1.0 / 4294967296.0:
        x *= 4294967296.0
        e -= 32.0
    if x < 1.0 / 65536.0:
        x *= 65536.0
        e -= 16.0
    if x < 1.0 / 256.0:
        x *= 256.0
        e -= 8.0
    if x < 1.0 / 16.0:
        x *= 16.0
        e -= 4.0
    if x < 0.25:
        x *= 4.0
        e -= 2.0
    if x < 0.5:
        x *= 2.0
        e -= 1.0
    if x >= _SQRT2:          # 0.5 <= x < 2 here: centre it on 1
        x *= 0.5
        e += 1.0
    if x < 0.5 * _SQRT2:
        x *= 2.0
        e -= 1.0
    s = (x - 1.0) / (x + 1.0)            # ln x = 2 atanh s, |s| <= 0.1716
    z = s * s
    return e + 2.0 * _INV_LN2 * s * (1.0 + z * (1.0 / 3 + z * (1.0 / 5 + z * (1.0 / 7 + z / 9))))


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def exp2_fast(y):
    """2^y for |y| < 32, to about 1e-9 relative (vectorisable)."""
    n = np.floor(y + 0.5)
    r = (y - n) * _LN2                  # |r| <= ln2 / 2
    e = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6 + r * (1.0 / 24 + r * (1.0 / 120 + r * (
        1.0 / 720 + r * (1.0 / 5040 + r / 40320)))))))
    k = abs(n)
    p = 1.0            # 2^|n| and 2^-|n|, built side by side (no division)
    p_inv = 1.0
    if k >= 16.0:
        p *= 65536.0
        p_inv *= 1.0 / 65536.0
        k -= 16.0
    if k >= 8.0:
        p *= 256.0
        p_inv *= 1.0 / 256.0
        k -= 8.0
    if k >= 4.0:
        p *= 16.0
        p_inv *= 1.0 / 16.0
        k -= 4.0
    if k >= 2.0:
        p *= 4.0
        p_inv *= 0.25
        k -= 2.0
    if k >= 1.0:
        p *= 2.0
        p_inv *= 0.5
    return e * p_inv if n < 0.0 else e * p
