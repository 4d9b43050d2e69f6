"""Stability of the straight span under a harmonic axial load: Floquet multipliers from one
load period per point (docs/model.md sec. 8, kernels/floquet.py).

Linearised about q = 0, mode n of the span obeys a damped Mathieu equation

    q_n'' + c_n q_n' + (k_n + kc_n cos W t) q_n = 0

with, from the one-mode coefficients (sweep/models/modal.py, m the modal mass):
c_1 = c / m, k_1 = k0 / m, kc_1 = k1 / m (either coefficient set, the paper's too), and for the
consistent model's mode n (docs/model.md sec. 7, a harmonic load has no mean part)
c_n = n^2 c_1, k_n = n^4 k_1, kc_n = n^2 kc_1. The base excitation and the nonlinear terms do
not enter: this is the stability of the straight span itself. Pinned modes decouple, so a
point's multiplier is the largest of its modes' (`_per_mode_points`; so is one mode of any
span, from its own one-mode coefficients).

Clamped and elastic ends with several modes: the axial load couples the span's own modes
(docs/model.md sec. 10.2: A_ij = int phi_i' phi_j', modes 1 and 3 of a clamped span), and the
N modes obey

    q'' + D q' + (S + L cos W t) q = 0,    D_n = (w_n / w_1) c_1,  S_n = (w_n / w_1)^2 k_1,
    L = kc_1 L' / L'_11,    L'_nm = int phi_m'' phi_n / int phi_n^2  (s = x / l)

(the time-domain N-mode model's modal damping 2 zeta w_n and load projection, kernels/modes.py;
L' by the basis' own quadrature, `coupled_matrices`; the basis of each point's clamps K =
k_t l / EI, modal.oscillator's end_stiffness). `_coupled_points` integrates the 2N-state
monodromy (kernels.floquet.coupled_block) and takes its eigenvalues here (`dominant`).

Outputs: `floquet_multiplier` (max |lambda|, 1), `growth_rate` (ln max |lambda| / T, 1/s: > 0
unstable, -zeta w1 in a stable region of a damped span), `stability` (CF flags: stable,
unstable_period_1 with a multiplier > 1, the response repeating every load period,
unstable_period_2 with one < -1, every two: the principal zone near W = 2 w1 is of this kind;
unstable_complex, a complex pair outside the unit circle: coupled modes' combination resonance
near W = w1 + w3), and with several modes `floquet_mode`: the mode that has the largest
multiplier (pinned), or the one with the largest |q_n| in the largest multiplier's eigenvector
(coupled).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .. import grid

if TYPE_CHECKING:
    from .basis import Basis

STABILITY_FLAGS = {-1: "invalid_input", 0: "stable", 1: "unstable_period_1",
                   2: "unstable_period_2", 3: "unstable_complex"}
"""kernels.floquet's kinds -> CF flag meanings."""
OUTPUTS = ("floquet_multiplier", "growth_rate", "stability", "floquet_mode")
"""The variables `stability_outputs` can make."""
CHUNK = 4096
"""Points whose monodromy matrices (2N x 2N each) are held at once on the coupled path."""
REAL = 1e-9
"""A multiplier whose imaginary part is at most this times its size counts as real."""
MARGIN = 1e-9
"""On the coupled path a point is unstable where max |lambda| > 1 + MARGIN: an undamped span's
stable multipliers lie on the unit circle, and the integration puts them there only to about
1e-12 (the per-mode path takes the exact det, so its stable |lambda| is 1 exactly)."""


def mode_coefficients(coeffs: dict[str, Any], n: int) -> tuple[Any, Any, Any]:
    """(c_n in 1/s, k_n and kc_n in 1/s^2) of mode n from the one-mode coefficients (any shape)."""
    c = np.asarray(coeffs["damping"] / coeffs["mass"], float)
    k = np.asarray(coeffs["k0"] / coeffs["mass"], float)
    kc = np.asarray(coeffs["k1"] / coeffs["mass"], float)
    return n * n * c, n ** 4 * k, n * n * kc


def coupled_matrices(basis: Basis) -> tuple[np.ndarray, np.ndarray]:
    """(w_n / w_1 (N,), L / L_11 (N, N)) of a basis (both dimensionless): its modes' natural
    frequencies over the first's, and its axial-load matrix L_nm = int phi_m'' phi_n /
    int phi_n^2 (s = x / l) over its (1, 1) entry, by the basis' own quadrature (its tables,
    as the time-domain N-mode kernel projects the load term: kernels/modes.py). L = -M^-1 A
    (docs/model.md sec. 10.2): diagonal, n^2, for pinned sines; clamped or elastic ends
    couple modes 1 and 3 (and 2 and 4, ...)."""
    load = basis.tables[4] @ basis.tables[1].T            # [n, m]: pi^-2 int phi_m'' phi_n / M_n
    ratio = basis.frequency_ratio / basis.frequency_ratio[0]
    return (np.ascontiguousarray(ratio, np.float64),
            np.ascontiguousarray(load / load[0, 0], np.float64))


