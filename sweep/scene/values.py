"""The document's keys and values against the schema (`sweep.schema`): the top level (name,
description, the sections), each section's keys (an unknown one gets a suggestion), and one
value's kind, bounds and choices, with the message and example that say how to fix it.

Kinds of value: "float", "int", "bool", "str", and "floats", a TOML list of finite numbers
(may be empty, each within the key's bounds; ints accepted, bools not), stored as a tuple of
Python floats, e.g. ``outputs.snapshot_times``.
"""

from __future__ import annotations

import math
from typing import Any, NoReturn

import numpy as np

from .. import schema
from ..models import rules
from .document import _VALUE_SECTIONS, _toml_value
from .messages import _close, _fail, _guess_key, _section_not_table, _show, _suggestion
from .reading import _check_text

MAX_INT = 2**63 - 1
"""Largest size of an integer key's value (int64; larger ones cannot even be compared as floats)."""

# How to fix an out-of-range value, for the keys users most often get wrong.
_HINTS: dict[str, str] = {
    "cable.length": "give the span length in metres",
    "cable.density": "give the density in kg/m^3, e.g. 8900 for copper",
    "cable.area": "give the cross-sectional area in m^2, e.g. 6e-6 for 6 mm^2",
    "cable.inertia": "give the bending second moment of area in m^4, e.g. 2.865e-12 (a solid "
                     "round 6 mm^2 section), or leave it out for A^2/(4 pi)",
    "cable.youngs_modulus": "give Young's modulus in Pa, e.g. 1.1e11 for copper",
    "cable.damping_ratio": "give the damping ratio as a fraction of critical, e.g. 0.02 for 2 %",
    "model.membrane": "use 0.375 (the paper), 0.25 (classical stretching) or 0 (none)",
    "load.frequency_ratio": "give the load frequency as a multiple of w1, e.g. 2.0",
    "load.frequency": "give the load frequency in Hz",
    "base.acceleration": "give the peak base acceleration in m/s^2, e.g. 4.9, or use "
                         "base.acceleration_g",
    "base.acceleration_g": "give the peak base acceleration in g, e.g. 0.5",
    "base.frequency": "give the base excitation frequency in Hz, e.g. 20.0",
    "base.frequency_ratio": "give the base excitation frequency as a multiple of f1, e.g. 1.0",
    "solver.t_end": "give the simulated time in seconds, e.g. 5.0",
    "solver.transits": "give the end time in wave transits l/a, e.g. 8.0",
    "solver.intervals": "give the number of spatial intervals per span, e.g. 1000",
    "solver.courant": "use 1.0, which is exact at the nodes",
    "outputs.snapshot_times": "give the snapshot times in seconds, e.g. [0.0001, 0.0002]",
    "solver.rtol": "use e.g. 1e-8; typical values are 1e-6 to 1e-10",
    "solver.atol": "give a small positive absolute tolerance, e.g. 1e-12 (m for q)",
    "solver.max_steps": "give a positive step budget, e.g. 1000000",
    "metrics.tail": "give the tail window as a fraction of t_end, e.g. 0.5",
    "metrics.tolerance": "give a relative tolerance, e.g. 0.02",
    "run.threads": "give a thread count, or 0 for all cores",
}

_SECTIONS_TEXT = ("remove it, or move it into its section: the top level holds name, "
                  "description and the sections "
                  + ", ".join(f"[{s}]" for s in schema.SECTIONS))


def _check_top_level(doc: dict[str, Any]) -> None:
    """Only ``name``, ``description`` and the schema's sections may appear at the top."""
    for key, value in doc.items():
        if key in schema.TOP_LEVEL:
            continue
        if key in schema.SECTIONS:
            if not isinstance(value, dict):
                _section_not_table(key, value)
            continue
        _unknown_top_level(key, value)


def _unknown_top_level(key: str, value: Any) -> NoReturn:
    """Report an unknown top-level key or section, with a suggestion."""
    if isinstance(value, dict) and value:
        first = next(iter(value))
        section = _close(key, _VALUE_SECTIONS)
        guess = _guess_key(first, section) if section else _guess_key(first)
        _fail(f"scene key '{key}.{first}'", f"unknown section '{key}'",
              _suggestion(guess or section, _SECTIONS_TEXT))
    guess = _close(key, [*schema.TOP_LEVEL, *schema.SECTIONS]) or _guess_key(key)
    _fail(f"scene key '{key}'", "unknown top-level key", _suggestion(guess, _SECTIONS_TEXT))


