"""A result as the figures read it: open and check a result file, pick the points to draw.

`load_result` opens a netCDF written by `sweep run` and refuses, in one line (UserError), what
is not one, before reading anything that could block or any data too large; `check_result`
refuses a Dataset the figures cannot be drawn from faithfully. `select_points` fixes the axes
beyond two; `_scene` and `_setting` read the load case from the result's `scene` attribute.
No matplotlib here.
"""

from __future__ import annotations

import functools
import math
import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import xarray as xr

from ..errors import UserError
from ..schema import BY_AXIS

_TIME_DIMS = ("elapsed_time", "time")     # the dimension of stored histories (new, old name)
DIRECTION_DIM = "direction"                # a stepped sweep's up and down (continuation)
# A random result's Monte Carlo records (sweep.models.random_scene.REALISATION_DIM): a
# statistical dimension, not a swept axis; its clearance levels of |q| (m) another.
REALISATION_DIM = "realisation"
CLEARANCE_DIM = "clearance"
ASD_FREQUENCY_DIM = "asd_frequency"   # its spectra's (sweep.models.response_asd.FREQUENCY_DIM)
_DIRECTIONS = ("up", "down")

# What a result may hold. `sweep run` writes far less; a file beyond these limits was not
# written by it (or was altered since), and is refused before any of it is used: an attribute
# is never shortened or dropped silently, since a figure without its units or state meanings
# would show wrong numbers.
_ATTR_CHARS = {"units": 64, "long_name": 1024, "flag_meanings": 4096, "title": 256,
               "model_kind": 64, "coefficients": 64, "cable_sweep_version": 64}
_ATTR_LIMIT = 65536       # characters (or array elements) of any other attribute
_SCENE_BASE = 65536       # characters of the `scene` attribute, plus _SCENE_PER_VALUE per
_SCENE_PER_VALUE = 64     # coordinate value (it lists the axes' values)
_TEXT_ATTRS = ("units", "long_name", "flag_meanings")     # shown on figures: plain text only
_MAX_FLAGS = 64
_MAX_COORD = 1e100        # |coordinate| beyond this: cell edges and scales overflow
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")
_SIGNATURES = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")
# Variables the figures read: over the swept axes only, or a history / snapshots over them.
_OVER_AXES = ("amplitude", "settling_time", "peak_end_displacement", "dynamic_amplification",
              "load_ratio", "natural_frequency", "transit_time", "static_end_displacement",
              "peak_fixed_end_force", "force_amplification", "damping_ratio",
              "absolute_acceleration_g", "transmissibility", "peak_amplitude",
              "peak_frequency", "sweep_duration", "floquet_multiplier", "growth_rate",
              "floquet_mode",
              # a random result's: per realisation, and their means over the realisations
              "rms_deflection", "peak_deflection", "peak_factor", "rms_acceleration_g",
              "rms_deflection_mean", "rms_deflection_ci", "peak_deflection_mean",
              "peak_deflection_ci", "rms_acceleration_g_mean", "rms_acceleration_g_ci",
              "peak_factor_mean", "peak_factor_ci", "escape_probability", "linear_rms")
# A random result's clearance statistics: over the swept axes, the realisations and CLEARANCE_DIM
# (those of _POOLED without the realisations: each made from every record's crossings at once).
_POOLED = ("clearance_upcrossings", "expected_exceedances", "exceedance_probability")
_OVER_CLEARANCE = ("clearance_upcrossing_rate", *_POOLED)
# A stability result's flags (outputs.stability): CF flags like `state`'s, over the swept axes.
# With the time-domain outputs off a result has no `state`: `stability` stands in for it.
STABILITY = "stability"
# A continuous sine sweep's envelope and input level: over (some of) the swept axes and
# BAND_DIM, the centres of its 1/N-octave bands (Hz), with CF bounds (BAND_DIM, nv).
BAND_DIM = "band_frequency"
_OVER_BANDS = ("envelope", "base_level_g")
_HISTORIES = ("displacement", "end_displacement", "fixed_end_force")
_SNAPSHOTS = tuple(f"snapshot_{f}{s}" for f in ("displacement", "force", "velocity")
                   for s in ("", "_ratio"))
