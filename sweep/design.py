"""The clamp-spacing question (docs/model.md sec. 9): the largest span between clamps that
meets a harness's criteria under the load case of a result.

`max_span(ds, min_frequency=..., max_amplitude=...)` walks a result's `length` axis upwards
and, for every combination of its other swept axes, returns the largest span before the first
grid length that fails, interpolated between that length and the last passing one on the
margin of the criterion that binds. A length fails when

* ``min_frequency``: its first natural frequency (Hz) is below the limit: `loaded_frequency`,
  the loaded span's, where the result's end load is constant (a compressive load lowers it),
  else `natural_frequency` (`frequency_of`);
* ``max_amplitude``: its response (`peak_amplitude` of a swept result, one with
  `peak_frequency`; else `amplitude`; or the response named by ``quantity``, one of
  RESPONSES, m) is above the limit, or is missing (NaN);
* ``max_deflection``: its largest deflection anywhere on the span (`max_deflection`, m; a
  one-mode result's midspan amplitude, where its mode peaks) is above the limit;
* ``max_strain``: its largest outer-fibre strain (`max_strain`: the bending strain at the
  clamp or at midspan, whichever is larger, plus the stretching's, sweep.models.loads) is
  above the limit;
* ``max_rms`` (a random result, docs/model.md sec. 11): its mean over the realisations of the
  RMS midspan deflection (`rms_deflection_mean`, m) is above the limit;
* ``max_peak`` (a random result): its mean over the realisations of the largest |midspan
  deflection| (`peak_deflection_mean`, m) is above the limit;
* ``clearance`` (a random result with outputs.clearance): the probability that |midspan
  deflection| exceeds the clearance level at least once in the test (`exceedance_probability`
  at that `clearance` level, from the crossing rate pooled over the realisations, 1) is above
  ``max_probability``
  (0.01 by default);
* ``state``: its `state` is a failure (invalid_input, diverged, step_size_too_small,
  max_steps_reached);
* ``stability``: where the result has `stability`, the straight span is unstable there
  (`growth_rate` > 0, or a flag other than stable).

A stepped or swept result's `direction` (up, down) and a random result's `realisation` (its
Monte Carlo records) count at their worst: a quantity's maximum over them, and a length fails
on a state or stability failure of any of them (a realisation that escaped, state diverged,
fails its length); a random result's criteria read statistics over its records, and the sine
response limits (SINE_LIMITS) are refused for it. The design is over the result's axes less
length, direction and realisation.

Interpolation between the last passing grid length l_a and the first failing one l_b:
frequency in log f against log l (exact for pinned and clamped ends, whose unloaded
f1 ~ l^-2; not for elastic ends, whose K = k_t l / EI grows with the length: up to 2e-4
relative on a 50 mm grid near K = 1), amplitude and every other upper limit linearly in l of
(quantity - limit), stability linearly in l of growth_rate; a state failure (which has no
margin), a missing value and a value that does not cross its limit between l_a and l_b (a
stability flag that fails where growth_rate is still <= 0) give l_a. When several criteria
fail at l_b the smallest of their spans binds. max_span runs no analysis: its span is only as
good as the grid.

`over` (`sweep design --over AXIS [AXIS ...]`) asks one span for every value of some axes
together (a stepped sine test covers every frequency of its continuation axis and both
directions; an uncertain damping ratio or load level must pass at each value): `max_span` is
the minimum over those axes of each value's span, a NaN (no span at some value) first,
`limited_by` the criterion binding there, and `binding_<axis>` (in the axis's units, its
comment quoting the axis's long_name; `binding_<coordinate>` too for a coordinate along it, a
[points] set's values) names the value it binds at: the first in the axis's order where several give the same span,
NaN (or empty, for a string axis) where every value's longest grid length passes.
`direction` already counts at its worst at each length, so --over direction leaves max_span
as it is and adds `binding_direction`, the direction whose own span is the shorter. length
and realisation cannot be given (the axis the span is found along; a random result's
criteria are statistics over its realisations already), nor an axis twice (one line naming it).

`refine_span` (`sweep design --refine [--tolerance M]`) goes beyond the grid: for each
bracketed span it bisects on length with one-length engine runs of the result's stored scene,
the other axes fixed to the combination's values, evaluating the same criteria (`_margins`,
shared with max_span) until the bracket is below the tolerance (1 mm by default), and reports
the bracket's passing end (conservative). The frequency criterion needs no run (log f against
log l is exact for pinned or clamped ends, f1 ~ l^-2; elastic ends bisect on the closed-form
f1), so a frequency-only refinement costs none; the runs made are counted in the attribute
`refine_runs`.
"""

from __future__ import annotations

import datetime
import math
from typing import Any, Callable, Sequence

import numpy as np
import xarray as xr

from sweep.kernels import states as km

from .errors import UserError
from .models.random_scene import REALISATION_DIM
from .scene.points import POINT_DIM
from .schema import BY_AXIS

LENGTH = "length"
DIRECTION = "direction"
REALISATION = REALISATION_DIM
CLEARANCE = "clearance"
WORST_OVER = (DIRECTION, REALISATION)
"""Dimensions a criterion counts at its worst over, never a design axis."""
DEFAULT_MAX_PROBABILITY = 0.01
"""The clearance criterion's largest exceedance probability by default (1 %)."""
STATE_FAILURES = tuple(km.STATE_MEANINGS[f] for f in (km.INVALID_INPUT, km.DIVERGED,
                                                      km.STEP_TOO_SMALL, km.MAX_STEPS))
"""`state` flag meanings that fail a length (the one state table, kernels/states.py)."""
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "km": 1e3,
                "metre": 1.0, "meter": 1.0, "metres": 1.0, "meters": 1.0,
                "millimetre": 1e-3, "millimeter": 1e-3, "millimetres": 1e-3,
                "millimeters": 1e-3}
"""The units a result's `length` axis may be in, and their size in metres."""
CRITERIA = ("min_frequency", "max_amplitude", "max_deflection", "max_strain", "max_rms",
            "max_peak", "clearance", "state", "stability")
"""The criteria in the order they are named when the shortest span fails several; a failed
solve (`state`) comes first wherever it fails, as its NaN values fail no limit."""
LIMITED_BY = CRITERIA + ("grid",)
SPAN_LONG_NAME = "largest span between clamps meeting the criteria"
NAN_SPAN = "NaN: the shortest grid length already fails (limited_by says which criterion)"
GRID_SPAN_COMMENT = ("every shorter grid length passes; interpolated between the last passing "
                     "and the first failing grid length on the binding criterion's margin "
                     "(sweep.design, docs/model.md sec. 9), the longest grid length where none "
                     f"fails. {NAN_SPAN}")
"""max_span's labels: a long_name short and complete (<= 100 characters), how in comment."""
LIMITED_BY_ATTRS = {
    "long_name": "criterion that limits the span (see comment)",
    "comment": "one of " + ", ".join(LIMITED_BY) + "; grid: no grid length fails (max_span is "
               "the longest grid length, the true one may be longer); with a NaN max_span, the "
               "criterion the shortest grid length fails"}
"""limited_by's labels: the criteria it may name listed in full in comment."""
NO_CRITERION = ("design: no criterion given (give --min-frequency HZ, --max-amplitude M, "
                "--max-deflection M, --max-strain S, --max-rms M, --max-peak M or "
                "--clearance M)")


STRAIN_UNITS = {"%": 1e-2, "percent": 1e-2, "microstrain": 1e-6, "ustrain": 1e-6,
                "\u00b5strain": 1e-6, "\u00b5\u03b5": 1e-6, "\u03bcstrain": 1e-6,
                "\u03bc\u03b5": 1e-6, "ue": 1e-6, "ppm": 1e-6}
"""What a strain limit may be written in besides a plain number (1, m/m); micro as the micro
sign (U+00B5) or the Greek letter mu (U+03BC), as a length limit takes both."""
UNIT_EXAMPLES = {"m": "'2 mm'", "Hz": "'100 Hz'"}
"""How a limit in these units may be written with its unit (limit_value)."""


def limit_value(text: str, units: str) -> float:
    """A limit written as text, in `units`: "m" or "Hz", a plain number in them or a number
    with a unit converted as a scene key's ("2 mm", "0.1 kHz": sweep.scene.units); "1", a
    strain, plain (m/m) or with a unit of STRAIN_UNITS ("300 microstrain", "0.03 %").
    ValueError, one line (what it takes), otherwise; the sign is checked by the caller."""
    if units == "1":
        return _strain_value(text)
    try:
        return float(text)
    except ValueError:
        pass
    from .errors import SceneError
    from .scene.units import to_si
    from .schema import Key
    try:
        return to_si("value", Key("design", "limit", "float", None, units=units), text)
    except SceneError as exc:
        said = str(exc).removeprefix("value: ").replace("the key takes", "it takes")
        raise ValueError(f"{said}; a plain number is in {units}, or write e.g. "
                         f"{UNIT_EXAMPLES[units]}") from None


