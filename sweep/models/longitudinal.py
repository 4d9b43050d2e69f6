"""The longitudinal model: cable data -> central-difference kernel over every span -> Dataset.

The span is fixed at x = 0 and loaded by a constant compressive force P0 at x = l from t = 0
(docs/model.md sec. 4). Exact facts the outputs can be read against: the front travels at
a = sqrt(E/rho); the loaded end moves in a triangle wave of peak 2 P0 l/EA and period 4 l/a;
the fixed-end force is a square wave between 0 and 2 P0 (dynamic amplification 2).
Sign convention: tension positive, so the compressive forces here are negative.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from typing import Any

import numpy as np
import xarray as xr

from .. import grid
from ..dataset import TIME_DIM, counter, derived, elapsed_time, flag_attrs, global_attrs
from ..errors import CableSweepWarning
from ..execute import longitudinal_chunk, longitudinal_outputs
from ..runner import check_memory, solve_chunked
from ..scene import Scene
from .wave import wave_parameters

KIND = "longitudinal"



_DERIVED = {
    "wave_speed": ("m s-1", "longitudinal wave speed a = sqrt(E/rho)"),
    "transit_time": ("s", "time for the front to cross the span, l/a"),
    "static_end_displacement": ("m", "static end displacement P0 l/EA"),
}


def _snapshot_times(scene: Scene) -> np.ndarray:
    times = scene.get("outputs.snapshot_times")
    return np.asarray(times if times is not None else (), dtype=float)


def _warn_courant(courant: float) -> None:
    if courant < 1.0:
        warnings.warn(f"solver.courant = {courant:g} < 1: the central difference is dispersive "
                      "there, so fronts will ring (1.0 is exact at the nodes)",
                      CableSweepWarning, stacklevel=3)


def run_longitudinal(scene: Scene, threads: int = 0, progress: bool = False,
                     output: str | os.PathLike | None = None, resume: bool = False,
                     overwrite: bool = False, scheduler: str | None = None) -> xr.Dataset:
    """The longitudinal (central-difference) sweep of `scene` as a Dataset."""
    from sweep.kernels import wave_layout as lk

    coords = grid.coordinates(scene)
    dims = tuple(coords)
    shape = tuple(coords[d].size for d in dims)
    n = int(np.prod(shape, dtype=np.int64))
    n_int = int(scene.get("solver.intervals"))
    courant = float(scene.get("solver.courant"))
    snap_times = _snapshot_times(scene)
    n_snap = snap_times.size
    fields = 5 if scene.get("outputs.normalised") else 3
    # Histories need the longest end time; check the snapshots' size before that.
    check_memory(n, 3.0 * 8 * (lk.N_PARAMS + lk.N_REALS + 1 + fields * n_snap * (n_int + 1)),
                 "parameters, metrics and snapshots")
    params = grid.parameters(scene, coords)
    waves = wave_parameters(params, scene.get("solver.t_end"), scene.get("solver.transits"))
    table = grid.flatten(waves, lk.PARAM_NAMES, dims, shape)
    _warn_courant(courant)
    t_max = float(np.max(table[:, lk.T_END])) if n else 0.0
    dt_sample = scene.get("outputs.sample_interval") or t_max / 1000.0
    n_hist = int(math.floor(t_max / dt_sample + 1e-9)) + 1 if scene.get("outputs.histories") else 0
    check_memory(n, 3.0 * 8 * (lk.N_PARAMS + lk.N_REALS + 1 + 2 * n_hist
                               + fields * n_snap * (n_int + 1)),
                 "parameters, metrics, histories and snapshots")
    settings = np.zeros(lk.N_SETTINGS)
    settings[lk.INTERVALS] = n_int
    settings[lk.COURANT] = courant
    settings[lk.SAMPLE_DT] = dt_sample
    settings[lk.MAX_LEVELS] = scene.get("solver.max_steps")

    started = time.perf_counter()
    n_nodes = n_int + 1
    out = solve_chunked(scene, longitudinal_chunk, lambda points: table[points],
                        (settings, snap_times, n_hist, n_nodes),
                        longitudinal_outputs(n, n_hist, n_snap, n_nodes),
                        output=output, resume=resume, overwrite=overwrite, threads=threads,
                        progress=progress, scheduler=scheduler)
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
               "1", "peak fixed-end force over P0 (exact: 2)")
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
        if scene.get("outputs.normalised"):
            load = xr.DataArray(field(table[:, lk.LOAD]), dims=dims)
            impedance = grid.flatten(waves, ("impedance",), dims, shape)[:, 0]
            impedance = xr.DataArray(field(impedance), dims=dims)
            data["snapshot_force_ratio"] = (data["snapshot_force"] / load).assign_attrs(
                units="1", long_name="axial force over the end load, N/P0")
            data["snapshot_velocity_ratio"] = (
                data["snapshot_velocity"] * impedance / load).assign_attrs(
                units="1", long_name="velocity in units of P0/(rho A a), v rho A a / P0")
    attrs = global_attrs(scene, shape, elapsed, "longitudinal wave, explicit central "
                                                "difference (Eq.38) with a ghost-node force end")
    return xr.Dataset(data, coords=all_coords, attrs=attrs)


def run(scene: Scene, *, threads: int = 0, progress: bool = False,
        output: str | os.PathLike | None = None, resume: bool = False, overwrite: bool = False,
        scheduler: str | None = None) -> xr.Dataset:
    """The model's entry point (sweep.models.model_for): `run_longitudinal`."""
    return run_longitudinal(scene, threads=threads, progress=progress, output=output,
                            resume=resume, overwrite=overwrite, scheduler=scheduler)