# Scene values the footer and overlays read: tables, numbers, short strings.
_SCENE_TABLES = ("model", "cable", "load", "base", "initial", "solver", "metrics", "outputs",
                 "run", "axes")
_SCENE_NUMBERS = (("load", "amplitude"), ("load", "frequency_ratio"), ("load", "frequency"),
                  ("base", "acceleration"), ("base", "acceleration_g"), ("base", "frequency"),
                  ("base", "frequency_ratio"),
                  ("cable", "length"), ("cable", "damping_ratio"), ("model", "membrane"),
                  ("initial", "displacement"), ("initial", "velocity"), ("solver", "t_end"),
                  ("solver", "intervals"), ("solver", "courant"), ("solver", "transits"),
                  ("solver", "rtol"), ("metrics", "tail"), ("metrics", "tolerance"))
_SCENE_STRINGS = (("model", "kind"), ("model", "coefficients"), ("model", "paper_parametric"),
                  ("load", "type"), ("solver", "method"))
_REWRITE = "not a result as 'sweep run' writes it; write it again with 'sweep run ... -o FILE.nc'"


def load_result(path: str | os.PathLike) -> xr.Dataset:
    """Open a cable-sweep result (netCDF written by `sweep run`) into memory.

    Raises UserError (one line) before reading anything that could block or not end (a FIFO,
    device or socket; a directory; an empty file or one without a netCDF/HDF5 signature), for
    attributes beyond the sizes a result has, data declared larger than the memory available,
    an unreadable (truncated, corrupted) file, and for a netCDF that is not a cable-sweep
    result or contradicts itself (`check_result`).
    """
    from ..lazydask import defer
    defer()                                       # reading a file needs no dask
    raw = os.fspath(path)
    where = f"result '{raw}'"
    p = Path(raw)
    try:
        info = p.stat()
    except FileNotFoundError:
        raise UserError(f"{where}: no such file (give a netCDF file written by "
                        "'sweep run ... -o FILE.nc')") from None
    except (OSError, ValueError) as exc:
        raise UserError(f"{where}: cannot be read ({getattr(exc, 'strerror', None) or exc})"
                        ) from None
    if stat.S_ISDIR(info.st_mode):
        raise UserError(f"{where}: is a directory, not a netCDF file")
    if not stat.S_ISREG(info.st_mode):
        kind = ("a FIFO" if stat.S_ISFIFO(info.st_mode) else "a socket"
                if stat.S_ISSOCK(info.st_mode) else "a device")
        raise UserError(f"{where}: is {kind}, not a regular file (give a netCDF file written by "
                        "'sweep run ... -o FILE.nc')")
    if info.st_size == 0:
        raise UserError(f"{where}: is an empty file, not a netCDF file (give a file written by "
                        "'sweep run ... -o FILE.nc')")
    try:
        with open(p, "rb") as f:
            head = f.read(8)
    except OSError as exc:
        raise UserError(f"{where}: cannot be read ({exc.strerror or exc})") from None
    if not head.startswith(_SIGNATURES):
        raise UserError(f"{where}: not a readable netCDF file (no netCDF or HDF5 signature at "
                        "its start); give a file written by 'sweep run ... -o FILE.nc'")
    try:
        opened = xr.open_dataset(p, engine="netcdf4", decode_times=False,
                                 decode_timedelta=False)
    except Exception as exc:  # noqa: BLE001 - any failure to open means: not a readable netCDF
        raise _unreadable(where, exc) from exc
    with opened:
        _check_attrs(opened, where)
        _check_bytes(opened, where, info.st_size)
        try:
            ds = opened.load()
        except Exception as exc:  # noqa: BLE001 - a truncated or corrupted file
            raise _unreadable(where, exc) from exc
    missing = [what for what, ok in (("no 'cable_sweep_version' attribute",
                                      "cable_sweep_version" in ds.attrs),
                                     ("no 'state' variable", flags_variable(ds) is not None
                                      or is_design_result(ds)))
               if not ok]
    if missing:
        raise UserError(f"{where}: not a cable-sweep result ({' and '.join(missing)}); "
                        "give a file written by 'sweep run ... -o FILE.nc'")
    if is_design_result(ds):
        check_design_result(ds, where)
    else:
        check_result(ds, where)
    return ds