def _strain_value(text: str) -> float:
    """A strain (1) written plain (m/m) or with a unit of STRAIN_UNITS; ValueError, one line,
    otherwise."""
    import re
    match = re.fullmatch(r"\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*(\S*)\s*", text)
    unit = match.group(2).lower() if match else ""
    factor = 1.0 if not unit else STRAIN_UNITS.get(unit)
    try:
        value = float(match.group(1)) if match else None
    except ValueError:
        value = None
    if value is None or factor is None:
        raise ValueError(f"{text!r}: not a strain (a plain number is in m/m, e.g. 0.0003, or "
                         "write it with one of '%', 'microstrain', 'ppm': '300 microstrain', "
                         "'0.03 %')")
    return value * factor


def _number(value: Any, flag: str, example: str, units: str | None = None) -> float:
    """A criterion's limit as a positive finite float: a number, or (from Python) a string
    with a unit of `units` (limit_value; None: a plain number only); one-line UserError
    otherwise, naming `flag` (the command's) and the keyword argument it is."""
    if isinstance(value, str) and units is not None:
        keyword = flag.removeprefix("--").replace("-", "_")
        try:
            value = limit_value(value, units)
        except ValueError as exc:
            raise UserError(f"design: {keyword}={value!r} ({flag}): {exc}") from None
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise UserError(f"{flag} {value!r}: not a number (give e.g. {flag} {example})") from None
    if not (math.isfinite(x) and x > 0.0):
        raise UserError(f"{flag} {x:g}: must be a positive finite number, e.g. {flag} "
                        f"{example}")
    return x


def _flags(var: xr.DataArray) -> dict[int, str]:
    values = np.atleast_1d(var.attrs.get("flag_values", [])).tolist()
    meanings = str(var.attrs.get("flag_meanings", "")).split()
    return {int(v): m for v, m in zip(values, meanings)}


def _default_quantity(ds: xr.Dataset) -> str:
    return "peak_amplitude" if "peak_frequency" in ds else "amplitude"


RESPONSES = ("amplitude", "peak_amplitude", "max_deflection", "linear_amplitude",
             "peak_end_displacement", "static_end_displacement")
"""What --quantity may name: the span's responses in m a limit applies to (sweep.models
.transverse: the midspan's `amplitude` and `peak_amplitude`, `max_deflection` anywhere on the
span, the linearised span's closed form `linear_amplitude`; sweep.models.longitudinal: the
loaded end's `peak_end_displacement` and `static_end_displacement`). Not every variable in m
is one: `max_deflection_position` is where along the span the largest deflection lies, and
`escape_barrier` the |q| beyond which the span escapes, a threshold (NON_RESPONSES)."""
NON_RESPONSES = ("max_deflection_position", "escape_barrier")
"""Variables in m over the swept axes that are no response to limit (RESPONSES)."""


def _length_quantities(ds: xr.Dataset, axes: tuple[str, ...]) -> list[str]:
    """The responses (RESPONSES) in m over the swept axes only: what --quantity may name."""
    return sorted(str(n) for n, v in ds.data_vars.items()
                  if n in RESPONSES and v.attrs.get("units") == "m" and LENGTH in v.dims
                  and set(v.dims) <= set(axes))


Limit = float | str | None
"""A criterion's limit as max_span takes it: a number in the criterion's units (Hz, m, 1), a
string with its unit ("2 mm", "0.1 kHz", "300 microstrain": limit_value), or None (not given)."""
Limits = dict[str, tuple[str, float, float | None]]
"""The upper-limit criteria of a design: criterion -> (the variable it reads, its limit, the
`clearance` level (m) it is read at, or None)."""

RANDOM_HOW = ("it comes from a random scene ([base] asd_g2 or asd, e.g. the built-in "
              "launch-random-gevs)")


def _clearance_index(var: xr.DataArray, level: float) -> int | None:
    """The index of `level` (m) among `var`'s `clearance` coordinate, None where absent."""
    levels = np.asarray(var[CLEARANCE].values, float) if CLEARANCE in var.coords else \
        np.empty(0)
    hits = np.flatnonzero(np.isclose(levels, level, rtol=1e-9, atol=0.0))
    return int(hits[0]) if hits.size else None


def _limits(ds: xr.Dataset, axes: tuple[str, ...], max_deflection: float | None,
            max_strain: float | None, max_rms: float | None = None,
            max_peak: float | None = None, clearance: float | None = None,
            max_probability: float | None = None) -> Limits:
    """The upper-limit criteria's variables (`max_deflection`, m: the largest deflection
    anywhere on the span, which a one-mode result's midspan amplitude is; `max_strain`, 1:
    bending plus stretching at the clamp or midspan; a random result's `rms_deflection_mean`
    and `peak_deflection_mean`, m, and `exceedance_probability` at the `clearance` level, 1),
    refused in one line where the result lacks them."""
    limits: Limits = {}
    if max_deflection is not None:
        if "max_deflection" in ds:
            limits["max_deflection"] = ("max_deflection", max_deflection, None)
        elif "mode" not in ds.dims:                  # one mode: its largest is at midspan
            limits["max_deflection"] = (_default_quantity(ds), max_deflection, None)
        else:
            raise UserError("design: --max-deflection needs the variable 'max_deflection' "
                            "(m, the largest deflection over the span), which this result "
                            "lacks (a run with outputs.amplitude = false, or a sine sweep of "
                            "several modes written before 2026-12-05, has none: run it with "
                            "the tail amplitude on, or use --max-amplitude)")
    if max_strain is not None:
        if "max_strain" not in ds:
            raise UserError("design: --max-strain needs the variable 'max_strain' (bending "
                            "plus stretching strain), which this result lacks: it comes with "
                            "the uniform stretching tension (not with model.membrane or "
                            "model.coefficients = 'paper': the paper's local term) and the "
                            "cable's diameter (a data-sheet cable needs cable.diameter)")
        limits["max_strain"] = ("max_strain", max_strain, None)
    for criterion, flag, name, limit, what in (
            ("max_rms", "--max-rms", "rms_deflection_mean", max_rms,
             "m, the mean over the realisations of the RMS midspan deflection"),
            ("max_peak", "--max-peak", "peak_deflection_mean", max_peak,
             "m, the mean over the realisations of the largest |midspan deflection|")):
        if limit is None:
            continue
        if name not in ds:
            raise UserError(f"design: {flag} needs the variable '{name}' ({what}), which this "
                            f"result lacks: {RANDOM_HOW}")
        limits[criterion] = (name, limit, None)
    if clearance is not None:
        name = "exceedance_probability"
        if name not in ds:
            raise UserError(f"design: --clearance needs the variable '{name}' (the probability "
                            "that |midspan deflection| exceeds a clearance level in the test), "
                            f"which this result lacks: {RANDOM_HOW}, with outputs.clearance = "
                            f"[levels in m] including {clearance:g}")
        if _clearance_index(ds[name], clearance) is None:
            levels = np.asarray(ds[CLEARANCE].values, float) if CLEARANCE in ds.coords \
                else np.empty(0)
            have = ", ".join(f"{v:g}" for v in levels) or "none"
            raise UserError(f"design: --clearance {clearance:g}: not one of the result's "
                            f"clearance levels ({have} m); run the scene with "
                            f"outputs.clearance = [...] including {clearance:g}")
        p = DEFAULT_MAX_PROBABILITY if max_probability is None else max_probability
        limits["clearance"] = (name, p, clearance)
    for _, (name, _, level) in limits.items():
        extra = [d for d in ds[name].dims if d not in axes
                 and not (level is not None and d == CLEARANCE)]
        if extra:
            raise UserError(f"design: '{name}' lies over {', '.join(map(str, extra))}, not "
                            "a swept axis")
    return limits


def check_result(ds: xr.Dataset, name: str | None = None) -> tuple[str, ...]:
    """The axes of a result (a Dataset) `max_span` can walk (its state's or stability's dims),
    or a one-line UserError (naming the result `name` where given): neither state nor
    stability, no positive finite `length` axis."""
    which = "the result" if name is None else f"result '{name}'"
    template = "state" if "state" in ds else "stability" if "stability" in ds else None
    if template is None:
        raise UserError(f"design: {which} has neither 'state' nor 'stability' (give a "
                        "result written by 'sweep run ... -o FILE.nc')")
    axes = tuple(str(d) for d in ds[template].dims)
    if LENGTH not in axes or LENGTH not in ds.coords:
        have = ", ".join(a for a in axes if a not in WORST_OVER) or "none"
        raise UserError(f"design: {which} has no 'length' axis (its axes: {have}); run the "
                        "scene with one, e.g. --set 'axes.length={start=0.1, stop=0.6, num=11}'")
    lengths = np.asarray(ds[LENGTH].values, float)
    if not (np.all(np.isfinite(lengths)) and np.all(lengths > 0)):
        raise UserError(f"design: {which}'s 'length' axis holds values that are not "
                        "positive finite lengths (m); give a result written by 'sweep run'")
    units = ds[LENGTH].attrs.get("units")
    if units not in LENGTH_UNITS:
        said = "no units" if units is None else f"units {units!r}"
        raise UserError(f"design: {which}'s 'length' axis has {said}, not one of "
                        f"{', '.join(LENGTH_UNITS)}; give a result whose length coordinate "
                        "says its unit (a result 'sweep run' wrote is in m)")
    return axes


