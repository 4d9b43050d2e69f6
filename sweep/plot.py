"""Figures of a cable-sweep result: pick what fits the Dataset, draw it with matplotlib.

    from sweep.plot import plot, save
    figures = plot(ds)                       # {"amplitude": Figure, "state": Figure, ...}
    save(figures, "figs", formats=("png", "svg"), prefix="fig5-")

What `plot` draws, by the result's content:

- transverse, one swept axis: amplitude and settling time against it (`plot_line`), markers
  coloured by `state`;
- transverse, two swept axes: maps (`plot_map`) of amplitude and settling time with the
  modulated, unsettled, diverged and failed points marked, and a map of `state`
  (`plot_state_map`); closed-form overlays where the axes allow: the principal parametric
  resonance zone W = 2 w1 sqrt(1 +- mu), mu = P0/(2 Pcr) (docs/model.md sec. 2; dotted where
  damping suppresses it, mu < 2 zeta) and the buckling length where P0 = Pcr; under base
  excitation also a map of the absolute midspan acceleration in g and the linear resonance
  f = f1 (docs/model.md sec. 5);
- stored time series: q(t), one panel per point (`plot_time_series`, the paper's Fig 5);
- longitudinal: snapshots along the span (`plot_snapshots`, the paper's Fig 7) and the end
  histories (`plot_histories`); with swept axes also the peak end displacement and the
  dynamic amplification over them.

What every figure keeps to, so that it says something:

- a quantity that is NaN everywhere or has one value at every point (e.g. the settling times
  of an undamped run, all 0 s) gets no figure; `plot` records why (`Figures.skipped`) and
  `save` logs it;
- displacements are in mm on every axis, colour bar and label (times and forces get the
  prefix their size calls for); no axis uses an offset or a scientific multiplier, and
  near-constant data get a +-5 % range around their value;
- on a log-coloured displacement map, a cell below FLOOR (1e-3) times the map's largest
  value is drawn white, "no response", and the colours span the three decades above it;
- dense maps (more than 100 cells) mark the modulated, unsettled, diverged and failed points
  by hatched regions outlined along the cell edges, so the colour under them still shows;
- `plot` puts the load case (`footer`: model, P0, frequency, damping, initial state, t_end,
  solver, metrics; from the result's `scene` attribute) under each figure;
- on the paper's Fig 5 case (paper coefficients, P0 = 4 N, W/w0 = 1) the paper's amplitudes
  4.1, 3.8, 3.4, 3.0 mm (l = 0.5, 0.7, 0.85, 1 m) are marked "paper Fig 5".

More than two swept axes: `select={"dim": value, ...}` picks the values of the others (each
value must be one of the axis's coordinates); `save` writes the selection into the file names
(RESULT-DIM=VALUE-FIGURE.png), so that two selections do not overwrite each other. Labels read
`long_name` and `units` from the Dataset. Like xarray's plotting functions, the single-panel
ones take `ax=None` and return the Axes, and pass extra keyword arguments to matplotlib.
Figures are made with the object-oriented API (`matplotlib.figure.Figure`): no pyplot, no
display and no backend choice are needed, and none is forced on the caller.
"""

from __future__ import annotations

import contextlib
import functools
import io
import logging
import math
import os
import re
import stat
import textwrap
import tomllib
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps as mpl_colormaps
from matplotlib import colors as mcolors
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import ScalarFormatter

from .errors import UserError
from .files import write_temporary
from .schema import BY_AXIS, G_UNITS

__all__ = ["FLOOR", "Figures", "PAPER_FIG5_AMPLITUDES", "STATE_STYLES", "footer", "label",
           "check_result", "load_result", "parse_select", "plot", "plot_histories",
           "plot_line", "plot_map", "plot_snapshots", "plot_state_map", "plot_time_series",
           "save", "select_points", "state_styles", "swept_axes", "why_not_drawn"]

# A fixed colour and map marker per state meaning (CF flag_meanings); marker None: a good
# state, not marked on maps. Meanings not listed here get a fallback colour and "*".
STATE_STYLES: dict[str, tuple[str, str | None]] = {
    "invalid_input": ("#7f7f7f", "s"),
    "decayed": ("#2ca02c", None),
    "steady": ("#1f77b4", None),
    "completed": ("#1f77b4", None),
    "modulated": ("#ff7f0e", "o"),
    "unsettled": ("#e6c619", "^"),
    "diverged": ("#d62728", "X"),
    "step_size_too_small": ("#9467bd", "P"),
    "max_steps_reached": ("#8c564b", "D"),
}
_FALLBACK_COLOURS = ("#17becf", "#e377c2", "#bcbd22", "#393b79", "#637939")
_NAN_COLOUR = "0.82"
_OUTLINE = [patheffects.Stroke(linewidth=3.0, foreground="k"), patheffects.Normal()]
_DECADES = 6          # a log colour scale spans at most this many decades below the maximum
_MAX_LABEL = 60
# Displacement maps: amplitudes below FLOOR x the map's largest one are drawn in one
# "no response" colour, and the log colour scale spans only the three decades above it.
FLOOR = 1e-3
_NO_RESPONSE_COLOUR = "white"
# Maps with more cells than this mark the states by hatched, outlined regions, not markers.
_MARKER_CELLS = 100
_HATCHES = {"modulated": "\\\\\\", "unsettled": "///", "diverged": "xxx",
            "step_size_too_small": "...", "max_steps_reached": "+++", "invalid_input": "---"}
# The paper's Fig 5 tail amplitudes [m] by span length [m] (P0 = 4 N, W/w0 = 1, Eq.32).
PAPER_FIG5_AMPLITUDES: dict[float, float] = {0.5: 4.1e-3, 0.7: 3.8e-3, 0.85: 3.4e-3,
                                             1.0: 3.0e-3}
_FOOTER_PT = 7.0
_TIME_DIMS = ("elapsed_time", "time")     # the dimension of stored histories (new, old name)
_log = logging.getLogger(__name__)


# ---------------------------------------------------------------------------------- reading

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
              "absolute_acceleration_g", "transmissibility")
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
        _check_bytes(opened, where)
        try:
            ds = opened.load()
        except Exception as exc:  # noqa: BLE001 - a truncated or corrupted file
            raise _unreadable(where, exc) from exc
    missing = [what for what, ok in (("no 'cable_sweep_version' attribute",
                                      "cable_sweep_version" in ds.attrs),
                                     ("no 'state' variable", "state" in ds.data_vars)) if not ok]
    if missing:
        raise UserError(f"{where}: not a cable-sweep result ({' and '.join(missing)}); "
                        "give a file written by 'sweep run ... -o FILE.nc'")
    check_result(ds, where)
    return ds


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


def _check_bytes(ds: xr.Dataset, where: str) -> None:
    """Refuse data declared larger than the memory available (before reading any of it)."""
    from .run import available_memory
    sizes = {name: int(var.size) * var.dtype.itemsize for name, var in ds.variables.items()}
    have = available_memory()
    total = sum(sizes.values())
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


