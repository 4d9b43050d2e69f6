"""``--set KEY=VALUE`` overrides: parsed as TOML values and written into the parsed document
before validation.

A table sets the keys it names and keeps the others, for a section
(``--set 'cable={length=0.3}'``) as for a table inside one (``--set 'base.sweep={start=80.0}'``).
An override that sets a sweepable key as a scalar removes that key's axis (or [points] entry),
one that sets an axis removes the key's [points] entry and the other way round
(``--set points.length=[0.3, 0.5]``); an override of one key of an either-or pair
(`sweep.models.rules.PAIRS`: the load frequency, the base level, the base frequency; as a
scalar or an axis) removes its partner, one of the other ways to give one quantity
(`ALTERNATIVES`: the base level as a table in g, a spectrum in g^2/Hz or in (m/s^2)^2/Hz)
the others, and one of the end-time keys (solver.t_end, solver.transits) the other; so
``--set`` can always replace what the scene file says.
Overrides of both keys of a pair are refused.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import schema
from ..models.rules import BASE_LEVEL_KEYS, BASE_TABLE_KEY, END_TIME_KEYS, PAIRS
from .axes import _axis_or_none
from .messages import _fail, _section_not_table


ALTERNATIVES: tuple[tuple[str, ...], ...] = (
    BASE_LEVEL_KEYS + (BASE_TABLE_KEY,),         # a base level: m/s^2, g, or (Hz, g) table
    ("base.asd_g2", "base.asd"),                 # a spectrum: g^2/Hz or (m/s^2)^2/Hz
)
"""Groups of keys that give one quantity different ways, beside the either-or PAIRS: a
``--set`` of one removes the others the scene gives (scalars and axes)."""


def parse_override(item: str) -> tuple[str, Any]:
    """Split ``"KEY=VALUE"`` into the dotted key and the value parsed as a TOML value.

    A VALUE that is not valid TOML is kept as the raw string, so ``model.coefficients=paper``
    works as well as ``model.coefficients="paper"``.
    """
    key, sep, value = item.partition("=")
    key = key.strip()
    if not sep or not key:
        _fail(f"override '{item}'", "must have the form KEY=VALUE",
              "write a dotted scene key, '=' and a value, e.g. solver.rtol=1e-9 or "
              "axes.length=[0.5, 1.0]")
    return key, _parse_value_text(value)


def _parse_value_text(text: str) -> Any:
    """A TOML value from text, or the stripped text itself if it is not one."""
    try:
        parsed = tomllib.loads("v = " + text)
    except (ValueError, RecursionError):         # TOMLDecodeError is a ValueError
        return text.strip()
    return parsed["v"] if list(parsed) == ["v"] else text.strip()


def _expects_string(dotted: str) -> bool:
    """Whether a dotted key holds a string (so a raw string override is taken as is)."""
    if dotted in schema.TOP_LEVEL:
        return True
    key = schema.BY_DOTTED.get(dotted)
    return key is not None and key.kind == "str"


def _override_value(dotted: str, value: Any) -> Any:
    """An override's value as a plain Python value; strings are parsed as TOML values."""
    if not isinstance(value, str):
        return _plain(value)
    parsed = _parse_value_text(value)
    if _expects_string(dotted) and not isinstance(parsed, str):
        return value
    return parsed