_DESIGN_LIMITS = ("min_frequency", "max_amplitude", "max_deflection", "max_strain", "max_rms",
                  "max_peak", "clearance", "state", "stability", "grid")
"""sweep.design.LIMITED_BY (not imported: the figures do not depend on the design layer)."""


def is_design_result(ds: xr.Dataset) -> bool:
    """A file written by 'sweep design -o': `max_span` and `limited_by`, no flags variable."""
    return ("max_span" in ds.data_vars and "limited_by" in ds.data_vars
            and flags_variable(ds) is None)


def check_design_result(ds: xr.Dataset, where: str = "the design result") -> None:
    """Refuse (UserError, one line) a design result the chart cannot show faithfully:
    attributes beyond a result's sizes, a `max_span` that is not numbers in m, a `limited_by`
    over other axes or naming no criterion, axes without finite, distinct coordinates."""
    _check_attrs(ds, where)
    span, by = ds["max_span"], ds["limited_by"]
    if span.dtype.kind not in "iuf" or span.attrs.get("units") != "m":
        raise _refuse(where, f"variable 'max_span' holds {span.dtype} in "
                             f"{span.attrs.get('units')!r}, not numbers in 'm'")
    if by.dims != span.dims:
        raise _refuse(where, f"'limited_by' lies over {by.dims}, 'max_span' over {span.dims}")
    odd = sorted({str(v) for v in np.asarray(by.values).ravel()} - set(_DESIGN_LIMITS))
    if odd:
        raise _refuse(where, f"'limited_by' holds {_short(', '.join(odd))}, not one of "
                             f"{', '.join(_DESIGN_LIMITS)}")
    for dim in span.dims:
        _check_axis(ds, dim, where, unique=True)


def _unreadable(where: str, exc: BaseException) -> UserError:
    reason = (exc.strerror or _short(" ".join(str(exc).split()), 80)) \
        if isinstance(exc, OSError) else "not a format xarray recognises or damaged"
    return UserError(f"{where}: not a readable netCDF file ({reason}); give a file written by "
                     "'sweep run ... -o FILE.nc'")


def _short(text: str, n: int = 60) -> str:
    """`text` as one printable line of at most n characters (escaped, shortened)."""
    shown = ascii(str(text)[:n + 1])[1:-1]
    return shown if len(shown) <= n else shown[:n - 3] + "..."


def _size(value: Any) -> int:
    return len(value) if isinstance(value, (str, bytes)) else int(np.size(value))


def _check_attrs(ds: xr.Dataset, where: str) -> None:
    """Refuse attributes beyond the sizes a result has, and figure text that is not plain."""
    values = sum(int(n) for n in ds.sizes.values())
    owners = [(None, ds.attrs)] + [(name, var.attrs) for name, var in ds.variables.items()]
    for var, attrs in owners:
        for key, value in attrs.items():
            of = f"attribute '{_short(key)}'" + (f" of variable '{_short(var)}'" if var else "")
            limit = (_SCENE_BASE + _SCENE_PER_VALUE * values if key == "scene" and var is None
                     else _ATTR_CHARS.get(key, _ATTR_LIMIT))
            size = _size(value)
            if size > limit:
                raise UserError(f"{where}: {of} is {size:,} characters or values long, more "
                                f"than the {limit:,} a result has; {_REWRITE}")
            if key in _TEXT_ATTRS or (var is None and key in ("title", "model_kind",
                                                              "coefficients", "scene")):
                if not isinstance(value, str):
                    raise UserError(f"{where}: {of} is {type(value).__name__} "
                                    f"{_short(repr(value))}, not text; {_REWRITE}")
                if key != "scene" and ("$" in value or not value.isprintable()):
                    raise UserError(f"{where}: {of} ('{_short(value)}') holds '$' or control "
                                    f"characters, which a figure cannot show as text; "
                                    f"{_REWRITE}")


