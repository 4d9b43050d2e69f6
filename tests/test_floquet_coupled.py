"""The Floquet chart of spans whose clamps are not pins (docs/model.md secs. 8, 10): their modes
couple through the axial-load matrix A_ij = int phi_i' phi_j' (modes 1 and 3 of a clamped span),
so the chart integrates the 2N-state system over one load period (kernels/floquet.py
`coupled_monodromy`). Checked against references written here, not from sweep.models.basis:

- SciPy solve_ivp (DOP853, rtol 1e-12) of rho A M q'' + c M q' + EI B q - P(t) A q = 0 with M, B,
  A by Gauss-Legendre quadrature of the textbook clamped shapes (tests/galerkin.py) or of the
  elastic ends' shapes written below about midspan, modal damping 2 zeta w_n;
- scipy.special.mathieu_a / mathieu_b for one undamped clamped mode's principal zone;
- Liouville: det Phi(T) = exp(-tr(D) T).
"""

from __future__ import annotations

import math
import subprocess
import sys
from typing import Callable

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import sweep
from sweep.models import basis, stability

import galerkin as g

E, RHO, AREA, INERTIA = 1.1e11, 8900.0, 6e-6, 2.865e-12
EI, RHO_A = E * INERTIA, RHO * AREA
LENGTH = 0.8
CLAMPED_BL = (4.730040745, 7.853204624, 10.99560784)      # b_n l, docs/model.md sec. 10.1

CHART = """
name = "coupled-chart"
[model]
modes = {modes}
[cable]
inertia = 2.865e-12
damping_ratio = {zeta}
length = 0.8
[clamps]
rotation = "{rotation}"
{extra}
[load]
type = "harmonic"
[axes]
frequency_ratio = {ratios}
load_amplitude = {loads}
[outputs]
stability = true
amplitude = false
peak_amplitude = false
settling_time = false
response_period = false
solver_stats = false
"""


def chart(rotation: str, modes: int, ratios: list[float], loads: list[float], zeta: float,
          extra: str = ""):
    text = CHART.format(modes=modes, zeta=zeta, rotation=rotation, extra=extra,
                        ratios=[float(r) for r in ratios], loads=[float(p) for p in loads])
    return sweep.run(sweep.load_scene_text(text), progress=False)


# --- the references ----------------------------------------------------------------------

