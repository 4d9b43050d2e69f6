"""What the span does to its clamps and its wires (docs/model.md sec. 10.5): the bending strain
at the clamps and at midspan, the clamp's moment and transverse reaction, the stretching's
tension and strain, and the largest strain of them all, each its peak over the tail window.

Several modes: from the multi-mode kernels' load observers (kernels/modal_driver.py: the
curvature sum phi_n''(s) q_n at s = 0, 1, 1/2, the stretch E = q^T C q and the clamp shear
F_e = sum phi_n'''(e) q_n - (kappa E - P(t) l^2 / EI) sum a_n(e) q_n +- r (rho A l^4 / EI)
a_b(t), each's largest over the tail window).
The clamp shear is the span's equilibrium: beside the modes' shear, the parts of the loads
that the modes kept leave out go to the clamps as they would statically (the mode-acceleration
correction, docs/model.md sec. 10.5): the base's inertia load's, r (rho A l^4 / EI) a_b(t)
(r = 1/2 - sum_n Gamma_n int (1 - s) phi_n, kernels.modes.inertia_factor), and the axial
load's, through a_n(e) (sweep.models.basis.reaction_rows: phi_n'(e) for pinned sines, not 0
at a clamped end, where the tension's true shape bends over a boundary layer the modes do not
hold). Without them the reaction converges like 1/N and one mode misses 19 % (pinned) to
31 % (clamped) of a quasi-static one.
One mode: every one of them but the shear grows with |q| (the curvatures as |q|, the stretch
as q^2), so each peaks where q does and is the mode's integral times the tail amplitude
(sweep.models.basis.one_mode_integrals). Its shear is F = -a q + c a_b(t) (a = |phi'''(0)| +
(kappa E - P l^2 / EI) a_1(0), of one sign below buckling; c the left-out inertia's
factor), which need not peak with q. In a steady response q lags the base's a_b = A sin(W t)
by theta, and the damping's work per cycle gives sin(theta) = d W Q / (Gamma A) (d = 2 zeta
w1, Gamma the participation, Q the tail amplitude; the mode's equation q'' + d q' + R(q) =
-Gamma a_b, R = k0 q + g0 q^3 + h q^5): then max |F| = sqrt((a Q + c A cos(theta))^2 +
(c A sin(theta))^2), cos(theta) > 0 below the span's resonance at that amplitude (W^2 <
R(Q)/Q: the two parts in phase, their peaks added) and < 0 above it (opposed). W, A: the
base's angular frequency and level (a sweep's where q peaked). Exact for a linear span in
steady state; never above the bound a Q + c A. A sweep whose level table rises far above the
level at resonance (tens of g at several f1) can peak where q is small and the inertia carries
the reaction, which one mode misses. Two modes or more follow F in time. A random record (no
one frequency or level) and a harmonic end load (whose -P(t) w_x need not peak with q) give
one mode none (NaN).

In SI, l the length, EI the bending and EA the axial stiffness, d the cable's outer diameter:
curvature kappa = c / l^2 (c the observed curvature sum), strain (d / 2) kappa, moment EI kappa;
tension N = k_s pi^2 E / (2 l) (k_s: sweep.models.modal.stretching), its strain N / EA;
reaction EI F / l^3. `OUTPUTS` is the table: a new output is one row of it.
"""

from __future__ import annotations

import math
from typing import Any, Callable, NamedTuple

import numpy as np
import xarray as xr

from sweep.kernels import layout as tk

from ..dataset import derived
from . import modal
from .basis import end_stiffness, span_ends


class Peaks(NamedTuple):
    """The observed peaks over the tail window, as DataArrays over the grid: curvature sums at
    the clamps and at midspan (m: times 1 / l^2 the curvature), the stretch E (m^2) and the
    clamp shear F (m: times EI / l^3 the reaction)."""
    clamp: xr.DataArray
    midspan: xr.DataArray
    stretch: xr.DataArray
    shear: xr.DataArray