MAX_INFLATION = 200
"""Most a result's declared data may exceed its file's size (beyond INFLATION_FLOOR bytes):
what `sweep run` writes compresses far less; a small file that declares gigabytes of one
repeated value would take minutes to inflate."""
INFLATION_FLOOR = 256 * 2**20


def _check_bytes(ds: xr.Dataset, where: str, file_bytes: int | None = None) -> None:
    """Refuse data declared larger than the memory available, or (given the file's size
    `file_bytes`) more than MAX_INFLATION times the file, before reading any of it."""
    from ..run import available_memory
    sizes = {name: int(var.size) * var.dtype.itemsize for name, var in ds.variables.items()}
    have = available_memory()
    total = sum(sizes.values())
    if file_bytes is not None and total > max(INFLATION_FLOOR, MAX_INFLATION * file_bytes):
        big = max(sizes, key=sizes.get)
        raise UserError(f"{where}: declares {total / 2**30:,.1f} GiB of data (variable "
                        f"'{_short(big)}') in a file of {file_bytes / 2**20:,.1f} MiB, more "
                        f"than {MAX_INFLATION} times it: no result of 'sweep run' compresses "
                        f"so; {_REWRITE}")
    if have is not None and total > 0.8 * have[0]:
        big = max(sizes, key=sizes.get)
        dims = ", ".join(f"{d} = {n:,}" for d, n in ds[big].sizes.items())
        raise UserError(f"{where}: declares {total / 2**30:,.1f} GiB of data (variable "
                        f"'{_short(big)}': {dims}), more than the {have[0] / 2**30:,.1f} GiB of "
                        f"{have[1]} here allow; {_REWRITE}")


def _refuse(where: str, what: str) -> UserError:
    return UserError(f"{where}: {what}; {_REWRITE}")


def _check_axis(ds: xr.Dataset, dim: str, where: str, unique: bool) -> None:
    """A dimension the figures draw along: a name, a 1-D numeric coordinate of finite values
    (distinct ones for a swept axis), at least one value."""
    if not isinstance(dim, str) or not _NAME.fullmatch(dim):
        raise _refuse(where, f"dimension '{_short(dim)}' is not a plain name")
    if ds.sizes[dim] == 0:
        raise _refuse(where, f"axis '{dim}' has no values")
    if dim not in ds.coords:
        raise _refuse(where, f"axis '{dim}' has no coordinate variable (its values)")
    coord = ds[dim]
    if coord.dims != (dim,) or coord.dtype.kind not in "iuf":
        raise _refuse(where, f"coordinate '{dim}' holds {coord.dtype} over {coord.dims}, not "
                             f"numbers along '{dim}'")
    v = np.asarray(coord.values, dtype=float)
    if not np.all(np.isfinite(v)) or np.any(np.abs(v) > _MAX_COORD):
        raise _refuse(where, f"coordinate '{dim}' has NaN, infinite or out-of-range values "
                             f"({_values_text(v)})")
    if unique and np.unique(v).size != v.size:
        raise _refuse(where, f"axis '{dim}' has repeated values ({_values_text(v)})")


def _check_directions(ds: xr.Dataset, where: str) -> None:
    """A stepped sweep's `direction` coordinate: 'up' and/or 'down', each once."""
    if DIRECTION_DIM not in ds.coords:
        raise _refuse(where, f"axis '{DIRECTION_DIM}' has no coordinate variable (its values)")
    values = [str(v) for v in np.atleast_1d(ds[DIRECTION_DIM].values)]
    if not values or any(v not in _DIRECTIONS for v in values) or len(set(values)) != len(values):
        raise _refuse(where, f"coordinate '{DIRECTION_DIM}' holds {_short(repr(values))}, not "
                             "'up' and 'down', each once")


