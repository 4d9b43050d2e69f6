"""The scene-key reference, generated from `sweep.schema` so that docs and code cannot drift.

    sweep keys                      # every scene key: type, default, units, allowed values, help
    sweep keys solver               # one section (or one dotted key, e.g. solver.rtol)
    sweep keys --markdown > docs/scene-keys.md

The committed docs/scene-keys.md is this module's `markdown()`; tests/test_keys.py fails when the
two differ (the schema changed and the page was not regenerated).
"""

from __future__ import annotations

import math
import textwrap
from typing import Any

from . import schema
from .errors import UserError

REGENERATE = "sweep keys --markdown > docs/scene-keys.md"
"""The command that rewrites docs/scene-keys.md from the schema."""

_UNITS_TEXT = {"1": "1 (dimensionless)"}


def toml_value(value: Any) -> str:
    """A default as it would be written in a scene file (TOML syntax); '' when there is none."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return "nan" if math.isnan(value) else _float(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return str(value)


def _float(value: float) -> str:
    """Python's round-trip text, or the shortest exponent form that reads back as `value` where
    that is clearly shorter; exponents plain: 1e-8, 1.1e11, 8900.0."""
    def plain(text: str) -> str:
        mantissa, _, exponent = text.partition("e")
        return f"{mantissa}e{int(exponent)}" if exponent else text
    short = next(t for t in (f"{value:.{d}e}" for d in range(17)) if float(t) == value)
    exact, exponent = plain(repr(value)), plain(short)
    return exponent if len(exponent) + 2 <= len(exact) else exact


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() and abs(value) < 1e15 else _float(value)


def allowed(key: schema.Key) -> str:
    """The values a key accepts, in words: its choices, or its bounds ('' when unbounded)."""
    if key.choices:
        return " | ".join(toml_value(c) for c in key.choices)
    if key.kind == "bool":
        return "true | false"
    low = high = ""
    if key.minimum is not None:
        low = f"{'>' if key.exclusive_min else '>='} {_number(key.minimum)}"
    if key.maximum is not None:
        high = f"{'<' if key.exclusive_max else '<='} {_number(key.maximum)}"
    bounds = ", ".join(b for b in (low, high) if b)
    if key.kind == "floats":
        return "a list of numbers" + (f", each {bounds}" if bounds else "")
    if key.kind == "pairs":
        return "a list of [x, y] pairs, x increasing, both > 0"
    return bounds


def units(key: schema.Key) -> str:
    """The key's units as the docs show them ('' for non-numeric keys)."""
    return _UNITS_TEXT.get(key.units, key.units)


def accepted_units(key: schema.Key) -> str:
    """The values with units a key accepts ('' for keys without units): sweep.scene.units."""
    from .scene.units import accepted
    return accepted(key)


def help_text(key: schema.Key) -> str:
    """What the key means: the schema's help text if it has one, else its long name."""
    return getattr(key, "help", "") or key.long_name


def _select(which: str | None) -> list[schema.Key]:
    if which is None:
        return list(schema.KEYS)
    if which in schema.BY_DOTTED:
        return [schema.BY_DOTTED[which]]
    keys = [k for k in schema.KEYS if k.section == which]
    if not keys:
        sections = ", ".join(s for s in schema.SECTIONS if s not in schema.SWEPT_SECTIONS)
        raise UserError(f"keys: no scene section or dotted key '{which}' (sections: {sections}, "
                        "axes, points; or a dotted key such as solver.rtol; or leave it out for "
                        "all keys)")
    return keys


def text(which: str | None = None) -> str:
    """The reference as plain text, one block per key; `which` is a section or a dotted key."""
    if which == "axes":
        return _axes_text() + "\n"
    if which == "points":
        return _points_text() + "\n"
    lines: list[str] = []
    if which is None:
        for name, meaning in schema.TOP_LEVEL.items():
            lines += [f"{name}  str (top level, optional)", f"    {meaning}", ""]
    for key in _select(which):
        head = f"{key.dotted}  {key.kind}"
        default = toml_value(key.default)
        head += f" = {default}" if default else " (no fixed default)"
        if key.units and key.units != "1":
            head += f"  [{key.units}]"
        if key.axis is not None:
            head += f"  (axis: {key.axis})"
        lines.append(head)
        if allowed(key):
            lines.append(f"    allowed: {allowed(key)}")
        if accepted_units(key):
            lines += textwrap.wrap(f"units: {accepted_units(key)}", 96, initial_indent="    ",
                                   subsequent_indent="        ")
        lines += textwrap.wrap(help_text(key), 96, initial_indent="    ",
                               subsequent_indent="    ") + [""]
    if which is None:
        lines += [_axes_text(), "", _points_text(), ""]
    return "\n".join(lines)


