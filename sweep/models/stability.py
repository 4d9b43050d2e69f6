"""Stability of the straight span under a harmonic axial load: Floquet multipliers from one
load period per point (docs/model.md sec. 8, kernels/floquet.py).

Linearised about q = 0, mode n of the span obeys a damped Mathieu equation

    q_n'' + c_n q_n' + (k_n + kc_n cos W t) q_n = 0

with, from the one-mode coefficients (sweep/models/modal.py, m the modal mass):
c_1 = c / m, k_1 = k0 / m, kc_1 = k1 / m (either coefficient set, the paper's too), and for the
consistent model's mode n (docs/model.md sec. 7, a harmonic load has no mean part)
c_n = n^2 c_1, k_n = n^4 k_1, kc_n = n^2 kc_1. The base excitation and the nonlinear terms do
not enter: this is the stability of the straight span itself. The modes decouple, so a point's
multiplier is the largest of its modes'.

Outputs: `floquet_multiplier` (max |lambda|, 1), `growth_rate` (ln max |lambda| / T, 1/s: > 0
unstable, -zeta w1 in a stable region of a damped span), `stability` (CF flags: stable,
unstable_period_1 with a multiplier > 1, the response repeating every load period,
unstable_period_2 with one < -1, every two: the principal zone near W = 2 w1 is of this kind),
and with several modes `floquet_mode`, the mode that has the largest multiplier.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .. import grid

STABILITY_FLAGS = {-1: "invalid_input", 0: "stable", 1: "unstable_period_1",
                   2: "unstable_period_2", 3: "unstable_complex"}
"""kernels.floquet's kinds -> CF flag meanings."""
OUTPUTS = ("floquet_multiplier", "growth_rate", "stability", "floquet_mode")
"""The variables `stability_outputs` can make."""


def mode_coefficients(coeffs: dict[str, Any], n: int) -> tuple[Any, Any, Any]:
    """(c_n in 1/s, k_n and kc_n in 1/s^2) of mode n from the one-mode coefficients (any shape)."""
    c = np.asarray(coeffs["damping"] / coeffs["mass"], float)
    k = np.asarray(coeffs["k0"] / coeffs["mass"], float)
    kc = np.asarray(coeffs["k1"] / coeffs["mass"], float)
    return n * n * c, n ** 4 * k, n * n * kc


def stability_outputs(coeffs: dict[str, Any], dims: tuple[str, ...], shape: tuple[int, ...],
                      n_modes: int, threads: int = 0) -> dict[str, xr.DataArray]:
    """The Floquet outputs of every grid point (module docstring): coeffs are modal.oscillator's
    on their axes, dims and shape the grid's; mode by mode, on `threads` threads (0: all)."""
    from sweep.kernels import floquet

    from ..threads import run_blocks
    names = ("damping", "mass", "k0", "k1", "omega")
    table = grid.flatten({k: coeffs[k] for k in names}, names, dims, shape)
    per_point = dict(zip(names, table.T))
    size = table.shape[0]
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
        out["floquet_mode"] = xr.DataArray(np.where(bad, 0, mode).reshape(shape), dims=dims,
                                           attrs={"units": "1", "long_name": "the mode n whose "
                                                  "Floquet multiplier is the largest (0: none)"})
    return out
