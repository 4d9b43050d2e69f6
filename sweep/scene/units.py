"""Values with units: a scene may write any dimensional number as a string, "33.3 g/m",
"1.27 mm", "0.5 g", "3.2 lb/kft", "100 Hz", and it is converted here, once, to the key's SI
unit (the schema's ``units``), before any other check sees it. Plain numbers stay SI. A string
is one number (a point for decimals) and its unit: a comma, or a number or sign in the unit
other than an exponent, is refused, not computed ("53,4 g/m" would be 534 g/m to pint).
UDUNITS' exponents ("N m2", "m s-2") are read as powers, and "mil" is a data sheet's 1/1000
inch (pint's is an angle), "Nm" a newton metre (pint's is a "number metre"), and a sweep rate
may say "oct/min" (pint's octave is a level ratio). An angle per time on a frequency key is
read in cycles ("20 rad/s" is 20 / 2 pi Hz, "1200 rpm" 20 Hz), where pint would take the
radian for a pure number.

Where: every float key, the items of "floats" and "pairs" keys (a pair's first item is a
frequency, Hz), the values of [axes] lists and ranges (start, stop) and of [points] lists.
A string on a dimensionless key, a unit of the wrong dimension or an unknown unit is one
SceneError line. pint parses the strings, and is imported only when a scene holds one.

"g" means grams to pint, "G" the gauss. On an acceleration key (base.acceleration in m/s^2,
the keys in g: base.acceleration_g, base.levels_g) and an acceleration spectral density
(base.asd, base.asd_g2) a "g" or "G" written alone (as test specifications write "G^2/Hz") is read as
standard gravity (schema.STANDARD_GRAVITY, 9.80665 m/s^2), so "0.5 g" is half of it there, as
are "g0", "gn", "g_0" and "g_n"; "mG" is a thousandth of it ("500 mG" is 0.5 g). There "mg", a
milligram, is refused with a line suggesting mG, and an RMS level ("14.1 grms") on a sine's
level key with a line saying that the key takes the peak. On a spectral density "grms^2/Hz"
("grms2/Hz", "g_rms^2/Hz", "Grms^2/Hz") is g^2/Hz: engineers write both for the same density.
Everywhere else g is the gram ("33.3 g/m"), and a G, mG, g0 or gn is refused with a line
saying where it means gravity.
A reciprocal unit may be written with its 1: "20 1/s" is "20 /s".
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Any

from .. import schema
from ..errors import SceneError
from .messages import _fail, _show

ACCELERATION_UNITS = ("m s-2", schema.G_UNITS, "m2 s-4 Hz-1", schema.G2_UNITS)
"""Schema units of the keys on which "g" (or "G") means standard gravity."""
_UNIT_POWER = re.compile(r"(?<![\w.])([A-Za-z]+)(-?\d+)(?![\w.])")   # m2, s-2 (UDUNITS)
_LONE_G = re.compile(r"(?<![A-Za-z_])[gG](?![A-Za-z_0-9])")    # "0.5 g", "0.16 G^2/Hz"
_GRAVITY_G = re.compile(r"(?<![A-Za-z_])(?:m?G|g_?0|gn)(?![A-Za-z_])")   # G, mG, g0, gn: gravity
_GRAVITY_NAMES = re.compile(r"(?<![A-Za-z_])(?:g_?n(?![A-Za-z_])|g_?0(?![A-Za-z_0-9]))")
"""g0, g_0, gn, g_n: standard gravity; gn and g_n also with a UDUNITS exponent ("gn2/Hz")."""
_MILLI_G = re.compile(r"(?<![A-Za-z_])mG(?![A-Za-z_0-9])")      # a thousandth of gravity
_MILLIGRAM = re.compile(r"(?<![A-Za-z_])mg(?![A-Za-z_0-9])")    # "500 mg": a mass
_RMS = re.compile(r"(?<![A-Za-z])(?:[gG]_?)?(?:rms|RMS)(?![A-Za-z])")  # "14.1 grms", "1 g rms"
_G_RMS = re.compile(r"(?<![A-Za-z_])([gG])_?(?:rms|RMS)(?![A-Za-z_])")   # grms, g_rms, Grms, GRMS
SPECTRUM_UNITS = ("m2 s-4 Hz-1", schema.G2_UNITS)
"""Schema units of an acceleration spectral density (base.asd, base.asd_g2)."""
LEVEL_UNITS = ("m s-2", schema.G_UNITS)
"""Schema units of a sine's level keys (a peak acceleration)."""
GRAVITY_WORDS = "'g', 'G', 'g0' or 'gn' is standard gravity and 'mG' a thousandth of it"
_RECIPROCAL = re.compile(r"^1\s*/")          # a unit written "1/s", "1/min": pint's "/s"