def matrices(shapes: list[Callable], stiffness: float = 0.0, nodes: int = 120
             ) -> tuple[np.ndarray, ...]:
    """M = int phi_i phi_j, B = int phi_i'' phi_j'' + (K / l) (phi_i' phi_j' at both ends),
    A = int phi_i' phi_j' (x in m) by Gauss-Legendre on [0, LENGTH]; shapes: phi(x, k), the
    k-th derivative (galerkin.py's); stiffness: the clamps' K = k_t l / EI (the springs'
    energy k_t w'^2 / 2 at each end, over EI; 0 for clamped ends, whose slope is 0)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    x, w = 0.5 * LENGTH * (x + 1.0), 0.5 * LENGTH * w
    d = [np.array([phi(x, k) for phi in shapes]) for k in range(3)]
    ends = np.array([phi(np.array([0.0, LENGTH]), 1) for phi in shapes])     # (N, 2)
    springs = stiffness / LENGTH * ends @ ends.T
    return (d[0] * w) @ d[0].T, (d[2] * w) @ d[2].T + springs, (d[1] * w) @ d[1].T


def reference(M: np.ndarray, B: np.ndarray, A: np.ndarray, omegas: np.ndarray, zeta: float,
              load: float, W: float, diagonal: bool = False) -> tuple[np.ndarray, float]:
    """(Phi(T), T) of rho A M q'' + rho A M D q' + EI B q - P0 cos(W t) A q = 0, D =
    diag(2 zeta w_n), by solve_ivp DOP853 (rtol 1e-12) from the identity; diagonal: A's
    off-diagonal entries dropped (the uncoupled approximation)."""
    n = M.shape[0]
    A = np.diag(np.diag(A)) if diagonal else A
    inverse = np.linalg.inv(M)
    stiff, axial = inverse @ B * EI / RHO_A, -inverse @ A * load / RHO_A
    damping = np.diag(2.0 * zeta * np.asarray(omegas))
    period = 2.0 * math.pi / W

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        Y = y.reshape(2 * n, 2 * n)
        q, v = Y[:n], Y[n:]
        return np.concatenate((v, -damping @ v - (stiff + axial * math.cos(W * t)) @ q)).ravel()

    y = solve_ivp(rhs, (0.0, period), np.eye(2 * n).ravel(), method="DOP853", rtol=1e-12,
                  atol=1e-14).y[:, -1]
    return y.reshape(2 * n, 2 * n), period


def top(phi: np.ndarray, period: float) -> tuple[float, float]:
    """(max |lambda|, ln(max |lambda|) / T (1/s)) of a monodromy matrix."""
    size = float(np.max(np.abs(np.linalg.eigvals(phi))))
    return size, math.log(size) / period


def unit_max(shapes: list[Callable]) -> list[Callable]:
    """The shapes scaled to max |phi| = 1 over the span (the engine's q: the deflection at the
    mode's largest); the sign kept (phi > 0 near x = 0, as the engine's)."""
    scaled = []
    for phi in shapes:
        x = np.linspace(0.0, LENGTH, 20001)
        k = int(np.argmax(np.abs(phi(x, 0))))
        found = minimize_scalar(lambda z: -abs(float(phi(z, 0))), bounds=(
            x[max(k - 1, 0)], x[min(k + 1, x.size - 1)]), method="bounded",
            options={"xatol": 1e-12})
        size = max(abs(float(phi(found.x, 0))), float(np.max(np.abs(phi(x, 0)))))
        scaled.append(lambda z, k, phi=phi, size=size: phi(z, k) / size)
    return scaled


def elastic_shapes(stiffness: float) -> tuple[list[Callable], np.ndarray]:
    """Modes 1, 2, 3 of the span with rotational springs K = k_t l / EI at both ends, written
    about midspan (u = x / l - 1/2): symmetric cos(b u) + c cosh(b u), c = -cos(b/2) /
    cosh(b/2), antisymmetric sin(b u) + c sinh(b u), c = -sin(b/2) / sinh(b/2) (phi = 0 at the
    ends), b the roots of phi'' + K phi' = 0 at u = 1/2 (derivatives in u) by brentq on a scan.
    Returns (shapes phi(x, k), the b_n l)."""
    def parts(b: float, u: np.ndarray, odd: bool) -> list[np.ndarray]:
        if odd:
            c = -math.sin(b / 2) / math.sinh(b / 2)
            return [np.sin(b * u) + c * np.sinh(b * u), b * (np.cos(b * u) + c * np.cosh(b * u)),
                    b * b * (-np.sin(b * u) + c * np.sinh(b * u))]
        c = -math.cos(b / 2) / math.cosh(b / 2)
        return [np.cos(b * u) + c * np.cosh(b * u), b * (-np.sin(b * u) + c * np.sinh(b * u)),
                b * b * (-np.cos(b * u) + c * np.cosh(b * u))]

    def roots(odd: bool, count: int) -> list[float]:
        def residual(b: float) -> float:
            _, d1, d2 = parts(b, np.array(0.5), odd)
            return float(d2 + stiffness * d1) / (b * b + stiffness * b)
        grid = np.linspace(0.5, 20.0, 4000)
        values = [residual(b) for b in grid]
        found = [brentq(residual, grid[k], grid[k + 1], xtol=1e-14)
                 for k in range(grid.size - 1) if values[k] * values[k + 1] < 0]
        return found[:count]

    (b1, b3), (b2,) = roots(False, 2), roots(True, 1)
    shapes = []
    for b, odd in ((b1, False), (b2, True), (b3, False)):
        def phi(x, k, b=b, odd=odd):
            return parts(b, np.asarray(x, float) / LENGTH - 0.5, odd)[k] / LENGTH ** k
        shapes.append(phi)
    return shapes, np.array([b1, b2, b3])


def frequencies(bl: np.ndarray) -> np.ndarray:
    """w_n = (b_n l / l)^2 sqrt(EI / rho A) (rad/s)."""
    return (np.asarray(bl) / LENGTH) ** 2 * math.sqrt(EI / RHO_A)


def one(ds, name: str, **at) -> float:
    return float(ds[name].sel(**at).item())


def _check_chart(ds, M: np.ndarray, B: np.ndarray, A: np.ndarray, w: np.ndarray,
                 ratios: list[float], loads: list[float]) -> None:
    """The chart's multiplier (1e-8), growth rate (1e-6) and stability flag at every (ratio,
    load) against SciPy's monodromy of the same system (`reference`), damping ratio 0.01."""
    for r in ratios:
        for p in loads:
            size, rate = top(*reference(M, B, A, w, 0.01, p, r * w[0]))
            at = {"frequency_ratio": r, "load_amplitude": p}
            assert one(ds, "floquet_multiplier", **at) == pytest.approx(size, rel=1e-8)
            assert one(ds, "growth_rate", **at) == pytest.approx(rate, rel=1e-6, abs=1e-7)
            assert (one(ds, "stability", **at) != 0) == (size > 1.0)


