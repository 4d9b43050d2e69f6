"""Stored histories: the response against time, one panel per point (`plot_time_series`, the
paper's Fig 5), and, for the longitudinal model, snapshots along the span (`plot_snapshots`,
the paper's Fig 7) and the end histories (`plot_histories`)."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..errors import UserError
from .labels import _point_text, _title, _wrap, label
from .overlays import overlays_for
from .result import _time_dim, select_points, swept_axes
from .style import _fmt, _plain_ticks, _scaled, _state_colour, _state_meaning, _unit


def _points(ds: xr.Dataset, max_points: int) -> tuple[list[dict[str, int]], int]:
    """Index dicts of up to max_points points, evenly spread over the swept grid; the total."""
    axes = swept_axes(ds)
    shape = [ds.sizes[d] for d in axes]
    total = int(np.prod(shape, dtype=np.int64))
    flat = np.unique(np.linspace(0, total - 1, min(total, max_points)).round().astype(int))
    return [dict(zip(axes, map(int, np.unravel_index(i, shape)))) for i in flat], total


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
        for draw in overlays_for(ds, "time_series"):     # paper Fig 5 (overlays.py)
            draw(ax, ds, point, var, factor, units)
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
            ax.plot(time.values * tfactor, point[name].values * factor, label=text or None,
                    **kwargs)
        for draw in overlays_for(ds, "histories"):       # exact peaks (overlays.py)
            draw(ax, ds, [ds.isel(p) for p in points], name, factor)
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