_DIMENSION_NAMES: dict[str, str] = {
    "[length]": "a length", "[mass]": "a mass", "[time]": "a time",
    "[mass] / [length]": "a mass per length", "[mass] / [length] ** 3": "a density",
    "[length] ** 2": "an area", "[length] ** 4": "a second moment of area",
    "1 / [time]": "a frequency", "[length] / [time]": "a speed",
    "[length] / [time] ** 2": "an acceleration", "[mass] * [length] / [time] ** 2": "a force",
    "[mass] / [length] / [time] ** 2": "a pressure",
    "[mass] * [length] ** 3 / [time] ** 2": "a bending stiffness (force x area)",
    "[mass] * [length] ** 2 / [time] ** 2": "a moment (force x length)",
    "[mass] / [time] ** 2": "a stiffness (force per length)",
    "[length] ** 2 / [time] ** 3": "an acceleration spectral density",
    "1 / [time] ** 2": "an acceleration per length",
    "dimensionless": "a pure number",
}
_EXAMPLES: dict[str, str] = {
    "m": "'1.27 mm'", "kg m-1": "'33.3 g/m' or '3.2 lb/kft'", "Hz": "'100 Hz'",
    "N m2": "'2e-3 N m^2'", "N": "'1.6 MN'", "m s-2": "'0.5 g' or '4.9 m/s^2'",
    schema.G_UNITS: "'0.5 g'", "kg m-3": "'8.9 g/cm^3'", "Pa": "'110 GPa'", "m2": "'6 mm^2'",
    "m4": "'2.9e-12 m^4'", "s": "'20 ms'", "N m rad-1": "'0.5 N m/rad'", "N m-1": "'1 MN/m'",
    "m s-1": "'0.1 m/s'", "min-1": "'2 /min'", "m2 s-4 Hz-1": "'0.16 g^2/Hz'",
    schema.G2_UNITS: "'0.16 g^2/Hz'",
}


_QUANTITIES: dict[str, str] = {
    "m": "length", "kg m-1": "mass per length", "Hz": "frequency", "N m2": "bending stiffness",
    "N": "force", "m s-2": "acceleration", schema.G_UNITS: "acceleration", "kg m-3": "density",
    "Pa": "pressure", "m2": "area", "m4": "second moment of area", "s": "time",
    "N m rad-1": "rotational stiffness", "N m-1": "stiffness", "m s-1": "speed",
    "min-1": "rate", "m2 s-4 Hz-1": "acceleration spectral density",
    schema.G2_UNITS: "acceleration spectral density",
}


def accepted(key: schema.Key) -> str:
    """What a key accepts besides a plain SI number, in words ('' for a key without units):
    e.g. "or a string with any length unit, e.g. '1.27 mm'". No pint needed."""
    if key.units in ("", "1") or key.kind not in ("float", "floats", "pairs"):
        return ""
    quantity = _QUANTITIES.get(key.units, key.units)
    gravity = f" ({GRAVITY_WORDS})" if key.units in ACCELERATION_UNITS else ""
    if key.units in SPECTRUM_UNITS:
        gravity = f" ({GRAVITY_WORDS}; 'grms^2/Hz' is g^2/Hz)"
    shown = {schema.G_UNITS: "g", schema.G2_UNITS: "g^2/Hz"}.get(key.units, key.units)
    return (f"a number in {shown}, or a string with "
            f"any {quantity} unit, e.g. {_EXAMPLES.get(key.units, key.units)}{gravity}")