class Span(NamedTuple):
    """A grid's span quantities the outputs need (SI; numbers or DataArrays): l, EI, EA, d and
    k_s (None: the paper's local membrane term, no uniform tension)."""
    length: Any
    bending: Any
    axial: Any
    diameter: Any
    k_s: Any


def _strain(name: str) -> Callable[[Peaks, Span], Any]:
    return lambda p, s: 0.5 * s.diameter * getattr(p, name) / s.length ** 2


def _tension(p: Peaks, s: Span) -> Any:
    return s.k_s * math.pi ** 2 * p.stretch / (2.0 * s.length)


def _largest_strain(p: Peaks, s: Span) -> Any:
    bending = np.maximum(_strain("clamp")(p, s), _strain("midspan")(p, s))
    return bending + _tension(p, s) / s.axial


class Output(NamedTuple):
    """One row of `OUTPUTS`: name, units, long name, value(peaks, span), and when it is made:
    `clamped` (only where the clamps hold rotation: a pin's is 0), `tension` (only with the
    uniform stretching tension) and `diameter` (only where the cable's outer diameter is
    known: a data sheet without cable.diameter gives none)."""
    name: str
    units: str
    long_name: str
    value: Callable[[Peaks, Span], Any]
    clamped: bool = False
    tension: bool = False
    diameter: bool = False


OUTPUTS = (
    Output("clamp_bending_strain", "1", "bending strain of the outer fibre at the clamp: (d / 2) "
           "max |w_xx| at either clamp over the tail window (d the cable's diameter; the "
           "stretching's N / EA not included)", _strain("clamp"), clamped=True, diameter=True),
    Output("clamp_moment", "N m", "bending moment at the clamp: EI max |w_xx| at either clamp "
           "over the tail window", lambda p, s: s.bending * p.clamp / s.length ** 2,
           clamped=True),
    Output("midspan_bending_strain", "1", "bending strain of the outer fibre at midspan: "
           "(d / 2) max |w_xx(l/2)| over the tail window", _strain("midspan"), diameter=True),
    Output("clamp_force", "N", "transverse reaction at the clamp: max |V| at either clamp over "
           "the tail window, V = -EI w_xxx + (N - P) w_x (the shear, the stretching "
           "tension's transverse part and the end load's, P compression positive; without "
           "model.membrane's local term), by the span's equilibrium: the parts of the base's "
           "inertia and of the axial load that the modes kept leave out carried to the clamps "
           "as statically (mode acceleration); one mode: from its "
           "steady response's phase, at most the bound of its two parts' peaks added (NaN "
           "under a random record or a harmonic end load)",
           lambda p, s: s.bending * p.shear / s.length ** 3),
    Output("axial_tension", "N", "stretching tension of the span: its largest N = k_s e over "
           "the tail window (e = (1/2) int w_x^2 dx the elongation, k_s the span and its clamps "
           "in series)", _tension, tension=True),
    Output("axial_strain", "1", "stretching strain of the span: axial_tension / EA",
           lambda p, s: _tension(p, s) / s.axial, tension=True),
    Output("max_strain", "1", "largest outer-fibre strain reported: max(clamp_bending_strain, "
           "midspan_bending_strain) + axial_strain (their peaks added: an upper bound where "
           "they do not coincide; an end load's own axial strain -P / EA not included)",
           _largest_strain, tension=True, diameter=True),
)
NAMES = tuple(o.name for o in OUTPUTS)


def wanted(params: dict[str, Any]) -> bool:
    """Whether a scene gets these outputs: clamps that hold rotation, or the uniform tension
    (pinned clamps under the paper's local membrane term report none: model.membrane, or the
    paper's Eq.32 as printed, model.coefficients = 'paper', whose numbers hold that term)."""
    local = params.get("membrane") is not None or params.get("coefficients") == "paper"
    return _wanted(params.get("clamps_rotation"), local)