def in_metres(ds: xr.Dataset) -> xr.Dataset:
    """`ds` with its `length` coordinate in metres (converted from LENGTH_UNITS, its units
    attribute then "m"); `check_result` refuses any other units first."""
    units = ds[LENGTH].attrs.get("units")
    if units == "m":
        return ds
    length = ds[LENGTH]
    metres = np.asarray(length.values, float) * LENGTH_UNITS[units]
    return ds.assign_coords({LENGTH: (length.dims, metres, {**length.attrs, "units": "m"})})


SINE_LIMITS = {"max_amplitude": "--max-amplitude", "max_deflection": "--max-deflection",
               "max_strain": "--max-strain"}
"""The criteria that limit a deterministic response (a sine or dwell's tail or sweep peak): a
random result holds the same variables, but as each record's own peak, no statistic of the
test, so it is asked only its own criteria (--max-rms, --max-peak, --clearance)."""


def _refuse_sine_limits_of_a_random_result(ds: xr.Dataset, max_amplitude: float | None,
                                           max_deflection: float | None,
                                           max_strain: float | None) -> None:
    """Refuse (one line) a SINE_LIMITS criterion given for a random result (one with
    `realisation`)."""
    given = dict(max_amplitude=max_amplitude, max_deflection=max_deflection,
                 max_strain=max_strain)
    flags = [SINE_LIMITS[k] for k, v in given.items() if v is not None]
    if REALISATION in ds.dims and flags:
        raise UserError(f"design: {flags[0]} limits a sine or dwell response, and this is a "
                        "random result, whose records' peaks are no statistic of the test; "
                        "give --max-peak M (the mean largest |midspan deflection|), --max-rms "
                        "M or --clearance M for it")


def _check(ds: xr.Dataset, min_frequency: float | None, max_amplitude: float | None,
           quantity: str | None, max_deflection: float | None = None,
           max_strain: float | None = None, max_rms: float | None = None,
           max_peak: float | None = None, clearance: float | None = None,
           max_probability: float | None = None) -> tuple[tuple[str, ...], Limits]:
    """Refuse (one-line UserError) what max_span cannot answer; the swept axes and the
    upper-limit criteria with the variables they read (`Limits`)."""
    if not isinstance(ds, xr.Dataset):
        raise UserError(f"max_span: needs a result (an xarray Dataset), got "
                        f"{type(ds).__name__}")
    if all(c is None for c in (min_frequency, max_amplitude, max_deflection, max_strain,
                               max_rms, max_peak, clearance)):
        raise UserError(NO_CRITERION)
    axes = check_result(ds)
    _refuse_sine_limits_of_a_random_result(ds, max_amplitude, max_deflection, max_strain)
    if min_frequency is not None and frequency_of(ds) not in ds:
        raise UserError("design: --min-frequency needs the variable 'natural_frequency' (Hz), "
                        "which this result lacks (a transverse result has it)")
    if quantity is not None and max_amplitude is None:
        raise UserError(f"design: --quantity {quantity}: is the response --max-amplitude "
                        "limits; give --max-amplitude M too")
    limits = _limits(ds, axes, max_deflection, max_strain, max_rms, max_peak, clearance,
                     max_probability)
    if max_amplitude is None:
        return axes, limits
    name = _default_quantity(ds) if quantity is None else str(quantity)
    choices = ", ".join(_length_quantities(ds, axes)) or "none"
    if name not in ds.data_vars:
        how = "--quantity" if quantity is not None else "the default quantity"
        raise UserError(f"design: {how} '{name}': no such variable in the result (responses "
                        f"in m over its length axis: {choices}; give --quantity NAME)")
    units = ds[name].attrs.get("units")
    if units != "m":
        raise UserError(f"design: --max-amplitude limits '{name}', whose units are "
                        f"{units!r}, not 'm' (give --quantity NAME of one in m: {choices})")
    if name not in RESPONSES:
        raise UserError(f"design: --quantity {name}: not a response of the span to limit (a "
                        "position along it or a threshold, not a deflection); give --quantity "
                        f"NAME of a response: {choices}")
    extra = [d for d in ds[name].dims if d not in axes]
    if extra:
        raise UserError(f"design: quantity '{name}' lies over {', '.join(map(str, extra))}, "
                        f"not a swept axis (give --quantity NAME of one over the axes only: "
                        f"{choices})")
    return axes, {"max_amplitude": (name, max_amplitude, None), **limits}


def validated(ds: xr.Dataset, *, min_frequency: Any = None, max_amplitude: Any = None,
              quantity: str | None = None, max_deflection: Any = None,
              max_strain: Any = None, max_rms: Any = None, max_peak: Any = None,
              clearance: Any = None, max_probability: Any = None
              ) -> tuple[dict[str, float | None], tuple[str, ...], Limits]:
    """The criteria parsed (`_parse`) and checked against the result (`_check`), each refused
    in one line: the limits as floats, the result's axes and the upper limits with the
    variables they read. What `max_span` answers, without answering it."""
    c = _parse(min_frequency, max_amplitude, max_deflection, max_strain, max_rms, max_peak,
               clearance, max_probability)
    axes, limits = _check(ds, c["min_frequency"], c["max_amplitude"], quantity,
                          c["max_deflection"], c["max_strain"], c["max_rms"], c["max_peak"],
                          c["clearance"], c["max_probability"])
    return c, axes, limits


def _parse(min_frequency: Any, max_amplitude: Any, max_deflection: Any, max_strain: Any,
           max_rms: Any, max_peak: Any, clearance: Any, max_probability: Any
           ) -> dict[str, float | None]:
    """The criteria's limits as positive finite floats (None where not given), refused in one
    line otherwise; max_probability below 1 too."""
    given = {"min_frequency": (min_frequency, "--min-frequency", "100", "Hz"),
             "max_amplitude": (max_amplitude, "--max-amplitude", "0.002", "m"),
             "max_deflection": (max_deflection, "--max-deflection", "0.002", "m"),
             "max_strain": (max_strain, "--max-strain", "0.001", "1"),
             "max_rms": (max_rms, "--max-rms", "0.001", "m"),
             "max_peak": (max_peak, "--max-peak", "0.004", "m"),
             "clearance": (clearance, "--clearance", "0.002", "m"),
             "max_probability": (max_probability, "--max-probability", "0.01", None)}
    out = {k: None if v is None else _number(v, flag, example, units)
           for k, (v, flag, example, units) in given.items()}
    p = out["max_probability"]
    if p is not None and clearance is None:
        raise UserError(f"design: --max-probability {p:g} is the limit of the clearance "
                        "criterion; give --clearance M too")
    if p is not None and not p < 1.0:
        raise UserError(f"--max-probability {p:g}: a probability must be below 1, e.g. "
                        "--max-probability 0.01")
    return out


def _like(var: xr.DataArray) -> xr.DataArray:
    """`var` without the dimensions criteria count at their worst over (direction,
    realisation): the shape of the design's pass/fail arrays."""
    for d in WORST_OVER:
        if d in var.dims:
            var = var.isel({d: 0}, drop=True)
    return var


def _broadcast(var: xr.DataArray, like: xr.DataArray) -> np.ndarray:
    """`var` as a float array shaped like `like`, length last."""
    return np.asarray(var.broadcast_like(like).transpose(*like.dims).values, float)


def frequency_of(ds: xr.Dataset) -> str:
    """The variable --min-frequency judges a result by: `loaded_frequency` (Hz, the span's
    first natural frequency under a constant end load) where the result has it, else
    `natural_frequency` (the unloaded span's)."""
    return "loaded_frequency" if "loaded_frequency" in ds else "natural_frequency"


def _binding_order(failing: list[str], value: Callable[[str], Any]) -> list[str]:
    """The criteria that fail at one length (in CRITERIA's order), in the order `limited_by`
    names them: where the solve failed there ('state'), 'state' first and the others only
    where their value there (`value(name)`) is finite, since a failed solve's NaN values fail
    every limit without telling anything about it (the grid answer, --refine's bracket end and
    each of its runs alike)."""
    if "state" not in failing:
        return failing
    return ["state"] + [k for k in failing
                        if k != "state" and np.all(np.isfinite(value(k)))]