def _axes_text() -> str:
    spacings = " | ".join(toml_value(s) for s in schema.AXIS_SPACINGS)
    names = ", ".join(schema.BY_AXIS)
    meaning = ("sweeps a float key over these values instead of one value; NAME is the key's "
               f"axis name: {names}")
    return "\n".join([f"[axes] NAME = [v1, v2, ...] or {{start, stop, num, spacing = {spacings}}}",
                      *textwrap.wrap(meaning, 96, initial_indent="    ", subsequent_indent="    ")])


_POINTS_MEANING = ("zipped parameter sets: equal-length lists of sweepable keys (named as under "
                   "[axes]), entry i of every list being parameter set i, the result's `point` "
                   "dimension (coordinate 0, 1, ...; each key's values ride on it as a "
                   "coordinate, e.g. ds.length). Points combine with [axes] as a product: every "
                   "point is solved at every axis combination. A key is under [axes] or "
                   "[points], not both; values need not be ordered or distinct.")


def _points_text() -> str:
    return "\n".join(["[points] NAME = [v1, v2, ...]  (every NAME the same number of values)",
                      *textwrap.wrap(_POINTS_MEANING.replace("`", ""), 96,
                                     initial_indent="    ", subsequent_indent="    ")])


def _cell(value: str) -> str:
    return value.replace("|", "\\|") if value else ""


def markdown() -> str:
    """The reference as a Markdown page (docs/scene-keys.md)."""
    out = ["# Scene keys", "",
           "Generated from `sweep/schema.py` by", "", f"    {REGENERATE}", "",
           "Do not edit it by hand: a test fails when this page and the schema differ. The same",
           "reference in a terminal: `sweep keys`, or `sweep keys SECTION` (or one dotted key).", "",
           "A scene is a TOML file in SI units. *Default* is the value used when the key is absent",
           "(empty: none; the description says what happens then). *Axis*: a float key that may",
           "instead be swept under `[axes]`, by that name. Units `1`: dimensionless. *Accepts*:",
           "a key with units also takes a string with a unit, converted to SI when the scene",
           "loads (\"1.27 mm\", \"33.3 g/m\", \"0.5 g\"; on acceleration keys g is standard",
           "gravity, elsewhere the gram).", "",
           "## Top level", "", "| key | type | description |", "|---|---|---|"]
    out += [f"| `{name}` | str | {_cell(meaning)} |" for name, meaning in schema.TOP_LEVEL.items()]
    for section in schema.SECTIONS:
        keys = [k for k in schema.KEYS if k.section == section]
        if not keys:
            continue
        out += ["", f"## [{section}]", "",
                "| key | type | default | units | allowed | axis | description | accepts |",
                "|---|---|---|---|---|---|---|---|"]
        for k in keys:
            default = toml_value(k.default)
            out.append(f"| `{k.dotted}` | {k.kind} | {f'`{default}`' if default else ''} | "
                       f"{_cell(k.units)} | {_cell(allowed(k))} | "
                       f"{f'`{k.axis}`' if k.axis else ''} | {_cell(help_text(k))} | "
                       f"{_cell(accepted_units(k))} |")
    spacings = ", ".join(f"`{s}`" for s in schema.AXIS_SPACINGS)
    out += ["", "## [axes]", "",
            "Each entry sweeps one float key: `NAME = [v1, v2, ...]`, or",
            f"`NAME = {{start = ..., stop = ..., num = ..., spacing = ...}}` with spacing {spacings}",
            "(default linear). The result has one dimension per axis, in the order the axes are",
            "written. NAME is the key's axis name:", ""]
    out += [f"- `{axis}`: `{key.dotted}`" for axis, key in schema.BY_AXIS.items()]
    out += ["", "## [points]", "", "`NAME = [v1, v2, ...]`: " + _POINTS_MEANING,
            "", "    [points]                       # three harness segments",
            "    length = [0.30, 0.45, 0.30]    # m", "    area = [6e-6, 4e-6, 3e-6]      # m^2",
            "    inertia = [2.865e-12, 1.3e-12, 0.7e-12]   # m^4"]
    return "\n".join(out) + "\n"