def monodromies(c: np.ndarray, k: np.ndarray, kc: np.ndarray, omega: np.ndarray,
                index: np.ndarray, rate_ratio: np.ndarray, load_shape: np.ndarray,
                threads: int = 0) -> np.ndarray:
    """Phi(T) (rows, 2N, 2N) of each row's N coupled modes (kernels.floquet.coupled_block):
    q'' + D q' + (S + L cos W t) q = 0 with D = c rate_ratio[b] (1/s), S = k rate_ratio[b]^2,
    L = kc load_shape[b] (1/s^2), b = index (the row's basis, int), from mode 1's c (1/s),
    k, kc (1/s^2) and W = omega (rad/s) (float arrays (rows,)); NaN where the kernel refuses a
    row. rate_ratio, load_shape: `coupled_matrices` of each basis, stacked."""
    from sweep.kernels import floquet

    from ..threads import run_blocks
    rows, n = c.shape[0], rate_ratio.shape[1]
    phi = np.empty((rows, 2 * n, 2 * n))
    args = [np.ascontiguousarray(a, np.float64) for a in (c, k, kc, omega)]
    index = np.ascontiguousarray(index, np.int64)
    rate_ratio = np.ascontiguousarray(rate_ratio, np.float64)
    load_shape = np.ascontiguousarray(load_shape, np.float64)

    def block(lo: int, hi: int) -> None:
        floquet.coupled_block(*args, index, rate_ratio, load_shape, lo, hi, phi)

    run_blocks(block, rows, threads, None)
    return phi


def dominant(phi: np.ndarray, period: np.ndarray) -> tuple[np.ndarray, ...]:
    """(max |lambda| (1), growth rate ln(max |lambda|) / T (1/s), kind (kernels.floquet's
    kinds), mode) of monodromy matrices phi (rows, 2N, 2N) over periods T (s, (rows,)): the
    multipliers are Phi's eigenvalues (numpy); unstable where max |lambda| > 1 + MARGIN; the
    kind is that of the largest (a real one, if its imaginary part is at most REAL times its
    size, by its sign; a complex pair outside the unit circle: a combination resonance of two
    coupled modes, or negative damping); mode is the mode n (1..N) with the largest |q_n| in
    its eigenvector (1 with one mode). Rows with a non-finite Phi: NaN, KIND_BAD (-1), mode 0."""
    from sweep.kernels import floquet

    rows, n = phi.shape[0], phi.shape[1] // 2
    mag = np.full(rows, np.nan)
    rate = np.full(rows, np.nan)
    kind = np.full(rows, floquet.KIND_BAD, np.int64)
    mode = np.zeros(rows, np.int32)
    good = np.all(np.isfinite(phi), axis=(1, 2)) & (period > 0)
    if not np.any(good):
        return mag, rate, kind, mode
    values, vectors = np.linalg.eig(phi[good])
    top = np.argmax(np.abs(values), axis=1)
    at = np.arange(top.size)
    lam = values[at, top]
    size = np.abs(lam)
    real = np.abs(lam.imag) <= REAL * size
    unstable = size > 1.0 + MARGIN
    kinds = np.where(~unstable, floquet.KIND_STABLE,
                     np.where(~real, floquet.KIND_COMPLEX,
                              np.where(lam.real > 0.0, floquet.KIND_POSITIVE,
                                       floquet.KIND_NEGATIVE)))
    share = np.abs(vectors[at, :n, top])
    mag[good] = size
    with np.errstate(divide="ignore"):
        rate[good] = np.log(size) / period[good]
    kind[good] = kinds
    mode[good] = np.argmax(share, axis=1) + 1
    return mag, rate, kind, mode