def max_span(ds: xr.Dataset, *, min_frequency: Limit = None,
             max_amplitude: Limit = None, quantity: str | None = None,
             max_deflection: Limit = None, max_strain: Limit = None,
             max_rms: Limit = None, max_peak: Limit = None,
             clearance: Limit = None, max_probability: float | None = None,
             over: str | Sequence[str] = ()) -> xr.Dataset:
    """The largest span between clamps (m) that meets the criteria, per combination of the
    result's other swept axes (less those of `over`).

    Parameters
    ----------
    ds : a result of `sweep.run` (or `sweep.plot.load_result`) with a `length` axis in m (or
        mm, cm, km or their spelled-out names, as its units attribute says: converted to m).
    min_frequency : Hz; a length passes when its first natural frequency (`frequency_of`:
        the loaded span's under a constant end load) >= min_frequency.
    max_amplitude : m; a length passes when the response <= max_amplitude. The response is
        `quantity` (one of RESPONSES, in m over the swept axes), by default `peak_amplitude` for a
        swept result (one with `peak_frequency`) and `amplitude` otherwise; its worst
        (largest) value over `direction` counts. Not for a random result (SINE_LIMITS), nor
        are max_deflection and max_strain.
    quantity : the response `max_amplitude` limits, one of RESPONSES (needs max_amplitude).
    max_deflection : m; a length passes when `max_deflection`, the largest deflection anywhere
        on the span, is at most this (one mode: the midspan's, where its largest lies).
    max_strain : 1; a length passes when `max_strain` (the outer fibre's bending strain at
        the clamp or midspan, whichever is larger, plus the stretching's) is at most this.
    max_rms : m; a random result's length passes when `rms_deflection_mean`, the mean over the
        realisations of the RMS midspan deflection, is at most this.
    max_peak : m; a random result's length passes when `peak_deflection_mean`, the mean over
        the realisations of the largest |midspan deflection|, is at most this.
    clearance : m, one of a random result's `clearance` levels (outputs.clearance); a length
        passes when `exceedance_probability` there (that |midspan deflection| exceeds it at
        least once in the test, from the crossing rate pooled over the realisations) is at
        most `max_probability`.
    max_probability : 1, below 1; the clearance criterion's limit (needs clearance; default
        0.01, i.e. 1 %).

    over : an axis of the result, or several (not length, not realisation), whose values the
        span must pass at all together (`reduce_over`): max_span is the minimum over them of
        each value's span (a NaN first), and `binding_<axis>` names the value it binds at.
        `direction` counts at its worst already: over it, max_span stays as it is and
        `binding_direction` names the direction whose own span is the shorter.

    Each limit but max_probability may be a string with its unit, as the command takes it
    ("2 mm", "0.1 kHz", "300 microstrain": limit_value).

    Every length must also have a `state` that is not a failure (invalid_input, diverged,
    step_size_too_small, max_steps_reached on either direction or in any realisation) and,
    where the result has `stability`, be stable (growth_rate <= 0). Warned (one line,
    CableSweepWarning), not failed: a passing length whose state is unsettled (its response
    still changing at t_end), a clearance pass whose crossings are too few to vouch for
    the limit (`exceedance_probability_upper` above it), and a midspan criterion passing a
    length where an even mode (a node at midspan) moved.

    Returns
    -------
    A Dataset over the result's axes other than `length`, `direction` and `realisation` (their
    coordinates kept) with `max_span` (m): the largest length before the first failing grid
    length, interpolated between the last passing and the first failing one on the binding
    criterion's margin (module docstring); the longest grid length when none fails; NaN when
    the shortest already fails. `limited_by` (strings): the binding criterion, one of
    CRITERIA, or "grid" when no length fails (with a NaN max_span the criterion the shortest
    span fails). Attributes: `criteria`, the
    source result's `title`.

    Raises UserError (one line) without a criterion, without a `length` axis or one whose
    units are not LENGTH_UNITS, for an unknown
    quantity or one whose units are not m, a non-positive limit, a result without the
    variable a criterion reads (a random one's for max_rms, max_peak, clearance), a sine
    response's limit (SINE_LIMITS) for a random result, a clearance level the result does not
    hold, and an `over` axis the result lacks, length or realisation.
    """
    asked = dict(min_frequency=min_frequency, max_amplitude=max_amplitude,
                 quantity=quantity, max_deflection=max_deflection, max_strain=max_strain,
                 max_rms=max_rms, max_peak=max_peak, clearance=clearance,
                 max_probability=max_probability)
    c, axes, limits = validated(ds, **asked)
    over = over_axes(over, axes)
    fmin = c["min_frequency"]
    ds = in_metres(ds).sortby(LENGTH)
    others = tuple(a for a in axes if a not in (LENGTH, *WORST_OVER))
    template_name = "state" if "state" in ds else "stability"
    like = _like(ds[template_name]).transpose(*others, LENGTH)
    shape = like.shape
    lengths = np.asarray(ds[LENGTH].values, float)

    margins = _margins(ds, fmin, limits, like)
    flat = {k: (m.reshape(-1, shape[-1]), v.reshape(-1, shape[-1]), how)
            for k, (m, v, how) in margins.items()}
    n = int(np.prod(shape[:-1], dtype=int))
    spans = np.full(n, np.nan)
    limited = np.empty(n, dtype=object)
    passed = np.zeros((n, shape[-1]), bool)      # the grid lengths below each first failure
    for i in range(n):
        passes = np.ones(shape[-1], bool)
        for m, _, _ in flat.values():
            passes &= m[i] >= 0.0                # NaN margin: fails
        if passes.all():
            spans[i], limited[i] = lengths[-1], "grid"
            passed[i] = True
            continue
        b = int(np.argmin(passes))               # the first failing length
        passed[i, :b] = True
        failing = _binding_order([k for k in CRITERIA if k in flat
                                  and not flat[k][0][i, b] >= 0.0],
                                 lambda k: flat[k][1][i, b])
        if b == 0:
            spans[i], limited[i] = np.nan, failing[0]
            continue
        a = b - 1
        best = (math.inf, "")
        for k in failing:
            _, v, how = flat[k]
            span = _interpolate(lengths[a], lengths[b], v[i, a], v[i, b],
                                fmin if k == "min_frequency" else 0.0, how)
            if span < best[0]:
                best = (span, k)
        spans[i], limited[i] = best
    if "clearance" in limits:
        _warn_unresolved(ds, limits["clearance"], like, passed, lengths)
    if limits:
        _warn_unsettled(ds, like, passed, lengths)
        _warn_off_midspan(ds, limits, like, passed, lengths)
    out_shape = shape[:-1]
    coords = {d: _coordinate(ds, d) for d in others}
    if POINT_DIM in others:                      # each parameter set's [points] values
        coords.update({c: _coordinate(ds, c) for c in ds.coords
                       if c != POINT_DIM and ds[c].dims == (POINT_DIM,)})
    title = str(ds.attrs.get("title", ""))
    criteria = "; ".join(
        ([f"{frequency_of(ds)} >= {fmin:g} Hz"] if fmin is not None else [])
        + [f"{name} <= {limit:g} {_shown_units(ds[name])}".rstrip()
           if level is None else f"{name} at clearance {level:g} m (pooled over the "
           f"realisations) <= {limit:g}" for name, limit, level in limits.values()]
        + (["state not in (" + ", ".join(STATE_FAILURES) + ")"] if "state" in ds else [])
        + (["growth_rate <= 0 (stable)"] if "stability" in ds else []))
    from .version import package_version
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    result = xr.Dataset(
        {"max_span": xr.DataArray(spans.reshape(out_shape), dims=others, attrs={
            "units": "m", "long_name": SPAN_LONG_NAME, "comment": GRID_SPAN_COMMENT}),
         "limited_by": xr.DataArray(limited.reshape(out_shape).astype(str).astype(object),
                                    dims=others, attrs=dict(LIMITED_BY_ATTRS))},
        coords=coords,
        attrs={"title": f"maximum span: {title}" if title else "maximum span",
               "Conventions": "CF-1.11",
               "source": f"cable-sweep {package_version()}: sweep.design.max_span of a result",
               "history": f"{now} max_span by cable-sweep {package_version()} from result "
                          f"'{title}' ({criteria})",
               "cable_sweep_version": package_version(),
               "source_title": title,
               "criteria": criteria,
               "length_grid": f"{lengths.size} lengths, {lengths[0]:g} to {lengths[-1]:g} m"})
    from .dataset import short_long_names
    result = short_long_names(result)
    if DIRECTION in over:
        result = with_binding_direction(ds, result, asked)
    return reduce_over(result, over) if over else result


