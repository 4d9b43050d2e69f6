"""Result Dataset assembly: labelled dims in scene order, CF attributes, units everywhere."""

from __future__ import annotations

import datetime as _dt
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from sweep.kernels import metrics as km
from sweep.kernels import transverse as tk

from .scene import Scene
from .schema import BY_AXIS, G_UNITS, STANDARD_GRAVITY
from .version import package_version  # noqa: F401  (re-exported: the version written into results)

if TYPE_CHECKING:
    from .run import KernelResult

CONVENTIONS = "CF-1.11"

# name -> (kernel column, units, long_name, scene output switch)
_REALS = {
    "amplitude": (tk.AMPLITUDE, "m", "max |q| over the tail window (midspan deflection)",
                  "outputs.amplitude"),
    "peak_amplitude": (tk.PEAK, "m", "max |q| over the whole run (overshoot)",
                       "outputs.peak_amplitude"),
    "settling_time": (tk.SETTLING, "s", "time after which every envelope peak stays within "
                      "+-tolerance of its final level (decayed: last time |q| > tolerance * peak)",
                      "outputs.settling_time"),
    "response_period": (tk.PERIOD, "s", "mean time between maxima of q in the tail window",
                        "outputs.response_period"),
    "failure_time": (tk.FAILURE_TIME, "s", "time at which a diverged or failed point stopped",
                     None),
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
_INT32 = np.iinfo(np.int32)
TIME_DIM = "elapsed_time"       # the dimension (and coordinate) of stored histories
_DERIVED = {
    "natural_frequency": ("Hz", "first linear natural frequency of the unloaded span"),
    "buckling_load": ("N", "Euler buckling load of the span (paper: implied by Eq.32)"),
    "load_ratio": ("1", "load amplitude over buckling load, P0/Pcr"),
    "load_frequency": ("Hz", "load frequency W/(2 pi)"),
    "escape_barrier": ("m", "|q| beyond which the softening quintic lets the span escape, "
                            "for the mean (harmonic) or constant load; NaN: no barrier, or one "
                            "beyond the model's range (mode slope pi q_b / l > 1)"),
}
# Scenes with [base] (docs/model.md sec. 5): the excitation in both spellings (each stored
# only where it is not an axis: then the axis is its coordinate) and closed forms.
_BASE_DERIVED = {
    **{axis: (BY_AXIS[axis].units, BY_AXIS[axis].long_name)
       for axis in ("base_acceleration", "base_acceleration_g", "base_frequency",
                    "base_frequency_ratio")},
    "linear_amplitude": ("m", "steady midspan amplitude of the linearised span (no load, "
                              "K3 = K5 = 0), (4/pi) A / sqrt((w1^2 - w^2)^2 + (2 zeta w1 w)^2); "
                              "NaN: unbounded (undamped at resonance)"),
    "resonance_amplification": ("1", "linear resonance amplification Q = 1/(2 zeta): peak "
                                     "amplitude over the quasi-static (4/pi) A / w1^2; NaN: "
                                     "undamped"),
}



def counter(values: Any) -> Any:
    """A count as int32 (what every netCDF reader takes) when every value fits, else int64."""
    values = np.asarray(values)
    if values.size == 0 or (values.min() >= _INT32.min and values.max() <= _INT32.max):
        return values.astype(np.int32)
    return values.astype(np.int64)


def elapsed_time(values: np.ndarray) -> xr.DataArray:
    """The coordinate TIME_DIM of stored histories: times since the start of the run (s).

    Not CF's `time`: a CF time coordinate (standard_name time, and the name `time` to the IOOS
    compliance checker) needs units "s since <date>", and these are durations from the
    simulation's t = 0, which has no date.
    """
    return xr.DataArray(values, dims=TIME_DIM, attrs={
        "units": "s", "long_name": "simulated time since t = 0 (the initial state)"})


def derived(values: Any, coords: dict[str, xr.DataArray]) -> xr.DataArray:
    """A derived quantity as a DataArray over exactly the axes it depends on."""
    if isinstance(values, xr.DataArray):
        dims = [d for d in coords if d in values.dims]
        return values.transpose(*dims).drop_vars(list(values.coords), errors="ignore")
    return xr.DataArray(float(values))


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
    return {"absolute_acceleration": absolute, "absolute_acceleration_g": in_g,
            "transmissibility": ratio}


def global_attrs(scene: Scene, shape: tuple[int, ...], elapsed: float,
                 method: str) -> dict[str, Any]:
    """The dataset's global attributes: CF conventions, provenance and the resolved scene."""
    version = package_version()
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "title": scene.name,
        "description": scene.description,
        "Conventions": CONVENTIONS,
        "source": f"cable-sweep {version}: {method}",
        "history": f"{now} created by cable-sweep {version} from scene '{scene.source}'",
        "cable_sweep_version": version,
        "scene": scene.to_toml(),
        "model_kind": scene.get("model.kind"),
        "coefficients": scene.get("model.coefficients"),
        "run_seconds": float(elapsed),
        "n_points": counter(np.prod(shape, dtype=np.int64))[()],
    }