def convert_document(doc: dict[str, Any]) -> None:
    """Replace every unit string on a numeric key of `doc` by its SI value, in place (the
    sections' keys, [axes] and [points]; flattened, overrides applied)."""
    from .axes import _axis_or_none
    for section, table in doc.items():
        if not isinstance(table, dict):
            continue
        for name, raw in table.items():
            if section in schema.SWEPT_SECTIONS:
                axis = _axis_or_none(name)
                if axis is None:
                    continue
                key = schema.BY_AXIS[axis]
                where = f"{'axis' if section == 'axes' else '[points] entry'} '{name}'"
                table[name] = _swept(where, key, raw)
                continue
            key = schema.BY_DOTTED.get(f"{section}.{name}")
            if key is not None and key.kind in ("float", "floats", "pairs"):
                table[name] = _value(f"scene key '{key.dotted}'", key, raw)


def _swept(where: str, key: schema.Key, raw: Any) -> Any:
    if isinstance(raw, list):
        return [to_si(where, key, v) if _has_unit(v) else v for v in raw]
    if isinstance(raw, dict):
        return {k: to_si(where, key, v) if k in ("start", "stop") and _has_unit(v) else v
                for k, v in raw.items()}
    return to_si(where, key, raw) if _has_unit(raw) else raw


def _value(where: str, key: schema.Key, raw: Any) -> Any:
    if key.kind == "float":
        return to_si(where, key, raw) if _has_unit(raw) else raw
    if not isinstance(raw, list):
        return raw
    if key.kind == "floats":
        return [to_si(where, key, v) if _has_unit(v) else v for v in raw]
    hertz = schema.BY_DOTTED["base.frequency"]            # a pair's first item: Hz
    return [[to_si(where, hertz, item[0]) if _has_unit(item[0]) else item[0],
             to_si(where, key, item[1]) if _has_unit(item[1]) else item[1]]
            if isinstance(item, list) and len(item) == 2 else item for item in raw]


def _has_unit(value: Any) -> bool:
    """Whether `value` is a string that is not a plain number (a quoted plain number is left
    for the value checks, which say it must be a number)."""
    if not isinstance(value, str):
        return False
    try:
        float(value)
    except ValueError:
        return True
    return False


_LEADING_NUMBER = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?=\s|[^\d.eE]|$)")
_MIL = re.compile(r"(?<![A-Za-z_])mils?(?![A-Za-z_])")
_NEWTON_METRE = re.compile(r"(?<![A-Za-z_])Nm(?![A-Za-z_])")   # a data sheet's "Nm", "Nm^2"
_OCTAVES = re.compile(r"(?<![A-Za-z_])oct(?:ave)?s?(?![A-Za-z_])")
_EXPONENT = re.compile(r"(?:\^|\*\*)\s*\(?\s*[+-]?\d+(?:\.\d+)?\s*\)?")


def _unit_text(where: str, text: str, example: str, gravity: bool = False) -> str:
    """`text` as pint should read it: one number, then its unit, UDUNITS' exponents ("N m2",
    "m s-2") written as powers; with `gravity` (an acceleration key), "g0", "g_0", "gn" and
    "g_n" read as standard gravity (not g to the power 0). Refused in one line: a comma (a
    decimal comma or a thousands separator, which pint would drop: '53,4 g/m' read as 534 g/m),
    and any number or sign in the unit other than an exponent ('g/m 2', 'g/m + 1 g/m': pint
    would compute them)."""
    fix = f"give one number with a point for decimals, then the unit, e.g. {example}"
    if "," in text:
        _fail(where, f"{_show(text)} has a comma (a decimal comma or a thousands separator "
              "reads as another number)", fix)
    number = _LEADING_NUMBER.match(text)
    if number is None:                   # pint would read a unit alone as 1 of it ('a': a year)
        _fail(where, f"{_show(text)} does not start with a number", fix)
    unit = " ".join(text[number.end():].split())
    if gravity:
        unit = _GRAVITY_NAMES.sub("gravity", unit)
    unit = _RECIPROCAL.sub("/", _powers(unit))
    unit = _MIL.sub("thou", unit)        # a data sheet's mil, 1/1000 inch (pint's is an angle)
    unit = _NEWTON_METRE.sub("N m", unit)    # pint's Nm is a "number metre"
    if re.search(r"[\d+-]", _EXPONENT.sub("", unit)):
        _fail(where, f"{_show(text)} has a number or a sign inside its unit (only exponents "
              "such as m^2, m**2 or m2 may follow the unit)", fix)
    return f"{number.group(0).strip()} {unit}"