def _coupled_points(per_point: dict[str, np.ndarray], n_modes: int, threads: int
                    ) -> tuple[np.ndarray, ...]:
    """`dominant`'s four arrays for every point of a span whose ends are not pins (its
    per_point end_stiffness K, mode 1's damping, mass, k0, k1 and omega): one basis per
    distinct K, the points a CHUNK at a time."""
    from .basis import span_basis
    stiffness = per_point["end_stiffness"]
    values, index = np.unique(stiffness, return_inverse=True)
    pairs = [coupled_matrices(span_basis(float(K), n_modes)) for K in values]
    rate_ratio = np.stack([p[0] for p in pairs])
    load_shape = np.stack([p[1] for p in pairs])
    mass = per_point["mass"]
    c, k, kc = (per_point[name] / mass for name in ("damping", "k0", "k1"))
    omega = per_point["omega"]
    with np.errstate(divide="ignore", invalid="ignore"):
        period = 2.0 * np.pi / omega
    size = omega.shape[0]
    out = (np.empty(size), np.empty(size), np.empty(size, np.int64), np.empty(size, np.int32))
    for lo in range(0, size, CHUNK):
        part = slice(lo, min(size, lo + CHUNK))
        phi = monodromies(c[part], k[part], kc[part], omega[part], index[part], rate_ratio,
                          load_shape, threads)
        for whole, piece in zip(out, dominant(phi, period[part])):
            whole[part] = piece
    return out


def _per_mode_points(per_point: dict[str, np.ndarray], n_modes: int, threads: int
                     ) -> tuple[np.ndarray, ...]:
    """(max |lambda|, growth rate, kind, mode) of every point of a pinned span (or any span with
    one mode): mode by mode, each a damped Mathieu equation (`mode_coefficients`), the largest
    multiplier of the modes; NaN, -1 and mode 0 where any mode's case is bad."""
    from sweep.kernels import floquet

    from ..threads import run_blocks
    size = per_point["omega"].shape[0]
    best = np.full(size, -np.inf)
    growth = np.full(size, np.nan)
    kind = np.full(size, -1, np.int8)
    mode = np.zeros(size, np.int32)
    omega = np.ascontiguousarray(per_point["omega"])
    bad = np.zeros(size, bool)
    for n in range(1, n_modes + 1):
        c, k, kc = (np.ascontiguousarray(a) for a in mode_coefficients(per_point, n))
        mult = np.empty(size)
        rate = np.empty(size)
        kinds = np.empty(size, np.int64)

        def block(lo: int, hi: int) -> None:
            floquet.floquet_block(c, k, kc, omega, lo, hi, mult, rate, kinds)

        run_blocks(block, size, threads, None)
        bad |= kinds < 0
        larger = mult > best
        best = np.where(larger, mult, best)
        growth = np.where(larger, rate, growth)
        kind = np.where(larger, kinds, kind).astype(np.int8)
        mode = np.where(larger, n, mode).astype(np.int32)
    best = np.where(bad, np.nan, best)
    growth = np.where(bad, np.nan, growth)
    kind = np.where(bad, -1, kind).astype(np.int8)
    return best, growth, kind, np.where(bad, 0, mode)


def _warn_unanswered(kind: np.ndarray, per_point: dict[str, np.ndarray]) -> None:
    """Warn (one line) where points have no Floquet answer (kind -1, invalid_input) though
    their inputs are finite, saying why: one load period needs more than the kernel's
    MAX_STEPS steps (a load this slow, W/w1 below about 4e-5, is quasi-static: the span
    buckles where P0 exceeds Pcr), or the damping decays the monodromy over one period past
    double precision (zeta w1 T of several hundred)."""
    finite = np.all([np.isfinite(v) for v in per_point.values()], axis=0)
    bad = (kind < 0) & finite & (per_point["omega"] > 0.0)
    if not bad.any():
        return
    import warnings

    from ..errors import CableSweepWarning
    with np.errstate(all="ignore"):
        w1 = np.sqrt(per_point["k0"] / per_point["mass"])
        ratio = per_point["omega"] / w1
        decay = np.pi * per_point["damping"] / (per_point["mass"] * per_point["omega"])
    warnings.warn(f"{int(bad.sum())} of {kind.size} points have no Floquet answer "
                  f"(stability invalid_input) at W/w1 down to {float(np.min(ratio[bad])):.3g} "
                  f"and zeta w1 T up to {float(np.max(decay[bad])):.3g}: one load period too "
                  "long for the kernel's steps (a load this slow is quasi-static: the span "
                  "buckles where P0 exceeds Pcr) or too damped for double precision (the "
                  "span is stable there); keep W/w1 above 1e-4", CableSweepWarning,
                  stacklevel=5)


