"""``--set KEY=VALUE`` overrides: parsed as TOML values and written into the parsed document
before validation.

A table sets the keys it names and keeps the others, for a section
(``--set 'cable={length=0.3}'``) as for a table inside one (``--set 'base.sweep={start=80.0}'``).
An override that sets a sweepable key as a scalar removes that key's axis (or [points] entry),
one that sets an axis removes the key's [points] entry and the other way round
(``--set points.length=[0.3, 0.5]``); an override of one key of an either-or pair
(`sweep.models.rules.PAIRS`: the load frequency, the base level, the base frequency; as a
scalar or an axis) removes its partner, one of the other ways to give one quantity
(`ALTERNATIVES`: the base level as a table in g, a spectrum in g^2/Hz or in (m/s^2)^2/Hz,
the base frequency as a sweep table) the others, and one of the end-time keys (solver.t_end,
solver.transits) the other; so ``--set`` can always replace what the scene file says. A fixed
base frequency (key or axis) replaces the scene's whole sweep table, and with it the envelope
outputs that only a sweep has (outputs.envelope, outputs.bands_per_octave); a scene whose run
ended with its sweep (no solver.t_end) then needs a solver.t_end override, refused in one line
without one. A sweep's start, stop or rate (key or axis) replaces the scene's base.frequency
or frequency_ratio (key or axis), that dwell's solver.t_end (unless an override gives one)
and a stepped sweep's [continuation], and keeps the sweep's other keys. A [continuation] whose
axis an override removes goes with it, unless an override gives the continuation (then the
rules judge its axis, as a scene file's).
Overrides of two ways to give one quantity are refused.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import schema
from ..models.excitation import SWEEP_KEYS
from ..models.rules import (BASE_FREQUENCY_KEYS, BASE_LEVEL_KEYS, BASE_TABLE_KEY, END_TIME_KEYS,
                            PAIRS)
from .axes import _axis_or_none
from .messages import _fail, _section_not_table


SWEEP_TABLE = "base.sweep"
"""A continuous sine sweep, as one way to give the base frequency: set by its start, stop or
rate (`SWEEP_KEYS`, keys or axes); replaced whole (every base.sweep key and axis)."""
SWEEP_OUTPUTS: tuple[str, ...] = ("outputs.envelope", "outputs.bands_per_octave")
"""Outputs only a sweep has: a fixed frequency that replaces the scene's sweep removes the
scene's (an override of one of them stays, and the rules refuse it without a sweep)."""
ALTERNATIVES: tuple[tuple[str, ...], ...] = (
    BASE_LEVEL_KEYS + (BASE_TABLE_KEY,),         # a base level: m/s^2, g, or (Hz, g) table
    ("base.asd_g2", "base.asd"),                 # a spectrum: g^2/Hz or (m/s^2)^2/Hz
    BASE_FREQUENCY_KEYS + (SWEEP_TABLE,),        # a base frequency: Hz, f/f1, or a sweep
)
"""Groups of ways to give one quantity, beside the either-or PAIRS: a ``--set`` of one
removes the others the scene gives (scalars and axes). A member is a key, or `SWEEP_TABLE`."""


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
    parsed = _parse_value_text(value)
    if isinstance(parsed, str) and parsed[:1] in ("[", "{") and not _expects_string(key):
        kind = "list" if parsed[0] == "[" else "table"
        _fail(f"override '{key}'", f"{parsed} is not a valid TOML {kind}",
              "write it with its brackets closed and each value with a unit quoted, e.g. "
              "axes.length='[\"200 mm\", \"300 mm\"]' or axes.length=[0.2, 0.3]")
    return key, parsed


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
    """The member of an either-or `pair` (or `ALTERNATIVES` group) an override sets (as scalar
    or axis), or None."""
    return _member(_target(dotted), pair)


def _target(dotted: str) -> str:
    """The scene key an override sets: an [axes] or [points] entry's key, else `dotted`."""
    section, _, name = dotted.partition(".")
    if section in schema.SWEPT_SECTIONS:
        axis = _axis_or_none(name)
        if axis is not None:
            return schema.BY_AXIS[axis].dotted
    return dotted


def _member(dotted: str, group: tuple[str, ...]) -> str | None:
    """The member of `group` that setting key `dotted` gives: the key itself, or
    `SWEEP_TABLE` for a sweep's start, stop or rate; None if neither is in the group."""
    if dotted in group:
        return dotted
    if dotted in SWEEP_KEYS and SWEEP_TABLE in group:
        return SWEEP_TABLE
    return None


