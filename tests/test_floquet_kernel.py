"""kernels/floquet.py: Floquet multipliers of q'' + c q' + (k + kc cos W t) q = 0 against
independent references: SciPy's Mathieu characteristic values (undamped stability chart) and a
SciPy solve_ivp DOP853 monodromy (damped multipliers, growth rates, the step rule's
convergence)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import mathieu_a, mathieu_b

from sweep.kernels import floquet as fq


def reference_monodromy(c, k, kc, W, rtol=1e-12, atol=1e-14):
    """Phi(T) by SciPy's adaptive DOP853, both columns (independent of the kernel)."""
    T = 2.0 * math.pi / W

    def f(t, y):
        s = k + kc * math.cos(W * t)
        return [y[1], -c * y[1] - s * y[0], y[3], -c * y[3] - s * y[2]]

    sol = solve_ivp(f, (0.0, T), [1.0, 0.0, 0.0, 1.0], method="DOP853", rtol=rtol, atol=atol)
    assert sol.success
    y = sol.y[:, -1]
    return np.array([[y[0], y[2]], [y[1], y[3]]])


def reference_multipliers(phi, T):
    """(max |lambda|, sigma, kind) from the eigenvalues of Phi (numpy, not the kernel's formula)."""
    lam = np.linalg.eigvals(phi)
    i = int(np.argmax(np.abs(lam)))
    mag = float(abs(lam[i]))
    kind = 0 if mag <= 1.0 else (1 if lam[i].real > 0 else 2)
    return mag, math.log(mag) / T, kind


def block(c, k, kc, W):
    c, k, kc, W = (np.ascontiguousarray(np.broadcast_to(np.asarray(x, float), np.shape(W)))
                   for x in (c, k, kc, W))
    n = W.shape[0]
    m = np.full(n, -7.0)
    g = np.full(n, -7.0)
    kd = np.full(n, -7, np.int64)
    fq.floquet_block(c, k, kc, W, 0, n, m, g, kd)
    return m, g, kd


def case(r, load, zeta, k=(2 * math.pi * 40.0) ** 2):
    """(c, k, kc, W) of one mode: r = W / w1, load = P0 / Pcr."""
    w1 = math.sqrt(k)
    return 2.0 * zeta * w1, k, -k * load, r * w1


# --- 1. the undamped chart against SciPy's Mathieu characteristic values -----------------------

def test_undamped_chart_matches_mathieu_characteristic_values():
    r, load = np.meshgrid(np.linspace(0.3, 3.0, 60), np.linspace(0.0, 1.0, 40), indexing="ij")
    r, load = r.ravel(), load.ravel()
    k = 4.0e4                                           # w1 = 200 rad/s
    W = r * math.sqrt(k)
    kc = -k * load
    m, g, kd = block(0.0, k, kc, W)
    assert np.all(kd >= 0)
    unstable_kernel = kd > 0
    # Mathieu form y'' + (a - 2 s cos 2z) y = 0, z = W t / 2:
    # (W^2/4) y_zz + (k + kc cos 2z) y = 0  ->  a = 4 k / W^2, s = -2 kc / W^2 (>= 0 here)
    a = 4.0 * k / W**2
    s = -2.0 * kc / W**2
    assert np.allclose(a, 4.0 / r**2) and np.allclose(s, 2.0 * load / r**2)
    M = 12
    assert np.all(mathieu_b(M, s) > a.max())            # every zone below a is listed
    unstable_ref = a < mathieu_a(0, s)
    near = np.abs(a - mathieu_a(0, s)) <= 1e-6 * np.abs(a)
    for order in range(1, M + 1):
        am, bm = mathieu_a(order, s), mathieu_b(order, s)
        unstable_ref |= (bm < a) & (a < am)
        near |= (np.abs(a - am) <= 1e-6 * np.abs(a)) | (np.abs(a - bm) <= 1e-6 * np.abs(a))
    keep = ~near
    excluded = int(near.sum())
    print(f"\nMathieu chart: {r.size} points, {excluded} excluded within 1e-6 of a boundary, "
          f"{int(unstable_ref[keep].sum())} unstable")
    assert excluded < 0.02 * r.size                     # the band is thin
    assert unstable_ref[keep].sum() > 0.1 * keep.sum()  # both classes well represented
    bad = np.flatnonzero(keep & (unstable_kernel != unstable_ref))
    assert bad.size == 0, [(r[i], load[i], a[i], s[i], m[i]) for i in bad[:5]]
    # undamped and stable: |lambda| = 1 (complex pair on the unit circle), sigma = 0
    stable = keep & ~unstable_ref
    assert np.all(np.abs(m[stable] - 1.0) <= 1e-9) and np.all(np.abs(g[stable]) <= 1e-9)


