"""The sweep grid: axes as labelled coordinates, parameters as scalars or axis DataArrays."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .models import random_scene
from .models.cable import resolve
from .models.rules import default_inertia
from .scene import Scene
from .scene.points import POINT_DIM
from .schema import BY_AXIS


def coordinates(scene: Scene) -> dict[str, xr.DataArray]:
    """The grid's coordinates, with units and long_name: with [points], first the `point`
    dimension (0, 1, ...) and one coordinate on it per [points] key (its values, so
    ``ds.length`` gives each point's length); then one 1-D coordinate per axis, in scene
    order. `dimensions` picks the dimension coordinates out."""
    coords = {}
    if scene.points:
        count = len(next(iter(scene.points.values())))
        names = ", ".join(scene.points)
        coords[POINT_DIM] = xr.DataArray(
            np.arange(count, dtype=np.int32), dims=POINT_DIM,
            attrs={"units": "1", "long_name": f"parameter set (entry of the scene's [points]: "
                                              f"{names})"})
        for name, values in scene.points.items():
            key = BY_AXIS[name]
            coords[name] = xr.DataArray(np.asarray(values, dtype=float), dims=POINT_DIM,
                                        attrs={"units": key.units, "long_name": key.long_name})
    for name, values in scene.axes.items():
        key = BY_AXIS[name]
        coords[name] = xr.DataArray(np.asarray(values, dtype=float), dims=name,
                                    attrs={"units": key.units, "long_name": key.long_name})
    if random_scene.is_random(scene.values):        # last: the records every point sees
        coords[random_scene.REALISATION_DIM] = xr.DataArray(
            np.arange(scene.get("base.realisations"), dtype=np.int32),
            dims=random_scene.REALISATION_DIM,
            attrs={"units": "1", "long_name": "realisation: which record of the random base "
                                              "acceleration (the same records at every point)"})
    return coords


def dimensions(coords: dict[str, xr.DataArray]) -> tuple[str, ...]:
    """The grid's dimensions, in order: the names of `coords` that are dimension coordinates
    (the point dimension and the axes, not the [points] values on it)."""
    return tuple(name for name, c in coords.items() if c.dims == (name,))


def parameters(scene: Scene, coords: dict[str, xr.DataArray]) -> dict[str, Any]:
    """Every model parameter by axis name: the axis coordinate if swept, else the scalar."""
    params: dict[str, Any] = {}
    for name, key in BY_AXIS.items():
        params[name] = coords[name] if name in coords else scene.get(key.dotted)
    params = resolve(params, scene.values)      # a data-sheet cable: its equivalent material
    if params["inertia"] is None:                 # not given, area swept: follows the area
        params["inertia"] = default_inertia(params["area"])
    params["coefficients"] = scene.get("model.coefficients")
    params["paper_parametric"] = scene.get("model.paper_parametric")
    params["load_type"] = scene.get("load.type")
    params["clamps_rotation"] = scene.get("clamps.rotation")
    params["divergence_bound"] = scene.get("metrics.divergence_bound")
    params["base_levels_g"] = scene.get("base.levels_g")
    params["base_sweep_ramp_cycles"] = scene.get("base.sweep.ramp_cycles")
    params.update(random_parameters(scene.values, coords))
    if params["load_type"] == "constant":      # no frequency axis: refused by load_scene
        params["frequency"] = None
    if params.get("load_ratio") is not None:    # P0 as a multiple of the span's own Pcr
        from .models.modal import load_from_ratio
        load_from_ratio(params)
    return params


def random_parameters(values: dict[str, Any], coords: dict[str, xr.DataArray]
                      ) -> dict[str, Any]:
    """A random scene's parameters (None where the scene is not random): base_asd, its
    spectrum as (f in Hz, W in (m/s^2)^2/Hz) breakpoints; base_sample_rate (Hz); realisation,
    the record each point follows (on the realisation dimension); statistics_tolerance, the
    decay (metrics.tolerance) after which a point's statistics start; base_ramp (s), the
    records' level rise (base.ramp, 0: none); record_t_end (s), the run's end."""
    key = random_scene.spectrum_key(values)
    if key is None:
        return {"base_asd": None, "base_sample_rate": None, "realisation": None,
                "statistics_tolerance": None, "base_ramp": None, "record_t_end": None}
    from .models.random import spectrum
    return {"base_asd": spectrum(values[key], key=key, per_g2=key == "base.asd_g2"),
            "base_sample_rate": random_scene.sample_rate(values),
            "realisation": coords[random_scene.REALISATION_DIM].astype(float),
            "statistics_tolerance": values["metrics.tolerance"],
            "base_ramp": random_scene.ramp_time(values),
            "record_t_end": float(values["solver.t_end"])}


def flatten(values: dict[str, Any], names: tuple[str, ...], dims: tuple[str, ...],
            shape: tuple[int, ...]) -> np.ndarray:
    """Stack the named values, broadcast to the full grid (dims in order), as rows (n, len(names))."""
    n = int(np.prod(shape, dtype=np.int64))
    table = np.empty((n, len(names)))
    for j, name in enumerate(names):
        value = values[name]
        if isinstance(value, xr.DataArray):
            value = value.transpose(*[d for d in dims if d in value.dims])
            expanded = value.values.reshape([shape[i] if d in value.dims else 1
                                             for i, d in enumerate(dims)])
            table[:, j] = np.broadcast_to(expanded, shape).reshape(n)
        else:
            table[:, j] = float(value)
    return table


def point_values(params: dict[str, Any], dims: tuple[str, ...], shape: tuple[int, ...],
                 points: np.ndarray) -> dict[str, Any]:
    """The parameters at grid points `points` (flat C-order indices): each axis coordinate
    (or a parameter over several axes, as a load given as a ratio of each span's buckling
    load) replaced by its values at those points, scalars kept."""
    if not shape:
        return dict(params)                      # no axes: one point, all scalars
    index = np.unravel_index(points, shape)
    return {name: value.values[tuple(index[dims.index(d)] for d in value.dims)]
            if isinstance(value, xr.DataArray) else value
            for name, value in params.items()}


def rows(values: dict[str, Any], names: tuple[str, ...], m: int) -> np.ndarray:
    """The named values (scalars or length-m arrays) as m parameter rows, C-contiguous."""
    table = np.empty((m, len(names)))
    for j, name in enumerate(names):
        table[:, j] = values[name]
    return table
