"""The scene-file schema: every key a scene may hold, its type, default, bounds and units.

This table is data. `sweep.scene` validates a parsed TOML document against it; the
dataset builder takes units and long names from it. Add a key here first.

Kinds of value:
    "float"   a finite real number (a TOML integer is accepted and converted)
    "int"     an integer
    "bool"    true or false
    "str"     a string; `choices` lists the allowed values
    "floats"  a list of finite real numbers (may be empty), each within the bounds
    "pairs"   a list of [x, y] pairs of finite positive numbers, x strictly increasing
              (a table of breakpoints: ``base.levels_g``)
A float key with ``sweepable=True`` may also appear under ``[axes]``, by its axis name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .wires import WIRE_NAMES

STANDARD_GRAVITY = 9.80665
"""g (m s-2), the standard acceleration of gravity: what a level in g (``base.acceleration_g``,
the ``absolute_acceleration_g`` output) is a multiple of. The one place this number is written."""
G_UNITS = f"{STANDARD_GRAVITY:g} m s-2"
"""UDUNITS units of a value given in g: "9.80665 m s-2" (a scaled unit that converts to m s-2
in any UDUNITS tool; "g" would mean grams, "1" dimensionless)."""
G2_UNITS = f"{STANDARD_GRAVITY ** 2:.10g} m2 s-4 Hz-1"
"""UDUNITS units of a spectral density given in g^2/Hz (base.asd_g2)."""


@dataclass(frozen=True)
class Key:
    """One scene key.

    section, name: where it lives (``[section] name = ...``).
    kind: "float" | "int" | "bool" | "str".
    default: value used when the key is absent; None means "no default" (optional key).
    units: SI units of the value ("1" for dimensionless, "" for non-numeric).
    long_name: a human description, used as the netCDF ``long_name``.
    minimum, maximum: inclusive bounds unless ``exclusive_min`` / ``exclusive_max``.
    choices: allowed strings for kind "str".
    axis: the axis (and coordinate) name when the key is sweepable, else None.
    help: what `sweep keys` says of it, where that is more than the long name.
    """

    section: str
    name: str
    kind: str
    default: Any
    units: str = ""
    long_name: str = ""
    minimum: float | None = None
    maximum: float | None = None
    exclusive_min: bool = False
    exclusive_max: bool = False
    choices: tuple[str, ...] = field(default_factory=tuple)
    axis: str | None = None
    help: str = ""

    @property
    def dotted(self) -> str:
        return f"{self.section}.{self.name}"


KEYS: tuple[Key, ...] = (
    # [model]
    Key("model", "kind", "str", "transverse", choices=("transverse", "longitudinal"),
        long_name="which vibration problem is solved"),
    Key("model", "coefficients", "str", "consistent", choices=("consistent", "paper"),
        long_name="transverse modal coefficients: re-derived (consistent) or Eq.32 as printed (paper)"),
    Key("model", "membrane", "float", None, units="1", minimum=0.0,
        long_name="the paper's local membrane stretching 4 alpha EA w_xx w_x^2: its alpha (3/8 "
                  "as Eq.17 implies); absent: the uniform tension between the clamps "
                  "(clamps.axial_stiffness)", axis="membrane",
        help="the paper's local membrane stretching 4 alpha EA w_xx w_x^2, alpha = 3/8 as its "
        "Eq.17 implies (the built-in scenes give it); absent: the span stretches as a whole, "
        "the uniform tension N = k_s e between axially restrained clamps (clamps."
        "axial_stiffness; docs/model.md sec. 10)"),
    Key("model", "paper_parametric", "str", "printed", choices=("printed", "corrected"),
        long_name="paper preset: Eq.32's parametric (cos) terms as printed or 10x-corrected"),
    Key("model", "modes", "int", 1, units="1", minimum=1, maximum=12,
        long_name="transverse: Galerkin modes kept, the span's own n = 1..modes (sin(n pi x/l) "
                  "between pins, beam functions between clamps), coupled by the nonlinear terms "
                  "(1: the paper's one-mode model)"),
    # [clamps]: what each clamp holds of the span (docs/model.md sec. 10)
    Key("clamps", "rotation", "str", "pinned", choices=("pinned", "clamped", "elastic"),
        long_name="what each clamp holds of the span's rotation: nothing (pinned, modes "
                  "sin(n pi x/l)), all of it (clamped) or a rotational spring (elastic, "
                  "clamps.rotational_stiffness)"),
    Key("clamps", "rotational_stiffness", "float", None, units="N m rad-1", minimum=0.0,
        long_name="rotational stiffness k_t of each clamp (rotation = 'elastic'), K = k_t l / EI: "
                  "0 pinned, inf clamped",
        axis="clamp_rotational_stiffness"),
    Key("clamps", "axial_stiffness", "float", None, units="N m-1", minimum=0.0,
        long_name="axial stiffness k_a of each clamp, in series with the span's EA / l for the "
                  "stretching tension (default: immovable clamps; 0: the cable slides through "
                  "them and does not stretch)", axis="clamp_axial_stiffness"),
    # [cable]
    Key("cable", "youngs_modulus", "float", 1.1e11, units="Pa", minimum=0.0, exclusive_min=True,
        long_name="Young's modulus", axis="youngs_modulus"),
    Key("cable", "density", "float", 8900.0, units="kg m-3", minimum=0.0, exclusive_min=True,
        long_name="density", axis="density"),
    Key("cable", "area", "float", 6e-6, units="m2", minimum=0.0, exclusive_min=True,
        long_name="cross-sectional area", axis="area"),
    # No fixed default: sweep.models.rules.default_inertia gives A^2/(4 pi) from the area.
    Key("cable", "inertia", "float", None, units="m4", minimum=0.0, exclusive_min=True,
        long_name="bending second moment of area, EI/E (default A^2/(4 pi), a solid round "
                  "section; a stranded cable's is smaller: give a measured EI/E)", axis="inertia"),
    Key("cable", "diameter", "float", None, units="m", minimum=0.0, exclusive_min=True,
        long_name="outer diameter d: the outer fibre lies d/2 from the neutral axis (the bending "
                  "strain at the clamp); default that of the solid round section, "
                  "sqrt(4 A / pi)", axis="diameter"),
    # data-sheet alternatives to the material keys above (sweep/models/cable.py; either set)
    Key("cable", "linear_mass", "float", None, units="kg m-1", minimum=0.0, exclusive_min=True,
        long_name="mass per unit length m = rho A of the cable or bundle, as its data sheet "
                  "gives it (instead of density and area)", axis="linear_mass"),
    Key("cable", "bending_rigidity", "float", None, units="N m2", minimum=0.0,
        exclusive_min=True, long_name="bending stiffness EI (instead of youngs_modulus and "
                                      "inertia)", axis="bending_rigidity"),
    Key("cable", "axial_rigidity", "float", None, units="N", minimum=0.0, exclusive_min=True,
        long_name="axial stiffness EA of the cable's section, for its stretching (not the "
                  "clamps' axial_stiffness, N/m)", axis="axial_rigidity"),
    Key("cable", "f1_measured", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="first natural frequency measured on a span of f1_span between the scene's "
                  "clamps: gives EI (docs/model.md sec. 10) instead of bending_rigidity"),
    Key("cable", "f1_span", "float", None, units="m", minimum=0.0, exclusive_min=True,
        long_name="length of the span whose f1_measured was measured"),
    Key("cable", "wire", "str", None, choices=WIRE_NAMES,
        long_name="a wire of the table in sweep/wires.py: its mass, diameter, EA and EI "
                  "bounds, for a bundle of cable.wires of them"),
    Key("cable", "wires", "int", None, units="1", minimum=1, maximum=1000,
        long_name="number of identical cable.wire wires in the bundle (default 1)"),
    Key("cable", "bending", "str", None, choices=("lower", "upper"),
        long_name="which bound of a cable.wire bundle's EI: lower (strands slipping, n EI of "
                  "the wires' strands) or upper (the solid section); a measured f1 beats both"),
    Key("cable", "damping_ratio", "float", 0.0, units="1", minimum=0.0,
        long_name="modal viscous damping ratio", axis="damping_ratio"),
    Key("cable", "length", "float", 1.0, units="m", minimum=0.0, exclusive_min=True,
        long_name="span length between constraints", axis="length"),
    # [load]
    Key("load", "type", "str", "harmonic", choices=("harmonic", "constant"),
        long_name="end load: harmonic P0 cos(W t) or constant P0 from t = 0"),
    Key("load", "amplitude", "float", 0.0, units="N",
        long_name="end load amplitude P0 (positive = compression)", axis="load_amplitude",
        help="end load amplitude P0 (positive = compression); default 0: no end load unless "
        "the scene gives one (the paper scenes give 4 N)"),
    Key("load", "amplitude_ratio", "float", None, units="1",
        long_name="end load amplitude over the span's buckling load, P0/Pcr (Pcr of its own "
                  "ends, buckling_load)", axis="load_ratio",
        help="end load amplitude P0 as a multiple of the span's own buckling load (Pcr: EI "
        "(pi/l)^2 pinned, 4 pi^2 EI/l^2 clamped, between them for elastic clamps), so that a "
        "stability chart or a parametric map reads the same for any span and clamps; instead "
        "of load.amplitude (N), which the result then holds per point; negative: a tension, "
        "as a negative load.amplitude"),
    Key("load", "frequency_ratio", "float", None, units="1", minimum=0.0,
        long_name="load frequency over the span's first natural frequency, W/w1",
        axis="frequency_ratio",
        help="load frequency over the span's first natural frequency, W/w1; 1.0 (W = w1) "
        "where the scene gives neither load.frequency nor this key: give one for a harmonic "
        "load (the principal parametric resonance is at 2)"),
    Key("load", "frequency", "float", None, units="Hz", minimum=0.0,
        long_name="load frequency W/(2 pi)", axis="frequency"),
    # [base]: both clamps move transversely, a_b(t) = A sin(2 pi f t) (docs/model.md sec. 5)
    Key("base", "acceleration", "float", None, units="m s-2", minimum=0.0,
        long_name="base (clamp) acceleration amplitude A, peak",
        axis="base_acceleration"),
    Key("base", "acceleration_g", "float", None, units=G_UNITS, minimum=0.0,
        long_name=f"base (clamp) acceleration amplitude A, peak, in g ({STANDARD_GRAVITY:g} "
                  "m s-2)", axis="base_acceleration_g"),
    Key("base", "frequency", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="base excitation frequency f", axis="base_frequency"),
    Key("base", "frequency_ratio", "float", None, units="1", minimum=0.0, exclusive_min=True,
        long_name="base excitation frequency over the unloaded span's first natural frequency, "
                  "f/f1", axis="base_frequency_ratio"),
    # a logarithmic sine sweep instead of a frequency: [base] sweep = {start, stop, rate}
    Key("base", "sweep.start", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="logarithmic sine sweep: start frequency", axis="base_sweep_start"),
    Key("base", "sweep.stop", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="logarithmic sine sweep: stop frequency (below start: a down sweep)",
        axis="base_sweep_stop"),
    Key("base", "sweep.rate", "float", None, units="min-1", minimum=0.0, exclusive_min=True,
        long_name="logarithmic sine sweep: rate in octaves per minute", axis="base_sweep_rate"),
    Key("base", "sweep.ramp_cycles", "float", None, units="1", minimum=0.0,
        long_name="logarithmic sine sweep: cycles of the start frequency over which the level "
                  "rises from 0 (default 10; 0: full level from t = 0)"),
    Key("base", "sweep.direction", "str", None, choices=("up", "down", "both"),
        long_name="logarithmic sine sweep: from the lower of start and stop to the upper (up), "
                  "back (down) or both (a direction dimension); default: from start to stop"),
    Key("base", "levels_g", "pairs", None, units=G_UNITS,
        long_name="base level table instead of a constant level: (frequency in Hz, peak level "
                  "in g) breakpoints, interpolated log-log"),
    # a random base acceleration instead of a sine: [base] asd_g2 = [[Hz, g^2/Hz], ...]
    # (docs/model.md sec. 11; sweep/models/random.py)
    Key("base", "asd_g2", "pairs", None, units=G2_UNITS,
        long_name="random base acceleration: one-sided acceleration spectral density as "
                  "(frequency in Hz, level in g^2/Hz) breakpoints, interpolated log-log, zero "
                  "outside them"),
    Key("base", "asd", "pairs", None, units="m2 s-4 Hz-1",
        long_name="random base acceleration: one-sided acceleration spectral density as "
                  "(frequency in Hz, level in (m/s^2)^2/Hz) breakpoints, interpolated log-log"),
    Key("base", "asd_scale", "float", None, units="1", minimum=-60.0, maximum=60.0,
        long_name="random base acceleration: level relative to the spectrum given, in dB on "
                  "the ASD (10 log10 of its factor; -3: acceptance from qualification; "
                  "default 0)",
        axis="base_asd_scale"),
    Key("base", "duration", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="random base acceleration: length of each record (the run's end time)"),
    Key("base", "realisations", "int", None, units="1", minimum=1, maximum=100_000,
        long_name="random base acceleration: independent records, the same for every grid "
                  "point (a realisation dimension; default 1)"),
    Key("base", "seed", "int", None, units="1", minimum=0,
        long_name="random base acceleration: seed of the records (the same seed, the same "
                  "records, bit for bit; default 0)"),
    Key("base", "sample_rate", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="random base acceleration: the records' sample rate (default 10 x the "
                  "spectrum's top frequency)"),
    Key("base", "rms_accuracy", "float", None, units="1", minimum=0.0, exclusive_min=True,
        maximum=1.0,
        long_name="random base acceleration: the accuracy asked of the RMS deflection's mean "
                  "over the realisations, the relative half-width of its 95 % confidence "
                  "interval (0.02: +-2 %); a scene whose realisations cannot reach it at some "
                  "point is refused, with the count that does"),
    Key("base", "ramp", "float", None, units="s", minimum=0.0,
        long_name="random base acceleration: the records' level rises from 0 over this time, "
                  "(1 - cos(pi t / ramp)) / 2, as a shaker brings its level up; each point's "
                  "statistics start that much later (default 0: full level from t = 0, "
                  "which kicks a span whose first mode lies below the spectrum's band)"),
    Key("base", "test_duration", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="random base acceleration: the test's duration for the expected number of "
                  "exceedances of outputs.clearance (default base.duration; GEVS: 120 s an "
                  "axis)"),
    # [initial]
    Key("initial", "displacement", "float", 0.0, units="m",
        long_name="initial midspan deflection q(0)", axis="initial_displacement"),
    Key("initial", "velocity", "float", 0.0, units="m s-1",
        long_name="initial midspan velocity q'(0)", axis="initial_velocity"),
    Key("initial", "modal_displacement", "floats", None, units="m",
        long_name="initial modal deflections q_1(0), ..., q_N(0), one per mode (N = "
                  "model.modes); replaces initial.displacement, mode 1's alone"),
    Key("initial", "modal_velocity", "floats", None, units="m s-1",
        long_name="initial modal velocities q_1'(0), ..., q_N'(0), one per mode; replaces "
                  "initial.velocity, mode 1's alone"),
    # [solver]
    Key("solver", "rtol", "float", 1e-8, units="1", minimum=1e-14, maximum=0.1,
        long_name="relative tolerance"),
    Key("solver", "atol", "float", None, units="m", minimum=0.0, exclusive_min=True,
        maximum=1.0, long_name="absolute tolerance (m for q, m/s for q'); default: each "
                               "point's own, 0.01 x rtol x max(|q0|, |v0|/w1, (4/pi) A / "
                               "max(w1^2, w_b^2)) (w1 x that for q'; A, w_b: the [base] "
                               "excitation), so results do not depend on the response's size"),
    Key("solver", "t_end", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="end of the simulated time (default: 5 s transverse, 8 transits longitudinal)"),
    Key("solver", "transits", "float", None, units="1", minimum=0.0, exclusive_min=True,
        long_name="longitudinal: end time in wave transits l/a, instead of t_end"),
    Key("solver", "intervals", "int", 1000, units="1", minimum=2,
        long_name="longitudinal: spatial intervals per span"),
    Key("solver", "courant", "float", 1.0, units="1", minimum=0.0, exclusive_min=True,
        maximum=1.0, long_name="longitudinal: Courant number a dt/dx (exact at 1, unstable above)"),
    Key("solver", "driver", "str", "lanes", choices=("lanes", "scalar"),
        long_name="transverse kernel driver: lock-step SIMD lanes (fast) or one trajectory per "
                  "thread (SciPy's arithmetic exactly, the reference); default lanes, but scalar "
                  "for a sine sweep of several modes, for several modes where fewer than 4 points share one lanes "
                  "call (a single span; elastic clamps of 5 or more modes whose K differs at "
                  "every point: up to 4 modes every span's own modes share one call), and for a "
                  "random scene where fewer than 4 points x records share one (2 with one mode)"),
    Key("solver", "method", "str", "rk45", choices=("rk45", "dop853"),
        long_name="transverse integrator: Dormand-Prince 5(4) step for step as SciPy's RK45, or "
                  "8(5,3) step for step as SciPy's DOP853 (longer steps; faster at equal error); "
                  "default rk45 with one mode, dop853 with model.modes >= 2 or a spectrum"),
    Key("solver", "controller", "str", "scipy", choices=("scipy", "pi"),
        long_name="transverse step-size controller: SciPy RK45's (step for step as solve_ivp) "
                  "or PI (Gustafsson; fewer rejected steps)"),
    Key("solver", "max_steps", "int", 1_000_000, units="1", minimum=1,
        long_name="bound on accepted steps per point"),
    Key("solver", "max_step", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="largest step allowed (default: unbounded)"),
    Key("solver", "min_step", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="smallest step allowed before a point fails (default: SciPy's 10 ulps of t)"),
    Key("solver", "first_step", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="first step (default: SciPy's initial-step selection)"),
    Key("solver", "stop_when_steady", "bool", False,
        long_name="end a point early once its response is steady or has decayed: at a maximum "
                  "where the last steady_periods + 1 maxima and minima lie within "
                  "steady_tolerance x the amplitude of their last level, drift still to come "
                  "included; the tail window then becomes the steady_periods periods after "
                  "it (stop_time says when each point ended)"),
    Key("solver", "steady_periods", "int", 10, units="1", minimum=2, maximum=1000,
        long_name="with stop_when_steady: the periods the steadiness test spans and the moved "
                  "tail window holds"),
    Key("solver", "steady_tolerance", "float", 1e-4, units="1", minimum=0.0,
        exclusive_min=True, maximum=0.01,
        long_name="with stop_when_steady: the test's tolerance on the extrema, relative to the "
                  "amplitude (a decayed point: to the peak)"),
    # [metrics]
    Key("metrics", "tail", "float", 0.5, units="1", minimum=0.0, exclusive_min=True,
        maximum=1.0, long_name="tail window as a fraction of t_end"),
    Key("metrics", "tolerance", "float", 0.02, units="1", minimum=0.0, exclusive_min=True,
        maximum=0.5, long_name="settling band and decay threshold, relative"),
    Key("metrics", "divergence_bound", "float", None, units="m", minimum=0.0,
        exclusive_min=True, long_name="|q| beyond which a point is diverged (default: the span length)"),
    # [outputs]
    Key("outputs", "amplitude", "bool", True,
        long_name="store the tail amplitude (the midspan's max |q| over the tail window) and the "
                  "tail-window peaks that go with it: modal_amplitude, max_deflection and its "
                  "position, and the clamp and stretching loads and strains (false: none of "
                  "them)"),
    Key("outputs", "peak_amplitude", "bool", True,
        long_name="store the global max |q| (a sine sweep's: with the whole sweep's peaks that "
                  "go with it, as outputs.amplitude's with a fixed frequency)"),
    Key("outputs", "settling_time", "bool", True, long_name="compute and store the settling time"),
    Key("outputs", "response_period", "bool", True, long_name="store the response period"),
    Key("outputs", "solver_stats", "bool", True, long_name="store step and evaluation counts"),
    Key("outputs", "absolute_acceleration", "bool", True,
        long_name="scenes with [base]: store the absolute midspan acceleration amplitude (m s-2 "
                  "and g) and the transmissibility"),
    Key("outputs", "peak_frequency", "bool", True,
        long_name="swept base frequency: store the excitation frequency at the peak response"),
    Key("outputs", "envelope", "bool", False,
        long_name="swept base frequency: store the response envelope, the largest |q| at the "
                  "extrema of q in each 1/N-octave band of the excitation frequency"),
    Key("outputs", "bands_per_octave", "int", 3, units="1", minimum=1, maximum=24,
        long_name="swept base frequency: N of the envelope's 1/N-octave bands (3: third "
                  "octaves)"),
    Key("outputs", "stability", "bool", False,
        long_name="transverse, harmonic load: Floquet multiplier, growth rate and stability of "
                  "the straight span, from one load period (with the time-domain outputs off, "
                  "nothing else is integrated)"),
    Key("outputs", "clearance", "floats", None, units="m", minimum=0.0, exclusive_min=True,
        long_name="random base acceleration: levels of |midspan deflection| (at most 4) whose "
                  "up-crossing rates, expected exceedances in base.test_duration and "
                  "probability of at least one are stored"),
    Key("outputs", "response_asd", "bool", False,
        long_name="random base acceleration: store the spectral densities (Welch) of the "
                  "midspan deflection (m2 Hz-1) and absolute acceleration (g2 Hz-1) on an "
                  "asd_frequency dimension up to the spectrum's top frequency, mean over the "
                  "realisations, beside the input spectrum"),
    Key("outputs", "asd_resolution", "float", None, units="Hz", minimum=0.0, exclusive_min=True,
        long_name="random base acceleration, with outputs.response_asd: the spectra's frequency "
                  "resolution (default: the finest that fits 8 half-overlapping Welch segments "
                  "in the shortest statistics window)"),
    Key("outputs", "time_series", "bool", False, long_name="store q(t) at sample_interval"),
    Key("outputs", "sample_interval", "float", None, units="s", minimum=0.0, exclusive_min=True,
        long_name="time-series sample interval (default t_end/1000)"),
    Key("outputs", "histories", "bool", False,
        long_name="longitudinal: store end-displacement and fixed-end-force histories"),
    Key("outputs", "snapshot_times", "floats", None, units="s", minimum=0.0,
        long_name="longitudinal: times of the field snapshots u(x), N(x), v(x)"),
    Key("outputs", "normalised", "bool", False,
        long_name="longitudinal: also store N/P0 and v rho A a/P0 snapshots"),
    # [continuation]
    Key("continuation", "axis", "str", None,
        long_name="stepped sweep: the axis solved in order, each point starting from the "
                  "previous one's final state with the excitation phase carried on"),
    Key("continuation", "direction", "str", "up", choices=("up", "down", "both"),
        long_name="stepped sweep: along increasing axis values (up), decreasing (down), or both "
                  "(a direction dimension)"),
    Key("continuation", "jump_ratio", "float", 1.5, units="1", minimum=1.0, exclusive_min=True,
        long_name="stepped sweep: a jump is where the tail amplitude of one step differs from "
                  "the step before by more than this factor"),
    # [run]
    Key("run", "threads", "int", 0, units="1", minimum=0,
        long_name="worker threads (0 = all cores)"),
    Key("run", "chunk_size", "int", None, units="1", minimum=1,
        long_name="grid points per kernel call or dask task (default: chosen from the grid)"),
    Key("run", "backend", "str", "threads", choices=("threads", "dask"),
        long_name="where the chunks run: in-process threads, or dask.distributed (a "
                  "LocalCluster started for the run; an existing cluster only from the command "
                  "line, --scheduler)"),
    Key("run", "workers", "int", 0, units="1", minimum=0,
        long_name="dask LocalCluster worker processes (0 = one per core)"),
)

TOP_LEVEL: dict[str, str] = {"name": "a short name for the sweep",
                             "description": "one line saying what the sweep is for"}

SECTIONS: tuple[str, ...] = tuple(dict.fromkeys(k.section for k in KEYS)) + ("axes", "points")
"""Every section a scene may have: those of the keys, then [axes] and [points] (swept values)."""
SWEPT_SECTIONS: tuple[str, ...] = ("axes", "points")

BY_DOTTED: dict[str, Key] = {k.dotted: k for k in KEYS}
TABLES: dict[str, str] = {"base.sweep": "sweep = { start = 5.0, stop = 100.0, rate = 2.0 } "
                                        "(Hz, Hz, octaves per minute)"}
"""Inline tables of keys (their keys are the schema's ``sweep.start`` ...) -> an example."""
BY_AXIS: dict[str, Key] = {k.axis: k for k in KEYS if k.axis is not None}

AXIS_SPACINGS: tuple[str, ...] = ("linear", "log")
