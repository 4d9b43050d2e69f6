"""Physical models: cable data and load -> coefficients of the kernel's modal oscillator.

    m q'' + c q' + (k0 + k1 cos W t) q + (g0 + g1 cos W t) q^3 + h q^5 = -m Gamma A sin(w_b t)

The right-hand side is base excitation of the clamps (docs/model.md sec. 5): both clamps move
transversely with acceleration A sin(w_b t), q is the deflection relative to them and Gamma =
4/pi the participation factor of sin(pi x / l) (of the span's own first mode where the clamps
are not pins, docs/model.md sec. 10); A = 0 without a [base] table.

Every function here works element-wise on floats, NumPy arrays or xarray DataArrays, so the
derived quantities keep exactly the dimensions of the axes they depend on.

Two coefficient sets (docs/model.md sec. 2):
- "consistent": the Galerkin projection on sin(pi x / l) (the span's own first mode where the
  clamps are not pins), divided by rho A l / 2, so m = 1 and q is the midspan deflection in
  metres; the bending terms from the span's energy, or the paper's Eq.17 re-derived where
  the scene gives the paper's local membrane term (`energy_bending`).
- "paper": Eq.32 exactly as printed (Table 1 cable baked in), including its errors: the
  parametric (cos) terms 10x too small, the frequency 1.86 n pi rad/s with the 1/l^4 of w0
  dropped, and a quintic of the wrong sign. `paper_parametric = "corrected"` multiplies the two
  cos terms back to their consistent size (37.5/1.86^2 and 18.7/1.86^2 from Eq.31). The printed
  terms are for P0 = 4 N; they are scaled by P0 / 4 N for other load amplitudes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping

import sys

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

from ..schema import STANDARD_GRAVITY
from . import excitation
from .excitation import EXCITATION_NAMES

# Eq.32 as printed (SI, P0 = 4 N).
PAPER_LOAD = 4.0                      # N, the load Eq.32 was printed for
PAPER_OMEGA0 = 1.86 * np.pi           # rad/s, "w0 = 1.86 pi / l^4" with the l^4 dropped
PAPER_COS_LINEAR = {"printed": 1.08, "corrected": 37.5 / 1.86 ** 2}   # x l^5
PAPER_COS_CUBIC = {"printed": 0.54, "corrected": 18.7 / 1.86 ** 2}    # x pi^2 l^3

PARTICIPATION = 4.0 / np.pi
"""Gamma (1), the participation factor of sin(pi x / l) under uniform base motion:
int phi dx / int phi^2 dx over the span (docs/model.md sec. 5)."""


def power(x: Any, n: int) -> Any:
    """x**n for a whole n >= 1 by repeated squaring: each element rounded the same way whatever
    the array's length or shape. NumPy's ``**`` on arrays may take a vectorised pow whose
    results differ by an ulp from the one-element path, so a grid point would differ from the
    same point run alone."""
    result = None
    square = x
    while True:
        if n & 1:
            result = square if result is None else result * square
        n >>= 1
        if not n:
            return result
        square = square * square


def consistent(p: Mapping[str, Any], ends: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Coefficients of the re-derived modal equation (docs/model.md sec. 2), m = 1.

    p: youngs_modulus (Pa), density (kg/m^3), area (m^2), inertia (m^4), length (m),
    membrane (alpha, 1; None: the uniform tension, `stretching`), load_amplitude (N,
    compression > 0), and the clamps (clamps_rotation, clamp_rotational_stiffness,
    clamp_axial_stiffness; pinned by default: these closed forms, else `_consistent_ends`);
    ends: `span_ends_of`(p) where the caller has it already.
    Returns the load-independent part (k, g, h), the load-proportional parts (k_load,
    g_load), the unloaded natural angular frequency w1 (rad/s) and the buckling load (N).
    """
    ends = span_ends_of(p) if ends is None else ends
    if ends is not None:
        return _consistent_ends(p, ends)
    k = np.pi / p["length"]
    ei = p["youngs_modulus"] * p["inertia"]
    rho_a = p["density"] * p["area"]
    w1_sq = ei / rho_a * power(k, 4)
    w1 = np.sqrt(w1_sq)
    load = p["load_amplitude"]
    alpha, k_s = stretching(p)
    membrane = (alpha * p["youngs_modulus"] / p["density"] * power(k, 4) if k_s is None
                else k_s * np.pi ** 4 / (4.0 * rho_a * power(p["length"], 3)))
    # the bending terms: the span's energy's 3/2 and 9/4, or Eq.17's 5/4 and -21/16
    cubic, quintic = (1.5, 2.25) if energy_bending(p) else (1.25, -21.0 / 16.0)
    return {
        "mass": 1.0,
        "k": w1_sq,
        "g": membrane - cubic * ei / rho_a * power(k, 6),
        "h": quintic * ei / rho_a * power(k, 8),
        "k_load": -load * k ** 2 / rho_a,
        "g_load": load * power(k, 4) / (2.0 * rho_a),
        "omega_1": w1,
        "buckling_load": ei * k ** 2,
        "omega_ref": w1,
    }


