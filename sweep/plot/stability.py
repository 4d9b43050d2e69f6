"""Floquet stability of the straight span (outputs.stability): the Ince-Strutt chart over two
swept axes (`plot_stability_chart`), the growth rate over one (`plot_growth_rate`), and the
Floquet boundary over the time-domain map of a result that has both (`plot_stability_over_map`).

The chart colours the unstable points (`stability` flags 1-3, growth rate > 0) by the growth
rate in 1/s, draws the stable ones light grey and marks the invalid ones; on a W/w1 axis it
names the tongues m = 1, 2, 3, ... at W/w1 = 2/m (the principal one, m = 1, near W = 2 w1), and
over W/w1 x P0/Pcr it overlays the first-order Mathieu boundaries of the undamped principal and
second zones (overlays.py, figure "stability"). A load_amplitude axis is drawn as P0/Pcr when
the result's `load_ratio` lies over that axis alone.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib import colors as mcolors
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..errors import UserError
from .labels import _title, label
from .maps import (_MARKER_CELLS, _hatch_region, _map_axes, _mesh, _pair, plot_map,
                   plot_state_map)
from .overlays import overlays_for
from .result import STABILITY, select_points, swept_axes
from .style import (STATE_STYLES, _coord, _is_log_spaced, _legend, _new_axes, _plain_ticks,
                    _unit)

_STABLE_COLOUR = "0.9"               # stable points: light grey
_CMAP = "magma_r"                    # unstable points: growth rate, light (slow) to dark (fast)
_GAMMA = 0.5                         # the colour scale's power: the slow tongues stay visible
_EDGE_COLOUR = "0.15"                # growth rate = 0: the damped boundary
_INVALID_COLOUR = STATE_STYLES["invalid_input"][0]
_FLOQUET_COLOUR = "#e7298a"          # the Floquet boundary over a time-domain map
_FLOQUET_STYLE = dict(color=_FLOQUET_COLOUR, lw=1.8,
                      path_effects=[patheffects.Stroke(linewidth=3.4, foreground="w"),
                                    patheffects.Normal()])
FLOQUET_LABEL = "Floquet: unstable inside"
_FREQUENCY_AXES = ("frequency_ratio", "frequency")
_KINDS = {"unstable_period_2": "period 2 (odd m)", "unstable_period_1": "period 1 (even m)",
          "unstable_complex": "complex multipliers"}


def _rate_units(da: xr.DataArray) -> str:
    """The growth rate's units as shown: '1/s' for the stored 's-1'."""
    units = str(da.attrs.get("units", "s-1"))
    return "1/s" if units in ("s-1", "1/s", "s^-1") else units