# --- 2. damped multipliers and growth rates against a SciPy monodromy ---------------------------

def _random_cases(n=30, seed=20240611):
    rng = np.random.default_rng(seed)
    cases = []
    # the corners of the range first
    for k in (1.0, 1e8):
        for r, kcr, zeta in ((0.2, 1.0, 0.1), (0.2, -1.0, 0.0), (4.0, 1.0, 0.1)):
            cases.append((k, r, kcr, zeta))
    cases += [(1e4, 1.0, 0.8, 0.01), (1.0, 0.3, 1.0, 0.02)]     # kind 1 (second, fourth zone)
    while len(cases) < n:
        cases.append((10 ** rng.uniform(0, 8), rng.uniform(0.2, 4.0), rng.uniform(-1, 1),
                      rng.uniform(0.0, 0.1)))
    out = []
    for k, r, kcr, zeta in cases:
        w1 = math.sqrt(k)
        out.append((2 * zeta * w1, k, kcr * k, r * w1))
    return out


CASES = _random_cases()


def test_damped_multipliers_and_growth_rates_match_scipy_dop853():
    c, k, kc, W = (np.array(x) for x in zip(*CASES))
    m, g, kd = block(c, k, kc, W)
    worst_m = worst_g = 0.0
    kinds = set()
    for i, (ci, ki, kci, Wi) in enumerate(CASES):
        T = 2 * math.pi / Wi
        m_ref, g_ref, kind_ref = reference_multipliers(reference_monodromy(ci, ki, kci, Wi), T)
        err_m = abs(m[i] - m_ref)
        err_g = abs(g[i] - g_ref)
        assert err_m <= 1e-7 * m_ref + 1e-9, (CASES[i], m[i], m_ref)
        assert err_g <= 1e-7 * abs(g_ref) + 1e-9 / T, (CASES[i], g[i], g_ref)
        assert kd[i] == kind_ref, (CASES[i], kd[i], kind_ref)
        worst_m = max(worst_m, err_m / m_ref)
        worst_g = max(worst_g, err_g / max(abs(g_ref), 1e-300))
        kinds.add(int(kd[i]))
    print(f"\n{len(CASES)} damped cases: worst relative error max|lambda| {worst_m:.1e}, "
          f"sigma {worst_g:.1e}; kinds {sorted(kinds)}")
    assert kinds >= {0, 1, 2}                  # the sample covers every kind


def test_integrated_det_matches_liouville():
    worst = 0.0
    for c, k, kc, W in CASES:
        n = fq.steps_for(c, k, kc, W)
        dev = fq.liouville_deviation(c, k, kc, W, n)
        worst = max(worst, abs(dev))
        assert abs(dev) <= 1e-10, ((c, k, kc, W), dev)
    print(f"\nworst |det Phi / exp(-cT) - 1| = {worst:.1e}")
    # and the check sees a wrong det: a quarter of the steps is visibly off somewhere
    c, k, kc, W = CASES[0]
    assert abs(fq.liouville_deviation(c, k, kc, W, 8)) > 1e-6