OVER_REFUSED = {
    LENGTH: "length is the axis the span is found along, not one to take the shortest span "
            "over",
    REALISATION: "a random result's criteria are statistics over its realisations already "
                 "(means, a pooled probability), not one value per realisation"}
"""The axes --over cannot take, and why."""
BINDING = "binding_"
"""The prefix of the variables that name where a span taken over axes binds (reduce_over)."""


def over_axes(over: str | Sequence[str] | None, axes: Sequence[str],
              which: str = "the result") -> tuple[str, ...]:
    """The axes `over` names (one name or a sequence, in the order given), each one of `axes`
    (a result's swept axes, direction included) other than OVER_REFUSED, and each once; a
    one-line UserError, saying which axes may be given or naming the repeated one, otherwise.
    () for none."""
    if over is None:
        return ()
    names = (over,) if isinstance(over, str) else over
    if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
        raise UserError(f"design: over={over!r}: give an axis name or a list of them, e.g. "
                        "over=('base_frequency_ratio', 'direction')")
    choices = [str(a) for a in axes if a not in OVER_REFUSED]
    can = (f"--over takes {', '.join(choices)}" if choices else
           f"{which} has no axis but length to take the shortest span over")
    for name in names:
        if name in OVER_REFUSED:
            raise UserError(f"design: --over {name}: {OVER_REFUSED[name]} ({can})")
        if name not in choices:
            raise UserError(f"design: --over {name}: not an axis of {which} ({can})")
    once = tuple(dict.fromkeys(names))
    for name in once:
        if names.count(name) > 1:
            raise UserError(f"design: --over {' '.join(names)}: names the axis '{name}' "
                            f"{names.count(name)} times (name each axis once: --over "
                            f"{' '.join(once)})")
    return once


def _first_shortest(spans: np.ndarray) -> np.ndarray:
    """Along the last axis of `spans` (m), the index of the shortest, a NaN (no span) before
    any number, the first of equals."""
    return np.argmin(np.where(np.isnan(spans), -np.inf, spans), axis=-1)


def with_binding_direction(ds: xr.Dataset, result: xr.Dataset,
                           criteria: dict[str, Any]) -> xr.Dataset:
    """`result` (max_span of `ds` with `criteria`, over the axes less direction) with
    `binding_direction`: at each combination, the direction whose own span (max_span of that
    direction alone) is the shorter, a NaN first, the first of equals; empty where result's
    limited_by is grid (no direction fails). max_span stays the worst of both directions at
    each length: at most the shorter direction's own span, which fails at the same first
    grid length."""
    import warnings

    from .errors import CableSweepWarning
    span = result["max_span"]
    names = [str(v) for v in np.asarray(ds[DIRECTION].values)]
    with warnings.catch_warnings():        # each direction alone: max_span warned already
        warnings.simplefilter("ignore", CableSweepWarning)
        own = [max_span(ds.isel({DIRECTION: k}), **criteria)["max_span"]
               .transpose(*span.dims).values for k in range(len(names))]
    pick = _first_shortest(np.stack(own, axis=-1))
    binding = np.asarray(names, dtype=object)[pick]
    binding = np.where(np.asarray(result["limited_by"].values) == "grid", "", binding)
    attrs = {"long_name": f"{DIRECTION} at which the span binds",
             "comment": f"the {DIRECTION} ({', '.join(names)}) whose own span is the "
                        "shorter (the first where they are equal); empty where no length fails "
                        "(limited_by grid). "
                        "max_span is the worst of both directions at each length, as without "
                        "--over: at most that direction's own span"}
    return result.assign({BINDING + DIRECTION: xr.DataArray(
        np.asarray(binding, dtype=object).astype(str).astype(object), dims=span.dims,
        attrs=attrs)})


def reduce_over(result: xr.Dataset, over: Sequence[str]) -> xr.Dataset:
    """A span result (max_span's, refine_span's or governing_span's) taken over the axes
    `over`: at each combination of its other axes, the value of `over` whose max_span is the
    shortest (`_first_shortest`: a NaN, no span there, first; the first in order of equals),
    and every variable there (limited_by, limited_in, binding_direction). Adds
    `binding_<axis>` for each of them in the axis's units, its long_name naming the axis and
    its comment quoting the axis's long_name (and `binding_<coordinate>` for a coordinate
    along it, a [points] set's values): the value the span binds at, NaN (a string axis:
    empty) where every value's grid passes (limited_by grid). max_span lists them in its
    `ancillary_variables`; the attribute `over_axes` names `over`. `over` may name direction,
    which is no dimension of max_span (with_binding_direction gives its binding_direction):
    only the labels and the order of the variables name it."""
    span = result["max_span"]
    dims = [str(d) for d in span.dims if d in over]
    kept = [str(d) for d in span.dims if d not in over]
    sizes = [span.sizes[d] for d in dims]

    def rows(var: xr.DataArray) -> np.ndarray:
        """`var` shaped (the kept axes..., the `over` combinations)."""
        v = np.asarray(var.broadcast_like(span).transpose(*kept, *dims).values)
        return v.reshape(v.shape[:len(kept)] + (-1,))

    pick = _first_shortest(rows(span))

    def at_pick(values: np.ndarray) -> np.ndarray:
        return np.take_along_axis(values, pick[..., None], axis=-1)[..., 0]

    grid = np.all(rows(result["limited_by"]).astype(str) == "grid", axis=-1)
    data = {name: xr.DataArray(at_pick(rows(var)), dims=kept, attrs=dict(var.attrs))
            for name, var in result.data_vars.items()}
    named = ", ".join(over)
    where = ("the first in the axes' order where several values give the same span (a "
             "criterion these axes do not move binds at every value)")
    axis_of: dict[str, str] = {}
    for dim, index in zip(dims, np.unravel_index(pick, sizes) if dims else ()):
        along = [dim] + [str(c) for c in result.coords if c != dim and result[c].dims == (dim,)]
        for name in along:
            coord = result[name]
            values = np.asarray(coord.values)[index]
            attrs = {"long_name": f"{name} at which the span binds"}
            if values.dtype.kind in "fiub":
                values = np.where(grid, np.nan, values.astype(float))
                attrs["units"] = coord.attrs.get("units", "1")
                missing = "NaN"
            else:
                values = np.where(grid, "", values.astype(str)).astype(object)
                missing = "empty"
            attrs["comment"] = (f"the value of {name} ({coord.attrs.get('long_name', name)}) "
                                f"at which max_span, the shortest over {named}, binds: "
                                f"{where}; with a NaN max_span, the first "
                                f"whose shortest grid length fails; {missing} where every "
                                "value's longest grid length passes (limited_by grid)")
            data[BINDING + name] = xr.DataArray(values, dims=kept, attrs=attrs)
            axis_of[BINDING + name] = dim
    coords = {c: result[c] for c in result.coords if not set(result[c].dims) & set(dims)}
    # the span's variables first, then where each axis binds in the order `over` names them
    axis_of.update({BINDING + DIRECTION: DIRECTION})
    data = {name: data[name] for name in sorted(
        data, key=lambda n: list(over).index(axis_of[n]) if n in axis_of else -1)}
    out = xr.Dataset(data, coords=coords, attrs=dict(result.attrs))
    binding = [n for n in out.data_vars if str(n).startswith(BINDING)]
    label = f"{SPAN_LONG_NAME} at every {named}"
    out["max_span"].attrs.update({
        "long_name": label if len(label) <= 100 else
        f"{SPAN_LONG_NAME}, the shortest over the axes over_axes names",
        "comment": f"the shortest over {named} of each value's span (a NaN, no span at some "
                   f"value, first), {', '.join(binding)} naming where it binds; each value's: "
                   + str(out["max_span"].attrs.get("comment", "")),
        "ancillary_variables": " ".join(binding)})
    out.attrs["over_axes"] = named
    out.attrs["history"] = f"{out.attrs.get('history', '')}; the shortest over {named}"
    from .dataset import short_long_names
    return short_long_names(out)


def _worst(var: xr.DataArray, how: str) -> xr.DataArray:
    """`var` at its worst (`how`: "max" or "min") over direction and realisation."""
    over = [d for d in WORST_OVER if d in var.dims]
    if over:
        # skipna=False: a missing direction or realisation is not a pass
        return getattr(var, how)(over, skipna=False)
    return var


def _limited(ds: xr.Dataset, name: str, level: float | None) -> xr.DataArray:
    """The value an upper-limit criterion compares with its limit: `name` at its worst over
    direction and realisation, or at the `clearance` level (m): the pooled probability (a
    result written before it was pooled holds one per realisation: their mean over the finite
    values; a realisation that escaped has none, and fails `state`)."""
    var = ds[name]
    if level is None:
        return _worst(var, "max")
    index = _clearance_index(var, level)
    if index is None:                            # _limits refuses this first
        raise UserError(f"design: --clearance {level:g}: not one of the clearance levels of "
                        f"'{name}'")
    var = var.isel({CLEARANCE: index}, drop=True)
    if REALISATION in var.dims:
        var = var.mean(REALISATION)
    return _worst(var, "max")


