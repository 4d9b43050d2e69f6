"""A continuous sine sweep ([base] sweep = {start, stop, rate}): the response envelope against
the excitation frequency (`plot_envelope`).

The envelope is the largest |q| (midspan deflection) at the extrema of q while the sweep's
frequency lay in each base-2 1/N-octave band (variable `envelope`, m, over the axes and
`band_frequency`, Hz, the bands' centres; NaN where the sweep did not reach the band). The
input, `base_level_g` (g, at each band's centre), goes on a second y axis.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..errors import UserError
from .labels import _point_text, _title, label
from .result import DIRECTION_DIM, select_points, swept_axes
from .style import _legend, _log_ticks, _new_axes, state_styles

BAND_DIM = "band_frequency"          # the envelope's dimension (sweep.models.transverse.BAND_DIM)
_LEVEL_COLOUR = "0.55"               # the base level on the right axis
_F1_STYLE = dict(ls=(0, (2, 2)), lw=1.0, alpha=0.9, zorder=1)
_PEAK_STYLE = dict(marker="*", s=110, edgecolors="k", linewidths=0.6, zorder=5)
# A sweep run both ways (a `direction` dimension): up solid, filled; down dashed, hollow.
_WAYS = {"up": dict(ls="-", lw=1.6, filled=True), "down": dict(ls="--", lw=1.3, filled=False)}


def _good_states(state: xr.DataArray) -> set[int]:
    """The flag values of the states drawn: the good ones (`completed` for a sweep; style.py's
    states without a map marker)."""
    return {v for v, _meaning, _c, marker in state_styles(state) if marker is None}


def _meaning(state: xr.DataArray, value: int) -> str:
    return next((m for v, m, _c, _k in state_styles(state) if v == value), str(value))


def _positive(values: np.ndarray) -> np.ndarray:
    """`values` with NaN where a log axis cannot show them (NaN, zero, negative)."""
    v = np.asarray(values, dtype=float).copy()
    with np.errstate(invalid="ignore"):
        v[~(v > 0)] = np.nan
    return v


def _band_edges(ds: xr.Dataset) -> np.ndarray:
    """(n_bands, 2) band edges in Hz: the CF bounds variable when it is sound, else geometric
    midpoints between the centres (half a band's ratio beyond the ends)."""
    centres = np.asarray(ds[BAND_DIM].values, dtype=float)
    name = ds[BAND_DIM].attrs.get("bounds")
    if isinstance(name, str) and name in ds.variables:
        bounds = ds[name]
        if bounds.ndim == 2 and bounds.dims[0] == BAND_DIM and bounds.shape[1] == 2:
            b = np.asarray(bounds.values, dtype=float)
            if np.all(np.isfinite(b)) and np.all(b > 0) and np.all(b[:, 0] <= centres) \
                    and np.all(centres <= b[:, 1]):
                return b
    if centres.size == 1:
        return np.array([[centres[0] / 2 ** (1 / 6), centres[0] * 2 ** (1 / 6)]])
    w = np.log(centres)
    mid = 0.5 * (w[1:] + w[:-1])
    lo = np.concatenate([[w[0] - (mid[0] - w[0])], mid])
    hi = np.concatenate([mid, [w[-1] + (w[-1] - mid[-1])]])
    return np.exp(np.column_stack([lo, hi]))


def plot_envelope(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                  ax: Axes | None = None) -> Figure:
    """The response envelope of a continuous sine sweep against the excitation frequency, on
    log-log axes: x the bands' centre frequencies (Hz, `band_frequency`), left y the envelope,
    the largest |q| in each band (`envelope`, stored in m, drawn in mm), one line with a marker
    per band for each point of the swept axis (at most one may remain after `select`; a result
    of one point gets one line). Bands the sweep did not reach (NaN) are gaps, not zeros.

    Each point also gets a star at its overall peak (`peak_frequency`, Hz; `peak_amplitude`,
    m, drawn in mm) and a thin dotted vertical line at its span's first natural frequency
    (`natural_frequency`, Hz) when these are stored and in range. The input level
    (`base_level_g`, g, at each band's centre) is drawn as grey steps over the bands on a
    second, logarithmic y axis on the right; without it there is no second axis. Points whose
    state is not a good one (a sweep's `completed`) are not drawn, and the legend says how many
    were left out and why.

    A sweep run both ways (a `direction` dimension, [base] sweep.direction = "both") gets the
    up and down envelope of each point overlaid in the point's colour, up solid with filled
    markers, down dashed with hollow ones, and each direction's peak starred (up filled, down
    hollow); the legend names the points once and says once which line style is which.

    `select`: {axis: value} fixes the other swept axes, as for `plot_line`. `ax`: draw into
    these Axes (else a new Figure). Returns the Figure. Raises UserError without `envelope`, or
    with more than one swept axis left.
    """
    if "envelope" not in ds or BAND_DIM not in ds["envelope"].dims:
        raise UserError(f"plot_envelope: the result has no variable 'envelope' over "
                        f"'{BAND_DIM}' (a swept base frequency with outputs.envelope = true)")
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    if len(axes) > 1:
        example = " ".join(f"--select {d}={float(ds[d].values[0]):g}" for d in axes[1:])
        raise UserError(f"plot_envelope draws one line per point of one swept axis; this result "
                        f"has {len(axes)} ({', '.join(axes)}): pick the values of the others, "
                        f"e.g. {example} (select= in Python)")
    dim = axes[0] if axes else None
    ax = ax if ax is not None else _new_axes((7.2, 5.4))
    fig = ax.figure
    freq = np.asarray(ds[BAND_DIM].values, dtype=float)
    edges = _band_edges(ds)
    points = [ds.isel({dim: i}) for i in range(ds.sizes[dim])] if dim else [ds]
    good = _good_states(ds["state"])
    scale = _colour_scale(ds, dim, len(points))
    colours = ([scale[0](scale[1](float(v))) for v in ds[dim].values] if scale else
               [f"C{i % 10}" for i in range(len(points))])
    ways = ([str(d) for d in ds[DIRECTION_DIM].values] if DIRECTION_DIM in ds["state"].dims
            else [None])
    handles: list = []
    left_out: dict[str, int] = {}
    drawn: list[tuple[xr.Dataset, str]] = []
    peaks: list[tuple[xr.Dataset, str, str | None]] = []
    for point, colour in zip(points, colours):
        text = _point_text(point, [dim]) if dim else str(ds.attrs.get("title", "envelope"))
        first = None
        for way in ways:
            part = point if way is None else point.sel({DIRECTION_DIM: way})
            value = int(part["state"].values)
            if value not in good:
                meaning = _meaning(ds["state"], value)
                left_out[meaning] = left_out.get(meaning, 0) + 1
                continue
            y = _positive(part["envelope"].transpose(BAND_DIM).values) * 1e3
            style = _WAYS.get(way, _WAYS["up"])
            line, = ax.plot(freq, y, color=colour, lw=style["lw"], ls=style["ls"], marker="o",
                            ms=3.5, mfc=colour if style["filled"] else "white", mec=colour,
                            zorder=3, label=text if way is None else f"{text}, swept {way}",
                            gid="envelope")
            peaks.append((part, colour, way))
            if first is None:
                first = line
                drawn.append((part, colour))
        if first is not None and scale is None:
            handles.append(first if ways == [None] else
                           Line2D([], [], color=colour, lw=2.0, label=text))
    if ways != [None] and drawn:
        handles += [Line2D([], [], color="0.3", marker="o", ms=3.5, mfc="white" if not
                           _WAYS.get(w, _WAYS["up"])["filled"] else "0.3", mec="0.3",
                           ls=_WAYS.get(w, _WAYS["up"])["ls"], label=f"swept {w}")
                    for w in ways]
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(float(edges[0, 0]), float(edges[-1, 1]))
    stars = _draw_peaks(ax, peaks, edges)
    f1 = _draw_natural_frequencies(ax, drawn, edges)
    handles += stars + f1
    level = _draw_level(ax, ds, dim, drawn, edges)
    handles += level
    if left_out:
        total = sum(left_out.values())
        why = ", ".join(f"{m} {n}" for m, n in sorted(left_out.items()))
        runs = (f"{len(points)} point{'s' if len(points) != 1 else ''}" if ways == [None] else
                f"{len(points) * len(ways)} sweeps ({len(points)} point"
                f"{'s' if len(points) != 1 else ''} x {len(ways)} directions)")
        handles.append(Line2D([], [], ls="none", label=f"left out: {total} of {runs} not "
                              f"completed ({why})"))
    if not drawn:
        ax.text(0.5, 0.5, "no completed point: nothing to draw", transform=ax.transAxes,
                ha="center", va="center", color="0.3")
    ax.set_xlabel(f"excitation frequency [{ds[BAND_DIM].attrs.get('units', 'Hz')}]")
    ax.set_ylabel("envelope, max |q| [mm]")
    n = _bands_per_octave(freq)
    both = f", swept {' and '.join(ways)}" if ways != [None] else ""
    ax.set_title(_title(ds, f"response envelope{f' in 1/{n}-octave bands' if n else ''}{both}"),
                 fontsize="medium")
    ax.grid(True, which="major", color="0.88", zorder=0)
    ax.grid(True, which="minor", color="0.95", zorder=0)
    _log_ticks(ax, "x")
    if drawn:
        _log_ticks(ax, "y")
    if scale is not None:
        _colour_bar(ax, ds, dim, scale)
    _legend(ax, handles)
    return fig


MAX_NAMED_POINTS = 8
"""More points than this get a colour scale by their value and a colour bar, not a legend
entry each (ten colours would repeat, and the legend would outgrow the plot)."""


def _colour_scale(ds: xr.Dataset, dim: str | None, count: int) -> tuple | None:
    """(colormap, Normalize) over the swept axis's values when there are more than
    MAX_NAMED_POINTS points of a numeric axis; None otherwise."""
    if dim is None or count <= MAX_NAMED_POINTS or ds[dim].dtype.kind not in "iuf":
        return None
    from matplotlib import colormaps
    from matplotlib.colors import Normalize
    values = np.asarray(ds[dim].values, dtype=float)
    return colormaps["viridis"], Normalize(float(np.nanmin(values)), float(np.nanmax(values)))


def _colour_bar(ax: Axes, ds: xr.Dataset, dim: str, scale: tuple) -> None:
    """The colour bar of `_colour_scale`, under the plot, labelled with the axis and units."""
    from matplotlib.cm import ScalarMappable
    bar = ax.figure.colorbar(ScalarMappable(norm=scale[1], cmap=scale[0]), ax=ax,
                             location="top", fraction=0.05, pad=0.02, aspect=40)
    bar.set_label(label(ds[dim]), fontsize="small")
    bar.ax.tick_params(labelsize="small")


def _bands_per_octave(freq: np.ndarray) -> int | None:
    """N of 1/N-octave bands from their centres (None with fewer than two)."""
    if freq.size < 2 or not np.all(freq > 0):
        return None
    n = 1.0 / float(np.median(np.diff(np.log2(freq))))
    return int(round(n)) if math.isfinite(n) and abs(n - round(n)) < 1e-3 and n >= 1 else None


def _in_range(value: float, edges: np.ndarray) -> bool:
    return math.isfinite(value) and edges[0, 0] <= value <= edges[-1, 1]


def _draw_peaks(ax: Axes, drawn: list[tuple[xr.Dataset, str, str | None]],
                edges: np.ndarray) -> list:
    """A star at each drawn run's (peak_frequency, peak_amplitude), in its point's colour:
    filled, or hollow for the down sweep of a sweep run both ways; the legend handles (one,
    or one per direction)."""
    shown: list[str | None] = []
    for point, colour, way in drawn:
        if "peak_frequency" not in point or "peak_amplitude" not in point:
            continue
        f, q = float(point["peak_frequency"].values), float(point["peak_amplitude"].values)
        if _in_range(f, edges) and math.isfinite(q) and q > 0:
            filled = _WAYS.get(way, _WAYS["up"])["filled"]
            style = dict(_PEAK_STYLE, edgecolors="k" if filled else colour,
                         linewidths=0.6 if filled else 1.3)
            ax.scatter([f], [q * 1e3], color=colour if filled else "white", **style)
            if way not in shown:
                shown.append(way)
    if shown == [None]:
        return [Line2D([], [], ls="none", marker="*", ms=10, color="0.6", markeredgecolor="k",
                       markeredgewidth=0.6, label="peak: max |q| of the run at its frequency")]
    handles = []
    for way in (w for w in _WAYS if w in shown):
        filled = _WAYS[way]["filled"]
        handles.append(Line2D([], [], ls="none", marker="*", ms=10,
                              color="0.6" if filled else "white",
                              markeredgecolor="k" if filled else "0.4",
                              markeredgewidth=0.6 if filled else 1.2,
                              label=f"peak of the {way} sweep: max |q| at its frequency"))
    return handles


def _draw_natural_frequencies(ax: Axes, drawn: list[tuple[xr.Dataset, str]],
                              edges: np.ndarray) -> list:
    """A thin dotted vertical line at each drawn span's f1 within the bands, in the point's
    colour (grey, one line, when every span has the same f1); the legend handle, which counts
    the spans whose f1 lies outside the bands."""
    values = [(float(p["natural_frequency"].values), c) for p, c in drawn
              if "natural_frequency" in p and p["natural_frequency"].ndim == 0]
    values = [(f, c) for f, c in values if math.isfinite(f)]
    if not values:
        return []
    same = len({f for f, _c in values}) == 1
    inside = [(f, c) for f, c in values if _in_range(f, edges)]
    outside = len(values) - len(inside) if not same else 0
    for f, colour in (inside[:1] if same else inside):
        ax.axvline(f, color="0.4" if same else colour, **_F1_STYLE)
    if same:
        where = "" if inside else ", outside the bands"
        label = f"natural frequency f1 = {values[0][0]:.4g} Hz{where}"
    else:
        label = "natural frequency f1 of each span" + (
            f" ({outside} outside the bands)" if outside else "")
    return [Line2D([], [], color="0.4", label=label, **_F1_STYLE)]


def _draw_level(ax: Axes, ds: xr.Dataset, dim: str | None,
                drawn: list[tuple[xr.Dataset, str]], edges: np.ndarray) -> list:
    """`base_level_g` as steps over the bands on a log right y axis in g: one grey staircase,
    or, when the level differs between the drawn points, one dashed staircase per point in its
    colour. Nothing (no second axis) without the variable or without a positive level."""
    if "base_level_g" not in ds or BAND_DIM not in ds["base_level_g"].dims:
        return []
    level = ds["base_level_g"]
    per_point = dim is not None and dim in level.dims
    if per_point:
        rows = [(_positive(p["base_level_g"].transpose(BAND_DIM).values), c) for p, c in drawn]
        if rows and all(np.array_equal(r, rows[0][0], equal_nan=True) for r, _c in rows):
            rows, per_point = rows[:1], False
    else:
        extra = [d for d in level.dims if d != BAND_DIM]
        values = level.isel({d: 0 for d in extra}).values if extra else level.values
        rows = [(_positive(values), _LEVEL_COLOUR)]
    rows = [(r, c) for r, c in rows if np.isfinite(r).any()]
    if not rows:
        return []
    twin = ax.twinx()
    x = edges.ravel()                        # lo0, hi0, lo1, hi1, ...: a staircase
    for values, colour in rows:
        style = dict(color=colour if per_point else _LEVEL_COLOUR, lw=1.3,
                     ls="--" if per_point else "-", zorder=2)
        twin.plot(x, np.repeat(values, 2), **style)
    twin.set_yscale("log")
    low = min(float(np.nanmin(r)) for r, _c in rows)
    high = max(float(np.nanmax(r)) for r, _c in rows)
    twin.set_ylim(low / 1.6, high * 1.6) if high / low < 100 else twin.set_ylim(low / 2, high * 2)
    twin.set_ylabel("base acceleration level [g]", color="0.35")
    twin.tick_params(axis="y", which="both", colors="0.35")
    _log_ticks(twin, "y")
    twin.set_xlim(ax.get_xlim())
    ax.set_zorder(twin.get_zorder() + 1)       # the envelope over the level, legend on top
    ax.patch.set_visible(False)
    return [Line2D([], [], color=_LEVEL_COLOUR, lw=1.3, ls="--" if per_point else "-",
                   label="base level (right axis)")]
