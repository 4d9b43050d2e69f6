"""What every figure shares (xarray's plot/utils.py): the colour and marker of each state, the
units a quantity is shown in, plain tick labels, ranges and log scales, cell edges, legends.

Units: displacements (units m, not the span length) are in mm everywhere; times and forces get
the prefix their largest value calls for; a level in g reads as g; anything else as stored.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter, ScalarFormatter

from ..schema import G_UNITS

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
# The dark edge that keeps a white overlay line visible on any colour.
_OUTLINE = [patheffects.Stroke(linewidth=3.0, foreground="k"), patheffects.Normal()]


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



def _state_meaning(ds: xr.Dataset) -> str:
    value = int(ds["state"].values)
    for v, meaning, _c, _m in state_styles(ds["state"]):
        if v == value:
            return meaning
    return str(value)


def _state_colour(ds: xr.Dataset) -> str:
    value = int(ds["state"].values)
    return next((c for v, _m, c, _k in state_styles(ds["state"]) if v == value), "k")


# ---------------------------------------------------------------------------------- units

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
    """The factor and units a variable is shown in: displacements in mm, span lengths in m,
    times and forces with the prefix their largest value calls for (`_scaled`), anything else
    as stored."""
    if _is_displacement(da):
        return 1e3, "mm"
    if da.name == "length":                       # span lengths: in metres, as the closed-form
        return 1.0, "m"                           # overlays (buckling length, ...) are placed
    if da.attrs.get("units") == G_UNITS:          # a level in g: "9.80665 m s-2" reads as g
        return 1.0, "g"
    return _scaled(da.values if values is None else values, da.attrs.get("units"))


def _fmt(value: float, units: str | None) -> str:
    factor, scaled = (1e3, "mm") if units == "m" else _scaled(np.array([value]), units)
    text = f"{value * factor:.4g}"
    return f"{text} {scaled}" if scaled and scaled != "1" else text


def _coord(ds: xr.Dataset, dim: str) -> np.ndarray:
    """An axis's values as drawn (displacement axes in mm)."""
    return ds[dim].values.astype(float) * _unit(ds[dim])[0]


# ---------------------------------------------------------------------------------- axes

def _plain_ticks(ax: Axes) -> None:
    """Tick labels that are the numbers themselves: no offset ("1e-12+2") and no scientific
    multiplier on any linear axis, and on a log axis (a colour bar's too) 10, 20, 50, 100 as
    engineers read them, not 10^1, 10^2 (`_log_ticks`)."""
    for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
        if axis.get_scale() == "log":
            _log_ticks(ax, which)
            continue
        formatter = axis.get_major_formatter()
        if isinstance(formatter, ScalarFormatter):
            formatter.set_useOffset(False)
            formatter.set_scientific(False)


def _log_ticks(ax: Axes, which: str) -> None:
    """Plain numbers on a log axis ('20', '50', not '2 x 10^1'); over less than about two
    decades the 2 and 5 of each decade are labelled too (within one decade also the 3, within
    0.7 decades every digit)."""
    axis = ax.xaxis if which == "x" else ax.yaxis
    low, high = (ax.get_xlim() if which == "x" else ax.get_ylim())
    if not (low > 0 and high > low):
        return
    decades = math.log10(high / low)
    plain = FuncFormatter(lambda v, _pos: f"{v:g}")
    axis.set_major_locator(LogLocator(base=10.0))
    axis.set_major_formatter(plain)
    subs = (tuple(np.arange(2.0, 10.0)) if decades < 0.7 else (2.0, 3.0, 5.0) if decades < 1.2
            else (2.0, 5.0) if decades < 2.2 else ())
    axis.set_minor_locator(LogLocator(base=10.0, subs=tuple(np.arange(2.0, 10.0))))
    if subs:
        def minor(v: float, _pos: Any) -> str:
            mantissa = v / 10.0 ** math.floor(math.log10(v) + 1e-9)
            return f"{v:g}" if any(math.isclose(mantissa, s, rel_tol=1e-6) for s in subs) else ""
        axis.set_minor_formatter(FuncFormatter(minor))
    else:
        axis.set_minor_formatter(NullFormatter())


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

