"""The transverse model: the modal oscillator of the span (RK45 or DOP853 kernels).

Its pieces, in the order a run uses them: the kernel settings of a scene (`settings_vector`),
the parameter rows of any set of grid points (coefficients from sweep/models/modal.py), the
kernel over chunks of points through the generic runner (sweep/runner.py), and the result
Dataset (`assemble`): the output variables with their units and long names, the derived
closed forms, the state flags. docs/model.md secs. 2, 3 and 5 are its mathematics.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from sweep.kernels import layout as tk        # plain constants: no Numba is imported
from sweep.kernels import states as km

from .. import grid
from ..dataset import (TIME_DIM, Provenance, counter, derived, elapsed_time, flag_attrs,
                       global_attrs, provenance)
from ..runner import RunOptions, check_memory, placer, point_order, solve_chunked
from ..scene import Scene
from ..schema import BY_AXIS, G2_UNITS, G_UNITS, STANDARD_GRAVITY
from . import excitation, linear, loads, modal, random_outputs, response_asd
from .basis import Basis, BasisFamily, end_stiffness, span_basis
from .random_outputs import RandomInputs
from .continuation import DIRECTION_DIM
from .random_scene import REALISATION_DIM

KIND = "transverse"
MODE_DIM = "mode"              # the dimension of per-mode outputs (model.modes >= 2)
BASE_OUTPUTS = ("absolute_acceleration", "absolute_acceleration_g", "transmissibility")
"""The variables `base_outputs` makes, in its order."""
ATOL_SCALE = 0.01              # default atol: this x rtol x each point's own scales (m, m/s)

# name -> (kernel column, units, long_name, scene output switch)
_REALS = {
    "amplitude": (tk.AMPLITUDE, "m", "max |q| over the tail window (midspan deflection)",
                  "outputs.amplitude"),
    "peak_amplitude": (tk.PEAK, "m", "max |q| over the whole run (overshoot)",
                       "outputs.peak_amplitude"),
    "settling_time": (tk.SETTLING, "s", "time after which every envelope peak stays within "
                      "+-tolerance of its final level (decayed: last time |q| > tolerance * "
                      "peak); NaN where the span is undamped (nothing settles)",
                      "outputs.settling_time"),
    "response_period": (tk.PERIOD, "s", "mean time between maxima of q in the tail window",
                        "outputs.response_period"),
    "failure_time": (tk.FAILURE_TIME, "s", "time at which a diverged or failed point stopped",
                     None),
    "stop_time": (tk.STOP_TIME, "s", "time at which a point found steady or decayed ended, its "
                  "tail window the solver.steady_periods periods before it "
                  "(solver.stop_when_steady); NaN: the point ran to t_end",
                  "solver.stop_when_steady"),
}
_COUNTS = {
    "n_steps": (tk.STEPS, "accepted {method} steps"),
    "n_rejected": (tk.REJECTED, "rejected {method} step attempts"),
    "n_rhs": (tk.RHS_EVALS, "right-hand-side evaluations"),
}
# solver.method -> how the source attribute and the counters name the integrator.
METHODS = {"rk45": ("RK45", "Dormand-Prince 5(4) (RK45)"),
           "dop853": ("DOP853", "Dormand-Prince 8(5,3) (DOP853)")}
CONTROLLERS = {"scipy": "SciPy's step-size control", "pi": "PI (Gustafsson) step-size control"}
_DERIVED = {
    "natural_frequency": ("Hz", "first linear natural frequency of the unloaded span"),
    "buckling_load": ("N", "Euler buckling load of the span (paper: implied by Eq.32)"),
    "load_ratio": ("1", "load amplitude over buckling load, P0/Pcr"),
    "load_amplitude": ("N", "end load amplitude P0 (positive = compression), from "
                            "load.amplitude_ratio times buckling_load"),
    "load_frequency": ("Hz", "load frequency W/(2 pi)"),
    "escape_barrier": ("m", "|q| beyond which the softening quintic lets the span escape, "
                            "for the mean (harmonic) or constant load; NaN: no barrier, or one "
                            "beyond the model's range (mode slope pi q_b / l > 1)"),
}
# Scenes with a constant end load: the frequency `sweep design --min-frequency` judges.
_LOADED = {
    "loaded_frequency": ("Hz", "first linear natural frequency of the straight span under the "
                               "constant end load (the run's modes, which the load couples "
                               "where the clamps are not pins); NaN: the load buckles it"),
}
# Scenes with [base] (docs/model.md sec. 5): the excitation in both spellings (each stored
# only where it is not an axis: then the axis is its coordinate) and closed forms.
_BASE_DERIVED = {
    **{axis: (BY_AXIS[axis].units, BY_AXIS[axis].long_name)
       for axis in ("base_acceleration", "base_acceleration_g", "base_frequency",
                    "base_frequency_ratio")},
    "resonance_amplification": ("1", "linear resonance amplification Q = 1/(2 zeta): peak "
                                     "amplitude over the quasi-static Gamma A / w1^2; NaN: "
                                     "undamped"),
}


# Scenes with a swept base frequency (docs/model.md sec. 6).
_SWEEP_DERIVED = {
    "sweep_duration": ("s", "duration of the logarithmic sine sweep, 60 |log2(stop/start)| / "
                            "rate"),
}
BAND_DIM = "band_frequency"    # the envelope's dimension: its bands' centre frequencies (Hz)


@dataclass
class KernelResult:
    """Flat per-point kernel outputs, in grid (C) order."""
    states: np.ndarray      # int8 state flags
    reals: np.ndarray       # (n, kernels.transverse.N_REALS)
    counts: np.ndarray      # (n, kernels.transverse.N_COUNTS) int64
    series: np.ndarray      # (n, n_samples) q samples (m); n_samples may be 0
    sample_times: np.ndarray
    modal: np.ndarray | None = None    # (n, N) each mode's tail amplitude (m); N >= 2 only
    envelope: np.ndarray | None = None  # (n, n_bands) the response envelope (m); swept only
    spectra: dict[str, np.ndarray] | None = None   # outputs.response_asd's (n, n_freq) arrays
    reduction: Any = None                          # and their response_asd.Reduction


def sample_times(t_end: float, dt: float) -> np.ndarray:
    """k * dt for every k with k * dt <= t_end (s); computed as the kernel computes them."""
    n = int(math.floor(t_end / dt)) + 1
    k = np.arange(max(n - 2, 0), n + 2)
    return np.arange(int(k[k * dt <= t_end][-1]) + 1) * dt


def settings_vector(scene: Scene) -> np.ndarray:
    """The kernel's settings vector (kernels.transverse) from the scene's solver/metrics keys.

    solver.atol given: that absolute tolerance for q (m) and q' (m/s), as SciPy's scalar atol.
    Not given: each point's own, ATOL_SCALE x rtol x its displacement and velocity scales
    (sweep.models.state_scale), so results do not depend on the response's size.
    BASE is 1.0 for a scene with base excitation ([base]): the kernel then adds the forcing
    term and computes the absolute acceleration.
    """
    s = np.zeros(tk.N_SETTINGS)
    s[tk.RTOL] = scene.get("solver.rtol")
    atol = scene.get("solver.atol")
    s[tk.ATOL] = 0.0 if atol is None else atol
    s[tk.ATOL_SCALE] = ATOL_SCALE if atol is None else 0.0
    s[tk.T_END] = excitation.end_time(scene.values, scene.swept)
    s[tk.MAX_STEPS] = scene.get("solver.max_steps")
    s[tk.MAX_STEP] = scene.get("solver.max_step") or math.inf
    s[tk.FIRST_STEP] = scene.get("solver.first_step") or 0.0
    s[tk.TAIL] = scene.get("metrics.tail")
    s[tk.TOL] = scene.get("metrics.tolerance")
    s[tk.SAMPLE_DT] = scene.get("outputs.sample_interval") or s[tk.T_END] / 1000.0
    s[tk.WANT_SETTLING] = 1.0 if scene.get("outputs.settling_time") else 0.0
    s[tk.MIN_STEP] = scene.get("solver.min_step") or 0.0
    s[tk.CONTROLLER] = 1.0 if scene.get("solver.controller") == "pi" else 0.0
    s[tk.METHOD] = 1.0 if scene.get("solver.method") == "dop853" else 0.0
    if scene.has_base:                  # else 0.0: no forcing term compiled
        s[tk.BASE] = 1.0
    s[tk.LOADS] = loads.observation(scene, excitation.is_swept(scene.values, scene.swept))
    if scene.get("solver.stop_when_steady"):
        s[tk.STOP_STEADY] = 1.0
        s[tk.STEADY_PERIODS] = scene.get("solver.steady_periods")
        s[tk.STEADY_TOL] = scene.get("solver.steady_tolerance")
    if excitation.is_swept(scene.values, scene.swept):
        s[tk.SWEPT] = 1.0
        s[tk.BANDS_PER_OCTAVE], s[tk.FIRST_BAND] = scene.get("outputs.bands_per_octave"), 0.0
        if scene.get("outputs.envelope"):
            s[tk.FIRST_BAND] = envelope_bands(scene)[0]
    return s


def envelope_bands(scene: Scene) -> tuple[int, int]:
    """(first band k, number of bands) of a swept scene's envelope: the base-2 1/N-octave
    bands, centres 1000 x 2^(k/N) Hz (N = outputs.bands_per_octave), that hold every
    frequency its sweeps reach."""
    start, stop, _ = excitation.sweep_grid(scene.values, scene.swept)
    n = scene.get("outputs.bands_per_octave")
    low = int(excitation.band_index(float(np.min(np.minimum(start, stop))), n))
    high = int(excitation.band_index(float(np.max(np.maximum(start, stop))), n))
    return low, high - low + 1


def set_constant_stiffness(settings: np.ndarray, coeffs: dict[str, Any]) -> None:
    """settings[CONSTANT_STIFFNESS] from the scene's coefficients (modal.oscillator, on their
    axes, or the parameter table's columns by name): 1.0 when no point has a time-varying
    stiffness (k1 = g1 = 0 everywhere: a constant or zero end load), so the kernels leave the
    cos(W t) terms out (the same results to the bit, and a cheaper right-hand side)."""
    varying = any(bool(np.any(np.asarray(coeffs[c]) != 0.0)) for c in ("k1", "g1"))
    settings[tk.CONSTANT_STIFFNESS] = 0.0 if varying else 1.0


def solve_points(params: np.ndarray, settings: np.ndarray, n_samples: int,
                 threads: int = 0, progress: bool = False,
                 chunk_size: int | None = None, driver: str = "lanes") -> KernelResult:
    """Run the transverse kernel over the rows of `params` in-process (grid order in, grid
    order out). driver: "lanes" (kernels.lanes, lock-step SIMD) or "scalar"
    (kernels.transverse, one trajectory per iteration); the two agree to round-off."""
    from ..execute import default_chunk_size, execute, transverse_chunk, transverse_outputs
    n = params.shape[0]
    order = point_order(n)
    outputs = transverse_outputs(n, n_samples)
    execute(transverse_chunk, lambda lo, hi: np.ascontiguousarray(params[order[lo:hi]]), n,
            (settings, n_samples, driver), placer(outputs, order),
            chunk_size=chunk_size or default_chunk_size(n, "threads", 0),
            threads=threads, progress=progress)
    return KernelResult(outputs["states"], outputs["reals"], outputs["counts"],
                        outputs["series"], np.empty(0))


@dataclass(frozen=True)
class Inputs:
    """A transverse scene resolved once (`resolve`) into what the model's steps need; nothing
    after `resolve` reads the scene.

    coords, dims, shape: the grid (one coordinate per axis, scene order); params: the
    parameters by axis name (scalars, or DataArrays over their own axes; grid.parameters);
    settings: the kernel settings vector (`settings_vector`); sample_times: the time-series
    sample times (s; empty when none are stored); driver, method, controller: solver.driver,
    solver.method, solver.controller; wanted: the outputs.* switches that are on (dotted
    keys); has_base: the scene has base excitation; origin: its provenance; n_modes:
    model.modes; basis: the span's mode shapes (sweep/models/basis.py: one Basis, or a
    BasisFamily where elastic ends vary over the grid);
    modal_q0, modal_v0: the initial modal deflections (m) and velocities (m/s),
    n_modes scalars or axis parameters each (mode 1's from initial.displacement and
    initial.velocity, the others 0, unless the scene gives initial.modal_displacement or
    initial.modal_velocity); continuation, direction, jump_ratio: the stepped sweep's axis
    (None: every point independent), its direction and its jump factor ([continuation]);
    swept: the base frequency is swept ([base] sweep); bands: (first band, count, bands per
    octave) of its envelope (None: no envelope); per_point_end: every point ends with its own
    sweep (no solver.t_end given); sweep_direction: base.sweep.direction (None: from start to
    stop); random: a random scene's inputs (None: not random); resolution:
    outputs.asd_resolution (Hz, None: the default).
    """
    coords: dict[str, xr.DataArray]
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    params: dict[str, Any]
    settings: np.ndarray
    sample_times: np.ndarray
    driver: str
    method: str
    controller: str
    wanted: frozenset[str]
    has_base: bool
    origin: Provenance
    n_modes: int = 1
    basis: Basis | BasisFamily | None = None
    modal_q0: tuple = ()
    modal_v0: tuple = ()
    continuation: str | None = None
    direction: str = "up"
    jump_ratio: float = 1.5
    swept: bool = False
    bands: tuple[int, int, int] | None = None
    per_point_end: bool = False
    sweep_direction: str | None = None
    random: RandomInputs | None = None
    resolution: float | None = None


def end_stiffness_of(params: dict[str, Any]) -> Any:
    """K = k_t l / EI (1) of elastic ends from `params` (grid.parameters, or their values at
    points: the same bits either way)."""
    return end_stiffness("elastic", params["clamp_rotational_stiffness"], params["length"],
                         params["youngs_modulus"] * params["inertia"])


def _basis(rotation: str, params: dict[str, Any], n_modes: int) -> Basis | BasisFamily:
    """The span's modes: one Basis for pinned or clamped ends; for elastic ones a Basis per
    distinct K over the grid (a BasisFamily; one basis when K does not vary)."""
    if rotation != "elastic":
        return span_basis(end_stiffness(rotation, None, None, None), n_modes)
    stiffness = end_stiffness_of(params)
    if np.ndim(stiffness) == 0:
        return span_basis(float(stiffness), n_modes)
    return BasisFamily.of(stiffness, n_modes)


def resolve(scene: Scene) -> Inputs:
    """The Inputs of a transverse scene: the only place this model reads it."""
    coords = grid.coordinates(scene)
    dims = grid.dimensions(coords)
    settings = settings_vector(scene)
    wanted = frozenset(k for k in scene.values if (k.startswith("outputs.")
                                                    or k == "solver.stop_when_steady")
                       and scene.get(k) is True)
    random = RandomInputs.of(scene.values)
    if random is not None and "outputs.response_asd" in wanted:   # the spectra's samples
        settings[tk.SAMPLE_DT] = 1.0 / response_asd.asd_rate(random.sample_rate,
                                                             float(random.spectrum[0][-1]))
    times = (sample_times(settings[tk.T_END], settings[tk.SAMPLE_DT])
             if wanted & {"outputs.time_series", "outputs.response_asd"} else np.empty(0))
    params = grid.parameters(scene, coords)
    swept = excitation.is_swept(scene.values, scene.swept)
    n_modes = scene.get("model.modes")
    initial = []
    for listed, single in (("initial.modal_displacement", "initial_displacement"),
                           ("initial.modal_velocity", "initial_velocity")):
        values = scene.get(listed)
        initial.append(tuple(values) if values is not None
                       else (params[single],) + (0.0,) * (n_modes - 1))
        if values is not None and n_modes == 1:    # one mode's driver reads the single key
            params[single] = float(values[0])
    return Inputs(coords=coords, dims=dims, shape=tuple(coords[d].size for d in dims),
                  params=params, settings=settings, sample_times=times,
                  driver=scene.get("solver.driver"), method=scene.get("solver.method"),
                  controller=scene.get("solver.controller"), wanted=wanted,
                  has_base=scene.has_base, origin=provenance(scene), n_modes=n_modes,
                  basis=_basis(scene.get("clamps.rotation"), params, n_modes),
                  modal_q0=initial[0], modal_v0=initial[1],
                  continuation=scene.get("continuation.axis"),
                  direction=scene.get("continuation.direction"),
                  jump_ratio=scene.get("continuation.jump_ratio"), swept=swept,
                  bands=(envelope_bands(scene) + (scene.get("outputs.bands_per_octave"),)
                         if swept and scene.get("outputs.envelope") else None),
                  per_point_end=swept and scene.get("solver.t_end") is None,
                  sweep_direction=scene.get("base.sweep.direction"),
                  random=random, resolution=scene.get("outputs.asd_resolution"))


TIME_DOMAIN_OUTPUTS = ("outputs.amplitude", "outputs.peak_amplitude", "outputs.settling_time",
                       "outputs.response_period", "outputs.solver_stats", "outputs.time_series")
"""Outputs that need the time-domain run (with base excitation also the absolute acceleration,
with a sweep its peak frequency and envelope)."""


def time_domain(inputs: Inputs) -> bool:
    """Whether the scene asks for anything the time-domain run gives (else, with
    outputs.stability, only the monodromy is computed)."""
    wanted = set(TIME_DOMAIN_OUTPUTS)
    if inputs.has_base:
        wanted.add("outputs.absolute_acceleration")
    if inputs.swept:
        wanted |= {"outputs.peak_frequency", "outputs.envelope"}
    return bool(wanted & inputs.wanted)


def run(scene: Scene, options: RunOptions) -> xr.Dataset:
    """The transverse sweep of `scene` as a Dataset, run as `options` say: the model's entry
    point (sweep.models.model_for)."""
    inputs = resolve(scene)
    if "outputs.stability" not in inputs.wanted or time_domain(inputs):
        _check_time_domain_memory(inputs)      # before anything is computed over the grid
    coeffs = modal.oscillator(inputs.params)   # derived quantities, on the axes they need
    if inputs.params["load_type"] == "constant" and np.any(np.asarray(coeffs["load_ratio"]) != 0):
        from .stability import loaded_frequency
        coeffs["loaded_frequency"] = loaded_frequency(coeffs, inputs.n_modes)
    if "outputs.stability" not in inputs.wanted:
        return _warn_steep(_run_time_domain(inputs, coeffs, options), inputs)
    from .stability import stability_outputs
    started = time.perf_counter()
    stable = stability_outputs(coeffs, inputs.dims, inputs.shape, inputs.n_modes,
                               options.threads)
    if not time_domain(inputs):
        if inputs.continuation is not None:
            from ..errors import UserError
            raise UserError("scene key 'continuation.axis': a stepped sweep needs a time-domain "
                            "output (outputs.amplitude, ...), and this scene asks only for "
                            "outputs.stability; remove [continuation] or turn an output on")
        return stability_dataset(inputs, coeffs, stable, time.perf_counter() - started)
    ds = _run_time_domain(inputs, coeffs, options)
    return _warn_steep(ds.assign(stable), inputs)


STEEP_SLOPE = 0.5
"""The largest slope pi w / l (w the largest deflection reported, l the span) past which a
run warns: the cubic and quintic terms are the first of a series in the squared slope (docs/
model.md sec. 2), whose next term is about slope^6 of the curvature there (1.6 % at 0.5) and
which diverges at 1 (modal.MAX_SLOPE)."""
_DEFLECTIONS = ("max_deflection", "amplitude", "peak_amplitude", "peak_deflection")
_WITHIN_A_POINT = (DIRECTION_DIM, REALISATION_DIM)   # a sweep's two ways, a point's records


def _warn_steep(ds: xr.Dataset, inputs: Inputs) -> xr.Dataset:
    """Warn (one line) where some point's largest deflection reported (its largest over the
    _DEFLECTIONS it has, both ways and every record) puts its slope, about pi w / l, above
    STEEP_SLOPE: its answers are then qualitative. Returns ds."""
    import warnings

    from ..errors import CableSweepWarning
    length = derived(inputs.params["length"], inputs.coords)
    slopes = [(math.pi * ds[name] / length).max([d for d in ds[name].dims
                                                  if d in _WITHIN_A_POINT])
              for name in _DEFLECTIONS if name in ds]
    if not slopes:
        return ds
    steep = xr.concat(slopes, "deflection").max("deflection")
    count = int((steep > STEEP_SLOPE).sum())
    if count == 0:
        return ds
    warnings.warn(f"{count} of {steep.size} points deflect to a slope of about "
                  f"{float(steep.max()):.2g} (pi w / l > {STEEP_SLOPE:g}): beyond the moderate "
                  "slopes the model's cubic and quintic terms describe (docs/model.md sec. 2), "
                  "so their answers are qualitative", CableSweepWarning, stacklevel=4)
    return ds


def derived_variables(coeffs: dict[str, Any], coords: dict[str, xr.DataArray],
                      table: dict[str, tuple[str, str]]) -> dict[str, xr.DataArray]:
    """The closed forms of `table` (name -> (units, long_name)) that `coeffs` holds, each on
    the axes it depends on; none that is itself an axis (its coordinate holds it)."""
    out = {}
    for name, (units, long_name) in table.items():
        if name in coeffs and name not in coords:
            out[name] = derived(coeffs[name], coords)
            out[name].attrs = {"units": units, "long_name": long_name}
    return out


SPAN_NAMES = ("max_deflection", "max_deflection_position")
"""`span_outputs`' variables: each point's, solved by the kernels."""


def span_outputs(reals: np.ndarray, dims: tuple[str, ...], shape: tuple[int, ...],
                 swept: bool, length: xr.DataArray) -> dict[str, xr.DataArray]:
    """Several modes: the largest deflection anywhere on the span (`max_deflection`, m, over
    the tail window; a sine sweep's over the whole sweep) and its distance from the nearer
    clamp (`max_deflection_position`, m; l/2 at midspan), from the kernels' SPAN_MAX and
    SPAN_PLACE (x / l) columns; length: the span (m) on the result's axes."""
    window = "the whole sweep" if swept else "the tail window"
    place = reals[:, tk.SPAN_PLACE].reshape(shape)
    nearer = xr.DataArray(np.minimum(place, 1.0 - place), dims=dims)
    return {
        "max_deflection": xr.DataArray(
            reals[:, tk.SPAN_MAX].reshape(shape), dims=dims,
            attrs={"units": "m", "long_name": "largest deflection anywhere on the span: max "
                   f"|w(x, t)| over 0 <= x <= l and {window} (amplitude is the midspan's)"}),
        "max_deflection_position": (nearer * length).assign_attrs(
            units="m", long_name="where the largest deflection (max_deflection) occurred: "
            "its distance from the nearer clamp (half the span: at midspan)")}


def _one_mode(inputs: Any, coeffs: dict[str, Any], coords: dict[str, xr.DataArray],
              reals: np.ndarray, dims: tuple[str, ...], shape: tuple[int, ...]
              ) -> loads.OneMode:
    """What one mode's clamp reaction needs (sweep.models.loads.OneMode): the base's level and
    angular frequency where the response peaked (a fixed frequency's; a sweep's where q
    peaked, its level table read there), the mode's equation's coefficients; NaN level and
    frequency for a random record (no one of either)."""
    p = inputs.params
    levels = p.get("base_levels_g")
    if inputs.random is not None:
        level = omega = math.nan
    elif inputs.swept:
        hertz = xr.DataArray(reals[:, tk.PEAK_FREQUENCY].reshape(shape), dims=dims)
        omega = 2.0 * math.pi * hertz
        level = (excitation.table_level(levels, hertz) if levels is not None
                 else derived(coeffs["base_accel"], coords))
    else:
        level = derived(coeffs["base_accel"], coords)
        omega = derived(coeffs["base_omega"], coords)
    return loads.OneMode(level, omega, *(derived(coeffs[k], coords) for k in (
        "damping", "k0", "g0", "h", "participation")))


def _derived_table(coeffs: dict[str, Any], has_base: bool) -> dict[str, tuple[str, str]]:
    """The closed forms a time-domain result stores: _DERIVED, without load_frequency where
    the scene has no end load at any point (it would be a frequency of nothing), and with
    base excitation's."""
    table = dict(_DERIVED)
    if not np.any(np.asarray(coeffs["load_ratio"]) != 0.0):
        table.pop("load_frequency")
    if "loaded_frequency" in coeffs:
        table.update(_LOADED)
    return table | (_BASE_DERIVED if has_base else {})


def stability_dataset(inputs: Inputs, coeffs: dict[str, Any], stable: dict[str, xr.DataArray],
                      elapsed: float) -> xr.Dataset:
    """The Dataset of a stability-only scene: the Floquet outputs and the closed forms."""
    data = {**stable, **derived_variables(coeffs, inputs.coords, _DERIVED)}
    system = ("transverse modal oscillator" if inputs.n_modes == 1 else
              f"transverse Galerkin model, {inputs.n_modes} modes")
    attrs = global_attrs(inputs.origin, inputs.shape, elapsed,
                         f"{system} linearised about q = 0, Floquet multipliers over one load "
                         f"period (fixed-step DOP853 eighth order)")
    attrs.update(span_attrs(inputs.params))
    return xr.Dataset(data, coords=dict(inputs.coords), attrs=attrs)


def _check_time_domain_memory(inputs: Inputs) -> None:
    """Refuse, before any work, a grid whose time-domain outputs (and their Dataset copies),
    solve order and derived quantities would not fit in memory: the parameter rows are built
    chunk by chunk and never held for the whole grid."""
    n_points = int(np.prod(inputs.shape, dtype=np.int64))
    samples = inputs.sample_times.size
    if "outputs.response_asd" in inputs.wanted:     # spectra kept, samples only per chunk
        samples = (samples if "outputs.time_series" in inputs.wanted else 0) + 2 * (
            response_asd.max_bins(inputs.random, inputs.resolution))
    check_memory(n_points, 2.0 * (1 + 8 * (tk.N_REALS + tk.N_COUNTS + samples
                                           + (inputs.n_modes if inputs.n_modes > 1 else 0)))
                 + 40, "metrics and time series")


def _run_time_domain(inputs: Inputs, coeffs: dict[str, Any],
                     options: RunOptions) -> xr.Dataset:
    """The time-domain run of a transverse scene (every point integrated over [0, t_end]);
    coeffs: modal.oscillator of its parameters."""
    shape = inputs.shape
    settings = inputs.settings.copy()
    n_points = int(np.prod(shape, dtype=np.int64))
    set_constant_stiffness(settings, coeffs)
    records = None
    if inputs.random is not None:          # its statistics window, levels and records
        random_outputs.set_settings(settings, inputs.random, coeffs, inputs.params,
                                    settings[tk.TOL])
        from ..threads import thread_count
        records = inputs.random.records(thread_count(options.threads))
    system = _system(inputs, settings, records)
    reduction = None
    if inputs.random is not None and "outputs.response_asd" in inputs.wanted:
        reduction = _spectra(inputs, coeffs, settings)
        system = _reduced(system, reduction, records)
        options = response_asd.capped(options, inputs.sample_times.size)
    started = time.perf_counter()
    if inputs.continuation is not None:
        return _run_stepped(inputs, options, coeffs, system, settings, started)
    if inputs.sweep_direction is not None:
        return _run_directed(inputs, options, coeffs, settings, started)
    out = solve_chunked(options, system.chunk_fn, system.rows_at, system.args,
                        system.outputs(n_points))
    result = _result(out, inputs)
    if reduction is not None:
        result.spectra = {name: out[name] for name in response_asd.NAMES}
        result.reduction = reduction
    return assemble(inputs, coeffs, result, time.perf_counter() - started, records)


def _spectra(inputs: Inputs, coeffs: dict[str, Any],
             settings: np.ndarray) -> response_asd.Reduction:
    """outputs.response_asd's Reduction: the segment from the grid's shortest statistics
    window, a row's record and level columns from its System's excitation block."""
    from sweep.kernels import excitation as ex
    from sweep.kernels import modes as md
    from sweep.kernels import oscillator as osc
    from .random_scene import shortest_window
    t_end = float(settings[tk.T_END])
    window = shortest_window(t_end, float(settings[tk.TAIL]), float(settings[tk.TOL]),
                             coeffs["natural_frequency"], inputs.params["damping_ratio"],
                             inputs.random.ramp)
    block = osc.EXCITATION if inputs.n_modes == 1 else md.EXCITATION
    return response_asd.reduction(
        inputs.random, window, inputs.resolution, t_end,
        record_column=block + ex.RECORD, scale_column=block + ex.RECORD_SCALE,
        window_column=tk.WINDOW, keep_series="outputs.time_series" in inputs.wanted)


def _reduced(system: _System, reduction: response_asd.Reduction,
             records: np.ndarray) -> _System:
    """`system` with its chunks' time series reduced to spectra (sweep.execute.reduced_chunk)."""
    from ..execute import reduced_chunk

    def outputs(n: int) -> dict[str, np.ndarray]:
        return {**system.outputs(n), **reduction.empty(n)}

    return _System(system.rows_at, reduced_chunk,
                   (system.chunk_fn, system.args, reduction, records), outputs, None)


def _run_directed(inputs: Inputs, options: RunOptions, coeffs: dict[str, Any],
                  settings: np.ndarray, started: float) -> xr.Dataset:
    """A sweep with base.sweep.direction: up (from the lower of start and stop to the upper),
    down, or both, solved as one grid of twice the points (the down sweeps after the up
    sweeps: one chunk store, one dask graph), the two halves on a `direction` dimension."""
    directions = ["up", "down"] if inputs.sweep_direction == "both" else [inputs.sweep_direction]
    systems = [_system(oriented(inputs, d), settings) for d in directions]
    n = int(np.prod(inputs.shape, dtype=np.int64))

    def rows_at(points: np.ndarray) -> np.ndarray:
        rows = np.empty((points.size, systems[0].rows_at(points[:0]).shape[1]))
        for k, system in enumerate(systems):
            mine = points // n == k
            if np.any(mine):
                rows[mine] = system.rows_at(points[mine] % n)
        return rows

    out = solve_chunked(options, systems[0].chunk_fn, rows_at, systems[0].args,
                        systems[0].outputs(n * len(directions)))
    elapsed = time.perf_counter() - started
    results = [assemble(oriented(inputs, d), coeffs,
                        _result({k: v[i * n:(i + 1) * n] for k, v in out.items()}, inputs),
                        elapsed) for i, d in enumerate(directions)]
    if len(results) == 1:
        return results[0]
    return _both_directions(results, inputs.dims, directions,
                            "direction of the sine sweep (up: increasing frequency)")


def oriented(inputs: Inputs, direction: str) -> Inputs:
    """`inputs` with its sweep running up (from the lower of start and stop to the upper) or
    down."""
    import dataclasses
    start, stop = inputs.params["base_sweep_start"], inputs.params["base_sweep_stop"]
    low, high = np.minimum(start, stop), np.maximum(start, stop)
    first, last = (low, high) if direction == "up" else (high, low)
    return dataclasses.replace(inputs, params={**inputs.params, "base_sweep_start": first,
                                               "base_sweep_stop": last})


@dataclass(frozen=True)
class _System:
    """How the runner drives one of the transverse Systems (the one-mode oscillator or the
    N-mode Galerkin model): rows_at(points) their raw parameter rows, chunk_fn(rows, *args) the
    kernel call (sweep.execute), outputs(n) its empty outputs, carry what a stepped sweep
    carries from one dwell to the next (sweep/models/continuation.py)."""
    rows_at: Any
    chunk_fn: Any
    args: tuple
    outputs: Any
    carry: Any


def modal_rows(inputs: Inputs, points: np.ndarray) -> np.ndarray:
    """The raw rows (kernels.modes columns) of the N-mode System, N = inputs.n_modes (1 too),
    at grid points `points` (flat indices): what a run with model.modes >= 2 solves; tests and
    benchmarks take their rows from here."""
    from sweep.kernels import modes as md
    dims, shape, params, n = inputs.dims, inputs.shape, inputs.params, inputs.n_modes
    names = md.FIXED_NAMES + tuple(f"q0_{i}" for i in range(1, n + 1)) + tuple(
        f"v0_{i}" for i in range(1, n + 1))

    def values_at(modal_values: tuple) -> list:
        return [grid.point_values({"v": v}, dims, shape, points)["v"] for v in modal_values]

    at = grid.point_values(params, dims, shape, points)
    columns = modal.modes_columns(at, modal.oscillator(at), n, values_at(inputs.modal_q0),
                                  values_at(inputs.modal_v0))
    rows = grid.rows(columns, names, points.size)
    if isinstance(inputs.basis, BasisFamily):     # each row's basis, in a last column
        index = inputs.basis.index(np.broadcast_to(end_stiffness_of(at), points.shape))
        rows = np.ascontiguousarray(np.hstack([rows, index[:, None].astype(float)]))
    return rows


def _system(inputs: Inputs, settings: np.ndarray, records: np.ndarray | None = None) -> _System:
    """How the runner drives the System of `inputs`: the one-mode oscillator (model.modes = 1)
    or the N-mode model (`modal_rows`); records: a random scene's (the kernels' `base`)."""
    from sweep.kernels import oscillator as osc

    from ..execute import modes_chunk, modes_outputs, transverse_chunk, transverse_outputs
    from .continuation import Carry
    dims, shape, params, n = inputs.dims, inputs.shape, inputs.params, inputs.n_modes
    n_samples = inputs.sample_times.size
    # a swept base frequency: the envelope's bands and whether each point ends with its sweep
    swept = (() if not inputs.swept else
             ((inputs.bands[1] if inputs.bands else 0), inputs.per_point_end))
    n_bands = swept[0] if swept else -1
    if records is not None:            # after the sweep's arguments, which it has not
        swept = (-1, False, records)
    if n == 1:
        def rows_at(points: np.ndarray) -> np.ndarray:
            at = grid.point_values(params, dims, shape, points)
            return grid.rows(modal.oscillator(at), osc.PARAM_NAMES, points.size)

        carry = None if inputs.continuation is None else Carry(
            state=(osc.Q0, osc.V0), base_phase=osc.BASE_PHASE, load_phase=osc.LOAD_PHASE,
            base_omega=osc.BASE_OMEGA, load_omega=osc.OMEGA,
            final="reals")
        return _System(rows_at, transverse_chunk, (settings, n_samples, inputs.driver) + swept,
                       lambda m: transverse_outputs(m, n_samples, n_bands), carry)

    from sweep.kernels import modes as md      # the N-mode System: only when it runs
    carry = None if inputs.continuation is None else Carry(
        state=tuple(range(md.N_FIXED, md.N_FIXED + 2 * n)), base_phase=md.BASE_PHASE,
        load_phase=md.LOAD_PHASE, base_omega=md.BASE_OMEGA, load_omega=md.OMEGA,
        final="final")
    return _System(lambda points: modal_rows(inputs, points), modes_chunk,
                   (settings, n_samples, inputs.basis.kernel_arrays(), inputs.driver) + swept,
                   lambda m: modes_outputs(m, n_samples, n, n_bands), carry)


def _result(out: dict[str, np.ndarray], inputs: Inputs) -> KernelResult:
    """The KernelResult of a kernel's outputs by name."""
    return KernelResult(out["states"], out["reals"], out["counts"], out["series"],
                        inputs.sample_times, out.get("modal"), out.get("envelope"))


def _run_stepped(inputs: Inputs, options: RunOptions, coeffs: dict[str, Any], system: _System,
                 settings: np.ndarray, started: float) -> xr.Dataset:
    """A stepped sweep along inputs.continuation (sweep/models/continuation.py): each
    direction's Dataset, with its `jump` flags; both directions on a `direction` dimension.

    A line (one direction, one combination of the other axes' values, all its dwells) is the
    unit of work the runner chunks (`execute.stepped_chunk`): the threads share a chunk's
    lines, a dask task takes a chunk of lines, the chunk store keeps finished lines to resume
    from. Without an output file every line is one chunk: no thread waits between chunks."""
    import dataclasses

    from ..execute import stepped_chunk
    from ..threads import thread_count
    from . import continuation as ct
    dims, shape = inputs.dims, inputs.shape
    n_points = int(np.prod(shape, dtype=np.int64))
    axis = dims.index(inputs.continuation)
    dwells = shape[axis]
    values = inputs.coords[inputs.continuation].values
    directions = ["up", "down"] if inputs.direction == "both" else [inputs.direction]
    orders = tuple(ct.dwell_order(values, direction) for direction in directions)
    lines = np.moveaxis(np.arange(n_points).reshape(shape), axis, -1).reshape(-1, dwells)
    n_lines = lines.shape[0]

    def line_rows(points: np.ndarray) -> np.ndarray:
        """Rows of lines `points` (direction index x n_lines + line): the direction, then
        the kernel rows of the line's dwells in the axis's order."""
        rows = system.rows_at(lines[points % n_lines].reshape(-1))
        rows = rows.reshape(points.size, -1)
        return np.ascontiguousarray(np.hstack([(points // n_lines)[:, None].astype(float),
                                               rows]))

    args = (system.chunk_fn, system.args, dwells, orders, system.carry,
            float(settings[tk.T_END]))
    total = n_lines * len(directions)
    workers = thread_count(options.threads)
    if options.chunk_size is None:
        chunk = total if options.output is None else max(ct.MIN_SHARE * workers, -(-total // 4))
        options = dataclasses.replace(options, chunk_size=min(chunk, total))
    template = system.outputs(0)
    out = solve_chunked(options, stepped_chunk, line_rows, args,
                        {k: np.empty((total, dwells) + v.shape[1:], v.dtype)
                         for k, v in template.items()}, unit="lines")
    outs = []
    for d in range(len(directions)):
        grid_out = {k: np.empty((n_points,) + v.shape[1:], v.dtype) for k, v in template.items()}
        for k, v in out.items():
            grid_out[k][lines.reshape(-1)] = v[d * n_lines:(d + 1) * n_lines].reshape(
                (n_lines * dwells,) + v.shape[2:])
        outs.append(grid_out)
    amplitudes = [out["reals"][:, tk.AMPLITUDE].reshape(shape) for out in outs]
    flags = [ct.jumps(a, out["states"].reshape(shape), axis, order, inputs.jump_ratio)
             for a, out, order in zip(amplitudes, outs, orders)]
    both = len(directions) == 2
    if both:
        flags = ct.branches_differ(flags, amplitudes, axis, orders, inputs.jump_ratio)
    flags = [ct.first_only(f, axis, order) for f, order in zip(flags, orders)]
    results = []
    for out, flag in zip(outs, flags):
        ds = assemble(inputs, coeffs, _result(out, inputs), time.perf_counter() - started)
        ds["jump"] = xr.DataArray(flag, dims=dims, attrs=ct.jump_attrs(
            inputs.continuation, inputs.jump_ratio, both))
        results.append(ds)
    if len(results) == 1:
        ds = results[0]
    else:
        ds = _both_directions(results, dims, directions)
    ds.attrs["continuation_axis"] = inputs.continuation
    ds.attrs["continuation_direction"] = inputs.direction
    ds.attrs["run_seconds"] = time.perf_counter() - started
    return ds


def _both_directions(results: list[xr.Dataset], dims: tuple[str, ...], directions: list[str],
                     long_name: str | None = None) -> xr.Dataset:
    """The up and down Datasets of a sweep as one, what the kernel solved on a leading
    `direction` dimension, the rest (closed forms of the parameters) once; long_name: the
    direction coordinate's (default: a stepped sweep's)."""
    from . import continuation as ct
    first = results[0]
    solved = {"state", "jump", "modal_amplitude", "peak_frequency", "envelope",
              *_REALS, *_COUNTS, *BASE_OUTPUTS, *loads.NAMES, *SPAN_NAMES}
    per_point = [name for name in first.data_vars if name in solved]
    stacked = xr.concat([r[per_point] for r in results], dim=ct.DIRECTION_DIM)
    ds = first.drop_vars(per_point).merge(stacked)
    ds = ds.assign_coords({ct.DIRECTION_DIM: ct.direction_coordinate(directions)
                           if long_name is None else
                           ct.direction_coordinate(directions, long_name)})
    for name in per_point:
        ds[name] = ds[name].transpose(ct.DIRECTION_DIM, *first[name].dims)
        ds[name].attrs = first[name].attrs
    ds.attrs = dict(first.attrs)
    # every point solved, in both directions (each direction's Dataset counted its own)
    ds.attrs["n_points"] = counter(int(first.attrs["n_points"]) * len(results))[()]
    return ds


def base_outputs(acceleration: np.ndarray, dims: tuple[str, ...],
                 level: xr.DataArray) -> dict[str, xr.DataArray]:
    """The outputs of base excitation: the kernel's absolute midspan acceleration amplitude
    max |q'' + a_b| over the tail window (m s-2, over `dims`), the same in g, and the
    transmissibility, that over the base level A (`level`, m s-2, over some of `dims`; NaN
    where A = 0). Like `amplitude`, NaN where the point failed."""
    absolute = xr.DataArray(acceleration, dims=dims, attrs={
        "units": "m s-2",
        "long_name": "absolute midspan acceleration amplitude, max |q'' + a_b| over the tail "
                     "window"})
    in_g = xr.DataArray(acceleration / STANDARD_GRAVITY, dims=dims, attrs={
        "units": G_UNITS,
        "long_name": f"absolute midspan acceleration amplitude in g ({STANDARD_GRAVITY:g} "
                     "m s-2)"})
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = xr.where(level > 0, absolute / level, np.nan).transpose(*dims)
    ratio.attrs = {"units": "1", "long_name": "transmissibility: absolute midspan "
                                               "acceleration amplitude over the base level A"}
    return dict(zip(BASE_OUTPUTS, (absolute, in_g, ratio)))


def modal_outputs(amplitudes: np.ndarray, dims: tuple[str, ...], shape: tuple[int, ...],
                  coeffs: dict[str, Any], coords: dict[str, xr.DataArray],
                  basis: Basis | BasisFamily, params: dict[str, Any] | None = None
                  ) -> dict[str, xr.DataArray]:
    """The outputs of a multi-mode run (docs/model.md sec. 7): modal_amplitude, each mode's
    max |q_n| over the tail window (m, over dims and `mode`; NaN where the point failed), and
    modal_frequency, the basis' w_n / w_1 times the span's f1 (Hz, over `mode` and the axes
    f1 depends on; pinned sines: n^2 f1; a BasisFamily's ratios over the axes K depends on)."""
    n_modes = amplitudes.shape[1]
    amplitude = xr.DataArray(amplitudes.reshape(shape + (n_modes,)), dims=dims + (MODE_DIM,),
                             attrs={"units": "m", "long_name": "modal amplitude: max |q_n| over "
                                    f"the tail window, q_n the coefficient of {basis.mode_text}"})
    f1 = derived(coeffs["natural_frequency"], coords)
    if isinstance(basis, BasisFamily):
        stiffness = end_stiffness_of(params)
        ratios = xr.DataArray(basis.frequency_ratios(stiffness),
                              dims=tuple(stiffness.dims) + (MODE_DIM,))
        frequency = (f1 * ratios).transpose(..., MODE_DIM)
    else:
        frequency = modal.modal_frequencies(f1, basis.frequency_ratio / basis.frequency_ratio[0]
                                            ).transpose(..., MODE_DIM)
    frequency.attrs = {"units": "Hz", "long_name": "linear natural frequency of mode n of the "
                                                  f"unloaded span, {basis.frequency_text}"}
    return {"modal_amplitude": amplitude, "modal_frequency": frequency}


def sweep_outputs(result: KernelResult, inputs: Inputs,
                  coeffs: dict[str, Any]) -> dict[str, xr.DataArray]:
    """The outputs of a swept base frequency (docs/model.md sec. 6): peak_frequency (Hz, the
    excitation frequency at the largest |q|), the envelope (m, over the axes and BAND_DIM;
    `band_coordinates`) and the sweep's duration (s); NaN where a point failed."""
    dims, shape = inputs.dims, inputs.shape
    out: dict[str, xr.DataArray] = {}
    if "outputs.peak_frequency" in inputs.wanted:
        out["peak_frequency"] = xr.DataArray(
            result.reals[:, tk.PEAK_FREQUENCY].reshape(shape), dims=dims,
            attrs={"units": "Hz", "long_name": "excitation frequency of the sweep when |q| had "
                                               "its largest extremum during the sweep (with a "
                                               "solver.t_end past the sweep's end, "
                                               "peak_amplitude also covers the ring-down after "
                                               "it, and may be larger)"})
    if inputs.bands is not None:
        n = inputs.bands[2]
        out["envelope"] = xr.DataArray(
            result.envelope.reshape(shape + (result.envelope.shape[1],)), dims=dims + (BAND_DIM,),
            attrs={"units": "m", "long_name": f"response envelope: the largest midspan |q| in "
                   f"each 1/{n}-octave band of the excitation frequency",
                   "comment": f"response envelope: the largest |q| at the extrema of q while "
                   f"the sweep's frequency lay in the 1/{n}-octave band",
                   "cell_methods": f"{BAND_DIM}: maximum"})
        from .excitation import band_centres, table_level
        centres = xr.DataArray(band_centres(*inputs.bands), dims=BAND_DIM)
        levels = inputs.params.get("base_levels_g")
        level = (table_level(levels, centres) if levels is not None
                 else derived(coeffs["base_accel"], inputs.coords) * xr.ones_like(centres))
        out["base_level_g"] = (level / STANDARD_GRAVITY).transpose(..., BAND_DIM)
        out["base_level_g"].attrs = {
            "units": G_UNITS, "long_name": f"base acceleration level at the band's centre "
                                           f"frequency, in g ({STANDARD_GRAVITY:g} m s-2)"}
    out.update(derived_variables(coeffs, inputs.coords, _SWEEP_DERIVED))
    return out


def band_coordinates(first: int, count: int, bands_per_octave: int) -> dict[str, xr.DataArray]:
    """The envelope's coordinate: the bands' centre frequencies (Hz) on BAND_DIM, with CF cell
    bounds (their edges) in BAND_DIM_bounds."""
    from .excitation import band_bounds, band_centres
    bounds_name = f"{BAND_DIM}_bounds"
    centre = xr.DataArray(band_centres(first, count, bands_per_octave), dims=BAND_DIM, attrs={
        "units": "Hz", "long_name": f"centre frequency of the base-2 1/{bands_per_octave}-octave "
                                    "band, 1000 x 2^(k/N) Hz", "bounds": bounds_name})
    # CF 7.1: a bounds variable takes its parent's units and long name (xarray writes none)
    edges = xr.DataArray(band_bounds(first, count, bands_per_octave), dims=(BAND_DIM, "nv"))
    return {BAND_DIM: centre, bounds_name: edges}


def state_attrs(swept: bool = False, random: bool = False) -> dict[str, Any]:
    """CF flag attributes of the transverse `state` variable (`swept`: of a swept base
    frequency, whose points complete their sweeps or fail; `random`: of a random base
    acceleration, whose records run to their ends or escape)."""
    if random:
        return {**flag_attrs(km.SWEPT_STATES), "long_name": "response state of the point",
                "comment": "completed: the record ran to its end (a random response has no "
                           "settling to judge); diverged: the span escaped (failure_time says "
                           "when); the failure states have NaN outputs"}
    if swept:
        return {**flag_attrs(km.SWEPT_STATES), "long_name": "response state of the point",
                "comment": "completed: the point ran its whole sweep (a sweep has no settling "
                           "to judge); the failure states have NaN outputs"}
    return {
        **flag_attrs(km.TRANSVERSE_STATES),
        "long_name": "response state of the point",
        "comment": "decayed/steady have a settling time; modulated (beating, quasi-periodic), "
                   "unsettled (still drifting at t_end: lengthen solver.t_end) and the failure "
                   "states have NaN",
    }


def _undamped_unsettled(settling: xr.DataArray, inputs: Inputs) -> xr.DataArray:
    """settling_time with NaN where the span has no damping (damping_ratio 0): an undamped
    response has no transient that settles, so a time would be an artefact of the tolerance
    band (the paper's undamped Eq.32, periodic from t = 0, read 0 s)."""
    undamped = derived(inputs.params["damping_ratio"], inputs.coords) == 0.0
    return settling.where(~undamped).transpose(*settling.dims)


def assemble(inputs: Inputs, coeffs: dict[str, Any], result: KernelResult,
             elapsed: float, records: np.ndarray | None = None) -> xr.Dataset:
    """Build the result Dataset from the flat kernel result: the variables the
    scene asked for (inputs.wanted), with units and long names; the derived closed forms
    (`coeffs`, sweep/models/modal.py) on their own axes; elapsed: the solve's wall time (s).
    A random scene: its records (for the input's realised grms)."""
    coords, dims, shape = inputs.coords, inputs.dims, inputs.shape
    short, method = METHODS[inputs.method]
    data: dict[str, xr.DataArray] = {}
    data["state"] = xr.DataArray(result.states.reshape(shape), dims=dims,
                                 attrs=state_attrs(inputs.swept, inputs.random is not None))
    for name, (col, units, long_name, switch) in _REALS.items():
        if switch is None or switch in inputs.wanted:
            data[name] = xr.DataArray(result.reals[:, col].reshape(shape), dims=dims,
                                      attrs={"units": units, "long_name": long_name})
    if "settling_time" in data:
        data["settling_time"] = _undamped_unsettled(data["settling_time"], inputs)
    if "outputs.solver_stats" in inputs.wanted:
        for name, (col, long_name) in _COUNTS.items():
            data[name] = xr.DataArray(counter(result.counts[:, col].reshape(shape)), dims=dims,
                                      attrs={"units": "1",
                                             "long_name": long_name.format(method=short)})
    data.update(derived_variables(coeffs, coords, _derived_table(coeffs, inputs.has_base)))
    if "resonance_amplification" in coeffs:          # a fixed-frequency sine base
        data["linear_amplitude"] = linear.linear_amplitude(coeffs, inputs.params, inputs.basis,
                                                           inputs.n_modes, coords)
    if result.modal is not None:
        modes = modal_outputs(result.modal, dims, shape, coeffs, coords, inputs.basis,
                              inputs.params)
        if inputs.swept:                 # a sweep's tail window is the whole sweep
            attrs = modes["modal_amplitude"].attrs
            attrs["long_name"] = attrs["long_name"].replace("over the tail window",
                                                            "over the whole sweep")
        # the peaks of the tail window (a sweep's: of the whole sweep) go with the midspan's
        # own switch (loads.peak_switch): the modes' and the span's beside the midspan's
        peaks = loads.peak_switch(inputs.swept) in inputs.wanted
        if not peaks:
            del modes["modal_amplitude"]
        data.update(modes)
        if peaks:
            data.update(span_outputs(result.reals, dims, shape, inputs.swept,
                                     derived(inputs.params["length"], coords)))
    if inputs.settings[tk.LOADS] != 0.0:
        data.update(loads.load_outputs(
            inputs.params, result.reals, result.modal is not None, dims, shape, coords,
            inputs.swept, _one_mode(inputs, coeffs, coords, result.reals, dims, shape)))
    if inputs.random is not None:
        variables, extra = random_outputs.outputs(
            result.reals, result.states, dims, shape, coords, inputs.random, coeffs,
            inputs.params, records, inputs.basis, inputs.n_modes, data)
        data.update(variables)
        coords = {**coords, **extra}
        if result.spectra is not None:
            variables, extra = response_asd.variables(
                result.spectra, result.reduction, dims, shape, REALISATION_DIM,
                derived(coeffs["base_accel"], coords), inputs.random.spectrum,
                STANDARD_GRAVITY, G2_UNITS)
            data.update(variables)
            data.update(random_outputs.linear_spectra(
                inputs.random, coeffs, inputs.params, inputs.basis, inputs.n_modes, coords,
                extra[response_asd.FREQUENCY_DIM]))
            coords = {**coords, **extra}
    elif inputs.has_base and "outputs.absolute_acceleration" in inputs.wanted:
        outputs = base_outputs(result.reals[:, tk.ACCELERATION].reshape(shape), dims,
                               derived(coeffs["base_accel"], coords))
        if inputs.swept and inputs.params.get("base_levels_g") is not None:
            del outputs["transmissibility"]         # no one level to divide by
        data.update(outputs)
    all_coords: dict[str, Any] = dict(coords)
    if inputs.swept:
        data.update(sweep_outputs(result, inputs, coeffs))
        if inputs.bands is not None:
            all_coords.update(band_coordinates(*inputs.bands))
    if result.modal is not None:
        all_coords[MODE_DIM] = xr.DataArray(
            np.arange(1, result.modal.shape[1] + 1, dtype=np.int32), dims=MODE_DIM,
            attrs={"units": "1", "long_name": "Galerkin mode number n (the modes: "
                                              f"{inputs.basis.mode_text})"})
    if result.series.shape[1] > 0:
        all_coords[TIME_DIM] = elapsed_time(result.sample_times)
        data["displacement"] = xr.DataArray(
            result.series.reshape(shape + (result.series.shape[1],)), dims=dims + (TIME_DIM,),
            attrs={"units": "m", "long_name": "midspan deflection q(t)"})
    system = ("transverse modal oscillator" if inputs.n_modes == 1 else
              f"transverse Galerkin model, {inputs.n_modes} coupled modes")
    attrs = global_attrs(inputs.origin, shape, elapsed,
                         f"{system}, {method}, {CONTROLLERS[inputs.controller]}")
    attrs.update(span_attrs(inputs.params))
    return xr.Dataset(data, coords=all_coords, attrs=attrs)


def span_attrs(params: dict[str, Any]) -> dict[str, str]:
    """What the clamps hold, how the span stretches and whose bending terms it takes, in
    words (global attributes `clamps`, `stretching` and `bending`; docs/model.md secs. 7 and
    10), from the parameters by axis name."""
    def value(name: str, units: str) -> str:
        v = params.get(name)
        return f"over the axis {name}" if hasattr(v, "dims") else f"{float(v):g} {units}"
    rotation = params.get("clamps_rotation") or "pinned"
    clamps = {"pinned": "pinned: no deflection and no moment at the clamps, modes sin(n pi x/l)",
              "clamped": "clamped: no deflection and no rotation at the clamps, beam-function "
                         "modes (cos(b l) cosh(b l) = 1)"}.get(rotation)
    if clamps is None:
        clamps = ("elastic: rotational springs at the clamps, k_t "
                  f"{value('clamp_rotational_stiffness', 'N m/rad')} each (K = k_t l / EI)")
    bending = ("from the span's bending energy (EI/2) int w_xx^2 (1 - 3 w_x^2 + 6 w_x^4) dx, "
               "its weak form" if modal.energy_bending(params) else
               "the paper's Eq.17 terms as printed (not the gradient of an energy with several "
               "modes)")
    if params.get("coefficients") == "paper":
        return {"clamps": clamps, "stretching": "the paper's Eq.32 as printed (its numbers hold "
                "the local membrane term with alpha = 3/8)", "bending": bending}
    alpha, k_s = modal.stretching(params)
    if k_s is None:
        stretching = (f"the paper's local membrane term 4 alpha EA w_xx w_x^2, alpha "
                      f"{value('membrane', '')}".rstrip() + " (model.membrane)")
    elif params.get("clamp_axial_stiffness") is None:
        stretching = ("the uniform tension N = k_s e of the span's elongation e = (1/2) int "
                      "w_x^2 dx between immovable clamps, k_s = EA / l")
    else:
        stretching = ("the uniform tension N = k_s e of the span's elongation e = (1/2) int "
                      "w_x^2 dx, 1 / k_s = l / EA + 2 / k_a, clamps of axial stiffness k_a "
                      f"{value('clamp_axial_stiffness', 'N/m')} each (0: no stretching)")
    return {"clamps": clamps, "stretching": stretching, "bending": bending}