def _plain(value: Any) -> Any:
    """Numpy scalars/arrays and tuples -> Python scalars and lists, recursively."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (np.ndarray, tuple, list)):
        return [_plain(v) for v in (value.tolist() if isinstance(value, np.ndarray) else value)]
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _parse_overrides(overrides: Mapping[str, Any] | None) -> dict[str, Any]:
    """Check override keys and parse their values; refuse both keys of an either-or pair."""
    parsed: dict[str, Any] = {}
    for key, value in (overrides or {}).items():
        if not isinstance(key, str) or not key.strip():
            _fail(f"override {key!r}", "has no key",
                  "write KEY=VALUE with a dotted scene key, e.g. solver.rtol=1e-9")
        key = key.strip()
        value = _override_value(key, value)
        if isinstance(value, Mapping) and ("." not in key or key in schema.TABLES):
            # a table for a whole section, or for a table in one (base.sweep), sets the keys
            # it names, as `section.key` overrides do (replacing the table would drop its
            # other keys to their defaults unsaid)
            parsed.update(_section_keys(key, value))
        else:
            parsed[key] = value
    for group in PAIRS + ALTERNATIVES:
        given = sorted({_pair_target(k, group) for k in parsed} - {None}, key=group.index)
        if len(given) >= 2:
            _fail(f"overrides '{given[0]}' and '{given[1]}'", "give one, not both",
                  "remove one of the two overrides")
    if all(k in parsed for k in END_TIME_KEYS):
        _fail("overrides 'solver.t_end' and 'solver.transits'", "give one, not both",
              "remove one of the two overrides")
    return parsed


def _section_keys(prefix: str, table: Mapping[str, Any]) -> dict[str, Any]:
    """A section's table (or a nested table's, prefix 'base.sweep') as dotted overrides: nested tables flattened (base={sweep={rate=1}}
    is base.sweep.rate) down to a key the schema knows or an entry of [axes] or [points],
    whose value a table may be ({start, stop, num})."""
    out: dict[str, Any] = {}
    for name, value in table.items():
        dotted = f"{prefix}.{name}"
        if (isinstance(value, Mapping) and dotted not in schema.BY_DOTTED
                and prefix not in schema.SWEPT_SECTIONS):
            out.update(_section_keys(dotted, value))
        else:
            out[dotted] = _plain(value)
    return out


def _pair_target(dotted: str, pair: tuple[str, ...]) -> str | None:
    """The key of an either-or `pair` (or `ALTERNATIVES` group) an override sets (as scalar or
    axis), or None."""
    if dotted in pair:
        return dotted
    section, _, name = dotted.partition(".")
    if section in schema.SWEPT_SECTIONS:
        axis = _axis_or_none(name)
        if axis is not None and schema.BY_AXIS[axis].dotted in pair:
            return schema.BY_AXIS[axis].dotted
    return None


def _apply_overrides(doc: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """Write overrides into the parsed document (in place), before validation."""
    for dotted, value in overrides.items():
        section, _, name = dotted.partition(".")
        if not name:
            doc[dotted] = value
        elif section in schema.SWEPT_SECTIONS:
            _override_axis(doc, name, value, section)
        else:
            _override_scalar(doc, section, name, value)


def _override_table(doc: dict[str, Any], section: str) -> dict[str, Any]:
    """The document's ``[section]`` table, created if absent."""
    table = doc.setdefault(section, {})
    if not isinstance(table, dict):
        _section_not_table(section, table)
    return table


def _override_axis(doc: dict[str, Any], name: str, value: Any, section: str = "axes") -> None:
    """Set or replace an axis or a [points] entry (`section`; keeping its place); drop the
    same key from the other section, and the other key of its either-or pair (load or base
    frequency, base level)."""
    axes = _override_table(doc, section)
    axis = _axis_or_none(name)
    if axis is None:
        axes[name] = value
        return
    other = next(s for s in schema.SWEPT_SECTIONS if s != section)
    _drop_axis(doc, axis, (other,))
    _drop_partners(doc, schema.BY_AXIS[axis].dotted)
    replaced = {(axis if _axis_or_none(k) == axis else k): v for k, v in axes.items()}
    replaced[axis] = value
    axes.clear()
    axes.update(replaced)


def _override_scalar(doc: dict[str, Any], section: str, name: str, value: Any) -> None:
    """Set a scalar key; it replaces an axis on the same key, or the other end-time key."""
    table = _override_table(doc, section)
    table[name] = value
    dotted = f"{section}.{name}"
    if dotted in END_TIME_KEYS:
        table.pop(END_TIME_KEYS[1 - END_TIME_KEYS.index(dotted)].partition(".")[2], None)
    key = schema.BY_DOTTED.get(dotted)
    if key is not None and key.axis is not None:
        _drop_axis(doc, key.axis)
    _drop_partners(doc, dotted)


def _drop_axis(doc: dict[str, Any], axis: str,
               sections: tuple[str, ...] = schema.SWEPT_SECTIONS) -> None:
    """Remove every ``[axes]`` and ``[points]`` entry (of `sections`) that names ``axis``."""
    for section in sections:
        table = doc.get(section)
        if isinstance(table, dict):
            for entry in [k for k in table if _axis_or_none(k) == axis]:
                del table[entry]


def _drop_partners(doc: dict[str, Any], dotted: str) -> None:
    """When a key of an either-or pair (PAIRS: the load frequency, the base level, the base
    frequency) or of an `ALTERNATIVES` group is set, remove the others (scalar and axis)."""
    for group in PAIRS + ALTERNATIVES:
        if dotted not in group:
            continue
        for other in group:
            if other == dotted:
                continue
            partner = schema.BY_DOTTED[other]
            table = doc.get(partner.section)
            if isinstance(table, dict):
                table.pop(partner.name, None)
            if partner.axis is not None:
                _drop_axis(doc, partner.axis)