def check_result(ds: xr.Dataset, where: str = "the result") -> None:
    """Refuse (UserError, one line naming `where`) a Dataset the figures cannot be drawn from
    faithfully: attributes beyond a result's sizes, a `state` that is not integer flags with
    matching `flag_values` / `flag_meanings`, swept axes without finite, distinct coordinate
    values or with none, plotted variables that are not numbers or lie over other dimensions,
    a `scene` attribute that is not a scene of this result's model. `plot` calls it; so does
    `load_result`."""
    _check_attrs(ds, where)
    if "state" not in ds.data_vars:
        raise _refuse(where, "no 'state' variable")
    state = ds["state"]
    if state.dtype.kind not in "iu":
        raise _refuse(where, f"variable 'state' holds {state.dtype}, not integer state flags")
    flags = np.asarray(state.attrs.get("flag_values", []))
    meanings = str(state.attrs.get("flag_meanings", "")).split()
    if flags.ndim != 1 or flags.dtype.kind not in "iu" or not 1 <= flags.size <= _MAX_FLAGS:
        raise _refuse(where, f"state's flag_values are {_short(repr(flags))}, not 1 to "
                             f"{_MAX_FLAGS} integers")
    if len(meanings) != flags.size or len(set(meanings)) != len(meanings):
        raise _refuse(where, f"state has {flags.size} flag_values but {len(meanings)} "
                             f"flag_meanings ({len(set(meanings))} distinct): they must pair up")
    if np.unique(flags).size != flags.size:
        raise _refuse(where, f"state's flag_values ({_short(repr(flags.tolist()))}) repeat a "
                             "value")
    if any(len(m) > 64 for m in meanings):
        raise _refuse(where, "state has a flag meaning longer than 64 characters")
    odd = np.setdiff1d(np.unique(state.values), flags)
    if odd.size:
        raise _refuse(where, f"state holds values that are not among its flag_values "
                             f"({_short(repr(odd.tolist()))})")
    axes = list(state.dims)
    for dim in axes:
        _check_axis(ds, dim, where, unique=True)
    for name in (*_OVER_AXES, *_HISTORIES, *_SNAPSHOTS):
        if name not in ds or name in ds.coords and name in axes:
            continue
        da = ds[name]
        if da.dtype.kind not in "iuf":
            raise _refuse(where, f"variable '{name}' holds {da.dtype}, not numbers")
        extra = [d for d in da.dims if d not in axes]
        if name in _HISTORIES:
            expected = [d for d in _TIME_DIMS if d in da.dims][:1]
        elif name in _SNAPSHOTS:
            expected = ["snapshot_time", "position"]
        else:
            expected = []
        if sorted(extra) != sorted(expected) or (expected and len(da.dims) != len(axes) + len(
                expected)):
            want = ", ".join(axes + (expected or ([_TIME_DIMS[0]] if name in _HISTORIES
                                                  else [])))
            raise _refuse(where, f"variable '{name}' lies over ({', '.join(map(str, da.dims))})"
                                 f", not over ({want})")
        for dim in expected:
            _check_axis(ds, dim, where, unique=False)
    for key in ("title", "model_kind", "coefficients", "scene"):
        if key in ds.attrs and not isinstance(ds.attrs[key], str):
            raise _refuse(where, f"attribute '{key}' is not text")
    _check_scene(ds, where)


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


def parse_select(items: Iterable[str]) -> dict[str, float]:
    """`["length=0.5", "frequency_ratio=2"]` -> {"length": 0.5, "frequency_ratio": 2.0}."""
    out: dict[str, float] = {}
    for item in items:
        dim, sep, value = item.partition("=")
        dim, value = dim.strip(), value.strip()
        if not sep or not dim or not value:
            raise UserError(f"--select '{item}': expected DIM=VALUE, e.g. --select length=0.5")
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
    """The result's swept axes with more than one value, in scene order (the dims of state)."""
    return [d for d in ds["state"].dims if ds.sizes[d] > 1]


def select_points(ds: xr.Dataset, select: Mapping[str, Any] | None = None) -> xr.Dataset:
    """`ds` with each axis in `select` fixed at the given value, single-valued axes dropped to
    scalar coordinates and the remaining axes sorted; at most two swept axes may remain.

    A value must be one of the axis's coordinate values (to 1e-6 relative). Raises UserError
    for an unknown axis, a value not on the axis, or more than two remaining swept axes.
    """
    if "state" not in ds.data_vars:
        raise UserError("not a cable-sweep result: no 'state' variable")
    axes = list(ds["state"].dims)
    for dim, value in (select or {}).items():
        shown = f"{value:g}" if isinstance(value, (int, float, np.number)) else str(value)
        if dim not in axes:
            raise UserError(f"select {dim}={shown}: '{dim}' is not a swept axis of this result "
                            f"(its axes: {', '.join(axes) or 'none'})")
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
        extra = axes[2:]
        example = " ".join(f"--select {d}={float(ds[d].values[0]):g}" for d in extra)
        raise UserError(f"the result has {len(axes)} swept axes ({', '.join(axes)}): pick "
                        f"the values of all but two to plot, e.g. {example} (select= in "
                        "Python)")
    return ds.sortby(axes) if axes else ds


# ---------------------------------------------------------------------------------- labels

def label(da: xr.DataArray, units: str | None = None) -> str:
    """'long_name [units]' from the attributes (shortened: the text before ' (' when that is
    long, the variable name when still too long; no brackets for dimensionless '1')."""
    name = str(da.attrs.get("long_name") or da.name or "")
    if len(name) > 40 and " (" in name and name.index(" (") >= 10:
        name = name[:name.index(" (")]
    if len(name) > _MAX_LABEL:
        name = str(da.name or name).replace("_", " ")
    units = da.attrs.get("units") if units is None else units
    return f"{name} [{units}]" if units and units != "1" else name


_PREFIXES = ((1.0, ""), (1e-3, "m"), (1e-6, "\u00b5"), (1e-9, "n"))


def _scaled(values: np.ndarray, units: str | None) -> tuple[float, str | None]:
    """A factor and prefixed units for m, s and N, chosen from the largest finite value."""
    if units not in ("m", "s", "N"):
        return 1.0, units
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite)]
    top = float(finite.max()) if finite.size else 0.0
    if top == 0.0:
        return 1.0, units
    for factor, prefix in _PREFIXES:
        if top >= 0.999 * factor:
            return 1.0 / factor, prefix + units
    factor, prefix = _PREFIXES[-1]
    return 1.0 / factor, prefix + units


def _is_displacement(da: xr.DataArray) -> bool:
    """A displacement (units m, not the span length): always shown in mm."""
    return da.attrs.get("units") == "m" and da.name != "length"


def _unit(da: xr.DataArray, values: np.ndarray | None = None) -> tuple[float, str | None]:
    """The factor and units a variable is shown in: displacements in mm, times and forces
    with the prefix their largest value calls for (`_scaled`), anything else as stored."""
    if _is_displacement(da):
        return 1e3, "mm"
    if da.attrs.get("units") == G_UNITS:          # a level in g: "9.80665 m s-2" reads as g
        return 1.0, "g"
    return _scaled(da.values if values is None else values, da.attrs.get("units"))


def _fmt(value: float, units: str | None) -> str:
    factor, scaled = (1e3, "mm") if units == "m" else _scaled(np.array([value]), units)
    text = f"{value * factor:.4g}"
    return f"{text} {scaled}" if scaled and scaled != "1" else text


def _point_text(ds: xr.Dataset, dims: Iterable[str]) -> str:
    def one(d: str) -> str:
        factor, units = (1e3, "mm") if _is_displacement(ds[d]) else (1.0, ds[d].attrs.get("units"))
        value = f"{float(ds[d].values) * factor:.4g}"
        return f"{d} = {value} {units}" if units and units != "1" else f"{d} = {value}"
    return ", ".join(one(d) for d in dims)


def _title(ds: xr.Dataset, what: str = "") -> str:
    """The result's title plus the fixed (selected or single-valued) axis values."""
    fixed = [d for d in _scene_axes(ds) if d in ds.coords and ds[d].ndim == 0]
    parts = [str(ds.attrs.get("title", "cable-sweep result"))]
    if what:
        parts[0] += f": {what}"
    if fixed:
        parts.append(_point_text(ds, fixed))
    return ", ".join(parts)


def _scene_axes(ds: xr.Dataset) -> list[str]:
    doc = _scene(ds)
    return list(doc.get("axes", {})) if doc else [c for c in ds.coords
                                                 if c not in (*_TIME_DIMS, "snapshot_time",
                                                              "position")]


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