def test_step_rule_convergence_study():
    """The trace's error against a tighter SciPy reference at the corners of the range: at the
    rule's h Omega (H_OMEGA) below 1e-11 of max(|tr|, 2 sqrt(det)), and order 8 (halving
    h Omega from 2 H_OMEGA divides the error by about 2^8)."""
    rows = []
    for k in (1.0, 1e8):
        for r in (0.2, 0.5, 1.2, 4.0):
            for kcr, zeta in ((1.0, 0.0), (-0.9, 0.1), (0.7, 0.06)):
                w1 = math.sqrt(k)
                c, kc, W = 2 * zeta * w1, kcr * k, r * w1
                phi = reference_monodromy(c, k, kc, W, rtol=1e-13, atol=1e-15)
                tr_ref = np.trace(phi)
                scale = max(abs(tr_ref), 2 * math.exp(-c * math.pi / W))
                errs = []
                for ho in (2 * fq.H_OMEGA, fq.H_OMEGA):
                    n = fq.steps_for(c, k, kc, W, ho)
                    errs.append(abs(fq.monodromy_trace(c, k, kc, W, n) - tr_ref) / scale)
                rows.append((k, r, kcr, zeta, *errs))
    coarse = np.array([x[4] for x in rows])
    fine = np.array([x[5] for x in rows])
    print(f"\ntrace error / scale: h Omega = {2 * fq.H_OMEGA}: max {coarse.max():.1e}; "
          f"h Omega = {fq.H_OMEGA}: max {fine.max():.1e}")
    assert fine.max() <= 1e-11
    big = coarse > 1e-10                # where the coarse error stands clear of the reference's
    assert big.sum() >= 6
    ratio = coarse[big] / np.maximum(fine[big], 1e-16)
    assert np.median(ratio) > 100.0, ratio       # order ~8 (2^8 = 256), not 4 or 5


# --- 3. kinds -----------------------------------------------------------------------------------

def test_kind_in_each_zone():
    cases = [case(2.0, 0.3, 0.0), case(1.0, 0.5, 0.0), case(1.5, 0.2, 0.0), case(1.5, 0.2, 0.05),
             case(2.0, 0.3, 0.01)]
    c, k, kc, W = (np.array(x) for x in zip(*cases))
    m, g, kd = block(c, k, kc, W)
    assert kd[0] == fq.KIND_NEGATIVE and m[0] > 1.0 and g[0] > 0.0       # principal zone
    assert kd[1] == fq.KIND_POSITIVE and m[1] > 1.0 and g[1] > 0.0       # second zone
    assert kd[2] == fq.KIND_STABLE and abs(m[2] - 1.0) <= 1e-9 and abs(g[2]) <= 1e-9
    # damped and stable: a complex pair of modulus exp(-c T / 2), sigma = -c / 2
    T = 2 * math.pi / W[3]
    assert kd[3] == fq.KIND_STABLE
    assert m[3] == pytest.approx(math.exp(-c[3] * T / 2), rel=1e-12)
    assert g[3] == pytest.approx(-c[3] / 2, rel=1e-12)
    # light damping leaves the principal zone unstable, still period 2T
    assert kd[4] == fq.KIND_NEGATIVE
    # the sign of the real multiplier, as the trace's: the period-2T response flips each period
    tr0 = fq.monodromy_trace(c[0], k[0], kc[0], W[0], fq.steps_for(c[0], k[0], kc[0], W[0]))
    tr1 = fq.monodromy_trace(c[1], k[1], kc[1], W[1], fq.steps_for(c[1], k[1], kc[1], W[1]))
    assert tr0 < -2.0 and tr1 > 2.0


