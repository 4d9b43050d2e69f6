"""One swept axis: a quantity against it, markers coloured by state (`plot_line`)."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from ..errors import UserError
from .labels import _title, label
from .overlays import overlays_for
from .result import select_points, swept_axes
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
    for draw in overlays_for(ds, "line"):         # buckling length, paper Fig 5 (overlays.py)
        handles += draw(ax, ds, dim, var, factor, units, kwargs["s"])
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