# --- one clamped mode ----------------------------------------------------------------------

def test_one_clamped_mode_against_scipy():
    """modes = 1: the chart's multipliers and growth rates against the 2-state equation built
    from the textbook clamped shape by quadrature."""
    ratios, loads = [1.0, 2.0, 2.3], [4.0, 12.0]
    ds = chart("clamped", 1, ratios, loads, zeta=0.01)
    M, B, A = matrices(g.clamped_shapes(1, LENGTH))
    w = frequencies(CLAMPED_BL[:1])
    _check_chart(ds, M, B, A, w, ratios, loads)


def test_one_clamped_mode_zone_is_mathieus():
    """Undamped, one clamped mode is Mathieu's equation y'' + (a - 2 s cos 2z) y = 0 with
    a = 4 / r^2, s = 2 (P0 / Pcr) / r^2, r = W / w1, Pcr = EI B_11 / A_11 (40.69 EI / l^2):
    unstable (period 2T) between b_1(s) and a_1(s), stable just outside."""
    from scipy.special import mathieu_a, mathieu_b
    M, B, A = matrices(g.clamped_shapes(1, LENGTH))
    buckling = EI * B[0, 0] / A[0, 0]
    assert buckling * LENGTH ** 2 / EI == pytest.approx(40.69, abs=5e-3)
    load = 0.3 * buckling
    edges = []
    for curve in (mathieu_a, mathieu_b):        # a = curve(1, s(a)): the boundary's a
        a = brentq(lambda a: float(curve(1, 0.3 * a / 2.0)) - a, 0.3, 3.0, xtol=1e-13)
        edges.append(2.0 / math.sqrt(a))
    low, high = sorted(edges)
    ratios = [low * 0.999, low * 1.001, high * 0.999, high * 1.001]
    ds = chart("clamped", 1, ratios, [load], zeta=0.0)
    flags = [int(one(ds, "stability", frequency_ratio=r, load_amplitude=load)) for r in ratios]
    assert flags == [0, 2, 2, 0]


# --- three clamped modes: 1 and 3 couple ---------------------------------------------------

def test_three_clamped_modes_monodromy_against_scipy():
    """Phi(T) of modes 1, 2, 3 (kernels.floquet.coupled_block through stability.monodromies,
    the basis' matrices from stability.coupled_matrices) against SciPy's 6-state system on the
    textbook shapes (scaled to max |phi| = 1 like the engine's), entry by entry; and det Phi
    against Liouville's exp(-tr(D) T)."""
    shapes = unit_max(g.clamped_shapes(3, LENGTH))
    M, B, A = matrices(shapes)
    assert abs(A[0, 2]) > 0.5 * A[0, 0] and abs(A[0, 1]) < 1e-9 * A[0, 0]
    w = frequencies(CLAMPED_BL)
    rate_ratio, load_shape = stability.coupled_matrices(basis.clamped(3))
    for zeta, r, load in ((0.01, 2.0, 15.0), (0.02, 6.4, 10.0)):
        W = r * w[0]
        kc = -load * A[0, 0] / (M[0, 0] * RHO_A)           # mode 1's, from the textbook
        phi = stability.monodromies(np.array([2.0 * zeta * w[0]]), np.array([w[0] ** 2]),
                                    np.array([kc]), np.array([W]), np.array([0]),
                                    rate_ratio[None], load_shape[None])[0]
        expected, period = reference(M, B, A, w, zeta, load, W)
        scale = np.max(np.abs(expected), axis=1, keepdims=True)     # each row's size (units)
        assert np.max(np.abs(phi - expected) / scale) < 1e-8
        liouville = math.exp(-2.0 * zeta * w.sum() * period)
        assert np.linalg.det(phi) / liouville - 1.0 == pytest.approx(0.0, abs=1e-10)


