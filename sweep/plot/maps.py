"""Two swept axes: maps of a quantity (`plot_map`) and of the state (`plot_state_map`), with
the points in a state that is not a good one marked and the model's closed-form overlays."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib import colormaps as mpl_colormaps
from matplotlib import colors as mcolors
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..errors import UserError
from .labels import POINT_DIM, _title, label, point_ticks
from .overlays import overlays_for
from .result import DIRECTION_DIM, select_points, swept_axes
from .style import (_coord, _edges, _is_displacement, _is_log_spaced, _legend, _new_axes,
                    _padded_range, _plain_ticks, _unit, _wide_range, state_styles,
                    symlog_scale, symlog_threshold)

_NAN_COLOUR = "0.82"
_DECADES = 6          # a log colour scale spans at most this many decades below the maximum
# Displacement maps: amplitudes below FLOOR x the map's largest one are drawn in one
# "no response" colour, and the log colour scale spans only the three decades above it.
FLOOR = 1e-3
_NO_RESPONSE_COLOUR = "white"
# Maps with more cells than this mark the states by hatched, outlined regions, not markers.
_MARKER_CELLS = 100
_HATCHES = {"modulated": "\\\\\\", "unsettled": "///", "diverged": "xxx",
            "step_size_too_small": "...", "max_steps_reached": "+++", "invalid_input": "---"}


def _map_axes(ds: xr.Dataset, x: str | None, y: str | None, who: str,
              var: str | None = None) -> tuple[str, str]:
    """The map's x and y: the swept axes, and the dimensions `var` lies over beyond them (a
    sweep's envelope bands, `band_frequency`), with more than one value; exactly two."""
    axes = swept_axes(ds)
    if var is not None and var in ds:
        axes += [d for d in ds[var].dims if d not in ds["state"].dims and ds.sizes[d] > 1]
    if len(axes) != 2:
        raise UserError(f"{who} needs exactly two swept axes; this result has {len(axes)} "
                        f"({', '.join(axes) or 'none'})" + (": use plot_line" if len(axes) == 1
                                                            else ""))
    if x is None and y is None:
        y, x = axes                      # xarray's convention: rows (first dim) on y
    return _pair(axes, x, y, who)


def _pair(axes: list[str], x: str | None, y: str | None, who: str) -> tuple[str, str]:
    """(x, y) over the two `axes`, the one not given being the other; UserError unless they
    are the two axes."""
    if x is None:
        x = next(d for d in axes if d != y)
    if y is None:
        y = next(d for d in axes if d != x)
    if {x, y} != set(axes):
        raise UserError(f"{who}: x and y must be the swept axes {axes[0]} and {axes[1]}")
    return x, y


def _one_direction(ds: xr.Dataset, direction: str | None, who: str) -> xr.Dataset:
    """`ds` at one value of its `direction` dimension (a sweep run up and down); `ds` itself
    when it has none. UserError for a missing or unknown direction."""
    if DIRECTION_DIM not in ds.dims:
        if direction is not None:
            raise UserError(f"{who}: direction={direction!r}, but the result was swept one way "
                            "(no 'direction' dimension)")
        return ds
    values = [str(v) for v in ds[DIRECTION_DIM].values]
    if direction is None and len(values) == 1:
        direction = values[0]
    if direction not in values:
        raise UserError(f"{who}: the result was swept {' and '.join(values)}: pick one map, "
                        f"direction={values[0]!r} (one of {', '.join(map(repr, values))})")
    return ds.sel({DIRECTION_DIM: direction})


def _scale(ax: Axes, which: str, values: np.ndarray, scale: str | None) -> None:
    """The x or y scale: `scale` when given ("linear", "log"), else log for a log-spaced
    coordinate. A log scale needs positive values (UserError otherwise)."""
    if scale is None:
        threshold = symlog_threshold(values)
        if threshold is not None:
            symlog_scale(ax, which, values, threshold)
            return
        scale = "log" if _is_log_spaced(values) else "linear"
    if scale not in ("linear", "log"):
        raise UserError(f"{which}scale '{scale}': use 'linear' or 'log'")
    if scale == "log" and not np.all(np.asarray(values, float) > 0):
        raise UserError(f"{which}scale 'log': the {which} axis has values <= 0")
    (ax.set_xscale if which == "x" else ax.set_yscale)(scale)