def _wanted(rotation: str | None, membrane: bool) -> bool:
    return (rotation or "pinned") != "pinned" or not membrane


TAIL_WINDOW = 1.0
"""kernels/layout.py's LOADS setting: the loads' peaks over the tail window
(kernels.modal_driver.TAIL_WINDOW)."""
WHOLE_RUN = 2.0
"""LOADS: over the whole run, a sine sweep's (kernels.modal_driver.WHOLE_RUN)."""


def peak_switch(swept: bool) -> str:
    """The outputs.* switch of the peaks over the tail window (a sine sweep's: over the whole
    sweep): outputs.amplitude, or outputs.peak_amplitude for a sweep. It governs the midspan's
    peak and every peak that goes with it: each mode's (modal_amplitude), the span's largest
    deflection (max_deflection and its position) and the loads (sweep.models.loads)."""
    return "outputs.peak_amplitude" if swept else "outputs.amplitude"


def observation(scene: Any, swept: bool) -> float:
    """kernels/layout.py's LOADS setting for `scene`: where it gets these outputs (`wanted`)
    and the deflection's peak they go with (`peak_switch`), their peaks over the tail window
    (TAIL_WINDOW: with outputs.amplitude) or, swept, over the whole sweep (WHOLE_RUN: with
    outputs.peak_amplitude, the peak a sweep reports); else 0.0, and the kernels skip that
    work."""
    membrane = (scene.get("model.membrane") is not None or "membrane" in scene.axes
                or "membrane" in (scene.points or {})
                or scene.get("model.coefficients") == "paper")
    if not (scene.get(peak_switch(swept)) and _wanted(scene.get("clamps.rotation"), membrane)):
        return 0.0
    return WHOLE_RUN if swept else TAIL_WINDOW


class OneMode(NamedTuple):
    """What one mode's clamp shear needs beside its tail amplitude (module docstring), each a
    number or a DataArray over the grid: the base's level A (m/s^2; NaN for a random record)
    and angular frequency W (rad/s), both a sweep's where q peaked, the mode's equation
    q'' + d q' + k0 q + g0 q^3 + h q^5 = -Gamma a_b (d, 1/s; k0, 1/s^2; g0, 1/(s^2 m^2); h,
    1/(s^2 m^4); Gamma, 1)."""
    level: Any
    omega: Any
    damping: Any
    k0: Any
    g0: Any
    h: Any
    participation: Any


def _one_mode_peaks(params: dict[str, Any], amplitude: xr.DataArray,
                    coords: dict[str, xr.DataArray], mode: OneMode) -> Peaks:
    """The peaks of one mode from its largest |q| and its equation (module docstring)."""
    p = params
    stiffness = end_stiffness(p.get("clamps_rotation") or "pinned",
                              p.get("clamp_rotational_stiffness"), p["length"],
                              p["youngs_modulus"] * p["inertia"])
    ends = span_ends(stiffness)
    ends = {k: derived(v, coords) for k, v in ends.items()}
    q = amplitude
    stretch = ends["slope_square"] / math.pi ** 2 * q * q
    _, k_s = modal.stretching(p)
    kappa = 0.0 if k_s is None else derived(
        k_s * math.pi ** 2 * p["length"] / (2.0 * p["youngs_modulus"] * p["inertia"]), coords)
    # the end load's part -P w_x (compression positive), as P l^2 / EI: with a constant load
    # the reaction still grows with |q| below buckling and peaks where q does; under a
    # harmonic one it need not, and one mode's peak |q| cannot give it: NaN there
    load = derived(p["load_amplitude"] * p["length"] ** 2
                   / (p["youngs_modulus"] * p["inertia"]), coords)
    a = ends["clamp_shear"] + (kappa * stretch - load) * ends["axial_slope"]
    l2 = p["length"] * p["length"]     # (not ** 4: pow may round differently by array length)
    c = ends["inertia"] * derived(p["density"] * p["area"] * (l2 * l2)
                                  / (p["youngs_modulus"] * p["inertia"]), coords)
    modes_part, inertia_part = abs(a * q), c * mode.level
    with np.errstate(divide="ignore", invalid="ignore"):
        q2 = q * q
        restoring = mode.k0 + (mode.g0 + mode.h * q2) * q2              # R(Q) / Q
        w2 = mode.omega * mode.omega
        lag = np.minimum(mode.damping * mode.omega * q / abs(mode.participation * mode.level),
                         1.0)                                           # sin(theta)
        lead = np.sqrt(1.0 - lag * lag) * xr.where(w2 > restoring, -1.0, 1.0)   # cos(theta)
        shear = np.sqrt((modes_part + inertia_part * lead) ** 2 + (inertia_part * lag) ** 2)
    shear = xr.where(inertia_part == 0.0, modes_part, shear)
    if p.get("load_type") == "harmonic":
        shear = shear.where(load == 0.0)
    _warn_above_resonance(shear, mode, coords, p.get("clamps_rotation") or "pinned")
    return Peaks(q * ends["clamp_curvature"], q * ends["midspan_curvature"], stretch, shear)