def _apply_overrides(doc: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """Write overrides into the parsed document (in place), before validation: first remove
    what they replace (`_drop_partners`), then write them, so that no override removes
    another."""
    stepped = _continuation_axis_present(doc)
    for dotted in overrides:
        target = _target(dotted)
        lost = _drop_partners(doc, target)
        if SWEEP_TABLE in lost:
            _check_end_time(doc, overrides, dotted)
        elif lost and _member(target, (SWEEP_TABLE,)) == SWEEP_TABLE:
            _drop_dwell_end(doc, overrides)
    for dotted, value in overrides.items():
        section, _, name = dotted.partition(".")
        if not name:
            doc[dotted] = value
        elif section in schema.SWEPT_SECTIONS:
            _override_axis(doc, name, value, section)
        else:
            _override_scalar(doc, section, name, value)
    stepping = any(d == "continuation" or d.startswith("continuation.") for d in overrides)
    if stepped and not stepping and not _continuation_axis_present(doc):
        del doc["continuation"]     # an override removed the stepped axis: nothing to step along


def _check_end_time(doc: dict[str, Any], overrides: Mapping[str, Any], dotted: str) -> None:
    """A fixed frequency (override `dotted`) replaced the scene's sweep: the run's end time was
    the sweep's own unless the scene or an override gives solver.t_end; refuse without one
    (the 5 s default of a fixed frequency is nobody's choice here, and may end before the
    start-up transient has decayed)."""
    solver = doc.get("solver")
    if "solver.t_end" in overrides or (isinstance(solver, dict) and "t_end" in solver):
        return
    _fail(f"override '{dotted}'", "replaces the scene's sweep, whose run ended with the sweep; "
          "the scene gives no solver.t_end for a fixed frequency",
          "add the override solver.t_end=20.0 (s: the tail window, the last half, should start "
          "several decay times 1/(zeta w1) in, once the start-up transient has died away)")


def _drop_dwell_end(doc: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """A sweep replaced the scene's fixed frequency: the scene's solver.t_end was that dwell's
    (a sweep's run ends with the sweep by default, and a dwell's t_end refuses a longer
    sweep), so it goes unless an override gives one."""
    solver = doc.get("solver")
    if "solver.t_end" not in overrides and isinstance(solver, dict):
        solver.pop("t_end", None)


def _continuation_axis_present(doc: dict[str, Any]) -> bool:
    """Whether the document has a stepped sweep's [continuation] whose axis is among its
    [axes] or [points]: `_apply_overrides` removes a [continuation] whose axis the overrides
    removed (a fixed frequency replaced the stepped frequency axis), as nothing is left to
    step along; one whose axis the scene never had is left for the rules' own message."""
    continuation = doc.get("continuation")
    if not isinstance(continuation, dict):
        return False
    axis = _axis_or_none(str(continuation.get("axis", "")))
    return axis is not None and any(
        _axis_or_none(k) == axis for section in schema.SWEPT_SECTIONS
        if isinstance(doc.get(section), dict) for k in doc[section])


def _override_table(doc: dict[str, Any], section: str) -> dict[str, Any]:
    """The document's ``[section]`` table, created if absent."""
    table = doc.setdefault(section, {})
    if not isinstance(table, dict):
        _section_not_table(section, table)
    return table


def _override_axis(doc: dict[str, Any], name: str, value: Any, section: str = "axes") -> None:
    """Set or replace an axis or a [points] entry (`section`; keeping its place); drop the
    same key from the other section."""
    axes = _override_table(doc, section)
    axis = _axis_or_none(name)
    if axis is None:
        axes[name] = value
        return
    other = next(s for s in schema.SWEPT_SECTIONS if s != section)
    _drop_axis(doc, axis, (other,))
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


def _drop_axis(doc: dict[str, Any], axis: str,
               sections: tuple[str, ...] = schema.SWEPT_SECTIONS) -> bool:
    """Remove every ``[axes]`` and ``[points]`` entry (of `sections`) that names ``axis``;
    whether there was one."""
    had = False
    for section in sections:
        table = doc.get(section)
        if isinstance(table, dict):
            for entry in [k for k in table if _axis_or_none(k) == axis]:
                del table[entry]
                had = True
    return had


def _drop_partners(doc: dict[str, Any], dotted: str) -> list[str]:
    """When a key of an either-or pair (PAIRS: the load frequency, the base level, the base
    frequency) or a member of an `ALTERNATIVES` group is set (key `dotted`), remove the others
    (scalar and axis; the sweep table whole, with the outputs only a sweep has; a sweep also
    removes a stepped sweep's [continuation]). Returns the members the scene gave and lost."""
    lost = []
    for group in PAIRS + ALTERNATIVES:
        member = _member(dotted, group)
        if member is None:
            continue
        for other in (o for o in group if o != member):
            if _drop_keys(doc, _member_keys(other)):
                lost.append(other)
            if other == SWEEP_TABLE:
                _drop_keys(doc, [schema.BY_DOTTED[d] for d in SWEEP_OUTPUTS])
        if member == SWEEP_TABLE:
            _drop_keys(doc, [k for k in schema.KEYS if k.section == "continuation"])
    return lost


def _member_keys(member: str) -> list[schema.Key]:
    """The keys a member of an `ALTERNATIVES` group stands for: the key, or every base.sweep
    key for `SWEEP_TABLE`."""
    if member != SWEEP_TABLE:
        return [schema.BY_DOTTED[member]]
    return [k for k in schema.KEYS if k.dotted.startswith(SWEEP_TABLE + ".")]


def _drop_keys(doc: dict[str, Any], keys: list[schema.Key]) -> bool:
    """Remove `keys` from the document, as scalars and as axes or [points] entries; whether
    the document had any of them."""
    had = False
    for key in keys:
        table = doc.get(key.section)
        if isinstance(table, dict) and key.name in table:
            del table[key.name]
            had = True
        if key.axis is not None:
            had = _drop_axis(doc, key.axis) or had
    return had