def _mesh(ax: Axes, ds: xr.Dataset, x: str, y: str, values: np.ndarray,
          xscale: str | None = None, yscale: str | None = None, **kwargs: Any):
    xv, yv = _coord(ds, x), _coord(ds, y)
    xe, ye = _edges(xv), _edges(yv)
    # A log axis gets geometric cell edges even when the centres are not log-spaced.
    if xscale == "log" and not _is_log_spaced(xv) and np.all(xv > 0):
        xe = np.exp(_edges(np.log(xv)))
    if yscale == "log" and not _is_log_spaced(yv) and np.all(yv > 0):
        ye = np.exp(_edges(np.log(yv)))
    mesh = ax.pcolormesh(xe, ye, values, shading="flat", **kwargs)
    _scale(ax, "x", xv, xscale)
    _scale(ax, "y", yv, yscale)
    ax.set_xlabel(label(ds[x], _unit(ds[x])[1]))
    ax.set_ylabel(label(ds[y], _unit(ds[y])[1]))
    for which, dim in (("x", x), ("y", y)):
        if dim == POINT_DIM:
            point_ticks(ax, ds, which)
    return mesh


def _state_label(meaning: str, count: int) -> str:
    return f"{meaning} ({count})"


def _mark_states(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """Mark the cells whose state is not a good one; returns the legend handles. A small grid
    (at most 100 cells) gets a marker per cell; a denser one gets each state's region hatched
    and outlined in the state's colour along the cell edges, so the colour under it shows."""
    points = ds["state"].values              # the counts are of points, not of cells
    state = ds["state"]
    for dim in (x, y):                       # a map over a dimension beyond the swept axes
        if dim not in state.dims:            # (envelope bands): a point's state on its row
            state = state.expand_dims({dim: ds.sizes[dim]})
    state = state.transpose(y, x).values
    styles = [s for s in state_styles(ds["state"]) if s[3] is not None and (state == s[0]).any()]
    if state.size > _MARKER_CELLS:
        return [_hatch_region(ax, ds, x, y, state == value, meaning, colour,
                              int((points == value).sum()))
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
                              label=_state_label(meaning, int((points == value).sum()))))
    return handles


def _hatch_region(ax: Axes, ds: xr.Dataset, x: str, y: str, mask: np.ndarray, meaning: str,
                  colour: str, count: int | None = None) -> Patch:
    """Hatch and outline the cells of `mask` (rows: y); its legend handle, counting `count`
    points (default: the cells of `mask`)."""
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
                 label=_state_label(meaning, int(mask.sum()) if count is None else count))