def _warn_unsettled(ds: xr.Dataset, like: xr.DataArray, passed: np.ndarray,
                    lengths: np.ndarray) -> None:
    """Warn (one line) where a response criterion passed a grid length whose state is
    unsettled (in any direction or realisation): its response still changed over the tail
    window at t_end (a parametric response still growing, a transient still fading), so its
    amplitude is not yet the steady one and may grow. A reviewer's parametric map passed
    every span at t_end = 5 s and limited it at 0.53 m at 30 s."""
    if "state" not in ds:
        return
    flag = {m: v for v, m in _flags(ds["state"]).items()}.get(
        km.STATE_MEANINGS[km.UNSETTLED])
    if flag is None:
        return
    unsettled = _broadcast(_worst(ds["state"] == flag, "max"), like).reshape(passed.shape) > 0
    weak = passed & unsettled
    if not weak.any():
        return
    i, j, at = _first(ds, like, weak, lengths)
    _warn(f"design: {int(weak.sum())} passing grid span(s) are unsettled (e.g. {at}): "
                  "their response still changed at the run's end, so their amplitude may not "
                  "be the steady one (a parametric response still growing); run them longer "
                  "(solver.t_end) before trusting max_span")


def _first(ds: xr.Dataset, like: xr.DataArray, weak: np.ndarray, lengths: np.ndarray
           ) -> tuple[int, int, str]:
    """The first flagged (row, length) of `weak` (shaped like the design's rows x lengths) and
    where it is, in words: its length and the other axes' values."""
    i, j = (int(k[0]) for k in np.nonzero(weak))
    where = ", ".join(f"{d} {_coordinate(ds, str(d)).values[k]}" for d, k in
                      zip(like.dims[:-1], np.unravel_index(i, like.shape[:-1])))
    return i, j, f"length {lengths[j]:g} m" + (f" at {where}" if where else "")


def _warn(message: str) -> None:
    """A design's caveat, one line (CableSweepWarning), reported at max_span's caller."""
    import warnings

    from .errors import CableSweepWarning
    warnings.warn(message, CableSweepWarning, stacklevel=4)


MIDSPAN_SHARE = 0.01
"""A mode with a node at midspan counts as moving (`_warn_off_midspan`) above this share of
the midspan's own amplitude."""


def _warn_off_midspan(ds: xr.Dataset, limits: Limits, like: xr.DataArray, passed: np.ndarray,
                      lengths: np.ndarray) -> None:
    """Warn (one line) where a criterion that reads the midspan deflection (amplitude, peak,
    RMS, clearance) passed a grid length at which an even mode, with a node at midspan,
    moved by more than MIDSPAN_SHARE of the midspan's amplitude (`modal_amplitude`): the
    midspan does not see it, and the largest deflection along the span can be larger. The
    stretching tension parametrically excites mode 2 of a span driven near resonance (a
    reviewer's sweep: mode 2 at 0.45 mm beside 1.84 mm at midspan, the largest deflection
    10.6 % above the midspan's in a dwell)."""
    midspan = [k for k, (name, _, _) in limits.items() if name != "max_deflection"
               and k != "max_strain"]
    if not midspan or "modal_amplitude" not in ds or "mode" not in ds["modal_amplitude"].dims:
        return
    modes = np.asarray(ds["mode"].values if "mode" in ds.coords
                       else np.arange(1, ds.sizes["mode"] + 1))
    even = [i for i, n in enumerate(modes) if int(n) % 2 == 0]
    reference = next((v for v in ("peak_amplitude", "amplitude") if v in ds), None)
    if not even or reference is None:
        return
    moving = _worst(ds["modal_amplitude"].isel(mode=even).max("mode"), "max")
    own = _worst(ds[reference], "max")
    share = _broadcast(moving / own, like).reshape(passed.shape)
    weak = passed & (share > MIDSPAN_SHARE)
    if not weak.any():
        return
    i, j, at = _first(ds, like, weak, lengths)
    _warn(f"design: at {int(weak.sum())} passing grid span(s) a mode with a node at "
                  f"midspan moved (e.g. {at}: {share[i, j]:.1%} of the midspan's amplitude, "
                  "modal_amplitude), which the midspan criteria ("
                  + ", ".join(midspan) + ") do not see: the largest deflection along the span "
                  "can be larger (a run of several modes holds it in max_deflection: "
                  "--max-deflection)")


def _warn_unresolved(ds: xr.Dataset, limit: tuple[str, float, float | None],
                     like: xr.DataArray, passed: np.ndarray, lengths: np.ndarray) -> None:
    """Warn (one line) where the clearance criterion passed the last grid length before the
    span's first failure (the one max_span rests on) on an estimate the records cannot vouch
    for: its exceedance_probability at most the limit, its upper confidence bound
    (`exceedance_probability_upper`: few or no crossings seen) above it. Such a span may be
    long; more records decide. A result written before the bound was stored is not checked."""
    name, p, level = limit
    upper_name = "exceedance_probability_upper"
    if upper_name not in ds or level is None:
        return
    estimate = _broadcast(_limited(ds, name, level), like).reshape(passed.shape)
    upper = _broadcast(_limited(ds, upper_name, level), like).reshape(passed.shape)
    last = np.zeros_like(passed)
    rows = np.flatnonzero(passed.any(axis=1))
    last[rows, passed[rows].sum(axis=1) - 1] = True
    weak = last & (estimate <= p) & ~(upper <= p)
    if not weak.any():
        return
    from .models.random_outputs import CONFIDENCE
    i, j, at = _first(ds, like, weak, lengths)
    _warn(f"design: --clearance {level:g}: {int(weak.sum())} span(s) rest on a grid "
              f"length with too few crossings to vouch for a probability <= {p:g} (e.g. {at}: "
              f"exceedance_probability {estimate[i, j]:.3g}, its {CONFIDENCE:.0%} upper bound "
              f"{upper[i, j]:.3g}; exceedance_probability_upper), so max_span may be long: "
              f"counting vouches for it only once the records without a crossing are "
              f"{3.0 / -math.log1p(-p):.3g} times the test's duration; more realisations "
              "(base.realisations) narrow it")


def _margins(ds: xr.Dataset, fmin: float | None, limits: Limits,
             like: xr.DataArray) -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """The pass/fail logic max_span and refine_span share: per criterion, its margin (>= 0
    passes, NaN fails), the value interpolated on, and how (`_interpolate`), each an array
    shaped like `like` (the flags over the axes less direction and realisation, length
    last)."""
    shape = like.shape
    margins: dict[str, tuple[np.ndarray, np.ndarray, str]] = {}
    if fmin is not None:
        f = _broadcast(_worst(ds[frequency_of(ds)], "min"), like)
        margins["min_frequency"] = (f - fmin, f, "log")
    for criterion, (name, limit, level) in limits.items():
        q = _broadcast(_limited(ds, name, level), like)
        margins[criterion] = (limit - q, q - limit, "linear")
    if "state" in ds:
        meanings = _flags(ds["state"])
        bad = [v for v, m in meanings.items() if m in STATE_FAILURES]
        failed = _worst(ds["state"].isin(bad), "max")
        ok = np.where(_broadcast(failed, like) > 0, -1.0, 0.0)
        margins["state"] = (ok, np.full(shape, np.nan), "none")
    if "stability" in ds:
        meanings = _flags(ds["stability"])
        bad = [v for v, m in meanings.items() if m != "stable"]
        failed = _broadcast(_worst(ds["stability"].isin(bad), "max"), like) > 0
        if "growth_rate" in ds:
            g = _broadcast(_worst(ds["growth_rate"], "max"), like)
            failed |= ~(g <= 0.0)
        else:
            g = np.full(shape, np.nan)
        margins["stability"] = (np.where(failed, -1.0, 0.0), g, "linear")
    return margins


def _frequency_span(f1: Callable[[float], float], lo: float, hi: float, fmin: float,
                    tol: float) -> float:
    """The length in [lo, hi] (m) where f1(length) (Hz, falling with length) crosses fmin, by
    bisection to a thousandth of `tol`: for ends whose f1 is not ~ l^-2 (elastic clamps,
    K = k_t l / EI)."""
    for _ in range(MAX_BISECTIONS):
        if not hi - lo > 1e-3 * tol:
            break
        mid = 0.5 * (lo + hi)
        if f1(mid) >= fmin:
            lo = mid
        else:
            hi = mid
    return lo