def flags_variable(ds: xr.Dataset) -> str | None:
    """The variable whose dimensions are the result's swept axes and whose CF flags say how
    each point went: `state`; for a stability-only result (outputs.stability with the
    time-domain outputs off: `growth_rate` and `stability`, no `state`) `stability`; None for
    neither."""
    if "state" in ds.data_vars:
        return "state"
    if STABILITY in ds.data_vars and "growth_rate" in ds.data_vars:
        return STABILITY
    return None


def _check_flags(state: xr.DataArray, name: str, where: str) -> None:
    """Integer CF flags: flag_values and flag_meanings that pair up, values among them."""
    if state.dtype.kind not in "iu":
        raise _refuse(where, f"variable '{name}' holds {state.dtype}, not integer "
                             f"{name} flags")
    flags = np.asarray(state.attrs.get("flag_values", []))
    meanings = str(state.attrs.get("flag_meanings", "")).split()
    if flags.ndim != 1 or flags.dtype.kind not in "iu" or not 1 <= flags.size <= _MAX_FLAGS:
        raise _refuse(where, f"{name}'s flag_values are {_short(repr(flags))}, not 1 to "
                             f"{_MAX_FLAGS} integers")
    if len(meanings) != flags.size or len(set(meanings)) != len(meanings):
        raise _refuse(where, f"{name} has {flags.size} flag_values but {len(meanings)} "
                             f"flag_meanings ({len(set(meanings))} distinct): they must pair up")
    if np.unique(flags).size != flags.size:
        raise _refuse(where, f"{name}'s flag_values ({_short(repr(flags.tolist()))}) repeat a "
                             "value")
    if any(len(m) > 64 for m in meanings):
        raise _refuse(where, f"{name} has a flag meaning longer than 64 characters")
    odd = np.setdiff1d(np.unique(state.values), flags)
    if odd.size:
        raise _refuse(where, f"{name} holds values that are not among its flag_values "
                             f"({_short(repr(odd.tolist()))})")


def check_result(ds: xr.Dataset, where: str = "the result") -> None:
    """Refuse (UserError, one line naming `where`) a Dataset the figures cannot be drawn from
    faithfully: attributes beyond a result's sizes, a `state` that is not integer flags with
    matching `flag_values` / `flag_meanings`, swept axes without finite, distinct coordinate
    values or with none, plotted variables that are not numbers or lie over other dimensions,
    a `scene` attribute that is not a scene of this result's model. A stability-only result
    (`growth_rate` and `stability`, no `state`: outputs.stability with the time-domain outputs
    off) is checked with `stability` in state's place; a result with both has both checked,
    over the same axes. `plot` calls it; so does `load_result`."""
    _check_attrs(ds, where)
    name = flags_variable(ds)
    if name is None:
        raise _refuse(where, "no 'state' variable")
    state = ds[name]
    _check_flags(state, name, where)
    if name == "state" and STABILITY in ds.data_vars:   # both kinds: the stability flags too
        _check_flags(ds[STABILITY], STABILITY, where)
        over = [d for d in state.dims if d != DIRECTION_DIM]
        if sorted(ds[STABILITY].dims) != sorted(over):
            raise _refuse(where, f"variable '{STABILITY}' lies over "
                                 f"({', '.join(map(str, ds[STABILITY].dims))}), not over "
                                 f"({', '.join(over)})")
    axes = [d for d in state.dims if d != DIRECTION_DIM]
    for dim in axes:
        _check_axis(ds, dim, where, unique=True)
    if DIRECTION_DIM in state.dims:
        _check_directions(ds, where)
    for name in (*_OVER_AXES, *_HISTORIES, *_SNAPSHOTS, *_OVER_CLEARANCE):
        if name not in ds or name in ds.coords and name in axes:
            continue
        da = ds[name]
        if da.dtype.kind not in "iuf":
            raise _refuse(where, f"variable '{name}' holds {da.dtype}, not numbers")
        own = [d for d in axes if d != REALISATION_DIM] if name in _POOLED else axes
        extra = [d for d in da.dims if d not in own and d != DIRECTION_DIM]
        if name in _HISTORIES:
            expected = [d for d in _TIME_DIMS if d in da.dims][:1]
        elif name in _SNAPSHOTS:
            expected = ["snapshot_time", "position"]
        elif name in _OVER_CLEARANCE:
            expected = [CLEARANCE_DIM]
        else:
            expected = []
        if sorted(extra) != sorted(expected) or (expected and len(da.dims) != len(own) + len(
                expected)):
            want = ", ".join(own + (expected or ([_TIME_DIMS[0]] if name in _HISTORIES
                                                 else [])))
            raise _refuse(where, f"variable '{name}' lies over ({', '.join(map(str, da.dims))})"
                                 f", not over ({want})")
        for dim in expected:
            _check_axis(ds, dim, where, unique=name in _OVER_CLEARANCE)
    _check_bands(ds, axes, where)
    for key in ("title", "model_kind", "coefficients", "scene"):
        if key in ds.attrs and not isinstance(ds.attrs[key], str):
            raise _refuse(where, f"attribute '{key}' is not text")
    _check_scene(ds, where)