def flag_attrs(flags: tuple[int, ...]) -> dict[str, Any]:
    """CF flag attributes of an int8 `state` variable that can hold the given flags.

    Every kind draws its flags from the one table of kernels/metrics.py (STATE_MEANINGS), so
    the same integer has the same meaning in every dataset.
    """
    return {
        "long_name": "state of the point",
        "units": "1",
        "flag_values": np.array(flags, dtype=np.int8),
        "flag_meanings": " ".join(km.STATE_MEANINGS[f] for f in flags),
    }


def state_attrs() -> dict[str, Any]:
    """CF flag attributes of the transverse `state` variable."""
    return {
        **flag_attrs(km.TRANSVERSE_STATES),
        "long_name": "response state of the point",
        "comment": "decayed/steady have a settling time; modulated (beating, quasi-periodic), "
                   "unsettled (still drifting at t_end: lengthen solver.t_end) and the failure "
                   "states have NaN",
    }


def assemble(scene: Scene, coords: dict[str, xr.DataArray], shape: tuple[int, ...],
             coeffs: dict[str, Any], result: "KernelResult", elapsed: float) -> xr.Dataset:
    """Build the result Dataset of the contract from the flat kernel result."""
    dims = tuple(coords)
    short, method = METHODS[scene.get("solver.method")]
    data: dict[str, xr.DataArray] = {}
    data["state"] = xr.DataArray(result.states.reshape(shape), dims=dims, attrs=state_attrs())
    for name, (col, units, long_name, switch) in _REALS.items():
        if switch is None or scene.get(switch):
            data[name] = xr.DataArray(result.reals[:, col].reshape(shape), dims=dims,
                                      attrs={"units": units, "long_name": long_name})
    if scene.get("outputs.solver_stats"):
        for name, (col, long_name) in _COUNTS.items():
            data[name] = xr.DataArray(counter(result.counts[:, col].reshape(shape)), dims=dims,
                                      attrs={"units": "1",
                                             "long_name": long_name.format(method=short)})
    for name, (units, long_name) in (_DERIVED | (_BASE_DERIVED if scene.has_base else {})
                                     ).items():
        if name in coeffs and name not in coords:
            data[name] = derived(coeffs[name], coords)
            data[name].attrs = {"units": units, "long_name": long_name}
    if scene.has_base and scene.get("outputs.absolute_acceleration"):
        data.update(base_outputs(result.reals[:, tk.ACCELERATION].reshape(shape), dims,
                                 derived(coeffs["base_accel"], coords)))
    all_coords: dict[str, Any] = dict(coords)
    if result.series.shape[1] > 0:
        all_coords[TIME_DIM] = elapsed_time(result.sample_times)
        data["displacement"] = xr.DataArray(
            result.series.reshape(shape + (result.series.shape[1],)), dims=dims + (TIME_DIM,),
            attrs={"units": "m", "long_name": "midspan deflection q(t)"})
    attrs = global_attrs(scene, shape, elapsed,
                         f"transverse modal oscillator, {method}, "
                         f"{CONTROLLERS[scene.get('solver.controller')]}")
    return xr.Dataset(data, coords=all_coords, attrs=attrs)