def footer(ds: xr.Dataset) -> str:
    """The load case in one line, from the result's scene (its `scene` attribute) and fixed
    axis values: model, end load, damping, initial state, span, end time, solver, metrics.
    Swept quantities are left out (they are on the axes). Empty without a scene."""
    doc = _scene(ds)
    if not doc:
        return ""

    def get(section: str, key: str) -> Any:
        return _setting(ds, section, key)

    def num(value: Any) -> str:
        return f"{float(value):.4g}"

    parts = []
    load = doc.get("load", {})
    kind = doc.get("model", {}).get("kind", ds.attrs.get("model_kind", "transverse"))
    p0 = get("load", "amplitude")
    text = f"{load.get('type', 'harmonic')} end load" + ("" if p0 is None else
                                                        f" P0 = {num(p0)} N")
    if p0 is not None and float(p0) == 0.0 and kind != "longitudinal":
        text = "no end load"
    elif load.get("type", "harmonic") == "harmonic" and kind != "longitudinal":
        ratio, freq = get("load", "frequency_ratio"), get("load", "frequency")
        if ratio is not None:
            text += f" at W/w1 = {num(ratio)}"
        elif freq is not None:
            text += f" at {num(freq)} Hz"
    parts.append(text)
    if "absolute_acceleration_g" in ds or "base" in doc or any(
            str(a).startswith("base_") for a in doc.get("axes", {})):
        parts.append(_base_text(get))
    length = get("cable", "length")
    if length is not None:
        parts.append(f"l = {num(length)} m")
    solver = doc.get("solver", {})
    if kind == "longitudinal":
        parts.append("longitudinal wave, central difference")
        parts.append(f"{solver.get('intervals', '?')} intervals, "
                     f"C = {num(solver.get('courant', 1))}")
        if solver.get("transits") is not None:
            parts.append(f"{num(solver['transits'])} transits")
        elif solver.get("t_end") is not None:
            parts.append(f"t_end = {_fmt(float(solver['t_end']), 's')}")
        return "Load case: " + "; ".join(parts)
    model = doc.get("model", {})
    coeff = model.get("coefficients", ds.attrs.get("coefficients", "?"))
    text = f"{coeff} coefficients"
    if coeff == "paper":
        text += f" (cos terms {model.get('paper_parametric', 'printed')})"
    elif get("model", "membrane") is not None:
        text += f", membrane {num(get('model', 'membrane'))}"
    parts.insert(0, text)
    zeta = get("cable", "damping_ratio")
    if zeta is not None:
        parts.append(f"damping ratio {num(zeta)}")
    q0, v0 = get("initial", "displacement"), get("initial", "velocity")
    start = [t for t in ((None if q0 is None else f"q(0) = {_fmt(float(q0), 'm')}"),
                         (None if v0 is None else f"q'(0) = {num(v0)} m/s")) if t]
    if start:
        parts.append(", ".join(start))
    if solver.get("t_end") is not None:
        parts.append(f"t_end = {num(solver['t_end'])} s")
    parts.append(f"{solver.get('method', 'rk45')} rtol {num(solver.get('rtol', 1e-8))}")
    metrics = doc.get("metrics", {})
    if metrics:
        parts.append(f"tail {num(metrics.get('tail', 0.5))}, "
                     f"tolerance {num(metrics.get('tolerance', 0.02))}")
    return "Load case: " + "; ".join(parts)


def _base_text(get: Any) -> str:
    """'base sine 1 g at 20 Hz' for the footer; swept parts left out (they are on the axes)."""
    level_g, level = get("base", "acceleration_g"), get("base", "acceleration")
    freq, ratio = get("base", "frequency"), get("base", "frequency_ratio")
    text = "base sine"
    if level_g is not None:
        text += f" {float(level_g):.4g} g"
    elif level is not None:
        text += f" {float(level):.4g} m/s^2"
    if freq is not None:
        text += f" at {float(freq):.4g} Hz"
    elif ratio is not None:
        text += f" at f/f1 = {float(ratio):.4g}"
    return text