def _check_bands(ds: xr.Dataset, axes: list[str], where: str) -> None:
    """A sweep's envelope (over every swept axis and BAND_DIM) and base level (over BAND_DIM
    and some of the axes): numbers, a band axis of distinct positive frequencies, and band
    bounds, when the axis names them, of two finite edges around each centre."""
    present = [name for name in _OVER_BANDS if name in ds]
    if not present:
        return
    for name in present:
        da = ds[name]
        if da.dtype.kind not in "iuf":
            raise _refuse(where, f"variable '{name}' holds {da.dtype}, not numbers")
        others = [d for d in da.dims if d not in (BAND_DIM, DIRECTION_DIM)]
        want = axes if name == "envelope" else [d for d in axes if d in others]
        if BAND_DIM not in da.dims or sorted(others) != sorted(want) \
                or len(others) != len(set(others)):
            shown = ", ".join(axes + [BAND_DIM]) if name == "envelope" else \
                f"{BAND_DIM} and some of ({', '.join(axes)})"
            raise _refuse(where, f"variable '{name}' lies over ({', '.join(map(str, da.dims))})"
                                 f", not over ({shown})")
    _check_axis(ds, BAND_DIM, where, unique=True)
    centres = np.asarray(ds[BAND_DIM].values, dtype=float)
    if np.any(centres <= 0):
        raise _refuse(where, f"coordinate '{BAND_DIM}' has values <= 0 "
                             f"({_values_text(centres)}), not band frequencies")
    bounds = ds[BAND_DIM].attrs.get("bounds")
    if bounds is None:
        return
    if not isinstance(bounds, str) or bounds not in ds.variables:
        raise _refuse(where, f"coordinate '{BAND_DIM}' names bounds {_short(repr(bounds))}, "
                             "which the result does not hold")
    b = ds[bounds]
    if b.ndim != 2 or b.dims[0] != BAND_DIM or b.shape[1] != 2 or b.dtype.kind not in "iuf":
        raise _refuse(where, f"bounds '{_short(bounds)}' hold {b.dtype} over "
                             f"({', '.join(map(str, b.dims))}), not two edges per band")
    v = np.asarray(b.values, dtype=float)
    if not (np.all(np.isfinite(v)) and np.all(v[:, 0] <= centres) and np.all(centres <= v[:, 1])
            and np.all(v > 0)):
        raise _refuse(where, f"bounds '{_short(bounds)}' are not finite positive edges around "
                             f"each band's centre")


