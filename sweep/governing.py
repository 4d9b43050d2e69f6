"""The clamp spacing under several results at once: a launch's sine and random tests.

A harness span must pass every test of its load case, each its own result (a sine sweep, a
random test, a resonant dwell). `governing_span(results, **criteria)` asks each result the
criteria it holds the variables of (`sweep.design.max_span`: --min-frequency of every
transverse result, --max-rms, --max-peak and --clearance of a random one, --max-amplitude,
--max-deflection and --max-strain of a sine one, never of a random one), and keeps,
for every combination of the results' other axes, the shortest of their spans, `limited_by`
the criterion that binds there and `limited_in` the result it binds in. Every criterion must
apply to some result, and every result must have a criterion that applies to it; axes the
results share must hold the same values (an axis only one of them has spreads over the
others, whose spans do not vary along it). Results whose stored scenes describe different spans
(the cable's mass, rigidities and damping, the clamps: `_check_same_span`) are warned of in one
line.
"""

from __future__ import annotations

import datetime
from typing import Any, Sequence

import numpy as np
import xarray as xr

from .design import (BINDING, DIRECTION, GRID_SPAN_COMMENT, NO_CRITERION, SPAN_LONG_NAME,
                     Limit, check_result, max_span, over_axes, reduce_over, validated,
                     with_binding_direction)
from .errors import UserError

CRITERIA = ("min_frequency", "max_amplitude", "max_deflection", "max_strain", "max_rms",
            "max_peak", "clearance")
"""The criteria a result may or may not hold the variables of (sweep.design's limits)."""


def _criterion(name: str, criteria: dict[str, Any]) -> dict[str, Any]:
    """The keyword arguments of max_span for criterion `name` alone (with its companion:
    --quantity for --max-amplitude, --max-probability for --clearance)."""
    one = {name: criteria[name]}
    if name == "max_amplitude" and criteria.get("quantity") is not None:
        one["quantity"] = criteria["quantity"]
    if name == "clearance" and criteria.get("max_probability") is not None:
        one["max_probability"] = criteria["max_probability"]
    return one


def _applies(ds: xr.Dataset, one: dict[str, Any]) -> str | None:
    """None where max_span can answer the criterion `one` on `ds`, else its one-line reason
    (sweep.design.validated: its checks, without the answer)."""
    try:
        validated(ds, **one)
    except UserError as exc:
        return str(exc)
    return None


def governing_span(results: Sequence[tuple[str, xr.Dataset]], *,
                   min_frequency: Limit = None, max_amplitude: Limit = None,
                   quantity: str | None = None, max_deflection: Limit = None,
                   max_strain: Limit = None, max_rms: Limit = None,
                   max_peak: Limit = None, clearance: Limit = None,
                   max_probability: float | None = None,
                   over: str | Sequence[str] = ()) -> xr.Dataset:
    """The largest span between clamps (m) that meets every criterion in every result it
    applies to: `max_span` of each (name, result) pair with its own criteria, the shortest
    over the results at each combination of their other axes. Returns a Dataset with
    `max_span`, `limited_by` (sweep.design.LIMITED_BY) and `limited_in` (the binding
    result's name); attributes `criteria` (each result's) and `results`. A NaN span (a
    result's shortest length fails) wins over any other. `over` (axes of any of the results,
    direction too) takes the governing span over them as sweep.design.max_span does
    (`reduce_over`), binding_<axis> naming where it binds (binding_direction: in the result
    it binds in, empty where that one has no direction).

    Raises UserError (one line): no criterion, a criterion no result holds the variables of
    (its reason in the first result), a result no criterion applies to, axes the results
    share with different values.
    """
    criteria = dict(min_frequency=min_frequency, max_amplitude=max_amplitude,
                    quantity=quantity, max_deflection=max_deflection, max_strain=max_strain,
                    max_rms=max_rms, max_peak=max_peak, clearance=clearance,
                    max_probability=max_probability)
    given = [c for c in CRITERIA if criteria[c] is not None]
    if not given:
        raise UserError(NO_CRITERION)
    if (isinstance(results, (str, xr.Dataset)) or not results
            or not all(isinstance(r, (tuple, list)) and len(r) == 2
                       and isinstance(r[1], xr.Dataset) for r in results)):
        raise UserError("governing_span: results must be (name, Dataset) pairs, e.g. "
                        "[('qual.nc', ds_sine), ('gevs.nc', ds_random)] (open a file with "
                        "sweep.plot.load_result)")
    names = [name for name, _ in results]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UserError(f"design: result '{twice[0]}' given twice (give each result once)")
    axes = [check_result(ds, name) for name, ds in results]
    over = over_axes(over, list(dict.fromkeys(a for each in axes for a in each)),
                     "any of the results")
    _check_same_span(results)
    asked: list[dict[str, Any]] = [{} for _ in results]
    refused: list[str] = ["" for _ in results]       # each result's first reason, in words
    for c in given:
        one = _criterion(c, criteria)
        reasons = [_applies(ds, one) for _, ds in results]
        if all(r is not None for r in reasons):
            raise UserError(f"{reasons[0]} (nor does any other result given)")
        for i, reason in enumerate(reasons):
            if reason is None:
                asked[i].update(one)
            elif not refused[i]:
                refused[i] = reason.removeprefix("design: ")
    spans = []
    for (name, ds), own, why in zip(results, asked, refused):
        if not own:
            raise UserError(f"design: result '{name}': none of the criteria given applies to "
                            f"it ({why}; or leave it out)")
        span = max_span(ds, **own)
        if DIRECTION in over and DIRECTION in ds.dims:
            span = with_binding_direction(ds, span, own)
        spans.append(span)
    shortest = _shortest(spans, names)
    return reduce_over(shortest, over) if over else shortest