def elastic_ends(ds: xr.Dataset) -> bool:
    """Whether result `ds` has elastic clamps (its `clamps` attribute, sweep.models.transverse
    .span_attrs): K = k_t l / EI grows with the span, so f1 is not ~ l^-2."""
    return str(ds.attrs.get("clamps", "")).startswith("elastic")


def interpolated(result: xr.Dataset, sources: dict[str, xr.Dataset]) -> dict[str, int]:
    """How many spans of `max_span`'s (or `governing_span`'s) result lie strictly between two
    grid lengths of the result they bind in (`sources`: name -> result; `limited_in` names
    it, else the one source), by kind: "response" (a response criterion or the growth rate
    interpolated linearly in l: a resonance or a tongue between the lengths can put the true
    limit shorter) and "frequency" (log f against log l with elastic ends or under a constant
    end load, not exact). A
    span that is a grid length (a state failure, a limit not crossed in the bracket, the
    grid's longest, a NaN) is not counted, nor is a frequency span of unloaded pinned or
    clamped ends (exact, f1 ~ l^-2)."""
    spans = np.asarray(result["max_span"].values, dtype=float).ravel()
    limited = np.asarray(result["limited_by"].values, dtype=str).ravel()
    where = (np.asarray(result["limited_in"].values, dtype=str).ravel()
             if "limited_in" in result else np.full(spans.size, next(iter(sources))))
    grids = {name: np.asarray(in_metres(ds)[LENGTH].values, float)
             for name, ds in sources.items()}           # each source's lengths, m
    counts = {"response": 0, "frequency": 0}
    for span, by, name in zip(spans, limited, where):
        if name not in sources or not np.isfinite(span):
            continue
        if np.any(np.isclose(grids[name], span, rtol=1e-12, atol=0.0)):
            continue
        if by != "min_frequency":
            counts["response"] += 1
        elif elastic_ends(sources[name]) or frequency_of(sources[name]) == "loaded_frequency":
            counts["frequency"] += 1
    return counts


def _shown_units(values: xr.DataArray) -> str:
    """A variable's units as a criterion line shows them: none for a pure number ("1")."""
    units = values.attrs.get("units", "")
    return "" if units == "1" else units


def _interpolate(la: float, lb: float, va: float, vb: float, limit: float, how: str) -> float:
    """Where (m), between the passing la and failing lb (m), the criterion's value crosses its
    limit: `log` (a lower limit, log v against log l: v falls from va >= limit to
    vb < limit), `linear` (an upper limit, v linear in l: v rises from va <= limit to
    vb > limit); la where it does not cross there (no margin, a missing value, a value that
    fails by its flag but not by its limit: an unstable flag with growth_rate <= 0)."""
    if how == "none" or not (np.isfinite(va) and np.isfinite(vb)):
        return float(la)
    if how == "log":
        if not (vb > 0 and limit > 0 and va >= limit > vb):
            return float(la)
        t = (math.log(limit) - math.log(va)) / (math.log(vb) - math.log(va))
        return float(math.exp(math.log(la) + t * (math.log(lb) - math.log(la))))
    if not va <= limit < vb:
        return float(la)
    t = (limit - va) / (vb - va)
    return float(la + t * (lb - la))


def _coordinate(ds: xr.Dataset, dim: str) -> xr.DataArray:
    """The coordinate of `dim` with its attributes (less `bounds`, whose variable stays
    behind, so the output names nothing it lacks)."""
    if dim in ds.coords:
        c = ds[dim]
        attrs = {k: v for k, v in c.attrs.items() if k != "bounds"}
        return xr.DataArray(c.values, dims=c.dims, attrs=attrs)
    return xr.DataArray(np.arange(ds.sizes[dim]), dims=(dim,),
                        attrs={"long_name": f"index along {dim}", "units": "1"})


def table(result: xr.Dataset) -> str:
    """A short text table of `max_span`: one line per combination of the other axes, their
    values (a parameter set's [points] values too), max_span in mm, limited_by and, for a span
    taken over axes (reduce_over), the binding_<axis> values ('-' where none binds)."""
    span = result["max_span"]
    dims = list(span.dims)
    on_points = [c for c in result.coords if c != POINT_DIM and result[c].dims == (POINT_DIM,)]
    columns = [(d, d) for d in dims] + [(c, POINT_DIM) for c in on_points]
    where = "limited_in" in result          # several results (sweep.governing)
    binding = [str(n) for n in result.data_vars if str(n).startswith(BINDING)]
    head = ([c for c, _ in columns] + ["max_span_mm", "limited_by"] + binding
            + (["in"] if where else []))

    def shown(value: Any) -> str:
        if isinstance(value, (float, np.floating)) and not np.isfinite(value):
            return "-"
        return f"{value:g}" if isinstance(value, (int, float, np.number)) else \
            (str(value) or "-")

    rows = []
    for index in np.ndindex(*span.shape):
        at = dict(zip(dims, index))
        values = [f"{result[c].values[at[d]]:g}" if np.asarray(result[c].values).dtype.kind
                  in "fiu" else str(result[c].values[at[d]]) for c, d in columns]
        s = float(span.values[index])
        by = str(result["limited_by"].values[index])
        rows.append([*values, f"{s * 1e3:.2f}" if np.isfinite(s) else "nan",
                     by if np.isfinite(s) else f"{by} (shortest span fails)"]
                    + [shown(result[b].values[index]) for b in binding]
                    + ([str(result["limited_in"].values[index])] if where else []))
    widths = [max(len(r[j]) for r in [head, *rows]) for j in range(len(head))]
    lines = ["  ".join(c.rjust(w) if j < len(head) - 1 else c
                       for j, (c, w) in enumerate(zip(r, widths))) for r in [head, *rows]]
    return "\n".join(lines)


MIN_REFINE_TOLERANCE = 1e-9
"""Finest --tolerance relative to the longest length: a bracket is halved about 30 times
from a 1 m grid step to it, far above the round-off where bisection stops halving."""
MAX_BISECTIONS = 64
"""Most halvings of one bracket (a bound whatever the tolerance)."""