def buckling_load(p: Mapping[str, Any]) -> Any:
    """The span's buckling load Pcr (N; a number or an array over the points): the
    `buckling_load` of its coefficients (`consistent` for its ends, or Eq.32's own under the
    paper preset), which no end load changes."""
    unloaded = {**p, "load_amplitude": 0.0}
    if p["coefficients"] != "consistent":
        return paper(unloaded)["buckling_load"]
    return consistent(unloaded)["buckling_load"]


def load_from_ratio(p: dict[str, Any]) -> None:
    """In place: p's load_amplitude (N) from its load_ratio (P0/Pcr, load.amplitude_ratio)
    times the span's own `buckling_load`, where the scene gives the load so."""
    if p.get("load_ratio") is not None:
        p["load_amplitude"] = p["load_ratio"] * buckling_load(p)


def energy_bending(p: Mapping[str, Any]) -> bool:
    """Whether p's bending nonlinearity comes from the span's energy (docs/model.md sec. 7):
    the weak form of (EI / 2) int w_xx^2 (1 - 3 w_x^2 + 6 w_x^4) dx, the exact curvature's
    energy to quintic order, whose forces are its gradient (an undamped, unforced span keeps
    its energy). Where the scene reproduces the paper (coefficients = "paper", or its local
    membrane term model.membrane: Eq.17 projected as printed) the bending terms are Eq.17's
    instead, which with several modes are not the gradient of any energy."""
    return p.get("coefficients", "consistent") != "paper" and p.get("membrane") is None


def stretching(p: Mapping[str, Any]) -> tuple[Any, Any]:
    """How p's span stretches (docs/model.md sec. 10.4): (alpha, None), the paper's local
    membrane term 4 alpha EA w_xx w_x^2 where the scene gives model.membrane (p's membrane),
    or (0, k_s), the uniform tension N = k_s e of a span between axially restrained clamps,
    e = (1/2) int w_x^2 dx its elongation and 1 / k_s = l / EA + 2 / k_a (N/m; k_a = p's
    clamp_axial_stiffness, None: immovable clamps, k_s = EA / l; 0: the cable slides, no
    stretching)."""
    if p.get("membrane") is not None:
        return p["membrane"], None
    ea = p["youngs_modulus"] * p["area"]
    k_a = p.get("clamp_axial_stiffness")
    if k_a is None:
        return 0.0, ea / p["length"]
    return 0.0, ea * k_a / (k_a * p["length"] + 2.0 * ea)


def span_ends_of(p: Mapping[str, Any]) -> dict[str, Any] | None:
    """The ends of p's span as `_consistent_ends` takes them (sweep.models.basis.span_ends:
    mode 1's integrals and the buckling factor, over the points where K = k_t l / EI varies),
    or None for pinned ends (p's clamps_rotation, default pinned: the closed forms)."""
    rotation = p.get("clamps_rotation") or "pinned"
    if rotation == "pinned":
        return None
    from .basis import span_ends
    return span_ends(_end_stiffness(p))