SPAN = (("linear_mass", "kg/m"), ("bending_rigidity", "N m^2"), ("axial_rigidity", "N"),
        ("damping_ratio", "1"), ("clamps_rotation", ""), ("clamp_rotational_stiffness", "N m/rad"),
        ("clamp_axial_stiffness", "N/m"))
"""What makes two results the same span (its cable and its clamps, whatever the spelling:
a data sheet's or the material's), compared by `_check_same_span`."""


def _span_of(ds: xr.Dataset) -> dict[str, Any] | None:
    """The span a result describes, from its stored scene: SPAN's quantities, each a number, a
    string or a DataArray over the axes or the [points] dimension it varies on; None for a
    result without a readable scene (an old or hand-made file: not compared)."""
    from . import grid
    from .scene import load_scene_text
    text = ds.attrs.get("scene")
    if not isinstance(text, str) or not text.strip():
        return None
    try:
        scene = load_scene_text(text, source="the result's scene")
        p = grid.parameters(scene, grid.coordinates(scene))
    except Exception:                     # a scene this version cannot read: not compared
        return None
    span = {"linear_mass": p["density"] * p["area"],
            "bending_rigidity": p["youngs_modulus"] * p["inertia"],
            "axial_rigidity": p["youngs_modulus"] * p["area"]}
    span.update({name: p.get(name) for name, _ in SPAN[3:]})
    return span


def _differs(a: Any, b: Any) -> Any:
    """Where two span quantities differ (a bool or a boolean DataArray, broadcast): numbers
    beyond 1e-9 relative, None against a value, strings unequal."""
    if a is None or b is None:
        return (a is None) != (b is None)
    if isinstance(a, str) or isinstance(b, str):
        return a != b
    with np.errstate(invalid="ignore"):
        return ~(abs(a - b) <= 1e-9 * np.maximum(abs(a), abs(b)))


def _check_same_span(results: Sequence[tuple[str, xr.Dataset]]) -> None:
    """Warn (one line) where results describe different spans (SPAN: the cable's mass,
    rigidities and damping, the clamps) at some combination of their axes and [points]
    sets: their spans' shortest mixes one cable's limit into another's (a reviewer's
    bundle's frequency criterion bound a second cable of a [points] result at the bundle's
    span). A quantity one result sweeps and another does not must match at every value.
    A warning, not a refusal: bracketing a cable by two others is a question one may ask."""
    import warnings

    from .errors import CableSweepWarning
    spans = [(name, _span_of(ds)) for name, ds in results]
    spans = [(n, s) for n, s in spans if s is not None]
    for (name_a, a), (name_b, b) in zip(spans, spans[1:]):
        for quantity, units in SPAN:
            diff = _differs(a[quantity], b[quantity])
            if not bool(np.any(diff)):
                continue
            where, first = "", {}
            if isinstance(diff, xr.DataArray) and diff.ndim:
                first = {d: int(i[0]) for d, i in zip(diff.dims, np.nonzero(diff.values))}
                where = " at " + ", ".join(f"{d} {i}" if d == "point" else
                                           f"{d} {diff[d].values[i]}" for d, i in first.items())

            def show(v: Any) -> str:
                if isinstance(v, xr.DataArray):
                    v = v.isel({d: i for d, i in first.items() if d in v.dims}).values[()]
                return "none" if v is None else f"{v:.4g}" if not isinstance(v, str) else v
            warnings.warn(f"design: results '{name_a}' and '{name_b}' describe different spans "
                          f"({quantity.replace('_', ' ')} {show(a[quantity])} against "
                          f"{show(b[quantity])}{(' ' + units) if units else ''}{where}): the "
                          "shortest of their spans gives one span another's limit; design each "
                          "span from its own results", CableSweepWarning, stacklevel=3)
            return


