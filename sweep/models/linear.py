"""The span made linear (no stretching, no end load), mode by mode: what the nonlinear results
are read against. Its modes are uncoupled (the unloaded basis' eigenmodes), each a damped
oscillator driven by the base through its participation, so the midspan's receptance is a sum
over the modes the scene keeps (model.modes): G(w) = -sum_n g_n / (w_n^2 - w^2 + i 2 zeta w_n w),
g_n = phi_n(l/2) Gamma_n (midspan value times participation; for pinned sines 4/(n pi) and
sin(n pi / 2)). A sine's steady midspan amplitude is A |G(w)| (`linear_amplitude`); a random
record's RMS and spectra integrate |G|^2 over its spectrum (sweep/models/random_outputs.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..dataset import derived


MODE = "mode_"
"""The modes' axis of `linear_modes`' arrays (summed away by `receptance`)."""


def receptance(omega: np.ndarray, damping: np.ndarray, weights: np.ndarray,
               w: np.ndarray) -> np.ndarray:
    """The midspan's receptance G(w) = -sum_n weights_n / (omega_n^2 - w^2 + i damping_n w)
    (m per m/s^2 of base acceleration) at angular frequencies w (rad/s), from `linear_modes`'
    omega (rad/s), damping (2 zeta omega, 1/s) and weights, each (..., N): w's shape
    broadcasts against their leading axes."""
    w = np.asarray(w)[..., None]
    return -np.sum(weights / (omega ** 2 - w ** 2 + 1j * damping * w), axis=-1)


def linear_modes(coeffs: dict[str, Any], params: dict[str, Any], basis: Any, n_modes: int,
                 coords: dict[str, xr.DataArray]
                 ) -> tuple[xr.DataArray, np.ndarray, np.ndarray, np.ndarray, xr.DataArray]:
    """The span made linear, mode by mode, on the axes it depends on: (a template on those
    axes, omega (rad/s), 2 zeta omega (1/s) and weights (midspan value times participation),
    each (..., mode), and the base level factor on the template's axes). Mode n at f1 times
    its basis frequency ratio with damping ratio zeta; elastic ends swept over the grid: each
    point's own basis."""
    from .basis import BasisFamily, end_stiffness
    mode = MODE
    if n_modes == 1:
        ratio = xr.DataArray(np.ones(1), dims=mode)
        weight = xr.DataArray(np.ones(1), dims=mode)
        gamma = derived(coeffs["participation"], coords)
    elif isinstance(basis, BasisFamily):  # elastic ends varying: each point's own basis
        stiffness = derived(end_stiffness("elastic", params["clamp_rotational_stiffness"],
                                          params["length"],
                                          params["youngs_modulus"] * params["inertia"]), coords)
        at = basis.index(np.asarray(stiffness.values, float))
        ratios = np.array([b.frequency_ratio / b.frequency_ratio[0] for b in basis.bases])
        weights = np.array([b.midspan * b.participation_ratio for b in basis.bases])
        ratio = xr.DataArray(ratios[at], dims=stiffness.dims + (mode,))
        weight = xr.DataArray(weights[at], dims=stiffness.dims + (mode,))
        gamma = derived(4.0 / np.pi, coords)
    else:
        ratio = xr.DataArray(basis.frequency_ratio / basis.frequency_ratio[0], dims=mode)
        weight = xr.DataArray(basis.midspan * basis.participation_ratio, dims=mode)
        gamma = derived(4.0 / np.pi, coords)
    f1 = derived(coeffs["natural_frequency"], coords)
    zeta = derived(params["damping_ratio"], coords)
    level = derived(coeffs["base_accel"], coords)
    f1, zeta, gamma, level, ratio, weight = xr.broadcast(f1, zeta, gamma, level, ratio, weight)
    order = [d for d in f1.dims if d != mode] + [mode]
    omega = 2.0 * np.pi * (f1 * ratio).transpose(*order).values
    template = f1.isel({mode: 0}, drop=True).transpose(*order[:-1])
    level = level.isel({mode: 0}, drop=True).transpose(*order[:-1])
    return (template, omega, 2.0 * zeta.transpose(*order).values * omega,
            (gamma * weight).transpose(*order).values, level)


def linear_amplitude(coeffs: dict[str, Any], params: dict[str, Any], basis: Any, n_modes: int,
                     coords: dict[str, xr.DataArray]) -> xr.DataArray:
    """The steady midspan amplitude (m) of the span made linear under the scene's base sine
    A sin(w t), over its n_modes modes (`linear_modes`): A |sum_n g_n / (w_n^2 - w^2 + i 2 zeta
    w_n w)|, NaN where unbounded (undamped at resonance); on the axes it depends on."""
    template, omega, damping, weights, level = linear_modes(coeffs, params, basis, n_modes,
                                                            coords)
    modes = [xr.DataArray(a, dims=template.dims + (MODE,)) for a in (omega, damping, weights)]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        g = xr.apply_ufunc(receptance, *modes, derived(coeffs["base_omega"], coords),
                           input_core_dims=[[MODE]] * 3 + [[]])
        amplitude = abs(g) * level.drop_vars(list(level.coords))
    amplitude = amplitude.where(np.isfinite(amplitude))
    amplitude = amplitude.transpose(*[d for d in coords if d in amplitude.dims])
    return amplitude.assign_attrs(
        units="m", long_name=LINEAR_AMPLITUDE_LONG_NAME.format(modes=(
            "its first mode" if n_modes == 1 else f"its {n_modes} modes (model.modes)")))


LINEAR_AMPLITUDE_LONG_NAME = (
    "steady midspan amplitude of the span made linear (no stretching, no end load) over "
    "{modes}: A |sum_n Gamma_n phi_n(l/2) / (w_n^2 - w^2 + i 2 zeta w_n w)|, Gamma_n the mode's "
    "participation (Gamma_1 phi_1(l/2) = 4/pi for pinned ends); NaN: unbounded (undamped at "
    "resonance)")