def _end_stiffness(p: Mapping[str, Any]) -> Any:
    """K = k_t l / EI (1) of p's clamps (sweep.models.basis.end_stiffness: inf clamped)."""
    from .basis import end_stiffness
    return end_stiffness(p.get("clamps_rotation") or "pinned", p.get("clamp_rotational_stiffness"),
                         p["length"], p["youngs_modulus"] * p["inertia"])


def _consistent_ends(p: Mapping[str, Any], ends: Mapping[str, Any]) -> dict[str, Any]:
    """`consistent` for a span whose clamps are not pins (docs/model.md sec. 10): the same
    projection of Eq.17 on the span's own first mode phi(x / l), from its integrals `ends`
    (sweep.models.basis.one_mode_integrals, each a number or an array over the points, plus
    "buckling": Pcr l^2 / EI, basis.buckling_factor); q is the deflection at the mode's
    largest, its midspan; the bending terms from the span's energy or Eq.17's
    (`energy_bending`). Pinned sines' integrals give `consistent`'s closed forms."""
    l = p["length"]
    ei = p["youngs_modulus"] * p["inertia"]
    rho_a = p["density"] * p["area"]
    w1_sq = ei / rho_a * power(ends["beta"] / l, 4)
    load = p["load_amplitude"]
    stretch = ends["stretch"] / power(l, 4)
    alpha, k_s = stretching(p)
    membrane = (-4.0 * alpha * p["youngs_modulus"] / p["density"] * stretch if k_s is None
                else k_s * ends["load"] ** 2 * ends["mass"] / (2.0 * rho_a * power(l, 3)))
    cubic, quintic = ((ends["bend_cubic"], ends["bend_quintic"]) if energy_bending(p)
                      else (ends["curvature"], 10.5 * ends["quintic"]))
    return {
        "mass": 1.0,
        "k": w1_sq,
        "g": membrane - ei / rho_a * cubic / power(l, 6),
        "h": ei / rho_a * quintic / power(l, 8),
        "k_load": load * ends["load"] / (rho_a * l * l),
        "g_load": -2.0 * load / rho_a * stretch,
        "omega_1": np.sqrt(w1_sq),
        "buckling_load": ei * ends["buckling"] / (l * l),
        "omega_ref": np.sqrt(w1_sq),
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
    k_cos = PAPER_COS_LINEAR[p["paper_parametric"]] * power(l, 5)
    mass = 0.5 * l
    return {
        "mass": mass,
        "k": k_static,
        "g": 6.6e5 * np.pi ** 2 * power(l, 3) - 2.1 * np.pi ** 4 / l,
        "h": 76.0 * np.pi ** 6 / power(l, 3),
        "k_load": -k_cos * scale,
        "g_load": PAPER_COS_CUBIC[p["paper_parametric"]] * np.pi ** 2 * power(l, 3) * scale,
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
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        q2 = (-g - np.sqrt(g * g - 4.0 * h * k)) / (2.0 * h)
        q_b = np.sqrt(q2)
        valid = (h < 0) & (k > 0) & (np.pi * q_b / length <= MAX_SLOPE)
        if any(_is_dataarray(v) for v in (k, g, h, length)):
            return sys.modules["xarray"].where(valid, q_b, np.nan)
        return np.where(valid, q_b, np.nan)[()]


def state_scale(q0: Any, v0: Any, omega: Any, bound: Any, forcing: Any = 0.0,
                base_omega: Any = 0.0) -> tuple[Any, Any]:
    """The size of a point's response: (displacement scale L in m, velocity scale in m/s).

    L = max(|q0|, |v0| / omega, |forcing| / max(omega^2, base_omega^2)) from the initial
    conditions q0 (m), v0 (m/s), the span's natural angular frequency omega (rad/s) and the
    base forcing Gamma A (m/s^2) at base_omega (rad/s): the last is the quasi-static (below
    resonance) or mass-line (above) response of the linear span. The velocity scale is
    omega L. Without forcing a point started at rest at q = 0 stays there: it gets L = bound
    (m, the divergence bound), any positive scale would do. The solver's default absolute
    tolerances are a fixed fraction of rtol times these (sweep.run.settings_vector), so a
    response and the same response 1e5 times smaller are integrated alike.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        driven = np.abs(forcing) / np.maximum(omega * omega, base_omega * base_omega)
    scale = np.maximum(np.maximum(np.abs(q0), np.abs(v0) / omega), driven)
    scale = sys.modules["xarray"].where(scale > 0, scale, bound) if _is_dataarray(scale) \
        else np.where(scale > 0, scale, bound)[()]
    return scale, omega * scale


def oscillator(p: Mapping[str, Any]) -> dict[str, Any]:
    """Kernel coefficients and derived quantities for one model configuration.

    p holds the scene's parameters by axis name (scalars or arrays) plus "coefficients",
    "load_type" and "paper_parametric". Returns the oscillator coefficients under the names of
    `kernels.oscillator.PARAM_NAMES` (q_scale, v_scale: `state_scale`) and the derived
    quantities natural_frequency (Hz), buckling_load (N), load_ratio (1), escape_barrier (m,
    for the mean or constant load) and load_frequency (Hz, harmonic load only).

    Base excitation (p's base_acceleration (m/s^2) or base_acceleration_g (g), and
    base_frequency (Hz) or base_frequency_ratio (f/f1, f1 of the unloaded span); all None
    without a [base] table): the columns base_accel = A (m/s^2), base_omega = 2 pi f (rad/s),
    participation = 4/pi, zeros without base; and `base_response`'s derived quantities.
    """
    ends = span_ends_of(p) if p["coefficients"] == "consistent" else None
    c = consistent(p, ends) if p["coefficients"] == "consistent" else paper(p)
    # the clamps' K = k_t l / EI where they are not pins (sweep/models/stability.py's modes)
    stiffness = {} if ends is None else {"end_stiffness": _end_stiffness(p)}
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
        **stiffness,
    }
    if p.get("load_ratio") is not None:  # given as a ratio: the load in N beside it
        out["load_amplitude"] = p["load_amplitude"]
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
    out["escape_barrier"] = escape_barrier(
        out["k0"], out["g0"], out["h"], p["length"] if ends is None
        else p["length"] * np.pi / ends["slope"])
    base = base_excitation(p, c["omega_1"])
    if ends is not None:
        base["participation"] = base["participation"] * ends["gamma"] / PARTICIPATION
    out.update(base)                     # its base_phase 0: a stepped sweep carries the phases
    out["load_phase"] = 0.0              # (continuation.py)
    swept = p.get("base_sweep_start") is not None
    level, omega_b = base["base_accel"], base["base_omega"]
    random = p.get("base_asd") is not None
    if random:                  # the scales of three times the record's RMS, quasi-static
        f, w = p["base_asd"]
        from .random import mean_square
        level, omega_b = 3.0 * base["base_accel"] * np.sqrt(mean_square(f, w)), c["omega_1"]
    elif np.any(base["participation"] != 0.0) and not swept:
        out.update(base_response(level, omega_b, c["omega_1"], p["damping_ratio"]))
    if swept:                     # the scales of the sweep's largest level, lowest frequency
        start, stop, rate = p["base_sweep_start"], p["base_sweep_stop"], p["base_sweep_rate"]
        out["sweep_duration"] = excitation.sweep_duration(start, stop, rate)
        levels = p.get("base_levels_g")
        if levels is not None:
            level = max(b[1] for b in levels) * STANDARD_GRAVITY
        omega_b = 2.0 * np.pi * np.minimum(start, stop)
    out["scale_forcing"] = base["participation"] * level     # (m/s^2, rad/s): state_scale's
    out["scale_omega"] = omega_b
    out["q_scale"], out["v_scale"] = state_scale(
        out["q0"], out["v0"], c["omega_1"], out["bound"], out["scale_forcing"], omega_b)
    return out


def base_excitation(p: Mapping[str, Any], omega_1: Any) -> dict[str, Any]:
    """The kernel's base-excitation columns from p's base keys (by axis name, None if absent):
    participation Gamma = 4/pi and kernels.excitation's block (`excitation.block`).

    Level: base_acceleration (m/s^2), base_acceleration_g times STANDARD_GRAVITY, or the table
    base_levels_g ((Hz, g) breakpoints, log-log). Frequency: base_frequency (Hz),
    base_frequency_ratio times omega_1 (rad/s, the unloaded span's w1), or a logarithmic sweep
    base_sweep_start -> base_sweep_stop (Hz) at base_sweep_rate (octaves per minute), which
    ends after its duration (`excitation.sweep_duration`). Every column 0 when p has no base
    level (no [base] table)."""
    levels = p.get("base_levels_g")
    if p.get("base_asd") is not None:     # the record kind: level factor, sample rate, record
        from .random_scene import runs_after_startup, transient_time
        block = excitation.block(random_level(p), p["base_sample_rate"])
        block["base_phase"] = p["realisation"]
        # the row's statistics start after its own start-up transient; a row whose start-up
        # outlasts the run has none: NaN, which the kernels flag invalid_input
        start = transient_time(omega_1, p["damping_ratio"], p["statistics_tolerance"],
                               p["base_ramp"])
        keep = runs_after_startup(start, p["record_t_end"])
        block["sweep_end"] = (start.where(keep) if _is_dataarray(start)
                              else np.where(keep, start, np.nan)[()])
        block["level_ramp"] = p["base_ramp"]    # the records' level rise (s; 0: none)
        return {"participation": PARTICIPATION, **block}
    if p.get("base_acceleration") is None and p.get("base_acceleration_g") is None \
            and levels is None:
        return {"participation": 0.0, **excitation.block(0.0, 0.0)}
    start = p.get("base_sweep_start")
    if start is not None:
        stop, rate = p["base_sweep_stop"], p["base_sweep_rate"]
        omega = 2.0 * np.pi * start
        lam = excitation.sweep_rate(start, stop, rate)
        end = excitation.sweep_duration(start, stop, rate)
        accel = 0.0 if levels is not None else _level(p)
        cycles = p.get("base_sweep_ramp_cycles")
        ramp = excitation.ramp_time(start, excitation.DEFAULT_RAMP_CYCLES if cycles is None
                                    else cycles)
        return {"participation": PARTICIPATION,
                **excitation.block(accel, omega, lam, end, levels, ramp)}
    if p.get("base_frequency") is not None:
        omega = 2.0 * np.pi * p["base_frequency"]
    else:
        omega = p["base_frequency_ratio"] * omega_1
    accel = (excitation.table_level(levels, omega / (2.0 * np.pi)) if levels is not None
             else _level(p))
    return {"participation": PARTICIPATION, **excitation.block(accel, omega)}


def random_level(p: Mapping[str, Any]) -> Any:
    """The level factor (1) on a random scene's records: 10^(dB / 20) of base_asd_scale (dB
    on the ASD, so its square root on the acceleration)."""
    return 10.0 ** (p["base_asd_scale"] / 20.0)


def _level(p: Mapping[str, Any]) -> Any:
    """A constant base level (m/s^2) from base_acceleration or base_acceleration_g (g)."""
    if p.get("base_acceleration") is not None:
        return p["base_acceleration"]
    return p["base_acceleration_g"] * STANDARD_GRAVITY


def base_response(accel: Any, omega: Any, omega_1: Any, damping_ratio: Any) -> dict[str, Any]:
    """Derived quantities of base excitation A sin(w t) (docs/model.md sec. 5), element-wise.

    accel: A (m/s^2); omega: w (rad/s); omega_1: the unloaded w1 (rad/s); damping_ratio: zeta.
    Returns base_acceleration (m/s^2), base_acceleration_g (g), base_frequency (Hz),
    base_frequency_ratio (f/f1) and resonance_amplification (1): Q = 1/(2 zeta), the linear
    span's peak over its quasi-static Gamma A / w1^2 (NaN undamped). The linear span's own
    steady amplitude, over the scene's modes, is sweep/models/linear.py's `linear_amplitude`.
    """
    with np.errstate(divide="ignore"):
        q_factor = 0.5 / (np.float64(damping_ratio) if isinstance(damping_ratio, (int, float))
                          else damping_ratio)
    return {
        "base_acceleration": accel,
        "base_acceleration_g": accel / STANDARD_GRAVITY,
        "base_frequency": omega / (2.0 * np.pi),
        "base_frequency_ratio": omega / omega_1,
        "resonance_amplification": _finite_or_nan(q_factor),
    }


def _finite_or_nan(value: Any) -> Any:
    """value with its infinities (and NaNs) as NaN: a float, array or DataArray."""
    if _is_dataarray(value):
        return value.where(np.isfinite(value))
    return np.where(np.isfinite(value), value, np.nan)[()]


def modes_columns(p: Mapping[str, Any], one_mode: Mapping[str, Any], n_modes: int,
                  q0: Any, v0: Any) -> dict[str, Any]:
    """The multi-mode kernel's raw columns (kernels.modes: FIXED_NAMES, then q0_1..q0_N and
    v0_1..v0_N) of the consistent model with n_modes modes (docs/model.md sec. 7).

    p: the scene's parameters by axis name, as `oscillator` takes them; one_mode: `oscillator`(p)
    (its load frequency, bound and base columns are shared by every mode); q0, v0: sequences of
    n_modes initial modal deflections (m) and velocities (m/s), each a scalar or an array over
    the points. The state scales are `state_scale`'s with the largest initial deflection and
    velocity of any mode.
    """
    k = np.pi / p["length"]
    rho_a = p["density"] * p["area"]
    w1_sq = p["youngs_modulus"] * p["inertia"] / rho_a * power(k, 4)
    w1 = np.sqrt(w1_sq)
    load = p["load_amplitude"] * k ** 2 / rho_a
    alpha, k_s = stretching(p)
    harmonic = p["load_type"] == "harmonic"
    out = {
        "w1_sq": w1_sq,
        "damping": 2.0 * p["damping_ratio"] * w1,
        "load_mean": 0.0 if harmonic else load,
        "load_cos": load if harmonic else 0.0,
        "membrane": 4.0 * alpha * p["youngs_modulus"] / p["density"] * power(k, 4),
        "tension": 0.0 if k_s is None else k_s * power(k, 4) * p["length"] / (2.0 * rho_a),
        "bending": 1.0 if energy_bending(p) else 0.0,
        "k_sq": k ** 2,
        "omega": one_mode["omega"],
        "bound": one_mode["bound"],
        # the kernel's reference: 4/pi, times each mode's basis ratio Gamma_n / (4/pi)
        "participation": np.where(np.asarray(one_mode["participation"]) != 0.0,
                                  PARTICIPATION, 0.0)[()],
        "load_phase": 0.0,
        **{name: one_mode[name] for name in EXCITATION_NAMES},
    }
    q_max = np.max(np.abs(np.broadcast_arrays(*[np.asarray(q, float) for q in q0])), axis=0)
    v_max = np.max(np.abs(np.broadcast_arrays(*[np.asarray(v, float) for v in v0])), axis=0)
    out["q_scale"], out["v_scale"] = state_scale(
        q_max, v_max, w1, out["bound"], one_mode["scale_forcing"], one_mode["scale_omega"])
    for n in range(n_modes):
        out[f"q0_{n + 1}"] = q0[n]
        out[f"v0_{n + 1}"] = v0[n]
    return out


def _is_dataarray(value: Any) -> bool:
    """Whether `value` is an xarray.DataArray, without importing xarray (the scene rules use
    these functions on plain floats; a DataArray exists only once xarray is imported)."""
    xr = sys.modules.get("xarray")
    return xr is not None and isinstance(value, xr.DataArray)


def modal_frequencies(natural_frequency: Any, ratios: np.ndarray) -> xr.DataArray:
    """ratios[n - 1] f1 (Hz) for n = 1..N on a dimension `mode`: the linear natural frequencies
    of the unloaded span's modes, ratios being a basis' w_n / w_p (pinned sines: n^2,
    sweep/models/basis.py) and natural_frequency the pinned span's f1 (Hz, a float or a
    DataArray over some axes)."""
    import xarray as xr
    ratio = xr.DataArray(np.asarray(ratios, float), dims="mode")
    return (ratio * natural_frequency).astype(float)
