"""A random base excitation ([base] asd_g2 / asd, docs/model.md sec. 11): the result's own
figures, over the Monte Carlo records (the `realisation` dimension) rather than along it.

- `plot_rms`: the mean RMS midspan deflection over the realisations (m, drawn in mm) with its
  95 % interval as a band, and the exact linear RMS (`linear_rms`) dashed beside it;
- `plot_peak`: the mean peak deflection with its interval, the clearance levels as lines;
- `plot_exceedance`: the probability of exceeding each clearance level in the test (1), the
  mean over the realisations;
- `plot_peak_factors`: the empirical distribution of peak / RMS (1) over every record;
- `plot_asd` (outputs.response_asd): the absolute midspan acceleration's spectral density
  (g^2/Hz) of a few spans over the input spectrum at the same level, log-log.

Each draws against one swept axis (span length when it is swept), one line per value of at
most one other (`MAX_LEVELS` of them).
"""

from __future__ import annotations

import textwrap
from typing import Any, Mapping

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..errors import UserError
from .labels import POINT_DIM, _point_text, _title, label, point_ticks
from .result import (ASD_FREQUENCY_DIM, CLEARANCE_DIM, REALISATION_DIM, select_points,
                     swept_axes)
from .style import _legend, _new_axes, _plain_ticks, _unit