def _flags(ds: xr.Dataset) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(unstable, stable, invalid) masks of every point, from the `stability` flags (else from
    the sign of the growth rate), shaped like `ds.growth_rate`."""
    g = np.asarray(ds["growth_rate"].values, float)
    if STABILITY not in ds:
        invalid = ~np.isfinite(g)
        return (g > 0) & ~invalid, (g <= 0) & ~invalid, invalid
    flags = ds[STABILITY].transpose(*ds["growth_rate"].dims).values
    meaning = dict(zip(np.atleast_1d(ds[STABILITY].attrs.get("flag_values", [])).tolist(),
                       str(ds[STABILITY].attrs.get("flag_meanings", "")).split()))
    names = np.vectorize(lambda v: meaning.get(int(v), ""), otypes=[object])(flags) \
        if flags.size else np.zeros(flags.shape, object)
    unstable = np.char.startswith(names.astype(str), "unstable")
    stable = names == "stable"
    return unstable, stable, ~(unstable | stable)


def _chart_axes(ds: xr.Dataset, x: str | None, y: str | None, who: str) -> tuple[str, str]:
    """x and y of a chart: the two swept axes, x a load frequency (W/w1, or Hz) when one is
    swept; y may be given as load_ratio for a load_amplitude axis."""
    axes = swept_axes(ds)
    if len(axes) != 2:
        raise UserError(f"{who} needs exactly two swept axes; this result has {len(axes)} "
                        f"({', '.join(axes) or 'none'})" + (": use plot_growth_rate"
                                                            if len(axes) == 1 else ""))
    if "growth_rate" not in ds:
        raise UserError(f"{who}: the result has no 'growth_rate' (run it with "
                        "outputs.stability = true)")
    if sorted(ds["growth_rate"].dims) != sorted(axes):
        raise UserError(f"{who}: growth_rate lies over ({', '.join(ds['growth_rate'].dims)}), "
                        f"not over the swept axes ({', '.join(axes)})")
    x = "load_amplitude" if x == "load_ratio" else x
    y = "load_amplitude" if y == "load_ratio" else y
    if x is None and y is None:
        x = next((a for a in _FREQUENCY_AXES if a in axes), axes[1])
    return _pair(axes, x, y, who)


def _as_load_ratio(ds: xr.Dataset, dim: str) -> xr.Dataset | None:
    """`ds` drawn over P0/Pcr instead of load_amplitude (`load_ratio` becomes the dimension),
    when `load_ratio` lies over load_amplitude alone and grows with it; else None."""
    if dim != "load_amplitude" or "load_ratio" not in ds or \
            ds["load_ratio"].dims != ("load_amplitude",):
        return None
    ratio = np.asarray(ds["load_ratio"].values, float)
    if not (np.all(np.isfinite(ratio)) and np.all(np.diff(ratio) > 0)):
        return None
    return ds.swap_dims({"load_amplitude": "load_ratio"})


def _tongue_positions(ds: xr.Dataset, x: str, low: float, high: float) -> list[tuple[int, float]]:
    """(m, position) of the tongues W = 2 w1 / m within [low, high] on a W/w1 axis (or a
    frequency axis in Hz when w1 is one number), m = 1, 2, ... while the labels keep apart."""
    if x == "frequency_ratio":
        top = 2.0
    elif x == "frequency" and "natural_frequency" in ds and ds["natural_frequency"].ndim == 0:
        top = 2.0 * float(ds["natural_frequency"].values)
    else:
        return []
    span = high - low
    found = []
    for m in range(1, 64):
        pos = top / m
        if pos < low:
            break
        if found and found[-1][1] - pos < 0.03 * span:
            break
        if pos <= high:
            found.append((m, pos))
    return found


def _label_tongues(ax: Axes, ds: xr.Dataset, x: str) -> bool:
    """The tongue orders over the top of the chart at W/w1 = 2/m, 'm = 1', then '2', '3', ...
    (a short tick each); False when none is in range."""
    low, high = sorted(ax.get_xlim())
    tongues = _tongue_positions(ds, x, low, high)
    trans = ax.get_xaxis_transform()
    for m, pos in tongues:
        ax.plot([pos, pos], [0.975, 1.0], transform=trans, color="0.2", lw=1.0,
                clip_on=False, zorder=6, gid=f"tongue-{m}")
        ax.text(pos, 1.008, "m = 1" if m == 1 else str(m), transform=trans, ha="center",
                va="bottom",
                fontsize="small", color="0.2", gid=f"tongue-label-{m}")
    return bool(tongues)


def _mark_invalid(ax: Axes, ds: xr.Dataset, x: str, y: str, invalid: np.ndarray) -> list:
    """The invalid points: a grey square per cell on small grids, a hatched, outlined region on
    dense ones (as maps mark a state); their legend handle."""
    count = int(invalid.sum())
    if not count:
        return []
    if invalid.size > _MARKER_CELLS:
        return [_hatch_region(ax, ds, x, y, invalid, "invalid_input", _INVALID_COLOUR, count)]
    xx, yy = np.meshgrid(_coord(ds, x), _coord(ds, y))
    ax.scatter(xx[invalid], yy[invalid], marker="s", s=30, color=_INVALID_COLOUR,
               edgecolors="k", linewidths=0.6, zorder=4)
    return [Line2D([], [], ls="none", marker="s", color=_INVALID_COLOUR, markeredgecolor="k",
                   label=f"invalid_input ({count})")]


def plot_stability_chart(ds: xr.Dataset, *, x: str | None = None, y: str | None = None,
                         select: Mapping[str, Any] | None = None,
                         ax: Axes | None = None) -> Figure:
    """The Ince-Strutt chart of a stability result over its two swept axes: x the load
    frequency (frequency_ratio W/w1, or frequency) when swept, y the other, a load_amplitude
    axis drawn as P0/Pcr when `load_ratio` lies over it alone (name y="load_amplitude"
    to keep newtons). Unstable points are coloured by the Floquet growth rate (1/s; a
    sequential scale, square-root spaced so the slow tongues show), stable points light
    grey, invalid points marked; the damped boundary (growth rate 0) is outlined. On a W/w1
    axis the tongues m = 1, 2, 3, ... are named at W/w1 = 2/m over the top; over W/w1 x
    P0/Pcr the first-order boundaries of the undamped principal and second zones are drawn
    dashed ("first-order boundaries (undamped)", overlays.py). Returns the Figure (the chart
    is its first Axes, `ax` when given; the colour bar the next)."""
    ds = select_points(ds, select)
    newtons = "load_amplitude" in (x, y)           # named: keep the load in N
    x, y = _chart_axes(ds, x, y, "plot_stability_chart")
    ratio = None if newtons else _as_load_ratio(ds, y)
    if ratio is not None:
        ds, y = ratio, "load_ratio"
    ax = ax if ax is not None else _new_axes((7.4, 6.2))
    g_da = ds["growth_rate"].transpose(y, x)
    g = np.asarray(g_da.values, float)
    unstable, stable, invalid = _flags(ds.assign(growth_rate=g_da))
    units = _rate_units(ds["growth_rate"])
    _mesh(ax, ds, x, y, np.ma.masked_where(~stable, np.zeros(g.shape)),
          cmap=mcolors.ListedColormap([_STABLE_COLOUR]), vmin=0.0, vmax=1.0)
    rates = g[unstable & np.isfinite(g)]
    top = float(rates.max()) if rates.size else 1.0
    norm = mcolors.PowerNorm(_GAMMA, vmin=0.0, vmax=top if top > 0 else 1.0)
    mesh = _mesh(ax, ds, x, y, np.ma.masked_where(~unstable | ~np.isfinite(g), g),
                 cmap=_CMAP, norm=norm)
    ax.set_facecolor("white")
    handles: list = [Patch(facecolor=_STABLE_COLOUR, edgecolor="0.6",
                           label=f"stable ({int(stable.sum())})")]
    if unstable.any():
        kinds = []
        if STABILITY in ds:
            flags = ds[STABILITY].transpose(y, x).values
            for value, meaning in zip(
                    np.atleast_1d(ds[STABILITY].attrs.get("flag_values", [])),
                    str(ds[STABILITY].attrs.get("flag_meanings", "")).split()):
                n = int((flags == value).sum())
                if meaning in _KINDS and n:
                    kinds.append(f"{_KINDS[meaning]} {n}")
        text = f"unstable ({int(unstable.sum())})" + (f":\n{', '.join(kinds)}" if kinds else "")
        handles.append(Patch(facecolor=mesh.cmap(0.55), edgecolor="0.6", label=text))
    else:
        handles.append(Patch(facecolor="white", edgecolor="0.6", label="no unstable point"))
    handles += _mark_invalid(ax, ds, x, y, invalid)
    lims = ax.get_xlim(), ax.get_ylim()
    xv, yv = _coord(ds, x), _coord(ds, y)
    finite = np.isfinite(g)
    if (g[finite] > 0).any() and (g[finite] <= 0).any() and min(g.shape) > 1:
        edge = ax.contour(xv, yv, np.where(finite, g, np.nan), levels=[0.0],
                          colors=[_EDGE_COLOUR], linewidths=0.8, zorder=3)
        edge.set_gid("growth-rate-zero")
        handles.append(Line2D([], [], color=_EDGE_COLOUR, lw=0.8,
                              label="growth rate 0 (damped boundary)"))
    for draw in overlays_for(ds, "stability"):     # first-order Mathieu boundaries
        handles += draw(ax, ds, x, y)
    ax.set_xlim(*lims[0])
    ax.set_ylim(*lims[1])
    bar = ax.figure.colorbar(mesh, ax=ax, label=f"Floquet growth rate, unstable [{units}]")
    _plain_ticks(bar.ax)
    tongues = _label_tongues(ax, ds, x)
    ax.set_title(_title(ds, "Floquet stability chart"), fontsize="medium",
                 pad=16 if tongues else 6)
    _plain_ticks(ax)
    _legend(ax, handles)
    return ax.figure


def plot_growth_rate(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                     ax: Axes | None = None) -> Figure:
    """The Floquet growth rate (1/s) against the one swept axis, markers coloured by the
    stability flag, the zero line (stability limit) dashed; on a W/w1 axis the tongues named
    at W/w1 = 2/m. Returns the Figure."""
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    if len(axes) != 1:
        raise UserError(f"plot_growth_rate needs exactly one swept axis; this result has "
                        f"{len(axes)} ({', '.join(axes) or 'none'}): use plot_stability_chart")
    (dim,) = axes
    if "growth_rate" not in ds or ds["growth_rate"].dims != (dim,):
        raise UserError("plot_growth_rate: the result has no 'growth_rate' over "
                        f"'{dim}' (run it with outputs.stability = true)")
    ax = ax if ax is not None else _new_axes((6.8, 5.0))
    xfactor, xunits = _unit(ds[dim])
    xv = ds[dim].values.astype(float) * xfactor
    g = ds["growth_rate"].values.astype(float)
    unstable, stable, invalid = _flags(ds)
    units = _rate_units(ds["growth_rate"])
    ax.plot(xv, g, color="0.7", lw=1.0, zorder=1)
    ax.axhline(0.0, color="k", ls="--", lw=1.0, zorder=2)
    handles: list = [Line2D([], [], color="k", ls="--", lw=1.0,
                            label="growth rate 0: stability limit")]
    cmap = colormaps[_CMAP]
    for mask, colour, text in ((stable, _STABLE_COLOUR, "stable"),
                               (unstable, cmap(0.55), "unstable")):
        if mask.any():
            ax.scatter(xv[mask], g[mask], s=30, color=colour, edgecolors="k", linewidths=0.5,
                       zorder=3)
            handles.append(Line2D([], [], ls="none", marker="o", color=colour,
                                  markeredgecolor="k", label=f"{text} ({int(mask.sum())})"))
    if invalid.any():
        ax.scatter(xv[invalid], np.zeros(int(invalid.sum())), marker="s", s=30,
                   color=_INVALID_COLOUR, edgecolors="k", zorder=3, clip_on=False,
                   transform=ax.get_xaxis_transform())
        handles.append(Line2D([], [], ls="none", marker="s", color=_INVALID_COLOUR,
                              markeredgecolor="k", label=f"invalid_input ({int(invalid.sum())})"))
    if _is_log_spaced(xv):
        ax.set_xscale("log")
    ax.set_xlabel(label(ds[dim], xunits))
    ax.set_ylabel(f"Floquet growth rate [{units}]")
    ax.grid(True, color="0.92", zorder=0)
    tongues = _label_tongues(ax, ds, dim)
    ax.set_title(_title(ds, "Floquet growth rate"), fontsize="medium", pad=16 if tongues else 6)
    _plain_ticks(ax)
    _legend(ax, handles)
    return ax.figure


def time_domain_variable(ds: xr.Dataset) -> str | None:
    """The time-domain quantity a Floquet boundary is drawn over: amplitude, else
    peak_amplitude (when it varies), else the state map ('state'); None without a `state`."""
    if "state" not in ds.data_vars:
        return None
    for var in ("amplitude", "peak_amplitude"):
        values = np.asarray(ds[var].values, float) if var in ds else np.array([])
        values = values[np.isfinite(values)]
        if values.size and values.min() < values.max():
            return var
    return "state"


def plot_stability_over_map(ds: xr.Dataset, var: str | None = None, *, x: str | None = None,
                            y: str | None = None, select: Mapping[str, Any] | None = None,
                            ax: Axes | None = None) -> Figure:
    """The time-domain map of a result that has both kinds (`amplitude`, as `plot_map` draws
    it, with its state marks and overlays; `var` to pick another, 'state' for the state map)
    with the Floquet unstable region's boundary, growth rate = 0, drawn over it as a line
    ("Floquet: unstable inside"). Returns the Figure (the map is its first Axes)."""
    ds = select_points(ds, select)
    if "state" not in ds.data_vars:
        raise UserError("plot_stability_over_map: the result has no time-domain map (no "
                        "'state'): use plot_stability_chart")
    var = var or time_domain_variable(ds)
    who = "plot_stability_over_map"
    x, y = _map_axes(ds, x, y, who, None if var == "state" else var)
    if "growth_rate" not in ds or sorted(ds["growth_rate"].dims) != sorted([x, y]):
        raise UserError(f"{who}: the result has no 'growth_rate' over ({y}, {x}) (run it with "
                        "outputs.stability = true)")
    proxy = Line2D([], [], label=FLOQUET_LABEL, **_FLOQUET_STYLE)
    if var == "state":
        ax = plot_state_map(ds, x=x, y=y, ax=ax, extra_handles=[proxy])
    else:
        ax = plot_map(ds, var, x=x, y=y, ax=ax, extra_handles=[proxy])
    g = np.asarray(ds["growth_rate"].transpose(y, x).values, float)
    lims = ax.get_xlim(), ax.get_ylim()
    finite = np.isfinite(g)
    if (g[finite] > 0).any() and (g[finite] <= 0).any() and min(g.shape) > 1:
        style = dict(_FLOQUET_STYLE)
        line = ax.contour(_coord(ds, x), _coord(ds, y), np.where(finite, g, np.nan),
                          levels=[0.0], colors=[style.pop("color")],
                          linewidths=style.pop("lw"), zorder=5, **style)
        line.set_gid("floquet-boundary")
    ax.set_xlim(*lims[0])
    ax.set_ylim(*lims[1])
    ax.set_title(_title(ds, f"{var}, Floquet boundary over it"), fontsize="medium")
    return ax.figure


def floquet_boundary_in_range(ds: xr.Dataset) -> bool:
    """Whether the growth rate changes sign over the grid (a boundary to draw)."""
    g = np.asarray(ds["growth_rate"].values, float)
    g = g[np.isfinite(g)]
    return bool((g > 0).any() and (g <= 0).any())