def _check_scene(ds: xr.Dataset, where: str) -> None:
    """The `scene` attribute, when present: TOML of this result's model, with tables where a
    scene has tables and numbers and short strings where the figures read them."""
    if "scene" not in ds.attrs:
        return
    try:
        doc = _parse_scene(str(ds.attrs["scene"]))
    except (tomllib.TOMLDecodeError, ValueError, RecursionError) as exc:
        raise _refuse(where, f"its 'scene' attribute is not valid TOML "
                             f"({_short(' '.join(str(exc).split()))})") from None
    for section in _SCENE_TABLES:
        if section in doc and not isinstance(doc[section], dict):
            raise _refuse(where, f"its 'scene' attribute has '{section}' = "
                                 f"{_short(repr(doc[section]))}, not a table")
    for section, key in _SCENE_NUMBERS:
        value = doc.get(section, {}).get(key)
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                  or not math.isfinite(value)):
            raise _refuse(where, f"its 'scene' attribute has {section}.{key} = "
                                 f"{_short(repr(value))}, not a finite number")
    for section, key in _SCENE_STRINGS:
        value = doc.get(section, {}).get(key)
        if value is not None and not (isinstance(value, str) and len(value) <= 64
                                      and value.isprintable() and "$" not in value):
            raise _refuse(where, f"its 'scene' attribute has {section}.{key} = "
                                 f"{_short(repr(value))}, not a short plain string")
    kind = doc.get("model", {}).get("kind", "transverse")
    stored = ds.attrs.get("model_kind")
    if stored is not None and kind != stored:
        raise _refuse(where, f"its 'scene' attribute is a {_short(kind)} scene but the result's "
                             f"model_kind is {_short(stored)}")


@functools.lru_cache(maxsize=8)
def _parse_scene(text: str) -> dict[str, Any]:
    """The scene TOML, parsed once per text (the figures read it many times)."""
    return tomllib.loads(text)


# Why a sweep's `direction` is never selected (--select and select=).
_DIRECTION_NOTE = ("a sweep's up and down directions: the figures draw both, up solid and down "
                   "dashed, or one figure each")


def parse_select(items: Iterable[str]) -> dict[str, float]:
    """`["length=0.5", "frequency_ratio=2"]` -> {"length": 0.5, "frequency_ratio": 2.0}."""
    out: dict[str, float] = {}
    for item in items:
        dim, sep, value = item.partition("=")
        dim, value = dim.strip(), value.strip()
        if not sep or not dim or not value:
            raise UserError(f"--select '{item}': expected DIM=VALUE, e.g. --select length=0.5")
        if dim == DIRECTION_DIM:
            raise UserError(f"--select '{item}': '{dim}' is not a swept axis to select "
                            f"({_DIRECTION_NOTE}); select a swept axis, e.g. --select length=0.5")
        try:
            out[dim] = float(value)
        except ValueError:
            raise UserError(f"--select '{item}': '{value}' is not a number (give an axis value, "
                            "e.g. --select length=0.5)") from None
    return out


def _values_text(values: np.ndarray) -> str:
    v = np.asarray(values)
    if v.size <= 8:
        return ", ".join(f"{x:g}" for x in v)
    return f"{v.size} values from {v.min():g} to {v.max():g}: {v[0]:g}, {v[1]:g}, ..., {v[-1]:g}"


def swept_axes(ds: xr.Dataset) -> list[str]:
    """The result's swept axes with more than one value, in scene order (the dims of state, of
    `stability` in a stability-only result; a stepped sweep's `direction` and a random
    result's `realisation` are not)."""
    return [d for d in ds[flags_variable(ds) or "state"].dims
            if ds.sizes[d] > 1 and d not in (DIRECTION_DIM, REALISATION_DIM)]


def is_random_result(ds: xr.Dataset) -> bool:
    """A random base excitation's result ([base] asd_g2 / asd): statistics per realisation
    (`rms_deflection`, m) and their means (docs/model.md sec. 11)."""
    return "rms_deflection" in ds.data_vars


def over_points(ds: xr.Dataset) -> xr.Dataset:
    """A random result as the per-point figures read it: without its `realisation` dimension
    (every per-realisation variable dropped; the means over the realisations stay) and with
    `state` per point: `completed` where every realisation completed, else the state most of
    those that did not ended in (e.g. `diverged` where one escaped). `ds` itself when it
    has no realisation dimension."""
    if REALISATION_DIM not in ds["state"].dims:
        return ds
    state = ds["state"]
    meanings = dict(zip(np.atleast_1d(state.attrs.get("flag_values", [])).tolist(),
                        str(state.attrs.get("flag_meanings", "")).split()))
    values = state.transpose(..., REALISATION_DIM).values
    summary = values[..., 0].copy()
    for index in np.ndindex(summary.shape):
        bad = [int(v) for v in values[index] if meanings.get(int(v)) != "completed"]
        if bad:
            summary[index] = max(set(bad), key=lambda v: (bad.count(v), -v))
    out = ds.drop_dims(REALISATION_DIM)
    out["state"] = xr.DataArray(summary, dims=[d for d in state.dims if d != REALISATION_DIM],
                                attrs=state.attrs)
    return out


