"""Physical models: cable data and load -> coefficients of the kernel's modal oscillator.

    m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = 0

Every function here works element-wise on floats, NumPy arrays or xarray DataArrays, so the
derived quantities keep exactly the dimensions of the axes they depend on.

Two coefficient sets (docs/model.md sec. 2):
- "consistent": the Galerkin projection of the paper's Eq.17 on sin(pi x / l), re-derived;
  divided by rho A l / 2, so m = 1 and q is the midspan deflection in metres.
- "paper": Eq.32 exactly as printed (Table 1 cable baked in), including its errors: the
  parametric (cos) terms 10x too small, the frequency 1.86 n pi rad/s with the 1/l^4 of w0
  dropped, and a quintic of the wrong sign. `paper_parametric = "corrected"` multiplies the two
  cos terms back to their consistent size (37.5/1.86^2 and 18.7/1.86^2 from Eq.31). The printed
  terms are for P0 = 4 N; they are scaled by P0 / 4 N for other load amplitudes.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

# Eq.32 as printed (SI, P0 = 4 N).
PAPER_LOAD = 4.0                      # N, the load Eq.32 was printed for
PAPER_OMEGA0 = 1.86 * np.pi           # rad/s, "w0 = 1.86 pi / l^4" with the l^4 dropped
PAPER_COS_LINEAR = {"printed": 1.08, "corrected": 37.5 / 1.86 ** 2}   # x l^5
PAPER_COS_CUBIC = {"printed": 0.54, "corrected": 18.7 / 1.86 ** 2}    # x pi^2 l^3


def consistent(p: Mapping[str, Any]) -> dict[str, Any]:
    """Coefficients of the re-derived modal equation (docs/model.md sec. 2), m = 1.

    p: youngs_modulus (Pa), density (kg/m^3), area (m^2), inertia (m^4), length (m),
    membrane (alpha, 1), load_amplitude (N, compression > 0).
    Returns the load-independent part (k, g, h), the load-proportional parts (k_load,
    g_load), the unloaded natural angular frequency w1 (rad/s) and the buckling load (N).
    """
    k = np.pi / p["length"]
    ei = p["youngs_modulus"] * p["inertia"]
    rho_a = p["density"] * p["area"]
    w1_sq = ei / rho_a * k ** 4
    w1 = np.sqrt(w1_sq)
    load = p["load_amplitude"]
    return {
        "mass": 1.0,
        "k": w1_sq,
        "g": p["membrane"] * p["youngs_modulus"] / p["density"] * k ** 4
        - 1.25 * ei / rho_a * k ** 6,
        "h": -21.0 / 16.0 * ei / rho_a * k ** 8,
        "k_load": -load * k ** 2 / rho_a,
        "g_load": load * k ** 4 / (2.0 * rho_a),
        "omega_1": w1,
        "buckling_load": ei * k ** 2,
        "omega_ref": w1,
    }


def paper(p: Mapping[str, Any]) -> dict[str, Any]:
    """Coefficients of the paper's Eq.32 as printed (or with corrected cos terms).

    p: length (m), load_amplitude (N), paper_parametric ("printed" | "corrected").
    The buckling load is the one Eq.32's own coefficients imply: the load at which the
    parametric stiffness would cancel the linear stiffness.
    """
    l = p["length"]
    scale = p["load_amplitude"] / PAPER_LOAD
    k_static = 1.73 * np.pi ** 2 * l
    k_cos = PAPER_COS_LINEAR[p["paper_parametric"]] * l ** 5
    mass = 0.5 * l
    return {
        "mass": mass,
        "k": k_static,
        "g": 6.6e5 * np.pi ** 2 * l ** 3 - 2.1 * np.pi ** 4 / l,
        "h": 76.0 * np.pi ** 6 / l ** 3,
        "k_load": -k_cos * scale,
        "g_load": PAPER_COS_CUBIC[p["paper_parametric"]] * np.pi ** 2 * l ** 3 * scale,
        "omega_1": np.sqrt(k_static / mass),
        "buckling_load": PAPER_LOAD * k_static / k_cos,
        "omega_ref": PAPER_OMEGA0,
    }


# Largest mode slope pi q / l (rad) at which the one-mode cubic-quintic model still means
# something: its cubic and quintic terms are the first terms of series in the squared slope
# (the exact curvature w''/(1 + w'^2)^(3/2)) that diverge for slopes beyond 1 (docs/model.md
# sec. 2).
MAX_SLOPE = 1.0


def escape_barrier(k: Any, g: Any, h: Any, length: Any) -> Any:
    """Positive root q_b (m) of k + g q^2 + h q^4 = 0 for a softening quintic (h < 0, k > 0).

    Started at rest beyond q_b the span escapes (blows up in finite time). NaN where there is
    no such barrier (h >= 0 or k <= 0) and where the barrier lies outside the model's range:
    the mode's largest slope there, pi q_b / length (length in m), exceeds MAX_SLOPE (the
    Table 1 cable's 1 m span would otherwise report 55 m).
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        q2 = (-g - np.sqrt(g * g - 4.0 * h * k)) / (2.0 * h)
        q_b = np.sqrt(q2)
        valid = (h < 0) & (k > 0) & (np.pi * q_b / length <= MAX_SLOPE)
        if any(isinstance(v, xr.DataArray) for v in (k, g, h, length)):
            return xr.where(valid, q_b, np.nan)
        return np.where(valid, q_b, np.nan)[()]