def to_si(where: str, key: schema.Key, text: str) -> float:
    """The number a unit string means, in the key's SI unit (schema units); refused in one
    line for a dimensionless key, an unknown unit, or a quantity of another dimension."""
    if key.units in ("", "1"):
        _fail(where, f"{_show(text)} is a string; the key is a pure number and takes no unit",
              f"write {key.name} = a plain number, without quotes")
    import pint
    registry = _registry()
    acceleration = key.units in ACCELERATION_UNITS
    target = _pint_units(key.units)
    example = _EXAMPLES.get(key.units, f"a number with a unit of {key.units}")
    parsed_text = _unit_text(where, text, example, gravity=acceleration)
    named = _GRAVITY_G.search(text[_LEADING_NUMBER.match(text).end():])
    if not acceleration and named:
        keys = ", ".join(k.dotted for k in schema.KEYS if k.units in ACCELERATION_UNITS)
        _fail(where, f"{_show(text)} has a '{named.group(0)}': standard gravity, which only the "
              f"acceleration keys take ({keys})", f"give e.g. {example}")
    if key.units in LEVEL_UNITS and _RMS.search(text):
        _fail(where, f"{_show(text)} is an RMS level; the key takes the sine's peak "
              "acceleration, in g or m/s^2", "give the peak, e.g. '0.5 g' or '4.9 m/s^2' (a "
              "sine's peak is sqrt(2) x its RMS); a random environment's grms comes from its "
              "spectrum, base.asd_g2 in g^2/Hz")
    if key.units in SPECTRUM_UNITS:      # "0.16 grms^2/Hz" is the same density as g^2/Hz
        parsed_text = _G_RMS.sub(r"\1", parsed_text)
    if acceleration:
        parsed_text = _MILLI_G.sub("milligravity", _LONE_G.sub("g_0", parsed_text))
    if key.units == "min-1":             # a sweep rate in octaves per minute: "2 oct/min"
        parsed_text = _OCTAVES.sub("", parsed_text)
    gravity = f" (on this key {GRAVITY_WORDS})" if acceleration else ""
    try:
        quantity = registry.Quantity(parsed_text.strip())
    except (pint.errors.UndefinedUnitError, AttributeError) as exc:
        unknown = getattr(exc, "unit_names", None) or ()
        named = f"unknown unit '{unknown[0] if isinstance(unknown, (list, tuple)) else unknown}'" \
            if unknown else "not a number with a unit"
        _fail(where, f"{_show(text)}: {named}",
              f"give a number and a unit of {key.units}, e.g. {example}{gravity}")
    except Exception:                            # pint's parser raises many kinds
        _fail(where, f"{_show(text)} is not a number with a unit",
              f"give a number and a unit of {key.units}, e.g. {example}{gravity}")
    if not isinstance(quantity, registry.Quantity):    # a bare number parses as a float
        quantity = registry.Quantity(quantity)
    try:
        quantity = _cycles(where, key, text, quantity, target, registry)
    except ArithmeticError:                      # "0a176 kg/m": pint reads a^176 (years)
        _fail(where, f"{_show(text)} is not a number with a unit",
              f"give a number and a unit of {key.units}, e.g. {example}{gravity}")
    try:
        value = float(quantity.to(target).magnitude)
    except pint.errors.DimensionalityError:
        if acceleration and _MILLIGRAM.search(text):
            _milligram(where, key, text)
        got = _dimension_name(quantity.dimensionality)
        want = _dimension_name(registry.Quantity(1.0, target).dimensionality)
        _fail(where, f"{_show(text)} is {got}, the key takes {want} ({key.units})",
              f"give e.g. {example}{gravity}")
    except Exception as exc:                     # offset units (degC) and the like
        _fail(where, f"{_show(text)} cannot be converted to {key.units} ({exc})",
              f"give e.g. {example}")
    # 15 significant digits: '33.3 g/m' is 0.0333, not 33.3 x 0.001 = 0.033299999999999996;
    # a number typed with more digits keeps them all (no rounding: its SI number's bits)
    digits = _significant_digits(_LEADING_NUMBER.match(text).group(0))
    return float(f"{value:.15g}") if digits <= 15 else value