def _check_name(value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        _fail("scene key 'name'", f"must be a non-empty string, got {_show(value)}",
              'write e.g. name = "my-sweep"')
    _check_text("scene key 'name'", value, "the name", 'write e.g. name = "my-sweep"')
    return value


def _check_description(value: Any) -> str:
    if not isinstance(value, str):
        _fail("scene key 'description'", f"must be a string, got {_show(value)}",
              'write e.g. description = "what the sweep is for"')
    _check_text("scene key 'description'", value, "the description",
                'write e.g. description = "what the sweep is for"')
    return value


def _check_sections(doc: dict[str, Any]) -> dict[str, Any]:
    """Validate every scalar key present in the sections; dotted key -> value."""
    given: dict[str, Any] = {}
    for section in _VALUE_SECTIONS:
        for name, raw in doc.get(section, {}).items():
            dotted = f"{section}.{name}"
            key = schema.BY_DOTTED.get(dotted)
            if dotted == "run.scheduler":
                _fail(f"scene key '{dotted}'", "a scene cannot choose the dask cluster it runs "
                      "on (connecting lets the cluster run code in this process)",
                      "remove it, and pass --scheduler tcp://HOST:8786 on the command line, "
                      "or sweep.run(scene, scheduler=...)")
            if key is None:
                _unknown_section_key(section, dotted)
            given[dotted] = _check_value(f"scene key '{dotted}'", key, raw)
    return given


def _unknown_section_key(section: str, dotted: str) -> NoReturn:
    valid = [k.name for k in schema.KEYS if k.section == section]
    fallback = f"remove it, or use one of the valid keys in [{section}]: {', '.join(valid)}"
    _fail(f"scene key '{dotted}'", "unknown key",
          _suggestion(_guess_key(dotted.partition(".")[2], section), fallback))


def _check_value(where: str, key: schema.Key, raw: Any) -> Any:
    """A value of the key's kind, within its bounds and choices."""
    if key.kind == "floats":
        return _as_floats(where, key, raw)
    if key.kind == "pairs":
        return _as_pairs(where, key, raw)
    if isinstance(raw, (dict, list)):
        _fail(where, f"must be a single value, got {_show(raw)}", _container_fix(key, raw))
    if key.kind == "float":
        value: Any = _as_float(where, raw, _example(key))
    elif key.kind == "int":
        value = _as_int(where, raw, _example(key))
    elif key.kind == "bool":
        value = _as_bool(where, key, raw)
    else:
        value = _as_choice(where, key, raw)
    rules.check_value(where, key.dotted, value)
    if key.kind in ("float", "int"):
        _check_bounds(where, key, value)
    return value


def _as_floats(where: str, key: schema.Key, raw: Any) -> tuple[float, ...]:
    """A tuple of finite floats from a list of numbers (may be empty), each within bounds."""
    fix = f"write e.g. {key.name} = [0.0001, 0.0002]"
    if not isinstance(raw, list):
        _fail(where, f"must be a list of numbers, got {_show(raw)}", fix)
    values = []
    for number, item in enumerate(raw, start=1):
        value = _as_float(where, item, fix, f"item {number} of the list ")
        if not _within(key, np.array(value)):
            _fail(where, f"item {number} of the list must be {_bounds_text(key)}, "
                         f"got {_show(item)}", _HINTS.get(key.dotted) or _generic_hint(key))
        values.append(value)
    return tuple(values)


MAX_SPECTRUM_BREAKPOINTS = 200
"""Most breakpoints of a random spectrum (base.asd_g2, base.asd)."""


def _as_pairs(where: str, key: schema.Key, raw: Any) -> tuple[tuple[float, float], ...]:
    """A table of breakpoints: 2 to MAX_BREAKPOINTS [x, y] pairs of finite numbers > 0, x
    strictly increasing (``base.levels_g``: x in Hz, y in g; a spectrum, ``base.asd_g2`` or
    ``base.asd``: up to MAX_SPECTRUM_BREAKPOINTS, y in g^2/Hz or (m/s^2)^2/Hz)."""
    from ..models.excitation import MAX_BREAKPOINTS
    if key.name.startswith("asd"):
        MAX_BREAKPOINTS = MAX_SPECTRUM_BREAKPOINTS      # read by the models, not a kernel table
        unit = "g^2/Hz" if key.name == "asd_g2" else "(m/s^2)^2/Hz"
        fix = (f"write e.g. {key.name} = [[20.0, 0.026], [50.0, 0.16], [800.0, 0.16], "
               f"[2000.0, 0.026]] (Hz, {unit})")
    else:
        fix = f"write e.g. {key.name} = [[5.0, 0.5], [100.0, 0.6]] (Hz, g)"
    if not isinstance(raw, list) or not 2 <= len(raw) <= MAX_BREAKPOINTS:
        _fail(where, f"must be a list of 2 to {MAX_BREAKPOINTS} [frequency, level] pairs, got "
              f"{_show(raw)}", fix)
    pairs = []
    for number, item in enumerate(raw, start=1):
        if not isinstance(item, list) or len(item) != 2:
            _fail(where, f"item {number} must be a pair [frequency, level], got {_show(item)}",
                  fix)
        x = _as_float(where, item[0], fix, f"item {number}'s frequency ")
        y = _as_float(where, item[1], fix, f"item {number}'s level ")
        if not (x > 0.0 and y > 0.0):
            _fail(where, f"item {number} must have a frequency and a level > 0 (a log-log "
                  f"table), got {_show(item)}", fix)
        if pairs and not x > pairs[-1][0]:
            _fail(where, f"item {number}'s frequency {_show(x)} Hz must be above the one "
                  f"before ({_show(pairs[-1][0])} Hz)", "list the breakpoints in order of "
                  "increasing frequency, each frequency once")
        pairs.append((x, y))
    return tuple(pairs)


def _container_fix(key: schema.Key, raw: Any) -> str:
    """How to fix a list or table given where a single value is expected."""
    if isinstance(raw, list) and key.axis is not None:
        return f"to sweep it, put it under [axes] as {key.axis} = [...]"
    if isinstance(raw, list):
        return f"{key.dotted} cannot be swept; {_example(key)}"
    return _example(key)


def _example(key: schema.Key) -> str:
    """'write e.g. rtol = 1e-08', or a generic hint for keys without a default."""
    if key.default is None:
        if key.dotted in _HINTS:
            return _HINTS[key.dotted]
        return f"write e.g. {key.name} = 1.0" if key.kind == "float" else "give a single value"
    return f"write e.g. {key.name} = {_toml_value(key.default)}"


def _as_float(where: str, raw: Any, fix: str, what: str = "") -> float:
    """A finite float from an int or float (never a bool); `what` names the value in the
    message when it is not the key's own (an item of a list)."""
    if isinstance(raw, bool) or not isinstance(raw, (int, float)):
        _fail(where, f"{what}must be a number, got {_show(raw)}", fix)
    try:
        value = float(raw)
    except OverflowError:
        value = math.inf
    if not math.isfinite(value):
        _fail(where, f"{what}must be a finite number, got {_show(raw)}", fix)
    return value


def _as_int(where: str, raw: Any, fix: str) -> int:
    """An int from an int or an integral float such as 1e6 (never a bool)."""
    value = _as_float(where, raw, fix) if isinstance(raw, float) else raw
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        _fail(where, f"must be a whole number, got {_show(raw)}", fix)
    if isinstance(value, float) and not value.is_integer():
        _fail(where, f"must be a whole number, got {_show(raw)}", fix)
    if abs(value) > MAX_INT:
        _fail(where, f"must be at most {MAX_INT:,} in size, got {_show(raw)}", fix)
    return int(value)


def _as_bool(where: str, key: schema.Key, raw: Any) -> bool:
    if not isinstance(raw, bool):
        _fail(where, f"must be true or false, got {_show(raw)}",
              f"write {key.name} = true or {key.name} = false, without quotes")
    return raw


def _as_choice(where: str, key: schema.Key, raw: Any) -> str:
    """A string, one of the key's choices if it has any."""
    if not isinstance(raw, str):
        _fail(where, f"must be a string, got {_show(raw)}", f'write {key.name} = "..." with quotes')
    _check_text(where, raw, "the value", f'write {key.name} = "..." in UTF-8 text')
    if key.choices and raw not in key.choices:
        listed = ", ".join(f"'{c}'" for c in key.choices)
        _fail(where, f"must be one of {listed}, got {_show(raw)}",
              _suggestion(_close(raw, key.choices), "use one of those"))
    return raw


def _check_bounds(where: str, key: schema.Key, values: Any) -> None:
    """Refuse a scalar, or the first element of an axis, outside the key's bounds."""
    array = np.atleast_1d(np.asarray(values, dtype=float))
    bad = ~_within(key, array)
    if not bad.any():
        return
    fix = _HINTS.get(key.dotted) or _generic_hint(key)
    if np.ndim(values) == 0:
        _fail(where, f"must be {_bounds_text(key)}, got {_show(values)}", fix)
    value = float(array[np.argmax(bad)])
    _fail(where, f"value {_show(value)} is out of range: must be {_bounds_text(key)}", fix)


def _within(key: schema.Key, array: np.ndarray) -> np.ndarray:
    """Elementwise: does each value satisfy the key's minimum and maximum?"""
    ok = np.ones(array.shape, dtype=bool)
    if key.minimum is not None:
        ok &= array > key.minimum if key.exclusive_min else array >= key.minimum
    if key.maximum is not None:
        ok &= array < key.maximum if key.exclusive_max else array <= key.maximum
    return ok


def _bounds_text(key: schema.Key) -> str:
    """E.g. '> 0 m' or '>= 1e-14 and <= 0.1'."""
    units = f" {key.units}" if key.units not in ("", "1") else ""
    if key.units == schema.G_UNITS:
        units = " g"
    parts = []
    if key.minimum is not None:
        parts.append(f"{'>' if key.exclusive_min else '>='} {key.minimum:g}{units}")
    if key.maximum is not None:
        parts.append(f"{'<' if key.exclusive_max else '<='} {key.maximum:g}{units}")
    return " and ".join(parts)


def _generic_hint(key: schema.Key) -> str:
    units = f" in {key.units}" if key.units not in ("", "1") else ""
    return f"give the {key.long_name or key.name}{units} within that range"