ONE_MODE_REACTION_LIMIT = 1.6
"""One mode's clamp reaction is warned of (`_warn_above_resonance`) above this many times the
mode's own linear frequency."""


# What one mode's reaction was measured to miss above ONE_MODE_REACTION_LIMIT, by the span's
# ends (`_warn_above_resonance`); elastic ends, between the two, were not measured.
_MEASURED_MISS = {"clamped": "-18 to -63 % at 1.7-3 f1 against five modes",
                  "pinned": "7-22 % near 2 f1 against the exact beam"}


def _warn_above_resonance(shear: xr.DataArray, mode: OneMode,
                          coords: dict[str, xr.DataArray], rotation: str = "pinned") -> None:
    """Warn (one line) where one mode's clamp reaction was computed at an excitation frequency
    above ONE_MODE_REACTION_LIMIT times the mode's linear one (sqrt(k0), rad/s). There the
    clamps' inertia opposes the span's shear, and the modes left out, which the static
    correction carries as if they did not move, are driven closer to their own resonances:
    measured against five modes on a clamped span, within 5 % up to 1.5 f1, then -18 to
    -63 % at 1.7-3 f1 (the reaction's two parts nearly cancel near 1.8 f1), and 7-22 % near
    2 f1 pinned against the exact beam. The line gives the frequency ratio in words and quotes
    the measured miss only for the span's own ends (`rotation`: clamps.rotation). Only where
    the base shakes the span (a level A != 0) below its buckling load (k0 > 0): a span at
    rest under an end load past buckling has no frequency to be above, and its reaction is
    the static one."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = (mode.omega / np.sqrt(mode.k0)) * xr.ones_like(shear)
        above = (np.isfinite(shear) & (mode.level != 0.0) & (mode.k0 > 0.0)
                 & (mode.omega * mode.omega > ONE_MODE_REACTION_LIMIT ** 2 * mode.k0))
    above = np.asarray(above.broadcast_like(shear).transpose(*shear.dims))
    if not above.any():
        return
    import warnings

    from ..errors import CableSweepWarning
    ratios = np.asarray(ratio.transpose(*shear.dims))[above]
    ratios = ratios[np.isfinite(ratios)]
    low, high = (f"{r:.2g}" for r in (ratios.min(), ratios.max())) if ratios.size else ("", "")
    at = ("at " + (low if low == high else f"{low} to {high}") + " times"
          if ratios.size else f"above {ONE_MODE_REACTION_LIMIT:g} times")
    index = np.unravel_index(int(np.argmax(above)), above.shape)
    example = ", ".join(f"{d} {float(coords[d].values[i]):.4g}{_unit_words(coords[d])}"
                        for d, i in zip(shear.dims, index) if d in coords)
    miss = _MEASURED_MISS.get(rotation)
    off = (f"(on a {rotation} span {miss})" if miss else "by up to tens of per cent")
    warnings.warn(f"clamp_force of one mode: {int(above.sum())} point(s) are shaken {at} the "
                  f"span's first natural frequency, past the {ONE_MODE_REACTION_LIMIT:g} times "
                  "one mode's reaction holds to"
                  f"{' (e.g. ' + example + ')' if example else ''}: the clamps' inertia opposes "
                  "the span's shear and the modes left out move, so one mode's reaction is off "
                  f"there {off}; run model.modes = 3 for clamp_force there",
                  CableSweepWarning, stacklevel=6)


def _unit_words(coord: xr.DataArray) -> str:
    """A coordinate's units as a number's suffix: ' m', ' g' for the keys in g, '' for 1."""
    from ..schema import G2_UNITS, G_UNITS
    units = coord.attrs.get("units", "1")
    units = {G_UNITS: "g", G2_UNITS: "g^2/Hz"}.get(units, units)
    return "" if units == "1" else f" {units}"


def outer_diameter(params: dict[str, Any], coords: dict[str, xr.DataArray]) -> Any:
    """The cable's outer diameter (m) on the axes it depends on: cable.diameter, or that of
    the solid round section of its area."""
    if params.get("diameter") is not None:
        return derived(params["diameter"], coords)
    return np.sqrt(4.0 * derived(params["area"], coords) / np.pi)


def strain_per_curvature(params: dict[str, Any], coords: dict[str, xr.DataArray]) -> Any:
    """The outer-fibre bending strain per unit of the kernels' curvature times l^2 (1/m):
    d / (2 l^2), as clamp_bending_strain is made from kernels.layout.CLAMP_BEND."""
    return 0.5 * outer_diameter(params, coords) / derived(params["length"], coords) ** 2


def load_outputs(params: dict[str, Any], reals: np.ndarray, multi_mode: bool,
                 dims: tuple[str, ...], shape: tuple[int, ...],
                 coords: dict[str, xr.DataArray], swept: bool = False,
                 one_mode: OneMode | None = None) -> dict[str, xr.DataArray]:
    """The rows of `OUTPUTS` a scene gets (`wanted`), from a transverse run's `reals` (n,
    kernels.layout.N_REALS): the load observers' columns with several modes, the tail
    amplitude and `one_mode` with one (`_one_mode_peaks`); `swept`: a sine sweep's, each peak
    over the whole sweep (one mode: from its peak over the run)."""
    def column(c: int) -> xr.DataArray:
        return xr.DataArray(reals[:, c].reshape(shape), dims=dims)
    if multi_mode:
        peaks = Peaks(column(tk.CLAMP_BEND), column(tk.MID_BEND), column(tk.STRETCH),
                      column(tk.CLAMP_SHEAR))
    else:
        peaks = _one_mode_peaks(params, column(tk.PEAK if swept else tk.AMPLITUDE), coords,
                                one_mode)
    p = params
    diameter = outer_diameter(p, coords)
    _, k_s = modal.stretching(p)
    span = Span(derived(p["length"], coords), derived(p["youngs_modulus"] * p["inertia"], coords),
                derived(p["youngs_modulus"] * p["area"], coords), diameter,
                None if k_s is None else derived(k_s, coords))
    clamped = (p.get("clamps_rotation") or "pinned") != "pinned"
    sheet_without_diameter = p.get("diameter") is None and p.get("linear_mass") is not None
    out = {}
    for o in OUTPUTS:
        if ((o.clamped and not clamped) or (o.tension and span.k_s is None)
                or (o.diameter and sheet_without_diameter)):
            continue
        value = xr.DataArray(o.value(peaks, span)).transpose(*dims)
        long_name = o.long_name.replace("over the tail window", "over the whole sweep") \
            if swept else o.long_name
        value.attrs = {"units": o.units, "long_name": long_name}
        out[o.name] = value
    return out