def select_points(ds: xr.Dataset, select: Mapping[str, Any] | None = None) -> xr.Dataset:
    """`ds` with each axis in `select` fixed at the given value, single-valued axes dropped to
    scalar coordinates and the remaining axes sorted; at most two swept axes may remain (a
    random result's `realisation` is not one: it stays whole, and cannot be selected).

    A value must be one of the axis's coordinate values (to 1e-6 relative). Raises UserError
    for an unknown axis, a value not on the axis, or more than two remaining swept axes.
    """
    name = flags_variable(ds)
    if name is None:
        raise UserError("not a cable-sweep result: no 'state' variable")
    axes = [d for d in ds[name].dims if d not in (DIRECTION_DIM, REALISATION_DIM)]
    for dim, value in (select or {}).items():
        shown = f"{value:g}" if isinstance(value, (int, float, np.number)) else str(value)
        if dim not in axes:
            records = (" (the random records: the figures show statistics over them)"
                       if dim == REALISATION_DIM and dim in ds[name].dims else
                       f" ({_DIRECTION_NOTE})" if dim == DIRECTION_DIM and dim in ds[name].dims
                       else "")
            raise UserError(f"select {dim}={shown}: '{dim}' is not a swept axis of this result"
                            f"{records} (its axes: {', '.join(axes) or 'none'})")
        coord = np.asarray(ds[dim].values, dtype=float)
        try:
            target = float(value)
        except (TypeError, ValueError):
            raise UserError(f"select {dim}={shown}: not a number") from None
        scale = float(np.max(np.abs(coord))) if coord.size else 0.0
        hits = np.flatnonzero(np.isclose(coord, target, rtol=1e-6, atol=1e-12 * scale))
        if not hits.size:
            raise UserError(f"select {dim}={shown}: not a value of axis '{dim}' (its values: "
                            f"{_values_text(coord)})")
        ds = ds.isel({dim: int(hits[0])})
        axes.remove(dim)
    single = {d: 0 for d in axes if ds.sizes[d] == 1}
    ds = ds.isel(single)
    axes = [d for d in axes if d not in single]
    if len(axes) > 2:
        stepped = ds.attrs.get("continuation_axis")    # a stepped sweep's: never the one to fix
        others = [d for d in axes if d != stepped]
        extra = others[len(others) - (len(axes) - 2):]
        example = " ".join(f"--select {d}={float(ds[d].values[0]):g}" for d in extra)
        raise UserError(f"the result has {len(axes)} swept axes ({', '.join(axes)}): pick "
                        f"the values of all but two to plot, e.g. {example} (select= in "
                        "Python)")
    return ds.sortby(axes) if axes else ds


def _scene(ds: xr.Dataset) -> dict[str, Any]:
    try:
        return _parse_scene(str(ds.attrs.get("scene", "")))
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        return {}


def _setting(ds: xr.Dataset, section: str, key: str) -> Any:
    """A scene value as this (selected) result has it: a fixed axis's coordinate, None while
    the axis is still swept (its values are on the figure's axes), else the scene's value."""
    axis = next((a for a, k in BY_AXIS.items() if (k.section, k.name) == (section, key)), None)
    if axis is not None and axis in ds.coords:
        return float(ds[axis].values) if ds[axis].ndim == 0 else None
    if axis is not None and axis in _scene(ds).get("axes", {}):
        return None
    return _scene(ds).get(section, {}).get(key)



def _time_dim(da: xr.DataArray) -> str | None:
    """The time dimension of a stored history, None when `da` has none."""
    return next((d for d in _TIME_DIMS if d in da.dims), None)