def _overlays(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """The closed-form curves of the result's model that the map's axes allow
    (overlays.py); their legend handles."""
    handles: list = []
    for draw in overlays_for(ds, "map"):
        handles += draw(ax, ds, x, y)
    return handles


def plot_map(ds: xr.Dataset, var: str = "amplitude", *, x: str | None = None,
             y: str | None = None, select: Mapping[str, Any] | None = None,
             ax: Axes | None = None, add_colorbar: bool = True, add_legend: bool = True,
             mark_states: bool = True, overlays: bool = True, xscale: str | None = None,
             yscale: str | None = None, direction: str | None = None,
             extra_handles: list | None = None, **kwargs: Any) -> Axes:
    """A pcolormesh map of `var` over the two swept axes (x: the second, y: the first, as
    xarray draws a 2-D DataArray; or name them). A variable spanning more than two decades gets
    a log colour scale; cells with no value (NaN) are grey. Displacements are in mm; on a log
    scale, a displacement below FLOOR (1e-3) times the map's largest is drawn white as "no
    response" and the colours span only the three decades above it (other variables: at most
    six decades, the rest in the lowest colour). Points in a state that is not a good one
    (modulated, unsettled, diverged, failures) are marked: a marker per cell on small grids,
    hatched and outlined regions on dense ones (`_MARKER_CELLS`). The closed-form curves the
    axes allow are drawn in white (sweep/plot/overlays.py). A variable over one swept axis and
    a dimension of its own (a sweep's `envelope` over `band_frequency`, Hz) is mapped over the
    two; a point's state marks its whole row. `xscale`, `yscale`: "linear" or "log" (None: log
    for a log-spaced coordinate, such as the envelope's band centres). Extra keyword arguments
    go to `Axes.pcolormesh` (cmap, norm, vmin, vmax, ...).

    `direction`: for a result swept both ways (a `direction` dimension, 'up' and 'down'), the
    one drawn; its colour scale spans both, so that the up and down maps compare colour for
    colour. `extra_handles`: legend entries of what the caller draws over the map (the Floquet
    boundary of stability.plot_stability_over_map). Returns the Axes.
    """
    ds = select_points(ds, select)
    x, y = _map_axes(ds, x, y, "plot_map", var)
    if var not in ds:
        raise UserError(f"plot_map: the result has no variable '{var}'")
    both = ds[var]                             # the colour scale: over every direction
    ds = _one_direction(ds, direction, "plot_map")
    ax = ax if ax is not None else _new_axes((7.0, 6.0))
    da = ds[var].transpose(y, x) if ds[var].ndim == 2 else ds[var].broadcast_like(
        ds["state"]).transpose(y, x)
    factor, units = _unit(both, both.values)
    values = np.ma.masked_invalid(da.values.astype(float) * factor)
    scale = np.ma.masked_invalid(np.asarray(both.values, dtype=float) * factor).compressed()
    extend = "neither"
    handles = []
    cmap = kwargs.pop("cmap", "viridis")
    user_scale = "norm" in kwargs or "vmin" in kwargs or "vmax" in kwargs
    if not user_scale and _wide_range(scale):
        top, low = float(scale.max()), float(scale.min())
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
        shown = values.compressed()
        extend = "min" if shown.size and float(shown.min()) < floor else "neither"
        kwargs["norm"] = mcolors.LogNorm(vmin=max(low, floor), vmax=top, clip=False)
    elif not user_scale:
        padded = _padded_range(scale)
        if padded is None and DIRECTION_DIM in both.dims and scale.size:
            kwargs["vmin"], kwargs["vmax"] = float(scale.min()), float(scale.max())
        if padded is not None:
            kwargs["vmin"], kwargs["vmax"] = padded
    mesh = _mesh(ax, ds, x, y, values, xscale, yscale, cmap=cmap, **kwargs)
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
    ax.set_title(_title(ds, str(var) + _swept(ds)), fontsize="medium")
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles + list(extra_handles or ()))
    return ax


def _swept(ds: xr.Dataset) -> str:
    """', swept up' for one direction of a sweep run both ways; '' otherwise."""
    if DIRECTION_DIM in ds.coords and ds[DIRECTION_DIM].ndim == 0:
        return f", swept {ds[DIRECTION_DIM].values}"
    return ""


def plot_state_map(ds: xr.Dataset, *, x: str | None = None, y: str | None = None,
                   select: Mapping[str, Any] | None = None, ax: Axes | None = None,
                   add_legend: bool = True, overlays: bool = True,
                   direction: str | None = None, extra_handles: list | None = None,
                   **kwargs: Any) -> Axes:
    """A map of `state` over the two swept axes, one fixed colour per flag meaning, with the
    closed-form overlays of `plot_map`; `direction` and `extra_handles` as for `plot_map`.
    Returns the Axes."""
    ds = select_points(ds, select)
    x, y = _map_axes(ds, x, y, "plot_state_map")
    ds = _one_direction(ds, direction, "plot_state_map")
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
    ax.set_title(_title(ds, "state" + _swept(ds)), fontsize="medium")
    _plain_ticks(ax)
    if add_legend:
        _legend(ax, handles + list(extra_handles or ()))
    return ax
