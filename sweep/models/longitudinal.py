"""The longitudinal model: cable data -> central-difference kernel over every span -> Dataset.

The span is fixed at x = 0 and loaded by a constant compressive force P0 at x = l from t = 0
(docs/model.md sec. 4). Exact facts the outputs can be read against: the front travels at
a = sqrt(E/rho); the loaded end moves in a triangle wave of peak 2 P0 l/EA and period 4 l/a;
the fixed-end force is a square wave between 0 and 2 P0 (dynamic amplification 2).
Sign convention: tension positive, so the compressive forces here are negative.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from .. import grid
from ..dataset import (TIME_DIM, Provenance, counter, derived, elapsed_time, flag_attrs,
                       global_attrs, provenance)
from ..errors import CableSweepWarning
from ..execute import longitudinal_chunk, longitudinal_outputs
from ..runner import RunOptions, check_memory, solve_chunked
from ..scene import Scene
from .wave import wave_parameters

KIND = "longitudinal"



_DERIVED = {
    "wave_speed": ("m s-1", "longitudinal wave speed a = sqrt(E/rho)"),
    "transit_time": ("s", "time for the front to cross the span, l/a"),
    "static_end_displacement": ("m", "static end displacement P0 l/EA"),
}


@dataclass(frozen=True)
class Inputs:
    """A longitudinal scene resolved once (`resolve`); nothing after it reads the scene.

    coords, dims, shape, params: the grid and its parameters (grid.coordinates, .parameters);
    intervals, courant: solver.intervals, solver.courant; t_end (s) or transits (in l/a):
    the end time; max_levels: solver.max_steps; snapshot_times (s); histories, normalised:
    the outputs.* switches; sample_interval (s, or None: t_end/1000); origin: provenance.
    """
    coords: dict[str, xr.DataArray]
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    params: dict[str, Any]
    intervals: int
    courant: float
    t_end: float | None
    transits: float | None
    max_levels: int
    snapshot_times: np.ndarray
    histories: bool
    normalised: bool
    sample_interval: float | None
    origin: Provenance


def resolve(scene: Scene) -> Inputs:
    """The Inputs of a longitudinal scene: the only place this model reads it."""
    coords = grid.coordinates(scene)
    dims = grid.dimensions(coords)
    times = scene.get("outputs.snapshot_times")
    return Inputs(coords=coords, dims=dims, shape=tuple(coords[d].size for d in dims),
                  params=grid.parameters(scene, coords),
                  intervals=int(scene.get("solver.intervals")),
                  courant=float(scene.get("solver.courant")), t_end=scene.get("solver.t_end"),
                  transits=scene.get("solver.transits"),
                  max_levels=scene.get("solver.max_steps"),
                  snapshot_times=np.asarray(times if times is not None else (), dtype=float),
                  histories=bool(scene.get("outputs.histories")),
                  normalised=bool(scene.get("outputs.normalised")),
                  sample_interval=scene.get("outputs.sample_interval"),
                  origin=provenance(scene))


def _warn_courant(courant: float) -> None:
    if courant < 1.0:
        warnings.warn(f"solver.courant = {courant:g} < 1: the central difference is dispersive "
                      "there, so fronts ring and the peaks overshoot (the fixed-end force's peak "
                      "by 10-30 % of the exact 2 P0 at C = 0.5-0.999, more intervals do not "
                      "shrink it: the ringing narrows, it does not fade); 1.0 is exact at the "
                      "nodes", CableSweepWarning, stacklevel=3)


def _working_bytes(n_spans: int, n_intervals: int, options: RunOptions) -> float:
    """Bytes of the kernel's working arrays: three time levels of n_intervals + 1 nodes for
    each span solved at once (one a thread: sweep.threads.thread_count)."""
    from ..threads import thread_count
    return 3.0 * 8.0 * (n_intervals + 1) * min(max(n_spans, 1), thread_count(options.threads))


def run(scene: Scene, options: RunOptions) -> xr.Dataset:
    """The longitudinal (central-difference) sweep of `scene` as a Dataset, run as `options`
    say: the model's entry point (sweep.models.model_for)."""
    from sweep.kernels import wave_layout as lk

    inputs = resolve(scene)
    coords, dims, shape = inputs.coords, inputs.dims, inputs.shape
    n = int(np.prod(shape, dtype=np.int64))
    n_int = inputs.intervals
    courant = inputs.courant
    snap_times = inputs.snapshot_times
    n_snap = snap_times.size
    fields = 5 if inputs.normalised else 3
    # The scheme's three time levels of n_int + 1 nodes, for each span being solved at once
    working = _working_bytes(n, n_int, options)
    working_what = f"the scheme's three time levels of {n_int + 1:,} nodes a span"
    fix = "use fewer solver.intervals, fewer axis values, or store fewer snapshots"
    # Histories need the longest end time; check the snapshots' size before that.
    check_memory(n, 3.0 * 8 * (lk.N_PARAMS + lk.N_REALS + 1 + fields * n_snap * (n_int + 1)),
                 "parameters, metrics and snapshots", working=working,
                 working_what=working_what, fix=fix)
    waves = wave_parameters(inputs.params, inputs.t_end, inputs.transits)
    table = grid.flatten(waves, lk.PARAM_NAMES, dims, shape)
    _warn_courant(courant)
    t_max = float(np.max(table[:, lk.T_END])) if n else 0.0
    dt_sample = inputs.sample_interval or t_max / 1000.0
    n_hist = int(math.floor(t_max / dt_sample + 1e-9)) + 1 if inputs.histories else 0
    check_memory(n, 3.0 * 8 * (lk.N_PARAMS + lk.N_REALS + 1 + 2 * n_hist
                               + fields * n_snap * (n_int + 1)),
                 "parameters, metrics, histories and snapshots", working=working,
                 working_what=working_what, fix=fix)
    settings = np.zeros(lk.N_SETTINGS)
    settings[lk.INTERVALS] = n_int
    settings[lk.COURANT] = courant
    settings[lk.SAMPLE_DT] = dt_sample
    settings[lk.MAX_LEVELS] = inputs.max_levels

    started = time.perf_counter()
    n_nodes = n_int + 1
    out = solve_chunked(options, longitudinal_chunk, lambda points: table[points],
                        (settings, snap_times, n_hist, n_nodes),
                        longitudinal_outputs(n, n_hist, n_snap, n_nodes))
    elapsed = time.perf_counter() - started
    states, reals, steps, hist_u, hist_f = (out[k] for k in ("states", "reals", "steps",
                                                              "hist_u", "hist_f"))
    snaps = [out["snap_u"], out["snap_f"], out["snap_v"]]

    def field(values: np.ndarray) -> np.ndarray:
        return values.reshape(shape + values.shape[1:])

    data: dict[str, xr.DataArray] = {}
    data["state"] = xr.DataArray(field(states), dims=dims, attrs={
        **flag_attrs(lk.STATES),
        "comment": "diverged: non-finite values or |u(l)| beyond metrics.divergence_bound; "
                   "max_steps_reached: the span needed more than solver.max_steps time levels "
                   "(its metrics cover the levels it took)"})

    def scalar(name: str, values: np.ndarray, units: str, long_name: str) -> None:
        data[name] = xr.DataArray(field(values), dims=dims,
                                  attrs={"units": units, "long_name": long_name})

    r = reals
    scalar("peak_end_displacement", r[:, lk.PEAK_END_DISPLACEMENT], "m",
           "max |u(l, t)|, the loaded end's peak displacement")
    scalar("peak_fixed_end_force", r[:, lk.PEAK_FIXED_END_FORCE], "N",
           "max |N(0, t)|, the peak axial force at the fixed end")
    static = table[:, lk.LOAD] * table[:, lk.LENGTH] / table[:, lk.AXIAL_STIFFNESS]
    with np.errstate(divide="ignore", invalid="ignore"):
        scalar("dynamic_amplification", r[:, lk.PEAK_END_DISPLACEMENT] / np.abs(static), "1",
               "peak end displacement over the static one, P0 l/EA (exact: 2)")
        scalar("force_amplification", r[:, lk.PEAK_FIXED_END_FORCE] / np.abs(table[:, lk.LOAD]),
               "1", "peak fixed-end force over P0 (exact: 2; below solver.courant = 1 the "
               "scheme's ringing overshoots it)")
    scalar("arrival_time", r[:, lk.ARRIVAL_TIME], "s",
           "first time |N(0, t)| reaches |P0| (half the 2 P0 step; exact: l/a)")
    scalar("period", r[:, lk.PERIOD], "s",
           "mean time between successive arrivals at the fixed end (exact: 4 l/a)")
    scalar("failure_time", r[:, lk.FAILURE_TIME], "s",
           "time at which a diverged or step-limited span stopped")
    scalar("time_step", r[:, lk.TIME_STEP], "s", "time step dt = C dx / a")
    scalar("n_steps", counter(steps), "1", "time steps taken")
    data["courant"] = xr.DataArray(courant, attrs={"units": "1",
                                                   "long_name": "Courant number a dt/dx"})
    for name, (units, long_name) in _DERIVED.items():
        data[name] = derived(waves[name], coords)
        data[name].attrs = {"units": units, "long_name": long_name}

    all_coords: dict[str, Any] = dict(coords)
    if n_hist:
        all_coords[TIME_DIM] = elapsed_time(np.arange(n_hist) * dt_sample)
        data["end_displacement"] = xr.DataArray(
            field(hist_u), dims=dims + (TIME_DIM,),
            attrs={"units": "m", "long_name": "displacement of the loaded end u(l, t)"})
        data["fixed_end_force"] = xr.DataArray(
            field(hist_f), dims=dims + (TIME_DIM,),
            attrs={"units": "N", "long_name": "axial force at the fixed end N(0, t), "
                                              "tension positive"})
    if n_snap:
        all_coords["snapshot_time"] = xr.DataArray(
            snap_times, dims="snapshot_time",
            attrs={"units": "s", "long_name": "requested snapshot time (the nearest time "
                                              "level is stored)"})
        all_coords["position"] = xr.DataArray(
            np.arange(n_int + 1) / n_int, dims="position",
            attrs={"units": "1", "long_name": "position along the span x/l, fixed end at 0"})
        sdims = dims + ("snapshot_time", "position")
        names = (("snapshot_displacement", "m", "displacement u(x)"),
                 ("snapshot_force", "N", "axial force N(x) = EA u_x, tension positive"),
                 ("snapshot_velocity", "m s-1", "velocity u_t(x)"))
        for (name, units, long_name), values in zip(names, snaps):
            data[name] = xr.DataArray(field(values), dims=sdims,
                                      attrs={"units": units, "long_name": long_name})
        if inputs.normalised:
            load = xr.DataArray(field(table[:, lk.LOAD]), dims=dims)
            impedance = grid.flatten(waves, ("impedance",), dims, shape)[:, 0]
            impedance = xr.DataArray(field(impedance), dims=dims)
            data["snapshot_force_ratio"] = (data["snapshot_force"] / load).assign_attrs(
                units="1", long_name="axial force over the end load, N/P0")
            data["snapshot_velocity_ratio"] = (
                data["snapshot_velocity"] * impedance / load).assign_attrs(
                units="1", long_name="velocity in units of P0/(rho A a), v rho A a / P0")
    attrs = global_attrs(inputs.origin, shape, elapsed, "longitudinal wave, explicit central "
                                                "difference (Eq.38) with a ghost-node force end")
    return xr.Dataset(data, coords=all_coords, attrs=attrs)

