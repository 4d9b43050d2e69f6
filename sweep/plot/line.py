"""One swept axis: a quantity against it, markers coloured by state (`plot_line`); a sine
sweep run both ways (a `direction` dimension): up and down overlaid (`_plot_directions`)."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from ..errors import UserError
from .labels import POINT_DIM, _title, label, point_ticks
from .overlays import overlays_for
from .result import DIRECTION_DIM, select_points, swept_axes
from .style import (_is_log_spaced, _legend, _new_axes, _padded_range, _plain_ticks, _unit,
                    _wide_range, state_styles)


def plot_line(ds: xr.Dataset, var: str = "amplitude", *, select: Mapping[str, Any] | None = None,
              ax: Axes | None = None, add_legend: bool = True, **kwargs: Any) -> Axes:
    """`var` against the one swept axis, markers coloured by `state` (a thin grey line joins
    them). Points with no value (NaN, e.g. the settling time of a modulated point) are drawn
    hollow on the bottom edge in their state's colour. With length swept and P0/Pcr depending
    on it only, a dashed line marks the buckling length (P0 = Pcr) when it is in range.
    Displacements are in mm; near-constant data get a +-5 % range around their value (not a
    range of round-off); no axis uses an offset. On the paper's Fig 5 case the paper's own
    amplitudes are marked ("paper Fig 5"). Extra keyword arguments go to `Axes.scatter`.

    A result with a `direction` dimension (a continuous sine sweep run both ways, [base]
    sweep.direction = "both") gets the up and down values overlaid instead: up solid with
    filled markers, down dashed with hollow ones, in one colour (legend "swept up" / "swept
    down"); points in a state that is not a good one are marked with their state's map marker.
    Extra keyword arguments then go to `Axes.plot`. Returns the Axes."""
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
    if DIRECTION_DIM in ds["state"].dims:
        return _plot_directions(ds, dim, var, ax, add_legend, **kwargs)
    xfactor, xunits = _unit(ds[dim])
    x = ds[dim].values.astype(float) * xfactor
    y = ds[var].values.astype(float)
    state = ds["state"].values
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
    return _finish_axes(ax, ds, dim, var, x, y, factor, units, xunits, handles, nan_any,
                        kwargs["s"], _title(ds), add_legend, "state")


def _finish_axes(ax: Axes, ds: xr.Dataset, dim: str, var: str, x: np.ndarray, y: np.ndarray,
                 factor: float, units: str, xunits: str, handles: list, nan_any: bool,
                 size: float, title: str, add_legend: bool, *legend_args: Any) -> Axes:
    """What every line plot ends with: the NaN legend entry, the kind's overlays (buckling
    length, paper Fig 5: overlays.py), a log y axis for data over decades (else a padded
    range), a log x axis for a log-spaced axis, labels with units, title, grid, legend."""
    if nan_any:
        handles.append(Line2D([], [], ls="none", marker="v", markerfacecolor="none",
                              markeredgecolor="0.3", label="no value (NaN)"))
    for draw in overlays_for(ds, "line"):
        handles += draw(ax, ds, dim, var, factor, units, size)
    if _wide_range(y):
        ax.set_yscale("log")
    else:
        padded = _padded_range(y * factor)
        if padded is not None:
            ax.set_ylim(*padded)
    if _is_log_spaced(x):
        ax.set_xscale("log")
    ax.set_xlabel(label(ds[dim], xunits))
    ax.set_ylabel(label(ds[var], units))
    ax.set_title(title, fontsize="medium")
    ax.grid(True, color="0.92", zorder=0)
    _plain_ticks(ax)
    if dim == POINT_DIM:
        point_ticks(ax, ds, "x")
    if add_legend:
        _legend(ax, handles, *legend_args)
    return ax


_DIRECTION_STYLE = {"up": dict(ls="-", filled=True), "down": dict(ls="--", filled=False)}


def _plot_directions(ds: xr.Dataset, dim: str, var: str, ax: Axes, add_legend: bool,
                     **kwargs: Any) -> Axes:
    """`var` against `dim` for each value of `direction` ('up', 'down'), overlaid in one colour:
    up solid with filled markers, down dashed with hollow ones (as `plot_branches` draws a
    stepped sweep). Points whose state is not a good one get their state's map marker over
    them; points with no value (NaN) a hollow triangle on the bottom edge."""
    xfactor, xunits = _unit(ds[dim])
    x = ds[dim].values.astype(float) * xfactor
    da = ds[var].broadcast_like(ds["state"]).transpose(DIRECTION_DIM, dim)
    y_all = da.values.astype(float)
    state_all = ds["state"].transpose(DIRECTION_DIM, dim).values
    factor, units = _unit(ds[var], y_all)
    directions = [str(d) for d in ds[DIRECTION_DIM].values]
    colour = "C0"
    handles = []
    marked: dict[tuple[int, str, str, str], int] = {}
    nan_any = False
    for i, direction in enumerate(directions):
        style = _DIRECTION_STYLE.get(direction, dict(ls=":", filled=True))
        y = y_all[i] * factor
        ax.plot(x, y, ls=style["ls"], color=colour, marker="o", ms=4.5, lw=1.3,
                mfc=colour if style["filled"] else "white", mec=colour, zorder=2,
                label=f"swept {direction}", gid=f"direction-{direction}", **kwargs)
        handles.append(Line2D([], [], ls=style["ls"], color=colour, marker="o", ms=4.5,
                              mfc=colour if style["filled"] else "white", mec=colour,
                              label=f"swept {direction}"))
        for value, meaning, s_colour, marker in state_styles(ds["state"]):
            mask = state_all[i] == value
            if marker is None or not mask.any():
                continue
            marked[(value, meaning, s_colour, marker)] = marked.get(
                (value, meaning, s_colour, marker), 0) + int(mask.sum())
            good = mask & np.isfinite(y)
            if good.any():
                ax.scatter(x[good], y[good], marker=marker, s=60, color=s_colour,
                           edgecolors="k", linewidths=0.6, zorder=4)
        bad = ~np.isfinite(y)
        if bad.any():
            nan_any = True
            ax.scatter(x[bad], np.zeros(bad.sum()), marker="v", facecolors="none",
                       edgecolors=colour, linewidths=1.2, s=36, zorder=3, clip_on=False,
                       transform=ax.get_xaxis_transform())
    for (_value, meaning, s_colour, marker), count in sorted(marked.items()):
        handles.append(Line2D([], [], ls="none", marker=marker, color=s_colour,
                              markeredgecolor="k", markeredgewidth=0.6,
                              label=f"{meaning} ({count})"))
    ways = " and ".join(directions)
    return _finish_axes(ax, ds, dim, var, x, y_all, factor, units, xunits, handles, nan_any, 36,
                        _title(ds, f"swept {ways}"), add_legend)