def test_multipliers_formula_and_negative_damping():
    T = 0.1
    m, g, kd = fq.multipliers(3.0, 1.0, T)
    assert m == pytest.approx((3 + math.sqrt(5)) / 2, rel=1e-15) and kd == fq.KIND_POSITIVE
    assert g == pytest.approx(math.log((3 + math.sqrt(5)) / 2) / T, rel=1e-14)
    m, g, kd = fq.multipliers(-3.0, 1.0, T)
    assert m == pytest.approx((3 + math.sqrt(5)) / 2, rel=1e-15) and kd == fq.KIND_NEGATIVE
    m, g, kd = fq.multipliers(0.5, 4.0, T)               # det > 1: c < 0, complex, unstable
    assert m == 2.0 and kd == fq.KIND_COMPLEX and g == pytest.approx(math.log(2) / T)
    m, g, kd = fq.multipliers(1.0, 0.25, T)              # double root 0.5
    assert m == 0.5 and kd == fq.KIND_STABLE
    m, g, kd = fq.multipliers(1.2, 0.35, T)              # real roots 0.7 and 0.5: stable
    assert m == pytest.approx(0.7, rel=1e-15) and kd == fq.KIND_STABLE and g < 0.0
    # just outside the unit circle: |tr| = 2 + 1e-8, det = 1 -> lambda = 1 + 1e-4 (about)
    for tr, kind in ((2.0 + 1e-8, fq.KIND_POSITIVE), (-2.0 - 1e-8, fq.KIND_NEGATIVE)):
        m, g, kd = fq.multipliers(tr, 1.0, T)
        assert kd == kind and m == pytest.approx(1.0 + 1e-4, rel=1e-8) and g > 0.0
    m, g, kd = fq.multipliers(2.0 - 1e-8, 1.0, T)        # just inside: on the unit circle
    assert kd == fq.KIND_STABLE and m == 1.0 and g == 0.0


def test_trace_is_the_same_for_kc_and_minus_kc():
    """A half-period shift turns kc into -kc and conjugates Phi(T): the same trace."""
    for c, k, kc, W in CASES[:8]:
        n = fq.steps_for(c, k, kc, W)
        t1 = fq.monodromy_trace(c, k, kc, W, n)
        t2 = fq.monodromy_trace(c, k, -kc, W, n)
        assert abs(t1 - t2) <= 1e-10 * max(abs(t1), 1.0)


# --- 4. bad cases -------------------------------------------------------------------------------

def test_bad_cases_give_nan_and_kind_minus_one():
    good = case(2.0, 0.3, 0.01)
    nan, inf = math.nan, math.inf
    rows = [good, (0.0, 1.0, 0.0, 0.0), (0.0, 1.0, 0.0, -3.0), (nan, 1.0, 0.0, 1.0),
            (0.0, nan, 0.0, 1.0), (0.0, 1.0, nan, 1.0), (0.0, 1.0, 0.0, nan),
            (inf, 1.0, 0.0, 1.0), (0.0, 1.0, 0.0, inf), (0.0, 1e12, 0.0, 1e-3), good]
    c, k, kc, W = (np.array(x) for x in zip(*rows))
    n = len(rows)
    m = np.full(n, -7.0)
    g = np.full(n, -7.0)
    kd = np.full(n, -7, np.int64)
    fq.floquet_block(c, k, kc, W, 1, n - 1, m, g, kd)        # rows 1..n-2 only
    assert np.all(np.isnan(m[1:-1])) and np.all(np.isnan(g[1:-1]))
    assert np.all(kd[1:-1] == fq.KIND_BAD)
    assert m[0] == -7.0 and m[-1] == -7.0 and kd[0] == -7 and kd[-1] == -7   # outside lo..hi
    fq.floquet_block(c, k, kc, W, 0, n, m, g, kd)
    assert kd[0] == kd[-1] == fq.KIND_NEGATIVE and m[0] == m[-1] > 1.0
    assert math.isnan(fq.monodromy_trace(0.0, 1.0, 0.0, 0.0, 10))
    assert math.isnan(fq.monodromy_trace(0.0, 1.0, 0.0, 1.0, 0))
    assert fq.steps_for(0.0, 1.0, 0.0, 0.0) == -1