def refine_span(ds: xr.Dataset, *, min_frequency: Limit = None,
                max_amplitude: Limit = None, quantity: str | None = None,
                max_deflection: Limit = None, max_strain: Limit = None,
                max_rms: Limit = None, max_peak: Limit = None,
                clearance: Limit = None, max_probability: float | None = None,
                tolerance: float | str = 1e-3, over: str | Sequence[str] = ()
                ) -> xr.Dataset:
    """`max_span` refined beyond the grid by bisecting on length with the engine itself.

    For every combination of the result's other axes whose grid max_span is bracketed (a
    passing grid length l_a and the first failing one l_b; not "grid", not NaN), the scene
    stored in the result (`attrs["scene"]`) is run again at one trial length (`axes.length` a
    one-value axis, every other axis fixed to the combination's value as a one-element list;
    a stepped result's continuation axis is kept whole and the combination's value read off
    it), the same criteria (`_margins`) are evaluated on that one-length result, and the
    bracket is halved until it is below `tolerance` (m). max_span is then the bracket's
    passing end (conservative: within `tolerance` below the true span), limited_by the
    criterion its failing end fails.

    The frequency criterion needs no run: natural_frequency is the closed form of the
    unloaded span, f1 ~ l^-2 with pinned or clamped ends, so interpolating log f against
    log l between the grid lengths is exact there; with elastic ends (K = k_t l / EI, f1 not
    ~ l^-2) or a constant end load (`loaded_frequency`, sweep.models.stability: the load's
    share grows as l^2) the length where the closed-form frequency crosses the limit is
    bisected instead. Where
    only it fails at l_b the span is that length (no run; with only min_frequency the
    refinement costs no run at all). Where another criterion fails at
    l_b too and the frequency span l_f lies inside the bracket, one run at l_f decides:
    passing, the span is l_f; failing, the bisection runs on [l_a, l_f].

    `over` (axes, not direction) takes the refined spans over those axes as max_span does
    (`reduce_over`): every combination is refined, then the shortest binds.

    Returns max_span's Dataset with the refined spans; attributes `refine_runs` (engine runs
    made), `refine_tolerance` (m) and `refinement` (how). Raises UserError (one line) as
    max_span, for direction in `over` (the bisection reads the worst of both directions and
    cannot say which binds), for a result without its scene, a non-positive tolerance, an
    axis the stored scene lacks, a stepped result stepped along length (its branch depends on the path), and a
    random result (one with `realisation`: its criteria are Monte Carlo means of a few
    records, whose scatter from one length to the next is more than a bisection resolves;
    refine the scene's length axis, and add records).
    """
    from .run import run
    from .scene import load_scene_text

    tol = _number(tolerance, "--tolerance", "0.001", "m")
    if isinstance(ds, xr.Dataset) and REALISATION in ds.dims:
        raise UserError("design: --refine bisects between lengths, and a random result's "
                        "criteria are Monte Carlo means whose scatter from one length to the "
                        "next is more than a bisection resolves; for a random result refine "
                        "the length axis in the scene instead (and add base.realisations)")
    criteria = dict(min_frequency=min_frequency, max_amplitude=max_amplitude,
                    max_deflection=max_deflection, max_strain=max_strain, max_rms=max_rms,
                    max_peak=max_peak, clearance=clearance, max_probability=max_probability)
    c, axes, limits = validated(ds, quantity=quantity, **criteria)
    over = over_axes(over, axes)
    if DIRECTION in over:
        raise UserError("design --refine: --over direction: the bisection reads the worse of "
                        "both directions at each length and cannot say which of them binds; "
                        "leave direction out of --over (max_span is the worse direction's "
                        "already), or leave --refine out")
    grid = max_span(ds, quantity=quantity, **criteria)
    fmin = c["min_frequency"]
    text = ds.attrs.get("scene")
    if not isinstance(text, str) or not text.strip():
        raise UserError("design --refine: the result has no 'scene' attribute to run again "
                        "(give a result written by 'sweep run ... -o FILE.nc')")
    # the reader's machine decides how the runs execute, never the file's scene
    here = {"run.backend": "threads", "run.workers": 0, "run.threads": 0}
    stored = load_scene_text(text, source="the result's scene", overrides=here)
    loaded = frequency_of(ds) == "loaded_frequency"
    scene_axes = set(stored.axes) | ({POINT_DIM} if stored.points else set())
    stepped = ds.attrs.get("continuation_axis")
    stepped = stepped if isinstance(stepped, str) and stepped in ds.dims else None
    if stepped == LENGTH:
        raise UserError("design --refine: the result is stepped along length (its branch "
                        "depends on the path); refine on a finer length axis instead")
    ds = ds.sortby(LENGTH)
    others = tuple(a for a in axes if a not in (LENGTH, *WORST_OVER))
    missing = [a for a in others if a not in scene_axes or a not in ds.coords]
    if missing:
        raise UserError(f"design --refine: axis {', '.join(missing)} is not an axis of the "
                        "result's stored scene, so it cannot be run again (refine the result "
                        "'sweep run' wrote)")
    extra = sorted(a for a in scene_axes if a not in ds.dims)
    if extra:
        raise UserError(f"design --refine: the result's stored scene has axis "
                        f"{', '.join(extra)} that its data do not: the file was not written "
                        "by 'sweep run' as it stands (refine the result 'sweep run' wrote)")
    units = ds[LENGTH].attrs.get("units")
    if units != "m":
        raise UserError(f"design --refine: the result's length is in {units!r}, not metres: "
                        "the stored scene would be run at the wrong spans (refine the result "
                        "'sweep run' wrote)")
    lengths = np.asarray(ds[LENGTH].values, float)
    finest = MIN_REFINE_TOLERANCE * float(np.max(np.abs(lengths)))
    if not tol >= finest:
        raise UserError(f"--tolerance {tol:g}: below what a bisection on these lengths can "
                        f"reach ({MIN_REFINE_TOLERANCE:g} of the longest, {finest:.3g} m; "
                        "give --tolerance 0.001 or any length down to that)")
    nonfrequency = [k for k in CRITERIA if k != "min_frequency"]
    runs = 0

    def scene_at(point: dict[str, Any], length: float) -> dict[str, Any]:
        """The overrides that make the stored scene the one-length run at `point`."""
        overrides: dict[str, Any] = {f"axes.{LENGTH}": [float(length)], **here}
        for a, v in point.items():
            if a == POINT_DIM:               # the parameter set's values, as scalars
                overrides.update({BY_AXIS[k].dotted: float(values[int(v)])
                                  for k, values in stored.points.items()})
            elif a != stepped:
                overrides[f"axes.{a}"] = [v.item() if hasattr(v, "item") else v]
        return overrides

    def fails(point: dict[str, Any], length: float) -> list[str]:
        """The non-frequency criteria the engine's one-length run at `length` fails."""
        nonlocal runs
        one = run(load_scene_text(text, source="the result's scene",
                                  overrides=scene_at(point, length)), progress=False)
        runs += 1
        if stepped is not None:
            one = one.sel({stepped: [point[stepped]]})
        name = "state" if "state" in one else "stability"
        like = _like(one[name])
        like = like.transpose(*[a for a in others if a in like.dims], LENGTH)
        margins = _margins(one, None, limits, like)
        return _binding_order([k for k in nonfrequency if k in margins
                               and not np.all(margins[k][0] >= 0.0)],
                              lambda k: margins[k][1])

    def frequency_at(point: dict[str, Any], length: float) -> float:
        """The closed-form f1 (Hz) of the stored scene at `length` and `point`: no run."""
        from .grid import coordinates, parameters
        from .models.modal import oscillator
        scene = load_scene_text(text, source="the result's scene", overrides=scene_at(
            point, length))
        coeffs = oscillator(parameters(scene, coordinates(scene)))
        if loaded:
            from .models.stability import loaded_frequency
            f1 = loaded_frequency(coeffs, int(scene.get("model.modes")))
        else:
            f1 = coeffs["natural_frequency"]
        return float(np.min(np.asarray(f1, float)))

    spans = grid["max_span"].values.copy().reshape(-1)
    limited = grid["limited_by"].values.copy().reshape(-1)
    shape = grid["max_span"].shape
    for flat_i, index in enumerate(np.ndindex(*shape)):
        if limited[flat_i] == "grid" or not np.isfinite(spans[flat_i]):
            continue
        point = {a: ds[a].values[i] for a, i in zip(others, index)}
        sub = ds.sel({a: v for a, v in point.items()}) if point else ds
        sub = sub.expand_dims({a: [v] for a, v in point.items()}) if point else sub
        like_name = "state" if "state" in sub else "stability"
        like = _like(sub[like_name]).transpose(*others, LENGTH)
        margins = {k: (m.reshape(-1), v.reshape(-1), how)
                   for k, (m, v, how) in _margins(sub, fmin, limits, like).items()}
        passes = np.logical_and.reduce([m >= 0.0 for m, _, _ in margins.values()])
        b = int(np.argmin(passes))
        a = b - 1
        lo, hi = float(lengths[a]), float(lengths[b])
        failing = _binding_order([k for k in CRITERIA if k in margins
                                  and not margins[k][0][b] >= 0.0],
                                 lambda k: margins[k][1][b])
        l_f = math.inf
        if "min_frequency" in failing:
            f = margins["min_frequency"][1]
            l_f = _interpolate(lo, hi, f[a], f[b], fmin, "log")
            if loaded or stored.get("clamps.rotation") == "elastic":   # f1 not ~ l^-2
                l_f = _frequency_span(lambda length: frequency_at(point, length), lo, hi,
                                      fmin, tol)
        others_fail = [k for k in failing if k != "min_frequency"]
        if not others_fail:                      # the frequency alone: no run
            spans[flat_i], limited[flat_i] = l_f, "min_frequency"
            continue
        by = others_fail[0]
        if lo < l_f < hi:
            at_f = fails(point, l_f)
            if not at_f:
                spans[flat_i], limited[flat_i] = l_f, "min_frequency"
                continue
            hi, by = l_f, at_f[0]
        for _ in range(MAX_BISECTIONS):
            if not hi - lo > tol:
                break
            mid = 0.5 * (lo + hi)
            at_mid = fails(point, mid)
            if at_mid:
                hi, by = mid, at_mid[0]
            else:
                lo = mid
        spans[flat_i], limited[flat_i] = lo, by
    grid["max_span"].values = spans.reshape(shape)
    grid["limited_by"].values = limited.reshape(shape)
    grid["max_span"].attrs["long_name"] = f"{SPAN_LONG_NAME}, refined by bisection with the engine"
    grid["max_span"].attrs["comment"] = (
        f"the passing end of a bracket bisected on length with engine runs of the result's scene "
        f"to below {tol:g} m (conservative: at most that below the true span; min_frequency "
        f"without a run), the longest grid length where none fails. {NAN_SPAN}")
    grid.attrs["refine_runs"] = np.int32(runs)
    grid.attrs["refine_tolerance"] = float(tol)
    grid.attrs["refinement"] = (
        f"bisection on length with engine runs of the result's scene until the bracket is "
        f"below {tol:g} m, max_span its passing end (conservative); min_frequency by "
        f"log f vs log l interpolation, exact for the unloaded f1 ~ l^-2 (elastic clamps: "
        f"bisection on the closed-form f1), no run")
    grid.attrs["history"] += f"; refined by bisection ({runs} engine runs, tolerance {tol:g} m)"
    return reduce_over(grid, over) if over else grid