def _significant_digits(number: str) -> int:
    """How many significant digits a number as typed has ('0.0333': 3, '2.86e-12': 3)."""
    mantissa = re.split(r"[eE]", number.strip().lstrip("+-"))[0].replace(".", "")
    return max(1, len(mantissa.lstrip("0")))


def _milligram(where: str, key: schema.Key, text: str) -> None:
    """Refuse a milligram written for a thousandth of gravity ("500 mg" on an acceleration
    key) in one line that gives the text in mG and in g; return if mG would not fit either."""
    fixed = _MILLIGRAM.sub("mG", text)
    try:
        value = to_si(where, key, fixed)
    except SceneError:
        return
    power = 2 if key.units in SPECTRUM_UNITS else 1
    in_g = value if key.units in (schema.G_UNITS, schema.G2_UNITS) else (
        value / schema.STANDARD_GRAVITY ** power)
    unit = "g^2/Hz" if power == 2 else "g"
    _fail(where, f"{_show(text)} is a mass (mg: a milligram), the key takes "
          f"{'an acceleration spectral density' if power == 2 else 'an acceleration'}",
          f"write {_show(fixed)} (mG: a thousandth of standard gravity) or "
          f"'{in_g:.6g} {unit}'")


def _cycles(where: str, key: schema.Key, text: str, quantity: Any, target: str,
            registry: Any) -> Any:
    """`quantity` with its angle read as pint cannot: pint takes the radian for a pure number,
    so "20 rad/s" would be 20 Hz and "20 rpm" 2.09 Hz (2 pi off, silently). A frequency key
    (Hz) given an angle per time is read as cycles: "20 rad/s" is 20 / (2 pi) Hz, "1200 rpm"
    20 Hz, "20 cycles/s" 20 Hz. Any other key given an angle its unit does not hold ("2 rpm"
    as an octave rate) is refused; one written without the angle its unit holds ("0.5 N m"
    for N m/rad) is read with it, as pint does."""
    def radians(q: Any) -> float:
        return dict(q.to_root_units().unit_items()).get("radian", 0)

    have = radians(quantity)
    want = radians(registry.Quantity(1.0, target))
    if have == 0 or have == want:
        return quantity
    if key.units == "Hz" and have == 1:
        return (quantity.to("radian / second") / (2.0 * 3.141592653589793)
                / registry.radian)
    _fail(where, f"{_show(text)} holds an angle, the key takes {key.units}",
          f"give e.g. {_EXAMPLES.get(key.units, f'a number with a unit of {key.units}')}")


def _dimension_name(dimensionality: Any) -> str:
    text = str(dimensionality)
    return _DIMENSION_NAMES.get(text, f"of dimension {text}")


def _pint_units(units: str) -> str:
    """A schema (UDUNITS) unit string in pint's syntax: "kg m-3" -> "kg m ** -3"; the keys
    in g -> "g_0" (standard gravity)."""
    if units == schema.G_UNITS:
        return "g_0"
    if units == schema.G2_UNITS:
        return "g_0 ** 2 / Hz"
    return _powers(units)


def _powers(units: str) -> str:
    """UDUNITS' exponents as pint's powers: "m s-2" -> "m s ** -2", "kg/m3" -> "kg/m ** 3"."""
    return _UNIT_POWER.sub(r"\1 ** \2", units)


@lru_cache(maxsize=1)
def _registry() -> Any:
    """pint's unit registry (built once: about 0.5 s)."""
    import pint
    return pint.UnitRegistry()