MAX_LEVELS = 5
"""Most lines of the other swept axis on one figure; more need --select (select= in Python)."""
# The other axis's levels on the exceedance figure (colour is the clearance level there).
_LEVEL_STYLES = (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"), ((0, (5, 1, 1, 1)), "v"))
_BAND_ALPHA = 0.2
_LINEAR_LABEL = "linear (Miles-like, exact)"


def random_axes(ds: xr.Dataset) -> tuple[str | None, str | None]:
    """(x, level): the swept axis drawn along (`length` when swept, else the first) and the
    one drawn as lines (None for none). UserError for more than MAX_LEVELS lines."""
    axes = swept_axes(ds)
    if not axes:
        return None, None
    x = "length" if "length" in axes else axes[0]
    others = [d for d in axes if d != x]
    level = others[0] if others else None
    if level is not None and ds.sizes[level] > MAX_LEVELS:
        raise UserError(f"{ds.sizes[level]} values of {level} are more lines than one figure "
                        f"shows ({MAX_LEVELS}): pick one, e.g. --select "
                        f"{level}={float(ds[level].values[0]):g} (select= in Python)")
    return x, level


def _levels(ds: xr.Dataset, level: str | None) -> list[tuple[xr.Dataset, str]]:
    """(the result at each value of `level`, its legend text); the whole result once (text:
    its title) without a level."""
    if level is None:
        return [(ds, str(ds.attrs.get("title", "result")))]
    return [(ds.isel({level: i}), _point_text(ds.isel({level: i}), [level]))
            for i in range(ds.sizes[level])]


def _records(ds: xr.Dataset) -> str:
    """'8 records' (or '1 record'): the realisations the means are taken over."""
    n = int(ds.sizes.get(REALISATION_DIM, 1))
    return f"{n} record{'s' if n != 1 else ''}"


def _prepare(ds: xr.Dataset, select: Mapping[str, Any] | None,
             ax: Axes | None, need: str) -> tuple[xr.Dataset, str, str | None, Axes]:
    """The selected result, its x and level axes and the Axes to draw into; UserError without
    `need` or without a swept axis."""
    if need not in ds:
        raise UserError(f"the result has no variable '{need}' (not a random result?)")
    ds = select_points(ds, select)
    x, level = random_axes(ds)
    if x is None:
        raise UserError(f"drawing {need} needs a swept axis with more than one value")
    return ds, x, level, ax if ax is not None else _new_axes((7.0, 5.4))


def _mean_with_band(ax: Axes, ds: xr.Dataset, x: str, level: str | None, name: str) -> list:
    """`NAME_mean` against `x` (a line with markers per level) and `NAME_ci` as a band of the
    same colour; displacements in mm. Parameter sets ([points]: x is `point`) are separate
    spans, not a curve: markers with error bars, no line between them. The legend handles,
    one per level."""
    xfactor = _unit(ds[x])[0]
    yfactor = _unit(ds[f"{name}_mean"])[0]
    sets = x == POINT_DIM
    handles = []
    for i, (part, text) in enumerate(_levels(ds, level)):
        colour = f"C{i % 10}"
        xv = part[x].values.astype(float) * xfactor
        mean = part[f"{name}_mean"].broadcast_like(part[x]).values.astype(float) * yfactor
        line, = ax.plot(xv, mean, color=colour, marker="o", ms=4, lw=1.6, zorder=3,
                        ls="none" if sets else "-", label=text, gid=f"{name}_mean")
        handles.append(line)
        if f"{name}_ci" in part:
            half = part[f"{name}_ci"].broadcast_like(part[x]).values.astype(float) * yfactor
            if sets:
                ax.errorbar(xv, mean, yerr=half, fmt="none", ecolor=colour, capsize=3,
                            zorder=2)
            else:
                ax.fill_between(xv, mean - half, mean + half, color=colour,
                                alpha=_BAND_ALPHA, lw=0, zorder=2)
    if f"{name}_ci" in ds and np.isfinite(ds[f"{name}_ci"].values).any():
        what = f"95 % interval of the mean of {_records(ds)}"
        handles.append(Line2D([], [], color="0.3", ls="none", marker="|", ms=10, label=what)
                       if sets else Patch(facecolor="0.5", alpha=_BAND_ALPHA * 2, label=what))
    return handles


def _finish(ax: Axes, ds: xr.Dataset, x: str, yname: str, ylabel: str, what: str,
            handles: list) -> Figure:
    """Labels with units, title, grid, legend; the Figure."""
    units = _unit(ds[yname])[1]
    ax.set_xlabel(label(ds[x], _unit(ds[x])[1]))
    ax.set_ylabel(f"{ylabel} [{units}]" if units and units != "1" else ylabel)
    ax.set_title(_title(ds, what), fontsize="medium")
    ax.grid(True, color="0.92", zorder=0)
    _plain_ticks(ax)
    if x == POINT_DIM:
        point_ticks(ax, ds, "x")
    _legend(ax, handles)
    return ax.figure


def plot_rms(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
             ax: Axes | None = None) -> Figure:
    """The RMS midspan deflection against the swept axis (span length when swept; m), in mm:
    the mean over the realisations (`rms_deflection_mean`, m) with its 95 % interval
    (`rms_deflection_ci`) as a shaded band, and the exact linear RMS of the same span
    (`linear_rms`, m) dashed in the same colour, so the nonlinearity's effect shows; one line
    per value of at most one other swept axis (e.g. `base_asd_scale`, dB). Returns the
    Figure."""
    ds, x, level, ax = _prepare(ds, select, ax, "rms_deflection_mean")
    handles = _mean_with_band(ax, ds, x, level, "rms_deflection")
    if "linear_rms" in ds and np.isfinite(ds["linear_rms"].values).any():
        xfactor, yfactor = _unit(ds[x])[0], _unit(ds["linear_rms"])[0]
        for i, (part, _text) in enumerate(_levels(ds, level)):
            ax.plot(part[x].values.astype(float) * xfactor,
                    part["linear_rms"].broadcast_like(part[x]).values.astype(float) * yfactor,
                    color=f"C{i % 10}", ls="none" if x == POINT_DIM else "--",
                    marker="_" if x == POINT_DIM else None, ms=12, lw=1.2, zorder=2,
                    gid="linear_rms")
        sets = x == POINT_DIM                 # as drawn: a tick per set, or a dashed line
        handles.append(Line2D([], [], color="0.3", ls="none" if sets else "--",
                              marker="_" if sets else None, ms=12, lw=1.2, label=_LINEAR_LABEL))
    ax.set_ylim(bottom=0.0)
    return _finish(ax, ds, x, "rms_deflection_mean", "RMS midspan deflection", "RMS midspan "
                   f"deflection, mean of {_records(ds)}", handles)


def plot_peak(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
              ax: Axes | None = None) -> Figure:
    """The peak |midspan deflection| over each record's statistics window against the swept
    axis, in mm: the mean over the realisations (`peak_deflection_mean`, m) with its 95 %
    interval as a band, one line per value of at most one other swept axis; the clearance
    levels (`clearance`, m), when the result has them, as grey horizontal lines labelled with
    their value. Returns the Figure."""
    ds, x, level, ax = _prepare(ds, select, ax, "peak_deflection_mean")
    handles = _mean_with_band(ax, ds, x, level, "peak_deflection")
    if CLEARANCE_DIM in ds.coords and ds[CLEARANCE_DIM].ndim == 1:
        factor, units = _unit(ds[CLEARANCE_DIM])
        for value in ds[CLEARANCE_DIM].values.astype(float) * factor:
            ax.axhline(value, color="0.45", ls=":", lw=1.1, zorder=1, gid="clearance")
            ax.annotate(f"clearance {value:.4g} {units}", (1.0, value),
                        xycoords=("axes fraction", "data"), xytext=(-4, 2),
                        textcoords="offset points", ha="right", va="bottom",
                        fontsize="small", color="0.35")
        handles.append(Line2D([], [], color="0.45", ls=":", lw=1.1, label="clearance levels"))
    ax.set_ylim(bottom=0.0)
    return _finish(ax, ds, x, "peak_deflection_mean", "peak midspan deflection", "peak "
                   f"midspan deflection, mean of {_records(ds)}", handles)


def plot_exceedance(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                    ax: Axes | None = None) -> Figure:
    """The probability that |midspan deflection| exceeds each clearance level at least once
    in the test (`exceedance_probability`, 1: from the crossing rate pooled over the
    realisations that did not escape) against the swept axis: one colour per clearance level
    (m, shown in mm), one line style per value of at most one other swept axis. Returns the
    Figure."""
    if CLEARANCE_DIM not in ds.dims:
        raise UserError("the result has no clearance levels (give outputs.clearance)")
    ds, x, level, ax = _prepare(ds, select, ax, "exceedance_probability")
    p = ds["exceedance_probability"]
    mean = p.mean(REALISATION_DIM) if REALISATION_DIM in p.dims else p
    xfactor = _unit(ds[x])[0]
    cfactor, cunits = _unit(ds[CLEARANCE_DIM])
    handles: list = []
    parts = _levels(ds.assign(exceedance_mean=mean), level)
    for k, value in enumerate(ds[CLEARANCE_DIM].values.astype(float)):
        colour = f"C{k % 10}"
        for j, (part, _text) in enumerate(parts):
            ls, marker = _LEVEL_STYLES[j % len(_LEVEL_STYLES)]
            y = part["exceedance_mean"].isel({CLEARANCE_DIM: k}).broadcast_like(part[x])
            ax.plot(part[x].values.astype(float) * xfactor, y.values.astype(float),
                    color=colour, ls="none" if x == POINT_DIM else ls, marker=marker, ms=4,
                    lw=1.4, zorder=3, gid="exceedance")
        handles.append(Line2D([], [], color=colour, lw=2.0,
                              label=f"clearance {value * cfactor:.4g} {cunits}"))
    if level is not None:
        handles += [Line2D([], [], color="0.3", ls=_LEVEL_STYLES[j % len(_LEVEL_STYLES)][0],
                           marker=_LEVEL_STYLES[j % len(_LEVEL_STYLES)][1], ms=4, label=text)
                    for j, (_part, text) in enumerate(parts)]
    ax.set_ylim(-0.02, 1.02)
    return _finish(ax, ds, x, "exceedance_probability",
                   "probability of exceeding the clearance in the test",
                   f"clearance exceedance, pooled over {_records(ds)}", handles)


def peak_factors(ds: xr.Dataset) -> np.ndarray:
    """Every finite peak / RMS of the midspan deflection in `ds` (1), sorted: the records of
    every realisation and point (`peak_deflection` / `rms_deflection`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.asarray(ds["peak_deflection"].values, float) / np.asarray(
            ds["rms_deflection"].values, float)
    return np.sort(ratio[np.isfinite(ratio)].ravel())


def plot_peak_factors(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
                      ax: Axes | None = None) -> Figure:
    """The empirical distribution (fraction of records, 1) of the peak factor, peak / RMS
    midspan deflection over each record's statistics window (1), over every realisation and
    every point of the swept axis: one step curve per value of at most one other swept axis
    (the level), one curve in all without one. Returns the Figure."""
    for need in ("peak_deflection", "rms_deflection"):
        if need not in ds:
            raise UserError(f"the result has no variable '{need}' (not a random result?)")
    ds = select_points(ds, select)
    _x, level = random_axes(ds)
    ax = ax if ax is not None else _new_axes((7.0, 5.4))
    handles = []
    for i, (part, text) in enumerate(_levels(ds, level)):
        values = peak_factors(part)
        if not values.size:
            continue
        fraction = np.arange(1, values.size + 1) / values.size
        line, = ax.step(values, fraction, where="post", color=f"C{i % 10}", lw=1.6,
                        label=f"{text} ({values.size} records)", gid="peak_factors")
        handles.append(line)
    ax.set_xlabel("peak factor, peak / RMS midspan deflection")
    ax.set_ylabel("fraction of records at or below")
    ax.set_ylim(0.0, 1.02)
    ax.set_title(_title(ds, "peak factor over every record"), fontsize="medium")
    ax.grid(True, color="0.92", zorder=0)
    _plain_ticks(ax)
    _legend(ax, handles)
    return ax.figure


def _spread(n: int, most: int) -> list[int]:
    """At most `most` indices of 0..n-1, evenly spread, the first and last included."""
    return sorted({int(round(k)) for k in np.linspace(0, n - 1, min(n, most))})


TITLE_CHARS = 72
"""Characters a line of the ASD figure's title holds at its 7 in width (wrapped beyond)."""


def plot_asd(ds: xr.Dataset, *, select: Mapping[str, Any] | None = None,
             ax: Axes | None = None) -> Figure:
    """The spectral density of the absolute midspan acceleration (`acceleration_asd`, g^2/Hz,
    the mean over the realisations) against frequency (Hz), log-log, over the input spectrum
    at the same level (`base_asd_g2`, dashed black): one line per value of the swept axis drawn
    along elsewhere (span length when swept; at most MAX_LEVELS of them, evenly spread, the
    first and last included), at the highest value of the other swept axis (the level, e.g.
    base_asd_scale in dB) unless `select` fixes it; each span's exact linear density
    (`linear_acceleration_asd`) dashed in its colour. Returns the Figure."""
    if "acceleration_asd" not in ds:
        raise UserError("the result has no variable 'acceleration_asd' (give "
                        "outputs.response_asd = true in a random scene)")
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    x = "length" if "length" in axes else (axes[0] if axes else None)
    dropped = []
    for other in [d for d in axes if d != x]:
        dropped.append(f"the highest of {ds.sizes[other]} values (--select another)")
        ds = ds.isel({other: int(np.argmax(np.asarray(ds[other].values, float)))})
    ax = ax if ax is not None else _new_axes((7.0, 5.4))
    f = np.asarray(ds[ASD_FREQUENCY_DIM].values, float)
    shown = f > 0.0
    handles = []
    picks = [None] if x is None else _spread(ds.sizes[x], MAX_LEVELS)
    for i, k in enumerate(picks):
        part = ds if k is None else ds.isel({x: k})
        y = np.asarray(part["acceleration_asd"].values, float)
        text = (str(ds.attrs.get("title", "response")) if k is None
                else _point_text(part, [x]))
        line, = ax.loglog(f[shown], y[shown], color=f"C{i % 10}", lw=1.2, label=text,
                          gid="acceleration_asd")
        handles.append(line)
        if "linear_acceleration_asd" in part:
            linear = np.asarray(part["linear_acceleration_asd"].values, float)
            ax.loglog(f[shown], linear[shown], color=f"C{i % 10}", ls="--", lw=0.9,
                      zorder=2, gid="linear_acceleration_asd")
    if "linear_acceleration_asd" in ds:
        handles.append(Line2D([], [], color="0.3", ls="--", lw=0.9, label=_LINEAR_LABEL))
    given = np.asarray(ds["base_asd_g2"].values, float)
    if given.ndim > 1:                       # the level's spectrum does not depend on the span
        given = given.reshape(-1, given.shape[-1])[0]
    inside = shown & (given > 0.0)
    line, = ax.loglog(f[inside], given[inside], color="k", ls="--", lw=1.4, zorder=4,
                      label="input (base) spectrum", gid="base_asd_g2")
    handles.append(line)
    if inside.any():                         # the spectrum's band, and what lies in it
        ax.set_xlim(f[inside][0], f[inside][-1])
        drawn = np.concatenate([np.asarray(line.get_ydata(), float)[
            (line.get_xdata() >= f[inside][0]) & (line.get_xdata() <= f[inside][-1])]
            for line in ax.get_lines()])
        drawn = drawn[np.isfinite(drawn) & (drawn > 0.0)]
        if drawn.size:
            ax.set_ylim(drawn.min() / 2.0, drawn.max() * 2.0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("acceleration spectral density [g$^2$/Hz]")
    title = _title(ds, f"midspan acceleration ASD, mean of {_records(ds)}")
    title = "\n".join(textwrap.wrap("; ".join([title] + dropped), TITLE_CHARS))
    ax.set_title(title, fontsize="medium")
    ax.grid(True, which="both", color="0.92", zorder=0)
    _legend(ax, handles)
    return ax.figure
