"""A stepped sweep (continuation): the response against the stepped axis, up and down
overlaid, the jumps marked (`plot_branches`)."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from ..errors import UserError
from .labels import _title, label
from .result import DIRECTION_DIM, select_points, swept_axes
from .style import _is_log_spaced, _legend, _new_axes, _plain_ticks, _unit, _wide_range

JUMP_UP, JUMP_DOWN = 1, 2            # the `jump` flags (sweep/models/continuation.py)


def stepped_axis(ds: xr.Dataset) -> str | None:
    """The continuation axis of a stepped-sweep result (its `continuation_axis` attribute),
    or None for a result of independent points."""
    axis = ds.attrs.get("continuation_axis")
    return axis if isinstance(axis, str) and axis in ds.dims else None


def plot_branches(ds: xr.Dataset, var: str = "amplitude", *,
                  select: Mapping[str, Any] | None = None, ax: Axes | None = None,
                  add_legend: bool = True, **kwargs: Any) -> Axes:
    """`var` against the stepped axis, one curve per value of at most one other swept axis:
    the up sweep solid with filled markers, the down sweep dashed with hollow ones, and every
    jump (`jump` flag) marked with a triangle pointing the way the response jumped, so the
    hysteresis loop between the two folds shows. Displacements in mm; log axes where the
    values span more than two decades (y) or are log spaced (x). Extra keyword arguments go to
    `Axes.plot`. Returns the Axes."""
    axis = stepped_axis(ds)
    if axis is None:
        raise UserError("plot_branches: not a stepped sweep (no continuation_axis): use "
                        "plot_line or plot_map")
    if var not in ds:
        raise UserError(f"plot_branches: the result has no variable '{var}'")
    ds = select_points(ds, select)
    others = [d for d in swept_axes(ds) if d != axis]
    if len(others) > 1:
        example = " ".join(f"--select {d}={float(ds[d].values[0]):g}" for d in others[1:])
        raise UserError(f"a stepped sweep draws one curve per value of one other axis; this "
                        f"result has {len(others)} ({', '.join(others)}): pick the others, "
                        f"e.g. {example}")
    ax = ax if ax is not None else _new_axes()
    xfactor, xunits = _unit(ds[axis])
    x = ds[axis].values.astype(float) * xfactor
    y_all = ds[var].values.astype(float)
    factor, units = _unit(ds[var], y_all)
    directions = ([str(d) for d in ds[DIRECTION_DIM].values] if DIRECTION_DIM in ds.dims
                  else [str(ds.attrs.get("continuation_direction", "up"))])
    curves = [None] if not others else list(ds[others[0]].values)
    colours = [f"C{i % 10}" for i in range(len(curves))]
    handles = []
    for value, colour in zip(curves, colours):
        one = ds if value is None else ds.sel({others[0]: value})
        for direction in directions:
            part = one.sel({DIRECTION_DIM: direction}) if DIRECTION_DIM in one.dims else one
            y = part[var].values.astype(float) * factor
            up = direction == "up"
            ax.plot(x, y, ls="-" if up else "--", color=colour, marker="o", ms=3.5,
                    mfc=colour if up else "white", mec=colour, lw=1.2, zorder=2, **kwargs)
            if "jump" in part:
                flags = part["jump"].values
                for flag, marker in ((JUMP_UP, "^"), (JUMP_DOWN, "v")):
                    hit = (flags == flag) & np.isfinite(y)
                    if hit.any():
                        ax.scatter(x[hit], y[hit], marker=marker, s=90, color=colour,
                                   edgecolors="k", linewidths=0.8, zorder=4)
        if value is not None:
            vfactor, vunits = _unit(ds[others[0]])
            text = f"{others[0]} = {float(value) * vfactor:.4g}" + (
                f" {vunits}" if vunits and vunits != "1" else "")
            handles.append(Line2D([], [], color=colour, lw=2.0, label=text))
    handles += [Line2D([], [], color="0.3", ls="-", marker="o", ms=4, label="stepped up"),
                Line2D([], [], color="0.3", ls="--", marker="o", ms=4, mfc="white",
                       label="stepped down"),
                Line2D([], [], ls="none", marker="^", ms=8, color="0.5", mec="k",
                       label="jump up"),
                Line2D([], [], ls="none", marker="v", ms=8, color="0.5", mec="k",
                       label="jump down")]
    if _wide_range(y_all):
        ax.set_yscale("log")
    if _is_log_spaced(x):
        ax.set_xscale("log")
    ax.set_xlabel(label(ds[axis], xunits))
    ax.set_ylabel(label(ds[var], units))
    ax.set_title(_title(ds, "stepped up and down" if len(directions) == 2
                        else f"stepped {directions[0]}"), fontsize="medium")
    ax.grid(True, color="0.92", zorder=0)
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles)
    return ax