def stability_outputs(coeffs: dict[str, Any], dims: tuple[str, ...], shape: tuple[int, ...],
                      n_modes: int, threads: int = 0) -> dict[str, xr.DataArray]:
    """The Floquet outputs of every grid point (module docstring): coeffs are modal.oscillator's
    on their axes (with end_stiffness where the clamps are not pins), dims and shape the
    grid's; on `threads` threads (0: all). Pinned ends or one mode: mode by mode; other ends
    with several modes: the coupled modes' monodromy."""
    names = ("damping", "mass", "k0", "k1", "omega")
    coupled = n_modes > 1 and "end_stiffness" in coeffs
    if coupled:
        names += ("end_stiffness",)
    table = grid.flatten({k: coeffs[k] for k in names}, names, dims, shape)
    per_point = dict(zip(names, table.T))
    best, growth, kind, mode = (_coupled_points if coupled else _per_mode_points)(
        per_point, n_modes, threads)
    kind = kind.astype(np.int8)
    _warn_unanswered(kind, per_point)
    out = {
        "floquet_multiplier": xr.DataArray(best.reshape(shape), dims=dims, attrs={
            "units": "1", "long_name": "largest Floquet multiplier |lambda| of the straight span "
                                       "linearised about q = 0 (over one load period)"}),
        "growth_rate": xr.DataArray(growth.reshape(shape), dims=dims, attrs={
            "units": "s-1", "long_name": "Floquet growth rate ln(max |lambda|) / T of the "
                                         "straight span (> 0: unstable)"}),
        "stability": xr.DataArray(kind.reshape(shape), dims=dims, attrs={
            "units": "1", "long_name": "stability of the straight span under the harmonic load",
            "flag_values": np.array(sorted(STABILITY_FLAGS), np.int8),
            "flag_meanings": " ".join(STABILITY_FLAGS[f] for f in sorted(STABILITY_FLAGS))}),
    }
    if n_modes > 1:
        text = ("the mode n with the largest |q_n| in the eigenvector of the largest Floquet "
                "multiplier (the modes are coupled; 0: none)" if coupled else
                "the mode n whose Floquet multiplier is the largest (0: none)")
        out["floquet_mode"] = xr.DataArray(mode.astype(np.int32).reshape(shape), dims=dims,
                                           attrs={"units": "1", "long_name": text})
    return out


def loaded_frequency(coeffs: dict[str, Any], n_modes: int) -> Any:
    """The first natural frequency (Hz) of the straight span under its constant end load:
    the lowest of the run's own linearised model about q = 0 with the load's stiffness in, so
    the frequency a `sweep design --min-frequency` judges the loaded span by. coeffs are
    modal.oscillator's for a constant load (k0 with the load's part, mass, natural_frequency
    the unloaded f1; end_stiffness where the clamps are not pins), scalars or DataArrays on
    their axes; NaN where the load buckles the straight span (no positive stiffness).

    One mode, or pinned sines (the load does not couple them, and mode 1 stays the lowest):
    sqrt(k0 / m) / 2 pi. Clamped or elastic ends with several modes: the load couples modes
    1 and 3 (and 2 and 4, ...), so the lowest eigenvalue of diag(w_n^2) + (k0 / m - w_1^2)
    L / L_11 (`coupled_matrices` of the basis of each distinct K; k0 / m - w_1^2 is mode 1's
    load stiffness)."""
    stiffness = coeffs["k0"] / coeffs["mass"]
    if n_modes == 1 or "end_stiffness" not in coeffs:
        with np.errstate(invalid="ignore"):
            return np.sqrt(stiffness.where(stiffness > 0.0) if isinstance(
                stiffness, xr.DataArray) else np.where(stiffness > 0.0, stiffness, np.nan)) / (
                2.0 * np.pi)
    from .basis import span_basis
    w1_sq = (2.0 * np.pi * coeffs["natural_frequency"]) ** 2
    k, w, ends = xr.broadcast(*(xr.DataArray(v) for v in (stiffness, w1_sq,
                                                            coeffs["end_stiffness"])))
    flat_k, flat_w, flat_e = (np.asarray(a.values, float).reshape(-1) for a in (k, w, ends))
    lowest = np.full(flat_k.shape, np.nan)
    for value in np.unique(flat_e[~np.isnan(flat_e)]):
        ratio, load = coupled_matrices(span_basis(float(value), n_modes))
        at = flat_e == value
        matrices = (np.diag(ratio * ratio)[None] * flat_w[at, None, None]
                    + (flat_k[at] - flat_w[at])[:, None, None] * load[None])
        lowest[at] = np.linalg.eigvals(matrices).real.min(axis=1)
    with np.errstate(invalid="ignore"):
        f = np.sqrt(np.where(lowest > 0.0, lowest, np.nan)) / (2.0 * np.pi)
    return xr.DataArray(f.reshape(k.shape), dims=k.dims, coords=k.coords)
