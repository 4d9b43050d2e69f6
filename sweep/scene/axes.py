"""``[axes]``: each swept key's values, from a list or a ``{start, stop, num, spacing}`` range
table, as a read-only float64 array (strictly monotonic, within the key's bounds). Ranges are
exact: `linear_range` rounds each exact rational value once, `log_range` keeps short decimals.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np

from .. import schema
from .document import _VALUE_SECTIONS
from .messages import _close, _fail, _show, _suggestion
from .values import _as_float, _as_int, _check_bounds

RANGE_KEYS: tuple[str, ...] = ("start", "stop", "num", "spacing")
LOG_DIGITS = 15
"""Significant digits of the values of a log-spaced range (its endpoints are kept exactly)."""
MAX_AXIS_POINTS = 10_000_000
MAX_GRID_POINTS = 10_000_000_000
"""Most points of the product of the axes, refused from the axes' sizes before any value is
built (the memory check later refuses what this machine cannot hold)."""
_COMMON_AXES = ("length", "load_amplitude", "frequency_ratio", "frequency", "damping_ratio")
_SWEEPABLE_TEXT = ", ".join(dict.fromkeys([*(a for a in _COMMON_AXES if a in schema.BY_AXIS),
                                          *schema.BY_AXIS]))


def _flatten_axes(table: dict[str, Any]) -> dict[str, Any]:
    """``[axes] cable.length = ...`` parses as a nested table: make it ``"cable.length"``."""
    flat: dict[str, Any] = {}
    for entry, value in table.items():
        if entry in _VALUE_SECTIONS and isinstance(value, dict):
            flat.update({f"{entry}.{name}": v for name, v in value.items()})
        else:
            flat[entry] = value
    return flat


def _check_axes(table: dict[str, Any]) -> dict[str, np.ndarray]:
    """Validate ``[axes]``: axis name -> read-only float64 array, in table order."""
    _check_grid_size(table)
    axes: dict[str, np.ndarray] = {}
    for entry, raw in table.items():
        axis = _axis_name(entry)
        if axis in axes:
            _fail(f"axis '{entry}'", f"axis '{axis}' is given twice", "keep one of the entries")
        axes[axis] = _axis_values(axis, raw)
    return axes


def _check_grid_size(table: dict[str, Any]) -> None:
    """Refuse a grid of more than MAX_GRID_POINTS from its axes' sizes (list lengths and range
    nums), before building any axis: a 10^7 x 10^7 grid is refused at once."""
    sizes = []
    for entry, raw in table.items():
        if isinstance(raw, list):
            sizes.append((entry, len(raw)))
        elif isinstance(raw, dict) and isinstance(raw.get("num"), int) \
                and not isinstance(raw.get("num"), bool) and raw["num"] >= 1:
            sizes.append((entry, raw["num"]))
    total = math.prod(n for _, n in sizes)
    if total > MAX_GRID_POINTS:
        shape = " x ".join(f"{n:,}" for _, n in sizes)
        _fail(f"axes {', '.join(repr(e) for e, _ in sizes)}", f"a grid of {shape} = "
              f"{total:.3g} points, more than {MAX_GRID_POINTS:.0e}: its results alone need "
              f"over {total * 8 / 2**30:,.0f} GiB (8 bytes a point at the least)",
              "give fewer values (smaller nums), or split the sweep into several runs")


def _axis_or_none(entry: str) -> str | None:
    """The axis an ``[axes]`` entry name means (axis name or sweepable dotted key), or None."""
    if entry in schema.BY_AXIS:
        return entry
    key = schema.BY_DOTTED.get(entry)
    return key.axis if key is not None else None


def _axis_name(entry: str, where: str | None = None) -> str:
    """The axis an ``[axes]`` entry names; refuse unknown and non-sweepable names (`where`
    names the entry in the message; default ``axis 'ENTRY'``)."""
    where = where or f"axis '{entry}'"
    axis = _axis_or_none(entry)
    if axis is not None:
        return axis
    sweepable = _SWEEPABLE_TEXT
    key = schema.BY_DOTTED.get(entry)
    same_name = [k for k in schema.KEYS if k.name == entry]
    if key is None and same_name and all(k.axis is None for k in same_name):
        key = same_name[0]
    if key is not None:
        _fail(where, f"'{key.dotted}' cannot be swept",
              f"sweepable: {sweepable}; set {key.dotted} as a single value in [{key.section}]")
    candidates = [*schema.BY_AXIS, *(k.dotted for k in schema.BY_AXIS.values())]
    guess = _close(entry, candidates) or next((k.axis for k in same_name if k.axis), None)
    _fail(where, "unknown axis",
          _suggestion(guess, f"use one of the sweepable axes; sweepable: {sweepable}"))


def _axis_values(axis: str, raw: Any) -> np.ndarray:
    """An axis's values from a list or a range table, checked against the key's bounds."""
    where = f"axis '{axis}'"
    if isinstance(raw, list):
        values = _axis_list(where, raw)
    elif isinstance(raw, dict):
        values = _axis_range(where, raw)
    else:
        _fail(where, f"must be a list of values or a range table, got {_show(raw)}",
              f"write e.g. {axis} = [0.5, 1.0] or {axis} = {{start = 0.5, stop = 1.0, num = 11}}")
    _check_monotonic(where, values)
    _check_bounds(where, schema.BY_AXIS[axis], values)
    values.flags.writeable = False
    return values


def _axis_list(where: str, raw: list) -> np.ndarray:
    if not raw:
        _fail(where, "empty list", "give at least one value")
    fix = "give a list of numbers, e.g. [0.5, 0.7, 1.0]"
    return np.array([_as_float(where, v, fix) for v in raw], dtype=np.float64)


def _axis_range(where: str, raw: dict) -> np.ndarray:
    """Values of a ``{start, stop, num, spacing}`` table (linear or log)."""
    fix = "write e.g. {start = 0.5, stop = 3.0, num = 26, spacing = \"linear\"}"
    unknown = [k for k in raw if k not in RANGE_KEYS]
    if unknown:
        _fail(where, f"unknown key '{unknown[0]}' in range table",
              f"remove it; a range table takes only {', '.join(RANGE_KEYS)}")
    missing = [k for k in ("start", "stop", "num") if k not in raw]
    if missing:
        _fail(where, f"range table needs '{missing[0]}'", fix)
    start = _as_float(where, raw["start"], fix)
    stop = _as_float(where, raw["stop"], fix)
    num = _as_int(where, raw["num"], fix)
    if not 1 <= num <= MAX_AXIS_POINTS:
        _fail(where, f"num must be between 1 and {MAX_AXIS_POINTS}, got {_show(raw['num'])}", fix)
    spacing = raw.get("spacing", "linear")
    if spacing not in schema.AXIS_SPACINGS:
        _fail(where, f"spacing must be one of {', '.join(schema.AXIS_SPACINGS)}, "
                     f"got {_show(spacing)}", 'write spacing = "linear" or spacing = "log"')
    if spacing == "log":
        if start <= 0 or stop <= 0:
            _fail(where, f"log spacing needs start and stop > 0, got start = {start!r}, "
                         f"stop = {stop!r}", 'use positive limits or spacing = "linear"')
        return log_range(start, stop, num)
    return linear_range(start, stop, num)


def linear_range(start: float, stop: float, num: int) -> np.ndarray:
    """``num`` evenly spaced values from start to stop, each the float nearest to its exact value.

    start and stop are read as the decimals they print as (``repr``: what a user wrote, e.g.
    0.3), and value i is the exact rational (start (num-1-i) + stop i) / (num-1) rounded once
    to float64. So {start = 0.3, stop = 1.2, num = 10} gives 0.4, not linspace's
    0.39999999999999997, and the endpoints are start and stop exactly.
    """
    if num == 1:
        return np.array([start], dtype=np.float64)
    first, last = Fraction(repr(start)), Fraction(repr(stop))
    scale = math.lcm(first.denominator, last.denominator)
    a, b = int(first * scale), int(last * scale)
    steps = num - 1
    denominator = scale * steps
    if max(abs(a), abs(b)) * steps < 2**53 and denominator < 2**53:
        # Every integer here is exact in float64, so one IEEE division rounds correctly.
        i = np.arange(num, dtype=np.int64)
        numerators = a * (steps - i) + b * i
        return numerators.astype(np.float64) / float(denominator)
    # Python's int / int is correctly rounded at any size.
    return np.fromiter(((a * (steps - i) + b * i) / denominator for i in range(num)),
                       dtype=np.float64, count=num)


def log_range(start: float, stop: float, num: int) -> np.ndarray:
    """``num`` log-spaced values from start to stop (both > 0), rounded to LOG_DIGITS
    significant digits, endpoints exact.

    A value that is a short decimal (1, 10, 100, 1000 for {start = 1, stop = 1000, num = 4})
    is that decimal's float exactly; any other is within 5e-15 relative of start (stop /
    start)^(i / (num - 1)) (plus float64 geomspace's few ulps where long double is double). If rounding would merge neighbours, the unrounded values are kept.
    """
    # In long double where the platform has it: within an ulp of the exact value before rounding.
    values = np.geomspace(np.longdouble(start), np.longdouble(stop), num).astype(np.float64)
    rounded = np.fromiter((float(f"{v:.{LOG_DIGITS}g}") for v in values), dtype=np.float64,
                          count=num)
    rounded[0], rounded[-1] = start, stop
    steps = np.diff(rounded)
    if np.all(steps > 0) or np.all(steps < 0):
        return rounded
    values[0], values[-1] = start, stop
    return values


def _check_monotonic(where: str, values: np.ndarray) -> None:
    steps = np.diff(values)
    if not (np.all(steps > 0) or np.all(steps < 0)):
        _fail(where, "values must be strictly increasing or strictly decreasing",
              "sort them and remove duplicates")