def state_scale(q0: Any, v0: Any, omega: Any, bound: Any) -> tuple[Any, Any]:
    """The size of a point's response: (displacement scale L in m, velocity scale in m/s).

    L = max(|q0|, |v0| / omega) from the initial conditions q0 (m), v0 (m/s) and the span's
    natural angular frequency omega (rad/s); the velocity scale is omega L. The oscillator has
    no forcing, so a point started at rest at q = 0 stays there: it gets L = bound (m, the
    divergence bound), any positive scale would do. The solver's default absolute tolerances
    are a fixed fraction of rtol times these (sweep.run.settings_vector), so a response and
    the same response 1e5 times smaller are integrated alike.
    """
    scale = np.maximum(np.abs(q0), np.abs(v0) / omega)
    scale = xr.where(scale > 0, scale, bound) if isinstance(scale, xr.DataArray) \
        else np.where(scale > 0, scale, bound)[()]
    return scale, omega * scale


def oscillator(p: Mapping[str, Any]) -> dict[str, Any]:
    """Kernel coefficients and derived quantities for one model configuration.

    p holds the scene's parameters by axis name (scalars or arrays) plus "coefficients",
    "load_type" and "paper_parametric". Returns the oscillator coefficients under the names of
    `kernels.oscillator.PARAM_NAMES` (q_scale, v_scale: `state_scale`) and the derived
    quantities natural_frequency (Hz), buckling_load (N), load_ratio (1), escape_barrier (m,
    for the mean or constant load) and load_frequency (Hz, harmonic load only).
    """
    c = consistent(p) if p["coefficients"] == "consistent" else paper(p)
    out = {
        "mass": c["mass"],
        "damping": 2.0 * p["damping_ratio"] * c["mass"] * c["omega_1"],
        "h": c["h"],
        "q0": p["initial_displacement"],
        "v0": p["initial_velocity"],
        "bound": p["divergence_bound"] if p.get("divergence_bound") is not None
        else p["length"],
        "natural_frequency": c["omega_1"] / (2.0 * np.pi),
        "buckling_load": c["buckling_load"],
        "load_ratio": p["load_amplitude"] / c["buckling_load"],
    }
    if p["load_type"] == "harmonic":
        if p.get("frequency") is not None:
            omega = 2.0 * np.pi * p["frequency"]
        else:
            omega = p["frequency_ratio"] * c["omega_ref"]
        out.update(k0=c["k"], k1=c["k_load"], g0=c["g"], g1=c["g_load"], omega=omega,
                   load_frequency=omega / (2.0 * np.pi))
    else:
        out.update(k0=c["k"] + c["k_load"], k1=0.0, g0=c["g"] + c["g_load"], g1=0.0,
                   omega=0.0)
    out["escape_barrier"] = escape_barrier(out["k0"], out["g0"], out["h"], p["length"])
    out["q_scale"], out["v_scale"] = state_scale(out["q0"], out["v0"], c["omega_1"],
                                                 out["bound"])
    return out