def _shortest(spans: list[xr.Dataset], names: list[str]) -> xr.Dataset:
    """The shortest of several max_span results at each combination of their axes."""
    shared = sorted(set.intersection(*[set(s["max_span"].dims) for s in spans]))
    different = UserError("design: the results' shared axes (" + ", ".join(shared) + ") hold "
                          "different values; run them over the same values")
    try:
        aligned = xr.align(*[s["max_span"] for s in spans], join="exact")
    except ValueError:
        raise different from None
    for s in spans[1:]:       # a [points] set's values ride on `point`, not on its index
        for c in s.coords:
            if (c in spans[0].coords and set(s[c].dims) <= set(shared)
                    and not np.array_equal(s[c].values, spans[0][c].values)):
                raise different
    values = xr.broadcast(*aligned)
    limited = xr.broadcast(*[s["limited_by"] for s in spans])
    dims = values[0].dims
    stack = np.stack([v.transpose(*dims).values for v in values])
    by = np.stack([b.transpose(*dims).values for b in limited])
    # a NaN span (the shortest length fails) binds first; then the shortest
    order = np.where(np.isnan(stack), -np.inf, stack)
    pick = np.argmin(order, axis=0)
    span = np.take_along_axis(stack, pick[None], axis=0)[0]
    limited_by = np.asarray(np.take_along_axis(by, pick[None], axis=0)[0], dtype=object)
    grid = np.all(by == "grid", axis=0)
    carried: dict[str, xr.DataArray] = {}     # each result's binding_direction, if it has one
    name = BINDING + DIRECTION
    if any(name in s for s in spans):
        own = xr.broadcast(*[s[name] if name in s else s["max_span"].copy(
            data=np.full(s["max_span"].shape, "", dtype=object)) for s in spans])
        stacked = np.stack([b.transpose(*dims).values for b in own])
        carried[name] = xr.DataArray(
            np.asarray(np.take_along_axis(stacked, pick[None], axis=0)[0]).astype(str)
            .astype(object), dims=dims, attrs=next(s[name].attrs for s in spans if name in s))
    limited_in = np.asarray(np.where(grid, "", np.asarray(names, dtype=object)[pick]),
                            dtype=object)
    nan = np.isnan(span)                  # the shortest length fails: name every result
    if nan.any():                         # it fails in, not the first given
        failing = np.isnan(stack)
        every = np.empty(span.shape, dtype=object)
        for index in np.ndindex(span.shape):
            every[index] = ", ".join(n for n, f in zip(names, failing[(slice(None), *index)])
                                     if f)
        limited_in = np.asarray(np.where(nan, every, limited_in), dtype=object)
    first = spans[0]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    criteria = " | ".join(f"{n}: {s.attrs.get('criteria', '')}" for n, s in zip(names, spans))
    coords = {d: values[0][d] for d in dims if d in values[0].coords}
    for s in spans:                     # a [points] set's own coordinates
        for c in s.coords:
            if c not in coords and set(s[c].dims) <= set(dims):
                coords[c] = s[c]
    return xr.Dataset(
        {"max_span": xr.DataArray(span, dims=dims, attrs={
            **first["max_span"].attrs,
            "long_name": f"{SPAN_LONG_NAME} in every result they apply to",
            "comment": f"the shortest of the results' spans, each: {GRID_SPAN_COMMENT}"}),
         "limited_by": xr.DataArray(limited_by.astype(str).astype(object), dims=dims,
                                    attrs=first["limited_by"].attrs),
         "limited_in": xr.DataArray(limited_in.astype(str).astype(object), dims=dims, attrs={
             "long_name": "the result the binding criterion holds in (empty: every result's "
                          "grid passes)"}), **carried},
        coords=coords,
        attrs={"title": "maximum span: " + " + ".join(str(s.attrs.get("source_title") or n)
                                                      for n, s in zip(names, spans)),
               "Conventions": first.attrs.get("Conventions", "CF-1.11"),
               "source": first.attrs.get("source", ""),
               "history": f"{now} governing span of {', '.join(names)} ({criteria})",
               "cable_sweep_version": first.attrs.get("cable_sweep_version", ""),
               "criteria": criteria,
               "results": ", ".join(names)})