def test_coupling_moves_the_growth_rate(tmp_path):
    """End to end (`sweep run` of a clamped 3-mode scene to a file): the chart against SciPy's
    coupled system; near W = w1 + w3 (6.40 w1) the coupling of modes 1 and 3 makes a
    combination resonance (an unstable complex pair) where the diagonal-only approximation is
    stable; in the principal zone (W = 2 w1) it moves the growth rate measurably."""
    ratios, loads = [2.0, 6.4], [15.0]
    scene = tmp_path / "clamped.toml"
    scene.write_text(CHART.format(modes=3, zeta=0.01, rotation="clamped", extra="",
                                  ratios=ratios, loads=loads))
    out = tmp_path / "chart.nc"
    done = subprocess.run([sys.executable, "-m", "sweep.cli", "run", str(scene), "-o", str(out)],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    import xarray as xr
    with xr.open_dataset(out) as ds:
        ds.load()
    M, B, A = matrices(g.clamped_shapes(3, LENGTH))
    w = frequencies(CLAMPED_BL)
    rates = {}
    for r in ratios:
        at = {"frequency_ratio": r, "load_amplitude": 15.0}
        coupled = top(*reference(M, B, A, w, 0.01, 15.0, r * w[0]))
        alone = top(*reference(M, B, A, w, 0.01, 15.0, r * w[0], diagonal=True))
        assert one(ds, "floquet_multiplier", **at) == pytest.approx(coupled[0], rel=1e-8)
        assert one(ds, "growth_rate", **at) == pytest.approx(coupled[1], rel=1e-6)
        rates[r] = (one(ds, "growth_rate", **at), alone[1])
    combination = {"frequency_ratio": 6.4, "load_amplitude": 15.0}
    assert rates[6.4][0] > 2.5 and rates[6.4][1] < -0.8          # 2.89 1/s against -0.85
    assert one(ds, "stability", **combination) == 3               # unstable_complex
    assert abs(rates[2.0][0] - rates[2.0][1]) > 0.05              # 14.86 against 14.80 1/s
    full = ds["floquet_mode"].attrs["long_name"] + ds["floquet_mode"].attrs.get("comment", "")
    assert "largest |q_n|" in full       # the label, or the whole text in comment


def test_undamped_stable_points_stay_stable():
    """Undamped, the stable multipliers lie on the unit circle: the coupled chart calls them
    stable (within stability.MARGIN), its combination resonance unstable."""
    ds = chart("clamped", 3, [3.0, 6.4], [15.0], zeta=0.0)
    calm = {"frequency_ratio": 3.0, "load_amplitude": 15.0}
    assert one(ds, "stability", **calm) == 0
    assert one(ds, "floquet_multiplier", **calm) == pytest.approx(1.0, abs=1e-11)
    assert one(ds, "stability", frequency_ratio=6.4, load_amplitude=15.0) == 3


# --- elastic ends --------------------------------------------------------------------------

def test_elastic_ends_against_scipy():
    """K = k_t l / EI = 10, three modes (shapes written here about midspan): the chart's
    multipliers and growth rates against SciPy's 6-state system, in the principal zone and
    near the combination W = w1 + w3."""
    stiffness = 10.0
    shapes, bl = elastic_shapes(stiffness)
    assert bl[0] == pytest.approx(4.1557, abs=1e-4)                # docs/model.md sec. 10
    M, B, A = matrices(shapes, stiffness)
    assert np.allclose(np.linalg.solve(M, B) * LENGTH ** 4, np.diag(bl ** 4), rtol=1e-9,
                       atol=1e-9 * bl[-1] ** 4)            # the shapes are the span's modes
    w = frequencies(bl)
    ratios, loads = [2.0, round(1.0 + w[2] / w[0], 3)], [6.0, 12.0]
    ds = chart("elastic", 3, ratios, loads, zeta=0.01,
               extra=f"rotational_stiffness = {stiffness * EI / LENGTH!r}")
    _check_chart(ds, M, B, A, w, ratios, loads)