def _base_overlay(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """The linear resonance of a base-excited map: f = f1 over the other axis (a
    base_frequency axis, when f1 depends on that axis alone) or f/f1 = 1; its legend handle."""
    style = dict(color="w", lw=1.4, ls=(0, (1, 1.5)), zorder=3, path_effects=_OUTLINE)
    if "base_frequency_ratio" in (x, y):
        (ax.axvline if x == "base_frequency_ratio" else ax.axhline)(1.0, **style)
    elif "base_frequency" in (x, y) and "natural_frequency" in ds:
        other = y if x == "base_frequency" else x
        f1 = ds["natural_frequency"]
        if not _depends_only_on(f1, [other]) or other not in f1.dims:
            return []
        pos = _coord(ds, other)
        values = np.asarray(f1.transpose(other).values, float)
        px, py = (values, pos) if x == "base_frequency" else (pos, values)
        ax.plot(px, py, **style)
    else:
        return []
    return [Line2D([], [], label="linear resonance f = f1", **style)]


def _add_footer(fig: Figure, ds: xr.Dataset) -> None:
    """The footer under a constrained-layout figure, with room kept for it."""
    text = footer(ds)
    if not text:
        return
    width = fig.get_size_inches()[0]
    chars = max(40, int(width * 72.0 / (0.62 * _FOOTER_PT)))
    wrapped = _wrap(text, chars)
    lines = wrapped.count("\n") + 1
    height = (lines * 1.25 * _FOOTER_PT + 6.0) / 72.0 / fig.get_size_inches()[1]
    fig.text(0.01, 0.004, wrapped, fontsize=_FOOTER_PT, color="0.3", ha="left", va="bottom")
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set"):
        engine.set(rect=(0.0, height, 1.0, 1.0 - height))


def _paper_fig5(ds: xr.Dataset) -> dict[float, float]:
    """The paper's Fig 5 amplitudes [m] by span length for the points of this result, when it
    is the paper's Fig 5 case (paper coefficients, harmonic P0 = 4 N at W/w0 = 1, spans among
    0.5, 0.7, 0.85, 1 m); else empty."""
    if ds.attrs.get("coefficients") != "paper" or "length" not in ds.coords:
        return {}
    if _scene(ds).get("load", {}).get("type", "harmonic") != "harmonic":
        return {}
    p0, ratio = _setting(ds, "load", "amplitude"), _setting(ds, "load", "frequency_ratio")
    if p0 is None or ratio is None or not (math.isclose(float(p0), 4.0)
                                           and math.isclose(float(ratio), 1.0)):
        return {}
    found = {}
    for length in np.atleast_1d(ds["length"].values).astype(float):
        for paper_length, amplitude in PAPER_FIG5_AMPLITUDES.items():
            if math.isclose(length, paper_length, rel_tol=1e-6):
                found[float(length)] = amplitude
    return found


# ---------------------------------------------------------------------------------- states

def state_styles(state: xr.DataArray) -> list[tuple[int, str, str, str | None]]:
    """(flag value, meaning, colour, map marker) for every flag the `state` variable declares."""
    values = np.atleast_1d(state.attrs.get("flag_values", []))
    meanings = str(state.attrs.get("flag_meanings", "")).split()
    styles = []
    spare = iter(_FALLBACK_COLOURS * (1 + len(meanings) // len(_FALLBACK_COLOURS)))
    for value, meaning in zip(values, meanings):
        colour, marker = STATE_STYLES.get(meaning, (next(spare), "*"))
        styles.append((int(value), meaning, colour, marker))
    return sorted(styles)   # by flag value: colour boundaries must increase (longitudinal: 0 5 7 8)


# ---------------------------------------------------------------------------------- helpers

def _wrap(text: str, width: int) -> str:
    return textwrap.fill(text, width, break_long_words=False)


def _plain_ticks(ax: Axes) -> None:
    """Tick labels that are the numbers themselves: no offset ("1e-12+2") and no scientific
    multiplier on any linear axis (log axes keep their own formatter)."""
    for axis in (ax.xaxis, ax.yaxis):
        formatter = axis.get_major_formatter()
        if isinstance(formatter, ScalarFormatter):
            formatter.set_useOffset(False)
            formatter.set_scientific(False)


def _padded_range(values: np.ndarray) -> tuple[float, float] | None:
    """For near-constant data (spread below 1e-6 of its size): its mean +- 5 %, so that the
    axis shows the value, not round-off; None otherwise."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return None
    mean, spread = float(v.mean()), float(v.max() - v.min())
    if spread > 1e-6 * abs(mean) or (mean == 0.0 and spread > 0.0):
        return None
    half = 0.05 * abs(mean) if mean else 1.0
    return mean - half, mean + half


def why_not_drawn(da: xr.DataArray) -> str | None:
    """Why a figure of `da` would say nothing: every value NaN, or every finite value the same
    (e.g. settling times all 0 s); None when it varies."""
    v = np.asarray(da.values, dtype=float)
    finite = v[np.isfinite(v)]
    if not finite.size:
        return "no point has a value (all NaN)"
    if finite.min() == finite.max():
        factor, units = _unit(da, finite)
        value = f"{finite[0] * factor:.4g}" + (f" {units}" if units and units != "1" else "")
        some = " with a value" if finite.size < v.size else ""
        return f"every point{some} has the same value, {value}"
    return None


def _time_dim(da: xr.DataArray) -> str | None:
    """The time dimension of a stored history, None when `da` has none."""
    return next((d for d in _TIME_DIMS if d in da.dims), None)


def _new_axes(figsize: tuple[float, float] = (6.4, 4.8)) -> Axes:
    return Figure(figsize=figsize, layout="constrained").add_subplot()


def _is_log_spaced(values: np.ndarray) -> bool:
    v = np.asarray(values, dtype=float)
    if v.size < 3 or np.any(v <= 0):
        return False
    d = np.diff(v)
    if np.allclose(d, d[0], rtol=1e-6):
        return False
    r = v[1:] / v[:-1]
    return bool(np.allclose(r, r[0], rtol=1e-6))


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres (geometric for a log-spaced axis)."""
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        return v[0] + (np.array([-0.05, 0.05]) * abs(v[0]) if v[0] else np.array([-0.5, 0.5]))
    log = _is_log_spaced(v)
    w = np.log(v) if log else v
    mid = 0.5 * (w[1:] + w[:-1])
    e = np.concatenate([[w[0] - (mid[0] - w[0])], mid, [w[-1] + (w[-1] - mid[-1])]])
    return np.exp(e) if log else e


def _wide_range(values: np.ndarray) -> bool:
    """Positive values over more than two decades: plot them on a log scale."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return bool(v.size and np.all(v > 0) and v.max() > 100 * v.min())


def _crossing(x: np.ndarray, y: np.ndarray, level: float) -> float | None:
    """The first x in the sampled range where y crosses `level` (log-log interpolation)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    for i in range(x.size - 1):
        a, b = y[i] - level, y[i + 1] - level
        if a == 0:
            return float(x[i])
        if a * b < 0:
            if min(x[i], x[i + 1], y[i], y[i + 1]) > 0:
                t = math.log(level / y[i]) / math.log(y[i + 1] / y[i])
                return float(x[i] * (x[i + 1] / x[i]) ** t)
            return float(x[i] + (x[i + 1] - x[i]) * (-a) / (b - a))
    return float(x[-1]) if y[-1] == level else None


def _depends_only_on(da: xr.DataArray, dims: Iterable[str]) -> bool:
    return set(da.dims) <= set(dims)


def _buckling_length(ds: xr.Dataset) -> float | None:
    """The span length where P0 = Pcr, when length is swept and P0/Pcr varies with it only."""
    if ds.attrs.get("model_kind") == "longitudinal" or "load_ratio" not in ds \
            or "length" not in ds.dims or ds["load_ratio"].dims != ("length",):
        return None
    return _crossing(ds["length"].values, ds["load_ratio"].values, 1.0)


def _legend(ax: Axes, handles: list, title: str | None = None) -> None:
    if handles:
        ax.legend(handles=handles, title=title, loc="upper center", bbox_to_anchor=(0.5, -0.14),
                  ncols=min(2, len(handles)), fontsize="small", title_fontsize="small",
                  frameon=False, handlelength=3.0)


# ---------------------------------------------------------------------------------- one axis

def plot_line(ds: xr.Dataset, var: str = "amplitude", *, select: Mapping[str, Any] | None = None,
              ax: Axes | None = None, add_legend: bool = True, **kwargs: Any) -> Axes:
    """`var` against the one swept axis, markers coloured by `state` (a thin grey line joins
    them). Points with no value (NaN, e.g. the settling time of a modulated point) are drawn
    hollow on the bottom edge in their state's colour. With length swept and P0/Pcr depending
    on it only, a dashed line marks the buckling length (P0 = Pcr) when it is in range.
    Displacements are in mm; near-constant data get a +-5 % range around their value (not a
    range of round-off); no axis uses an offset. On the paper's Fig 5 case the paper's own
    amplitudes are marked ("paper Fig 5"). Extra keyword arguments go to `Axes.scatter`.
    Returns the Axes."""
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    if len(axes) != 1:
        raise UserError(f"plot_line needs exactly one swept axis; this result has "
                        f"{len(axes)} ({', '.join(axes) or 'none'}): use plot_map, or "
                        "select values of the others")
    (dim,) = axes
    if var not in ds:
        raise UserError(f"plot_line: the result has no variable '{var}'")
    ax = ax if ax is not None else _new_axes()
    xfactor, xunits = _unit(ds[dim])
    x = ds[dim].values.astype(float) * xfactor
    y = ds[var].values.astype(float)
    state = ds["state"].values
    log_y = _wide_range(y)
    factor, units = _unit(ds[var], y)
    ax.plot(x, y * factor, color="0.7", lw=1.0, zorder=1)
    handles = []
    nan_any = False
    kwargs.setdefault("s", 36)
    for value, meaning, colour, _marker in state_styles(ds["state"]):
        mask = state == value
        if not mask.any():
            continue
        good = mask & np.isfinite(y)
        if good.any():
            ax.scatter(x[good], y[good] * factor, color=colour, zorder=3,
                       edgecolors="k", linewidths=0.4, **kwargs)
        bad = mask & ~np.isfinite(y)
        if bad.any():
            nan_any = True
            ax.scatter(x[bad], np.zeros(bad.sum()), marker="v", facecolors="none",
                       edgecolors=colour, linewidths=1.2, s=kwargs["s"], zorder=3, clip_on=False,
                       transform=ax.get_xaxis_transform())
        handles.append(Line2D([], [], ls="none", marker="o", color=colour, markeredgecolor="k",
                              markeredgewidth=0.4, label=f"{meaning} ({int(mask.sum())})"))
    # The NaN points are drawn in axes coordinates: keep them in the x range.
    ax.update_datalim(np.column_stack([x, np.full(x.shape, np.nanmin(y * factor)
                                                  if np.isfinite(y).any() else 0.0)]),
                      updatey=False)
    ax.autoscale_view()
    if nan_any:
        handles.append(Line2D([], [], ls="none", marker="v", markerfacecolor="none",
                              markeredgecolor="0.3", label="no value (NaN)"))
    if dim == "length":
        l_cr = _buckling_length(ds)
        if l_cr is not None:
            ax.axvline(l_cr, color="k", ls="--", lw=1.0, zorder=2)
            handles.append(Line2D([], [], color="k", ls="--", lw=1.0,
                                  label=f"P0 = Pcr, l = {l_cr:.3g} m"))
        paper = _paper_fig5(ds) if var == "amplitude" else {}
        if paper:
            ax.scatter(list(paper), np.array(list(paper.values())) * factor, marker="D",
                       s=kwargs["s"], facecolors="none", edgecolors="k", linewidths=1.2,
                       zorder=4)
            handles.append(Line2D([], [], ls="none", marker="D", markerfacecolor="none",
                                  markeredgecolor="k", label="paper Fig 5: " + ", ".join(
                                      f"{a * factor:g}" for a in paper.values()) + f" {units}"))
    if log_y:
        ax.set_yscale("log")
    else:
        padded = _padded_range(y * factor)
        if padded is not None:
            ax.set_ylim(*padded)
    if _is_log_spaced(x):
        ax.set_xscale("log")
    ax.set_xlabel(label(ds[dim], xunits))
    ax.set_ylabel(label(ds[var], units))
    ax.set_title(_title(ds), fontsize="medium")
    ax.grid(True, color="0.92", zorder=0)
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles, "state")
    return ax


# ---------------------------------------------------------------------------------- maps

def _map_axes(ds: xr.Dataset, x: str | None, y: str | None, who: str) -> tuple[str, str]:
    axes = swept_axes(ds)
    if len(axes) != 2:
        raise UserError(f"{who} needs exactly two swept axes; this result has {len(axes)} "
                        f"({', '.join(axes) or 'none'})" + (": use plot_line" if len(axes) == 1
                                                            else ""))
    if x is None and y is None:
        y, x = axes                      # xarray's convention: rows (first dim) on y
    elif x is None:
        x = next(d for d in axes if d != y)
    elif y is None:
        y = next(d for d in axes if d != x)
    if {x, y} != set(axes):
        raise UserError(f"{who}: x and y must be the swept axes {axes[0]} and {axes[1]}")
    return x, y


def _coord(ds: xr.Dataset, dim: str) -> np.ndarray:
    """An axis's values as drawn (displacement axes in mm)."""
    return ds[dim].values.astype(float) * _unit(ds[dim])[0]


def _mesh(ax: Axes, ds: xr.Dataset, x: str, y: str, values: np.ndarray, **kwargs: Any):
    xv, yv = _coord(ds, x), _coord(ds, y)
    mesh = ax.pcolormesh(_edges(xv), _edges(yv), values, shading="flat", **kwargs)
    if _is_log_spaced(xv):
        ax.set_xscale("log")
    if _is_log_spaced(yv):
        ax.set_yscale("log")
    ax.set_xlabel(label(ds[x], _unit(ds[x])[1]))
    ax.set_ylabel(label(ds[y], _unit(ds[y])[1]))
    return mesh


def _state_label(meaning: str, count: int) -> str:
    return f"{meaning} ({count})"


def _mark_states(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """Mark the cells whose state is not a good one; returns the legend handles. A small grid
    (at most 100 cells) gets a marker per cell; a denser one gets each state's region hatched
    and outlined in the state's colour along the cell edges, so the colour under it shows."""
    state = ds["state"].transpose(y, x).values
    styles = [s for s in state_styles(ds["state"]) if s[3] is not None and (state == s[0]).any()]
    if state.size > _MARKER_CELLS:
        return [_hatch_region(ax, ds, x, y, state == value, meaning, colour)
                for value, meaning, colour, _marker in styles]
    xx, yy = np.meshgrid(_coord(ds, x), _coord(ds, y))
    # Markers fit in their cells: at most 60 % of the smaller cell side (and 30 pt^2).
    box = ax.get_window_extent()
    cell = min(box.width / state.shape[1], box.height / state.shape[0]) * 72.0 / ax.figure.dpi
    size = float(np.clip((0.6 * cell) ** 2, 2.0, 30.0))
    edge = 0.6 if size >= 12.0 else 0.3
    handles = []
    for value, meaning, colour, marker in styles:
        mask = state == value
        ax.scatter(xx[mask], yy[mask], marker=marker, s=size, color=colour, edgecolors="k",
                   linewidths=edge, zorder=4)
        handles.append(Line2D([], [], ls="none", marker=marker, color=colour,
                              markeredgecolor="k", markeredgewidth=0.6,
                              label=_state_label(meaning, int(mask.sum()))))
    return handles


def _hatch_region(ax: Axes, ds: xr.Dataset, x: str, y: str, mask: np.ndarray, meaning: str,
                  colour: str) -> Patch:
    """Hatch and outline the cells of `mask` (rows: y); its legend handle."""
    def doubled(edges: np.ndarray) -> np.ndarray:
        # Two samples per cell just inside its edges: contouring the 0/1 mask at 0.5 then
        # crosses exactly on the cell edges (also on a log-spaced axis).
        inset = 1e-3 * np.diff(edges)
        return np.column_stack([edges[:-1] + inset, edges[1:] - inset]).ravel()

    xs, ys = doubled(_edges(_coord(ds, x))), doubled(_edges(_coord(ds, y)))
    fine = np.repeat(np.repeat(mask.astype(float), 2, axis=0), 2, axis=1)
    hatch = _HATCHES.get(meaning, "ooo")
    filled = ax.contourf(xs, ys, fine, levels=[0.5, 1.5], colors="none", hatches=[hatch],
                         zorder=4)
    filled.set_hatchcolor(colour)
    filled.set_edgecolor("none")
    ax.contour(xs, ys, fine, levels=[0.5], colors=[colour], linewidths=1.1, zorder=4,
               path_effects=[patheffects.Stroke(linewidth=2.3, foreground="k"),
                             patheffects.Normal()])
    return Patch(facecolor="none", edgecolor=colour, hatch=hatch, linewidth=1.1,
                 label=_state_label(meaning, int(mask.sum())))


def _damping(ds: xr.Dataset) -> Any:
    if "damping_ratio" in ds.coords:
        return ds["damping_ratio"]
    try:
        return float(_scene(ds)["cable"]["damping_ratio"])
    except (KeyError, TypeError, ValueError):
        return None


def _overlays(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """Closed-form curves the map's axes allow (docs/model.md sec. 2); their legend handles."""
    handles: list = []
    if ds.attrs.get("model_kind") == "longitudinal":
        return handles
    if "absolute_acceleration_g" in ds or "base_frequency" in (x, y) \
            or "base_frequency_ratio" in (x, y):
        handles += _base_overlay(ax, ds, x, y)

    def draw(along: str, pos: np.ndarray, val: np.ndarray, **style: Any) -> None:
        # `pos` runs along the `along` axis; `val` is the other map coordinate.
        px, py = (pos, val) if along == x else (val, pos)
        ax.plot(px, py, **style)

    l_cr = _buckling_length(ds) if "length" in (x, y) else None
    if l_cr is not None:
        (ax.axvline if x == "length" else ax.axhline)(l_cr, color="w", ls=(0, (4, 2)), lw=1.4,
                                                      zorder=3, path_effects=_OUTLINE)
        handles.append(Line2D([], [], color="w", ls=(0, (4, 2)), lw=1.4, path_effects=_OUTLINE,
                              label=f"P0 = Pcr: l = {l_cr:.3g} m"))
    freq = next((f for f in ("frequency_ratio", "frequency") if f in (x, y)), None)
    is_harmonic = _scene(ds).get("load", {}).get("type", "harmonic") == "harmonic"
    if freq is None or ds.attrs.get("coefficients") != "consistent" or not is_harmonic \
            or "load_ratio" not in ds:
        return handles
    other = y if freq == x else x
    ratio = ds["load_ratio"]
    base = xr.DataArray(1.0) if freq == "frequency_ratio" else ds.get("natural_frequency")
    zeta = _damping(ds)
    parts = [ratio, base] + ([zeta] if isinstance(zeta, xr.DataArray) else [])
    if base is None or not all(_depends_only_on(p, [other]) for p in parts):
        return handles
    pos = _coord(ds, other)
    dense = np.geomspace(pos[0], pos[-1], 200) if pos[0] > 0 else np.linspace(pos[0], pos[-1], 200)

    def along(da: Any) -> np.ndarray:
        vals = np.broadcast_to(np.asarray(da.values if isinstance(da, xr.DataArray) else da,
                                          float), pos.shape)
        if np.all(vals > 0) and pos[0] > 0:
            return np.exp(np.interp(np.log(dense), np.log(pos), np.log(vals)))
        return np.interp(dense, pos, vals)

    mu = 0.5 * along(ratio)
    w1 = along(base)
    active = mu >= 2.0 * along(zeta) if zeta is not None else np.ones(dense.shape, bool)
    unit = "W/w1" if freq == "frequency_ratio" else "f"
    for sign in (1.0, -1.0):
        with np.errstate(invalid="ignore"):
            curve = 2.0 * w1 * np.sqrt(1.0 + sign * mu)
        on = np.where(active, curve, np.nan)
        off = np.where(active, np.nan, curve)
        # Join the solid and dotted parts where they meet.
        edge = np.flatnonzero(np.diff(active.astype(int)) != 0)
        off[edge] = curve[edge]
        off[edge + 1] = curve[edge + 1]
        draw(other, dense, on, color="w", lw=1.4, zorder=3, path_effects=_OUTLINE)
        draw(other, dense, off, color="w", lw=1.4, ls=":", zorder=3, path_effects=_OUTLINE)
    handles.append(Line2D([], [], color="w", lw=1.4, path_effects=_OUTLINE,
                          label=f"{unit} = 2 {'' if unit == 'W/w1' else 'f1 '}"
                                "sqrt(1 \u00b1 mu), mu = P0/2Pcr"))
    if not active.all():
        handles.append(Line2D([], [], color="w", lw=1.4, ls=":", path_effects=_OUTLINE,
                              label="damped out: mu < 2 zeta"))
    return handles


def plot_map(ds: xr.Dataset, var: str = "amplitude", *, x: str | None = None,
             y: str | None = None, select: Mapping[str, Any] | None = None,
             ax: Axes | None = None, add_colorbar: bool = True, add_legend: bool = True,
             mark_states: bool = True, overlays: bool = True, **kwargs: Any) -> Axes:
    """A pcolormesh map of `var` over the two swept axes (x: the second, y: the first, as
    xarray draws a 2-D DataArray; or name them). A variable spanning more than two decades gets
    a log colour scale; cells with no value (NaN) are grey. Displacements are in mm; on a log
    scale, a displacement below FLOOR (1e-3) times the map's largest is drawn white as "no
    response" and the colours span only the three decades above it (other variables: at most
    six decades, the rest in the lowest colour). Points in a state that is not a good one
    (modulated, unsettled, diverged, failures) are marked: a marker per cell on small grids,
    hatched and outlined regions on dense ones (`_MARKER_CELLS`). The closed-form curves the
    axes allow are drawn in white (see the module docstring). Extra keyword arguments go to
    `Axes.pcolormesh` (cmap, norm, vmin, vmax, ...). Returns the Axes.
    """
    ds = select_points(ds, select)
    x, y = _map_axes(ds, x, y, "plot_map")
    if var not in ds:
        raise UserError(f"plot_map: the result has no variable '{var}'")
    ax = ax if ax is not None else _new_axes((7.0, 6.0))
    da = ds[var].transpose(y, x) if ds[var].ndim == 2 else ds[var].broadcast_like(
        ds["state"]).transpose(y, x)
    factor, units = _unit(ds[var], da.values)
    values = np.ma.masked_invalid(da.values.astype(float) * factor)
    extend = "neither"
    handles = []
    cmap = kwargs.pop("cmap", "viridis")
    user_scale = "norm" in kwargs or "vmin" in kwargs or "vmax" in kwargs
    if not user_scale and _wide_range(values.compressed()):
        top, low = float(values.max()), float(values.min())
        if _is_displacement(ds[var]):
            floor = FLOOR * top
            cmap = mpl_colormaps[cmap] if isinstance(cmap, str) else cmap
            cmap = cmap.with_extremes(under=_NO_RESPONSE_COLOUR)
            below = int((values.compressed() < floor).sum())
            if below:
                handles.append(Patch(facecolor=_NO_RESPONSE_COLOUR, edgecolor="0.5",
                                     label=f"no response, < {floor:.2g} {units} ({below})"))
        else:
            floor = top * 10.0 ** -_DECADES
        extend = "min" if low < floor else "neither"
        kwargs["norm"] = mcolors.LogNorm(vmin=max(low, floor), vmax=top, clip=False)
    elif not user_scale:
        padded = _padded_range(values.compressed())
        if padded is not None:
            kwargs["vmin"], kwargs["vmax"] = padded
    mesh = _mesh(ax, ds, x, y, values, cmap=cmap, **kwargs)
    ax.set_facecolor(_NAN_COLOUR)
    if values.mask.any():
        handles.append(Patch(facecolor=_NAN_COLOUR, edgecolor="0.5", label="no value (NaN)"))
    if mark_states:
        handles += _mark_states(ax, ds, x, y)
    if overlays:
        lims = ax.get_xlim(), ax.get_ylim()
        handles += _overlays(ax, ds, x, y)
        ax.set_xlim(*lims[0])
        ax.set_ylim(*lims[1])
    if add_colorbar:
        bar = ax.figure.colorbar(mesh, ax=ax, label=label(ds[var], units), extend=extend)
        _plain_ticks(bar.ax)
    ax.set_title(_title(ds, str(var)), fontsize="medium")
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles)
    return ax


def plot_state_map(ds: xr.Dataset, *, x: str | None = None, y: str | None = None,
                   select: Mapping[str, Any] | None = None, ax: Axes | None = None,
                   add_legend: bool = True, overlays: bool = True, **kwargs: Any) -> Axes:
    """A map of `state` over the two swept axes, one fixed colour per flag meaning, with the
    closed-form overlays of `plot_map`. Returns the Axes."""
    ds = select_points(ds, select)
    x, y = _map_axes(ds, x, y, "plot_state_map")
    ax = ax if ax is not None else _new_axes((7.0, 6.0))
    styles = state_styles(ds["state"])
    values = [s[0] for s in styles]
    cmap = mcolors.ListedColormap([s[2] for s in styles])
    bounds = np.concatenate([[values[0] - 0.5], np.asarray(values[:-1]) + 0.5,
                             [values[-1] + 0.5]]) if values else np.array([-0.5, 0.5])
    norm = mcolors.BoundaryNorm(bounds, cmap.N) if values else None
    state = ds["state"].transpose(y, x).values
    _mesh(ax, ds, x, y, state, cmap=cmap, norm=norm, edgecolors="face", **kwargs)
    handles: list = [Patch(facecolor=colour, label=f"{meaning} ({int((state == v).sum())})")
                     for v, meaning, colour, _m in styles if (state == v).any()]
    if overlays:
        lims = ax.get_xlim(), ax.get_ylim()
        handles += _overlays(ax, ds, x, y)
        ax.set_xlim(*lims[0])
        ax.set_ylim(*lims[1])
    ax.set_title(_title(ds, "state"), fontsize="medium")
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles)
    return ax


# ---------------------------------------------------------------------------------- series

def _points(ds: xr.Dataset, max_points: int) -> tuple[list[dict[str, int]], int]:
    """Index dicts of up to max_points points, evenly spread over the swept grid; the total."""
    axes = swept_axes(ds)
    shape = [ds.sizes[d] for d in axes]
    total = int(np.prod(shape, dtype=np.int64))
    flat = np.unique(np.linspace(0, total - 1, min(total, max_points)).round().astype(int))
    return [dict(zip(axes, map(int, np.unravel_index(i, shape)))) for i in flat], total


def _state_meaning(ds: xr.Dataset) -> str:
    value = int(ds["state"].values)
    for v, meaning, _c, _m in state_styles(ds["state"]):
        if v == value:
            return meaning
    return str(value)


def _state_colour(ds: xr.Dataset) -> str:
    value = int(ds["state"].values)
    return next((c for v, _m, c, _k in state_styles(ds["state"]) if v == value), "k")


def plot_time_series(ds: xr.Dataset, var: str = "displacement", *,
                     select: Mapping[str, Any] | None = None, max_panels: int = 8,
                     fig: Figure | None = None, **kwargs: Any) -> Figure:
    """The stored response against time, one panel per point (the paper's Fig 5 style), lines
    in the colour of the point's state; at most `max_panels` points, spread evenly over the
    grid. Panels share the y scale when their peaks are within a factor 10. Displacements are
    in mm. On the paper's Fig 5 case, dashed lines mark the paper's amplitude +-A of each
    span. Extra keyword arguments go to `Axes.plot`. Returns the Figure."""
    ds = select_points(ds, select)
    if var not in ds or _time_dim(ds[var]) is None:
        raise UserError(f"plot_time_series: the result stores no '{var}' time series (set "
                        "outputs.time_series = true in the scene)")
    points, total = _points(ds, max_panels)
    n = len(points)
    data = ds[var]
    peaks = [float(np.nanmax(np.abs(data.isel(p).values), initial=0.0)) for p in points]
    share = bool(min(peaks) > 0 and max(peaks) < 10 * min(peaks))
    factor, units = _unit(data, np.array(peaks))
    paper = _paper_fig5(ds) if var == "displacement" else {}
    time = ds[_time_dim(ds[var])]
    tfactor, tunits = _scaled(time.values, time.attrs.get("units"))
    fig = fig if fig is not None else Figure(figsize=(7.0, 1.0 + 1.45 * n), layout="constrained")
    axs = fig.subplots(n, 1, sharex=True, sharey=share, squeeze=False)[:, 0]
    kwargs.setdefault("lw", 0.8)
    for ax, p in zip(axs, points):
        point = ds.isel(p)
        ax.plot(time.values * tfactor, point[var].values * factor,
                color=_state_colour(point), **kwargs)
        text = _point_text(point, swept_axes(ds)) or "the point"
        ax.set_title(f"{text}: {_state_meaning(point)}", fontsize="small", loc="left")
        ax.grid(True, color="0.92")
        length = float(point["length"].values) if "length" in point.coords else None
        if length in paper:
            amplitude = paper[length] * factor
            for sign in (1.0, -1.0):
                ax.axhline(sign * amplitude, color="k", ls="--", lw=0.9,
                           label=f"paper Fig 5: \u00b1{amplitude:g} {units}" if sign > 0
                           else None)
            ax.legend(loc="upper right", fontsize="x-small", framealpha=0.9)
        _plain_ticks(ax)
    axs[-1].set_xlabel(label(time, tunits))
    fig.supylabel(label(data, units), fontsize="medium")
    shown = "" if n == total else f" ({n} of {total} points)"
    fig.suptitle(_title(ds, "response against time") + shown, fontsize="medium")
    return fig


def _snapshot_fields(ds: xr.Dataset) -> list[str]:
    fields = []
    for base in ("snapshot_displacement", "snapshot_force", "snapshot_velocity"):
        for name in ((base + "_ratio", base) if base != "snapshot_displacement" else (base,)):
            if name in ds:
                fields.append(name)
                break
    return fields


def plot_snapshots(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                   max_times: int = 8, max_lines: int = 10, fig: Figure | None = None,
                   **kwargs: Any) -> Figure:
    """Longitudinal snapshots along the span (the paper's Fig 7 style): one row per snapshot
    time (at most `max_times`, spread evenly), one column per field: displacement u(x), force
    (N/P0 when stored normalised, else N) and velocity (v rho A a/P0, else m/s) against x/l;
    one line per point (at most `max_lines`). Extra keyword arguments go to `Axes.plot`.
    Returns the Figure."""
    ds = select_points(ds, select)
    fields = _snapshot_fields(ds)
    if not fields:
        raise UserError("plot_snapshots: the result stores no snapshots (set "
                        "outputs.snapshot_times in a longitudinal scene)")
    points, total = _points(ds, max_lines)
    n_times = ds.sizes["snapshot_time"]
    rows = np.unique(np.linspace(0, n_times - 1, min(n_times, max_times)).round().astype(int))
    fig = fig if fig is not None else Figure(figsize=(3.3 * len(fields) + 0.8,
                                                      1.1 + 1.75 * rows.size),
                                             layout="constrained")
    axs = fig.subplots(rows.size, len(fields), sharex=True, sharey="col", squeeze=False)
    x = ds["position"].values
    kwargs.setdefault("lw", 1.4)
    for j, name in enumerate(fields):
        factor, units = _unit(ds[name])
        axs[0, j].set_title(_wrap(label(ds[name], units), 34), fontsize="small")
        axs[-1, j].set_xlabel(_wrap(label(ds["position"]), 34))
        for i, k in enumerate(rows):
            ax = axs[i, j]
            for n, p in enumerate(points):
                point = ds.isel(p)
                ax.plot(x, point[name].isel(snapshot_time=k).values * factor,
                        color=f"C{n % 10}", label=_point_text(point, swept_axes(ds)) or None,
                        **kwargs)
            ax.axhline(0.0, color="0.6", lw=0.6, zorder=0)
            ax.grid(True, color="0.92")
            _plain_ticks(ax)
    for i, k in enumerate(rows):
        t = float(ds["snapshot_time"].values[k])
        text = f"t = {_fmt(t, 's')}"
        if "transit_time" in ds and ds["transit_time"].ndim == 0:
            text += f"\n= {t / float(ds['transit_time'].values):.3g} l/a"
        axs[i, 0].set_ylabel(text, fontsize="small")
    if len(points) > 1:
        axs[0, -1].legend(fontsize="x-small", loc="best")
    shown = "" if len(points) == total else f" ({len(points)} of {total} points)"
    fig.suptitle(_title(ds, "snapshots along the span") + shown, fontsize="medium")
    return fig


def plot_histories(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                   max_lines: int = 10, fig: Figure | None = None, **kwargs: Any) -> Figure:
    """Longitudinal end histories: the loaded end's displacement u(l, t) and the fixed end's
    force N(0, t) against time, one line per point (at most `max_lines`); for a single point
    the closed-form peaks 2 P0 l/EA and 2 P0 are drawn dashed. Returns the Figure."""
    ds = select_points(ds, select)
    names = [n for n in ("end_displacement", "fixed_end_force") if n in ds]
    if not names:
        raise UserError("plot_histories: the result stores no end histories (set "
                        "outputs.histories = true in a longitudinal scene)")
    points, total = _points(ds, max_lines)
    fig = fig if fig is not None else Figure(figsize=(7.0, 1.2 + 2.6 * len(names)),
                                             layout="constrained")
    axs = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    time = ds[_time_dim(ds[names[0]])]
    tfactor, tunits = _scaled(time.values, time.attrs.get("units"))
    kwargs.setdefault("lw", 1.2)
    for ax, name in zip(axs, names):
        factor, units = _unit(ds[name])
        for p in points:
            point = ds.isel(p)
            text = _point_text(point, swept_axes(ds))
            line, = ax.plot(time.values * tfactor, point[name].values * factor,
                            label=text or None, **kwargs)
            if len(points) == 1:
                exact = _exact_peak(point, name)
                if exact is not None:
                    formula = "2 P0 l/EA" if name == "end_displacement" else "2 P0"
                    ax.axhline(exact * factor, color="0.3", ls="--", lw=0.9,
                               label=f"exact peak {formula} = "
                                     f"{_fmt(abs(exact), ds[name].attrs.get('units'))}")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_ylabel(_wrap(label(ds[name], units), 26))
        ax.grid(True, color="0.92")
        _plain_ticks(ax)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small", loc="best")
    axs[-1].set_xlabel(label(time, tunits))
    shown = "" if len(points) == total else f" ({len(points)} of {total} points)"
    fig.suptitle(_title(ds, "end histories") + shown, fontsize="medium")
    return fig


def _exact_peak(point: xr.Dataset, name: str) -> float | None:
    """d'Alembert's peak of a history, signed as the history runs (docs/model.md sec. 4)."""
    values = point[name].values
    finite = values[np.isfinite(values)]
    if not finite.size:
        return None
    sign = 1.0 if finite[np.argmax(np.abs(finite))] >= 0 else -1.0
    if name == "end_displacement" and "static_end_displacement" in point:
        return sign * 2.0 * abs(float(point["static_end_displacement"].values))
    if name == "fixed_end_force" and "peak_fixed_end_force" in point \
            and "force_amplification" in point:
        load = float(point["peak_fixed_end_force"].values) / float(
            point["force_amplification"].values)
        return sign * 2.0 * abs(load) if math.isfinite(load) else None
    return None


# ---------------------------------------------------------------------------------- choose

class Figures(dict):
    """The figures `plot` drew, by name (a dict), with the selection they were drawn for
    (`select`, written into the file names by `save`) and the figures left out with the
    reason (`skipped`: name -> why)."""

    def __init__(self, figures: Mapping[str, Figure] | None = None, *,
                 select: Mapping[str, Any] | None = None,
                 skipped: Mapping[str, str] | None = None) -> None:
        super().__init__(figures or {})
        self.select = dict(select or {})
        self.skipped = dict(skipped or {})


def plot(ds: xr.Dataset, select: Mapping[str, Any] | None = None) -> Figures:
    """Every figure that fits the result, keyed by name (the file name `save` gives it).

    Transverse: 'amplitude' and 'settling_time' (lines over one swept axis, maps over two),
    and 'absolute_acceleration_g' under base excitation,
    'state' (map, two axes), 'time_series' (when stored). Longitudinal: 'snapshots',
    'histories' (when stored), and 'peak_end_displacement', 'dynamic_amplification' over the
    swept axes. A quantity that says nothing (all NaN, or one value at every point, e.g. the
    settling times of an undamped run, all 0 s; a state map with one state) gets no figure:
    the reason goes to `Figures.skipped` and the log (info here; `save` repeats it as a
    warning, which reaches stderr by default).
    Each figure has the load case in a footer (`footer`). An empty result when nothing fits.
    Raises UserError (one line) for a Dataset the figures cannot be drawn from faithfully
    (`check_result`), before drawing anything.
    """
    check_result(ds)
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    figures = Figures(select=select)
    if ds.attrs.get("model_kind") == "longitudinal":
        scalars = ["peak_end_displacement", "dynamic_amplification"]
    else:
        scalars = ["amplitude", "settling_time"]
        if "absolute_acceleration_g" in ds:        # base excitation (docs/model.md sec. 5)
            scalars.insert(1, "absolute_acceleration_g")
    if len(axes) == 2:
        scalars.append("state")
    for var in scalars:
        if var not in ds or len(axes) not in (1, 2):
            continue
        if var == "state":
            reason = (f"every point is {_state_meaning(ds.isel({a: 0 for a in axes}))}"
                      if np.unique(ds["state"].values).size == 1 else None)
        else:
            reason = why_not_drawn(ds[var])
        if reason is not None:
            figures.skipped[var] = reason
            _log.info("%s: %s: no figure (%s)", ds.attrs.get("title", "result"), var, reason)
        elif var == "state":
            figures[var] = plot_state_map(ds).figure
        elif len(axes) == 1:
            figures[var] = plot_line(ds, var).figure
        else:
            figures[var] = plot_map(ds, var).figure
    if "displacement" in ds and _time_dim(ds["displacement"]) is not None:
        figures["time_series"] = plot_time_series(ds)
    if _snapshot_fields(ds):
        figures["snapshots"] = plot_snapshots(ds)
    if "end_displacement" in ds or "fixed_end_force" in ds:
        figures["histories"] = plot_histories(ds)
    for fig in figures.values():
        for ax in fig.axes:
            _plain_ticks(ax)
        _add_footer(fig, ds)
    return figures


def _select_tag(select: Mapping[str, Any]) -> str:
    """'load_amplitude=4-length=0.5' for a selection, file-system safe (letters, digits and
    . _ = + - only)."""
    parts = []
    for dim, value in select.items():
        try:
            shown = f"{float(value):g}"
        except (TypeError, ValueError):
            shown = str(value)
        parts.append(re.sub(r"[^A-Za-z0-9._=+-]", "_", f"{dim}={shown}"))
    return "-".join(parts)


def save(figures: Mapping[str, Figure], directory: str | os.PathLike = ".",
         formats: Iterable[str] = ("png",), *, prefix: str = "", dpi: float = 100,
         select: Mapping[str, Any] | None = None) -> list[Path]:
    """Write each figure as DIRECTORY/PREFIX + key + .FORMAT (the directory is created);
    with a selection (`select`, else the one `plot` recorded on its `Figures`) the name is
    PREFIX + 'DIM=VALUE-' ... + key, so that figures of different selections do not overwrite
    each other (e.g. map-load_amplitude=4-amplitude.png). `dpi`: dots per inch of raster
    formats. The figures `plot` left out (`Figures.skipped`) are logged as warnings, one line
    each. Returns the paths written. Raises UserError for an unknown format or an
    unwritable directory."""
    select = getattr(figures, "select", None) if select is None else select
    tag = _select_tag(select) + "-" if select else ""
    formats = [f.strip().lower().lstrip(".") for f in formats if f.strip()]
    supported = Figure().canvas.get_supported_filetypes()
    for fmt in formats:
        if fmt not in supported:
            raise UserError(f"format '{fmt}': not a figure format matplotlib writes (use one of "
                            f"{', '.join(sorted(supported))})")
    out = Path(directory)
    # Every figure is drawn (in memory) before any file is written: a figure that fails to
    # draw leaves nothing behind.
    rendered = []
    for key, fig in figures.items():
        for fmt in formats:
            buffer = io.BytesIO()
            fig.savefig(buffer, format=fmt, dpi=dpi)
            rendered.append((out / f"{prefix}{tag}{key}.{fmt}", buffer.getvalue()))
    for key, reason in getattr(figures, "skipped", {}).items():
        _log.warning("%s%s%s: no figure (%s)", prefix, tag, key, reason)
    created = _make_directory(out)
    try:
        return _write_all(rendered)
    except BaseException:
        for path in reversed(created):
            with contextlib.suppress(OSError):
                path.rmdir()
        raise


def _make_directory(out: Path) -> list[Path]:
    """Create `out` and its missing parents; the directories created, outermost first."""
    missing = [p for p in (out, *out.parents) if not p.exists()][::-1]
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"output directory '{out}': could not be created "
                        f"({exc.strerror or exc})") from exc
    return missing


def _write_all(rendered: list[tuple[Path, bytes]]) -> list[Path]:
    """Write each (path, bytes) atomically: all to fresh temporary files in the target
    directory first (O_EXCL, unpredictable names, fsynced), then renamed over the targets.
    On any failure, removes every temporary and every file this call already renamed into
    place, and raises UserError naming the file (OSError) or re-raises."""
    mask = os.umask(0o022)
    os.umask(mask)
    temps: list[str] = []
    done: list[Path] = []
    path = None
    try:
        for path, data in rendered:
            temps.append(write_temporary(path.parent, f".{path.name}.", data, 0o666 & ~mask))
        for (path, _data), tmp in zip(rendered, temps):
            os.replace(tmp, path)
            done.append(path)
    except BaseException as exc:
        for name in temps:
            with contextlib.suppress(OSError):
                os.unlink(name)
        for written in done:
            with contextlib.suppress(OSError):
                written.unlink()
        if isinstance(exc, OSError):
            raise UserError(f"figure '{path}': could not be written ({exc.strerror or exc}); "
                            "no figure of this call was kept") from exc
        raise
    return done