def _new_axes(figsize: tuple[float, float] = (6.4, 4.8)) -> Axes:
    return Figure(figsize=figsize, layout="constrained").add_subplot()


def _is_log_spaced(values: np.ndarray) -> bool:
    """Whether a coordinate is drawn on a log axis: three or more positive values in a
    geometric (not an arithmetic) progression or, not arithmetic, spanning two decades or more
    (k_t = 0.5, 7.88, 100 N m/rad: a linear axis left the first two cells slivers), or two
    positive values a decade or more apart (a linear axis put their cells' edges below zero:
    k_t = 0.01 and 100 N m/rad)."""
    v = np.asarray(values, dtype=float)
    if v.size == 2 and np.all(v > 0):
        return bool(max(v) >= 10.0 * min(v))
    if v.size < 3 or np.any(v <= 0):
        return False
    d = np.diff(v)
    if np.allclose(d, d[0], rtol=1e-6):
        return False
    if max(v) >= 100.0 * min(v):
        return True
    r = v[1:] / v[:-1]
    return bool(np.allclose(r, r[0], rtol=1e-6))


def symlog_threshold(values: np.ndarray) -> float | None:
    """The smallest positive value of a coordinate that is one 0 and positive values drawn on
    a log axis (`_is_log_spaced`: clamp_axial_stiffness = 0 (sliding), 1e4, 1e6 N/m, whose two
    first cells were slivers on a linear axis), else None. Such an axis is drawn symlog, linear
    below that value (`symlog_scale`)."""
    v = np.sort(np.asarray(values, dtype=float))
    if v.size < 3 or v[0] != 0.0 or not _is_log_spaced(v[1:]):
        return None
    return float(v[1])


SYMLOG_LINSCALE = 0.9
"""matplotlib's symlog `linscale` (base 10) that makes its linear part x / linthresh, so the
linear stretch 0..linthresh is as long as one decade above it, as `_edges` assumes."""


def symlog_scale(ax: Axes, which: str, values: np.ndarray, threshold: float) -> None:
    """Draw axis `which` ("x", "y") symlog, linear below `threshold`, ticked at the values."""
    (ax.set_xscale if which == "x" else ax.set_yscale)(
        "symlog", linthresh=threshold, linscale=SYMLOG_LINSCALE)
    (ax.set_xticks if which == "x" else ax.set_yticks)(
        values, [f"{v:g}" for v in np.asarray(values, float)])


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres (geometric for a log-spaced axis; for a symlog one,
    `symlog_threshold`, midway in x / t below the threshold t and 1 + log10(x / t) above)."""
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        return v[0] + (np.array([-0.05, 0.05]) * abs(v[0]) if v[0] else np.array([-0.5, 0.5]))
    t = symlog_threshold(v)
    if t is not None:
        e = _edges(np.where(v <= t, v / t, 1.0 + np.log10(np.maximum(v, t) / t)))
        return np.where(e <= 1.0, e * t, t * 10.0 ** (e - 1.0))
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

LONG_LEGEND_LABEL = 44
"""Characters of a legend label beyond which the legend takes one column: two columns of
such labels are wider than the figure and would be cut off at its edges."""


def _legend(ax: Axes, handles: list, title: str | None = None) -> None:
    if handles:
        longest = max(len(str(h.get_label())) for h in handles)
        columns = 1 if longest > LONG_LEGEND_LABEL else min(2, len(handles))
        ax.legend(handles=handles, title=title, loc="upper center", bbox_to_anchor=(0.5, -0.14),
                  ncols=columns, fontsize="small", title_fontsize="small",
                  frameon=False, handlelength=3.0)
